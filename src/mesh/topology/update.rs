//! The topology after patches are replaced (Algorithm 1, step e), without sorting every
//! half-edge again.
//!
//! [`Topology::build`] sorts all half-edges; Algorithm 1 needs the topology after every
//! patch, and on a mesh of 50k faces and thousands of patches the rebuilds would be most of
//! the run (notes/real-world-inputs.md). Here only the edges of the removed and the new faces are
//! looked at again; the rest is carried over through the face renumbering, in linear passes
//! without sorting. The result equals [`Topology::build`] on the new mesh, field for field,
//! and debug builds check that after every update. When the replacement might change the
//! components (the new faces are not edge-connected, they touch another component, or a
//! connection that ran through the removed faces is not carried by new ones), the topology
//! is built from scratch instead: the certificates then see exactly what the build sees.

use super::{vertex_face_lists, ComponentInfo, Topology, NONE};
use crate::ids::{EdgeKey, FaceId, VertexId};
use crate::mesh::{TriMesh, UnionFind};
use std::ops::Range;

/// An undirected edge whose faces changed: one of the removed faces' edges or one of the new
/// faces'.
struct Changed {
    key: EdgeKey,
    /// Its index in the old topology's edges, when it had one.
    old: Option<u32>,
    /// Half-edges on it of faces that stay (new ids).
    kept: Vec<u32>,
    /// Half-edges on it of removed faces.
    removed: u32,
    /// Whether a kept face on it lies in another component than the removed faces.
    kept_elsewhere: bool,
    /// Half-edges on it of new faces (new ids).
    new: Vec<u32>,
}

impl Changed {
    fn count(&self) -> usize {
        self.kept.len() + self.new.len()
    }
}

/// The kept faces' renumbering: the removed faces dropped, the others keeping their order.
struct Renumbering {
    /// Whether each old face is removed.
    gone: Vec<bool>,
    /// Old face → new face; `NONE` for removed faces.
    fmap: Vec<u32>,
    /// The new faces (appended after the kept ones).
    new_faces: Range<usize>,
    /// The component of the removed faces (they all lie in one).
    c0: u32,
}

/// The edge list after the update, and where the old and the changed edges went in it.
struct MergedEdges {
    edges: Vec<EdgeKey>,
    edge_face_count: Vec<u32>,
    /// Old edge → new edge; `NONE` for edges no face uses any more.
    remap: Vec<u32>,
    /// Changed edge → new edge; `NONE` for edges no face uses any more.
    index_of_changed: Vec<u32>,
}

/// The half-edge fields after the update.
struct PairedHalfedges {
    halfedge_edge: Vec<u32>,
    opposite: Vec<u32>,
    non_manifold_edges: Vec<(EdgeKey, usize)>,
    inconsistent_edges: Vec<EdgeKey>,
}

impl Topology {
    /// The topology of `mesh`, which is this topology's mesh with the faces `removed` dropped
    /// (the others keeping their order) and new faces appended, as
    /// [`crate::stitch::stitch_all`] leaves the working mesh. Equal to
    /// `Topology::build(mesh)`; faster when the removed and new faces are few.
    pub fn after_replacing(&self, mesh: &TriMesh, removed: &[FaceId]) -> Topology {
        let topo = self
            .updated(mesh, removed)
            .unwrap_or_else(|| Topology::build(mesh));
        debug_assert!(
            topo.same_as(&Topology::build(mesh)),
            "the updated topology differs from the one built from scratch"
        );
        topo
    }

    /// Every derived field equal (the lazily found non-manifold vertices aside).
    pub(super) fn same_as(&self, other: &Topology) -> bool {
        self.triangles == other.triangles
            && self.n_vertices == other.n_vertices
            && self.opposite == other.opposite
            && self.halfedge_edge == other.halfedge_edge
            && self.edges == other.edges
            && self.edge_face_count == other.edge_face_count
            && self.vf_offsets == other.vf_offsets
            && self.vf_faces == other.vf_faces
            && self.face_component == other.face_component
            && self.components == other.components
            && self.boundary_loops == other.boundary_loops
            && self.boundary_loop_component == other.boundary_loop_component
            && self.non_manifold_edges == other.non_manifold_edges
            && self.inconsistent_edges == other.inconsistent_edges
    }

    /// The update, or `None` when it must be built from scratch (see the module docs).
    fn updated(&self, mesh: &TriMesh, removed: &[FaceId]) -> Option<Topology> {
        let faces = self.renumbering(mesh, removed)?;
        let changed = self.changed_edges(mesh, removed, &faces);
        if !components_unchanged(&changed, faces.new_faces.clone()) {
            return None;
        }
        let merged = self.merged_edges(&changed, faces.new_faces.len());
        let paired = self.paired_halfedges(mesh, &faces, &changed, &merged);
        let (vf_offsets, vf_faces) = vertex_face_lists(mesh);
        let (face_component, components) =
            self.components_after(mesh, removed, &faces, &changed, (&vf_offsets, &vf_faces))?;

        let boundary_changed = changed.iter().any(|c| {
            c.count() == 1 || c.old.is_some_and(|e| self.edge_face_count[e as usize] == 1)
        });
        let mut topo = Topology {
            triangles: mesh.triangles.clone(),
            n_vertices: mesh.n_vertices(),
            opposite: paired.opposite,
            halfedge_edge: paired.halfedge_edge,
            edges: merged.edges,
            edge_face_count: merged.edge_face_count,
            vf_offsets,
            vf_faces,
            face_component,
            components,
            boundary_loops: Vec::new(),
            boundary_loop_component: Vec::new(),
            non_manifold_edges: paired.non_manifold_edges,
            inconsistent_edges: paired.inconsistent_edges,
            non_manifold_vertices: std::sync::OnceLock::new(),
        };
        // Untouched boundary half-edges keep their order under the face map, so the loops
        // (traced from the first unused one) come out the same.
        topo.boundary_loops = match boundary_changed {
            true => topo.trace_boundary_loops(),
            false => self.boundary_loops.clone(),
        };
        topo.boundary_loop_component = topo.loop_components();
        topo.recount_loops_and_genus();
        Some(topo)
    }

    /// The kept faces' renumbering, or `None` when the new mesh is not this one with
    /// `removed` dropped and faces appended, or the removed faces span two components.
    fn renumbering(&self, mesh: &TriMesh, removed: &[FaceId]) -> Option<Renumbering> {
        let old_nf = self.triangles.len();
        let mut gone = vec![false; old_nf];
        for f in removed {
            if f.idx() >= old_nf || gone[f.idx()] {
                return None;
            }
            gone[f.idx()] = true;
        }
        let kept_faces = old_nf - removed.len();
        let nf = mesh.n_faces();
        if removed.is_empty() || nf <= kept_faces || mesh.n_vertices() < self.n_vertices {
            return None;
        }
        // Old face → new face; the kept faces must be the new mesh's first faces, in order.
        let mut fmap = vec![NONE; old_nf];
        let mut next = 0u32;
        for f in 0..old_nf {
            if !gone[f] {
                if mesh.triangles[next as usize] != self.triangles[f] {
                    return None;
                }
                fmap[f] = next;
                next += 1;
            }
        }
        let c0 = self.face_component[removed[0].idx()];
        if removed.iter().any(|f| self.face_component[f.idx()] != c0) {
            return None;
        }
        Some(Renumbering {
            gone,
            fmap,
            new_faces: kept_faces..nf,
            c0,
        })
    }

    /// Every edge of a removed or a new face, in key order, with its kept, removed and new
    /// half-edges.
    fn changed_edges(
        &self,
        mesh: &TriMesh,
        removed: &[FaceId],
        faces: &Renumbering,
    ) -> Vec<Changed> {
        // The new faces' half-edges by edge.
        let mut new_he: Vec<(EdgeKey, u32)> = faces
            .new_faces
            .clone()
            .flat_map(|f| (0..3).map(move |i| (f, i)))
            .map(|(f, i)| (edge_key(&mesh.triangles[f], i), (3 * f + i) as u32))
            .collect();
        new_he.sort_unstable();
        let mut old_keys: Vec<u32> = removed
            .iter()
            .flat_map(|f| (0..3).map(move |i| self.halfedge_edge[3 * f.idx() + i]))
            .collect();
        let mut changed: Vec<Changed> = Vec::new();
        let mut i = 0;
        while i < new_he.len() {
            let mut j = i;
            while j < new_he.len() && new_he[j].0 == new_he[i].0 {
                j += 1;
            }
            let key = new_he[i].0;
            let old = self.edges.binary_search(&key).ok().map(|e| e as u32);
            if let Some(e) = old {
                old_keys.push(e);
            }
            changed.push(Changed {
                key,
                old,
                kept: Vec::new(),
                removed: 0,
                kept_elsewhere: false,
                new: new_he[i..j].iter().map(|h| h.1).collect(),
            });
            i = j;
        }
        old_keys.sort_unstable();
        old_keys.dedup();
        let of_new = changed.len();
        for &e in &old_keys {
            let key = self.edges[e as usize];
            // The new faces' edges came first, in key order.
            if changed[..of_new]
                .binary_search_by_key(&key, |c| c.key)
                .is_err()
            {
                changed.push(Changed {
                    key,
                    old: Some(e),
                    kept: Vec::new(),
                    removed: 0,
                    kept_elsewhere: false,
                    new: Vec::new(),
                });
            }
        }
        changed.sort_unstable_by_key(|c| c.key);
        // The old half-edges of every changed edge, found around its first vertex.
        for c in changed.iter_mut().filter(|c| c.old.is_some()) {
            for &f in self.vertex_faces(c.key.0) {
                for i in 0..3 {
                    if edge_key(&self.triangles[f.idx()], i) != c.key {
                        continue;
                    }
                    match faces.gone[f.idx()] {
                        true => c.removed += 1,
                        false => {
                            c.kept.push(3 * faces.fmap[f.idx()] + i as u32);
                            c.kept_elsewhere |= self.face_component[f.idx()] != faces.c0;
                        }
                    }
                }
            }
            c.kept.sort_unstable();
        }
        changed
    }

    /// The edges after the update: the old ones still in use merged with the new ones, in
    /// key order.
    fn merged_edges(&self, changed: &[Changed], n_new_faces: usize) -> MergedEdges {
        let mut edges = Vec::with_capacity(self.edges.len() + 3 * n_new_faces / 2);
        let mut edge_face_count = Vec::with_capacity(edges.capacity());
        let mut remap = vec![NONE; self.edges.len()];
        let mut index_of_changed = vec![NONE; changed.len()];
        let (mut e, mut k) = (0usize, 0usize);
        while e < self.edges.len() || k < changed.len() {
            let take_changed =
                k < changed.len() && (e >= self.edges.len() || changed[k].key <= self.edges[e]);
            if take_changed {
                let c = &changed[k];
                if c.old == Some(e as u32) {
                    e += 1;
                }
                if c.count() > 0 {
                    index_of_changed[k] = edges.len() as u32;
                    if let Some(o) = c.old {
                        remap[o as usize] = edges.len() as u32;
                    }
                    edges.push(c.key);
                    edge_face_count.push(c.count() as u32);
                }
                k += 1;
            } else {
                remap[e] = edges.len() as u32;
                edges.push(self.edges[e]);
                edge_face_count.push(self.edge_face_count[e]);
                e += 1;
            }
        }
        MergedEdges {
            edges,
            edge_face_count,
            remap,
            index_of_changed,
        }
    }

    /// The half-edges after the update: carried over through the face map, then the changed
    /// edges paired again by the build's rule.
    fn paired_halfedges(
        &self,
        mesh: &TriMesh,
        faces: &Renumbering,
        changed: &[Changed],
        merged: &MergedEdges,
    ) -> PairedHalfedges {
        let nh = 3 * mesh.n_faces();
        let mut halfedge_edge = vec![NONE; nh];
        let mut opposite = vec![NONE; nh];
        for f in 0..self.triangles.len() {
            if faces.gone[f] {
                continue;
            }
            let g = faces.fmap[f] as usize;
            for i in 0..3 {
                let e = self.halfedge_edge[3 * f + i] as usize;
                halfedge_edge[3 * g + i] = merged.remap[e];
                let o = self.opposite[3 * f + i];
                if o != NONE {
                    let of = faces.fmap[(o / 3) as usize];
                    if of != NONE {
                        opposite[3 * g + i] = 3 * of + o % 3;
                    }
                }
            }
        }
        let from = |h: u32| mesh.triangles[(h / 3) as usize][(h % 3) as usize];
        let mut non_manifold_edges: Vec<(EdgeKey, usize)> = Vec::new();
        let mut inconsistent_edges: Vec<EdgeKey> = Vec::new();
        let mut hs: Vec<u32> = Vec::new();
        for (c, &index) in changed.iter().zip(&merged.index_of_changed) {
            hs.clear();
            hs.extend(c.kept.iter().chain(&c.new));
            hs.sort_unstable();
            for &h in &hs {
                halfedge_edge[h as usize] = index;
                opposite[h as usize] = NONE;
            }
            match hs.len() {
                0 | 1 => {}
                2 => {
                    let (h0, h1) = (hs[0], hs[1]);
                    if from(h0) != from(h1) {
                        opposite[h0 as usize] = h1;
                        opposite[h1 as usize] = h0;
                    } else {
                        inconsistent_edges.push(c.key);
                    }
                }
                n => non_manifold_edges.push((c.key, n)),
            }
        }
        let is_changed = |key: &EdgeKey| changed.binary_search_by_key(key, |c| c.key).is_ok();
        non_manifold_edges.extend(
            self.non_manifold_edges
                .iter()
                .filter(|(key, _)| !is_changed(key)),
        );
        non_manifold_edges.sort_unstable();
        inconsistent_edges.extend(self.inconsistent_edges.iter().filter(|k| !is_changed(k)));
        inconsistent_edges.sort_unstable();
        PairedHalfedges {
            halfedge_edge,
            opposite,
            non_manifold_edges,
            inconsistent_edges,
        }
    }

    /// The face labels and component summaries after the update: the new faces join the
    /// removed faces' component, whose counts change by what came and went; labels are
    /// renumbered in order of first face. `None` when a component emptied (the labels would
    /// not match the build's).
    fn components_after(
        &self,
        mesh: &TriMesh,
        removed: &[FaceId],
        faces: &Renumbering,
        changed: &[Changed],
        (vf_offsets, vf_faces): (&[u32], &[FaceId]),
    ) -> Option<(Vec<u32>, Vec<ComponentInfo>)> {
        let (nf, c0) = (mesh.n_faces(), faces.c0);
        let mut face_component: Vec<u32> = Vec::with_capacity(nf);
        face_component.extend(
            (0..self.triangles.len())
                .filter(|&f| !faces.gone[f])
                .map(|f| self.face_component[f]),
        );
        face_component.resize(nf, c0);
        let mut components = self.components.clone();
        {
            let info = &mut components[c0 as usize];
            info.faces = info.faces + faces.new_faces.len() - removed.len();
            let born = changed
                .iter()
                .filter(|c| c.old.is_none() && c.count() > 0)
                .count();
            let died = changed
                .iter()
                .filter(|c| c.old.is_some() && c.count() == 0)
                .count();
            info.edges = info.edges + born - died;
            let mut touched: Vec<VertexId> = removed
                .iter()
                .flat_map(|f| self.triangles[f.idx()])
                .chain(faces.new_faces.clone().flat_map(|f| mesh.triangles[f]))
                .collect();
            touched.sort_unstable();
            touched.dedup();
            let in_c0_after = |v: VertexId| {
                let (a, b) = (
                    vf_offsets[v.idx()] as usize,
                    vf_offsets[v.idx() + 1] as usize,
                );
                vf_faces[a..b].iter().any(|f| face_component[f.idx()] == c0)
            };
            for v in touched {
                let before = v.idx() < self.n_vertices
                    && self
                        .vertex_faces(v)
                        .iter()
                        .any(|f| self.face_component[f.idx()] == c0);
                match (before, in_c0_after(v)) {
                    (false, true) => info.vertices += 1,
                    (true, false) => info.vertices -= 1,
                    _ => {}
                }
            }
        }
        let n_comp = components.len();
        let mut relabel = vec![NONE; n_comp];
        let mut next = 0u32;
        for label in face_component.iter_mut() {
            let l = *label as usize;
            if relabel[l] == NONE {
                relabel[l] = next;
                next += 1;
            }
            *label = relabel[l];
        }
        if next as usize != n_comp {
            return None;
        }
        let mut ordered = components.clone();
        for (l, info) in components.into_iter().enumerate() {
            ordered[relabel[l] as usize] = info;
        }
        Some((face_component, ordered))
    }
}

/// The undirected edge of half-edge `i` of triangle `t`.
fn edge_key(t: &[VertexId; 3], i: usize) -> EdgeKey {
    EdgeKey::new(t[i], t[(i + 1) % 3])
}

/// The components stay as they were when the new faces are edge-connected, every edge that
/// joined a kept face to a removed one joins it to a new one, and the new faces touch no
/// other component.
fn components_unchanged(changed: &[Changed], new_faces: Range<usize>) -> bool {
    let first = new_faces.start;
    let mut sets = UnionFind::new(new_faces.len());
    for c in changed {
        if c.removed > 0 && !c.kept.is_empty() && c.new.is_empty() {
            return false;
        }
        if !c.new.is_empty() && c.kept_elsewhere {
            return false;
        }
        for h in c.new.iter().skip(1) {
            sets.union((c.new[0] / 3) as usize - first, (*h / 3) as usize - first);
        }
    }
    sets.count() == 1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;
    use rand::{Rng, SeedableRng};

    /// `mesh` with the fan of `v` replaced by a fan around a new vertex (the same ring), as
    /// the stitcher leaves it: kept faces in order, new ones appended.
    fn refan(mesh: &TriMesh, topo: &Topology, v: VertexId) -> (TriMesh, Vec<FaceId>) {
        let fan: Vec<FaceId> = topo.vertex_faces(v).to_vec();
        let w = VertexId::new(mesh.n_vertices());
        let mut positions = mesh.positions.clone();
        positions.push(mesh.positions[v.idx()] + nalgebra::Vector3::new(1e-3, 0.0, 0.0));
        let mut triangles: Vec<[VertexId; 3]> = (0..mesh.n_faces())
            .filter(|f| !fan.contains(&FaceId::new(*f)))
            .map(|f| mesh.triangles[f])
            .collect();
        triangles.extend(
            fan.iter()
                .map(|f| mesh.triangles[f.idx()].map(|u| if u == v { w } else { u })),
        );
        (
            TriMesh {
                positions,
                triangles,
            },
            fan,
        )
    }

    /// The two faces of an interior edge replaced by the other diagonal's pair (no new
    /// vertex), when that makes no edge twice.
    fn flip(
        mesh: &TriMesh,
        topo: &Topology,
        f: FaceId,
        i: usize,
    ) -> Option<(TriMesh, Vec<FaceId>)> {
        let g = topo.neighbor(f, i)?;
        let t = mesh.triangles[f.idx()];
        let (a, b, c) = (t[i], t[(i + 1) % 3], t[(i + 2) % 3]);
        let d = mesh.triangles[g.idx()]
            .into_iter()
            .find(|&x| x != a && x != b)?;
        if topo.vertex_neighbors(c).contains(&d) {
            return None;
        }
        let mut triangles: Vec<[VertexId; 3]> = (0..mesh.n_faces())
            .filter(|&k| k != f.idx() && k != g.idx())
            .map(|k| mesh.triangles[k])
            .collect();
        triangles.push([c, a, d]);
        triangles.push([d, b, c]);
        Some((
            TriMesh {
                positions: mesh.positions.clone(),
                triangles,
            },
            vec![f, g],
        ))
    }

    /// Random fan replacements and flips on closed, open, multi-component and higher-genus
    /// meshes: the update equals the build every time (the debug assertion inside checks
    /// it too; this test states it in release builds).
    #[test]
    fn the_update_equals_the_build_after_random_replacements() {
        let two = {
            let mut a = generators::icosphere(1.0, 1);
            let b = generators::disk(1.0, 3, 8);
            let n = a.n_vertices() as u32;
            a.positions.extend(
                b.positions
                    .iter()
                    .map(|p| p + nalgebra::Vector3::new(5.0, 0.0, 0.0)),
            );
            a.triangles
                .extend(b.triangles.iter().map(|t| t.map(|v| VertexId(v.0 + n))));
            a
        };
        let meshes = [
            ("sphere", generators::icosphere(1.0, 2)),
            ("disk", generators::disk(1.0, 4, 10)),
            ("torus", generators::torus(2.0, 0.5, 12, 8)),
            ("genus-2 plate", generators::genus_plate(2, 6)),
            ("sphere and disk", two),
        ];
        let mut rng = crate::Rng::seed_from_u64(7);
        let mut updated = 0;
        for (name, mut mesh) in meshes {
            let mut topo = Topology::build(&mesh);
            for step in 0..40 {
                let next = match step % 2 {
                    0 => {
                        let v = VertexId::new(rng.random_range(0..mesh.n_vertices()));
                        (!topo.vertex_faces(v).is_empty()).then(|| refan(&mesh, &topo, v))
                    }
                    _ => {
                        let f = FaceId::new(rng.random_range(0..mesh.n_faces()));
                        flip(&mesh, &topo, f, rng.random_range(0..3))
                    }
                };
                let Some((after, removed)) = next else {
                    continue;
                };
                let built = Topology::build(&after);
                if !built.is_oriented_manifold() {
                    continue;
                }
                updated += topo.updated(&after, &removed).is_some() as usize;
                let t = topo.after_replacing(&after, &removed);
                assert!(t.same_as(&built), "{name}, step {step}");
                (mesh, topo) = (after, t);
            }
        }
        assert!(updated > 100, "the update path ran {updated} times");
    }

    /// Replacements that could change the components are built from scratch: faces that
    /// split off, and new faces that join two components.
    #[test]
    fn component_changes_fall_back_to_the_build() {
        let m = generators::disk(1.0, 2, 6);
        let topo = Topology::build(&m);
        // The fan of the centre replaced by two faces that are not edge-connected.
        let fan: Vec<FaceId> = topo.vertex_faces(VertexId(0)).to_vec();
        let mut triangles: Vec<[VertexId; 3]> = (0..m.n_faces())
            .filter(|f| !fan.contains(&FaceId::new(*f)))
            .map(|f| m.triangles[f])
            .collect();
        triangles.push(m.triangles[fan[0].idx()]);
        triangles.push(m.triangles[fan[3].idx()]);
        let split = TriMesh {
            positions: m.positions.clone(),
            triangles,
        };
        assert!(topo.updated(&split, &fan).is_none());
        assert!(topo
            .after_replacing(&split, &fan)
            .same_as(&Topology::build(&split)));
        // A kept face order that is not the stitcher's.
        let mut shuffled = m.clone();
        let last = shuffled.triangles.remove(5);
        shuffled.triangles.swap(0, 1);
        shuffled.triangles.push(last);
        assert!(topo.updated(&shuffled, &[FaceId(5)]).is_none());
    }
}
