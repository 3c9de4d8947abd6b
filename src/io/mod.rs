//! Mesh file formats: OBJ, OFF, PLY, STL, Medit `.mesh` (one file per format, reader and
//! writer). Writers are atomic: a failure leaves no partial output file.
//!
//! Every reader works on the whole file in memory, never trusts a count from a header for an
//! allocation (pre-allocation is capped by what the file's size can hold), and turns every
//! malformed input into a typed [`IoError`] naming the file, the line (text formats) and the
//! element. Readers build a [`TriMesh`] through its validating constructor; whether the mesh is
//! manifold or consistently oriented is not the reader's business (that is `check`).

mod defect;
mod medit;
mod obj;
mod off;
mod outputs;
pub mod patches;
pub mod paths;
mod ply;
mod polygon;
pub mod sol;
mod stl;
mod text;

pub use defect::{AttributeProblem, Syntax, Truncation, Unread, Want};
pub use outputs::{Outputs, TEMP_PREFIX};
pub use polygon::PolygonProblem;

use crate::mesh::{MeshError, TriMesh};
use nalgebra::{Point2, Point3};
use std::io::Write;
use std::path::Path;
use thiserror::Error;

/// At most 24 characters of a byte string, non-printable bytes shown as `?`.
pub(crate) fn printable(bytes: &[u8]) -> String {
    String::from_utf8_lossy(&bytes[..bytes.len().min(24)])
        .chars()
        .map(|c| {
            if c.is_ascii_graphic() || c == ' ' {
                c
            } else {
                '?'
            }
        })
        .collect()
}

/// " line N" for text formats, nothing for binary ones (line 0).
fn loc(line: &usize) -> String {
    if *line == 0 {
        String::new()
    } else {
        format!(":{line}")
    }
}

/// Errors of reading and writing mesh files. Each names the file and, where there is one,
/// the line (`path:line:`) and the element (face or vertex number, 0-based as in the file's
/// own order).
#[derive(Debug, Error)]
pub enum IoError {
    /// Operating-system error on a path. The OS error is part of the message and not a
    /// `source()`, so error chains (`anyhow`'s `{:#}`) do not print it twice.
    #[error("{path}: {error}")]
    Os {
        /// the file
        path: String,
        /// the OS error
        error: std::io::Error,
    },
    /// The file extension names no supported format.
    #[error("{path}: unsupported format (expected .obj, .off, .ply, .stl or .mesh)")]
    UnsupportedFormat {
        /// the file
        path: String,
    },
    /// The file holds nothing (zero bytes, or only whitespace and comments).
    #[error("{path}: empty {format} file")]
    Empty {
        /// the file
        path: String,
        /// format name
        format: &'static str,
    },
    /// The file does not start with the format's magic word.
    #[error("{path}: wrong magic for {format} (file starts with {found:?})")]
    BadMagic {
        /// the file
        path: String,
        /// format name
        format: &'static str,
        /// what the file starts with (shortened)
        found: String,
    },
    /// Malformed text or header.
    #[error("{path}{}: {format} parse error: {defect}", loc(.line))]
    Parse {
        /// the file
        path: String,
        /// format name
        format: &'static str,
        /// 1-based line (0 when the format is binary)
        line: usize,
        /// what is wrong
        defect: Syntax,
    },
    /// The file ends before the data its header announced.
    #[error("{path}: truncated {format} file: {missing}")]
    Truncated {
        /// the file
        path: String,
        /// format name
        format: &'static str,
        /// what was expected and what was found
        missing: Truncation,
    },
    /// A header claims more elements than a `u32` id can name (a file claiming more than it
    /// can hold, but fewer than that, is [`IoError::Truncated`]).
    #[error("{path}: {format} header claims {claimed} {what}, more than u32 ids can name (file has {file_bytes} bytes)")]
    TooLarge {
        /// the file
        path: String,
        /// format name
        format: &'static str,
        /// "vertices", "faces", ...
        what: &'static str,
        /// the claimed count
        claimed: u64,
        /// size of the file
        file_bytes: u64,
    },
    /// A face refers to a vertex that does not exist (index as written in the file).
    #[error("{path}{}: face {face} refers to vertex index {index}, but the file has {n_vertices} vertices", loc(.line))]
    BadIndex {
        /// the file
        path: String,
        /// 1-based line (0 for binary formats)
        line: usize,
        /// face number in the file (0-based)
        face: usize,
        /// the index as written (1-based for OBJ and Medit, may be negative)
        index: i64,
        /// number of vertices
        n_vertices: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("{path}{}: vertex {vertex} has a non-finite coordinate", loc(.line))]
    NonFinite {
        /// the file
        path: String,
        /// 1-based line (0 for binary formats)
        line: usize,
        /// vertex number in the file (0-based; for STL the facet corner 3·facet + k)
        vertex: usize,
    },
    /// A face uses the same vertex twice.
    #[error(
        "{path}{}: face {face} repeats vertex {vertex} (`conemesh remesh --repair` leaves such \
         faces out)",
        loc(.line)
    )]
    RepeatedVertex {
        /// the file
        path: String,
        /// 1-based line (0 for binary formats)
        line: usize,
        /// face number in the file (0-based)
        face: usize,
        /// the repeated vertex (0-based)
        vertex: usize,
    },
    /// A polygon face that cannot be cut into triangles inside it ([`PolygonProblem`]).
    #[error("{path}{}: face {face} ({corners} corners) {problem}", loc(.line))]
    BadPolygon {
        /// the file
        path: String,
        /// 1-based line (0 for binary formats)
        line: usize,
        /// face number in the file (0-based)
        face: usize,
        /// its number of corners
        corners: usize,
        /// what is wrong with it
        problem: PolygonProblem,
    },
    /// A PLY property type that the PLY format does not define.
    #[error("{path}{}: PLY property `{property}` of element `{element}` has unknown type `{ty}`", loc(.line))]
    UnknownProperty {
        /// the file
        path: String,
        /// 1-based header line
        line: usize,
        /// element name
        element: String,
        /// property name
        property: String,
        /// the unknown type name
        ty: String,
    },
    /// A variant of the format that conemesh does not read (named).
    #[error("{path}: {format}: {what} is not supported")]
    Unsupported {
        /// the file
        path: String,
        /// format name
        format: &'static str,
        /// the unsupported feature
        what: Unread,
    },
    /// The file holds no faces.
    #[error("{path}: {format} file has no faces")]
    NoFaces {
        /// the file
        path: String,
        /// format name
        format: &'static str,
    },
    /// Attributes handed to a writer do not match the mesh.
    #[error("{path}: bad attribute: {problem}")]
    BadAttribute {
        /// the file
        path: String,
        /// what does not match
        problem: AttributeProblem,
    },
    /// The mesh arrays are invalid (a writer refuses to write them).
    #[error("{path}: {source}")]
    Mesh {
        /// the file
        path: String,
        /// the mesh error
        source: MeshError,
    },
}

impl IoError {
    /// A short stable name of the error kind (used by the bad-input corpus table).
    pub fn kind(&self) -> &'static str {
        match self {
            IoError::Os { .. } => "os",
            IoError::UnsupportedFormat { .. } => "unsupported-format",
            IoError::Empty { .. } => "empty",
            IoError::BadMagic { .. } => "bad-magic",
            IoError::Parse { .. } => "parse",
            IoError::Truncated { .. } => "truncated",
            IoError::TooLarge { .. } => "too-large",
            IoError::BadIndex { .. } => "bad-index",
            IoError::NonFinite { .. } => "non-finite",
            IoError::RepeatedVertex { .. } => "repeated-vertex",
            IoError::BadPolygon { .. } => "bad-polygon",
            IoError::UnknownProperty { .. } => "unknown-property",
            IoError::Unsupported { .. } => "unsupported",
            IoError::NoFaces { .. } => "no-faces",
            IoError::BadAttribute { .. } => "bad-attribute",
            IoError::Mesh { .. } => "mesh",
        }
    }
}

/// A mesh read from a file, with what the reader had to fix or skip.
#[derive(Clone, Debug)]
pub struct LoadedMesh {
    /// The triangles and positions as read (unreferenced vertices kept).
    pub mesh: TriMesh,
    /// Polygon faces with more than three corners that were cut into triangles.
    pub polygons_triangulated: usize,
    /// Vertices merged because they had bit-identical positions (STL).
    pub welded_vertices: usize,
    /// Human-readable warnings (one line each).
    pub warnings: Vec<String>,
    /// Attributes found in the file (OBJ `vt`, PLY `u v`, PLY integer face properties and
    /// `red green blue`), per triangle after polygons are cut into triangles.
    pub attributes: MeshAttributes,
    /// Faces that use a vertex twice (after STL's welding of corners), left out of `mesh`.
    /// Only [`ReadOptions::drop_repeated_indices`] lets a read return them; otherwise the
    /// first is an [`IoError::RepeatedVertex`].
    pub repeated_index_faces: Vec<RepeatedIndexFace>,
}

/// A file face that uses a vertex twice, left out of the mesh read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct RepeatedIndexFace {
    /// Face number in the file (0-based; STL: the facet).
    pub face: usize,
    /// 1-based line (0 for binary formats).
    pub line: usize,
    /// The repeated vertex (0-based, after welding for STL).
    pub vertex: usize,
}

/// How a file is read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// Leave out faces that use a vertex twice and list them
    /// ([`LoadedMesh::repeated_index_faces`]) instead of refusing the file (`remesh --repair`).
    pub drop_repeated_indices: bool,
}

/// Optional per-element data to write with a mesh (formats that cannot hold an attribute
/// ignore it; PLY holds face properties and colours, OBJ holds `vt`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshAttributes {
    /// Named integer properties per face (PLY `property int NAME`).
    pub face_ints: Vec<(String, Vec<i64>)>,
    /// RGB colour per face (PLY `red green blue`).
    pub face_colors: Option<Vec<[u8; 3]>>,
    /// Texture coordinates per vertex (OBJ `vt`, PLY `u v`).
    pub uv: Option<Vec<Point2<f64>>>,
}

/// Encoding choices for writers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// Binary encoding where the format has one (PLY, STL).
    pub binary: bool,
    /// Big-endian binary PLY (default little-endian).
    pub big_endian: bool,
}

/// The supported formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ.
    Obj,
    /// Object File Format.
    Off,
    /// Stanford PLY.
    Ply,
    /// STL (stereolithography).
    Stl,
    /// Medit / INRIA `.mesh` (ASCII).
    Medit,
}

impl Format {
    /// The format named by a path's extension (case-insensitive).
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "obj" => Format::Obj,
            "off" => Format::Off,
            "ply" => Format::Ply,
            "stl" => Format::Stl,
            "mesh" => Format::Medit,
            _ => return None,
        })
    }
}

/// Read a mesh, choosing the format by extension (`.obj`, `.off`, `.ply`, `.stl`, `.mesh`).
pub fn read_mesh(path: &Path) -> Result<LoadedMesh, IoError> {
    read_mesh_with(path, &ReadOptions::default())
}

/// [`read_mesh`] with options.
pub fn read_mesh_with(path: &Path, options: &ReadOptions) -> Result<LoadedMesh, IoError> {
    let p = path.display().to_string();
    let format =
        Format::from_path(path).ok_or_else(|| IoError::UnsupportedFormat { path: p.clone() })?;
    let bytes = std::fs::read(path).map_err(|error| IoError::Os {
        path: p.clone(),
        error,
    })?;
    read_mesh_bytes_with(&bytes, format, &p, options)
}

/// Read a mesh from bytes in a given format; `path` only names the source in errors.
pub fn read_mesh_bytes(bytes: &[u8], format: Format, path: &str) -> Result<LoadedMesh, IoError> {
    read_mesh_bytes_with(bytes, format, path, &ReadOptions::default())
}

/// [`read_mesh_bytes`] with options.
pub fn read_mesh_bytes_with(
    bytes: &[u8],
    format: Format,
    path: &str,
    options: &ReadOptions,
) -> Result<LoadedMesh, IoError> {
    let mut loaded = read_any(bytes, format, path)?;
    match loaded.repeated_index_faces.first() {
        Some(r) if !options.drop_repeated_indices => Err(IoError::RepeatedVertex {
            path: path.to_string(),
            line: r.line,
            face: r.face,
            vertex: r.vertex,
        }),
        Some(_) => {
            let n = loaded.repeated_index_faces.len();
            loaded.warnings.push(format!(
                "{path}: {n} faces that use a vertex twice left out (repair)"
            ));
            Ok(loaded)
        }
        None => Ok(loaded),
    }
}

fn read_any(bytes: &[u8], format: Format, path: &str) -> Result<LoadedMesh, IoError> {
    match format {
        Format::Obj => obj::read(bytes, path),
        Format::Off => off::read(bytes, path),
        // A byte-order mark before the text formats' magic words (editors on Windows write
        // one); the other formats skip it in `text::as_text`.
        Format::Ply => ply::read(text::strip_bom_before(bytes, b"ply"), path),
        Format::Stl => stl::read(text::strip_bom_before(bytes, b"solid"), path),
        Format::Medit => medit::read(bytes, path),
    }
}

/// Write a mesh atomically, choosing the format by extension.
pub fn write_mesh(path: &Path, mesh: &TriMesh) -> Result<(), IoError> {
    write_mesh_with(
        path,
        mesh,
        &MeshAttributes::default(),
        &WriteOptions::default(),
    )
}

/// Write a mesh with attributes and encoding options, atomically: the bytes go to a temporary
/// file in the target directory, which is renamed over `path` only once complete, so that a
/// failure leaves no partial output. The mesh is validated first ([`TriMesh::validate`]).
/// Several outputs written as one transaction: [`Outputs::mesh`].
///
/// Precision: text formats and binary PLY store `f64` exactly (text uses Rust's shortest
/// round-trip `Display`); binary STL stores `f32` by definition of the format, so each
/// coordinate is rounded to the nearest `f32`.
pub fn write_mesh_with(
    path: &Path,
    mesh: &TriMesh,
    attrs: &MeshAttributes,
    opts: &WriteOptions,
) -> Result<(), IoError> {
    let mut out = Outputs::new();
    out.mesh(path, mesh, attrs, opts)?;
    out.commit()
}

/// The writer of `mesh` in the format of `path`'s extension, after validating the mesh and
/// its attributes.
fn mesh_writer<'a>(
    path: &Path,
    mesh: &'a TriMesh,
    attrs: &'a MeshAttributes,
    opts: &'a WriteOptions,
) -> Result<impl FnOnce(&mut dyn Write) -> std::io::Result<()> + 'a, IoError> {
    let p = path.display().to_string();
    let format =
        Format::from_path(path).ok_or_else(|| IoError::UnsupportedFormat { path: p.clone() })?;
    mesh.validate().map_err(|source| IoError::Mesh {
        path: p.clone(),
        source,
    })?;
    check_attributes(mesh, attrs, &p)?;
    Ok(move |w: &mut dyn Write| match format {
        Format::Obj => obj::write(w, mesh, attrs),
        Format::Off => off::write(w, mesh),
        Format::Ply => ply::write(w, mesh, attrs, opts),
        Format::Stl => stl::write(w, mesh, opts),
        Format::Medit => medit::write(w, mesh, attrs),
    })
}

fn check_attributes(mesh: &TriMesh, attrs: &MeshAttributes, path: &str) -> Result<(), IoError> {
    let bad = |problem: AttributeProblem| IoError::BadAttribute {
        path: path.to_string(),
        problem,
    };
    for (name, vals) in &attrs.face_ints {
        if vals.len() != mesh.n_faces() {
            return Err(bad(AttributeProblem::FacePropertyLength {
                name: name.clone(),
                values: vals.len(),
                faces: mesh.n_faces(),
            }));
        }
        if name.is_empty() || name.contains(char::is_whitespace) {
            return Err(bad(AttributeProblem::FacePropertyName {
                name: name.clone(),
            }));
        }
    }
    if let Some(c) = &attrs.face_colors {
        if c.len() != mesh.n_faces() {
            return Err(bad(AttributeProblem::FaceColors {
                colors: c.len(),
                faces: mesh.n_faces(),
            }));
        }
    }
    if let Some(uv) = &attrs.uv {
        if uv.len() != mesh.n_vertices() {
            return Err(bad(AttributeProblem::UvCount {
                uvs: uv.len(),
                vertices: mesh.n_vertices(),
            }));
        }
        if let Some(v) = uv
            .iter()
            .position(|q| !(q.x.is_finite() && q.y.is_finite()))
        {
            return Err(bad(AttributeProblem::NonFiniteUv {
                vertex: crate::ids::VertexId(v as u32),
            }));
        }
    }
    Ok(())
}

/// Write `bytes` to `path` atomically (temporary file beside it, then rename), e.g. a JSON
/// report: a failure leaves no partial file.
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<(), IoError> {
    let mut out = Outputs::new();
    out.bytes(path, bytes)?;
    out.commit()
}

/// Faces as read from a file, before triangulation: flat 0-based indices, one entry per face
/// with its start offset and its line (0 for binary formats).
#[derive(Default)]
pub(crate) struct RawFaces {
    idx: Vec<i64>,
    start: Vec<usize>,
    line: Vec<usize>,
    /// Index as written (for messages), when it differs from the 0-based one (OBJ, Medit).
    base: i64,
}

impl RawFaces {
    pub(crate) fn with_capacity(faces: usize, base: i64) -> Self {
        RawFaces {
            idx: Vec::with_capacity(faces.saturating_mul(3)),
            start: Vec::with_capacity(faces),
            line: Vec::with_capacity(faces),
            base,
        }
    }
    pub(crate) fn begin(&mut self, line: usize) {
        self.start.push(self.idx.len());
        self.line.push(line);
    }
    pub(crate) fn push(&mut self, i: i64) {
        self.idx.push(i);
    }
    pub(crate) fn len(&self) -> usize {
        self.start.len()
    }
    fn face(&self, f: usize) -> &[i64] {
        let end = self.start.get(f + 1).copied().unwrap_or(self.idx.len());
        &self.idx[self.start[f]..end]
    }
}

/// Check indices, cut polygons into triangles inside them ([`polygon`]) and build the
/// validated [`TriMesh`]. Returns the
/// mesh, the number of polygons triangulated, for each triangle the face it came from, and
/// the faces left out because they use a vertex twice (the caller refuses them unless asked
/// to drop them, [`read_mesh_bytes_with`]).
pub(crate) fn build_mesh(
    path: &str,
    format: &'static str,
    positions: Vec<Point3<f64>>,
    faces: &RawFaces,
) -> Result<Built, IoError> {
    let n = positions.len();
    if faces.len() == 0 {
        return Err(IoError::NoFaces {
            path: path.to_string(),
            format,
        });
    }
    let mut tris: Vec<[usize; 3]> = Vec::with_capacity(faces.len());
    let mut origin = Vec::with_capacity(faces.len());
    let mut polygons = 0;
    let mut repeated = Vec::new();
    for f in 0..faces.len() {
        let poly = faces.face(f);
        let line = faces.line[f];
        if poly.len() < 3 {
            return Err(IoError::Parse {
                path: path.to_string(),
                format,
                line,
                defect: Syntax::FewVertices {
                    face: f,
                    vertices: poly.len(),
                },
            });
        }
        for &i in poly {
            if i < 0 || i as u64 >= n as u64 {
                return Err(IoError::BadIndex {
                    path: path.to_string(),
                    line,
                    face: f,
                    index: i.saturating_add(faces.base),
                    n_vertices: n,
                });
            }
        }
        if let Some(k) = (1..poly.len()).find(|&k| poly[..k].contains(&poly[k])) {
            repeated.push(RepeatedIndexFace {
                face: f,
                line,
                vertex: poly[k] as usize,
            });
            continue;
        }
        if poly.len() > 3 {
            polygons += 1;
        }
        let corners: Vec<usize> = poly.iter().map(|&i| i as usize).collect();
        let cut =
            polygon::triangulate(&positions, &corners).map_err(|problem| IoError::BadPolygon {
                path: path.to_string(),
                line,
                face: f,
                corners: corners.len(),
                problem,
            })?;
        origin.extend(cut.iter().map(|_| f));
        tris.extend(cut);
    }
    // Nothing left to repair when every face repeats a vertex.
    if let (true, Some(r)) = (tris.is_empty(), repeated.first()) {
        return Err(IoError::RepeatedVertex {
            path: path.to_string(),
            line: r.line,
            face: r.face,
            vertex: r.vertex,
        });
    }
    let mesh = TriMesh::from_indices(positions, &tris).map_err(|source| IoError::Mesh {
        path: path.to_string(),
        source,
    })?;
    Ok((mesh, polygons, origin, repeated))
}

/// What [`build_mesh`] returns: mesh, polygons triangulated, source face per triangle, faces
/// left out for a repeated vertex.
pub(crate) type Built = (TriMesh, usize, Vec<usize>, Vec<RepeatedIndexFace>);

/// The number of elements to pre-allocate for a header claiming `claimed` elements of at
/// least `min_bytes` bytes each, when `available` bytes remain: never more than fits.
pub(crate) fn capped(claimed: u64, available: usize, min_bytes: usize) -> usize {
    (claimed.min((available / min_bytes.max(1)) as u64)) as usize
}

/// Refuse a claimed count that a `u32` id cannot name ([`IoError::TooLarge`]) or that the
/// file cannot hold at `min_bytes` per element ([`IoError::Truncated`]), before anything is
/// allocated for it.
pub(crate) fn check_claim(
    path: &str,
    format: &'static str,
    what: &'static str,
    claimed: u64,
    min_bytes: u64,
    file_bytes: usize,
) -> Result<(), IoError> {
    if claimed > u32::MAX as u64 {
        return Err(IoError::TooLarge {
            path: path.to_string(),
            format,
            what,
            claimed,
            file_bytes: file_bytes as u64,
        });
    }
    if claimed.saturating_mul(min_bytes) > file_bytes as u64 {
        return Err(IoError::Truncated {
            path: path.to_string(),
            format,
            missing: Truncation::Claim {
                claimed,
                what,
                file_bytes,
            },
        });
    }
    Ok(())
}

/// Per-vertex uv from per-corner `(vertex, uv)` pairs, when every vertex gets one uv only
/// (vertices no face uses get the origin). `None` when a vertex has two different uvs (a seam
/// that a per-vertex attribute cannot hold).
pub(crate) fn uv_per_vertex(
    n_vertices: usize,
    corners: &[(usize, Point2<f64>)],
) -> Option<Vec<Point2<f64>>> {
    let mut uv: Vec<Option<Point2<f64>>> = vec![None; n_vertices];
    for &(v, t) in corners {
        match uv.get(v)? {
            Some(old) if *old != t => return None,
            _ => uv[v] = Some(t),
        }
    }
    Some(
        uv.into_iter()
            .map(|o| o.unwrap_or(Point2::origin()))
            .collect(),
    )
}

#[cfg(test)]
mod tests;
