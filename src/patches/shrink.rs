//! Shrinking a patch whose attempt failed (the retry ladder of Algorithm 1): the default of
//! [`super::PatchStrategy::shrink`].

use super::grow::DiskPatch;
use super::PatchContext;
use crate::ids::FaceId;
use std::collections::{HashSet, VecDeque};

/// A smaller disk inside `faces`: grown face by face (breadth first, exact disk rule) from
/// `seed_face` if it is unprocessed, else from the first unprocessed face, up to `target`
/// faces. Deterministic.
pub fn shrink_breadth_first(
    ctx: &PatchContext<'_>,
    faces: &[FaceId],
    seed_face: FaceId,
    target: usize,
) -> Vec<FaceId> {
    let processed = |f: FaceId| ctx.processed.get(f.idx()).copied().unwrap_or(true);
    let inside: HashSet<FaceId> = faces.iter().copied().collect();
    let start = if inside.contains(&seed_face) && !processed(seed_face) {
        seed_face
    } else {
        match faces.iter().find(|f| !processed(**f)) {
            Some(f) => *f,
            None => return faces.to_vec(),
        }
    };
    let mut disk = DiskPatch::new(ctx, start);
    let mut queue = VecDeque::from([start]);
    while let Some(f) = queue.pop_front() {
        if disk.len() >= target.max(1) {
            break;
        }
        for i in 0..3 {
            if let Some(g) = ctx.topology.neighbor(f, i) {
                if inside.contains(&g) && !disk.contains(g) && disk.try_add(g).is_ok() {
                    queue.push_back(g);
                    if disk.len() >= target.max(1) {
                        break;
                    }
                }
            }
        }
    }
    disk.sorted_faces()
}
