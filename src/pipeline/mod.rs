//! Algorithm 1: the loop over patches.
//!
//! ```text
//! while an unprocessed face remains:
//!     P  = strategy.next_patch(working mesh, processed, rng)       // Sec. 3.2  (certify_disk)
//!     uv = parameterizer.parameterize(P)                            // Sec. 3.3  (certify_bijective)
//!     M2 = transfer_metric(P, uv, M at the reference locations)     // Eq. 4
//!     P' = remesher.remesh(uv domain, M2, L_tar)                    // LCT       (certify_planar)
//!     lift P' by barycentric location in the initial 2D mesh and
//!         project onto the reference surface                        // "Mapping back"
//!     certify the candidate (no degenerate, flipped or intersecting new face)
//!     stitch P' into the working mesh, mark its faces processed     // manifold, oriented,
//!                                                                   // same topology, boundary
//! the improvers, in order: the connectivity and vertex position      // Sec. 3.4
//!     updates on the surface; Algorithm 2 around the faces of low
//!     quality (Eq. 5-6)                                             // improve::Improver
//! at the end: the whole mesh again, and no self-intersections (exact)
//! ```
//!
//! [`remesh`] runs in the unit-diagonal space of the metric field's reference mesh
//! ([`crate::metric::Normalization`]); [`Remesher`] does the whole job from a mesh in file
//! units (scaling, the curvature or user metric, mapping back, re-certification).
//!
//! Files: `options.rs` (options and stages), `sizing.rs` (the [`Plan`] resolved before the
//! loop), `context.rs` (what a run reads and the loop's state), `step.rs` (one patch with its
//! retry ladder), `replace.rs` (stitching and the per-patch certificates), `improvement.rs`
//! (the improvers after the loop, [`crate::improve::ImproveRun`]), `finish.rs` (the certificates of the
//! output, the report), `records.rs` (report types),
//! `error.rs`, `debug.rs` (offending patches written out), `remesher.rs` (the whole job).

mod chains;
mod context;
mod debug;
mod error;
mod finish;
mod improvement;
mod options;
mod records;
mod remesher;
mod replace;
mod sizing;
mod step;

pub use error::{PipelineError, Stage, StageError};
pub use options::{
    default_improvers, Cancel, CoarseInput, RemeshOptions, Stages, TargetLength, COARSE_RATIO,
    DEFAULT_IMPROVERS,
};
pub use records::{
    AngleSummary, Certificate, FailedAttempt, Fallbacks, ImprovementReport, ImproverRecord,
    PatchRecord, Progress, RemeshReport, RemeshResult, StageTimes, Warning,
};
pub use remesher::{Remeshed, Remesher};
pub use sizing::{coarse_input_estimate, expected_faces, Plan, MAX_EXPECTED_FACES};
pub use step::MIN_PATCH_FACES;

use crate::mesh::Topology;
use crate::metric::MetricField;
use context::{LoopState, RunContext};
use rand::SeedableRng;
use std::time::Instant;

/// Run Algorithm 1 on the metric field's reference mesh (unit-diagonal space).
///
/// Randomness: one ChaCha8 stream seeded with `options.seed`, drawn only by the patch
/// strategy and the planar remesher, in patch order, so the output depends on the seed only
/// (not on thread count).
pub fn remesh(
    field: &MetricField,
    stages: &Stages,
    options: &RemeshOptions,
    mut on_progress: impl FnMut(Progress),
) -> Result<RemeshResult, PipelineError> {
    for i in &stages.improvers {
        i.validate()
            .map_err(|e| PipelineError::Input(format!("improver `{}`: {e}", i.name())))?;
    }
    let topo = certified_input_topology(field)?;
    let plan = Plan::resolve(field, &topo, options)?;
    let ctx = RunContext::new(plan.quality_field(field), topo, &plan, stages);
    let mut state = LoopState::new(&ctx)?;
    let mut rng = crate::Rng::seed_from_u64(plan.options.seed);
    while state.face_remains(&ctx) {
        let patch = next_patch(&ctx, &mut state, &mut rng)?; // (a) Sec. 3.2
        let outcome = step::patch_step(&ctx, &mut state, &patch, &mut rng)?; // (b)-(e)
        replace::replace_patch(&ctx, &mut state, outcome)?; // replace P, update M
        on_progress(state.progress(&ctx));
        options.cancel.check(state.patches)?;
    }
    state.loop_patches = state.patches;
    options.cancel.check(state.patches)?;
    improvement::run(&ctx, &mut state, &mut rng)?; // Sec. 3.4, the improvers in order
    finish::certify_output(&ctx, &mut state)?;
    Ok(finish::into_result(&ctx, state))
}

/// The input must be an oriented 2-manifold (with or without boundary): say so up front,
/// naming the elements, rather than failing later inside a patch.
fn certified_input_topology(field: &MetricField) -> Result<Topology, PipelineError> {
    let reference = field.reference();
    let topo = Topology::build(reference);
    crate::invariants::certify_manifold(reference, &topo)
        .and_then(|()| crate::invariants::certify_oriented(reference, &topo))
        .map_err(|e| {
            PipelineError::Input(format!("the input mesh is not an oriented manifold: {e}"))
        })?;
    Ok(topo)
}

/// Algorithm 1, line 3: the strategy's next patch around an unprocessed face.
fn next_patch(
    ctx: &RunContext<'_>,
    state: &mut LoopState,
    rng: &mut crate::Rng,
) -> Result<crate::patches::Patch, PipelineError> {
    let t0 = Instant::now();
    let strategy = &ctx.stages.patches;
    let patch = match strategy.next_patch(&state.patch_context(ctx), rng) {
        Ok(Some(p)) => p,
        Ok(None) => {
            return Err(PipelineError::StrategyStopped {
                strategy: strategy.name(),
                unprocessed: state.work.unprocessed(),
            })
        }
        Err(e) => {
            return Err(PipelineError::Stage {
                patch: crate::ids::PatchId::new(state.patches),
                seed: None,
                stage: Stage::PatchGeneration,
                source: e.into(),
            })
        }
    };
    state.counters.times.patches += t0.elapsed().as_secs_f64();
    Ok(patch)
}
