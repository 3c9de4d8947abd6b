//! Quality of a planar mesh in a metric (the yardstick of Sec. 4.1 applied in the plane).

use super::{Metric2d, PlanarMesh};
use nalgebra::{Matrix2, Point2};
use serde::Serialize;

/// Quality summary of a planar mesh under a metric.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlanarQuality {
    /// Vertex count.
    pub n_vertices: usize,
    /// Triangle count.
    pub n_faces: usize,
    /// Minimum of `q = 2√3·a / (p·h)` (Sec. 3.4) over the triangles mapped by the metric.
    pub q_min: f64,
    /// Mean of `q`.
    pub q_avg: f64,
    /// Smallest angle (degrees) of any mapped triangle.
    pub theta_min_deg: f64,
    /// Mean over triangles of each mapped triangle's smallest angle (degrees).
    pub theta_avg_deg: f64,
    /// Fraction of edges whose metric length (tensor at the edge midpoint) is in
    /// `[L/√2, √2·L]`.
    pub edges_in_range: f64,
    /// Mean metric edge length over L.
    pub edge_mean: f64,
}

/// The metric side lengths `[|p1p2|, |p2p0|, |p0p1|]` of a planar triangle in the tensor
/// `m`, and its quality `q = 2√3·a/(p·h)` (Sec. 3.4; 0 for a degenerate triangle).
pub(crate) fn sides_and_quality(p: &[Point2<f64>; 3], m: &Matrix2<f64>) -> ([f64; 3], f64) {
    let len = |u: usize, v: usize| {
        let e = p[v] - p[u];
        e.dot(&(m * e)).max(0.0).sqrt()
    };
    let l = [len(1, 2), len(2, 0), len(0, 1)];
    let area = 0.5 * (p[1] - p[0]).perp(&(p[2] - p[0])) * m.determinant().max(0.0).sqrt();
    let semi = 0.5 * (l[0] + l[1] + l[2]);
    let h = l[0].max(l[1]).max(l[2]);
    let q = if semi > 0.0 && h > 0.0 {
        2.0 * 3f64.sqrt() * area / (semi * h)
    } else {
        0.0
    };
    (l, q)
}

/// Measure `mesh` under `metric`: each triangle is mapped by the square root of the tensor at
/// its centroid (its edge lengths become `√(eᵀ M_c e)`), then `q`, its angles; each edge's
/// metric length uses the tensor at the edge midpoint.
pub fn planar_quality(
    mesh: &PlanarMesh,
    metric: &dyn Metric2d,
    target_length: f64,
) -> PlanarQuality {
    let (mut qmin, mut qsum, mut tmin, mut tsum) = (f64::INFINITY, 0.0, f64::INFINITY, 0.0);
    for t in &mesh.triangles {
        let p = t.map(|i| mesh.points[i as usize]);
        let c = Point2::from((p[0].coords + p[1].coords + p[2].coords) / 3.0);
        let m = metric.metric(&c);
        let (l, q) = sides_and_quality(&p, &m);
        // Smallest angle: opposite the shortest side, by the law of cosines.
        let th = (0..3)
            .map(|i| {
                let (a, b, c) = (l[i], l[(i + 1) % 3], l[(i + 2) % 3]);
                let cs = ((b * b + c * c - a * a) / (2.0 * b * c)).clamp(-1.0, 1.0);
                cs.acos().to_degrees()
            })
            .fold(f64::INFINITY, f64::min);
        qmin = qmin.min(q);
        qsum += q;
        tmin = tmin.min(th);
        tsum += th;
    }
    let mut edges: Vec<(u32, u32)> = mesh
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let lengths: Vec<f64> = edges
        .iter()
        .map(|(a, b)| {
            let (pa, pb) = (mesh.points[*a as usize], mesh.points[*b as usize]);
            let mid = Point2::from((pa.coords + pb.coords) * 0.5);
            let m = metric.metric(&mid);
            let e = pb - pa;
            e.dot(&(m * e)).max(0.0).sqrt() / target_length
        })
        .collect();
    let inr = lengths
        .iter()
        .filter(|l| (std::f64::consts::FRAC_1_SQRT_2..=std::f64::consts::SQRT_2).contains(*l))
        .count();
    let nf = mesh.triangles.len().max(1) as f64;
    PlanarQuality {
        n_vertices: mesh.points.len(),
        n_faces: mesh.triangles.len(),
        q_min: qmin,
        q_avg: qsum / nf,
        theta_min_deg: tmin,
        theta_avg_deg: tsum / nf,
        edges_in_range: inr as f64 / edges.len().max(1) as f64,
        edge_mean: lengths.iter().sum::<f64>() / lengths.len().max(1) as f64,
    }
}
