//! The bad-input corpus (`tests/bad-inputs/`, table in its README.md): every malformed file
//! fails with its typed error kind, through the library and through the CLI (non-zero exit,
//! no panic, the error printed, no output file left); the topologically broken ones read fine.

use conemesh::io::read_mesh;
use std::path::{Path, PathBuf};
use std::process::Command;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/bad-inputs");

/// (file, expected kind) rows of the README table.
fn corpus() -> Vec<(String, String)> {
    let readme = std::fs::read_to_string(Path::new(DIR).join("README.md")).expect("README.md");
    readme
        .lines()
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            (cells.len() >= 4 && cells[1].contains('.') && cells[1] != "file")
                .then(|| (cells[1].to_string(), cells[2].to_string()))
        })
        .collect()
}

#[test]
fn corpus_table_lists_every_file_and_has_thirty() {
    let rows = corpus();
    let mut listed: Vec<&str> = rows.iter().map(|(f, _)| f.as_str()).collect();
    listed.sort_unstable();
    let mut files: Vec<String> = std::fs::read_dir(DIR)
        .expect("corpus dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n != "README.md" && n != "make.py")
        .collect();
    files.sort_unstable();
    assert_eq!(listed, files);
    assert!(rows.iter().filter(|(_, k)| k != "ok").count() >= 30);
}

#[test]
fn library_gives_the_expected_error_kind() {
    let mut wrong = Vec::new();
    for (file, kind) in corpus() {
        let got = match read_mesh(&Path::new(DIR).join(&file)) {
            Ok(_) => "ok".to_string(),
            Err(e) => {
                let msg = e.to_string();
                assert!(
                    msg.contains(&file),
                    "{file}: message does not name the file: {msg}"
                );
                e.kind().to_string()
            }
        };
        if got != kind {
            wrong.push(format!("{file}: expected {kind}, got {got}"));
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

fn run(args: &[&Path]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .args(args)
        .output()
        .expect("run conemesh");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn cli_convert_fails_cleanly_on_every_malformed_file() {
    let tmp = tempfile::tempdir().expect("tempdir");
    for (file, kind) in corpus() {
        if kind == "ok" {
            continue;
        }
        let input = PathBuf::from(DIR).join(&file);
        let out = tmp.path().join("out.obj");
        let (ok, stderr) = run(&[Path::new("convert"), &input, &out]);
        assert!(!ok, "{file}: convert succeeded");
        assert!(!stderr.contains("panicked"), "{file}: {stderr}");
        let expected = read_mesh(&input).expect_err("malformed").to_string();
        assert!(
            stderr.contains(&expected),
            "{file}: stderr {stderr:?} lacks {expected:?}"
        );
        assert!(!out.exists(), "{file}: partial output left");
        let left = std::fs::read_dir(tmp.path()).expect("tmp").count();
        assert_eq!(left, 0, "{file}: temporary files left");
    }
}

#[test]
fn topological_defects_read_and_convert() {
    let tmp = tempfile::tempdir().expect("tempdir");
    for (file, kind) in corpus() {
        if kind != "ok" {
            continue;
        }
        let input = PathBuf::from(DIR).join(&file);
        let out = tmp.path().join("out.ply");
        let (ok, stderr) = run(&[Path::new("convert"), &input, &out]);
        assert!(ok, "{file}: {stderr}");
        assert!(out.exists());
    }
}

/// `conemesh check` exits non-zero on every file of the corpus: 2 when it cannot read it,
/// 1 when it reads but is invalid (the topological defects), never with a panic.
#[test]
fn cli_check_rejects_the_whole_corpus() {
    for (file, kind) in corpus() {
        let input = PathBuf::from(DIR).join(&file);
        let out = Command::new(env!("CARGO_BIN_EXE_conemesh"))
            .arg("check")
            .arg(&input)
            .output()
            .expect("run conemesh");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("panicked"), "{file}: {stderr}");
        let expected_code = if kind == "ok" { 1 } else { 2 };
        assert_eq!(out.status.code(), Some(expected_code), "{file}: {stderr}");
        if kind == "ok" {
            let stdout = String::from_utf8_lossy(&out.stdout);
            assert!(stdout.contains("valid: no"), "{file}: {stdout}");
        }
    }
}
