//! [`DiskDefect`]: why a face set is not a topological disk, the one vocabulary of the
//! patch certificate (`certify_disk`), the parameterizers' input check
//! (`param::validate_disk`) and the planar output's certificate (`certify_planar`).

use super::Offenders;
use crate::ids::{EdgeKey, FaceId, VertexId};
use serde::Serialize;
use thiserror::Error;

/// What makes a face set not a topological disk, with the offending elements and counts as
/// data. A connected, oriented, manifold surface with one boundary loop and Euler
/// characteristic 1 is a disk (χ = 2 − 2g − b).
#[derive(Debug, Error, Clone, PartialEq, Serialize)]
pub enum DiskDefect {
    /// The face set is empty.
    #[error("no faces")]
    NoFaces,
    /// A face is listed more than once.
    #[error("face {0} listed twice")]
    RepeatedFace(FaceId),
    /// A face id past the end of the mesh.
    #[error("face {face} does not exist (mesh has {faces} faces)")]
    FaceOutOfRange {
        /// the face
        face: FaceId,
        /// the mesh's face count
        faces: usize,
    },
    /// A vertex id past the end of the mesh (in a boundary loop handed in).
    #[error("boundary vertex {vertex} out of range (mesh has {vertices} vertices)")]
    VertexOutOfRange {
        /// the vertex
        vertex: VertexId,
        /// the mesh's vertex count
        vertices: usize,
    },
    /// A vertex no triangle references.
    #[error("{0} is referenced by no triangle")]
    UnreferencedVertex(VertexId),
    /// An edge with more than two faces.
    #[error("edge {edge} has {faces} faces (non-manifold)")]
    NonManifoldEdge {
        /// the edge
        edge: EdgeKey,
        /// its face count
        faces: usize,
    },
    /// An edge whose two faces traverse it in the same direction (the faces, when known).
    #[error("edge {edge}: its two faces{} are oriented inconsistently", face_pair(.faces))]
    InconsistentEdge {
        /// the edge
        edge: EdgeKey,
        /// its two faces, when the check names them
        faces: Option<(FaceId, FaceId)>,
    },
    /// A vertex whose faces form more than one fan (`fans` of them, when counted).
    #[error("vertex {vertex} is a pinch: its faces form {} fans", fan_count(.fans))]
    Pinch {
        /// the vertex
        vertex: VertexId,
        /// its fans, when counted
        fans: Option<usize>,
    },
    /// More than one connected component (two faces of different components, when named).
    #[error("not connected: {components} components{}", unjoined(.faces))]
    Disconnected {
        /// the component count
        components: usize,
        /// two faces not joined through edges, when the check names them
        faces: Option<(FaceId, FaceId)>,
    },
    /// No boundary at all: the faces form a closed surface.
    #[error("no boundary: the {faces} faces form a closed surface")]
    Closed {
        /// the face count
        faces: usize,
    },
    /// A boundary half-edge chain that does not close.
    #[error("boundary is open at vertex {0}")]
    OpenBoundary(VertexId),
    /// A boundary chain through the same vertex twice.
    #[error("boundary revisits vertex {0}")]
    BoundaryRevisits(VertexId),
    /// Not exactly one boundary loop (the first vertex of each, when listed).
    #[error("{loops} boundary loops (need 1){}", through(.starts))]
    BoundaryLoops {
        /// the loop count
        loops: usize,
        /// the first vertex of each loop, when listed
        starts: Offenders<VertexId>,
    },
    /// A boundary loop handed in too short to bound a triangle.
    #[error("boundary of {0} vertices (need at least 3)")]
    ShortBoundary(usize),
    /// The boundary loop handed in is not the mesh's boundary loop.
    #[error(
        "the given boundary ({given} vertices, starting at {}) is not the mesh's boundary loop \
         ({actual} vertices, surface on the left)",
        start.map_or("nothing".to_string(), |v| v.to_string())
    )]
    BoundaryMismatch {
        /// vertices of the given loop
        given: usize,
        /// its first vertex
        start: Option<VertexId>,
        /// vertices of the mesh's loop
        actual: usize,
    },
    /// The Euler characteristic V − E + F is not 1.
    #[error("Euler characteristic V − E + F = {vertices} − {edges} + {faces} = {chi}, not 1")]
    EulerCharacteristic {
        /// V
        vertices: usize,
        /// E
        edges: usize,
        /// F
        faces: usize,
        /// V − E + F
        chi: i64,
    },
}

impl DiskDefect {
    /// The defect for counts `vertices`, `edges`, `faces` (whose V − E + F is not 1).
    pub fn euler(vertices: usize, edges: usize, faces: usize) -> DiskDefect {
        DiskDefect::EulerCharacteristic {
            vertices,
            edges,
            faces,
            chi: vertices as i64 - edges as i64 + faces as i64,
        }
    }

    /// The vertices the defect names.
    pub fn vertices(&self) -> Vec<VertexId> {
        use DiskDefect as D;
        match self {
            D::VertexOutOfRange { vertex, .. } | D::Pinch { vertex, .. } => vec![*vertex],
            D::UnreferencedVertex(v) | D::OpenBoundary(v) | D::BoundaryRevisits(v) => vec![*v],
            D::BoundaryLoops { starts, .. } => starts.0.clone(),
            D::BoundaryMismatch { start, .. } => start.iter().copied().collect(),
            _ => Vec::new(),
        }
    }

    /// The faces the defect names.
    pub fn faces(&self) -> Vec<FaceId> {
        use DiskDefect as D;
        match self {
            D::RepeatedFace(f) | D::FaceOutOfRange { face: f, .. } => vec![*f],
            D::InconsistentEdge {
                faces: Some((a, b)),
                ..
            }
            | D::Disconnected {
                faces: Some((a, b)),
                ..
            } => vec![*a, *b],
            _ => Vec::new(),
        }
    }

    /// The edges the defect names.
    pub fn edges(&self) -> Vec<EdgeKey> {
        match self {
            DiskDefect::NonManifoldEdge { edge, .. }
            | DiskDefect::InconsistentEdge { edge, .. } => {
                vec![*edge]
            }
            _ => Vec::new(),
        }
    }
}

fn face_pair(faces: &Option<(FaceId, FaceId)>) -> String {
    faces.map_or(String::new(), |(a, b)| format!(" {a} and {b}"))
}

fn fan_count(fans: &Option<usize>) -> String {
    fans.map_or("several separate".to_string(), |n| format!("{n} separate"))
}

fn unjoined(faces: &Option<(FaceId, FaceId)>) -> String {
    faces.map_or(String::new(), |(a, b)| {
        format!(" (faces {a} and {b} are not joined through edges)")
    })
}

fn through(starts: &Offenders<VertexId>) -> String {
    match starts.0.is_empty() {
        true => String::new(),
        false => format!(" (through vertices {starts})"),
    }
}
