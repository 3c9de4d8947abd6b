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
    for flag in ["--report", "--write-metric", "--write-input-metric"] {
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

/// Every file under `dir` whose name marks it as a temporary of `conemesh::io::Outputs`.
fn temporaries(dir: &Path) -> Vec<String> {
    let mut found = Vec::new();
    for e in std::fs::read_dir(dir).expect("read dir") {
        let p = e.expect("entry").path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with(conemesh::io::TEMP_PREFIX) {
            found.push(p.display().to_string());
        }
        if p.is_dir() {
            found.extend(temporaries(&p));
        }
    }
    found
}

/// Issue 20, item 1: the outputs of `remesh` are one transaction. The last output (a plot)
/// cannot be renamed into place (a folder of its name is in `--plots`): the mesh, the metric
/// and the report written before it are undone, their old contents are back, the message
/// names the plot, and no temporary remains.
#[test]
fn all_outputs_as_one_transaction_remesh_undoes_the_mesh_when_the_last_plot_fails() {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = write_torus(dir.path());
    let d = |n: &str| dir.path().join(n);
    std::fs::write(d("out.obj"), b"old mesh").expect("write");
    std::fs::write(d("report.json"), b"old report").expect("write");
    std::fs::create_dir_all(d("plots/hist_min_angles.png")).expect("mkdir");
    std::fs::write(d("plots/hist_q.png"), b"old plot").expect("write");
    let s = |n: &str| d(n).to_str().unwrap().to_string();
    let o = conemesh(&[
        "remesh",
        &input,
        "-o",
        &s("out.obj"),
        "--report",
        &s("report.json"),
        "--write-metric",
        &s("out.sol"),
        "--write-input-metric",
        &s("in.sol"),
        "--plots",
        &s("plots"),
        "--quiet",
        "--improvers",
        "surface",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("hist_min_angles.png"), "{err}");
    assert!(err.contains("none of them was written"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(std::fs::read(d("out.obj")).unwrap(), b"old mesh");
    assert_eq!(std::fs::read(d("report.json")).unwrap(), b"old report");
    assert_eq!(std::fs::read(d("plots/hist_q.png")).unwrap(), b"old plot");
    assert!(!d("out.sol").exists() && !d("in.sol").exists());
    assert!(!d("plots/hist_angles.png").exists());
    assert!(d("plots/hist_min_angles.png").is_dir());
    assert_eq!(temporaries(dir.path()), Vec::<String>::new());
    // Without the obstacle the same run writes everything, and leaves no temporary either.
    std::fs::remove_dir(d("plots/hist_min_angles.png")).expect("rmdir");
    let o = conemesh(&[
        "remesh",
        &input,
        "-o",
        &s("out.obj"),
        "--report",
        &s("report.json"),
        "--write-metric",
        &s("out.sol"),
        "--write-input-metric",
        &s("in.sol"),
        "--plots",
        &s("plots"),
        "--quiet",
        "--improvers",
        "surface",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mesh = conemesh::io::read_mesh(&d("out.obj")).expect("new mesh");
    assert!(mesh.mesh.n_faces() > 0);
    assert_ne!(std::fs::read(d("report.json")).unwrap(), b"old report");
    assert!(d("out.sol").is_file() && d("in.sol").is_file());
    assert!(d("plots/hist_min_angles.png").is_file());
    assert_ne!(std::fs::read(d("plots/hist_q.png")).unwrap(), b"old plot");
    assert_eq!(temporaries(dir.path()), Vec::<String>::new());
}

/// Issue 20, item 1, for `eval`: the JSON report and the plots are one transaction.
#[test]
fn all_outputs_as_one_transaction_eval_keeps_the_old_json_when_a_plot_fails() {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = write_torus(dir.path());
    let d = |n: &str| dir.path().join(n);
    std::fs::write(d("r.json"), b"old json").expect("write");
    std::fs::create_dir_all(d("plots/hist_angles.png")).expect("mkdir");
    let o = conemesh(&[
        "eval",
        "--input",
        &input,
        "--output",
        &input,
        "--samples",
        "1000",
        "--json",
        d("r.json").to_str().unwrap(),
        "--plots",
        d("plots").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("hist_angles.png"), "{err}");
    assert_eq!(std::fs::read(d("r.json")).unwrap(), b"old json");
    assert!(!d("plots/hist_q.png").exists());
    assert_eq!(temporaries(dir.path()), Vec::<String>::new());
}

/// Plot folders whose parent folder does not exist, or under a regular file, are refused
/// before any work (they used to fail after the mesh was written).
#[test]
fn a_plots_folder_under_a_file_or_a_missing_folder_is_refused_before_any_work() {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = write_torus(dir.path());
    let out = dir.path().join("out.obj");
    for plots in [
        format!("{input}/plots"),
        dir.path().join("no/plots").display().to_string(),
    ] {
        let o = conemesh(&[
            "remesh",
            &input,
            "-o",
            out.to_str().unwrap(),
            "--plots",
            &plots,
        ]);
        refused(&o, "--plots");
        assert!(!out.exists());
        let o = conemesh(&[
            "eval", "--input", &input, "--output", &input, "--plots", &plots,
        ]);
        refused(&o, "--plots");
    }
    assert_eq!(temporaries(dir.path()), Vec::<String>::new());
}

/// An output path that is not UTF-8 (the OS accepts any bytes but `/` and NUL) is written, and
/// the report holds it lossily; it used to panic after the work was done.
#[cfg(unix)]
#[test]
fn output_paths_that_are_not_utf8_are_written_and_reported_lossily() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().expect("temp dir");
    let input = write_torus(dir.path());
    let out = dir
        .path()
        .join(std::ffi::OsStr::from_bytes(b"out-\xe9.obj"));
    let report = dir
        .path()
        .join(std::ffi::OsStr::from_bytes(b"report-\xe9.json"));
    let o = Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .args([
            "remesh",
            &input,
            "-q",
            "--max-patches",
            "2",
            "--improvers",
            "surface",
            "-o",
        ])
        .arg(&out)
        .arg("--report")
        .arg(&report)
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(out.exists() && report.exists(), "{err}");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&report).expect("report")).expect("json");
    let written = json["output"].as_str().expect("a string");
    assert!(written.ends_with("out-\u{fffd}.obj"), "{written}");
}

#[test]
fn a_disk_read_as_one_polygon_of_100000_corners_is_refused_by_name_with_no_output() {
    // Issue 35's hostile disk: the centre first, then the circle. Its triangulation is the fan
    // of 99,998 slivers around the centre; the remesh refuses it by the centre's id, before
    // computing the metric, and writes nothing.
    let dir = tempfile::tempdir().expect("tempdir");
    let input = dir.path().join("disk.obj");
    let n = 100_000;
    let mut text = String::from("v 0 0 0\n");
    for i in 0..n - 1 {
        let a = std::f64::consts::TAU * i as f64 / (n - 1) as f64;
        text += &format!("v {} {} 0\n", a.cos(), a.sin());
    }
    text += "f";
    for i in 1..=n {
        text += &format!(" {i}");
    }
    text += "\n";
    std::fs::write(&input, text).expect("write");
    let out = dir.path().join("out.obj");
    let report = dir.path().join("out.json");
    let o = conemesh(&[
        "remesh",
        input.to_str().expect("utf-8"),
        "-o",
        out.to_str().expect("utf-8"),
        "--report",
        report.to_str().expect("utf-8"),
    ]);
    refused(
        &o,
        "input vertex v0 is a corner of 99998 faces (at most 16384)",
    );
    assert!(!out.exists() && !report.exists());
}
