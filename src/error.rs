//! The crate's error: one `thiserror` enum per stage, wrapped here. The binary adds
//! context with `anyhow`; the library never does.

use thiserror::Error;

/// Any error of the conemesh library.
#[derive(Debug, Error)]
pub enum Error {
    /// Invalid mesh arrays.
    #[error(transparent)]
    Mesh(#[from] crate::mesh::MeshError),
    /// Reading or writing a file.
    #[error(transparent)]
    Io(#[from] crate::io::IoError),
    /// A certified invariant does not hold.
    #[error(transparent)]
    Invariant(#[from] crate::invariants::InvariantError),
    /// Reading or writing a Medit `.sol` metric.
    #[error(transparent)]
    Sol(#[from] crate::io::sol::SolError),
    /// Metric field (Sec. 3.1).
    #[error(transparent)]
    Metric(#[from] crate::metric::MetricError),
    /// Patch generation (Sec. 3.2).
    #[error(transparent)]
    Patch(#[from] crate::patches::PatchError),
    /// Parameterization (Sec. 3.3).
    #[error(transparent)]
    Param(#[from] crate::param::ParamError),
    /// Planar remeshing (Sec. 3.3).
    #[error(transparent)]
    Remesh2d(#[from] crate::remesh2d::Remesh2dError),
    /// Mapping a remeshed patch back to the surface (Sec. 3.3).
    #[error(transparent)]
    Lift(#[from] crate::lift::LiftError),
    /// Replacing a patch in the working mesh.
    #[error(transparent)]
    Stitch(#[from] crate::stitch::StitchError),
    /// Scoring a remeshed surface (`conemesh eval`).
    #[error(transparent)]
    Eval(#[from] crate::quality::EvalError),
    /// Building a registered extension-point implementation.
    #[error(transparent)]
    Registry(#[from] crate::registry::RegistryError),
    /// Algorithm 1.
    #[error(transparent)]
    Pipeline(#[from] crate::pipeline::PipelineError),
    /// Writing reports and plots.
    #[error(transparent)]
    Report(#[from] crate::report::ReportError),
}

/// Result with the crate's [`enum@Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
