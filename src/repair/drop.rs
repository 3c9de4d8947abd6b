//! Step 2, **drop**: faces that welding collapsed, repeated faces and faces of exactly zero
//! area, a T-junction's sliver first flipped away.

use super::{DropReason, DroppedFace, RepairLog, ZeroAreaFlip};
use crate::ids::{EdgeKey, FaceId, VertexId};
use crate::mesh::TriMesh;
use crate::predicates::collinear3d;

/// The faces kept after welding, as (input face ids, triangles in input vertex ids).
pub(super) fn kept_faces(
    mesh: &TriMesh,
    rep: &[VertexId],
    drop_degenerate: bool,
    log: &mut RepairLog,
) -> (Vec<FaceId>, Vec<[VertexId; 3]>) {
    let mut faces = Vec::with_capacity(mesh.n_faces());
    let mut tris = Vec::with_capacity(mesh.n_faces());
    let mut first_with: std::collections::HashMap<[VertexId; 3], FaceId> = Default::default();
    let mut zero = Vec::new();
    for f in mesh.faces() {
        let t = mesh.face(f).map(|v| rep[v.idx()]);
        let reason = if !drop_degenerate {
            None
        } else if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            Some(DropReason::Collapsed)
        } else if collinear3d(
            mesh.position(t[0]),
            mesh.position(t[1]),
            mesh.position(t[2]),
        ) {
            Some(DropReason::ZeroArea)
        } else {
            let mut sorted = t;
            sorted.sort();
            match first_with.entry(sorted) {
                std::collections::hash_map::Entry::Occupied(e) => {
                    Some(DropReason::Duplicate(*e.get()))
                }
                std::collections::hash_map::Entry::Vacant(e) => {
                    e.insert(f);
                    None
                }
            }
        };
        match reason {
            // A zero-area face stays for now: flipping its long edge may remove it without
            // opening a hole (`flip_zero_area`).
            Some(DropReason::ZeroArea) => {
                zero.push(faces.len());
                faces.push(f);
                tris.push(t);
            }
            Some(reason) => log.dropped_faces.push(DroppedFace { face: f, reason }),
            None => {
                faces.push(f);
                tris.push(t);
            }
        }
    }
    let unflipped = flip_zero_area(mesh, &faces, &mut tris, &zero, log);
    if !unflipped.is_empty() {
        for &k in &unflipped {
            log.dropped_faces.push(DroppedFace {
                face: faces[k],
                reason: DropReason::ZeroArea,
            });
        }
        log.dropped_faces.sort_by_key(|d| d.face);
        let gone: std::collections::HashSet<usize> = unflipped.into_iter().collect();
        let mut k = 0;
        faces.retain(|_| {
            k += 1;
            !gone.contains(&(k - 1))
        });
        let mut k = 0;
        tris.retain(|_| {
            k += 1;
            !gone.contains(&(k - 1))
        });
    }
    (faces, tris)
}

/// Remove the zero-area faces `zero` (indices into `tris`) by edge flips where one keeps the
/// surface: a face whose corners are exactly collinear has one corner `c` strictly inside the
/// segment of the other two, `a`–`b` (bit-identical corners were welded). When exactly one
/// other face `G` has the edge `a`–`b`, traversing it as `x → y`, with third corner `d`, the
/// two faces become `(y, d, c)` and `(d, x, c)`: they tile `G`'s triangle (the zero-area face
/// covers nothing), keep `G`'s orientation, and are kept only when both have positive area
/// (exact) and the edge `c`–`d` is new. Flips repeat until none applies. Returns the faces
/// left with zero area (to drop).
pub(super) fn flip_zero_area(
    mesh: &TriMesh,
    faces: &[FaceId],
    tris: &mut [[VertexId; 3]],
    zero: &[usize],
    log: &mut RepairLog,
) -> Vec<usize> {
    if zero.is_empty() {
        return Vec::new();
    }
    let mut at_edge: std::collections::HashMap<EdgeKey, Vec<usize>> = Default::default();
    for (k, t) in tris.iter().enumerate() {
        for i in 0..3 {
            at_edge
                .entry(EdgeKey::new(t[i], t[(i + 1) % 3]))
                .or_default()
                .push(k);
        }
    }
    let p = |v: VertexId| mesh.position(v);
    // The corner strictly between the other two (coordinates compared exactly).
    let middle = |t: [VertexId; 3]| -> usize {
        (0..3)
            .find(|&i| {
                let (a, b, c) = (p(t[(i + 1) % 3]), p(t[(i + 2) % 3]), p(t[i]));
                (0..3).all(|k| (a[k] <= c[k] && c[k] <= b[k]) || (b[k] <= c[k] && c[k] <= a[k]))
            })
            .unwrap_or(0)
    };
    let mut pending: Vec<usize> = zero.to_vec();
    loop {
        let before = pending.len();
        pending.retain(|&k| {
            let t = tris[k];
            // Flipped away already, as the face across another one.
            if !collinear3d(p(t[0]), p(t[1]), p(t[2])) {
                return false;
            }
            let m = middle(t);
            let (c, a, b) = (t[m], t[(m + 1) % 3], t[(m + 2) % 3]);
            let edge = EdgeKey::new(a, b);
            let others: Vec<usize> = at_edge[&edge].iter().copied().filter(|&g| g != k).collect();
            let [g] = others[..] else { return true };
            let tg = tris[g];
            let Some(i) = (0..3).find(|&i| EdgeKey::new(tg[i], tg[(i + 1) % 3]) == edge) else {
                return true;
            };
            let (x, y, d) = (tg[i], tg[(i + 1) % 3], tg[(i + 2) % 3]);
            let new = [[y, d, c], [d, x, c]];
            if d == c
                || at_edge.contains_key(&EdgeKey::new(c, d))
                || new.iter().any(|n| collinear3d(p(n[0]), p(n[1]), p(n[2])))
            {
                return true;
            }
            for (face, old) in [(k, t), (g, tg)] {
                for i in 0..3 {
                    let e = EdgeKey::new(old[i], old[(i + 1) % 3]);
                    if let Some(list) = at_edge.get_mut(&e) {
                        list.retain(|&h| h != face);
                        if list.is_empty() {
                            at_edge.remove(&e);
                        }
                    }
                }
            }
            tris[k] = new[0];
            tris[g] = new[1];
            for (face, t) in [(k, new[0]), (g, new[1])] {
                for i in 0..3 {
                    at_edge
                        .entry(EdgeKey::new(t[i], t[(i + 1) % 3]))
                        .or_default()
                        .push(face);
                }
            }
            log.zero_area_flips.push(ZeroAreaFlip {
                face: faces[k],
                across: faces[g],
            });
            false
        });
        if pending.len() == before {
            return pending;
        }
    }
}
