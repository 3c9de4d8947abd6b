//! Algorithm 2 (minimum-angle improvement, Sec. 3.4) through the library: certified like
//! Algorithm 1, never worse at the bottom, counted, reproducible.

use conemesh::invariants::certify_boundary_on_curves;
use conemesh::mesh::{Topology, TriMesh};
use conemesh::pipeline::{ImproveOptions, RemeshOptions, Remesher};
use std::path::Path;

fn shared(name: &str) -> TriMesh {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/meshes")).join(name);
    conemesh::io::read_mesh(&path).expect("shared mesh").mesh
}

fn with_improve(q: f64, seed: u64) -> RemeshOptions {
    RemeshOptions {
        seed,
        improve: ImproveOptions {
            enabled: true,
            q_threshold: q,
            ..ImproveOptions::default()
        },
        ..RemeshOptions::default()
    }
}

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn the_screwdriver_loses_small_angles_and_stays_certified() {
    let input = shared("screwdriver.off");
    let out = Remesher::new(with_improve(0.7, 1))
        .run(&input)
        .expect("remeshes");
    let r = &out.unit.report;
    let imp = r.improvement.expect("Algorithm 2 ran");
    // It found faces to improve, in counted passes and patches.
    assert!(
        imp.patches > 0 && imp.passes >= 1 && imp.passes <= 3,
        "{imp:?}"
    );
    assert!(!imp.budget_exhausted);
    // Never worse at the bottom, and better here (measured: θ_min 11.8° → 19.5°, q_min
    // 0.287 → 0.435, faces below 20° 5 → 1).
    assert!(imp.after.theta_min > imp.before.theta_min + 5.0, "{imp:?}");
    assert!(imp.after.q_min > imp.before.q_min + 0.1, "{imp:?}");
    assert!(imp.after.below_20 < imp.before.below_20, "{imp:?}");
    assert!(imp.rejected < imp.patches, "{imp:?}");
    assert!(imp.after.q_avg >= imp.before.q_avg - 0.002, "{imp:?}");
    assert_eq!(imp.after.faces, out.mesh.n_faces());
    // Certified as Algorithm 1's patches: every patch (both algorithms) counted once for
    // the manifold and topology certificates, no flips, no self-intersections.
    let c = &r.certificate;
    assert_eq!(c.manifold, r.patches);
    assert_eq!(c.same_topology, r.patches);
    assert_eq!(c.self_intersecting_pairs, 0);
    let q = conemesh::quality::flips(&out.input, &out.mesh);
    assert!(q.is_empty(), "flipped faces {q:?}");
    let topo = Topology::build(&out.unit.mesh);
    certify_boundary_on_curves(
        &out.unit.curves,
        &out.input,
        &out.mesh,
        &topo,
        &out.unit.curve,
    )
    .expect("boundary on the input's curves");
    // Off by default: the same run without it is Algorithm 1's output.
    let plain = Remesher::new(RemeshOptions::default())
        .run(&input)
        .expect("remeshes");
    assert!(plain.unit.report.improvement.is_none());
    assert!(plain.unit.report.patches < r.patches);
}

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn same_seed_same_bytes_with_the_improvement() {
    let input = shared("3holes.off");
    let a = Remesher::new(with_improve(0.8, 2)).run(&input).expect("a");
    let b = Remesher::new(with_improve(0.8, 2)).run(&input).expect("b");
    assert_eq!(a.mesh.positions, b.mesh.positions);
    assert_eq!(a.mesh.triangles, b.mesh.triangles);
    let imp = a.unit.report.improvement.expect("ran");
    // A patch is replaced only when neither its smallest quality nor its smallest angle
    // drops, so the mesh's cannot.
    assert!(imp.after.theta_min >= imp.before.theta_min, "{imp:?}");
    assert!(imp.after.q_min >= imp.before.q_min, "{imp:?}");
}

#[test]
fn the_cli_reports_and_plots_the_step_and_refuses_bad_values() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out_mesh = dir.path().join("out.obj");
    let report = dir.path().join("r.json");
    let plots = dir.path().join("plots");
    let run = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_conemesh"))
            .arg("remesh")
            .arg("-o")
            .arg(&out_mesh)
            .args(["--quiet", "--improve"])
            .args(extra)
            .output()
            .expect("runs")
    };
    let o = run(&[
        "--improve-q",
        "0.9",
        "--report",
        report.to_str().unwrap(),
        "--plots",
        plots.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let imp = &doc["run"]["improvement"];
    assert!(imp["patches"].as_u64().unwrap() > 0, "{imp}");
    let hist: Vec<u64> = imp["after"]["hist_min_angles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect();
    assert_eq!(
        hist.iter().sum::<u64>(),
        imp["after"]["faces"].as_u64().unwrap()
    );
    assert!(plots.join("hist_min_angles_improve.png").is_file());
    for bad in [
        ["--improve-q", "1.5"],
        ["--improve-w", "nan"],
        ["--improve-rings", "0"],
    ] {
        std::fs::remove_file(&out_mesh).ok();
        let o = run(&bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains("improvement") || err.contains("weight w"),
            "{err}"
        );
        assert!(!out_mesh.exists(), "no output for {bad:?}");
    }
}
