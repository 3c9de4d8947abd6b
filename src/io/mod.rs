//! Mesh file formats: OBJ, OFF, PLY, STL, Medit `.mesh` (one file per format, reader and
//! writer). Writers are atomic: a failure leaves no partial output file.
//!
//! The API below is the contract other modules build on; the format files implement it.

pub mod sol;

use crate::mesh::TriMesh;
use nalgebra::Point2;
use std::path::Path;
use thiserror::Error;

/// Errors of reading and writing mesh files.
#[derive(Debug, Error)]
pub enum IoError {
    /// Operating-system error on a path.
    #[error("{path}: {source}")]
    Os {
        /// the file
        path: String,
        /// the OS error
        source: std::io::Error,
    },
    /// The file extension names no supported format.
    #[error("{path}: unsupported format (expected .obj, .off, .ply, .stl or .mesh)")]
    UnsupportedFormat {
        /// the file
        path: String,
    },
}

/// A mesh read from a file, with what the reader had to fix or skip.
#[derive(Clone, Debug)]
pub struct LoadedMesh {
    /// The triangles and positions as read (unreferenced vertices kept).
    pub mesh: TriMesh,
    /// Polygon faces with more than three corners that were fan-triangulated.
    pub polygons_triangulated: usize,
    /// Vertices merged because they had bit-identical positions (STL).
    pub welded_vertices: usize,
    /// Human-readable warnings (one line each).
    pub warnings: Vec<String>,
}

/// Optional per-element data to write with a mesh (formats that cannot hold an attribute
/// ignore it; PLY holds face properties and colours, OBJ holds `vt`).
#[derive(Clone, Debug, Default)]
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

/// Read a mesh, choosing the format by extension (`.obj`, `.off`, `.ply`, `.stl`, `.mesh`).
pub fn read_mesh(path: &Path) -> Result<LoadedMesh, IoError> {
    Err(IoError::UnsupportedFormat {
        path: path.display().to_string(),
    })
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

/// Write a mesh with attributes and encoding options, atomically.
pub fn write_mesh_with(
    path: &Path,
    _mesh: &TriMesh,
    _attrs: &MeshAttributes,
    _opts: &WriteOptions,
) -> Result<(), IoError> {
    Err(IoError::UnsupportedFormat {
        path: path.display().to_string(),
    })
}
