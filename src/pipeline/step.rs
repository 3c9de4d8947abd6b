//! One patch of Algorithm 1: stages (b)–(e) for a disk patch, certified, with the retry
//! ladder around them.
//!
//! [`patch_step`] tries the patch; an attempt whose parameterization, planar remesh or lifted
//! faces fail their certificates is not accepted: the patch is shrunk (by the strategy,
//! [`crate::patches::PatchStrategy::shrink`]) to a smaller disk around an unprocessed face and
//! tried again, down to [`MIN_PATCH_FACES`], which are then kept as they are. Either way every
//! face that enters the working mesh is certified and the unprocessed count strictly
//! decreases (termination).

use super::chains::{self, PatchDomain};
use super::context::{Counters, LoopState, RunContext};
use super::debug::{write_candidate, write_debug};
use super::error::{PipelineError, Stage, StageError};
use super::records::{FailedAttempt, Fallbacks, PatchRecord};
use crate::fidelity::{self, PatchVertices, Refined, RoundOutput, RoundsSetup, VertexFactors};
use crate::ids::{FaceId, PatchId};
use crate::invariants::{self, InvariantError};
use crate::lift::{lift, DomainVertex, PatchFrame};
use crate::mesh::{PlanarDomain, Topology};
use crate::param::DistortionReport;
use crate::patches::{extract_patch, interior_corner, interior_feature, Patch, PatchMesh};
use crate::remesh2d::{
    pullback_corners, transfer_metric, PlanarMesh, PlanarMetricField, TransferMethod,
};
use crate::stitch::{Replacement, WorkingMesh};
use nalgebra::{Matrix2, Matrix3};
use rayon::prelude::*;
use std::time::Instant;

/// Smallest patch the retry ladder shrinks to before keeping the faces unchanged.
pub const MIN_PATCH_FACES: usize = 8;

/// What became of a patch.
pub enum PatchOutcome {
    /// Remeshed: replace `faces` by the certified candidate.
    Remeshed {
        /// The faces the candidate replaces (after any shrinking).
        faces: Vec<FaceId>,
        /// The certified candidate and the factors to keep.
        refined: Refined,
        /// Its record (retries filled in).
        record: PatchRecord,
    },
    /// Even the smallest attempt failed: `faces` stay as they are, marked processed.
    Kept {
        /// The kept faces.
        faces: Vec<FaceId>,
        /// Its record.
        record: PatchRecord,
    },
}

/// Stages (b)–(e) for every patch of a batch ([`super::RemeshOptions::batch`]), at the same
/// time (rayon): each patch reads the same working mesh and draws from its own RNG stream
/// ([`patch_rng`]), so the outcomes, returned in batch order, do not depend on the thread
/// count. With batches of one patch, `rng` (the strategy's stream) is drawn instead. The first error in batch order is the batch's.
pub fn batch_steps(
    ctx: &RunContext<'_>,
    state: &LoopState,
    batch: &[Patch],
    rng: &mut crate::Rng,
) -> Result<Vec<(PatchOutcome, StepLog)>, PipelineError> {
    if ctx.plan.options.batch == 1 {
        // One patch at a time: the run's one stream, drawn by the strategy and the remesher in
        // patch order (the paper's loop, and this crate's outputs before batches).
        let pid = PatchId::new(state.patches);
        return batch
            .iter()
            .map(|p| patch_step(ctx, state, pid, p, rng))
            .collect();
    }
    let step = |k: usize, patch: &Patch| {
        let slot = state.patches + k;
        let mut rng = patch_rng(ctx.plan.options.seed, state.streams + slot as u64);
        patch_step(ctx, state, PatchId::new(slot), patch, &mut rng)
    };
    let results: Vec<_> = match batch {
        [patch] => vec![step(0, patch)],
        _ => batch
            .par_iter()
            .enumerate()
            .map(|(k, p)| step(k, p))
            .collect(),
    };
    results.into_iter().collect()
}

/// The RNG of the patch in slot `slot` of the loop (its id before deferrals): stream
/// `slot + 1` of the run's seed (stream 0 is the patch strategy's).
pub fn patch_rng(seed: u64, slot: u64) -> crate::Rng {
    let mut rng = <crate::Rng as rand::SeedableRng>::seed_from_u64(seed);
    rng.set_stream(slot + 1);
    rng
}

/// What one patch's step did besides its outcome: its stage times and certificate counts and
/// its retry log, merged into the run's in patch order ([`StepLog::merge_into`]) so that a
/// batch's patches can run at the same time.
#[derive(Default)]
pub struct StepLog {
    /// Times and certificates of this patch's attempts.
    pub counters: Counters,
    /// Its failed attempts, shrinks and kept faces.
    pub fallbacks: Fallbacks,
}

impl StepLog {
    /// Add this log to the run's state.
    pub fn merge_into(self, state: &mut LoopState) {
        state.counters.absorb(self.counters);
        let f = &mut state.fallbacks;
        f.shrinks += self.fallbacks.shrinks;
        f.kept_faces += self.fallbacks.kept_faces;
        f.failures.extend(self.fallbacks.failures);
    }
}

/// One patch through stages (b)–(e) with the retry ladder (module docs). Reads the working
/// mesh and changes nothing in it (so the patches of a batch can run at the same time): what
/// it did goes into the returned [`StepLog`]. `pid` names the patch in records and errors.
pub fn patch_step(
    ctx: &RunContext<'_>,
    state: &LoopState,
    pid: PatchId,
    patch: &Patch,
    rng: &mut crate::Rng,
) -> Result<(PatchOutcome, StepLog), PipelineError> {
    let seed = patch.seed_vertex;
    let mut log = StepLog::default();
    let mut faces = patch.faces.clone();
    let mut outcome = loop {
        let unprocessed_in = faces.iter().filter(|&&f| !state.work.processed[f]).count();
        if unprocessed_in == 0 {
            return Err(PipelineError::NoProgress { patch: pid, seed });
        }
        certify_patch(ctx, state, &mut log.counters, pid, patch, &faces)?;
        let record =
            |faces_out: usize, kept: bool, distortion, fidelity_rounds: usize| PatchRecord {
                id: pid,
                seed,
                faces_in: faces.len(),
                unprocessed_in,
                faces_out,
                cone_angle_deg: patch.cone.filter(|_| !kept).map(|c| c.angle.to_degrees()),
                distortion,
                retries: 0,
                kept,
                fidelity_rounds,
            };
        let view = PatchView {
            work: &state.work,
            topo: &state.topo,
            near: state.near.as_ref(),
            factors: &state.factors,
            refine: !state.over_face_budget && !state.over_work_budget(),
        };
        log.counters.work += faces.len();
        match attempt(ctx, &view, &faces, rng, &mut log.counters) {
            Ok((refined, distortion)) => {
                log.counters.work += refined.replacement.triangles.len() * (1 + refined.rounds);
                let record = record(
                    refined.replacement.triangles.len(),
                    false,
                    distortion,
                    refined.rounds,
                );
                break PatchOutcome::Remeshed {
                    faces,
                    refined,
                    record,
                };
            }
            Err(failure) => {
                if ctx.plan.options.strict {
                    return Err(failure.into_error(ctx, pid, patch, &state.work, &faces));
                }
                log.fallbacks.failures.push(FailedAttempt {
                    patch: pid,
                    faces: faces.len(),
                    stage: failure.stage,
                    error: failure.error,
                });
                if faces.len() <= MIN_PATCH_FACES {
                    log.fallbacks.kept_faces += unprocessed_in;
                    let record = record(faces.len(), true, DistortionReport::default(), 0);
                    break PatchOutcome::Kept { faces, record };
                }
                log.fallbacks.shrinks += 1;
                let target = faces.len() / 2;
                faces = ctx.stages.patches.shrink(
                    &state.patch_context(ctx),
                    &faces,
                    patch.seed_face,
                    target,
                );
            }
        }
    };
    let retries = log.fallbacks.failures.len();
    match &mut outcome {
        PatchOutcome::Remeshed { record, .. } | PatchOutcome::Kept { record, .. } => {
            record.retries = retries
        }
    }
    Ok((outcome, log))
}

/// The strategy's contract on one attempt's faces: a disk (the hard certificate: a strategy
/// or a shrink that returns a non-disk is a bug, not a numerical accident), no corner vertex
/// and no feature edge inside.
fn certify_patch(
    ctx: &RunContext<'_>,
    state: &LoopState,
    counters: &mut Counters,
    pid: PatchId,
    patch: &Patch,
    faces: &[FaceId],
) -> Result<(), PipelineError> {
    let seed = patch.seed_vertex;
    let t0 = Instant::now();
    invariants::certify_disk(&state.work.mesh, faces).map_err(|e| PipelineError::Certificate {
        patch: pid,
        seed: Some(seed),
        violation: e,
        debug_file: write_debug(&ctx.plan.options, pid, "patch", &state.work.mesh, faces),
    })?;
    counters.cert.disk += 1;
    if let Some(vertex) =
        interior_corner(&state.work.mesh, &state.topo, faces, ctx.corners.as_slice())
    {
        return Err(PipelineError::CornerInterior {
            patch: pid,
            seed,
            vertex,
        });
    }
    if let Some(edge) = state
        .feature_edges()
        .and_then(|fe| interior_feature(&state.work.mesh, faces, fe))
    {
        return Err(PipelineError::FeatureInterior {
            patch: pid,
            seed,
            edge,
        });
    }
    counters.times.patches += t0.elapsed().as_secs_f64();
    Ok(())
}

/// The working mesh as one attempt reads it.
struct PatchView<'a> {
    work: &'a WorkingMesh,
    topo: &'a Topology,
    near: Option<&'a crate::invariants::NearFaces>,
    factors: &'a VertexFactors,
    /// The fidelity control may refine (false once the run is over its face budget).
    refine: bool,
}

/// A recoverable failure of one attempt: the stage, its error, and the lifted candidate when
/// that is what failed (written for inspection in strict runs).
struct AttemptFailure {
    stage: Stage,
    error: StageError,
    candidate: Option<Box<Replacement>>,
}

impl AttemptFailure {
    fn at(stage: Stage) -> impl Fn(StageError) -> AttemptFailure {
        move |error| AttemptFailure {
            stage,
            error,
            candidate: None,
        }
    }

    fn lifted(error: InvariantError, candidate: Replacement) -> AttemptFailure {
        AttemptFailure {
            stage: Stage::LiftedFaces,
            error: error.into(),
            candidate: Some(Box::new(candidate)),
        }
    }

    /// The hard error of a strict run, with the patch (and candidate) written for inspection.
    fn into_error(
        self,
        ctx: &RunContext<'_>,
        pid: PatchId,
        patch: &Patch,
        work: &WorkingMesh,
        faces: &[FaceId],
    ) -> PipelineError {
        let options = &ctx.plan.options;
        let what = self.stage.to_string();
        let patch_file = write_debug(options, pid, &what, &work.mesh, faces);
        let cand = self
            .candidate
            .as_ref()
            .and_then(|c| write_candidate(options, pid, work, c));
        let seed = patch.seed_vertex;
        match self.error {
            StageError::Certificate(violation) => PipelineError::Certificate {
                patch: pid,
                seed: Some(seed),
                violation,
                debug_file: cand.or(patch_file),
            },
            source => PipelineError::Stage {
                patch: pid,
                seed: Some(seed),
                stage: self.stage,
                source,
            },
        }
    }
}

/// Stages (b)–(e) of Algorithm 1 for one disk patch of the working mesh: parameterize
/// (certified bijective), transfer the metric (Eq. 4), remesh in 2D with the boundary fixed
/// (certified) and lift onto the reference surface, within the fidelity rounds; then certify
/// the new faces (none degenerate, flipped or intersecting).
fn attempt(
    ctx: &RunContext<'_>,
    view: &PatchView<'_>,
    faces: &[FaceId],
    rng: &mut crate::Rng,
    counters: &mut Counters,
) -> Result<(Refined, DistortionReport), AttemptFailure> {
    let disk = extract_patch(&view.work.mesh, faces)
        .map_err(|e| AttemptFailure::at(Stage::PatchExtraction)(e.into()))?;

    // (b) bijective parameterization, certified (the parameterizer certifies; we check again
    // because it is a research extension point).
    let t0 = Instant::now();
    let param = ctx
        .stages
        .parameterizer
        .parameterize(&disk.mesh, &disk.boundary)
        .map_err(|e| AttemptFailure::at(Stage::Parameterization)(e.into()))?;
    invariants::certify_bijective(&param.uv, &disk.mesh.triangles, &disk.boundary)
        .map_err(|e| AttemptFailure::at(Stage::Parameterization)(e.into()))?;
    counters.cert.bijective += 1;
    if param.report.fell_back {
        counters.cert.param_fallbacks += 1;
    }
    counters.times.param += t0.elapsed().as_secs_f64();

    // (c) metric transfer (Eq. 4): the 3D metric at each patch vertex's reference location,
    // carried to the plane.
    let t0 = Instant::now();
    let metrics3d = fidelity::patch_metrics(
        ctx.field(),
        &ctx.plan.fid_scale,
        view.factors,
        &disk.mesh,
        &disk.to_global,
        &view.work.locations,
    );
    let transfer = Transferred::new(ctx, &disk, &param.uv, &metrics3d)?;
    // The free boundary chains resampled on the input's curves, in the first round's metric.
    let round0 = transfer
        .field(
            &transfer.metrics,
            &transfer
                .metrics
                .iter()
                .map(|m| m.trace())
                .collect::<Vec<_>>(),
        )
        .map_err(AttemptFailure::at(Stage::MetricTransfer))?;
    let domain = chains::patch_domain(ctx, view.work, view.topo, &disk, &param.uv, &round0);
    counters.cert.chains += domain.chains;
    counters.times.transfer += t0.elapsed().as_secs_f64();

    // (d) planar remeshing with the patch boundary fixed, certified, and (e) mapping back,
    // repeated by the fidelity control while the lifted patch deviates from the reference.
    let refined = remesh_and_lift(ctx, view, &disk, &transfer, &domain, rng, counters)?;

    // The candidate's new faces, certified before the working mesh is touched.
    let t0 = Instant::now();
    let checked = invariants::certify_replacement(
        &ctx.flip_test,
        view.work,
        view.topo,
        faces,
        &refined.replacement,
    );
    counters.times.certify += t0.elapsed().as_secs_f64();
    if let Err(e) = checked {
        return Err(AttemptFailure::lifted(e, refined.replacement));
    }
    counters.cert.no_degenerate += 1;
    counters.cert.no_flips += 1;
    if ctx.embedded_input {
        let t0 = Instant::now();
        let checked = invariants::certify_candidate_embedded(
            view.work,
            view.topo,
            view.near,
            faces,
            &refined.replacement,
        );
        counters.times.certify += t0.elapsed().as_secs_f64();
        if let Err(e) = checked {
            return Err(AttemptFailure::lifted(e, refined.replacement));
        }
        counters.cert.locally_embedded += 1;
    }
    Ok((refined, param.report))
}

/// The patch in the plane: the parameterization as a planar domain, and the metric carried
/// onto it.
struct Transferred {
    /// The parameterization's points and triangles: the planar metric field lives on them.
    uv: Vec<nalgebra::Point2<f64>>,
    triangles: Vec<[u32; 3]>,
    metrics: Vec<Matrix2<f64>>,
    /// Per-triangle corner tensors ([`super::RemeshOptions::corner_pullback`]).
    corners: Option<Vec<[Matrix2<f64>; 3]>>,
}

impl Transferred {
    fn new(
        ctx: &RunContext<'_>,
        disk: &PatchMesh,
        uv: &[nalgebra::Point2<f64>],
        metrics3d: &[Matrix3<f64>],
    ) -> Result<Transferred, AttemptFailure> {
        let o = &ctx.plan.options;
        let fail = AttemptFailure::at(Stage::MetricTransfer);
        let metrics =
            transfer_metric(&disk.mesh, uv, metrics3d, o.transfer).map_err(|e| fail(e.into()))?;
        let corners = match o.corner_pullback && o.transfer == TransferMethod::JacobianPullback {
            true => Some(pullback_corners(&disk.mesh, uv, metrics3d).map_err(|e| fail(e.into()))?),
            false => None,
        };
        Ok(Transferred {
            uv: uv.to_vec(),
            triangles: disk.mesh.index_triangles(),
            metrics,
            corners,
        })
    }

    /// The planar metric field of one round: the (possibly scaled) vertex tensors and, with
    /// corner tensors, those scaled by the same factor (the ratio of traces).
    fn field(
        &self,
        metrics: &[Matrix2<f64>],
        base_trace: &[f64],
    ) -> Result<PlanarMetricField, StageError> {
        let field =
            PlanarMetricField::new(self.uv.clone(), self.triangles.clone(), metrics.to_vec())?;
        let Some(c) = &self.corners else {
            return Ok(field);
        };
        let factor: Vec<f64> = metrics
            .iter()
            .zip(base_trace)
            .map(|(m, b)| if *b > 0.0 { m.trace() / b } else { 1.0 })
            .collect();
        let scaled = c
            .iter()
            .zip(&self.triangles)
            .map(|(c, t)| [0, 1, 2].map(|k| c[k] * factor[t[k] as usize]))
            .collect();
        Ok(field.with_corner_metrics(scaled)?)
    }
}

/// Stages (d) and (e) inside the fidelity rounds ([`fidelity::refine`]): each round remeshes
/// the domain in the plane (certified) and lifts it by barycentric location in the initial 2D
/// mesh, projected onto the reference.
fn remesh_and_lift(
    ctx: &RunContext<'_>,
    view: &PatchView<'_>,
    disk: &PatchMesh,
    transfer: &Transferred,
    domain: &PatchDomain,
    rng: &mut crate::Rng,
    counters: &mut Counters,
) -> Result<Refined, AttemptFailure> {
    let field = ctx.field();
    let carried = view.factors;
    // Over the face budget the patch is remeshed once, in the metric it starts from (the
    // factors carried so far still apply): the run's size stops growing.
    let mut fidelity = ctx.plan.options.fidelity;
    if !view.refine {
        fidelity.rounds = 0;
    }
    let setup = RoundsSetup {
        options: &fidelity,
        field,
        normals: ctx.ref_normals.as_slice(),
        l_tar: ctx.plan.l_tar,
        min_edge: ctx.plan.min_edge,
    };
    let frame = PatchFrame {
        triangles: &disk.mesh.triangles,
        positions: &disk.mesh.positions,
        to_global: &disk.to_global,
        domain: &domain.vertices,
    };
    let base_trace: Vec<f64> = transfer.metrics.iter().map(|m| m.trace()).collect();
    let mut clock = 0.0;
    let refined = fidelity::refine(
        &setup,
        PatchVertices {
            to_global: &disk.to_global,
        },
        carried,
        transfer.metrics.clone(),
        &mut clock,
        |metrics, round| {
            let t0 = Instant::now();
            let planar_field = transfer
                .field(metrics, &base_trace)
                .map_err(AttemptFailure::at(Stage::MetricTransfer))?;
            // A patch whose metric asks for more faces than the whole run may have is refused
            // before any remesher refines it out of memory (an input of wildly mixed scales).
            let max = ctx.plan.patch_face_cap();
            let faces = crate::remesh2d::ideal_faces(&domain.domain, &planar_field, ctx.plan.l_tar);
            if faces > max {
                let e = crate::remesh2d::Remesh2dError::TooDense { faces, max };
                return Err(AttemptFailure::at(Stage::PlanarRemeshing)(e.into()));
            }
            let planar = ctx
                .stages
                .remesher
                .remesh_bounded(&domain.domain, &planar_field, ctx.plan.l_tar, max, rng)
                .map_err(|e| {
                    // The faces made before the cap stopped it are work the budget counts.
                    if let crate::remesh2d::Remesh2dError::TooDense { faces, .. } = e {
                        counters.work = counters.work.saturating_add(faces as usize);
                    }
                    AttemptFailure::at(Stage::PlanarRemeshing)(e.into())
                })?;
            invariants::certify_planar(&domain.domain, &planar)
                .map_err(|e| AttemptFailure::at(Stage::PlanarRemeshing)(e.into()))?;
            match round {
                0 => counters.cert.planar += 1,
                _ => counters.cert.planar_refined += 1,
            }
            counters.times.remesh2d += t0.elapsed().as_secs_f64();
            let t0 = Instant::now();
            let replacement = lift(
                &planar,
                &frame,
                |p| Some(planar_field.locate_or_nearest(p)),
                |p| field.project(p).0,
                field.reference(),
            )
            .map_err(|e| AttemptFailure::at(Stage::MappingBack)(e.into()))?;
            counters.times.lift += t0.elapsed().as_secs_f64();
            let (lifted, new_uv) = round_vertices(&planar, domain, &replacement);
            let kept = kept_vertices(&domain.domain, &planar);
            Ok(RoundOutput {
                lifted,
                new_uv,
                planar,
                kept,
                field: planar_field,
                replacement,
            })
        },
    );
    counters.times.fidelity += clock;
    refined
}

/// The 3D position of every planar vertex of a lifted round (a domain vertex's own position,
/// else the next new vertex of the replacement: new vertices are made in planar order, a
/// domain vertex on a curve included), and the plane position of every new vertex.
fn round_vertices(
    planar: &crate::mesh::PlanarMesh,
    domain: &PatchDomain,
    replacement: &Replacement,
) -> (Vec<nalgebra::Point3<f64>>, Vec<nalgebra::Point2<f64>>) {
    let mut new_uv = Vec::with_capacity(replacement.new_positions.len());
    let lifted = planar
        .origin
        .iter()
        .zip(&planar.points)
        .map(|(origin, p)| match origin {
            Some(i) => {
                if matches!(domain.vertices[*i as usize], DomainVertex::Curve { .. }) {
                    new_uv.push(*p);
                }
                domain.positions[*i as usize]
            }
            None => {
                new_uv.push(*p);
                replacement.new_positions[new_uv.len() - 1]
            }
        })
        .collect();
    (lifted, new_uv)
}

/// The planar vertices that are kept boundary or constrained vertices of `domain` (what no
/// remesh of it can move).
fn kept_vertices(domain: &PlanarDomain, planar: &PlanarMesh) -> Vec<bool> {
    let mut kept = vec![false; domain.points.len()];
    for &b in domain
        .boundary
        .iter()
        .chain(domain.constrained_edges.iter().flatten())
    {
        kept[b as usize] = true;
    }
    planar
        .origin
        .iter()
        .map(|o| o.is_some_and(|i| kept[i as usize]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point2;

    #[test]
    fn only_boundary_and_constrained_vertices_are_kept() {
        // A square with two interior vertices, one of them on a constrained chord from corner 0.
        let domain = PlanarDomain {
            points: vec![
                Point2::new(0.0, 0.0),
                Point2::new(1.0, 0.0),
                Point2::new(1.0, 1.0),
                Point2::new(0.0, 1.0),
                Point2::new(0.5, 0.5),
                Point2::new(0.7, 0.3),
            ],
            triangles: Vec::new(),
            boundary: vec![0, 1, 2, 3],
            constrained_edges: vec![[0, 4]],
        };
        // The remesh keeps every input vertex (an interior one the remesher did not move keeps
        // its origin too) and adds one.
        let planar = PlanarMesh {
            points: Vec::new(),
            triangles: Vec::new(),
            origin: vec![Some(3), Some(5), Some(4), None, Some(0), Some(1), Some(2)],
        };
        assert_eq!(
            kept_vertices(&domain, &planar),
            vec![true, false, true, false, true, true, true]
        );
    }
}
