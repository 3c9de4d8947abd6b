//! Covering runs of the patch strategies on generated surfaces (Sec. 3.2).

use conemesh::ids::{EdgeKey, FaceId};
use conemesh::invariants::certify_disk;
use conemesh::mesh::{generators, Topology, TriMesh};
use conemesh::patches::{
    cover, grow_patch, ConeOptions, ConePatches, CoverOptions, CoverRun, KRingDisks, PatchContext,
    PatchStrategy,
};
use rand::SeedableRng;
use std::collections::HashSet;

fn run(mesh: &TriMesh, s: &dyn PatchStrategy, seed: u64) -> CoverRun {
    let mut rng = conemesh::Rng::seed_from_u64(seed);
    cover(mesh, s, &CoverOptions::default(), &mut rng).expect("cover")
}

fn check_run(mesh: &TriMesh, r: &CoverRun, c_max: Option<f64>) {
    assert!(r.complete);
    let mut covered = vec![false; mesh.n_faces()];
    for p in &r.patches {
        let b = certify_disk(mesh, &p.faces).expect("disk");
        assert_eq!(b, p.boundary);
        for f in &p.faces {
            covered[f.idx()] = true;
        }
        if let (Some(c), Some(m)) = (c_max, p.max_growth_cost) {
            assert!(m < c, "growth cost {m} >= c_max {c}");
        }
    }
    assert!(covered.iter().all(|&c| c));
}

#[test]
fn developable_pieces_grow_into_one_patch() {
    for (name, m) in [
        (
            "cylinder",
            generators::cylinder_piece(1.0, 2.5, 1.5, 24, 10),
        ),
        ("cone", generators::cone_piece(0.6, 2.5, 0.5, 2.0, 24, 10)),
    ] {
        let r = run(&m, &ConePatches::default(), 3);
        check_run(&m, &r, Some(0.1));
        assert_eq!(r.patches.len(), 1, "{name}: {:?}", r.stats);
        assert_eq!(r.patches[0].faces.len(), m.n_faces(), "{name}");
        assert!(
            r.stats[0].developability < 1e-20,
            "{name}: {:?}",
            r.stats[0]
        );
    }
}

#[test]
fn closed_cylinder_grows_until_the_disk_rule_stops_it() {
    // An open cylinder is developable everywhere but is an annulus: one patch cannot cover
    // it; the first patch stops where closing the loop would break the disk.
    let m = generators::cylinder(1.0, 1.0, 24, 6);
    let r = run(&m, &ConePatches::default(), 5);
    check_run(&m, &r, Some(0.1));
    let first = &r.patches[0];
    // Only a seam strip (at most two columns) is left for the next patch.
    assert!(
        first.faces.len() + 2 * 2 * 6 >= m.n_faces(),
        "{:?}",
        r.stats
    );
    assert!(first.faces.len() < m.n_faces());
    assert!(r.patches.len() >= 2);
}

#[test]
fn sphere_gives_many_small_patches() {
    let m = generators::icosphere(1.0, 3);
    let r = run(&m, &ConePatches::default(), 1);
    check_run(&m, &r, Some(0.1));
    let largest = r.stats.iter().map(|s| s.faces).max().unwrap_or(0);
    eprintln!("sphere: {} patches, largest {largest}", r.patches.len());
    assert!(r.patches.len() >= 6, "{} patches", r.patches.len());
    assert!(largest < m.n_faces() / 3, "largest patch {largest}");
}

#[test]
fn same_seed_same_patches_and_strategies_differ() {
    let m = generators::torus(1.0, 0.35, 40, 16);
    for s in [
        &ConePatches::default() as &dyn PatchStrategy,
        &KRingDisks::default(),
    ] {
        let a = run(&m, s, 11);
        let b = run(&m, s, 11);
        assert_eq!(a, b, "{}", s.name());
        check_run(&m, &a, Some(0.1));
        let c = run(&m, s, 12);
        assert_ne!(a.patches, c.patches, "{}: seed must matter", s.name());
    }
}

#[test]
fn patches_never_cross_feature_or_boundary_edges() {
    // genus-2 plate: mark the sharp edges (dihedral angle 90°) as features.
    let m = generators::genus_plate(2, 2);
    let topo = Topology::build(&m);
    let mut features = HashSet::new();
    for f in m.faces() {
        for i in 0..3 {
            if let Some(g) = topo.neighbor(f, i) {
                if m.face_normal(f).dot(&m.face_normal(g)) < 0.5 {
                    let t = m.face(f);
                    features.insert(EdgeKey::new(t[i], t[(i + 1) % 3]));
                }
            }
        }
    }
    assert!(!features.is_empty());
    let opts = CoverOptions {
        feature_edges: Some(features.clone()),
        corners: None,
        max_patches: None,
    };
    let mut rng = conemesh::Rng::seed_from_u64(2);
    let r = cover(&m, &ConePatches::default(), &opts, &mut rng).expect("cover");
    check_run(&m, &r, Some(0.1));
    for p in &r.patches {
        let set: HashSet<FaceId> = p.faces.iter().copied().collect();
        for &f in &p.faces {
            for i in 0..3 {
                if let Some(g) = topo.neighbor(f, i) {
                    if set.contains(&g) {
                        let t = m.face(f);
                        let e = EdgeKey::new(t[i], t[(i + 1) % 3]);
                        assert!(!features.contains(&e), "feature edge {e} inside a patch");
                    }
                }
            }
        }
    }
    // A disk with a boundary: patches stay inside, boundary vertices may lie on it.
    let d = generators::disk(1.0, 6, 6);
    let r = run(&d, &ConePatches::default(), 4);
    check_run(&d, &r, Some(0.1));
    assert_eq!(r.patches.len(), 1, "a flat disk is one cone patch");
}

#[test]
fn growth_respects_c_max_and_costs_are_recorded() {
    let m = generators::torus(1.0, 0.35, 48, 18);
    let topo = Topology::build(&m);
    let processed = vec![false; m.n_faces()];
    let ctx = PatchContext {
        mesh: &m,
        topology: &topo,
        processed: &processed,
        feature_edges: None,
        corners: None,
        blocked: None,
    };
    let cone = conemesh::patches::fit_cone(&m, &[FaceId(0), FaceId(1)]);
    for c_max in [0.01, 0.1, 1.0] {
        let opts = ConeOptions {
            c_max,
            ..Default::default()
        };
        let g = grow_patch(&ctx, FaceId(0), &cone, &opts);
        assert_eq!(g.costs.len() + 1, g.patch.len());
        assert!(g.costs.iter().all(|&c| c < c_max));
        certify_disk(&m, &g.patch.sorted_faces()).expect("grown patch is a disk");
    }
}
