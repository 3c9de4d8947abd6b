//! `conemesh bench --suite analytic`: the analytic suite ([`conemesh::suite`]) written into the
//! out dir, then per case, each in a child process of its own, `conemesh remesh` and, when an
//! MMG binary is found, `mmgs_O3` with the issue-17 protocol on the same `.mesh` and `.sol`;
//! both outputs scored by `conemesh eval` at L_tar = 1 against the case's input and metric.
//! Writes `analytic.md` (printed too): per case and tool faces, Table-1 quality, edge
//! conformity, Hausdorff distance, flips, validity and wall time, and the time ratio.
//!
//! A failing or timed-out child is a `FAILED` row naming its error; the other runs go on, and
//! the exit code is then 1. Without MMG its rows say "not installed" (not a failure).

use super::tools::{
    self, find_mmg, own_seconds, run_and_score, Eval, Header, Outcome, ToolRun, MMG_ENV, MMG_NAME,
    MMG_PROTOCOL,
};
use super::{cell, refuse_own_args, remove_stale, BenchArgs, OWN_ARGS};
use anyhow::Context;
use conemesh::suite::{self, Case, CaseFiles};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::{Command, ExitCode};
use std::time::Duration;

/// Every run's target metric length: the suite's metrics put an edge on target at length 1.
const LTAR: &str = "1";

/// Run `conemesh bench --suite analytic`.
pub(super) fn run(args: &BenchArgs) -> anyhow::Result<ExitCode> {
    let mut own: Vec<&str> = OWN_ARGS.to_vec();
    own.extend(["--metric", "--ltar", "--ltar-factor"]);
    refuse_own_args(&args.remesh_args, &own)?;
    let timeout = super::timeout(args.timeout)?;
    let cases = suite::select(suite::ANALYTIC, &args.cases)?;
    let mmg = find_mmg(args.mmg.as_deref())?;
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("creating {}", args.out_dir.display()))?;
    let runner = Runner {
        exe: std::env::current_exe().context("locating the conemesh executable")?,
        out_dir: args.out_dir.clone(),
        mmg,
        remesh_args: args.remesh_args.clone(),
        timeout,
    };
    let header = Header::start(runner.mmg.as_deref(), runner.timeout);
    let mut rows = Vec::new();
    for case in cases {
        let row = runner.run_case(case)?;
        for t in [&row.conemesh, &row.mmg] {
            eprintln!("{}", tool_row(&row, t));
        }
        rows.push(row);
    }
    let header = header.end();
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
        tools::time_ratio(&self.conemesh.outcome, &self.mmg.outcome)
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
        let eval_json = self.path(name, &format!("-{key}-eval.json"));
        // `conemesh eval --input NAME.mesh --output OUT --metric NAME.sol --ltar 1 --json J`.
        let eval = Eval {
            exe: &self.exe,
            input: &files.mesh,
            metric: Some(&files.sol),
            ltar: LTAR.to_string(),
            timeout: self.timeout,
        };
        let mut log = Vec::new();
        let mut outcome = run_and_score(tool, cmd, &output, self.timeout, &mut log, |log| {
            eval.score(&output, &eval_json, log)
        });
        if let Outcome::Done { own, .. } = &mut outcome {
            if tool == "conemesh" {
                *own = own_seconds(&self.path(name, "-conemesh.json"));
            }
        }
        let log_path = self.path(name, &format!("-{key}.log"));
        conemesh::io::write_bytes_atomic(&log_path, &log)
            .with_context(|| format!("writing {}", log_path.display()))?;
        Ok(ToolRun { tool, outcome })
    }
}

/// One Markdown row.
fn tool_row(row: &CaseRow, t: &ToolRun) -> String {
    tools::tool_row(row.case.name, t, row.time_ratio())
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
    let _ = writeln!(s, "{}", tools::results_header("case"));
    for r in rows {
        for t in [&r.conemesh, &r.mmg] {
            let _ = writeln!(s, "{}", tool_row(r, t));
        }
    }
    s
}
