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
pub use lct::{
    remesh_planar, Lct, LctOptions, MAX_LCT_FACES, MAX_OVERSHOOT, MIN_TRANSIENT_BASE,
    SPLIT_OVERSHOOT,
};
pub use registry::{planar_remesher, REMESHERS};
pub use stats::{planar_quality, PlanarQuality};
pub use transfer::{clamp_spd, pullback_corners, transfer_metric, TransferMethod, EIGEN_FLOOR_REL};

use crate::ids::{FaceId, VertexId};
pub use crate::mesh::{PlanarDomain, PlanarMesh};
use nalgebra::{Matrix2, Point2};
use rand_chacha::ChaCha8Rng;
use thiserror::Error;

/// Errors of planar remeshing.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum Remesh2dError {
    /// The input domain fails its certificate (not a positively oriented disk triangulation,
    /// …), naming the elements.
    #[error("invalid planar domain: {0}")]
    InvalidDomain(#[source] crate::invariants::InvariantError),
    /// Per-element data whose count is not the element count.
    #[error("{elements} {of} but {found} {data}")]
    CountMismatch {
        /// the element count
        elements: usize,
        /// which elements ("vertices", "points", "triangles")
        of: &'static str,
        /// the data's count
        found: usize,
        /// which data ("uv positions", "metrics", "corner metric triples")
        data: &'static str,
    },
    /// A metric field over no triangles.
    #[error("invalid planar domain: no triangles")]
    NoTriangles,
    /// A point with a NaN or infinite coordinate.
    #[error("invalid planar domain: point {0} is not finite")]
    NonFinitePoint(VertexId),
    /// A triangle naming a point that does not exist.
    #[error("invalid planar domain: triangle {0} has an out-of-range vertex")]
    VertexOutOfRange(FaceId),
    /// A triangle that is not positively oriented (exact).
    #[error("invalid planar domain: triangle {0} is not positively oriented")]
    NotPositive(FaceId),
    /// A parameter triangle of zero area (no Jacobian for the metric's pull-back).
    #[error("degenerate parameter triangle {0}")]
    DegenerateParamTriangle(FaceId),
    /// A boundary polygon of fewer than 3 vertices.
    #[error("invalid planar domain: polygon has {0} vertices")]
    ShortPolygon(usize),
    /// A boundary polygon that is not counter-clockwise.
    #[error("invalid planar domain: polygon is not counter-clockwise")]
    Clockwise,
    /// A boundary polygon that self-intersects or repeats a point.
    #[error("invalid planar domain: polygon self-intersects or has duplicate points")]
    SelfIntersecting,
    /// The constrained Delaunay triangulation refused a point (NaN, too large or too small).
    #[error("invalid planar domain: triangulation failed: {0:?}")]
    Triangulation(spade::InsertionError),
    /// A target edge length that is not a positive number.
    #[error("target length {0} is not positive")]
    BadTargetLength(f64),
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
    /// The metric asks for more faces than the caller allows in this domain (a metric many
    /// orders of magnitude off for its domain would otherwise refine until memory runs out).
    #[error(
        "the metric asks for about {faces:.3e} faces in this domain, more than the {max:e} allowed"
    )]
    TooDense {
        /// The faces an ideal mesh of the domain's metric area has ([`ideal_faces`]), or the
        /// count reached.
        faces: f64,
        /// The most allowed.
        max: f64,
    },
}

/// The number of faces of an ideal mesh of `domain` in `metric` at edge length
/// `target_length`: the domain's metric area (each triangle's Euclidean area times √det of
/// the metric at its centroid, the mean of its corners' tensors when the metric is linear on
/// the triangle, as [`PlanarMetricField`] is) over √3/4·L². NaN when a tensor is not SPD.
///
/// A domain narrower than `target_length` in the metric has a small area but needs a face
/// per boundary piece whatever its width: the count is at least the boundary loop's metric
/// length over L (each boundary edge measured at 4 samples), less 2.
pub fn ideal_faces(domain: &PlanarDomain, metric: &dyn Metric2d, target_length: f64) -> f64 {
    let n = domain.boundary.len();
    let perimeter: f64 = (0..n)
        .map(|k| {
            let (a, b) = (domain.boundary[k], domain.boundary[(k + 1) % n]);
            let (a, b) = (domain.points[a as usize], domain.points[b as usize]);
            metric_length(metric, &a, &b, 4)
        })
        .sum();
    let by_boundary = perimeter / target_length - 2.0;
    let mut area = 0.0;
    for t in &domain.triangles {
        let p = t.map(|i| domain.points[i as usize]);
        let centroid = Point2::from((p[0].coords + p[1].coords + p[2].coords) / 3.0);
        let Some(m) = clamp_spd(&metric.metric(&centroid)) else {
            return f64::NAN;
        };
        let a = 0.5 * (p[1] - p[0]).perp(&(p[2] - p[0]));
        area += a.abs() * m.determinant().max(0.0).sqrt();
    }
    (area / (3f64.sqrt() / 4.0 * target_length * target_length)).max(by_boundary)
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

    /// [`PlanarRemesher::remesh`] with at most `max_faces` faces: more is
    /// [`Remesh2dError::TooDense`]. The pipeline calls this one with its per-patch cap. The
    /// default checks the result; a remesher that refines in steps should override it to stop
    /// as soon as it passes the cap (a metric far too fine in one direction for its domain has
    /// a small area but asks for unbounded refinement), as [`Lct`] does.
    fn remesh_bounded(
        &self,
        domain: &PlanarDomain,
        metric: &dyn Metric2d,
        target_length: f64,
        max_faces: f64,
        rng: &mut ChaCha8Rng,
    ) -> Result<PlanarMesh, Remesh2dError> {
        let mesh = self.remesh(domain, metric, target_length, rng)?;
        let faces = mesh.triangles.len() as f64;
        match faces > max_faces {
            true => Err(Remesh2dError::TooDense {
                faces,
                max: max_faces,
            }),
            false => Ok(mesh),
        }
    }
}
