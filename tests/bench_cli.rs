//! `conemesh bench` (the end-to-end benchmark of issue 9's table): one row per mesh with the
//! numbers of the run's own report, a failing mesh reported by name without stopping the
//! others, a non-zero exit when any run failed, and an error when there is nothing to run.
//! With MMG (a FAKE one here) each mesh also runs through MMG on the run's input metric, both
//! outputs scored by `conemesh eval`; `--threads` tables several thread counts.

use conemesh::mesh::generators;
use std::path::Path;
use std::process::Command;

/// `conemesh bench ARGS` with no MMG to be found (PATH empty, CONEMESH_MMG unset; bench starts
/// its conemesh children through its own path, not PATH).
fn bench(args: &[&str]) -> std::process::Output {
    let empty = tempfile::tempdir().expect("tempdir");
    Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .arg("bench")
        .args(args)
        .env("PATH", empty.path())
        .env_remove("CONEMESH_MMG")
        .output()
        .expect("run conemesh bench")
}

/// The lines of the first table (conemesh's), before the side-by-side section.
fn first_table(table: &str) -> &str {
    table.split("\n## ").next().expect("a table")
}

/// The cells of the side-by-side row of `name` and `tool`.
fn tool_row(table: &str, name: &str, tool: &str) -> Vec<String> {
    row(table, &format!("{name} | {tool}"))
        .into_iter()
        .skip(1)
        .collect()
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
        first_table(&table)
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
    // Without MMG its row says so (not a failure); conemesh's output is scored by eval.
    let m = tool_row(&table, "torus", "MMG");
    assert_eq!(m[1], "not installed", "{m:?}");
    let c = tool_row(&table, "torus", "conemesh");
    assert_eq!(c[1], t[2], "eval counts the faces of the written output");
    assert!(
        c[2].ends_with(&format!("{q_avg:.3}")),
        "the same yardstick: {}",
        c[2]
    );
    assert!(
        !out.join("torus-input.sol").exists(),
        "no metric without MMG"
    );

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

/// A FAKE `mmgs_O3` (a shell script, for tests only): it remeshes nothing, it copies the `-in`
/// mesh to `-out` and records its arguments in `OUT.args`, so the MMG row must show the
/// input's own faces.
fn fake_mmg(dir: &Path) -> std::path::PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let path = dir.join("fake-mmgs_O3");
    let script = "#!/bin/sh\n# FAKE mmgs_O3 for conemesh's tests: not MMG, it only copies -in to -out.\n\
         PATH=/usr/bin:/bin; args=\"$*\"\n\
         if [ \"$1\" = \"-h\" ]; then echo '  -- FAKE MMGS, Release 0.0 (test stub)'; exit 0; fi\n\
         while [ $# -gt 0 ]; do case \"$1\" in -in) in=\"$2\"; shift;; -out) out=\"$2\"; shift;; esac; shift; done\n\
         cp \"$in\" \"$out\" && echo \"$args\" > \"$out.args\"\n";
    std::fs::write(&path, script).expect("write fake");
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    path
}

/// With (a fake) MMG: the run writes the input metric (one tensor per input vertex), MMG gets
/// the input as `.mesh` with that metric and the issue's protocol, its output is scored by
/// `conemesh eval` at conemesh's L_tar, and the table has both rows and the time ratio.
#[test]
fn with_mmg_the_folder_bench_scores_both_tools_and_gives_the_time_ratio() {
    let dir = tempfile::tempdir().expect("tempdir");
    let torus = generators::torus(1.0, 0.35, 24, 10);
    let input = dir.path().join("torus.off");
    conemesh::io::write_mesh(&input, &torus).expect("write");
    let mmg = fake_mmg(dir.path());
    let out = dir.path().join("out");
    let o = bench(&[
        input.to_str().expect("utf-8"),
        "--mmg",
        mmg.to_str().expect("utf-8"),
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    let table = std::fs::read_to_string(out.join("remesh.md")).expect("table");
    assert!(
        table.contains("FAKE MMGS, Release 0.0"),
        "the version: {table}"
    );

    // The metric of the run, one tensor per input vertex, went to MMG with the protocol.
    let sol = out.join("torus-input.sol");
    let metric = conemesh::io::sol::read_sol(&sol, torus.n_vertices()).expect("input metric");
    assert!(
        metric.iter().all(|m| m.symmetric_eigenvalues().min() > 0.0),
        "SPD"
    );
    let args = std::fs::read_to_string(out.join("torus-mmg.mesh.args")).expect("fake ran");
    assert!(
        args.contains(&format!("-in {}", out.join("torus.mesh").display()))
            && args.contains(&format!("-sol {}", sol.display()))
            && args.contains("-nr -hausd 10 -hgrad -1 -v -1"),
        "{args}"
    );

    // MMG's output (the input itself, copied) scored by eval at the run's L_tar.
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("torus.json")).expect("report"))
            .expect("json");
    let eval: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("torus-mmg-eval.json")).expect("MMG scored"),
    )
    .expect("json");
    assert_eq!(eval["report"]["output"]["faces"], torus.n_faces());
    let l_tar = |v: &serde_json::Value| v.as_f64().expect("l_tar");
    assert_eq!(
        l_tar(&eval["report"]["l_tar"]),
        l_tar(&report["run"]["l_tar"]),
        "one L_tar for both tools"
    );
    let m = tool_row(&table, "torus", "MMG");
    assert_eq!(m[1], torus.n_faces().to_string(), "{m:?}");
    let q = eval["report"]["output_quality"]["q_avg"]
        .as_f64()
        .expect("q");
    assert!(m[2].ends_with(&format!("{q:.3}")), "{m:?}");
    let c = tool_row(&table, "torus", "conemesh");
    assert_eq!(c[1], report["run"]["faces_out"].to_string(), "{c:?}");
    let ratio: f64 = c.last().expect("cells").parse().expect("a time ratio");
    let (wall_c, wall_m): (f64, f64) = (c[9].parse().expect("wall"), m[9].parse().expect("wall"));
    assert!(ratio > 0.0 && wall_c > 0.0 && wall_m >= 0.0, "{c:?} {m:?}");
    assert_eq!(
        m.last().map(String::as_str),
        Some("-"),
        "the ratio is on conemesh's row"
    );
}

/// `--threads 1,2`: both counts run, their times and the speed-up are tabled, and the output
/// is the same (it does not depend on the thread count), here with batches of 4 patches.
#[test]
fn threads_tables_each_count_and_the_outputs_are_the_same() {
    let dir = tempfile::tempdir().expect("tempdir");
    let input = dir.path().join("torus.off");
    conemesh::io::write_mesh(&input, &generators::torus(1.0, 0.35, 24, 10)).expect("write");
    let out = dir.path().join("out");
    let o = bench(&[
        input.to_str().expect("utf-8"),
        "--threads",
        "1,2",
        "-o",
        out.to_str().expect("utf-8"),
        "--",
        "--batch",
        "4",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let table = std::fs::read_to_string(out.join("remesh.md")).expect("table");
    let section = table
        .split("## Thread counts")
        .nth(1)
        .expect("threads section");
    assert!(section.contains("| mesh | s at 1 | s at 2 | speed-up 1→2 | same output at 2 |"));
    let cells = row(section, "torus");
    let (t1, t2): (f64, f64) = (cells[1].parse().expect("s"), cells[2].parse().expect("s"));
    let speedup: f64 = cells[3].parse().expect("speed-up");
    // The cells are rounded to 0.01: the speed-up is the ratio of the times within that.
    let (lo, hi) = ((t1 - 0.005) / (t2 + 0.005), (t1 + 0.005) / (t2 - 0.005));
    assert!(
        t2 > 0.005 && (lo - 0.005..=hi + 0.005).contains(&speedup),
        "{t1} / {t2} vs {speedup}"
    );
    assert_eq!(
        cells[4], "yes",
        "the output at 2 threads is the output at 1"
    );
    let report = |p: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(out.join(p)).expect("report")).expect("json")
    };
    assert_eq!(report("torus.json")["run"]["options"]["batch"], 4);
    assert_eq!(report("torus-t2.json")["run"]["options"]["batch"], 4);
    // --threads is bench's to set then.
    let o = bench(&[
        input.to_str().expect("utf-8"),
        "--threads",
        "1,2",
        "-o",
        out.to_str().expect("utf-8"),
        "--",
        "--threads",
        "2",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("set by bench"));
}
