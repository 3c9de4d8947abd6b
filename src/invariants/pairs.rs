//! The self-intersection search of a whole mesh ([`super::self_intersections`]): which pairs
//! of faces meet beyond the vertices and edges they share, decided exactly, in time close to
//! linear also on fans of long thin faces (issue 20).
//!
//! Two faces `f ≠ g` sharing at most one vertex meet (beyond that vertex) iff an edge of one
//! of them with neither endpoint in the other meets the other (closed segment against closed
//! triangle): with no shared vertex, the convex set `f ∩ g` has a point on the boundary of
//! `f` or of `g`; with the shared vertex `v`, the edges through `v` touch the other face at
//! `v` anyway and the test is the one of the edges opposite `v` (CGAL's rule,
//! [`crate::predicates::vertex_adjacent_triangles_intersect`]). So the search runs one query
//! per *edge* of the mesh, against a bounding-volume hierarchy over the faces whose subtrees
//! carry the vertices all their faces share: a subtree whose faces all contain an endpoint of
//! the edge is pruned whole, without looking at its faces. That removes the quadratic term of
//! a fan (every face of a 20,000-face fan contains its apex, and every box of it overlaps the
//! others near the apex): the spokes of the fan are pruned at the root, and a rim edge's box
//! meets a few faces only. Faces sharing an edge (two vertices) are tested per edge of the
//! mesh ([`edge_adjacent_triangles_overlap`]), faces with three shared vertices (duplicates)
//! meet, and a degenerate face is the pair `(f, f)` and takes no further part.
//!
//! The boxes are the exact minima and maxima of the coordinates, compared closed (`<=`): a
//! segment meeting a triangle has a point in both boxes, so the pruning loses no pair, and
//! every verdict is an exact predicate.

use crate::ids::{FaceId, VertexId};
use crate::mesh::TriMesh;
use crate::predicates::{
    coplanar_fan_is_embedded, edge_adjacent_triangles_overlap, segment_triangle_intersect,
};
use nalgebra::Point3;
use rayon::prelude::*;

/// Below this many faces the search does not use rayon.
pub(super) const PARALLEL_MIN_FACES: usize = 1024;

/// Faces per leaf of the hierarchy.
const LEAF_FACES: usize = 4;

/// What one search did: how many exact tests it ran (segment against triangle, edge-adjacent
/// pair, duplicate) and how many tree nodes it visited. Counts, not times: the tests of the
/// search's cost assert them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SearchStats {
    /// Exact segment–triangle tests (one per candidate edge–face pair).
    pub segment_tests: usize,
    /// Exact tests of two faces sharing an edge.
    pub edge_pair_tests: usize,
    /// Tree nodes visited by all queries.
    pub nodes_visited: usize,
}

/// Closed axis-aligned box, exact min/max of coordinates.
#[derive(Clone, Copy, Debug)]
struct Box3 {
    lo: [f64; 3],
    hi: [f64; 3],
}

impl Box3 {
    fn of(points: &[Point3<f64>]) -> Box3 {
        let mut b = Box3 {
            lo: [f64::INFINITY; 3],
            hi: [f64::NEG_INFINITY; 3],
        };
        for p in points {
            for k in 0..3 {
                b.lo[k] = b.lo[k].min(p[k]);
                b.hi[k] = b.hi[k].max(p[k]);
            }
        }
        b
    }
    fn union(&self, o: &Box3) -> Box3 {
        let mut b = *self;
        for k in 0..3 {
            b.lo[k] = b.lo[k].min(o.lo[k]);
            b.hi[k] = b.hi[k].max(o.hi[k]);
        }
        b
    }
    #[inline]
    fn overlaps(&self, o: &Box3) -> bool {
        (0..3).all(|k| self.lo[k] <= o.hi[k] && o.lo[k] <= self.hi[k])
    }
}

/// The vertices every face of a subtree contains (at most three).
#[derive(Clone, Copy, Debug, Default)]
struct Common {
    v: [Option<VertexId>; 3],
}

impl Common {
    fn of(t: &[VertexId; 3]) -> Common {
        Common {
            v: [Some(t[0]), Some(t[1]), Some(t[2])],
        }
    }
    fn contains(&self, x: VertexId) -> bool {
        self.v.contains(&Some(x))
    }
    fn meet(&self, o: &Common) -> Common {
        let mut c = Common::default();
        for (slot, x) in c.v.iter_mut().zip(self.v) {
            *slot = x.filter(|&x| o.contains(x));
        }
        c
    }
}

/// A node of the hierarchy: its box, the vertices all its faces share, and either two
/// children or a range of `order`.
struct Node {
    bbox: Box3,
    common: Common,
    kind: Kind,
}

enum Kind {
    Inner(usize, usize),
    Leaf(usize, usize),
}

/// A static hierarchy over the non-degenerate faces, split at the median of the longest axis
/// of the face centroids (ties by face id, so the tree does not depend on anything but the
/// mesh).
struct FaceTree {
    nodes: Vec<Node>,
    /// Face ids, leaf ranges index into it.
    order: Vec<usize>,
}

impl FaceTree {
    fn build(mesh: &TriMesh, faces: Vec<usize>, boxes: &[Box3]) -> FaceTree {
        let mut t = FaceTree {
            nodes: Vec::with_capacity(2 * faces.len() / LEAF_FACES + 1),
            order: faces,
        };
        if !t.order.is_empty() {
            let n = t.order.len();
            t.split(mesh, boxes, 0, n);
        }
        t
    }

    /// Build the subtree of `order[lo..hi]`; returns its node index.
    fn split(&mut self, mesh: &TriMesh, boxes: &[Box3], lo: usize, hi: usize) -> usize {
        let faces = &mut self.order[lo..hi];
        let bbox = faces
            .iter()
            .skip(1)
            .fold(boxes[faces[0]], |b, &f| b.union(&boxes[f]));
        if faces.len() <= LEAF_FACES {
            let common = faces
                .iter()
                .skip(1)
                .fold(Common::of(&mesh.triangles[faces[0]]), |c, &f| {
                    c.meet(&Common::of(&mesh.triangles[f]))
                });
            self.nodes.push(Node {
                bbox,
                common,
                kind: Kind::Leaf(lo, hi),
            });
            return self.nodes.len() - 1;
        }
        // Twice the box centre: only the order matters.
        let centre = |f: usize, k: usize| boxes[f].lo[k] + boxes[f].hi[k];
        let axis = (0..3)
            .max_by(|&a, &b| {
                let ext = |k: usize| bbox.hi[k] - bbox.lo[k];
                ext(a).total_cmp(&ext(b))
            })
            .unwrap_or(0);
        let mid = faces.len() / 2;
        faces.select_nth_unstable_by(mid, |&a, &b| {
            centre(a, axis).total_cmp(&centre(b, axis)).then(a.cmp(&b))
        });
        let me = self.nodes.len();
        self.nodes.push(Node {
            bbox,
            common: Common::default(),
            kind: Kind::Inner(0, 0),
        });
        let left = self.split(mesh, boxes, lo, lo + mid);
        let right = self.split(mesh, boxes, lo + mid, hi);
        self.nodes[me].common = self.nodes[left].common.meet(&self.nodes[right].common);
        self.nodes[me].kind = Kind::Inner(left, right);
        me
    }

    /// Call `hit` on every face whose box overlaps `q` and whose vertices `skip` does not
    /// refuse, pruning the subtrees whose common vertices `skip` refuses (then it refuses each
    /// of their faces). Returns the nodes visited.
    fn query(
        &self,
        mesh: &TriMesh,
        boxes: &[Box3],
        q: &Box3,
        skip: impl Fn(&Common) -> bool,
        mut hit: impl FnMut(usize),
    ) -> usize {
        let mut visited = 0;
        if self.nodes.is_empty() {
            return 0;
        }
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            visited += 1;
            let n = &self.nodes[i];
            if !n.bbox.overlaps(q) || skip(&n.common) {
                continue;
            }
            match n.kind {
                Kind::Inner(l, r) => {
                    stack.push(r);
                    stack.push(l);
                }
                Kind::Leaf(lo, hi) => {
                    for &g in &self.order[lo..hi] {
                        if boxes[g].overlaps(q) && !skip(&Common::of(&mesh.triangles[g])) {
                            hit(g);
                        }
                    }
                }
            }
        }
        visited
    }
}

/// What one edge's query found: pairs, exact tests, nodes visited.
type EdgeResult = (Vec<(FaceId, FaceId)>, usize, usize);

/// Stars of at least this many faces are tested for being a flat embedded fan.
const FAN_MIN_FACES: usize = 16;

/// Per vertex, whether its star (non-degenerate faces) has at least [`FAN_MIN_FACES`] faces
/// and is a coplanar fan whose faces meet only at the vertex and along shared edges
/// ([`coplanar_fan_is_embedded`]): then two faces of it sharing only that vertex do not meet.
fn flat_fans(mesh: &TriMesh, degenerate: &[bool]) -> Vec<bool> {
    let mut degree = vec![0usize; mesh.n_vertices()];
    for (t, _) in mesh.triangles.iter().zip(degenerate).filter(|(_, d)| !**d) {
        for v in t {
            degree[v.idx()] += 1;
        }
    }
    let mut stars: std::collections::HashMap<VertexId, Vec<usize>> = Default::default();
    for (f, t) in mesh
        .triangles
        .iter()
        .enumerate()
        .filter(|(f, _)| !degenerate[*f])
    {
        for &v in t.iter().filter(|v| degree[v.idx()] >= FAN_MIN_FACES) {
            stars.entry(v).or_default().push(f);
        }
    }
    let mut flat = vec![false; mesh.n_vertices()];
    for (v, faces) in stars {
        let sectors: Vec<[(Point3<f64>, VertexId); 2]> = faces
            .iter()
            .map(|&f| {
                let t = mesh.triangles[f];
                let k = t.iter().position(|&x| x == v).unwrap_or(0);
                let (x, y) = (t[(k + 1) % 3], t[(k + 2) % 3]);
                [(mesh.positions[x.idx()], x), (mesh.positions[y.idx()], y)]
            })
            .collect();
        flat[v.idx()] = coplanar_fan_is_embedded(&mesh.positions[v.idx()], &sectors);
    }
    flat
}

/// Self-intersecting face pairs `(f, g)`, `f < g`, sorted, with `(f, f)` for a degenerate
/// face (see the module documentation), and what the search did.
pub fn self_intersections_with_stats(mesh: &TriMesh) -> (Vec<(FaceId, FaceId)>, SearchStats) {
    let n = mesh.n_faces();
    // Small meshes (the local checks after every patch, flip and move of Algorithm 1) run on
    // the calling thread: waking rayon's workers for a few dozen faces cost more than the
    // test itself. The result is sorted, so it does not depend on the path taken.
    let parallel = n >= PARALLEL_MIN_FACES;
    let degenerate: Vec<bool> = if parallel {
        (0..n)
            .into_par_iter()
            .map(|f| super::is_degenerate(mesh, FaceId::new(f)))
            .collect()
    } else {
        (0..n)
            .map(|f| super::is_degenerate(mesh, FaceId::new(f)))
            .collect()
    };
    let boxes: Vec<Box3> = (0..n)
        .map(|f| Box3::of(&mesh.face_points(FaceId::new(f))))
        .collect();
    let mut pairs: Vec<(FaceId, FaceId)> = (0..n)
        .filter(|&f| degenerate[f])
        .map(|f| (FaceId::new(f), FaceId::new(f)))
        .collect();
    let mut stats = SearchStats::default();

    // Every edge of a non-degenerate face, with the face: sorted, each edge's faces are a run.
    let mut edge_faces: Vec<(VertexId, VertexId, usize)> = Vec::with_capacity(3 * n);
    for f in (0..n).filter(|&f| !degenerate[f]) {
        let t = mesh.triangles[f];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edge_faces.push((a.min(b), a.max(b), f));
        }
    }
    edge_faces.sort_unstable();
    let runs: Vec<&[(VertexId, VertexId, usize)]> = edge_faces
        .chunk_by(|x, y| (x.0, x.1) == (y.0, y.1))
        .collect();

    // Faces sharing two or three vertices: per edge.
    let third = |f: usize, a: VertexId, b: VertexId| {
        mesh.triangles[f]
            .into_iter()
            .find(|&v| v != a && v != b)
            .unwrap_or(a)
    };
    for run in &runs {
        let (a, b) = (run[0].0, run[0].1);
        for (i, &(_, _, f)) in run.iter().enumerate() {
            for &(_, _, g) in &run[i + 1..] {
                let (r, s) = (third(f, a, b), third(g, a, b));
                let meet = if r == s {
                    // The same three vertices: a duplicated face (counted on each of its
                    // three edges, deduplicated below).
                    true
                } else {
                    stats.edge_pair_tests += 1;
                    let p = |v: VertexId| mesh.positions[v.idx()];
                    edge_adjacent_triangles_overlap(&p(a), &p(b), &p(r), &p(s))
                };
                if meet {
                    pairs.push((FaceId::new(f.min(g)), FaceId::new(f.max(g))));
                }
            }
        }
    }

    // Faces sharing at most one vertex: one query per edge (module documentation).
    let tree = FaceTree::build(mesh, (0..n).filter(|&f| !degenerate[f]).collect(), &boxes);
    // A face g sharing only the vertex v with f, v the corner of f opposite the edge, does not
    // meet f when v's star is a flat embedded fan: skipped, and so is every subtree all of
    // whose faces are skipped for every face on the edge.
    let flat = flat_fans(mesh, &degenerate);
    let per_edge = |run: &&[(VertexId, VertexId, usize)]| {
        let (a, b) = (run[0].0, run[0].1);
        let (pa, pb) = (mesh.positions[a.idx()], mesh.positions[b.idx()]);
        let q = Box3::of(&[pa, pb]);
        let apex: Vec<(usize, Option<VertexId>)> = run
            .iter()
            .map(|&(_, _, f)| {
                let v = third(f, a, b);
                (f, flat[v.idx()].then_some(v))
            })
            .collect();
        let fan_skips = |c: &Common, v: Option<VertexId>| v.is_some_and(|v| c.contains(v));
        let skip = |c: &Common| {
            c.contains(a) || c.contains(b) || apex.iter().all(|&(_, v)| fan_skips(c, v))
        };
        let mut found = Vec::new();
        let mut tests = 0;
        let visited = tree.query(mesh, &boxes, &q, skip, |g| {
            tests += 1;
            if segment_triangle_intersect(&pa, &pb, &mesh.face_points(FaceId::new(g))) {
                let gc = Common::of(&mesh.triangles[g]);
                for &(f, _) in apex.iter().filter(|&&(_, v)| !fan_skips(&gc, v)) {
                    found.push((FaceId::new(f.min(g)), FaceId::new(f.max(g))));
                }
            }
        });
        (found, tests, visited)
    };
    let results: Vec<EdgeResult> = if parallel {
        runs.par_iter().map(per_edge).collect()
    } else {
        runs.iter().map(per_edge).collect()
    };
    for (found, tests, visited) in results {
        pairs.extend(found);
        stats.segment_tests += tests;
        stats.nodes_visited += visited;
    }
    pairs.sort_unstable();
    pairs.dedup();
    (pairs, stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;

    #[test]
    fn boxes_overlap_needs_overlap_on_every_axis() {
        let b = |lo: [f64; 3], hi: [f64; 3]| Box3 { lo, hi };
        let unit = b([0.0; 3], [1.0; 3]);
        assert!(
            unit.overlaps(&b([1.0, 0.5, 0.5], [2.0, 2.0, 2.0])),
            "touching counts"
        );
        for axis in 0..3 {
            let mut lo = [0.25; 3];
            let mut hi = [0.75; 3];
            lo[axis] = 1.5;
            hi[axis] = 2.0;
            assert!(!unit.overlaps(&b(lo, hi)), "apart along axis {axis}");
            assert!(!b(lo, hi).overlaps(&unit), "apart along axis {axis}");
        }
    }

    /// A disk: `n` rim vertices, joined to a centre vertex at height `lift` (`centre`; a
    /// flat disk at 0, a cone otherwise) or fanned from rim vertex 0 (the reader's
    /// triangulation of an `n`-gon), winding `turns` times around.
    fn fan(n: usize, centre: bool, lift: f64, turns: f64) -> TriMesh {
        use std::f64::consts::TAU;
        let rim = (0..n).map(|i| {
            let a = turns * TAU * i as f64 / n as f64;
            Point3::new(a.cos(), a.sin(), 0.0)
        });
        let (positions, tris): (Vec<Point3<f64>>, Vec<[usize; 3]>) = if centre {
            let closed = if turns == 1.0 { n } else { n - 1 };
            (
                std::iter::once(Point3::new(0.0, 0.0, lift))
                    .chain(rim)
                    .collect(),
                (0..closed).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect(),
            )
        } else {
            (rim.collect(), (1..n - 1).map(|i| [0, i, i + 1]).collect())
        };
        TriMesh::from_indices(positions, &tris).expect("fan")
    }

    /// Issue 20, item 2: the search was quadratic on fans of long thin faces (every face
    /// box overlaps every other near the apex; a 20,000-face fan took over a minute in
    /// `check`). Now the exact tests and the visited nodes grow linearly: a fan 4 times larger
    /// costs at most about 4 times as many (quadratic would be 16), and a few per face.
    #[test]
    fn self_intersection_search_is_linear_on_long_thin_fans() {
        for (centre, lift) in [(true, 0.0), (false, 0.0), (true, 0.5)] {
            let (small, large) = (fan(1000, centre, lift, 1.0), fan(4000, centre, lift, 1.0));
            let (ps, ss) = self_intersections_with_stats(&small);
            let (pl, sl) = self_intersections_with_stats(&large);
            assert!(ps.is_empty() && pl.is_empty(), "a flat disk is embedded");
            let per_face = |s: &SearchStats, m: &TriMesh| {
                (
                    s.segment_tests as f64 / m.n_faces() as f64,
                    s.nodes_visited as f64 / m.n_faces() as f64,
                )
            };
            let (ts, vs) = per_face(&ss, &small);
            let (tl, vl) = per_face(&sl, &large);
            assert!(tl <= 8.0 && vl <= 200.0, "centre {centre}: {sl:?}");
            assert!(
                tl <= 1.5 * ts + 1.0 && vl <= 1.5 * vs + 10.0,
                "centre {centre}: {ss:?} → {sl:?}"
            );
            // Still exact: a thin vertical triangle piercing the fan is found.
            let mut bad = large.clone();
            let n = bad.positions.len() as u32;
            bad.positions.extend([
                Point3::new(0.3, 0.3, -1.0),
                Point3::new(0.35, 0.3, 1.0),
                Point3::new(0.3, 0.35, 1.0),
            ]);
            bad.triangles
                .push([VertexId(n), VertexId(n + 1), VertexId(n + 2)]);
            let (pairs, _) = self_intersections_with_stats(&bad);
            assert!(!pairs.is_empty(), "centre {centre}");
            let brute = brute_force(&bad, &pairs);
            assert_eq!(pairs, brute, "centre {centre}");
        }
    }

    /// The pairs among the faces named in `hint` and every other face, by
    /// [`super::super::faces_intersect`] (all pairs of 4,000 faces would be slow in a test).
    fn brute_force(m: &TriMesh, hint: &[(FaceId, FaceId)]) -> Vec<(FaceId, FaceId)> {
        let mut faces: Vec<FaceId> = hint.iter().flat_map(|&(f, g)| [f, g]).collect();
        faces.sort_unstable();
        faces.dedup();
        let mut v = Vec::new();
        for &f in &faces {
            for g in m.faces().filter(|&g| g != f) {
                if super::super::faces_intersect(m, f, g) {
                    v.push((f.min(g), f.max(g)));
                }
            }
        }
        v.sort_unstable();
        v.dedup();
        v
    }

    /// A flat fan that winds twice around its apex (or a polygon winding twice) overlaps
    /// itself: the fan certificate refuses it and the search finds the brute-force pairs.
    #[test]
    fn a_flat_fan_winding_twice_is_not_skipped() {
        for centre in [true, false] {
            let m = fan(40, centre, 0.0, 2.0);
            let (pairs, _) = self_intersections_with_stats(&m);
            let mut brute = Vec::new();
            for f in m.faces() {
                for g in m.faces().filter(|&g| g > f) {
                    if super::super::faces_intersect(&m, f, g) {
                        brute.push((f, g));
                    }
                }
            }
            assert!(brute.len() > 10, "centre {centre}: {}", brute.len());
            assert_eq!(pairs, brute, "centre {centre}");
        }
    }

    #[test]
    fn coplanar_fan_certificate_refuses_folds_shared_rays_and_bent_fans() {
        let c = Point3::new(0.0, 0.0, 0.0);
        let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
        let s = |a: Point3<f64>, ka: u32, b: Point3<f64>, kb: u32| [(a, ka), (b, kb)];
        // Two sectors sharing the ray to key 2: embedded; the same ray reached by another
        // key (a duplicate vertex): not.
        let x = p(1.0, 0.0, 0.0);
        let y = p(0.0, 1.0, 0.0);
        let z = p(-1.0, 0.0, 0.0);
        assert!(coplanar_fan_is_embedded(
            &c,
            &[s(x, 1, y, 2), s(y, 2, z, 3)]
        ));
        assert!(
            coplanar_fan_is_embedded(&c, &[s(y, 2, z, 3), s(y, 2, x, 1)]),
            "either orientation"
        );
        assert!(!coplanar_fan_is_embedded(
            &c,
            &[s(x, 1, y, 2), s(y, 9, z, 3)]
        ));
        // Overlapping sectors (a fold).
        assert!(!coplanar_fan_is_embedded(
            &c,
            &[s(x, 1, y, 2), s(p(1.0, 1.0, 0.0), 4, z, 3)]
        ));
        // Bent out of the plane by one ulp.
        let bent = p(-1.0, 0.0, f64::EPSILON);
        assert!(!coplanar_fan_is_embedded(
            &c,
            &[s(x, 1, y, 2), s(y, 2, bent, 3)]
        ));
        // A full turn of four sectors, and the same turn with one sector too many.
        let w = p(0.0, -1.0, 0.0);
        let full = [s(x, 1, y, 2), s(y, 2, z, 3), s(z, 3, w, 4), s(w, 4, x, 1)];
        assert!(coplanar_fan_is_embedded(&c, &full));
        let mut more = full.to_vec();
        more.push(s(p(1.0, 0.5, 0.0), 5, p(0.5, 1.0, 0.0), 6));
        assert!(!coplanar_fan_is_embedded(&c, &more));
    }

    #[test]
    fn duplicates_and_folds_are_found_on_their_edges() {
        // A duplicated face and a face folded onto its neighbour (coplanar, same side).
        let m = TriMesh::from_indices(
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
                Point3::new(0.5, 0.5, 0.0),
                Point3::new(0.0, -1.0, 0.0),
            ],
            &[[0, 1, 2], [0, 2, 1], [0, 1, 3], [0, 4, 1]],
        )
        .expect("mesh");
        let (pairs, stats) = self_intersections_with_stats(&m);
        let f = FaceId::new;
        assert!(pairs.contains(&(f(0), f(1))), "{pairs:?}");
        assert!(pairs.contains(&(f(0), f(2))), "{pairs:?}");
        assert!(!pairs.contains(&(f(0), f(3))), "{pairs:?}");
        assert!(stats.edge_pair_tests > 0);
        let sphere = generators::icosphere(1.0, 2);
        assert!(self_intersections_with_stats(&sphere).0.is_empty());
    }
}
