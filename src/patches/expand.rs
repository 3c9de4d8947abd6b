//! Expansion of a patch into the processed region (Sec. 4.2, "Expansion of cone patches").
//!
//! After growth, `rings` rings of *processed* faces adjacent to the patch are added, so that
//! consecutive patches overlap (Fig. 4, Ω_blue) and the previous patch's boundary region is
//! remeshed again. Every addition obeys the exact disk rule of `grow.rs`; a face that would
//! break the disk (or crosses a feature edge) is skipped. Within one ring the candidates are
//! tried in id order, repeatedly, until none can be added (a face refused as a pinch may
//! become a corner once its neighbour joins).

use super::grow::DiskPatch;

/// Add up to `rings` rings of processed faces to `patch`; returns the number added.
pub fn expand_rings(patch: &mut DiskPatch<'_, '_>, processed: &[bool], rings: usize) -> usize {
    let mut added = 0;
    for _ in 0..rings {
        let ring = patch.adjacent_faces(|g| processed.get(g.idx()).copied().unwrap_or(false));
        let mut changed = true;
        let mut ring_added = 0;
        while changed {
            changed = false;
            for &f in &ring {
                if patch.try_add(f).is_ok() {
                    changed = true;
                    ring_added += 1;
                }
            }
        }
        added += ring_added;
        if ring_added == 0 {
            break;
        }
    }
    added
}
