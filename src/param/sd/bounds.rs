//! Step bounds of the line search along a Newton direction `dir` (dof `2v + c`): the
//! largest flip-free step (Smith & Schaefer 2015) and the largest step along which the
//! boundary stays simple (boundary-collision bound). Float arithmetic: they only choose the
//! first trial; the exact certificate judges every iterate.

use crate::ids::VertexId;
use nalgebra::{Point2, Vector2};

/// Largest `t` with every triangle's `det(U + t dU) > 0` (∞ if none vanishes): the
/// smallest positive root over all triangles of that quadratic in `t`.
pub(super) fn max_flip_free_step(uv: &[Point2<f64>], dir: &[f64], tris: &[[VertexId; 3]]) -> f64 {
    let mut tmax = f64::INFINITY;
    for t in tris {
        let p = |k: usize| uv[t[k].idx()];
        let q = |k: usize| Vector2::new(dir[2 * t[k].idx()], dir[2 * t[k].idx() + 1]);
        let (e1, e2) = (p(1) - p(0), p(2) - p(0));
        let (d1, d2) = (q(1) - q(0), q(2) - q(0));
        // det(U + t dU) = c0 + c1 t + c2 t².
        let c0 = e1.perp(&e2);
        let c1 = e1.perp(&d2) + d1.perp(&e2);
        let c2 = d1.perp(&d2);
        if let Some(r) = smallest_positive_root(c2, c1, c0) {
            tmax = tmax.min(r);
        }
    }
    tmax
}

/// Largest `t ∈ (0, horizon]` such that along `uv + s·dir`, `s ∈ [0, t)`, no boundary vertex
/// meets a boundary edge not incident to it (`horizon` if none does). Two moving segments
/// first touch at an endpoint lying on the other segment, so this keeps a simple boundary
/// polygon simple. For each pair the orientation `orient2d(a(s), b(s), p(s))` is a
/// quadratic in `s`; its positive roots are where `p` crosses the moving line `ab`, and a
/// root counts when `p` then lies on the segment (with a margin of 1e-6 of its length:
/// over-counting only shortens the step). Broad phase: sort-and-sweep on x over the boxes
/// swept in `[0, horizon]`, like the certificate's.
pub(super) fn max_collision_free_step(
    uv: &[Point2<f64>],
    dir: &[f64],
    boundary: &[VertexId],
    horizon: f64,
) -> f64 {
    let m = boundary.len();
    if m < 4 || horizon.is_nan() || horizon <= 0.0 {
        return horizon;
    }
    let pos = |i: usize| uv[boundary[i % m].idx()];
    let vel = |i: usize| {
        let v = boundary[i % m].idx();
        Vector2::new(dir[2 * v], dir[2 * v + 1])
    };
    let items = swept_boxes(m, pos, vel, horizon);
    let first_contact = |vi: usize, ei: usize| -> f64 {
        let mut first = horizon;
        if vi == ei || vi == (ei + 1) % m {
            return first;
        }
        let (p, a, b) = (pos(vi), pos(ei), pos(ei + 1));
        let (dp, da, db) = (vel(vi), vel(ei), vel(ei + 1));
        // orient(s) = (b − a + s(db − da)) × (p − a + s(dp − da)).
        let (e, de) = (b - a, db - da);
        let (w, dw) = (p - a, dp - da);
        let c0 = e.perp(&w);
        let c1 = e.perp(&dw) + de.perp(&w);
        let c2 = de.perp(&dw);
        for s in quadratic_roots(c2, c1, c0) {
            if s > 0.0 && s < horizon {
                let (es, ws) = (e + de * s, w + dw * s);
                let l2 = es.norm_squared();
                let u = if l2 > 0.0 { es.dot(&ws) / l2 } else { 0.5 };
                if (-1e-6..=1.0 + 1e-6).contains(&u) {
                    first = first.min(s);
                }
            }
        }
        first
    };
    let mut tmax = horizon;
    let mut active: Vec<usize> = Vec::new();
    for k in 0..items.len() {
        let (x0, _, y0, y1, id) = items[k];
        active.retain(|&j| items[j].1 >= x0);
        for &j in &active {
            let (_, _, yj0, yj1, jd) = items[j];
            if yj1 < y0 || yj0 > y1 || (id & 1) == (jd & 1) {
                continue;
            }
            let (v, e) = if id & 1 == 0 { (id, jd) } else { (jd, id) };
            tmax = tmax.min(first_contact(v / 2, e / 2));
        }
        active.push(k);
    }
    tmax
}

/// The boxes swept over `[0, horizon]` by the boundary vertices (item `2i`) and edges
/// (item `2i + 1` = edge `(i, i + 1)`), as `(x0, x1, y0, y1, item)` sorted by `x0`.
fn swept_boxes(
    m: usize,
    pos: impl Fn(usize) -> Point2<f64>,
    vel: impl Fn(usize) -> Vector2<f64>,
    horizon: f64,
) -> Vec<(f64, f64, f64, f64, usize)> {
    let mut items: Vec<(f64, f64, f64, f64, usize)> = Vec::with_capacity(2 * m);
    for i in 0..m {
        let (p, q) = (pos(i), pos(i) + vel(i) * horizon);
        items.push((
            p.x.min(q.x),
            p.x.max(q.x),
            p.y.min(q.y),
            p.y.max(q.y),
            2 * i,
        ));
    }
    for i in 0..m {
        let (x0, x1, y0, y1, _) = items[i];
        let (x2, x3, y2, y3, _) = items[(i + 1) % m];
        items.push((x0.min(x2), x1.max(x3), y0.min(y2), y1.max(y3), 2 * i + 1));
    }
    items.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    items
}

/// Real roots of `a t² + b t + c` (numerically stable form; a degenerate quadratic gives
/// its linear root, and the far root when `a` is not exactly 0).
fn quadratic_roots(a: f64, b: f64, c: f64) -> Vec<f64> {
    if a.abs() <= 1e-300 || (a.abs() * c.abs() <= 1e-24 * b * b && b != 0.0) {
        let mut r = Vec::new();
        if b != 0.0 {
            r.push(-c / b);
        }
        if a != 0.0 && b != 0.0 {
            r.push(-b / a);
        }
        return r;
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return Vec::new();
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    if q != 0.0 {
        vec![q / a, c / q]
    } else {
        let r = (-c / a).sqrt();
        vec![r, -r]
    }
}

/// Smallest positive finite root of `a t² + b t + c`, if any.
fn smallest_positive_root(a: f64, b: f64, c: f64) -> Option<f64> {
    quadratic_roots(a, b, c)
        .into_iter()
        .filter(|&r| r > 0.0 && r.is_finite())
        .reduce(f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collision_bound_stops_a_vertex_at_the_opposite_edge() {
        // Loop (0,0) (2,0) (2,2) (1,1.5) (0,2): vertex 3 at (1, 1.5) moving down by 2 per
        // unit step reaches the bottom edge (0,0)-(2,0) at t = 0.75.
        let uv = [
            Point2::new(0.0, 0.0),
            Point2::new(2.0, 0.0),
            Point2::new(2.0, 2.0),
            Point2::new(1.0, 1.5),
            Point2::new(0.0, 2.0),
        ];
        let boundary: Vec<VertexId> = (0..5).map(VertexId::new).collect();
        let mut dir = vec![0.0; 10];
        dir[7] = -2.0;
        let t = max_collision_free_step(&uv, &dir, &boundary, 10.0);
        assert!((t - 0.75).abs() < 1e-12, "{t}");
        // Moving sideways instead, it never meets a non-incident edge within the horizon.
        dir[7] = 0.0;
        dir[6] = 0.1;
        assert_eq!(max_collision_free_step(&uv, &dir, &boundary, 1.0), 1.0);
        // A vertex passing beside an edge's line but outside the segment is not a collision.
        dir[6] = 0.0;
        dir[7] = 0.0;
        dir[0] = -1.0; // v0 moves left along the x axis: the line of edge (1,2) is x = 2
        assert_eq!(max_collision_free_step(&uv, &dir, &boundary, 5.0), 5.0);
    }

    #[test]
    fn flip_free_step_is_where_a_triangle_degenerates() {
        // The apex of a unit right triangle moving down by 1 per unit step: flat at t = 1.
        let uv = [
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(0.0, 1.0),
        ];
        let tris = [[VertexId::new(0), VertexId::new(1), VertexId::new(2)]];
        let dir = [0.0, 0.0, 0.0, 0.0, 0.0, -1.0];
        assert_eq!(max_flip_free_step(&uv, &dir, &tris), 1.0);
        // Moving up it never flips.
        let dir = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
        assert_eq!(max_flip_free_step(&uv, &dir, &tris), f64::INFINITY);
    }

    #[test]
    fn quadratic_roots() {
        assert_eq!(smallest_positive_root(1.0, -3.0, 2.0), Some(1.0));
        assert_eq!(smallest_positive_root(0.0, -2.0, 1.0), Some(0.5));
        assert_eq!(smallest_positive_root(1.0, 0.0, 1.0), None);
        assert_eq!(smallest_positive_root(1.0, 3.0, 2.0), None);
    }
}
