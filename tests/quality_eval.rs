//! `conemesh eval` on the shared meshes, each scored against itself (Sec. 4.1, Table 1):
//! the library half on every mesh (heavy, snapshot of the input rows) and the CLI on a
//! small one (JSON, plots, printed row).

use conemesh::quality::{evaluate, EvalOptions};
use std::collections::BTreeMap;

mod common;

fn r3(x: f64) -> String {
    format!("{x:.3}")
}

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn eval_of_every_shared_mesh_against_itself() -> anyhow::Result<()> {
    let mut rows = BTreeMap::new();
    for m in &common::SHARED_MESHES {
        let name = m.name();
        let mesh = m.load();
        let opts = EvalOptions {
            samples: 20_000,
            ..EvalOptions::default()
        };
        let r = evaluate(&mesh, &mesh, None, &opts)?;
        // Against itself: nothing moved, nothing flipped, same topology, same statistics.
        assert!(r.distance.hausdorff_rel < 1e-12, "{name}: {:?}", r.distance);
        assert!(r.flips.is_empty(), "{name}: flips {:?}", r.flips);
        assert!(r.topology_kept, "{name}: {:?}", r.topology_detail);
        // The output's metrics come from the field at its vertices, which is exactly the
        // input's vertex tensor, except where two input vertices coincide (cow has one such
        // pair): the closest face then belongs to either. So: equal up to such vertices.
        let (qi, qo) = (&r.input_quality, &r.output_quality);
        assert_eq!(qi.faces, qo.faces, "{name}");
        assert!(
            (qi.q_avg - qo.q_avg).abs() < 1e-3 && (qi.theta_avg - qo.theta_avg).abs() < 1e-2,
            "{name}: {qi:?} {qo:?}"
        );
        assert_eq!(qi.q_max, qo.q_max, "{name}");
        assert!((r.input_conformity.mean - 1.0 / 1.5).abs() < 1e-9, "{name}");
        assert!(
            (r.output_conformity.mean - 1.0 / 1.5).abs() < 1e-3,
            "{name}"
        );
        let q = &r.input_quality;
        rows.insert(
            name.to_string(),
            serde_json::json!({
                "V": r.input.vertices,
                "F": r.input.faces,
                "q": format!("{}/{}/{}", r3(q.q_min), r3(q.q_max), r3(q.q_avg)),
                "theta": format!("{}/{}/{}", r3(q.theta_min), r3(q.theta_max), r3(q.theta_avg)),
                "pct_min_lt_10_20_30": format!("{}/{}/{}", r3(q.pct_min_angle_lt_10), r3(q.pct_min_angle_lt_20), r3(q.pct_min_angle_lt_30)),
                "pct_max_gt_120": r3(q.pct_max_angle_gt_120),
                "conformity_median_inrange": format!("{}/{}", r3(r.input_conformity.median), r3(r.input_conformity.fraction_in_range)),
                "self_intersections": r.self_intersections.len(),
            }),
        );
        eprintln!("{}", r.table_row(name));
    }
    insta::with_settings!({snapshot_path => concat!(env!("CARGO_MANIFEST_DIR"), "/snapshots"), prepend_module_to_snapshot => false}, {
        insta::assert_json_snapshot!("eval_input_rows", rows);
    });
    Ok(())
}

#[test]
fn cli_eval_prints_a_row_and_writes_json_and_plots() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let knight = common::path("decimated-knight.off");
    let json = dir.path().join("r.json");
    let plots = dir.path().join("plots");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .args(["eval", "--input"])
        .arg(&knight)
        .arg("--output")
        .arg(&knight)
        .args(["--samples", "2000", "--json"])
        .arg(&json)
        .arg("--plots")
        .arg(&plots)
        .output()?;
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout)?;
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    assert!(lines[0].starts_with("mesh") && lines[0].contains("q_min/q_max/q_avg"));
    assert!(
        lines[1].starts_with("decimated-knight")
            && lines[1].contains(" 502 ")
            && lines[1].contains("1000")
    );
    assert!(lines[1].trim_end().ends_with("yes"), "{}", lines[1]);
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json)?)?;
    assert_eq!(doc["report"]["input"]["faces"], 1000);
    assert_eq!(doc["report"]["flips"].as_array().map(Vec::len), Some(0));
    assert_eq!(doc["report"]["metric_source"], "curvature");
    let l_avg = doc["report"]["l_avg"].as_f64().unwrap_or(0.0);
    let l_tar = doc["report"]["l_tar"].as_f64().unwrap_or(0.0);
    assert!((l_tar - 1.5 * l_avg).abs() < 1e-12 && l_avg > 0.0);
    for f in ["hist_q.png", "hist_angles.png", "hist_min_angles.png"] {
        assert!(plots.join(f).is_file(), "{f} missing");
    }
    // An absolute L_tar in file units and a conflicting pair of options.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .args([
            "eval",
            "--no-header",
            "--samples",
            "100",
            "--ltar-factor",
            "1",
            "--ltar",
            "2",
            "--input",
        ])
        .arg(&knight)
        .arg("--output")
        .arg(&knight)
        .output()?;
    assert!(
        !out.status.success(),
        "conflicting --ltar and --ltar-factor accepted"
    );
    // A missing output file is an error naming it, not a panic.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .args(["eval", "--input"])
        .arg(&knight)
        .arg("--output")
        .arg(dir.path().join("nope.off"))
        .output()?;
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nope.off"));
    Ok(())
}
