//! Property tests of patch generation (Sec. 3.2): the exact disk rule, certified covering runs.

#[path = "seed.rs"]
mod seed;
use conemesh::ids::FaceId;
use conemesh::invariants::certify_disk;
use conemesh::mesh::{generators, Topology, TriMesh};
use conemesh::patches::{
    cover, ConePatches, CoverOptions, DiskPatch, KRingDisks, PatchContext, PatchStrategy,
};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};

fn config(cases: u32) -> ProptestConfig {
    seed::config(cases, "patches", 0x9a7c4)
}

fn surface(kind: u8, seed: u64) -> TriMesh {
    let mut rng = conemesh::Rng::seed_from_u64(seed);
    match kind % 5 {
        0 => generators::torus(1.0, 0.35, 24, 10),
        1 => generators::genus_plate(1 + (seed % 3) as usize, 1),
        2 => generators::disk(1.0, 5, 6),
        3 => generators::perturb(&generators::torus(1.0, 0.4, 20, 10), 0.03, &mut rng),
        _ => generators::perturb(&generators::icosphere(1.0, 2), 0.02, &mut rng),
    }
}

proptest! {
    #![proptest_config(config(48))]

    /// The exact disk rule accepts a face sharing an edge with a disk iff the union is a
    /// certified disk.
    #[test]
    fn disk_rule_agrees_with_certificate(kind in 0u8..5, seed in 0u64..1000) {
        let m = surface(kind, seed);
        let topo = Topology::build(&m);
        let processed = vec![false; m.n_faces()];
        let ctx = PatchContext { mesh: &m, topology: &topo, processed: &processed, feature_edges: None, corners: None, blocked: None };
        let mut rng = conemesh::Rng::seed_from_u64(seed);
        let start = FaceId::new(rng.random_range(0..m.n_faces()));
        let mut disk = DiskPatch::new(&ctx, start);
        for _ in 0..(2 * m.n_faces()) {
            let cands = disk.adjacent_faces(|_| true);
            if cands.is_empty() {
                break;
            }
            let t = cands[rng.random_range(0..cands.len())];
            let mut union = disk.sorted_faces();
            union.push(t);
            let certified = certify_disk(&m, &union);
            let rule = disk.check_add(t);
            prop_assert_eq!(rule.is_ok(), certified.is_ok(), "face {}: rule {:?}, certificate {:?}", t, rule, certified);
            if rule.is_ok() {
                disk.try_add(t).expect("checked");
            }
        }
    }

    /// A batch's later patches: with the faces around an earlier patch blocked, both built-in
    /// strategies return a certified disk with no blocked face (so a vertex apart from the
    /// earlier patch), or nothing.
    #[test]
    fn strategies_keep_off_blocked_faces(kind in 0u8..5, seed in 0u64..1000, kring in any::<bool>()) {
        let m = surface(kind, seed);
        let topo = Topology::build(&m);
        let cone = ConePatches::default();
        let kr = KRingDisks::default();
        let s: &dyn PatchStrategy = if kring { &kr } else { &cone };
        let mut rng = conemesh::Rng::seed_from_u64(seed);
        // Some faces processed, as in the middle of a run.
        let processed: Vec<bool> = (0..m.n_faces()).map(|_| rng.random_bool(0.3)).collect();
        let free = PatchContext { mesh: &m, topology: &topo, processed: &processed, feature_edges: None, corners: None, blocked: None };
        let Some(first) = s.next_patch(&free, &mut rng).expect("a patch") else { return Ok(()) };
        let mut blocked = vec![false; m.n_faces()];
        for f in &first.faces {
            for v in m.face(*f) {
                for g in topo.vertex_faces(v) {
                    blocked[g.idx()] = true;
                }
            }
        }
        let ctx = PatchContext { blocked: Some(&blocked), ..free };
        if let Some(second) = s.next_patch(&ctx, &mut rng).expect("a patch or none") {
            prop_assert!(certify_disk(&m, &second.faces).is_ok());
            prop_assert!(second.faces.iter().all(|f| !blocked[f.idx()]), "a blocked face in the second patch");
            let first_vertices: std::collections::HashSet<_> = first.faces.iter().flat_map(|f| m.face(*f)).collect();
            prop_assert!(second.faces.iter().flat_map(|f| m.face(*f)).all(|v| !first_vertices.contains(&v)), "a shared vertex");
        }
    }

    /// Covering runs: every patch a certified disk, every face covered, growth costs below
    /// C_max, and the same seed gives the same patches.
    #[test]
    fn cover_runs_are_certified_complete_and_reproducible(kind in 0u8..5, seed in 0u64..1000, kring in any::<bool>()) {
        let m = surface(kind, seed);
        let cone = ConePatches::default();
        let kr = KRingDisks::default();
        let s: &dyn PatchStrategy = if kring { &kr } else { &cone };
        let run = |seed| {
            let mut rng = conemesh::Rng::seed_from_u64(seed);
            cover(&m, s, &CoverOptions::default(), &mut rng).expect("cover")
        };
        let a = run(seed);
        prop_assert!(a.complete);
        let mut covered = vec![false; m.n_faces()];
        for p in &a.patches {
            let b = certify_disk(&m, &p.faces);
            prop_assert!(b.is_ok(), "{:?}", b);
            for f in &p.faces { covered[f.idx()] = true; }
            if let Some(c) = p.max_growth_cost { prop_assert!(c < 0.1); }
        }
        prop_assert!(covered.iter().all(|&c| c));
        prop_assert!(a
            .patch_of_face
            .iter()
            .all(|p| p.is_some_and(|p| p.idx() < a.patches.len())));
        let b = run(seed);
        prop_assert_eq!(a, b);
    }

    /// With random vertices marked as corners, no patch of a covering run (cone or k-ring)
    /// contains a corner in its interior, and the run still covers every face.
    #[test]
    fn cover_runs_keep_corners_on_patch_boundaries(kind in 0u8..5, seed in 0u64..1000, kring in any::<bool>()) {
        let m = surface(kind, seed);
        let topo = Topology::build(&m);
        let mut rng = conemesh::Rng::seed_from_u64(seed);
        let corners: Vec<bool> = (0..m.n_vertices()).map(|_| rng.random_bool(0.2)).collect();
        let cone = ConePatches::default();
        let kr = KRingDisks::default();
        let s: &dyn PatchStrategy = if kring { &kr } else { &cone };
        let opts = CoverOptions { corners: Some(corners.clone()), ..Default::default() };
        let run = cover(&m, s, &opts, &mut rng).expect("cover");
        prop_assert!(run.complete);
        for p in &run.patches {
            let mut count = std::collections::HashMap::new();
            for f in &p.faces {
                for v in m.face(*f) {
                    *count.entry(v).or_insert(0usize) += 1;
                }
            }
            for (v, n) in count {
                let interior = !topo.is_boundary_vertex(v) && n == topo.vertex_faces(v).len();
                prop_assert!(!(corners[v.idx()] && interior), "corner {} inside a patch", v);
            }
        }
    }
}
