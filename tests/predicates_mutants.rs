//! Tests that pin `crate::predicates` to independent oracles, written to kill the mutants
//! `cargo mutants` finds surviving in `src/predicates.rs` (TESTING.md).
//!
//! Oracles: exact integer determinants (every coordinate is a small integer, so `i128`
//! arithmetic is exact), an exact rational segment–segment test, and CGAL's exact
//! `do_intersect` through `reference/cgal/conemesh-cgal-check` (same discovery and failure
//! rules as `tests/cgal_crossval.rs`).

use conemesh::invariants;
use conemesh::io;
use conemesh::predicates::{
    collinear3d, incircle, orient2d, orient3d, point_in_triangle, segment_triangle_intersect,
    segments_intersect, segments_intersect_3d, triangles_intersect, SegmentIntersection, Sign,
};
use conemesh::TriMesh;
use nalgebra::{Point2, Point3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::Value;
use std::path::PathBuf;
use std::process::Command;

fn sign(x: i128) -> Sign {
    match x.cmp(&0) {
        std::cmp::Ordering::Greater => Sign::Positive,
        std::cmp::Ordering::Less => Sign::Negative,
        std::cmp::Ordering::Equal => Sign::Zero,
    }
}

type I2 = [i64; 2];
type I3 = [i64; 3];

fn f2(p: I2) -> Point2<f64> {
    Point2::new(p[0] as f64, p[1] as f64)
}

fn f3(p: I3) -> Point3<f64> {
    Point3::new(p[0] as f64, p[1] as f64, p[2] as f64)
}

fn det2(a: I2, b: I2, c: I2) -> i128 {
    let (bx, by) = ((b[0] - a[0]) as i128, (b[1] - a[1]) as i128);
    let (cx, cy) = ((c[0] - a[0]) as i128, (c[1] - a[1]) as i128);
    bx * cy - by * cx
}

fn det3(a: I3, b: I3, c: I3, d: I3) -> i128 {
    let v = |p: I3| {
        [
            (p[0] - a[0]) as i128,
            (p[1] - a[1]) as i128,
            (p[2] - a[2]) as i128,
        ]
    };
    let (u, v2, w) = (v(b), v(c), v(d));
    u[0] * (v2[1] * w[2] - v2[2] * w[1]) - u[1] * (v2[0] * w[2] - v2[2] * w[0])
        + u[2] * (v2[0] * w[1] - v2[1] * w[0])
}

fn det_incircle(a: I2, b: I2, c: I2, d: I2) -> i128 {
    let row = |p: I2| {
        let (x, y) = ((p[0] - d[0]) as i128, (p[1] - d[1]) as i128);
        [x, y, x * x + y * y]
    };
    let (r0, r1, r2) = (row(a), row(b), row(c));
    r0[0] * (r1[1] * r2[2] - r1[2] * r2[1]) - r0[1] * (r1[0] * r2[2] - r1[2] * r2[0])
        + r0[2] * (r1[0] * r2[1] - r1[1] * r2[0])
}

fn rnd2(rng: &mut ChaCha8Rng, k: i64) -> I2 {
    [rng.random_range(-k..=k), rng.random_range(-k..=k)]
}

fn rnd3(rng: &mut ChaCha8Rng, k: i64) -> I3 {
    [
        rng.random_range(-k..=k),
        rng.random_range(-k..=k),
        rng.random_range(-k..=k),
    ]
}

#[test]
fn orientation_and_incircle_signs_equal_integer_determinants() {
    // Small grids make zeros (collinear, coplanar, cocircular) frequent.
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut zeros = [0usize; 3];
    for _ in 0..3000 {
        let (a, b, c, d) = (
            rnd2(&mut rng, 3),
            rnd2(&mut rng, 3),
            rnd2(&mut rng, 3),
            rnd2(&mut rng, 3),
        );
        let o = sign(det2(a, b, c));
        assert_eq!(
            orient2d(&f2(a), &f2(b), &f2(c)),
            o,
            "orient2d {a:?} {b:?} {c:?}"
        );
        assert_eq!(orient2d(&f2(b), &f2(a), &f2(c)), o.reversed());
        // incircle > 0 when d is inside the circle through a, b, c (ccw).
        let ic = sign(det_incircle(a, b, c, d));
        assert_eq!(
            incircle(&f2(a), &f2(b), &f2(c), &f2(d)),
            ic,
            "incircle {a:?} {b:?} {c:?} {d:?}"
        );
        zeros[0] += (o == Sign::Zero) as usize;
        zeros[1] += (ic == Sign::Zero) as usize;
        let (p, q, r, s) = (
            rnd3(&mut rng, 2),
            rnd3(&mut rng, 2),
            rnd3(&mut rng, 2),
            rnd3(&mut rng, 2),
        );
        // orient3d > 0 when s is on the side of (q − p) × (r − p).
        let o3 = sign(det3(p, q, r, s));
        assert_eq!(orient3d(&f3(p), &f3(q), &f3(r), &f3(s)), o3, "orient3d");
        zeros[2] += (o3 == Sign::Zero) as usize;
        // collinear3d: the cross product is zero.
        let cr = {
            let (u, v) = (
                [q[0] - p[0], q[1] - p[1], q[2] - p[2]],
                [r[0] - p[0], r[1] - p[1], r[2] - p[2]],
            );
            [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ]
        };
        assert_eq!(
            collinear3d(&f3(p), &f3(q), &f3(r)),
            cr == [0, 0, 0],
            "collinear3d {p:?} {q:?} {r:?}"
        );
    }
    // The grid really produced degenerate inputs (else the test proves little).
    assert!(zeros.iter().all(|&z| z > 50), "{zeros:?}");
}

/// Exact rational oracle for closed 2D segments (non-degenerate): `None` = disjoint,
/// `Some(true)` = one crossing point interior to both, `Some(false)` = any other contact.
fn segment_oracle(a: I2, b: I2, c: I2, d: I2) -> Option<bool> {
    let r = [(b[0] - a[0]) as i128, (b[1] - a[1]) as i128];
    let s = [(d[0] - c[0]) as i128, (d[1] - c[1]) as i128];
    let ca = [(c[0] - a[0]) as i128, (c[1] - a[1]) as i128];
    let cross = |u: [i128; 2], v: [i128; 2]| u[0] * v[1] - u[1] * v[0];
    let den = cross(r, s);
    if den != 0 {
        // a + t r = c + u s, t = (ca × s) / den, u = (ca × r) / den.
        let (mut tn, mut un, mut dd) = (cross(ca, s), cross(ca, r), den);
        if dd < 0 {
            (tn, un, dd) = (-tn, -un, -dd);
        }
        let inside = |x: i128| (0..=dd).contains(&x);
        if !(inside(tn) && inside(un)) {
            return None;
        }
        let interior = |x: i128| x > 0 && x < dd;
        return Some(interior(tn) && interior(un));
    }
    if cross(ca, r) != 0 {
        return None; // parallel, not collinear
    }
    // Collinear: overlap of the parameter intervals along r.
    let rr = r[0] * r[0] + r[1] * r[1];
    let t = |p: I2| ((p[0] - a[0]) as i128) * r[0] + ((p[1] - a[1]) as i128) * r[1];
    let (t0, t1) = (t(c).min(t(d)), t(c).max(t(d)));
    (t1 >= 0 && t0 <= rr).then_some(false)
}

#[test]
fn segments_intersect_equals_rational_oracle() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let mut seen = [0usize; 3];
    for _ in 0..5000 {
        let (a, b, c, d) = (
            rnd2(&mut rng, 3),
            rnd2(&mut rng, 3),
            rnd2(&mut rng, 3),
            rnd2(&mut rng, 3),
        );
        if a == b || c == d {
            continue;
        }
        let want = match segment_oracle(a, b, c, d) {
            None => SegmentIntersection::Disjoint,
            Some(true) => SegmentIntersection::Proper,
            Some(false) => SegmentIntersection::Touching,
        };
        seen[want as usize] += 1;
        let got = segments_intersect(&f2(a), &f2(b), &f2(c), &f2(d));
        assert_eq!(got, want, "{a:?}-{b:?} vs {c:?}-{d:?}");
        // Symmetric in the two segments and in their directions.
        assert_eq!(segments_intersect(&f2(d), &f2(c), &f2(b), &f2(a)), want);
        // The 3D test on the same segments lifted to a tilted plane agrees on contact.
        let lift = |p: I2| Point3::new(p[0] as f64, p[1] as f64, (p[0] + 2 * p[1]) as f64);
        assert_eq!(
            segments_intersect_3d(&lift(a), &lift(b), &lift(c), &lift(d)),
            want != SegmentIntersection::Disjoint,
            "3D {a:?}-{b:?} vs {c:?}-{d:?}"
        );
    }
    assert!(seen.iter().all(|&n| n > 100), "{seen:?}");
    // Non-coplanar 3D segments never meet; a segment through another's midpoint in 3D does.
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    assert!(!segments_intersect_3d(
        &p(0.0, 0.0, 0.0),
        &p(2.0, 0.0, 0.0),
        &p(1.0, -1.0, 1.0),
        &p(1.0, 1.0, 1.0)
    ));
    assert!(segments_intersect_3d(
        &p(0.0, 0.0, 0.0),
        &p(2.0, 0.0, 0.0),
        &p(1.0, -1.0, 0.0),
        &p(1.0, 1.0, 0.0)
    ));
}

#[test]
fn point_in_triangle_counts_edges_exactly() {
    let (a, b, c) = ([0, 0], [4, 0], [0, 4]);
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    for _ in 0..2000 {
        let p = rnd2(&mut rng, 5);
        let s = [det2(a, b, p), det2(b, c, p), det2(c, a, p)];
        let want = (!s.iter().any(|&x| x < 0)).then(|| s.iter().filter(|&&x| x == 0).count());
        assert_eq!(
            point_in_triangle(&f2(a), &f2(b), &f2(c), &f2(p)),
            want,
            "{p:?}"
        );
    }
}

// ---------------------------------------------------------------------------------------
// Against CGAL's exact do_intersect.

fn checker() -> PathBuf {
    if let Ok(p) = std::env::var("CONEMESH_CGAL_CHECK") {
        if std::path::Path::new(&p).is_file() {
            return PathBuf::from(p);
        }
    }
    let b =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("reference/cgal/build/conemesh-cgal-check");
    assert!(
        b.is_file(),
        "CGAL checker missing at {}: run ./scripts/test (installs libcgal-dev, cmake, g++ and \
         builds it), or build reference/cgal with cmake",
        b.display()
    );
    b
}

fn cgal_pairs(m: &TriMesh) -> Vec<(usize, usize)> {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("soup.off");
    io::write_mesh(&path, m).expect("write OFF");
    let out = Command::new(checker())
        .arg(&path)
        .output()
        .expect("run checker");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("json");
    v["self_intersecting_pairs"]
        .as_array()
        .expect("pairs")
        .iter()
        .map(|p| {
            (
                p[0].as_u64().expect("id") as usize,
                p[1].as_u64().expect("id") as usize,
            )
        })
        .collect()
}

fn soup(tris: &[[I3; 3]]) -> TriMesh {
    let pos: Vec<Point3<f64>> = tris.iter().flat_map(|t| t.map(f3)).collect();
    let idx: Vec<[usize; 3]> = (0..tris.len())
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    TriMesh::from_indices(pos, &idx).expect("soup")
}

#[test]
fn triangle_triangle_and_segment_triangle_match_cgal() {
    // Triangles with their own vertices (no shared ids, so CGAL tests every pair with its exact
    // do_intersect). Half lie in the plane z = 0 (coplanar cases: 2D edge and point tests),
    // half in a small cube (touching at points, edges, faces is frequent).
    let mut rng = ChaCha8Rng::seed_from_u64(14);
    let mut tris: Vec<[I3; 3]> = Vec::new();
    while tris.len() < 300 {
        let flat = tris.len() % 2 == 0;
        let mut p = || {
            let mut q = rnd3(&mut rng, 2);
            if flat {
                q[2] = 0;
            }
            q
        };
        let t = [p(), p(), p()];
        if !collinear3d(&f3(t[0]), &f3(t[1]), &f3(t[2])) {
            tris.push(t);
        }
    }
    let m = soup(&tris);
    let mut ours = Vec::new();
    for i in 0..tris.len() {
        for j in i + 1..tris.len() {
            let (a, b) = (tris[i].map(f3), tris[j].map(f3));
            let hit = triangles_intersect(&a, &b);
            assert_eq!(hit, triangles_intersect(&b, &a), "symmetry f{i} f{j}");
            // A triangle pair meets iff an edge of one meets the other (convexity).
            let by_edges = (0..3).any(|k| segment_triangle_intersect(&a[k], &a[(k + 1) % 3], &b))
                || (0..3).any(|k| segment_triangle_intersect(&b[k], &b[(k + 1) % 3], &a));
            assert_eq!(hit, by_edges, "edge characterisation f{i} f{j}");
            if hit {
                ours.push((i, j));
            }
        }
    }
    let theirs = cgal_pairs(&m);
    assert!(theirs.len() > 100, "few intersections: {}", theirs.len());
    assert!(
        theirs.len() < tris.len() * (tris.len() - 1) / 2 / 2,
        "almost all pairs intersect: the corpus has no disjoint cases"
    );
    assert_eq!(ours, theirs, "triangles_intersect vs CGAL do_intersect");
    assert_eq!(
        invariants::self_intersections(&m)
            .into_iter()
            .map(|(f, g)| (f.idx(), g.idx()))
            .collect::<Vec<_>>(),
        theirs
    );
}

#[test]
fn shared_vertex_and_shared_edge_rules_match_cgal() {
    // Faces drawn from a pool of 10 points in a small cube: many share vertices and edges (in
    // both directions, non-manifold), so CGAL's shared-edge and shared-vertex rules decide.
    let mut rng = ChaCha8Rng::seed_from_u64(15);
    let pool: Vec<I3> = (0..10)
        .map(|i| {
            let mut q = rnd3(&mut rng, 2);
            if i < 5 {
                q[2] = 0; // five coplanar points: coplanar folds and overlaps
            }
            q
        })
        .collect();
    let mut faces: Vec<[usize; 3]> = Vec::new();
    while faces.len() < 120 {
        let t = [
            rng.random_range(0..10),
            rng.random_range(0..10),
            rng.random_range(0..10),
        ];
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            continue;
        }
        if collinear3d(&f3(pool[t[0]]), &f3(pool[t[1]]), &f3(pool[t[2]])) {
            continue;
        }
        faces.push(t);
    }
    let m = TriMesh::from_indices(pool.iter().map(|&p| f3(p)).collect(), &faces).expect("mesh");
    let ours: Vec<(usize, usize)> = invariants::self_intersections(&m)
        .into_iter()
        .map(|(f, g)| (f.idx(), g.idx()))
        .collect();
    let theirs = cgal_pairs(&m);
    assert!(!theirs.is_empty());
    assert_eq!(
        ours, theirs,
        "faces_intersect rules vs CGAL's do_faces_intersect"
    );
}

/// A degenerate (collinear) triangle is the union of its three edges: a segment crossing one
/// of those edges strictly between the corners meets it; one passing beside it does not.
#[test]
fn segment_meets_a_degenerate_triangle_along_its_edges() {
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    let t = [p(0.0, 0.0, 0.0), p(4.0, 0.0, 0.0), p(1.0, 0.0, 0.0)];
    // Crosses the long edge at (2, 0, 0), which is no corner.
    assert!(segment_triangle_intersect(
        &p(2.0, -1.0, 0.0),
        &p(2.0, 1.0, 0.0),
        &t
    ));
    // Out of the line's plane at x = 2: passes above the edge.
    assert!(!segment_triangle_intersect(
        &p(2.0, -1.0, 1.0),
        &p(2.0, 1.0, 1.0),
        &t
    ));
    // Beyond the far corner.
    assert!(!segment_triangle_intersect(
        &p(5.0, -1.0, 0.0),
        &p(5.0, 1.0, 0.0),
        &t
    ));
}
