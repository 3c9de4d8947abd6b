//! Planar anisotropic remeshing (Sec. 3.3): metric transfer (Eq. 4), the LCT remesher
//! (ref. \[5\]) and the [`PlanarRemesher`] extension point.

mod demo;
mod domain;
mod field;
mod lct;
mod registry;
pub(crate) mod stats;
mod transfer;

pub use demo::{demo_cases, run_demo_case, DemoDomain, DemoMetric};
pub use domain::{metric_length, resample_polygon, triangulate_polygon, triangulate_polygon_with};
pub use field::PlanarMetricField;
pub use lct::{remesh_planar, Lct, LctOptions};
pub use registry::{planar_remesher, REMESHERS};
pub use stats::{planar_quality, PlanarQuality};
pub use transfer::{clamp_spd, pullback_corners, transfer_metric, TransferMethod, EIGEN_FLOOR_REL};

pub use crate::mesh::{PlanarDomain, PlanarMesh};
use nalgebra::{Matrix2, Point2};
use rand_chacha::ChaCha8Rng;
use thiserror::Error;

/// Errors of planar remeshing.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum Remesh2dError {
    /// The input domain is invalid (not a positively oriented disk triangulation, …).
    #[error("invalid planar domain: {0}")]
    InvalidDomain(String),
    /// A metric value is not symmetric positive definite.
    #[error("metric not SPD at ({x}, {y})")]
    MetricNotSpd {
        /// x
        x: f64,
        /// y
        y: f64,
    },
    /// The output failed its certificate.
    #[error(transparent)]
    Invariant(#[from] crate::invariants::InvariantError),
}

/// A metric field on the plane: an SPD 2×2 tensor at every point of the domain.
pub trait Metric2d: Sync {
    /// The metric at `p`.
    fn metric(&self, p: &Point2<f64>) -> Matrix2<f64>;
}

/// The research extension point: remesh a planar domain to follow a metric, keeping the
/// boundary loop and constrained edges exactly.
pub trait PlanarRemesher: Send + Sync {
    /// Short name used in reports.
    fn name(&self) -> &'static str;
    /// Remesh `domain` so that edges have metric length close to `target_length`.
    fn remesh(
        &self,
        domain: &PlanarDomain,
        metric: &dyn Metric2d,
        target_length: f64,
        rng: &mut ChaCha8Rng,
    ) -> Result<PlanarMesh, Remesh2dError>;
}
