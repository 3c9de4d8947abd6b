//! Invariances of the quality measures (Sec. 4.1): rigid motions (mesh rotated and
//! translated, metric conjugated R M Rᵀ) and uniform scaling (mesh ×s, metric ÷s²) change
//! neither q, θ, L_avg/L_tar nor the relative approximation error.

#[path = "seed.rs"]
mod seed;
use conemesh::mesh::generators;
use conemesh::quality::{
    approximation_error, edge_conformity, edge_length_average, quality_stats, QualityStats,
};
use conemesh::{Rng, TriMesh};
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use proptest::prelude::*;
use rand::{Rng as _, SeedableRng};

fn config(cases: u32) -> ProptestConfig {
    seed::config(cases, "quality", 0x9a11)
}

/// A perturbed torus and a random per-vertex metric: rank 2 (curvature-like, zero along a
/// random direction) or full rank, eigenvalues spread over four decades.
fn mesh_and_metrics(seed: u64) -> (TriMesh, Vec<Matrix3<f64>>) {
    let mut rng = Rng::seed_from_u64(seed);
    let m = generators::perturb(&generators::torus(1.0, 0.35, 14, 9), 0.02, &mut rng);
    let metrics = (0..m.n_vertices())
        .map(|_| {
            let r = random_rotation(&mut rng);
            let k3 = if rng.random_bool(0.5) {
                0.0
            } else {
                rng.random_range(1e-2..1e2)
            };
            let d = Vector3::new(rng.random_range(1e-2..1e2), rng.random_range(1e-2..1e2), k3);
            r.matrix() * Matrix3::from_diagonal(&d) * r.matrix().transpose()
        })
        .collect();
    (m, metrics)
}

fn random_rotation(rng: &mut Rng) -> Rotation3<f64> {
    let axis = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let axis = Unit::try_new(axis, 1e-6).unwrap_or(Vector3::x_axis());
    Rotation3::from_axis_angle(&axis, rng.random_range(0.0..std::f64::consts::TAU))
}

fn assert_stats_close(a: &QualityStats, b: &QualityStats) {
    let close = |x: f64, y: f64, tol: f64| (x - y).abs() <= tol;
    assert_eq!(a.faces, b.faces);
    assert!(
        close(a.q_min, b.q_min, 1e-9),
        "q_min {} vs {}",
        a.q_min,
        b.q_min
    );
    assert!(
        close(a.q_max, b.q_max, 1e-9),
        "q_max {} vs {}",
        a.q_max,
        b.q_max
    );
    assert!(
        close(a.q_avg, b.q_avg, 1e-9),
        "q_avg {} vs {}",
        a.q_avg,
        b.q_avg
    );
    assert!(
        close(a.theta_min, b.theta_min, 1e-7),
        "{} vs {}",
        a.theta_min,
        b.theta_min
    );
    assert!(
        close(a.theta_max, b.theta_max, 1e-7),
        "{} vs {}",
        a.theta_max,
        b.theta_max
    );
    assert!(
        close(a.theta_avg, b.theta_avg, 1e-7),
        "{} vs {}",
        a.theta_avg,
        b.theta_avg
    );
}

proptest! {
    #![proptest_config(config(24))]

    #[test]
    fn stats_are_invariant_under_rigid_motion(seed in 0u64..1_000_000, angle in 0.0f64..std::f64::consts::TAU,
                                              ax in -1.0f64..1.0, ay in -1.0f64..1.0, az in 0.1f64..1.0,
                                              tx in -10.0f64..10.0) {
        let (m, metrics) = mesh_and_metrics(seed);
        let r = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(ax, ay, az)), angle);
        let t = Vector3::new(tx, -0.5 * tx, 3.0);
        let mut moved = m.clone();
        for p in &mut moved.positions {
            *p = r * *p + t;
        }
        // The metric is a bilinear form on displacements: it moves as R M Rᵀ.
        let conj: Vec<Matrix3<f64>> = metrics.iter().map(|mm| r.matrix() * mm * r.matrix().transpose()).collect();
        assert_stats_close(&quality_stats(&m, &metrics), &quality_stats(&moved, &conj));
        let (l0, l1) = (edge_length_average(&m, &metrics), edge_length_average(&moved, &conj));
        prop_assert!((l0 - l1).abs() <= 1e-9 * l0);
    }

    #[test]
    fn stats_are_invariant_under_uniform_scaling(seed in 0u64..1_000_000, s in 1e-3f64..1e3) {
        let (m, metrics) = mesh_and_metrics(seed);
        let mut scaled = m.clone();
        for p in &mut scaled.positions {
            p.coords *= s;
        }
        // Lengths ×s, metric ÷s²: every metric length is unchanged.
        let div: Vec<Matrix3<f64>> = metrics.iter().map(|mm| mm / (s * s)).collect();
        assert_stats_close(&quality_stats(&m, &metrics), &quality_stats(&scaled, &div));
        let (l0, l1) = (edge_length_average(&m, &metrics), edge_length_average(&scaled, &div));
        prop_assert!((l0 - l1).abs() <= 1e-9 * l0);
        let (c0, c1) = (edge_conformity(&m, &metrics, 1.5 * l0), edge_conformity(&scaled, &div, 1.5 * l1));
        prop_assert!((c0.mean - c1.mean).abs() < 1e-9 && (c0.median - c1.median).abs() < 1e-9);
        prop_assert!((c0.fraction_in_range - c1.fraction_in_range).abs() < 1e-12);
    }
}

proptest! {
    #![proptest_config(config(8))]

    #[test]
    fn relative_distance_is_invariant_under_scaling_and_motion(seed in 0u64..1_000_000, s in 1e-2f64..1e2,
                                                               angle in 0.0f64..std::f64::consts::TAU) {
        let mut rng = Rng::seed_from_u64(seed);
        let a = generators::torus(1.0, 0.35, 14, 9);
        let b = generators::perturb(&a, 0.01, &mut rng);
        let r = Rotation3::from_axis_angle(&Vector3::y_axis(), angle);
        let tr = |m: &TriMesh| {
            let mut m = m.clone();
            for p in &mut m.positions {
                *p = r * (*p * s) + Vector3::new(1.0, 2.0, 3.0);
            }
            m
        };
        // The same seed draws the same barycentric samples on the moved surfaces.
        let d0 = approximation_error(&a, &b, 2_000, &mut Rng::seed_from_u64(seed));
        let d1 = approximation_error(&tr(&a), &tr(&b), 2_000, &mut Rng::seed_from_u64(seed));
        prop_assert!(d0.hausdorff > 0.0);
        prop_assert!((d0.hausdorff * s - d1.hausdorff).abs() <= 1e-8 * d1.hausdorff, "{d0:?} {d1:?}");
        // The bbox diagonal is not rotation invariant, so absolute values ×s are compared.
        prop_assert!((d0.rms * s - d1.rms).abs() <= 1e-8 * d1.rms, "{d0:?} {d1:?}");
    }
}
