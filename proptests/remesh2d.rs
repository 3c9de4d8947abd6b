//! Property tests of the planar LCT remesher (Sec. 3.3): random convex and star-shaped
//! polygons, random constant and varying SPD metrics → the planar certificate holds, every
//! output vertex lies in the input domain, and on constant anisotropic metrics over convex
//! polygons the mesh is good (q_avg ≥ 0.9, ≥ 90 % of edges within [L/√2, √2·L]).

#[path = "seed.rs"]
mod seed;
use conemesh::invariants::certify_planar;
use conemesh::remesh2d::{
    planar_quality, resample_polygon, triangulate_polygon, Lct, Metric2d, PlanarMetricField,
    PlanarRemesher,
};
use nalgebra::{Matrix2, Point2};
use proptest::prelude::*;
use rand::SeedableRng;
use std::f64::consts::PI;

#[derive(Clone, Debug)]
enum TestMetric {
    /// `R(θ) diag(1, a) R(θ)ᵀ`.
    Constant { theta: f64, a: f64 },
    /// Direction turning with x, anisotropy growing with y.
    Varying { theta: f64, a: f64, k: f64 },
}

impl Metric2d for TestMetric {
    fn metric(&self, p: &Point2<f64>) -> Matrix2<f64> {
        let (th, a) = match *self {
            TestMetric::Constant { theta, a } => (theta, a),
            TestMetric::Varying { theta, a, k } => (
                theta + k * p.x,
                1.0 + (a - 1.0) * (0.5 + 0.5 * p.y).clamp(0.0, 1.0),
            ),
        };
        let r = Matrix2::new(th.cos(), -th.sin(), th.sin(), th.cos());
        r * Matrix2::new(1.0, 0.0, 0.0, a) * r.transpose()
    }
}

/// A polygon around the origin with `jitter.len()` vertices at angles `2πi/n` jittered by up
/// to ±0.35 of the spacing, radius 1 (convex, inscribed in the unit circle) or random in
/// [0.35, 1] (star-shaped, generally non-convex).
fn polygon(jitter: &[f64], radii: &[f64], convex: bool) -> Vec<Point2<f64>> {
    let n = jitter.len();
    jitter
        .iter()
        .zip(radii)
        .enumerate()
        .map(|(i, (j, r))| {
            let t = 2.0 * PI * (i as f64 + 0.35 * j) / n as f64;
            let r = if convex { 1.0 } else { *r };
            Point2::new(r * t.cos(), r * t.sin())
        })
        .collect()
}

fn metric_strategy() -> impl Strategy<Value = TestMetric> {
    prop_oneof![
        (0.0..PI, 1.0..60.0f64).prop_map(|(theta, a)| TestMetric::Constant { theta, a }),
        (0.0..PI, 1.0..30.0f64, -1.5..1.5f64).prop_map(|(theta, a, k)| TestMetric::Varying {
            theta,
            a,
            k
        }),
    ]
}

proptest! {
    // A fixed seed: the quality thresholds are properties of these 24 inputs, not flaky draws.
    #![proptest_config(seed::config(24, "remesh2d", 0x5eed2d))]

    #[test]
    fn lct_output_is_certified_and_inside(
        jitter in prop::collection::vec(-1.0..1.0f64, 5..12),
        radii in prop::collection::vec(0.35..1.0f64, 12),
        convex in any::<bool>(),
        constrain in any::<bool>(),
        metric in metric_strategy(),
        seed in any::<u64>(),
    ) {
        let poly = polygon(&jitter, &radii, convex);
        // About 500-800 output triangles: L from the metric area of the unit disk.
        let m0 = metric.metric(&Point2::origin());
        let l = (PI * m0.determinant().sqrt() / (0.433 * 700.0)).sqrt();
        let boundary = resample_polygon(&poly, &metric, l);
        let dom = triangulate_polygon(&boundary, &[]);
        prop_assume!(dom.is_ok());
        let mut dom = dom.map_err(|e| TestCaseError::fail(e.to_string()))?;
        if constrain {
            // Constrain the first interior edge (a chord or an edge to an interior vertex).
            let nb = dom.boundary.len() as u32;
            let chord = dom.triangles.iter().flat_map(|t| (0..3).map(move |k| [t[k], t[(k + 1) % 3]]))
                .find(|[a, b]| !((a + 1) % nb == *b || (b + 1) % nb == *a));
            if let Some(e) = chord {
                dom.constrained_edges.push(e);
            }
        }
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let out = Lct::default()
            .remesh(&dom, &metric, l, &mut rng)
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        certify_planar(&dom, &out).map_err(|e| TestCaseError::fail(e.to_string()))?;
        // Every output vertex is locatable in the input domain.
        let field = PlanarMetricField::new(
            dom.points.clone(),
            dom.triangles.clone(),
            vec![Matrix2::identity(); dom.points.len()],
        )
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
        for (i, p) in out.points.iter().enumerate() {
            prop_assert!(field.locate(p).is_some(), "v{} at {} not located", i, p);
        }
        let q = planar_quality(&out, &metric, l);
        // A constrained chord is a fixed long edge: quality is only promised without one.
        if convex && !constrain && matches!(metric, TestMetric::Constant { .. }) {
            prop_assert!(q.q_avg >= 0.9, "{:?}", q);
            prop_assert!(q.edges_in_range >= 0.9, "{:?}", q);
        }
    }

    #[test]
    fn lct_quality_on_constant_anisotropic_convex(
        jitter in prop::collection::vec(-1.0..1.0f64, 5..12),
        theta in 0.0..PI,
        a in 1.0..60.0f64,
        seed in any::<u64>(),
    ) {
        let poly = polygon(&jitter, &[1.0; 12], true);
        let metric = TestMetric::Constant { theta, a };
        let l = (PI * a.sqrt() / (0.433 * 700.0)).sqrt();
        let dom = triangulate_polygon(&resample_polygon(&poly, &metric, l), &[])
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        let out = Lct::default()
            .remesh(&dom, &metric, l, &mut rand_chacha::ChaCha8Rng::seed_from_u64(seed))
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        let q = planar_quality(&out, &metric, l);
        prop_assert!(q.q_avg >= 0.9, "{:?}", q);
        prop_assert!(q.edges_in_range >= 0.9, "{:?}", q);
    }
}
