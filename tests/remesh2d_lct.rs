//! Integration tests of the planar LCT remesher (Sec. 3.3): constraints, the transferred
//! metric field, determinism, and refusals of bad input.

use conemesh::invariants::{certify_planar, InvariantError, PlanarDefect};
use conemesh::remesh2d::{
    planar_quality, resample_polygon, triangulate_polygon, Lct, Metric2d, PlanarDomain,
    PlanarMetricField, PlanarRemesher, Remesh2dError,
};
use nalgebra::{Matrix2, Point2};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

struct Iso;
impl Metric2d for Iso {
    fn metric(&self, _: &Point2<f64>) -> Matrix2<f64> {
        Matrix2::identity()
    }
}

struct Shear;
impl Metric2d for Shear {
    fn metric(&self, p: &Point2<f64>) -> Matrix2<f64> {
        let th = 0.8 * p.x;
        let r = Matrix2::new(th.cos(), -th.sin(), th.sin(), th.cos());
        r * Matrix2::new(1.0, 0.0, 0.0, 9.0 + 20.0 * p.y * p.y) * r.transpose()
    }
}

fn square_domain(metric: &dyn Metric2d, l: f64) -> Result<PlanarDomain, Remesh2dError> {
    let c = [
        Point2::new(0.0, 0.0),
        Point2::new(1.0, 0.0),
        Point2::new(1.0, 1.0),
        Point2::new(0.0, 1.0),
    ];
    triangulate_polygon(&resample_polygon(&c, metric, l), &[])
}

#[test]
fn constrained_edges_and_their_vertices_are_kept() -> Result<(), Remesh2dError> {
    // A square whose diagonal is a constrained chord through one interior vertex.
    let pts = vec![
        Point2::new(0.0, 0.0),
        Point2::new(1.0, 0.0),
        Point2::new(1.0, 1.0),
        Point2::new(0.0, 1.0),
        Point2::new(0.5, 0.5),
    ];
    let dom = PlanarDomain {
        points: pts,
        triangles: vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]],
        boundary: vec![0, 1, 2, 3],
        constrained_edges: vec![[0, 4], [4, 2]],
    };
    let out = Lct::default().remesh(&dom, &Iso, 0.3, &mut ChaCha8Rng::seed_from_u64(1))?;
    certify_planar(&dom, &out)?;
    assert!(out.origin.contains(&Some(4)), "constrained vertex v4 kept");
    // The boundary edges are fixed and long (metric length 1/0.3): no new vertex on them, but
    // the interior got refined.
    assert!(out.points.len() > 5);
    Ok(())
}

#[test]
fn remeshes_under_a_transferred_field_and_every_vertex_is_locatable() -> Result<(), Remesh2dError> {
    let l = 0.4;
    // The boundary resampled to the target metric length (the patch boundary of the pipeline
    // comes from earlier remeshing, so it has about that length too).
    let dom = square_domain(&Shear, l)?;
    // The field: the analytic metric sampled at the initial mesh's vertices.
    let metrics = dom.points.iter().map(|p| Shear.metric(p)).collect();
    let field = PlanarMetricField::new(dom.points.clone(), dom.triangles.clone(), metrics)?;
    let out = Lct::default().remesh(&dom, &field, l, &mut ChaCha8Rng::seed_from_u64(3))?;
    certify_planar(&dom, &out)?;
    for (i, p) in out.points.iter().enumerate() {
        assert!(field.locate(p).is_some(), "v{i} at {p} not located");
    }
    let q = planar_quality(&out, &field, l);
    assert!(q.q_avg > 0.85, "{q:?}");
    Ok(())
}

#[test]
fn same_seed_same_output() -> Result<(), Remesh2dError> {
    let dom = square_domain(&Iso, 0.1)?;
    let a = Lct::default().remesh(&dom, &Shear, 0.5, &mut ChaCha8Rng::seed_from_u64(5))?;
    let b = Lct::default().remesh(&dom, &Shear, 0.5, &mut ChaCha8Rng::seed_from_u64(5))?;
    assert_eq!(a, b);
    Ok(())
}

#[test]
fn refuses_bad_input() -> Result<(), Remesh2dError> {
    let mut dom = square_domain(&Iso, 0.25)?;
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let r = Lct::default().remesh(&dom, &Iso, 0.0, &mut rng);
    assert!(matches!(r, Err(Remesh2dError::BadTargetLength(l)) if l == 0.0));
    struct Bad;
    impl Metric2d for Bad {
        fn metric(&self, _: &Point2<f64>) -> Matrix2<f64> {
            -Matrix2::identity()
        }
    }
    let r = Lct::default().remesh(&dom, &Bad, 0.2, &mut rng);
    assert!(matches!(r, Err(Remesh2dError::MetricNotSpd { .. })));
    dom.triangles[0].swap(0, 1);
    let r = Lct::default().remesh(&dom, &Iso, 0.2, &mut rng);
    assert!(
        matches!(
            &r,
            Err(Remesh2dError::InvalidDomain(InvariantError::PlanarInvalid(
                PlanarDefect::NonPositive(faces)
            ))) if faces.0.contains(&conemesh::FaceId(0))
        ),
        "{r:?}"
    );
    Ok(())
}

/// The patch boundary of the pipeline is whatever the input mesh has: much finer or much
/// coarser than L, and metrics far from isotropic. The result must stay certified.
#[test]
fn mismatched_boundaries_and_extreme_anisotropy_stay_certified() -> Result<(), Remesh2dError> {
    struct Needle;
    impl Metric2d for Needle {
        fn metric(&self, _: &Point2<f64>) -> Matrix2<f64> {
            let th: f64 = 0.3;
            let r = Matrix2::new(th.cos(), -th.sin(), th.sin(), th.cos());
            r * Matrix2::new(1.0, 0.0, 0.0, 1e4) * r.transpose()
        }
    }
    let cases: [(f64, &dyn Metric2d, f64); 4] = [
        (0.02, &Iso, 0.3),   // boundary 15× finer than L
        (0.5, &Iso, 0.05),   // boundary 10× coarser than L
        (0.1, &Needle, 1.0), // anisotropy 100 in lengths, boundary not adapted
        (0.25, &Shear, 0.3),
    ];
    for (i, (spacing, metric, l)) in cases.into_iter().enumerate() {
        let dom = square_domain(&Iso, spacing)?;
        let out =
            Lct::default().remesh(&dom, metric, l, &mut ChaCha8Rng::seed_from_u64(i as u64))?;
        certify_planar(&dom, &out)?;
        let kept = out.origin.iter().filter(|o| o.is_some()).count();
        assert!(kept >= dom.boundary.len(), "case {i}");
    }
    Ok(())
}

/// Smallest inputs: one triangle (nothing to do), a quad with one interior chord.
#[test]
fn tiny_domains() -> Result<(), Remesh2dError> {
    let tri = PlanarDomain {
        points: vec![
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(0.0, 1.0),
        ],
        triangles: vec![[0, 1, 2]],
        boundary: vec![0, 1, 2],
        constrained_edges: vec![],
    };
    let out = Lct::default().remesh(&tri, &Iso, 0.1, &mut ChaCha8Rng::seed_from_u64(0))?;
    assert_eq!(out.triangles.len(), 1);
    let quad = PlanarDomain {
        points: vec![
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(1.0, 1.0),
            Point2::new(0.0, 1.0),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        boundary: vec![0, 1, 2, 3],
        constrained_edges: vec![],
    };
    for l in [0.05, 1.0, 10.0] {
        let out = Lct::default().remesh(&quad, &Iso, l, &mut ChaCha8Rng::seed_from_u64(0))?;
        certify_planar(&quad, &out)?;
    }
    Ok(())
}

/// The rectangle `[0, w] × [0, h]`, its boundary resampled to `l`, with the nodes of a regular
/// `nx × ny` grid inside (in row order, as a generated or scanned grid comes).
fn grid_domain(
    w: f64,
    h: f64,
    nx: usize,
    ny: usize,
    l: f64,
) -> Result<PlanarDomain, Remesh2dError> {
    let c = [
        Point2::new(0.0, 0.0),
        Point2::new(w, 0.0),
        Point2::new(w, h),
        Point2::new(0.0, h),
    ];
    let mut inside = Vec::new();
    for j in 1..ny {
        for i in 1..nx {
            inside.push(Point2::new(
                w * i as f64 / nx as f64,
                h * j as f64 / ny as f64,
            ));
        }
    }
    triangulate_polygon(&resample_polygon(&c, &Iso, l), &inside)
}

#[test]
fn a_grid_that_is_anisotropic_in_the_metric_leaves_no_lattice_behind() -> Result<(), Remesh2dError>
{
    // The isotropic cylinder of the analytic suite, unrolled: cells 0.49 × 0.31 L. Keeping
    // the grid's vertices 0.8 L apart in id order leaves a regular sub-lattice of right
    // triangles, which split, collapse, flips and smoothing cannot leave (measured: q_avg
    // 0.857 and 3,844 faces for an ideal 2,956); a seeded random order gives a disordered start
    // that relaxes (0.931, 2,986 faces).
    let dom = grid_domain(6.4, 2.0, 128, 64, 0.1)?;
    let lct = Lct {
        options: conemesh::remesh2d::LctOptions::for_absolute_sizes(),
    };
    let out = lct.remesh(&dom, &Iso, 0.1, &mut ChaCha8Rng::seed_from_u64(1))?;
    certify_planar(&dom, &out)?;
    let q = planar_quality(&out, &Iso, 0.1);
    assert!(q.q_avg >= 0.92, "q_avg {:.3}", q.q_avg);
    // An ideal mesh of the rectangle has area / (√3/4 · L²) faces.
    let ideal = 6.4 * 2.0 / (3f64.sqrt() / 4.0 * 0.01);
    let off = (q.n_faces as f64 - ideal).abs() / ideal;
    assert!(off <= 0.05, "{} faces for an ideal {ideal:.0}", q.n_faces);
    Ok(())
}

/// A metric many orders too fine for its domain is refused by name before any refinement:
/// against LCT's own cap, and against the caller's in `remesh_bounded` (the pipeline's patch
/// face cap). The split passes' own limit, for a metric whose area is small but one direction
/// far too fine, is covered end to end by `an_input_with_one_vertex_at_1e19_to_1e55_ends_certified`
/// in `tests/pipeline_regressions.rs`.
#[test]
fn a_metric_too_fine_for_its_domain_is_refused_not_refined_out_of_memory(
) -> Result<(), Remesh2dError> {
    struct Scaled(f64);
    impl Metric2d for Scaled {
        fn metric(&self, _: &Point2<f64>) -> Matrix2<f64> {
            Matrix2::identity() * self.0
        }
    }
    let dom = square_domain(&Iso, 0.25)?;
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let unit = 3f64.sqrt() / 4.0 * 0.0625;
    let ideal = conemesh::remesh2d::ideal_faces(&dom, &Iso, 0.25);
    assert!((ideal - 1.0 / unit).abs() < 1e-9, "{ideal}");
    // Area: 1e20 unit squares.
    match Lct::default().remesh(&dom, &Scaled(1e20), 0.25, &mut rng) {
        Err(Remesh2dError::TooDense { faces, max }) => {
            assert!((faces - 1e20 / unit).abs() < 1e6, "{faces}");
            assert_eq!(max, conemesh::remesh2d::MAX_LCT_FACES);
        }
        other => panic!("expected TooDense, got {other:?}"),
    }
    // 100 times the area: an ideal mesh has 1/unit·100 ≈ 3,695 faces, over a cap of 2,000.
    match Lct::default().remesh_bounded(&dom, &Scaled(100.0), 0.25, 2000.0, &mut rng) {
        Err(Remesh2dError::TooDense { faces, max }) => {
            assert!(
                (faces - 100.0 / unit).abs() < 1e-6 && max == 2000.0,
                "{faces} {max}"
            );
        }
        other => panic!("expected TooDense, got {other:?}"),
    }
    // Under the cap, a bounded remesh is the plain one.
    let a = Lct::default().remesh(&dom, &Iso, 0.25, &mut ChaCha8Rng::seed_from_u64(3))?;
    let b =
        Lct::default().remesh_bounded(&dom, &Iso, 0.25, 1e4, &mut ChaCha8Rng::seed_from_u64(3))?;
    assert_eq!(a.points, b.points);
    assert_eq!(a.triangles, b.triangles);
    Ok(())
}
