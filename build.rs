//! Records the git commit conemesh is built from (`CONEMESH_GIT_COMMIT`, read by
//! `conemesh::compare::snapshot::GIT_COMMIT`). Outside a git checkout (a tarball) or without
//! git the variable is not set and the snapshot says "unknown".

use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    if !out.status.success() {
        return None;
    }
    let s = String::from_utf8(out.stdout).ok()?.trim().to_string();
    (!s.is_empty()).then_some(s)
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    // Only this crate's own checkout: a tarball unpacked inside another repository must not
    // take that repository's commit.
    let manifest = std::env::var("CARGO_MANIFEST_DIR").unwrap_or_default();
    let top = git(&["-C", &manifest, "rev-parse", "--show-toplevel"]);
    let ours = top
        .as_deref()
        .is_some_and(|t| std::fs::canonicalize(t).ok() == std::fs::canonicalize(&manifest).ok());
    if !ours {
        return;
    }
    if let Some(commit) = git(&["-C", &manifest, "rev-parse", "HEAD"]) {
        println!("cargo:rustc-env=CONEMESH_GIT_COMMIT={commit}");
    }
    // Rebuild when HEAD moves: a new commit or a checkout of another branch.
    for p in ["HEAD", "logs/HEAD"] {
        if let Some(path) = git(&["-C", &manifest, "rev-parse", "--git-path", p]) {
            let path = std::path::Path::new(&manifest).join(path);
            println!("cargo:rerun-if-changed={}", path.display());
        }
    }
}
