//! Symmetric Dirichlet parameterizer: developable patches become isometric, the energy never
//! increases, every iterate is certified, and the certificate catches bad maps by name.

use conemesh::invariants::{certify_bijective, DiskDefect, InvariantError, MapDefect};
use conemesh::mesh::generators;
use conemesh::param::{
    disk_boundary, optimize_with_log, ParamError, Parameterizer, SdOptions, SymmetricDirichlet,
    Tutte, TutteWeights,
};
use conemesh::{TriMesh, VertexId};
use nalgebra::{Point2, Point3};

fn developable() -> Vec<(&'static str, TriMesh)> {
    vec![
        (
            "cylinder_piece",
            generators::cylinder_piece(1.0, 2.5, 1.5, 24, 10),
        ),
        (
            "cone_piece",
            generators::cone_piece(0.6, 2.5, 0.4, 2.0, 20, 10),
        ),
        (
            "narrow_cone_piece",
            generators::cone_piece(0.25, 5.0, 0.5, 1.5, 30, 6),
        ),
    ]
}

#[test]
fn developable_patches_become_isometric() {
    for (name, m) in developable() {
        let b = disk_boundary(&m).unwrap();
        let p = SymmetricDirichlet::default().parameterize(&m, &b).unwrap();
        certify_bijective(&p.uv, &m.triangles, &b).unwrap();
        let r = &p.report;
        assert!(r.max_conformal <= 1.01, "{name}: {r:?}");
        assert!(r.max_area_distortion <= 0.02, "{name}: {r:?}");
        assert!(!r.fell_back && !r.hit_budget, "{name}: {r:?}");
    }
}

#[test]
fn energy_never_increases_and_every_iterate_is_positive() {
    let mut rng = <conemesh::Rng as rand::SeedableRng>::seed_from_u64(7);
    let m = generators::perturb(&generators::icosphere(1.0, 3), 0.0, &mut rng);
    // A strongly curved cap: faces of the sphere with all corners above z = −0.3.
    let keep: Vec<[usize; 3]> = m
        .triangles
        .iter()
        .filter(|t| t.iter().all(|v| m.position(*v).z > -0.3))
        .map(|t| [t[0].idx(), t[1].idx(), t[2].idx()])
        .collect();
    let cap = TriMesh::from_indices(m.positions.clone(), &keep)
        .unwrap()
        .without_unreferenced_vertices()
        .0;
    let b = disk_boundary(&cap).unwrap();
    let p0 = Tutte {
        weights: TutteWeights::MeanValue,
    }
    .parameterize(&cap, &b)
    .unwrap();
    let (uv, log) = optimize_with_log(&cap, &b, &p0.uv, &SdOptions::default()).unwrap();
    certify_bijective(&uv, &cap.triangles, &b).unwrap();
    assert!(log.iterations >= 2, "{log:?}");
    for w in log.energies.windows(2) {
        assert!(w[1] <= w[0], "energy increased: {:?}", log.energies);
    }
    assert!(log.min_double_area.iter().all(|&a| a > 0.0));
    assert!(log.energies.last().unwrap() < &log.energies[0]);
}

#[test]
fn non_disks_are_rejected_by_name() {
    let m = generators::cylinder(1.0, 1.0, 12, 3);
    let b: Vec<VertexId> = (0..12).map(VertexId).collect();
    let e = SymmetricDirichlet::default()
        .parameterize(&m, &b)
        .unwrap_err();
    assert!(
        matches!(
            e,
            ParamError::Input(InvariantError::NotADisk(DiskDefect::EulerCharacteristic {
                chi: 0,
                ..
            }))
        ),
        "{e}"
    );
    let d = generators::disk(1.0, 3, 6);
    let mut wrong = disk_boundary(&d).unwrap();
    wrong.reverse();
    let e = SymmetricDirichlet::default()
        .parameterize(&d, &wrong)
        .unwrap_err();
    assert!(
        matches!(
            e,
            ParamError::Input(InvariantError::NotADisk(DiskDefect::BoundaryMismatch {
                given: 18,
                actual: 18,
                ..
            }))
        ),
        "{e}"
    );
}

/// A strip of triangles whose uv image winds around like a spiral so that its boundary
/// overlaps itself while every triangle stays positive.
fn spiral_strip(turns: f64, n: usize) -> (Vec<Point2<f64>>, Vec<[VertexId; 3]>, Vec<VertexId>) {
    // Inner vertices i (0..=n) and outer vertices n+1+i along a spiral of angle θ_i.
    let mut uv = Vec::new();
    let theta = |i: usize| 2.0 * std::f64::consts::PI * turns * i as f64 / n as f64;
    for i in 0..=n {
        let r = 1.0 + 0.05 * theta(i);
        uv.push(Point2::new(r * theta(i).cos(), r * theta(i).sin()));
    }
    for i in 0..=n {
        let r = 1.5 + 0.05 * theta(i);
        uv.push(Point2::new(r * theta(i).cos(), r * theta(i).sin()));
    }
    let o = n + 1;
    let mut tris = Vec::new();
    for i in 0..n {
        // (inner i, outer i, outer i+1) and (inner i, outer i+1, inner i+1), counter-clockwise.
        tris.push([
            VertexId::new(i),
            VertexId::new(o + i),
            VertexId::new(o + i + 1),
        ]);
        tris.push([
            VertexId::new(i),
            VertexId::new(o + i + 1),
            VertexId::new(i + 1),
        ]);
    }
    // Boundary (surface on the left): outer side forwards, inner side backwards.
    let mut b: Vec<VertexId> = (0..=n).map(|i| VertexId::new(o + i)).collect();
    b.extend((0..=n).rev().map(VertexId::new));
    // Fix orientation: with this construction the region lies to the left of the outer side
    // walked backwards; build the loop from the triangles' boundary half-edges instead.
    let mesh = TriMesh {
        positions: uv.iter().map(|p| Point3::new(p.x, p.y, 0.0)).collect(),
        triangles: tris.clone(),
    };
    let b = disk_boundary(&mesh).unwrap_or(b);
    (uv, tris, b)
}

#[test]
fn certificate_names_flipped_triangles_and_self_overlapping_boundaries() {
    // Less than one turn: bijective.
    let (uv, t, b) = spiral_strip(0.8, 40);
    assert!(
        t.iter().all(|t| (uv[t[1].idx()] - uv[t[0].idx()])
            .perp(&(uv[t[2].idx()] - uv[t[0].idx()]))
            > 0.0),
        "test construction: all triangles positive"
    );
    certify_bijective(&uv, &t, &b).unwrap();
    // More than one turn: all triangles positive, but the strip overlaps itself.
    let (uv, t, b) = spiral_strip(1.6, 80);
    let e = certify_bijective(&uv, &t, &b).unwrap_err();
    assert!(
        matches!(&e, InvariantError::NotBijective(MapDefect::NotSimple(pairs)) if !pairs.0.is_empty()),
        "names the edge pairs: {e}"
    );
    // A flipped triangle in an otherwise good map is named.
    let (mut uv, t, b) = spiral_strip(0.8, 40);
    let c = uv[10];
    uv[10] = uv[51] + (uv[51] - c) * 0.5; // push an inner vertex across the outer side
    let e = certify_bijective(&uv, &t, &b).unwrap_err();
    let InvariantError::NotBijective(MapDefect::NonPositive(faces)) = &e else {
        panic!("{e}");
    };
    assert!(faces.0.iter().any(|f| (18..=20).contains(&f.0)), "{e}");
}

#[test]
fn running_out_of_budget_is_reported_not_an_error() {
    let m = generators::cone_piece(0.6, 2.5, 0.4, 2.0, 20, 10);
    let b = disk_boundary(&m).unwrap();
    // From the Tutte map (the LSCM of this developable piece is already an isometry up to
    // scale, so one iteration would not exhaust the budget).
    let tight = SymmetricDirichlet {
        options: SdOptions {
            max_iters: 1,
            free_boundary_init: false,
            ..Default::default()
        },
    };
    let p = tight.parameterize(&m, &b).unwrap();
    certify_bijective(&p.uv, &m.triangles, &b).unwrap();
    assert_eq!(p.report.iterations, 1);
    assert!(p.report.hit_budget && !p.report.fell_back, "{:?}", p.report);
    let full = SymmetricDirichlet {
        options: SdOptions {
            free_boundary_init: false,
            ..Default::default()
        },
    }
    .parameterize(&m, &b)
    .unwrap();
    assert!(!full.report.hit_budget);
    assert!(full.report.symmetric_dirichlet < p.report.symmetric_dirichlet);
}

#[test]
fn tiny_disks_without_interior_vertices() {
    let tri = TriMesh::from_indices(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(3.0, 0.0, 1.0),
            Point3::new(0.0, 0.2, 0.0),
        ],
        &[[0, 1, 2]],
    )
    .unwrap();
    let quad = TriMesh::from_indices(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.5),
            Point3::new(0.0, 1.0, 0.0),
        ],
        &[[0, 1, 2], [0, 2, 3]],
    )
    .unwrap();
    for m in [tri, quad] {
        let b = disk_boundary(&m).unwrap();
        let p = SymmetricDirichlet::default().parameterize(&m, &b).unwrap();
        certify_bijective(&p.uv, &m.triangles, &b).unwrap();
        // No interior vertex: the free boundary lets every triangle become isometric.
        assert!(p.report.max_conformal < 1.001, "{:?}", p.report);
    }
}
