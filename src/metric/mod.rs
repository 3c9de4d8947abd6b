//! The Riemannian metric field (Sec. 3.1, Sec. 4.1): curvature metric per reference vertex,
//! evaluated anywhere on the reference surface by closest point + barycentric interpolation.
//!
//! - [`normalize`]: the unit-diagonal normalization the pipeline works in.
//! - [`curvature`]: principal curvatures and directions by a local quadric fit.
//! - [`curvature_metric`]: `M = (d₁,d₂,n) diag(max(|k₁|,10⁻⁴), max(|k₂|,10⁻⁴), 0) (d₁,d₂,n)ᵀ`.
//! - [`field`]: [`MetricField`], the one way later stages ask for the metric.
//! - [`unit_target`]: a metric in MMG's `-ltar 1` convention, SPD in 3D, for other remeshers.
//!
//! User-supplied metrics come from Medit `.sol` files ([`crate::io::sol`]).

pub mod creases;
pub mod curvature;
pub mod field;
pub mod normalize;
pub mod sizes;
pub mod unit_target;

pub use curvature::{principal_curvatures, tangent_frame, CurvatureOptions, PrincipalCurvature};
pub use field::{validate_vertex_metric, MetricField};
pub use normalize::Normalization;
pub use sizes::{apply_sizes, SizeOptions};
pub use unit_target::unit_target_metric;

use crate::features::FeatureRule;
use crate::mesh::{MeshError, TriMesh};
use nalgebra::Matrix3;
use thiserror::Error;

/// Errors of the metric stage.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MetricError {
    /// A tensor is not symmetric positive (semi-)definite on the tangent plane, or is so
    /// badly conditioned there that it cannot be used (`defect` says which, with its numbers).
    #[error("metric at vertex v{vertex} cannot be used: {defect}")]
    NotSpd {
        /// vertex index
        vertex: usize,
        /// what is wrong with the tensor
        defect: SpdDefect,
    },
    /// A tensor has a NaN or infinite entry.
    #[error("metric at vertex v{vertex} has a NaN or infinite entry")]
    NonFinite {
        /// vertex index
        vertex: usize,
    },
    /// The number of tensors differs from the number of reference vertices.
    #[error("metric has {found} tensors but the reference mesh has {expected} vertices")]
    CountMismatch {
        /// number of reference vertices
        expected: usize,
        /// number of tensors given
        found: usize,
    },
    /// The reference mesh is invalid (empty, non-finite coordinates, bad indices).
    #[error("reference mesh: {0}")]
    Mesh(#[from] MeshError),
    /// The closest-point structure could not be built.
    #[error("closest-point BVH: {0}")]
    Bvh(#[source] parry3d_f64::shape::TriMeshBuilderError),
}

/// Why a tensor cannot be used as a metric ([`MetricError::NotSpd`]), with its numbers.
#[derive(Debug, Error, Clone, Copy, PartialEq)]
pub enum SpdDefect {
    /// `m − mᵀ` is beyond [`field::SPD_RELATIVE_TOLERANCE`] of the largest entry.
    #[error("not symmetric (max |m_ij − m_ji| = {asymmetry:e})")]
    NotSymmetric {
        /// max |m_ij − m_ji|
        asymmetry: f64,
    },
    /// An eigenvalue of the symmetric part is negative.
    #[error(
        "negative eigenvalue (eigenvalues {:e}, {:e}, {:e})",
        eigenvalues[0],
        eigenvalues[1],
        eigenvalues[2]
    )]
    NegativeEigenvalue {
        /// the three eigenvalues
        eigenvalues: [f64; 3],
    },
    /// The tensor restricted to the tangent plane is not positive definite.
    #[error(
        "not positive definite on the tangent plane (eigenvalues there {:e}, {:e})",
        eigenvalues[0],
        eigenvalues[1]
    )]
    TangentIndefinite {
        /// the two eigenvalues on the tangent plane
        eigenvalues: [f64; 2],
    },
    /// Positive definite on the tangent plane, but conditioned beyond what the predicates and
    /// the planar stage can carry ([`field::TANGENT_PD_RELATIVE_TOLERANCE`]).
    #[error(
        "positive definite on the tangent plane but conditioned beyond {:e}:1 \
         (eigenvalues there {:e}, {:e}; sizes differing by more than {:e} at one point)",
        1.0 / field::TANGENT_PD_RELATIVE_TOLERANCE,
        eigenvalues[0],
        eigenvalues[1],
        field::TANGENT_PD_RELATIVE_TOLERANCE.sqrt().recip()
    )]
    IllConditioned {
        /// the two eigenvalues on the tangent plane
        eigenvalues: [f64; 2],
    },
}

/// Options of the curvature metric (Sec. 4.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetricOptions {
    /// Curvature estimation (quadric fit radius).
    pub curvature: CurvatureOptions,
    /// Lower bound on |k₁|, |k₂| (default `1e-4`, the paper's value, "to prevent the long
    /// edge length caused by too small curvature"); in unit-space units (1/bbox diagonal).
    pub floor: f64,
    /// The feature lines the curvature is fitted around ([`creases`]): each side of a crease
    /// gets its own curvature. Default [`FeatureRule::Off`]: the paper's and libigl's fit
    /// across creases, the yardstick of `PEERS.md`. [`crate::pipeline::Remesher`] sets it to
    /// [`crate::pipeline::RemeshOptions::features`] when
    /// [`crate::pipeline::RemeshOptions::crease_metric`] is on.
    pub features: FeatureRule,
}

impl Default for MetricOptions {
    fn default() -> Self {
        MetricOptions {
            curvature: CurvatureOptions::default(),
            floor: 1e-4,
            features: FeatureRule::Off,
        }
    }
}

/// The curvature metric of one vertex (Sec. 4.1):
/// `M = (d₁, d₂, d₁×d₂) diag(max(|k₁|, floor), max(|k₂|, floor), 0) (d₁, d₂, d₁×d₂)ᵀ`.
/// Rank 2: zero along the normal, at least `floor` on the tangent plane.
pub fn metric_from_curvature(pc: &PrincipalCurvature, floor: f64) -> Matrix3<f64> {
    let l1 = pc.k1.abs().max(floor);
    let l2 = pc.k2.abs().max(floor);
    let m = pc.d1 * pc.d1.transpose() * l1 + pc.d2 * pc.d2.transpose() * l2;
    // Exactly symmetric, whatever the rounding of the outer products.
    (m + m.transpose()) * 0.5
}

/// The curvature metric (Sec. 4.1) at every vertex of `mesh`, from
/// [`principal_curvatures`] and [`metric_from_curvature`]; fitted around the feature lines of
/// `opts.features` where there are any ([`creases`]).
///
/// Expects the **unit-space** mesh (bounding-box diagonal 1, see [`Normalization`]): the floor
/// is in 1/(unit length). Convert the result to file units with
/// [`Normalization::metric_from_unit`] if needed.
pub fn curvature_metric(
    mesh: &TriMesh,
    opts: &MetricOptions,
) -> Result<Vec<Matrix3<f64>>, MetricError> {
    mesh.validate()?;
    let feature: std::collections::HashSet<_> = opts
        .features
        .edges(mesh, &crate::mesh::Topology::build(mesh))
        .into_iter()
        .collect();
    if !feature.is_empty() {
        return Ok(creases::crease_aware_metric(
            mesh,
            &opts.curvature,
            opts.floor,
            &feature,
        ));
    }
    let pcs = principal_curvatures(mesh, &opts.curvature)?;
    Ok(pcs
        .iter()
        .map(|pc| metric_from_curvature(pc, opts.floor))
        .collect())
}
