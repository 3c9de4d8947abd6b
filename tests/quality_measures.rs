//! The yardstick's measures on cases whose answer is known by hand (Sec. 4.1).

use conemesh::mesh::generators;
use conemesh::quality::{
    approximation_error, edge_conformity, edge_length_average, flips, quality_stats,
    triangle_quality,
};
use conemesh::{FaceId, Rng, TriMesh};
use nalgebra::{Matrix3, Point3, Rotation3, Unit, Vector3};
use rand::{Rng as _, SeedableRng};

fn equilateral() -> [Point3<f64>; 3] {
    [
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.5, 3f64.sqrt() / 2.0, 0.0),
    ]
}

#[test]
fn equilateral_under_identity_has_q_one_and_60_degree_angles() {
    let t = triangle_quality(equilateral(), &Matrix3::identity());
    assert!((t.q - 1.0).abs() < 1e-14, "q = {}", t.q);
    for a in t.angles {
        assert!((a - 60.0).abs() < 1e-12, "angle {a}");
    }
}

fn random_rotation(rng: &mut Rng) -> Rotation3<f64> {
    let axis = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let axis = Unit::try_new(axis, 1e-6).unwrap_or(Vector3::z_axis());
    Rotation3::from_axis_angle(&axis, rng.random_range(0.0..std::f64::consts::TAU))
}

#[test]
fn triangle_stretched_by_inverse_sqrt_of_rank2_metric_has_q_one() {
    let mut rng = Rng::seed_from_u64(7);
    for _ in 0..200 {
        // Random tangent frame (d1, d2, n) and curvature-like eigenvalues, zero on the normal.
        let r = random_rotation(&mut rng);
        let (k1, k2) = (rng.random_range(1e-3..1e3), rng.random_range(1e-3..1e3));
        let m = r.matrix()
            * Matrix3::from_diagonal(&Vector3::new(k1, k2, 0.0))
            * r.matrix().transpose();
        // Equilateral in the isotropic space, mapped back by Q⁺ = R diag(1/√k1, 1/√k2, 0) Rᵀ,
        // then moved along the normal by arbitrary amounts (invisible to a rank-2 metric).
        let spin = rng.random_range(0.0..std::f64::consts::TAU);
        let base = Point3::new(rng.random_range(-5.0..5.0), 0.3, -1.0);
        let pts: Vec<Point3<f64>> = (0..3)
            .map(|i| {
                let a = spin + i as f64 * std::f64::consts::TAU / 3.0;
                let local = Vector3::new(
                    a.cos() / k1.sqrt(),
                    a.sin() / k2.sqrt(),
                    rng.random_range(-1.0..1.0),
                );
                base + r * local
            })
            .collect();
        let t = triangle_quality([pts[0], pts[1], pts[2]], &m);
        assert!((t.q - 1.0).abs() < 1e-9, "q = {} for k1 {k1} k2 {k2}", t.q);
        for a in t.angles {
            assert!((a - 60.0).abs() < 1e-6, "angle {a}");
        }
    }
}

#[test]
fn triangle_30_30_120_has_the_formula_value() {
    // Sides 1, 1, √3: area = ½·sin 120° = √3/4, semi-perimeter p = (2 + √3)/2, longest h = √3,
    // so q = 2√3·(√3/4) / ((2 + √3)/2 · √3) = √3 / (2 + √3) ≈ 0.4641.
    let p = [
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(3f64.sqrt(), 0.0, 0.0),
        Point3::new(3f64.sqrt() / 2.0, 0.5, 0.0),
    ];
    let t = triangle_quality(p, &Matrix3::identity());
    let expect = 3f64.sqrt() / (2.0 + 3f64.sqrt());
    assert!(
        (t.q - expect).abs() < 1e-14,
        "q = {} expected {expect}",
        t.q
    );
    assert!((t.angles[0] - 30.0).abs() < 1e-12);
    assert!((t.angles[1] - 30.0).abs() < 1e-12);
    assert!((t.angles[2] - 120.0).abs() < 1e-12);
    // q is invariant under a uniform metric scaling: M = 4·I gives the same q.
    let t4 = triangle_quality(p, &(Matrix3::identity() * 4.0));
    assert!((t4.q - expect).abs() < 1e-14);
}

#[test]
fn stats_of_a_two_triangle_mesh() {
    // One equilateral and one 30-30-120 triangle sharing no vertex.
    let e = equilateral();
    let mut pos = e.to_vec();
    pos.extend([
        Point3::new(0.0, 0.0, 1.0),
        Point3::new(3f64.sqrt(), 0.0, 1.0),
        Point3::new(3f64.sqrt() / 2.0, 0.5, 1.0),
    ]);
    let m = TriMesh::from_indices(pos, &[[0, 1, 2], [3, 4, 5]]).expect("mesh");
    let s = quality_stats(&m, &vec![Matrix3::identity(); 6]);
    let q2 = 3f64.sqrt() / (2.0 + 3f64.sqrt());
    assert_eq!(s.faces, 2);
    assert!((s.q_min - q2).abs() < 1e-12 && (s.q_max - 1.0).abs() < 1e-12);
    assert!((s.q_avg - (1.0 + q2) / 2.0).abs() < 1e-12);
    assert!((s.theta_min - 30.0).abs() < 1e-9 && (s.theta_max - 120.0).abs() < 1e-9);
    assert!((s.theta_avg - 45.0).abs() < 1e-9);
    assert_eq!(s.pct_min_angle_lt_10, 0.0);
    assert_eq!(s.pct_min_angle_lt_20, 0.0);
    assert_eq!(s.hist_q.iter().sum::<usize>(), 2);
    assert_eq!(s.hist_q[4], 1); // q ≈ 0.464
    assert_eq!(s.hist_q[9], 1);
    assert_eq!(s.hist_angles.iter().sum::<usize>(), 6);
    assert_eq!(s.hist_angles[6], 3); // the three 60° angles
    assert_eq!(s.hist_min_angles.iter().sum::<usize>(), 2);
}

#[test]
fn edge_length_average_and_conformity_of_a_uniform_grid() {
    // In the metric 4·I (2× lengths) the mean edge length doubles, and conformity against
    // that mean has mean exactly 1.
    let m = generators::icosphere(1.0, 2);
    let id = vec![Matrix3::identity(); m.n_vertices()];
    let four = vec![Matrix3::identity() * 4.0; m.n_vertices()];
    let l1 = edge_length_average(&m, &id);
    let l2 = edge_length_average(&m, &four);
    assert!((l2 - 2.0 * l1).abs() < 1e-12);
    let c = edge_conformity(&m, &four, l2);
    assert!((c.mean - 1.0).abs() < 1e-12);
    assert_eq!(c.edges, 3 * m.n_faces() / 2);
    assert!(c.fraction_in_range > 0.99, "{c:?}");
}

#[test]
fn mesh_against_itself_has_zero_distance_and_no_flips() {
    let m = generators::torus(1.0, 0.3, 24, 12);
    let mut rng = Rng::seed_from_u64(1);
    let d = approximation_error(&m, &m, 20_000, &mut rng);
    assert!(d.hausdorff < 1e-12, "{d:?}");
    assert!(d.rms < 1e-12, "{d:?}");
    assert_eq!(d.samples, 2 * (m.n_vertices() + 20_000));
    assert!(flips(&m, &m).is_empty());
}

#[test]
fn disk_shifted_along_its_normal_has_hausdorff_of_the_shift() {
    let a = generators::disk(1.0, 8, 6);
    let diag = a.bbox_diagonal();
    let shift = 1e-3 * diag;
    let mut b = a.clone();
    for p in &mut b.positions {
        p.z += shift;
    }
    let mut rng = Rng::seed_from_u64(2);
    let d = approximation_error(&a, &b, 10_000, &mut rng);
    assert!((d.hausdorff - shift).abs() < 1e-12 * diag, "{d:?}");
    assert!((d.rms - shift).abs() < 1e-12 * diag, "{d:?}");
    assert!((d.hausdorff_rel - 1e-3).abs() < 1e-12, "{d:?}");
    assert!(flips(&a, &b).is_empty());
}

#[test]
fn disk_shifted_sideways_is_measured_at_its_overhang() {
    // Shifting in-plane by s: the overhanging rim is s away from the other disk's rim
    // (a polygon, so exactly s at the rim vertices along the shift direction).
    let a = generators::disk(1.0, 8, 6);
    let s = 0.01;
    let mut b = a.clone();
    for p in &mut b.positions {
        p.x += s;
    }
    let mut rng = Rng::seed_from_u64(3);
    let d = approximation_error(&a, &b, 10_000, &mut rng);
    assert!((d.hausdorff - s).abs() < 1e-12, "{d:?}");
    assert!(d.rms < s, "{d:?}");
}

#[test]
fn reversed_orientation_flips_every_face() {
    for m in [
        generators::icosphere(1.0, 2),
        generators::torus(1.0, 0.3, 16, 8),
        generators::disk(1.0, 4, 6),
    ] {
        let f = flips(&m, &m.flipped());
        assert_eq!(f, m.faces().collect::<Vec<FaceId>>());
    }
}

#[test]
fn sampling_is_seeded() {
    let a = generators::icosphere(1.0, 2);
    let b = generators::icosphere(1.01, 1);
    let d1 = approximation_error(&a, &b, 5_000, &mut Rng::seed_from_u64(9));
    let d2 = approximation_error(&a, &b, 5_000, &mut Rng::seed_from_u64(9));
    assert_eq!(d1, d2);
    assert!(d1.hausdorff > 0.01 && d1.hausdorff < 0.1, "{d1:?}");
}

#[test]
fn unreferenced_vertices_are_not_samples() {
    // Regression (stanford-bunny has 1113 unreferenced scan vertices): a stray vertex far
    // from the surface must not count as a distance.
    let a = generators::disk(1.0, 4, 6);
    let mut b = a.clone();
    b.positions.push(Point3::new(0.0, 0.0, 5.0));
    let d = approximation_error(&a, &b, 1_000, &mut Rng::seed_from_u64(4));
    assert!(d.hausdorff < 1e-12, "{d:?}");
    assert_eq!(d.samples, 2 * (a.n_vertices() + 1_000));
}

/// M_t is the mean of the three vertex tensors (not some other combination).
#[test]
fn face_metric_is_the_mean_of_the_vertex_metrics() {
    use conemesh::quality::face_metric;
    use conemesh::VertexId;
    let m = [
        Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 0.0)),
        Matrix3::from_diagonal(&Vector3::new(4.0, 8.0, 0.0)),
        Matrix3::from_diagonal(&Vector3::new(16.0, 32.0, 0.0)),
    ];
    let got = face_metric(&m, [VertexId(0), VertexId(1), VertexId(2)]);
    assert_eq!(got, Matrix3::from_diagonal(&Vector3::new(7.0, 14.0, 0.0)));
}

/// The small- and large-angle percentages count exactly the triangles below/above the
/// thresholds, over the number of triangles.
#[test]
fn angle_percentages_count_triangles_exactly() {
    use conemesh::quality::stats_of;
    use conemesh::quality::TriangleQuality;
    let t = |a: f64, b: f64| TriangleQuality {
        q: 0.5,
        angles: [a, b, 180.0 - a - b],
    };
    // Min angles 15°, 25°, 60°, 5°; max angles 150°, 130°, 60°, 90°.
    let qs = [t(15.0, 15.0), t(25.0, 25.0), t(60.0, 60.0), t(5.0, 85.0)];
    let s = stats_of(&qs);
    assert_eq!(s.pct_min_angle_lt_10, 25.0);
    assert_eq!(s.pct_min_angle_lt_20, 50.0);
    assert_eq!(s.pct_min_angle_lt_30, 75.0);
    assert_eq!(s.pct_max_angle_gt_120, 50.0);
    assert_eq!(s.theta_avg, (15.0 + 25.0 + 60.0 + 5.0) / 4.0);
}

/// The median of L/L_tar: the middle value for an odd edge count, the mean of the two middle
/// values for an even one.
#[test]
fn conformity_median_for_odd_and_even_edge_counts() {
    let id = |n: usize| vec![Matrix3::identity(); n];
    // Two triangles sharing an edge: 5 edges of lengths 1, 1, √2, 2, √5 (sorted).
    let kite = TriMesh::from_indices(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(-1.0, -1.0, 0.0),
        ],
        &[[0, 1, 2], [0, 3, 1]],
    )
    .expect("valid");
    let lens = {
        let mut l: Vec<f64> = conemesh::quality::unique_edges(&kite)
            .iter()
            .map(|e| (kite.position(e.0) - kite.position(e.1)).norm())
            .collect();
        l.sort_by(f64::total_cmp);
        l
    };
    assert_eq!(lens.len(), 5);
    let c = edge_conformity(&kite, &id(4), 1.0);
    assert!(
        (c.median - lens[2]).abs() < 1e-15,
        "{} vs {}",
        c.median,
        lens[2]
    );
    // A tetrahedron: 6 edges, 1, 1, 1, √2, √2, √2 → median (1 + √2)/2.
    let tet = TriMesh::from_indices(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(0.0, 0.0, 1.0),
        ],
        &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    )
    .expect("valid");
    let c = edge_conformity(&tet, &id(4), 1.0);
    assert_eq!(c.edges, 6);
    assert!((c.median - (1.0 + 2f64.sqrt()) / 2.0).abs() < 1e-15);
}
