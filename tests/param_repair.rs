//! Heavy (issue 7, Sec. 3.3): the overlap repair of the LSCM start on the hard cover patches
//! of the Stanford bunny (cone patches, seed 1), whose free-boundary LSCM overlaps where
//! narrow slits of the ragged patch boundary close. Before the repair they started from the
//! Tutte map and needed 68–100 Newton iterations (p2 ran out of budget at mean σ1/σ2 1.31).

#[path = "common/param_cover.rs"]
mod param_cover;

use conemesh::invariants::certify_bijective;
use conemesh::param::{
    initial_map, lscm, scale_to_area, InitialMap, Parameterizer, SdOptions, SymmetricDirichlet,
};
use conemesh::patches::{cover, extract_patch, ConePatches, CoverOptions};
use rand::SeedableRng;

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn hard_bunny_patches_start_from_the_repaired_lscm() {
    let mesh = param_cover::load("stanford-bunny.obj");
    let mut rng = conemesh::Rng::seed_from_u64(1);
    let run = cover(
        &mesh,
        &ConePatches::default(),
        &CoverOptions::default(),
        &mut rng,
    )
    .expect("cover");
    for (pi, max_mean_conformal) in [(11, 1.02), (2, 1.03)] {
        let faces = &run.patches[pi].faces;
        assert!(
            faces.len() > 4000,
            "p{pi}: {} faces (covering run changed?)",
            faces.len()
        );
        let pm = extract_patch(&mesh, faces).expect("extract");
        // The premise: the LSCM itself is not certified.
        let mut l = lscm(&pm.mesh, &pm.boundary).expect("lscm");
        scale_to_area(&pm.mesh, &mut l);
        assert!(
            certify_bijective(&l, &pm.mesh.triangles, &pm.boundary).is_err(),
            "p{pi}: the LSCM is certified (covering run changed?)"
        );
        let (uv0, kind) =
            initial_map(&pm.mesh, &pm.boundary, &SdOptions::default()).expect("initial map");
        assert_eq!(kind, InitialMap::RepairedLscm, "p{pi}");
        certify_bijective(&uv0, &pm.mesh.triangles, &pm.boundary).expect("certified start");
        let p = SymmetricDirichlet::default()
            .parameterize(&pm.mesh, &pm.boundary)
            .expect("parameterize");
        certify_bijective(&p.uv, &pm.mesh.triangles, &pm.boundary).expect("certified map");
        let r = &p.report;
        eprintln!("p{pi}: {r:?}");
        assert!(!r.hit_budget && !r.fell_back, "p{pi}: {r:?}");
        assert!(r.iterations <= 30, "p{pi}: {} iterations", r.iterations);
        assert!(r.mean_conformal <= max_mean_conformal, "p{pi}: {r:?}");
        // Without the repair (Tutte start) the same budget gives a worse or equal map.
        let tutte = SymmetricDirichlet {
            options: SdOptions {
                repair_iters: 0,
                ..Default::default()
            },
        }
        .parameterize(&pm.mesh, &pm.boundary)
        .expect("parameterize from Tutte");
        assert!(
            r.mean_conformal <= tutte.report.mean_conformal + 1e-3,
            "p{pi}: repaired {} vs Tutte {}",
            r.mean_conformal,
            tutte.report.mean_conformal
        );
    }
}
