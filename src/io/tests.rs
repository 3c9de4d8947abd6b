//! Unit tests of the readers and writers on small inline files.

use super::*;
use crate::ids::VertexId;

fn rd(text: &str, f: Format) -> Result<LoadedMesh, IoError> {
    read_mesh_bytes(text.as_bytes(), f, "t")
}

#[test]
fn off_reads_quad_as_two_triangles_keeping_orientation() -> Result<(), IoError> {
    let m = rd(
        "OFF\n# comment\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n",
        Format::Off,
    )?;
    assert_eq!(m.mesh.n_vertices(), 4);
    assert_eq!(m.mesh.n_faces(), 2);
    assert_eq!(m.polygons_triangulated, 1);
    for f in m.mesh.faces() {
        assert!(m.mesh.face_normal(f).z > 0.0);
    }
    Ok(())
}

#[test]
fn off_counts_on_magic_line_and_coff_extras() -> Result<(), IoError> {
    let m = rd(
        "COFF 3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2 9 9 9\n",
        Format::Off,
    )?;
    assert_eq!(m.mesh.n_faces(), 1);
    Ok(())
}

#[test]
fn off_errors_are_named() {
    let e = rd("OFF\n3 1 0\n0 0 0\n1 0 0\n", Format::Off).unwrap_err();
    assert_eq!(e.kind(), "truncated", "{e}");
    let e = rd("OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", Format::Off).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::NonFinite {
                vertex: 1,
                line: 4,
                ..
            }
        ),
        "{e}"
    );
    let e = rd("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", Format::Off).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::BadIndex {
                face: 0,
                index: 7,
                n_vertices: 3,
                line: 6,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(
        e.to_string(),
        "t:6: face 0 refers to vertex index 7, but the file has 3 vertices"
    );
    let e = rd("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 1\n", Format::Off).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::RepeatedVertex {
                face: 0,
                vertex: 1,
                ..
            }
        ),
        "{e}"
    );
    let e = rd("OFF\n1000000000000 1 0\n0 0 0\n", Format::Off).unwrap_err();
    assert_eq!(e.kind(), "too-large", "{e}");
    assert_eq!(rd("", Format::Off).unwrap_err().kind(), "empty");
    assert_eq!(rd("PLY\n", Format::Off).unwrap_err().kind(), "bad-magic");
}

#[test]
fn obj_reads_all_face_forms_and_relative_indices() -> Result<(), IoError> {
    let m = rd(
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\ng x\ns off\nusemtl m\n\
         f 1/1/1 2//1 3\nf -4 -2 -1\n",
        Format::Obj,
    )?;
    assert_eq!(m.mesh.n_faces(), 2);
    assert_eq!(m.mesh.triangles[1], [VertexId(0), VertexId(2), VertexId(3)]);
    let e = rd("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", Format::Obj).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::BadIndex {
                index: 0,
                line: 4,
                ..
            }
        ),
        "{e}"
    );
    let e = rd("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n", Format::Obj).unwrap_err();
    assert!(matches!(e, IoError::BadIndex { index: -4, .. }), "{e}");
    let e = rd("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", Format::Obj).unwrap_err();
    assert!(matches!(e, IoError::BadIndex { index: 4, .. }), "{e}");
    let e = rd("v 0 0 0\nv 1 0 0\n", Format::Obj).unwrap_err();
    assert_eq!(e.kind(), "no-faces");
    let e = rd("v 0 0 0\nv 1 inf 0\n", Format::Obj).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::NonFinite {
                vertex: 1,
                line: 2,
                ..
            }
        ),
        "{e}"
    );
    let e = read_mesh_bytes(b"v 0 0 0\n\x00\xff\xfe", Format::Obj, "t").unwrap_err();
    assert!(matches!(e, IoError::Parse { line: 2, .. }), "{e}");
    Ok(())
}

#[test]
fn obj_keeps_uv_when_one_per_vertex() -> Result<(), IoError> {
    let m = rd(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 0.25\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n",
        Format::Obj,
    )?;
    let uv = m.attributes.uv.expect("uv kept");
    assert_eq!(uv[0], Point2::new(0.5, 0.25));
    Ok(())
}

/// The shared test meshes read with the vertex and face counts of their README.
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn shared_meshes_read_with_expected_counts() -> Result<(), IoError> {
    let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/meshes"));
    let table = [
        ("3holes.off", 3596, 7200),
        ("screwdriver.off", 3395, 6786),
        ("fertility.off", 4494, 9000),
        ("bunny.off", 3485, 6966),
        ("fandisk.off", 7229, 14454),
        ("cow.off", 2762, 5520),
        ("bumpy.off", 1250, 2496),
        ("decimated-knight.off", 502, 1000),
        ("spot.obj", 2930, 5856),
        ("homer.obj", 6002, 12000),
        ("stanford-bunny.obj", 35947, 69451),
        ("armadillo.obj", 43243, 86482),
    ];
    for (name, nv, nf) in table {
        let m = read_mesh(&dir.join(name))?;
        assert_eq!((m.mesh.n_vertices(), m.mesh.n_faces()), (nv, nf), "{name}");
    }
    Ok(())
}
