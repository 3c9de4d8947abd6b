//! What the benchmarks that run other tools share (`--suite analytic` and the folder bench
//! with `--mmg`): finding MMG and its version, running a child with a timeout and timing it,
//! and scoring an output by `conemesh eval`, so that every tool is measured by one yardstick.

use super::cell;
use anyhow::ensure;
use conemesh::compare::process::{error_line, ChildError};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus};
use std::rc::Rc;
use std::time::Duration;

/// MMG's surface remesher, looked up on PATH.
pub(super) const MMG_NAME: &str = "mmgs_O3";
/// The environment variable naming MMG when it is not on PATH.
pub(super) const MMG_ENV: &str = "CONEMESH_MMG";
/// The issue-17 protocol (issue 19 runs it on the shared meshes too): no ridge detection
/// (`-nr`: the suite's surfaces are smooth or flat, their boundaries are kept as boundaries
/// anyway), no geometric approximation control (`-hausd 10`, far above any of the sizes) and
/// no gradation (`-hgrad -1`), so MMG follows the given metric alone, as conemesh does;
/// `-v -1` silences it.
pub(super) const MMG_PROTOCOL: [&str; 7] = ["-nr", "-hausd", "10", "-hgrad", "-1", "-v", "-1"];

/// The MMG binary: `--mmg PATH`, else `mmgs_O3` on PATH, else `$CONEMESH_MMG`; `None` when
/// there is none. A named binary that does not exist is an error naming it.
pub(super) fn find_mmg(option: Option<&Path>) -> anyhow::Result<Option<PathBuf>> {
    if let Some(p) = option {
        ensure!(p.is_file(), "--mmg {}: no such file", p.display());
        return Ok(Some(p.to_path_buf()));
    }
    let on_path = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|d| d.join(MMG_NAME))
            .find(|p| is_executable(p))
    });
    if on_path.is_some() {
        return Ok(on_path);
    }
    match std::env::var_os(MMG_ENV) {
        Some(v) if !v.is_empty() => {
            let p = PathBuf::from(v);
            ensure!(p.is_file(), "{MMG_ENV}={}: no such file", p.display());
            Ok(Some(p))
        }
        _ => Ok(None),
    }
}

fn is_executable(p: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    p.metadata()
        .is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

/// MMG's release line from `-h` (e.g. "MMGS, Release 5.8.0 (Oct. 30, 2024)"), or why not.
pub(super) fn mmg_version(mmg: &Path, timeout: Duration) -> String {
    match run_timed(Command::new(mmg).arg("-h"), timeout) {
        Ok(f) => {
            let text = String::from_utf8_lossy(&f.stdout).into_owned()
                + &String::from_utf8_lossy(&f.stderr);
            text.lines()
                .find(|l| l.contains("Release"))
                .map(|l| l.trim().trim_start_matches("--").trim().to_string())
                .unwrap_or_else(|| "version not printed by -h".to_string())
        }
        Err(e) => format!("version unknown ({e})"),
    }
}

/// The 1-minute load average (`/proc/loadavg`), where there is one.
pub(super) fn load_average() -> Option<String> {
    let s = std::fs::read_to_string("/proc/loadavg").ok()?;
    Some(s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
}

/// What a table's preamble says about the run: MMG's version, the machine's load.
pub(super) struct Header {
    pub mmg_version: Option<String>,
    pub load_start: Option<String>,
    pub load_end: Option<String>,
}

impl Header {
    /// Before the first run.
    pub fn start(mmg: Option<&Path>, timeout: Duration) -> Header {
        Header {
            mmg_version: mmg.map(|p| mmg_version(p, timeout)),
            load_start: load_average(),
            load_end: None,
        }
    }

    /// After the last run.
    pub fn end(self) -> Header {
        Header {
            load_end: load_average(),
            ..self
        }
    }
}

pub(super) use conemesh::compare::process::{run_timed, Finished};

/// Why a tool's run, or its scoring, gave no numbers; a FAILED cell shows its message.
#[derive(Debug, thiserror::Error)]
pub(super) enum ToolError {
    /// The child gave no exit status (`step` names it, except in the tool's own row).
    #[error("{}{source}", step.map_or(String::new(), |s| format!("{s} ")))]
    NoExit {
        /// the child: `remesh`, `eval`, `convert`
        step: Option<&'static str>,
        /// why there is no exit status
        source: ChildError,
    },
    /// The child exited with a failure.
    #[error("{step} failed ({status}): {stderr_line}")]
    Failed {
        /// the child: the tool, `remesh`, `eval`, `convert`
        step: &'static str,
        /// its exit status
        status: ExitStatus,
        /// the line of its stderr that names the error (the child's text, as it wrote it)
        stderr_line: String,
    },
    /// The tool succeeded without writing its output.
    #[error("{tool} exited without writing {}", output.display())]
    NoOutput {
        /// the tool
        tool: &'static str,
        /// the output it was asked for
        output: PathBuf,
    },
    /// A report cannot be read.
    #[error("reading {}: {source}", path.display())]
    Read {
        /// the report
        path: PathBuf,
        /// the OS error
        source: std::io::Error,
    },
    /// A report is not JSON.
    #[error("{}: {source}", path.display())]
    Json {
        /// the report
        path: PathBuf,
        /// the parser's error
        source: serde_json::Error,
    },
    /// A report lacks a number.
    #[error(transparent)]
    Field(#[from] FieldError),
    /// MMG was not run: conemesh's run failed, so there is no metric for it.
    #[error("not run: conemesh failed, so there is no {name}-input.sol")]
    NoMetric {
        /// the input's name
        name: String,
    },
    /// conemesh's run has numbers but no wall time.
    #[error("remesh: no wall time")]
    NoWall,
}

impl ToolError {
    /// The failure of a child that exited with `status`.
    pub(super) fn failed(step: &'static str, f: &Finished) -> ToolError {
        ToolError::Failed {
            step,
            status: f.status,
            stderr_line: error_line(&String::from_utf8_lossy(&f.stderr)).to_string(),
        }
    }
}

/// A field a report (`which`: "report" or "eval report") lacks or holds in another type; `path`
/// is its keys from the top.
#[derive(Debug, thiserror::Error)]
pub(super) enum FieldError {
    /// No such field.
    #[error("the {which} has no `{}`", path.join("."))]
    Missing {
        /// "report" or "eval report"
        which: &'static str,
        /// the keys
        path: &'static [&'static str],
    },
    /// Not a number.
    #[error("`{}` is not a number", path.join("."))]
    NotNumber {
        /// the keys
        path: &'static [&'static str],
    },
    /// Not a count.
    #[error("`{}` is not a count", path.join("."))]
    NotCount {
        /// the keys
        path: &'static [&'static str],
    },
    /// Not a list.
    #[error("`{}` is not a list", path.join("."))]
    NotList {
        /// the keys
        path: &'static [&'static str],
    },
    /// Not a boolean.
    #[error("`{}` is not a boolean", path.join("."))]
    NotBool {
        /// the keys
        path: &'static [&'static str],
    },
}

/// The field at `path` of `json`, a report called `which`.
pub(super) fn field<'a>(
    json: &'a serde_json::Value,
    which: &'static str,
    path: &'static [&'static str],
) -> Result<&'a serde_json::Value, FieldError> {
    path.iter()
        .try_fold(json, |v, k| v.get(k))
        .ok_or(FieldError::Missing { which, path })
}

/// A report read as JSON.
pub(super) fn read_json(path: &Path) -> Result<serde_json::Value, ToolError> {
    let text = std::fs::read_to_string(path).map_err(|source| ToolError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    serde_json::from_str(&text).map_err(|source| ToolError::Json {
        path: path.to_path_buf(),
        source,
    })
}

/// One tool's numbers on one case, from `conemesh eval --json`.
pub(super) struct Score {
    pub faces: u64,
    pub q_min: f64,
    pub q_avg: f64,
    pub theta_min: f64,
    pub theta_avg: f64,
    pub in_range: f64,
    pub mean_ratio: f64,
    pub hausdorff_rel: f64,
    pub flips: usize,
    pub self_intersections: usize,
    pub topology_kept: bool,
}

impl Score {
    pub(super) fn from_eval(json: &serde_json::Value) -> Result<Score, FieldError> {
        let get = |path: &'static [&'static str]| field(json, "eval report", path);
        let f = |path: &'static [&'static str]| -> Result<f64, FieldError> {
            get(path)?.as_f64().ok_or(FieldError::NotNumber { path })
        };
        let len = |path: &'static [&'static str]| -> Result<usize, FieldError> {
            get(path)?
                .as_array()
                .map(|a| a.len())
                .ok_or(FieldError::NotList { path })
        };
        const FACES: &[&str] = &["report", "output", "faces"];
        const KEPT: &[&str] = &["report", "topology_kept"];
        Ok(Score {
            faces: get(FACES)?
                .as_u64()
                .ok_or(FieldError::NotCount { path: FACES })?,
            q_min: f(&["report", "output_quality", "q_min"])?,
            q_avg: f(&["report", "output_quality", "q_avg"])?,
            theta_min: f(&["report", "output_quality", "theta_min"])?,
            theta_avg: f(&["report", "output_quality", "theta_avg"])?,
            in_range: f(&["report", "output_conformity", "fraction_in_range"])?,
            mean_ratio: f(&["report", "output_conformity", "mean"])?,
            hausdorff_rel: f(&["report", "distance", "hausdorff_rel"])?,
            flips: len(&["report", "flips"])?,
            self_intersections: len(&["report", "self_intersections"])?,
            topology_kept: get(KEPT)?
                .as_bool()
                .ok_or(FieldError::NotBool { path: KEPT })?,
        })
    }
}

/// How one tool's run on one case went.
pub(super) enum Outcome {
    /// No MMG binary was found.
    NotInstalled,
    /// The tool or its eval failed (`wall`: the tool's time when it ran to the end).
    Failed {
        error: Rc<ToolError>,
        wall: Option<f64>,
    },
    /// Ran and scored; `own` is conemesh's own time from its report (no eval, no writing).
    Done {
        wall: f64,
        own: Option<f64>,
        score: Score,
    },
}

/// One tool's run on one input.
pub(super) struct ToolRun {
    pub tool: &'static str,
    pub outcome: Outcome,
}

/// conemesh and MMG on one input.
pub(super) struct Pair {
    pub conemesh: ToolRun,
    pub mmg: ToolRun,
}

impl Pair {
    /// conemesh's wall time over MMG's, when both ran.
    pub fn time_ratio(&self) -> Option<f64> {
        time_ratio(&self.conemesh.outcome, &self.mmg.outcome)
    }
}

/// conemesh's wall time over MMG's, when both ran.
pub(super) fn time_ratio(conemesh: &Outcome, mmg: &Outcome) -> Option<f64> {
    match (conemesh, mmg) {
        (Outcome::Done { wall: c, .. }, Outcome::Done { wall: m, .. }) if *m > 0.0 => Some(c / m),
        _ => None,
    }
}

/// The header and separator of the results table whose first column is `first`.
pub(super) fn results_header(first: &str) -> String {
    format!(
        "| {first} | tool | faces | q_min / q_avg | θ_min / θ_avg (°) | in range % | mean L/L_tar | Hausdorff % | flips | valid | wall s | remesh s | conemesh/MMG |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|"
    )
}

/// One tool's Markdown row under [`results_header`] (`ratio`: [`time_ratio`], shown on the
/// conemesh row).
pub(super) fn tool_row(name: &str, t: &ToolRun, ratio: Option<f64>) -> String {
    let name = cell(name);
    let ratio = match (t.tool, ratio) {
        ("conemesh", Some(r)) => format!("{r:.2}"),
        _ => "-".to_string(),
    };
    match &t.outcome {
        Outcome::NotInstalled => format!(
            "| {name} | {} | not installed | - | - | - | - | - | - | - | - | - | - |",
            t.tool
        ),
        Outcome::Failed { error, wall } => format!(
            "| {name} | {} | FAILED: {} | - | - | - | - | - | - | - | {} | - | - |",
            t.tool,
            cell(&error.to_string()),
            wall.map_or("-".to_string(), |w| format!("{w:.2}"))
        ),
        Outcome::Done {
            wall,
            own,
            score: s,
        } => {
            let valid = match (s.self_intersections, s.topology_kept) {
                (0, true) => "yes".to_string(),
                (0, false) => "topology changed".to_string(),
                (n, true) => format!("{n} self-int"),
                (n, false) => format!("{n} self-int, topology changed"),
            };
            format!(
                "| {name} | {} | {} | {:.3} / {:.3} | {:.2} / {:.2} | {:.1} | {:.2} | {:.3} | {} | {valid} | {wall:.2} | {} | {ratio} |",
                t.tool,
                s.faces,
                s.q_min,
                s.q_avg,
                s.theta_min,
                s.theta_avg,
                100.0 * s.in_range,
                s.mean_ratio,
                100.0 * s.hausdorff_rel,
                s.flips,
                own.map_or("-".to_string(), |o| format!("{o:.2}"))
            )
        }
    }
}

/// Run one tool that writes `output`, then score that output with `score`; the tool's and the
/// scoring's stdout and stderr go to `log`. `own` is left `None` for the caller to fill.
pub(super) fn run_and_score(
    tool: &'static str,
    cmd: &mut Command,
    output: &Path,
    timeout: Duration,
    log: &mut Vec<u8>,
    score: impl FnOnce(&mut Vec<u8>) -> Result<Score, ToolError>,
) -> Outcome {
    let ran = run_timed(cmd, timeout)
        .map_err(|source| ToolError::NoExit { step: None, source })
        .and_then(|f| {
            log.extend_from_slice(&f.stdout);
            log.extend_from_slice(&f.stderr);
            if !f.status.success() {
                return Err(ToolError::failed(tool, &f));
            }
            if !output.is_file() {
                return Err(ToolError::NoOutput {
                    tool,
                    output: output.to_path_buf(),
                });
            }
            Ok(f.wall)
        });
    match ran {
        Err(error) => Outcome::Failed {
            error: Rc::new(error),
            wall: None,
        },
        Ok(wall) => match score(log) {
            Err(error) => Outcome::Failed {
                error: Rc::new(error),
                wall: Some(wall),
            },
            Ok(score) => Outcome::Done {
                wall,
                own: None,
                score,
            },
        },
    }
}

/// The yardstick: `conemesh eval --input INPUT --output OUTPUT [--metric M] --ltar L --json
/// JSON` run by `exe` (this executable), its stdout and stderr appended to `log`.
pub(super) struct Eval<'a> {
    pub exe: &'a Path,
    pub input: &'a Path,
    pub metric: Option<&'a Path>,
    /// L_tar as given to `--ltar` (metric length, input file units).
    pub ltar: String,
    pub timeout: Duration,
}

impl Eval<'_> {
    pub fn score(&self, output: &Path, json: &Path, log: &mut Vec<u8>) -> Result<Score, ToolError> {
        let mut cmd = Command::new(self.exe);
        cmd.arg("eval")
            .arg("--input")
            .arg(self.input)
            .arg("--output")
            .arg(output);
        if let Some(m) = self.metric {
            cmd.arg("--metric").arg(m);
        }
        cmd.args(["--ltar", &self.ltar, "--json"]).arg(json);
        let f = run_timed(&mut cmd, self.timeout).map_err(|source| ToolError::NoExit {
            step: Some("eval"),
            source,
        })?;
        log.extend_from_slice(b"\n--- conemesh eval ---\n");
        log.extend_from_slice(&f.stdout);
        log.extend_from_slice(&f.stderr);
        if !f.status.success() {
            return Err(ToolError::failed("eval", &f));
        }
        Ok(Score::from_eval(&read_json(json)?)?)
    }
}

/// conemesh's own time (`seconds` of its report: reading, metric, Algorithm 1 with its
/// certificates; not its built-in eval nor writing).
pub(super) fn own_seconds(report: &Path) -> Option<f64> {
    let text = std::fs::read_to_string(report).ok()?;
    serde_json::from_str::<serde_json::Value>(&text)
        .ok()?
        .get("seconds")?
        .as_f64()
}
