//! Property tests of the metric stage: projection onto the reference surface, interpolation,
//! and independence of the unit-space curvature metric from the file's placement and scale.

#[path = "../proptests/seed.rs"]
mod seed;
use conemesh::mesh::generators;
use conemesh::metric::{curvature_metric, MetricField, MetricOptions, Normalization};
use conemesh::{FaceId, SurfaceLocation, TriMesh};
use nalgebra::{Point3, Vector3};
use proptest::prelude::*;
use std::sync::OnceLock;

fn config(cases: u32) -> ProptestConfig {
    seed::config(cases, "metric", 0x3e7c)
}

fn field() -> &'static MetricField {
    static FIELD: OnceLock<MetricField> = OnceLock::new();
    FIELD.get_or_init(|| {
        let m = generators::torus(1.0, 0.35, 32, 16);
        let unit = Normalization::of(&m).apply(&m);
        MetricField::from_curvature(unit, &MetricOptions::default()).expect("valid torus field")
    })
}

proptest! {
    #![proptest_config(config(64))]

    #[test]
    fn points_on_the_surface_project_to_themselves_and_evaluate_consistently(
        f in 0usize..1024, u in 0.0f64..1.0, v in 0.0f64..1.0,
    ) {
        let field = field();
        let m = field.reference();
        let face = FaceId::new(f % m.n_faces());
        let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
        let loc = SurfaceLocation { face, bary: [1.0 - u - v, u, v] };
        let p = loc.position(m);
        let (got, q) = field.project(&p);
        prop_assert!((q - p).norm() < 1e-12, "{q} vs {p}");
        prop_assert!((got.bary.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        let a = field.eval_at(&loc);
        let b = field.eval(&p);
        // Same point: same tensor (up to round-off, or the neighbour face's interpolation on an
        // edge, which agrees there because interpolation is linear along the shared edge).
        prop_assert!((a - b).norm() < 1e-9 * a.norm(), "{a} vs {b}");
        // Interpolated tensors stay symmetric positive semi-definite.
        prop_assert!((a - a.transpose()).norm() == 0.0);
        prop_assert!(a.symmetric_eigenvalues().min() > -1e-12 * a.norm());
    }

    #[test]
    fn unit_space_curvature_metric_ignores_placement_and_scale(
        s in 0.001f64..1000.0, tx in -10.0f64..10.0, ty in -10.0f64..10.0, tz in -10.0f64..10.0,
    ) {
        // The point of the unit-diagonal normalization (Sec. 3.1 notes): the same shape at
        // any position and size gets the same unit-space metric, floor included.
        let m = generators::torus(1.0, 0.35, 24, 12);
        let moved = TriMesh {
            positions: m.positions.iter()
                .map(|p| Point3::from(p.coords * s + Vector3::new(tx, ty, tz)))
                .collect(),
            triangles: m.triangles.clone(),
        };
        let opts = MetricOptions::default();
        let a = curvature_metric(&Normalization::of(&m).apply(&m), &opts)
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        let b = curvature_metric(&Normalization::of(&moved).apply(&moved), &opts)
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        for (v, (x, y)) in a.iter().zip(&b).enumerate() {
            prop_assert!((x - y).norm() < 1e-6 * x.norm(), "v{v}: {x} vs {y}");
        }
    }
}
