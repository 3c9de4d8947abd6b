//! `conemesh bench`: the end-to-end benchmark. Runs `conemesh remesh` on every mesh of a
//! folder (the shared meshes by default), one child process at a time, and writes the table
//! the issues ask for: faces, Table-1 quality, Hausdorff distance, flips, wall time and peak
//! memory per mesh, and whether the Algorithm-1 targets are met.
//!
//! Each mesh runs in its own process so that its peak resident memory is its own (the child
//! reports `VmHWM` in its JSON report) and a failing mesh cannot take the others down.
//!
//! `conemesh bench --suite analytic` runs the generated analytic suite instead, conemesh and
//! MMG side by side ([`analytic`]).

mod analytic;
mod tools;

use anyhow::{bail, Context};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::time::Instant;

/// The extensions `conemesh` reads (see `conemesh::io`).
const MESH_EXTENSIONS: [&str; 5] = ["obj", "off", "ply", "stl", "mesh"];

/// The generated suites of `--suite`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Suite {
    /// Surfaces with user-style metrics (`conemesh::suite::ANALYTIC`): conemesh and MMG.
    Analytic,
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
    /// (the remesh report) and `NAME.log` (its stdout and stderr). With `--suite`:
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
    /// Suite only: run the cases whose name contains SUBSTRING (repeatable; default all).
    #[arg(long = "case", value_name = "SUBSTRING", requires = "suite")]
    pub cases: Vec<String>,
    /// Suite only: MMG's surface remesher [default: `mmgs_O3` on PATH, else $CONEMESH_MMG;
    /// without one the MMG rows say "not installed"].
    #[arg(long, value_name = "PATH", requires = "suite")]
    pub mmg: Option<PathBuf>,
    /// Suite only: wall-clock limit of every child process, seconds (past it the child is
    /// killed and its row is FAILED).
    #[arg(long, value_name = "SECONDS", default_value_t = 900.0)]
    pub timeout: f64,
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

/// The targets of Algorithm 1 before minimum-angle improvement (issue 9, the paper's Table 1
/// level), measured by `eval` against the input at the run's L_tar.
const TARGET_Q_AVG: f64 = 0.85;
const TARGET_THETA_AVG: f64 = 47.0;
const TARGET_HAUSDORFF_REL: f64 = 0.01;

/// One benchmark row.
struct Row {
    name: String,
    outcome: Result<Numbers, String>,
    wall: f64,
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
    fn from_report(json: &serde_json::Value) -> Result<Numbers, String> {
        let get = |path: &[&str]| -> Result<&serde_json::Value, String> {
            path.iter()
                .try_fold(json, |v, k| v.get(k))
                .ok_or_else(|| format!("the report has no `{}`", path.join(".")))
        };
        let f = |path: &[&str]| -> Result<f64, String> {
            get(path)?
                .as_f64()
                .ok_or_else(|| format!("`{}` is not a number", path.join(".")))
        };
        let u = |path: &[&str]| -> Result<u64, String> {
            get(path)?
                .as_u64()
                .ok_or_else(|| format!("`{}` is not a count", path.join(".")))
        };
        Ok(Numbers {
            faces_in: u(&["run", "faces_in"])?,
            faces_out: u(&["run", "faces_out"])?,
            patches: u(&["run", "patches"])?,
            q_min: f(&["eval", "output_quality", "q_min"])?,
            q_avg: f(&["eval", "output_quality", "q_avg"])?,
            theta_min: f(&["eval", "output_quality", "theta_min"])?,
            theta_avg: f(&["eval", "output_quality", "theta_avg"])?,
            hausdorff_rel: f(&["eval", "distance", "hausdorff_rel"])?,
            flips: get(&["eval", "flips"])?
                .as_array()
                .map(|a| a.len())
                .ok_or("`eval.flips` is not a list")?,
            seconds: f(&["seconds"])?,
            peak_mb: json.get("peak_rss_mib").and_then(|v| v.as_f64()),
        })
    }
}

/// Run `conemesh bench`.
pub fn run(args: BenchArgs) -> anyhow::Result<ExitCode> {
    if let Some(Suite::Analytic) = args.suite {
        return analytic::run(&args);
    }
    let meshes = if args.meshes.is_empty() {
        meshes_in(&args.dir)?
    } else {
        args.meshes.clone()
    };
    if meshes.is_empty() {
        bail!("no mesh files in {}", args.dir.display());
    }
    refuse_own_args(&args.remesh_args, &OWN_ARGS)?;
    // Outputs are named by the input's file stem: two inputs with one stem would overwrite
    // each other's output, report and log.
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
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("creating {}", args.out_dir.display()))?;
    // An output must not replace its input (a mesh benched from inside the output folder).
    let out_dir = args
        .out_dir
        .canonicalize()
        .with_context(|| format!("resolving {}", args.out_dir.display()))?;
    for mesh in &meshes {
        let input = mesh
            .canonicalize()
            .with_context(|| format!("reading {}", mesh.display()))?;
        if input == out_dir.join(format!("{}.obj", stem(mesh))) {
            bail!(
                "{} would be overwritten by its own output; choose another --out-dir",
                mesh.display()
            );
        }
    }
    let exe = std::env::current_exe().context("locating the conemesh executable")?;
    let mut rows = Vec::new();
    for mesh in &meshes {
        let name = stem(mesh);
        let out = args.out_dir.join(format!("{name}.obj"));
        let report = args.out_dir.join(format!("{name}.json"));
        // A stale report must not be read as this run's, nor a stale mesh stand beside a
        // failed run.
        for stale in [&report, &out] {
            remove_stale(stale)?;
        }
        let t0 = Instant::now();
        let child = Command::new(&exe)
            .arg("remesh")
            .arg(mesh)
            .arg("-o")
            .arg(&out)
            .arg("--report")
            .arg(&report)
            .arg("--quiet")
            .args(&args.remesh_args)
            .output()
            .with_context(|| format!("running {} remesh", exe.display()))?;
        let wall = t0.elapsed().as_secs_f64();
        let mut log = child.stdout.clone();
        log.extend_from_slice(&child.stderr);
        let log_path = args.out_dir.join(format!("{name}.log"));
        conemesh::io::write_bytes_atomic(&log_path, &log)
            .with_context(|| format!("writing {}", log_path.display()))?;
        let outcome = if child.status.success() {
            std::fs::read_to_string(&report)
                .map_err(|e| format!("reading {}: {e}", report.display()))
                .and_then(|s| {
                    serde_json::from_str::<serde_json::Value>(&s)
                        .map_err(|e| format!("{}: {e}", report.display()))
                })
                .and_then(|j| Numbers::from_report(&j))
        } else {
            Err(format!(
                "remesh failed ({}): {}",
                child.status,
                error_line(&String::from_utf8_lossy(&child.stderr))
            ))
        };
        let row = Row {
            name,
            outcome,
            wall,
        };
        eprintln!("{}", row_text(&row));
        rows.push(row);
    }
    let table = table(&rows, &args.remesh_args);
    print!("{table}");
    let path = args.out_dir.join("remesh.md");
    conemesh::io::write_bytes_atomic(&path, table.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {}", path.display());
    let failed = rows.iter().filter(|r| r.outcome.is_err()).count();
    if failed > 0 {
        eprintln!("error: {failed} of {} runs failed", rows.len());
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
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

/// The line of a failed child's stderr that names the error (or a panic's message), not a
/// trailing hint.
fn error_line(stderr: &str) -> &str {
    stderr
        .lines()
        .find(|l| l.contains("panicked"))
        .or_else(|| {
            stderr
                .lines()
                .rev()
                .find(|l| !l.trim().is_empty() && !l.starts_with("note:"))
        })
        .unwrap_or("no message")
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
                "| {} | {} | {} | {:.3} / {:.3} | {:.2} / {:.2} | {:.2} | {} | {} | {:.2} | {:.2} | {} | {} |",
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
                r.wall,
                n.peak_mb.map_or("-".into(), |m| format!("{m:.0}")),
                if missed.is_empty() {
                    "met".to_string()
                } else {
                    format!("missed: {}", missed.join(", "))
                }
            )
        }
        Err(e) => format!(
            "| {} | - | - | - | - | - | - | - | - | {:.2} | - | FAILED: {} |",
            cell(&r.name),
            r.wall,
            cell(e)
        ),
    }
}

fn table(rows: &[Row], remesh_args: &[String]) -> String {
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
         θ_avg ≥ {TARGET_THETA_AVG}°, 0 flips, Hausdorff ≤ {} %.\n",
        100.0 * TARGET_HAUSDORFF_REL
    );
    let _ = writeln!(
        s,
        "| mesh | F in | F out | q_min / q_avg | θ_min / θ_avg (°) | Hausdorff % | flips | patches | remesh s | wall s | peak MiB | targets |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(s, "{}", row_text(r));
    }
    s
}
