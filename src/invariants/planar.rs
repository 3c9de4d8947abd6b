//! Certificate of a planar remeshing result (Sec. 3.3): the output triangulates exactly the
//! input polygon, with the boundary loop and constrained edges kept bit for bit.

use super::{DirectedEdge, InputVertex, InvariantError, Offenders, PlanarDefect};
use crate::ids::{FaceId, VertexId};
use crate::mesh::{PlanarDomain, PlanarMesh};
use crate::predicates::{orient2d, Sign};
use nalgebra::Point2;
use std::collections::HashMap;

fn invalid(defect: PlanarDefect) -> InvariantError {
    InvariantError::PlanarInvalid(defect)
}

/// The vertex with index `i` of a planar mesh or domain.
fn v(i: u32) -> VertexId {
    VertexId(i)
}

/// The edge `a → b` of a planar mesh or domain.
fn edge(a: u32, b: u32) -> DirectedEdge {
    DirectedEdge(v(a), v(b))
}

/// Twice the signed area of a polygon (shoelace; floating point).
fn polygon_area2(pts: &[Point2<f64>]) -> f64 {
    let n = pts.len();
    (0..n)
        .map(|i| {
            let (a, b) = (pts[i], pts[(i + 1) % n]);
            a.x * b.y - a.y * b.x
        })
        .sum()
}

/// Exact point-in-polygon: `Some(true)` strictly inside, `Some(false)` strictly outside,
/// `None` on the boundary. Crossing number along the ray to +x, with every side decision
/// taken by [`orient2d`] and half-open edges (an edge counts when exactly one endpoint is
/// strictly above `p`).
pub fn point_in_polygon(poly: &[Point2<f64>], p: &Point2<f64>) -> Option<bool> {
    crossing_test(poly, 0..poly.len(), p)
}

/// [`point_in_polygon`] over the edges `edges` (edge `i` runs from `poly[i]` to the next
/// corner): the same verdict whenever `edges` holds every edge whose y-range contains `p.y`.
fn crossing_test(
    poly: &[Point2<f64>],
    edges: impl IntoIterator<Item = usize>,
    p: &Point2<f64>,
) -> Option<bool> {
    let n = poly.len();
    let mut inside = false;
    for i in edges {
        let (a, b) = (&poly[i], &poly[(i + 1) % n]);
        let o = orient2d(a, b, p);
        if o == Sign::Zero
            && p.x >= a.x.min(b.x)
            && p.x <= a.x.max(b.x)
            && p.y >= a.y.min(b.y)
            && p.y <= a.y.max(b.y)
        {
            return None;
        }
        if (a.y > p.y) != (b.y > p.y) {
            // The edge straddles the horizontal line through p; it crosses the ray to the right
            // when p is left of the upward-directed edge.
            let left = if b.y > a.y {
                o == Sign::Positive
            } else {
                o == Sign::Negative
            };
            if left {
                inside = !inside;
            }
        }
    }
    Some(inside)
}

/// [`point_in_polygon`] for many points: the polygon's edges bucketed by horizontal slabs of
/// their y-range, so a point meets only the edges of its slab (the only ones the crossing test
/// counts, or that can hold the point) instead of all of them. Same verdicts, exact.
pub struct PolygonSlabs<'a> {
    poly: &'a [Point2<f64>],
    y0: f64,
    height: f64,
    slabs: Vec<Vec<usize>>,
}

impl<'a> PolygonSlabs<'a> {
    /// Index `poly` (finite corners).
    pub fn new(poly: &'a [Point2<f64>]) -> PolygonSlabs<'a> {
        let n = poly.len();
        let (lo, hi) = poly
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), q| {
                (l.min(q.y), h.max(q.y))
            });
        let k = n.max(1);
        let height = if hi > lo { (hi - lo) / k as f64 } else { 1.0 };
        let mut index = PolygonSlabs {
            poly,
            y0: lo,
            height,
            slabs: vec![Vec::new(); k],
        };
        for i in 0..n {
            let (a, b) = (poly[i].y, poly[(i + 1) % n].y);
            let (from, to) = (index.slab(a.min(b)), index.slab(a.max(b)));
            for slab in &mut index.slabs[from..=to] {
                slab.push(i);
            }
        }
        index
    }

    /// The slab holding height `y`, clamped to the polygon's range (a rounding of the slab
    /// arithmetic at most moves a boundary value to a neighbouring slab, so the edges are
    /// registered one slab wider on each side).
    fn slab(&self, y: f64) -> usize {
        let k = ((y - self.y0) / self.height).floor();
        (k.max(0.0) as usize).min(self.slabs.len().max(1) - 1)
    }

    /// [`point_in_polygon`] of `p`.
    pub fn contains(&self, p: &Point2<f64>) -> Option<bool> {
        if self.slabs.is_empty() {
            return point_in_polygon(self.poly, p);
        }
        let k = self.slab(p.y);
        // The neighbours too: an edge ending exactly on a slab boundary.
        let lo = k.saturating_sub(1);
        let hi = (k + 1).min(self.slabs.len() - 1);
        let mut edges: Vec<usize> = self.slabs[lo..=hi].iter().flatten().copied().collect();
        edges.sort_unstable();
        edges.dedup();
        crossing_test(self.poly, edges, p)
    }
}

/// Certify a planar remesh `out` of `domain` (Sec. 3.3, invariants of the LCT remesher):
///
/// 1. indices in range, coordinates finite, `origin` has one entry per point, every point used;
/// 2. every triangle positive by exact [`orient2d`];
/// 3. every boundary vertex of `domain` and every endpoint of a constrained edge appears in `out`
///    through `origin`, at a bit-identical position (and every `origin` entry is bit-identical);
/// 4. every edge has one or two faces, interior edges are traversed once each way, and the
///    boundary half-edges of `out` are exactly the images of the domain's boundary loop
///    (so `out`'s boundary is that loop, in the same order);
/// 5. every constrained edge is an edge of `out`;
/// 6. `out` is a disk: `V − E + F = 1` (with (4), one boundary loop);
/// 7. total area equals the polygon's up to a relative 1e-9 (floating point sums);
/// 8. every other vertex lies strictly inside the polygon (exact, [`point_in_polygon`]).
///
/// (2) and (4) together already imply an exact tiling of the polygon: a positively oriented
/// 2-chain whose boundary is a simple loop covers its inside exactly once.
pub fn certify_planar(domain: &PlanarDomain, out: &PlanarMesh) -> Result<(), InvariantError> {
    let np = points_and_orientation(out)?;
    let image = kept_vertices(domain, out)?;
    let he = half_edges(out)?;
    let (expected, n_boundary) = boundary_loop_kept(domain, &image, &he)?;
    constrained_edges_kept(domain, &image, &he)?;
    euler_disk(out, np, he.len() + n_boundary)?;
    let poly: Vec<Point2<f64>> = domain
        .boundary
        .iter()
        .map(|&b| domain.points[b as usize])
        .collect();
    area_kept(&poly, out)?;
    interior_inside(&poly, out, &expected)
}

/// Checks (1) and (2): `origin` one entry per point, coordinates finite, indices in range,
/// every triangle positive. The number of points.
fn points_and_orientation(out: &PlanarMesh) -> Result<usize, InvariantError> {
    let np = out.points.len();
    if out.origin.len() != np {
        return Err(invalid(PlanarDefect::OriginCount {
            points: np,
            origins: out.origin.len(),
        }));
    }
    if let Some(i) = out
        .points
        .iter()
        .position(|p| !p.x.is_finite() || !p.y.is_finite())
    {
        return Err(invalid(PlanarDefect::NonFinitePoint(VertexId::new(i))));
    }
    if let Some(f) = out
        .triangles
        .iter()
        .position(|t| t.iter().any(|&i| i as usize >= np))
    {
        return Err(invalid(PlanarDefect::VertexOutOfRange(FaceId::new(f))));
    }
    // (2) orientation.
    let bad: Vec<FaceId> = out
        .triangles
        .iter()
        .enumerate()
        .filter(|(_, t)| {
            let [a, b, c] = t.map(|i| out.points[i as usize]);
            orient2d(&a, &b, &c) != Sign::Positive
        })
        .map(|(f, _)| FaceId::new(f))
        .collect();
    if !bad.is_empty() {
        return Err(invalid(PlanarDefect::NonPositive(Offenders(bad))));
    }
    Ok(np)
}

/// Check (3): every kept vertex at its bit-identical input position, once. Input vertex →
/// output vertex.
fn kept_vertices(
    domain: &PlanarDomain,
    out: &PlanarMesh,
) -> Result<HashMap<u32, u32>, InvariantError> {
    // (3) kept vertices.
    let mut image: HashMap<u32, u32> = HashMap::new();
    for (i, o) in out.origin.iter().enumerate() {
        if let Some(j) = *o {
            let q = domain.points.get(j as usize).ok_or_else(|| {
                invalid(PlanarDefect::UnknownOrigin {
                    vertex: VertexId::new(i),
                    origin: v(j),
                })
            })?;
            let p = out.points[i];
            if p.x.to_bits() != q.x.to_bits() || p.y.to_bits() != q.y.to_bits() {
                return Err(invalid(PlanarDefect::Moved {
                    vertex: VertexId::new(i),
                    input: v(j),
                    at: [p.x, p.y],
                    expected: [q.x, q.y],
                }));
            }
            if image.insert(j, i as u32).is_some() {
                return Err(invalid(PlanarDefect::InputTwice(v(j))));
            }
        }
    }
    let mut kept: Vec<u32> = domain.boundary.clone();
    kept.extend(domain.constrained_edges.iter().flatten());
    let missing: Vec<InputVertex> = kept
        .iter()
        .filter(|j| !image.contains_key(j))
        .map(|&j| InputVertex(v(j)))
        .collect();
    if !missing.is_empty() {
        return Err(invalid(PlanarDefect::KeptMissing(Offenders(missing))));
    }
    Ok(image)
}

/// Check (4), first half: every directed half-edge once. Half-edge → its face.
fn half_edges(out: &PlanarMesh) -> Result<HashMap<(u32, u32), u32>, InvariantError> {
    let mut he: HashMap<(u32, u32), u32> = HashMap::with_capacity(out.triangles.len() * 3);
    for (f, t) in out.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if he.insert((a, b), f as u32).is_some() {
                return Err(invalid(PlanarDefect::HalfEdgeTwice {
                    edge: edge(a, b),
                    face: FaceId::new(f),
                }));
            }
        }
    }
    Ok(he)
}

/// Check (4), second half: the output's boundary half-edges are exactly the images of the
/// domain's loop. Those images in loop order, and the number of boundary half-edges.
fn boundary_loop_kept(
    domain: &PlanarDomain,
    image: &HashMap<u32, u32>,
    he: &HashMap<(u32, u32), u32>,
) -> Result<(Vec<(u32, u32)>, usize), InvariantError> {
    let boundary_he: Vec<(u32, u32)> = he
        .keys()
        .filter(|(a, b)| !he.contains_key(&(*b, *a)))
        .copied()
        .collect();
    let nb = domain.boundary.len();
    let mut expected = Vec::with_capacity(nb);
    for k in 0..nb {
        let (a, b) = (domain.boundary[k], domain.boundary[(k + 1) % nb]);
        // Both are in `image` (checked above).
        let (ia, ib) = (image[&a], image[&b]);
        if !he.contains_key(&(ia, ib)) || he.contains_key(&(ib, ia)) {
            return Err(invalid(PlanarDefect::BoundaryEdgeLost {
                input: edge(a, b),
                output: edge(ia, ib),
            }));
        }
        expected.push((ia, ib));
    }
    if boundary_he.len() != expected.len() {
        let mut extra: Vec<(u32, u32)> = boundary_he
            .iter()
            .filter(|e| !expected.contains(e))
            .copied()
            .collect();
        extra.sort_unstable();
        return Err(invalid(PlanarDefect::ExtraBoundaryEdges {
            output: boundary_he.len(),
            input: expected.len(),
            extra: Offenders(extra.iter().map(|&(a, b)| edge(a, b)).collect()),
        }));
    }
    Ok((expected, boundary_he.len()))
}

/// Check (5): every constrained edge is an edge of the output.
fn constrained_edges_kept(
    domain: &PlanarDomain,
    image: &HashMap<u32, u32>,
    he: &HashMap<(u32, u32), u32>,
) -> Result<(), InvariantError> {
    for &[a, b] in &domain.constrained_edges {
        let (ia, ib) = (image[&a], image[&b]);
        if !he.contains_key(&(ia, ib)) && !he.contains_key(&(ib, ia)) {
            return Err(invalid(PlanarDefect::ConstrainedEdgeMissing {
                input: edge(a, b),
                output: edge(ia, ib),
            }));
        }
    }
    Ok(())
}

/// Check (6): every point used, and `V − E + F = 1`; `half_edges` is the output's half-edges
/// plus its boundary half-edges once more, so twice its edges.
fn euler_disk(out: &PlanarMesh, np: usize, half_edges: usize) -> Result<(), InvariantError> {
    // (6) disk: every point used, V − E + F = 1.
    let mut used = vec![false; np];
    for t in &out.triangles {
        for &i in t {
            used[i as usize] = true;
        }
    }
    if let Some(i) = used.iter().position(|u| !u) {
        return Err(invalid(PlanarDefect::UnusedVertex(VertexId::new(i))));
    }
    let n_edges = half_edges / 2;
    let chi = np as i64 - n_edges as i64 + out.triangles.len() as i64;
    if chi != 1 {
        return Err(InvariantError::NotADisk(super::DiskDefect::euler(
            np,
            n_edges,
            out.triangles.len(),
        )));
    }
    Ok(())
}

/// Check (7): the total area equals the polygon's `poly` up to a relative 1e-9.
fn area_kept(poly: &[Point2<f64>], out: &PlanarMesh) -> Result<(), InvariantError> {
    // (7) area.
    let a_poly = 0.5 * polygon_area2(poly);
    let a_out: f64 = out
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| out.points[i as usize]);
            0.5 * (b - a).perp(&(c - a))
        })
        .sum();
    // Written so that a NaN area fails too.
    let area_ok = (a_out - a_poly).abs() <= 1e-9 * a_poly.abs();
    if !area_ok {
        return Err(invalid(PlanarDefect::Area {
            area: a_out,
            polygon: a_poly,
        }));
    }
    Ok(())
}

/// Check (8): every vertex off the loop `boundary` lies strictly inside the polygon `poly`.
fn interior_inside(
    poly: &[Point2<f64>],
    out: &PlanarMesh,
    boundary: &[(u32, u32)],
) -> Result<(), InvariantError> {
    let np = out.points.len();
    // (8) interior vertices strictly inside.
    let on_loop: std::collections::HashSet<u32> = boundary.iter().map(|e| e.0).collect();
    let slabs = PolygonSlabs::new(poly);
    let outside: Vec<VertexId> = (0..np as u32)
        .filter(|i| !on_loop.contains(i))
        .filter(|&i| slabs.contains(&out.points[i as usize]) != Some(true))
        .map(v)
        .collect();
    if !outside.is_empty() {
        return Err(invalid(PlanarDefect::Outside(Offenders(outside))));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> PlanarDomain {
        PlanarDomain {
            points: vec![
                Point2::new(0.0, 0.0),
                Point2::new(1.0, 0.0),
                Point2::new(1.0, 1.0),
                Point2::new(0.0, 1.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            boundary: vec![0, 1, 2, 3],
            constrained_edges: vec![],
        }
    }

    fn with_center(c: Point2<f64>) -> PlanarMesh {
        let d = square();
        let mut points = d.points.clone();
        points.push(c);
        PlanarMesh {
            points,
            triangles: vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]],
            origin: vec![Some(0), Some(1), Some(2), Some(3), None],
        }
    }

    #[test]
    fn accepts_valid_remesh() -> Result<(), InvariantError> {
        certify_planar(&square(), &with_center(Point2::new(0.3, 0.6)))
    }

    #[test]
    fn rejects_moved_boundary_vertex() {
        let mut m = with_center(Point2::new(0.5, 0.5));
        m.points[2].x = 1.0 + f64::EPSILON;
        let e = certify_planar(&square(), &m);
        assert!(
            matches!(
                e,
                Err(InvariantError::PlanarInvalid(PlanarDefect::Moved {
                    vertex: VertexId(2),
                    input: VertexId(2),
                    ..
                }))
            ),
            "{e:?}"
        );
    }

    #[test]
    fn rejects_flipped_and_outside() {
        // The center outside: some triangle turns clockwise.
        let m = with_center(Point2::new(1.5, 0.5));
        let e = certify_planar(&square(), &m);
        assert!(
            matches!(
                e,
                Err(InvariantError::PlanarInvalid(PlanarDefect::NonPositive(_)))
            ),
            "{e:?}"
        );
        // The center on the boundary: a degenerate triangle.
        let m = with_center(Point2::new(1.0, 0.5));
        assert!(certify_planar(&square(), &m).is_err());
    }

    #[test]
    fn rejects_missing_boundary_edge() {
        // Triangles of another square order: boundary loop (0, 1, 3, 2) is not the input loop.
        let mut m = with_center(Point2::new(0.5, 0.5));
        m.triangles.pop();
        let e = certify_planar(&square(), &m);
        assert!(
            matches!(
                e,
                Err(InvariantError::PlanarInvalid(
                    PlanarDefect::BoundaryEdgeLost {
                        input: DirectedEdge(VertexId(3), VertexId(0)),
                        ..
                    }
                ))
            ),
            "{e:?}"
        );
    }

    #[test]
    fn slabs_agree_with_the_plain_crossing_test() {
        use rand::{Rng, SeedableRng};
        let mut rng = crate::Rng::seed_from_u64(3);
        for case in 0..200 {
            // A star-shaped polygon, some corners on a coarse grid so that points hit corners,
            // edges and slab boundaries exactly.
            let n = rng.random_range(3..40);
            let poly: Vec<Point2<f64>> = (0..n)
                .map(|i| {
                    let t = std::f64::consts::TAU * i as f64 / n as f64;
                    let r = rng.random_range(0.3..1.0);
                    let (x, y) = (r * t.cos(), r * t.sin());
                    match case % 2 {
                        0 => {
                            Point2::new((x * 4.0).round() / 4.0 + t * 1e-3, (y * 4.0).round() / 4.0)
                        }
                        _ => Point2::new(x, y),
                    }
                })
                .collect();
            let slabs = PolygonSlabs::new(&poly);
            let mut probes: Vec<Point2<f64>> = poly.clone();
            for i in 0..n {
                let (a, b) = (poly[i], poly[(i + 1) % n]);
                probes.push(Point2::from((a.coords + b.coords) * 0.5));
            }
            for _ in 0..200 {
                let (x, y) = (rng.random_range(-1.2..1.2), rng.random_range(-1.2..1.2));
                probes.push(Point2::new(x, y));
                probes.push(Point2::new(
                    (x * 4.0).round() / 4.0,
                    (y * 4.0).round() / 4.0,
                ));
            }
            for p in &probes {
                assert_eq!(
                    slabs.contains(p),
                    point_in_polygon(&poly, p),
                    "case {case}: {p:?}"
                );
            }
        }
    }

    #[test]
    fn point_in_polygon_is_exact() {
        let sq = square().points;
        assert_eq!(point_in_polygon(&sq, &Point2::new(0.5, 0.5)), Some(true));
        assert_eq!(point_in_polygon(&sq, &Point2::new(1.0, 0.5)), None);
        assert_eq!(point_in_polygon(&sq, &Point2::new(0.0, 0.0)), None);
        assert_eq!(
            point_in_polygon(&sq, &Point2::new(1.0 + f64::EPSILON, 0.5)),
            Some(false)
        );
        assert_eq!(point_in_polygon(&sq, &Point2::new(0.5, 1.0)), None);
        assert_eq!(point_in_polygon(&sq, &Point2::new(-0.5, 0.0)), Some(false));
    }
}
