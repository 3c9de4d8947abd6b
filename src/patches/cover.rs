//! The covering run of `conemesh patches`: Algorithm 1's patch loop without remeshing.
//!
//! Patches are generated until every face is in some patch; each patch is certified a disk
//! and all its faces become processed (as they would after remeshing). Every patch must
//! contain an unprocessed face, so the run ends after at most F patches.

use super::cone_fit::{cone_objective, face_cone_error, fit_cone};
use super::{Patch, PatchContext, PatchError, PatchStrategy};
use crate::ids::{EdgeKey, PatchId};
use crate::mesh::{Topology, TriMesh};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use std::collections::HashSet;

/// Options of [`cover`].
#[derive(Clone, Debug, Default)]
pub struct CoverOptions {
    /// Edges no patch may contain in its interior (feature lines). Default none.
    pub feature_edges: Option<HashSet<EdgeKey>>,
    /// Stop after this many patches (`None`: until covered). Default `None`.
    pub max_patches: Option<usize>,
    /// Vertices no patch may contain in its interior ([`super::corner_vertices`]). Default
    /// none.
    pub corners: Option<Vec<bool>>,
}

/// Statistics of one patch.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PatchStats {
    /// The patch.
    pub patch: PatchId,
    /// Number of faces.
    pub faces: usize,
    /// Faces that were unprocessed before this patch (the rest is overlap).
    pub new_faces: usize,
    /// Boundary loop length in vertices.
    pub boundary_vertices: usize,
    /// Area (mesh units).
    pub area: f64,
    /// Angle α_P of the patch's cone, degrees (strategies with a cone).
    pub cone_angle_deg: Option<f64>,
    /// Largest Eq. 1 error E(P, t) over the patch's faces, with the patch's cone.
    pub max_e: Option<f64>,
    /// Developability: the Eq. 2 objective `(1/A_P) Σ A_t E` of the cone refitted to the
    /// whole patch (0 for a piece of a cone or cylinder).
    pub developability: f64,
    /// Largest Eq. 3 cost of a face added by growth (strategies growing by cost).
    pub max_growth_cost: Option<f64>,
}

/// The result of a covering run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CoverRun {
    /// The strategy's name.
    pub strategy: String,
    /// The patches in order of creation.
    pub patches: Vec<Patch>,
    /// Their statistics (parallel to `patches`).
    pub stats: Vec<PatchStats>,
    /// For every face, the first patch that contained it.
    pub patch_of_face: Vec<Option<PatchId>>,
    /// True when every face is covered.
    pub complete: bool,
}

/// Cover `mesh` with patches of `strategy` (see module docs); randomness from `rng` only.
pub fn cover(
    mesh: &TriMesh,
    strategy: &dyn PatchStrategy,
    opts: &CoverOptions,
    rng: &mut ChaCha8Rng,
) -> Result<CoverRun, PatchError> {
    mesh.validate()?;
    let topology = Topology::build(mesh);
    let nf = mesh.n_faces();
    let mut processed = vec![false; nf];
    let mut patch_of_face: Vec<Option<PatchId>> = vec![None; nf];
    let mut remaining = nf;
    let mut patches = Vec::new();
    let mut stats = Vec::new();
    let limit = opts.max_patches.unwrap_or(usize::MAX);
    while remaining > 0 && patches.len() < limit {
        let id = PatchId::new(patches.len());
        let ctx = PatchContext {
            mesh,
            topology: &topology,
            processed: &processed,
            feature_edges: opts.feature_edges.as_ref(),
            corners: opts.corners.as_deref(),
            blocked: None,
        };
        let patch = match strategy.next_patch(&ctx, rng) {
            Ok(Some(p)) => p,
            Ok(None) => break,
            Err(PatchError::NotCertified { seed, source, .. }) => {
                return Err(PatchError::NotCertified {
                    patch: Some(id),
                    seed,
                    source,
                })
            }
            Err(e) => return Err(e),
        };
        if let Some(&face) = patch.faces.iter().find(|f| f.idx() >= nf) {
            return Err(PatchError::FaceOutOfRange { patch: id, face });
        }
        // The caller's certificate (the strategy's own boundary is not trusted).
        let boundary = crate::invariants::certify_disk(mesh, &patch.faces).map_err(|source| {
            PatchError::NotCertified {
                patch: Some(id),
                seed: patch.seed_vertex,
                source,
            }
        })?;
        let new_faces = patch.faces.iter().filter(|f| !processed[f.idx()]).count();
        if new_faces == 0 {
            return Err(PatchError::NoProgress {
                patch: id,
                seed: patch.seed_vertex,
            });
        }
        for &f in &patch.faces {
            if !processed[f.idx()] {
                processed[f.idx()] = true;
                patch_of_face[f.idx()] = Some(id);
                remaining -= 1;
            }
        }
        let area = patch.faces.iter().map(|&f| mesh.face_area(f)).sum();
        let refit = fit_cone(mesh, &patch.faces);
        let max_e = patch.cone.map(|c| {
            patch
                .faces
                .iter()
                .map(|&f| face_cone_error(mesh, &c, f))
                .fold(0.0, f64::max)
        });
        stats.push(PatchStats {
            patch: id,
            faces: patch.faces.len(),
            new_faces,
            boundary_vertices: boundary.len(),
            area,
            cone_angle_deg: patch.cone.map(|c| c.angle.to_degrees()),
            max_e,
            developability: cone_objective(mesh, &refit, &patch.faces),
            max_growth_cost: patch.max_growth_cost,
        });
        patches.push(patch);
    }
    Ok(CoverRun {
        strategy: strategy.name().to_string(),
        patches,
        stats,
        patch_of_face,
        complete: remaining == 0,
    })
}
