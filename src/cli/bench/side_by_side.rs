//! The folder bench's MMG side (issue 19): per mesh, after conemesh's run, MMG on the same
//! input (as Medit `.mesh`, by `conemesh convert`) with the metric conemesh's run remeshes to
//! (`NAME-input.sol` from `remesh --write-input-metric`: the curvature or user metric with the
//! run's fidelity scaling, over L_tar², so MMG's target length is 1), with the analytic suite's
//! protocol ([`MMG_PROTOCOL`]); both outputs scored by `conemesh eval` against the input at
//! the run's L_tar, so that the two tools are measured by one yardstick.
//!
//! A tool that fails is a FAILED row naming its error; without MMG its rows say "not
//! installed", which is not a failure.

use super::tools::{
    self, run_and_score, run_timed, Eval, Header, Outcome, Pair, ToolError, ToolRun, MMG_ENV,
    MMG_NAME, MMG_PROTOCOL,
};
use super::{Folder, Row};
use anyhow::Context;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::rc::Rc;

/// MMG reads Medit `.mesh` only: any other input is converted first.
pub(super) fn needs_conversion(input: &Path) -> bool {
    !input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mesh"))
}

/// Score conemesh's output of `row` and run and score MMG on `mesh` (see the module). Only a
/// log the out dir refuses is an error.
pub(super) fn run_mesh(f: &Folder, mesh: &Path, name: &str, row: &Row) -> anyhow::Result<Pair> {
    let (numbers, wall) = match (&row.outcome, row.wall) {
        (Ok(n), Some(wall)) => (n, wall),
        (outcome, wall) => {
            let error = match outcome {
                Err(e) => Rc::clone(e),
                Ok(_) => Rc::new(ToolError::NoWall),
            };
            let mmg = match f.mmg {
                None => Outcome::NotInstalled,
                Some(_) => Outcome::Failed {
                    error: Rc::new(ToolError::NoMetric {
                        name: name.to_string(),
                    }),
                    wall: None,
                },
            };
            return Ok(pair(Outcome::Failed { error, wall }, mmg));
        }
    };
    let eval = Eval {
        exe: &f.exe,
        input: mesh,
        metric: f.metric.as_deref(),
        // The shortest text that reads back to the same f64: the same L_tar for both tools.
        ltar: numbers.l_tar.to_string(),
        timeout: f.timeout,
    };
    let mut log = Vec::new();
    let conemesh = match eval.score(&f.path(name, ".obj"), &f.path(name, "-eval.json"), &mut log) {
        Ok(score) => Outcome::Done {
            wall,
            own: Some(numbers.seconds),
            score,
        },
        Err(error) => Outcome::Failed {
            error: Rc::new(error),
            wall: Some(wall),
        },
    };
    write_log(&f.path(name, "-eval.log"), &log)?;
    let Some(bin) = &f.mmg else {
        return Ok(pair(conemesh, Outcome::NotInstalled));
    };
    let mut log = Vec::new();
    let out = f.path(name, "-mmg.mesh");
    let mmg = match mmg_input(f, mesh, name, &mut log) {
        Err(error) => Outcome::Failed {
            error: Rc::new(error),
            wall: None,
        },
        Ok(input) => {
            let mut cmd = Command::new(bin);
            cmd.arg("-in")
                .arg(&input)
                .arg("-sol")
                .arg(f.path(name, "-input.sol"))
                .arg("-out")
                .arg(&out)
                .args(MMG_PROTOCOL);
            run_and_score("MMG", &mut cmd, &out, f.timeout, &mut log, |log| {
                eval.score(&out, &f.path(name, "-mmg-eval.json"), log)
            })
        }
    };
    write_log(&f.path(name, "-mmg.log"), &log)?;
    Ok(pair(conemesh, mmg))
}

fn pair(conemesh: Outcome, mmg: Outcome) -> Pair {
    Pair {
        conemesh: ToolRun {
            tool: "conemesh",
            outcome: conemesh,
        },
        mmg: ToolRun {
            tool: "MMG",
            outcome: mmg,
        },
    }
}

fn write_log(path: &Path, log: &[u8]) -> anyhow::Result<()> {
    conemesh::io::write_bytes_atomic(path, log)
        .with_context(|| format!("writing {}", path.display()))
}

/// MMG's input: `mesh` itself when it is a `.mesh`, else `conemesh convert MESH NAME.mesh`
/// (the same vertices in the same order, so `NAME-input.sol` has one tensor per vertex).
fn mmg_input(f: &Folder, mesh: &Path, name: &str, log: &mut Vec<u8>) -> Result<PathBuf, ToolError> {
    if !needs_conversion(mesh) {
        return Ok(mesh.to_path_buf());
    }
    let converted = f.path(name, ".mesh");
    let mut cmd = Command::new(&f.exe);
    cmd.arg("convert").arg(mesh).arg(&converted);
    let c = run_timed(&mut cmd, f.timeout).map_err(|source| ToolError::NoExit {
        step: Some("convert"),
        source,
    })?;
    log.extend_from_slice(b"--- conemesh convert ---\n");
    log.extend_from_slice(&c.stdout);
    log.extend_from_slice(&c.stderr);
    log.extend_from_slice(b"--- MMG ---\n");
    if !c.status.success() {
        return Err(ToolError::failed("convert", &c));
    }
    Ok(converted)
}

/// The section of `remesh.md`: the commands, the machine's load, one conemesh and one MMG row
/// per mesh.
pub(super) fn section<'a>(
    s: &mut String,
    rows: impl Iterator<Item = (&'a str, &'a Pair)>,
    f: &Folder,
    header: &Header,
) {
    let _ = writeln!(s, "\n## conemesh and MMG side by side\n");
    let _ = match (&f.mmg, &header.mmg_version) {
        (Some(p), Some(v)) => writeln!(
            s,
            "- MMG: `{} -in NAME.mesh -sol NAME-input.sol -out NAME-mmg.mesh {}` ({v}); `NAME.mesh` \
             is `conemesh convert MESH NAME.mesh` (a `.mesh` input is given as it is), \
             `NAME-input.sol` the metric conemesh's run remeshes to (`--write-input-metric`: the \
             run's metric with its a-priori fidelity scaling, over L_tar², so MMG's target length is 1).",
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
        "- Scores: `conemesh eval --input MESH --output OUT --ltar L{} --json NAME[-mmg]-eval.json` for \
         both tools, L the conemesh run's L_tar (its report); `in range` = edges with L/L_tar in \
         [0.71, 1.41]; Hausdorff in % of the input's bounding-box diagonal; valid = no \
         self-intersections and the topology kept.",
        match &f.metric {
            Some(m) => format!(" --metric {}", m.display()),
            None => String::new(),
        }
    );
    let _ = writeln!(
        s,
        "- Times: `wall s` is the whole child process, spawn to exit (conemesh's includes its \
         built-in eval of the output, MMG's its reading and writing); `remesh s` is conemesh's \
         own time from its report (reading, metric, Algorithm 1 with its certificates); \
         `conemesh/MMG` is the ratio of the wall times, measured in this run, one process at a time."
    );
    let _ = writeln!(
        s,
        "- Load average (1, 5, 15 min) at the start: {}; at the end: {}; {} cores.\n",
        header.load_start.as_deref().unwrap_or("unknown"),
        header.load_end.as_deref().unwrap_or("unknown"),
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    let _ = writeln!(s, "{}", tools::results_header("mesh"));
    for (name, p) in rows {
        for t in [&p.conemesh, &p.mmg] {
            let _ = writeln!(s, "{}", tools::tool_row(name, t, p.time_ratio()));
        }
    }
}
