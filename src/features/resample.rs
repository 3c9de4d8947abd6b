//! Feature lines resampled to the metric (ours): the feature-line form of the boundary
//! curves' resampling ([`crate::boundary`]).
//!
//! A CAD part's creases are often far finer than the target: anchor's feature edges are a
//! median 0.07 L_tar long in the metric. Kept at the input's resolution, every face beside a
//! crease is a sliver between a short crease edge and the long edges the metric asks for
//! (paper-notes "Feature lines"). So before Algorithm 1 each *feature chain* — a run of
//! feature edges between *nodes* (where other than two feature edges meet, corners, the
//! boundary, or where the line turns by at least [`NODE_TURN`]) — gets `n = round(S)` pieces
//! of equal metric arc length, `S` being its metric length in units of L_tar. A piece's end is
//! the chain vertex at that arc when one lies within [`SNAP`] of a piece's length, otherwise a
//! new vertex on the input edge (located there exactly, as the split does). The chain
//! vertices that are not ends are then collapsed, each into its neighbour on the chain towards
//! the nearer end, when the collapse keeps the mesh valid ([`try_collapse`]); a vertex whose
//! collapse would not stays on the line.
//!
//! Every vertex left on a feature line is an input vertex or a point on an input feature edge,
//! so the output's creases lie exactly on the input's. The faces a collapse changes are chords
//! of the input; the patches that remesh them project their new vertices onto the input
//! surface ([`crate::lift`]).

use super::{EdgeSplitter, FeatureLines};
use crate::boundary::point_segment_distance;
use crate::ids::{EdgeKey, VertexId};
use crate::invariants::FlipTest;
use crate::mesh::{Topology, TriMesh};
use crate::predicates::collinear3d;
use crate::stitch::WorkingMesh;
use nalgebra::{Matrix3, Point3};
use std::collections::{HashMap, HashSet};

/// A chain vertex where the line turns by at least this many degrees (between the directions
/// of its two feature edges) is a node, so a corner of a crease stays (the boundary curves'
/// corner angle).
pub const NODE_TURN: f64 = 45.0;

/// A chain vertex within this fraction of a piece's arc length from a piece's end is that end
/// (no new vertex next to an input vertex).
pub const SNAP: f64 = 0.25;

/// Smallest cosine between a face's normal before and after a collapse: a collapse may tilt
/// the faces around the removed vertex by at most 60°, so it neither folds a face over nor
/// makes a new crease.
const MIN_NORMAL_COS: f64 = 0.5;

/// The feature chains of `reference` over the feature edges `sharp`: vertex paths from node to
/// node (a closed line without a node starts and ends at its smallest vertex). `extra_node[v]`
/// marks further nodes (corners).
pub fn feature_chains(
    reference: &TriMesh,
    topo: &Topology,
    sharp: &[EdgeKey],
    extra_node: &[bool],
) -> Vec<Vec<VertexId>> {
    let mut at: HashMap<VertexId, Vec<VertexId>> = HashMap::new();
    for e in sharp {
        at.entry(e.0).or_default().push(e.1);
        at.entry(e.1).or_default().push(e.0);
    }
    let cos_turn = NODE_TURN.to_radians().cos();
    let p = |v: VertexId| reference.positions[v.idx()];
    let is_node = |v: VertexId| {
        let n = &at[&v];
        if n.len() != 2 || extra_node.get(v.idx()).copied().unwrap_or(false) {
            return true;
        }
        if topo.is_boundary_vertex(v) {
            return true;
        }
        let (d0, d1) = (p(v) - p(n[0]), p(n[1]) - p(v));
        d0.dot(&d1) < cos_turn * d0.norm() * d1.norm()
    };
    let mut starts: Vec<VertexId> = at.keys().copied().filter(|&v| is_node(v)).collect();
    starts.sort_unstable();
    let mut used: HashSet<EdgeKey> = HashSet::new();
    let mut chains = Vec::new();
    let mut walk = |start: VertexId, used: &mut HashSet<EdgeKey>| {
        let mut nbrs = at[&start].clone();
        nbrs.sort_unstable();
        for first in nbrs {
            if used.contains(&EdgeKey::new(start, first)) {
                continue;
            }
            let mut chain = vec![start];
            let mut v = first;
            used.insert(EdgeKey::new(start, v));
            loop {
                chain.push(v);
                if v == start || is_node(v) {
                    break;
                }
                let Some(&next) = at[&v]
                    .iter()
                    .find(|&&w| !used.contains(&EdgeKey::new(v, w)))
                else {
                    break;
                };
                used.insert(EdgeKey::new(v, next));
                v = next;
            }
            chains.push(chain);
        }
    };
    for &s in &starts {
        walk(s, &mut used);
    }
    // Closed lines without a node.
    let mut rest: Vec<VertexId> = at.keys().copied().collect();
    rest.sort_unstable();
    for s in rest {
        walk(s, &mut used);
    }
    chains
}

/// Where the ends of a chain's pieces go: a chain vertex (its index) or a new point on the
/// chain's edge `i` at parameter `t` from `chain[i]`.
#[derive(Clone, Copy, Debug, PartialEq)]
enum End {
    Vertex(usize),
    OnEdge(usize, f64),
}

/// The inner piece ends of a chain cut into `n` pieces, whose edges have metric lengths `len`
/// (units of L_tar).
fn piece_ends(len: &[f64], n: usize) -> Vec<End> {
    let total: f64 = len.iter().sum();
    let h = total / n as f64;
    let mut arc = Vec::with_capacity(len.len() + 1);
    let mut s = 0.0;
    arc.push(0.0);
    for l in len {
        s += l;
        arc.push(s);
    }
    let mut ends = Vec::new();
    let mut i = 0;
    for j in 1..n {
        let target = j as f64 * h;
        while i + 1 < len.len() && arc[i + 1] < target {
            i += 1;
        }
        let near = if target - arc[i] <= arc[i + 1] - target {
            i
        } else {
            i + 1
        };
        let inner = near > 0 && near < len.len();
        if inner && (arc[near] - target).abs() <= SNAP * h {
            if ends.last() != Some(&End::Vertex(near)) {
                ends.push(End::Vertex(near));
            }
        } else if len[i] > 0.0 {
            let t = ((target - arc[i]) / len[i]).clamp(0.0, 1.0);
            if t > 0.0 && t < 1.0 {
                ends.push(End::OnEdge(i, t));
            } else if inner {
                ends.push(End::Vertex(near));
            }
        }
    }
    ends
}

/// Most pieces per input edge of a chain (bounds the search for a fine enough resampling).
const MAX_PIECES_PER_EDGE: usize = 64;

/// Most pieces of one input edge longer than the target: far more than any run's output
/// allows ([`crate::pipeline::MAX_EXPECTED_FACES`]), so only an input of wildly mixed scales
/// (a vertex 1e19 away, say) reaches it, whose edge would otherwise be cut into pieces until
/// memory runs out.
const MAX_PIECES_PER_LONG_EDGE: usize = 1 << 14;

/// The piece ends of `chain` (edge metric lengths `len`): when `round(S)` is at least the
/// chain's edge count, every chain vertex and each edge cut into `round(length)` pieces (at
/// most [`MAX_PIECES_PER_LONG_EDGE`]); otherwise `round(S)` pieces (at least 3 on a closed
/// chain), more while a piece's chord is farther than `max_deviation` (0: no bound) from the
/// chain vertices it replaces, so a curved crease keeps the distance tolerance the fidelity
/// control asks of the faces.
fn chain_ends(
    reference: &TriMesh,
    chain: &[VertexId],
    len: &[f64],
    max_deviation: f64,
) -> Vec<End> {
    let total: f64 = len.iter().sum();
    let closed = chain.first() == chain.last();
    let most = (len.len() * MAX_PIECES_PER_EDGE).max(1);
    let mut n = (total.round() as usize)
        .max(if closed { 3 } else { 1 })
        .min(most);
    if n >= len.len() {
        // Not finer than the target: keep every chain vertex and split each edge into
        // round(length) pieces, so the crease stays exactly the input's.
        return (0..len.len())
            .flat_map(|i| {
                let k = (len[i].round() as usize).clamp(1, MAX_PIECES_PER_LONG_EDGE);
                let inner = (1..k).map(move |j| End::OnEdge(i, j as f64 / k as f64));
                let vertex = (i + 1 < len.len()).then_some(End::Vertex(i + 1));
                inner.chain(vertex)
            })
            .collect();
    }
    loop {
        let ends = piece_ends(len, n);
        if max_deviation <= 0.0 || n >= most || deviation(reference, chain, &ends) <= max_deviation
        {
            return ends;
        }
        n = (n + n.div_ceil(4)).min(most);
    }
}

/// The largest distance from a chain vertex to the chord of the piece it lies in.
fn deviation(reference: &TriMesh, chain: &[VertexId], ends: &[End]) -> f64 {
    let p = |k: usize| reference.positions[chain[k].idx()];
    // Each end as (position, first chain index after it, chain index bound before it).
    let mut marks: Vec<(Point3<f64>, usize, usize)> = vec![(p(0), 1, 0)];
    for e in ends {
        marks.push(match *e {
            End::Vertex(k) => (p(k), k + 1, k),
            End::OnEdge(i, t) => (p(i) + (p(i + 1) - p(i)) * t, i + 1, i + 1),
        });
    }
    marks.push((p(chain.len() - 1), chain.len(), chain.len() - 1));
    let mut worst = 0.0f64;
    for w in marks.windows(2) {
        let ((a, from, _), (b, _, to)) = (w[0], w[1]);
        for k in from..to.max(from) {
            worst = worst.max(point_segment_distance(&p(k), &a, &b));
        }
    }
    worst
}

/// Largest factor [`crease_scale`] gives a vertex (sizes shrink by at most its square root, 5×,
/// as the a-priori fidelity factor's cap).
pub const MAX_CREASE_FACTOR: f64 = 25.0;

/// Largest ratio between the crease factors of two vertices of an input face (sizes grow by at
/// most its square root, 1.2×, from face to face away from a curved crease).
const CREASE_GRADE2: f64 = 1.44;

/// The metric factor per reference vertex that a curved crease asks for (ours; the a-priori
/// fidelity scaling, [`crate::fidelity::a_priori_scale`], stops at creases by design).
///
/// The curvature fit puts no curvature along a crease: on a flat plate with a round hole the
/// metric along the hole's rim is the plate's, and pieces of L_tar there cut the rim by far
/// more than `eps`. The chord of a piece of length `h` on a curve of curvature `κ` deviates by
/// `h²κ/8`, so the rim needs `h ≤ √(8·eps/κ)`. At a vertex where two feature edges meet at a
/// turn below [`NODE_TURN`] (`κ` from the circle through it and its two neighbours), the factor
/// is the `s` for which the rim's direction `t` has metric length L_tar at that size,
/// `s = L_tar²·κ / (8·eps·tᵀMt)`, at least 1, at most [`MAX_CREASE_FACTOR`] and never below
/// `min_edge`'s. The factor scales the whole tensor, so the faces beside the crease keep the
/// metric's shape (their quality is measured in it) and only get smaller; it is then graded
/// over the faces so sizes grow smoothly away from the rim.
pub fn crease_scale(
    reference: &TriMesh,
    sharp: &[EdgeKey],
    metrics: &[Matrix3<f64>],
    l_tar: f64,
    eps: f64,
    min_edge: f64,
) -> Vec<f64> {
    let n = reference.n_vertices();
    let mut s = vec![1.0; n];
    if eps <= 0.0 || sharp.is_empty() {
        return s;
    }
    let mut at: HashMap<VertexId, Vec<VertexId>> = HashMap::new();
    for e in sharp {
        at.entry(e.0).or_default().push(e.1);
        at.entry(e.1).or_default().push(e.0);
    }
    let p = |v: VertexId| reference.positions[v.idx()];
    let cos_turn = NODE_TURN.to_radians().cos();
    for (&v, nbrs) in &at {
        let [a, b] = nbrs[..] else { continue };
        let (d0, d1) = (p(v) - p(a), p(b) - p(v));
        let (l0, l1) = (d0.norm(), d1.norm());
        let chord = (p(b) - p(a)).norm();
        if l0 <= 0.0 || l1 <= 0.0 || chord <= 0.0 || d0.dot(&d1) < cos_turn * l0 * l1 {
            continue;
        }
        // Circle through a, v, b: κ = 2 sin(turn) / |b − a|.
        let sin_turn = d0.cross(&d1).norm() / (l0 * l1);
        let kappa = 2.0 * sin_turn / chord;
        let t = (p(b) - p(a)) / chord;
        let along = t.dot(&(metrics[v.idx()] * t));
        if !(kappa > 0.0 && along > 0.0) {
            continue;
        }
        // The size at factor s is l_tar / √(s·along); it may not fall below min_edge.
        let floor_cap = if min_edge > 0.0 {
            (l_tar * l_tar / (min_edge * min_edge * along)).max(1.0)
        } else {
            f64::INFINITY
        };
        let want = l_tar * l_tar * kappa / (8.0 * eps * along);
        s[v.idx()] = want.clamp(1.0, MAX_CREASE_FACTOR.min(floor_cap));
    }
    // Graded over the faces, as far as the factor needs to fall back to 1.
    let passes = (MAX_CREASE_FACTOR.ln() / CREASE_GRADE2.ln()).ceil() as usize;
    crate::mesh::grade_factors(reference, &mut s, CREASE_GRADE2, passes);
    s
}

/// What a feature line is resampled to: pieces of metric length `l_tar` in `metrics` (one
/// tensor per reference vertex), each chord within `max_deviation` of the crease (0: no bound).
#[derive(Clone, Copy, Debug)]
pub struct PieceTarget<'a> {
    /// The metric the planar remesher sees, per reference vertex.
    pub metrics: &'a [Matrix3<f64>],
    /// Target metric edge length.
    pub l_tar: f64,
    /// Largest distance from a piece's chord to the crease it replaces (unit space).
    pub max_deviation: f64,
}

/// Resample every feature chain of `sharp` to pieces of about `l_tar` in `metrics` (see the
/// module docs); `flips` is the run's flip certificate on `reference`. Returns the feature
/// lines: pieces, pinned vertices, positions.
pub fn resample_feature_lines(
    work: &mut WorkingMesh,
    reference: &TriMesh,
    topo: &Topology,
    sharp: &[EdgeKey],
    extra_node: &[bool],
    target: &PieceTarget<'_>,
    flips: &FlipTest,
) -> FeatureLines {
    let PieceTarget {
        metrics,
        l_tar,
        max_deviation,
    } = *target;
    let chains = feature_chains(reference, topo, sharp, extra_node);
    let metric_len = |a: VertexId, b: VertexId| {
        let d = reference.positions[b.idx()] - reference.positions[a.idx()];
        let mm = (metrics[a.idx()] + metrics[b.idx()]) * 0.5;
        d.dot(&(mm * d)).max(0.0).sqrt() / l_tar
    };
    // 1. Split: each chain becomes its full vertex path with the new ends in it, and a flag
    //    per vertex saying whether it is a piece end (nodes are).
    let mut splitter = EdgeSplitter::new(work, reference);
    let mut paths: Vec<(Vec<VertexId>, Vec<bool>)> = Vec::with_capacity(chains.len());
    for chain in &chains {
        let len: Vec<f64> = chain.windows(2).map(|w| metric_len(w[0], w[1])).collect();
        let ends = chain_ends(reference, chain, &len, max_deviation);
        let mut on_edge: Vec<Vec<f64>> = vec![Vec::new(); len.len()];
        let mut is_end = vec![false; chain.len()];
        is_end[0] = true;
        is_end[chain.len() - 1] = true;
        for e in ends {
            match e {
                End::Vertex(k) => is_end[k] = true,
                End::OnEdge(i, t) => on_edge[i].push(t),
            }
        }
        let mut path = vec![chain[0]];
        let mut flags = vec![true];
        for (i, w) in chain.windows(2).enumerate() {
            let mut params = std::mem::take(&mut on_edge[i]);
            params.sort_by(f64::total_cmp);
            params.dedup();
            if !params.is_empty() {
                if let Some(piece) = splitter.split(work, reference, w[0], w[1], &params) {
                    for &v in &piece[1..piece.len() - 1] {
                        path.push(v);
                        flags.push(true);
                    }
                }
            }
            path.push(w[1]);
            flags.push(is_end[i + 1]);
        }
        paths.push((path, flags));
    }
    // 2. Collapse the vertices between ends towards the nearer end.
    let mut collapser = Collapser::new(work, flips);
    let mut lines = FeatureLines {
        input_edges: sharp.len(),
        ..FeatureLines::default()
    };
    let mut pinned: Vec<VertexId> = Vec::new();
    for (path, flags) in &paths {
        let arc: Vec<f64> = std::iter::once(0.0)
            .chain(path.windows(2).scan(0.0, |s, w| {
                *s += (work.mesh.positions[w[1].idx()] - work.mesh.positions[w[0].idx()]).norm();
                Some(*s)
            }))
            .collect();
        let mut keep = flags.clone();
        let mut start = 0;
        for k in 1..path.len() {
            if !flags[k] {
                continue;
            }
            // Between ends `start` and `k`: the first half into `start`, the rest into `k`.
            let mid = 0.5 * (arc[start] + arc[k]);
            let split = (start + 1..k).find(|&j| arc[j] > mid).unwrap_or(k);
            let mut into = start;
            for j in start + 1..split {
                match collapser.try_collapse(work, path[j], path[into]) {
                    true => {}
                    false => {
                        keep[j] = true;
                        into = j;
                    }
                }
            }
            let mut into = k;
            for j in (split..k).rev() {
                match collapser.try_collapse(work, path[j], path[into]) {
                    true => {}
                    false => {
                        keep[j] = true;
                        into = j;
                    }
                }
            }
            start = k;
        }
        let kept: Vec<VertexId> = path
            .iter()
            .zip(&keep)
            .filter_map(|(v, k)| k.then_some(*v))
            .collect();
        for w in kept.windows(2) {
            lines.edges.insert(EdgeKey::new(w[0], w[1]));
        }
        pinned.extend(kept);
    }
    collapser.finish(work);
    lines.pin(work, pinned);
    lines
}

/// Edge collapses on the working mesh before the loop: faces are marked dead and dropped at
/// [`Collapser::finish`]; vertices stay in the arrays (unreferenced, as after a stitch).
struct Collapser<'a> {
    /// Per vertex: the live faces around it.
    faces_at: Vec<Vec<usize>>,
    dead: Vec<bool>,
    /// The run's flip certificate against the reference: a face a collapse changes may be
    /// kept as it is if no patch reaches it, so it must not face away from the input.
    flips: &'a FlipTest,
}

impl<'a> Collapser<'a> {
    fn new(work: &WorkingMesh, flips: &'a FlipTest) -> Collapser<'a> {
        let mut faces_at = vec![Vec::new(); work.mesh.n_vertices()];
        for (f, t) in work.mesh.triangles.iter().enumerate() {
            for v in t {
                faces_at[v.idx()].push(f);
            }
        }
        Collapser {
            faces_at,
            dead: vec![false; work.mesh.n_faces()],
            flips,
        }
    }

    fn neighbours(&self, work: &WorkingMesh, v: VertexId) -> HashSet<VertexId> {
        self.faces_at[v.idx()]
            .iter()
            .flat_map(|&f| work.mesh.triangles[f])
            .filter(|&u| u != v)
            .collect()
    }

    /// Collapse the edge `v`–`w` into `w` when it is an interior edge with exactly two faces,
    /// the link condition holds (the only common neighbours of `v` and `w` are those two
    /// faces' third corners, so the topology is kept), and every face that keeps `v`'s place
    /// stays non-degenerate (exact), tilts by less than 60° and passes the run's flip
    /// certificate against the reference ([`FlipTest::is_flipped_anywhere`]). Returns whether
    /// it collapsed.
    fn try_collapse(&mut self, work: &mut WorkingMesh, v: VertexId, w: VertexId) -> bool {
        let tri = |f: usize| work.mesh.triangles[f];
        let around = &self.faces_at[v.idx()];
        let shared: Vec<usize> = around
            .iter()
            .copied()
            .filter(|&f| tri(f).contains(&w))
            .collect();
        if shared.len() != 2 {
            return false;
        }
        let apexes: HashSet<VertexId> = shared
            .iter()
            .flat_map(|&f| tri(f))
            .filter(|&u| u != v && u != w)
            .collect();
        let common: HashSet<VertexId> = self
            .neighbours(work, v)
            .intersection(&self.neighbours(work, w))
            .copied()
            .collect();
        if common != apexes || apexes.len() != 2 {
            return false;
        }
        let pos = |u: VertexId| work.mesh.positions[u.idx()];
        let moved: Vec<(usize, [VertexId; 3])> = around
            .iter()
            .filter(|f| !shared.contains(f))
            .map(|&f| (f, tri(f).map(|u| if u == v { w } else { u })))
            .collect();
        for &(f, t) in &moved {
            let [a, b, c] = t.map(pos);
            if collinear3d(&a, &b, &c) {
                return false;
            }
            let old = normal(tri(f).map(pos));
            let new = normal([a, b, c]);
            if old.dot(&new) < MIN_NORMAL_COS * old.norm() * new.norm()
                || self.flips.is_flipped_anywhere(&[a, b, c])
            {
                return false;
            }
        }
        for &f in &shared {
            self.dead[f] = true;
            for u in tri(f) {
                self.faces_at[u.idx()].retain(|&g| g != f);
            }
        }
        for (f, t) in moved {
            work.mesh.triangles[f] = t;
            self.faces_at[w.idx()].push(f);
        }
        self.faces_at[v.idx()].clear();
        true
    }

    /// Drop the dead faces (the others keep their order).
    fn finish(self, work: &mut WorkingMesh) {
        let mut k = 0;
        work.mesh.triangles.retain(|_| {
            k += 1;
            !self.dead[k - 1]
        });
        work.processed.drop_marked(&self.dead);
    }
}

fn normal(p: [Point3<f64>; 3]) -> nalgebra::Vector3<f64> {
    (p[1] - p[0]).cross(&(p[2] - p[0]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::sharp_edges;
    use crate::mesh::generators;

    /// Resample `m`'s edges sharper than 60° to `l_tar` in the identity metric.
    fn resample(m: &TriMesh, l_tar: f64, max_deviation: f64) -> (WorkingMesh, FeatureLines) {
        let topo = Topology::build(m);
        let sharp = sharp_edges(m, &topo, 60.0);
        let mut w = WorkingMesh::from_reference(m);
        let metrics = vec![Matrix3::identity(); m.n_vertices()];
        let none = vec![false; m.n_vertices()];
        let target = PieceTarget {
            metrics: &metrics,
            l_tar,
            max_deviation,
        };
        let lines =
            resample_feature_lines(&mut w, m, &topo, &sharp, &none, &target, &FlipTest::new(m));
        (w, lines)
    }

    /// The live part of the working mesh is a valid surface of the input's topology: an
    /// oriented manifold with the same Euler characteristic, `processed` parallel, no
    /// degenerate face (exact), none facing away from the input (the run's flip certificate).
    fn assert_valid(w: &WorkingMesh, m: &TriMesh) {
        let (live, _) = w.mesh.without_unreferenced_vertices();
        let t = Topology::build(&live);
        assert!(t.is_oriented_manifold());
        assert_eq!(
            t.euler_characteristic(),
            Topology::build(m).euler_characteristic()
        );
        assert_eq!(w.processed.len(), w.mesh.n_faces());
        let flips = FlipTest::new(m);
        for tri in &w.mesh.triangles {
            let [a, b, c] = tri.map(|v| w.mesh.positions[v.idx()]);
            assert!(!collinear3d(&a, &b, &c), "{tri:?} is degenerate");
            assert!(
                !flips.is_flipped_anywhere(&[a, b, c]),
                "{tri:?} faces away from the input"
            );
        }
    }

    /// A cube cut 24 times along each edge, resampled to a quarter of an edge: each of the 12
    /// creases becomes 4 pieces of exactly 6 input edges, every feature vertex is an input
    /// vertex on a cube edge, and every face still faces out.
    #[test]
    fn a_finely_cut_crease_is_coarsened_to_the_target() {
        let m = generators::cube(24);
        let (w, lines) = resample(&m, 0.25, 0.0035);
        assert_eq!(lines.input_edges, 12 * 24);
        assert_eq!(lines.edges.len(), 12 * 4);
        for e in &lines.edges {
            let d = w.mesh.positions[e.1.idx()] - w.mesh.positions[e.0.idx()];
            assert!(
                (d.norm() - 0.25).abs() < 1e-12,
                "{e:?} is {} long",
                d.norm()
            );
        }
        let on_cube_edge =
            |p: &Point3<f64>| p.coords.iter().filter(|&&x| x == 0.0 || x == 1.0).count() >= 2;
        for (v, p) in &lines.positions {
            assert!(
                v.idx() < m.n_vertices(),
                "{v} is new: the pieces snap to input vertices"
            );
            assert!(on_cube_edge(p), "{v} at {p} is off the cube's edges");
            assert_eq!(*p, m.positions[v.idx()]);
        }
        assert_eq!(lines.positions.len(), 8 + 12 * 3);
        assert_valid(&w, &m);
        let centre = Point3::new(0.5, 0.5, 0.5);
        for f in w.mesh.faces() {
            let n = w.mesh.face_normal_raw(f);
            assert!(
                n.dot(&(w.mesh.face_centroid(f) - centre)) > 0.0,
                "{f} faces inwards"
            );
        }
        // Collapsing only changes faces next to the creases: the area stays the cube's.
        let (live, _) = w.mesh.without_unreferenced_vertices();
        assert!((live.area() - 6.0).abs() < 1e-9, "area {}", live.area());
    }

    /// A lens's equator cut into 256 edges, resampled to a length whose chords would miss it
    /// by 3 %: the deviation bound adds pieces until every input equator vertex is within
    /// the tolerance of the output polyline, and every output vertex lies on an input edge.
    #[test]
    fn a_curved_crease_keeps_its_chords_within_the_deviation() {
        let m = generators::lens(50f64.to_radians(), 12, 256);
        let tol = 0.005;
        let (w, lines) = resample(&m, 0.5, tol);
        let (_, coarse) = resample(&m, 0.5, 0.0);
        // Unbounded: round(2π / 0.5) = 13 pieces; bounded: at least π / acos(1 − tol) ≈ 32.
        assert_eq!(coarse.edges.len(), 13);
        assert!(
            lines.edges.len() >= 32 && lines.edges.len() < 256,
            "{}",
            lines.edges.len()
        );
        let pieces: Vec<(Point3<f64>, Point3<f64>)> = lines
            .edges
            .iter()
            .map(|e| (w.mesh.positions[e.0.idx()], w.mesh.positions[e.1.idx()]))
            .collect();
        for p in m.positions.iter().filter(|p| p.z == 0.0) {
            let d = pieces
                .iter()
                .map(|(a, b)| point_segment_distance(p, a, b))
                .fold(f64::INFINITY, f64::min);
            assert!(d <= tol, "input equator vertex {p} is {d} from the output");
        }
        let equator: Vec<EdgeKey> = sharp_edges(&m, &Topology::build(&m), 60.0);
        assert_eq!(equator.len(), 256);
        for p in lines.positions.values() {
            assert_eq!(p.z, 0.0);
            let d = equator
                .iter()
                .map(|e| {
                    point_segment_distance(p, &m.positions[e.0.idx()], &m.positions[e.1.idx()])
                })
                .fold(f64::INFINITY, f64::min);
            assert!(d < 1e-15, "{p} is {d} off the input equator");
        }
        assert_valid(&w, &m);
    }

    /// On the lens's equator (the unit circle, κ = 1) in the metric λ·I the crease factor is
    /// L_tar²·κ / (8·eps·λ), clamped to [1, 25]; it falls by at most 1.44 from face to face and
    /// is 1 at the poles; a straight crease (the cube's) asks for nothing.
    #[test]
    fn crease_scale_refines_curved_creases_only() {
        let m = generators::lens(50f64.to_radians(), 12, 64);
        let sharp = sharp_edges(&m, &Topology::build(&m), 60.0);
        let (lambda, l_tar, eps) = (4.0, 0.4, 0.001);
        let metrics = vec![Matrix3::identity() * lambda; m.n_vertices()];
        let s = crease_scale(&m, &sharp, &metrics, l_tar, eps, 0.0);
        let want = l_tar * l_tar / (8.0 * eps * lambda);
        assert!(want > 1.0 && want < MAX_CREASE_FACTOR);
        for (v, p) in m.positions.iter().enumerate() {
            if p.z == 0.0 {
                // κ of the circle through three vertices of a regular polygon on the unit circle.
                assert!((s[v] - want).abs() < 1e-9 * want, "{v}: {} vs {want}", s[v]);
            }
            if p.x == 0.0 && p.y == 0.0 {
                assert_eq!(s[v], 1.0, "pole {v}");
            }
        }
        for t in &m.triangles {
            let f: Vec<f64> = t.iter().map(|v| s[v.idx()]).collect();
            let (lo, hi) = (
                f.iter().copied().fold(f64::INFINITY, f64::min),
                f.iter().copied().fold(0.0, f64::max),
            );
            assert!(hi <= lo * CREASE_GRADE2 * (1.0 + 1e-12), "{t:?}: {f:?}");
        }
        // A much smaller tolerance hits the cap; the size floor caps it lower.
        let capped = crease_scale(&m, &sharp, &metrics, l_tar, eps / 1000.0, 0.0);
        assert!(capped.iter().copied().fold(0.0, f64::max) == MAX_CREASE_FACTOR);
        let floored = crease_scale(&m, &sharp, &metrics, l_tar, eps / 1000.0, 0.1);
        let floor = l_tar * l_tar / (0.1 * 0.1 * lambda);
        assert!((floored.iter().copied().fold(0.0, f64::max) - floor).abs() < 1e-9 * floor);
        let cube = generators::cube(8);
        let edges = sharp_edges(&cube, &Topology::build(&cube), 60.0);
        let flat = crease_scale(
            &cube,
            &edges,
            &metrics[..cube.n_vertices()],
            l_tar,
            eps,
            0.0,
        );
        assert!(flat.iter().all(|&f| f == 1.0));
        // Off without a tolerance.
        assert!(crease_scale(&m, &sharp, &metrics, l_tar, 0.0, 0.0)
            .iter()
            .all(|&f| f == 1.0));
    }

    /// A chain no finer than the target keeps every input vertex, each edge split into
    /// round(length) pieces (the crease is exactly the input's).
    #[test]
    fn a_coarse_crease_keeps_its_vertices() {
        let m = generators::cube(2);
        let (w, lines) = resample(&m, 0.25, 0.0035);
        assert_eq!(lines.edges.len(), 12 * 4);
        assert_eq!(lines.positions.len(), 8 + 12 * 3);
        for v in 0..m.n_vertices() {
            let v = VertexId::new(v);
            let on = m.positions[v.idx()]
                .coords
                .iter()
                .filter(|&&x| x == 0.0 || x == 1.0)
                .count();
            assert_eq!(lines.is_pinned(v), on >= 2, "{v}");
        }
        assert_valid(&w, &m);
    }
}
