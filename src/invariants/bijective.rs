//! Certificate of a bijective 2D map of a disk (Sec. 3.3, "embedded one-to-one into the
//! plane"; claim (II) of the paper's introduction).
//!
//! Why these tests suffice: a piecewise-linear map of a triangulated disk whose triangles
//! are all positively oriented covers every point of the plane (off the image edges) exactly
//! as many times as the image of the boundary loop winds around it (degree argument). If the
//! boundary polygon is simple and counter-clockwise that winding number is 1 inside and 0
//! outside, so the map is a bijection onto the polygon's interior. All sign decisions are
//! exact (`crate::predicates`), so the certificate has no tolerance.

use super::{DirectedEdge, InvariantError, MapDefect, Offenders};
use crate::ids::{FaceId, VertexId};
use crate::predicates::{orient2d, segments_intersect, SegmentIntersection, Sign};
use nalgebra::Point2;
use std::fmt;

/// A pair of boundary edges given by their start vertices along the loop, printed
/// `(v3, v4)×(v10, v11)`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct EdgePair(pub [VertexId; 2], pub [VertexId; 2]);

impl fmt::Display for EdgePair {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "({}, {})×({}, {})",
            self.0[0], self.0[1], self.1[0], self.1[1]
        )
    }
}

fn not_bijective(defect: MapDefect) -> InvariantError {
    InvariantError::NotBijective(defect)
}

/// Faces whose image is not strictly counter-clockwise (exact `orient2d`).
pub fn non_positive_faces(uv: &[Point2<f64>], triangles: &[[VertexId; 3]]) -> Vec<FaceId> {
    triangles
        .iter()
        .enumerate()
        .filter(|(_, t)| {
            orient2d(&uv[t[0].idx()], &uv[t[1].idx()], &uv[t[2].idx()]) != Sign::Positive
        })
        .map(|(i, _)| FaceId::new(i))
        .collect()
}

/// Certify that `uv` maps the disk `triangles` (with boundary loop `boundary`, surface on the
/// left) bijectively into the plane:
/// 1. every triangle is positively oriented (exact `orient2d > 0`);
/// 2. `boundary` is the boundary of `triangles` (each loop edge is a triangle half-edge with
///    no opposite), each vertex once;
/// 3. the boundary polygon is simple: no two non-adjacent boundary edges meet (exact
///    segment tests after a sort-and-sweep broad phase on x-intervals) and no two adjacent
///    edges fold back onto each other;
/// 4. the boundary loop is counter-clockwise.
///
/// Errors name the faces or boundary edges that break a rule.
pub fn certify_bijective(
    uv: &[Point2<f64>],
    triangles: &[[VertexId; 3]],
    boundary: &[VertexId],
) -> Result<(), InvariantError> {
    let n = uv.len();
    if let Some(t) = triangles.iter().find(|t| t.iter().any(|v| v.idx() >= n)) {
        return Err(not_bijective(MapDefect::TriangleWithoutUv {
            triangle: *t,
            positions: n,
        }));
    }
    if let Some(v) = boundary.iter().find(|v| v.idx() >= n) {
        return Err(not_bijective(MapDefect::BoundaryWithoutUv {
            vertex: *v,
            positions: n,
        }));
    }
    if let Some(p) = uv
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite()))
    {
        return Err(not_bijective(MapDefect::NonFiniteAt(VertexId::new(p))));
    }
    // 1. Orientation of every triangle.
    let bad = non_positive_faces(uv, triangles);
    if !bad.is_empty() {
        return Err(not_bijective(MapDefect::NonPositive(Offenders(bad))));
    }
    // 2. The loop is the mesh boundary.
    let m = boundary.len();
    if m < 3 {
        return Err(not_bijective(MapDefect::ShortLoop(m)));
    }
    let mut seen = vec![false; n];
    for &v in boundary {
        if std::mem::replace(&mut seen[v.idx()], true) {
            return Err(not_bijective(MapDefect::LoopRevisits(v)));
        }
    }
    let mut half_edges: Vec<(u32, u32)> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |i| (t[i].0, t[(i + 1) % 3].0)))
        .collect();
    half_edges.sort_unstable();
    let has = |a: u32, b: u32| half_edges.binary_search(&(a, b)).is_ok();
    for i in 0..m {
        let (a, b) = (boundary[i], boundary[(i + 1) % m]);
        if !has(a.0, b.0) || has(b.0, a.0) {
            return Err(not_bijective(MapDefect::NotABoundaryEdge(DirectedEdge(
                a, b,
            ))));
        }
    }
    let n_boundary_half_edges = half_edges.iter().filter(|&&(a, b)| !has(b, a)).count();
    if n_boundary_half_edges != m {
        return Err(not_bijective(MapDefect::BoundaryEdgeCount {
            triangles: n_boundary_half_edges,
            loop_edges: m,
        }));
    }
    certify_embedding_geometry(uv, boundary)
}

/// Steps 3 and 4 of [`certify_bijective`] (after step 1 on the triangles) for a caller that
/// has already checked that `boundary` is the boundary loop of its triangles and that every
/// index is in range: the optimiser's line search, where only positions change.
pub(crate) fn certify_map_of_known_disk(
    uv: &[Point2<f64>],
    triangles: &[[VertexId; 3]],
    boundary: &[VertexId],
) -> Result<(), InvariantError> {
    if uv.iter().any(|p| !(p.x.is_finite() && p.y.is_finite())) {
        return Err(not_bijective(MapDefect::NonFinite));
    }
    let bad = non_positive_faces(uv, triangles);
    if !bad.is_empty() {
        return Err(not_bijective(MapDefect::NonPositive(Offenders(bad))));
    }
    certify_embedding_geometry(uv, boundary)
}

/// Simple, counter-clockwise boundary polygon (steps 3 and 4); `boundary.len() ≥ 3`.
fn certify_embedding_geometry(
    uv: &[Point2<f64>],
    boundary: &[VertexId],
) -> Result<(), InvariantError> {
    let m = boundary.len();
    // 3. Simple boundary polygon.
    let p = |i: usize| &uv[boundary[i % m].idx()];
    let edge = |i: usize| [boundary[i % m], boundary[(i + 1) % m]];
    let mut crossings = Vec::new();
    // Adjacent edges (i-1, i) and (i, i+1) share vertex i; they overlap only when collinear
    // and folded back (the next vertex lies on the ray towards the previous one).
    for i in 0..m {
        let (a, b, c) = (p(i + m - 1), p(i), p(i + 1));
        if orient2d(a, b, c) == Sign::Zero {
            let same_side = |x: f64, y: f64, z: f64| (x - y).signum() == (z - y).signum();
            let folded = if a.x != b.x || c.x != b.x {
                same_side(a.x, b.x, c.x) && a.x != b.x && c.x != b.x
            } else {
                same_side(a.y, b.y, c.y)
            };
            if folded {
                crossings.push(EdgePair(edge(i + m - 1), edge(i)));
            }
        }
    }
    // Sort-and-sweep on x-intervals; exact test for pairs whose boxes overlap.
    let boxes: Vec<[f64; 4]> = (0..m)
        .map(|i| {
            let (a, b) = (p(i), p(i + 1));
            [a.x.min(b.x), a.x.max(b.x), a.y.min(b.y), a.y.max(b.y)]
        })
        .collect();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_unstable_by(|&i, &j| boxes[i][0].total_cmp(&boxes[j][0]));
    for (k, &i) in order.iter().enumerate() {
        for &j in &order[k + 1..] {
            if boxes[j][0] > boxes[i][1] {
                break;
            }
            let d = (i + m - j) % m;
            if d <= 1 || d == m - 1 {
                continue; // same or adjacent edge, handled above
            }
            if boxes[j][2] > boxes[i][3] || boxes[i][2] > boxes[j][3] {
                continue;
            }
            if segments_intersect(p(i), p(i + 1), p(j), p(j + 1)) != SegmentIntersection::Disjoint {
                let (lo, hi) = (i.min(j), i.max(j));
                crossings.push(EdgePair(edge(lo), edge(hi)));
            }
        }
    }
    if !crossings.is_empty() {
        return Err(not_bijective(MapDefect::NotSimple(Offenders(crossings))));
    }
    // 4. Counter-clockwise: at the lexicographically lowest vertex of a simple polygon the
    // turn (prev, it, next) has the orientation of the polygon.
    let low = (0..m)
        .min_by(|&i, &j| {
            let (a, b) = (p(i), p(j));
            a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y))
        })
        .unwrap_or(0);
    if orient2d(p(low + m - 1), p(low), p(low + 1)) != Sign::Positive {
        return Err(not_bijective(MapDefect::Clockwise(boundary[low])));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(i: u32) -> VertexId {
        VertexId(i)
    }

    /// A square fan: centre 4, corners 0..4 counter-clockwise.
    fn square() -> (Vec<Point2<f64>>, Vec<[VertexId; 3]>, Vec<VertexId>) {
        let uv = vec![
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(1.0, 1.0),
            Point2::new(0.0, 1.0),
            Point2::new(0.5, 0.5),
        ];
        let tris = (0..4).map(|i| [v(i), v((i + 1) % 4), v(4)]).collect();
        (uv, tris, (0..4).map(v).collect())
    }

    #[test]
    fn square_fan_is_certified() {
        let (uv, t, b) = square();
        certify_bijective(&uv, &t, &b).unwrap();
    }

    #[test]
    fn flipped_triangle_is_named() {
        let (mut uv, t, b) = square();
        uv[4] = Point2::new(1.5, 0.5); // centre outside: f1 (1,2,4) becomes clockwise
        let e = certify_bijective(&uv, &t, &b).unwrap_err();
        assert_eq!(
            e,
            InvariantError::NotBijective(MapDefect::NonPositive(Offenders(vec![FaceId(1)])))
        );
        // Exactly collinear corners are rejected too (degenerate, not positive).
        uv[4] = Point2::new(1.0, 0.5);
        let e = certify_bijective(&uv, &t, &b).unwrap_err();
        assert!(
            matches!(&e, InvariantError::NotBijective(MapDefect::NonPositive(f)) if f.0.contains(&FaceId(1))),
            "{e}"
        );
    }

    #[test]
    fn wrong_loop_is_rejected() {
        let (uv, t, mut b) = square();
        b.reverse();
        assert!(certify_bijective(&uv, &t, &b).is_err());
    }
}
