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

use crate::ids::VertexId;
use crate::mesh::{Topology, TriMesh};
use nalgebra::Point2;
use serde::Serialize;
use thiserror::Error;

/// Errors of parameterization.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ParamError {
    /// The input is not a topological disk.
    #[error("not a disk: {0}")]
    NotADisk(String),
    /// Even the initial (Tutte) map could not be certified.
    #[error("no certified map: {0}")]
    NotCertified(String),
    /// The linear solver failed.
    #[error("linear solve failed: {0}")]
    Solver(String),
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
    let bad = |s: String| Err(ParamError::NotADisk(s));
    if let Err(e) = disk.validate() {
        return bad(e.to_string());
    }
    if let Some(v) = disk.unreferenced_vertices().first() {
        return bad(format!("{v} is referenced by no triangle"));
    }
    let topo = Topology::build(disk);
    if let Some((e, k)) = topo.non_manifold_edges().first() {
        return bad(format!("edge {e} has {k} faces"));
    }
    if let Some(e) = topo.inconsistent_edges().first() {
        return bad(format!("faces on edge {e} are inconsistently oriented"));
    }
    if let Some(v) = topo.non_manifold_vertices().first() {
        return bad(format!("vertex {v} is non-manifold"));
    }
    if topo.components().len() != 1 {
        return bad(format!("{} components (need 1)", topo.components().len()));
    }
    let chi = topo.euler_characteristic();
    if chi != 1 {
        return bad(format!("Euler characteristic V − E + F = {chi} (need 1)"));
    }
    let loops = topo.boundary_loops();
    if loops.len() != 1 {
        return bad(format!("{} boundary loops (need 1)", loops.len()));
    }
    let l = &loops[0];
    let start = boundary
        .first()
        .and_then(|b0| l.iter().position(|v| v == b0));
    let matches = l.len() == boundary.len()
        && start.is_some_and(|s| (0..l.len()).all(|i| l[(s + i) % l.len()] == boundary[i]));
    if !matches {
        return bad(format!(
            "the given boundary ({} vertices, starting at {}) is not the mesh's boundary loop \
             ({} vertices, surface on the left)",
            boundary.len(),
            boundary
                .first()
                .map_or("nothing".to_string(), |v| v.to_string()),
            l.len()
        ));
    }
    Ok(())
}

/// The boundary loop of a disk mesh (surface on the left), after [`validate_disk`]-style
/// checks of the topology.
pub fn disk_boundary(disk: &TriMesh) -> Result<Vec<VertexId>, ParamError> {
    let topo = Topology::build(disk);
    let b = match topo.boundary_loops() {
        [l] => l.clone(),
        ls => {
            return Err(ParamError::NotADisk(format!(
                "{} boundary loops (need 1)",
                ls.len()
            )))
        }
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
        .map_err(|e| ParamError::NotCertified(e.to_string()))
}

/// Certify a map and turn a failure into [`ParamError::NotCertified`].
pub(crate) fn certify(
    disk: &TriMesh,
    uv: &[Point2<f64>],
    boundary: &[VertexId],
) -> Result<(), ParamError> {
    crate::invariants::certify_bijective(uv, &disk.triangles, boundary)
        .map_err(|e| ParamError::NotCertified(e.to_string()))
}
