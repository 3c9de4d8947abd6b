//! `conemesh bench` (the end-to-end benchmark of issue 9's table): one row per mesh with the
//! numbers of the run's own report, a failing mesh reported by name without stopping the
//! others, a non-zero exit when any run failed, and an error when there is nothing to run.

use conemesh::mesh::generators;
use std::process::Command;

fn bench(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .arg("bench")
        .args(args)
        .output()
        .expect("run conemesh bench")
}

/// The cells of the table row whose first cell is `name`.
fn row(table: &str, name: &str) -> Vec<String> {
    table
        .lines()
        .find(|l| l.starts_with(&format!("| {name} |")))
        .unwrap_or_else(|| panic!("no row for {name} in\n{table}"))
        .trim_matches('|')
        .split('|')
        .map(|c| c.trim().to_string())
        .collect()
}

#[test]
fn bench_tables_every_mesh_of_a_folder_and_names_the_failing_one() {
    let dir = tempfile::tempdir().expect("tempdir");
    let meshes = dir.path().join("meshes");
    std::fs::create_dir(&meshes).expect("mkdir");
    let torus = generators::torus(1.0, 0.35, 32, 12);
    conemesh::io::write_mesh(&meshes.join("torus.off"), &torus).expect("write");
    // A vertex with a NaN coordinate: remesh refuses it, bench goes on.
    std::fs::write(
        meshes.join("broken.off"),
        "OFF\n3 1 0\n0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n",
    )
    .expect("write");
    // Not a mesh extension: not run.
    std::fs::write(meshes.join("notes.txt"), "not a mesh").expect("write");
    let out = dir.path().join("out");
    let o = bench(&[
        "--dir",
        meshes.to_str().expect("utf-8"),
        "-o",
        out.to_str().expect("utf-8"),
        "--",
        "--seed",
        "3",
    ]);
    assert_eq!(o.status.code(), Some(1), "one run failed: exit 1");
    let table = std::fs::read_to_string(out.join("remesh.md")).expect("table written");
    assert!(table.contains("`conemesh remesh MESH --seed 3`"), "{table}");
    assert_eq!(
        table
            .lines()
            .filter(|l| l.starts_with("| ") && !l.starts_with("| mesh"))
            .count(),
        2,
        "two mesh rows (the .txt is skipped):\n{table}"
    );

    let t = row(&table, "torus");
    assert_eq!(t[1], torus.n_faces().to_string(), "faces in");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("torus.json")).expect("report"))
            .expect("json");
    assert_eq!(
        report["run"]["options"]["seed"], 3,
        "the extra args reach remesh"
    );
    assert_eq!(t[2], report["run"]["faces_out"].to_string(), "faces out");
    let q_avg = report["eval"]["output_quality"]["q_avg"]
        .as_f64()
        .expect("q_avg");
    assert!(t[3].ends_with(&format!("{q_avg:.3}")), "{}", t[3]);
    let (q_min, q_avg_cell) = t[3].split_once('/').expect("q_min / q_avg");
    let q_min: f64 = q_min.trim().parse().expect("q_min");
    assert!(q_min > 0.0 && q_min <= q_avg_cell.trim().parse::<f64>().expect("q_avg"));
    let h: f64 = t[5].parse().expect("Hausdorff");
    assert!((0.0..5.0).contains(&h), "Hausdorff {h} %");
    assert_eq!(t[6], "0", "no flips on a torus");
    let peak: f64 = t[10].parse().expect("peak MB is measured on Linux");
    assert!(peak > 1.0 && peak < 4096.0, "peak {peak} MB");
    assert!(out.join("torus.obj").is_file());

    let b = row(&table, "broken");
    let status = b.last().expect("cells");
    assert!(
        status.starts_with("FAILED") && status.contains("non-finite"),
        "the failure names the problem: {status}"
    );
    assert!(
        !out.join("broken.obj").exists(),
        "no output for the failed run"
    );
}

#[test]
fn bench_without_meshes_is_an_error_and_writes_no_table() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let o = bench(&[
        "--dir",
        dir.path().to_str().expect("utf-8"),
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no mesh files in"));
    assert!(!out.join("remesh.md").exists());
}

#[test]
fn bench_refuses_inputs_it_would_overwrite_or_mix_up() {
    let dir = tempfile::tempdir().expect("tempdir");
    let torus = generators::torus(1.0, 0.35, 16, 8);
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    for d in [&a, &b] {
        std::fs::create_dir(d).expect("mkdir");
        conemesh::io::write_mesh(&d.join("t.off"), &torus).expect("write");
    }
    let s = |p: &std::path::Path| p.to_str().expect("utf-8").to_string();
    let out = dir.path().join("out");
    // Two inputs named `t`: their outputs would overwrite each other.
    let o = bench(&[&s(&a.join("t.off")), &s(&b.join("t.off")), "-o", &s(&out)]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("share the name `t`"), "{err}");
    assert!(!out.join("remesh.md").exists());
    // An input inside the output folder with the output's name: it would be replaced.
    conemesh::io::write_mesh(&a.join("u.obj"), &torus).expect("write");
    let o = bench(&[&s(&a.join("u.obj")), "-o", &s(&a)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("overwritten by its own output"));
    assert_eq!(
        conemesh::io::read_mesh(&a.join("u.obj"))
            .expect("still there")
            .mesh
            .n_faces(),
        torus.n_faces()
    );
    // Arguments bench sets itself are refused before anything runs.
    let o = bench(&[
        &s(&a.join("t.off")),
        "-o",
        &s(&out),
        "--",
        "--report=x.json",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("set by bench"));
}

#[test]
fn a_stale_report_is_not_read_as_a_failed_runs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    std::fs::create_dir(&out).expect("mkdir");
    let broken = dir.path().join("broken.off");
    std::fs::write(&broken, "OFF\n3 1 0\n0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n").expect("write");
    // Leftovers of an earlier, successful run of a mesh with that name.
    let torus = generators::torus(1.0, 0.35, 16, 8);
    conemesh::io::write_mesh(&out.join("broken.obj"), &torus).expect("write");
    std::fs::write(
        out.join("broken.json"),
        r#"{"seconds": 1.0, "run": {"faces_in": 1, "faces_out": 1, "patches": 1}}"#,
    )
    .expect("write");
    let o = bench(&[
        broken.to_str().expect("utf-8"),
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let table = std::fs::read_to_string(out.join("remesh.md")).expect("table");
    assert!(row(&table, "broken")
        .last()
        .expect("cells")
        .starts_with("FAILED"));
    assert!(
        !out.join("broken.obj").exists(),
        "the stale output is removed"
    );
    assert!(
        !out.join("broken.json").exists(),
        "the stale report is removed"
    );
}
