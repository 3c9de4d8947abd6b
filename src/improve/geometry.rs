//! Geometric helpers of the surface passes.

use crate::ids::{FaceId, VertexId};
use crate::mesh::TriMesh;
use nalgebra::{Matrix3, Point3, Vector3};

/// The metric-optimal position of `v` (our addition, the anisotropic counterpart of the
/// centroid): for every face `(v, a, b)` of its fan the apex that makes the face equilateral
/// in the metric `m` at `v` (restricted to the fan's tangent plane), averaged over the fan.
/// `None` when the plane or the metric there is degenerate.
pub(crate) fn metric_optimal_point(
    mesh: &TriMesh,
    fan: &[FaceId],
    v: VertexId,
    m: &Matrix3<f64>,
) -> Option<Point3<f64>> {
    use nalgebra::{Matrix2, Vector2};
    let n = fan
        .iter()
        .fold(Vector3::zeros(), |acc, f| acc + mesh.face_normal_raw(*f))
        .try_normalize(1e-300)?;
    let e1 = n
        .cross(&Vector3::x())
        .try_normalize(1e-6)
        .or_else(|| n.cross(&Vector3::y()).try_normalize(1e-6))?;
    let e2 = n.cross(&e1);
    let m2 = Matrix2::new(
        e1.dot(&(m * e1)),
        e1.dot(&(m * e2)),
        e2.dot(&(m * e1)),
        e2.dot(&(m * e2)),
    );
    // Metric coordinates y = Lᵀx with M₂ = L Lᵀ (det L > 0 keeps orientations).
    let l = m2.cholesky()?.l();
    let lt = l.transpose();
    let lt_inv = lt.try_inverse()?;
    let o = mesh.positions[v.idx()];
    let to2 = |p: &Point3<f64>| lt * Vector2::new((p - o).dot(&e1), (p - o).dot(&e2));
    let mut sum = Vector2::zeros();
    for f in fan {
        let t = mesh.triangles[f.idx()];
        let k = t.iter().position(|u| *u == v)?;
        let (a, b) = (
            to2(&mesh.positions[t[(k + 1) % 3].idx()]),
            to2(&mesh.positions[t[(k + 2) % 3].idx()]),
        );
        // (p, a, b) counter-clockwise: p to the left of a → b.
        let d = b - a;
        sum += (a + b) * 0.5 + Vector2::new(-d.y, d.x) * (3f64.sqrt() / 2.0);
    }
    let x = lt_inv * (sum / fan.len() as f64);
    let p = o + e1 * x.x + e2 * x.y;
    p.coords.iter().all(|c| c.is_finite()).then_some(p)
}

/// Euclidean distance from `p` to the triangle `t` (parry's point-triangle projection).
pub(crate) fn point_triangle_distance(p: &Point3<f64>, t: &[Point3<f64>; 3]) -> f64 {
    use parry3d_f64::math::Vector as PVec;
    use parry3d_f64::query::PointQuery;
    let v = |x: &Point3<f64>| PVec::new(x.x, x.y, x.z);
    parry3d_f64::shape::Triangle::new(v(&t[0]), v(&t[1]), v(&t[2]))
        .distance_to_local_point(v(p), false)
}

/// Distance between the segments `ab` and `cd` (sampled closest-point iteration is not
/// needed: the exact minimum over the clamped parameters).
pub(crate) fn segment_distance(
    a: Point3<f64>,
    b: Point3<f64>,
    c: Point3<f64>,
    d: Point3<f64>,
) -> f64 {
    let (u, v, w) = (b - a, d - c, a - c);
    let (aa, bb, cc, dd, ee) = (u.dot(&u), u.dot(&v), v.dot(&v), u.dot(&w), v.dot(&w));
    let den = aa * cc - bb * bb;
    let mut s = if den > 1e-300 {
        ((bb * ee - cc * dd) / den).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = if cc > 0.0 { (bb * s + ee) / cc } else { 0.0 };
    if t < 0.0 {
        t = 0.0;
        s = if aa > 0.0 {
            (-dd / aa).clamp(0.0, 1.0)
        } else {
            0.0
        };
    } else if t > 1.0 {
        t = 1.0;
        s = if aa > 0.0 {
            ((bb - dd) / aa).clamp(0.0, 1.0)
        } else {
            0.0
        };
    }
    ((a + u * s) - (c + v * t)).norm()
}
