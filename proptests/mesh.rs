//! Properties of the mesh core and its certificates: Euler characteristic of the generated
//! surfaces, validity of small perturbations, and invariance of every topological verdict
//! under face permutation and vertex relabelling.
//!
//! Case counts are fixed (`CASES`) so the suite's time is stable.

use conemesh::check::{check_mesh, CheckOptions, CheckReport};
use conemesh::invariants::{certify_boundary_preserved, certify_same_topology, self_intersections};
use conemesh::mesh::generators;
use conemesh::{Topology, TriMesh, VertexId};
use nalgebra::Point3;
use proptest::prelude::*;
use proptest::test_runner::FileFailurePersistence;
use rand::seq::SliceRandom;
use rand::SeedableRng;

const CASES: u32 = 48;

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: CASES,
        failure_persistence: Some(Box::new(FileFailurePersistence::Direct(
            "proptests/regressions/mesh.txt",
        ))),
        ..Default::default()
    }
}

fn rng(seed: u64) -> conemesh::Rng {
    conemesh::Rng::seed_from_u64(seed)
}

/// Smallest triangle altitude of the mesh (twice the area over the longest edge).
fn min_altitude(m: &TriMesh) -> f64 {
    m.faces()
        .map(|f| {
            let p = m.face_points(f);
            let longest = [
                (p[1] - p[0]).norm(),
                (p[2] - p[1]).norm(),
                (p[0] - p[2]).norm(),
            ]
            .into_iter()
            .fold(0.0, f64::max);
            2.0 * m.face_area(f) / longest
        })
        .fold(f64::INFINITY, f64::min)
}

/// Apply a face permutation and a vertex relabelling (both seeded).
fn shuffled(m: &TriMesh, seed: u64) -> TriMesh {
    let mut r = rng(seed);
    let mut perm: Vec<usize> = (0..m.n_vertices()).collect();
    perm.shuffle(&mut r);
    let mut positions = vec![Point3::origin(); m.n_vertices()];
    for (old, &new) in perm.iter().enumerate() {
        positions[new] = m.positions[old];
    }
    let mut triangles: Vec<[VertexId; 3]> = m
        .triangles
        .iter()
        .map(|t| t.map(|v| VertexId::new(perm[v.idx()])))
        .collect();
    triangles.shuffle(&mut r);
    // Rotating the corners of a face keeps its orientation.
    for (k, t) in triangles.iter_mut().enumerate() {
        t.rotate_left(k % 3);
    }
    TriMesh::new(positions, triangles).expect("a relabelling of a valid mesh is valid")
}

/// The parts of a report that do not name elements.
fn counts(r: &CheckReport) -> CheckReport {
    CheckReport {
        non_manifold_edge_ids: vec![],
        non_manifold_vertex_ids: vec![],
        inconsistently_oriented_edge_ids: vec![],
        degenerate_face_ids: vec![],
        self_intersections: r.self_intersections.as_ref().map(|s| {
            conemesh::check::SelfIntersectionReport {
                pairs: s.pairs,
                first: vec![],
            }
        }),
        ..r.clone()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn euler_characteristic_is_two_minus_two_genus(g in 0usize..5, res in 1usize..3,
                                                   nu in 3usize..20, nv in 3usize..12,
                                                   sub in 0u32..3) {
        for (m, genus) in [
            (generators::genus_plate(g, res), g as i64),
            (generators::torus(2.0, 0.5, nu, nv), 1),
            (generators::icosphere(1.0, sub), 0),
        ] {
            let t = Topology::build(&m);
            prop_assert_eq!(t.euler_characteristic(), 2 - 2 * genus);
            prop_assert_eq!(t.components().len(), 1);
            prop_assert_eq!(t.components()[0].genus, Some(genus as u32));
            prop_assert!(t.boundary_loops().is_empty());
        }
    }

    /// Moving every vertex by less than a fifth of the smallest altitude (so no altitude can
    /// shrink to zero) keeps a convex or
    /// nearly convex closed surface valid (no fold, no self-intersection), with the same
    /// topology; boundary vertices that moved are caught by the boundary certificate.
    #[test]
    fn small_perturbations_stay_valid(seed in any::<u64>(), which in 0usize..3) {
        let m = match which {
            0 => generators::icosphere(1.0, 2),
            1 => generators::torus(1.0, 0.4, 24, 12),
            _ => generators::disk(1.0, 4, 12),
        };
        let p = generators::perturb(&m, 0.2 * min_altitude(&m), &mut rng(seed));
        let r = check_mesh(&p, &CheckOptions::default());
        prop_assert!(r.valid, "{}", r);
        prop_assert!(certify_same_topology(&m, &p).is_ok());
        prop_assert_eq!(certify_boundary_preserved(&m, &p).is_ok(), which != 2);
    }

    #[test]
    fn verdicts_are_invariant_under_relabelling(seed in any::<u64>(), which in 0usize..4) {
        let mut m = match which {
            0 => generators::genus_plate(2, 1),
            1 => generators::cylinder(1.0, 2.0, 12, 4),
            2 => generators::icosphere(1.0, 2),
            _ => generators::torus(1.0, 0.3, 16, 8),
        };
        if which == 2 {
            // Make it broken in several ways: a vertex pushed through the far side and a
            // flipped face.
            m.positions[0] = Point3::from(-m.positions[0].coords * 1.5);
            m.triangles[7].swap(1, 2);
        }
        let s = shuffled(&m, seed);
        let (a, b) = (check_mesh(&m, &CheckOptions::default()), check_mesh(&s, &CheckOptions::default()));
        prop_assert_eq!(counts(&a), counts(&b));
        prop_assert_eq!(self_intersections(&m).len(), self_intersections(&s).len());
        prop_assert!(certify_same_topology(&m, &s).is_ok());
        prop_assert!(certify_boundary_preserved(&m, &s).is_ok());
    }
}
