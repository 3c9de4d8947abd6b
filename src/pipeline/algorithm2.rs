//! Algorithm 2, minimum-angle improvement (Sec. 3.4), after the loop of Algorithm 1.
//!
//! ```text
//! while a face has q below the threshold and the budget is not spent:
//!     P  = a cone patch over `rings` rings around it          // through the PatchStrategy
//!     uv = parameterize P (certified bijective); M2 = Eq. 4
//!     vertex position and connectivity updates in the plane    // Eq. 5-6, improve::eq5
//!     map back, certify and replace P                          // as a patch of Algorithm 1
//! ```
//!
//! It reuses Algorithm 1's patch step with other stages: a pass marks the faces at or above
//! the threshold as processed, so the cone strategy seeds only at bad faces and its ring
//! expansion takes their neighbourhood; the planar stage is [`crate::improve::Eq5Improver`],
//! which keeps the patch's vertices and boundary; the patch's boundary chains are not
//! resampled. Every replaced patch is certified as in Algorithm 1. Termination: within a pass
//! every patch marks at least one unprocessed face processed (Algorithm 1's argument); a
//! further pass runs only when the previous one strictly lowered the count of faces below the
//! threshold, and there are at most `passes` of them. Each pass takes one ring more around the
//! bad faces than the last.

use super::context::{LoopState, RunContext};
use super::error::PipelineError;
use super::options::Stages;
use super::records::{AngleSummary, ImprovementReport};
use super::step::PatchOutcome;
use super::{replace, step};
use crate::ids::FaceId;
use crate::improve::Eq5Improver;
use crate::param::SymmetricDirichlet;
use crate::patches::{ConeOptions, ConePatches};
use crate::quality::{face_qualities, stats_of, triangle_quality, TriangleQuality};
use crate::stitch::{PatchVertex, Replacement};
use std::time::Instant;

/// Run Algorithm 2 on the working mesh when it is enabled; its report goes to the state.
pub fn run(
    ctx: &RunContext<'_>,
    state: &mut LoopState,
    rng: &mut crate::Rng,
) -> Result<(), PipelineError> {
    let o = &ctx.plan.options.improve;
    if !o.enabled {
        return Ok(());
    }
    let t0 = Instant::now();
    let before = summary(&qualities(ctx, state));
    let mut bad_before = usize::MAX;
    let (mut passes, mut patches, mut rejected, mut budget_exhausted) = (0, 0, 0, false);
    while passes < o.passes {
        let q = qualities(ctx, state);
        let bad: Vec<bool> = q.iter().map(|t| t.q < o.q_threshold).collect();
        let n_bad = bad.iter().filter(|b| **b).count();
        if n_bad == 0 || n_bad >= bad_before {
            break;
        }
        bad_before = n_bad;
        // Each pass reaches one ring farther: the faces still bad after a pass are those whose
        // patch was too small to move their vertices (they sat on its boundary).
        let stages = stages_for(o, o.rings + passes);
        let ictx = ctx.for_improvement(&stages);
        passes += 1;
        state.work.processed = bad.iter().map(|b| !b).collect();
        while state.work.unprocessed() > 0 {
            if o.max_patches.is_some_and(|m| patches >= m) {
                budget_exhausted = true;
                break;
            }
            let patch = super::next_patch(&ictx, state, rng)?;
            let outcome = match step::patch_step(&ictx, state, &patch, rng)? {
                PatchOutcome::Remeshed {
                    faces,
                    refined,
                    record,
                } if !improves(ctx, state, &faces, &refined.replacement) => {
                    rejected += 1;
                    PatchOutcome::Kept { faces, record }
                }
                outcome => outcome,
            };
            replace::replace_patch(&ictx, state, outcome)?;
            patches += 1;
        }
        if budget_exhausted {
            break;
        }
    }
    state.work.processed.iter_mut().for_each(|p| *p = true);
    state.improvement = Some(ImprovementReport {
        before,
        after: summary(&qualities(ctx, state)),
        passes,
        patches,
        rejected,
        budget_exhausted,
        seconds: t0.elapsed().as_secs_f64(),
    });
    Ok(())
}

/// Algorithm 2's stages: cone patches expanded by `rings` rings, SD, the planar updates.
fn stages_for(o: &super::options::ImproveOptions, rings: usize) -> Stages {
    Stages {
        patches: Box::new(ConePatches {
            options: ConeOptions {
                expand_rings: rings,
                ..ConeOptions::default()
            },
        }),
        parameterizer: Box::new(SymmetricDirichlet::default()),
        remesher: Box::new(Eq5Improver {
            options: o.planar.clone(),
        }),
    }
}

/// The candidate is better at the bottom than the faces it replaces: neither its smallest
/// metric quality nor its smallest angle is lower, and one of them is higher. (The planar
/// updates lower the energy in the plane; lifted across a crease or a strongly curved part a
/// move can still make a worse triangle on the surface, which is refused.)
fn improves(
    ctx: &RunContext<'_>,
    state: &LoopState,
    faces: &[FaceId],
    candidate: &Replacement,
) -> bool {
    let work = &state.work;
    let bottom = |qs: &mut dyn Iterator<Item = TriangleQuality>| {
        qs.fold((f64::INFINITY, f64::INFINITY), |(q, a), t| {
            (q.min(t.q), a.min(t.min_angle()))
        })
    };
    let (old_q, old_a) = bottom(&mut faces.iter().map(|&f| {
        let t = work.mesh.face(f);
        let m = t.map(|v| ctx.quality_field.eval_at(&work.locations[v.idx()]));
        triangle_quality(work.mesh.face_points(f), &((m[0] + m[1] + m[2]) / 3.0))
    }));
    let vertex = |v: PatchVertex| match v {
        PatchVertex::Existing(u) => (
            *work.mesh.position(u),
            ctx.quality_field.eval_at(&work.locations[u.idx()]),
        ),
        PatchVertex::New(i) => (
            candidate.new_positions[i as usize],
            ctx.quality_field
                .eval_at(&candidate.new_locations[i as usize]),
        ),
    };
    let (new_q, new_a) = bottom(&mut candidate.triangles.iter().map(|t| {
        let c = t.map(vertex);
        triangle_quality(c.map(|c| c.0), &((c[0].1 + c[1].1 + c[2].1) / 3.0))
    }));
    new_q >= old_q && new_a >= old_a && (new_q > old_q || new_a > old_a)
}

/// Per-face quality of the working mesh in the unscaled metric (what `eval` measures).
fn qualities(ctx: &RunContext<'_>, state: &LoopState) -> Vec<TriangleQuality> {
    face_qualities(&state.work.mesh, &state.vertex_metrics(ctx))
}

/// The Table-1 row of `qs` and its counts of small angles.
fn summary(qs: &[TriangleQuality]) -> AngleSummary {
    let stats = stats_of(qs);
    let below = |deg: f64| qs.iter().filter(|t| t.min_angle() < deg).count();
    AngleSummary {
        faces: stats.faces,
        q_min: stats.q_min,
        q_avg: stats.q_avg,
        theta_min: stats.theta_min,
        theta_avg: stats.theta_avg,
        below_10: below(10.0),
        below_20: below(20.0),
        below_25: below(25.0),
        below_30: below(30.0),
        hist_min_angles: stats.hist_min_angles,
    }
}
