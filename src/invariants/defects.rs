//! The defects of the bijectivity, planar, boundary-curve and topology certificates, with the
//! offending elements and counts as data (like [`super::DiskDefect`] for disks).

use super::Offenders;
use crate::ids::{FaceId, VertexId};
use serde::Serialize;
use std::fmt;
use thiserror::Error;

/// A directed edge `a → b`, printed `(v3, v9)` (an [`crate::ids::EdgeKey`] is undirected).
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct DirectedEdge(pub VertexId, pub VertexId);

impl fmt::Display for DirectedEdge {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}, {})", self.0, self.1)
    }
}

/// A vertex of a planar remesher's input domain, printed `input v3`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize)]
pub struct InputVertex(pub VertexId);

impl fmt::Display for InputVertex {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "input {}", self.0)
    }
}

/// Why a 2D map of a disk is not bijective ([`super::InvariantError::NotBijective`]).
#[derive(Debug, Error, Clone, PartialEq, Serialize)]
pub enum MapDefect {
    /// A triangle with a vertex past the end of the positions.
    #[error(
        "triangle {triangle:?} references a vertex without a uv position ({positions} positions)"
    )]
    TriangleWithoutUv {
        /// the triangle
        triangle: [VertexId; 3],
        /// the number of positions
        positions: usize,
    },
    /// A boundary vertex past the end of the positions.
    #[error("boundary vertex {vertex} has no uv position ({positions} positions)")]
    BoundaryWithoutUv {
        /// the vertex
        vertex: VertexId,
        /// the number of positions
        positions: usize,
    },
    /// A vertex whose position is NaN or infinite.
    #[error("{0} has a non-finite uv position")]
    NonFiniteAt(VertexId),
    /// Some position is NaN or infinite (the line search's check, which does not look for
    /// which).
    #[error("a uv position is not finite")]
    NonFinite,
    /// Triangles that are not strictly counter-clockwise.
    #[error("non-positive (flipped or degenerate) triangles: {0}")]
    NonPositive(Offenders<FaceId>),
    /// A boundary loop of fewer than 3 vertices.
    #[error("boundary loop has {0} vertices (need at least 3)")]
    ShortLoop(usize),
    /// A boundary loop through a vertex twice.
    #[error("boundary loop visits {0} twice")]
    LoopRevisits(VertexId),
    /// A loop edge that is not a boundary half-edge of the triangles.
    #[error("boundary edge {0} is not a boundary half-edge of the triangles")]
    NotABoundaryEdge(DirectedEdge),
    /// The triangles have another number of boundary edges than the loop.
    #[error("the triangles have {triangles} boundary edges, the loop has {loop_edges}")]
    BoundaryEdgeCount {
        /// boundary half-edges of the triangles
        triangles: usize,
        /// edges of the loop
        loop_edges: usize,
    },
    /// Boundary edges that meet other than at a shared vertex (or fold back).
    #[error("boundary polygon is not simple, boundary edges meet: {0}")]
    NotSimple(Offenders<super::EdgePair>),
    /// The loop turns clockwise at its lowest vertex.
    #[error("boundary loop is not counter-clockwise (turn at {0} is clockwise)")]
    Clockwise(VertexId),
}

impl MapDefect {
    /// The vertices the defect names.
    pub fn vertices(&self) -> Vec<VertexId> {
        use MapDefect as M;
        match self {
            M::TriangleWithoutUv { triangle, .. } => triangle.to_vec(),
            M::BoundaryWithoutUv { vertex: v, .. }
            | M::NonFiniteAt(v)
            | M::LoopRevisits(v)
            | M::Clockwise(v) => vec![*v],
            _ => Vec::new(),
        }
    }

    /// The faces the defect names.
    pub fn faces(&self) -> Vec<FaceId> {
        match self {
            MapDefect::NonPositive(o) => o.0.clone(),
            _ => Vec::new(),
        }
    }

    /// The edges the defect names, as (from, to).
    pub fn edges(&self) -> Vec<(VertexId, VertexId)> {
        match self {
            MapDefect::NotABoundaryEdge(e) => vec![(e.0, e.1)],
            MapDefect::NotSimple(o) => {
                o.0.iter()
                    .flat_map(|p| [(p.0[0], p.0[1]), (p.1[0], p.1[1])])
                    .collect()
            }
            _ => Vec::new(),
        }
    }
}

/// How a planar remesher's output breaks its contract ([`super::InvariantError::PlanarInvalid`]).
/// Vertices and faces are the output's, unless named `input`.
#[derive(Debug, Error, Clone, PartialEq, Serialize)]
pub enum PlanarDefect {
    /// `origin` has another length than `points`.
    #[error("{points} points but {origins} origin entries")]
    OriginCount {
        /// points
        points: usize,
        /// origin entries
        origins: usize,
    },
    /// A point that is NaN or infinite.
    #[error("point {0} is not finite")]
    NonFinitePoint(VertexId),
    /// A triangle with a vertex past the end of the points.
    #[error("triangle {0} has an out-of-range vertex")]
    VertexOutOfRange(FaceId),
    /// Triangles that are not strictly counter-clockwise.
    #[error("non-positive triangles: {0}")]
    NonPositive(Offenders<FaceId>),
    /// An origin that is not an input vertex.
    #[error("{vertex} has origin {origin}, not an input vertex")]
    UnknownOrigin {
        /// the output vertex
        vertex: VertexId,
        /// its origin
        origin: VertexId,
    },
    /// A kept vertex not at its input position, bit for bit.
    #[error(
        "{vertex} (input {input}) moved: ({}, {}) instead of ({}, {})",
        at[0],
        at[1],
        expected[0],
        expected[1]
    )]
    Moved {
        /// the output vertex
        vertex: VertexId,
        /// its input vertex
        input: VertexId,
        /// where it is
        at: [f64; 2],
        /// where the input vertex is
        expected: [f64; 2],
    },
    /// An input vertex kept twice.
    #[error("input {0} appears twice in the output")]
    InputTwice(VertexId),
    /// Boundary or constrained vertices of the input that are not output vertices.
    #[error("boundary/constrained vertices missing: {0}")]
    KeptMissing(Offenders<InputVertex>),
    /// A half-edge of two triangles.
    #[error("half-edge {edge} used twice ({face}): non-manifold or inconsistent")]
    HalfEdgeTwice {
        /// the half-edge
        edge: DirectedEdge,
        /// the second triangle using it
        face: FaceId,
    },
    /// An input boundary edge whose image is not a boundary edge of the output.
    #[error("input boundary edge {input} is not a boundary edge {output} of the output")]
    BoundaryEdgeLost {
        /// the input edge
        input: DirectedEdge,
        /// its image
        output: DirectedEdge,
    },
    /// The output has boundary edges that are not images of the input's loop.
    #[error("output has {output} boundary edges, input loop has {input}; extra: {extra}")]
    ExtraBoundaryEdges {
        /// boundary edges of the output
        output: usize,
        /// edges of the input loop
        input: usize,
        /// the output's boundary edges that are not images
        extra: Offenders<DirectedEdge>,
    },
    /// A constrained edge that is not an output edge.
    #[error("constrained edge {input} missing (output {}, {})", output.0, output.1)]
    ConstrainedEdgeMissing {
        /// the input edge
        input: DirectedEdge,
        /// its image
        output: DirectedEdge,
    },
    /// A point no triangle uses.
    #[error("{0} is not used by any triangle")]
    UnusedVertex(VertexId),
    /// The triangles' total area is not the polygon's (relative 1e-9).
    #[error("total area {area} differs from the polygon's {polygon}")]
    Area {
        /// the triangles' area
        area: f64,
        /// the polygon's area
        polygon: f64,
    },
    /// Vertices off the boundary that are not strictly inside the polygon.
    #[error("interior vertices not strictly inside the polygon: {0}")]
    Outside(Offenders<VertexId>),
}

impl PlanarDefect {
    /// The output vertices the defect names (input vertices: [`PlanarDefect::input_vertices`]).
    pub fn vertices(&self) -> Vec<VertexId> {
        use PlanarDefect as P;
        match self {
            P::NonFinitePoint(v) | P::UnusedVertex(v) => vec![*v],
            P::UnknownOrigin { vertex, .. } | P::Moved { vertex, .. } => vec![*vertex],
            P::Outside(o) => o.0.clone(),
            _ => Vec::new(),
        }
    }

    /// The input vertices the defect names.
    pub fn input_vertices(&self) -> Vec<VertexId> {
        use PlanarDefect as P;
        match self {
            P::Moved { input, .. } | P::InputTwice(input) => vec![*input],
            P::KeptMissing(o) => o.0.iter().map(|v| v.0).collect(),
            P::BoundaryEdgeLost { input, .. } | P::ConstrainedEdgeMissing { input, .. } => {
                vec![input.0, input.1]
            }
            _ => Vec::new(),
        }
    }

    /// The output faces the defect names.
    pub fn faces(&self) -> Vec<FaceId> {
        use PlanarDefect as P;
        match self {
            P::VertexOutOfRange(f) | P::HalfEdgeTwice { face: f, .. } => vec![*f],
            P::NonPositive(o) => o.0.clone(),
            _ => Vec::new(),
        }
    }

    /// The output edges the defect names, as (from, to).
    pub fn edges(&self) -> Vec<(VertexId, VertexId)> {
        use PlanarDefect as P;
        match self {
            P::HalfEdgeTwice { edge: e, .. }
            | P::BoundaryEdgeLost { output: e, .. }
            | P::ConstrainedEdgeMissing { output: e, .. } => vec![(e.0, e.1)],
            P::ExtraBoundaryEdges { extra, .. } => extra.0.iter().map(|e| (e.0, e.1)).collect(),
            _ => Vec::new(),
        }
    }
}

/// How an output's boundary loops fail to follow the input's boundary curves
/// ([`super::InvariantError::BoundaryCurves`]); curves are numbered as in
/// [`crate::boundary::BoundaryCurves`].
#[derive(Debug, Error, Clone, PartialEq, Serialize)]
pub enum CurvesDefect {
    /// Another number of loops than curves.
    #[error("{loops} boundary loops for {curves} input boundary curves")]
    LoopCount {
        /// loops of the output
        loops: usize,
        /// curves of the input
        curves: usize,
    },
    /// One loop on two curves.
    #[error("the loop through {first} and {other} lies on two curves ({} and {})", curves.0, curves.1)]
    TwoCurves {
        /// the loop's first vertex, on the first curve
        first: VertexId,
        /// its first vertex on another curve
        other: VertexId,
        /// the two curves
        curves: (u32, u32),
    },
    /// Two loops on one curve.
    #[error("two loops lie on curve {curve} (one through {through})")]
    SharedCurve {
        /// the curve
        curve: u32,
        /// the first vertex of the second loop on it
        through: VertexId,
    },
    /// A loop that does not go once around its curve in the curve's direction.
    #[error(
        "the loop through {at} does not go once around curve {curve} in its direction ({backward} backward steps among {vertices} vertices)"
    )]
    NotOnceAround {
        /// a vertex where the loop steps backward (or its first vertex)
        at: VertexId,
        /// the curve
        curve: u32,
        /// backward steps
        backward: usize,
        /// vertices of the loop
        vertices: usize,
    },
}

impl CurvesDefect {
    /// The vertices the defect names.
    pub fn vertices(&self) -> Vec<VertexId> {
        match self {
            CurvesDefect::LoopCount { .. } => Vec::new(),
            CurvesDefect::TwoCurves { first, other, .. } => vec![*first, *other],
            CurvesDefect::SharedCurve { through: v, .. }
            | CurvesDefect::NotOnceAround { at: v, .. } => vec![*v],
        }
    }
}

/// Each component's (genus, boundary loops), sorted; printed
/// `[(genus 0, 2 loops), (genus ?, 1 loops)]`, `?` for a genus that is not a non-negative
/// integer.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ComponentTopologies(pub Vec<(Option<u32>, usize)>);

impl fmt::Display for ComponentTopologies {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[")?;
        for (i, (g, b)) in self.0.iter().enumerate() {
            if i > 0 {
                write!(f, ", ")?;
            }
            match g {
                Some(g) => write!(f, "(genus {g}, {b} loops)")?,
                None => write!(f, "(genus ?, {b} loops)")?,
            }
        }
        write!(f, "]")
    }
}

/// The first difference of two topologies ([`super::InvariantError::TopologyChanged`]).
#[derive(Debug, Error, Clone, PartialEq, Serialize)]
pub enum TopologyChange {
    /// The number of connected components.
    #[error("components was {before}, is {after}")]
    Components {
        /// before
        before: usize,
        /// after
        after: usize,
    },
    /// The number of boundary loops.
    #[error("boundary loops was {before}, is {after}")]
    BoundaryLoops {
        /// before
        before: usize,
        /// after
        after: usize,
    },
    /// The per-component (genus, boundary loops), with the same counts.
    #[error("per-component genus and boundary loops was {before}, is {after}")]
    PerComponent {
        /// before
        before: ComponentTopologies,
        /// after
        after: ComponentTopologies,
    },
}
