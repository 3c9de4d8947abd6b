//! One child process with a time limit, its output captured and its wall time measured
//! (shared by `conemesh compare` and `conemesh bench`).

use std::io::Read;
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// A finished child process.
#[derive(Debug)]
pub struct Finished {
    /// its exit status
    pub status: ExitStatus,
    /// everything it wrote to stdout
    pub stdout: Vec<u8>,
    /// everything it wrote to stderr
    pub stderr: Vec<u8>,
    /// wall-clock seconds from spawn to exit
    pub wall: f64,
}

/// Why a child gave no exit status.
#[derive(Debug, thiserror::Error)]
pub enum ChildError {
    /// It could not be started.
    #[error("cannot start {program}: {source}")]
    Start {
        /// the program
        program: String,
        /// the OS error
        source: std::io::Error,
    },
    /// It ran past its limit and was killed.
    #[error("timed out after {seconds} s (killed)")]
    Timeout {
        /// the limit, seconds
        seconds: f64,
    },
    /// Waiting for it failed.
    #[error("waiting for {program}: {source}")]
    Wait {
        /// the program
        program: String,
        /// the OS error
        source: std::io::Error,
    },
}

/// Run `cmd` (stdin closed, stdout and stderr captured) for at most `timeout`; a child still
/// running then is killed. The wall time is the whole process's, spawn to exit.
pub fn run_timed(cmd: &mut Command, timeout: Duration) -> Result<Finished, ChildError> {
    let name = format!("{:?}", cmd.get_program());
    let program = || name.clone();
    let t0 = Instant::now();
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|source| ChildError::Start {
            program: program(),
            source,
        })?;
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
                return Err(ChildError::Timeout {
                    seconds: timeout.as_secs_f64(),
                });
            }
            Ok(None) => {
                std::thread::sleep(nap);
                nap = (nap * 2).min(Duration::from_millis(5));
            }
            Err(source) => {
                return Err(ChildError::Wait {
                    program: program(),
                    source,
                })
            }
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

/// The line of a failed child's stderr that names the error (or a panic's message), not a
/// trailing hint.
pub fn error_line(stderr: &str) -> &str {
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
