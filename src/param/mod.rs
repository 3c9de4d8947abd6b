//! Bijective low-distortion parameterization of a disk patch (Sec. 3.3, ref. \[30\]) and the
//! [`Parameterizer`] extension point.

mod distortion;
mod lscm;
mod registry;
mod sd;
mod sparse;
mod tutte;

pub use distortion::{distortion, triangle_frames, TriangleFrame};
pub use lscm::lscm;
pub use registry::{parameterizer, PARAMETERIZERS};
pub use sd::{
    initial_map, optimize_locally_injective, optimize_with_log, InitialMap, SdLog, SdOptions,
    SdProfile, SymmetricDirichlet,
};
pub use tutte::{circle_boundary, scale_to_area, tutte_embedding, Tutte, TutteWeights};

use crate::ids::{FaceId, VertexId};
use crate::invariants::{DiskDefect, InvariantError, Offenders};
use crate::mesh::{Topology, TriMesh};
use nalgebra::Point2;
use serde::Serialize;
use thiserror::Error;

/// Errors of parameterization.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ParamError {
    /// The mesh arrays are not a mesh.
    #[error("the disk mesh: {0}")]
    Mesh(#[from] crate::mesh::MeshError),
    /// The input is not a topological disk ([`InvariantError::NotADisk`]).
    #[error(transparent)]
    Input(#[from] InvariantError),
    /// Even the initial (Tutte) map could not be certified.
    #[error("no certified map: {0}")]
    NotCertified(#[source] InvariantError),
    /// The map under optimisation flipped a triangle.
    #[error("no certified map: {face} is flipped during optimisation")]
    Flipped {
        /// the flipped triangle
        face: FaceId,
    },
    /// The optimisation's start has a flipped or degenerate triangle (locally injective mode).
    #[error(
        "no certified map: the start has a flipped or degenerate triangle{}",
        face.map_or(String::new(), |f| format!(" ({f})"))
    )]
    FlippedStart {
        /// the first triangle of non-positive area, if one is (else the energy is not finite
        /// for another reason)
        face: Option<FaceId>,
    },
    /// A boundary vertex reached a boundary edge during optimisation.
    #[error("no certified map: boundary vertex {vertex} touches boundary edge {edge}")]
    BoundaryTouch {
        /// the vertex
        vertex: VertexId,
        /// the edge it touches
        edge: crate::ids::EdgeKey,
    },
    /// The linear solver failed.
    #[error("linear solve failed: {system}: {failure}")]
    Solver {
        /// which system
        system: LinearSystem,
        /// which step of it
        failure: SolveFailure,
    },
    /// A solve gave a NaN or infinite position.
    #[error("{system} gave a non-finite position for {vertex}")]
    NonFinite {
        /// which system
        system: LinearSystem,
        /// the vertex
        vertex: VertexId,
    },
    /// Boundary vertices and their positions differ in number.
    #[error("{vertices} boundary vertices but {positions} boundary positions")]
    BoundaryCount {
        /// boundary vertices
        vertices: usize,
        /// positions given
        positions: usize,
    },
    /// LSCM's two pinned vertices are the same (a boundary of coincident points).
    #[error("LSCM: coincident pins at {vertex}")]
    CoincidentPins {
        /// the pinned vertex
        vertex: VertexId,
    },
}

/// The linear systems of parameterization.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize)]
pub enum LinearSystem {
    /// The Tutte Laplacian.
    Tutte,
    /// The LSCM normal equations.
    Lscm,
    /// The Newton Hessian of the symmetric Dirichlet optimisation.
    NewtonHessian,
    /// The 1-ring pattern shared by LSCM and Newton (its symbolic factorisation).
    VertexPattern,
}

impl std::fmt::Display for LinearSystem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LinearSystem::Tutte => "Tutte Laplacian",
            LinearSystem::Lscm => "LSCM",
            LinearSystem::NewtonHessian => "Newton Hessian",
            LinearSystem::VertexPattern => "vertex 1-ring pattern",
        })
    }
}

/// Which step of a sparse solve failed (faer's error kinds).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Error, Serialize)]
pub enum SolveFailure {
    /// The matrix could not be assembled from its triplets.
    #[error("assembling the matrix")]
    Assembly,
    /// The symbolic factorisation failed (out of memory or index overflow).
    #[error("symbolic factorisation")]
    Symbolic,
    /// The Cholesky factorisation met a non-positive pivot.
    #[error("not positive definite (Cholesky)")]
    NotPositiveDefinite,
    /// The LU factorisation failed (a singular matrix).
    #[error("LU factorisation (singular matrix)")]
    Lu,
}

/// Distortion of a 2D map of a 3D disk.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct DistortionReport {
    /// Area-weighted mean symmetric Dirichlet energy (4 for an isometry).
    pub symmetric_dirichlet: f64,
    /// Largest singular-value ratio σ1/σ2 over triangles (1 = conformal).
    pub max_conformal: f64,
    /// Area-weighted mean σ1/σ2.
    pub mean_conformal: f64,
    /// Largest |log(σ1·σ2)| (0 = area preserving).
    pub max_area_distortion: f64,
    /// Optimisation iterations taken.
    pub iterations: usize,
    /// The iteration budget ran out before the stopping rule was met.
    pub hit_budget: bool,
    /// The optimiser fell back to the last certified iterate (see `certify_bijective`).
    pub fell_back: bool,
}

/// A certified parameterization: `uv[v]` for every vertex of the disk mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameterization {
    /// Positions in the plane; the boundary loop is counter-clockwise.
    pub uv: Vec<Point2<f64>>,
    /// Distortion of the returned map.
    pub report: DistortionReport,
}

/// The research extension point of Sec. 3.3: map a disk mesh bijectively to the plane.
///
/// `disk` is a single topological disk (local vertex ids), `boundary` its boundary loop
/// with the surface on the left. The result must pass `invariants::certify_bijective`.
pub trait Parameterizer: Send + Sync {
    /// Short name used in reports.
    fn name(&self) -> &'static str;
    /// Compute the map.
    fn parameterize(
        &self,
        disk: &TriMesh,
        boundary: &[VertexId],
    ) -> Result<Parameterization, ParamError>;
}

/// Check that `disk` is a topological disk whose single boundary loop is `boundary` (up to
/// the starting vertex): an oriented manifold, one component, V − E + F = 1, every vertex
/// referenced. Errors name the offending count or vertex.
pub fn validate_disk(disk: &TriMesh, boundary: &[VertexId]) -> Result<(), ParamError> {
    let bad = |d: DiskDefect| Err(ParamError::Input(InvariantError::NotADisk(d)));
    disk.validate()?;
    if let Some(v) = disk.unreferenced_vertices().first() {
        return bad(DiskDefect::UnreferencedVertex(*v));
    }
    let topo = Topology::build(disk);
    if let Some((e, k)) = topo.non_manifold_edges().first() {
        return bad(DiskDefect::NonManifoldEdge {
            edge: *e,
            faces: *k,
        });
    }
    if let Some(e) = topo.inconsistent_edges().first() {
        return bad(DiskDefect::InconsistentEdge {
            edge: *e,
            faces: None,
        });
    }
    if let Some(v) = topo.non_manifold_vertices().first() {
        return bad(DiskDefect::Pinch {
            vertex: *v,
            fans: None,
        });
    }
    if topo.components().len() != 1 {
        return bad(DiskDefect::Disconnected {
            components: topo.components().len(),
            faces: None,
        });
    }
    if topo.euler_characteristic() != 1 {
        return bad(DiskDefect::euler(
            disk.n_vertices(),
            topo.edges().len(),
            disk.n_faces(),
        ));
    }
    let loops = topo.boundary_loops();
    if loops.len() != 1 {
        return bad(boundary_loops(loops));
    }
    let l = &loops[0];
    let start = boundary
        .first()
        .and_then(|b0| l.iter().position(|v| v == b0));
    let matches = l.len() == boundary.len()
        && start.is_some_and(|s| (0..l.len()).all(|i| l[(s + i) % l.len()] == boundary[i]));
    if !matches {
        return bad(DiskDefect::BoundaryMismatch {
            given: boundary.len(),
            start: boundary.first().copied(),
            actual: l.len(),
        });
    }
    Ok(())
}

/// The defect of a mesh with `loops` boundary loops (not 1), naming each loop's first vertex.
fn boundary_loops(loops: &[Vec<VertexId>]) -> DiskDefect {
    DiskDefect::BoundaryLoops {
        loops: loops.len(),
        starts: Offenders(loops.iter().filter_map(|l| l.first().copied()).collect()),
    }
}

/// The boundary loop of a disk mesh (surface on the left), after [`validate_disk`]-style
/// checks of the topology.
pub fn disk_boundary(disk: &TriMesh) -> Result<Vec<VertexId>, ParamError> {
    let topo = Topology::build(disk);
    let b = match topo.boundary_loops() {
        [l] => l.clone(),
        ls => return Err(InvariantError::NotADisk(boundary_loops(ls)).into()),
    };
    validate_disk(disk, &b)?;
    Ok(b)
}

/// Certify a new map of a disk whose triangles and boundary loop `certify` has already
/// accepted once (positions only: orientation, simple CCW boundary).
pub(crate) fn recertify(
    disk: &TriMesh,
    uv: &[Point2<f64>],
    boundary: &[VertexId],
) -> Result<(), ParamError> {
    crate::invariants::certify_map_of_known_disk(uv, &disk.triangles, boundary)
        .map_err(ParamError::NotCertified)
}

/// Certify a map and turn a failure into [`ParamError::NotCertified`].
pub(crate) fn certify(
    disk: &TriMesh,
    uv: &[Point2<f64>],
    boundary: &[VertexId],
) -> Result<(), ParamError> {
    crate::invariants::certify_bijective(uv, &disk.triangles, boundary)
        .map_err(ParamError::NotCertified)
}
