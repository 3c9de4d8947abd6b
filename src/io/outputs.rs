//! Several output files (and folders) of one run as one transaction: all are written, or none
//! (issue 20).
//!
//! [`Outputs`] stages every output as a temporary file (or folder) in its destination's own
//! folder, so that nothing a reader could see changes while the outputs are written. Only
//! [`Outputs::commit`] moves them into place, one rename each; a destination that already
//! exists is first kept aside under a temporary name, so that when a later rename fails the
//! earlier ones are undone and every pre-existing destination gets its old content back.
//! Dropping an uncommitted [`Outputs`] (an error, a panic) removes every temporary it made.
//!
//! ```no_run
//! # fn main() -> Result<(), conemesh::io::IoError> {
//! use conemesh::io::Outputs;
//! use std::path::Path;
//! let mut out = Outputs::new();
//! out.bytes(Path::new("report.json"), b"{}")?;
//! let plots = out.dir(Path::new("plots"))?; // write the folder's files into `plots`
//! std::fs::write(plots.join("a.txt"), b"a").map_err(|error| conemesh::io::IoError::Os {
//!     path: "plots/a.txt".into(),
//!     error,
//! })?;
//! out.commit()?; // report.json and plots/a.txt appear together, or neither does
//! # Ok(())
//! # }
//! ```

use super::IoError;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Prefix of every temporary name [`Outputs`] makes (staged outputs and kept-aside old
/// files), so that a leftover can be recognised.
pub const TEMP_PREFIX: &str = ".conemesh-";
const PREFIX: &str = TEMP_PREFIX;

/// One staged output.
#[derive(Debug)]
enum Staged {
    /// A complete temporary file, to be renamed to `dest`.
    File { tmp: PathBuf, dest: PathBuf },
    /// A temporary folder whose files go into the folder `dest`.
    Dir { tmp: PathBuf, dest: PathBuf },
}

/// A rename done by [`Outputs::commit`], with what it replaced (kept aside under `backup`).
#[derive(Debug)]
struct Done {
    dest: PathBuf,
    backup: Option<PathBuf>,
    /// `dest` is a folder this commit created (removed again on rollback).
    new_dir: bool,
}

/// The outputs of one run, staged as temporaries until [`Outputs::commit`]. See the module
/// documentation.
#[derive(Debug, Default)]
#[must_use = "staged outputs are removed unless committed"]
pub struct Outputs {
    staged: Vec<Staged>,
}

fn os(path: &Path) -> impl Fn(std::io::Error) -> IoError + '_ {
    move |error| IoError::Os {
        path: path.display().to_string(),
        error,
    }
}

/// The folder a destination lives in (`.` for a bare file name).
fn folder_of(dest: &Path) -> &Path {
    match dest.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// A fresh temporary name in `dir` that nothing else holds: a file is created empty and kept
/// (renames replace it).
fn fresh_name(dir: &Path, suffix: &str) -> std::io::Result<PathBuf> {
    let f = tempfile::Builder::new()
        .prefix(PREFIX)
        .suffix(suffix)
        .tempfile_in(dir)?;
    let (_, path) = f.keep().map_err(|e| e.error)?;
    Ok(path)
}

impl Outputs {
    /// No outputs staged yet.
    pub fn new() -> Self {
        Outputs::default()
    }

    /// Stage the file `dest`, written by `body` into a temporary file in `dest`'s folder
    /// (flushed and synced). A failure removes the temporary and leaves the other staged
    /// outputs as they were.
    pub fn file(
        &mut self,
        dest: &Path,
        body: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
    ) -> Result<(), IoError> {
        let e = os(dest);
        let mut tmp = tempfile::Builder::new()
            .prefix(PREFIX)
            .suffix(".tmp")
            .tempfile_in(folder_of(dest))
            .map_err(&e)?;
        {
            let mut w = std::io::BufWriter::new(tmp.as_file_mut());
            body(&mut w).map_err(&e)?;
            w.flush().map_err(&e)?;
        }
        tmp.as_file().sync_all().map_err(&e)?;
        #[cfg(unix)]
        {
            // tempfile creates 0600; give the result the usual permissions of a new file.
            use std::os::unix::fs::PermissionsExt;
            let _ = tmp
                .as_file()
                .set_permissions(std::fs::Permissions::from_mode(0o644));
        }
        let (_, tmp) = tmp.keep().map_err(|x| e(x.error))?;
        self.staged.push(Staged::File {
            tmp,
            dest: dest.to_path_buf(),
        });
        Ok(())
    }

    /// Stage the mesh file `dest` in the format of its extension (validated first, as
    /// [`super::write_mesh_with`]).
    pub fn mesh(
        &mut self,
        dest: &Path,
        mesh: &crate::mesh::TriMesh,
        attrs: &super::MeshAttributes,
        opts: &super::WriteOptions,
    ) -> Result<(), IoError> {
        let body = super::mesh_writer(dest, mesh, attrs, opts)?;
        self.file(dest, body)
    }

    /// Stage the file `dest` holding `bytes`.
    pub fn bytes(&mut self, dest: &Path, bytes: &[u8]) -> Result<(), IoError> {
        self.file(dest, |w| w.write_all(bytes))
    }

    /// Stage the folder `dest`: returns a temporary folder beside it to write the folder's
    /// files into (flat: sub-folders are not carried over). At commit, a missing `dest` is the
    /// temporary folder renamed; an existing one receives each file by its own rename (its
    /// other files stay).
    pub fn dir(&mut self, dest: &Path) -> Result<PathBuf, IoError> {
        let parent = folder_of(dest);
        let tmp = tempfile::Builder::new()
            .prefix(PREFIX)
            .suffix(".tmp")
            .tempdir_in(parent)
            .map_err(os(dest))?
            .keep();
        self.staged.push(Staged::Dir {
            tmp: tmp.clone(),
            dest: dest.to_path_buf(),
        });
        Ok(tmp)
    }

    /// The destinations staged so far, in order (a folder's files are not listed).
    pub fn destinations(&self) -> Vec<&Path> {
        self.staged
            .iter()
            .map(|s| match s {
                Staged::File { dest, .. } | Staged::Dir { dest, .. } => dest.as_path(),
            })
            .collect()
    }

    /// Move every staged output into place. On success every destination holds its new
    /// content and no temporary is left. On failure (the error names the destination) every
    /// rename already done is undone, so each destination holds what it held before (or does
    /// not exist, as before), and no temporary is left.
    pub fn commit(mut self) -> Result<(), IoError> {
        let staged = std::mem::take(&mut self.staged);
        // Expand folders: a missing destination is one rename of the whole folder; an
        // existing one one rename per file.
        let mut renames: Vec<(PathBuf, PathBuf, bool)> = Vec::new();
        let mut tmp_dirs: Vec<PathBuf> = Vec::new();
        let mut pending: Vec<PathBuf> = Vec::new(); // every temporary, for cleanup
        let mut expand = |s: &Staged| -> Result<(), IoError> {
            match s {
                Staged::File { tmp, dest } => {
                    pending.push(tmp.clone());
                    renames.push((tmp.clone(), dest.clone(), false));
                }
                Staged::Dir { tmp, dest } => {
                    pending.push(tmp.clone());
                    if std::fs::symlink_metadata(dest).is_err() {
                        renames.push((tmp.clone(), dest.clone(), true));
                    } else {
                        tmp_dirs.push(tmp.clone());
                        let mut files: Vec<PathBuf> = std::fs::read_dir(tmp)
                            .map_err(os(dest))?
                            .map(|e| e.map(|e| e.path()))
                            .collect::<Result<_, _>>()
                            .map_err(os(dest))?;
                        files.sort();
                        for f in files {
                            let name = f.file_name().map(PathBuf::from).unwrap_or_default();
                            renames.push((f, dest.join(name), false));
                        }
                    }
                }
            }
            Ok(())
        };
        let mut result = staged.iter().try_for_each(&mut expand);
        let mut done: Vec<Done> = Vec::new();
        if result.is_ok() {
            for (tmp, dest, whole_dir) in &renames {
                match rename_keeping(tmp, dest, *whole_dir) {
                    Ok(d) => done.push(d),
                    Err(e) => {
                        result = Err(e);
                        break;
                    }
                }
            }
        }
        match result {
            Ok(()) => {
                for d in &done {
                    if let Some(b) = &d.backup {
                        let _ = std::fs::remove_file(b);
                    }
                }
                for t in &tmp_dirs {
                    let _ = std::fs::remove_dir_all(t);
                }
                Ok(())
            }
            Err(e) => {
                // Undo in reverse order: the old content back, or the new entry removed.
                for d in done.iter().rev() {
                    match &d.backup {
                        Some(b) => {
                            let _ = std::fs::rename(b, &d.dest);
                        }
                        None if d.new_dir => {
                            let _ = std::fs::remove_dir_all(&d.dest);
                        }
                        None => {
                            let _ = std::fs::remove_file(&d.dest);
                        }
                    }
                }
                for t in pending {
                    remove_any(&t);
                }
                Err(e)
            }
        }
    }
}

/// Rename `tmp` to `dest`; an existing file at `dest` is first kept aside (hard link to a
/// temporary name where the file system allows, so `dest` never disappears; a rename
/// otherwise).
fn rename_keeping(tmp: &Path, dest: &Path, whole_dir: bool) -> Result<Done, IoError> {
    let e = os(dest);
    let backup = match std::fs::symlink_metadata(dest) {
        Ok(m) if m.is_dir() => {
            return Err(IoError::Os {
                path: dest.display().to_string(),
                error: std::io::Error::new(
                    std::io::ErrorKind::IsADirectory,
                    "a folder of that name is in the way",
                ),
            })
        }
        Ok(_) => {
            let b = fresh_name(folder_of(dest), ".old").map_err(&e)?;
            let linked = std::fs::remove_file(&b)
                .and_then(|()| std::fs::hard_link(dest, &b))
                .is_ok();
            if !linked {
                if let Err(x) = std::fs::rename(dest, &b) {
                    let _ = std::fs::remove_file(&b);
                    return Err(e(x));
                }
            }
            Some(b)
        }
        Err(_) => None,
    };
    if let Err(x) = std::fs::rename(tmp, dest) {
        if let Some(b) = &backup {
            // Put the old file back if it was moved; a hard link is just dropped.
            if std::fs::symlink_metadata(dest).is_err() {
                let _ = std::fs::rename(b, dest);
            } else {
                let _ = std::fs::remove_file(b);
            }
        }
        return Err(e(x));
    }
    Ok(Done {
        dest: dest.to_path_buf(),
        backup,
        new_dir: whole_dir,
    })
}

fn remove_any(p: &Path) {
    match std::fs::symlink_metadata(p) {
        Ok(m) if m.is_dir() => {
            let _ = std::fs::remove_dir_all(p);
        }
        Ok(_) => {
            let _ = std::fs::remove_file(p);
        }
        Err(_) => {}
    }
}

impl Drop for Outputs {
    /// An uncommitted transaction removes its temporaries.
    fn drop(&mut self) {
        for s in self.staged.drain(..) {
            match s {
                Staged::File { tmp, .. } | Staged::Dir { tmp, .. } => remove_any(&tmp),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type R = Result<(), Box<dyn std::error::Error>>;

    fn leftovers(dir: &Path) -> Vec<String> {
        let mut v = Vec::new();
        for e in walk(dir) {
            let n = e.file_name().unwrap().to_string_lossy().into_owned();
            if n.starts_with(PREFIX) {
                v.push(e.display().to_string());
            }
        }
        v
    }

    fn walk(dir: &Path) -> Vec<PathBuf> {
        let mut v = Vec::new();
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                v.extend(walk(&p));
            }
            v.push(p);
        }
        v
    }

    #[test]
    fn all_outputs_appear_together() -> R {
        let d = tempfile::tempdir()?;
        let (a, b, plots) = (d.path().join("a"), d.path().join("b"), d.path().join("p"));
        std::fs::write(&a, b"old a")?;
        let mut o = Outputs::new();
        o.bytes(&a, b"new a")?;
        o.bytes(&b, b"new b")?;
        let p = o.dir(&plots)?;
        std::fs::write(p.join("x.png"), b"x")?;
        // Nothing visible before the commit.
        assert_eq!(std::fs::read(&a)?, b"old a");
        assert!(!b.exists() && !plots.exists());
        o.commit()?;
        assert_eq!(std::fs::read(&a)?, b"new a");
        assert_eq!(std::fs::read(&b)?, b"new b");
        assert_eq!(std::fs::read(plots.join("x.png"))?, b"x");
        assert!(leftovers(d.path()).is_empty(), "{:?}", leftovers(d.path()));
        // Into an existing folder: its other files stay, the plot is replaced.
        std::fs::write(plots.join("keep.txt"), b"k")?;
        let mut o = Outputs::new();
        let p = o.dir(&plots)?;
        std::fs::write(p.join("x.png"), b"y")?;
        o.commit()?;
        assert_eq!(std::fs::read(plots.join("x.png"))?, b"y");
        assert_eq!(std::fs::read(plots.join("keep.txt"))?, b"k");
        assert!(leftovers(d.path()).is_empty(), "{:?}", leftovers(d.path()));
        Ok(())
    }

    #[test]
    fn all_outputs_as_one_transaction_a_failed_last_rename_undoes_the_first() -> R {
        let d = tempfile::tempdir()?;
        let (a, b, plots) = (d.path().join("a"), d.path().join("b"), d.path().join("p"));
        std::fs::write(&a, b"old a")?;
        std::fs::create_dir(&plots)?;
        std::fs::write(plots.join("x.png"), b"old x")?;
        // The last file's destination is a folder: its rename fails.
        std::fs::create_dir(plots.join("y.png"))?;
        let mut o = Outputs::new();
        o.bytes(&a, b"new a")?;
        o.bytes(&b, b"new b")?;
        let p = o.dir(&plots)?;
        std::fs::write(p.join("x.png"), b"new x")?;
        std::fs::write(p.join("y.png"), b"new y")?;
        let err = o.commit().unwrap_err().to_string();
        assert!(err.contains("y.png"), "{err}");
        assert_eq!(std::fs::read(&a)?, b"old a");
        assert!(!b.exists());
        assert_eq!(std::fs::read(plots.join("x.png"))?, b"old x");
        assert!(plots.join("y.png").is_dir());
        assert!(leftovers(d.path()).is_empty(), "{:?}", leftovers(d.path()));
        Ok(())
    }

    #[test]
    fn all_outputs_as_one_transaction_a_failed_write_or_a_drop_leaves_nothing() -> R {
        let d = tempfile::tempdir()?;
        let (a, b) = (d.path().join("a"), d.path().join("b"));
        std::fs::write(&a, b"old a")?;
        let mut o = Outputs::new();
        o.bytes(&a, b"new a")?;
        let p = o.dir(&d.path().join("plots"))?;
        std::fs::write(p.join("x.png"), b"x")?;
        let err = o
            .file(&b, |w| {
                w.write_all(b"half")?;
                Err(std::io::Error::other("disk full"))
            })
            .unwrap_err()
            .to_string();
        assert!(err.contains("disk full") && err.contains('b'), "{err}");
        drop(o);
        assert_eq!(std::fs::read(&a)?, b"old a");
        assert!(!b.exists() && !d.path().join("plots").exists());
        assert!(leftovers(d.path()).is_empty(), "{:?}", leftovers(d.path()));
        // A folder that does not exist is an error naming the file.
        let mut o = Outputs::new();
        let missing = d.path().join("no/such/x");
        let err = o.bytes(&missing, b"x").unwrap_err().to_string();
        assert!(err.contains("no/such/x"), "{err}");
        Ok(())
    }
}
