//! Planar triangulations: the domain a planar remesher receives (a parameterized patch) and
//! the mesh it returns. They live here, beside [`super::TriMesh`], because both the
//! remeshers ([`crate::remesh2d`]) and their certificate ([`crate::invariants::certify_planar`])
//! use them.

use nalgebra::Point2;

/// The input of a planar remesher: a positively oriented triangulation of a simple polygon.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarDomain {
    /// Vertex positions.
    pub points: Vec<Point2<f64>>,
    /// Counter-clockwise triangles.
    pub triangles: Vec<[u32; 3]>,
    /// The boundary loop (counter-clockwise); these vertices and the edges between
    /// consecutive ones are kept exactly.
    pub boundary: Vec<u32>,
    /// Interior edges that must also be kept (mesh boundary or feature lines).
    pub constrained_edges: Vec<[u32; 2]>,
}

/// The output of a planar remesher.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarMesh {
    /// Vertex positions.
    pub points: Vec<Point2<f64>>,
    /// Counter-clockwise triangles.
    pub triangles: Vec<[u32; 3]>,
    /// For each output vertex, the input vertex it is (bit-identical position), if any.
    /// Every boundary and constrained vertex of the input appears here.
    pub origin: Vec<Option<u32>>,
}
