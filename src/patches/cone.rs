//! The paper's strategy (Sec. 3.2 + 4.2): cone patches.
//!
//! Seed vertex: the first is drawn with the RNG among the vertices of unprocessed faces;
//! later ones on the boundary of the processed region (a vertex shared by a processed and an
//! unprocessed face, Sec. 4.2), drawn with the RNG among those, in id order. The cone is
//! fitted to the seed's whole 1-ring (Eq. 2); the seed triangle s_P is the *unprocessed*
//! 1-ring face of least E (so every patch contains an unprocessed face, which the loop of
//! Algorithm 1 needs to terminate). Growth starts from s_P alone (the 1-ring may not be a
//! disk, or may be partly processed), through unprocessed faces (Eq. 3, `grow.rs`); the cone
//! is then refitted to the grown patch and growth resumed (`ConeOptions::refit_rounds`);
//! finally the patch expands into processed faces (`expand.rs`). `Patch::cone` is the cone
//! of the last growth round that added faces.

use super::cone_fit::{fit_cone, least_error_face};
use super::expand::expand_rings;
use super::grow::{grow_patch, DiskPatch};
use super::growth_cost::ConeOptions;
use super::{Cone, Patch, PatchContext, PatchError, PatchStrategy};
use crate::ids::{FaceId, VertexId};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// The next seed vertex (see module docs), or `None` when every face is processed.
///
/// One pass over the faces marks, per vertex, whether it has an unprocessed unblocked face
/// (free), a processed face (on the front when also free) and a blocked face; the candidates
/// are then read in id order, so no list of the mesh's size is sorted for every patch.
pub fn pick_seed_vertex(ctx: &PatchContext<'_>, rng: &mut ChaCha8Rng) -> Option<VertexId> {
    const FREE: u8 = 1;
    const BY_PROCESSED: u8 = 2;
    const BY_BLOCKED: u8 = 4;
    let mesh = ctx.mesh;
    let processed = |f: FaceId| ctx.processed.get(f.idx()).copied().unwrap_or(false);
    let mut mark = vec![0u8; mesh.n_vertices()];
    let mut any_processed = false;
    for f in mesh.faces() {
        let (done, blocked) = (processed(f), ctx.is_blocked(f));
        any_processed |= done;
        let bit = match (done, blocked) {
            (true, true) => BY_PROCESSED | BY_BLOCKED,
            (true, false) => BY_PROCESSED,
            (false, true) => BY_BLOCKED,
            (false, false) => FREE,
        };
        for v in mesh.face(f) {
            mark[v.idx()] |= bit;
        }
    }
    // A seed next to another patch of the batch could only start a patch inside its margin.
    let free = |m: u8| m & FREE != 0 && (ctx.blocked.is_none() || m & BY_BLOCKED == 0);
    let pick = |want: u8| -> Vec<VertexId> {
        mark.iter()
            .enumerate()
            .filter(|&(_, &m)| free(m) && m & want == want)
            .map(|(v, _)| VertexId::new(v))
            .collect()
    };
    let mut candidates = match any_processed {
        true => pick(BY_PROCESSED),
        false => Vec::new(),
    };
    // Processed and unprocessed regions may not touch (another component): fall back.
    if candidates.is_empty() {
        candidates = pick(0);
    }
    if candidates.is_empty() {
        return None;
    }
    Some(candidates[rng.random_range(0..candidates.len())])
}

/// The seed vertex's unprocessed 1-ring faces, sorted.
pub fn unprocessed_ring(ctx: &PatchContext<'_>, v: VertexId) -> Vec<FaceId> {
    let mut ring: Vec<FaceId> = ctx
        .topology
        .vertex_faces(v)
        .iter()
        .copied()
        .filter(|f| !ctx.processed.get(f.idx()).copied().unwrap_or(true) && !ctx.is_blocked(*f))
        .collect();
    ring.sort_unstable();
    ring
}

/// Turn a grown disk into a certified [`Patch`] (the last step of a strategy's
/// [`PatchStrategy::next_patch`]): its faces sorted, its boundary loop certified as a disk's,
/// and the seed, cone and growth cost as given.
pub fn finish_patch(
    disk: &DiskPatch<'_, '_>,
    ctx: &PatchContext<'_>,
    seed_vertex: VertexId,
    seed_face: FaceId,
    cone: Option<Cone>,
    max_growth_cost: Option<f64>,
) -> Result<Patch, PatchError> {
    finish_faces(
        disk.sorted_faces(),
        ctx,
        seed_vertex,
        seed_face,
        cone,
        max_growth_cost,
    )
}

/// [`finish_patch`] of a face set (sorted).
fn finish_faces(
    faces: Vec<FaceId>,
    ctx: &PatchContext<'_>,
    seed_vertex: VertexId,
    seed_face: FaceId,
    cone: Option<Cone>,
    max_growth_cost: Option<f64>,
) -> Result<Patch, PatchError> {
    let boundary = crate::invariants::certify_disk(ctx.mesh, &faces).map_err(|source| {
        PatchError::NotCertified {
            patch: None,
            seed: seed_vertex,
            source,
        }
    })?;
    Ok(Patch {
        faces,
        boundary,
        seed_vertex,
        seed_face,
        cone,
        max_growth_cost,
    })
}

/// Cone patches (the paper, Sec. 3.2): name `cone`, the default strategy.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConePatches {
    /// Growth and expansion options.
    pub options: ConeOptions,
}

impl PatchStrategy for ConePatches {
    fn name(&self) -> &'static str {
        "cone"
    }

    /// The same options with `rings` expansion rings, and no trimming of ragged expansions:
    /// the trim is for Algorithm 1's combs of needles (paper-notes "Ragged expansions");
    /// Algorithm 2's patches keep the rings around their bad faces whole, as they were
    /// measured (paper-notes Sec. 3.4).
    fn widened(&self, rings: usize) -> Option<Box<dyn PatchStrategy>> {
        Some(Box::new(ConePatches {
            options: ConeOptions {
                expand_rings: rings,
                trim_ragged: false,
                ..self.options.clone()
            },
        }))
    }

    fn next_patch(
        &self,
        ctx: &PatchContext<'_>,
        rng: &mut ChaCha8Rng,
    ) -> Result<Option<Patch>, PatchError> {
        let Some(seed_vertex) = pick_seed_vertex(ctx, rng) else {
            return Ok(None);
        };
        // Eq. 2 on the full 1-ring Ω_f.
        let mut omega: Vec<FaceId> = ctx.topology.vertex_faces(seed_vertex).to_vec();
        omega.sort_unstable();
        let cone = fit_cone(ctx.mesh, &omega);
        let candidates = unprocessed_ring(ctx, seed_vertex);
        let Some(seed_face) = least_error_face(ctx.mesh, &cone, &candidates) else {
            return Err(PatchError::SeedWithoutFace { seed: seed_vertex });
        };
        let mut grown = grow_patch(ctx, seed_face, &cone, &self.options);
        let mut cone = cone;
        for _ in 0..self.options.refit_rounds {
            if grown.patch.len() < 3 {
                break;
            }
            let refit = fit_cone(ctx.mesh, grown.patch.faces());
            if grown.grow(&refit, &self.options) == 0 {
                break;
            }
            cone = refit;
        }
        let max_cost = grown.max_cost();
        expand_rings(&mut grown.patch, ctx.processed, self.options.expand_rings);
        let faces = match self.options.trim_ragged {
            true => super::expand::trim_ragged(ctx, grown.patch.sorted_faces()),
            false => grown.patch.sorted_faces(),
        };
        finish_faces(
            faces,
            ctx,
            seed_vertex,
            seed_face,
            Some(cone),
            Some(max_cost),
        )
        .map(Some)
    }
}
