//! Hostile option values and output paths (issue 20), each refused by name before any work:
//! exit code 2, the offending flag in the message, and no output file written or replaced.

use std::path::Path;
use std::process::{Command, Output};

fn conemesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .args(args)
        .output()
        .expect("runs")
}

fn refused(o: &Output, says: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains(says), "expected `{says}` in: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

fn write_torus(dir: &Path) -> String {
    let p = dir.join("in.obj");
    conemesh::io::write_mesh(&p, &conemesh::mesh::generators::torus(1.0, 0.4, 12, 6))
        .expect("write");
    p.to_str().expect("utf-8").to_string()
}

#[test]
fn eval_refuses_a_sample_count_it_cannot_allocate_before_reading_anything() {
    // The meshes do not exist: the count is refused first (it used to abort on a 24 TB
    // allocation).
    let o = conemesh(&[
        "eval",
        "--input",
        "missing-in.obj",
        "--output",
        "missing-out.obj",
        "--samples",
        "1000000000000",
    ]);
    refused(&o, "--samples 1000000000000");
    // The library refuses it too, naming the limit.
    let m = conemesh::mesh::generators::torus(1.0, 0.4, 8, 4);
    let opts = conemesh::quality::EvalOptions {
        samples: conemesh::quality::MAX_SAMPLES + 1,
        ..Default::default()
    };
    assert!(matches!(
        conemesh::quality::evaluate(&m, &m, None, &opts),
        Err(conemesh::quality::EvalError::TooManySamples(n)) if n == conemesh::quality::MAX_SAMPLES + 1
    ));
}

#[test]
fn negative_values_are_read_as_values_and_refused_by_what_they_mean() {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = write_torus(dir.path());
    let out = dir.path().join("out.obj");
    let o = conemesh(&[
        "remesh",
        &input,
        "-o",
        out.to_str().unwrap(),
        "--ltar",
        "-1",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("unexpected argument"), "{err}");
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("-1"), "{err}");
    assert!(!out.exists());
}

#[test]
fn output_paths_are_checked_before_any_work() {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = write_torus(dir.path());
    let d = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let out = d("out.obj");
    // A folder as the mesh output.
    refused(
        &conemesh(&["remesh", &input, "-o", dir.path().to_str().unwrap()]),
        "is a directory",
    );
    // Outputs into folders that do not exist.
    let missing = d("no-such-folder/out.obj");
    refused(
        &conemesh(&["remesh", &input, "-o", &missing]),
        "does not exist",
    );
    for flag in ["--report", "--write-metric"] {
        let o = conemesh(&["remesh", &input, "-o", &out, flag, &missing]);
        refused(&o, flag);
        assert!(!Path::new(&out).exists(), "{flag}: no mesh written");
    }
    // `--plots` on a regular file.
    std::fs::write(d("plots-file"), b"x").expect("write");
    refused(
        &conemesh(&["remesh", &input, "-o", &out, "--plots", &d("plots-file")]),
        "--plots",
    );
    // The report where the mesh goes, the mesh over the input.
    refused(
        &conemesh(&["remesh", &input, "-o", &out, "--report", &out]),
        "same path as -o",
    );
    refused(
        &conemesh(&["remesh", &input, "-o", &input]),
        "same path as the input",
    );
    assert!(!Path::new(&out).exists());
    // The input is still the torus it was.
    let back = conemesh::io::read_mesh(Path::new(&input)).expect("input intact");
    assert_eq!(back.mesh.n_faces(), 12 * 6 * 2);
}
