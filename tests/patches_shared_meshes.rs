//! Cover every shared test mesh with cone patches (seed 1): every patch a certified disk,
//! complete coverage; snapshot of the rounded patch statistics.

use conemesh::invariants::certify_disk;
use conemesh::patches::{cover, ConePatches, CoverOptions};
use rand::SeedableRng;
use std::collections::BTreeMap;

mod common;

fn r3(x: f64) -> f64 {
    if x == 0.0 {
        return 0.0;
    }
    let m = 10f64.powi(2 - x.abs().log10().floor() as i32);
    (x * m).round() / m
}

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn cone_patches_cover_every_shared_mesh() {
    let mut snap = BTreeMap::new();
    for m in &common::SHARED_MESHES {
        let name = m.file.to_string();
        let mesh = m.load();
        let mut rng = conemesh::Rng::seed_from_u64(1);
        let t0 = std::time::Instant::now();
        let run = cover(
            &mesh,
            &ConePatches::default(),
            &CoverOptions::default(),
            &mut rng,
        )
        .expect("cover");
        let secs = t0.elapsed().as_secs_f64();
        assert!(run.complete, "{name}");
        for p in &run.patches {
            certify_disk(&mesh, &p.faces).expect("certified disk");
            assert!(p.max_growth_cost.is_some_and(|c| c < 0.1), "{name}");
        }
        let sizes: Vec<usize> = run.stats.iter().map(|s| s.faces).collect();
        let n = sizes.len();
        let mean = sizes.iter().sum::<usize>() as f64 / n as f64;
        let max = sizes.iter().copied().max().unwrap_or(0);
        let mut dev: Vec<f64> = run.stats.iter().map(|s| s.developability).collect();
        dev.sort_by(f64::total_cmp);
        eprintln!(
            "{name}: {} faces, {n} patches, mean {mean:.1}, max {max} faces/patch, {secs:.3} s",
            mesh.n_faces()
        );
        snap.insert(
            name,
            serde_json::json!({
                "faces": mesh.n_faces(),
                "patches": n,
                "mean_faces": r3(mean),
                "max_faces": max,
                "median_developability": r3(dev[dev.len() / 2]),
            }),
        );
    }
    insta::with_settings!({snapshot_path => concat!(env!("CARGO_MANIFEST_DIR"), "/snapshots"), prepend_module_to_snapshot => false}, {
        insta::assert_json_snapshot!("patches_shared_meshes_seed1", snap);
    });
}
