//! `conemesh bench`: the end-to-end benchmark. Runs `conemesh remesh` on every mesh of a
//! folder (the shared meshes by default), one child process at a time, and writes the table
//! the issues ask for: faces, Table-1 quality, Hausdorff distance, flips, wall time and peak
//! memory per mesh, and whether the Algorithm-1 targets are met.
//!
//! Each mesh runs in its own process so that its peak resident memory is its own (the child
//! reports `VmHWM` in its JSON report) and a failing mesh cannot take the others down.
//!
//! With MMG (`--mmg`, else `mmgs_O3` on PATH, else `$CONEMESH_MMG`) every mesh also runs
//! through MMG on the same input and the metric conemesh's run remeshes to, both outputs scored
//! by `conemesh eval` ([`side_by_side`]); `--threads 1,2` runs conemesh once per thread count
//! and tables the times, the speed-up and whether the outputs are the same.
//!
//! `conemesh bench --suite analytic` runs the generated analytic suite instead, conemesh and
//! MMG side by side ([`analytic`]).

mod analytic;
mod scaling;
mod side_by_side;
mod tools;

use anyhow::{bail, ensure, Context};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::rc::Rc;
use std::time::Duration;
use tools::{FieldError, ToolError};

/// The extensions `conemesh` reads (see `conemesh::io`).
const MESH_EXTENSIONS: [&str; 5] = ["obj", "off", "ply", "stl", "mesh"];

/// The generated suites of `--suite`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Suite {
    /// Surfaces with user-style metrics (`conemesh::suite::ANALYTIC`): conemesh and MMG.
    Analytic,
    /// Generated surfaces of 20k to 1.3M faces (the bumpy sphere and a noisy open scan at
    /// icosphere levels 5-8), run as a folder; adds the fitted time exponent and peak memory.
    Scaling,
}

/// Arguments of `conemesh bench`.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// Meshes to run; without any, every mesh file in `--dir`, by name.
    #[arg(conflicts_with = "suite")]
    pub meshes: Vec<PathBuf>,
    /// Folder whose meshes run when none are named.
    #[arg(long, default_value = "../shared/meshes", conflicts_with = "suite")]
    pub dir: PathBuf,
    /// Folder for the outputs: `remesh.md` (the table), and per mesh `NAME.obj`, `NAME.json`
    /// (the remesh report), `NAME.log` (its stdout and stderr), `NAME-eval.json`/`.log` (its
    /// score); with MMG also `NAME-input.sol` (the metric of the run), `NAME.mesh` (the input
    /// for MMG), `NAME-mmg.mesh`, `NAME-mmg-eval.json` and `NAME-mmg.log`; with `--threads`
    /// the further counts' `NAME-tN.obj`/`.json`/`.log`. With `--suite`:
    /// `analytic.md`, and per case its input `NAME.mesh` + `NAME.sol`, then per tool (`conemesh`,
    /// `mmg`) `NAME-TOOL.obj`/`.mesh`, `NAME-TOOL-eval.json` and `NAME-TOOL.log`.
    #[arg(short, long, default_value = "bench")]
    pub out_dir: PathBuf,
    /// Further arguments for every `conemesh remesh` run, after `--`
    /// (e.g. `conemesh bench -- --sweeps 2 --seed 3`).
    #[arg(last = true)]
    pub remesh_args: Vec<String>,
    /// Run a generated suite instead of mesh files: its cases are written into `--out-dir`
    /// (`NAME.mesh`, `NAME.sol`), conemesh and MMG (when found) run on each, both scored by
    /// `conemesh eval` at L_tar = 1; the table is `analytic.md`.
    #[arg(long, value_enum)]
    pub suite: Option<Suite>,
    /// Suite only: run the cases whose name contains SUBSTRING (repeatable; default all;
    /// the scaling cases are `bumpy-l5` … `bumpy-l8` and `scan-l5` … `scan-l8`).
    #[arg(long = "case", value_name = "SUBSTRING", requires = "suite")]
    pub cases: Vec<String>,
    /// MMG's surface remesher [default: `mmgs_O3` on PATH, else $CONEMESH_MMG; without one
    /// the MMG rows say "not installed"]. On a folder: per mesh, after conemesh's run,
    /// `PATH -in NAME.mesh -sol NAME-input.sol -out NAME-mmg.mesh -nr -hausd 10 -hgrad -1 -v -1`
    /// with the metric conemesh's run remeshes to (`remesh --write-input-metric`, target
    /// length 1), both outputs scored by `conemesh eval` at the run's L_tar.
    #[arg(long, value_name = "PATH")]
    pub mmg: Option<PathBuf>,
    /// Wall-clock limit of every child process, seconds (past it the child is killed and its
    /// row is FAILED).
    #[arg(long, value_name = "SECONDS", default_value_t = 900.0)]
    pub timeout: f64,
    /// Folder only: run conemesh once per thread count of the comma-separated list (`remesh
    /// --threads N`; e.g. `--threads 1,2 -- --batch 8`); the first count's run is the one
    /// tabled and compared with MMG, and a table gives every count's time, the speed-up over
    /// the first and whether the output is byte for byte the first's.
    #[arg(long, value_name = "N,N,...", value_delimiter = ',')]
    pub threads: Vec<usize>,
}

/// Remesh arguments bench sets itself for every run: a second value would only make every
/// run fail (the suite also sets the metric and L_tar).
fn refuse_own_args(remesh_args: &[String], own: &[&str]) -> anyhow::Result<()> {
    if let Some(a) = remesh_args.iter().find(|a| {
        let name = a.split('=').next().unwrap_or(a);
        own.contains(&name)
    }) {
        bail!("`{a}` is set by bench for every run; leave it out of the remesh arguments");
    }
    Ok(())
}

const OWN_ARGS: [&str; 5] = ["-o", "--output", "--report", "-q", "--quiet"];

/// `--timeout` as a duration, refused unless a positive number of seconds.
fn timeout(seconds: f64) -> anyhow::Result<Duration> {
    ensure!(
        seconds > 0.0 && seconds.is_finite(),
        "--timeout must be a positive number of seconds, got {seconds}"
    );
    Ok(Duration::from_secs_f64(seconds))
}

/// The value of `flag` among the remesh arguments (`--flag V` or `--flag=V`).
fn remesh_arg_value<'a>(remesh_args: &'a [String], flag: &str) -> Option<&'a str> {
    remesh_args.iter().enumerate().find_map(|(i, a)| {
        if a == flag {
            remesh_args.get(i + 1).map(String::as_str)
        } else {
            a.strip_prefix(flag).and_then(|v| v.strip_prefix('='))
        }
    })
}

/// The targets of Algorithm 1 before minimum-angle improvement (issue 9, the paper's Table 1
/// level), measured by `eval` against the input at the run's L_tar.
const TARGET_Q_AVG: f64 = 0.85;
const TARGET_THETA_AVG: f64 = 47.0;
const TARGET_HAUSDORFF_REL: f64 = 0.01;

/// One benchmark row.
struct Row {
    name: String,
    outcome: Result<Numbers, Rc<ToolError>>,
    /// The child's wall time, spawn to exit (`None`: it could not start, or timed out).
    wall: Option<f64>,
}

struct Numbers {
    faces_in: u64,
    faces_out: u64,
    patches: u64,
    q_min: f64,
    q_avg: f64,
    theta_min: f64,
    theta_avg: f64,
    hausdorff_rel: f64,
    flips: usize,
    seconds: f64,
    peak_mb: Option<f64>,
    /// The run's target metric edge length (what MMG's output is scored at too).
    l_tar: f64,
}

impl Numbers {
    /// The targets this run misses, by name.
    fn missed(&self) -> Vec<&'static str> {
        let mut m = Vec::new();
        if self.q_avg < TARGET_Q_AVG {
            m.push("q_avg");
        }
        if self.theta_avg < TARGET_THETA_AVG {
            m.push("θ_avg");
        }
        if self.flips > 0 {
            m.push("flips");
        }
        if self.hausdorff_rel > TARGET_HAUSDORFF_REL {
            m.push("Hausdorff");
        }
        m
    }

    /// The numbers of a `conemesh remesh --report` file.
    fn from_report(json: &serde_json::Value) -> Result<Numbers, FieldError> {
        let get = |path: &'static [&'static str]| tools::field(json, "report", path);
        let f = |path: &'static [&'static str]| -> Result<f64, FieldError> {
            get(path)?.as_f64().ok_or(FieldError::NotNumber { path })
        };
        let u = |path: &'static [&'static str]| -> Result<u64, FieldError> {
            get(path)?.as_u64().ok_or(FieldError::NotCount { path })
        };
        const FLIPS: &[&str] = &["eval", "flips"];
        Ok(Numbers {
            faces_in: u(&["run", "faces_in"])?,
            faces_out: u(&["run", "faces_out"])?,
            patches: u(&["run", "patches"])?,
            q_min: f(&["eval", "output_quality", "q_min"])?,
            q_avg: f(&["eval", "output_quality", "q_avg"])?,
            theta_min: f(&["eval", "output_quality", "theta_min"])?,
            theta_avg: f(&["eval", "output_quality", "theta_avg"])?,
            hausdorff_rel: f(&["eval", "distance", "hausdorff_rel"])?,
            flips: get(FLIPS)?
                .as_array()
                .map(|a| a.len())
                .ok_or(FieldError::NotList { path: FLIPS })?,
            seconds: f(&["seconds"])?,
            peak_mb: json.get("peak_rss_mib").and_then(|v| v.as_f64()),
            l_tar: f(&["run", "l_tar"])?,
        })
    }
}

/// Run `conemesh bench`.
pub fn run(args: BenchArgs) -> anyhow::Result<ExitCode> {
    if let Some(Suite::Analytic) = args.suite {
        ensure!(
            args.threads.is_empty(),
            "--threads is for a folder or `--suite scaling`, not the analytic suite"
        );
        return analytic::run(&args);
    }
    let meshes = if args.suite == Some(Suite::Scaling) {
        scaling::write_cases(&args.out_dir, &args.cases)?
    } else if args.meshes.is_empty() {
        meshes_in(&args.dir)?
    } else {
        args.meshes.clone()
    };
    if meshes.is_empty() {
        bail!("no mesh files in {}", args.dir.display());
    }
    let mut own: Vec<&str> = OWN_ARGS.to_vec();
    own.push("--write-input-metric");
    if !args.threads.is_empty() {
        own.push("--threads");
    }
    refuse_own_args(&args.remesh_args, &own)?;
    let timeout = timeout(args.timeout)?;
    if let Some(n) = args.threads.iter().find(|n| **n == 0) {
        bail!("--threads: every thread count must be at least 1, got {n}");
    }
    distinct_stems(&meshes)?;
    let mmg = tools::find_mmg(args.mmg.as_deref())?;
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("creating {}", args.out_dir.display()))?;
    let folder = Folder {
        exe: std::env::current_exe().context("locating the conemesh executable")?,
        out_dir: args.out_dir.clone(),
        remesh_args: args.remesh_args.clone(),
        threads: args.threads.clone(),
        timeout,
        mmg,
        metric: remesh_arg_value(&args.remesh_args, "--metric").map(PathBuf::from),
    };
    refuse_overwriting_inputs(&folder, &meshes, &args.out_dir)?;
    let header = tools::Header::start(folder.mmg.as_deref(), timeout);
    let mut rows = Vec::new();
    for mesh in &meshes {
        rows.push(bench_mesh(&folder, mesh)?);
    }
    let header = header.end();
    let mut table = table(&rows, &folder, &header);
    if args.suite == Some(Suite::Scaling) {
        let points: Vec<scaling::Point> = rows
            .iter()
            .filter_map(|r| {
                let n = r.row.outcome.as_ref().ok()?;
                Some(scaling::Point {
                    name: &r.row.name,
                    faces_in: n.faces_in as f64,
                    seconds: n.seconds,
                    peak_mb: n.peak_mb,
                })
            })
            .collect();
        scaling::section(&mut table, &points);
    }
    print!("{table}");
    let path = args.out_dir.join("remesh.md");
    conemesh::io::write_bytes_atomic(&path, table.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {}", path.display());
    let failed = rows.iter().filter(|r| r.failed()).count();
    if failed > 0 {
        eprintln!("error: {failed} of {} meshes had a failed run", rows.len());
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}

/// Outputs are named by the input's file stem: two inputs with one stem would overwrite each
/// other's output, report and log.
fn distinct_stems(meshes: &[PathBuf]) -> anyhow::Result<()> {
    let mut stems: Vec<(String, &PathBuf)> = meshes.iter().map(|m| (stem(m), m)).collect();
    stems.sort();
    if let Some(w) = stems.windows(2).find(|w| w[0].0 == w[1].0) {
        bail!(
            "{} and {} share the name `{}` (outputs are named by it); bench them separately",
            w[0].1.display(),
            w[1].1.display(),
            w[0].0
        );
    }
    Ok(())
}

/// An output must not replace its input (a mesh benched from inside the output folder).
fn refuse_overwriting_inputs(
    folder: &Folder,
    meshes: &[PathBuf],
    out_dir: &Path,
) -> anyhow::Result<()> {
    let out_dir = out_dir
        .canonicalize()
        .with_context(|| format!("resolving {}", out_dir.display()))?;
    for mesh in meshes {
        let input = mesh
            .canonicalize()
            .with_context(|| format!("reading {}", mesh.display()))?;
        let name = stem(mesh);
        if folder
            .outputs(&name, mesh)
            .iter()
            .any(|o| input == out_dir.join(o.file_name().unwrap_or_default()))
        {
            bail!(
                "{} would be overwritten by its own output; choose another --out-dir",
                mesh.display()
            );
        }
    }
    Ok(())
}

/// One mesh's runs: conemesh (again at each further thread count, compared byte for byte),
/// then MMG beside it.
fn bench_mesh(folder: &Folder, mesh: &Path) -> anyhow::Result<MeshRows> {
    let name = stem(mesh);
    // A stale report must not be read as this run's, nor a stale mesh stand beside a
    // failed run.
    for stale in folder.outputs(&name, mesh) {
        remove_stale(&stale)?;
    }
    let row = folder.remesh(mesh, &name, "", folder.threads.first().copied())?;
    eprintln!("{}", row_text(&row));
    let mut threads = Vec::new();
    for &n in folder.threads.iter().skip(1) {
        let other = folder.remesh(mesh, &name, &format!("-t{n}"), Some(n))?;
        let same = match (&row.outcome, &other.outcome) {
            (Ok(_), Ok(_)) => Some(same_bytes(
                &folder.path(&name, ".obj"),
                &folder.path(&name, &format!("-t{n}.obj")),
            )),
            _ => None,
        };
        threads.push(ThreadRun {
            outcome: other.outcome.map(|o| o.seconds),
            same,
        });
    }
    let pair = side_by_side::run_mesh(folder, mesh, &name, &row)?;
    for t in [&pair.conemesh, &pair.mmg] {
        eprintln!("{}", tools::tool_row(&name, t, pair.time_ratio()));
    }
    Ok(MeshRows { row, threads, pair })
}

impl MeshRows {
    /// Whether any of the mesh's runs failed, or a thread count changed the output.
    fn failed(&self) -> bool {
        self.row.outcome.is_err()
            || self
                .threads
                .iter()
                .any(|t| t.outcome.is_err() || t.same == Some(false))
            || [&self.pair.conemesh, &self.pair.mmg]
                .iter()
                .any(|t| matches!(t.outcome, tools::Outcome::Failed { .. }))
    }
}

/// What every mesh's runs share.
struct Folder {
    exe: PathBuf,
    out_dir: PathBuf,
    remesh_args: Vec<String>,
    /// `--threads`: the thread counts, the first for the tabled run (empty: remesh's default).
    threads: Vec<usize>,
    timeout: Duration,
    mmg: Option<PathBuf>,
    /// The remesh arguments' `--metric`, for scoring MMG's output in the same metric.
    metric: Option<PathBuf>,
}

impl Folder {
    fn path(&self, name: &str, suffix: &str) -> PathBuf {
        self.out_dir.join(format!("{name}{suffix}"))
    }

    /// Every file bench writes for the mesh `name` at `input` (the table aside).
    fn outputs(&self, name: &str, input: &Path) -> Vec<PathBuf> {
        let mut suffixes: Vec<String> = [".obj", ".json", ".log", "-eval.json", "-eval.log"]
            .map(String::from)
            .to_vec();
        if self.mmg.is_some() {
            suffixes.extend(
                [
                    "-input.sol",
                    "-mmg.mesh",
                    "-mmg.sol",
                    "-mmg-eval.json",
                    "-mmg.log",
                ]
                .map(String::from),
            );
            if side_by_side::needs_conversion(input) {
                suffixes.push(".mesh".into());
            }
        }
        for n in self.threads.iter().skip(1) {
            suffixes.extend([".obj", ".json", ".log"].map(|s| format!("-t{n}{s}")));
        }
        suffixes.iter().map(|s| self.path(name, s)).collect()
    }

    /// One `conemesh remesh` run of `mesh` writing `NAME{tag}.obj`, `.json` and `.log` (with
    /// `--threads N` when given; with `--write-input-metric NAME-input.sol` for MMG on the
    /// tabled run). Only a log the out dir refuses is an error; a failing run is a FAILED row.
    fn remesh(
        &self,
        mesh: &Path,
        name: &str,
        tag: &str,
        threads: Option<usize>,
    ) -> anyhow::Result<Row> {
        let out = self.path(name, &format!("{tag}.obj"));
        let report = self.path(name, &format!("{tag}.json"));
        let mut cmd = Command::new(&self.exe);
        cmd.arg("remesh")
            .arg(mesh)
            .arg("-o")
            .arg(&out)
            .arg("--report")
            .arg(&report)
            .arg("--quiet");
        if let Some(n) = threads {
            cmd.args(["--threads", &n.to_string()]);
        }
        if self.mmg.is_some() && tag.is_empty() {
            cmd.arg("--write-input-metric")
                .arg(self.path(name, "-input.sol"));
        }
        cmd.args(&self.remesh_args);
        let (outcome, wall) = match tools::run_timed(&mut cmd, self.timeout) {
            Err(source) => (
                Err(Rc::new(ToolError::NoExit {
                    step: Some("remesh"),
                    source,
                })),
                None,
            ),
            Ok(child) => {
                let mut log = child.stdout.clone();
                log.extend_from_slice(&child.stderr);
                let log_path = self.path(name, &format!("{tag}.log"));
                conemesh::io::write_bytes_atomic(&log_path, &log)
                    .with_context(|| format!("writing {}", log_path.display()))?;
                let outcome = if child.status.success() {
                    tools::read_json(&report)
                        .and_then(|j| Ok(Numbers::from_report(&j)?))
                        .map_err(Rc::new)
                } else {
                    Err(Rc::new(ToolError::failed("remesh", &child)))
                };
                (outcome, Some(child.wall))
            }
        };
        Ok(Row {
            name: name.to_string(),
            outcome,
            wall,
        })
    }
}

/// The two files have the same bytes (both readable).
fn same_bytes(a: &Path, b: &Path) -> bool {
    matches!((std::fs::read(a), std::fs::read(b)), (Ok(x), Ok(y)) if x == y)
}

/// A further thread count's run of one mesh.
struct ThreadRun {
    /// The run's own time (`remesh s`), or why it failed.
    outcome: Result<f64, Rc<ToolError>>,
    /// Its output is byte for byte the tabled run's (`None`: one of them failed).
    same: Option<bool>,
}

/// Everything one mesh gave.
struct MeshRows {
    row: Row,
    threads: Vec<ThreadRun>,
    pair: tools::Pair,
}

/// Remove a previous run's output, so that it is not read as this run's nor left beside a
/// failed run.
fn remove_stale(path: &Path) -> anyhow::Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(e).with_context(|| format!("removing {}", path.display()))
        }
        _ => Ok(()),
    }
}

/// A mesh's name in the table and in its output files: the file stem.
fn stem(mesh: &Path) -> String {
    mesh.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| mesh.display().to_string())
}

/// Text for a Markdown table cell.
fn cell(s: &str) -> String {
    s.replace('|', "\\|")
}

/// The mesh files of `dir`, sorted by file name.
fn meshes_in(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))? {
        let path = entry
            .with_context(|| format!("reading {}", dir.display()))?
            .path();
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if path.is_file() && ext.is_some_and(|e| MESH_EXTENSIONS.contains(&e.as_str())) {
            out.push(path);
        }
    }
    out.sort_by(|a, b| a.file_name().cmp(&b.file_name()));
    Ok(out)
}

fn row_text(r: &Row) -> String {
    match &r.outcome {
        Ok(n) => {
            let missed = n.missed();
            format!(
                "| {} | {} | {} | {:.3} / {:.3} | {:.2} / {:.2} | {:.2} | {} | {} | {:.2} | {} | {} | {} |",
                cell(&r.name),
                n.faces_in,
                n.faces_out,
                n.q_min,
                n.q_avg,
                n.theta_min,
                n.theta_avg,
                100.0 * n.hausdorff_rel,
                n.flips,
                n.patches,
                n.seconds,
                seconds(r.wall),
                n.peak_mb.map_or("-".into(), |m| format!("{m:.0}")),
                if missed.is_empty() {
                    "met".to_string()
                } else {
                    format!("missed: {}", missed.join(", "))
                }
            )
        }
        Err(e) => format!(
            "| {} | - | - | - | - | - | - | - | - | {} | - | FAILED: {} |",
            cell(&r.name),
            seconds(r.wall),
            cell(&e.to_string())
        ),
    }
}

/// A time in seconds for a cell, `-` when there is none.
fn seconds(t: Option<f64>) -> String {
    t.map_or("-".to_string(), |t| format!("{t:.2}"))
}

/// `remesh.md`: conemesh's table, then conemesh and MMG side by side, then (with several
/// `--threads`) the thread counts.
fn table(rows: &[MeshRows], folder: &Folder, header: &tools::Header) -> String {
    let remesh_args = &folder.remesh_args;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# conemesh bench: `conemesh remesh MESH{}{}`, one process per mesh\n",
        if remesh_args.is_empty() { "" } else { " " },
        remesh_args.join(" ").replace('`', "'")
    );
    let _ = writeln!(
        s,
        "Quality and distance from `eval` of the written output against its input (metric space, \
         L_tar of the run); Hausdorff in % of the input's bounding-box diagonal; `remesh s` is the \
         run's own time (reading, metric, Algorithm 1 with its certificates), `wall s` the whole \
         process's (also `eval` and writing); \
         peak MiB is the process's peak resident memory (VmHWM). Targets (issue 9): q_avg ≥ {TARGET_Q_AVG}, \
         θ_avg ≥ {TARGET_THETA_AVG}°, 0 flips, Hausdorff ≤ {} %.{}\n",
        100.0 * TARGET_HAUSDORFF_REL,
        match folder.threads.first() {
            Some(n) => format!(" Every run here with `--threads {n}`."),
            None => String::new(),
        }
    );
    let _ = writeln!(
        s,
        "| mesh | F in | F out | q_min / q_avg | θ_min / θ_avg (°) | Hausdorff % | flips | patches | remesh s | wall s | peak MiB | targets |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(s, "{}", row_text(&r.row));
    }
    side_by_side::section(
        &mut s,
        rows.iter().map(|r| (r.row.name.as_str(), &r.pair)),
        folder,
        header,
    );
    if folder.threads.len() > 1 {
        threads_section(&mut s, rows, &folder.threads);
    }
    s
}

/// The thread counts' table: each count's own time, the speed-up over the first count, and
/// whether the output is the first count's byte for byte.
fn threads_section(s: &mut String, rows: &[MeshRows], counts: &[usize]) {
    let first = counts[0];
    let others = &counts[1..];
    let _ = writeln!(s, "\n## Thread counts\n");
    let _ = writeln!(
        s,
        "`remesh s` (the run's own time, from its report) of `conemesh remesh MESH --threads N` \
         per count N, run one after the other; speed-up = the time at {first} over the time at N; \
         same output = the output file is byte for byte the one at {first} (it must not depend on \
         the thread count).\n"
    );
    let mut head = format!("| mesh | s at {first} |");
    let mut rule = "|---|---|".to_string();
    for n in others {
        let _ = write!(
            head,
            " s at {n} | speed-up {first}→{n} | same output at {n} |"
        );
        rule.push_str("---|---|---|");
    }
    let _ = writeln!(s, "{head}\n{rule}");
    for r in rows {
        let base = r.row.outcome.as_ref().map(|n| n.seconds);
        let mut line = format!(
            "| {} | {} |",
            cell(&r.row.name),
            match &base {
                Ok(t) => format!("{t:.2}"),
                Err(_) => "FAILED".to_string(),
            }
        );
        for t in &r.threads {
            let (time, speedup) = match (&base, &t.outcome) {
                (Ok(b), Ok(o)) => (format!("{o:.2}"), format!("{:.2}", b / o)),
                (_, Ok(o)) => (format!("{o:.2}"), "-".to_string()),
                (_, Err(e)) => (format!("FAILED: {}", cell(&e.to_string())), "-".to_string()),
            };
            let same = match t.same {
                Some(true) => "yes",
                Some(false) => "NO",
                None => "-",
            };
            let _ = write!(line, " {time} | {speedup} | {same} |");
        }
        let _ = writeln!(s, "{line}");
    }
}
