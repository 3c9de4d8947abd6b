//! Medit `.sol` metric files: bit-exact round trips and named errors on bad files.

use conemesh::io::sol::{read_sol, write_sol, SolError, SolSyntax, SolTruncation, SolUnsupported};
use conemesh::mesh::generators;
use conemesh::metric::{curvature_metric, MetricError, MetricField, MetricOptions, Normalization};
use nalgebra::Matrix3;
use std::path::Path;

type R = Result<(), Box<dyn std::error::Error>>;

fn metrics() -> Result<(conemesh::TriMesh, Vec<Matrix3<f64>>), MetricError> {
    let m0 = generators::torus(1.0, 0.3, 24, 12);
    let m = Normalization::of(&m0).apply(&m0);
    let mut ms = curvature_metric(&m, &MetricOptions::default())?;
    // Awkward values: tiny, huge, negative zero off-diagonal.
    ms[0][(0, 0)] = 1e-300;
    ms[1][(2, 2)] = 1.2345678901234567e300;
    ms[2][(0, 1)] = -0.0;
    ms[2][(1, 0)] = -0.0;
    Ok((m, ms))
}

fn bits(m: &[Matrix3<f64>]) -> Vec<u64> {
    m.iter()
        .flat_map(|x| x.iter().map(|y| y.to_bits()))
        .collect()
}

#[test]
fn ascii_and_binary_round_trips_are_bit_exact() -> R {
    let dir = tempfile::tempdir()?;
    let (m, ms) = metrics()?;
    for binary in [false, true] {
        let path = dir.path().join(if binary { "m.solb.sol" } else { "m.sol" });
        write_sol(&path, &ms, binary)?;
        let back = read_sol(&path, m.n_vertices())?;
        assert_eq!(bits(&back), bits(&ms), "binary = {binary}");
        // Written twice: same bytes (deterministic writer).
        let first = std::fs::read(&path)?;
        write_sol(&path, &back, binary)?;
        assert_eq!(first, std::fs::read(&path)?);
    }
    Ok(())
}

#[test]
fn ascii_layout_is_m11_m12_m22_m13_m23_m33() -> R {
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("order.sol");
    std::fs::write(
        &path,
        "MeshVersionFormatted 2\n# a comment\nDimension 3\nSolAtVertices\n1\n1 3\n11 12 22 13 23 33\nEnd\n",
    )?;
    let m = &read_sol(&path, 1)?[0];
    assert_eq!(
        *m,
        Matrix3::new(11.0, 12.0, 13.0, 12.0, 22.0, 23.0, 13.0, 23.0, 33.0)
    );
    write_sol(&path, &[*m], false)?;
    let text = std::fs::read_to_string(&path)?;
    assert!(
        text.contains("1.1e1 1.2e1 2.2e1 1.3e1 2.3e1 3.3e1"),
        "{text}"
    );
    Ok(())
}

#[test]
fn scalar_solutions_are_isotropic_sizes() -> R {
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("iso.sol");
    std::fs::write(
        &path,
        "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n2\n1 1\n0.5\n2\nEnd\n",
    )?;
    let ms = read_sol(&path, 2)?;
    assert_eq!(ms[0], Matrix3::identity() * 4.0);
    assert_eq!(ms[1], Matrix3::identity() * 0.25);
    std::fs::write(
        &path,
        "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n2\n1 1\n0.5\n-2\nEnd\n",
    )?;
    assert!(matches!(
        read_sol(&path, 2),
        Err(SolError::InvalidSize { vertex: 1, .. })
    ));
    Ok(())
}

fn write(dir: &Path, name: &str, body: &str) -> std::io::Result<std::path::PathBuf> {
    let p = dir.join(name);
    std::fs::write(&p, body)?;
    Ok(p)
}

#[test]
fn bad_ascii_files_give_named_errors() -> R {
    let dir = tempfile::tempdir()?;
    let d = dir.path();
    let head = "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n";
    let p = write(
        d,
        "count.sol",
        &format!("{head}2\n1 3\n1 0 1 0 0 0\n1 0 1 0 0 0\nEnd\n"),
    )?;
    let e = read_sol(&p, 3).unwrap_err();
    assert!(
        matches!(
            e,
            SolError::CountMismatch {
                expected: 3,
                found: 2,
                ..
            }
        ),
        "{e}"
    );
    let p = write(
        d,
        "nan.sol",
        &format!("{head}2\n1 3\n1 0 1 0 0 0\n1 0 nan 0 0 0\nEnd\n"),
    )?;
    let e = read_sol(&p, 2).unwrap_err();
    assert!(matches!(e, SolError::NaN { vertex: 1, .. }), "{e}");
    assert!(e.to_string().contains("v1"));
    let p = write(
        d,
        "trunc.sol",
        &format!("{head}2\n1 3\n1 0 1 0 0 0\n1 0 1\n"),
    )?;
    let e = read_sol(&p, 2).unwrap_err();
    assert!(
        matches!(
            e,
            SolError::Truncated {
                missing: SolTruncation::Values {
                    need: 12,
                    found: 9,
                    vertex: 1
                },
                ..
            }
        ),
        "{e}"
    );
    let p = write(
        d,
        "parse.sol",
        &format!("{head}2\n1 3\n1 0 1 0 0 0\n1 0 x 0 0 0\nEnd\n"),
    )?;
    let e = read_sol(&p, 2).unwrap_err();
    assert!(
        matches!(
            &e,
            SolError::Parse {
                line: 7,
                defect: SolSyntax::NotANumber { found },
                ..
            } if found == "x"
        ),
        "{e}"
    );
    let p = write(d, "type.sol", &format!("{head}2\n1 2\n1 0 1\n1 0 1\nEnd\n"))?;
    let e = read_sol(&p, 2).unwrap_err();
    assert!(
        matches!(
            &e,
            SolError::UnsupportedType {
                what: SolUnsupported::Types { types, .. },
                ..
            } if types == &[2]
        ),
        "{e}"
    );
    let p = write(
        d,
        "dim.sol",
        "MeshVersionFormatted 2\nDimension 2\nSolAtVertices\n1\n1 3\n1 0 1\nEnd\n",
    )?;
    let e = read_sol(&p, 1).unwrap_err();
    assert!(
        matches!(
            e,
            SolError::UnsupportedType {
                what: SolUnsupported::Dimension(2),
                ..
            }
        ),
        "{e}"
    );
    let e = read_sol(&d.join("missing.sol"), 1).unwrap_err();
    assert!(matches!(e, SolError::Io { .. }), "{e}");
    Ok(())
}

#[test]
fn bad_binary_files_give_named_errors() -> R {
    let dir = tempfile::tempdir()?;
    let (m, ms) = metrics()?;
    let p = dir.path().join("b.sol");
    write_sol(&p, &ms, true)?;
    let full = std::fs::read(&p)?;
    let e = read_sol(&p, m.n_vertices() + 1).unwrap_err();
    assert!(matches!(e, SolError::CountMismatch { .. }), "{e}");
    std::fs::write(&p, &full[..full.len() - 20])?;
    let e = read_sol(&p, m.n_vertices()).unwrap_err();
    assert!(
        matches!(
            e,
            SolError::Truncated {
                missing: SolTruncation::Bytes { .. },
                ..
            }
        ),
        "{e}"
    );
    std::fs::write(&p, &full[..10])?;
    let e = read_sol(&p, m.n_vertices()).unwrap_err();
    assert!(
        matches!(
            e,
            SolError::Truncated {
                missing: SolTruncation::Word { byte: 8, .. },
                ..
            }
        ),
        "{e}"
    );
    // A NaN in the data of vertex 3 (data starts at byte 40, 48 bytes per vertex).
    let mut bad = full.clone();
    bad[40 + 3 * 48 + 16..40 + 3 * 48 + 24].copy_from_slice(&f64::NAN.to_le_bytes());
    std::fs::write(&p, &bad)?;
    let e = read_sol(&p, m.n_vertices()).unwrap_err();
    assert!(matches!(e, SolError::NaN { vertex: 3, .. }), "{e}");
    // Writing a NaN is refused and leaves no file.
    let mut nan = ms.clone();
    nan[4][(1, 2)] = f64::NAN;
    let q = dir.path().join("never.sol");
    assert!(matches!(
        write_sol(&q, &nan, false),
        Err(SolError::NaN { vertex: 4, .. })
    ));
    assert!(!q.exists());
    Ok(())
}

#[test]
fn big_endian_binary_is_read() -> R {
    // Version 1 (float32), big-endian, one tensor.
    let mut b = Vec::new();
    for w in [1i32, 1, 3, 20, 3, 62, 64, 1, 1, 3] {
        b.extend_from_slice(&w.to_be_bytes());
    }
    for x in [1.0f32, 0.5, 2.0, 0.0, 0.25, 3.0] {
        b.extend_from_slice(&x.to_be_bytes());
    }
    b.extend_from_slice(&54i32.to_be_bytes());
    b.extend_from_slice(&0i32.to_be_bytes());
    let dir = tempfile::tempdir()?;
    let p = dir.path().join("be.sol");
    std::fs::write(&p, &b)?;
    let m = read_sol(&p, 1)?;
    assert_eq!(
        m[0],
        Matrix3::new(1.0, 0.5, 0.0, 0.5, 2.0, 0.25, 0.0, 0.25, 3.0)
    );
    Ok(())
}

/// Issue 20: a tensor that is positive definite but conditioned beyond what the field takes is
/// not called indefinite, and the CLI names the .sol file and the vertex.
#[test]
fn an_ill_conditioned_tensor_is_named_as_such_with_its_file() -> R {
    let dir = tempfile::tempdir()?;
    let mesh = conemesh::TriMesh::new(
        vec![
            nalgebra::Point3::new(0.0, 0.0, 0.0),
            nalgebra::Point3::new(1.0, 0.0, 0.0),
            nalgebra::Point3::new(0.0, 1.0, 0.0),
            nalgebra::Point3::new(1.0, 1.0, 0.1),
        ],
        vec![
            [
                conemesh::VertexId(0),
                conemesh::VertexId(1),
                conemesh::VertexId(2),
            ],
            [
                conemesh::VertexId(1),
                conemesh::VertexId(3),
                conemesh::VertexId(2),
            ],
        ],
    )?;
    let input = dir.path().join("q.obj");
    conemesh::io::write_mesh(&input, &mesh)?;
    let mut ms = vec![nalgebra::Matrix3::identity(); 4];
    ms[3][(0, 0)] = 1e12;
    let sol = dir.path().join("skewed.sol");
    write_sol(&sol, &ms, false)?;
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .arg("remesh")
        .arg(&input)
        .arg("--metric")
        .arg(&sol)
        .arg("-o")
        .arg(dir.path().join("out.obj"))
        .arg("--quiet")
        .output()?;
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("skewed.sol") && err.contains("vertex v3"),
        "{err}"
    );
    assert!(err.contains("conditioned beyond"), "{err}");
    assert!(!err.contains("not positive definite"), "{err}");
    assert!(!dir.path().join("out.obj").exists());
    Ok(())
}

#[test]
fn non_spd_tensor_from_a_sol_file_is_rejected_by_the_field() -> R {
    let dir = tempfile::tempdir()?;
    let m0 = generators::torus(1.0, 0.3, 24, 12);
    let m = Normalization::of(&m0).apply(&m0);
    let mut ms = curvature_metric(&m, &MetricOptions::default())?;
    assert!(MetricField::new(m.clone(), ms.clone()).is_ok());
    ms[11] = -ms[11];
    let p = dir.path().join("neg.sol");
    write_sol(&p, &ms, false)?;
    let back = read_sol(&p, m.n_vertices())?;
    let e = MetricField::new(m, back).unwrap_err();
    assert!(
        matches!(
            e,
            MetricError::NotSpd {
                vertex: 11,
                defect: conemesh::metric::SpdDefect::NegativeEigenvalue { .. }
            }
        ),
        "{e}"
    );
    Ok(())
}
