//! Bijective low-distortion parameterization of a disk patch (Sec. 3.3, ref. [30]) and the
//! [`Parameterizer`] extension point.

use crate::ids::VertexId;
use crate::mesh::TriMesh;
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
