//! Properties of the mesh core and its certificates: Euler characteristic of the generated
//! surfaces, validity of small perturbations, and invariance of every topological verdict
//! under face permutation and vertex relabelling.
//!
//! Case counts are fixed (`CASES`) so the suite's time is stable.

#[path = "seed.rs"]
mod seed;
use conemesh::check::{check_mesh, CheckOptions, CheckReport};
use conemesh::invariants::{
    certify_boundary_preserved, certify_same_topology, faces_intersect, is_degenerate,
    self_intersections,
};
use conemesh::mesh::generators;
use conemesh::{Topology, TriMesh, VertexId};
use nalgebra::Point3;
use proptest::prelude::*;
use rand::seq::SliceRandom;
use rand::SeedableRng;

const CASES: u32 = 48;

fn config() -> ProptestConfig {
    seed::config(CASES, "mesh", 0x3e54)
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

    /// The BVH broad phase loses no pair: on a small, heavily crumpled sphere (many crossing,
    /// touching and folded faces) `self_intersections` equals the all-pairs brute force.
    #[test]
    fn self_intersections_equal_brute_force(seed in any::<u64>(), amp in 0.05..0.6f64) {
        let m = generators::perturb(&generators::icosphere(1.0, 1), amp, &mut rng(seed));
        let mut slow = Vec::new();
        for i in m.faces() {
            if is_degenerate(&m, i) {
                slow.push((i, i));
                continue;
            }
            for j in m.faces().filter(|&j| j > i && !is_degenerate(&m, j)) {
                if faces_intersect(&m, i, j) {
                    slow.push((i, j));
                }
            }
        }
        slow.sort_unstable();
        prop_assert_eq!(self_intersections(&m), slow);
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

/// The crumpled spheres of `self_intersections_equal_brute_force` do self-intersect (so the
/// comparison is not between two empty lists).
#[test]
fn crumpled_spheres_self_intersect() {
    let hits = (0..8u64)
        .filter(|&seed| {
            let m = generators::perturb(&generators::icosphere(1.0, 1), 0.6, &mut rng(seed));
            !self_intersections(&m).is_empty()
        })
        .count();
    assert!(hits >= 4, "{hits} of 8");
}

/// A generated surface broken the ways real files are: as a soup (every face with its own
/// vertices) with a random subset of faces reversed and the faces shuffled.
fn broken(kind: u8, seed: u64) -> (TriMesh, TriMesh) {
    let base = match kind % 4 {
        0 => generators::icosphere(1.0, 1),
        1 => generators::torus(1.0, 0.3, 10, 6),
        2 => generators::disk(1.0, 3, 8),
        _ => generators::genus_plate(2, 2),
    };
    let mut r = rng(seed);
    let mut soup = generators::triangle_soup(&base);
    soup.triangles.shuffle(&mut r);
    for t in &mut soup.triangles {
        if rand::Rng::random_bool(&mut r, 0.4) {
            t.swap(1, 2);
        }
    }
    (base, soup)
}

proptest! {
    #![proptest_config(config())]

    /// `repair` makes any such soup the surface it came from again: a certified oriented
    /// manifold with the same faces, vertices, components, genus and boundary loops, every
    /// output vertex at its source's position, and only reversed faces listed as flipped.
    #[test]
    fn repair_rebuilds_a_shuffled_soup(kind in 0u8..4, seed in any::<u64>()) {
        let (base, soup) = broken(kind, seed);
        let r = conemesh::repair::repair(&soup, &Default::default()).expect("repairs");
        let (t0, t1) = (Topology::build(&base), Topology::build(&r.mesh));
        prop_assert!(t1.is_oriented_manifold());
        prop_assert_eq!(r.mesh.n_faces(), base.n_faces());
        prop_assert_eq!(r.mesh.n_vertices(), base.n_vertices());
        prop_assert_eq!(t0.components(), t1.components());
        prop_assert!(r.log.split_vertices.is_empty() && r.log.cut_edges.is_empty());
        for v in r.mesh.vertices() {
            prop_assert_eq!(r.mesh.position(v), soup.position(r.source_vertex[v.idx()]));
        }
        prop_assert!(r.log.flipped_faces.len() * 2 <= soup.n_faces() + 1, "kept the majority");
    }
}
