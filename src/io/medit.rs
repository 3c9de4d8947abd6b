//! Medit / INRIA `.mesh` (ASCII): `MeshVersionFormatted`, `Dimension`, then sections
//! `KEYWORD count records…` until `End`. `Vertices` (x y z ref, or x y ref in 2D, read with
//! z = 0) and `Triangles` (a b c ref, 1-based) are read, `Quadrilaterals` cut into triangles;
//! every other known section is skipped by its record size. Triangle references are kept as
//! the face attribute `ref` when any is non-zero, and written from the first face attribute.

use super::text::{as_text, count, float, int, short, Tokens};
use super::{
    build_mesh, check_claim, IoError, LoadedMesh, MeshAttributes, RawFaces, Syntax, Truncation,
};
use crate::mesh::TriMesh;
use nalgebra::Point3;
use std::io::Write;

const F: &str = "Medit";

/// Tokens per record of a section in dimension `d`; `None` for an unknown keyword.
fn record_tokens(key: &str, d: usize) -> Option<usize> {
    Some(match key {
        "vertices" => d + 1,
        "edges" => 3,
        "triangles" => 4,
        "quadrilaterals" | "tetrahedra" => 5,
        "pyramids" => 6,
        "prisms" => 7,
        "hexahedra" => 9,
        "corners"
        | "ridges"
        | "requiredvertices"
        | "requirededges"
        | "requiredtriangles"
        | "requiredquadrilaterals"
        | "requiredtetrahedra" => 1,
        "normals" | "tangents" => d,
        // (vertex, normal / tangent index); MMG writes both by default.
        "normalatvertices" | "tangentatvertices" => 2,
        "normalattrianglevertices"
        | "normalatquadrilateralvertices"
        | "tangentatedgevertices"
        | "normalatedgevertices" => 3,
        _ => return None,
    })
}

/// What the sections conemesh reads hold, record by record.
struct Records {
    positions: Vec<Point3<f64>>,
    faces: RawFaces,
    /// Each face's reference number (the record's last token).
    refs: Vec<i64>,
}

impl Records {
    /// One record `rec` of section `key` (lower case), written on line `line`; the records of
    /// sections conemesh skips are read and dropped.
    fn take(
        &mut self,
        key: &str,
        rec: &[&str],
        dim: usize,
        line: usize,
        path: &str,
    ) -> Result<(), IoError> {
        match key {
            "vertices" => {
                let mut p = Point3::origin();
                for j in 0..dim {
                    p[j] = float(rec[j], line, path, F)?;
                }
                if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                    return Err(IoError::NonFinite {
                        path: path.to_string(),
                        line,
                        vertex: self.positions.len(),
                    });
                }
                self.positions.push(p);
            }
            "triangles" | "quadrilaterals" => {
                let (corners, reference) = rec.split_at(rec.len() - 1);
                self.faces.begin(line);
                for r in corners {
                    // 1-based in the file.
                    self.faces.push(int(r, line, path, F)?.saturating_sub(1));
                }
                self.refs.push(int(reference[0], line, path, F)?);
            }
            _ => {}
        }
        Ok(())
    }
}

pub(super) fn read(bytes: &[u8], path: &str) -> Result<LoadedMesh, IoError> {
    let text = as_text(bytes, path, F)?;
    let mut t = Tokens::new(text);
    let parse = |line: usize, defect: Syntax| IoError::Parse {
        path: path.to_string(),
        format: F,
        line,
        defect,
    };
    let trunc = |missing: Truncation| IoError::Truncated {
        path: path.to_string(),
        format: F,
        missing,
    };
    let in_section = |section: &str, line: usize| {
        trunc(Truncation::InsideSection {
            section: short(section),
            line,
        })
    };
    let Some((l0, first)) = t.next() else {
        return Err(IoError::Empty {
            path: path.to_string(),
            format: F,
        });
    };
    if !first.eq_ignore_ascii_case("MeshVersionFormatted") {
        return Err(IoError::BadMagic {
            path: path.to_string(),
            format: F,
            found: super::printable(first.as_bytes()),
        });
    }
    let _version = match t.next() {
        Some((l, tok)) => int(tok, l, path, F)?,
        None => return Err(trunc(Truncation::InsideHeader { line: l0 })),
    };
    let mut dim = 3;
    let mut records = Records {
        positions: Vec::new(),
        faces: RawFaces::with_capacity(0, 1),
        refs: Vec::new(),
    };
    let mut warnings = Vec::new();
    while let Some((l, tok)) = t.next() {
        let key = tok.to_ascii_lowercase();
        if key == "end" {
            break;
        }
        if key == "dimension" {
            let (dl, d) = t.next().ok_or_else(|| {
                trunc(Truncation::InsideKeyword {
                    keyword: "Dimension",
                    line: l,
                })
            })?;
            dim = match int(d, dl, path, F)? {
                2 => 2,
                3 => 3,
                d => return Err(parse(dl, Syntax::Dimension(d))),
            };
            continue;
        }
        let Some(k) = record_tokens(&key, dim) else {
            return Err(parse(l, Syntax::UnknownSection { found: short(tok) }));
        };
        let (cl, c) = t.next().ok_or_else(|| in_section(tok, l))?;
        let n = count(c, cl, path, F)?;
        // Each record takes at least k tokens of 2 bytes.
        check_claim(path, F, "records", n, 2 * k as u64, bytes.len() + 1)?;
        let mut rec = [""; 9];
        for _ in 0..n {
            for slot in rec.iter_mut().take(k) {
                *slot = t.next().ok_or_else(|| in_section(tok, t.last_line))?.1;
            }
            records.take(&key, &rec[..k], dim, t.last_line, path)?;
        }
        if !matches!(key.as_str(), "vertices" | "triangles" | "quadrilaterals") {
            warnings.push(format!("{path}: section `{tok}` skipped"));
        }
    }
    let Records {
        positions,
        faces,
        refs,
    } = records;
    let (mesh, polygons, origin, repeated) = build_mesh(path, F, positions, &faces)?;
    if polygons > 0 {
        warnings.push(format!(
            "{path}: {polygons} quadrilaterals cut into triangles"
        ));
    }
    let mut attributes = MeshAttributes::default();
    if refs.iter().any(|&r| r != 0) {
        let r: Option<Vec<i64>> = origin.iter().map(|&f| refs.get(f).copied()).collect();
        if let Some(r) = r {
            attributes.face_ints.push(("ref".into(), r));
        }
    }
    Ok(LoadedMesh {
        mesh,
        polygons_triangulated: polygons,
        welded_vertices: 0,
        warnings,
        attributes,
        repeated_index_faces: repeated,
    })
}

pub(super) fn write(
    w: &mut dyn Write,
    mesh: &TriMesh,
    attrs: &MeshAttributes,
) -> std::io::Result<()> {
    writeln!(w, "MeshVersionFormatted 2\nDimension 3\n")?;
    writeln!(w, "Vertices\n{}", mesh.n_vertices())?;
    for p in &mesh.positions {
        // `{:?}` of f64 is the shortest text that parses back to the same bits.
        writeln!(w, "{:?} {:?} {:?} 0", p.x, p.y, p.z)?;
    }
    writeln!(w, "\nTriangles\n{}", mesh.n_faces())?;
    let refs = attrs.face_ints.first().map(|(_, v)| v);
    for (f, t) in mesh.triangles.iter().enumerate() {
        let r = refs.and_then(|v| v.get(f)).copied().unwrap_or(0);
        writeln!(
            w,
            "{} {} {} {r}",
            t[0].0 as u64 + 1,
            t[1].0 as u64 + 1,
            t[2].0 as u64 + 1
        )?;
    }
    writeln!(w, "\nEnd")?;
    Ok(())
}
