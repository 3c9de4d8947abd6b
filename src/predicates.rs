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
    if s.iter().any(|x| *x == Sign::Negative) {
        return None;
    }
    Some(s.iter().filter(|x| **x == Sign::Zero).count())
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

    #[test]
    fn point_in_triangle_counts_edges() {
        let (a, b, c) = (p2(0., 0.), p2(1., 0.), p2(0., 1.));
        assert_eq!(point_in_triangle(&a, &b, &c, &p2(0.2, 0.2)), Some(0));
        assert_eq!(point_in_triangle(&a, &b, &c, &p2(0.5, 0.0)), Some(1));
        assert_eq!(point_in_triangle(&a, &b, &c, &p2(0.0, 0.0)), Some(2));
        assert_eq!(point_in_triangle(&a, &b, &c, &p2(0.6, 0.6)), None);
    }
}
