//! Topology derived from a [`TriMesh`]'s triangles (never stored separately from them).
//!
//! Half-edges are implicit: half-edge `3·f + i` runs `t[i] → t[(i+1)%3]` of face `f = [t0,t1,t2]`.
//! `opposite` pairs two half-edges of one undirected edge when exactly two faces share it
//! *with opposite directions* (a manifold, consistently oriented edge). Every other case is
//! recorded so that `check` can report it by element: boundary edges (one face),
//! non-manifold edges (three or more faces), and inconsistently oriented edges (two faces
//! traversing the edge in the same direction).
//!
//! Built by sorting, not hashing, so that every list comes out in a deterministic order.

mod update;

use super::{TriMesh, UnionFind};
use crate::ids::{EdgeKey, FaceId, HalfedgeId, VertexId};
use serde::Serialize;

const NONE: u32 = u32::MAX;

/// Per-component summary (components are face sets connected through shared edges).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ComponentInfo {
    /// Number of faces.
    pub faces: usize,
    /// Number of distinct vertices referenced by the faces.
    pub vertices: usize,
    /// Number of distinct undirected edges.
    pub edges: usize,
    /// Number of boundary loops.
    pub boundary_loops: usize,
    /// Euler characteristic V − E + F.
    pub euler: i64,
    /// Genus from χ = 2 − 2g − b; `None` when it is not a non-negative integer (non-manifold
    /// or non-orientable components).
    pub genus: Option<u32>,
}

/// Derived connectivity of a triangle mesh.
#[derive(Clone, Debug)]
pub struct Topology {
    triangles: Vec<[VertexId; 3]>,
    n_vertices: usize,
    /// Opposite half-edge or `NONE`.
    opposite: Vec<u32>,
    /// Undirected edge of each half-edge.
    halfedge_edge: Vec<u32>,
    /// Unique undirected edges, sorted.
    edges: Vec<EdgeKey>,
    /// Number of faces on each edge.
    edge_face_count: Vec<u32>,
    /// Faces around each vertex (CSR).
    vf_offsets: Vec<u32>,
    vf_faces: Vec<FaceId>,
    /// Component label per face.
    face_component: Vec<u32>,
    components: Vec<ComponentInfo>,
    boundary_loops: Vec<Vec<VertexId>>,
    boundary_loop_component: Vec<u32>,
    non_manifold_edges: Vec<(EdgeKey, usize)>,
    inconsistent_edges: Vec<EdgeKey>,
    /// Computed on first use: Algorithm 1 rebuilds the topology after every patch and
    /// certifies the vertices it touched itself (`invariants::non_manifold_vertices_among`).
    non_manifold_vertices: std::sync::OnceLock<Vec<VertexId>>,
}

impl Topology {
    /// Derive the topology. Works on any mesh whose indices are in range (see
    /// [`TriMesh::validate`]); non-manifold and inconsistently oriented parts are recorded,
    /// not rejected.
    pub fn build(mesh: &TriMesh) -> Topology {
        let nf = mesh.n_faces();
        let nv = mesh.n_vertices();
        let nh = 3 * nf;
        // (key, halfedge), key = (min, max); sorted → groups of one undirected edge. Sorted
        // by a counting sort on `min` and small sorts inside each vertex's bucket (a vertex
        // has a handful of half-edges): the same order as sorting the whole list, in linear
        // time — this runs after every patch of Algorithm 1.
        let mut start = vec![0u32; nv + 1];
        for t in &mesh.triangles {
            for i in 0..3 {
                let m = t[i].0.min(t[(i + 1) % 3].0) as usize;
                start[m + 1] += 1;
            }
        }
        for k in 0..nv {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut hes: Vec<(u32, u32, u32)> = vec![(0, 0, 0); nh];
        for (f, t) in mesh.triangles.iter().enumerate() {
            for i in 0..3 {
                let (a, b) = (t[i].0, t[(i + 1) % 3].0);
                let m = a.min(b) as usize;
                hes[fill[m] as usize] = (a.min(b), a.max(b), (3 * f + i) as u32);
                fill[m] += 1;
            }
        }
        for k in 0..nv {
            hes[start[k] as usize..start[k + 1] as usize].sort_unstable();
        }
        let mut opposite = vec![NONE; nh];
        let mut halfedge_edge = vec![NONE; nh];
        let mut edges = Vec::new();
        let mut edge_face_count = Vec::new();
        let mut non_manifold_edges = Vec::new();
        let mut inconsistent_edges = Vec::new();
        let mut sets = UnionFind::new(nf);
        let from = |h: u32| mesh.triangles[(h / 3) as usize][(h % 3) as usize];
        let mut i = 0;
        while i < hes.len() {
            let mut j = i;
            while j < hes.len() && hes[j].0 == hes[i].0 && hes[j].1 == hes[i].1 {
                j += 1;
            }
            let e = edges.len() as u32;
            let key = EdgeKey(VertexId(hes[i].0), VertexId(hes[i].1));
            edges.push(key);
            edge_face_count.push((j - i) as u32);
            for g in &hes[i..j] {
                halfedge_edge[g.2 as usize] = e;
                sets.union((hes[i].2 / 3) as usize, (g.2 / 3) as usize);
            }
            match j - i {
                1 => {}
                2 => {
                    let (h0, h1) = (hes[i].2, hes[i + 1].2);
                    if from(h0) != from(h1) {
                        opposite[h0 as usize] = h1;
                        opposite[h1 as usize] = h0;
                    } else {
                        inconsistent_edges.push(key);
                    }
                }
                k => non_manifold_edges.push((key, k)),
            }
            i = j;
        }

        let (vf_offsets, vf_faces) = vertex_face_lists(mesh);

        // Components: faces joined through any shared edge.
        let mut face_component = vec![0u32; nf];
        let mut root_label = vec![NONE; nf];
        let mut n_comp = 0u32;
        for (f, label) in face_component.iter_mut().enumerate() {
            let r = sets.find(f);
            if root_label[r] == NONE {
                root_label[r] = n_comp;
                n_comp += 1;
            }
            *label = root_label[r];
        }

        let mut topo = Topology {
            triangles: mesh.triangles.clone(),
            n_vertices: nv,
            opposite,
            halfedge_edge,
            edges,
            edge_face_count,
            vf_offsets,
            vf_faces,
            face_component,
            components: Vec::new(),
            boundary_loops: Vec::new(),
            boundary_loop_component: Vec::new(),
            non_manifold_edges,
            inconsistent_edges,
            non_manifold_vertices: std::sync::OnceLock::new(),
        };
        topo.boundary_loops = topo.trace_boundary_loops();
        topo.boundary_loop_component = topo.loop_components();
        topo.components = topo.summarise_components(n_comp as usize);
        topo
    }

    /// The component of each boundary loop (of a face at its first vertex).
    fn loop_components(&self) -> Vec<u32> {
        self.boundary_loops
            .iter()
            .map(|l| self.face_component[self.vertex_faces(l[0])[0].idx()])
            .collect()
    }

    /// Each component's boundary loops from `boundary_loop_component`, and its χ and genus
    /// from its counts.
    fn recount_loops_and_genus(&mut self) {
        for c in &mut self.components {
            c.boundary_loops = 0;
        }
        for &l in &self.boundary_loop_component {
            self.components[l as usize].boundary_loops += 1;
        }
        for c in &mut self.components {
            c.euler = c.vertices as i64 - c.edges as i64 + c.faces as i64;
            c.genus = genus(c.euler, c.boundary_loops);
        }
    }

    fn find_non_manifold_vertices(&self) -> Vec<VertexId> {
        // A vertex is manifold when its faces form a single fan: connected through edges at
        // the vertex that are manifold (exactly two faces, opposite directions).
        let mut out = Vec::new();
        let mut sets = UnionFind::default();
        for v in 0..self.n_vertices {
            let faces = self.vertex_faces(VertexId::new(v));
            if faces.len() <= 1 {
                continue;
            }
            sets.reset(faces.len());
            for (a, &f) in faces.iter().enumerate() {
                let t = self.triangles[f.idx()];
                for i in 0..3 {
                    if t[i].idx() != v && t[(i + 1) % 3].idx() != v {
                        continue;
                    }
                    let o = self.opposite[3 * f.idx() + i];
                    if o == NONE {
                        continue;
                    }
                    let g = FaceId(o / 3);
                    if let Some(b) = faces.iter().position(|&x| x == g) {
                        sets.union(a, b);
                    }
                }
            }
            let r0 = sets.find(0);
            if (1..faces.len()).any(|k| sets.find(k) != r0) {
                out.push(VertexId::new(v));
            }
        }
        out
    }

    fn trace_boundary_loops(&self) -> Vec<Vec<VertexId>> {
        // Boundary half-edges: edges with exactly one face. Each loop runs in the direction of
        // its face's half-edges, so the surface lies to the left of the loop.
        let mut outgoing: Vec<Vec<u32>> = vec![Vec::new(); self.n_vertices];
        for h in 0..self.opposite.len() {
            if self.edge_face_count[self.halfedge_edge[h] as usize] == 1 {
                outgoing[self.from(HalfedgeId(h as u32)).idx()].push(h as u32);
            }
        }
        let mut used = vec![false; self.opposite.len()];
        let mut loops = Vec::new();
        for start in 0..self.opposite.len() {
            if used[start] || self.edge_face_count[self.halfedge_edge[start] as usize] != 1 {
                continue;
            }
            let mut lp = Vec::new();
            let mut h = start as u32;
            loop {
                used[h as usize] = true;
                lp.push(self.from(HalfedgeId(h)));
                let to = self.to(HalfedgeId(h));
                // At a pinch vertex several boundary half-edges leave; take the first unused.
                match outgoing[to.idx()]
                    .iter()
                    .copied()
                    .find(|&g| !used[g as usize])
                {
                    Some(g) => h = g,
                    None => break,
                }
            }
            loops.push(lp);
        }
        loops
    }

    fn summarise_components(&self, n: usize) -> Vec<ComponentInfo> {
        let mut faces = vec![0usize; n];
        let mut edges = vec![0usize; n];
        let mut verts = vec![0usize; n];
        let mut loops = vec![0usize; n];
        for &c in &self.face_component {
            faces[c as usize] += 1;
        }
        let mut edge_seen = vec![false; self.edges.len()];
        for h in 0..self.halfedge_edge.len() {
            let e = self.halfedge_edge[h] as usize;
            if !edge_seen[e] {
                edge_seen[e] = true;
                edges[self.face_component[h / 3] as usize] += 1;
            }
        }
        // A vertex counts once in every component it belongs to (a pinch vertex joining
        // two edge-connected components belongs to both).
        let mut cs: Vec<u32> = Vec::new();
        for v in 0..self.n_vertices {
            cs.clear();
            cs.extend(
                self.vertex_faces(VertexId::new(v))
                    .iter()
                    .map(|f| self.face_component[f.idx()]),
            );
            cs.sort_unstable();
            cs.dedup();
            for &c in &cs {
                verts[c as usize] += 1;
            }
        }
        for &c in &self.boundary_loop_component {
            loops[c as usize] += 1;
        }
        (0..n)
            .map(|c| {
                let euler = verts[c] as i64 - edges[c] as i64 + faces[c] as i64;
                ComponentInfo {
                    faces: faces[c],
                    vertices: verts[c],
                    edges: edges[c],
                    boundary_loops: loops[c],
                    euler,
                    genus: genus(euler, loops[c]),
                }
            })
            .collect()
    }

    /// Number of vertices of the mesh this was built from.
    pub fn n_vertices(&self) -> usize {
        self.n_vertices
    }

    /// Number of faces.
    pub fn n_faces(&self) -> usize {
        self.triangles.len()
    }

    /// Tail vertex of a half-edge.
    #[inline]
    pub fn from(&self, h: HalfedgeId) -> VertexId {
        self.triangles[h.face().idx()][h.local()]
    }

    /// Head vertex of a half-edge.
    #[inline]
    pub fn to(&self, h: HalfedgeId) -> VertexId {
        self.triangles[h.face().idx()][(h.local() + 1) % 3]
    }

    /// The paired half-edge across a manifold, consistently oriented edge.
    #[inline]
    pub fn opposite(&self, h: HalfedgeId) -> Option<HalfedgeId> {
        let o = self.opposite[h.idx()];
        (o != NONE).then_some(HalfedgeId(o))
    }

    /// The face across half-edge `i` of face `f`, if the edge is manifold.
    #[inline]
    pub fn neighbor(&self, f: FaceId, i: usize) -> Option<FaceId> {
        self.opposite(HalfedgeId::of(f, i)).map(HalfedgeId::face)
    }

    /// True when the half-edge's edge has exactly one face.
    #[inline]
    pub fn is_boundary_halfedge(&self, h: HalfedgeId) -> bool {
        self.edge_face_count[self.halfedge_edge[h.idx()] as usize] == 1
    }

    /// Index of the undirected edge of a half-edge (into [`Topology::edges`]).
    #[inline]
    pub fn edge_index(&self, h: HalfedgeId) -> usize {
        self.halfedge_edge[h.idx()] as usize
    }

    /// All undirected edges, sorted.
    pub fn edges(&self) -> &[EdgeKey] {
        &self.edges
    }

    /// Number of faces incident to each undirected edge (parallel to [`Topology::edges`]).
    pub fn edge_face_counts(&self) -> &[u32] {
        &self.edge_face_count
    }

    /// Faces incident to a vertex (unordered; each face once).
    #[inline]
    pub fn vertex_faces(&self, v: VertexId) -> &[FaceId] {
        let (a, b) = (
            self.vf_offsets[v.idx()] as usize,
            self.vf_offsets[v.idx() + 1] as usize,
        );
        &self.vf_faces[a..b]
    }

    /// Distinct vertices adjacent to `v` through an edge, sorted.
    pub fn vertex_neighbors(&self, v: VertexId) -> Vec<VertexId> {
        let mut out: Vec<VertexId> = Vec::new();
        for f in self.vertex_faces(v) {
            for w in self.triangles[f.idx()] {
                if w != v {
                    out.push(w);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// True when the vertex lies on a boundary edge.
    pub fn is_boundary_vertex(&self, v: VertexId) -> bool {
        self.vertex_faces(v).iter().any(|f| {
            (0..3).any(|i| {
                let h = HalfedgeId::of(*f, i);
                self.is_boundary_halfedge(h) && (self.from(h) == v || self.to(h) == v)
            })
        })
    }

    /// Boundary loops as ordered vertex cycles; the surface lies to the left of each loop
    /// (the loop follows its faces' half-edge direction).
    pub fn boundary_loops(&self) -> &[Vec<VertexId>] {
        &self.boundary_loops
    }

    /// Component label of each face (0-based, in order of first face).
    pub fn face_components(&self) -> &[u32] {
        &self.face_component
    }

    /// Per-component summaries.
    pub fn components(&self) -> &[ComponentInfo] {
        &self.components
    }

    /// Euler characteristic V − E + F of the referenced part of the mesh.
    pub fn euler_characteristic(&self) -> i64 {
        // V − E + F of the whole complex (a vertex shared by two components counts once
        // here and once in each component's own χ).
        let v = (0..self.n_vertices)
            .filter(|&v| !self.vertex_faces(VertexId::new(v)).is_empty())
            .count();
        v as i64 - self.edges.len() as i64 + self.triangles.len() as i64
    }

    /// Edges with three or more faces, with their face count.
    pub fn non_manifold_edges(&self) -> &[(EdgeKey, usize)] {
        &self.non_manifold_edges
    }

    /// Edges whose two faces traverse them in the same direction (orientation flips there).
    pub fn inconsistent_edges(&self) -> &[EdgeKey] {
        &self.inconsistent_edges
    }

    /// Vertices whose faces form more than one fan (pinch points), sorted.
    pub fn non_manifold_vertices(&self) -> &[VertexId] {
        self.non_manifold_vertices
            .get_or_init(|| self.find_non_manifold_vertices())
    }

    /// True when every edge has one or two faces, every vertex one fan, and orientation is
    /// consistent across every interior edge.
    pub fn is_oriented_manifold(&self) -> bool {
        self.non_manifold_edges.is_empty()
            && self.inconsistent_edges.is_empty()
            && self.non_manifold_vertices().is_empty()
    }
}

/// The genus from χ = 2 − 2g − b; `None` when it is not a non-negative integer.
fn genus(euler: i64, loops: usize) -> Option<u32> {
    let twice_g = 2 - euler - loops as i64;
    (twice_g >= 0 && twice_g % 2 == 0).then_some((twice_g / 2) as u32)
}

/// Vertex → faces (CSR): each vertex's faces in id order.
fn vertex_face_lists(mesh: &TriMesh) -> (Vec<u32>, Vec<FaceId>) {
    let nv = mesh.n_vertices();
    let mut vf_offsets = vec![0u32; nv + 1];
    for t in &mesh.triangles {
        for v in t {
            vf_offsets[v.idx() + 1] += 1;
        }
    }
    for k in 0..nv {
        vf_offsets[k + 1] += vf_offsets[k];
    }
    let mut fill = vf_offsets.clone();
    let mut vf_faces = vec![FaceId(0); 3 * mesh.n_faces()];
    for (f, t) in mesh.triangles.iter().enumerate() {
        for v in t {
            vf_faces[fill[v.idx()] as usize] = FaceId::new(f);
            fill[v.idx()] += 1;
        }
    }
    (vf_offsets, vf_faces)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;
    use nalgebra::Point3;

    /// Two triangles sharing the edge (v0, v1): each is the other's only neighbour, across the
    /// half-edge that runs along that edge; the other half-edges are boundary.
    #[test]
    fn neighbors_across_edges_and_vertex_neighbors() {
        let m = TriMesh::from_indices(
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
                Point3::new(0.0, -1.0, 0.0),
            ],
            &[[0, 1, 2], [1, 0, 3]],
        )
        .expect("valid");
        let t = Topology::build(&m);
        assert_eq!(t.neighbor(FaceId(0), 0), Some(FaceId(1)));
        assert_eq!(t.neighbor(FaceId(1), 0), Some(FaceId(0)));
        for i in 1..3 {
            assert_eq!(t.neighbor(FaceId(0), i), None);
            assert_eq!(t.neighbor(FaceId(1), i), None);
        }
        assert_eq!(
            t.vertex_neighbors(VertexId(0)),
            vec![VertexId(1), VertexId(2), VertexId(3)]
        );
        assert_eq!(
            t.vertex_neighbors(VertexId(2)),
            vec![VertexId(0), VertexId(1)]
        );
    }

    #[test]
    fn closed_surfaces_have_expected_genus() {
        let s = generators::icosphere(1.0, 2);
        let t = Topology::build(&s);
        assert!(t.is_oriented_manifold());
        assert_eq!(t.components().len(), 1);
        assert_eq!(t.components()[0].genus, Some(0));
        assert_eq!(t.euler_characteristic(), 2);
        let tor = generators::torus(2.0, 0.5, 24, 12);
        let tt = Topology::build(&tor);
        assert_eq!(tt.components()[0].genus, Some(1));
        assert!(tt.boundary_loops().is_empty());
    }

    /// Two tetrahedra sharing one vertex: two components, each a sphere with its 4 vertices
    /// (the shared vertex counts in both), while the whole complex has χ = 7 − 12 + 8 = 3.
    #[test]
    fn a_pinch_vertex_counts_in_both_components() {
        let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
        let tet = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
        let mut tris: Vec<[usize; 3]> = tet.to_vec();
        // Second tetrahedron on vertices 0, 4, 5, 6 (vertex 0 shared).
        let map = [0, 4, 5, 6];
        tris.extend(tet.iter().map(|t| t.map(|i| map[i])));
        let m = TriMesh::from_indices(
            vec![
                p(0.0, 0.0, 0.0),
                p(1.0, 0.0, 0.0),
                p(0.0, 1.0, 0.0),
                p(0.0, 0.0, 1.0),
                p(-1.0, 0.0, 0.0),
                p(0.0, -1.0, 0.0),
                p(0.0, 0.0, -1.0),
            ],
            &tris,
        )
        .expect("valid");
        let t = Topology::build(&m);
        assert_eq!(t.components().len(), 2);
        for c in t.components() {
            assert_eq!((c.faces, c.vertices, c.edges), (4, 4, 6));
            assert_eq!((c.euler, c.genus), (2, Some(0)));
        }
        assert_eq!(t.euler_characteristic(), 3);
        assert_eq!(t.non_manifold_vertices(), &[VertexId(0)]);
    }

    #[test]
    fn disk_has_one_boundary_loop_oriented_ccw() {
        let d = generators::disk(1.0, 4, 12);
        let t = Topology::build(&d);
        assert_eq!(t.boundary_loops().len(), 1);
        assert_eq!(t.components()[0].euler, 1);
        assert_eq!(t.components()[0].genus, Some(0));
        // Signed area of the boundary loop (xy plane, normals +z) is positive: surface on the left.
        let l = &t.boundary_loops()[0];
        let mut a = 0.0;
        for k in 0..l.len() {
            let p = d.positions[l[k].idx()];
            let q = d.positions[l[(k + 1) % l.len()].idx()];
            a += p.x * q.y - q.x * p.y;
        }
        assert!(a > 0.0);
        assert!(t.is_boundary_vertex(l[0]));
    }

    #[test]
    fn detects_non_manifold_edge_vertex_and_flip() {
        // Three triangles on edge (v0, v1).
        let p = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.5, 1.0, 0.0),
            Point3::new(0.5, -1.0, 0.0),
            Point3::new(0.5, 0.0, 1.0),
        ];
        let m = TriMesh::from_indices(p.clone(), &[[0, 1, 2], [1, 0, 3], [0, 1, 4]]).unwrap();
        let t = Topology::build(&m);
        assert_eq!(
            t.non_manifold_edges(),
            &[(EdgeKey(VertexId(0), VertexId(1)), 3)]
        );
        // Flipped neighbour.
        let m = TriMesh::from_indices(p.clone(), &[[0, 1, 2], [0, 1, 3]]).unwrap();
        let t = Topology::build(&m);
        assert_eq!(t.inconsistent_edges(), &[EdgeKey(VertexId(0), VertexId(1))]);
        assert!(!t.is_oriented_manifold());
        // Bow-tie: two triangles sharing only v0.
        let mut p2 = p;
        p2.push(Point3::new(-1.0, 0.5, 0.0));
        p2.push(Point3::new(-1.0, -0.5, 0.0));
        let m = TriMesh::from_indices(p2, &[[0, 1, 2], [0, 5, 6]]).unwrap();
        let t = Topology::build(&m);
        assert_eq!(t.non_manifold_vertices(), &[VertexId(0)]);
        assert_eq!(t.components().len(), 2);
    }
}
