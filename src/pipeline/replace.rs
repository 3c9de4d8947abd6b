//! Algorithm 1, step (e) "replace P, and update the mesh M": stitching a remeshed patch into
//! the working mesh (or keeping a failed one's faces), then certifying the working mesh.

use super::context::{a_priori_at, LoopState, RunContext};
use super::debug::write_debug;
use super::error::{PipelineError, Stage, StageError};
use super::step::PatchOutcome;
use crate::ids::{FaceId, PatchId, VertexId};
use crate::invariants::{self, InvariantError, TopologySignature};
use crate::mesh::Topology;
use crate::stitch::stitch;
use std::time::Instant;

/// Apply a patch's outcome to the working mesh and certify it: edge- and vertex-manifold
/// (at the vertices whose fans changed; the input was certified whole before the loop),
/// consistently oriented, the input's topology and boundary. A violation is a hard error: it
/// is a bug, not a numerical accident.
pub fn replace_patch(
    ctx: &RunContext<'_>,
    state: &mut LoopState,
    outcome: PatchOutcome,
) -> Result<(), PipelineError> {
    let pid = PatchId::new(state.patches);
    let (new_faces, record, touched) = match outcome {
        PatchOutcome::Remeshed {
            faces,
            refined,
            record,
        } => {
            let seed = record.seed;
            let stage_error = |stage, source| PipelineError::Stage {
                patch: pid,
                seed: Some(seed),
                stage,
                source,
            };
            let t0 = Instant::now();
            // Vertices of the faces the patch removes (its boundary and interior): with the
            // new faces' vertices, every vertex whose fan changed.
            let touched: Vec<VertexId> = faces
                .iter()
                .filter(|f| f.idx() < state.work.mesh.n_faces())
                .flat_map(|f| state.work.mesh.triangles[f.idx()])
                .collect();
            let new_faces = stitch(&mut state.work, &faces, &refined.replacement)
                .map_err(|e| stage_error(Stage::Stitching, e.into()))?;
            state.counters.times.stitch += t0.elapsed().as_secs_f64();
            let n = state.work.mesh.n_vertices();
            let reference = ctx.quality_field.reference();
            let first_new = n - refined.replacement.new_positions.len();
            for (k, loc) in refined.replacement.new_locations.iter().enumerate() {
                let rounds = refined.factors.new.get(k).copied().unwrap_or(1.0);
                state
                    .bound
                    .push(a_priori_at(&ctx.plan.fid_scale, reference, loc) * rounds);
            }
            debug_assert_eq!(
                state.bound.len(),
                first_new + refined.replacement.new_locations.len()
            );
            state
                .factors
                .absorb(refined.factors, ctx.plan.options.fidelity.persist, n)
                .map_err(|(factors, vertices)| {
                    stage_error(
                        Stage::FidelityFactors,
                        StageError::FactorCount { factors, vertices },
                    )
                })?;
            follow_provenance(
                &mut state.face_patch,
                &faces,
                state.work.mesh.n_faces(),
                pid,
            );
            (new_faces, record, touched)
        }
        PatchOutcome::Kept { faces, record } => {
            for f in &faces {
                state.work.processed[f.idx()] = true;
            }
            (faces, record, Vec::new())
        }
    };
    certify_after_patch(ctx, state, pid, record.seed, &new_faces, touched)?;
    state.records.push(record);
    state.patches += 1;
    Ok(())
}

/// `stitch` drops the patch's faces in order and appends the new ones: the provenance of
/// every face follows.
fn follow_provenance(
    face_patch: &mut Vec<Option<PatchId>>,
    removed: &[FaceId],
    n_faces: usize,
    pid: PatchId,
) {
    let mut gone = vec![false; face_patch.len()];
    for f in removed {
        gone[f.idx()] = true;
    }
    let mut k = 0;
    face_patch.retain(|_| {
        k += 1;
        !gone[k - 1]
    });
    face_patch.resize(n_faces, Some(pid));
}

/// The working-mesh certificates after a patch (see [`replace_patch`]).
fn certify_after_patch(
    ctx: &RunContext<'_>,
    state: &mut LoopState,
    pid: PatchId,
    seed: VertexId,
    new_faces: &[FaceId],
    mut touched: Vec<VertexId>,
) -> Result<(), PipelineError> {
    let t0 = Instant::now();
    state.topo = Topology::build(&state.work.mesh);
    let (work, topo) = (&state.work, &state.topo);
    let fail = |e: InvariantError| PipelineError::Certificate {
        patch: pid,
        seed: Some(seed),
        violation: e,
        debug_file: write_debug(&ctx.plan.options, pid, "stitched", &work.mesh, new_faces),
    };
    // Local: only the touched vertices' fans changed (`certify_manifold_at`); the whole mesh
    // again after the loop.
    touched.extend(
        new_faces
            .iter()
            .filter(|f| f.idx() < work.mesh.n_faces())
            .flat_map(|f| work.mesh.triangles[f.idx()]),
    );
    touched.sort_unstable();
    touched.dedup();
    invariants::certify_manifold_at(&work.mesh, topo, &touched).map_err(fail)?;
    debug_assert!(
        invariants::certify_manifold(&work.mesh, topo).is_ok(),
        "{pid}: the local manifold certificate passed, the whole-mesh one fails"
    );
    let cert = &mut state.counters.cert;
    cert.manifold += 1;
    invariants::certify_oriented(&work.mesh, topo).map_err(fail)?;
    cert.oriented += 1;
    ctx.signature
        .certify_same(&TopologySignature::of(topo))
        .map_err(fail)?;
    cert.same_topology += 1;
    certify_boundary(ctx, state).map_err(fail)?;
    state.counters.cert.boundary_preserved += 1;
    state.counters.times.certify += t0.elapsed().as_secs_f64();
    Ok(())
}

/// The boundary of the working mesh lies on the input's boundary curves, once around each,
/// every corner kept ([`invariants::certify_boundary_on_curves`]); without resampling also
/// the input's boundary vertices and edges, bit for bit.
pub fn certify_boundary(ctx: &RunContext<'_>, state: &LoopState) -> Result<(), InvariantError> {
    if ctx.input_boundary.is_empty() {
        return Ok(());
    }
    let reference = ctx.quality_field.reference();
    invariants::certify_boundary_on_curves(
        &ctx.curves,
        reference,
        &state.work.mesh,
        &state.topo,
        &state.work.curve,
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
