//! Running the grid: every (configuration, input, seed) as its own `conemesh remesh` process,
//! `jobs` at once, each with a time limit; a crash, a timeout or a refusal is a row. Each
//! successful output is then drawn by `conemesh render` where the binary has it.

use super::config::{Config, Input};
use super::measures::RunResult;
use super::process::{error_line, run_timed, ChildError};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::sync::Mutex;
use std::time::Duration;

/// The exit status of a `conemesh` command whose error is the input's or the options' (the
/// CLI's `error:` exit); a panic exits 101.
const REFUSED_EXIT: i32 = 2;

/// What to run.
#[derive(Clone, Debug)]
pub struct Grid {
    /// the `conemesh` binary (`std::env::current_exe()` for the CLI)
    pub exe: PathBuf,
    /// the configurations, the first the one the others are compared with
    pub configs: Vec<Config>,
    /// the input meshes
    pub inputs: Vec<Input>,
    /// the seeds
    pub seeds: Vec<u64>,
    /// the limit of each run (and of each picture)
    pub timeout: Duration,
    /// runs at once (at least 1)
    pub jobs: usize,
    /// draw each output with `conemesh render`
    pub pictures: bool,
}

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// It wrote its output and report.
    Ok,
    /// conemesh refused the input or the options (its `error:` exit).
    Refused,
    /// It died (a panic, a signal) or left no readable report.
    Crashed,
    /// It ran past the time limit and was killed.
    Timeout,
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Status::Ok => "ok",
            Status::Refused => "refused",
            Status::Crashed => "crashed",
            Status::Timeout => "timeout",
        })
    }
}

/// Why a run has no picture. `compare.json` holds its message, the text a reader sees.
#[derive(Clone, Debug, thiserror::Error)]
pub enum PictureError {
    /// The run wrote no output to draw.
    #[error("no output")]
    NoOutput,
    /// Pictures were not asked for (`--no-pictures`).
    #[error("pictures off")]
    Off,
    /// The binary's `render --help` fails: it has no `render` subcommand.
    #[error("no picture: this conemesh has no `render` subcommand")]
    NoRender,
    /// The binary's `render --help` gave no exit status.
    #[error("no picture: render {0}")]
    RenderUnavailable(#[source] Arc<ChildError>),
    /// `conemesh render` gave no exit status.
    #[error("render {0}")]
    Child(#[source] Arc<ChildError>),
    /// `conemesh render` failed; `stderr_line` is the line of its stderr that names the error.
    #[error("render {status}: {stderr_line}")]
    Failed {
        /// its exit status
        status: ExitStatus,
        /// the line of its stderr that names the error (the child's text, as it wrote it)
        stderr_line: String,
    },
    /// `conemesh render` succeeded without writing the picture.
    #[error("render wrote no picture")]
    NoPicture,
}

impl Serialize for PictureError {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

/// One (configuration, input, seed) of the grid and what it gave.
#[derive(Clone, Debug, Serialize)]
pub struct RunRecord {
    /// configuration name
    pub config: String,
    /// input name (file stem)
    pub mesh: String,
    /// the seed
    pub seed: u64,
    /// how it ended
    pub status: Status,
    /// why it was not ok (empty when ok)
    pub error: String,
    /// file names in the folder: output mesh, report, output metric, log
    pub files: RunFiles,
    /// SHA-256 of the output mesh's bytes (ok runs)
    pub output_sha256: Option<String>,
    /// the measures, options and histograms (ok runs)
    pub result: Option<RunResult>,
    /// the picture's file name, or why there is none
    pub picture: Result<String, PictureError>,
    /// the process's wall time, seconds (`None` when it timed out or did not start)
    pub wall: Option<f64>,
}

/// The files of one run, by name inside the comparison's folder.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunFiles {
    /// the output mesh (OBJ)
    pub output: String,
    /// the `--report` JSON
    pub report: String,
    /// the `--write-metric` `.sol` (the metric at the output vertices)
    pub metric: String,
    /// stdout and stderr of remesh (and render)
    pub log: String,
}

impl RunFiles {
    fn of(config: &str, mesh: &str, seed: u64) -> RunFiles {
        let clean: String = mesh
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let base = format!("{config}--{clean}--s{seed}");
        RunFiles {
            output: format!("{base}.obj"),
            report: format!("{base}.json"),
            metric: format!("{base}.sol"),
            log: format!("{base}.log"),
        }
    }

    /// The picture's file name.
    pub fn picture(&self) -> String {
        self.output.replace(".obj", ".png")
    }
}

/// One cell of the grid, by index.
#[derive(Clone, Copy, Debug)]
pub struct Job {
    /// index into [`Grid::configs`]
    pub config: usize,
    /// index into [`Grid::inputs`]
    pub input: usize,
    /// the seed
    pub seed: u64,
}

impl Grid {
    /// Every cell, by input, then configuration, then seed (the order of the tables).
    pub fn jobs(&self) -> Vec<Job> {
        let mut out = Vec::new();
        for input in 0..self.inputs.len() {
            for config in 0..self.configs.len() {
                for &seed in &self.seeds {
                    out.push(Job {
                        config,
                        input,
                        seed,
                    });
                }
            }
        }
        out
    }

    /// The `conemesh remesh` arguments of a cell (input, configuration, seed) with its files
    /// in `dir`.
    pub fn remesh_args(&self, job: Job, dir: &Path) -> Vec<String> {
        let c = &self.configs[job.config];
        let input = &self.inputs[job.input];
        let f = RunFiles::of(&c.name, &input.name, job.seed);
        let path = |name: &str| dir.join(name).to_string_lossy().into_owned();
        let mut args = vec![
            "remesh".to_string(),
            input.path.to_string_lossy().into_owned(),
            "-o".into(),
            path(&f.output),
            "--report".into(),
            path(&f.report),
            "--write-metric".into(),
            path(&f.metric),
            "--quiet".into(),
            "--seed".into(),
            job.seed.to_string(),
        ];
        args.extend(c.args.iter().cloned());
        args
    }

    /// Run every cell of `jobs` with its files in `dir` (which must exist), `self.jobs` at
    /// once; `done` is called as each finishes (from worker threads). The records are in the
    /// order of `jobs`. Only an unwritable `dir` is an error; every failing run is a record.
    pub fn run(
        &self,
        jobs: &[Job],
        dir: &Path,
        done: &(dyn Fn(&RunRecord) + Sync),
    ) -> Result<Vec<RunRecord>, super::CompareError> {
        let render = self
            .pictures
            .then(|| render_available(&self.exe, self.timeout));
        let next = AtomicUsize::new(0);
        let records: Mutex<Vec<Option<Result<RunRecord, super::CompareError>>>> =
            Mutex::new(jobs.iter().map(|_| None).collect());
        std::thread::scope(|s| {
            for _ in 0..self.jobs.max(1).min(jobs.len().max(1)) {
                s.spawn(|| loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&job) = jobs.get(i) else { break };
                    let r = self.run_one(job, dir, render.as_ref());
                    if let Ok(rec) = &r {
                        done(rec);
                    }
                    if let Ok(mut all) = records.lock() {
                        all[i] = Some(r);
                    }
                });
            }
        });
        // A worker's panic is re-raised by `scope` above, so every slot is filled here; an
        // empty one is still an error, not a panic.
        records
            .into_inner()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .into_iter()
            .map(|r| {
                r.unwrap_or_else(|| {
                    Err(super::CompareError::Os {
                        path: dir.display().to_string(),
                        source: std::io::Error::other("a run of the grid was never recorded"),
                    })
                })
            })
            .collect()
    }

    fn run_one(
        &self,
        job: Job,
        dir: &Path,
        render: Option<&Result<(), PictureError>>,
    ) -> Result<RunRecord, super::CompareError> {
        let c = &self.configs[job.config];
        let input = &self.inputs[job.input];
        let files = RunFiles::of(&c.name, &input.name, job.seed);
        let mut log = Vec::new();
        let mut rec = RunRecord {
            config: c.name.clone(),
            mesh: input.name.clone(),
            seed: job.seed,
            status: Status::Ok,
            error: String::new(),
            files: files.clone(),
            output_sha256: None,
            result: None,
            picture: Err(PictureError::NoOutput),
            wall: None,
        };
        self.remesh(job, dir, &mut log, &mut rec);
        if rec.status == Status::Ok {
            rec.picture = match render {
                None => Err(PictureError::Off),
                Some(Err(why)) => Err(why.clone()),
                Some(Ok(())) => self.picture(input, dir, &files, &mut log),
            };
        }
        let log_path = dir.join(&files.log);
        std::fs::write(&log_path, &log).map_err(|source| super::CompareError::Os {
            path: log_path.display().to_string(),
            source,
        })?;
        Ok(rec)
    }

    /// The `conemesh remesh` process of one cell: its status, error, wall time, output hash
    /// and report into `rec`, its stdout and stderr onto `log`.
    fn remesh(&self, job: Job, dir: &Path, log: &mut Vec<u8>, rec: &mut RunRecord) {
        let mut cmd = Command::new(&self.exe);
        cmd.args(self.remesh_args(job, dir));
        match run_timed(&mut cmd, self.timeout) {
            Err(e) => {
                rec.status = match e {
                    ChildError::Timeout { .. } => Status::Timeout,
                    _ => Status::Crashed,
                };
                rec.error = format!("remesh {e}");
            }
            Ok(f) => {
                log.extend_from_slice(&f.stdout);
                log.extend_from_slice(&f.stderr);
                rec.wall = Some(f.wall);
                if f.status.success() {
                    match read_result(dir, &rec.files) {
                        Ok((sha, result)) => {
                            rec.output_sha256 = Some(sha);
                            rec.result = Some(result);
                        }
                        Err(e) => {
                            rec.status = Status::Crashed;
                            rec.error = e.to_string();
                        }
                    }
                } else {
                    rec.status = match f.status.code() {
                        Some(REFUSED_EXIT) => Status::Refused,
                        _ => Status::Crashed,
                    };
                    rec.error = format!(
                        "remesh {}: {}",
                        f.status,
                        error_line(&String::from_utf8_lossy(&f.stderr))
                    );
                }
            }
        }
    }

    /// `conemesh render OUT -o PIC --color q --metric OUT.sol --reference INPUT`.
    fn picture(
        &self,
        input: &Input,
        dir: &Path,
        files: &RunFiles,
        log: &mut Vec<u8>,
    ) -> Result<String, PictureError> {
        let pic = files.picture();
        let mut cmd = Command::new(&self.exe);
        cmd.arg("render")
            .arg(dir.join(&files.output))
            .arg("-o")
            .arg(dir.join(&pic))
            .args(["--color", "q", "--metric"])
            .arg(dir.join(&files.metric))
            .arg("--reference")
            .arg(&input.path);
        let f = run_timed(&mut cmd, self.timeout).map_err(|e| PictureError::Child(Arc::new(e)))?;
        log.extend_from_slice(b"\n--- conemesh render ---\n");
        log.extend_from_slice(&f.stdout);
        log.extend_from_slice(&f.stderr);
        if !f.status.success() {
            return Err(PictureError::Failed {
                status: f.status,
                stderr_line: error_line(&String::from_utf8_lossy(&f.stderr)).to_string(),
            });
        }
        if !dir.join(&pic).is_file() {
            return Err(PictureError::NoPicture);
        }
        Ok(pic)
    }
}

/// Whether `exe` has the `render` subcommand: its `render --help` succeeds. A binary without
/// it answers with clap's usage error; the reason is what every row then records.
fn render_available(exe: &Path, timeout: Duration) -> Result<(), PictureError> {
    let mut cmd = Command::new(exe);
    cmd.args(["render", "--help"]);
    match run_timed(&mut cmd, timeout) {
        Ok(f) if f.status.success() => Ok(()),
        Ok(_) => Err(PictureError::NoRender),
        Err(e) => Err(PictureError::RenderUnavailable(Arc::new(e))),
    }
}

/// The output's SHA-256 and the report's numbers.
fn read_result(dir: &Path, files: &RunFiles) -> Result<(String, RunResult), super::CompareError> {
    let os = |path: &Path| {
        let path = path.display().to_string();
        move |source| super::CompareError::Os { path, source }
    };
    let out = dir.join(&files.output);
    let sha = sha256_file(&out).map_err(os(&out))?;
    let report = dir.join(&files.report);
    let text = std::fs::read_to_string(&report).map_err(os(&report))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| super::CompareError::Report {
            path: report.display().to_string(),
            defect: super::ReportDefect::NotJson(e),
        })?;
    let result = RunResult::from_report(&json, &files.report)?;
    Ok((sha, result))
}

/// The SHA-256 of a file's bytes, in lowercase hex.
pub fn sha256_file(path: &Path) -> std::io::Result<String> {
    let bytes = std::fs::read(path)?;
    Ok(hex(&Sha256::digest(&bytes)))
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}
