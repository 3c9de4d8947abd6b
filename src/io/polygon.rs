//! Polygon faces cut into triangles that cover exactly the polygon (the readers' n-gons).
//!
//! The polygon is projected onto the plane of its Newell normal, where it winds
//! counter-clockwise. A strictly convex polygon (every turn a left turn, exactly, and one
//! lowest corner, so it winds once) is cut as a fan around its first corner. Any other polygon
//! goes through spade's constrained Delaunay triangulation of its corners with its sides as
//! constraints; the triangles left of its sides, and those reached from them without crossing
//! a side, are the inside. Every decision is exact (`orient2d` and spade's predicates on the
//! projected corners, `orient3d` for the folds), and the cost is `O(n log n)` in the corners.
//! A polygon that crosses or touches itself, has two corners at one position, spans no area,
//! or is too far from planar to be cut without a fold is refused with a [`PolygonProblem`].

use crate::predicates::{orient2d, orient3d, Sign};
use nalgebra::{Point2, Point3, Vector3};
use spade::handles::FixedVertexHandle;
use spade::Triangulation as _;

/// Why a polygon face cannot be cut into triangles inside it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PolygonProblem {
    /// Its corners span no area: all on one line, or its outline cancels out.
    NoArea,
    /// Two corners (their places in the face, 0-based) lie at one position of its plane.
    CoincidentCorners {
        /// the first corner
        first: usize,
        /// the second corner
        second: usize,
    },
    /// Two sides cross or touch, or a corner lies on another side (in its plane).
    SelfIntersecting,
    /// It is too far from planar: its outline crosses itself in its best-fit plane while its
    /// corners stray from that plane, or a triangle inside it would face against it (a fold).
    NotPlanar,
}

impl std::fmt::Display for PolygonProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PolygonProblem::NoArea => write!(f, "spans no area"),
            PolygonProblem::CoincidentCorners { first, second } => write!(
                f,
                "is not simple: corners {first} and {second} lie at one position"
            ),
            PolygonProblem::SelfIntersecting => {
                write!(f, "is not simple: its sides cross or touch each other")
            }
            PolygonProblem::NotPlanar => write!(
                f,
                "is too far from planar to be cut into triangles without a fold"
            ),
        }
    }
}

/// Triangles covering the polygon `corners` (indices into `positions`, in the polygon's
/// order), each oriented like the polygon, `corners.len() − 2` of them (module docs).
pub(crate) fn triangulate(
    positions: &[Point3<f64>],
    corners: &[usize],
) -> Result<Vec<[usize; 3]>, PolygonProblem> {
    let n = corners.len();
    if n == 3 {
        return Ok(vec![[corners[0], corners[1], corners[2]]]);
    }
    let p = |k: usize| positions[corners[k]];
    let centre = corners
        .iter()
        .fold(Vector3::zeros(), |s, &c| s + positions[c].coords)
        / n as f64;
    let normal = (0..n).fold(Vector3::zeros(), |s, k| {
        s + (p(k).coords - centre).cross(&(p((k + 1) % n).coords - centre))
    });
    let len = normal.norm();
    if !(len.is_finite() && len > 0.0) {
        return Err(PolygonProblem::NoArea);
    }
    let normal = normal / len;
    let e1 = any_perpendicular(&normal);
    let e2 = normal.cross(&e1);
    let q: Vec<Point2<f64>> = (0..n)
        .map(|k| {
            let d = p(k).coords - centre;
            Point2::new(d.dot(&e1), d.dot(&e2))
        })
        .collect();
    let local: Vec<[usize; 3]> = match strictly_convex(&q) {
        true => (1..n - 1).map(|k| [0, k, k + 1]).collect(),
        false => constrained(&q, positions, corners, &normal)?,
    };
    let tris: Vec<[usize; 3]> = local.iter().map(|t| t.map(|k| corners[k])).collect();
    // A triangle that faces against the polygon's normal in 3D is a fold.
    for t in &tris {
        let [a, b, c] = t.map(|v| positions[v]);
        if orient3d(&a, &b, &c, &(a + normal)) != Sign::Positive {
            return Err(PolygonProblem::NotPlanar);
        }
    }
    Ok(tris)
}

/// A unit vector perpendicular to the unit vector `n`.
fn any_perpendicular(n: &Vector3<f64>) -> Vector3<f64> {
    let axis = match (
        n.x.abs() <= n.y.abs(),
        n.x.abs() <= n.z.abs(),
        n.y.abs() <= n.z.abs(),
    ) {
        (true, true, _) => Vector3::x(),
        (false, _, true) => Vector3::y(),
        _ => Vector3::z(),
    };
    n.cross(&axis).normalize()
}

/// Every turn of `q` is a strict left turn and it has one lowest corner (lexicographic in
/// `(y, x)`), so it winds once: a strictly convex polygon, whose fan from any corner is a
/// triangulation. Exact.
fn strictly_convex(q: &[Point2<f64>]) -> bool {
    let n = q.len();
    let left_turns =
        (0..n).all(|k| orient2d(&q[(k + n - 1) % n], &q[k], &q[(k + 1) % n]) == Sign::Positive);
    let below = |a: &Point2<f64>, b: &Point2<f64>| (a.y, a.x) < (b.y, b.x);
    let minima = (0..n)
        .filter(|&k| below(&q[k], &q[(k + n - 1) % n]) && below(&q[k], &q[(k + 1) % n]))
        .count();
    left_turns && minima == 1
}

/// The inside triangles of the constrained Delaunay triangulation of the polygon `q` (local
/// corner numbers, counter-clockwise), or why there are none.
fn constrained(
    q: &[Point2<f64>],
    positions: &[Point3<f64>],
    corners: &[usize],
    normal: &Vector3<f64>,
) -> Result<Vec<[usize; 3]>, PolygonProblem> {
    let n = q.len();
    let vertices: Vec<spade::Point2<f64>> =
        q.iter().map(|p| spade::Point2::new(p.x, p.y)).collect();
    let sides: Vec<[usize; 2]> = (0..n).map(|k| [k, (k + 1) % n]).collect();
    let mut crossing = false;
    let cdt = spade::ConstrainedDelaunayTriangulation::<spade::Point2<f64>>::try_bulk_load_cdt(
        vertices,
        sides,
        |_| crossing = true,
    )
    .map_err(|_| PolygonProblem::NoArea)?;
    if cdt.num_vertices() < n {
        return Err(coincident(q));
    }
    // A corner on another side splits that side's constraint in two.
    if crossing || cdt.num_constraints() != n {
        return Err(crossed(q, positions, corners, normal));
    }
    let handle = FixedVertexHandle::from_index;
    let mut inside = vec![false; cdt.num_all_faces()];
    let mut stack = Vec::new();
    for k in 0..n {
        let Some(edge) = cdt.get_edge_from_neighbors(handle(k), handle((k + 1) % n)) else {
            return Err(crossed(q, positions, corners, normal));
        };
        stack.push(edge.face());
    }
    let mut tris = Vec::with_capacity(n - 2);
    while let Some(face) = stack.pop() {
        let Some(inner) = face.as_inner() else {
            // The outside is reached without crossing a side: the outline does not close
            // around a region counter-clockwise.
            return Err(PolygonProblem::SelfIntersecting);
        };
        if std::mem::replace(&mut inside[inner.fix().index()], true) {
            continue;
        }
        tris.push(inner.vertices().map(|v| v.fix().index()));
        for edge in inner.adjacent_edges() {
            if !cdt.is_constraint_edge(edge.as_undirected().fix()) {
                stack.push(edge.rev().face());
            }
        }
    }
    // Any triangulation of a simple polygon without inner vertices has n − 2 triangles.
    if tris.len() != n - 2 {
        return Err(PolygonProblem::SelfIntersecting);
    }
    tris.sort_unstable();
    Ok(tris)
}

/// The first two corners at one position of the plane.
fn coincident(q: &[Point2<f64>]) -> PolygonProblem {
    let mut order: Vec<usize> = (0..q.len()).collect();
    order.sort_by(|&a, &b| {
        (q[a].x, q[a].y)
            .partial_cmp(&(q[b].x, q[b].y))
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(a.cmp(&b))
    });
    match order.windows(2).find(|w| q[w[0]] == q[w[1]]) {
        Some(w) => PolygonProblem::CoincidentCorners {
            first: w[0].min(w[1]),
            second: w[0].max(w[1]),
        },
        None => PolygonProblem::SelfIntersecting,
    }
}

/// A crossing outline: [`PolygonProblem::NotPlanar`] when the corners stray from the best-fit
/// plane by more than a tenth of the polygon's size (the crossing is then the projection's
/// doing), else [`PolygonProblem::SelfIntersecting`]. (The verdict, a refusal, is exact; this
/// only chooses its name.)
fn crossed(
    q: &[Point2<f64>],
    positions: &[Point3<f64>],
    corners: &[usize],
    normal: &Vector3<f64>,
) -> PolygonProblem {
    let centre = corners
        .iter()
        .fold(Vector3::zeros(), |s, &c| s + positions[c].coords)
        / corners.len() as f64;
    let off_plane = corners
        .iter()
        .map(|&c| (positions[c].coords - centre).dot(normal).abs())
        .fold(0.0, f64::max);
    let size = q.iter().map(|p| p.coords.norm()).fold(0.0, f64::max);
    match off_plane > 0.1 * size {
        true => PolygonProblem::NotPlanar,
        false => PolygonProblem::SelfIntersecting,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An L of area 3, counter-clockwise.
    const L_SHAPE: [[f64; 2]; 6] = [
        [0.0, 0.0],
        [2.0, 0.0],
        [2.0, 1.0],
        [1.0, 1.0],
        [1.0, 2.0],
        [0.0, 2.0],
    ];

    /// The polygon `pts` (in the plane z = 0) with corners 0..n.
    fn flat(pts: &[[f64; 2]]) -> (Vec<Point3<f64>>, Vec<usize>) {
        (
            pts.iter().map(|p| Point3::new(p[0], p[1], 0.0)).collect(),
            (0..pts.len()).collect(),
        )
    }

    /// Twice the signed area of a planar polygon (z = 0).
    fn area2(p: &[Point3<f64>], ring: &[usize]) -> f64 {
        (0..ring.len())
            .map(|k| {
                let (a, b) = (p[ring[k]], p[ring[(k + 1) % ring.len()]]);
                a.x * b.y - b.x * a.y
            })
            .sum()
    }

    /// Winding number of the polygon around `x` (z = 0).
    fn winds(p: &[Point3<f64>], ring: &[usize], x: Point2<f64>) -> i32 {
        let mut w = 0;
        for k in 0..ring.len() {
            let (a, b) = (p[ring[k]], p[ring[(k + 1) % ring.len()]]);
            let side = (b.x - a.x) * (x.y - a.y) - (x.x - a.x) * (b.y - a.y);
            if a.y <= x.y && b.y > x.y && side > 0.0 {
                w += 1;
            } else if a.y > x.y && b.y <= x.y && side < 0.0 {
                w -= 1;
            }
        }
        w
    }

    /// Triangles covering the polygon: n − 2 of them, counter-clockwise, inside, and of the
    /// polygon's area in all.
    fn assert_covers(p: &[Point3<f64>], ring: &[usize], tris: &[[usize; 3]]) {
        assert_eq!(tris.len(), ring.len() - 2);
        let mut sum = 0.0;
        for t in tris {
            let a = area2(p, t);
            assert!(a > 0.0, "{t:?} is not counter-clockwise");
            sum += a;
            let c = t.iter().fold(Point2::origin(), |s, &v| {
                s + Vector3::new(p[v].x, p[v].y, 0.0).xy() / 3.0
            });
            assert_eq!(winds(p, ring, c), 1, "{t:?} lies outside the polygon");
        }
        let total = area2(p, ring);
        assert!(
            (sum - total).abs() <= 1e-12 * total.abs(),
            "{sum} against {total}"
        );
    }

    #[test]
    fn a_convex_polygon_is_the_fan_of_its_first_corner() {
        let hex: Vec<[f64; 2]> = (0..6)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / 6.0;
                [t.cos(), t.sin()]
            })
            .collect();
        let (p, ring) = flat(&hex);
        let tris = triangulate(&p, &ring).expect("convex");
        assert_eq!(tris, [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]]);
    }

    #[test]
    fn l_comb_and_a_34_corner_concave_polygon_are_covered_from_inside() {
        // A comb: teeth up from a bar, the first corner in a notch (a fan from it goes outside).
        let mut comb = vec![[0.0, 0.0], [9.0, 0.0]];
        for k in (0..5).rev() {
            let x = 2.0 * k as f64;
            comb.extend([[x + 1.0, 3.0], [x, 3.0]]);
            if k > 0 {
                comb.extend([[x, 1.0], [x - 1.0, 1.0]]);
            }
        }
        comb.rotate_left(5);
        // 34 corners: a star of 17 points, rotated so the first corner is a reflex one.
        let star: Vec<[f64; 2]> = (0..34)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / 34.0;
                let r = if k % 2 == 0 { 1.0 } else { 0.35 };
                [r * t.cos(), r * t.sin()]
            })
            .cycle()
            .skip(1)
            .take(34)
            .collect();
        for pts in [&L_SHAPE[..], &comb, &star] {
            let (p, ring) = flat(pts);
            let tris = triangulate(&p, &ring).expect("simple polygon");
            assert_covers(&p, &ring, &tris);
        }
    }

    #[test]
    fn a_clockwise_polygon_keeps_its_orientation() {
        let (p, mut ring) = flat(&L_SHAPE);
        ring.reverse();
        let tris = triangulate(&p, &ring).expect("simple");
        assert_eq!(tris.len(), 4);
        for t in &tris {
            assert!(area2(&p, t) < 0.0, "{t:?} turned");
        }
    }

    #[test]
    fn polygons_that_are_not_simple_are_refused_by_name() {
        let bow_tie = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]];
        let (p, ring) = flat(&bow_tie);
        assert!(matches!(
            triangulate(&p, &ring),
            Err(PolygonProblem::SelfIntersecting | PolygonProblem::NoArea)
        ));
        // Two corners at one position (a pinched outline).
        let pinched = [
            [0.0, 0.0],
            [2.0, 0.0],
            [1.0, 1.0],
            [2.0, 2.0],
            [0.0, 2.0],
            [1.0, 1.0],
        ];
        let (p, ring) = flat(&pinched);
        assert_eq!(
            triangulate(&p, &ring),
            Err(PolygonProblem::CoincidentCorners {
                first: 2,
                second: 5
            })
        );
        // A corner on another side.
        let touching = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [1.0, 0.0], [0.0, 2.0]];
        let (p, ring) = flat(&touching);
        assert_eq!(
            triangulate(&p, &ring),
            Err(PolygonProblem::SelfIntersecting)
        );
        let line = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]];
        let (p, ring) = flat(&line);
        assert_eq!(triangulate(&p, &ring), Err(PolygonProblem::NoArea));
    }

    #[test]
    fn a_strongly_twisted_polygon_is_refused_as_not_planar() {
        // A hexagon whose corners go up and down by more than its size: its projection on
        // the best-fit plane crosses itself.
        let p: Vec<Point3<f64>> = [0usize, 3, 1, 4, 2, 5]
            .iter()
            .enumerate()
            .map(|(k, &j)| {
                let t = std::f64::consts::TAU * j as f64 / 6.0;
                Point3::new(t.cos(), t.sin(), if k % 2 == 0 { 2.0 } else { -2.0 })
            })
            .collect();
        let ring: Vec<usize> = (0..6).collect();
        assert!(matches!(
            triangulate(&p, &ring),
            Err(PolygonProblem::NotPlanar | PolygonProblem::SelfIntersecting)
        ));
    }

    #[test]
    fn collinear_corners_on_a_side_are_kept() {
        // A square with two extra corners on its bottom side (a CAD n-gon's T-vertices).
        let (p, ring) = flat(&[
            [0.0, 0.0],
            [1.0, 0.0],
            [2.0, 0.0],
            [3.0, 0.0],
            [3.0, 3.0],
            [0.0, 3.0],
        ]);
        let tris = triangulate(&p, &ring).expect("simple");
        assert_covers(&p, &ring, &tris);
    }

    #[test]
    fn a_100k_corner_disk_polygon_is_cut_inside_it() {
        // The centre first, then the circle: a pie with one slice missing.
        let n = 100_000;
        let mut pts = vec![[0.0, 0.0]];
        pts.extend((0..n - 1).map(|k| {
            let t = std::f64::consts::TAU * k as f64 / (n - 1) as f64 * 0.999;
            [t.cos(), t.sin()]
        }));
        let (p, ring) = flat(&pts);
        let tris = triangulate(&p, &ring).expect("simple");
        assert_eq!(tris.len(), n - 2);
        let sum: f64 = tris.iter().map(|t| area2(&p, t)).sum();
        assert!((sum - area2(&p, &ring)).abs() < 1e-9);
        assert!(tris.iter().all(|t| area2(&p, t) > 0.0));
    }
}
