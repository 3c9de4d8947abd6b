//! Overlap repair of an uncertified LSCM start (Sec. 3.3). Where narrow slits of a ragged
//! cover patch close, the LSCM boundary crosses itself at a few places. The repair runs
//! locally injective Newton steps on the symmetric Dirichlet energy plus, for every boundary
//! vertex that penetrates another part of the disk, `w ((s + m)/m)²` while positive (`s` its
//! signed distance inside the line of the edge it has to leave, `m` the margin). Pairs are
//! sticky: added when found, never dropped. Float arithmetic throughout: the exact
//! certificate judges the result before it is used as a start.

use super::super::sparse::Pattern;
use crate::ids::VertexId;
use crate::mesh::TriMesh;
use crate::param::recertify;
use nalgebra::{Point2, Vector2};

/// Repair iterations without fewer crossing boundary edges before it gives up (the caller
/// then starts from the Tutte map, and every further step is time lost).
const PATIENCE: usize = 6;

/// What the repair says after an accepted step.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(super) enum RepairStep {
    /// Certified, with every repaired vertex at least the clearance outside: done.
    Done,
    /// The number of crossing boundary edges has not fallen for [`PATIENCE`] steps.
    Stalled,
    /// New penetrating vertices were added: the objective changed.
    NewPairs,
    /// Nothing changed; carry on.
    Continue,
}

/// The repair penalty and the state of the repair.
pub(super) struct RepairPenalty<'a> {
    boundary: &'a [VertexId],
    /// Weight `w` of one term.
    weight: f64,
    /// Margin `m` (absolute).
    margin: f64,
    /// Fraction of `margin` a repaired vertex must be outside for the repair to end.
    clearance: f64,
    /// The (vertex, edge start, edge end) pairs found so far (vertex indices).
    pairs: Vec<[usize; 3]>,
    fewest_crossings: usize,
    stalled: usize,
}

impl<'a> RepairPenalty<'a> {
    /// A repair with no pairs yet; `margin` is absolute, `clearance` a fraction of it.
    pub(super) fn new(
        boundary: &'a [VertexId],
        weight: f64,
        margin: f64,
        clearance: f64,
    ) -> RepairPenalty<'a> {
        RepairPenalty {
            boundary,
            weight,
            margin,
            clearance,
            pairs: Vec::new(),
            fewest_crossings: usize::MAX,
            stalled: 0,
        }
    }

    /// `e` plus the penalty of `uv`.
    pub(super) fn add_energy(&self, uv: &[Point2<f64>], mut e: f64) -> f64 {
        for &[p, a, b] in &self.pairs {
            if let Some((sd, _)) = signed_gap(uv, p, a, b) {
                let x = (sd + self.margin) / self.margin;
                if x > 0.0 {
                    e += self.weight * x * x;
                }
            }
        }
        e
    }

    /// Add the penalty's gradient to `grad` and its Gauss–Newton blocks to `vals`: the
    /// gradient is along the edge's inner normal (p moves out, a and b by their share).
    pub(super) fn add_derivatives(
        &self,
        uv: &[Point2<f64>],
        pat: &Pattern,
        grad: &mut [f64],
        vals: &mut [f64],
    ) {
        let k = self.weight / (self.margin * self.margin);
        for &[p, a, b] in &self.pairs {
            let Some((sd, (nl, u))) = signed_gap(uv, p, a, b) else {
                continue;
            };
            if sd + self.margin <= 0.0 {
                continue;
            }
            let d1 = 2.0 * k * (sd + self.margin);
            for (v, c) in [(p, 1.0), (a, -(1.0 - u)), (b, -u)] {
                grad[2 * v] += d1 * c * nl.x;
                grad[2 * v + 1] += d1 * c * nl.y;
                pat.add_diag_outer(vals, v, 2.0 * k * c * c, [nl.x, nl.y]);
            }
        }
    }

    /// Judge the iterate `uv` after an accepted step, and add the pairs of vertices that
    /// now penetrate.
    pub(super) fn after_step(&mut self, disk: &TriMesh, uv: &[Point2<f64>]) -> RepairStep {
        let boundary = self.boundary;
        let clear = self.pairs.iter().all(|&[p, a, b]| {
            signed_gap(uv, p, a, b).is_none_or(|(sd, _)| sd <= -self.clearance * self.margin)
        });
        if clear && recertify(disk, uv, boundary).is_ok() {
            return RepairStep::Done;
        }
        let crossings = crossing_edges(uv, boundary).len();
        if crossings < self.fewest_crossings {
            self.fewest_crossings = crossings;
            self.stalled = 0;
        } else {
            self.stalled += 1;
            if self.stalled >= PATIENCE {
                return RepairStep::Stalled;
            }
        }
        if self.add_penetrations(uv) {
            RepairStep::NewPairs
        } else {
            RepairStep::Continue
        }
    }

    /// Add a pair for every boundary vertex of `uv` that now penetrates another part of the
    /// disk (and has none yet), and for the endpoints of crossing boundary edges that lie on
    /// the inner side of the other edge. Returns whether any was added.
    pub(super) fn add_penetrations(&mut self, uv: &[Point2<f64>]) -> bool {
        let boundary = self.boundary;
        let delta = 1e-3 * self.margin;
        let m = boundary.len();
        let mut added = false;
        let inside = penetrating_vertices(uv, boundary, delta);
        for (e1, e2) in crossing_edges(uv, boundary) {
            // Crossings with a penetrating endpoint are repaired through that vertex below;
            // the rest are thin spikes crossing each other (no vertex inside the other's
            // material).
            if [e1, (e1 + 1) % m, e2, (e2 + 1) % m]
                .iter()
                .any(|k| inside.contains(k))
            {
                continue;
            }
            for (e, f) in [(e1, e2), (e2, e1)] {
                let (a, b) = (boundary[f].idx(), boundary[(f + 1) % m].idx());
                for k in [e, (e + 1) % m] {
                    let p = boundary[k].idx();
                    let pair = [p, a, b];
                    if signed_gap(uv, p, a, b).is_some_and(|(sd, _)| sd > 0.0)
                        && !self.pairs.contains(&pair)
                    {
                        self.pairs.push(pair);
                        added = true;
                    }
                }
            }
        }
        for k in inside {
            let p = boundary[k].idx();
            if self.pairs.iter().any(|q| q[0] == p) {
                continue;
            }
            if let Some(e) = edge_to_leave(uv, boundary, k) {
                self.pairs
                    .push([p, boundary[e].idx(), boundary[(e + 1) % m].idx()]);
                added = true;
            }
        }
        added
    }
}

/// Boundary vertices (loop indices) that lie inside the image of another part of the disk:
/// a point a hair (`delta`) outside the vertex, along the bisector of its exterior angle,
/// has a non-zero winding number with respect to the boundary polygon (it would be 0 for a
/// simple counter-clockwise boundary).
fn penetrating_vertices(uv: &[Point2<f64>], boundary: &[VertexId], delta: f64) -> Vec<usize> {
    let m = boundary.len();
    let at = |i: usize| uv[boundary[i % m].idx()];
    let strips = Strips::new(uv, boundary);
    let mut out = Vec::new();
    for k in 0..m {
        let p = at(k);
        let (u1, u2) = (at(k + m - 1) - p, at(k + 1) - p);
        let (l1, l2) = (u1.norm(), u2.norm());
        if l1 <= 0.0 || l2 <= 0.0 {
            continue;
        }
        let (u1, u2) = (u1 / l1, u2 / l2);
        // The material lies counter-clockwise from u2 to u1, the exterior from u1 to u2.
        let mut ext = u1.perp(&u2).atan2(u1.dot(&u2));
        if ext <= 0.0 {
            ext += std::f64::consts::TAU;
        }
        let (c, s) = ((0.5 * ext).cos(), (0.5 * ext).sin());
        let q = p + Vector2::new(c * u1.x - s * u1.y, s * u1.x + c * u1.y) * delta;
        if strips.winding_number(q) != 0 {
            out.push(k);
        }
    }
    out
}

/// Horizontal strips of the boundary's y range, each listing the edges whose y-interval
/// meets it (boundary edges are short, so most lie in one or two): a +x ray cast at height
/// y only visits its strip instead of every edge.
struct Strips<'a> {
    uv: &'a [Point2<f64>],
    boundary: &'a [VertexId],
    y_lo: f64,
    height: f64,
    edges: Vec<Vec<usize>>,
}

impl<'a> Strips<'a> {
    /// `m / 8` strips (at least one) for a loop of `m` vertices.
    fn new(uv: &'a [Point2<f64>], boundary: &'a [VertexId]) -> Strips<'a> {
        let m = boundary.len();
        let at = |i: usize| uv[boundary[i % m].idx()];
        let (mut y_lo, mut y_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..m {
            y_lo = y_lo.min(at(i).y);
            y_hi = y_hi.max(at(i).y);
        }
        let n = (m / 8).max(1);
        let mut strips = Strips {
            uv,
            boundary,
            y_lo,
            height: (y_hi - y_lo) / n as f64,
            edges: vec![Vec::new(); n],
        };
        for i in 0..m {
            let (a, b) = (at(i), at(i + 1));
            let (s0, s1) = (strips.strip(a.y.min(b.y)), strips.strip(a.y.max(b.y)));
            for e in &mut strips.edges[s0..=s1] {
                e.push(i);
            }
        }
        strips
    }

    fn strip(&self, y: f64) -> usize {
        let n = self.edges.len();
        if self.height > 0.0 && y.is_finite() {
            (((y - self.y_lo) / self.height).max(0.0) as usize).min(n - 1)
        } else {
            0
        }
    }

    /// Winding number of the boundary polygon around `q`: signed crossings of the ray
    /// `x > q.x` (half-open rule on y).
    fn winding_number(&self, q: Point2<f64>) -> i32 {
        let m = self.boundary.len();
        let at = |i: usize| self.uv[self.boundary[i % m].idx()];
        let mut winding = 0i32;
        for &i in &self.edges[self.strip(q.y)] {
            let (a, b) = (at(i), at(i + 1));
            if (a.y <= q.y) != (b.y <= q.y) {
                let x = a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y);
                if x > q.x {
                    winding += if b.y > a.y { 1 } else { -1 };
                }
            }
        }
        winding
    }
}

/// For a penetrating boundary vertex (loop index `k`), the boundary edge it has to leave:
/// the nearest edge not within two steps along the loop that has `p` on its inner (left)
/// side. Returns the edge's loop index.
fn edge_to_leave(uv: &[Point2<f64>], boundary: &[VertexId], k: usize) -> Option<usize> {
    let m = boundary.len();
    let at = |i: usize| uv[boundary[i % m].idx()];
    let p = at(k);
    let mut best: Option<(f64, usize)> = None;
    for e in 0..m {
        let gap = (k + m - e) % m;
        if gap <= 2 || gap >= m - 1 {
            continue;
        }
        let (a, b) = (at(e), at(e + 1));
        let ab = b - a;
        let l2 = ab.norm_squared();
        if l2 <= 0.0 || ab.perp(&(p - a)) <= 0.0 {
            continue;
        }
        let u = ((p - a).dot(&ab) / l2).clamp(0.0, 1.0);
        let d = (p - (a + ab * u)).norm_squared();
        if best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, e));
        }
    }
    best.map(|(_, e)| e)
}

/// Signed distance of `uv[p]` from the line of `ab`, positive on the inner (left) side, with
/// the inner unit normal and the clamped projection parameter along `ab`.
fn signed_gap(
    uv: &[Point2<f64>],
    p: usize,
    a: usize,
    b: usize,
) -> Option<(f64, (Vector2<f64>, f64))> {
    let ab = uv[b] - uv[a];
    let l = ab.norm();
    if l <= 0.0 {
        return None;
    }
    let nl = Vector2::new(-ab.y, ab.x) / l;
    let w = uv[p] - uv[a];
    Some((w.dot(&nl), (nl, (w.dot(&ab) / (l * l)).clamp(0.0, 1.0))))
}

/// Pairs of non-adjacent boundary edges (loop indices) whose segments cross or touch (float
/// orientation tests; sort-and-sweep on x).
fn crossing_edges(uv: &[Point2<f64>], boundary: &[VertexId]) -> Vec<(usize, usize)> {
    let m = boundary.len();
    let at = |i: usize| uv[boundary[i % m].idx()];
    let mut items: Vec<(f64, f64, f64, f64, usize)> = (0..m)
        .map(|i| {
            let (a, b) = (at(i), at(i + 1));
            (a.x.min(b.x), a.x.max(b.x), a.y.min(b.y), a.y.max(b.y), i)
        })
        .collect();
    items.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    let orient = |a: Point2<f64>, b: Point2<f64>, c: Point2<f64>| (b - a).perp(&(c - a));
    let mut out = Vec::new();
    let mut active: Vec<usize> = Vec::new();
    for k in 0..items.len() {
        let (x0, _, y0, y1, i) = items[k];
        active.retain(|&j| items[j].1 >= x0);
        for &j in &active {
            let (_, _, yj0, yj1, e) = items[j];
            if yj1 < y0 || yj0 > y1 || (i + 1) % m == e || (e + 1) % m == i {
                continue;
            }
            let (a, b, c, d) = (at(i), at(i + 1), at(e), at(e + 1));
            let (o1, o2) = (orient(a, b, c), orient(a, b, d));
            let (o3, o4) = (orient(c, d, a), orient(c, d, b));
            if o1 * o2 <= 0.0 && o3 * o4 <= 0.0 {
                out.push((i, e));
            }
        }
        active.push(k);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlap_detection_finds_the_vertex_pushed_into_the_other_arm() {
        // A "U" (counter-clockwise): arms x ∈ [0, 1] and x ∈ [2, 3] above y = 1.
        let mut uv = vec![
            Point2::new(0.0, 0.0),
            Point2::new(3.0, 0.0),
            Point2::new(3.0, 3.0),
            Point2::new(2.0, 3.0),
            Point2::new(2.0, 1.0),
            Point2::new(1.0, 1.0),
            Point2::new(1.0, 3.0),
            Point2::new(0.0, 3.0),
        ];
        let boundary: Vec<VertexId> = (0..8).map(VertexId::new).collect();
        assert!(penetrating_vertices(&uv, &boundary, 1e-6).is_empty());
        assert!(crossing_edges(&uv, &boundary).is_empty());
        // The right arm's top-left corner pushed across the slit into the left arm.
        uv[3] = Point2::new(0.5, 2.5);
        let inside = penetrating_vertices(&uv, &boundary, 1e-6);
        assert!(inside.contains(&3), "{inside:?}");
        assert!(!inside.contains(&0) && !inside.contains(&1), "{inside:?}");
        let mut crossings: Vec<(usize, usize)> = crossing_edges(&uv, &boundary)
            .into_iter()
            .map(|(a, b)| (a.min(b), a.max(b)))
            .collect();
        crossings.sort_unstable();
        assert_eq!(crossings, vec![(2, 5), (3, 5)]);
        // The edge it has to leave is the left arm's inner side (5, 6), and the repair term
        // pushes it back out: its signed gap is positive (inside) now.
        assert_eq!(edge_to_leave(&uv, &boundary, 3), Some(5));
        let (sd, (n, _)) = signed_gap(&uv, 3, 5, 6).unwrap();
        assert!((sd - 0.5).abs() < 1e-12, "{sd}");
        assert!((n - Vector2::new(-1.0, 0.0)).norm() < 1e-12, "{n}");
        // The repair adds exactly that pair, once, and its penalty then pushes v3 out of
        // the left arm (a negative x gradient would pull it further in).
        let mut repair = RepairPenalty::new(&boundary, 1.0, 0.2, 0.5);
        assert!(repair.add_penetrations(&uv));
        assert_eq!(repair.pairs, vec![[3, 5, 6]]);
        assert!(!repair.add_penetrations(&uv));
        let x = (0.5 + 0.2) / 0.2;
        assert!((repair.add_energy(&uv, 0.0) - x * x).abs() < 1e-12);
    }
}
