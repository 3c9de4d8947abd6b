//! Greedy growth of a cone patch (Sec. 3.2) under the exact disk rule.
//!
//! **The exact disk rule.** Let `P` be a topological disk and `t ∉ P` a face of an
//! edge-manifold mesh, and `k` the number of edges `t` shares with `P` (each such edge is a
//! boundary edge of `P`: an interior edge already has its two faces in `P`).
//! - `k = 0`: `t` would touch `P` at most in vertices: refused (not adjacent; touching at a
//!   vertex would be a pinch).
//! - `k = 1`, shared edge `(a, b)`, free vertex `c`: `P ∪ t` is a disk iff `c ∉ P` (gluing a
//!   triangle along one boundary edge). If `c ∈ P` (necessarily on `P`'s boundary) the union
//!   pinches at `c` or encloses a hole: refused. This is the paper's loop test.
//! - `k = 2`, shared edges `(a, b)`, `(b, c)`: both are boundary edges at `b`, and `b` lies on
//!   the simple boundary loop once, so they are consecutive on it; `t` meets `P` exactly in
//!   that arc and closes `b`'s fan: the union is a disk. Accepted.
//! - `k = 3`: the boundary loop is `t`'s own three edges; adding `t` closes a sphere: refused
//!   (the paper's test would accept it).
//!
//! Shared edges become interior edges of the patch, so they must be manifold mesh edges
//! (two faces, consistently oriented: [`crate::mesh::Topology::neighbor`]) and not feature edges; mesh
//! boundary edges have a single face and are never shared, so patches never cross them.
//! `certify_disk` re-checks every produced patch.
//!
//! **Corners.** A face that would close the fan of a [`PatchContext::corners`] vertex (the
//! `k = 2` case at that vertex, or the last face around it) is refused
//! ([`Refusal::Corner`]), so such vertices never become interior to a patch.

use super::cone_fit::cone_error;
use super::growth_cost::{growth_cost, ConeOptions};
use super::{Cone, PatchContext};
use crate::ids::{EdgeKey, FaceId, VertexId};
use crate::mesh::TriMesh;
use rustc_hash::{FxHashMap, FxHashSet};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Why a face may not join a patch.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Refusal {
    /// Already in the patch.
    InPatch,
    /// Shares no edge with the patch.
    NotAdjacent,
    /// Its free vertex is already in the patch (`k = 1`): pinch or hole.
    Pinch(VertexId),
    /// It would close the patch into a sphere (`k = 3`).
    ClosesSphere,
    /// A shared edge is a feature edge.
    Feature(EdgeKey),
    /// A shared edge is not a manifold, consistently oriented mesh edge.
    NonManifold(EdgeKey),
    /// It would close the fan of a corner vertex ([`PatchContext::corners`]), making it an
    /// interior vertex of the patch.
    Corner(VertexId),
    /// Reserved by another patch of the batch ([`PatchContext::blocked`]).
    Blocked,
}

/// A face set that is a topological disk by construction (the exact rule above), with the
/// incremental bookkeeping growth needs.
#[derive(Clone)]
pub struct DiskPatch<'c, 'a> {
    ctx: &'c PatchContext<'a>,
    /// Faces in insertion order.
    faces: Vec<FaceId>,
    members: FxHashSet<FaceId>,
    edge_count: FxHashMap<EdgeKey, u8>,
    vertex_count: FxHashMap<VertexId, u32>,
    area: f64,
}

impl<'c, 'a> DiskPatch<'c, 'a> {
    /// The one-face patch `{seed}`.
    pub fn new(ctx: &'c PatchContext<'a>, seed: FaceId) -> Self {
        let mut p = DiskPatch {
            ctx,
            faces: Vec::new(),
            members: FxHashSet::default(),
            edge_count: FxHashMap::default(),
            vertex_count: FxHashMap::default(),
            area: 0.0,
        };
        p.insert(seed);
        p
    }

    fn insert(&mut self, t: FaceId) {
        let tri = self.ctx.mesh.face(t);
        for i in 0..3 {
            *self
                .edge_count
                .entry(EdgeKey::new(tri[i], tri[(i + 1) % 3]))
                .or_default() += 1;
            *self.vertex_count.entry(tri[i]).or_default() += 1;
        }
        self.members.insert(t);
        self.faces.push(t);
        self.area += self.ctx.mesh.face_area(t);
    }

    /// Faces in insertion order.
    pub fn faces(&self) -> &[FaceId] {
        &self.faces
    }

    /// Number of faces.
    pub fn len(&self) -> usize {
        self.faces.len()
    }

    /// Never empty (a patch starts from its seed face).
    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// Total area A_P.
    pub fn area(&self) -> f64 {
        self.area
    }

    /// True when `f` is in the patch.
    pub fn contains(&self, f: FaceId) -> bool {
        self.members.contains(&f)
    }

    /// True when `v` is a vertex of the patch.
    pub fn has_vertex(&self, v: VertexId) -> bool {
        self.vertex_count.contains_key(&v)
    }

    /// The patch faces across `t`'s edges, as (local edge index, neighbour) pairs, through
    /// manifold mesh edges only.
    pub fn patch_neighbors(&self, t: FaceId) -> impl Iterator<Item = (usize, FaceId)> + '_ {
        (0..3).filter_map(move |i| {
            self.ctx
                .topology
                .neighbor(t, i)
                .filter(|g| self.members.contains(g))
                .map(|g| (i, g))
        })
    }

    /// The exact disk rule (module docs): `Ok(())` when `P ∪ {t}` is a disk and `t` joins
    /// only through manifold, non-feature edges.
    pub fn check_add(&self, t: FaceId) -> Result<(), Refusal> {
        if self.members.contains(&t) {
            return Err(Refusal::InPatch);
        }
        if self.ctx.is_blocked(t) {
            return Err(Refusal::Blocked);
        }
        let tri = self.ctx.mesh.face(t);
        let mut shared = 0;
        let mut shared_edge = 0;
        for i in 0..3 {
            let key = EdgeKey::new(tri[i], tri[(i + 1) % 3]);
            if self.edge_count.get(&key).copied().unwrap_or(0) == 0 {
                continue;
            }
            shared += 1;
            shared_edge = i;
            let across = self.ctx.topology.neighbor(t, i);
            if !across.is_some_and(|g| self.members.contains(&g)) {
                return Err(Refusal::NonManifold(key));
            }
            if self.ctx.feature_edges.is_some_and(|fe| fe.contains(&key)) {
                return Err(Refusal::Feature(key));
            }
        }
        if shared > 0 && shared < 3 {
            // A corner vertex becomes interior exactly when `t` is the last face of its fan.
            for &v in &tri {
                if self.ctx.is_corner(v)
                    && !self.ctx.topology.is_boundary_vertex(v)
                    && self.vertex_count.get(&v).copied().unwrap_or(0) as usize + 1
                        == self.ctx.topology.vertex_faces(v).len()
                {
                    return Err(Refusal::Corner(v));
                }
            }
        }
        match shared {
            0 => Err(Refusal::NotAdjacent),
            1 => {
                // The free vertex, opposite the shared edge.
                let c = tri[(shared_edge + 2) % 3];
                if self.has_vertex(c) {
                    Err(Refusal::Pinch(c))
                } else {
                    Ok(())
                }
            }
            2 => Ok(()),
            _ => Err(Refusal::ClosesSphere),
        }
    }

    /// Add `t` if the disk rule allows it.
    pub fn try_add(&mut self, t: FaceId) -> Result<(), Refusal> {
        self.check_add(t)?;
        self.insert(t);
        Ok(())
    }

    /// Faces sharing a manifold edge with the patch and not in it, sorted, filtered by `keep`.
    pub fn adjacent_faces(&self, mut keep: impl FnMut(FaceId) -> bool) -> Vec<FaceId> {
        let mut out = Vec::new();
        for &f in &self.faces {
            for i in 0..3 {
                if let Some(g) = self.ctx.topology.neighbor(f, i) {
                    if !self.members.contains(&g) && keep(g) {
                        out.push(g);
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The faces, sorted by id.
    pub fn sorted_faces(&self) -> Vec<FaceId> {
        let mut v = self.faces.clone();
        v.sort_unstable();
        v
    }
}

/// A heap entry: min-heap by cost, then face id (total order, deterministic).
#[derive(Copy, Clone, Debug)]
struct Entry {
    cost: f64,
    face: FaceId,
    /// Patch size when the cost was computed (stale when the patch has grown since).
    version: usize,
}

impl PartialEq for Entry {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        // Reversed: BinaryHeap is a max-heap.
        o.cost
            .total_cmp(&self.cost)
            .then(o.face.cmp(&self.face))
            .then(o.version.cmp(&self.version))
    }
}

/// The result of [`grow_patch`].
#[derive(Clone)]
pub struct Grown<'c, 'a> {
    /// The grown disk.
    pub patch: DiskPatch<'c, 'a>,
    /// The Eq. 3 cost of every face added after the seed, in insertion order.
    pub costs: Vec<f64>,
    /// D(s_P, f) for every patch face (centroid path length inside the patch).
    pub distance: FxHashMap<FaceId, f64>,
}

impl Grown<'_, '_> {
    /// Largest cost of a face added by growth (0 for a seed-only patch).
    pub fn max_cost(&self) -> f64 {
        self.costs.iter().copied().fold(0.0, f64::max)
    }
}

/// Grow a cone patch from `seed` (Sec. 3.2): repeatedly add the unprocessed face of least
/// Eq. 3 cost `C(P, t)` that shares an edge with the patch and keeps it a disk, while
/// `C < c_max`.
///
/// Costs depend on `A_P` and on `D` inside the patch, which change as it grows (both only
/// make costs smaller); stale heap entries are recomputed when popped, and before stopping
/// every remaining entry is refreshed, so growth stops only when no addable face has a
/// current cost below `c_max`. The cone is the one fitted once at the seed (paper).
pub fn grow_patch<'c, 'a>(
    ctx: &'c PatchContext<'a>,
    seed: FaceId,
    cone: &Cone,
    opts: &ConeOptions,
) -> Grown<'c, 'a> {
    let mut distance = FxHashMap::default();
    distance.insert(seed, 0.0);
    let mut g = Grown {
        patch: DiskPatch::new(ctx, seed),
        costs: Vec::new(),
        distance,
    };
    g.grow(cone, opts);
    g
}

impl Grown<'_, '_> {
    /// Continue growing with `cone` (e.g. refitted to the patch grown so far); returns the
    /// number of faces added. `opts.max_faces` bounds the total over all calls.
    pub fn grow(&mut self, cone: &Cone, opts: &ConeOptions) -> usize {
        let ctx = self.patch.ctx;
        let mesh = ctx.mesh;
        let patch = &mut self.patch;
        let distance = &mut self.distance;
        let costs = &mut self.costs;
        let before = costs.len();
        let centroid = |f: FaceId| mesh.face_centroid(f);
        let addable = |f: FaceId| !ctx.processed.get(f.idx()).copied().unwrap_or(true);

        // D(s_P, t) for t outside the patch: through its patch neighbours.
        let d_outside = |patch: &DiskPatch, distance: &FxHashMap<FaceId, f64>, t: FaceId| -> f64 {
            let ct = centroid(t);
            patch
                .patch_neighbors(t)
                .filter_map(|(_, g)| distance.get(&g).map(|d| d + (centroid(g) - ct).norm()))
                .fold(f64::INFINITY, f64::min)
        };
        let cost_of = |patch: &DiskPatch, distance: &FxHashMap<FaceId, f64>, t: FaceId| -> f64 {
            let e = cone_error(cone, &mesh.face_normal(t));
            growth_cost(e, d_outside(patch, distance, t), patch.area(), opts.beta)
        };
        let mut heap = BinaryHeap::new();
        for g in patch.adjacent_faces(addable) {
            heap.push(Entry {
                cost: cost_of(&*patch, &*distance, g),
                face: g,
                version: patch.len(),
            });
        }
        let max_faces = opts.max_faces.unwrap_or(usize::MAX);
        while costs.len() < max_faces {
            let Some(top) = heap.pop() else { break };
            if patch.contains(top.face) {
                continue;
            }
            if top.version != patch.len() {
                heap.push(Entry {
                    cost: cost_of(&*patch, &*distance, top.face),
                    face: top.face,
                    version: patch.len(),
                });
                continue;
            }
            if top.cost.is_nan() || top.cost >= opts.c_max {
                // Refresh stale entries before giving up.
                let any_stale = refresh_stale(&mut heap, patch, |f| cost_of(patch, distance, f));
                if !any_stale {
                    break;
                }
                heap.push(top);
                continue;
            }
            if patch.try_add(top.face).is_err() {
                // It may become addable later (a pinch can turn into a corner); it is pushed
                // again when a neighbour joins.
                continue;
            }
            costs.push(top.cost);
            // Dijkstra inside the patch: the new face's distance, then shortcuts it opens.
            let d_t = d_outside(&*patch, &*distance, top.face);
            let d_t = if d_t.is_finite() { d_t } else { 0.0 };
            distance.insert(top.face, d_t);
            relax_from(mesh, patch, distance, top.face, d_t);
            for i in 0..3 {
                if let Some(g) = ctx.topology.neighbor(top.face, i) {
                    if !patch.contains(g) && addable(g) {
                        heap.push(Entry {
                            cost: cost_of(&*patch, &*distance, g),
                            face: g,
                            version: patch.len(),
                        });
                    }
                }
            }
        }
        costs.len() - before
    }
}

/// Re-cost the heap's entries made before the patch last grew (`cost` of a face, at the
/// current patch); whether there were any.
fn refresh_stale(
    heap: &mut BinaryHeap<Entry>,
    patch: &DiskPatch,
    cost: impl Fn(FaceId) -> f64,
) -> bool {
    let entries: Vec<Entry> = heap.drain().collect();
    let mut any_stale = false;
    for e in entries {
        if patch.contains(e.face) {
            continue;
        }
        if e.version != patch.len() {
            any_stale = true;
            heap.push(Entry {
                cost: cost(e.face),
                face: e.face,
                version: patch.len(),
            });
        } else {
            heap.push(e);
        }
    }
    any_stale
}

/// The patch's distances `D(s_P, ·)` after `face` joined at distance `d`.
fn relax_from(
    mesh: &TriMesh,
    patch: &DiskPatch,
    distance: &mut FxHashMap<FaceId, f64>,
    face: FaceId,
    d: f64,
) {
    let centroid = |f: FaceId| mesh.face_centroid(f);
    // Label-setting (Dijkstra) from the new face over the distances it lowers: each
    // face's distance falls at most once per added face (a stack-order relaxation
    // lowers the same faces many times over; notes/scaling.md). Ordered like the
    // growth heap: least distance first, then face id.
    let mut front = BinaryHeap::from([Entry {
        cost: d,
        face,
        version: 0,
    }]);
    while let Some(Entry {
        cost: df, face: f, ..
    }) = front.pop()
    {
        if distance.get(&f).is_some_and(|&d| d < df) {
            continue;
        }
        let cf = centroid(f);
        let nbrs: Vec<FaceId> = patch.patch_neighbors(f).map(|(_, g)| g).collect();
        for g in nbrs {
            let cand = df + (centroid(g) - cf).norm();
            if cand < distance.get(&g).copied().unwrap_or(f64::INFINITY) {
                distance.insert(g, cand);
                front.push(Entry {
                    cost: cand,
                    face: g,
                    version: 0,
                });
            }
        }
    }
}
