//! Finding (or building) the CGAL checker `reference/cgal` and running it; shared by the CGAL
//! cross-validation tests. Without CGAL these tests fail with a message naming the packages:
//! they must not pass silently.

#![allow(dead_code)]

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

pub fn build_checker(src: &Path) -> Result<PathBuf, String> {
    let build = src.join("build");
    let bin = build.join("conemesh-cgal-check");
    let cmake = |args: &[&str]| -> Result<std::process::Output, String> {
        Command::new("cmake").args(args).output().map_err(|e| {
            format!(
                "cannot run cmake ({e}): install the `cmake` package \
                 (apt-get install cmake libcgal-dev g++), or run ./scripts/test which does"
            )
        })
    };
    let conf = cmake(&[
        "-S",
        &src.display().to_string(),
        "-B",
        &build.display().to_string(),
        "-DCMAKE_BUILD_TYPE=Release",
    ])?;
    if !conf.status.success() {
        let err = String::from_utf8_lossy(&conf.stderr);
        let hint = if err.contains("CGAL") {
            "CGAL was not found: install the `libcgal-dev` package (apt-get install libcgal-dev)"
        } else {
            "cmake configure failed: install `libcgal-dev cmake g++`"
        };
        return Err(format!("{hint}\ncmake said:\n{err}"));
    }
    let b = cmake(&["--build", &build.display().to_string()])?;
    if !b.status.success() {
        return Err(format!(
            "building the CGAL checker failed (is `g++` installed? is `libcgal-dev` complete?):\n{}{}",
            String::from_utf8_lossy(&b.stdout),
            String::from_utf8_lossy(&b.stderr)
        ));
    }
    if bin.is_file() {
        Ok(bin)
    } else {
        Err(format!("cmake succeeded but {} is missing", bin.display()))
    }
}

/// The checker binary, found or built once per test process.
pub fn checker() -> &'static Path {
    static BIN: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    let r = BIN.get_or_init(|| {
        if let Ok(p) = std::env::var("CONEMESH_CGAL_CHECK") {
            let p = PathBuf::from(p);
            if p.is_file() {
                return Ok(p);
            }
        }
        let src = repo().join("reference/cgal");
        let bin = src.join("build/conemesh-cgal-check");
        let fresh = |b: &Path| -> bool {
            let m = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
            match (m(b), m(&src.join("conemesh_cgal_check.cpp"))) {
                (Some(tb), Some(ts)) => tb >= ts,
                _ => false,
            }
        };
        if bin.is_file() && fresh(&bin) {
            return Ok(bin);
        }
        build_checker(&src)
    });
    match r {
        Ok(p) => p,
        Err(e) => panic!(
            "CGAL cross-validation cannot run: the checker is not available.\n{e}\n\
             (these tests must not pass without CGAL; see TESTING.md)"
        ),
    }
}

pub fn run_checker(mesh: &Path, extra: &[&str]) -> Value {
    let out = Command::new(checker())
        .arg(mesh)
        .args(extra)
        .output()
        .unwrap_or_else(|e| panic!("running {}: {e}", checker().display()));
    assert!(
        out.status.success(),
        "conemesh-cgal-check {} {:?} failed: {}",
        mesh.display(),
        extra,
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "checker output is not JSON ({e}): {}",
            String::from_utf8_lossy(&out.stdout)
        )
    })
}
