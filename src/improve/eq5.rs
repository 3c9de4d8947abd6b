//! Algorithm 2's updates in the plane (Sec. 3.4, Eq. 5-6), as a [`PlanarRemesher`] that keeps
//! the patch's vertices and changes only their positions and the connectivity.
//!
//! Energy (Eq. 5): a triangle `t` with metric `M_t` (the mean of its vertex tensors, as the
//! paper writes) is mapped to metric space by `S_t = √M_t`; with `E = S_t [p1 − p0, p2 − p0]`
//! and `R` the edge matrix of the equilateral triangle of side `L_tar`, the Jacobian from `t`
//! to that triangle is `J = R E⁻¹` and
//!
//! ```text
//! Q_t = exp(w (‖J‖²_F + ‖J⁻¹‖²_F)),   Q_p = Σ_{t ∋ p} Q_t   (Eq. 6).
//! ```
//!
//! `‖J‖² + ‖J⁻¹‖² ≥ 4`, with equality exactly when `t` is equilateral of side `L_tar` in the
//! metric, and it grows without bound as `t` degenerates or flips, so a descent step cannot
//! pass through a flip. The sums are compared as `log Q_p` (log-sum-exp), which orders them as
//! `Q_p` does without overflowing at slivers.
//!
//! *Vertex position update*: each free vertex, worst first, moves along `−∇ log Q_p` (the
//! direction of `−∇Q_p`) with a backtracking line search; a step is taken only when `Q_p`
//! strictly decreases and every triangle around the vertex stays positive (exact
//! `orient2d`). *Connectivity update*: an interior edge that is not constrained is flipped
//! when its quad is strictly convex (exact) and the flip strictly lowers the pair's energy
//! ([`FlipRule::Energy`]) or raises its smaller metric quality ([`FlipRule::MaxMin`]).
//! Every accepted operation strictly lowers `Σ_t Q_t` (energy rule) or raises the sorted
//! vector of the pair's qualities, and the passes are counted, so the updates end.

use crate::predicates::{orient2d, Sign};
use crate::remesh2d::{
    clamp_spd, Metric2d, PlanarDomain, PlanarMesh, PlanarRemesher, Remesh2dError,
};
use nalgebra::{Matrix2, Point2, Vector2};
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;

/// How the connectivity update decides a flip.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum FlipRule {
    /// The pair's Eq. 5 energy strictly decreases.
    Energy,
    /// The pair's smaller metric quality strictly increases.
    MaxMin,
}

/// Options of the planar updates, with their defaults.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Eq5Options {
    /// The weight `w` of Eq. 5 (default 1). The paper leaves it open; it sets how strongly the
    /// sum of Eq. 6 is dominated by its worst triangle.
    pub w: f64,
    /// Rounds of (vertex position update, connectivity update) (default 10).
    pub rounds: usize,
    /// Gradient steps per vertex and round (default 4), each with its line search.
    pub steps: usize,
    /// Halvings of the line search (default 30).
    pub line_search: usize,
    /// The flip decision (default [`FlipRule::Energy`]).
    pub flip_rule: FlipRule,
    /// The equilateral triangle of Eq. 5 (default [`Target::OwnArea`], paper-notes.md Sec. 3.4).
    pub target: Target,
    /// Edge collapses after each connectivity update: a triangle whose smallest metric angle is
    /// below this (degrees) loses its shortest edge when that raises the smallest angle around
    /// it (default 0: none; notes/small-angles.md has what 30 does to the shared meshes). A short
    /// edge makes a small angle that neither flips nor moves can open: the vertices around it
    /// are too many for the space.
    pub collapse_below_deg: f64,
}

impl Default for Eq5Options {
    fn default() -> Self {
        Eq5Options {
            w: 1.0,
            rounds: 10,
            steps: 4,
            line_search: 30,
            flip_rule: FlipRule::Energy,
            target: Target::OwnArea,
            collapse_below_deg: 0.0,
        }
    }
}

/// The planar updates of Algorithm 2 (the vertex position and connectivity updates on the
/// energy of Eq. 5) as the planar stage of its patches: a [`PlanarRemesher`] that keeps the
/// patch's vertices. Not a registry row (it does not remesh a patch from its boundary);
/// [`super::Algorithm2`] (improver row `eq5`) runs it.
#[derive(Clone, Debug, Default)]
pub struct Eq5Updates {
    /// Options.
    pub options: Eq5Options,
}

impl PlanarRemesher for Eq5Updates {
    fn name(&self) -> &'static str {
        "eq5-updates"
    }

    fn remesh(
        &self,
        domain: &PlanarDomain,
        metric: &dyn Metric2d,
        target_length: f64,
        _rng: &mut ChaCha8Rng,
    ) -> Result<PlanarMesh, Remesh2dError> {
        improve_planar(domain, metric, target_length, &self.options).map(|(m, _)| m)
    }
}

/// What [`improve_planar`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Eq5Counts {
    /// Vertex moves taken.
    pub moves: usize,
    /// Edges flipped.
    pub flips: usize,
    /// Edges collapsed.
    pub collapses: usize,
    /// Rounds run (a round that changes nothing ends the updates).
    pub rounds: usize,
}

/// `‖J‖²_F + ‖J⁻¹‖²_F` of Eq. 5 for the triangle `p` in metric `s` (= √M_t), and its gradient
/// with respect to the three corners; `None` when the triangle is degenerate or flipped in the
/// metric (then the energy is infinite).
pub fn distortion(
    p: [Point2<f64>; 3],
    s: &Matrix2<f64>,
    l_tar: f64,
) -> Option<(f64, [Vector2<f64>; 3])> {
    distortion_with(p, s, l_tar, Target::Length)
}

/// The equilateral triangle Eq. 5 compares a triangle with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Target {
    /// Side `L_tar` (the paper): the energy also pulls the triangle's size to `L_tar`.
    Length,
    /// The triangle's own metric area: shape only, `2‖J‖²_F / det J` (the MIPS energy), so a
    /// mesh whose sizes are off target is not distorted to fix them.
    OwnArea,
}

/// [`distortion`] against `target`.
pub fn distortion_with(
    p: [Point2<f64>; 3],
    s: &Matrix2<f64>,
    l_tar: f64,
    target: Target,
) -> Option<(f64, [Vector2<f64>; 3])> {
    let r = Matrix2::new(l_tar, 0.5 * l_tar, 0.0, 0.5 * 3f64.sqrt() * l_tar);
    let r_inv = r.try_inverse()?;
    let e = s * Matrix2::from_columns(&[p[1] - p[0], p[2] - p[0]]);
    // Only to keep the energy finite: the decisions on orientation are `orient2d`'s (exact).
    let det = e.determinant();
    if det.is_nan() || det <= 0.0 {
        return None;
    }
    let a = e.try_inverse()?;
    let j = r * a;
    // d‖R A‖²/dE = −2 Aᵀ RᵀR A Aᵀ,  d‖E R⁻¹‖²/dE = 2 E R⁻¹ R⁻ᵀ,  d det E/dE = det E · Aᵀ.
    let d_ra = -2.0 * a.transpose() * r.transpose() * r * a * a.transpose();
    let (f, g) = match target {
        Target::Length => {
            let j_inv = e * r_inv;
            (
                j.norm_squared() + j_inv.norm_squared(),
                d_ra + 2.0 * e * r_inv * r_inv.transpose(),
            )
        }
        Target::OwnArea => {
            let (de, dr) = (e.determinant(), r.determinant());
            let n = j.norm_squared();
            (
                2.0 * n * de / dr,
                (d_ra * de + a.transpose() * (n * de)) * (2.0 / dr),
            )
        }
    };
    if !f.is_finite() {
        return None;
    }
    // E = S [p1 − p0, p2 − p0]: ∂/∂p1 = Sᵀ g₀, ∂/∂p2 = Sᵀ g₁, ∂/∂p0 = −(both).
    let st = s.transpose();
    let g1 = st * g.column(0);
    let g2 = st * g.column(1);
    Some((f, [-(g1 + g2), g1, g2]))
}

/// The symmetric square root of an SPD 2×2 tensor, in closed form: for `M` with
/// `δ = √det M` and `τ = √(tr M + 2δ)`, `√M = (M + δ I) / τ` (Cayley–Hamilton: `S² − tr S·S +
/// det S·I = 0` with `det S = δ`, `tr S = τ`). `None` when `M` is not SPD.
fn sqrt_spd(m: &Matrix2<f64>) -> Option<Matrix2<f64>> {
    let det = m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)];
    let tr = m[(0, 0)] + m[(1, 1)];
    if det.is_nan() || tr.is_nan() || det <= 0.0 || tr <= 0.0 {
        return None;
    }
    let delta = det.sqrt();
    let tau = (tr + 2.0 * delta).sqrt();
    Some((m + Matrix2::identity() * delta) / tau)
}

/// `log Σ exp(w·f)` over `fs`; `+∞` when one of them is (a degenerate or flipped triangle).
fn log_sum_exp(w: f64, fs: &[f64]) -> f64 {
    let max = fs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !max.is_finite() {
        return max;
    }
    w * max + fs.iter().map(|f| (w * (f - max)).exp()).sum::<f64>().ln()
}

/// The working state: positions, triangles, per-vertex tensors.
struct State<'a> {
    pts: Vec<Point2<f64>>,
    tris: Vec<[u32; 3]>,
    tensors: Vec<Matrix2<f64>>,
    /// `fixed[v]`: a boundary or constrained vertex.
    fixed: Vec<bool>,
    /// Constrained and boundary edges (sorted pairs), never flipped.
    locked: std::collections::HashSet<(u32, u32)>,
    /// Triangles around each vertex.
    star: Vec<Vec<u32>>,
    moved: Vec<bool>,
    metric: &'a dyn Metric2d,
    l_tar: f64,
    w: f64,
    target: Target,
}

impl State<'_> {
    fn tri_f(&self, t: [u32; 3], at: Option<(u32, Point2<f64>, Matrix2<f64>)>) -> f64 {
        let pos = |v: u32| match at {
            Some((u, p, _)) if u == v => p,
            _ => self.pts[v as usize],
        };
        let ten = |v: u32| match at {
            Some((u, _, m)) if u == v => m,
            _ => self.tensors[v as usize],
        };
        let m = (ten(t[0]) + ten(t[1]) + ten(t[2])) / 3.0;
        let Some(s) = sqrt_spd(&m) else {
            return f64::INFINITY;
        };
        distortion_with(t.map(pos), &s, self.l_tar, self.target).map_or(f64::INFINITY, |(f, _)| f)
    }

    fn positive(&self, t: [u32; 3], at: Option<(u32, Point2<f64>)>) -> bool {
        let pos = |v: u32| match at {
            Some((u, p)) if u == v => p,
            _ => self.pts[v as usize],
        };
        orient2d(&pos(t[0]), &pos(t[1]), &pos(t[2])) == Sign::Positive
    }

    /// `log Q_p` of the triangles around `v`, with `v` at `at` (tensor re-evaluated there).
    fn ring_energy(&self, v: u32, at: Option<(Point2<f64>, Matrix2<f64>)>) -> f64 {
        let fs: Vec<f64> = self.star[v as usize]
            .iter()
            .map(|&t| self.tri_f(self.tris[t as usize], at.map(|(p, m)| (v, p, m))))
            .collect();
        log_sum_exp(self.w, &fs)
    }

    /// `−∇ log Q_p` at `v` (softmax-weighted gradients of the ring's distortions).
    fn descent(&self, v: u32) -> Option<Vector2<f64>> {
        let mut parts = Vec::new();
        for &t in &self.star[v as usize] {
            let tri = self.tris[t as usize];
            let m = (self.tensors[tri[0] as usize]
                + self.tensors[tri[1] as usize]
                + self.tensors[tri[2] as usize])
                / 3.0;
            let s = sqrt_spd(&m)?;
            let (f, g) = distortion_with(
                tri.map(|u| self.pts[u as usize]),
                &s,
                self.l_tar,
                self.target,
            )?;
            let k = tri.iter().position(|&u| u == v)?;
            parts.push((f, g[k]));
        }
        let max = parts.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
        let mut d = Vector2::zeros();
        let mut z = 0.0;
        for (f, g) in parts {
            let e = (self.w * (f - max)).exp();
            d -= g * e;
            z += e;
        }
        (z > 0.0).then(|| d / z)
    }

    /// One vertex position update at `v`; true when it moved.
    fn move_vertex(&mut self, v: u32, halvings: usize) -> bool {
        let Some(d) = self.descent(v) else {
            return false;
        };
        let dn = d.norm();
        if dn.is_nan() || dn <= 0.0 {
            return false;
        }
        // Start with a step of the shortest edge around v.
        let p = self.pts[v as usize];
        let shortest = self.star[v as usize]
            .iter()
            .flat_map(|&t| self.tris[t as usize])
            .filter(|&u| u != v)
            .map(|u| (self.pts[u as usize] - p).norm())
            .fold(f64::INFINITY, f64::min);
        if !shortest.is_finite() {
            return false;
        }
        let before = self.ring_energy(v, None);
        let mut alpha = shortest / dn;
        for _ in 0..halvings {
            let q = p + d * alpha;
            let ok = self.star[v as usize]
                .iter()
                .all(|&t| self.positive(self.tris[t as usize], Some((v, q))));
            if ok {
                if let Some(m) = clamp_spd(&self.metric.metric(&q)) {
                    if self.ring_energy(v, Some((q, m))) < before {
                        self.pts[v as usize] = q;
                        self.tensors[v as usize] = m;
                        self.moved[v as usize] = true;
                        return true;
                    }
                }
            }
            alpha *= 0.5;
        }
        false
    }

    /// The metric quality `q` of a triangle (Sec. 4.1), in its mean vertex tensor.
    fn quality(&self, t: [u32; 3]) -> f64 {
        let m = (self.tensors[t[0] as usize]
            + self.tensors[t[1] as usize]
            + self.tensors[t[2] as usize])
            / 3.0;
        crate::remesh2d::stats::sides_and_quality(&t.map(|v| self.pts[v as usize]), &m).1
    }

    /// One connectivity update sweep over the interior edges; returns the flips.
    fn flip_pass(&mut self, rule: FlipRule) -> usize {
        let mut edges: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
        for (i, t) in self.tris.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                edges.insert((a, b), (i as u32, t[(k + 2) % 3]));
            }
        }
        let mut keys: Vec<(u32, u32)> = edges.keys().copied().filter(|(a, b)| a < b).collect();
        keys.sort_unstable();
        let mut flips = 0;
        for (a, b) in keys {
            if self.locked.contains(&(a, b)) {
                continue;
            }
            let (Some(&(t1, c)), Some(&(t2, d))) = (edges.get(&(a, b)), edges.get(&(b, a))) else {
                continue;
            };
            // The two triangles may have changed by an earlier flip of this pass.
            if !reads(self.tris[t1 as usize], a, b, c) || !reads(self.tris[t2 as usize], b, a, d) {
                continue;
            }
            let (n1, n2) = ([c, d, b], [d, c, a]);
            if !(self.positive(n1, None) && self.positive(n2, None)) {
                continue;
            }
            let (o1, o2) = (self.tris[t1 as usize], self.tris[t2 as usize]);
            let better = match rule {
                FlipRule::Energy => {
                    let old = log_sum_exp(self.w, &[self.tri_f(o1, None), self.tri_f(o2, None)]);
                    let new = log_sum_exp(self.w, &[self.tri_f(n1, None), self.tri_f(n2, None)]);
                    new < old
                }
                FlipRule::MaxMin => {
                    let old = self.quality(o1).min(self.quality(o2));
                    let new = self.quality(n1).min(self.quality(n2));
                    new > old
                }
            };
            if !better {
                continue;
            }
            self.tris[t1 as usize] = n1;
            self.tris[t2 as usize] = n2;
            for (t, tri) in [(t1, n1), (t2, n2)] {
                for k in 0..3 {
                    let (u, v) = (tri[k], tri[(k + 1) % 3]);
                    edges.insert((u, v), (t, tri[(k + 2) % 3]));
                }
            }
            edges.remove(&(a, b));
            edges.remove(&(b, a));
            flips += 1;
        }
        if flips > 0 {
            self.rebuild_stars();
        }
        flips
    }

    /// The smallest angle of a triangle in its mean vertex tensor, degrees.
    fn min_angle(&self, t: [u32; 3]) -> f64 {
        let m = (self.tensors[t[0] as usize]
            + self.tensors[t[1] as usize]
            + self.tensors[t[2] as usize])
            / 3.0;
        let (l, _) =
            crate::remesh2d::stats::sides_and_quality(&t.map(|v| self.pts[v as usize]), &m);
        smallest_angle_deg(l)
    }

    /// The live triangles around `v`.
    fn live_star<'s>(&'s self, v: u32, dead: &'s [bool]) -> impl Iterator<Item = u32> + 's {
        self.star[v as usize]
            .iter()
            .copied()
            .filter(move |&t| !dead[t as usize])
    }

    /// Collapse vertex `from` into `to` along the edge between them, if that is a valid
    /// collapse: `from` is free, the edge is not locked, the two vertices share exactly the two
    /// opposite vertices (the link condition: the result is a triangulation of the same disk),
    /// and every triangle that keeps `from`'s place is positive (exact). Returns the smallest
    /// angle of the triangles around `to` afterwards, and those triangles.
    fn collapse_result(&self, from: u32, to: u32, dead: &[bool]) -> Option<(f64, Vec<[u32; 3]>)> {
        if self.fixed[from as usize] || self.locked.contains(&(from.min(to), from.max(to))) {
            return None;
        }
        let ring = |v: u32| -> std::collections::BTreeSet<u32> {
            self.live_star(v, dead)
                .flat_map(|t| self.tris[t as usize])
                .filter(|&u| u != v)
                .collect()
        };
        let (rf, rt) = (ring(from), ring(to));
        let shared = self
            .live_star(from, dead)
            .filter(|&t| self.tris[t as usize].contains(&to))
            .count();
        if shared != 2 || rf.intersection(&rt).count() != 2 {
            return None;
        }
        // The new edges are no longer than the longest edge around the pair now, nor than the
        // lengths Algorithm 1 makes (1.4 L_tar in the metric): where the fidelity control made
        // the mesh finer than the metric asks, a longer edge would cut across the surface.
        let len = |u: u32, v: u32| {
            let e = self.pts[u as usize] - self.pts[v as usize];
            let m = (self.tensors[u as usize] + self.tensors[v as usize]) / 2.0;
            e.dot(&(m * e)).max(0.0).sqrt()
        };
        let longest = self
            .live_star(from, dead)
            .chain(self.live_star(to, dead))
            .flat_map(|t| {
                let t = self.tris[t as usize];
                [len(t[0], t[1]), len(t[1], t[2]), len(t[2], t[0])]
            })
            .fold(0.0, f64::max)
            .min(MAX_COLLAPSED_EDGE * self.l_tar);
        if rf.iter().any(|&u| u != to && len(u, to) > longest) {
            return None;
        }
        let mut after = Vec::new();
        for t in self.live_star(from, dead) {
            let tri = self.tris[t as usize];
            if tri.contains(&to) {
                continue;
            }
            let moved = tri.map(|u| if u == from { to } else { u });
            if !self.positive(moved, None) {
                return None;
            }
            after.push(moved);
        }
        after.extend(
            self.live_star(to, dead)
                .map(|t| self.tris[t as usize])
                .filter(|tri| !tri.contains(&from)),
        );
        let worst = after
            .iter()
            .map(|&t| self.min_angle(t))
            .fold(f64::INFINITY, f64::min);
        Some((worst, after))
    }

    /// One sweep of edge collapses: each triangle (in id order) whose smallest metric angle is
    /// below `below_deg` loses its shortest edge, into whichever end gives the larger smallest
    /// angle, when that angle beats the one before around both ends. The triangles touched wait
    /// for the next sweep; collapsed vertices are left without triangles (dropped at the end).
    fn collapse_pass(&mut self, below_deg: f64) -> usize {
        let mut dead = vec![false; self.tris.len()];
        let mut touched = vec![false; self.pts.len()];
        let mut collapses = 0;
        for t in 0..self.tris.len() {
            let tri = self.tris[t];
            if dead[t] || tri.iter().any(|&v| touched[v as usize]) {
                continue;
            }
            let m = (self.tensors[tri[0] as usize]
                + self.tensors[tri[1] as usize]
                + self.tensors[tri[2] as usize])
                / 3.0;
            let (l, _) =
                crate::remesh2d::stats::sides_and_quality(&tri.map(|v| self.pts[v as usize]), &m);
            if smallest_angle_deg(l) >= below_deg {
                continue;
            }
            // The shortest side is opposite the smallest angle: side k joins corners k+1, k+2.
            let k = (0..3).min_by(|&i, &j| l[i].total_cmp(&l[j])).unwrap_or(0);
            let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let before = self
                .live_star(a, &dead)
                .chain(self.live_star(b, &dead))
                .map(|t| self.min_angle(self.tris[t as usize]))
                .fold(f64::INFINITY, f64::min);
            let best = [(b, a), (a, b)]
                .into_iter()
                .filter_map(|(from, to)| {
                    self.collapse_result(from, to, &dead)
                        .map(|(worst, _)| (worst, from, to))
                })
                .max_by(|x, y| x.0.total_cmp(&y.0));
            let Some((worst, from, to)) = best else {
                continue;
            };
            if worst <= before {
                continue;
            }
            let star_from: Vec<u32> = self.live_star(from, &dead).collect();
            let star_to: Vec<u32> = self.live_star(to, &dead).collect();
            for &s in star_from.iter().chain(&star_to) {
                for v in self.tris[s as usize] {
                    touched[v as usize] = true;
                }
            }
            for s in star_from {
                let tri = &mut self.tris[s as usize];
                if tri.contains(&to) {
                    dead[s as usize] = true;
                } else {
                    *tri = tri.map(|u| if u == from { to } else { u });
                }
            }
            self.moved[from as usize] = true;
            collapses += 1;
        }
        if collapses > 0 {
            let mut keep = dead.iter().map(|d| !d);
            self.tris.retain(|_| keep.next().unwrap_or(true));
            self.rebuild_stars();
        }
        collapses
    }

    fn rebuild_stars(&mut self) {
        self.star = vec![Vec::new(); self.pts.len()];
        for (i, t) in self.tris.iter().enumerate() {
            for &v in t {
                self.star[v as usize].push(i as u32);
            }
        }
    }
}

/// The longest metric edge, over `L_tar`, an edge collapse may make: the upper end of the
/// lengths Algorithm 1 aims at (paper-notes.md Sec. 3.4).
const MAX_COLLAPSED_EDGE: f64 = 1.4;

/// The smallest angle (degrees) of a triangle with sides `l`, by the law of cosines.
fn smallest_angle_deg(l: [f64; 3]) -> f64 {
    (0..3)
        .map(|i| {
            let (a, b, c) = (l[i], l[(i + 1) % 3], l[(i + 2) % 3]);
            let cs = ((b * b + c * c - a * a) / (2.0 * b * c)).clamp(-1.0, 1.0);
            cs.acos().to_degrees()
        })
        .fold(f64::INFINITY, f64::min)
}

/// `t` is the triangle `(a, b, c)`, in some rotation.
fn reads(t: [u32; 3], a: u32, b: u32, c: u32) -> bool {
    (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b && t[(k + 2) % 3] == c)
}

/// Algorithm 2's planar updates on `domain`'s own triangulation (its boundary and constrained
/// vertices and edges kept): `rounds` × (vertex position update over the free vertices, worst
/// ring first; connectivity update), stopping early at a round that changes nothing. Errors
/// when a tensor is not SPD at a vertex.
pub fn improve_planar(
    domain: &PlanarDomain,
    metric: &dyn Metric2d,
    l_tar: f64,
    options: &Eq5Options,
) -> Result<(PlanarMesh, Eq5Counts), Remesh2dError> {
    let n = domain.points.len();
    let mut tensors = Vec::with_capacity(n);
    for p in &domain.points {
        tensors.push(
            clamp_spd(&metric.metric(p)).ok_or(Remesh2dError::MetricNotSpd { x: p.x, y: p.y })?,
        );
    }
    let mut fixed = vec![false; n];
    let mut locked = std::collections::HashSet::new();
    let nb = domain.boundary.len();
    for k in 0..nb {
        let (a, b) = (domain.boundary[k], domain.boundary[(k + 1) % nb]);
        fixed[a as usize] = true;
        locked.insert((a.min(b), a.max(b)));
    }
    for &[a, b] in &domain.constrained_edges {
        fixed[a as usize] = true;
        fixed[b as usize] = true;
        locked.insert((a.min(b), a.max(b)));
    }
    let mut s = State {
        pts: domain.points.clone(),
        tris: domain.triangles.clone(),
        tensors,
        fixed,
        locked,
        star: Vec::new(),
        moved: vec![false; n],
        metric,
        l_tar,
        w: options.w,
        target: options.target,
    };
    s.rebuild_stars();
    let mut counts = Eq5Counts::default();
    for _ in 0..options.rounds {
        counts.rounds += 1;
        // Worst ring first; ties by id, so the order is deterministic.
        let mut order: Vec<(f64, u32)> = (0..n as u32)
            .filter(|&v| !s.fixed[v as usize] && !s.star[v as usize].is_empty())
            .map(|v| (s.ring_energy(v, None), v))
            .collect();
        order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let mut changed = 0;
        for (_, v) in order {
            for _ in 0..options.steps {
                if !s.move_vertex(v, options.line_search) {
                    break;
                }
                counts.moves += 1;
                changed += 1;
            }
        }
        let flips = s.flip_pass(options.flip_rule);
        counts.flips += flips;
        changed += flips;
        if options.collapse_below_deg > 0.0 {
            let collapses = s.collapse_pass(options.collapse_below_deg);
            counts.collapses += collapses;
            changed += collapses;
        }
        if changed == 0 {
            break;
        }
    }
    // Collapsed vertices have no triangles left; only free vertices collapse, so every
    // boundary and constrained vertex stays.
    let mut new_id = vec![u32::MAX; n];
    let (mut points, mut origin) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for (v, id) in new_id.iter_mut().enumerate() {
        if s.star[v].is_empty() && !s.fixed[v] && counts.collapses > 0 {
            continue;
        }
        *id = points.len() as u32;
        points.push(s.pts[v]);
        origin.push((!s.moved[v]).then_some(v as u32));
    }
    let triangles = s
        .tris
        .iter()
        .map(|t| t.map(|v| new_id[v as usize]))
        .collect();
    Ok((
        PlanarMesh {
            points,
            triangles,
            origin,
        },
        counts,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::invariants::certify_planar;
    use rand::SeedableRng;

    struct Iso;
    impl Metric2d for Iso {
        fn metric(&self, _: &Point2<f64>) -> Matrix2<f64> {
            Matrix2::identity()
        }
    }

    #[test]
    fn the_closed_form_square_root_squares_back_and_refuses_what_is_not_spd() {
        for m in [
            Matrix2::new(4.0, 0.0, 0.0, 9.0),
            Matrix2::new(2.0, 0.7, 0.7, 0.5),
            Matrix2::new(1e4, -3.0, -3.0, 1e-2),
        ] {
            let s = sqrt_spd(&m).expect("SPD");
            assert!((s * s - m).norm() <= 1e-12 * m.norm(), "{m} {s}");
            assert!((s - s.transpose()).norm() == 0.0);
            assert!(s.determinant() > 0.0 && s.trace() > 0.0);
        }
        assert!(sqrt_spd(&Matrix2::new(1.0, 2.0, 2.0, 1.0)).is_none());
        assert!(sqrt_spd(&Matrix2::new(-1.0, 0.0, 0.0, -1.0)).is_none());
        assert!(sqrt_spd(&Matrix2::new(f64::NAN, 0.0, 0.0, 1.0)).is_none());
    }

    #[test]
    fn distortion_is_four_exactly_at_the_target_equilateral_and_its_gradient_is_exact() {
        let l = 0.7;
        let eq = [
            Point2::new(0.3, 0.1),
            Point2::new(0.3 + l, 0.1),
            Point2::new(0.3 + 0.5 * l, 0.1 + 0.5 * 3f64.sqrt() * l),
        ];
        let (f, g) = distortion(eq, &Matrix2::identity(), l).expect("positive");
        assert!((f - 4.0).abs() < 1e-12, "{f}");
        assert!(g.iter().all(|g| g.norm() < 1e-9), "{g:?}");
        // A skewed triangle in an anisotropic metric: central differences.
        let s = Matrix2::new(2.0, 0.3, 0.3, 0.7);
        let p = [
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.2),
            Point2::new(0.1, 0.8),
        ];
        for target in [Target::Length, Target::OwnArea] {
            let d = |p| distortion_with(p, &s, l, target);
            let (f0, g) = d(p).expect("positive");
            assert!(f0 > 4.0);
            let h = 1e-6;
            for k in 0..3 {
                for c in 0..2 {
                    let mut a = p;
                    let mut b = p;
                    a[k][c] += h;
                    b[k][c] -= h;
                    let fd = (d(a).unwrap().0 - d(b).unwrap().0) / (2.0 * h);
                    assert!(
                        (fd - g[k][c]).abs() < 1e-5 * (1.0 + fd.abs()),
                        "{k} {c}: {fd} vs {}",
                        g[k][c]
                    );
                }
            }
        }
        // Shape only: an equilateral triangle of another size is optimal for OwnArea.
        let big = eq.map(|q| Point2::from(q.coords * 3.0));
        let (f, g) = distortion_with(big, &Matrix2::identity(), l, Target::OwnArea).unwrap();
        assert!((f - 4.0).abs() < 1e-12 && g.iter().all(|g| g.norm() < 1e-9));
        assert!(distortion(big, &Matrix2::identity(), l).unwrap().0 > 4.5);
        // Flipped: infinite energy.
        assert!(distortion([p[0], p[2], p[1]], &s, l).is_none());
    }

    /// A square fan around one interior vertex pushed next to a corner: a sliver fan.
    fn sliver_fan() -> PlanarDomain {
        PlanarDomain {
            points: vec![
                Point2::new(0.0, 0.0),
                Point2::new(1.0, 0.0),
                Point2::new(1.0, 1.0),
                Point2::new(0.0, 1.0),
                Point2::new(0.98, 0.01),
            ],
            triangles: vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]],
            boundary: vec![0, 1, 2, 3],
            constrained_edges: Vec::new(),
        }
    }

    /// An obtuse triangle split at an inner vertex: whatever its position, one of the parts
    /// has an angle of at most half the base angle (19.3°); the triangle itself has 38.7°.
    fn split_triangle() -> PlanarDomain {
        PlanarDomain {
            points: vec![
                Point2::new(0.0, 0.0),
                Point2::new(2.0, 0.0),
                Point2::new(1.0, 0.8),
                Point2::new(1.0, 0.3),
            ],
            triangles: vec![[0, 1, 3], [1, 2, 3], [2, 0, 3]],
            boundary: vec![0, 1, 2],
            constrained_edges: Vec::new(),
        }
    }

    fn smallest_angle(m: &PlanarMesh) -> f64 {
        m.triangles
            .iter()
            .map(|t| {
                let p = t.map(|v| m.points[v as usize]);
                let (l, _) = crate::remesh2d::stats::sides_and_quality(&p, &Matrix2::identity());
                smallest_angle_deg(l)
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn an_inner_vertex_no_move_can_place_well_is_collapsed() -> Result<(), Remesh2dError> {
        let dom = split_triangle();
        let (kept, counts) = improve_planar(&dom, &Iso, 2.0, &Eq5Options::default())?;
        assert_eq!(
            (counts.collapses, kept.triangles.len()),
            (0, 3),
            "off by default"
        );
        let on = Eq5Options {
            collapse_below_deg: 30.0,
            ..Eq5Options::default()
        };
        let (out, counts) = improve_planar(&dom, &Iso, 2.0, &on)?;
        certify_planar(&dom, &out).expect("certified");
        assert_eq!(counts.collapses, 1, "{counts:?}");
        assert_eq!(out.triangles.len(), 1);
        assert_eq!(
            out.points,
            dom.points[..3],
            "boundary kept bit for bit, inner vertex gone"
        );
        assert_eq!(out.origin, vec![Some(0), Some(1), Some(2)]);
        let (before, after) = (smallest_angle(&kept), smallest_angle(&out));
        assert!(
            before < 19.4 && (after - 38.66).abs() < 0.01,
            "{before}° → {after}°"
        );
        Ok(())
    }

    #[test]
    fn a_sliver_fan_is_recentred_and_the_boundary_stays() -> Result<(), Remesh2dError> {
        let dom = sliver_fan();
        let (out, counts) = improve_planar(&dom, &Iso, 0.7, &Eq5Options::default())?;
        certify_planar(&dom, &out).expect("certified");
        assert!(counts.moves > 0);
        assert_eq!(
            &out.points[..4],
            &dom.points[..4],
            "boundary kept bit for bit"
        );
        assert_eq!(out.origin[4], None, "the moved vertex is new");
        let c = out.points[4];
        assert!(
            (c - Point2::new(0.5, 0.5)).norm() < 0.05,
            "{c:?} {counts:?}"
        );
        let worst = |m: &PlanarMesh| {
            m.triangles
                .iter()
                .map(|t| {
                    crate::remesh2d::stats::sides_and_quality(
                        &t.map(|v| m.points[v as usize]),
                        &Matrix2::identity(),
                    )
                    .1
                })
                .fold(1.0, f64::min)
        };
        let before = PlanarMesh {
            points: dom.points.clone(),
            triangles: dom.triangles.clone(),
            origin: (0..5).map(Some).collect(),
        };
        // Centred, the four triangles are right isosceles: q = √3/(1 + √2) ≈ 0.717.
        assert!(worst(&out) > 0.71 && worst(&before) < 0.1);
        Ok(())
    }

    #[test]
    fn the_updates_end_within_their_rounds_on_adversarial_inputs() -> Result<(), Remesh2dError> {
        // A metric with a discontinuity across x = 0.5 (1:100 in size), and a needle at a
        // boundary corner: the updates must end (counted rounds), keep the domain certified
        // and never raise the total energy.
        struct Jump;
        impl Metric2d for Jump {
            fn metric(&self, p: &Point2<f64>) -> Matrix2<f64> {
                match p.x < 0.5 {
                    true => Matrix2::identity(),
                    false => Matrix2::new(1e4, 0.0, 0.0, 1.0),
                }
            }
        }
        let mut dom = sliver_fan();
        dom.points[4] = Point2::new(0.999, 0.0005);
        for (metric, name) in [(&Jump as &dyn Metric2d, "jump"), (&Iso, "iso")] {
            for rule in [FlipRule::Energy, FlipRule::MaxMin] {
                let o = Eq5Options {
                    flip_rule: rule,
                    ..Eq5Options::default()
                };
                let (out, counts) = improve_planar(&dom, metric, 0.5, &o)?;
                certify_planar(&dom, &out).unwrap_or_else(|e| panic!("{name} {rule:?}: {e}"));
                assert!(counts.rounds <= o.rounds);
            }
        }
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let out = Eq5Updates::default().remesh(&dom, &Iso, 0.5, &mut rng)?;
        certify_planar(&dom, &out).expect("certified");
        Ok(())
    }
}
