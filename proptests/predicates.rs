//! Properties of the exact predicates: sign symmetries under permutation, exactness on
//! near-degenerate input (against an independent exact truth), and the triangle-triangle test
//! against an independent separating-axis oracle in integer arithmetic.
//!
//! Case counts are fixed (`CASES`) so the suite's time is stable.

#[path = "seed.rs"]
mod seed;
use conemesh::predicates::{
    incircle, orient2d, orient3d, segment_triangle_intersect, triangles_intersect, Sign,
};
use nalgebra::{Point2, Point3};
use proptest::prelude::*;

const CASES: u32 = 512;

fn config() -> ProptestConfig {
    seed::config(CASES, "predicates", 0x9ed1c)
}

fn p2() -> impl Strategy<Value = Point2<f64>> {
    (-10.0..10.0f64, -10.0..10.0f64).prop_map(|(x, y)| Point2::new(x, y))
}

fn p3() -> impl Strategy<Value = Point3<f64>> {
    (-10.0..10.0f64, -10.0..10.0f64, -10.0..10.0f64).prop_map(|(x, y, z)| Point3::new(x, y, z))
}

/// Small integer coordinates: many exactly degenerate configurations (coplanar, collinear,
/// touching), which is where intersection code breaks.
fn ip3() -> impl Strategy<Value = [i64; 3]> {
    [-3i64..=3, -3i64..=3, -3i64..=3]
}

fn tri_i() -> impl Strategy<Value = [[i64; 3]; 3]> {
    [ip3(), ip3(), ip3()]
}

fn to_f(t: &[[i64; 3]; 3]) -> [Point3<f64>; 3] {
    t.map(|p| Point3::new(p[0] as f64, p[1] as f64, p[2] as f64))
}

fn sub(a: [i64; 3], b: [i64; 3]) -> [i64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [i64; 3], b: [i64; 3]) -> [i64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [i64; 3], b: [i64; 3]) -> i64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Separating-axis oracle for two non-degenerate triangles with integer corners (exact in
/// i64): disjoint iff some axis among the two normals, the nine edge×edge cross products and
/// the six in-plane edge normals separates their projections strictly.
fn sat_intersect(a: &[[i64; 3]; 3], b: &[[i64; 3]; 3]) -> bool {
    let ea: Vec<[i64; 3]> = (0..3).map(|i| sub(a[(i + 1) % 3], a[i])).collect();
    let eb: Vec<[i64; 3]> = (0..3).map(|i| sub(b[(i + 1) % 3], b[i])).collect();
    let na = cross(ea[0], ea[1]);
    let nb = cross(eb[0], eb[1]);
    let mut axes = vec![na, nb];
    for x in &ea {
        for y in &eb {
            axes.push(cross(*x, *y));
        }
        axes.push(cross(na, *x));
    }
    for y in &eb {
        axes.push(cross(nb, *y));
    }
    !axes.iter().filter(|ax| **ax != [0, 0, 0]).any(|ax| {
        let pa: Vec<i64> = a.iter().map(|p| dot(*p, *ax)).collect();
        let pb: Vec<i64> = b.iter().map(|p| dot(*p, *ax)).collect();
        let (amin, amax) = (*pa.iter().min().unwrap(), *pa.iter().max().unwrap());
        let (bmin, bmax) = (*pb.iter().min().unwrap(), *pb.iter().max().unwrap());
        amax < bmin || bmax < amin
    })
}

fn degenerate_i(t: &[[i64; 3]; 3]) -> bool {
    cross(sub(t[1], t[0]), sub(t[2], t[0])) == [0, 0, 0]
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn orient2d_swaps_and_rotations(a in p2(), b in p2(), c in p2()) {
        let s = orient2d(&a, &b, &c);
        prop_assert_eq!(orient2d(&b, &a, &c), s.reversed());
        prop_assert_eq!(orient2d(&a, &c, &b), s.reversed());
        prop_assert_eq!(orient2d(&b, &c, &a), s);
        prop_assert_eq!(orient2d(&c, &a, &b), s);
    }

    #[test]
    fn orient3d_swaps_and_even_permutations(a in p3(), b in p3(), c in p3(), d in p3()) {
        let s = orient3d(&a, &b, &c, &d);
        prop_assert_eq!(orient3d(&b, &a, &c, &d), s.reversed());
        prop_assert_eq!(orient3d(&a, &b, &d, &c), s.reversed());
        prop_assert_eq!(orient3d(&b, &c, &a, &d), s);
        prop_assert_eq!(orient3d(&b, &a, &d, &c), s);
        // d against (a, b, c) equals a against (d, c, b) (an even permutation: two swaps).
        prop_assert_eq!(orient3d(&d, &c, &b, &a), s);
    }

    #[test]
    fn incircle_swaps_and_rotations(a in p2(), b in p2(), c in p2(), d in p2()) {
        let s = incircle(&a, &b, &c, &d);
        prop_assert_eq!(incircle(&b, &a, &c, &d), s.reversed());
        prop_assert_eq!(incircle(&b, &c, &a, &d), s);
        prop_assert_eq!(incircle(&c, &a, &b, &d), s);
        // The sign convention: for a counter-clockwise triple, positive = inside.
        if orient2d(&a, &b, &c) == Sign::Positive {
            let centroid = Point2::from((a.coords + b.coords + c.coords) / 3.0);
            prop_assert_ne!(incircle(&a, &b, &c, &centroid), Sign::Negative);
        }
    }

    /// `a`, `b` on the line y = x, `c` a few ulps (~1e-17 at these magnitudes) off it. The
    /// truth is sign(s − t)·sign(c.y − c.x), two exact comparisons.
    #[test]
    fn orient2d_exact_next_to_a_line(t in 0.0625..0.125f64, s in 0.0625..0.125f64,
                                     u in 0.0625..0.125f64, k in -4i32..=4) {
        let a = Point2::new(t, t);
        let b = Point2::new(s, s);
        let ulp = f64::EPSILON / 16.0; // spacing of doubles in [1/16, 1/8)
        let c = Point2::new(u, u + k as f64 * ulp);
        let truth = |x: f64| if x > 0.0 { Sign::Positive } else if x < 0.0 { Sign::Negative } else { Sign::Zero };
        let expect = match truth(s - t) {
            Sign::Zero => Sign::Zero,
            Sign::Positive => truth(c.y - c.x),
            Sign::Negative => truth(c.y - c.x).reversed(),
        };
        prop_assert_eq!(orient2d(&a, &b, &c), expect);
    }

    /// `a, b, c` on the plane z = x, `d` a few ulps off it: the truth is
    /// sign(orient2d of the xy projection)·sign(d.z − d.x).
    #[test]
    fn orient3d_exact_next_to_a_plane(a in p3(), b in p3(), c in p3(),
                                      u in 0.0625..0.125f64, v in -1.0..1.0f64, k in -4i32..=4) {
        let on = |p: Point3<f64>| Point3::new(p.x, p.y, p.x);
        let (a, b, c) = (on(a), on(b), on(c));
        let d = Point3::new(u, v, u + k as f64 * (f64::EPSILON / 16.0));
        let proj = orient2d(&a.xy(), &b.xy(), &c.xy());
        let off = if d.z > d.x { Sign::Positive } else if d.z < d.x { Sign::Negative } else { Sign::Zero };
        let expect = match proj {
            Sign::Zero => Sign::Zero,
            Sign::Positive => off,
            Sign::Negative => off.reversed(),
        };
        prop_assert_eq!(orient3d(&a, &b, &c, &d), expect);
    }

    #[test]
    fn triangles_intersect_is_symmetric_and_relabelling_invariant(a in tri_i(), b in tri_i(),
                                                                  shift in ip3(), scale in -3i32..=3) {
        let (fa, fb) = (to_f(&a), to_f(&b));
        let r = triangles_intersect(&fa, &fb);
        prop_assert_eq!(triangles_intersect(&fb, &fa), r);
        prop_assert_eq!(triangles_intersect(&[fa[1], fa[2], fa[0]], &fb), r);
        prop_assert_eq!(triangles_intersect(&[fa[0], fa[2], fa[1]], &[fb[2], fb[1], fb[0]]), r);
        // Translation by an integer vector and scaling by a power of two are exact.
        let m = 2f64.powi(scale);
        let tr = |t: &[Point3<f64>; 3]| t.map(|p| Point3::new(
            (p.x + shift[0] as f64) * m, (p.y + shift[1] as f64) * m, (p.z + shift[2] as f64) * m));
        prop_assert_eq!(triangles_intersect(&tr(&fa), &tr(&fb)), r);
        // An intersection implies some edge meets the other triangle, and vice versa.
        let edges = (0..3).any(|i| segment_triangle_intersect(&fa[i], &fa[(i + 1) % 3], &fb))
            || (0..3).any(|i| segment_triangle_intersect(&fb[i], &fb[(i + 1) % 3], &fa));
        prop_assert_eq!(edges, r);
    }

    #[test]
    fn triangles_intersect_agrees_with_separating_axes(a in tri_i(), b in tri_i()) {
        prop_assume!(!degenerate_i(&a) && !degenerate_i(&b));
        prop_assert_eq!(triangles_intersect(&to_f(&a), &to_f(&b)), sat_intersect(&a, &b));
    }
}

/// At least one near-degenerate configuration where the naive float determinant has the
/// wrong sign (otherwise the exactness properties above would prove nothing).
#[test]
fn naive_float_orientation_gets_some_sign_wrong() {
    let (a, b) = (Point2::new(12.0, 12.0), Point2::new(24.0, 24.0));
    let mut wrong = 0;
    for i in 0..64 {
        for j in 0..64 {
            let c = Point2::new(0.5 + i as f64 * f64::EPSILON, 0.5 + j as f64 * f64::EPSILON);
            let naive = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
            let naive = if naive > 0.0 {
                Sign::Positive
            } else if naive < 0.0 {
                Sign::Negative
            } else {
                Sign::Zero
            };
            let truth = if c.y > c.x {
                Sign::Positive
            } else if c.y < c.x {
                Sign::Negative
            } else {
                Sign::Zero
            };
            assert_eq!(orient2d(&a, &b, &c), truth);
            if naive != truth {
                wrong += 1;
            }
        }
    }
    assert!(wrong > 0);
}
