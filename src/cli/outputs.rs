//! Output-path checks and the one-transaction commit shared by the subcommands (also compiled
//! into the Python package beside `remesh.rs`).

use std::path::Path;

/// Commit the outputs of a subcommand as one transaction ([`conemesh::io::Outputs`]); the
/// error names the output that failed and says that none was written.
pub fn commit(outputs: conemesh::io::Outputs) -> anyhow::Result<()> {
    let all: Vec<String> = outputs
        .destinations()
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    outputs.commit().map_err(|e| {
        anyhow::anyhow!(
            "writing the outputs: {e}; none of them was written or changed ({})",
            all.join(", ")
        )
    })
}

/// A folder output (`--plots`), checked before any work: not a file, and its parent folder
/// exists (the folder itself is created).
pub fn check_plots_folder(flag: &str, d: &Path) -> anyhow::Result<()> {
    if d.exists() && !d.is_dir() {
        anyhow::bail!("{flag} {}: is a file, not a folder", d.display());
    }
    let parent = d.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(p) = parent.filter(|p| !p.is_dir()) {
        anyhow::bail!(
            "{flag} {}: folder {} does not exist",
            d.display(),
            p.display()
        );
    }
    Ok(())
}

/// A file output, checked before any work: not a folder, and its folder exists.
pub fn check_file_output(flag: &str, p: &Path) -> anyhow::Result<()> {
    if p.is_dir() {
        anyhow::bail!("{flag} {}: is a directory, not a file", p.display());
    }
    let parent = p.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(d) = parent.filter(|d| !d.is_dir()) {
        anyhow::bail!(
            "{flag} {}: folder {} does not exist",
            p.display(),
            d.display()
        );
    }
    Ok(())
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
