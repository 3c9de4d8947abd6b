//! `conemesh remesh --repair` (issue 20): inputs that are almost oriented manifolds are
//! refused by name without it (the message names `--repair`), and remeshed with it, the
//! report listing every change and the output certified.

use conemesh::mesh::generators;
use conemesh::{Topology, TriMesh, VertexId};
use std::path::Path;
use std::process::{Command, Output};

fn conemesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .args(args)
        .output()
        .expect("runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8")
}

/// A small torus with every third face reversed.
fn shuffled_torus() -> (TriMesh, usize) {
    let mut m = generators::torus(1.0, 0.4, 16, 8);
    let mut n = 0;
    for (f, t) in m.triangles.iter_mut().enumerate() {
        if f % 3 == 2 {
            t.swap(0, 1);
            n += 1;
        }
    }
    (m, n)
}

/// `conemesh remesh INPUT -o OUT --report REPORT --repair -q`.
fn remesh_repaired(input: &Path, out: &Path, rep: &Path) -> Output {
    conemesh(&[
        "remesh",
        s(input),
        "-o",
        s(out),
        "--report",
        s(rep),
        "--repair",
        "-q",
    ])
}

fn report(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).expect("report")).expect("json")
}

#[test]
fn shuffled_orientation_is_refused_naming_repair_and_oriented_with_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (m, flipped) = shuffled_torus();
    let input = dir.path().join("shuffled.off");
    conemesh::io::write_mesh(&input, &m).expect("write");
    let out = dir.path().join("out.obj");
    let rep = dir.path().join("report.json");

    let o = conemesh(&["remesh", s(&input), "-o", s(&out), "-q"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("not an oriented manifold"),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("--repair"), "{}", stderr(&o));
    assert!(!out.exists(), "no output after a refusal");

    let o = conemesh(&[
        "remesh",
        s(&input),
        "-o",
        s(&out),
        "--report",
        s(&rep),
        "--repair",
        "--seed",
        "3",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&format!("flipped {flipped} faces")),
        "{}",
        stderr(&o)
    );
    let r = report(&rep);
    let listed = r["repair"]["flipped_faces"].as_array().expect("list");
    assert_eq!(listed.len(), flipped);
    assert_eq!(listed[0], serde_json::json!(2), "input face ids");
    // The output is a certified torus.
    let c = conemesh(&["check", s(&out)]);
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stdout));
    let remeshed = conemesh::io::read_mesh(&out).expect("read").mesh;
    let topo = Topology::build(&remeshed);
    assert!(topo.is_oriented_manifold());
    assert_eq!(topo.components()[0].genus, Some(1));
}

#[test]
fn two_surfaces_touching_at_a_vertex_are_split_and_remeshed_apart() {
    // Two tori, the second shifted so that one of its vertices lands exactly on one of the
    // first's, written as separate vertices: welding makes the shared vertex non-manifold
    // (two fans), splitting separates it again, and the run remeshes two components.
    let a = generators::torus(1.0, 0.4, 16, 8);
    let pa = a.positions[0];
    let b0 = generators::torus(1.0, 0.4, 16, 8);
    // Mirror b's copy of vertex 0 onto a's: b is a reflected in the plane x = pa.x, which
    // maps pa to itself.
    let mut positions = a.positions.clone();
    let n = positions.len() as u32;
    positions.extend(b0.positions.iter().map(|p| {
        let mut q = *p;
        q.x = 2.0 * pa.x - q.x;
        q
    }));
    let mut tris = a.triangles.clone();
    // A reflection reverses orientation: reverse the faces back.
    tris.extend(b0.triangles.iter().map(|t| {
        [
            VertexId(t[0].0 + n),
            VertexId(t[2].0 + n),
            VertexId(t[1].0 + n),
        ]
    }));
    let m = TriMesh::new(positions, tris).expect("mesh");
    assert_eq!(
        m.positions[n as usize], m.positions[0],
        "the two tori touch at v0"
    );

    let dir = tempfile::tempdir().expect("temp dir");
    let input = dir.path().join("touching.obj");
    conemesh::io::write_mesh(&input, &m).expect("write");
    let out = dir.path().join("out.obj");
    let rep = dir.path().join("report.json");
    let o = remesh_repaired(&input, &out, &rep);
    assert!(o.status.success(), "{}", stderr(&o));
    let r = report(&rep);
    assert_eq!(r["repair"]["welded"].as_array().map(Vec::len), Some(1));
    let split = r["repair"]["split_vertices"].as_array().expect("list");
    assert_eq!(split.len(), 1, "{split:?}");
    assert_eq!(split[0]["vertex"], serde_json::json!(0));
    let remeshed = conemesh::io::read_mesh(&out).expect("read").mesh;
    let topo = Topology::build(&remeshed);
    assert!(topo.is_oriented_manifold());
    assert_eq!(topo.components().len(), 2);
    assert!(topo.components().iter().all(|c| c.genus == Some(1)));
}

#[test]
fn a_users_metric_follows_the_welded_vertices() {
    // The torus as a soup (three vertices per face) with a user metric per soup vertex.
    let m = generators::torus(1.0, 0.4, 12, 6);
    let soup = generators::triangle_soup(&m);
    let dir = tempfile::tempdir().expect("temp dir");
    let input = dir.path().join("soup.obj");
    conemesh::io::write_mesh(&input, &soup).expect("write");
    let sol = dir.path().join("soup.sol");
    let tensor = nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(25.0, 4.0, 4.0));
    conemesh::io::sol::write_sol(&sol, &vec![tensor; soup.n_vertices()], false).expect("sol");
    let out = dir.path().join("out.obj");
    let o = conemesh(&[
        "remesh",
        s(&input),
        "--metric",
        s(&sol),
        "-o",
        s(&out),
        "--repair",
        "-q",
    ]);
    // Without the repair the soup is a valid mesh of single triangles; with it, one torus,
    // the metric (one tensor per soup vertex) carried to the welded vertices.
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains(&format!(
        "welded {} vertices",
        soup.n_vertices() - m.n_vertices()
    )));
    let remeshed = conemesh::io::read_mesh(&out).expect("read").mesh;
    assert_eq!(Topology::build(&remeshed).components()[0].genus, Some(1));
}

#[test]
fn a_moebius_band_is_refused_by_name_with_no_output() {
    let m = generators::moebius_band(12);
    let dir = tempfile::tempdir().expect("temp dir");
    let input = dir.path().join("moebius.ply");
    conemesh::io::write_mesh(&input, &m).expect("write");
    let out = dir.path().join("out.obj");
    let o = conemesh(&["remesh", s(&input), "-o", s(&out), "--repair", "-q"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("not orientable"), "{}", stderr(&o));
    assert!(stderr(&o).contains("moebius.ply"), "{}", stderr(&o));
    assert!(!out.exists());
}

/// Faces that use a vertex twice (an OBJ face `f 1 1 2`, an STL facet whose corners weld into
/// one) are refused by name without `--repair`, naming it; with it they are left out, listed
/// in the report by file face and line, and the rest is remeshed.
#[test]
fn faces_that_repeat_a_vertex_are_refused_naming_repair_and_left_out_with_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let torus = generators::torus(1.0, 0.4, 16, 8);
    // OBJ: the torus plus one face naming vertex 1 twice (file face `n`, the last line).
    let obj = dir.path().join("repeated.obj");
    conemesh::io::write_mesh(&obj, &torus).expect("write");
    let mut text = std::fs::read_to_string(&obj).expect("read back");
    text.push_str("f 1 1 2\n");
    let last_line = text.lines().count();
    std::fs::write(&obj, &text).expect("append");
    // STL: the torus as a soup plus a facet with two equal corners.
    let stl = dir.path().join("degenerate.stl");
    let mut solid = String::from("solid t\n");
    let tri = |t: [nalgebra::Point3<f64>; 3]| {
        let mut f = String::from("facet normal 0 0 0\nouter loop\n");
        for p in t {
            f.push_str(&format!("vertex {} {} {}\n", p.x, p.y, p.z));
        }
        f + "endloop\nendfacet\n"
    };
    for t in &torus.triangles {
        solid.push_str(&tri(t.map(|v| torus.positions[v.idx()])));
    }
    let p0 = torus.positions[0];
    solid.push_str(&tri([p0, p0, torus.positions[1]]));
    solid.push_str("endsolid t\n");
    std::fs::write(&stl, solid).expect("write stl");

    for (input, face, line) in [
        (&obj, torus.n_faces(), last_line),
        // ASCII STL: the line of the facet's first corner.
        (&stl, torus.n_faces(), 2 + 7 * torus.n_faces() + 2),
    ] {
        let stem = input.file_stem().and_then(|s| s.to_str()).expect("stem");
        let out = dir.path().join(format!("{stem}-out.obj"));
        let rep = dir.path().join(format!("{stem}-report.json"));
        let o = conemesh(&["remesh", s(input), "-o", s(&out), "-q"]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.contains(&format!("face {face} repeats vertex")) && e.contains("--repair"),
            "{e}"
        );
        assert!(!out.exists(), "no output after a refusal");

        let o = remesh_repaired(input, &out, &rep);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("left out 1 file faces that use a vertex twice"),
            "{}",
            stderr(&o)
        );
        let r = report(&rep);
        let listed = r["repair"]["repeated_index_faces"]
            .as_array()
            .expect("list");
        assert_eq!(listed.len(), 1);
        assert_eq!(listed[0]["face"], serde_json::json!(face));
        assert_eq!(listed[0]["line"], serde_json::json!(line));
        let remeshed = conemesh::io::read_mesh(&out).expect("read").mesh;
        let topo = Topology::build(&remeshed);
        assert!(topo.is_oriented_manifold());
        assert_eq!(topo.components()[0].genus, Some(1));
    }
}
