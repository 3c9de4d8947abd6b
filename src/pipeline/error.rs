//! Errors of Algorithm 1. Every variant names the patch, its seed and the offending elements;
//! a stage's own error is kept as the `source`, not flattened to a string.

use crate::ids::{EdgeKey, PatchId, VertexId};
use crate::invariants::InvariantError;
use crate::lift::LiftError;
use crate::option_error::OptionError;
use crate::param::ParamError;
use crate::patches::PatchError;
use crate::quality::TargetLength;
use crate::remesh2d::Remesh2dError;
use crate::stitch::StitchError;
use serde::Serialize;
use std::fmt;
use std::path::PathBuf;
use thiserror::Error;

/// The stages of one patch of Algorithm 1, in order.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// (a) the patch strategy (Sec. 3.2).
    PatchGeneration,
    /// The patch as a mesh of its own.
    PatchExtraction,
    /// (b) bijective parameterization (Sec. 3.3).
    Parameterization,
    /// (c) metric transfer (Eq. 4).
    MetricTransfer,
    /// (d) planar remeshing.
    PlanarRemeshing,
    /// (e) mapping back onto the reference surface.
    MappingBack,
    /// The lifted candidate's certificates (no degenerate or flipped face, embedded).
    LiftedFaces,
    /// Replacing the patch in the working mesh.
    Stitching,
    /// The fidelity control's per-vertex factors after stitching.
    FidelityFactors,
}

impl fmt::Display for Stage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Stage::PatchGeneration => "patch generation",
            Stage::PatchExtraction => "patch extraction",
            Stage::Parameterization => "parameterization",
            Stage::MetricTransfer => "metric transfer",
            Stage::PlanarRemeshing => "planar remeshing",
            Stage::MappingBack => "mapping back",
            Stage::LiftedFaces => "lifted faces",
            Stage::Stitching => "stitching",
            Stage::FidelityFactors => "fidelity factors",
        })
    }
}

/// The typed error of one stage.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum StageError {
    /// Patch generation.
    #[error(transparent)]
    Patch(#[from] PatchError),
    /// Parameterization.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// Metric transfer or planar remeshing.
    #[error(transparent)]
    Remesh2d(#[from] Remesh2dError),
    /// Mapping back.
    #[error(transparent)]
    Lift(#[from] LiftError),
    /// Stitching.
    #[error(transparent)]
    Stitch(#[from] StitchError),
    /// A certificate of the stage's output failed.
    #[error(transparent)]
    Certificate(#[from] InvariantError),
    /// The patch's new faces cross those of an earlier patch of the same batch (exact): it
    /// waits for a later batch.
    #[error("its new faces cross those of patch {earlier} of the same batch (deferred to a later batch)")]
    Deferred {
        /// the earlier patch's place in the batch
        earlier: usize,
    },
    /// The fidelity control kept a factor count that does not match the working mesh.
    #[error("{factors} fidelity factors for {vertices} vertices after stitching")]
    FactorCount {
        /// factors kept
        factors: usize,
        /// working-mesh vertices
        vertices: usize,
    },
}

impl StageError {
    /// True when a certificate (not the stage itself) failed.
    pub fn is_certificate(&self) -> bool {
        matches!(self, StageError::Certificate(_))
    }
}

/// Errors of Algorithm 1.
#[derive(Debug, Error)]
pub enum PipelineError {
    /// A stage failed on a patch.
    #[error("patch {patch}{}: {stage} failed: {source}", seed_note(.seed))]
    Stage {
        /// which patch
        patch: PatchId,
        /// its seed vertex, when the strategy got as far as choosing one
        seed: Option<VertexId>,
        /// which stage
        stage: Stage,
        /// what failed
        #[source]
        source: StageError,
    },
    /// A certificate on the working mesh failed after a patch was stitched (or, with no
    /// seed, after the loop).
    #[error("{}: {violation}{}", where_note(.patch, .seed), debug_note(.debug_file))]
    Certificate {
        /// which patch (the patch count after the loop)
        patch: PatchId,
        /// its seed vertex; `None` for the certificate of the whole mesh after the loop
        seed: Option<VertexId>,
        /// the violated invariant, naming the elements
        #[source]
        violation: InvariantError,
        /// where the offending patch was written
        debug_file: Option<PathBuf>,
    },
    /// The working mesh failed its certificate after the feature lines were resampled, before
    /// the loop.
    #[error("after resampling the feature lines: {0}")]
    FeatureLines(#[source] InvariantError),
    /// The final mesh self-intersects.
    #[error("final mesh: {0}")]
    Final(#[source] InvariantError),
    /// The output mapped back to file units failed its exact re-certification (rounding of
    /// the new vertices).
    #[error("the output in file units (after mapping back from unit space): {0}")]
    FileUnits(#[source] InvariantError),
    /// The strategy returned a patch without an unprocessed face (the loop would not end).
    #[error(
        "patch {patch} (seed {seed}) contains no unprocessed face; the strategy must make progress"
    )]
    NoProgress {
        /// which patch
        patch: PatchId,
        /// its seed
        seed: VertexId,
    },
    /// The strategy returned no patch while faces were still unprocessed.
    #[error(
        "patch strategy `{strategy}` returned no patch with {unprocessed} faces still unprocessed"
    )]
    StrategyStopped {
        /// the strategy's name
        strategy: &'static str,
        /// faces left
        unprocessed: usize,
    },
    /// The strategy returned a patch with a corner vertex in its interior (the contract of
    /// [`crate::patches::PatchStrategy`] with [`crate::patches::PatchContext::corners`]).
    #[error(
        "patch {patch} (seed {seed}) contains the corner vertex {vertex} in its interior; the strategy must keep corners on patch boundaries"
    )]
    CornerInterior {
        /// which patch
        patch: PatchId,
        /// its seed
        seed: VertexId,
        /// the corner vertex
        vertex: VertexId,
    },
    /// The patch strategy returned a patch that crosses a feature line (contrary to
    /// [`crate::patches::PatchContext::feature_edges`]).
    #[error(
        "patch {patch} (seed {seed}) contains the feature-line edge {edge} in its interior; the strategy must keep feature edges on patch boundaries"
    )]
    FeatureInterior {
        /// which patch
        patch: PatchId,
        /// its seed
        seed: VertexId,
        /// the feature edge
        edge: EdgeKey,
    },
    /// A corner vertex of the input ([`super::RemeshOptions::corner_defect`]) is not in the
    /// output at its input position.
    #[error("final mesh: the input's corner vertex {0} was removed or moved")]
    CornerLost(VertexId),
    /// A piece of a feature line ([`super::RemeshOptions::features`]) is not an edge of
    /// the output, or one of its vertices moved.
    #[error("final mesh: the feature-line edge {0} was removed or moved")]
    FeatureLost(EdgeKey),
    /// The metric (a user metric that is not SPD on the surface, or the curvature estimate).
    #[error(transparent)]
    Metric(#[from] crate::metric::MetricError),
    /// An input vertex is a corner of more faces than [`super::MAX_FACES_AT_VERTEX`]: the
    /// patch around it would hold them all (they are slivers meeting there, e.g. a polygon of
    /// that many corners cut into a fan), and a patch's parameterization, certificates and
    /// projections cost more than linearly in such a fan. Refused before any work.
    #[error(
        "input vertex {vertex} is a corner of {faces} faces (at most {max}): the patch around it \
         would hold them all, slivers meeting at one point, which conemesh cannot remesh in \
         bounded time (a polygon of that many corners cut into a fan? triangulate it with \
         interior points first)"
    )]
    CrowdedVertex {
        /// the vertex (input numbering)
        vertex: VertexId,
        /// the faces it is a corner of
        faces: usize,
        /// the bound
        max: usize,
    },
    /// The input mesh has no faces.
    #[error("the input mesh has no faces")]
    EmptyInput,
    /// The input mesh is not an oriented 2-manifold (the certificate names the elements).
    #[error(
        "the input mesh is not an oriented manifold: {0} (`conemesh remesh --repair`, or \
         `repair=True` in Python, orients it and cuts non-manifold edges and vertices)"
    )]
    NotManifold(#[source] InvariantError),
    /// A user metric whose tensor count is not the input's vertex count.
    #[error("the metric has {tensors} tensors for {vertices} vertices")]
    MetricCount {
        /// tensors given
        tensors: usize,
        /// the input's vertices
        vertices: usize,
    },
    /// An option value no run can use.
    #[error(transparent)]
    Option(#[from] OptionError),
    /// An improver's option value no run can use.
    #[error("improver `{improver}`: {source}")]
    ImproverOption {
        /// the improver
        improver: &'static str,
        /// the option
        source: OptionError,
    },
    /// The target edge length L_tar is not a positive finite number.
    #[error("target edge length {l_tar} is not a positive finite number: {}", target_note(.target, .l_avg))]
    BadTarget {
        /// L_tar
        l_tar: f64,
        /// how it was asked for
        target: TargetLength,
        /// the input's mean metric edge length L_avg
        l_avg: f64,
    },
    /// A target edge length that would make far too many faces.
    #[error(
        "target edge length {l_tar:e} is too small for this input: the output would have \
         about {expected:.3e} faces (more than {max:e})"
    )]
    TargetTooSmall {
        /// L_tar
        l_tar: f64,
        /// the faces the output would have
        expected: f64,
        /// the most allowed
        max: f64,
    },
    /// The metric after the size controls (`hmin`, `hmax`, `hgrad`) is not usable.
    #[error("size-controlled metric: {0}")]
    SizedMetric(#[source] crate::metric::MetricError),
    /// The metric scaled by the fidelity control's a-priori factors is not usable.
    #[error("fidelity-scaled metric: {0}")]
    FidelityMetric(#[source] crate::metric::MetricError),
    /// The feature lines could not be resampled before the loop.
    #[error(transparent)]
    Features(#[from] crate::features::FeatureError),
    /// An improver gave a target flag count that is not the working mesh's face count.
    #[error("an improver gave {flags} target flags for {faces} faces")]
    ImproverTargets {
        /// flags given
        flags: usize,
        /// the working mesh's faces
        faces: usize,
    },
    /// The run was stopped through [`super::Cancel`] (e.g. Ctrl-C in the Python package);
    /// nothing is returned.
    #[error("cancelled after {patches} patches")]
    Cancelled {
        /// patches done when the stop was seen
        patches: usize,
    },
    /// The run of one piece of a mesh split into regions failed (paper-notes "Regions"); the
    /// patch, vertex, face and edge ids in `source` are the piece's own.
    #[error("{level} {index} ({faces} faces; ids below are the piece's own): {source}")]
    Region {
        /// which level: "region", "strip" or "junction"
        level: &'static str,
        /// the piece's index in its level
        index: usize,
        /// its faces
        faces: usize,
        /// what failed there
        source: Box<PipelineError>,
    },
    /// An improver failed with an error of its own.
    #[error("improver `{improver}`: {source}")]
    Improver {
        /// its name
        improver: &'static str,
        /// its error
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
}

fn target_note(target: &TargetLength, l_avg: &f64) -> String {
    match *target {
        TargetLength::Factor(f) if f.is_finite() && f > 0.0 => format!(
            "L_tar = {f} × L_avg, and the input's mean metric edge length L_avg is {l_avg} \
             (a mesh too large or too small for its metric, or a vanishing metric)"
        ),
        TargetLength::Factor(f) => {
            format!("the target factor (--ltar-factor) {f} is not a positive number")
        }
        TargetLength::Absolute(l) => {
            format!("the absolute target (--ltar) {l} is not a positive number")
        }
    }
}

fn seed_note(seed: &Option<VertexId>) -> String {
    seed.map(|s| format!(" (seed {s})")).unwrap_or_default()
}

fn where_note(patch: &PatchId, seed: &Option<VertexId>) -> String {
    match seed {
        Some(s) => format!("after patch {patch} (seed {s})"),
        None => format!("after the loop ({} patches)", patch.0),
    }
}

fn debug_note(p: &Option<PathBuf>) -> String {
    match p {
        Some(p) => format!(" (offending patch written to {})", p.display()),
        None => String::new(),
    }
}
