//! Expansion of a patch into the processed region (Sec. 4.2, "Expansion of cone patches").
//!
//! After growth, `rings` rings of *processed* faces adjacent to the patch are added, so that
//! consecutive patches overlap (Fig. 4, Ω_blue) and the previous patch's boundary region is
//! remeshed again. Every addition obeys the exact disk rule of `grow.rs`; a face that would
//! break the disk (or crosses a feature edge) is skipped. Within one ring the candidates are
//! tried in id order, repeatedly, until none can be added (a face refused as a pinch may
//! become a corner once its neighbour joins).

use super::grow::DiskPatch;
use super::PatchContext;
use crate::ids::{EdgeKey, FaceId, VertexId};

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

/// A face with `longest edge² / area` above this is a needle (an equilateral triangle has
/// 2.3, a right isosceles one 4; a metric-equilateral one at 10:1 about 23).
pub const NEEDLE_ASPECT: f64 = 15.0;

/// The patch with its ragged expansion trimmed: when its processed faces are needles (the
/// median of `longest edge² / area` above [`NEEDLE_ASPECT`], as an earlier remesh in a strongly
/// anisotropic metric leaves them) and more than half of its vertices are on its boundary
/// (rings of needles make a comb, which no parameterizer maps well), remove the processed
/// faces with two edges on the patch boundary (ears), which keeps a disk and its unprocessed
/// faces. Returns `faces` unchanged otherwise.
pub fn trim_ragged(ctx: &PatchContext<'_>, faces: Vec<FaceId>) -> Vec<FaceId> {
    use std::collections::HashMap;
    let mesh = ctx.mesh;
    let processed = |f: FaceId| ctx.processed.get(f.idx()).copied().unwrap_or(false);
    let mut aspects: Vec<f64> = faces
        .iter()
        .filter(|f| processed(**f))
        .map(|&f| {
            let [a, b, c] = mesh.face_points(f);
            let h = (b - a)
                .norm_squared()
                .max((c - b).norm_squared())
                .max((a - c).norm_squared());
            h / mesh.face_area(f).max(f64::MIN_POSITIVE)
        })
        .collect();
    if aspects.is_empty() {
        return faces;
    }
    aspects.sort_unstable_by(f64::total_cmp);
    if aspects[aspects.len() / 2] <= NEEDLE_ASPECT {
        return faces;
    }
    let mut faces = faces;
    for _ in 0..4 {
        let mut edges: HashMap<EdgeKey, u32> = HashMap::new();
        let mut vertices: HashMap<VertexId, u32> = HashMap::new();
        for &f in &faces {
            let t = mesh.face(f);
            for k in 0..3 {
                *edges.entry(EdgeKey::new(t[k], t[(k + 1) % 3])).or_default() += 1;
                *vertices.entry(t[k]).or_default() += 1;
            }
        }
        let on_boundary: std::collections::HashSet<VertexId> = edges
            .iter()
            .filter(|(_, n)| **n == 1)
            .flat_map(|(e, _)| [e.0, e.1])
            .collect();
        if 2 * on_boundary.len() <= vertices.len() || faces.len() < 4 {
            break;
        }
        let boundary_edges = |f: FaceId| {
            let t = mesh.face(f);
            (0..3)
                .filter(|&k| edges[&EdgeKey::new(t[k], t[(k + 1) % 3])] == 1)
                .count()
        };
        let before = faces.len();
        let kept: Vec<FaceId> = faces
            .iter()
            .copied()
            .filter(|&f| !(processed(f) && boundary_edges(f) == 2))
            .collect();
        // Ears of one another (two ears sharing their third edge) would leave nothing in
        // between: keep the patch when trimming would empty it of processed faces' support.
        if kept.len() == before || kept.iter().all(|&f| processed(f)) {
            break;
        }
        faces = kept;
    }
    faces
}
