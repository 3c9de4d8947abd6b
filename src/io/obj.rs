//! Wavefront OBJ: `v x y z`, `vt u v`, `f a a/b a//c a/b/c` with 1-based or negative
//! (relative) indices. Normals, groups, objects, smoothing groups, materials, lines and points
//! are ignored; other keywords are ignored with a warning. Names (`g`, `o`, `usemtl`, …) and
//! comments may hold bytes that are not UTF-8.

use super::text::{as_text_with_names, float, int, short};
use super::{build_mesh, uv_per_vertex, IoError, LoadedMesh, MeshAttributes, RawFaces, Syntax};
use crate::mesh::TriMesh;
use nalgebra::{Point2, Point3};
use std::io::Write;

const F: &str = "OBJ";

/// Keywords that carry nothing a triangle mesh needs.
const IGNORED: &[&str] = &[
    "vn",
    "vp",
    "g",
    "o",
    "s",
    "usemtl",
    "mtllib",
    "l",
    "p",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "mg",
    "lod",
    "bevel",
    "c_interp",
    "d_interp",
    "usemap",
    "maplib",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
];

/// Keywords followed by a name, which may hold any bytes (`text::as_text_with_names`).
const NAMES: &[&str] = &["g", "o", "s", "usemtl", "mtllib", "usemap", "maplib"];

/// Resolve an OBJ index (1-based, or negative: relative to the `n` elements defined so far)
/// to 0-based; `None` for 0 or an index before the first element.
fn resolve(i: i64, n: usize) -> Option<i64> {
    match i {
        0 => None,
        i if i > 0 => Some(i - 1),
        i => {
            let r = n as i64 + i;
            (r >= 0).then_some(r)
        }
    }
}

pub(super) fn read(bytes: &[u8], path: &str) -> Result<LoadedMesh, IoError> {
    let text = as_text_with_names(bytes, path, F, NAMES)?;
    let mut positions: Vec<Point3<f64>> = Vec::new();
    let mut vts: Vec<Point2<f64>> = Vec::new();
    let mut faces = RawFaces::with_capacity(0, 1);
    // (vertex, vt index) per corner, while every corner has a vt.
    let mut corner_vt: Option<Vec<(usize, i64)>> = Some(Vec::new());
    let mut unknown: Vec<String> = Vec::new();
    let mut any = false;
    for (i, raw) in super::text::lines(&text).enumerate() {
        let l = i + 1;
        let s = raw.split('#').next().unwrap_or("");
        let mut t = s.split_ascii_whitespace();
        let Some(key) = t.next() else { continue };
        any = true;
        match key {
            "v" => positions.push(vertex_line(t, l, path, positions.len())?),
            "vt" => vts.push(texture_line(t, l, path)?),
            "f" => face_line(
                t,
                l,
                path,
                positions.len(),
                &vts,
                &mut faces,
                &mut corner_vt,
            )?,
            k if IGNORED.contains(&k) => {}
            k => {
                let k = short(k);
                if !unknown.contains(&k) {
                    unknown.push(k);
                }
            }
        }
    }
    if !any {
        return Err(IoError::Empty {
            path: path.to_string(),
            format: F,
        });
    }
    let mut warnings: Vec<String> = unknown
        .iter()
        .map(|k| format!("{path}: unknown OBJ keyword `{k}` ignored"))
        .collect();
    let n_v = positions.len();
    let (mesh, polygons, _, repeated) = build_mesh(path, F, positions, &faces)?;
    if polygons > 0 {
        warnings.push(format!(
            "{path}: {polygons} polygon faces cut into triangles"
        ));
    }
    let attributes = texture_per_vertex(corner_vt, &vts, n_v, path, &mut warnings);
    Ok(LoadedMesh {
        mesh,
        polygons_triangulated: polygons,
        welded_vertices: 0,
        warnings,
        attributes,
        repeated_index_faces: repeated,
    })
}

/// A `v` line's position (its first three values); `n` vertices came before it.
fn vertex_line(
    t: std::str::SplitAsciiWhitespace,
    l: usize,
    path: &str,
    n: usize,
) -> Result<Point3<f64>, IoError> {
    let c: Vec<&str> = t.take(3).collect();
    if c.len() < 3 {
        return Err(IoError::Parse {
            path: path.to_string(),
            format: F,
            line: l,
            defect: Syntax::FewCoordinates {
                vertex: n,
                coordinates: c.len(),
            },
        });
    }
    let p = Point3::new(
        float(c[0], l, path, F)?,
        float(c[1], l, path, F)?,
        float(c[2], l, path, F)?,
    );
    if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
        return Err(IoError::NonFinite {
            path: path.to_string(),
            line: l,
            vertex: n,
        });
    }
    Ok(p)
}

/// A `vt` line's texture coordinate (missing values read as 0).
fn texture_line(
    mut t: std::str::SplitAsciiWhitespace,
    l: usize,
    path: &str,
) -> Result<Point2<f64>, IoError> {
    let u = float(t.next().unwrap_or("0"), l, path, F)?;
    let v = float(t.next().unwrap_or("0"), l, path, F)?;
    if !(u.is_finite() && v.is_finite()) {
        return Err(IoError::Parse {
            path: path.to_string(),
            format: F,
            line: l,
            defect: Syntax::NonFiniteTexture,
        });
    }
    Ok(Point2::new(u, v))
}

/// An `f` line's corners into `faces`; their texture indices into `corner_vt` while every
/// corner so far has one. `n_vertices` vertices and the `vts` came before it.
fn face_line(
    t: std::str::SplitAsciiWhitespace,
    l: usize,
    path: &str,
    n_vertices: usize,
    vts: &[Point2<f64>],
    faces: &mut RawFaces,
    corner_vt: &mut Option<Vec<(usize, i64)>>,
) -> Result<(), IoError> {
    let f = faces.len();
    faces.begin(l);
    for corner in t {
        let mut parts = corner.split('/');
        let written = int(parts.next().unwrap_or(""), l, path, F)?;
        let Some(v) = resolve(written, n_vertices) else {
            return Err(IoError::BadIndex {
                path: path.to_string(),
                line: l,
                face: f,
                index: written,
                n_vertices,
            });
        };
        faces.push(v);
        match parts.next().filter(|s| !s.is_empty()) {
            Some(vt) => {
                let wt = int(vt, l, path, F)?;
                // Like vertex indices, a texture index must name a `vt` above it.
                let r = resolve(wt, vts.len()).filter(|&r| (r as usize) < vts.len());
                match (r, corner_vt.as_mut()) {
                    (Some(r), Some(c)) => c.push((v as usize, r)),
                    (None, _) => {
                        return Err(IoError::Parse {
                            path: path.to_string(),
                            format: F,
                            line: l,
                            defect: Syntax::BadTextureIndex {
                                face: f,
                                index: wt,
                                defined: vts.len(),
                            },
                        })
                    }
                    _ => {}
                }
            }
            None => *corner_vt = None,
        }
    }
    Ok(())
}

/// The texture coordinates per vertex, when every corner has one and each vertex has one
/// (no seams); otherwise none, with a warning.
fn texture_per_vertex(
    corner_vt: Option<Vec<(usize, i64)>>,
    vts: &[Point2<f64>],
    n_v: usize,
    path: &str,
    warnings: &mut Vec<String>,
) -> MeshAttributes {
    let mut attributes = MeshAttributes::default();
    if let Some(c) = corner_vt.filter(|c| !c.is_empty()) {
        let mut corners = Vec::with_capacity(c.len());
        let mut ok = true;
        for (v, t) in c {
            match vts.get(t as usize) {
                Some(q) => corners.push((v, *q)),
                None => ok = false,
            }
        }
        attributes.uv = if ok {
            uv_per_vertex(n_v, &corners)
        } else {
            None
        };
        if attributes.uv.is_none() {
            warnings.push(format!(
                "{path}: texture coordinates are not one per vertex (seams); not kept"
            ));
        }
    }
    attributes
}

pub(super) fn write(
    w: &mut dyn Write,
    mesh: &TriMesh,
    attrs: &MeshAttributes,
) -> std::io::Result<()> {
    writeln!(
        w,
        "# conemesh: {} vertices, {} triangles",
        mesh.n_vertices(),
        mesh.n_faces()
    )?;
    for p in &mesh.positions {
        // `{:?}` of f64 is the shortest text that parses back to the same bits.
        writeln!(w, "v {:?} {:?} {:?}", p.x, p.y, p.z)?;
    }
    match &attrs.uv {
        Some(uv) => {
            for q in uv {
                writeln!(w, "vt {:?} {:?}", q.x, q.y)?;
            }
            for t in &mesh.triangles {
                let (a, b, c) = (t[0].0 as u64 + 1, t[1].0 as u64 + 1, t[2].0 as u64 + 1);
                writeln!(w, "f {a}/{a} {b}/{b} {c}/{c}")?;
            }
        }
        None => {
            for t in &mesh.triangles {
                writeln!(
                    w,
                    "f {} {} {}",
                    t[0].0 as u64 + 1,
                    t[1].0 as u64 + 1,
                    t[2].0 as u64 + 1
                )?;
            }
        }
    }
    Ok(())
}
