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

/// Side lengths of `p` in the metric `m`: √(eᵀ M e) per edge, e[i] from corner i to i+1.
/// Independent of `metric_sqrt`: |Q e|² = eᵀ Q² e = eᵀ M e for the PSD square root Q.
fn metric_sides(p: &[Point3<f64>; 3], m: &Matrix3<f64>) -> [f64; 3] {
    let side = |a: &Point3<f64>, b: &Point3<f64>| {
        let e = b - a;
        e.dot(&(m * e)).max(0.0).sqrt()
    };
    [side(&p[0], &p[1]), side(&p[1], &p[2]), side(&p[2], &p[0])]
}

/// q and the corner angles from the three side lengths only: Heron's area (Kahan's stable
/// form), q = 2√3·a/(p·h), angles by the law of cosines. Corner i is opposite side i+1.
fn oracle_quality(l: [f64; 3]) -> (f64, [f64; 3]) {
    let mut s = l;
    s.sort_by(|a, b| b.total_cmp(a));
    let (a, b, c) = (s[0], s[1], s[2]);
    let area = 0.25 * ((a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c))).sqrt();
    let semi = 0.5 * (l[0] + l[1] + l[2]);
    let q = 2.0 * 3f64.sqrt() * area / (semi * a);
    let angle = |opp: f64, x: f64, y: f64| {
        ((x * x + y * y - opp * opp) / (2.0 * x * y))
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees()
    };
    let angles = [
        angle(l[1], l[0], l[2]),
        angle(l[2], l[1], l[0]),
        angle(l[0], l[2], l[1]),
    ];
    (q, angles)
}

/// A random symmetric metric R·diag(k)·Rᵀ with eigenvalues over four decades, one of them 0
/// (rank 2, like the curvature metric) or negative (round-off; clamped to 0 by the measure)
/// in some cases. Returns (M as given to the measure, the PSD metric it stands for).
fn random_metric(rng: &mut Rng) -> (Matrix3<f64>, Matrix3<f64>) {
    let r = random_rotation(rng);
    let k = Vector3::new(
        rng.random_range(1e-2..1e2),
        rng.random_range(1e-2..1e2),
        rng.random_range(1e-2..1e2),
    );
    let (given, psd) = match rng.random_range(0..3) {
        0 => (k, k),
        1 => (Vector3::new(k.x, k.y, 0.0), Vector3::new(k.x, k.y, 0.0)),
        _ => (
            Vector3::new(k.x, k.y, -1e-3 * k.z),
            Vector3::new(k.x, k.y, 0.0),
        ),
    };
    let conj = |d: Vector3<f64>| r.matrix() * Matrix3::from_diagonal(&d) * r.matrix().transpose();
    (conj(given), conj(psd))
}

/// `triangle_quality` against the side-length oracle on random triangles and metrics,
/// including a metric with a tiny negative eigenvalue and an asymmetric input (only the
/// symmetric part counts).
#[test]
fn triangle_quality_matches_the_side_length_oracle() {
    use conemesh::quality::{metric_sqrt, triangle_quality_with_sqrt};
    let mut rng = Rng::seed_from_u64(0x9a11);
    for case in 0..300 {
        let p: [Point3<f64>; 3] = std::array::from_fn(|_| {
            Point3::new(
                rng.random_range(-2.0..2.0),
                rng.random_range(-2.0..2.0),
                rng.random_range(-2.0..2.0),
            )
        });
        let (m, psd) = random_metric(&mut rng);
        // An antisymmetric part changes no eᵀ M e.
        let skew = Matrix3::new(0.0, 1.0, -2.0, -1.0, 0.0, 0.5, 2.0, -0.5, 0.0)
            * rng.random_range(0.0..1.0);
        let given = if case % 2 == 0 { m } else { m + skew };
        let (q, angles) = oracle_quality(metric_sides(&p, &psd));
        if q < 1e-3 {
            continue; // nearly degenerate: the oracle's own rounding dominates
        }
        for t in [
            triangle_quality(p, &given),
            triangle_quality_with_sqrt(p, &metric_sqrt(&given)),
        ] {
            assert!((t.q - q).abs() < 1e-9, "case {case}: q {} vs {q}", t.q);
            for i in 0..3 {
                assert!(
                    (t.angles[i] - angles[i]).abs() < 1e-6,
                    "case {case}: angle {i}: {:?} vs {angles:?}",
                    t.angles
                );
            }
            assert!((t.angles.iter().sum::<f64>() - 180.0).abs() < 1e-9);
            assert_eq!(
                t.min_angle(),
                t.angles.iter().copied().fold(f64::MAX, f64::min)
            );
            assert_eq!(
                t.max_angle(),
                t.angles.iter().copied().fold(f64::MIN, f64::max)
            );
        }
        // Q = √M: symmetric, and Q·Q reproduces the PSD metric.
        let s = metric_sqrt(&given);
        assert!(
            (s - s.transpose()).norm() <= 1e-12 * s.norm(),
            "case {case}"
        );
        assert!((s * s - psd).norm() <= 1e-9 * psd.norm(), "case {case}");
    }
}

/// Degenerate in the metric: q = 0 and the 180° angle at the corner opposite the longest
/// mapped edge, whichever corner that is; also for coincident corners and non-finite input.
#[test]
fn degenerate_triangles_put_180_degrees_opposite_the_longest_edge() {
    let id = Matrix3::identity();
    let line = |x: [f64; 3]| x.map(|x| Point3::new(x, 2.0 * x, -x));
    for (xs, corner) in [
        ([0.0, 1.0, 3.0], 1),
        ([1.0, 0.0, 3.0], 0),
        ([0.0, 3.0, 1.0], 2),
    ] {
        let t = triangle_quality(line(xs), &id);
        assert_eq!(t.q, 0.0, "{xs:?}");
        let mut expect = [0.0; 3];
        expect[corner] = 180.0;
        assert_eq!(t.angles, expect, "{xs:?}");
        assert_eq!((t.min_angle(), t.max_angle()), (0.0, 180.0));
    }
    // Two coincident corners: a zero-length edge.
    let t = triangle_quality(line([0.0, 0.0, 1.0]), &id);
    assert_eq!(t.q, 0.0);
    assert_eq!(t.angles.iter().sum::<f64>(), 180.0);
    // A non-degenerate triangle that a rank-1 metric (along x only) flattens onto a line:
    // mapped edges 3, 2, 1 → the corner opposite the longest (edge 0) is corner 2.
    let rank1 = Matrix3::from_diagonal(&Vector3::new(1.0, 0.0, 0.0));
    let p = [
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(3.0, 5.0, 0.0),
        Point3::new(1.0, 1.0, 2.0),
    ];
    let t = triangle_quality(p, &rank1);
    assert_eq!((t.q, t.angles), (0.0, [0.0, 0.0, 180.0]));
    // Infinite coordinates are not a triangle.
    let mut inf = p;
    inf[2].x = f64::INFINITY;
    assert_eq!(triangle_quality(inf, &id).q, 0.0);
}

/// Every field of `quality_stats` against a direct recomputation from the side-length
/// oracle (face metric = mean of the vertex metrics), and the edge measures against
/// brute-force unique edges.
#[test]
fn quality_stats_and_conformity_match_brute_force() {
    use conemesh::quality::{edge_metric_length, face_qualities, unique_edges};
    use std::collections::BTreeSet;
    let mut rng = Rng::seed_from_u64(0x57a7);
    for case in 0..6 {
        let m = generators::perturb(&generators::icosphere(1.0, 1), 0.15, &mut rng);
        // PSD metrics only: the mean of clamped tensors is not the clamped mean.
        let psd: Vec<Matrix3<f64>> = (0..m.n_vertices())
            .map(|_| random_metric(&mut rng).1)
            .collect();
        let given = &psd;
        let per_face: Vec<(f64, [f64; 3])> = m
            .faces()
            .map(|f| {
                let t = m.face(f);
                let mt = (psd[t[0].idx()] + psd[t[1].idx()] + psd[t[2].idx()]) / 3.0;
                oracle_quality(metric_sides(&m.face_points(f), &mt))
            })
            .collect();
        let fq = face_qualities(&m, given);
        assert_eq!(fq.len(), m.n_faces());
        for (t, (q, a)) in fq.iter().zip(&per_face) {
            assert!((t.q - q).abs() < 1e-9 && (t.angles[0] - a[0]).abs() < 1e-6);
        }
        let s = quality_stats(&m, given);
        let nf = per_face.len() as f64;
        let mins: Vec<f64> = per_face
            .iter()
            .map(|(_, a)| a[0].min(a[1]).min(a[2]))
            .collect();
        let maxs: Vec<f64> = per_face
            .iter()
            .map(|(_, a)| a[0].max(a[1]).max(a[2]))
            .collect();
        let qs: Vec<f64> = per_face.iter().map(|(q, _)| *q).collect();
        let close = |x: f64, y: f64, tol: f64| (x - y).abs() < tol;
        assert_eq!(s.faces, per_face.len());
        assert!(close(
            s.q_min,
            qs.iter().copied().fold(f64::MAX, f64::min),
            1e-9
        ));
        assert!(close(
            s.q_max,
            qs.iter().copied().fold(f64::MIN, f64::max),
            1e-9
        ));
        assert!(close(s.q_avg, qs.iter().sum::<f64>() / nf, 1e-9));
        assert!(close(
            s.theta_min,
            mins.iter().copied().fold(f64::MAX, f64::min),
            1e-6
        ));
        assert!(close(
            s.theta_max,
            maxs.iter().copied().fold(f64::MIN, f64::max),
            1e-6
        ));
        assert!(close(s.theta_avg, mins.iter().sum::<f64>() / nf, 1e-6));
        let pct = |n: usize| 100.0 * n as f64 / nf;
        let count = |v: &[f64], f: &dyn Fn(f64) -> bool| v.iter().filter(|&&x| f(x)).count();
        assert_eq!(s.pct_min_angle_lt_10, pct(count(&mins, &|x| x < 10.0)));
        assert_eq!(s.pct_min_angle_lt_20, pct(count(&mins, &|x| x < 20.0)));
        assert_eq!(s.pct_min_angle_lt_30, pct(count(&mins, &|x| x < 30.0)));
        assert_eq!(s.pct_max_angle_gt_120, pct(count(&maxs, &|x| x > 120.0)));
        // Histograms: bin i holds [i·w, (i+1)·w), decided by comparisons.
        let hist = |v: &[f64], w: f64, n: usize| -> Vec<usize> {
            (0..n)
                .map(|i| {
                    count(v, &|x| {
                        x >= i as f64 * w && (x < (i + 1) as f64 * w || i == n - 1)
                    })
                })
                .collect()
        };
        let all_angles: Vec<f64> = per_face.iter().flat_map(|(_, a)| *a).collect();
        assert_eq!(s.hist_q.to_vec(), hist(&qs, 0.1, 10), "case {case}");
        assert_eq!(
            s.hist_angles.to_vec(),
            hist(&all_angles, 10.0, 18),
            "case {case}"
        );
        assert_eq!(
            s.hist_min_angles.to_vec(),
            hist(&mins, 10.0, 18),
            "case {case}"
        );
        assert!(
            s.pct_min_angle_lt_30 > 0.0 && s.pct_min_angle_lt_30 < 100.0,
            "{s:?}"
        );

        // Edges: unique undirected, sorted; metric length with the mean endpoint metric.
        let keys: BTreeSet<conemesh::EdgeKey> = m
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |i| conemesh::EdgeKey::new(t[i], t[(i + 1) % 3])))
            .collect();
        let edges = unique_edges(&m);
        assert_eq!(edges, keys.iter().copied().collect::<Vec<_>>());
        let lens: Vec<f64> = edges
            .iter()
            .map(|e| {
                let d = m.position(e.1) - m.position(e.0);
                let me = (psd[e.0.idx()] + psd[e.1.idx()]) / 2.0;
                d.dot(&(me * d)).max(0.0).sqrt()
            })
            .collect();
        for (e, l) in edges.iter().zip(&lens) {
            assert!((edge_metric_length(&m, given, *e) - l).abs() < 1e-9 * l.max(1.0));
        }
        let ne = lens.len() as f64;
        let avg = lens.iter().sum::<f64>() / ne;
        assert!((edge_length_average(&m, given) - avg).abs() < 1e-9 * avg);
        // Conformity against a target in the middle of the lengths, so that some edges fall
        // outside [1/√2, √2] on each side.
        let l_tar = avg;
        let r: Vec<f64> = lens.iter().map(|l| l / l_tar).collect();
        let mean = r.iter().sum::<f64>() / ne;
        let std = (r.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / ne).sqrt();
        let mut sorted = r.clone();
        sorted.sort_by(f64::total_cmp);
        let k = sorted.len();
        let median = if k % 2 == 1 {
            sorted[k / 2]
        } else {
            (sorted[k / 2 - 1] + sorted[k / 2]) / 2.0
        };
        let inside = count(&r, &|x| x >= 0.5f64.sqrt() && x <= 2f64.sqrt());
        let c = edge_conformity(&m, given, l_tar);
        assert_eq!(c.edges, k);
        assert!((c.mean - mean).abs() < 1e-9, "{c:?}");
        assert!((c.std - std).abs() < 1e-9, "{c:?} vs {std}");
        assert!((c.median - median).abs() < 1e-9, "{c:?} vs {median}");
        assert_eq!(c.fraction_in_range, inside as f64 / ne, "{c:?}");
        assert!(inside < k && c.std > 0.1, "{c:?}");
    }
}

/// An empty mesh (no faces) gives all-zero statistics, zero L_avg and zero conformity.
#[test]
fn empty_mesh_measures_are_zero() {
    use conemesh::quality::stats_of;
    let s = stats_of(&[]);
    assert_eq!(
        (
            s.faces,
            s.q_min,
            s.q_max,
            s.q_avg,
            s.theta_min,
            s.theta_max,
            s.theta_avg
        ),
        (0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    );
    assert_eq!(s.hist_q, [0; 10]);
    let m = TriMesh {
        positions: vec![Point3::origin()],
        triangles: vec![],
    };
    assert_eq!(edge_length_average(&m, &[Matrix3::identity()]), 0.0);
    let c = edge_conformity(&m, &[Matrix3::identity()], 1.0);
    assert_eq!(
        (c.edges, c.mean, c.std, c.median, c.fraction_in_range),
        (0, 0.0, 0.0, 0.0, 0.0)
    );
    // A metric that is not PSD gives eᵀMe < 0: the length counts as 0, not NaN.
    use conemesh::quality::edge_metric_length;
    let seg = generators::disk(1.0, 1, 3);
    let neg = vec![-Matrix3::identity(); seg.n_vertices()];
    let e = conemesh::quality::unique_edges(&seg)[0];
    assert_eq!(edge_metric_length(&seg, &neg, e), 0.0);
}

/// The thresholds are strict (Sec. 4.1 / Table 1: "θ < 10°", "> 120°"): a triangle whose
/// smallest angle is exactly 10°, 20° or 30°, or whose largest is exactly 120°, is not
/// counted in that class.
#[test]
fn angle_percentages_use_strict_thresholds() {
    use conemesh::quality::stats_of;
    use conemesh::quality::TriangleQuality;
    let t = |a: f64, b: f64| TriangleQuality {
        q: 0.5,
        angles: [a, b, 180.0 - a - b],
    };
    // (min, max): (10, 85), (20, 80), (30, 120).
    let s = stats_of(&[t(10.0, 85.0), t(20.0, 80.0), t(30.0, 30.0)]);
    assert_eq!(s.pct_min_angle_lt_10, 0.0);
    assert_eq!(s.pct_min_angle_lt_20, 100.0 / 3.0);
    assert_eq!(s.pct_min_angle_lt_30, 200.0 / 3.0);
    assert_eq!(s.pct_max_angle_gt_120, 0.0);
}

/// Zero computed area means degenerate, reported exactly as q = 0 and angles {0°, 0°, 180°}
/// with the 180° at the middle point, even when rounding leaves the *other* pairs of
/// edges a few ulps from parallel (so angles measured from them would be 1e-14° instead
/// of 0°). Points p2 = k·p1 on a line through the origin, searched over small integers and
/// rational k until e0 × e1 rounds to exactly zero.
#[test]
fn zero_area_triangles_get_exact_degenerate_angles() {
    let id = Matrix3::identity();
    let mut rng = Rng::seed_from_u64(0x2e40);
    let (mut zero_area, mut other_pairs_not_parallel) = (0, 0);
    for _ in 0..2000 {
        let p1 = Vector3::new(
            rng.random_range(1..10) as f64,
            rng.random_range(1..10) as f64,
            rng.random_range(0..3) as f64,
        );
        let k = rng.random_range(2..50) as f64 / [3.0, 7.0, 10.0][rng.random_range(0..3)];
        if k == 1.0 {
            continue; // a repeated point, not a line
        }
        let p = [Point3::origin(), Point3::from(p1), Point3::from(p1 * k)];
        let e = [p[1] - p[0], p[2] - p[1], p[0] - p[2]];
        if e[0].cross(&e[1]) != Vector3::zeros() {
            continue;
        }
        zero_area += 1;
        if e[1].cross(&e[2]) != Vector3::zeros() || e[2].cross(&e[0]) != Vector3::zeros() {
            other_pairs_not_parallel += 1;
        }
        let t = triangle_quality(p, &id);
        // The middle point: p1 when k > 1, p2 when k < 1.
        let mut expect = [0.0; 3];
        expect[if k > 1.0 { 1 } else { 2 }] = 180.0;
        assert_eq!((t.q, t.angles), (0.0, expect), "p1 {p1:?} k {k}");
    }
    assert!(
        zero_area > 100 && other_pairs_not_parallel > 20,
        "{zero_area} {other_pairs_not_parallel}"
    );
}
