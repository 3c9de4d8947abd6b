//! Step 1, **weld**: vertices at bit-identical positions become one, the lowest id kept.

use super::{RepairLog, Weld};
use crate::ids::VertexId;
use crate::mesh::TriMesh;

/// The welded representative of every vertex: the lowest id at the same position.
pub(super) fn weld(mesh: &TriMesh, log: &mut RepairLog) -> Vec<VertexId> {
    // −0 and +0 are the same point; every other value is compared by its bits, so the
    // grouping is exact and independent of the order of the vertices.
    let key = |v: VertexId| {
        let p = mesh.position(v);
        [p.x, p.y, p.z].map(|c| if c == 0.0 { 0u64 } else { c.to_bits() })
    };
    let mut order: Vec<VertexId> = mesh.vertices().collect();
    order.sort_by_key(|&v| (key(v), v));
    let mut rep: Vec<VertexId> = mesh.vertices().collect();
    let mut i = 0;
    while i < order.len() {
        let mut j = i + 1;
        while j < order.len() && key(order[j]) == key(order[i]) {
            rep[order[j].idx()] = order[i];
            log.welded.push(Weld {
                vertex: order[j],
                into: order[i],
            });
            j += 1;
        }
        i = j;
    }
    log.welded.sort_by_key(|w| w.vertex);
    rep
}
