//! Heavy (issue 7, "Done when"): every patch of the covering runs (cone patches, seed 1,
//! unit-diagonal mesh) of four shared meshes parameterizes with an exact bijectivity
//! certificate; snapshot of the per-mesh counts and rounded distortion. The full table over
//! all shared meshes is `cargo run --release --example param_cover`.

#[path = "common/param_cover.rs"]
mod param_cover;

use param_cover::run_mesh;
use std::collections::BTreeMap;

fn r2(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn every_cover_patch_of_four_shared_meshes_is_certified() {
    let mut snap = BTreeMap::new();
    for name in [
        "fertility.off",
        "3holes.off",
        "screwdriver.off",
        "bunny.off",
    ] {
        let (run, _, _) = run_mesh(name).unwrap_or_else(|e| panic!("{e}"));
        let failed: Vec<String> = run
            .patches
            .iter()
            .filter_map(|p| {
                p.error
                    .as_ref()
                    .map(|e| format!("patch {} ({} faces): {e}", p.patch, p.faces))
            })
            .collect();
        assert!(failed.is_empty(), "{name}: {failed:#?}");
        let s = run.summary();
        assert_eq!(s.certified, s.patches, "{name}");
        assert!(s.patches > 1, "{name}: a covering run has several patches");
        // σ1/σ2 ≥ 1 by definition; a certified map has finite distortion.
        assert!(
            s.mean_conformal_area_weighted >= 1.0 && s.worst_max_conformal.is_finite(),
            "{name}: {s:?}"
        );
        eprintln!("{name}: {s:?}");
        snap.insert(
            name,
            serde_json::json!({
                "patches": s.patches,
                "certified": s.certified,
                "fallbacks": s.fallbacks,
                "mean_conformal_area_weighted": r2(s.mean_conformal_area_weighted),
                "worst_max_conformal": r2(s.worst_max_conformal),
            }),
        );
    }
    insta::with_settings!({snapshot_path => concat!(env!("CARGO_MANIFEST_DIR"), "/snapshots"), prepend_module_to_snapshot => false}, {
        insta::assert_json_snapshot!("param_cover_seed1", snap);
    });
}
