//! Feature lines (our addition; the paper's Sec. 3.2 only relies on its cone patches stopping
//! at sharp features, Fig. 1 and 12).
//!
//! A *feature edge* is an input edge whose two faces' normals differ by more than a threshold
//! angle (a crease of the piecewise-flat input). Before Algorithm 1 starts, every feature edge
//! of the working mesh is split into pieces of about the target metric length, at points on
//! the input edge itself (so the crease is reproduced exactly, not cut by chords). The pieces
//! are passed to the patch strategy as edges no patch may contain in its interior
//! ([`crate::patches::PatchContext::feature_edges`]): they stay patch boundaries, which the
//! planar remesher keeps, so they are edges of the output. Their vertices are pinned (the
//! relocation pass does not move them) and the flip pass does not flip them.
//!
//! Why split first: a patch boundary is fixed, and the input's own edges are 2–3× longer than
//! the target on a coarse input (decimated-knight), which costs the triangles along them their
//! quality. Split to the target length, the patch beside a crease is remeshed as everywhere
//! else.

use crate::ids::{EdgeKey, FaceId, VertexId};
use crate::mesh::{SurfaceLocation, Topology, TriMesh};
use crate::option_error::OptionError;
use crate::stitch::WorkingMesh;
use nalgebra::Point3;
use std::collections::{HashMap, HashSet};

mod resample;
pub use resample::{
    crease_scale, feature_chains, resample_feature_lines, PieceTarget, MAX_CREASE_FACTOR,
    NODE_TURN, SNAP,
};

/// Most vertices a feature split may add (a target far below the feature edges' length
/// would otherwise ask for an unbounded allocation).
pub const MAX_NEW_VERTICES: usize = 10_000_000;

/// The feature lines of a working mesh after [`resample_feature_lines`] (or
/// [`split_feature_edges`]).
#[derive(Clone, Debug, Default)]
pub struct FeatureLines {
    /// The pieces of the input's feature edges, by working-mesh vertex ids.
    pub edges: HashSet<EdgeKey>,
    /// `pinned[v]`: working-mesh vertex `v` lies on a feature line (vertices past the end do
    /// not).
    pub pinned: Vec<bool>,
    /// Where each feature-line vertex was put (the certificate after the loop compares).
    pub positions: HashMap<VertexId, Point3<f64>>,
    /// Number of input edges that are feature edges.
    pub input_edges: usize,
}

impl FeatureLines {
    /// True when `v` lies on a feature line.
    pub fn is_pinned(&self, v: VertexId) -> bool {
        self.pinned.get(v.idx()).copied().unwrap_or(false)
    }

    /// Pin the vertices `on_lines` of `work` (all others unpinned) at their positions there.
    fn pin(&mut self, work: &WorkingMesh, on_lines: Vec<VertexId>) {
        let mut flags = vec![false; work.mesh.n_vertices()];
        for v in on_lines {
            flags[v.idx()] = true;
            self.positions.insert(v, work.mesh.positions[v.idx()]);
        }
        self.pinned = flags;
    }
}

/// Which input edges are feature lines.
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FeatureRule {
    /// None (the paper).
    Off,
    /// Every interior edge whose faces' normals differ by more than this many degrees
    /// (`--feature-angle DEG`).
    Angle(f64),
    /// [`auto_feature_edges`] (the default): edges sharper than [`AUTO_ANGLE`] that stand out
    /// from their faces' other edges and form long, smooth crease lines that join, close or reach
    /// the boundary; a CAD part's creases, few or none of an organic mesh's edges (paper-notes
    /// "Feature lines").
    #[default]
    Auto,
}

impl FeatureRule {
    /// The feature edges of `mesh` under this rule, sorted.
    pub fn edges(&self, mesh: &TriMesh, topo: &Topology) -> Vec<EdgeKey> {
        match *self {
            FeatureRule::Off => Vec::new(),
            FeatureRule::Angle(a) => sharp_edges(mesh, topo, a),
            FeatureRule::Auto => auto_feature_edges(mesh, topo),
        }
    }

    /// Reads `auto`, `off` (or `0`) or an angle in degrees, as `--feature-angle` takes it.
    pub fn parse(s: &str) -> Result<FeatureRule, OptionError> {
        match s.trim() {
            "auto" => Ok(FeatureRule::Auto),
            "off" => Ok(FeatureRule::Off),
            t => {
                let a: f64 = t.parse().map_err(|_| OptionError::Unparsed {
                    option: "feature angle",
                    value: t.to_string(),
                    expected: "auto, off or an angle in degrees",
                })?;
                let rule = match a == 0.0 {
                    true => FeatureRule::Off,
                    false => FeatureRule::Angle(a),
                };
                rule.validate()?;
                Ok(rule)
            }
        }
    }

    /// Checks the angle (in (0, 180) degrees).
    pub fn validate(&self) -> Result<(), OptionError> {
        match *self {
            FeatureRule::Angle(a) if !(a > 0.0 && a < 180.0) => Err(OptionError::OutOfRange {
                option: "feature angle",
                value: a,
                range: "between 0 and 180 degrees (exclusive)",
            }),
            _ => Ok(()),
        }
    }
}

/// The dihedral threshold of [`FeatureRule::Auto`], degrees between the faces' normals.
pub const AUTO_ANGLE: f64 = 40.0;

/// Largest turn (degrees) between consecutive edges of one crease line in
/// [`auto_feature_edges`].
pub const AUTO_MAX_TURN: f64 = 60.0;

/// Fewest edges of a crease line that neither closes nor joins other lines at both ends.
pub const AUTO_MIN_EDGES: usize = 3;

/// [`FeatureRule::Auto`]: the edges sharper than [`AUTO_ANGLE`], grouped into lines (chains of
/// sharp edges through vertices where exactly two meet and the line turns by at most
/// [`AUTO_MAX_TURN`]); a line is kept when it is closed, or joins other sharp edges at both
/// ends (a CAD edge from corner to corner, however short), or has at least
/// [`AUTO_MIN_EDGES`] edges. What is dropped are short open runs of sharp edges: the isolated
/// spikes and folds of a scan or of a coarse organic mesh. Then the lines are cut into chains
/// at their nodes ([`feature_chains`]) and only smooth, long chains stay (every turn at most
/// [`AUTO_CHAIN_TURN`]; more than [`AUTO_CHAIN_EDGES`] edges, or straight and at least
/// [`AUTO_CHAIN_LENGTH`] of the diagonal), with the short ones that run between two ends of
/// long ones; last, isolated lines go ([`without_isolated_lines`]).
pub fn auto_feature_edges(mesh: &TriMesh, topo: &Topology) -> Vec<EdgeKey> {
    let sharp = contrasted(mesh, topo, sharp_edges(mesh, topo, AUTO_ANGLE));
    if sharp.is_empty() {
        return sharp;
    }
    let mut at: HashMap<VertexId, Vec<usize>> = HashMap::new();
    for (i, e) in sharp.iter().enumerate() {
        at.entry(e.0).or_default().push(i);
        at.entry(e.1).or_default().push(i);
    }
    let cos_turn = AUTO_MAX_TURN.to_radians().cos();
    let dir = |i: usize, from: VertexId| {
        let e = sharp[i];
        let to = if e.0 == from { e.1 } else { e.0 };
        (mesh.positions[to.idx()] - mesh.positions[from.idx()]).normalize()
    };
    // A line passes through v when exactly two sharp edges meet there and they continue each
    // other (the second leaves v roughly opposite to where the first arrives).
    let passes = |v: VertexId| -> Option<(usize, usize)> {
        let es = at.get(&v)?;
        if es.len() != 2 {
            return None;
        }
        let (a, b) = (dir(es[0], v), dir(es[1], v));
        (-a.dot(&b) >= cos_turn).then_some((es[0], es[1]))
    };
    let mut line_of = vec![usize::MAX; sharp.len()];
    let mut keep = vec![false; sharp.len()];
    for start in 0..sharp.len() {
        if line_of[start] != usize::MAX {
            continue;
        }
        // Walk both ways from `start` through vertices the line passes.
        let mut members = vec![start];
        line_of[start] = start;
        let mut closed = false;
        let mut ends_joined = 0;
        for end in [sharp[start].0, sharp[start].1] {
            let (mut v, mut e) = (end, start);
            loop {
                match passes(v) {
                    Some((x, y)) => {
                        let next = if x == e { y } else { x };
                        if line_of[next] == start {
                            closed = true;
                            break;
                        }
                        line_of[next] = start;
                        members.push(next);
                        let k = sharp[next];
                        v = if k.0 == v { k.1 } else { k.0 };
                        e = next;
                    }
                    None => {
                        // An end: joined when other sharp edges meet here.
                        if at.get(&v).map_or(0, |x| x.len()) >= 2 {
                            ends_joined += 1;
                        }
                        break;
                    }
                }
            }
            if closed {
                break;
            }
        }
        if closed || ends_joined == 2 || members.len() >= AUTO_MIN_EDGES {
            for m in members {
                keep[m] = true;
            }
        }
    }
    let lines: Vec<EdgeKey> = sharp
        .into_iter()
        .zip(keep)
        .filter_map(|(e, k)| k.then_some(e))
        .collect();
    without_isolated_lines(topo, smooth_chains(mesh, topo, lines))
}

/// The feature edges `lines` less every *isolated line*: a connected set of them that is one
/// open path (no vertex where three or more meet, not closed) whose two ends are free (no other
/// feature edge there, not on the boundary). A CAD part's crease ends where it meets another
/// crease, a corner or the boundary, or closes around a face or a hole; a ridge of an organic
/// surface, sharp at the input's resolution, starts and ends in smooth surface. Every line the
/// chain filter keeps on the seven shared organic meshes with lines is isolated; of 25 CAD
/// parts of the CGAL corpus, only one edge of tripod's and the six fading lines of
/// fandisk_large are (notes/small-angles.md). Dropping ridges that branch as well (trees whose
/// ends are all free) took 30 edges of cheese's creases and none of a lion's.
pub fn without_isolated_lines(topo: &Topology, lines: Vec<EdgeKey>) -> Vec<EdgeKey> {
    let mut at: HashMap<VertexId, Vec<usize>> = HashMap::new();
    for (i, e) in lines.iter().enumerate() {
        at.entry(e.0).or_default().push(i);
        at.entry(e.1).or_default().push(i);
    }
    let mut component = vec![usize::MAX; lines.len()];
    let mut drop = vec![false; lines.len()];
    for start in 0..lines.len() {
        if component[start] != usize::MAX {
            continue;
        }
        // The edges connected to `start`, and the vertices they meet.
        let (mut members, mut stack, mut vertices) = (Vec::new(), vec![start], HashSet::new());
        component[start] = start;
        while let Some(i) = stack.pop() {
            members.push(i);
            for v in [lines[i].0, lines[i].1] {
                vertices.insert(v);
                for &j in &at[&v] {
                    if component[j] == usize::MAX {
                        component[j] = start;
                        stack.push(j);
                    }
                }
            }
        }
        let path = vertices.iter().all(|v| at[v].len() <= 2);
        let ends: Vec<VertexId> = vertices
            .iter()
            .copied()
            .filter(|v| at[v].len() == 1)
            .collect();
        let free = |v: &VertexId| !topo.is_boundary_vertex(*v);
        if path && ends.len() == 2 && ends.iter().all(free) {
            members.into_iter().for_each(|i| drop[i] = true);
        }
    }
    lines
        .into_iter()
        .zip(drop)
        .filter_map(|(e, d)| (!d).then_some(e))
        .collect()
}

/// A chain (between nodes, [`feature_chains`]) with more edges than this is long for
/// the chain filter of [`auto_feature_edges`].
pub const AUTO_CHAIN_EDGES: usize = 5;

/// A straight chain (every turn at most [`AUTO_STRAIGHT_TURN`]) at least this long (fraction of
/// the bounding-box diagonal) is long for the chain filter of [`auto_feature_edges`], whatever
/// its edge count: where a CAD part's flat sides meet along a few long edges.
pub const AUTO_CHAIN_LENGTH: f64 = 0.1;

/// Largest turn (degrees) of a chain that is long by [`AUTO_CHAIN_LENGTH`].
pub const AUTO_STRAIGHT_TURN: f64 = 5.0;

/// Largest turn (degrees) between consecutive edges of a chain that the chain filter of
/// [`auto_feature_edges`] keeps.
pub const AUTO_CHAIN_TURN: f64 = 30.0;

/// The chains of `lines` that look like a CAD part's creases: smooth (every turn at most
/// [`AUTO_CHAIN_TURN`]) and either long — more than [`AUTO_CHAIN_EDGES`] edges, or straight
/// and at least [`AUTO_CHAIN_LENGTH`] of the diagonal — or running between ends of long chains (a short CAD
/// edge from corner to corner). Measured on CAD parts and organic meshes
/// (paper-notes "Feature lines"): a part's creases are long, smooth chains (anchor, joint,
/// part, fandisk: 10-32 edges per chain, ≥ 90 % of their edges in such chains); the sharp
/// edges of an organic mesh are short jagged runs (bunny, cow, armadillo, knight: 1-2.4 edges
/// per chain), whose faces the feature lines would pin into slivers.
fn smooth_chains(mesh: &TriMesh, topo: &Topology, lines: Vec<EdgeKey>) -> Vec<EdgeKey> {
    if lines.is_empty() {
        return lines;
    }
    let cos_turn = AUTO_CHAIN_TURN.to_radians().cos();
    let p = |v: VertexId| mesh.positions[v.idx()];
    let chains: Vec<Vec<VertexId>> = feature_chains(mesh, topo, &lines, &[])
        .into_iter()
        .filter(|c| {
            c.windows(3).all(|w| {
                let (d0, d1) = (p(w[1]) - p(w[0]), p(w[2]) - p(w[1]));
                d0.dot(&d1) >= cos_turn * d0.norm() * d1.norm()
            })
        })
        .collect();
    // Long chains first (in edges, or in length: a CAD part's flat sides meet along single
    // long edges); then the short ones whose two ends are corners of long ones.
    let long_length = AUTO_CHAIN_LENGTH * mesh.bbox_diagonal();
    let cos_straight = AUTO_STRAIGHT_TURN.to_radians().cos();
    let long = |c: &Vec<VertexId>| {
        let straight = c.windows(3).all(|w| {
            let (d0, d1) = (p(w[1]) - p(w[0]), p(w[2]) - p(w[1]));
            d0.dot(&d1) >= cos_straight * d0.norm() * d1.norm()
        });
        let length: f64 = c.windows(2).map(|w| (p(w[1]) - p(w[0])).norm()).sum();
        c.len() > AUTO_CHAIN_EDGES || (straight && length >= long_length)
    };
    let mut long_ends: HashMap<VertexId, usize> = HashMap::new();
    for c in chains.iter().filter(|c| long(c)) {
        for v in [c[0], c[c.len() - 1]] {
            *long_ends.entry(v).or_default() += 1;
        }
    }
    let mut out: Vec<EdgeKey> = Vec::new();
    for c in &chains {
        let ends_on_long = [c[0], c[c.len() - 1]]
            .iter()
            .all(|v| long_ends.contains_key(v));
        if long(c) || ends_on_long {
            out.extend(c.windows(2).map(|w| EdgeKey::new(w[0], w[1])));
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// How many times sharper than the other edges of its two faces a crease of
/// [`auto_feature_edges`] is (the other edges' angles between normals, not counting other
/// sharp edges): a CAD crease runs between faces that are smooth on each side; a sharp edge
/// of a scan or a coarse organic mesh sits among other rough edges.
pub const AUTO_CONTRAST: f64 = 2.0;

/// The edges of `sharp` whose angle is at least [`AUTO_CONTRAST`] × the largest angle of the
/// other, not sharp, edges of their two faces.
fn contrasted(mesh: &TriMesh, topo: &Topology, sharp: Vec<EdgeKey>) -> Vec<EdgeKey> {
    let set: HashSet<EdgeKey> = sharp.iter().copied().collect();
    let angle = |f: FaceId, g: FaceId| {
        let (n1, n2) = (mesh.face_normal(f), mesh.face_normal(g));
        n1.dot(&n2).clamp(-1.0, 1.0).acos()
    };
    // Largest angle of a non-sharp edge of each face.
    let rough = |f: FaceId| {
        let t = mesh.face(f);
        (0..3)
            .filter(|&i| !set.contains(&EdgeKey::new(t[i], t[(i + 1) % 3])))
            .filter_map(|i| topo.neighbor(f, i).map(|g| angle(f, g)))
            .fold(0.0f64, f64::max)
    };
    let mut face_of: HashMap<EdgeKey, (FaceId, FaceId)> = HashMap::new();
    for f in mesh.faces() {
        let t = mesh.face(f);
        for i in 0..3 {
            let e = EdgeKey::new(t[i], t[(i + 1) % 3]);
            if let (true, Some(g)) = (set.contains(&e), topo.neighbor(f, i)) {
                face_of.insert(e, (f, g));
            }
        }
    }
    sharp
        .into_iter()
        .filter(|e| {
            face_of
                .get(e)
                .is_some_and(|&(f, g)| angle(f, g) >= AUTO_CONTRAST * rough(f).max(rough(g)))
        })
        .collect()
}

/// Interior edges of `mesh` whose two faces' unit normals make an angle larger than
/// `angle_deg` degrees, sorted. Edges of zero-area faces are skipped (no normal).
pub fn sharp_edges(mesh: &TriMesh, topo: &Topology, angle_deg: f64) -> Vec<EdgeKey> {
    let cos_max = angle_deg.to_radians().cos();
    let mut out = Vec::new();
    for f in mesh.faces() {
        let t = mesh.face(f);
        for i in 0..3 {
            let Some(g) = topo.neighbor(f, i) else {
                continue;
            };
            // Each interior edge once, from its smaller face.
            if g <= f {
                continue;
            }
            // A zero-area face (decided exactly: its float normal may be round-off of any
            // direction) has no dihedral angle; its edges are no crease.
            let flat = |h: FaceId| {
                let [a, b, c] = mesh.face_points(h);
                crate::predicates::collinear3d(&a, &b, &c)
            };
            if flat(f) || flat(g) {
                continue;
            }
            let (n1, n2) = (mesh.face_normal_raw(f), mesh.face_normal_raw(g));
            let (l1, l2) = (n1.norm(), n2.norm());
            if n1.dot(&n2) / (l1 * l2) < cos_max {
                out.push(EdgeKey::new(t[i], t[(i + 1) % 3]));
            }
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Splits input edges of a working mesh that still has them (before the loop), keeping an
/// oriented manifold: both faces beside an edge become fans over the new points.
struct EdgeSplitter {
    /// Directed edge → the working face that has it.
    directed: HashMap<(VertexId, VertexId), usize>,
    /// Directed input edge → the reference face that has it (the new points' location).
    on_reference: HashMap<(VertexId, VertexId), FaceId>,
}

impl EdgeSplitter {
    fn new(work: &WorkingMesh, reference: &TriMesh) -> EdgeSplitter {
        let mut directed = HashMap::new();
        for (f, t) in work.mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                directed.insert((t[k], t[(k + 1) % 3]), f);
            }
        }
        let on_reference = reference
            .faces()
            .flat_map(|f| {
                let t = reference.face(f);
                (0..3).map(move |k| ((t[k], t[(k + 1) % 3]), f))
            })
            .collect();
        EdgeSplitter {
            directed,
            on_reference,
        }
    }

    /// Split the input edge `a`–`b` at the parameters `params` (strictly increasing, in
    /// (0, 1), measured from `a`). Returns the chain `a, new…, b`, or `None` when `a`–`b` is
    /// not an interior edge of both the working mesh and the reference (nothing changes).
    fn split(
        &mut self,
        work: &mut WorkingMesh,
        reference: &TriMesh,
        a: VertexId,
        b: VertexId,
        params: &[f64],
    ) -> Option<Vec<VertexId>> {
        let f1 = *self.directed.get(&(a, b))?;
        let f2 = *self.directed.get(&(b, a))?;
        let loc_face = *self.on_reference.get(&(a, b))?;
        let rt = reference.face(loc_face);
        let ia = rt.iter().position(|&u| u == a)?;
        let ib = rt.iter().position(|&u| u == b)?;
        let mut chain = vec![a];
        for &s in params {
            let mut bary = [0.0; 3];
            bary[ia] = 1.0 - s;
            bary[ib] = s;
            let loc = SurfaceLocation {
                face: loc_face,
                bary,
            };
            let v = VertexId::new(work.mesh.positions.len());
            work.mesh.positions.push(loc.position(reference));
            work.locations.push(loc);
            work.curve.push(None);
            chain.push(v);
        }
        chain.push(b);
        // f1 = (a, b, c) → (chain[i], chain[i+1], c); f2 = (b, a, d) → (chain[i+1], chain[i], d).
        for (f, forward) in [(f1, true), (f2, false)] {
            let t = work.mesh.triangles[f];
            let apex = t.iter().copied().find(|v| *v != a && *v != b).unwrap_or(a);
            for k in 0..3 {
                self.directed.remove(&(t[k], t[(k + 1) % 3]));
            }
            for (i, w) in chain.windows(2).enumerate() {
                let tri = if forward {
                    [w[0], w[1], apex]
                } else {
                    [w[1], w[0], apex]
                };
                let slot = if i == 0 {
                    work.mesh.triangles[f] = tri;
                    f
                } else {
                    work.mesh.triangles.push(tri);
                    work.processed.push(false);
                    work.mesh.triangles.len() - 1
                };
                for k in 0..3 {
                    self.directed.insert((tri[k], tri[(k + 1) % 3]), slot);
                }
            }
        }
        Some(chain)
    }
}

/// Split every edge `e` of `edges` (input edges, present in `work` as they are in
/// `reference`) into `k` equal parts (`(e, k)`, `k ≥ 1`) at points on the edge, splitting both
/// faces beside it into fans. The new vertices are located on the reference face beside the
/// edge; the new faces are unprocessed. Returns the pieces and the pinned vertices. The caller
/// bounds the counts (the pipeline refuses a split beyond [`MAX_NEW_VERTICES`]).
pub fn split_feature_edges(
    work: &mut WorkingMesh,
    reference: &TriMesh,
    edges: &[(EdgeKey, usize)],
) -> FeatureLines {
    let mut splitter = EdgeSplitter::new(work, reference);
    let mut lines = FeatureLines {
        input_edges: edges.len(),
        ..FeatureLines::default()
    };
    let mut pinned: Vec<VertexId> = Vec::new();
    for &(e, k) in edges {
        let k = k.max(1);
        let params: Vec<f64> = (1..k).map(|j| j as f64 / k as f64).collect();
        let chain = match params.is_empty() {
            true => None,
            false => splitter.split(work, reference, e.0, e.1, &params),
        }
        // Not split (one piece, or not an interior edge): the edge itself is the feature.
        .unwrap_or_else(|| vec![e.0, e.1]);
        for w in chain.windows(2) {
            lines.edges.insert(EdgeKey::new(w[0], w[1]));
        }
        pinned.extend(chain);
    }
    lines.pin(work, pinned);
    lines
}

/// Errors of the feature split.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FeatureError {
    /// The target length is so small that the split would add more than
    /// [`MAX_NEW_VERTICES`] vertices.
    #[error(
        "feature lines would need {new_vertices:.3e} new vertices at L_tar = {l_tar:e} (more than \
         {MAX_NEW_VERTICES}): the target length is too small for the input's {edges} feature edges"
    )]
    TooManyVertices {
        /// vertices the split would add
        new_vertices: f64,
        /// the target length
        l_tar: f64,
        /// feature edges of the input
        edges: usize,
    },
}

/// The feature lines of Algorithm 1's working mesh (before the loop): the input edges `sharp`
/// (the run's [`FeatureRule`] picks them), resampled to `target` ([`resample_feature_lines`])
/// with `corners[v]` kept as chain nodes. Errors when the target is so small that the lines
/// would get more than [`MAX_NEW_VERTICES`] vertices.
pub fn split_to_target(
    work: &mut WorkingMesh,
    reference: &TriMesh,
    topo: &Topology,
    sharp: &[EdgeKey],
    corners: &[bool],
    target: &PieceTarget<'_>,
    flips: &crate::invariants::FlipTest,
) -> Result<FeatureLines, FeatureError> {
    if sharp.is_empty() {
        return Ok(FeatureLines::default());
    }
    let (metrics, l_tar) = (target.metrics, target.l_tar);
    // An upper bound on the new vertices (every edge split on its own).
    let new_vertices: f64 = sharp
        .iter()
        .map(|e| {
            let d = reference.positions[e.1.idx()] - reference.positions[e.0.idx()];
            let mm = (metrics[e.0.idx()] + metrics[e.1.idx()]) * 0.5;
            (d.dot(&(mm * d)).max(0.0).sqrt() / l_tar).round().max(1.0) - 1.0
        })
        .sum();
    if new_vertices.is_nan() || new_vertices > MAX_NEW_VERTICES as f64 {
        return Err(FeatureError::TooManyVertices {
            new_vertices,
            l_tar,
            edges: sharp.len(),
        });
    }
    Ok(resample_feature_lines(
        work, reference, topo, sharp, corners, target, flips,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;

    #[test]
    fn an_isolated_open_line_is_dropped_and_creases_that_join_close_or_reach_the_boundary_stay() {
        let m = generators::plate(8.0, 8);
        let topo = Topology::build(&m);
        let at = |x: f64, y: f64| {
            VertexId::new(
                m.positions
                    .iter()
                    .position(|p| p.x == x && p.y == y)
                    .expect("a grid vertex"),
            )
        };
        let line = |pts: &[(f64, f64)]| -> Vec<EdgeKey> {
            pts.windows(2)
                .map(|w| EdgeKey::new(at(w[0].0, w[0].1), at(w[1].0, w[1].1)))
                .collect()
        };
        let isolated = line(&[(1.0, 1.0), (2.0, 1.0), (3.0, 1.0)]);
        let to_boundary = line(&[(6.0, 1.0), (7.0, 1.0), (8.0, 1.0)]);
        let closed = line(&[(1.0, 5.0), (2.0, 5.0), (2.0, 6.0), (1.0, 6.0), (1.0, 5.0)]);
        let branching = [
            line(&[(4.0, 5.0), (5.0, 5.0)]),
            line(&[(6.0, 5.0), (5.0, 5.0)]),
            line(&[(5.0, 6.0), (5.0, 5.0)]),
        ]
        .concat();
        let all = [&isolated, &to_boundary, &closed, &branching]
            .into_iter()
            .flatten()
            .copied()
            .collect();
        let mut kept = without_isolated_lines(&topo, all);
        kept.sort_unstable();
        let mut expected = [to_boundary, closed, branching].concat();
        expected.sort_unstable();
        assert_eq!(kept, expected);
    }

    fn equator(m: &TriMesh) -> Vec<EdgeKey> {
        let on = |v: VertexId| m.positions[v.idx()].z == 0.0;
        let mut e: Vec<EdgeKey> = m
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .filter(|(a, b)| on(*a) && on(*b))
            .map(|(a, b)| EdgeKey::new(a, b))
            .collect();
        e.sort_unstable();
        e.dedup();
        e
    }

    /// The lens's faces meet at the equator at 180° − 2·50° = 80° between their normals (plus
    /// about 8° from the discretisation), elsewhere at a few degrees: a threshold between
    /// finds exactly the equator.
    #[test]
    fn sharp_edges_of_a_lens_are_its_equator() {
        let m = generators::lens(50f64.to_radians(), 6, 32);
        let topo = Topology::build(&m);
        assert!(topo.is_oriented_manifold());
        let eq = equator(&m);
        assert_eq!(eq.len(), 32);
        assert_eq!(sharp_edges(&m, &topo, 60.0), eq);
        assert_eq!(sharp_edges(&m, &topo, 30.0), eq);
        assert!(sharp_edges(&m, &topo, 95.0).is_empty());
        // A smooth sphere has none at 30°.
        let s = generators::icosphere(1.0, 3);
        assert!(sharp_edges(&s, &Topology::build(&s), 30.0).is_empty());
    }

    /// The auto rule keeps a subdivided cube's 12 edges (sharp, between flat sides) and finds
    /// nothing on a smooth sphere; the flag's values parse.
    #[test]
    fn auto_rule_keeps_cad_creases_and_skips_smooth_surfaces() {
        let cube = generators::cube(3);
        let topo = Topology::build(&cube);
        assert_eq!(FeatureRule::Auto.edges(&cube, &topo).len(), 12 * 3);
        let s = generators::icosphere(1.0, 3);
        assert!(FeatureRule::Auto.edges(&s, &Topology::build(&s)).is_empty());
        assert_eq!(FeatureRule::parse("auto"), Ok(FeatureRule::Auto));
        assert_eq!(FeatureRule::parse("0"), Ok(FeatureRule::Off));
        assert_eq!(FeatureRule::parse("30"), Ok(FeatureRule::Angle(30.0)));
        assert!(matches!(
            FeatureRule::parse("-5"),
            Err(OptionError::OutOfRange { value, .. }) if value == -5.0
        ));
        assert!(matches!(
            FeatureRule::parse("x"),
            Err(OptionError::Unparsed { .. })
        ));
    }

    /// The chain filter of the automatic rule on hand-made lines over a 20×20 plate: long
    /// straight runs (7 edges, or 3 edges spanning ≥ 0.1 of the diagonal) stay, and so does a
    /// 2-edge run between the ends of two long ones; an isolated 2-edge run and a staircase
    /// (every turn 90°: jagged, as on a scan) go.
    #[test]
    fn smooth_chains_keeps_long_smooth_lines_and_drops_jagged_ones() {
        let m = generators::plate(1.0, 20);
        let topo = Topology::build(&m);
        let at: HashMap<(i64, i64), VertexId> = m
            .vertices()
            .map(|v| {
                let p = m.positions[v.idx()];
                (
                    ((p.x * 20.0).round() as i64, (p.y * 20.0).round() as i64),
                    v,
                )
            })
            .collect();
        let run = |pts: &[(i64, i64)]| -> Vec<EdgeKey> {
            pts.windows(2)
                .map(|w| EdgeKey::new(at[&w[0]], at[&w[1]]))
                .collect()
        };
        let row = |y: i64, x0: i64, x1: i64| (x0..=x1).map(|x| (x, y)).collect::<Vec<_>>();
        let col = |x: i64, y0: i64, y1: i64| (y0..=y1).map(|y| (x, y)).collect::<Vec<_>>();
        let long_row = run(&row(10, 2, 9));
        let long_a = run(&col(14, 2, 9));
        let long_b = run(&col(16, 2, 9));
        let joiner = run(&row(9, 14, 16));
        let short_length_long = run(&row(19, 10, 13));
        let isolated = run(&row(4, 2, 4));
        let stairs = run(&[
            (2, 16),
            (3, 16),
            (3, 17),
            (4, 17),
            (4, 18),
            (5, 18),
            (5, 19),
        ]);
        let mut all = Vec::new();
        for l in [
            &long_row,
            &long_a,
            &long_b,
            &joiner,
            &short_length_long,
            &isolated,
            &stairs,
        ] {
            all.extend(l.iter().copied());
        }
        all.sort_unstable();
        let kept: HashSet<EdgeKey> = smooth_chains(&m, &topo, all).into_iter().collect();
        for (name, l, keep) in [
            ("7-edge row", &long_row, true),
            ("7-edge column", &long_a, true),
            ("joiner", &joiner, true),
            ("3 edges, 0.106 of the diagonal", &short_length_long, true),
            ("isolated 2-edge run", &isolated, false),
            ("staircase", &stairs, false),
        ] {
            for e in l {
                assert_eq!(kept.contains(e), keep, "{name}: {e:?}");
            }
        }
        assert_eq!(kept.len(), 7 + 7 + 7 + 2 + 3);
    }

    /// Splitting keeps an oriented manifold of the same topology and area; every new vertex
    /// lies on its input edge (located there exactly), and the pieces chain the equator.
    #[test]
    fn split_keeps_the_surface_and_chains_the_feature() {
        let m = generators::lens(50f64.to_radians(), 6, 32);
        let topo = Topology::build(&m);
        let eq = sharp_edges(&m, &topo, 60.0);
        let mut w = WorkingMesh::from_reference(&m);
        let with_k: Vec<(EdgeKey, usize)> = eq.iter().map(|e| (*e, 1 + e.0.idx() % 3)).collect();
        let lines = split_feature_edges(&mut w, &m, &with_k);
        let expect_new: usize = eq.iter().map(|e| e.0.idx() % 3).sum();
        assert_eq!(w.mesh.n_vertices(), m.n_vertices() + expect_new);
        assert_eq!(w.mesh.n_faces(), m.n_faces() + 2 * expect_new);
        assert_eq!(w.processed.len(), w.mesh.n_faces());
        assert!(w.processed.iter().all(|p| !p));
        assert_eq!(lines.input_edges, 32);
        assert_eq!(lines.edges.len(), 32 + expect_new);
        let t2 = Topology::build(&w.mesh);
        assert!(t2.is_oriented_manifold());
        assert_eq!(t2.euler_characteristic(), topo.euler_characteristic());
        assert!((w.mesh.area() - m.area()).abs() < 1e-12 * m.area());
        // No face lost its orientation against the face it came from.
        for f in w.mesh.faces() {
            let n = w.mesh.face_normal_raw(f);
            let c = w.mesh.face_centroid(f);
            assert!(n.norm() > 0.0, "{f} degenerate");
            assert!(n.dot(&c.coords) > 0.0, "{f} faces inwards");
        }
        for v in m.n_vertices()..w.mesh.n_vertices() {
            let v = VertexId::new(v);
            assert!(lines.is_pinned(v));
            let p = w.mesh.positions[v.idx()];
            assert_eq!(p.z, 0.0, "{v} off the equator plane");
            assert_eq!(w.locations[v].position(&m), p);
            assert!(lines.edges.iter().filter(|e| e.0 == v || e.1 == v).count() == 2);
        }
        // Every pinned vertex is on the equator, every equator vertex is pinned.
        for v in 0..m.n_vertices() {
            let v = VertexId::new(v);
            assert_eq!(lines.is_pinned(v), m.positions[v.idx()].z == 0.0, "{v}");
        }
    }

    /// Faces with two (cube) or three (tetrahedron) feature edges, each split into
    /// 2-4 pieces: still an oriented manifold, no degenerate face, every face turned the way
    /// of the input face it came from, `processed` parallel, every new vertex located on a
    /// reference face that has both ends of its edge, at the right point.
    #[test]
    fn split_with_several_feature_edges_per_face() {
        let cube = TriMesh::from_indices(
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(1.0, 1.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
                Point3::new(0.0, 0.0, 1.0),
                Point3::new(1.0, 0.0, 1.0),
                Point3::new(1.0, 1.0, 1.0),
                Point3::new(0.0, 1.0, 1.0),
            ],
            &[
                [0, 2, 1],
                [0, 3, 2],
                [4, 5, 6],
                [4, 6, 7],
                [0, 1, 5],
                [0, 5, 4],
                [1, 2, 6],
                [1, 6, 5],
                [2, 3, 7],
                [2, 7, 6],
                [3, 0, 4],
                [3, 4, 7],
            ],
        )
        .expect("cube");
        let tet = TriMesh::from_indices(
            vec![
                Point3::new(1.0, 1.0, 1.0),
                Point3::new(1.0, -1.0, -1.0),
                Point3::new(-1.0, 1.0, -1.0),
                Point3::new(-1.0, -1.0, 1.0),
            ],
            &[[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
        )
        .expect("tet");
        for (name, m, n_sharp) in [("cube", cube, 12), ("tet", tet, 6)] {
            let topo = Topology::build(&m);
            assert!(topo.is_oriented_manifold(), "{name}");
            let sharp = sharp_edges(&m, &topo, 30.0);
            assert_eq!(sharp.len(), n_sharp, "{name}");
            let centre = m
                .positions
                .iter()
                .fold(nalgebra::Vector3::zeros(), |a, p| a + p.coords)
                / m.n_vertices() as f64;
            let mut w = WorkingMesh::from_reference(&m);
            let with_k: Vec<(EdgeKey, usize)> = sharp
                .iter()
                .map(|e| (*e, 2 + (e.0.idx() + e.1.idx()) % 3))
                .collect();
            let lines = split_feature_edges(&mut w, &m, &with_k);
            let expect_new: usize = sharp.iter().map(|e| 1 + (e.0.idx() + e.1.idx()) % 3).sum();
            assert_eq!(w.mesh.n_vertices(), m.n_vertices() + expect_new, "{name}");
            assert_eq!(w.mesh.n_faces(), m.n_faces() + 2 * expect_new, "{name}");
            assert_eq!(w.processed.len(), w.mesh.n_faces());
            assert_eq!(w.locations.len(), w.mesh.n_vertices());
            assert_eq!(lines.edges.len(), n_sharp + expect_new, "{name}");
            let t2 = Topology::build(&w.mesh);
            assert!(t2.is_oriented_manifold(), "{name}");
            assert_eq!(t2.euler_characteristic(), 2, "{name}");
            assert!(
                (w.mesh.area() - m.area()).abs() < 1e-12 * m.area(),
                "{name}"
            );
            for f in w.mesh.faces() {
                let n = w.mesh.face_normal_raw(f);
                assert!(n.norm() > 1e-9, "{name}: {f} degenerate");
                assert!(
                    n.dot(&(w.mesh.face_centroid(f).coords - centre)) > 0.0,
                    "{name}: {f}"
                );
            }
            for v in m.n_vertices()..w.mesh.n_vertices() {
                let loc = w.locations[VertexId::new(v)];
                assert_eq!(loc.position(&m), w.mesh.positions[v], "{name}");
                let on: Vec<usize> = (0..3).filter(|&k| loc.bary[k] != 0.0).collect();
                assert_eq!(on.len(), 2, "{name}: v{v} not on an edge of its face");
                let rt = m.face(loc.face);
                let key = EdgeKey::new(rt[on[0]], rt[on[1]]);
                assert!(sharp.contains(&key), "{name}: v{v} on a non-feature edge");
                assert!(lines.is_pinned(VertexId::new(v)));
            }
        }
    }
}
