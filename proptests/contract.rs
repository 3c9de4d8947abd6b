//! The contract of every registered implementation of every extension point
//! (`conemesh::contract`), on seeded random inputs: every patch strategy over covering runs
//! (partly processed meshes, corners, feature edges), every parameterizer on disks cut from
//! curved surfaces, every planar remesher on polygons in isotropic and anisotropic metrics,
//! every improver on remeshed surfaces; and every row's own contract (its name and its
//! documented defaults). A row added to a registry is checked here without a new test.

#[path = "seed.rs"]
mod seed;
use conemesh::contract::{self, ImproverCase, StrategyCase};
use conemesh::ids::{EdgeKey, FaceId};
use conemesh::improve::IMPROVERS;
use conemesh::mesh::{generators, Topology, TriMesh};
use conemesh::param::PARAMETERIZERS;
use conemesh::patches::{corner_vertices, extract_patch, STRATEGIES};
use conemesh::registry::Params;
use conemesh::remesh2d::{
    resample_polygon, triangulate_polygon, DemoDomain, DemoMetric, REMESHERS,
};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use std::collections::HashSet;

fn config(cases: u32) -> ProptestConfig {
    seed::config(cases, "contract", 0xc077ac7)
}

fn surface(kind: u8, seed: u64) -> TriMesh {
    let mut rng = conemesh::Rng::seed_from_u64(seed);
    match kind % 5 {
        0 => generators::torus(1.0, 0.35, 20, 9),
        1 => generators::genus_plate(1 + (seed % 2) as usize, 1),
        2 => generators::disk(1.0, 4, 6),
        3 => generators::perturb(&generators::icosphere(1.0, 2), 0.02, &mut rng),
        _ => generators::lens(0.9, 5, 12),
    }
}

/// Edges whose faces meet at a sharp angle (the lens's crease), as feature lines.
fn creases(mesh: &TriMesh) -> HashSet<EdgeKey> {
    let topo = Topology::build(mesh);
    conemesh::features::sharp_edges(mesh, &topo, 45.0)
        .into_iter()
        .collect()
}

/// Every row of every built-in table builds under its name, with its documented defaults,
/// for both kinds of sizes.
#[test]
fn every_row_keeps_its_own_contract() {
    fn check<T: ?Sized + conemesh::registry::Stage>(rows: &[conemesh::registry::Entry<T>]) {
        for row in rows {
            if let Err(e) = contract::registry_row(row) {
                panic!("{} `{}`: {e}", T::KIND, row.name);
            }
        }
    }
    check(STRATEGIES);
    check(PARAMETERIZERS);
    check(REMESHERS);
    check(IMPROVERS);
}

proptest! {
    #![proptest_config(config(3))]

    /// Every registered improver keeps its contract after Algorithm 1 on a torus, a plate
    /// with holes and a lens (certified, reproducible, reported under its name).
    #[test]
    fn every_improver_keeps_its_contract(kind in 0u8..3, seed in 0u64..1000) {
        let mesh = match kind {
            0 => generators::torus(1.0, 0.35, 24, 10),
            1 => generators::genus_plate(1, 1),
            _ => generators::lens(0.9, 5, 12),
        };
        let case = ImproverCase { mesh: &mesh, seed };
        for entry in IMPROVERS {
            let improver = conemesh::improve::improver(entry.name, Params::default())
                .expect("default options");
            let r = contract::improver(improver, &case);
            prop_assert!(r.is_ok(), "{}: {}", entry.name, r.unwrap_err());
        }
    }
}

proptest! {
    #![proptest_config(config(24))]

    /// Every registered strategy keeps its contract over a covering run, from an empty or a
    /// random partly processed start, with the surface's corners and creases to respect.
    #[test]
    fn every_strategy_keeps_its_contract(kind in 0u8..5, seed in 0u64..1000, partial in any::<bool>()) {
        let mesh = surface(kind, seed);
        let topo = Topology::build(&mesh);
        let corners = corner_vertices(&mesh, &topo, 0.3);
        let features = creases(&mesh);
        let mut rng = conemesh::Rng::seed_from_u64(seed);
        let processed: Vec<bool> = (0..mesh.n_faces())
            .map(|_| partial && rng.random_bool(0.3))
            .collect();
        for entry in STRATEGIES {
            let strategy = conemesh::patches::strategy(entry.name, Params::default())
                .expect("default options");
            let case = StrategyCase {
                mesh: &mesh,
                processed: processed.clone(),
                corners: Some(&corners),
                feature_edges: Some(&features),
                seed,
            };
            let n = contract::patch_strategy(strategy.as_ref(), &case);
            prop_assert!(n.is_ok(), "{}: {}", entry.name, n.unwrap_err());
        }
    }

    /// Every registered parameterizer maps disks cut out of curved surfaces bijectively,
    /// reproducibly, and refuses a mesh that is not a disk.
    #[test]
    fn every_parameterizer_keeps_its_contract(kind in 0u8..4, seed in 0u64..1000) {
        let mesh = match kind {
            0 => generators::torus(1.0, 0.4, 24, 12),
            1 => generators::icosphere(1.0, 3),
            2 => generators::lens(0.9, 6, 14),
            _ => generators::genus_plate(2, 2),
        };
        // A breadth-first disk of 40–160 faces around a random face.
        let mut rng = conemesh::Rng::seed_from_u64(seed);
        let topo = Topology::build(&mesh);
        let start = FaceId::new(rng.random_range(0..mesh.n_faces()));
        let target = rng.random_range(40..160);
        let processed = vec![false; mesh.n_faces()];
        let ctx = conemesh::patches::PatchContext {
            mesh: &mesh,
            topology: &topo,
            processed: &processed,
            feature_edges: None,
            corners: None,
            blocked: None,
        };
        let all: Vec<FaceId> = mesh.faces().collect();
        let faces = conemesh::patches::shrink_breadth_first(&ctx, &all, start, target);
        let disk = extract_patch(&mesh, &faces).expect("a disk");
        for entry in PARAMETERIZERS {
            let param = conemesh::param::parameterizer(entry.name, Params::default())
                .expect("default options");
            let r = contract::parameterizer(param.as_ref(), &disk.mesh, &disk.boundary);
            prop_assert!(r.is_ok(), "{}: {}", entry.name, r.unwrap_err());
        }
    }
}

proptest! {
    #![proptest_config(config(6))]

    /// Every registered planar remesher keeps its contract on the square and the L-shape in
    /// an isotropic, a constant anisotropic and a boundary-layer metric.
    #[test]
    fn every_planar_remesher_keeps_its_contract(case in 0usize..6, seed in 0u64..1000) {
        let (domain, metric) = conemesh::remesh2d::demo_cases()[case];
        let l = match (domain, metric) {
            (_, DemoMetric::ConstantAnisotropic) => 0.2,
            (DemoDomain::LShape, _) => 0.15,
            _ => 0.12,
        };
        let boundary = resample_polygon(&domain.corners(), &metric, l);
        let dom = triangulate_polygon(&boundary, &[]).expect("a triangulated polygon");
        for entry in REMESHERS {
            let remesher = conemesh::remesh2d::planar_remesher(entry.name, Params::default())
                .expect("default options");
            let r = contract::planar_remesher(remesher.as_ref(), &dom, &metric, l, seed);
            prop_assert!(r.is_ok(), "{}: {}", entry.name, r.unwrap_err());
        }
    }
}

proptest! {
    #![proptest_config(config(6))]

    /// Algorithm 2's planar updates (not a registry row: they keep the patch's vertices) keep
    /// the planar remesher's contract on the demo domains with random interior vertices, for
    /// both flip rules.
    #[test]
    fn the_planar_updates_of_algorithm_2_keep_the_contract(case in 0usize..6, seed in 0u64..1000) {
        use conemesh::improve::{Eq5Updates, Eq5Options, FlipRule};
        let (domain, metric) = conemesh::remesh2d::demo_cases()[case];
        let boundary = resample_polygon(&domain.corners(), &metric, 0.15);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let inside: Vec<nalgebra::Point2<f64>> = (0..40)
            .map(|_| nalgebra::Point2::new(rng.random_range(0.0..1.0), rng.random_range(0.0..1.0)))
            .collect();
        let dom = triangulate_polygon(&boundary, &inside).expect("a triangulated polygon");
        for flip_rule in [FlipRule::Energy, FlipRule::MaxMin] {
            let improver = Eq5Updates {
                options: Eq5Options { flip_rule, ..Eq5Options::default() },
            };
            let r = contract::planar_remesher(&improver, &dom, &metric, 0.15, seed);
            prop_assert!(r.is_ok(), "{flip_rule:?}: {}", r.unwrap_err());
        }
    }
}
