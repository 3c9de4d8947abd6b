//! Algorithm 1, step (e) "replace P, and update the mesh M": stitching a remeshed patch into
//! the working mesh (or keeping a failed one's faces), then certifying the working mesh.

use super::context::{a_priori_at, LoopState, RunContext};
use super::debug::write_debug;
use super::error::{PipelineError, Stage, StageError};
use super::records::{FailedAttempt, PatchRecord};
use super::step::{PatchOutcome, StepLog};
use crate::fidelity::Refined;
use crate::ids::{FaceId, PatchId, VertexId};
use crate::invariants::{self, InvariantError, TopologySignature};
use crate::stitch::{stitch_all, Replacement};
use std::time::Instant;

/// Apply one patch's outcome (a batch of one, [`replace_batch`]).
pub fn replace_patch(
    ctx: &RunContext<'_>,
    state: &mut LoopState,
    outcome: PatchOutcome,
    log: StepLog,
) -> Result<(), PipelineError> {
    replace_batch(ctx, state, vec![(outcome, log)])
}

/// Apply the outcomes of a batch's patches (vertex-disjoint, made on the same working mesh, in
/// batch order) and certify the result: edge- and vertex-manifold (at the vertices whose fans
/// changed; the input was certified whole before the loop), consistently oriented, the
/// input's topology and boundary. A violation is a hard error: it is a bug, not a numerical
/// accident. The patches share no vertex, so no fan is changed by two of them and the
/// certificate of the stitched batch is the certificate after each of its patches; only their
/// new faces could meet each other in space (two sheets close together), which is checked
/// (exact) first: a patch whose new faces cross an earlier one's is deferred (its faces stay
/// unprocessed, for a later batch) and its failure recorded under the id the next patch takes.
pub fn replace_batch(
    ctx: &RunContext<'_>,
    state: &mut LoopState,
    outcomes: Vec<(PatchOutcome, StepLog)>,
) -> Result<(), PipelineError> {
    let (crossing, deferred) = deferred_patches(ctx, state, &outcomes);
    let Numbered {
        remeshed,
        kept_faces,
        records,
    } = number_patches(state, outcomes, &crossing, &deferred);
    for f in &kept_faces {
        state.work.processed[*f] = true;
    }
    let t0 = Instant::now();
    // Vertices of the faces the patches remove (their boundaries and interiors): with the
    // new faces' vertices, every vertex whose fan changed.
    let mut touched: Vec<VertexId> = remeshed
        .iter()
        .flat_map(|r| &r.1)
        .filter(|f| f.idx() < state.work.mesh.n_faces())
        .flat_map(|f| state.work.mesh.triangles[f.idx()])
        .collect();
    let new_faces = stitch_batch(state, &remeshed)?;
    state.counters.times.stitch += t0.elapsed().as_secs_f64();
    let gone: Vec<FaceId> = remeshed.iter().flat_map(|r| r.1.iter().copied()).collect();
    follow_stitched(ctx, state, remeshed, &gone, &new_faces)?;
    debug_assert!(
        state.in_step(),
        "the per-element state follows the working mesh"
    );
    // The stitched faces join the face index (the kept ones are listed already).
    if let Some(near) = &mut state.near {
        near.insert(&state.work.mesh, new_faces.iter().flatten().copied());
    }
    let all_new: Vec<FaceId> = new_faces.into_iter().flatten().chain(kept_faces).collect();
    touched.extend(
        all_new
            .iter()
            .filter(|f| f.idx() < state.work.mesh.n_faces())
            .flat_map(|f| state.work.mesh.triangles[f.idx()]),
    );
    if let Some(first) = records.first() {
        let (pid, seed) = (first.id, first.seed);
        let batch = Batch {
            pid,
            seed,
            patches: records.len(),
            removed: &gone,
            new_faces: &all_new,
        };
        certify_after_batch(ctx, state, batch, touched)?;
    }
    state.patches += records.len();
    state.records.extend(records);
    Ok(())
}

/// A patch stitched in: its id, the faces it removes, its refined replacement, its seed.
type Remeshed = (PatchId, Vec<FaceId>, Refined, VertexId);

/// The batch's patches under their ids.
struct Numbered {
    /// The remeshed patches to stitch, in batch order.
    remeshed: Vec<Remeshed>,
    /// The faces of the patches kept as they were.
    kept_faces: Vec<FaceId>,
    /// One record per patch not deferred.
    records: Vec<PatchRecord>,
}

/// The pairs of patches (batch indices) whose new faces may cross, checked only for an
/// embedded input, and which patches are deferred: in order, a patch is deferred when it
/// crosses an accepted earlier one.
fn deferred_patches(
    ctx: &RunContext<'_>,
    state: &mut LoopState,
    outcomes: &[(PatchOutcome, StepLog)],
) -> (Vec<(usize, usize)>, Vec<bool>) {
    let crossing = match ctx.embedded_input {
        true => {
            let candidates: Vec<(usize, &Replacement)> = outcomes
                .iter()
                .enumerate()
                .filter_map(|(k, (o, _))| match o {
                    PatchOutcome::Remeshed { refined, .. } => Some((k, &refined.replacement)),
                    PatchOutcome::Kept { .. } => None,
                })
                .collect();
            let t0 = Instant::now();
            let only: Vec<&Replacement> = candidates.iter().map(|c| c.1).collect();
            let pairs = invariants::crossing_candidates(&state.work, &only);
            state.counters.times.certify += t0.elapsed().as_secs_f64();
            pairs
                .into_iter()
                .map(|(j, k)| (candidates[j].0, candidates[k].0))
                .collect()
        }
        false => Vec::new(),
    };
    let mut deferred = vec![false; outcomes.len()];
    for &(j, k) in &crossing {
        if !deferred[j] {
            deferred[k] = true;
        }
    }
    (crossing, deferred)
}

/// The patches numbered in batch order (deferred ones record their failure under the id the
/// next patch takes), their logs merged into the run's.
fn number_patches(
    state: &mut LoopState,
    outcomes: Vec<(PatchOutcome, StepLog)>,
    crossing: &[(usize, usize)],
    deferred: &[bool],
) -> Numbered {
    let first_id = state.patches;
    let mut remeshed: Vec<Remeshed> = Vec::new();
    let mut kept_faces: Vec<FaceId> = Vec::new();
    let mut records = Vec::new();
    for (k, (outcome, mut log)) in outcomes.into_iter().enumerate() {
        let pid = PatchId::new(first_id + records.len());
        for f in &mut log.fallbacks.failures {
            f.patch = pid;
        }
        if deferred[k] {
            let with = crossing.iter().find(|c| c.1 == k && !deferred[c.0]);
            log.fallbacks.failures.push(FailedAttempt {
                patch: pid,
                faces: match &outcome {
                    PatchOutcome::Remeshed { faces, .. } | PatchOutcome::Kept { faces, .. } => {
                        faces.len()
                    }
                },
                stage: Stage::LiftedFaces,
                error: StageError::Deferred {
                    earlier: with.map_or(0, |c| c.0),
                },
            });
            log.merge_into(state);
            continue;
        }
        log.merge_into(state);
        match outcome {
            PatchOutcome::Remeshed {
                faces,
                refined,
                mut record,
            } => {
                record.id = pid;
                remeshed.push((pid, faces, refined, record.seed));
                records.push(record);
            }
            PatchOutcome::Kept { faces, mut record } => {
                record.id = pid;
                records.push(record);
                kept_faces.extend_from_slice(&faces);
            }
        }
    }
    Numbered {
        remeshed,
        kept_faces,
        records,
    }
}

/// Stitch the remeshed patches into the working mesh; the new faces of each. A failure
/// names the batch's first patch.
fn stitch_batch(
    state: &mut LoopState,
    remeshed: &[Remeshed],
) -> Result<Vec<Vec<FaceId>>, PipelineError> {
    let batch: Vec<(&[FaceId], &Replacement)> = remeshed
        .iter()
        .map(|r| (r.1.as_slice(), &r.2.replacement))
        .collect();
    let stitched = stitch_all(&mut state.work, &batch);
    stitched.map_err(|e| {
        let r = &remeshed[0];
        PipelineError::Stage {
            patch: r.0,
            seed: Some(r.3),
            stage: Stage::Stitching,
            source: e.into(),
        }
    })
}

/// The loop's per-vertex and per-face state follows the stitched patches, the one place it
/// does ([`stitch_all`] updates the working mesh's own): the `removed` faces' entries go, the
/// others keep their order; each new vertex gets its a-priori fidelity bound and factor, each
/// new face its patch. A new per-element field of [`LoopState`] follows here, and joins
/// [`LoopState::in_step`].
fn follow_stitched(
    ctx: &RunContext<'_>,
    state: &mut LoopState,
    remeshed: Vec<Remeshed>,
    removed: &[FaceId],
    new_faces: &[Vec<FaceId>],
) -> Result<(), PipelineError> {
    let mut gone = vec![false; state.face_patch.len()];
    for f in removed {
        gone[f.idx()] = true;
    }
    state.face_patch.drop_marked(&gone);
    let reference = ctx.quality_field.reference();
    let mut n = state.work.mesh.n_vertices()
        - remeshed
            .iter()
            .map(|r| r.2.replacement.new_positions.len())
            .sum::<usize>();
    for ((pid, _, refined, seed), faces) in remeshed.into_iter().zip(new_faces) {
        n += refined.replacement.new_positions.len();
        for (k, loc) in refined.replacement.new_locations.iter().enumerate() {
            let rounds = refined.factors.new.get(k).copied().unwrap_or(1.0);
            state
                .bound
                .push(a_priori_at(&ctx.plan.fid_scale, reference, loc) * rounds);
            // New vertices are not pinned: corners and feature-line vertices are never
            // inside a patch.
            state.pinned.push(false);
        }
        state
            .factors
            .absorb(refined.factors, ctx.plan.options.fidelity.persist, n)
            .map_err(|(factors, vertices)| PipelineError::Stage {
                patch: pid,
                seed: Some(seed),
                stage: Stage::FidelityFactors,
                source: StageError::FactorCount { factors, vertices },
            })?;
        state.face_patch.extend(faces.iter().map(|_| Some(pid)));
    }
    Ok(())
}

/// What a stitched batch changed, for its certificates.
struct Batch<'a> {
    /// The batch's first patch and its seed (an error names them).
    pid: PatchId,
    seed: VertexId,
    patches: usize,
    /// The faces the patches removed (ids before stitching) and the new ones (after).
    removed: &'a [FaceId],
    new_faces: &'a [FaceId],
}

/// The working-mesh certificates after a batch (see [`replace_batch`]); an error names the
/// batch's first patch.
fn certify_after_batch(
    ctx: &RunContext<'_>,
    state: &mut LoopState,
    batch: Batch<'_>,
    mut touched: Vec<VertexId>,
) -> Result<(), PipelineError> {
    let t0 = Instant::now();
    let Batch {
        pid,
        seed,
        patches,
        removed,
        new_faces,
    } = batch;
    // Only the removed and new faces' edges are looked at again (equal to a build from
    // scratch, checked in debug builds); a batch that only kept faces changed nothing.
    if !removed.is_empty() {
        state.topo = state.topo.after_replacing(&state.work.mesh, removed);
    }
    let (work, topo) = (&state.work, &state.topo);
    let fail = |e: InvariantError| PipelineError::Certificate {
        patch: pid,
        seed: Some(seed),
        violation: e,
        debug_file: write_debug(&ctx.plan.options, pid, "stitched", &work.mesh, new_faces),
    };
    // Local: only the touched vertices' fans changed (`certify_manifold_at`); the whole mesh
    // again after the loop.
    touched.sort_unstable();
    touched.dedup();
    invariants::certify_manifold_at(&work.mesh, topo, &touched).map_err(fail)?;
    debug_assert!(
        invariants::certify_manifold(&work.mesh, topo).is_ok(),
        "{pid}: the local manifold certificate passed, the whole-mesh one fails"
    );
    let cert = &mut state.counters.cert;
    cert.manifold += patches;
    invariants::certify_oriented(&work.mesh, topo).map_err(fail)?;
    cert.oriented += patches;
    ctx.signature
        .certify_same(&TopologySignature::of(topo))
        .map_err(fail)?;
    cert.same_topology += patches;
    certify_boundary(ctx, state).map_err(fail)?;
    state.counters.cert.boundary_preserved += patches;
    state.counters.times.certify += t0.elapsed().as_secs_f64();
    Ok(())
}

/// The boundary of the working mesh lies on the input's boundary curves, once around each,
/// every corner kept ([`invariants::certify_boundary_on_curves`]); without resampling also
/// the input's boundary vertices and edges, bit for bit.
pub fn certify_boundary(ctx: &RunContext<'_>, state: &LoopState) -> Result<(), InvariantError> {
    if let Some(cut) = &ctx.frozen {
        return certify_region_boundary(ctx, cut, state);
    }
    if ctx.input_boundary.is_empty() {
        return Ok(());
    }
    let reference = ctx.quality_field.reference();
    invariants::certify_boundary_on_curves(
        &ctx.curves,
        reference,
        &state.work.mesh,
        &state.topo,
        state.work.curve.as_slice(),
    )?;
    if ctx.plan.options.boundary.resample {
        return Ok(());
    }
    invariants::certify_boundary_kept(
        reference,
        &ctx.input_boundary,
        &state.work.mesh,
        &invariants::boundary_edges(&state.topo),
    )
}

/// A region's boundary after a patch or a pass: every cut edge still a boundary edge with
/// its vertices where they were (bit for bit), and every other boundary vertex exactly on the
/// input's boundary curves. (Once around each curve, with its corners, is the whole mesh's
/// certificate after the merge.)
fn certify_region_boundary(
    ctx: &RunContext<'_>,
    cut: &super::context::FrozenCut,
    state: &LoopState,
) -> Result<(), InvariantError> {
    let mesh = &state.work.mesh;
    let boundary = invariants::boundary_edges(&state.topo);
    let missing: Vec<crate::ids::EdgeKey> = cut
        .edges
        .iter()
        .copied()
        .filter(|e| boundary.binary_search(e).is_err())
        .collect();
    if !missing.is_empty() {
        return Err(InvariantError::BoundaryEdgesMissing(invariants::Offenders(
            missing,
        )));
    }
    let moved: Vec<VertexId> = (0..cut.vertices.len())
        .filter(|&v| cut.vertices[v] && mesh.positions[v] != cut.positions[v])
        .map(VertexId::new)
        .collect();
    if !moved.is_empty() {
        return Err(InvariantError::BoundaryVerticesMoved(
            invariants::Offenders(moved),
        ));
    }
    let reference = ctx.quality_field.reference();
    let mut off: Vec<VertexId> = boundary
        .iter()
        .filter(|e| !cut.is_cut_edge(e.0, e.1))
        .flat_map(|e| [e.0, e.1])
        .filter(|&v| match state.work.curve.get(v).copied().flatten() {
            Some(p) => {
                p.curve as usize >= ctx.curves.len()
                    || ctx.curves.position(reference, &p) != mesh.positions[v.idx()]
            }
            None => true,
        })
        .collect();
    off.sort_unstable();
    off.dedup();
    match off.is_empty() {
        true => Ok(()),
        false => Err(InvariantError::BoundaryOffCurve(invariants::Offenders(off))),
    }
}
