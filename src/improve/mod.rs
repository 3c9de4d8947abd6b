//! Quality improvement after the loop of Algorithm 1 (Sec. 3.4): the [`Improver`] extension
//! point and its two registered rows ([`IMPROVERS`]).
//!
//! Algorithm 2 of the paper improves the triangles of poor quality by the two updates of
//! Sec. 3.4, the *connectivity update* (edge flips) and the *vertex position update*. Both
//! improvers run them, in two places:
//! - [`SurfacePasses`] (row `surface`) runs them on the surface itself, directly on the
//!   working mesh: [`connectivity_update`] flips edges where the smaller metric quality of
//!   their two faces rises, [`vertex_position_update`] moves vertices along the reference
//!   surface where the worst face around them improves. The seams between patches are where
//!   they matter most: their vertices and edges were fixed patch-boundary elements while the
//!   patches were remeshed. Every change is a candidate certified like a patch's new faces
//!   (not degenerate, not flipped, locally embedded) and keeps the surface within the distance
//!   tolerance.
//! - [`Algorithm2`] (row `eq5`) is Algorithm 2 proper: a patch of the run's strategy around
//!   the bad triangles, parameterized by the run's parameterizer, the two updates in its plane
//!   on the energy of Eq. 5-6 ([`Eq5Updates`], a [`crate::remesh2d::PlanarRemesher`] that
//!   keeps the patch's vertices), mapped back and certified like a patch of Algorithm 1
//!   (through [`ImproveRun::patch_pass`]).
//!
//! Every improver is given the run's stages ([`LoopStages`]: strategy, parameterizer, planar
//! remesher), so `--strategy` and `--param` reach the improvement too. A new improver is one
//! file here plus one row in [`IMPROVERS`] (or a row given to a
//! [`crate::registry::Registry`] outside the crate); it works through [`ImproveRun`]
//! (implemented by the pipeline), which certifies whatever it changes, and
//! [`crate::contract::improver`] checks it. How the two compare: paper-notes.md, Sec. 3.4.
//!
//! Files: `flips.rs` (connectivity update), `relocate.rs` (vertex position update),
//! `geometry.rs` (the helpers they share), `eq5.rs` (Algorithm 2's planar updates),
//! `algorithm2.rs` (Algorithm 2's loop), `registry.rs` (the table).

mod algorithm2;
pub mod eq5;
mod flips;
mod geometry;
mod relocate;

mod registry;

pub use algorithm2::{Algorithm2, Bottom, ImproveOptions};
pub use eq5::{Eq5Options, Eq5Updates, FlipRule, Target};
pub use flips::connectivity_update;
pub(crate) use geometry::point_triangle_distance;
pub use registry::{improver, IMPROVERS};
pub use relocate::vertex_position_update;

use crate::ids::EdgeKey;
use crate::invariants::FlipTest;
use crate::metric::MetricField;
use crate::param::Parameterizer;
use crate::patches::PatchStrategy;
use crate::quality::TriangleQuality;
use crate::remesh2d::PlanarRemesher;
use crate::stitch::WorkingMesh;
use serde::Serialize;
use std::collections::HashSet;

/// What an improver may read and change of a run after the loop of Algorithm 1 (the pipeline
/// implements it). Every change goes through a certified operation: the surface passes'
/// candidates ([`ImproveRun::surface`]) or patches remeshed and replaced like those of
/// Algorithm 1 ([`ImproveRun::patch_pass`]); the whole output is certified again after the
/// last improver.
pub trait ImproveRun {
    /// The metric qualities are measured in (the input's, unscaled).
    fn quality_field(&self) -> &MetricField;
    /// The working mesh (unit-diagonal space; vertex ids stay valid until the end of the run).
    fn working_mesh(&self) -> &WorkingMesh;
    /// The target metric edge length L_tar.
    fn l_tar(&self) -> f64;
    /// Per-face quality of the working mesh in the unscaled metric (what `eval` measures).
    fn face_qualities(&self) -> Vec<TriangleQuality>;
    /// The surface passes' context (the metric, the certificates, the tolerance, what to
    /// leave alone) and the working mesh to change through it.
    fn surface(&mut self) -> (SurfaceContext<'_>, &mut WorkingMesh);
    /// Remesh the faces with `targets[f]` by patches of `stages`, as Algorithm 1 does (the
    /// strategy seeds only at target faces; every patch is certified like one of Algorithm
    /// 1; its boundary chains are kept as they are). A certified candidate replaces its faces
    /// only when `accept(old, new)` holds for the qualities of the faces it replaces and of the
    /// candidate's triangles on the surface (unscaled metric, as `conemesh eval`); otherwise the
    /// faces stay. At most `budget` patches, and no more than the
    /// run's own patch budget leaves. Ends: every patch marks at least one target face done.
    fn patch_pass(
        &mut self,
        stages: LoopStages<'_>,
        targets: &[bool],
        budget: Option<usize>,
        accept: &dyn Fn(&[TriangleQuality], &[TriangleQuality]) -> bool,
        rng: &mut crate::Rng,
    ) -> Result<PatchPass, RunError>;
}

/// The three stages one patch of Algorithm 1 goes through (Sec. 3.2-3.3), borrowed.
#[derive(Copy, Clone)]
pub struct LoopStages<'a> {
    /// Sec. 3.2.
    pub patches: &'a dyn PatchStrategy,
    /// Sec. 3.3, embedding.
    pub parameterizer: &'a dyn Parameterizer,
    /// Sec. 3.3, planar remeshing.
    pub remesher: &'a dyn PlanarRemesher,
}

impl LoopStages<'_> {
    /// Their names: strategy, parameterizer, remesher.
    pub fn names(&self) -> [String; 3] {
        [
            self.patches.name().to_string(),
            self.parameterizer.name().to_string(),
            self.remesher.name().to_string(),
        ]
    }
}

/// What [`ImproveRun::patch_pass`] did.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct PatchPass {
    /// Patches tried.
    pub patches: usize,
    /// Certified candidates the acceptance test refused (their faces stay).
    pub rejected: usize,
    /// The pass stopped at its budget with faces left.
    pub budget_exhausted: bool,
}

/// An error an improver passes on: the run's own (a failed certificate, a stage error;
/// the pipeline gets its typed error back) or one of the improver's.
#[derive(Debug, thiserror::Error)]
#[error(transparent)]
pub struct RunError(pub Box<dyn std::error::Error + Send + Sync + 'static>);

/// The research extension point of Sec. 3.4: an improvement of the working mesh after the
/// loop of Algorithm 1. The run calls every improver of its stages' `improvers` list
/// in order, giving each the run's own loop stages, and reports the Table-1 row after each;
/// whatever an improver changes goes through [`ImproveRun`], whose operations are certified,
/// and the whole output is certified again after the last one.
///
/// Contract ([`crate::contract::improver`]): it ends `Ok` on a run of the default stages,
/// the output passes every certificate, and the same seed gives the same mesh.
pub trait Improver: Send + Sync {
    /// Short name used in reports: its registry row's name.
    fn name(&self) -> &'static str;
    /// Errors for option values no run can use, naming the option (checked before the loop
    /// of Algorithm 1 starts).
    fn validate(&self) -> Result<(), crate::option_error::OptionError> {
        Ok(())
    }
    /// Improve the run's working mesh; `stages` are the run's strategy, parameterizer and
    /// planar remesher (for patches through [`ImproveRun::patch_pass`]). Randomness only
    /// from `rng`.
    fn improve(
        &self,
        stages: LoopStages<'_>,
        run: &mut dyn ImproveRun,
        rng: &mut crate::Rng,
    ) -> Result<ImproverCounts, RunError>;
}

/// What an improver did (each fills the counts that apply to it).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ImproverCounts {
    /// Edges flipped on the surface.
    pub flips: usize,
    /// Vertices moved on the surface.
    pub moves: usize,
    /// Passes over the faces to improve.
    pub passes: usize,
    /// Patches tried.
    pub patches: usize,
    /// Patches whose certified candidate was refused by the improver's acceptance test (the
    /// faces stay as they were).
    pub rejected: usize,
    /// Its budget ran out (the run still ends `Ok`; the report says so).
    pub budget_exhausted: bool,
}

/// What the surface passes read: the metric, the flip certificate, the tolerance, and the
/// elements they must leave alone.
#[derive(Clone, Copy)]
pub struct SurfaceContext<'a> {
    /// The metric every quality is measured in (the unscaled one, as `conemesh eval`).
    pub field: &'a MetricField,
    /// The flip certificate against the reference.
    pub flip_test: &'a FlipTest,
    /// Check candidates for local self-intersections (only for an embedded input).
    pub embedded_input: bool,
    /// How far a change may move the surface (unit space); `f64::INFINITY` when the distance
    /// control is off.
    pub tol: f64,
    /// The run's target length L_tar in [`SurfaceContext::field`]'s metric (NaN: unknown, then
    /// a boundary vertex sweeps its span only where its fan holds a bad face).
    pub l_tar: f64,
    /// A sliding boundary vertex also tries evenly spaced places between its neighbours, not
    /// only the balance point and half way there.
    pub slide_sweep: bool,
    /// Edges no flip may remove (feature lines).
    pub feature_edges: Option<&'a HashSet<EdgeKey>>,
    /// `pinned[v]`: vertex `v` may not move (corners and feature-line vertices).
    pub pinned: &'a [bool],
    /// The input's boundary curves, along which boundary vertices may slide.
    pub curves: Option<&'a crate::boundary::BoundaryCurves>,
    /// Slide boundary vertices along the input's boundary curves (not with the input's
    /// boundary kept bit for bit).
    pub slide_boundary: bool,
    /// `scope[v]`: the passes may move vertex `v` and flip the edges between such vertices
    /// (past the end: a vertex made after the flags were set, in scope); `None`: every vertex.
    /// The bands around the regions' cuts ([`crate::pipeline::RemeshOptions::region_faces`]).
    pub scope: Option<&'a crate::ids::VertexMap<bool>>,
}

impl SurfaceContext<'_> {
    /// The passes may change vertex `v` ([`SurfaceContext::scope`]).
    pub fn in_scope(&self, v: crate::ids::VertexId) -> bool {
        self.scope.is_none_or(|s| s.get(v).copied().unwrap_or(true))
    }
}

/// The connectivity and vertex position updates on the surface (row `surface`): the
/// connectivity update (with `flips`), then the vertex position update followed by the
/// connectivity update again (with `relocate`), within the fidelity tolerance (unbounded when
/// the control is off, `--hausd 0`).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize)]
pub struct SurfacePasses {
    /// Run the connectivity update (default `true`).
    pub flips: bool,
    /// Run the vertex position update, then flips again (default `true`).
    pub relocate: bool,
    /// A sliding boundary vertex also sweeps its span for a better place, not only the
    /// balance point (default `true`; [`SurfaceContext::slide_sweep`]).
    pub sweep: bool,
}

impl Default for SurfacePasses {
    fn default() -> Self {
        SurfacePasses {
            flips: true,
            relocate: true,
            sweep: true,
        }
    }
}

impl Improver for SurfacePasses {
    fn name(&self) -> &'static str {
        "surface"
    }

    fn improve(
        &self,
        _stages: LoopStages<'_>,
        run: &mut dyn ImproveRun,
        _rng: &mut crate::Rng,
    ) -> Result<ImproverCounts, RunError> {
        let (mut ctx, work) = run.surface();
        ctx.slide_sweep = self.sweep;
        let passes = finishing_passes(&ctx, work, self.flips, self.relocate);
        Ok(ImproverCounts {
            flips: passes.flips,
            moves: passes.moves,
            ..ImproverCounts::default()
        })
    }
}

/// What [`finishing_passes`] did.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct PassCounts {
    /// Edges flipped.
    pub flips: usize,
    /// Vertices moved.
    pub moves: usize,
}

/// The passes after the loop: the connectivity update (with `flips`), then the vertex
/// position update followed by the connectivity update again (with `relocate`).
pub fn finishing_passes(
    ctx: &SurfaceContext<'_>,
    work: &mut WorkingMesh,
    flips: bool,
    relocate: bool,
) -> PassCounts {
    let mut counts = PassCounts::default();
    if flips {
        counts.flips = connectivity_update(ctx, work);
    }
    if relocate {
        counts.moves = vertex_position_update(ctx, work);
        counts.flips += connectivity_update(ctx, work);
    }
    counts
}

#[cfg(test)]
mod tests;
