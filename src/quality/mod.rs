//! The yardstick (Sec. 4.1): per-triangle quality q and angles θ in the metric's isotropic
//! space, the Table-1 statistics, edge-length conformity to L_tar, approximation error
//! (Hausdorff / RMS) and flips against the input. One place for every measure, independent
//! of the remesher and of how the metric was obtained: every function takes the per-vertex
//! metric tensors as plain `Matrix3` arrays, so `conemesh eval`, the pipeline and the tests
//! all measure the same way.
//!
//! Units: lengths in whatever units the mesh and the metric share (eval normalises both to
//! the input's bounding-box diagonal 1); angles in degrees; percentages in 0..=100.

mod distance;
mod eval;

pub use distance::{approximation_error, flips, Distance};
pub use eval::{
    evaluate, EvalError, EvalOptions, EvalReport, EvalTimings, MeshSize, TargetLength, MAX_SAMPLES,
};

use crate::ids::{EdgeKey, VertexId};
use crate::mesh::TriMesh;
use nalgebra::{Matrix3, Point3, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};

/// The quality of one triangle in the isotropic space of a metric (Sec. 3.3 "Quality
/// evaluation", Sec. 4.1 (1)-(2)).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TriangleQuality {
    /// q = 2√3·a / (p·h) ∈ [0, 1]: a area, p semi-perimeter, h longest edge of the mapped
    /// triangle; 1 exactly for an equilateral mapped triangle, 0 for a degenerate one.
    pub q: f64,
    /// The three angles of the mapped triangle in degrees, at corners 0, 1, 2.
    pub angles: [f64; 3],
}

impl TriangleQuality {
    /// The smallest angle θ(t) of Sec. 4.1 (2), degrees.
    pub fn min_angle(&self) -> f64 {
        self.angles[0].min(self.angles[1]).min(self.angles[2])
    }

    /// The largest angle, degrees.
    pub fn max_angle(&self) -> f64 {
        self.angles[0].max(self.angles[1]).max(self.angles[2])
    }
}

/// Q = U Σ^½ Uᵀ, the symmetric square root of a symmetric positive semi-definite metric M
/// (Sec. 3.1: "Q implies the inverse transformation, which transforms anisotropic space to
/// isotropic space"). Eigen-decomposition rather than the paper's SVD: for a symmetric PSD
/// matrix they coincide, and the eigen form keeps Q symmetric even when M is rank 2 (the
/// curvature metric has eigenvalue 0 along the normal). Eigenvalues that round to a tiny
/// negative number are clamped to 0; M is symmetrised first so that a slightly asymmetric
/// input (file round-off) does not change the result.
pub fn metric_sqrt(m: &Matrix3<f64>) -> Matrix3<f64> {
    let sym = (m + m.transpose()) * 0.5;
    let eig = SymmetricEigen::new(sym);
    let s = eig.eigenvalues.map(|l| l.max(0.0).sqrt());
    eig.eigenvectors * Matrix3::from_diagonal(&s) * eig.eigenvectors.transpose()
}

/// Angle between two vectors in degrees, by `atan2(|u×v|, u·v)` (accurate near 0° and
/// 180°, unlike `acos`).
fn angle_deg(u: &Vector3<f64>, v: &Vector3<f64>) -> f64 {
    u.cross(v).norm().atan2(u.dot(v)).to_degrees()
}

/// Quality q and angles of the triangle `p` in the metric `m` (Sec. 3.3, Sec. 4.1).
///
/// The edges are mapped by Q = √M ([`metric_sqrt`]); the mapped triangle lives in 3D (M may
/// be rank 2, zero along the normal), so its area is ½|e₁×e₂| of the mapped edges. A mapped
/// triangle with a zero-length edge or zero area is reported as the worst possible:
/// q = 0 and angles [0°, 0°, 180°] (ordered so the 180° sits at the corner opposite the
/// longest edge when that is defined).
pub fn triangle_quality(p: [Point3<f64>; 3], m: &Matrix3<f64>) -> TriangleQuality {
    triangle_quality_with_sqrt(p, &metric_sqrt(m))
}

/// [`triangle_quality`] with Q = √M already computed.
pub fn triangle_quality_with_sqrt(p: [Point3<f64>; 3], q_t: &Matrix3<f64>) -> TriangleQuality {
    // Mapped edge vectors: e[i] goes from corner i to corner i+1.
    let e = [
        q_t * (p[1] - p[0]),
        q_t * (p[2] - p[1]),
        q_t * (p[0] - p[2]),
    ];
    let len = [e[0].norm(), e[1].norm(), e[2].norm()];
    let area = 0.5 * e[0].cross(&e[1]).norm();
    let h = len[0].max(len[1]).max(len[2]);
    let semi = 0.5 * (len[0] + len[1] + len[2]);
    let finite = area.is_finite() && h.is_finite();
    if !finite || len.contains(&0.0) || area == 0.0 {
        // Degenerate in the metric: the corner opposite the longest edge gets 180°.
        let mut angles = [0.0; 3];
        let opposite_longest = (0..3)
            .max_by(|&a, &b| len[(a + 1) % 3].total_cmp(&len[(b + 1) % 3]))
            .unwrap_or(0);
        angles[opposite_longest] = 180.0;
        return TriangleQuality { q: 0.0, angles };
    }
    // Sec. 4.1 (1): q = 2√3·a/(p·h).
    let q = (2.0 * 3f64.sqrt() * area / (semi * h)).min(1.0);
    // Angle at corner i between the outgoing edge e[i] and the reversed incoming edge.
    let angles = [
        angle_deg(&e[0], &(-e[2])),
        angle_deg(&e[1], &(-e[0])),
        angle_deg(&e[2], &(-e[1])),
    ];
    TriangleQuality { q, angles }
}

/// The q of [`triangle_quality`] from the metric's inner products of the edges (eᵢᵀ M eⱼ)
/// instead of the edges mapped by √M: the same number up to rounding (|Qa|² = aᵀMa, and
/// |Qa × Qb|² = |Qa|²|Qb|² − (Qa·Qb)² for the area), without the eigen-decomposition. The
/// surface passes score every candidate position and flip by it; what is reported is measured
/// by [`triangle_quality`].
pub fn triangle_q(p: [Point3<f64>; 3], m: &Matrix3<f64>) -> f64 {
    let e = [p[1] - p[0], p[2] - p[1], p[0] - p[2]];
    let dot = |a: &Vector3<f64>, b: &Vector3<f64>| 0.5 * (a.dot(&(m * b)) + b.dot(&(m * a)));
    let len = e.map(|x| dot(&x, &x).max(0.0).sqrt());
    let g01 = dot(&e[0], &e[1]);
    let area = 0.5
        * (len[0] * len[0] * len[1] * len[1] - g01 * g01)
            .max(0.0)
            .sqrt();
    let h = len[0].max(len[1]).max(len[2]);
    let semi = 0.5 * (len[0] + len[1] + len[2]);
    if !(area.is_finite() && h.is_finite()) || len.contains(&0.0) || area == 0.0 {
        return 0.0;
    }
    (2.0 * 3f64.sqrt() * area / (semi * h)).min(1.0)
}

/// M_t = (M₁ + M₂ + M₃)/3, the metric of a triangle (Sec. 3.3 "Vertex position update").
pub fn face_metric(vertex_metrics: &[Matrix3<f64>], f: [VertexId; 3]) -> Matrix3<f64> {
    (vertex_metrics[f[0].idx()] + vertex_metrics[f[1].idx()] + vertex_metrics[f[2].idx()]) / 3.0
}

/// Table-1 statistics of a mesh in a metric (Sec. 4.1), plus the percentages and histograms
/// used to compare with other remeshers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct QualityStats {
    /// Number of triangles measured.
    pub faces: usize,
    /// Smallest q over all triangles.
    pub q_min: f64,
    /// Largest q.
    pub q_max: f64,
    /// Mean q.
    pub q_avg: f64,
    /// Smallest angle anywhere (degrees).
    pub theta_min: f64,
    /// Largest angle anywhere (degrees).
    pub theta_max: f64,
    /// Mean over triangles of each triangle's smallest angle θ(t) (Table 1's θ_avg), degrees.
    pub theta_avg: f64,
    /// % of triangles whose smallest angle is < 10°.
    pub pct_min_angle_lt_10: f64,
    /// % of triangles whose smallest angle is < 20°.
    pub pct_min_angle_lt_20: f64,
    /// % of triangles whose smallest angle is < 30°.
    pub pct_min_angle_lt_30: f64,
    /// % of triangles whose largest angle is > 120°.
    pub pct_max_angle_gt_120: f64,
    /// Histogram of q: bin i counts q ∈ [i/10, (i+1)/10), q = 1 in the last bin.
    pub hist_q: [usize; 10],
    /// Histogram of all 3·F angles: bin i counts [10i°, 10(i+1)°), 180° in the last bin.
    pub hist_angles: [usize; 18],
    /// Histogram of each triangle's smallest angle, bins as `hist_angles`.
    pub hist_min_angles: [usize; 18],
}

fn bin(x: f64, width: f64, n: usize) -> usize {
    // NaN and negatives go to bin 0 (`as usize` saturates), values at the top edge to the
    // last. A value within 1e-9 bins below an edge counts in the upper bin, so that an
    // equilateral triangle's 60° (computed as 59.999999999999..°) is binned as 60°.
    ((x / width + 1e-9) as usize).min(n - 1)
}

/// Per-face quality in the metric M_t = mean of the three vertex metrics, in face order.
/// `vertex_metrics` is indexed by vertex id (length `mesh.n_vertices()`).
pub fn face_qualities(mesh: &TriMesh, vertex_metrics: &[Matrix3<f64>]) -> Vec<TriangleQuality> {
    mesh.faces()
        .map(|f| {
            let t = mesh.face(f);
            triangle_quality(mesh.face_points(f), &face_metric(vertex_metrics, t))
        })
        .collect()
}

/// The Table-1 statistics of `mesh` measured in the per-vertex metrics (Sec. 4.1).
///
/// Panics only if `vertex_metrics` is shorter than the vertex count (a caller bug, not a
/// data condition). A mesh without faces gives all-zero statistics.
pub fn quality_stats(mesh: &TriMesh, vertex_metrics: &[Matrix3<f64>]) -> QualityStats {
    stats_of(&face_qualities(mesh, vertex_metrics))
}

/// [`QualityStats`] of already computed per-face qualities.
pub fn stats_of(qs: &[TriangleQuality]) -> QualityStats {
    let n = qs.len();
    let mut s = QualityStats {
        faces: n,
        q_min: if n == 0 { 0.0 } else { f64::INFINITY },
        q_max: if n == 0 { 0.0 } else { f64::NEG_INFINITY },
        q_avg: 0.0,
        theta_min: if n == 0 { 0.0 } else { f64::INFINITY },
        theta_max: if n == 0 { 0.0 } else { f64::NEG_INFINITY },
        theta_avg: 0.0,
        pct_min_angle_lt_10: 0.0,
        pct_min_angle_lt_20: 0.0,
        pct_min_angle_lt_30: 0.0,
        pct_max_angle_gt_120: 0.0,
        hist_q: [0; 10],
        hist_angles: [0; 18],
        hist_min_angles: [0; 18],
    };
    if n == 0 {
        return s;
    }
    let (mut lt10, mut lt20, mut lt30, mut gt120) = (0usize, 0usize, 0usize, 0usize);
    for t in qs {
        let (lo, hi) = (t.min_angle(), t.max_angle());
        s.q_min = s.q_min.min(t.q);
        s.q_max = s.q_max.max(t.q);
        s.q_avg += t.q;
        s.theta_min = s.theta_min.min(lo);
        s.theta_max = s.theta_max.max(hi);
        s.theta_avg += lo;
        lt10 += usize::from(lo < 10.0);
        lt20 += usize::from(lo < 20.0);
        lt30 += usize::from(lo < 30.0);
        gt120 += usize::from(hi > 120.0);
        s.hist_q[bin(t.q, 0.1, 10)] += 1;
        for a in t.angles {
            s.hist_angles[bin(a, 10.0, 18)] += 1;
        }
        s.hist_min_angles[bin(lo, 10.0, 18)] += 1;
    }
    let nf = n as f64;
    s.q_avg /= nf;
    s.theta_avg /= nf;
    s.pct_min_angle_lt_10 = 100.0 * lt10 as f64 / nf;
    s.pct_min_angle_lt_20 = 100.0 * lt20 as f64 / nf;
    s.pct_min_angle_lt_30 = 100.0 * lt30 as f64 / nf;
    s.pct_max_angle_gt_120 = 100.0 * gt120 as f64 / nf;
    s
}

/// The unique undirected edges of a mesh, sorted (deterministic order).
pub fn unique_edges(mesh: &TriMesh) -> Vec<EdgeKey> {
    let mut edges: Vec<EdgeKey> = mesh
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |i| EdgeKey::new(t[i], t[(i + 1) % 3])))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}

/// Metric length √(eᵀ M e) of an edge, M = mean of its endpoint metrics (Sec. 4.1, edge
/// conformity as defined in the quality issue). A negative eᵀMe (metric not PSD) counts as 0.
pub fn edge_metric_length(mesh: &TriMesh, vertex_metrics: &[Matrix3<f64>], e: EdgeKey) -> f64 {
    let d = mesh.position(e.1) - mesh.position(e.0);
    let m = (vertex_metrics[e.0.idx()] + vertex_metrics[e.1.idx()]) * 0.5;
    d.dot(&(m * d)).max(0.0).sqrt()
}

/// L_avg: the mean metric length of the mesh's unique edges (Sec. 4.1, "1.5 L_avg" in
/// Table 1), each measured with the mean of its endpoint metrics. 0 for a mesh without edges.
pub fn edge_length_average(mesh: &TriMesh, vertex_metrics: &[Matrix3<f64>]) -> f64 {
    let edges = unique_edges(mesh);
    if edges.is_empty() {
        return 0.0;
    }
    edges
        .iter()
        .map(|&e| edge_metric_length(mesh, vertex_metrics, e))
        .sum::<f64>()
        / edges.len() as f64
}

/// How well the edges match the target length: statistics of metric length / L_tar.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Conformity {
    /// Mean of L/L_tar.
    pub mean: f64,
    /// Standard deviation (population) of L/L_tar.
    pub std: f64,
    /// Median of L/L_tar (mean of the two middle values for an even count).
    pub median: f64,
    /// Fraction (0..=1) of edges with L/L_tar in [1/√2, √2].
    pub fraction_in_range: f64,
    /// Number of unique edges measured.
    pub edges: usize,
}

/// Edge-length conformity of `mesh` to the target length `l_tar` in the per-vertex metrics:
/// each unique edge measured by [`edge_metric_length`], divided by `l_tar`.
pub fn edge_conformity(mesh: &TriMesh, vertex_metrics: &[Matrix3<f64>], l_tar: f64) -> Conformity {
    edge_conformity_where(mesh, vertex_metrics, l_tar, |_| true)
}

/// [`edge_conformity`] over the unique edges for which `keep` holds.
pub fn edge_conformity_where(
    mesh: &TriMesh,
    vertex_metrics: &[Matrix3<f64>],
    l_tar: f64,
    keep: impl Fn(EdgeKey) -> bool,
) -> Conformity {
    let mut r: Vec<f64> = unique_edges(mesh)
        .into_iter()
        .filter(|e| keep(*e))
        .map(|e| edge_metric_length(mesh, vertex_metrics, e) / l_tar)
        .collect();
    let n = r.len();
    if n == 0 {
        return Conformity {
            mean: 0.0,
            std: 0.0,
            median: 0.0,
            fraction_in_range: 0.0,
            edges: 0,
        };
    }
    let nf = n as f64;
    let mean = r.iter().sum::<f64>() / nf;
    let std = (r.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / nf).sqrt();
    let (lo, hi) = (std::f64::consts::FRAC_1_SQRT_2, std::f64::consts::SQRT_2);
    let in_range = r.iter().filter(|&&x| (lo..=hi).contains(&x)).count();
    r.sort_unstable_by(f64::total_cmp);
    let median = if n % 2 == 1 {
        r[n / 2]
    } else {
        0.5 * (r[n / 2 - 1] + r[n / 2])
    };
    Conformity {
        mean,
        std,
        median,
        fraction_in_range: in_range as f64 / nf,
        edges: n,
    }
}

#[cfg(test)]
mod tests {

    /// The inner-product q equals the √M one up to rounding, on random triangles in random
    /// full-rank and rank-2 metrics (the curvature metric is rank 2) and on degenerate ones.
    #[test]
    fn inner_product_q_matches_the_mapped_q() {
        use rand::{Rng, SeedableRng};
        let mut rng = crate::Rng::seed_from_u64(7);
        let mut r = || rng.random_range(-1.0..1.0);
        for k in 0..2000 {
            let p = [0, 1, 2].map(|_| Point3::new(r(), r(), r()));
            let a = nalgebra::Matrix3::from_fn(|_, _| r());
            let mut m = a * a.transpose();
            if k % 2 == 0 {
                // Rank 2: zero along a random direction.
                let n = Vector3::new(r(), r(), r()).normalize();
                let proj = nalgebra::Matrix3::identity() - n * n.transpose();
                m = proj * m * proj;
            }
            let want = super::triangle_quality(p, &m).q;
            let got = super::triangle_q(p, &m);
            assert!((want - got).abs() <= 1e-9, "case {k}: {want} vs {got}");
        }
        let flat = [
            Point3::origin(),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
        ];
        assert_eq!(super::triangle_q(flat, &nalgebra::Matrix3::identity()), 0.0);
    }
    use super::*;

    #[test]
    fn right_isoceles_triangle_has_known_quality() {
        // Legs 1, hypotenuse √2: a = 1/2, p = (2+√2)/2, h = √2.
        let p = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ];
        let t = triangle_quality(p, &Matrix3::identity());
        let expect = 2.0 * 3f64.sqrt() * 0.5 / ((2.0 + 2f64.sqrt()) / 2.0 * 2f64.sqrt());
        assert!((t.q - expect).abs() < 1e-14, "{} vs {expect}", t.q);
        assert!((t.angles[0] - 90.0).abs() < 1e-12);
        assert!((t.angles[1] - 45.0).abs() < 1e-12);
        assert!((t.angles[2] - 45.0).abs() < 1e-12);
    }

    #[test]
    fn degenerate_triangle_is_worst() {
        let p = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
        ];
        let t = triangle_quality(p, &Matrix3::identity());
        assert_eq!(t.q, 0.0);
        assert_eq!(t.angles, [0.0, 180.0, 0.0]);
        // A metric that kills the triangle's plane (rank 1 along z) also degenerates it.
        let m = Matrix3::from_diagonal(&Vector3::new(0.0, 0.0, 1.0));
        let p2 = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ];
        assert_eq!(triangle_quality(p2, &m).q, 0.0);
    }

    #[test]
    fn histogram_bins_close_at_the_top() {
        assert_eq!(bin(1.0, 0.1, 10), 9);
        assert_eq!(bin(0.0, 0.1, 10), 0);
        assert_eq!(bin(180.0, 10.0, 18), 17);
        assert_eq!(bin(59.999, 10.0, 18), 5);
        assert_eq!(bin(f64::NAN, 10.0, 18), 0);
    }

    #[test]
    fn conformity_median_and_range() {
        // Unit right triangle, identity metric: edges 1, 1, √2.
        let m = TriMesh::from_indices(
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
            ],
            &[[0, 1, 2]],
        )
        .expect("triangle");
        let id = vec![Matrix3::identity(); 3];
        let lavg = edge_length_average(&m, &id);
        assert!((lavg - (2.0 + 2f64.sqrt()) / 3.0).abs() < 1e-14);
        let c = edge_conformity(&m, &id, 1.0);
        assert_eq!(c.edges, 3);
        assert_eq!(c.median, 1.0);
        // √2 is in range (closed interval) up to rounding of √2 itself.
        assert!((c.fraction_in_range - 1.0).abs() < 1e-15);
        let c2 = edge_conformity(&m, &id, 0.5);
        assert_eq!(c2.fraction_in_range, 0.0);
    }
}
