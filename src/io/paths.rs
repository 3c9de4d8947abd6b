//! Output paths checked before any work, and the error of committing them: a run that would
//! fail on a bad path fails before it spends anything, and a failed commit says that nothing
//! was written ([`super::Outputs`]).

use super::{IoError, Outputs};
use std::path::{Path, PathBuf};

/// An output path refused before any work. `flag` is the option that named it (`-o`,
/// `--report`, ...).
#[derive(Debug, thiserror::Error)]
pub enum OutputPathError {
    /// A file output that is a folder.
    #[error("{flag} {}: is a directory, not a file", path.display())]
    IsADirectory {
        /// the option
        flag: &'static str,
        /// the path given
        path: PathBuf,
    },
    /// A folder output that is a file.
    #[error("{flag} {}: is a file, not a folder", path.display())]
    IsAFile {
        /// the option
        flag: &'static str,
        /// the path given
        path: PathBuf,
    },
    /// An output whose folder does not exist.
    #[error("{flag} {}: folder {} does not exist", path.display(), folder.display())]
    NoFolder {
        /// the option
        flag: &'static str,
        /// the path given
        path: PathBuf,
        /// its missing folder
        folder: PathBuf,
    },
    /// Two outputs, or an output and an input, that are the same file.
    #[error("{flag} {} is the same path as {other}", path.display())]
    SamePath {
        /// the option
        flag: &'static str,
        /// the path given
        path: PathBuf,
        /// the other option (or "the input")
        other: &'static str,
    },
}

/// A folder output (`--plots`), checked before any work: not a file, and its parent folder
/// exists (the folder itself is created).
pub fn check_plots_folder(flag: &'static str, d: &Path) -> Result<(), OutputPathError> {
    if d.exists() && !d.is_dir() {
        return Err(OutputPathError::IsAFile {
            flag,
            path: d.to_path_buf(),
        });
    }
    let parent = d.parent().filter(|p| !p.as_os_str().is_empty());
    match parent.filter(|p| !p.is_dir()) {
        Some(p) => Err(OutputPathError::NoFolder {
            flag,
            path: d.to_path_buf(),
            folder: p.to_path_buf(),
        }),
        None => Ok(()),
    }
}

/// A file output, checked before any work: not a folder, and its folder exists.
pub fn check_file_output(flag: &'static str, p: &Path) -> Result<(), OutputPathError> {
    if p.is_dir() {
        return Err(OutputPathError::IsADirectory {
            flag,
            path: p.to_path_buf(),
        });
    }
    let parent = p.parent().filter(|d| !d.as_os_str().is_empty());
    match parent.filter(|d| !d.is_dir()) {
        Some(d) => Err(OutputPathError::NoFolder {
            flag,
            path: p.to_path_buf(),
            folder: d.to_path_buf(),
        }),
        None => Ok(()),
    }
}

/// Two paths name the same file: compared as absolute paths, with `.` and `..` resolved
/// where the file exists.
pub fn same_path(a: &Path, b: &Path) -> bool {
    let key = |p: &Path| {
        std::fs::canonicalize(p)
            .or_else(|_| std::path::absolute(p))
            .unwrap_or_else(|_| p.to_path_buf())
    };
    key(a) == key(b)
}

/// A commit of [`Outputs`] that failed: none of the destinations was written or changed.
#[derive(Debug, thiserror::Error)]
#[error(
    "writing the outputs: {error}; none of them was written or changed ({})",
    destinations.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
)]
pub struct CommitError {
    /// what failed (part of the message, not a `source()`, so that a chain prints it once)
    pub error: Box<IoError>,
    /// every destination of the transaction
    pub destinations: Vec<PathBuf>,
}

/// Commit `outputs` as one transaction ([`Outputs::commit`]); the error names the output
/// that failed and says that none was written.
pub fn commit(outputs: Outputs) -> Result<(), CommitError> {
    let destinations: Vec<PathBuf> = outputs
        .destinations()
        .iter()
        .map(|p| p.to_path_buf())
        .collect();
    outputs.commit().map_err(|error| CommitError {
        error: Box::new(error),
        destinations,
    })
}
