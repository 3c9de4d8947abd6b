//! Step 3, **orient**: each edge-connected component oriented consistently by a
//! breadth-first walk over its manifold edges.

use super::{RepairError, RepairLog};
use crate::ids::{EdgeKey, FaceId, VertexId};
use std::collections::VecDeque;

/// Orient every component through its glued edges (see the module documentation): the
/// kept faces to reverse, in order.
pub(super) fn orient(
    faces: &[FaceId],
    tris: &[[VertexId; 3]],
    adjacency: &[[Option<(u32, bool)>; 3]],
    log: &mut RepairLog,
) -> Result<Vec<usize>, RepairError> {
    let n = tris.len();
    let mut flip: Vec<Option<bool>> = vec![None; n];
    let mut queue = VecDeque::new();
    for start in 0..n {
        if flip[start].is_some() {
            continue;
        }
        flip[start] = Some(false);
        queue.push_back(start);
        let mut component = vec![start];
        while let Some(k) = queue.pop_front() {
            let fk = flip[k] == Some(true);
            for (i, across) in adjacency[k].iter().enumerate() {
                let Some((h, same)) = *across else { continue };
                let g = (h / 3) as usize;
                // Two faces agree when they traverse their shared edge in opposite
                // directions, so a face across a same-direction edge must flip relative
                // to this one.
                let want = fk ^ same;
                match flip[g] {
                    None => {
                        flip[g] = Some(want);
                        queue.push_back(g);
                        component.push(g);
                    }
                    Some(have) if have != want => {
                        return Err(RepairError::NonOrientable {
                            face: faces[start],
                            edge: EdgeKey::new(tris[k][i], tris[k][(i + 1) % 3]),
                        });
                    }
                    Some(_) => {}
                }
            }
        }
        // Keep the orientation most of the component's faces have.
        let flipped = component.iter().filter(|&&k| flip[k] == Some(true)).count();
        if 2 * flipped > component.len() {
            for &k in &component {
                flip[k] = flip[k].map(|b| !b);
            }
        }
    }
    let flipped: Vec<usize> = (0..n).filter(|&k| flip[k] == Some(true)).collect();
    log.flipped_faces = flipped.iter().map(|&k| faces[k]).collect();
    Ok(flipped)
}
