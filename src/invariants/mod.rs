//! Certified invariants (`certify_*`), checked after every stage in every run, cheap
//! enough to leave on. Each returns the offending elements by id in its error.
//!
//! One file per family: `mesh.rs` (manifold, oriented, degenerate, self-intersections,
//! topology and boundary kept), `flips.rs` (faces flipped against a reference surface),
//! `candidate.rs` (a change to the working mesh before it is made: lifted patches, flips,
//! moves), `disk.rs` (patches), `bijective.rs` (parameterizations), `planar.rs` (2D
//! remeshing).

pub mod mesh;
pub mod pairs;

pub use mesh::{
    boundary_edges, certify_boundary_kept, certify_boundary_preserved, certify_manifold,
    certify_manifold_at, certify_no_degenerate_faces, certify_no_self_intersections,
    certify_oriented, certify_same_topology, degenerate_faces, faces_intersect, is_degenerate,
    non_manifold_vertices, non_manifold_vertices_among, self_intersections, TopologySignature,
};

use crate::ids::{EdgeKey, FaceId, VertexId};
use serde::Serialize;
use std::fmt;
use thiserror::Error;

/// Elements named in an invariant failure; prints the first ten and the count of the rest.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Offenders<T>(pub Vec<T>);

impl<T: fmt::Display> fmt::Display for Offenders<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, x) in self.0.iter().take(10).enumerate() {
            if i > 0 {
                write!(f, ", ")?;
            }
            write!(f, "{x}")?;
        }
        if self.0.len() > 10 {
            write!(f, " … and {} more", self.0.len() - 10)?;
        }
        Ok(())
    }
}

/// A pair of faces, printed `f3×f9`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct FacePair(pub FaceId, pub FaceId);

impl fmt::Display for FacePair {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}×{}", self.0, self.1)
    }
}

/// An edge with its face count, printed `(v3, v9) has 3 faces`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize)]
pub struct EdgeFaces(pub EdgeKey, pub usize);

impl fmt::Display for EdgeFaces {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} has {} faces", self.0, self.1)
    }
}

/// The shared vocabulary of invariant failures (CGAL habit).
#[derive(Debug, Error, Clone, PartialEq, Serialize)]
pub enum InvariantError {
    /// Edges with three or more faces.
    #[error("non-manifold edges: {0}")]
    NonManifoldEdges(Offenders<EdgeFaces>),
    /// Vertices whose faces form more than one fan.
    #[error("non-manifold vertices: {0}")]
    NonManifoldVertices(Offenders<VertexId>),
    /// Edges whose two faces traverse them in the same direction.
    #[error("inconsistent orientation across edges: {0}")]
    InconsistentOrientation(Offenders<EdgeKey>),
    /// Faces of exactly zero area (collinear corners, exact test).
    #[error("degenerate (zero-area) faces: {0}")]
    DegenerateFaces(Offenders<FaceId>),
    /// Pairs of faces that intersect other than in their shared elements.
    #[error("self-intersecting face pairs: {0}")]
    SelfIntersections(Offenders<FacePair>),
    /// Genus, component count or boundary-loop count changed.
    #[error("topology changed: {0}")]
    TopologyChanged(TopologyChange),
    /// Input boundary vertices that moved or vanished.
    #[error("boundary vertices not preserved: {0}")]
    BoundaryVerticesMoved(Offenders<VertexId>),
    /// Input boundary edges that vanished.
    #[error("boundary edges not preserved: {0}")]
    BoundaryEdgesMissing(Offenders<EdgeKey>),
    /// Boundary vertices that are not on the input's boundary curves (no curve point, or
    /// not exactly at it).
    #[error("boundary vertices not on the input's boundary curves: {0}")]
    BoundaryOffCurve(Offenders<VertexId>),
    /// Boundary loops that do not go once around the input's curves.
    #[error("boundary curves not followed: {0}")]
    BoundaryCurves(CurvesDefect),
    /// Corners of the input's boundary curves that are not output vertices.
    #[error("boundary corners lost (input vertices): {0}")]
    BoundaryCornersLost(Offenders<VertexId>),
    /// A face set (a patch, a disk handed to a parameterizer, a planar output) that is not a
    /// topological disk.
    #[error("not a disk: {0}")]
    NotADisk(DiskDefect),
    /// A 2D map with non-positive triangles or a self-touching boundary.
    #[error("map is not bijective: {0}")]
    NotBijective(MapDefect),
    /// Faces whose normal is more than 90° from the reference surface's normal.
    #[error("flipped faces relative to the reference surface: {0}")]
    FlippedFaces(Offenders<FaceId>),
    /// A planar remeshing result that broke its contract (boundary, area, orientation).
    #[error("planar mesh invalid: {0}")]
    PlanarInvalid(PlanarDefect),
}

mod disk;
pub use disk::*;
mod disk_defect;
pub use disk_defect::DiskDefect;
mod defects;
pub use defects::{
    ComponentTopologies, CurvesDefect, DirectedEdge, InputVertex, MapDefect, PlanarDefect,
    TopologyChange,
};
mod bijective;
pub use bijective::*;

mod planar;
pub use planar::*;

mod flips;
pub use flips::FlipTest;

mod candidate;
pub use candidate::*;

mod curves;
pub use curves::certify_boundary_on_curves;
