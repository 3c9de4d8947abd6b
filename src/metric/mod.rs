//! The Riemannian metric field (Sec. 3.1, Sec. 4.1): curvature metric per reference vertex,
//! evaluated anywhere on the reference surface by closest point + barycentric interpolation.

use thiserror::Error;

/// Errors of the metric stage.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MetricError {
    /// A tensor is not symmetric positive (semi-)definite on the tangent plane.
    #[error("metric at vertex v{vertex} is not SPD on the tangent plane: {detail}")]
    NotSpd {
        /// vertex index
        vertex: usize,
        /// eigenvalues or other detail
        detail: String,
    },
}
