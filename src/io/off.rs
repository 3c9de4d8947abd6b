//! OFF (Object File Format): `OFF`, counts `V F E`, V vertex lines, F face lines `n i1 … in`.
//! Variants `COFF`, `NOFF`, `STOFF`, … carry extra per-vertex values, which are skipped
//! (each vertex and face is one line). Binary OFF and 4D/nD OFF are refused by name.

use super::text::{as_text_with_names, count, float, int};
use super::{build_mesh, check_claim, IoError, LoadedMesh, RawFaces, Syntax, Truncation, Unread};
use crate::mesh::TriMesh;
use nalgebra::Point3;
use std::io::Write;

const F: &str = "OFF";

pub(super) fn read(bytes: &[u8], path: &str) -> Result<LoadedMesh, IoError> {
    let text = as_text_with_names(bytes, path, F, &[])?;
    let text: &str = &text;
    let mut lines = super::text::lines(text)
        .enumerate()
        .map(|(i, l)| (i + 1, l.split('#').next().unwrap_or("").trim()))
        .filter(|(_, l)| !l.is_empty());
    let (nv, nf) = counts(&mut lines, path)?;
    // Each vertex line needs at least "0 0 0" (5 bytes), each face "3 0 1 2" (7 bytes).
    check_claim(path, F, "vertices", nv, 5, bytes.len())?;
    check_claim(path, F, "faces", nf, 7, bytes.len())?;
    let positions = read_vertices(&mut lines, nv, path)?;
    let mut faces = RawFaces::with_capacity(nf as usize, 0);
    for f in 0..nf as usize {
        read_face(&mut lines, f, nf, &mut faces, path)?;
    }
    let mut warnings = Vec::new();
    if let Some((l, _)) = lines.next() {
        warnings.push(format!("{path}:{l}: data after the last face ignored"));
    }
    let (mesh, polygons, _, repeated) = build_mesh(path, F, positions, &faces)?;
    if polygons > 0 {
        warnings.push(format!(
            "{path}: {polygons} polygon faces cut into triangles"
        ));
    }
    Ok(LoadedMesh {
        mesh,
        polygons_triangulated: polygons,
        welded_vertices: 0,
        warnings,
        attributes: Default::default(),
        repeated_index_faces: repeated,
    })
}

/// The header: the magic word (`OFF` with its variant letters) and the counts `V F`, on its
/// line or the next.
fn counts<'a>(
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
    path: &str,
) -> Result<(u64, u64), IoError> {
    let Some((_, first)) = lines.next() else {
        return Err(IoError::Empty {
            path: path.to_string(),
            format: F,
        });
    };
    let mut head = first.split_ascii_whitespace();
    let magic = head.next().unwrap_or("");
    let prefix = magic.strip_suffix("OFF");
    let Some(prefix) = prefix.filter(|p| p.chars().all(|c| "STCN4n".contains(c))) else {
        return Err(IoError::BadMagic {
            path: path.to_string(),
            format: F,
            found: super::printable(first.as_bytes()),
        });
    };
    if prefix.contains('4') || prefix.contains('n') {
        return Err(IoError::Unsupported {
            path: path.to_string(),
            format: F,
            what: Unread::OffDimension {
                magic: magic.to_string(),
            },
        });
    }
    let mut rest: Vec<&str> = head.collect();
    if rest.first() == Some(&"BINARY") {
        return Err(IoError::Unsupported {
            path: path.to_string(),
            format: F,
            what: Unread::BinaryOff,
        });
    }
    let mut count_line = 1;
    if rest.is_empty() {
        let Some((l, s)) = lines.next() else {
            return Err(IoError::Truncated {
                path: path.to_string(),
                format: F,
                missing: Truncation::NoCounts,
            });
        };
        count_line = l;
        rest = s.split_ascii_whitespace().collect();
    }
    if rest.len() < 2 {
        return Err(IoError::Parse {
            path: path.to_string(),
            format: F,
            line: count_line,
            defect: Syntax::NoCounts,
        });
    }
    let nv = count(rest[0], count_line, path, F)?;
    let nf = count(rest[1], count_line, path, F)?;
    Ok((nv, nf))
}

/// The `nv` vertex lines: the first three values of each.
fn read_vertices<'a>(
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
    nv: u64,
    path: &str,
) -> Result<Vec<Point3<f64>>, IoError> {
    let mut positions = Vec::with_capacity(nv as usize);
    for i in 0..nv as usize {
        let Some((l, s)) = lines.next() else {
            return Err(IoError::Truncated {
                path: path.to_string(),
                format: F,
                missing: Truncation::Elements {
                    claimed: nv,
                    what: "vertices",
                    found: i,
                },
            });
        };
        let t: Vec<&str> = s.split_ascii_whitespace().take(3).collect();
        if t.len() < 3 {
            return Err(IoError::Parse {
                path: path.to_string(),
                format: F,
                line: l,
                defect: Syntax::FewCoordinates {
                    vertex: i,
                    coordinates: t.len(),
                },
            });
        }
        let p = Point3::new(
            float(t[0], l, path, F)?,
            float(t[1], l, path, F)?,
            float(t[2], l, path, F)?,
        );
        if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
            return Err(IoError::NonFinite {
                path: path.to_string(),
                line: l,
                vertex: i,
            });
        }
        positions.push(p);
    }
    Ok(positions)
}

/// Face `f` of `nf`: its count and indices, into `faces`.
fn read_face<'a>(
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
    f: usize,
    nf: u64,
    faces: &mut RawFaces,
    path: &str,
) -> Result<(), IoError> {
    let Some((l, s)) = lines.next() else {
        return Err(IoError::Truncated {
            path: path.to_string(),
            format: F,
            missing: Truncation::Elements {
                claimed: nf,
                what: "faces",
                found: f,
            },
        });
    };
    let mut t = s.split_ascii_whitespace();
    let k = count(t.next().unwrap_or(""), l, path, F)?;
    faces.begin(l);
    let mut got = 0u64;
    for tok in t.by_ref().take(k.min(u32::MAX as u64) as usize) {
        faces.push(int(tok, l, path, F)?);
        got += 1;
    }
    // OFF is read as a token stream by most readers (libigl's `readOFF` among them), and
    // some writers break a long face over lines: a face that ends its line short takes
    // the next lines' indices, as long as each such line holds nothing else.
    let mut at = l;
    while got < k {
        let Some((l2, s2)) = lines.next() else {
            break;
        };
        let toks: Vec<&str> = s2.split_ascii_whitespace().collect();
        if got + toks.len() as u64 > k {
            return Err(IoError::Parse {
                path: path.to_string(),
                format: F,
                line: l2,
                defect: Syntax::FaceOverflow {
                    face: f,
                    announced: k,
                    from_line: l,
                },
            });
        }
        for tok in toks {
            faces.push(int(tok, l2, path, F)?);
            got += 1;
        }
        at = l2;
    }
    let l = at;
    if got < k {
        return Err(IoError::Parse {
            path: path.to_string(),
            format: F,
            line: l,
            defect: Syntax::FaceShort {
                face: f,
                announced: k,
                listed: got,
            },
        });
    }
    Ok(())
}

pub(super) fn write(w: &mut dyn Write, mesh: &TriMesh) -> std::io::Result<()> {
    writeln!(w, "OFF")?;
    writeln!(w, "{} {} 0", mesh.n_vertices(), mesh.n_faces())?;
    for p in &mesh.positions {
        // `{:?}` of f64 is the shortest text that parses back to the same bits.
        writeln!(w, "{:?} {:?} {:?}", p.x, p.y, p.z)?;
    }
    for t in &mesh.triangles {
        writeln!(w, "3 {} {} {}", t[0].0, t[1].0, t[2].0)?;
    }
    Ok(())
}
