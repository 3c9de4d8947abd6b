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
//! A mesh larger than [`RemeshOptions::region_faces`] runs the loop and the improvers on
//! regions at the same time first, their cuts frozen, and then the loop above on the bands
//! around the cuts (`regions.rs`).
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
mod regions;
mod remesher;
mod replace;
mod sizing;
mod step;

pub use error::{PipelineError, Stage, StageError};
pub use options::{
    default_improver_names, default_improvers, Cancel, Choice, CoarseInput, Registries,
    RemeshOptions, Stages, TargetLength, COARSE_RATIO, DEFAULT_BATCH, DENSE_INPUT_RATIO,
    FACE_BUDGET, WORK_BUDGET,
};
pub use records::{
    AngleSummary, Certificate, FailedAttempt, Fallbacks, ImprovementReport, ImproverRecord,
    PatchRecord, PhaseTimes, Progress, RegionsReport, RemeshReport, RemeshResult, SmallAngleFace,
    SmallAngles, StageTimes, VertexKind, Warning, SMALL_ANGLE_DEG,
};
pub use regions::{
    partition, BAND_RINGS, CUT_QUANTILE, DEFAULT_REGION_FACES, MAX_CUT_EDGE, MIN_FACE_WEIGHT,
};
pub use remesher::{Remeshed, Remesher, MAX_FACES_AT_VERTEX};
pub use sizing::{
    coarse_input_estimate, expected_faces, Plan, MAX_EXPECTED_FACES, MIN_PATCH_FACE_CAP,
};
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
            .map_err(|source| PipelineError::ImproverOption {
                improver: i.name(),
                source,
            })?;
    }
    let clock = Instant::now();
    let topo = certified_input_topology(field)?;
    let plan = Plan::resolve(field, &topo, options)?;
    let ctx = RunContext::new(plan.quality_field(field), topo, &plan, stages);
    let mut state = LoopState::new(&ctx)?;
    let mut rng = crate::Rng::seed_from_u64(plan.options.seed);
    state.wall.setup = clock.elapsed().as_secs_f64();
    // Regions at the same time, their cuts frozen, then the band around the cuts in pieces;
    // the loop below takes what they left. One region (a mesh no larger than
    // RemeshOptions::region_faces): the loop runs on the whole mesh, as in the paper.
    let regions = regions::run_regions(&ctx, &mut state)?;
    if regions > 1 {
        on_progress(state.progress(&ctx));
    }
    let clock = Instant::now();
    state.index_faces(&ctx);
    patch_loop(&ctx, &mut state, &mut rng, &mut on_progress)?;
    state.loop_patches = state.patches;
    state.wall.patch_loop = clock.elapsed().as_secs_f64();
    options.cancel.check(state.patches)?;
    let clock = Instant::now();
    improvement::run(&ctx, &mut state, &mut rng)?; // Sec. 3.4, the improvers in order
    state.wall.improve = clock.elapsed().as_secs_f64();
    let clock = Instant::now();
    finish::certify_output(&ctx, &mut state)?;
    state.wall.finish = clock.elapsed().as_secs_f64();
    Ok(finish::into_result(&ctx, state))
}

/// Algorithm 1's loop: batches of patches until no unprocessed face remains (or a budget
/// ends it), each replaced in the working mesh and certified.
fn patch_loop(
    ctx: &RunContext<'_>,
    state: &mut LoopState,
    rng: &mut crate::Rng,
    on_progress: &mut dyn FnMut(Progress),
) -> Result<(), PipelineError> {
    let options = &ctx.plan.options;
    while state.face_remains(ctx) {
        let batch = next_batch(ctx, state, rng)?; // (a) Sec. 3.2, a vertex apart
        let outcomes = step::batch_steps(ctx, state, &batch, rng)?; // (b)-(e), at the same time
        replace::replace_batch(ctx, state, outcomes)?; // replace each P, update M
        state.note_face_budget(ctx); // past it, no more refinement: the run's cost is bounded
        state.note_work_budget(ctx); // past it, no refinement and then no further patch
        state.batches += 1;
        on_progress(state.progress(ctx));
        options.cancel.check(state.patches)?;
    }
    Ok(())
}

/// The input must be an oriented 2-manifold (with or without boundary): say so up front,
/// naming the elements, rather than failing later inside a patch.
fn certified_input_topology(field: &MetricField) -> Result<Topology, PipelineError> {
    let reference = field.reference();
    let topo = Topology::build(reference);
    crate::invariants::certify_manifold(reference, &topo)
        .and_then(|()| crate::invariants::certify_oriented(reference, &topo))
        .map_err(PipelineError::NotManifold)?;
    Ok(topo)
}

/// Algorithm 1, line 3, for a batch: the strategy's next patches around unprocessed faces, up
/// to [`RemeshOptions::batch`] (and the patch budget), each sharing no vertex with the earlier
/// ones (the strategy sees their surroundings as [`crate::patches::PatchContext::blocked`]).
/// A patch that runs into a blocked face (or next to one: its growth may have been cut short
/// there) is turned down; the batch closes when the strategy finds no further patch or after
/// [`MAX_BATCH_MISSES`] such answers. Its RNG draws are the same whatever the thread count.
fn next_batch(
    ctx: &RunContext<'_>,
    state: &mut LoopState,
    rng: &mut crate::Rng,
) -> Result<Vec<crate::patches::Patch>, PipelineError> {
    let o = &ctx.plan.options;
    let room = o
        .max_patches
        .map_or(o.batch, |max| {
            o.batch.min(max.saturating_sub(state.patches))
        })
        .max(1);
    // The first patch of a sweep sets the processed front alone: the batch's later patches
    // are seeded on that front, not scattered over an untouched surface.
    let room = match state.work.processed.iter().any(|p| *p) {
        true => room,
        false => 1,
    };
    let mut batch = vec![next_patch(ctx, state, rng)?];
    state.block_around(&batch[0].faces);
    let mut misses = 0;
    while batch.len() < room && misses < MAX_BATCH_MISSES {
        let t0 = Instant::now();
        let next = ctx
            .stages
            .patches
            .next_patch(&state.patch_context(ctx), rng);
        state.counters.times.patches += t0.elapsed().as_secs_f64();
        match next {
            Ok(Some(p)) if clear_of_blocked(state, &p.faces) => {
                state.block_around(&p.faces);
                batch.push(p);
            }
            Ok(Some(_)) => misses += 1,
            // No further patch, or an error the next batch's first patch meets unblocked.
            _ => break,
        }
    }
    state.blocked.clear();
    Ok(batch)
}

/// Strategy answers a batch may turn down (patches that touched the blocked faces) before it
/// closes.
const MAX_BATCH_MISSES: usize = 3;

/// No face of `faces` is blocked or shares an edge with a blocked face: the strategy never had
/// a blocked face to refuse, so the patch is the one it would have made without the mark (not
/// cut short where the batch's earlier patches lie).
fn clear_of_blocked(state: &LoopState, faces: &[crate::ids::FaceId]) -> bool {
    faces.iter().all(|&f| {
        !state.blocked[f]
            && (0..3).all(|i| state.topo.neighbor(f, i).is_none_or(|g| !state.blocked[g]))
    })
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
