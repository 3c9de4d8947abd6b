//! Cross-validation of conemesh's mesh verdicts against CGAL (issue 5).
//!
//! The witness is `reference/cgal/conemesh-cgal-check` (CGAL 5.5, exact Epick predicates).
//! It is found through `CONEMESH_CGAL_CHECK` (set by `scripts/test`) or at
//! `reference/cgal/build/conemesh-cgal-check`, and built with CMake when missing. If it cannot
//! be built the tests FAIL, naming the missing package: they never pass silently.
//!
//! Every case is written as OFF (or read from `../shared/meshes`), given to the checker, and
//! its JSON compared field by field with conemesh's own verdicts on the same triangles. A
//! disagreement lists the case and every differing field.
//!
//! Conventions (also in TESTING.md):
//! - Both sides use CGAL's self-intersection semantics: a degenerate (exactly collinear) face
//!   `f` is reported as the pair `(f, f)` and is not tested against other faces; faces sharing
//!   an edge intersect only when coplanar and folded onto each other; faces sharing a vertex
//!   only when an opposite edge meets the other face; touching counts. Pairs are compared as
//!   sorted lists of `(f, g)`, `f <= g`, in the file's face order.
//! - For soups that are not polygon meshes (non-manifold, inconsistently oriented), CGAL 5.5
//!   cannot build a `Surface_mesh`: `closed` and `boundary_cycles` are `null` there and only the
//!   counts, components, Euler characteristic, degenerate faces and self-intersections (the
//!   checker's replica of CGAL's pair test, itself validated against
//!   `PMP::self_intersections` on every valid mesh) are compared.
//! - conemesh's "valid" (manifold, consistently oriented, no self-intersection, no
//!   degenerate face) is compared with CGAL's `valid_polygon_mesh && !self_intersects`.

use conemesh::check::{check_mesh, CheckOptions, FIRST_FEW};
use conemesh::mesh::generators;
use conemesh::predicates::{orient2d, segments_intersect, SegmentIntersection, Sign};
use conemesh::{invariants, io, FaceId, Topology, TriMesh, VertexId};
use nalgebra::{Point2, Point3, Vector3};
use rand::SeedableRng;
use serde_json::Value;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

// The shared-mesh catalogue, through `param_cover` below (which includes it too).
use param_cover::catalogue as common;

#[path = "common/cgal.rs"]
mod cgal;
use cgal::run_checker;

// ---------------------------------------------------------------------------------------
// Files: conemesh's own reader and writer (so the witness sees exactly the bytes conemesh
// writes; OFF text stores f64 exactly).

fn write_off(path: &Path, m: &TriMesh) {
    io::write_mesh(path, m).unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
}

fn read(path: &Path) -> TriMesh {
    io::read_mesh(path)
        .unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
        .mesh
}

// ---------------------------------------------------------------------------------------
// conemesh's verdicts.

/// Compare conemesh with the checker's JSON; returns one line per disagreement.
fn compare(case: &str, m: &TriMesh, cgal: &Value) -> Vec<String> {
    let topo = Topology::build(m);
    let mut diffs = Vec::new();
    let mut eq = |field: &str, ours: Value| {
        let theirs = cgal.get(field).cloned().unwrap_or(Value::Null);
        if theirs != ours {
            diffs.push(format!("{case}: {field}: conemesh {ours} vs CGAL {theirs}"));
        }
    };
    let valid = topo.is_oriented_manifold();
    eq("vertices", m.n_vertices().into());
    eq("faces", m.n_faces().into());
    eq("triangle_only", true.into());
    eq("valid_polygon_mesh", valid.into());
    let referenced = m.n_vertices() - m.unreferenced_vertices().len();
    eq("referenced_vertices", referenced.into());
    eq("edges", topo.edges().len().into());
    eq("connected_components", topo.components().len().into());
    eq("euler_characteristic", topo.euler_characteristic().into());
    if valid {
        eq("closed", topo.boundary_loops().is_empty().into());
        eq("boundary_cycles", topo.boundary_loops().len().into());
    }
    let deg: Vec<usize> = invariants::degenerate_faces(m)
        .into_iter()
        .map(FaceId::idx)
        .collect();
    eq("degenerate_faces", deg.into());
    // Same convention on both sides: a degenerate face f is the pair (f, f) and takes no
    // further part; other pairs (f, g) with f < g, sorted.
    let pairs: Vec<[usize; 2]> = invariants::self_intersections(m)
        .into_iter()
        .map(|(f, g)| [f.idx(), g.idx()])
        .collect();
    eq("self_intersects", (!pairs.is_empty()).into());
    eq("self_intersecting_pairs", pairs.clone().into());
    // The whole verdict: a valid polygon mesh (manifold, oriented) without self-intersections.
    let manifold_oriented = invariants::certify_manifold(m, &topo).is_ok()
        && invariants::certify_oriented(m, &topo).is_ok();
    if manifold_oriented != valid {
        diffs.push(format!(
            "{case}: certify_manifold+certify_oriented say {manifold_oriented}, Topology says {valid}"
        ));
    }
    let ours_ok = manifold_oriented && pairs.is_empty();
    let cgal_ok = cgal["valid_polygon_mesh"] == Value::Bool(true)
        && cgal["self_intersects"] == Value::Bool(false);
    if ours_ok != cgal_ok {
        diffs.push(format!(
            "{case}: overall validity: conemesh {ours_ok} vs CGAL {cgal_ok}"
        ));
    }
    // `conemesh check`'s report (what the CLI prints) against the same witness.
    let rep = check_mesh(
        m,
        &CheckOptions {
            self_intersections: true,
        },
    );
    let cgal_distinct: Vec<[usize; 2]> = pairs.iter().copied().filter(|p| p[0] != p[1]).collect();
    let rep_first: Vec<[usize; 2]> = rep
        .self_intersections
        .as_ref()
        .map(|s| s.first.iter().map(|p| [p.0.idx(), p.1.idx()]).collect())
        .unwrap_or_default();
    let ours = (
        rep.valid,
        rep.components,
        rep.euler,
        rep.degenerate_faces,
        rep.self_intersections.as_ref().map(|s| s.pairs),
        rep_first,
    );
    let theirs = (
        cgal_ok,
        cgal["connected_components"].as_u64().unwrap_or(u64::MAX) as usize,
        cgal["euler_characteristic"].as_i64().unwrap_or(i64::MIN),
        cgal["degenerate_faces"]
            .as_array()
            .map_or(usize::MAX, Vec::len),
        Some(cgal_distinct.len()),
        cgal_distinct
            .into_iter()
            .take(FIRST_FEW)
            .collect::<Vec<_>>(),
    );
    if ours != theirs {
        diffs.push(format!(
            "{case}: check_mesh (valid, components, euler, degenerate, pairs, first pairs) \
             {ours:?} vs CGAL {theirs:?}"
        ));
    }
    if valid && rep.boundary_loops as u64 != cgal["boundary_cycles"].as_u64().unwrap_or(u64::MAX) {
        diffs.push(format!(
            "{case}: check_mesh boundary loops {} vs CGAL {}",
            rep.boundary_loops, cgal["boundary_cycles"]
        ));
    }
    diffs
}

fn check_case(dir: &Path, name: &str, m: &TriMesh) -> (Value, Vec<String>) {
    let path = dir.join(format!("{name}.off"));
    write_off(&path, m);
    let cgal = run_checker(&path, &[]);
    let d = compare(name, m, &cgal);
    (cgal, d)
}

// ---------------------------------------------------------------------------------------
// The broken-mesh corpus (generated in code).

fn translated(m: &TriMesh, t: Vector3<f64>) -> TriMesh {
    let mut m = m.clone();
    for p in &mut m.positions {
        *p += t;
    }
    m
}

fn merged(a: &TriMesh, b: &TriMesh) -> TriMesh {
    let n = a.n_vertices() as u32;
    let mut m = a.clone();
    m.positions.extend_from_slice(&b.positions);
    m.triangles.extend(b.triangles.iter().map(|t| {
        [
            VertexId(t[0].0 + n),
            VertexId(t[1].0 + n),
            VertexId(t[2].0 + n),
        ]
    }));
    m
}

fn mesh(pos: &[[f64; 3]], tris: &[[usize; 3]]) -> TriMesh {
    let p = pos.iter().map(|c| Point3::new(c[0], c[1], c[2])).collect();
    TriMesh::from_indices(p, tris).expect("corpus arrays are valid")
}

fn nearest_vertex(m: &TriMesh, p: Point3<f64>) -> usize {
    let mut best = (f64::INFINITY, 0);
    for (i, q) in m.positions.iter().enumerate() {
        let d = (q - p).norm();
        if d < best.0 {
            best = (d, i);
        }
    }
    best.1
}

/// What a corpus case is built to be (asserted against CGAL, so the corpus cannot rot).
struct Expect {
    valid: bool,
    self_intersects: bool,
    components: usize,
    boundary_cycles: Option<usize>,
}

const fn ex(valid: bool, si: bool, comps: usize, bnd: Option<usize>) -> Option<Expect> {
    Some(Expect {
        valid,
        self_intersects: si,
        components: comps,
        boundary_cycles: bnd,
    })
}

fn corpus() -> Vec<(&'static str, TriMesh, Option<Expect>)> {
    let sphere = generators::icosphere(1.0, 2);
    let mut cases = Vec::new();

    cases.push((
        "interpenetrating_icospheres",
        merged(&sphere, &translated(&sphere, Vector3::new(0.7, 0.1, 0.05))),
        ex(true, true, 2, Some(0)),
    ));

    // A vertex pushed through the sphere: its fan crosses the far side.
    let mut s = sphere.clone();
    s.positions[0] = Point3::from(s.positions[0].coords * -1.5);
    cases.push((
        "icosphere_vertex_pushed_through",
        s,
        ex(true, true, 1, Some(0)),
    ));

    // Torus (R = 2, r = 0.5): the outer-equator vertex at (2.5, 0, 0) pushed to x = 1.2,
    // through the inner wall at x = 1.5.
    let mut t = generators::torus(2.0, 0.5, 24, 12);
    let v = nearest_vertex(&t, Point3::new(2.5, 0.0, 0.0));
    t.positions[v] = Point3::new(1.2, 0.0, 0.0);
    cases.push(("torus_vertex_pushed_through", t, ex(true, true, 1, Some(0))));

    // Non-manifold edge: a third face standing on an interior edge of a flat disk.
    let mut d = generators::disk(1.0, 3, 6);
    let topo = Topology::build(&d);
    let (a, b) = topo
        .edges()
        .iter()
        .zip(topo.edge_face_counts())
        .find(|(_, &c)| c == 2)
        .map(|(e, _)| (e.0, e.1))
        .expect("disk has interior edges");
    let mid = nalgebra::center(d.position(a), d.position(b)) + Vector3::new(0.0, 0.0, 1.0);
    d.positions.push(mid);
    let apex = VertexId::new(d.n_vertices() - 1);
    d.triangles.push([a, b, apex]);
    cases.push(("non_manifold_edge", d, ex(false, false, 1, None)));

    // One face of a sphere reversed.
    let mut f = sphere.clone();
    f.triangles[7].swap(1, 2);
    cases.push(("flipped_face", f, ex(false, false, 1, None)));

    // Two tetrahedra sharing only their apex: a non-manifold (pinched) vertex.
    let tets = mesh(
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, -1.0],
            [1.0, 0.0, 1.0],
            [-1.0, 1.0, 1.0],
            [-1.0, -1.0, 1.0],
        ],
        &[
            [0, 1, 2],
            [0, 2, 3],
            [0, 3, 1],
            [1, 3, 2],
            [0, 5, 4],
            [0, 6, 5],
            [0, 4, 6],
            [4, 5, 6],
        ],
    );
    cases.push(("pinched_tetrahedra", tets, ex(false, false, 2, None)));

    // Exactly collinear face (integer coordinates) closing a flat strip.
    let strip = mesh(
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
        ],
        &[[0, 1, 3], [1, 2, 3], [0, 2, 1]],
    );
    cases.push(("degenerate_strip", strip, ex(true, true, 1, Some(1))));

    // A closed plate with one diagonal split at its exact midpoint on one side only: a
    // zero-area face [a, m, c] and a T-junction where m touches the face across the diagonal.
    let mut plate = generators::genus_plate(0, 1);
    let (fi, (a, c)) = plate
        .triangles
        .iter()
        .enumerate()
        .find_map(|(i, t)| {
            (0..3).find_map(|k| {
                let (p, q) = (plate.position(t[k]), plate.position(t[(k + 1) % 3]));
                (p.z == q.z && p.x != q.x && p.y != q.y).then_some((i, (t[(k + 1) % 3], t[k])))
            })
        })
        .expect("plate has diagonals");
    // face fi runs c → a along the diagonal; its third vertex:
    let t = plate.triangles[fi];
    let b = t
        .into_iter()
        .find(|&v| v != a && v != c)
        .expect("third vertex");
    plate
        .positions
        .push(nalgebra::center(plate.position(a), plate.position(c)));
    let m = VertexId::new(plate.n_vertices() - 1);
    // Face fi is the cycle (c, a, b). Split it at m into (c, m, b) and (m, a, b); the
    // degenerate (c, a, m) closes the gap against the face across the diagonal (a → c).
    plate.triangles[fi] = [c, m, b];
    plate.triangles.push([m, a, b]);
    plate.triangles.push([c, a, m]);
    cases.push((
        "degenerate_plate_t_junction",
        plate,
        ex(true, true, 1, Some(0)),
    ));

    cases.push((
        "two_components",
        merged(&sphere, &translated(&sphere, Vector3::new(3.0, 0.0, 0.0))),
        ex(true, false, 2, Some(0)),
    ));
    cases.push((
        "disk",
        generators::disk(1.0, 4, 8),
        ex(true, false, 1, Some(1)),
    ));
    cases.push((
        "cylinder",
        generators::cylinder(1.0, 2.0, 16, 4),
        ex(true, false, 1, Some(2)),
    ));

    // Sphere with two far-apart faces removed: two holes.
    let mut holes = sphere.clone();
    let c0 = holes.face_centroid(FaceId(0));
    let far = holes
        .faces()
        .max_by(|&f, &g| {
            let (df, dg) = (
                (holes.face_centroid(f) - c0).norm(),
                (holes.face_centroid(g) - c0).norm(),
            );
            df.total_cmp(&dg)
        })
        .expect("faces");
    holes.triangles.remove(far.idx());
    holes.triangles.remove(0);
    cases.push(("icosphere_two_holes", holes, ex(true, false, 1, Some(2))));

    cases.push((
        "genus_plate_2",
        generators::genus_plate(2, 2),
        ex(true, false, 1, Some(0)),
    ));

    // Two triangles sharing an edge, folded flat onto each other (coplanar overlap).
    let fold = mesh(
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.3, 1.0, 0.0],
            [0.5, 0.5, 0.0],
        ],
        &[[0, 1, 2], [1, 0, 3]],
    );
    cases.push(("coplanar_fold", fold, ex(true, true, 1, Some(1))));

    // Two coplanar triangles sharing one vertex, one poking into the other.
    let poke = mesh(
        &[
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            [0.5, 0.5, 0.0],
            [3.0, 1.0, 0.0],
        ],
        &[[0, 1, 2], [0, 3, 4]],
    );
    cases.push((
        "coplanar_shared_vertex_overlap",
        poke,
        ex(false, true, 2, None),
    ));

    // Heavy noise on a torus: whatever the truth, both sides must find the same pairs.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let noisy = generators::perturb(&generators::torus(2.0, 0.5, 32, 16), 0.15, &mut rng);
    cases.push(("noisy_torus", noisy, None));
    cases
}

#[test]
fn broken_corpus_agrees_with_cgal() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut diffs = Vec::new();
    for (name, m, expect) in corpus() {
        let (cgal, d) = check_case(dir.path(), name, &m);
        eprintln!(
            "{name}: valid {} components {} boundary {} euler {} self-intersecting pairs {} degenerate {}",
            cgal["valid_polygon_mesh"],
            cgal["connected_components"],
            cgal["boundary_cycles"],
            cgal["euler_characteristic"],
            cgal["self_intersecting_pairs"].as_array().map_or(0, Vec::len),
            cgal["degenerate_faces"],
        );
        diffs.extend(d);
        if let Some(e) = expect {
            let got = (
                cgal["valid_polygon_mesh"].as_bool(),
                cgal["self_intersects"].as_bool(),
                cgal["connected_components"].as_u64(),
                cgal["boundary_cycles"].as_u64(),
            );
            let want = (
                Some(e.valid),
                Some(e.self_intersects),
                Some(e.components as u64),
                e.boundary_cycles.map(|b| b as u64),
            );
            assert_eq!(
                got, want,
                "{name}: the corpus case is not what it claims to be \
                 (valid, self_intersects, components, boundary_cycles)"
            );
        }
    }
    assert!(
        diffs.is_empty(),
        "conemesh and CGAL disagree:\n{}",
        diffs.join("\n")
    );
}

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn shared_meshes_agree_with_cgal() {
    let paths: Vec<PathBuf> = common::SHARED_MESHES.iter().map(|m| m.path()).collect();
    let mut diffs = Vec::new();
    for p in &paths {
        let m = read(p);
        let cgal = run_checker(p, &[]);
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("?");
        diffs.extend(compare(name, &m, &cgal));
        // The replica used for non-manifold soups must agree with PMP::self_intersections.
        assert_eq!(cgal["soup_replica_agrees"], Value::Bool(true), "{name}");
    }
    assert!(
        diffs.is_empty(),
        "conemesh and CGAL disagree:\n{}",
        diffs.join("\n")
    );
}

// ---------------------------------------------------------------------------------------
// Planar (2D) checks: orientation of every triangle, simplicity of the boundary.

fn boundary_is_simple(m: &TriMesh, topo: &Topology) -> bool {
    let p2 = |v: VertexId| Point2::new(m.position(v).x, m.position(v).y);
    topo.boundary_loops().iter().all(|l| {
        let n = l.len();
        let seg = |k: usize| (p2(l[k]), p2(l[(k + 1) % n]));
        (0..n).all(|i| {
            (i + 1..n).all(|j| {
                let ((a, b), (c, d)) = (seg(i), seg(j));
                let adjacent = j == i + 1 || (i == 0 && j == n - 1);
                if adjacent {
                    // Consecutive edges may only share their common vertex: no fold-back.
                    let (p, q, r) = if j == i + 1 { (a, b, d) } else { (c, d, b) };
                    !(orient2d(&p, &q, &r) == Sign::Zero && (r - q).dot(&(p - q)) > 0.0)
                } else {
                    segments_intersect(&a, &b, &c, &d) == SegmentIntersection::Disjoint
                }
            })
        })
    })
}

#[test]
fn planar_checks_agree_with_cgal() {
    let dir = tempfile::tempdir().expect("tempdir");
    let disk = generators::disk(1.0, 3, 6);
    // Centre pushed past its first ring: the faces on the +x side turn clockwise.
    let mut folded = disk.clone();
    let c = nearest_vertex(&folded, Point3::origin());
    folded.positions[c] = Point3::new(0.5, 0.0, 0.0);
    // A strip wound 2.5 times around: every triangle ccw, the boundary crosses itself.
    let n = 40;
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    for k in 0..=n {
        let th = 2.5 * std::f64::consts::PI * k as f64 / n as f64;
        pos.push([th.cos(), th.sin(), 0.0]);
        pos.push([1.5 * th.cos(), 1.5 * th.sin(), 0.0]);
        if k < n {
            let (i0, o0, i1, o1) = (2 * k, 2 * k + 1, 2 * k + 2, 2 * k + 3);
            tris.push([i0, o0, o1]);
            tris.push([i0, o1, i1]);
        }
    }
    let wound = mesh(&pos, &tris);
    let cases = [
        ("flat_disk", disk, true, true),
        ("folded_disk", folded, false, true),
        ("wound_strip", wound, true, false),
    ];
    for (name, m, want_positive, want_simple) in cases {
        let path = dir.path().join(format!("{name}.off"));
        write_off(&path, &m);
        let cgal = run_checker(&path, &["--planar"]);
        let pl = &cgal["planar"];
        let ours_np: Vec<usize> = m
            .faces()
            .filter(|&f| {
                let [a, b, c] = m.face_points(f);
                let q = |p: Point3<f64>| Point2::new(p.x, p.y);
                orient2d(&q(a), &q(b), &q(c)) != Sign::Positive
            })
            .map(FaceId::idx)
            .collect();
        assert_eq!(
            pl["non_positive_faces"],
            Value::from(ours_np.clone()),
            "{name}: non-positive faces"
        );
        assert_eq!(ours_np.is_empty(), want_positive, "{name}: case as built");
        let topo = Topology::build(&m);
        let ours_simple = boundary_is_simple(&m, &topo);
        assert_eq!(
            pl["boundary_simple"],
            Value::Bool(ours_simple),
            "{name}: boundary simplicity"
        );
        assert_eq!(ours_simple, want_simple, "{name}: case as built");
        assert_eq!(
            pl["boundary_loops"],
            Value::from(topo.boundary_loops().len()),
            "{name}"
        );
    }
}

#[test]
fn planar_mode_reads_obj_texture_coordinates() {
    // A curved developable piece in 3D with its flattening as `vt`: the checker must use the
    // `vt` layout, not x/y.
    let m = generators::cylinder_piece(1.0, 2.0, 1.0, 8, 3);
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("piece.obj");
    let mut s = String::new();
    for p in &m.positions {
        let _ = writeln!(s, "v {:?} {:?} {:?}", p.x, p.y, p.z);
    }
    for p in &m.positions {
        // Unrolled: arc length along the circle, height.
        let _ = writeln!(s, "vt {:?} {:?}", p.y.atan2(p.x), p.z);
    }
    for t in &m.triangles {
        let (a, b, c) = (t[0].0 + 1, t[1].0 + 1, t[2].0 + 1);
        let _ = writeln!(s, "f {a}/{a} {b}/{b} {c}/{c}");
    }
    std::fs::write(&path, s).expect("write obj");
    let cgal = run_checker(&path, &["--planar"]);
    let pl = &cgal["planar"];
    assert_eq!(pl["source"], "obj_vt");
    // The cylinder piece's faces are ccw seen from outside; unrolled (angle, z) keeps that
    // orientation, so CGAL and conemesh must both call every triangle positive.
    let uv = |v: VertexId| {
        let p = m.position(v);
        Point2::new(p.y.atan2(p.x), p.z)
    };
    let ours: Vec<usize> = m
        .faces()
        .filter(|&f| {
            let t = m.face(f);
            orient2d(&uv(t[0]), &uv(t[1]), &uv(t[2])) != Sign::Positive
        })
        .map(FaceId::idx)
        .collect();
    assert_eq!(pl["non_positive_faces"], Value::from(ours));
    assert_eq!(pl["boundary_loops"], Value::from(1));
    assert_eq!(pl["boundary_simple"], Value::Bool(true));
}

// ---------------------------------------------------------------------------------------
// Hausdorff distance (CGAL side; conemesh side once crate::quality::approximation_error lands).

#[test]
fn cgal_hausdorff_matches_the_analytic_distance_of_offset_spheres() {
    // Two icospheres of radii 1 and 1.1 with identical directions: every vertex of the
    // small one is exactly 0.1 from the big one's vertex, and the big sphere's faces are
    // flat, so the distance from the small sphere to the big mesh lies in [0.1 − sagitta,
    // 0.1]; sagitta ≤ 1.1·(1 − cos(max edge / 2.2)).
    let a = generators::icosphere(1.0, 3);
    let mut b = a.clone();
    for p in &mut b.positions {
        *p = Point3::from(p.coords * 1.1);
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let (pa, pb) = (dir.path().join("a.off"), dir.path().join("b.off"));
    write_off(&pa, &a);
    write_off(&pb, &b);
    let cgal = run_checker(&pa, &["--hausdorff", pb.to_str().expect("utf-8 path")]);
    let h = &cgal["hausdorff"];
    let ab = h["mesh_to_other"].as_f64().expect("number");
    let ba = h["other_to_mesh"].as_f64().expect("number");
    let bound = h["error_bound"].as_f64().expect("number");
    let max_edge = b
        .faces()
        .flat_map(|f| {
            let [p, q, r] = b.face_points(f);
            [(q - p).norm(), (r - q).norm(), (p - r).norm()]
        })
        .fold(0.0, f64::max);
    let sagitta = 1.1 * (1.0 - (max_edge / 2.2).cos());
    assert!(
        ab <= 0.1 + 1e-12 && ab >= 0.1 - sagitta - bound,
        "small→big {ab}, sagitta {sagitta}, sampling bound {bound}"
    );
    // big→small: at least 0.1 (big vertices are 0.1 outside a mesh inscribed in the unit
    // sphere) — the sampled value may miss the maximum by at most the grid spacing.
    assert!(ba >= 0.1 - 1e-12, "big→small {ba}");
    assert!(ba <= 0.1 + 1.0 * (1.0 - (max_edge / 2.2).cos()) + 1e-12 + bound);
}

// The Hausdorff cross-check against conemesh's own measure lives in tests/cgal_pipeline.rs
// (outputs of `conemesh remesh` against their inputs).

// ---------------------------------------------------------------------------------------
// Parameterizations of real cover patches (issue 7: "The CGAL check program certifies our
// output orientation and boundary simplicity independently and must agree").

#[path = "common/param_cover.rs"]
mod param_cover;

/// Write the flat map `uv` of `disk` as an OFF with z = 0 (the checker's `xy` source).
fn write_flat(path: &Path, disk: &TriMesh, uv: &[Point2<f64>]) {
    let pos: Vec<[f64; 3]> = uv.iter().map(|p| [p.x, p.y, 0.0]).collect();
    let tris: Vec<[usize; 3]> = disk
        .triangles
        .iter()
        .map(|t| [t[0].idx(), t[1].idx(), t[2].idx()])
        .collect();
    write_off(path, &mesh(&pos, &tris));
}

/// CGAL's planar verdict on `uv` against `certify_bijective` and `non_positive_faces`;
/// returns whether conemesh certified the map.
fn planar_agrees(
    dir: &Path,
    name: &str,
    disk: &TriMesh,
    boundary: &[VertexId],
    uv: &[Point2<f64>],
) -> bool {
    let path = dir.join(format!("{name}.off"));
    write_flat(&path, disk, uv);
    let cgal = run_checker(&path, &["--planar"]);
    let pl = &cgal["planar"];
    assert_eq!(pl["source"], "xy", "{name}");
    let ours_np: Vec<usize> = invariants::non_positive_faces(uv, &disk.triangles)
        .into_iter()
        .map(FaceId::idx)
        .collect();
    assert_eq!(
        pl["non_positive_faces"],
        Value::from(ours_np.clone()),
        "{name}: non-positive faces"
    );
    assert_eq!(
        pl["boundary_loops"],
        Value::from(1),
        "{name}: boundary loops"
    );
    let certified = invariants::certify_bijective(uv, &disk.triangles, boundary).is_ok();
    // certify_bijective = every face positive + simple boundary + counter-clockwise boundary
    // (surface on the left); CGAL's border halfedges run against the faces, so that outer
    // boundary is "cw (faces ccw inside)" there.
    let cgal_bijective = pl["all_positively_oriented"] == Value::Bool(true)
        && pl["boundary_simple"] == Value::Bool(true)
        && pl["boundary_loop_orientation"][0] == "cw (faces ccw inside)";
    assert_eq!(
        cgal_bijective, certified,
        "{name}: CGAL says {pl}, certify_bijective says {certified}"
    );
    certified
}

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn cover_patch_parameterizations_agree_with_cgal() {
    use conemesh::param::{lscm, scale_to_area, Parameterizer, SymmetricDirichlet};
    use conemesh::patches::{cover, extract_patch, ConePatches, CoverOptions};
    let dir = tempfile::tempdir().expect("tempdir");
    let (mut checked, mut overlapping_lscm) = (0, 0);
    for name in ["fertility.off", "stanford-bunny.obj"] {
        let m = param_cover::load(name);
        let mut rng = conemesh::Rng::seed_from_u64(1);
        let run = cover(
            &m,
            &ConePatches::default(),
            &CoverOptions::default(),
            &mut rng,
        )
        .expect("cover");
        // The large patches (the hard, Tutte-started ones among them) and a few small ones.
        let mut order: Vec<usize> = (0..run.patches.len()).collect();
        order.sort_by_key(|&i| std::cmp::Reverse(run.patches[i].faces.len()));
        order.truncate(6);
        order.extend((0..run.patches.len()).rev().take(2));
        order.sort_unstable();
        order.dedup();
        for pi in order {
            let pm = extract_patch(&m, &run.patches[pi].faces).expect("extract");
            let p = SymmetricDirichlet::default()
                .parameterize(&pm.mesh, &pm.boundary)
                .expect("parameterize");
            let case = format!("{name}_p{pi}");
            assert!(
                planar_agrees(dir.path(), &case, &pm.mesh, &pm.boundary, &p.uv),
                "{case}: the parameterizer's output is not certified"
            );
            checked += 1;
            // The free-boundary LSCM often overlaps on these patches: both sides must then
            // reject it (the negative half of the cross-check).
            if let Ok(mut l) = lscm(&pm.mesh, &pm.boundary) {
                scale_to_area(&pm.mesh, &mut l);
                if !planar_agrees(
                    dir.path(),
                    &format!("{case}_lscm"),
                    &pm.mesh,
                    &pm.boundary,
                    &l,
                ) {
                    overlapping_lscm += 1;
                }
            }
        }
    }
    assert!(checked >= 10, "{checked} patches checked");
    // Known from the covering runs (bunny p2, p11 start from Tutte because of this).
    assert!(
        overlapping_lscm >= 2,
        "{overlapping_lscm} overlapping LSCM maps"
    );
}
