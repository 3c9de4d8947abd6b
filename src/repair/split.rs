//! Step 4, **split**: one vertex per fan; and the output's vertices when nothing is split.

use super::{RepairLog, Split};
use crate::ids::VertexId;
use crate::mesh::{TriMesh, UnionFind};

/// One output vertex per fan of faces around each input vertex (fans connect through glued
/// edges); returns positions, the source vertex of each, and the triangles.
pub(super) fn split_fans(
    mesh: &TriMesh,
    rep: &[VertexId],
    tris: &[[VertexId; 3]],
    adjacency: &[[Option<(u32, bool)>; 3]],
    log: &mut RepairLog,
) -> (
    Vec<nalgebra::Point3<f64>>,
    Vec<VertexId>,
    Vec<[VertexId; 3]>,
) {
    // Corner `c` of face `k` is `3k + c`. Half-edge `3k + i` runs from corner `i` to corner
    // `i + 1`; the other face's half-edge `3g + j` on the same edge starts at the same vertex
    // when both run the same way, at the other one otherwise.
    let next = |c: usize| c - c % 3 + (c % 3 + 1) % 3;
    let mut fans = UnionFind::new(3 * tris.len());
    for (k, sides) in adjacency.iter().enumerate() {
        for (i, across) in sides.iter().enumerate() {
            if let Some((h, same)) = *across {
                let (a, b) = (3 * k + i, next(3 * k + i));
                let (c, d) = (h as usize, next(h as usize));
                let (at_a, at_b) = if same { (c, d) } else { (d, c) };
                fans.union(a, at_a);
                fans.union(b, at_b);
            }
        }
    }
    let (mut positions, mut source, new_id) = referenced(mesh, rep, tris, log);
    // Fans in order of their first corner: the first fan of a vertex keeps its output id.
    const NONE: u32 = u32::MAX;
    let mut fan_vertex = vec![NONE; 3 * tris.len()];
    let mut taken = vec![false; mesh.n_vertices()];
    let mut splits: std::collections::BTreeMap<VertexId, Vec<VertexId>> = Default::default();
    let mut out = tris.to_vec();
    for (k, t) in tris.iter().enumerate() {
        for i in 0..3 {
            let root = fans.find(3 * k + i);
            if fan_vertex[root] == NONE {
                let v = t[i];
                fan_vertex[root] = if !taken[v.idx()] {
                    taken[v.idx()] = true;
                    new_id[v.idx()].0
                } else {
                    let copy = VertexId::new(positions.len());
                    positions.push(*mesh.position(v));
                    source.push(v);
                    splits
                        .entry(v)
                        .or_insert_with(|| vec![new_id[v.idx()]])
                        .push(copy);
                    copy.0
                };
            }
            out[k][i] = VertexId(fan_vertex[root]);
        }
    }
    log.split_vertices = splits
        .into_iter()
        .map(|(vertex, into)| Split { vertex, into })
        .collect();
    (positions, source, out)
}

/// Without splitting: the referenced vertices, renumbered.
pub(super) fn compact(
    mesh: &TriMesh,
    tris: &[[VertexId; 3]],
    log: &mut RepairLog,
) -> (
    Vec<nalgebra::Point3<f64>>,
    Vec<VertexId>,
    Vec<[VertexId; 3]>,
) {
    let identity: Vec<VertexId> = mesh.vertices().collect();
    let (positions, source, new_id) = referenced(mesh, &identity, tris, log);
    let out = tris.iter().map(|t| t.map(|v| new_id[v.idx()])).collect();
    (positions, source, out)
}

/// The vertices `tris` references, in input order: their positions, their input ids, and
/// the output id of each input vertex. Vertices no face references (welded ones included
/// only when their representative is unreferenced too) are logged.
pub(super) fn referenced(
    mesh: &TriMesh,
    rep: &[VertexId],
    tris: &[[VertexId; 3]],
    log: &mut RepairLog,
) -> (Vec<nalgebra::Point3<f64>>, Vec<VertexId>, Vec<VertexId>) {
    let mut used = vec![false; mesh.n_vertices()];
    for t in tris {
        for v in t {
            used[v.idx()] = true;
        }
    }
    let mut new_id = vec![VertexId(u32::MAX); mesh.n_vertices()];
    let (mut positions, mut source) = (Vec::new(), Vec::new());
    for v in mesh.vertices() {
        if used[v.idx()] {
            new_id[v.idx()] = VertexId::new(positions.len());
            positions.push(*mesh.position(v));
            source.push(v);
        } else if !used[rep[v.idx()].idx()] {
            log.unreferenced_vertices.push(v);
        }
    }
    (positions, source, new_id)
}
