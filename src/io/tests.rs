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
fn off_faces_broken_over_lines_are_read_as_a_token_stream() -> Result<(), IoError> {
    // As libigl's tutorial data `inspired_mesh_quads_*.off` writes them: a face's indices on
    // the lines after its count.
    let m = rd(
        "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 \n1 \n2\n3\n3 0 2 3\n",
        Format::Off,
    )?;
    assert_eq!(m.mesh.n_faces(), 3);
    // A continuation line that holds more than the face's indices is refused by line.
    let e = rd(
        "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1\n2 3 3\n0 2 3\n",
        Format::Off,
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::Parse {
                line: 8,
                defect: Syntax::FaceOverflow {
                    face: 0,
                    announced: 4,
                    from_line: 7
                },
                ..
            }
        ),
        "{e}"
    );
    Ok(())
}

#[test]
fn off_errors_are_named() {
    let e = rd("OFF\n3 1 0\n0 0 0\n1 0 0\n", Format::Off).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::Truncated {
                missing: Truncation::Elements {
                    claimed: 3,
                    what: "vertices",
                    found: 2
                },
                ..
            }
        ),
        "{e}"
    );
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
    assert!(
        matches!(
            e,
            IoError::Parse {
                line: 2,
                defect: Syntax::Binary { byte: 9 },
                ..
            }
        ),
        "{e}"
    );
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

/// A binary PLY with float x y z, an extra `ushort` vertex property and an extra face list,
/// a `ushort`-counted `vertex_index` list of `uint`, and an unknown element in between.
fn binary_ply(big_endian: bool) -> Vec<u8> {
    let mut b = format!(
        "ply\nformat {} 1.0\ncomment c\nelement vertex 4\nproperty float x\nproperty ushort junk\n\
         property float y\nproperty float z\nelement edge 1\nproperty int a\nproperty int b\n\
         element face 1\nproperty list uchar short other\nproperty list ushort uint vertex_index\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\nproperty int patch\nend_header\n",
        if big_endian { "binary_big_endian" } else { "binary_little_endian" }
    )
    .into_bytes();
    let f32b = |x: f32| {
        if big_endian {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        }
    };
    for (x, y, z) in [
        (0.0, 0.0, 0.0),
        (1.0, 0.0, 0.0),
        (1.0, 1.0, 0.0),
        (0.0, 1.0, 0.5),
    ] {
        b.extend(f32b(x));
        b.extend(if big_endian {
            7u16.to_be_bytes()
        } else {
            7u16.to_le_bytes()
        });
        b.extend(f32b(y));
        b.extend(f32b(z));
    }
    b.extend([0u8; 8]); // the edge
    b.push(2);
    b.extend([0u8; 4]); // `other`: two shorts
    b.extend(if big_endian {
        4u16.to_be_bytes()
    } else {
        4u16.to_le_bytes()
    });
    for i in 0u32..4 {
        b.extend(if big_endian {
            i.to_be_bytes()
        } else {
            i.to_le_bytes()
        });
    }
    b.extend([10, 20, 30]);
    b.extend(if big_endian {
        (-5i32).to_be_bytes()
    } else {
        (-5i32).to_le_bytes()
    });
    b
}

#[test]
fn ply_binary_both_endiannesses_skip_unknown_properties() -> Result<(), IoError> {
    for be in [false, true] {
        let m = read_mesh_bytes(&binary_ply(be), Format::Ply, "t")?;
        assert_eq!(m.mesh.n_vertices(), 4);
        assert_eq!(m.mesh.n_faces(), 2);
        assert_eq!(m.polygons_triangulated, 1);
        assert_eq!(m.mesh.positions[3], Point3::new(0.0, 1.0, 0.5));
        assert_eq!(m.attributes.face_colors, Some(vec![[10, 20, 30]; 2]));
        assert_eq!(
            m.attributes.face_ints,
            vec![("patch".to_string(), vec![-5, -5])]
        );
    }
    let mut cut = binary_ply(false);
    cut.truncate(cut.len() - 9);
    let e = read_mesh_bytes(&cut, Format::Ply, "t").unwrap_err();
    assert!(
        matches!(
            &e,
            IoError::Truncated {
                missing: Truncation::InsideElement { element, .. },
                ..
            } if element == "face"
        ),
        "{e}"
    );
    Ok(())
}

#[test]
fn ply_ascii_tristrips_and_header_errors() -> Result<(), IoError> {
    let m = rd(
        "ply\nformat ascii 1.0\nelement vertex 5\nproperty double x\nproperty double y\n\
         property double z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n\
         0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 2 0\n6 0 1 2 3 -1 4\n",
        Format::Ply,
    )?;
    assert_eq!(m.mesh.n_faces(), 2);
    // Strip triangles share one orientation.
    for f in m.mesh.faces() {
        assert!(m.mesh.face_normal_raw(f).z > 0.0);
    }
    let hdr = |extra: &str| {
        format!(
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n\
             property double z\n{extra}end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
        )
    };
    let e = rd(
        &hdr("element face 1\nproperty list uchar int128 vertex_indices\n"),
        Format::Ply,
    )
    .unwrap_err();
    assert!(
        matches!(&e, IoError::UnknownProperty { ty, .. } if ty == "int128"),
        "{e}"
    );
    let e = rd(
        &hdr("element face 1\nproperty list float int vertex_indices\n"),
        Format::Ply,
    )
    .unwrap_err();
    assert!(
        matches!(
            &e,
            IoError::Parse {
                line: 8,
                defect: Syntax::ListCountType { list, ty },
                ..
            } if list == "vertex_indices" && ty == "float"
        ),
        "{e}"
    );
    let e = rd(
        &hdr("element face 1\nproperty list uchar int vertex_indices\n")
            .replace("0 1 2\n", "0 1 9\n"),
        Format::Ply,
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::BadIndex {
                index: 9,
                line: 13,
                ..
            }
        ),
        "{e}"
    );
    let e = rd(
        &hdr("element face 1000000000000\nproperty list uchar int vertex_indices\n"),
        Format::Ply,
    )
    .unwrap_err();
    assert_eq!(e.kind(), "too-large", "{e}");
    Ok(())
}

#[test]
fn stl_ascii_and_binary_weld_corners() -> Result<(), IoError> {
    let ascii =
        "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n\
                 endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\n\
                 vertex -0 1 0\nendloop\nendfacet\nendsolid x\n";
    let m = rd(ascii, Format::Stl)?;
    assert_eq!(
        (m.mesh.n_vertices(), m.mesh.n_faces(), m.welded_vertices),
        (4, 2, 2)
    );
    let e = rd(&ascii[..ascii.len() - 30], Format::Stl).unwrap_err();
    assert_eq!(e.kind(), "truncated", "{e}");
    let e = rd(
        &ascii.replace("vertex 1 1 0", "vertex 1 NaN 0"),
        Format::Stl,
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::NonFinite {
                vertex: 4,
                line: 12,
                ..
            }
        ),
        "{e}"
    );
    Ok(())
}

#[test]
fn medit_reads_and_skips_sections() -> Result<(), IoError> {
    let m = rd(
        "MeshVersionFormatted 2\nDimension\n3\nVertices\n4\n0 0 0 1\n1 0 0 1\n1 1 0 1\n0 1 0 1\n\
         Edges\n1\n1 2 0\nTriangles\n1\n1 2 3 7\nQuadrilaterals\n1\n1 2 3 4 0\nCorners\n1\n1\nEnd\n",
        Format::Medit,
    )?;
    assert_eq!(m.mesh.n_faces(), 3);
    assert_eq!(
        m.attributes.face_ints,
        vec![("ref".to_string(), vec![7, 0, 0])]
    );
    // The geometry sections MMG writes after a surface remesh (ridges on): skipped by size.
    let m = rd(
        "MeshVersionFormatted 2\nDimension 3\nVertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\n\
         Corners\n1\n1\nRequiredVertices\n1\n1\nEdges\n1\n1 2 0\nRidges\n1\n1\n\
         Triangles\n1\n1 2 3 0\nNormals\n1\n0 0 1\nNormalAtVertices\n1\n1 1\n\
         Tangents\n1\n1 0 0\nTangentAtVertices\n1\n2 1\nEnd\n",
        Format::Medit,
    )?;
    assert_eq!(m.mesh.n_faces(), 1);
    assert_eq!(m.mesh.n_vertices(), 3);
    let e = rd("MeshVersionFormatted 2\nDimension 3\nVertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\nTriangles\n1\n0 1 2 0\nEnd\n", Format::Medit).unwrap_err();
    assert!(matches!(e, IoError::BadIndex { index: 0, .. }), "{e}");
    Ok(())
}

fn sample() -> TriMesh {
    let mut rng = <crate::Rng as rand::SeedableRng>::seed_from_u64(7);
    let mut m = crate::mesh::generators::perturb(
        &crate::mesh::generators::icosphere(1.0, 1),
        0.1,
        &mut rng,
    );
    m.positions[0].x = -0.0;
    m.positions[1].y = 1e-300;
    m.positions[2].z = 1.0 / 3.0;
    m
}

#[test]
fn writers_round_trip_bit_exact() -> Result<(), IoError> {
    let dir = tempfile::tempdir().map_err(|error| IoError::Os {
        path: "tmp".into(),
        error,
    })?;
    let m = sample();
    let n = m.n_faces();
    let attrs = MeshAttributes {
        face_ints: vec![("patch".into(), (0..n as i64).map(|i| i - 3).collect())],
        face_colors: Some((0..n).map(|i| [i as u8, 2, 255]).collect()),
        uv: Some(
            m.positions
                .iter()
                .map(|p| Point2::new(p.x, p.y * 0.5))
                .collect(),
        ),
    };
    for (name, binary, big_endian) in [
        ("a.obj", false, false),
        ("a.off", false, false),
        ("a.mesh", false, false),
        ("a.ply", false, false),
        ("b.ply", true, false),
        ("c.ply", true, true),
        ("a.stl", false, false),
    ] {
        let p = dir.path().join(name);
        write_mesh_with(&p, &m, &attrs, &WriteOptions { binary, big_endian })?;
        let back = read_mesh(&p)?;
        if name.ends_with(".stl") {
            assert_eq!(back.mesh.n_faces(), n);
            assert_eq!(back.welded_vertices, 3 * n - m.n_vertices());
            continue;
        }
        let bits = |t: &TriMesh| -> Vec<[u64; 3]> {
            t.positions
                .iter()
                .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                .collect()
        };
        assert_eq!(bits(&back.mesh), bits(&m), "{name}");
        assert_eq!(back.mesh.triangles, m.triangles, "{name}");
        if name.ends_with(".ply") {
            assert_eq!(back.attributes, attrs, "{name}");
        }
        if name.ends_with(".obj") {
            assert_eq!(back.attributes.uv, attrs.uv, "{name}");
        }
    }
    Ok(())
}

#[test]
fn attributes_that_do_not_match_the_mesh_are_refused_naming_the_problem() {
    let m = sample();
    let dir = tempfile::tempdir().expect("tempdir");
    let p = dir.path().join("x.ply");
    let write = |attrs: MeshAttributes| {
        write_mesh_with(&p, &m, &attrs, &WriteOptions::default()).expect_err("refused")
    };
    let e = write(MeshAttributes {
        face_ints: vec![("patch".into(), vec![0; m.n_faces() + 1])],
        ..Default::default()
    });
    assert!(
        matches!(
            &e,
            IoError::BadAttribute {
                problem: AttributeProblem::FacePropertyLength { name, values, faces },
                ..
            } if name == "patch" && *values == m.n_faces() + 1 && *faces == m.n_faces()
        ),
        "{e}"
    );
    let e = write(MeshAttributes {
        face_ints: vec![("two words".into(), vec![0; m.n_faces()])],
        ..Default::default()
    });
    assert!(
        matches!(
            &e,
            IoError::BadAttribute {
                problem: AttributeProblem::FacePropertyName { name },
                ..
            } if name == "two words"
        ),
        "{e}"
    );
    let mut uv = vec![Point2::origin(); m.n_vertices()];
    uv[2].y = f64::INFINITY;
    let e = write(MeshAttributes {
        uv: Some(uv),
        ..Default::default()
    });
    assert!(
        matches!(
            e,
            IoError::BadAttribute {
                problem: AttributeProblem::NonFiniteUv {
                    vertex: VertexId(2)
                },
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(e.kind(), "bad-attribute");
    assert!(std::fs::read_dir(dir.path()).expect("dir").next().is_none());
}

/// The typed defects print the messages users read: file, line, element, token.
#[test]
fn defects_print_what_is_wrong() {
    let stl = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nendsolid\n";
    let e = rd(stl, Format::Stl).unwrap_err();
    assert!(
        matches!(
            &e,
            IoError::Parse {
                line: 5,
                defect: Syntax::ExpectedKeyword {
                    keyword: "vertex",
                    found,
                },
                ..
            } if found == "endsolid"
        ),
        "{e}"
    );
    assert_eq!(
        e.to_string(),
        "t:5: STL parse error: expected `vertex`, found `endsolid`"
    );
    let e = rd("solid x\nfacet normal 0 0 1\nsolid\n", Format::Stl).unwrap_err();
    assert!(
        e.to_string().ends_with("expected `outer`, found `solid`"),
        "{e}"
    );
    let e = rd("solid x\nvertex\n", Format::Stl).unwrap_err();
    assert_eq!(
        e.to_string(),
        "t:2: STL parse error: expected `facet` or `endsolid`, found `vertex`"
    );
    let e = rd("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", Format::Off).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::Parse {
                line: 6,
                defect: Syntax::FaceShort {
                    face: 0,
                    announced: 4,
                    listed: 3
                },
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(
        e.to_string(),
        "t:6: OFF parse error: face 0 announces 4 vertices but lists 3"
    );
    let e = rd("MeshVersionFormatted 2\nDimension\n", Format::Medit).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::Truncated {
                missing: Truncation::InsideKeyword {
                    keyword: "Dimension",
                    line: 2
                },
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(
        e.to_string(),
        "t: truncated Medit file: file ends inside `Dimension` (line 2)"
    );
}

#[test]
fn failed_write_leaves_no_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = dir.path().join("x.ply");
    let mut m = sample();
    let attrs = MeshAttributes {
        face_ints: vec![("big".into(), vec![i64::MAX; m.n_faces()])],
        ..Default::default()
    };
    let e = write_mesh_with(&p, &m, &attrs, &WriteOptions::default()).unwrap_err();
    assert_eq!(e.kind(), "os", "{e}");
    m.positions[3].x = f64::NAN;
    let e = write_mesh(&dir.path().join("y.obj"), &m).unwrap_err();
    assert_eq!(e.kind(), "mesh", "{e}");
    let left: Vec<_> = std::fs::read_dir(dir.path()).expect("dir").collect();
    assert!(left.is_empty(), "{left:?}");
}

/// Issue 20: a byte-order mark before ASCII STL and PLY (it was only skipped in OBJ, OFF and
/// .mesh), and files whose lines end with a lone CR (they read as one line: "empty OBJ file").
#[test]
fn a_byte_order_mark_and_cr_only_line_ends_read_in_every_text_format() -> Result<(), IoError> {
    let stl = "\u{feff}solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
               vertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
    let ply = "\u{feff}ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
               property float y\nproperty float z\nelement face 1\n\
               property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    for (text, f) in [(stl, Format::Stl), (ply, Format::Ply)] {
        let m = rd(text, f)?;
        assert_eq!((m.mesh.n_vertices(), m.mesh.n_faces()), (3, 1), "{f:?}");
    }
    // Bytes that only look like a mark in a binary STL header are not stripped.
    let mut bin = b"\xEF\xBB\xBFbinary header".to_vec();
    bin.resize(80, b' ');
    bin.extend_from_slice(&0u32.to_le_bytes());
    assert!(
        matches!(
            read_mesh_bytes(&bin, Format::Stl, "t"),
            Err(IoError::NoFaces { .. }) | Err(IoError::Empty { .. })
        ),
        "{:?}",
        read_mesh_bytes(&bin, Format::Stl, "t").map(|m| m.mesh.n_faces())
    );
    let cr = |s: &str| s.replace('\n', "\r");
    for (text, f) in [
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", Format::Obj),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", Format::Off),
        (stl, Format::Stl),
        (ply, Format::Ply),
    ] {
        let m = rd(&cr(text), f)?;
        assert_eq!((m.mesh.n_vertices(), m.mesh.n_faces()), (3, 1), "{f:?}");
    }
    // Line numbers count lone CRs and CRLFs alike.
    let err = rd("v 0 0 0\r\nv 1 0 0\rv 0 1 0\r\nf 1 2 9\r", Format::Obj).unwrap_err();
    assert!(err.to_string().contains("t:4"), "{err}");
    Ok(())
}

/// Issue 20: a texture index beyond the `vt` lines is refused like a vertex index (it used to
/// pass, and the texture coordinates were dropped as "seams").
#[test]
fn an_obj_texture_index_out_of_range_is_refused_naming_it() {
    let err = rd(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/5 3/1\n",
        Format::Obj,
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            IoError::Parse {
                line: 5,
                defect: Syntax::BadTextureIndex {
                    face: 0,
                    index: 5,
                    defined: 1
                },
                ..
            }
        ),
        "{err}"
    );
    let s = err.to_string();
    assert!(s.contains("texture index 5") && s.contains("t:5"), "{s}");
}

#[test]
fn utf8_byte_order_mark_is_skipped() -> Result<(), IoError> {
    let m = rd("\u{feff}v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", Format::Obj)?;
    assert_eq!(m.mesh.n_vertices(), 3);
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    Ok(())
}

#[test]
fn names_and_comments_may_hold_latin1_bytes_but_numbers_may_not() -> Result<(), IoError> {
    let obj = b"# caf\xe9\nmtllib caf\xe9.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
                g gr\xfcn\nusemtl mat\xe9riau\no \x84obj\nf 1 2 3 4 # \xff\n";
    let m = read_mesh_bytes(obj, Format::Obj, "latin1.obj")?;
    assert_eq!((m.mesh.n_vertices(), m.mesh.n_faces()), (4, 2));
    let off = b"OFF\n# \xe9t\xe9\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_eq!(
        read_mesh_bytes(off, Format::Off, "c.off")?.mesh.n_faces(),
        1
    );
    // The same byte inside a number, or after a keyword that is no name, is binary data.
    for bad in [
        &b"v 0 0 0\nv 1 \xe90 0\nv 0 1 0\nf 1 2 3\n"[..],
        b"v 0 0 0\nvt \xe9\n",
    ] {
        let e = read_mesh_bytes(bad, Format::Obj, "bad.obj").expect_err("refused");
        assert!(
            matches!(
                e,
                IoError::Parse {
                    line: 2,
                    defect: Syntax::BinaryOutsideNames { .. },
                    ..
                }
            ),
            "{e}"
        );
    }
    // A NUL byte still marks a binary file, even in a comment.
    let e = read_mesh_bytes(b"# a\0b\nv 0 0 0\n", Format::Obj, "nul.obj").expect_err("refused");
    assert!(
        matches!(
            e,
            IoError::Parse {
                defect: Syntax::Binary { byte: 3 },
                ..
            }
        ),
        "{e}"
    );
    Ok(())
}

#[test]
fn a_ply_header_line_that_is_no_keyword_is_skipped_with_a_warning() -> Result<(), IoError> {
    let head = "ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org\n";
    let rest = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let mut bytes = head.as_bytes().to_vec();
    bytes.extend_from_slice(b"comment caf\xe9\nobj_info \xff\n");
    bytes.extend_from_slice(rest.as_bytes());
    let m = read_mesh_bytes(&bytes, Format::Ply, "blender.ply")?;
    assert_eq!(m.mesh.n_faces(), 1);
    assert!(
        m.warnings
            .iter()
            .any(|w| w.contains("blender.ply:3") && w.contains("`Created`")),
        "{:?}",
        m.warnings
    );
    // What sets the layout is still read strictly: a property of an unknown type, or a
    // header line that is not text and no comment.
    let unknown = format!(
        "{head}{}",
        rest.replace("property float z", "property float128 z")
    );
    assert!(rd(&unknown, Format::Ply).is_err());
    let mut not_text = head.as_bytes().to_vec();
    not_text.extend_from_slice(b"element \xe9 3\n");
    not_text.extend_from_slice(rest.as_bytes());
    assert!(read_mesh_bytes(&not_text, Format::Ply, "x.ply").is_err());
    Ok(())
}

#[test]
fn a_concave_polygon_reads_into_triangles_inside_it_and_a_crossing_one_is_refused() {
    // An L: a fan from its first corner (the reflex one) would put a triangle outside it.
    let l = "v 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 2 0 0\nv 2 1 0\nf 1 2 3 4 5 6\n";
    let m = rd(l, Format::Obj).expect("simple");
    assert_eq!(m.mesh.n_faces(), 4);
    let area: f64 = m
        .mesh
        .faces()
        .map(|f| m.mesh.face_normal(f).z * m.mesh.face_area(f))
        .sum();
    assert!((area - 3.0).abs() < 1e-12, "{area}");
    for f in m.mesh.faces() {
        assert!(m.mesh.face_normal(f).z > 0.0);
        let c = m.mesh.face_centroid(f);
        assert!(
            !(c.x > 1.0 && c.y > 1.0),
            "triangle {f} lies in the L's notch"
        );
    }
    let bow_tie = "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n";
    let e = rd(bow_tie, Format::Obj).expect_err("not simple");
    assert!(
        matches!(
            e,
            IoError::BadPolygon {
                line: 5,
                face: 0,
                corners: 4,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(e.kind(), "bad-polygon");
}
