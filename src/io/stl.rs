//! STL, ASCII (`solid … endsolid`) and binary (80-byte header, `u32` count, 50 bytes per
//! facet with `f32` coordinates). STL stores each facet's corners separately; the reader
//! welds corners with exactly equal coordinates (the count is `welded_vertices`).
//! A file is binary when its size is exactly `84 + 50·count`, else ASCII when it starts
//! with `solid`. Binary STL holds `f32`: writing rounds each coordinate to the nearest `f32`.

use super::text::{as_text, float, short, Tokens};
use super::{build_mesh, IoError, LoadedMesh, RawFaces, Syntax, Truncation, WriteOptions};
use crate::mesh::TriMesh;
use nalgebra::Point3;
use std::collections::HashMap;
use std::io::Write;

const F: &str = "STL";

/// Welds facet corners with equal coordinates (`-0.0` and `0.0` are equal).
struct Welder {
    map: HashMap<[u64; 3], usize>,
    positions: Vec<Point3<f64>>,
    faces: RawFaces,
    corners: usize,
}

impl Welder {
    fn new(facets: usize) -> Self {
        Welder {
            map: HashMap::with_capacity(facets),
            positions: Vec::with_capacity(facets / 2 + 3),
            faces: RawFaces::with_capacity(facets, 0),
            corners: 0,
        }
    }

    fn facet(&mut self, c: [Point3<f64>; 3], lines: [usize; 3], path: &str) -> Result<(), IoError> {
        self.faces.begin(lines[0]);
        for (k, p) in c.iter().enumerate() {
            if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                return Err(IoError::NonFinite {
                    path: path.to_string(),
                    line: lines[k],
                    vertex: self.corners + k,
                });
            }
            let key = [p.x, p.y, p.z].map(|x| (x + 0.0).to_bits());
            let n = self.positions.len();
            let v = *self.map.entry(key).or_insert(n);
            if v == n {
                self.positions.push(*p);
            }
            self.faces.push(v as i64);
        }
        self.corners += 3;
        Ok(())
    }

    fn finish(self, path: &str, mut warnings: Vec<String>) -> Result<LoadedMesh, IoError> {
        let welded = self.corners - self.positions.len();
        let (mesh, _, _, repeated) = build_mesh(path, F, self.positions, &self.faces)?;
        if welded > 0 {
            warnings.push(format!("{path}: {welded} duplicate facet corners welded"));
        }
        Ok(LoadedMesh {
            mesh,
            polygons_triangulated: 0,
            welded_vertices: welded,
            warnings,
            attributes: Default::default(),
            repeated_index_faces: repeated,
        })
    }
}

pub(super) fn read(bytes: &[u8], path: &str) -> Result<LoadedMesh, IoError> {
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(IoError::Empty {
            path: path.to_string(),
            format: F,
        });
    }
    let starts_solid = bytes
        .iter()
        .skip_while(|b| b.is_ascii_whitespace())
        .take(5)
        .eq(b"solid".iter());
    if bytes.len() >= 84 {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        let need = 84 + 50 * count;
        if need == bytes.len() as u64 || !starts_solid {
            return read_binary(bytes, count, path);
        }
    }
    if starts_solid {
        return read_ascii(bytes, path);
    }
    Err(IoError::Truncated {
        path: path.to_string(),
        format: F,
        missing: Truncation::ShortStl {
            file_bytes: bytes.len(),
        },
    })
}

fn read_binary(bytes: &[u8], count: u64, path: &str) -> Result<LoadedMesh, IoError> {
    let need = 84 + 50 * count;
    if need > bytes.len() as u64 {
        return Err(IoError::Truncated {
            path: path.to_string(),
            format: F,
            missing: Truncation::Facets {
                claimed: count,
                need,
                file_bytes: bytes.len(),
            },
        });
    }
    let mut warnings = Vec::new();
    if need < bytes.len() as u64 {
        warnings.push(format!(
            "{path}: {} bytes after the last facet ignored",
            bytes.len() as u64 - need
        ));
    }
    if count == 0 {
        return Err(IoError::NoFaces {
            path: path.to_string(),
            format: F,
        });
    }
    let mut w = Welder::new(count as usize);
    for rec in bytes[84..need as usize].chunks_exact(50) {
        let x = |k: usize| {
            let o = 12 + 4 * k;
            f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]) as f64
        };
        let c = [0, 1, 2].map(|j| Point3::new(x(3 * j), x(3 * j + 1), x(3 * j + 2)));
        w.facet(c, [0; 3], path)?;
    }
    w.finish(path, warnings)
}

fn read_ascii(bytes: &[u8], path: &str) -> Result<LoadedMesh, IoError> {
    let text = as_text(bytes, path, F)?;
    let mut t = Tokens::new(text);
    let mut w = Welder::new(0);
    let mut in_solid = false;
    let mut next = t.next();
    while let Some((l, tok)) = next.take() {
        let is = |word: &str| tok.eq_ignore_ascii_case(word);
        if is("solid") && !in_solid || is("endsolid") && in_solid {
            // The solid's name is the rest of the line.
            in_solid = !in_solid;
            next = t.by_ref().find(|&(l2, _)| l2 != l);
        } else if is("facet") && in_solid {
            expect(&mut t, "normal", path)?;
            for _ in 0..3 {
                num(&mut t, path)?;
            }
            expect(&mut t, "outer", path)?;
            expect(&mut t, "loop", path)?;
            let mut c = [Point3::origin(); 3];
            let mut vl = [l; 3];
            for (p, vl) in c.iter_mut().zip(&mut vl) {
                *vl = expect(&mut t, "vertex", path)?;
                *p = Point3::new(num(&mut t, path)?, num(&mut t, path)?, num(&mut t, path)?);
            }
            expect(&mut t, "endloop", path)?;
            expect(&mut t, "endfacet", path)?;
            w.facet(c, vl, path)?;
            next = t.next();
        } else {
            let found = short(tok);
            let defect = if in_solid {
                Syntax::NotAFacet { found }
            } else {
                Syntax::ExpectedKeyword {
                    keyword: "solid",
                    found,
                }
            };
            return Err(IoError::Parse {
                path: path.to_string(),
                format: F,
                line: l,
                defect,
            });
        }
    }
    if in_solid {
        return Err(IoError::Truncated {
            path: path.to_string(),
            format: F,
            missing: Truncation::NoEndsolid { line: t.last_line },
        });
    }
    if w.corners == 0 {
        return Err(IoError::NoFaces {
            path: path.to_string(),
            format: F,
        });
    }
    w.finish(path, Vec::new())
}

/// The next token must be `word`; returns its line.
fn expect(t: &mut Tokens, word: &'static str, path: &str) -> Result<usize, IoError> {
    match t.next() {
        Some((l, tok)) if tok.eq_ignore_ascii_case(word) => Ok(l),
        Some((l, tok)) => Err(IoError::Parse {
            path: path.to_string(),
            format: F,
            line: l,
            defect: Syntax::ExpectedKeyword {
                keyword: word,
                found: short(tok),
            },
        }),
        None => Err(IoError::Truncated {
            path: path.to_string(),
            format: F,
            missing: Truncation::Keyword {
                keyword: word,
                line: t.last_line,
            },
        }),
    }
}

fn num(t: &mut Tokens, path: &str) -> Result<f64, IoError> {
    match t.next() {
        Some((l, tok)) => float(tok, l, path, F),
        None => Err(IoError::Truncated {
            path: path.to_string(),
            format: F,
            missing: Truncation::InsideFacet { line: t.last_line },
        }),
    }
}

pub(super) fn write(w: &mut dyn Write, mesh: &TriMesh, opts: &WriteOptions) -> std::io::Result<()> {
    if opts.binary {
        let mut header = [b' '; 80];
        let tag = b"conemesh binary STL (f32 coordinates)";
        header[..tag.len()].copy_from_slice(tag);
        w.write_all(&header)?;
        let n = u32::try_from(mesh.n_faces()).map_err(std::io::Error::other)?;
        w.write_all(&n.to_le_bytes())?;
        for f in mesh.faces() {
            let nrm = mesh.face_normal(f);
            for x in [nrm.x, nrm.y, nrm.z] {
                w.write_all(&(x as f32).to_le_bytes())?;
            }
            for p in mesh.face_points(f) {
                // The format's precision: nearest f32.
                for x in [p.x, p.y, p.z] {
                    w.write_all(&(x as f32).to_le_bytes())?;
                }
            }
            w.write_all(&[0, 0])?;
        }
        return Ok(());
    }
    writeln!(w, "solid conemesh")?;
    for f in mesh.faces() {
        let n = mesh.face_normal(f);
        writeln!(w, "  facet normal {:?} {:?} {:?}", n.x, n.y, n.z)?;
        writeln!(w, "    outer loop")?;
        for p in mesh.face_points(f) {
            // `{:?}` of f64 round-trips exactly: ASCII STL keeps full precision.
            writeln!(w, "      vertex {:?} {:?} {:?}", p.x, p.y, p.z)?;
        }
        writeln!(w, "    endloop")?;
        writeln!(w, "  endfacet")?;
    }
    writeln!(w, "endsolid conemesh")?;
    Ok(())
}
