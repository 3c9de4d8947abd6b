//! `conemesh bench --suite analytic`: the analytic suite ([`conemesh::suite`]) written into the
//! out dir, then per case, each in a child process of its own, `conemesh remesh` and, when an
//! MMG binary is found, `mmgs_O3` with the issue-17 protocol on the same `.mesh` and `.sol`;
//! both outputs scored by `conemesh eval` at L_tar = 1 against the case's input and metric.
//! Writes `analytic.md` (printed too): per case and tool faces, Table-1 quality, edge
//! conformity, Hausdorff distance, flips, validity and wall time, and the time ratio.
//!
//! A failing or timed-out child is a `FAILED` row naming its error; the other runs go on, and
//! the exit code is then 1. Without MMG its rows say "not installed" (not a failure).

use super::{cell, error_line, refuse_own_args, remove_stale, BenchArgs, OWN_ARGS};
use anyhow::{ensure, Context};
use conemesh::suite::{self, Case, CaseFiles};
use std::fmt::Write as _;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// MMG's surface remesher, looked up on PATH.
const MMG_NAME: &str = "mmgs_O3";
/// The environment variable naming MMG when it is not on PATH.
const MMG_ENV: &str = "CONEMESH_MMG";
/// The issue-17 protocol: no ridge detection (`-nr`: the suite's surfaces are smooth or
/// flat, their boundaries are kept as boundaries anyway), no geometric approximation control
/// (`-hausd 10`, far above any of the suite's sizes) and no gradation (`-hgrad -1`), so MMG
/// follows the given metric alone, as conemesh does; `-v -1` silences it.
const MMG_PROTOCOL: [&str; 7] = ["-nr", "-hausd", "10", "-hgrad", "-1", "-v", "-1"];

/// Every run's target metric length: the suite's metrics put an edge on target at length 1.
const LTAR: &str = "1";

/// Run `conemesh bench --suite analytic`.
pub(super) fn run(args: &BenchArgs) -> anyhow::Result<ExitCode> {
    let mut own: Vec<&str> = OWN_ARGS.to_vec();
    own.extend(["--metric", "--ltar", "--ltar-factor"]);
    refuse_own_args(&args.remesh_args, &own)?;
    ensure!(
        args.timeout > 0.0 && args.timeout.is_finite(),
        "--timeout must be a positive number of seconds, got {}",
        args.timeout
    );
    let cases = suite::select(suite::ANALYTIC, &args.cases)?;
    let mmg = find_mmg(args.mmg.as_deref())?;
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("creating {}", args.out_dir.display()))?;
    let runner = Runner {
        exe: std::env::current_exe().context("locating the conemesh executable")?,
        out_dir: args.out_dir.clone(),
        mmg,
        remesh_args: args.remesh_args.clone(),
        timeout: Duration::from_secs_f64(args.timeout),
    };
    let header = Header {
        mmg_version: runner
            .mmg
            .as_deref()
            .map(|p| mmg_version(p, runner.timeout)),
        load_start: load_average(),
        load_end: None,
    };
    let mut rows = Vec::new();
    for case in cases {
        let row = runner.run_case(case)?;
        for t in [&row.conemesh, &row.mmg] {
            eprintln!("{}", tool_row(&row, t));
        }
        rows.push(row);
    }
    let header = Header {
        load_end: load_average(),
        ..header
    };
    let table = table(&rows, &runner, &header);
    print!("{table}");
    let path = args.out_dir.join("analytic.md");
    conemesh::io::write_bytes_atomic(&path, table.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {}", path.display());
    let failed = rows
        .iter()
        .flat_map(|r| [&r.conemesh, &r.mmg])
        .filter(|t| matches!(t.outcome, Outcome::Failed { .. }))
        .count();
    if failed > 0 {
        eprintln!("error: {failed} run(s) failed");
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}

/// The MMG binary: `--mmg PATH`, else `mmgs_O3` on PATH, else `$CONEMESH_MMG`; `None` when
/// there is none. A named binary that does not exist is an error naming it.
fn find_mmg(option: Option<&Path>) -> anyhow::Result<Option<PathBuf>> {
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
fn mmg_version(mmg: &Path, timeout: Duration) -> String {
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
fn load_average() -> Option<String> {
    let s = std::fs::read_to_string("/proc/loadavg").ok()?;
    Some(s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
}

/// What the table's preamble says about the run.
struct Header {
    mmg_version: Option<String>,
    load_start: Option<String>,
    load_end: Option<String>,
}

/// A finished child process.
struct Finished {
    status: ExitStatus,
    stdout: Vec<u8>,
    stderr: Vec<u8>,
    /// Wall-clock seconds from spawn to exit.
    wall: f64,
}

/// Run `cmd` (stdin closed, stdout and stderr captured) for at most `timeout`; a child still
/// running then is killed. The wall time is the whole process's, spawn to exit.
fn run_timed(cmd: &mut Command, timeout: Duration) -> Result<Finished, String> {
    let t0 = Instant::now();
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start {:?}: {e}", cmd.get_program()))?;
    // Readers drain the pipes while we wait, so a chatty child never blocks on a full pipe.
    let drain = |pipe: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            if let Some(mut p) = pipe {
                let _ = p.read_to_end(&mut buf);
            }
            buf
        })
    };
    let out = drain(
        child
            .stdout
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let err = drain(
        child
            .stderr
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    // Poll with a short, growing sleep: the timing error stays below a few milliseconds.
    let mut nap = Duration::from_micros(200);
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if t0.elapsed() > timeout => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(format!(
                    "timed out after {} s (killed)",
                    timeout.as_secs_f64()
                ));
            }
            Ok(None) => {
                std::thread::sleep(nap);
                nap = (nap * 2).min(Duration::from_millis(5));
            }
            Err(e) => return Err(format!("waiting for {:?}: {e}", cmd.get_program())),
        }
    };
    let wall = t0.elapsed().as_secs_f64();
    Ok(Finished {
        status,
        stdout: out.join().unwrap_or_default(),
        stderr: err.join().unwrap_or_default(),
        wall,
    })
}

/// One tool's numbers on one case, from `conemesh eval --json`.
struct Score {
    faces: u64,
    q_min: f64,
    q_avg: f64,
    theta_min: f64,
    theta_avg: f64,
    in_range: f64,
    mean_ratio: f64,
    hausdorff_rel: f64,
    flips: usize,
    self_intersections: usize,
    topology_kept: bool,
}

impl Score {
    fn from_eval(json: &serde_json::Value) -> Result<Score, String> {
        let get = |path: &[&str]| -> Result<&serde_json::Value, String> {
            path.iter()
                .try_fold(json, |v, k| v.get(k))
                .ok_or_else(|| format!("the eval report has no `{}`", path.join(".")))
        };
        let f = |path: &[&str]| -> Result<f64, String> {
            get(path)?
                .as_f64()
                .ok_or_else(|| format!("`{}` is not a number", path.join(".")))
        };
        let len = |path: &[&str]| -> Result<usize, String> {
            get(path)?
                .as_array()
                .map(|a| a.len())
                .ok_or_else(|| format!("`{}` is not a list", path.join(".")))
        };
        Ok(Score {
            faces: get(&["report", "output", "faces"])?
                .as_u64()
                .ok_or("`report.output.faces` is not a count")?,
            q_min: f(&["report", "output_quality", "q_min"])?,
            q_avg: f(&["report", "output_quality", "q_avg"])?,
            theta_min: f(&["report", "output_quality", "theta_min"])?,
            theta_avg: f(&["report", "output_quality", "theta_avg"])?,
            in_range: f(&["report", "output_conformity", "fraction_in_range"])?,
            mean_ratio: f(&["report", "output_conformity", "mean"])?,
            hausdorff_rel: f(&["report", "distance", "hausdorff_rel"])?,
            flips: len(&["report", "flips"])?,
            self_intersections: len(&["report", "self_intersections"])?,
            topology_kept: get(&["report", "topology_kept"])?
                .as_bool()
                .ok_or("`report.topology_kept` is not a boolean")?,
        })
    }
}

/// How one tool's run on one case went.
enum Outcome {
    /// No MMG binary was found.
    NotInstalled,
    /// The tool or its eval failed (`wall`: the tool's time when it ran to the end).
    Failed { error: String, wall: Option<f64> },
    /// Ran and scored; `own` is conemesh's own time from its report (no eval, no writing).
    Done {
        wall: f64,
        own: Option<f64>,
        score: Score,
    },
}

/// One tool's row.
struct ToolRun {
    tool: &'static str,
    outcome: Outcome,
}

/// One case's two rows.
struct CaseRow {
    case: &'static Case,
    files: CaseFiles,
    conemesh: ToolRun,
    mmg: ToolRun,
}

impl CaseRow {
    /// conemesh's wall time over MMG's, when both ran.
    fn time_ratio(&self) -> Option<f64> {
        match (&self.conemesh.outcome, &self.mmg.outcome) {
            (Outcome::Done { wall: c, .. }, Outcome::Done { wall: m, .. }) if *m > 0.0 => {
                Some(c / m)
            }
            _ => None,
        }
    }
}

/// What every case's runs share.
struct Runner {
    exe: PathBuf,
    out_dir: PathBuf,
    mmg: Option<PathBuf>,
    remesh_args: Vec<String>,
    timeout: Duration,
}

impl Runner {
    fn path(&self, name: &str, suffix: &str) -> PathBuf {
        self.out_dir.join(format!("{name}{suffix}"))
    }

    /// Write the case, run both tools and score them. Only a file the out dir refuses is an
    /// error (the next case would fail the same way); a failing run is a FAILED row.
    fn run_case(&self, case: &'static Case) -> anyhow::Result<CaseRow> {
        let files = case.write(&self.out_dir).with_context(|| {
            format!("writing case {} into {}", case.name, self.out_dir.display())
        })?;
        let name = case.name;
        for suffix in [
            "-conemesh.obj",
            "-conemesh.json",
            "-conemesh-eval.json",
            "-mmg.mesh",
            "-mmg.sol",
            "-mmg-eval.json",
        ] {
            remove_stale(&self.path(name, suffix))?;
        }
        let mut remesh = Command::new(&self.exe);
        remesh
            .arg("remesh")
            .arg(&files.mesh)
            .arg("--metric")
            .arg(&files.sol)
            .args(["--ltar", LTAR, "-o"])
            .arg(self.path(name, "-conemesh.obj"))
            .arg("--report")
            .arg(self.path(name, "-conemesh.json"))
            .arg("--quiet")
            .args(&self.remesh_args);
        let conemesh = self.run_tool("conemesh", &mut remesh, name, &files, "-conemesh.obj")?;
        let mmg = match &self.mmg {
            None => ToolRun {
                tool: "MMG",
                outcome: Outcome::NotInstalled,
            },
            Some(bin) => {
                let mut cmd = Command::new(bin);
                cmd.arg("-in")
                    .arg(&files.mesh)
                    .arg("-sol")
                    .arg(&files.sol)
                    .arg("-out")
                    .arg(self.path(name, "-mmg.mesh"))
                    .args(MMG_PROTOCOL);
                self.run_tool("MMG", &mut cmd, name, &files, "-mmg.mesh")?
            }
        };
        Ok(CaseRow {
            case,
            files,
            conemesh,
            mmg,
        })
    }

    /// Run one tool writing `NAME{out_suffix}`, then score that output; the tool's and the
    /// eval's stdout and stderr go to `NAME-{tool}.log`.
    fn run_tool(
        &self,
        tool: &'static str,
        cmd: &mut Command,
        name: &str,
        files: &CaseFiles,
        out_suffix: &str,
    ) -> anyhow::Result<ToolRun> {
        let key = tool.to_ascii_lowercase();
        let output = self.path(name, out_suffix);
        let mut log = Vec::new();
        let ran = run_timed(cmd, self.timeout).and_then(|f| {
            log.extend_from_slice(&f.stdout);
            log.extend_from_slice(&f.stderr);
            if !f.status.success() {
                return Err(format!(
                    "{tool} failed ({}): {}",
                    f.status,
                    error_line(&String::from_utf8_lossy(&f.stderr))
                ));
            }
            if !output.is_file() {
                return Err(format!(
                    "{tool} exited without writing {}",
                    output.display()
                ));
            }
            Ok(f.wall)
        });
        let outcome = match ran {
            Err(error) => Outcome::Failed { error, wall: None },
            Ok(wall) => {
                let eval_json = self.path(name, &format!("-{key}-eval.json"));
                match self.score(files, &output, &eval_json, &mut log) {
                    Err(error) => Outcome::Failed {
                        error,
                        wall: Some(wall),
                    },
                    Ok(score) => Outcome::Done {
                        wall,
                        own: (tool == "conemesh")
                            .then(|| own_seconds(&self.path(name, "-conemesh.json")))
                            .flatten(),
                        score,
                    },
                }
            }
        };
        let log_path = self.path(name, &format!("-{key}.log"));
        conemesh::io::write_bytes_atomic(&log_path, &log)
            .with_context(|| format!("writing {}", log_path.display()))?;
        Ok(ToolRun { tool, outcome })
    }

    /// `conemesh eval --input NAME.mesh --output OUT --metric NAME.sol --ltar 1 --json J`.
    fn score(
        &self,
        files: &CaseFiles,
        output: &Path,
        json: &Path,
        log: &mut Vec<u8>,
    ) -> Result<Score, String> {
        let mut cmd = Command::new(&self.exe);
        cmd.arg("eval")
            .arg("--input")
            .arg(&files.mesh)
            .arg("--output")
            .arg(output)
            .arg("--metric")
            .arg(&files.sol)
            .args(["--ltar", LTAR, "--json"])
            .arg(json);
        let f = run_timed(&mut cmd, self.timeout).map_err(|e| format!("eval {e}"))?;
        log.extend_from_slice(b"\n--- conemesh eval ---\n");
        log.extend_from_slice(&f.stdout);
        log.extend_from_slice(&f.stderr);
        if !f.status.success() {
            return Err(format!(
                "eval failed ({}): {}",
                f.status,
                error_line(&String::from_utf8_lossy(&f.stderr))
            ));
        }
        let text = std::fs::read_to_string(json)
            .map_err(|e| format!("reading {}: {e}", json.display()))?;
        let value: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| format!("{}: {e}", json.display()))?;
        Score::from_eval(&value)
    }
}

/// conemesh's own time (`seconds` of its report: reading, metric, Algorithm 1 with its
/// certificates; not its built-in eval nor writing).
fn own_seconds(report: &Path) -> Option<f64> {
    let text = std::fs::read_to_string(report).ok()?;
    serde_json::from_str::<serde_json::Value>(&text)
        .ok()?
        .get("seconds")?
        .as_f64()
}

/// One Markdown row.
fn tool_row(row: &CaseRow, t: &ToolRun) -> String {
    let name = cell(row.case.name);
    let ratio = match (t.tool, row.time_ratio()) {
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
            cell(error),
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

/// `analytic.md`: the commands, the machine's load, the cases, the results.
fn table(rows: &[CaseRow], runner: &Runner, header: &Header) -> String {
    let mut s = String::new();
    let extra = if runner.remesh_args.is_empty() {
        String::new()
    } else {
        format!(" {}", runner.remesh_args.join(" ").replace('`', "'"))
    };
    let _ = writeln!(s, "# conemesh bench --suite analytic\n");
    let _ = writeln!(
        s,
        "- conemesh: `conemesh remesh NAME.mesh --metric NAME.sol --ltar 1 -o NAME-conemesh.obj --report NAME-conemesh.json --quiet{extra}`"
    );
    let _ = match (&runner.mmg, &header.mmg_version) {
        (Some(p), Some(v)) => writeln!(
            s,
            "- MMG: `{} -in NAME.mesh -sol NAME.sol -out NAME-mmg.mesh {}` ({v})",
            p.display(),
            MMG_PROTOCOL.join(" ")
        ),
        _ => writeln!(
            s,
            "- MMG: not installed (no --mmg, no `{MMG_NAME}` on PATH, no ${MMG_ENV})"
        ),
    };
    let _ = writeln!(
        s,
        "- Scores: `conemesh eval --input NAME.mesh --output OUT --metric NAME.sol --ltar 1 --json NAME-TOOL-eval.json` \
         (metric space of the case's `.sol`; q and θ of Table 1; `in range` = edges with L/L_tar in [0.71, 1.41]; \
         Hausdorff in % of the input's bounding-box diagonal; valid = no self-intersections and the topology kept)."
    );
    let _ = writeln!(
        s,
        "- Times: `wall s` is the whole child process, spawn to exit (conemesh's includes its built-in eval of the output); \
         `remesh s` is conemesh's own time from its report (reading, metric, Algorithm 1 with its certificates); \
         `conemesh/MMG` is the ratio of the wall times, measured in this run."
    );
    let _ = writeln!(
        s,
        "- Load average (1, 5, 15 min) at the start: {}; at the end: {}; {} cores.\n",
        header.load_start.as_deref().unwrap_or("unknown"),
        header.load_end.as_deref().unwrap_or("unknown"),
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    let _ = writeln!(s, "## Cases\n");
    let _ = writeln!(
        s,
        "| case | surface | metric (file units) | input faces | expected faces |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.0} |",
            cell(r.case.name),
            cell(&r.case.shape.describe()),
            cell(&r.case.sizing.describe()),
            r.files.faces,
            r.files.expected_faces
        );
    }
    let _ = writeln!(s, "\n## Results\n");
    let _ = writeln!(
        s,
        "| case | tool | faces | q_min / q_avg | θ_min / θ_avg (°) | in range % | mean L/L_tar | Hausdorff % | flips | valid | wall s | remesh s | conemesh/MMG |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        for t in [&r.conemesh, &r.mmg] {
            let _ = writeln!(s, "{}", tool_row(r, t));
        }
    }
    s
}
