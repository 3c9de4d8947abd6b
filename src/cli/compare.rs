//! `conemesh compare`: named configurations × inputs × seeds, each run in its own `conemesh
//! remesh` process, tabled with mean ± sd and paired statistics against the first
//! configuration (`conemesh::compare`); `--check snapshot.json` reruns a snapshot and names
//! every difference.

use anyhow::Context;
use conemesh::compare::{self, page, Comparison, Config, Grid, Snapshot, Status};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

/// Arguments of `conemesh compare`.
#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// Input meshes, or folders whose mesh files (.obj, .off, .ply, .stl, .mesh) are taken.
    #[arg(required_unless_present = "check")]
    pub inputs: Vec<PathBuf>,
    /// A configuration, `NAME=ARGS`: `conemesh remesh` arguments, split at white space
    /// (quotes keep one argument together), e.g. `-c base= -c kring="--strategy kring
    /// --strategy-opt rings=4"`. Repeatable; the first is the one the others are compared
    /// with. Leave out the flags compare sets (-o, --report, --write-metric, --seed, --quiet,
    /// --debug-dir).
    #[arg(short = 'c', long = "config-arg", value_name = "NAME=ARGS")]
    pub configs: Vec<String>,
    /// A TOML file listing configurations (`[[config]]` tables with `name` and `args`, a
    /// string or a list), before those of `-c`.
    #[arg(long = "config", value_name = "FILE.toml")]
    pub config_file: Option<PathBuf>,
    /// Seeds: a range `1-5` (inclusive), a list `1,4,9`, or both.
    #[arg(long, default_value = "1")]
    pub seeds: String,
    /// Runs at once (each its own process).
    #[arg(short, long, default_value_t = 1)]
    pub jobs: usize,
    /// Time limit of every run (and picture), seconds; a run past it is killed and its row
    /// says "timeout".
    #[arg(long, value_name = "SECONDS", default_value_t = 1800.0)]
    pub timeout: f64,
    /// The folder written: `compare.md`, `compare.json`, `index.html`, `snapshot.json`, the
    /// plots (`plot-MEASURE.png`, `hist_*.png`) and per run `CONFIG--MESH--sSEED` `.obj`
    /// (output), `.json` (report), `.sol` (metric at the output), `.log` and `.png` (its
    /// picture by `conemesh render`, where this binary has it). All or nothing: a failure
    /// leaves no partial folder.
    #[arg(short, long, default_value = "compare")]
    pub out_dir: PathBuf,
    /// Do not draw the outputs.
    #[arg(long)]
    pub no_pictures: bool,
    /// Rerun what this snapshot lists (configurations, inputs, seeds) and report every input
    /// byte, output byte, measure or resolved option that differs: exit 0 printing
    /// "identical", 1 on any drift, 2 when the snapshot cannot be read or rerun.
    #[arg(long, value_name = "snapshot.json", conflicts_with_all = ["inputs", "configs", "config_file", "no_pictures"])]
    pub check: Option<PathBuf>,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Run `conemesh compare`.
pub fn run(args: CompareArgs) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(
        args.jobs >= 1,
        "--jobs must be at least 1 (got {})",
        args.jobs
    );
    if let Some(snapshot) = &args.check {
        return check(&args, snapshot);
    }
    let mut configs = match &args.config_file {
        Some(p) => compare::config::read_config_file(p)?,
        None => Vec::new(),
    };
    for c in &args.configs {
        configs.push(Config::parse(c)?);
    }
    compare::config::check_configs(&configs)?;
    let seeds = compare::config::parse_seeds(&args.seeds)?;
    let inputs = compare::config::collect_inputs(&args.inputs)?;
    super::check_plots_folder("--out-dir", &args.out_dir)?;
    let grid = Grid {
        exe: std::env::current_exe().context("locating the conemesh executable")?,
        configs,
        inputs,
        seeds,
        timeout: timeout(args.timeout)?,
        jobs: args.jobs,
        pictures: !args.no_pictures,
    };
    let hashes = input_hashes(&grid)?;
    let mut outputs = conemesh::io::Outputs::new();
    let dir = outputs
        .dir(&args.out_dir)
        .with_context(|| format!("writing {}", args.out_dir.display()))?;
    let jobs = grid.jobs();
    let records = run_grid(&grid, &jobs, &dir, args.quiet)?;
    let snapshot = Snapshot::of(&grid, &hashes, &records);
    let comparison = Comparison::of(&grid, records);
    page::write_plots(&dir, &comparison)?;
    let md = page::markdown(&comparison);
    let files: [(&str, Vec<u8>); 4] = [
        ("compare.md", md.clone().into_bytes()),
        ("compare.json", serde_json::to_vec_pretty(&comparison)?),
        ("snapshot.json", serde_json::to_vec_pretty(&snapshot)?),
        ("index.html", page::html(&comparison, &dir).into_bytes()),
    ];
    for (name, bytes) in files {
        let p = dir.join(name);
        std::fs::write(&p, bytes).with_context(|| format!("writing {}", p.display()))?;
    }
    super::commit(outputs)?;
    print!("{md}");
    println!("wrote {}", args.out_dir.display());
    let failed = comparison
        .runs
        .iter()
        .filter(|r| r.status != Status::Ok)
        .count();
    if failed > 0 {
        eprintln!(
            "error: {failed} of {} runs did not finish (see compare.md)",
            comparison.runs.len()
        );
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}

/// `--check`: rerun the snapshot's runs in a temporary folder and list the drift.
fn check(args: &CompareArgs, path: &Path) -> anyhow::Result<ExitCode> {
    let old = Snapshot::read(path)?;
    let exe = std::env::current_exe().context("locating the conemesh executable")?;
    let (grid, jobs) = old.grid(exe, args.jobs);
    let hashes = input_hashes(&grid)?;
    let work = tempfile::tempdir().context("creating a temporary folder for the rerun")?;
    let records = run_grid(&grid, &jobs, work.path(), args.quiet)?;
    let now = Snapshot::of(&grid, &hashes, &records);
    if old.conemesh != now.conemesh {
        println!(
            "note: the snapshot was written by conemesh {} ({}), this is {} ({})",
            old.conemesh.version, old.conemesh.commit, now.conemesh.version, now.conemesh.commit
        );
    }
    let drift = old.drift(&now);
    if drift.is_empty() {
        println!(
            "identical: {} runs, every output byte, measure and option",
            jobs.len()
        );
        return Ok(ExitCode::SUCCESS);
    }
    for d in &drift {
        println!("drift: {d}");
    }
    let runs: std::collections::BTreeSet<&str> = drift.iter().map(|d| d.what.as_str()).collect();
    println!(
        "{} differences in {} runs or inputs",
        drift.len(),
        runs.len()
    );
    Ok(ExitCode::from(1))
}

/// Run the grid's cells with a progress bar over the whole grid.
fn run_grid(
    grid: &Grid,
    jobs: &[compare::Job],
    dir: &Path,
    quiet: bool,
) -> anyhow::Result<Vec<compare::RunRecord>> {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::new(jobs.len() as u64);
        // A constant template; should it ever be refused, keep indicatif's default style.
        if let Ok(style) =
            ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} runs, {msg}")
        {
            b.set_style(style.progress_chars("=> "));
        }
        b
    };
    let records = grid.run(jobs, dir, &|r| {
        bar.inc(1);
        bar.set_message(format!(
            "{}/{}/seed {}: {}",
            r.config, r.mesh, r.seed, r.status
        ));
    });
    bar.finish_and_clear();
    Ok(records?)
}

/// Each input's SHA-256, in grid order.
fn input_hashes(grid: &Grid) -> anyhow::Result<Vec<String>> {
    grid.inputs
        .iter()
        .map(|i| {
            compare::grid::sha256_file(&i.path)
                .with_context(|| format!("reading input {}", i.path.display()))
        })
        .collect()
}

/// `--timeout` as a duration, refused unless a positive number of seconds.
fn timeout(seconds: f64) -> anyhow::Result<Duration> {
    anyhow::ensure!(
        seconds > 0.0 && seconds.is_finite(),
        "--timeout must be a positive number of seconds, got {seconds}"
    );
    Ok(Duration::from_secs_f64(seconds))
}
