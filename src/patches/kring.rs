//! A second, deliberately simple strategy: geodesic k-ring disks (name `kring`).
//!
//! Same seed vertices as the cone patches; the seed triangle is the lowest-id unprocessed
//! face of the seed's 1-ring; the patch grows breadth-first, ring by ring, through
//! unprocessed faces (ids in order within a ring) under the same exact disk rule, up to
//! `rings` rings or `max_faces` faces, then expands into processed faces like the cone
//! patches. No geometry is used: it shows what the cone criterion buys.
//!
//! The template of a strategy: it uses only public items (as a strategy written outside the
//! crate would), and its registry row reads its defaults from [`KRingDisks::default`].

use crate::patches::expand::expand_rings;
use crate::patches::{
    finish_patch, fit_cone, pick_seed_vertex, unprocessed_ring, DiskPatch, Patch, PatchContext,
    PatchError, PatchStrategy,
};
use rand_chacha::ChaCha8Rng;

/// Geodesic k-ring disks.
#[derive(Clone, Debug, PartialEq)]
pub struct KRingDisks {
    /// Rings of faces grown around the seed triangle. Default 6.
    pub rings: usize,
    /// Cap on the faces added by growth. Default 200.
    pub max_faces: usize,
    /// Rings of processed faces added afterwards (overlap). Default 1.
    pub expand_rings: usize,
}

impl Default for KRingDisks {
    fn default() -> Self {
        KRingDisks {
            rings: 6,
            max_faces: 200,
            expand_rings: 1,
        }
    }
}

impl PatchStrategy for KRingDisks {
    fn name(&self) -> &'static str {
        "kring"
    }

    fn widened(&self, rings: usize) -> Option<Box<dyn PatchStrategy>> {
        Some(Box::new(KRingDisks {
            expand_rings: rings,
            ..self.clone()
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
        let Some(&seed_face) = unprocessed_ring(ctx, seed_vertex).first() else {
            return Err(PatchError::SeedWithoutFace { seed: seed_vertex });
        };
        let unprocessed =
            |g: crate::ids::FaceId| !ctx.processed.get(g.idx()).copied().unwrap_or(true);
        let mut disk = DiskPatch::new(ctx, seed_face);
        'rings: for _ in 0..self.rings {
            let ring = disk.adjacent_faces(unprocessed);
            let mut added = 0;
            for f in ring {
                if disk.len() > self.max_faces {
                    break 'rings;
                }
                if disk.try_add(f).is_ok() {
                    added += 1;
                }
            }
            if added == 0 {
                break;
            }
        }
        expand_rings(&mut disk, ctx.processed, self.expand_rings);
        let cone = fit_cone(ctx.mesh, disk.faces());
        finish_patch(&disk, ctx, seed_vertex, seed_face, Some(cone), None).map(Some)
    }
}
