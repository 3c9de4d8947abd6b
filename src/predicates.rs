//! Every sign decision of conemesh, exact, through `robust` (Shewchuk's adaptive predicates).
//!
//! No other module compares an orientation or intersection value against an epsilon: they
//! call these functions. `robust` is pinned to an exact 1.x version in `Cargo.toml` because
//! the sign convention of `incircle` differed between its major versions; the conventions
//! used here are tested below and written in `paper-notes.md`.

use nalgebra::{Point2, Point3};
use robust::{Coord, Coord3D};
use serde::Serialize;

/// The sign of an exact predicate.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize)]
pub enum Sign {
    /// Strictly negative.
    Negative,
    /// Exactly zero (degenerate configuration).
    Zero,
    /// Strictly positive.
    Positive,
}

impl Sign {
    #[inline]
    fn of(x: f64) -> Sign {
        if x > 0.0 {
            Sign::Positive
        } else if x < 0.0 {
            Sign::Negative
        } else {
            Sign::Zero
        }
    }
    /// The opposite sign.
    #[inline]
    pub fn reversed(self) -> Sign {
        match self {
            Sign::Negative => Sign::Positive,
            Sign::Zero => Sign::Zero,
            Sign::Positive => Sign::Negative,
        }
    }
}

#[inline]
fn c2(p: &Point2<f64>) -> Coord<f64> {
    Coord { x: p.x, y: p.y }
}

#[inline]
fn c3(p: &Point3<f64>) -> Coord3D<f64> {
    Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// Orientation of the triangle `(a, b, c)` in the plane: `Positive` when counter-clockwise,
/// `Negative` when clockwise, `Zero` when collinear. Exact.
#[inline]
pub fn orient2d(a: &Point2<f64>, b: &Point2<f64>, c: &Point2<f64>) -> Sign {
    Sign::of(robust::orient2d(c2(a), c2(b), c2(c)))
}

/// Orientation of `d` relative to the plane through `a, b, c`: `Positive` when `d` lies on
/// the side the normal `(b − a) × (c − a)` points to, `Negative` on the other side, `Zero`
/// when coplanar. (This is the negation of `robust::orient3d`, which is positive when `d`
/// is *below* a counter-clockwise `abc`.) Exact.
#[inline]
pub fn orient3d(a: &Point3<f64>, b: &Point3<f64>, c: &Point3<f64>, d: &Point3<f64>) -> Sign {
    // Four points with one coordinate equal lie in an axis-aligned plane: the determinant is
    // exactly zero. Flat inputs (plates) hit this on every test, and robust would reach it
    // only through its slowest, adaptive stage.
    if (0..3).any(|k| a[k] == b[k] && a[k] == c[k] && a[k] == d[k]) {
        return Sign::Zero;
    }
    Sign::of(robust::orient3d(c3(a), c3(b), c3(c), c3(d))).reversed()
}

/// In-circle test: for a counter-clockwise `(a, b, c)`, `Positive` when `d` lies strictly
/// inside their circumcircle, `Negative` outside, `Zero` on it. For a clockwise triple the
/// sign is reversed (robust 1.x convention). Exact.
#[inline]
pub fn incircle(a: &Point2<f64>, b: &Point2<f64>, c: &Point2<f64>, d: &Point2<f64>) -> Sign {
    Sign::of(robust::incircle(c2(a), c2(b), c2(c), c2(d)))
}

/// How two closed segments meet.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize)]
pub enum SegmentIntersection {
    /// No common point.
    Disjoint,
    /// They cross at a single point interior to both.
    Proper,
    /// They share at least one point, and either an endpoint lies on the other segment or
    /// they are collinear and overlap.
    Touching,
}

/// `true` when collinear point `p` lies on the closed segment `[a, b]` (bounding-box test,
/// exact for collinear input).
#[inline]
fn on_segment_collinear(a: &Point2<f64>, b: &Point2<f64>, p: &Point2<f64>) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// Exact intersection test of closed segments `[a, b]` and `[c, d]` in the plane.
pub fn segments_intersect(
    a: &Point2<f64>,
    b: &Point2<f64>,
    c: &Point2<f64>,
    d: &Point2<f64>,
) -> SegmentIntersection {
    let o1 = orient2d(a, b, c);
    let o2 = orient2d(a, b, d);
    let o3 = orient2d(c, d, a);
    let o4 = orient2d(c, d, b);
    let straddle = |x: Sign, y: Sign| {
        (x == Sign::Positive && y == Sign::Negative) || (x == Sign::Negative && y == Sign::Positive)
    };
    if straddle(o1, o2) && straddle(o3, o4) {
        return SegmentIntersection::Proper;
    }
    let touch = (o1 == Sign::Zero && on_segment_collinear(a, b, c))
        || (o2 == Sign::Zero && on_segment_collinear(a, b, d))
        || (o3 == Sign::Zero && on_segment_collinear(c, d, a))
        || (o4 == Sign::Zero && on_segment_collinear(c, d, b));
    if touch {
        SegmentIntersection::Touching
    } else {
        SegmentIntersection::Disjoint
    }
}

/// Exact point-in-triangle test for a counter-clockwise triangle: the three orientations
/// of `p` against its edges. Returns `None` when `p` is outside, else the number of edges `p`
/// lies on (0 = strictly inside, 1 = on an edge, 2 = at a vertex).
pub fn point_in_triangle(
    a: &Point2<f64>,
    b: &Point2<f64>,
    c: &Point2<f64>,
    p: &Point2<f64>,
) -> Option<usize> {
    let s = [orient2d(a, b, p), orient2d(b, c, p), orient2d(c, a, p)];
    if s.contains(&Sign::Negative) {
        return None;
    }
    Some(s.iter().filter(|x| **x == Sign::Zero).count())
}

// ---------------------------------------------------------------------------------------
// 3D intersection tests (self-intersection certificate).
//
// Every decision below is an `orient3d` or an `orient2d` sign (exact); no coordinate is ever
// constructed. The key fact used throughout: two closed convex sets in 3D that are coplanar
// (or lie on a common line) intersect iff their images under an axis projection that is
// injective on their common plane intersect, and such an axis is found exactly as one whose
// projected `orient2d` is non-zero.
// ---------------------------------------------------------------------------------------

/// Drop coordinate `axis` (0 = x, 1 = y, 2 = z): the projection on the other two axes.
#[inline]
fn project(p: &Point3<f64>, axis: usize) -> Point2<f64> {
    match axis {
        0 => Point2::new(p.y, p.z),
        1 => Point2::new(p.z, p.x),
        _ => Point2::new(p.x, p.y),
    }
}

/// `true` when `p, q, r` lie on one line (or coincide), exactly: the three points are
/// collinear in 3D iff their projections on the yz, zx and xy planes are all collinear
/// (the three `orient2d` values are the components of `(q − p) × (r − p)`).
pub fn collinear3d(p: &Point3<f64>, q: &Point3<f64>, r: &Point3<f64>) -> bool {
    (0..3).all(|k| orient2d(&project(p, k), &project(q, k), &project(r, k)) == Sign::Zero)
}

/// An axis whose projection maps the plane of the non-degenerate triangle `p, q, r`
/// one-to-one onto a coordinate plane, with the sign of the projected triangle. The axis of
/// the largest float normal component is tried first (the dominant axis); the choice is then
/// confirmed by the exact `orient2d`, so a wrong float guess only costs another try.
/// `None` when the triangle is degenerate (collinear corners).
fn projection_axis(p: &Point3<f64>, q: &Point3<f64>, r: &Point3<f64>) -> Option<(usize, Sign)> {
    let n = (q - p).cross(&(r - p));
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| n[j].abs().total_cmp(&n[i].abs()));
    order.iter().find_map(|&k| {
        let s = orient2d(&project(p, k), &project(q, k), &project(r, k));
        (s != Sign::Zero).then_some((k, s))
    })
}

/// `p` on the ray from `c` through `s`, given that `c, s, p` are collinear and `p, s ≠ c`:
/// exact coordinate comparisons (the signs of `s − c` and `p − c` agree on both axes).
fn same_direction(c: &Point2<f64>, s: &Point2<f64>, p: &Point2<f64>) -> bool {
    s.x.total_cmp(&c.x) == p.x.total_cmp(&c.x) && s.y.total_cmp(&c.y) == p.y.total_cmp(&c.y)
}

/// The order of `p` and `q` met when turning counter-clockwise from the ray `c → s` (angles
/// in `[0, 2π)`), exactly: the half-plane of each relative to that ray, then `orient2d`.
fn ccw_order(
    c: &Point2<f64>,
    s: &Point2<f64>,
    p: &Point2<f64>,
    q: &Point2<f64>,
) -> std::cmp::Ordering {
    let class = |x: &Point2<f64>| match orient2d(c, s, x) {
        Sign::Zero if same_direction(c, s, x) => 0,
        Sign::Positive => 1,
        Sign::Zero => 2,
        Sign::Negative => 3,
    };
    let (kp, kq) = (class(p), class(q));
    if kp != kq {
        return kp.cmp(&kq);
    }
    match (kp, orient2d(c, p, q)) {
        (0 | 2, _) | (_, Sign::Zero) => std::cmp::Ordering::Equal,
        (_, Sign::Positive) => std::cmp::Ordering::Less,
        (_, Sign::Negative) => std::cmp::Ordering::Greater,
    }
}

/// Whether the non-degenerate triangles `(c, x, y)`, one per entry `[(x, key), (y, key)]` of
/// `sectors`, all lie in one plane and meet only at `c` and along the edges `c → x` they share
/// by key: their angular sectors at `c` are disjoint (a flat fan that winds at most once and
/// does not fold), and two sectors touching along a ray end at the same key there. Decided
/// exactly (`orient3d` for the plane, then `orient2d` in a projection the plane is not
/// perpendicular to); `false` when any condition fails, including a degenerate triangle.
/// Used to skip the pairs of such a fan in the self-intersection search: two of its faces
/// sharing only `c` do not meet elsewhere.
pub fn coplanar_fan_is_embedded<K: Copy + Eq>(
    c: &Point3<f64>,
    sectors: &[[(Point3<f64>, K); 2]],
) -> bool {
    let Some(first) = sectors.first() else {
        return true;
    };
    let (a, b) = (first[0].0, first[1].0);
    let Some((axis, _)) = projection_axis(c, &a, &b) else {
        return false;
    };
    if sectors
        .iter()
        .flatten()
        .any(|(p, _)| orient3d(c, &a, &b, p) != Sign::Zero)
    {
        return false;
    }
    let pc = project(c, axis);
    let mut sec: Vec<[(Point2<f64>, K); 2]> = Vec::with_capacity(sectors.len());
    for [(x, kx), (y, ky)] in sectors {
        let (px, py) = (project(x, axis), project(y, axis));
        match orient2d(&pc, &px, &py) {
            Sign::Positive => sec.push([(px, *kx), (py, *ky)]),
            Sign::Negative => sec.push([(py, *ky), (px, *kx)]),
            Sign::Zero => return false,
        }
    }
    let r0 = sec[0][0].0;
    sec.sort_by(|s, t| ccw_order(&pc, &r0, &s[0].0, &t[0].0));
    let m = sec.len();
    if m == 1 {
        return true;
    }
    (0..m).all(|k| {
        let [(s, _), (e, ke)] = sec[k];
        let (n, kn) = sec[(k + 1) % m][0];
        let starts_apart = !(orient2d(&pc, &s, &n) == Sign::Zero && same_direction(&pc, &s, &n));
        starts_apart
            && match ccw_order(&pc, &s, &e, &n) {
                std::cmp::Ordering::Less => true,
                std::cmp::Ordering::Equal => ke == kn,
                std::cmp::Ordering::Greater => false,
            }
    })
}

/// Closed 2D segment `[a, b]` against the closed non-degenerate triangle `t` whose
/// orientation is `t_sign` (exact).
fn segment_meets_triangle_2d(
    a: &Point2<f64>,
    b: &Point2<f64>,
    t: &[Point2<f64>; 3],
    t_sign: Sign,
) -> bool {
    let (p, q, r) = if t_sign == Sign::Negative {
        (&t[0], &t[2], &t[1])
    } else {
        (&t[0], &t[1], &t[2])
    };
    point_in_triangle(p, q, r, a).is_some()
        || point_in_triangle(p, q, r, b).is_some()
        || [(p, q), (q, r), (r, p)]
            .iter()
            .any(|(u, v)| segments_intersect(a, b, u, v) != SegmentIntersection::Disjoint)
}

/// Exact intersection test of closed segments `[a, b]` and `[c, d]` in 3D (segments may be
/// single points).
///
/// Non-coplanar segments never meet. Coplanar ones (including collinear ones) meet iff their
/// projections on all three coordinate planes meet: meeting in 3D implies meeting in every
/// projection, and at least one projection is injective on the common plane (or line), so
/// its verdict is the 3D truth.
pub fn segments_intersect_3d(
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
    d: &Point3<f64>,
) -> bool {
    if orient3d(a, b, c, d) != Sign::Zero {
        return false;
    }
    (0..3).all(|k| {
        segments_intersect(
            &project(a, k),
            &project(b, k),
            &project(c, k),
            &project(d, k),
        ) != SegmentIntersection::Disjoint
    })
}

/// Closed segment `[a, b]` against the closed triangle `t`, given the sides `sa`, `sb` of
/// `a`, `b` relative to the plane of `t` (`t` non-degenerate, projection `axis`/`t_sign`).
fn segment_meets_nondegenerate_triangle(
    a: &Point3<f64>,
    b: &Point3<f64>,
    sa: Sign,
    sb: Sign,
    t: &[Point3<f64>; 3],
    axis: usize,
    t_sign: Sign,
) -> bool {
    match (sa, sb) {
        (Sign::Positive, Sign::Positive) | (Sign::Negative, Sign::Negative) => false,
        (Sign::Zero, Sign::Zero) => {
            let tp = [
                project(&t[0], axis),
                project(&t[1], axis),
                project(&t[2], axis),
            ];
            segment_meets_triangle_2d(&project(a, axis), &project(b, axis), &tp, t_sign)
        }
        (Sign::Zero, _) | (_, Sign::Zero) => {
            // Exactly one endpoint lies in the plane: it is the only candidate point.
            let x = if sa == Sign::Zero { a } else { b };
            let tp = [
                project(&t[0], axis),
                project(&t[1], axis),
                project(&t[2], axis),
            ];
            let px = project(x, axis);
            if t_sign == Sign::Negative {
                point_in_triangle(&tp[0], &tp[2], &tp[1], &px).is_some()
            } else {
                point_in_triangle(&tp[0], &tp[1], &tp[2], &px).is_some()
            }
        }
        _ => {
            // The segment crosses the plane at one point strictly between a and b; that point
            // is in the closed triangle iff the line ab sees the three edges with no two
            // strictly opposite orientations (signed volumes ∝ barycentric coordinates).
            let s = [
                orient3d(a, b, &t[0], &t[1]),
                orient3d(a, b, &t[1], &t[2]),
                orient3d(a, b, &t[2], &t[0]),
            ];
            !(s.contains(&Sign::Positive) && s.contains(&Sign::Negative))
        }
    }
}

/// Exact intersection test of the closed segment `[a, b]` and the closed triangle `t` in 3D.
/// A degenerate triangle (collinear corners) is treated as the segment it covers, i.e. the
/// union of its three edges.
pub fn segment_triangle_intersect(a: &Point3<f64>, b: &Point3<f64>, t: &[Point3<f64>; 3]) -> bool {
    match projection_axis(&t[0], &t[1], &t[2]) {
        Some((axis, t_sign)) => {
            let sa = orient3d(&t[0], &t[1], &t[2], a);
            let sb = orient3d(&t[0], &t[1], &t[2], b);
            segment_meets_nondegenerate_triangle(a, b, sa, sb, t, axis, t_sign)
        }
        None => (0..3).any(|i| segments_intersect_3d(a, b, &t[i], &t[(i + 1) % 3])),
    }
}

/// Exact intersection test of two closed triangles in 3D (`true` when they share at least one
/// point, touching included). Degenerate triangles are treated as the segments (or points)
/// they cover.
///
/// Möller's plane-side rejection first (three `orient3d` per plane); then the triangles
/// meet iff an edge of one meets the other: the intersection of two convex polygons, if not
/// empty, has an extreme point on the boundary of one of them. Every decision is an exact
/// `orient3d`, or an exact `orient2d` on a projection chosen by `projection_axis`.
pub fn triangles_intersect(a: &[Point3<f64>; 3], b: &[Point3<f64>; 3]) -> bool {
    let pa = projection_axis(&a[0], &a[1], &a[2]);
    let pb = projection_axis(&b[0], &b[1], &b[2]);
    let side = |t: &[Point3<f64>; 3], x: &Point3<f64>| orient3d(&t[0], &t[1], &t[2], x);
    let separated = |s: &[Sign; 3]| {
        s.iter().all(|x| *x == Sign::Positive) || s.iter().all(|x| *x == Sign::Negative)
    };
    // Sides of b's corners relative to a's plane, and vice versa (only for non-degenerate).
    let sb = pa.map(|_| [side(a, &b[0]), side(a, &b[1]), side(a, &b[2])]);
    if sb.as_ref().is_some_and(separated) {
        return false;
    }
    let sa = pb.map(|_| [side(b, &a[0]), side(b, &a[1]), side(b, &a[2])]);
    if sa.as_ref().is_some_and(separated) {
        return false;
    }
    let edges_meet = |e: &[Point3<f64>; 3],
                      es: Option<[Sign; 3]>,
                      t: &[Point3<f64>; 3],
                      tp: Option<(usize, Sign)>| {
        (0..3).any(|i| {
            let j = (i + 1) % 3;
            match (tp, es) {
                (Some((axis, t_sign)), Some(s)) => {
                    segment_meets_nondegenerate_triangle(&e[i], &e[j], s[i], s[j], t, axis, t_sign)
                }
                _ => segment_triangle_intersect(&e[i], &e[j], t),
            }
        })
    };
    edges_meet(a, sa, b, pb) || edges_meet(b, sb, a, pa)
}

/// Two non-degenerate triangles `(p, q, r)` and `(p, q, s)` sharing the edge `pq`
/// (in either direction): `true` when they overlap beyond that edge. Their planes meet in
/// the line `pq` unless they are coplanar, so they overlap iff `p, q, r, s` are coplanar and
/// `r`, `s` lie on the same side of `pq` (CGAL's `coplanar` + `coplanar_orientation`).
/// Degenerate input returns `false` (callers report degenerate faces separately).
pub fn edge_adjacent_triangles_overlap(
    p: &Point3<f64>,
    q: &Point3<f64>,
    r: &Point3<f64>,
    s: &Point3<f64>,
) -> bool {
    if orient3d(p, q, r, s) != Sign::Zero {
        return false;
    }
    let Some((axis, sr)) = projection_axis(p, q, r) else {
        return false;
    };
    orient2d(&project(p, axis), &project(q, axis), &project(s, axis)) == sr
}

/// Two non-degenerate triangles `(v, a, b)` and `(v, c, d)` sharing exactly the corner `v`:
/// `true` when they meet anywhere else. The intersection is convex and contains `v`; any
/// other point of it makes its far end lie on the edge opposite `v` of one triangle and inside
/// the other, so the test is: `[c, d]` meets `(v, a, b)` or `[a, b]` meets `(v, c, d)` (the
/// opposite edges do not contain `v`; CGAL's rule).
pub fn vertex_adjacent_triangles_intersect(
    v: &Point3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
    d: &Point3<f64>,
) -> bool {
    segment_triangle_intersect(c, d, &[*v, *a, *b])
        || segment_triangle_intersect(a, b, &[*v, *c, *d])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p2(x: f64, y: f64) -> Point2<f64> {
        Point2::new(x, y)
    }

    #[test]
    fn orient2d_convention_is_ccw_positive() {
        assert_eq!(
            orient2d(&p2(0.0, 0.0), &p2(1.0, 0.0), &p2(0.0, 1.0)),
            Sign::Positive
        );
        assert_eq!(
            orient2d(&p2(0.0, 0.0), &p2(0.0, 1.0), &p2(1.0, 0.0)),
            Sign::Negative
        );
        assert_eq!(
            orient2d(&p2(0.0, 0.0), &p2(1.0, 1.0), &p2(2.0, 2.0)),
            Sign::Zero
        );
    }

    #[test]
    fn orient3d_convention_is_normal_side_positive() {
        let (a, b, c) = (
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        );
        assert_eq!(
            orient3d(&a, &b, &c, &Point3::new(0.2, 0.2, 1.0)),
            Sign::Positive
        );
        assert_eq!(
            orient3d(&a, &b, &c, &Point3::new(0.2, 0.2, -1.0)),
            Sign::Negative
        );
        assert_eq!(
            orient3d(&a, &b, &c, &Point3::new(5.0, -3.0, 0.0)),
            Sign::Zero
        );
    }

    #[test]
    fn incircle_convention_is_inside_positive_for_ccw() {
        let (a, b, c) = (p2(1.0, 0.0), p2(0.0, 1.0), p2(-1.0, 0.0));
        assert_eq!(incircle(&a, &b, &c, &p2(0.0, 0.0)), Sign::Positive);
        assert_eq!(incircle(&a, &b, &c, &p2(2.0, 0.0)), Sign::Negative);
        assert_eq!(incircle(&a, &b, &c, &p2(0.0, -1.0)), Sign::Zero);
        // Clockwise triple reverses the sign.
        assert_eq!(incircle(&c, &b, &a, &p2(0.0, 0.0)), Sign::Negative);
    }

    #[test]
    fn orient2d_is_exact_where_float_arithmetic_fails() {
        // Points a few ulps off the line y = x (Shewchuk's classic example): the naive
        // determinant gets the side wrong somewhere on this grid; the exact predicate never.
        let b = p2(12.0, 12.0);
        let c = p2(24.0, 24.0);
        let eps = f64::EPSILON;
        let mut naive_wrong = 0;
        for i in 0..64 {
            for j in 0..64 {
                let p = p2(0.5 + i as f64 * eps, 0.5 + j as f64 * eps);
                // p.y - p.x is exact here, so its sign is the truth.
                let truth = Sign::of(p.y - p.x);
                assert_eq!(orient2d(&b, &c, &p), truth, "at {i},{j}");
                let naive = (c.x - b.x) * (p.y - b.y) - (c.y - b.y) * (p.x - b.x);
                if Sign::of(naive) != truth {
                    naive_wrong += 1;
                }
            }
        }
        assert!(
            naive_wrong > 0,
            "the naive formula should fail somewhere on this grid"
        );
    }

    #[test]
    fn segment_intersection_cases() {
        let s = |a: (f64, f64), b: (f64, f64), c: (f64, f64), d: (f64, f64)| {
            segments_intersect(&p2(a.0, a.1), &p2(b.0, b.1), &p2(c.0, c.1), &p2(d.0, d.1))
        };
        assert_eq!(
            s((0., 0.), (2., 2.), (0., 2.), (2., 0.)),
            SegmentIntersection::Proper
        );
        assert_eq!(
            s((0., 0.), (1., 1.), (2., 2.), (3., 0.)),
            SegmentIntersection::Disjoint
        );
        assert_eq!(
            s((0., 0.), (2., 0.), (1., 0.), (1., 5.)),
            SegmentIntersection::Touching
        );
        assert_eq!(
            s((0., 0.), (2., 0.), (1., 0.), (3., 0.)),
            SegmentIntersection::Touching
        );
        assert_eq!(
            s((0., 0.), (1., 0.), (2., 0.), (3., 0.)),
            SegmentIntersection::Disjoint
        );
        assert_eq!(
            s((0., 0.), (1., 0.), (1., 0.), (1., 1.)),
            SegmentIntersection::Touching
        );
    }

    fn p3(x: f64, y: f64, z: f64) -> Point3<f64> {
        Point3::new(x, y, z)
    }

    fn tri(a: (f64, f64, f64), b: (f64, f64, f64), c: (f64, f64, f64)) -> [Point3<f64>; 3] {
        [p3(a.0, a.1, a.2), p3(b.0, b.1, b.2), p3(c.0, c.1, c.2)]
    }

    /// Both argument orders and all corner rotations must agree.
    fn tt(a: &[Point3<f64>; 3], b: &[Point3<f64>; 3]) -> bool {
        let r = triangles_intersect(a, b);
        for k in 0..3 {
            let ar = [a[k], a[(k + 1) % 3], a[(k + 2) % 3]];
            let bf = [b[0], b[2], b[1]];
            assert_eq!(triangles_intersect(&ar, b), r, "rotation {k}");
            assert_eq!(triangles_intersect(b, &ar), r, "swap, rotation {k}");
            assert_eq!(triangles_intersect(&ar, &bf), r, "flip, rotation {k}");
        }
        r
    }

    #[test]
    fn triangles_crossing_and_separated() {
        let a = tri((0., 0., 0.), (4., 0., 0.), (0., 4., 0.));
        // Pierces a's interior.
        assert!(tt(&a, &tri((1., 1., -1.), (1., 1., 1.), (2., 0.5, 1.))));
        // Same shape moved above the plane.
        assert!(!tt(&a, &tri((1., 1., 0.5), (1., 1., 1.), (2., 0.5, 1.))));
        // Straddles the plane but passes outside the triangle (beyond the hypotenuse).
        assert!(!tt(&a, &tri((3., 3., -1.), (3., 3., 1.), (5., 4., 0.))));
        // Linked like two rings: each pierces the other's edge region.
        let b = tri((2., -1., -1.), (2., -1., 1.), (2., 1., 0.));
        assert!(tt(&a, &b));
    }

    #[test]
    fn triangles_touching_at_a_point_or_edge() {
        let a = tri((0., 0., 0.), (4., 0., 0.), (0., 4., 0.));
        // A corner of b exactly on a's interior, the rest above.
        assert!(tt(&a, &tri((1., 1., 0.), (1., 1., 1.), (2., 0.5, 1.))));
        // A corner of b exactly on a's hypotenuse.
        assert!(tt(&a, &tri((2., 2., 0.), (3., 3., 1.), (2., 3., 1.))));
        // Corner to corner.
        assert!(tt(&a, &tri((4., 0., 0.), (5., 0., 1.), (5., 1., 1.))));
        // Edge of b lying on a's plane and crossing a's edge from outside.
        assert!(tt(&a, &tri((-1., 1., 0.), (1., 1., 0.), (0., 1., 3.))));
        // Same, but stopping short of the triangle.
        assert!(!tt(&a, &tri((-2., 1., 0.), (-1., 1., 0.), (-1.5, 1., 3.))));
    }

    #[test]
    fn coplanar_triangles() {
        let a = tri((0., 0., 1.), (4., 0., 1.), (0., 4., 1.));
        // Overlapping (a star of David-like crossing, no corner inside the other).
        assert!(tt(&a, &tri((-1., 1., 1.), (3., -1., 1.), (3., 3., 1.))));
        // b strictly inside a.
        assert!(tt(&a, &tri((1., 1., 1.), (2., 1., 1.), (1., 2., 1.))));
        // Sharing only part of an edge line, touching.
        assert!(tt(&a, &tri((1., 0., 1.), (3., 0., 1.), (2., -2., 1.))));
        // Disjoint in the plane.
        assert!(!tt(&a, &tri((3., 3., 1.), (5., 3., 1.), (3., 5., 1.))));
        // Tilted plane x + y + z = 3 (exact in binary), overlap and separation.
        let c = tri((3., 0., 0.), (0., 3., 0.), (0., 0., 3.));
        assert!(tt(&c, &tri((1., 1., 1.), (2., 1., 0.), (1., 2., 0.))));
        assert!(!tt(&c, &tri((-1., 4., 0.), (-2., 4., 1.), (-1., 5., -1.))));
    }

    #[test]
    fn degenerate_triangles_are_their_segments() {
        let a = tri((0., 0., 0.), (4., 0., 0.), (0., 4., 0.));
        // A "triangle" on a vertical segment through a's interior.
        assert!(tt(&a, &tri((1., 1., -1.), (1., 1., 1.), (1., 1., 0.5))));
        // Same segment beside the triangle.
        assert!(!tt(&a, &tri((5., 1., -1.), (5., 1., 1.), (5., 1., 0.5))));
        // A point (three equal corners) on the hypotenuse, and just off it.
        assert!(tt(&a, &tri((2., 2., 0.), (2., 2., 0.), (2., 2., 0.))));
        assert!(!tt(&a, &tri((2., 2.5, 0.), (2., 2.5, 0.), (2., 2.5, 0.))));
        // Two degenerate triangles on crossing segments, and on skew ones.
        let s = tri((0., 0., 0.), (2., 2., 0.), (1., 1., 0.));
        assert!(tt(&s, &tri((0., 2., 0.), (2., 0., 0.), (0.5, 1.5, 0.))));
        assert!(!tt(&s, &tri((0., 2., 1.), (2., 0., 1.), (0.5, 1.5, 1.))));
        assert!(collinear3d(&s[0], &s[1], &s[2]));
        assert!(!collinear3d(&a[0], &a[1], &a[2]));
    }

    #[test]
    fn shared_edge_overlaps_only_when_folded_over() {
        let (p, q) = (p3(0., 0., 0.), p3(2., 0., 0.));
        let r = p3(1., 1., 0.);
        // Flat continuation across the edge: no overlap.
        assert!(!edge_adjacent_triangles_overlap(
            &p,
            &q,
            &r,
            &p3(1., -1., 0.)
        ));
        // Bent dihedral: no overlap.
        assert!(!edge_adjacent_triangles_overlap(
            &p,
            &q,
            &r,
            &p3(1., -1., 0.5)
        ));
        assert!(!edge_adjacent_triangles_overlap(
            &p,
            &q,
            &r,
            &p3(1., 0.5, 0.5)
        ));
        // Folded completely onto r's side: overlap.
        assert!(edge_adjacent_triangles_overlap(
            &p,
            &q,
            &r,
            &p3(1.5, 3., 0.)
        ));
        assert!(edge_adjacent_triangles_overlap(
            &q,
            &p,
            &r,
            &p3(0.2, 0.1, 0.)
        ));
        // Tilted plane, folded.
        assert!(edge_adjacent_triangles_overlap(
            &p3(3., 0., 0.),
            &p3(0., 3., 0.),
            &p3(0., 0., 3.),
            &p3(1., 1., 1.)
        ));
    }

    #[test]
    fn shared_vertex_meets_elsewhere_or_not() {
        let v = p3(0., 0., 0.);
        let (a, b) = (p3(2., 0., 0.), p3(0., 2., 0.));
        // Fan neighbour in the same plane, no overlap.
        assert!(!vertex_adjacent_triangles_intersect(
            &v,
            &a,
            &b,
            &p3(-2., 0., 0.),
            &p3(0., -2., 0.)
        ));
        // Coplanar, overlapping the wedge.
        assert!(vertex_adjacent_triangles_intersect(
            &v,
            &a,
            &b,
            &p3(1., 1., 0.),
            &p3(2., 2., 0.)
        ));
        // Crossing through a's interior from above to below.
        assert!(vertex_adjacent_triangles_intersect(
            &v,
            &a,
            &b,
            &p3(1., 1., 1.),
            &p3(1., 1., -1.)
        ));
        // Above, leaning over without touching.
        assert!(!vertex_adjacent_triangles_intersect(
            &v,
            &a,
            &b,
            &p3(1., 1., 1.),
            &p3(2., 1., 1.)
        ));
    }

    #[test]
    fn triangles_intersect_is_exact_where_float_orient3d_fails() {
        // a lies in the vertical plane y = x. b's corner P sits a few ulps off that plane; b's
        // other corners are clearly on the y > x side, so b meets a iff P.y <= P.x. The plane
        // side of P is decided exactly; the naive float determinant gets some of these wrong.
        let a = tri((-12., -12., -10.), (24., 24., -10.), (0., 0., 10.));
        let eps = f64::EPSILON;
        let mut naive_wrong = 0;
        for i in 0..32 {
            for j in 0..32 {
                let pt = p3(0.5 + i as f64 * eps, 0.5 + j as f64 * eps, 0.5);
                let b = [pt, p3(0., 1., 0.5), p3(0., 1., 1.)];
                let truth = pt.y <= pt.x;
                assert_eq!(triangles_intersect(&a, &b), truth, "at {i},{j}");
                assert_eq!(triangles_intersect(&b, &a), truth, "at {i},{j}");
                let (u, v, w) = (a[0] - pt, a[1] - pt, a[2] - pt);
                let naive = u.dot(&v.cross(&w));
                let exact = orient3d(&a[0], &a[1], &a[2], &pt);
                if Sign::of(naive) != exact {
                    naive_wrong += 1;
                }
            }
        }
        assert!(
            naive_wrong > 0,
            "the naive determinant should fail somewhere on this grid"
        );
    }

    #[test]
    fn segments_in_3d() {
        let (a, b) = (p3(0., 0., 0.), p3(2., 2., 2.));
        assert!(segments_intersect_3d(
            &a,
            &b,
            &p3(2., 0., 0.),
            &p3(0., 2., 2.)
        ));
        assert!(!segments_intersect_3d(
            &a,
            &b,
            &p3(2., 0., 0.),
            &p3(0., 2., 3.)
        ));
        // Collinear overlap and collinear gap along a line parallel to no axis plane.
        assert!(segments_intersect_3d(
            &a,
            &b,
            &p3(1., 1., 1.),
            &p3(3., 3., 3.)
        ));
        assert!(!segments_intersect_3d(
            &a,
            &b,
            &p3(3., 3., 3.),
            &p3(4., 4., 4.)
        ));
        // Parallel, coplanar, not collinear.
        assert!(!segments_intersect_3d(
            &a,
            &b,
            &p3(1., 0., 0.),
            &p3(3., 2., 2.)
        ));
    }

    #[test]
    fn point_in_triangle_counts_edges() {
        let (a, b, c) = (p2(0., 0.), p2(1., 0.), p2(0., 1.));
        assert_eq!(point_in_triangle(&a, &b, &c, &p2(0.2, 0.2)), Some(0));
        assert_eq!(point_in_triangle(&a, &b, &c, &p2(0.5, 0.0)), Some(1));
        assert_eq!(point_in_triangle(&a, &b, &c, &p2(0.0, 0.0)), Some(2));
        assert_eq!(point_in_triangle(&a, &b, &c, &p2(0.6, 0.6)), None);
    }
}
