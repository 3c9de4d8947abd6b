//! The default parameterizer of Sec. 3.3: Tutte initialisation, then the area-weighted
//! symmetric Dirichlet energy minimised with a free boundary by projected Newton, with the
//! boundary barrier of ref. [30] and an exact certificate after every accepted step.
//!
//! * Energy per triangle (Smith & Schaefer 2015): `E(F) = σ1² + σ2² + σ1⁻² + σ2⁻²`, which
//!   for a 2×2 Jacobian is `‖F‖² (1 + det(F)⁻²)`; it is 4 for an isometry and ∞ on a flip.
//! * Newton: the 4×4 Hessian in `F` has the analytic eigensystem of isotropic energies
//!   (Smith, de Goes, Kim 2019); for this energy only the twist mode can be negative, with
//!   eigenvalue `2 − 2(‖F‖² − J)/J³`; it is clamped to 0 after a full step and replaced by
//!   its absolute value after a truncated one (`abs_twist`, Chen et al. 2024). Assembly
//!   uses a sparsity pattern fixed at start and one symbolic Cholesky reused every step.
//! * Boundary barrier (ref. [30], Su et al.): for every boundary vertex `p` and boundary edge
//!   `ab` not incident to it, the triangle-inequality gap `d = |p−a| + |p−b| − |a−b|`
//!   (zero exactly when `p` touches the edge) enters `(ε/d − 1)²` while `d < ε`, with `ε`
//!   a fraction of the mean edge length. Its Hessian is the Gauss–Newton term, kept on the
//!   2×2 diagonal blocks so the sparsity pattern does not change.
//! * Start: the free-boundary LSCM when certified; else the LSCM after the overlap repair
//!   (`repair_iters`) when that is certified; else the Tutte map. The repair steps are part
//!   of computing the start: only the certified start and the iterates after it count.
//! * Stopping: a step whose decrease is below `rel_tol` of the excess `E − 4`.
//! * Line search: the largest flip-free step (smallest positive root of `det J(t) = 0` over
//!   all triangles) times `step_fraction`, then Armijo backtracking; a trial is accepted only
//!   if `certify_bijective` (exact) passes, so every iterate is certified.

use super::distortion::{jacobian, triangle_frames, TriangleFrame};
use super::lscm::lscm_on;
use super::sparse::{Llt, Pattern, VertexSystem};
use super::tutte::{certified_tutte, scale_to_area, TutteWeights};
use super::{
    certify, distortion, recertify, validate_disk, ParamError, Parameterization, Parameterizer,
};
use crate::ids::VertexId;
use crate::mesh::TriMesh;
use faer::Mat;
use nalgebra::{Matrix4, Point2, Vector2, Vector4};
use std::cell::OnceCell;

/// Options of [`SymmetricDirichlet`] (defaults in brackets).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SdOptions {
    /// Weights of the Tutte initial map [`TutteWeights::Cotan`] (clamped positive, so Tutte's
    /// theorem applies; symmetric, so solved by sparse Cholesky, ~5× faster than the LU that
    /// mean-value weights need; uniform weights are the certified fallback).
    pub init_weights: TutteWeights,
    /// Start from the free-boundary least-squares conformal map ([`super::lscm()`]) when it
    /// passes the exact certificate, else from the Tutte map [true]. The circle boundary of
    /// the Tutte map squeezes triangles of curved patches to ~1e-7 of their area, and the
    /// optimisation from there needs many more iterations and can end in a worse local
    /// minimum with the boundary pressed against itself.
    pub free_boundary_init: bool,
    /// Newton iteration budget \[100\]; running out is reported (`hit_budget`), not an error.
    pub max_iters: usize,
    /// Stop when a step decreases the energy excess `E − 4` over an isometry by less than
    /// this fraction [1e-4].
    pub rel_tol: f64,
    /// Fraction of the largest flip-free step tried first [0.9].
    pub step_fraction: f64,
    /// Armijo sufficient-decrease constant [1e-4].
    pub armijo: f64,
    /// Barrier activation distance `ε` on the triangle-inequality gap, as a fraction of the
    /// mean 3D edge length [0.02].
    pub barrier_distance: f64,
    /// Weight of one barrier term relative to one average triangle's energy share [1.0].
    pub barrier_weight: f64,
    /// Hessian projection of the twist mode: `true` replaces a negative eigenvalue by its
    /// absolute value after an iteration whose step was truncated (Chen et al. 2024,
    /// "trust-region eigenvalue filtering": far from the rest shape the clamped Hessian
    /// over-trusts the twist direction, and the Armijo test then halves most steps) and
    /// clamps it to 0 after a full step; `false` always clamps [true]. On the strongly curved cover
    /// patches that start from the Tutte map this halves the final energy excess in the
    /// same budget.
    pub abs_twist: bool,
    /// Cap every first trial step at `step_fraction` times the largest step along which no
    /// boundary vertex meets a non-incident boundary edge (swept vertex–edge test), so the
    /// certificate rarely rejects a trial for a self-touching boundary [true].
    pub collision_bound: bool,
    /// Overlap repair of an LSCM that is not certified (its boundary overlaps itself, mostly
    /// where narrow slits of a ragged cover patch close): up to this many locally injective
    /// Newton steps from it on the symmetric Dirichlet energy plus a penalty pushing every
    /// penetrating boundary vertex `repair_margin` back out of the edge it crossed (no
    /// barrier, no certificate during the steps; stops early once certified, or when the
    /// number of crossing boundary edges has not fallen for 6 steps). The result is used
    /// only if it passes the exact certificate, else the Tutte map \[30\]; 0 disables.
    pub repair_iters: usize,
    /// Weight of one overlap-repair term relative to one average triangle's energy share
    /// (0: plain locally injective steps) \[100\].
    pub repair_weight: f64,
    /// Clearance the overlap repair aims for, as a fraction of the mean 3D edge length [0.2].
    pub repair_margin: f64,
    /// The overlap repair stops once the map is certified with every repaired vertex at
    /// least this fraction of `repair_margin` outside the edge it crossed \[0.5\].
    pub repair_clearance: f64,
}

impl Default for SdOptions {
    fn default() -> Self {
        SdOptions {
            init_weights: TutteWeights::Cotan,
            free_boundary_init: true,
            max_iters: 100,
            rel_tol: 1e-4,
            step_fraction: 0.9,
            armijo: 1e-4,
            barrier_distance: 0.02,
            barrier_weight: 1.0,
            abs_twist: true,
            collision_bound: true,
            repair_iters: 30,
            repair_weight: 100.0,
            repair_margin: 0.2,
            repair_clearance: 0.5,
        }
    }
}

/// Symmetric Dirichlet parameterizer (name `"sd"`), the default [`Parameterizer`].
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct SymmetricDirichlet {
    /// Options.
    pub options: SdOptions,
}

/// Iteration log of [`optimize_with_log`]. Index 0 is the initial map.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SdLog {
    /// Objective (mean symmetric Dirichlet energy + barrier) of every accepted iterate.
    pub energies: Vec<f64>,
    /// Smallest doubled signed triangle area of every accepted iterate (float).
    pub min_double_area: Vec<f64>,
    /// Accepted step length (fraction of the Newton step) of each iteration.
    pub steps: Vec<f64>,
    /// Largest flip-free step (before `step_fraction`) of each iteration.
    pub flip_free_steps: Vec<f64>,
    /// Newton decrement `−∇E·d` of each iteration's direction `d` (twice the decrease the
    /// quadratic model predicts for the full step).
    pub decrements: Vec<f64>,
    /// Line-search trials rejected by the Armijo test (or an infinite energy).
    pub armijo_rejections: usize,
    /// Newton iterations taken.
    pub iterations: usize,
    /// The budget ran out before the stopping rule was met.
    pub hit_budget: bool,
    /// A step was wanted but no trial passed the certificate: the last certified iterate
    /// was returned.
    pub fell_back: bool,
    /// Trials rejected by the exact certificate (after passing the float tests).
    pub certificate_rejections: usize,
    /// Wall time in milliseconds: [setup (pattern, symbolic factorisation), assembly,
    /// numeric factorisation and solve, line search with certification].
    pub time_ms: [f64; 4],
    /// Numeric Cholesky factorisations (more than one per iteration when the regularising
    /// shift had to grow).
    pub factorizations: usize,
    /// Iterations whose first trial step was capped by the boundary-collision bound.
    pub collision_limited: usize,
}

/// Overlap repair iterations without fewer crossing boundary edges before it gives up.
const REPAIR_PATIENCE: usize = 6;

/// Energy, gradient and projected Hessian of one triangle with respect to `vec(F)`
/// (row-major `a, b, c, d`). `None` when `det F ≤ 0` (infinite energy).
#[inline]
fn sd_in_f(
    f: &nalgebra::Matrix2<f64>,
    hess: bool,
    abs_twist: bool,
) -> Option<(f64, Vector4<f64>, Matrix4<f64>)> {
    let (a, b, c, d) = (f[(0, 0)], f[(0, 1)], f[(1, 0)], f[(1, 1)]);
    let j = a * d - b * c;
    if j.is_nan() || j <= 0.0 {
        return None;
    }
    let n = a * a + b * b + c * c + d * d;
    let (ij, ij2) = (1.0 / j, 1.0 / (j * j));
    let e = n * (1.0 + ij2);
    let fv = Vector4::new(a, b, c, d);
    // g = ∂J/∂vec(F) = vec(cof F).
    let gv = Vector4::new(d, -c, -b, a);
    let grad = fv * (2.0 * (1.0 + ij2)) - gv * (2.0 * n * ij2 * ij);
    if !hess {
        return Some((e, grad, Matrix4::zeros()));
    }
    let ij3 = ij2 * ij;
    let mut h = Matrix4::identity() * (2.0 * (1.0 + ij2))
        - (fv * gv.transpose() + gv * fv.transpose()) * (4.0 * ij3)
        + gv * gv.transpose() * (6.0 * n * ij2 * ij2);
    // −2 n J⁻³ ∂²J/∂vec(F)² (constant: +1 on (a,d), −1 on (b,c)).
    let k = 2.0 * n * ij3;
    h[(0, 3)] -= k;
    h[(3, 0)] -= k;
    h[(1, 2)] += k;
    h[(2, 1)] += k;
    // Project: the twist eigenvalue (Ψ1 + Ψ2)/(σ1 + σ2) = 2 − 2(n − J)/J³ is the only one
    // that can be negative; its eigenvector is vec(R90 · R), R the polar rotation of F.
    let twist = 2.0 - 2.0 * (n - j) * ij3;
    if twist < 0.0 {
        let (cs, sn) = (a + d, c - b);
        let r = cs.hypot(sn);
        if r > 0.0 {
            let (cs, sn) = (cs / r, sn / r);
            let q = Vector4::new(-sn, -cs, cs, -sn) * std::f64::consts::FRAC_1_SQRT_2;
            let lift = if abs_twist { -2.0 * twist } else { -twist };
            h += q * q.transpose() * lift;
        }
    }
    Some((e, grad, h))
}

/// Boundary barrier (ref. [30]): `φ(d) = (ε/d − 1)²` for `0 < d < ε` on the
/// triangle-inequality gap `d`. Returns the active terms as `(p, a, b, d)` (vertex indices).
fn barrier_pairs(
    uv: &[Point2<f64>],
    boundary: &[VertexId],
    eps: f64,
) -> Vec<(usize, usize, usize, f64)> {
    let m = boundary.len();
    let mut out = Vec::new();
    if m < 4 || eps <= 0.0 {
        return out;
    }
    // Vertices sorted by x; each edge looks up the x-range of its ellipse {d < ε}, whose
    // half-width beyond the segment is at most √(Lε + ε²)/2.
    let mut by_x: Vec<(f64, usize)> = (0..m).map(|i| (uv[boundary[i].idx()].x, i)).collect();
    by_x.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    for e in 0..m {
        let (ia, ib) = (boundary[e].idx(), boundary[(e + 1) % m].idx());
        let (a, b) = (uv[ia], uv[ib]);
        let l = (b - a).norm();
        let r = 0.5 * (l * eps + eps * eps).sqrt() * 1.000_001;
        let (x0, x1) = (a.x.min(b.x) - r, a.x.max(b.x) + r);
        let (y0, y1) = (a.y.min(b.y) - r, a.y.max(b.y) + r);
        let start = by_x.partition_point(|x| x.0 < x0);
        for &(px, k) in &by_x[start..] {
            if px > x1 {
                break;
            }
            if k == e || k == (e + 1) % m {
                continue;
            }
            let ip = boundary[k].idx();
            let p = uv[ip];
            if p.y < y0 || p.y > y1 {
                continue;
            }
            let d = (p - a).norm() + (p - b).norm() - l;
            if d < eps {
                out.push((ip, ia, ib, d.max(0.0)));
            }
        }
    }
    out
}

/// Boundary vertices (loop indices) that lie inside the image of another part of the disk:
/// a point a hair (`delta`) outside the vertex, along the bisector of its exterior angle,
/// has a non-zero winding number with respect to the boundary polygon (it would be 0 for a
/// simple counter-clockwise boundary). Float arithmetic: this only steers the overlap
/// repair; the exact certificate judges its result.
fn penetrating_vertices(uv: &[Point2<f64>], boundary: &[VertexId], delta: f64) -> Vec<usize> {
    let m = boundary.len();
    let at = |i: usize| uv[boundary[i % m].idx()];
    // Horizontal strips of the y range, each listing the edges whose y-interval meets it
    // (boundary edges are short, so most lie in one or two): a +x ray cast at height y only
    // visits its strip.
    let (mut y_lo, mut y_hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for i in 0..m {
        y_lo = y_lo.min(at(i).y);
        y_hi = y_hi.max(at(i).y);
    }
    let strips = (m / 8).max(1);
    let height = (y_hi - y_lo) / strips as f64;
    let strip = |y: f64| -> usize {
        if height > 0.0 && y.is_finite() {
            (((y - y_lo) / height).max(0.0) as usize).min(strips - 1)
        } else {
            0
        }
    };
    let mut edges: Vec<Vec<usize>> = vec![Vec::new(); strips];
    for i in 0..m {
        let (a, b) = (at(i), at(i + 1));
        for e in &mut edges[strip(a.y.min(b.y))..=strip(a.y.max(b.y))] {
            e.push(i);
        }
    }
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
        let mut winding = 0i32;
        for &i in &edges[strip(q.y)] {
            let (a, b) = (at(i), at(i + 1));
            // Half-open rule on y; count crossings of the ray x > q.x with sign.
            if (a.y <= q.y) != (b.y <= q.y) {
                let x = a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y);
                if x > q.x {
                    winding += if b.y > a.y { 1 } else { -1 };
                }
            }
        }
        if winding != 0 {
            out.push(k);
        }
    }
    out
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

/// The optimisation problem: rest frames, pattern, scales.
struct Problem<'a> {
    tris: &'a [[VertexId; 3]],
    frames: Vec<TriangleFrame>,
    boundary: &'a [VertexId],
    total_area: f64,
    eps: f64,
    barrier_w: f64,
    /// Overlap repair: weight (0 = off), clearance, and the (vertex, edge start, edge end)
    /// pairs found by [`penetrating_vertices`] so far.
    pen_w: f64,
    pen_margin: f64,
    pen_pairs: Vec<[usize; 3]>,
}

/// Gradient of the triangle-inequality gap `|p − a| + |p − b| − |a − b|` with respect to
/// `p`, `a` and `b`.
fn tri_gap_grad(uv: &[Point2<f64>], p: usize, a: usize, b: usize) -> [(usize, Vector2<f64>); 3] {
    let unit = |x: Point2<f64>, y: Point2<f64>| {
        let v = x - y;
        let l = v.norm();
        if l > 0.0 {
            v / l
        } else {
            Vector2::zeros()
        }
    };
    let (pp, pa, pb) = (uv[p], uv[a], uv[b]);
    [
        (p, unit(pp, pa) + unit(pp, pb)),
        (a, unit(pa, pp) - unit(pa, pb)),
        (b, unit(pb, pp) - unit(pb, pa)),
    ]
}

impl Problem<'_> {
    /// Objective: Σ A_t E_t / A + w Σ φ(d). ∞ if a triangle is flipped (float) or a barrier
    /// gap is zero.
    fn energy(&self, uv: &[Point2<f64>]) -> f64 {
        let mut e = 0.0;
        for (t, fr) in self.tris.iter().zip(&self.frames) {
            if fr.area <= 0.0 {
                continue;
            }
            let f = jacobian(fr, [uv[t[0].idx()], uv[t[1].idx()], uv[t[2].idx()]]);
            match sd_in_f(&f, false, false) {
                Some((et, _, _)) => e += fr.area * et,
                None => return f64::INFINITY,
            }
        }
        e /= self.total_area;
        for (_, _, _, d) in barrier_pairs(uv, self.boundary, self.eps) {
            if d <= 0.0 {
                return f64::INFINITY;
            }
            e += self.barrier_w * (self.eps / d - 1.0).powi(2);
        }
        for &[p, a, b] in &self.pen_pairs {
            if let Some((sd, _)) = signed_gap(uv, p, a, b) {
                let x = (sd + self.pen_margin) / self.pen_margin;
                if x > 0.0 {
                    e += self.pen_w * x * x;
                }
            }
        }
        e
    }

    /// Gradient and projected Hessian values (in `pattern` order).
    fn assemble(
        &self,
        uv: &[Point2<f64>],
        pat: &Pattern,
        grad: &mut [f64],
        vals: &mut [f64],
        abs_twist: bool,
    ) -> Result<(), ParamError> {
        grad.iter_mut().for_each(|x| *x = 0.0);
        vals.iter_mut().for_each(|x| *x = 0.0);
        for (ti, (t, fr)) in self.tris.iter().zip(&self.frames).enumerate() {
            if fr.area <= 0.0 {
                continue;
            }
            let f = jacobian(fr, [uv[t[0].idx()], uv[t[1].idx()], uv[t[2].idx()]]);
            let (_, gf, hf) = sd_in_f(&f, true, abs_twist).ok_or_else(|| {
                ParamError::NotCertified(format!("f{ti} is flipped during optimisation"))
            })?;
            let w = fr.area / self.total_area;
            let g = &fr.grad;
            // ∂vec(F)/∂u_{k,i}: entries (i, j) ↦ index 2i + j with coefficient G[k][j].
            for k in 0..3 {
                for i in 0..2 {
                    grad[2 * t[k].idx() + i] += w * (gf[2 * i] * g[k][0] + gf[2 * i + 1] * g[k][1]);
                }
            }
            // Block (i, m) of the 6×6 Hessian over corners: G · H_F[2i.., 2m..] · Gᵀ (3×3).
            for i in 0..2 {
                for m in 0..2 {
                    let hb = [
                        [hf[(2 * i, 2 * m)], hf[(2 * i, 2 * m + 1)]],
                        [hf[(2 * i + 1, 2 * m)], hf[(2 * i + 1, 2 * m + 1)]],
                    ];
                    for k in 0..3 {
                        let tk = [
                            w * (g[k][0] * hb[0][0] + g[k][1] * hb[1][0]),
                            w * (g[k][0] * hb[0][1] + g[k][1] * hb[1][1]),
                        ];
                        for l in 0..3 {
                            let v = tk[0] * g[l][0] + tk[1] * g[l][1];
                            vals[pat.tri_slot(ti, 2 * k + i, 2 * l + m)] += v;
                        }
                    }
                }
            }
        }
        for (p, a, b, d) in barrier_pairs(uv, self.boundary, self.eps) {
            if d <= 0.0 {
                return Err(ParamError::NotCertified(format!(
                    "boundary vertex v{p} touches boundary edge (v{a}, v{b})"
                )));
            }
            let r = self.eps / d;
            let d1 = self.barrier_w * 2.0 * (r - 1.0) * (-r / d);
            let d2 = self.barrier_w * (2.0 * r * r / (d * d) + 4.0 * r * (r - 1.0) / (d * d));
            for (v, gv) in tri_gap_grad(uv, p, a, b) {
                grad[2 * v] += d1 * gv.x;
                grad[2 * v + 1] += d1 * gv.y;
                pat.add_diag_outer(vals, v, d2, [gv.x, gv.y]);
            }
        }
        // Overlap repair: w ((s + margin) / margin)² while positive, s the signed distance of
        // p inside the line of ab; gradient along the edge's inner normal (p moves out, a and b
        // by their share), Gauss–Newton diagonal blocks.
        let k = self.pen_w / (self.pen_margin * self.pen_margin);
        for &[p, a, b] in &self.pen_pairs {
            let Some((sd, (nl, u))) = signed_gap(uv, p, a, b) else {
                continue;
            };
            if sd + self.pen_margin <= 0.0 {
                continue;
            }
            let d1 = 2.0 * k * (sd + self.pen_margin);
            for (v, c) in [(p, 1.0), (a, -(1.0 - u)), (b, -u)] {
                grad[2 * v] += d1 * c * nl.x;
                grad[2 * v + 1] += d1 * c * nl.y;
                pat.add_diag_outer(vals, v, 2.0 * k * c * c, [nl.x, nl.y]);
            }
        }
        Ok(())
    }

    /// Largest `t` with every triangle's `det(U + t dU) > 0` (∞ if none vanishes).
    fn max_flip_free_step(&self, uv: &[Point2<f64>], dir: &[f64]) -> f64 {
        let mut tmax = f64::INFINITY;
        for t in self.tris {
            let p = |k: usize| uv[t[k].idx()];
            let q = |k: usize| Vector2::new(dir[2 * t[k].idx()], dir[2 * t[k].idx() + 1]);
            let (e1, e2) = (p(1) - p(0), p(2) - p(0));
            let (d1, d2) = (q(1) - q(0), q(2) - q(0));
            // det(U + t dU) = c0 + c1 t + c2 t².
            let c0 = e1.perp(&e2);
            let c1 = e1.perp(&d2) + d1.perp(&e2);
            let c2 = d1.perp(&d2);
            if let Some(r) = smallest_positive_root(c2, c1, c0) {
                tmax = tmax.min(r);
            }
        }
        tmax
    }
}

/// Largest `t ∈ (0, horizon]` such that along `uv + s·dir`, `s ∈ [0, t)`, no boundary vertex
/// meets a boundary edge not incident to it (`horizon` if none does). Two moving segments
/// first touch at an endpoint lying on the other segment, so this keeps a simple boundary
/// polygon simple. For each pair the orientation `orient2d(a(s), b(s), p(s))` is a
/// quadratic in `s`; its positive roots are where `p` crosses the moving line `ab`, and a
/// root counts when `p` then lies on the segment (with a small margin: over-counting only
/// shortens the step). Broad phase: sort-and-sweep on x over the boxes swept in
/// `[0, horizon]`, like the certificate's. The exact certificate stays the final judge.
fn max_collision_free_step(
    uv: &[Point2<f64>],
    dir: &[f64],
    boundary: &[VertexId],
    horizon: f64,
) -> f64 {
    let m = boundary.len();
    if m < 4 || horizon.is_nan() || horizon <= 0.0 {
        return horizon;
    }
    let pos = |i: usize| uv[boundary[i % m].idx()];
    let vel = |i: usize| {
        let v = boundary[i % m].idx();
        Vector2::new(dir[2 * v], dir[2 * v + 1])
    };
    // Items: 2i = vertex i, 2i + 1 = edge (i, i + 1); swept x-interval and y-interval.
    let mut items: Vec<(f64, f64, f64, f64, usize)> = Vec::with_capacity(2 * m);
    for i in 0..m {
        let (p, q) = (pos(i), pos(i) + vel(i) * horizon);
        items.push((
            p.x.min(q.x),
            p.x.max(q.x),
            p.y.min(q.y),
            p.y.max(q.y),
            2 * i,
        ));
    }
    for i in 0..m {
        let (x0, x1, y0, y1, _) = items[i];
        let (x2, x3, y2, y3, _) = items[(i + 1) % m];
        items.push((x0.min(x2), x1.max(x3), y0.min(y2), y1.max(y3), 2 * i + 1));
    }
    items.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let mut tmax = horizon;
    let mut active: Vec<usize> = Vec::new();
    let test = |vi: usize, ei: usize, tmax: &mut f64| {
        if vi == ei || vi == (ei + 1) % m {
            return;
        }
        let (p, a, b) = (pos(vi), pos(ei), pos(ei + 1));
        let (dp, da, db) = (vel(vi), vel(ei), vel(ei + 1));
        // orient(s) = (b − a + s(db − da)) × (p − a + s(dp − da)).
        let (e, de) = (b - a, db - da);
        let (w, dw) = (p - a, dp - da);
        let c0 = e.perp(&w);
        let c1 = e.perp(&dw) + de.perp(&w);
        let c2 = de.perp(&dw);
        for s in quadratic_roots(c2, c1, c0) {
            if s > 0.0 && s < horizon {
                let (es, ws) = (e + de * s, w + dw * s);
                let l2 = es.norm_squared();
                let u = if l2 > 0.0 { es.dot(&ws) / l2 } else { 0.5 };
                if (-1e-6..=1.0 + 1e-6).contains(&u) {
                    *tmax = tmax.min(s);
                }
            }
        }
    };
    for k in 0..items.len() {
        let (x0, _, y0, y1, id) = items[k];
        active.retain(|&j| items[j].1 >= x0);
        for &j in &active {
            let (_, _, yj0, yj1, jd) = items[j];
            if yj1 < y0 || yj0 > y1 || (id & 1) == (jd & 1) {
                continue;
            }
            let (v, e) = if id & 1 == 0 { (id, jd) } else { (jd, id) };
            test(v / 2, e / 2, &mut tmax);
        }
        active.push(k);
    }
    tmax
}

/// Real roots of `a t² + b t + c` (numerically stable form; a degenerate quadratic gives
/// its linear root).
fn quadratic_roots(a: f64, b: f64, c: f64) -> Vec<f64> {
    if a.abs() <= 1e-300 || (a.abs() * c.abs() <= 1e-24 * b * b && b != 0.0) {
        let mut r = Vec::new();
        if b != 0.0 {
            r.push(-c / b);
        }
        if a != 0.0 && b != 0.0 {
            r.push(-b / a);
        }
        return r;
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return Vec::new();
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    if q != 0.0 {
        vec![q / a, c / q]
    } else {
        let r = (-c / a).sqrt();
        vec![r, -r]
    }
}

/// Smallest positive root of `a t² + b t + c` (numerically stable form), if any.
fn smallest_positive_root(a: f64, b: f64, c: f64) -> Option<f64> {
    let mut best: Option<f64> = None;
    let mut take = |r: f64| {
        if r > 0.0 && r.is_finite() {
            best = Some(best.map_or(r, |x: f64| x.min(r)));
        }
    };
    if a.abs() <= 1e-300 || (a.abs() * c.abs() <= 1e-24 * b * b && b != 0.0) {
        if b != 0.0 {
            take(-c / b);
        }
        if a != 0.0 && b != 0.0 {
            take(-b / a); // the far root of a nearly linear quadratic
        }
        return best;
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    let q = -0.5 * (b + b.signum() * s);
    if q != 0.0 {
        take(q / a);
        take(c / q);
    } else {
        take((-c / a).sqrt());
    }
    best
}

fn min_double_area(uv: &[Point2<f64>], tris: &[[VertexId; 3]]) -> f64 {
    tris.iter()
        .map(|t| {
            let (a, b, c) = (uv[t[0].idx()], uv[t[1].idx()], uv[t[2].idx()]);
            (b - a).perp(&(c - a))
        })
        .fold(f64::INFINITY, f64::min)
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

/// Add a repair pair for every boundary vertex of `uv` that now penetrates another part of
/// the disk (and has none yet), and for the endpoints of crossing boundary edges that lie
/// on the inner side of the other edge. Returns whether any was added.
fn add_penetrations(uv: &[Point2<f64>], boundary: &[VertexId], prob: &mut Problem) -> bool {
    let delta = 1e-3 * prob.pen_margin;
    let m = boundary.len();
    let mut added = false;
    let inside = penetrating_vertices(uv, boundary, delta);
    for (e1, e2) in crossing_edges(uv, boundary) {
        // Crossings with a penetrating endpoint are repaired through that vertex below; the
        // rest are thin spikes crossing each other (no vertex inside the other's material).
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
                    && !prob.pen_pairs.contains(&pair)
                {
                    prob.pen_pairs.push(pair);
                    added = true;
                }
            }
        }
    }
    for k in inside {
        let p = boundary[k].idx();
        if prob.pen_pairs.iter().any(|q| q[0] == p) {
            continue;
        }
        if let Some(e) = edge_to_leave(uv, boundary, k) {
            let m = boundary.len();
            prob.pen_pairs
                .push([p, boundary[e].idx(), boundary[(e + 1) % m].idx()]);
            added = true;
        }
    }
    added
}

/// Minimise the symmetric Dirichlet energy of the certified map `uv0` of `disk` (free
/// boundary, projected Newton, boundary barrier, certified line search; see the module
/// docs). Returns the last accepted iterate, which passes `certify_bijective`, and the log.
/// Errors: `NotCertified` if `uv0` itself does not pass the certificate, `Solver` if the
/// sparse factorisation fails.
pub fn optimize_with_log(
    disk: &TriMesh,
    boundary: &[VertexId],
    uv0: &[Point2<f64>],
    options: &SdOptions,
) -> Result<(Vec<Point2<f64>>, SdLog), ParamError> {
    certify(disk, uv0, boundary)?;
    newton(disk, boundary, uv0, options, true, &OnceCell::new())
}

/// [`optimize_with_log`] without the global part: locally injective projected Newton (no
/// barrier, no collision bound, no certificate; triangles stay float-positive), with the
/// overlap-repair penalty when `options.repair_weight > 0` (see `SdOptions::repair_iters`;
/// then it stops once the map is certified). The result may still overlap itself.
/// Errors: `NotCertified` if a triangle of `uv0` is not float-positive.
pub fn optimize_locally_injective(
    disk: &TriMesh,
    boundary: &[VertexId],
    uv0: &[Point2<f64>],
    options: &SdOptions,
) -> Result<(Vec<Point2<f64>>, SdLog), ParamError> {
    newton(disk, boundary, uv0, options, false, &OnceCell::new())
}

/// Projected Newton on the symmetric Dirichlet energy. `certified`: the full method of the
/// module docs (barrier, collision bound, every iterate certified); otherwise only locally
/// injective (float-positive triangles via a finite energy; no barrier, no collision bound,
/// no certificate) — the LSCM repair of [`initial_map`], whose result is certified by the
/// caller before it is used.
fn newton(
    disk: &TriMesh,
    boundary: &[VertexId],
    uv0: &[Point2<f64>],
    options: &SdOptions,
    certified: bool,
    system: &OnceCell<VertexSystem>,
) -> Result<(Vec<Point2<f64>>, SdLog), ParamError> {
    let n = disk.n_vertices();
    let frames = triangle_frames(disk);
    let total_area: f64 = frames.iter().map(|f| f.area).sum();
    let mut log = SdLog::default();
    let mut uv = uv0.to_vec();
    if total_area <= 0.0 {
        log.energies.push(f64::INFINITY);
        log.min_double_area
            .push(min_double_area(&uv, &disk.triangles));
        return Ok((uv, log));
    }
    let mut prob = Problem {
        tris: &disk.triangles,
        frames,
        boundary,
        total_area,
        eps: if certified {
            options.barrier_distance * disk.mean_edge_length()
        } else {
            0.0
        },
        barrier_w: options.barrier_weight / disk.n_faces() as f64,
        pen_w: if certified {
            0.0
        } else {
            options.repair_weight / disk.n_faces() as f64
        },
        pen_margin: options.repair_margin * disk.mean_edge_length(),
        pen_pairs: Vec::new(),
    };
    let clock = std::time::Instant::now();
    let mut lap = {
        let mut last = clock;
        move || {
            let now = std::time::Instant::now();
            let dt = (now - last).as_secs_f64() * 1e3;
            last = now;
            dt
        }
    };
    let system = VertexSystem::get(system, disk).map_err(ParamError::Solver)?;
    let pat = &system.pattern;
    let dim = 2 * n;
    let mut llt = Llt::new(system);
    let mut shifted = vec![0.0; pat.nnz()];
    log.time_ms[0] += lap();
    let mut vals = vec![0.0; pat.nnz()];
    let mut grad = vec![0.0; dim];
    if prob.pen_w > 0.0 {
        add_penetrations(&uv, boundary, &mut prob);
    }
    let mut energy = prob.energy(&uv);
    if !certified && !energy.is_finite() {
        return Err(ParamError::NotCertified(
            "the start has a flipped or degenerate triangle".to_string(),
        ));
    }
    log.energies.push(energy);
    log.min_double_area
        .push(min_double_area(&uv, &disk.triangles));
    let mut converged = false;
    let mut abs_twist = false;
    let mut trial = uv.clone();
    let mut probe = uv.clone();
    let (mut fewest_crossings, mut stalled) = (usize::MAX, 0);
    while log.iterations < options.max_iters {
        lap();
        prob.assemble(&uv, pat, &mut grad, &mut vals, abs_twist)?;
        log.time_ms[1] += lap();
        // Regularise the projected Hessian (translations and, at an isometry, rotations are
        // in its null space); grow the shift until the Cholesky factorisation succeeds.
        let trace: f64 = (0..dim).map(|v| vals[pat.diag_slot(v)]).sum();
        let mean_diag = trace / dim as f64;
        let mut solve = |log: &mut SdLog| -> Result<Vec<f64>, ParamError> {
            let mut mu = 1e-8 * mean_diag;
            for _ in 0..8 {
                shifted.copy_from_slice(&vals);
                for d in 0..dim {
                    shifted[pat.diag_slot(d)] += mu;
                }
                log.factorizations += 1;
                let mut sol = Mat::<f64>::zeros(dim, 1);
                for i in 0..dim {
                    sol[(i, 0)] = -grad[i];
                }
                if llt.solve(&shifted, &mut sol).is_ok() {
                    return Ok((0..dim).map(|i| sol[(i, 0)]).collect());
                }
                mu *= 100.0;
            }
            Err(ParamError::Solver(
                "Newton Hessian is not positive definite".to_string(),
            ))
        };
        let dir = solve(&mut log)?;
        let slope: f64 = dir.iter().zip(&grad).map(|(d, g)| d * g).sum();
        log.time_ms[2] += lap();
        // NaN-safe: a NaN slope also means no usable descent direction.
        if slope.is_nan() || slope >= 0.0 {
            converged = true; // no descent direction left
            break;
        }
        let t_flip = prob.max_flip_free_step(&uv, &dir);
        // Boundary-collision bound over the steps the first trial can reach (the
        // extrapolation beyond it is judged by the certificate alone).
        let horizon = t_flip.min(1.0 / options.step_fraction.max(f64::MIN_POSITIVE));
        let mut t_coll = horizon;
        // Not in the overlap repair: resolving an overlap moves vertices across edges.
        if options.collision_bound && certified {
            t_coll = max_collision_free_step(&uv, &dir, boundary, horizon);
            log.time_ms[2] += lap();
        }
        let t_safe = options.step_fraction * t_flip;
        if t_coll < horizon {
            log.collision_limited += 1;
        }
        let mut t = (options.step_fraction * t_coll).min(1.0);
        let mut accepted = None;
        for _ in 0..40 {
            for v in 0..n {
                trial[v] = Point2::new(uv[v].x + t * dir[2 * v], uv[v].y + t * dir[2 * v + 1]);
            }
            let e = prob.energy(&trial);
            if e <= energy + options.armijo * t * slope {
                if !certified || recertify(disk, &trial, boundary).is_ok() {
                    accepted = Some(e);
                    break;
                }
                log.certificate_rejections += 1;
            } else {
                log.armijo_rejections += 1;
            }
            t *= 0.5;
        }
        // Extrapolation: far from the optimum the energy is dominated by compressed triangles
        // (E ≈ J⁻²), where a full Newton step only grows J by 4/3; while the full step was
        // taken and the flip-free bound allows more, keep doubling as long as the energy drops.
        if let (Some(mut e_best), true) = (accepted, t == 1.0) {
            let mut t_try = 2.0;
            while t_try <= t_safe && t_try <= 1024.0 {
                for v in 0..n {
                    probe[v] = Point2::new(
                        uv[v].x + t_try * dir[2 * v],
                        uv[v].y + t_try * dir[2 * v + 1],
                    );
                }
                let e = prob.energy(&probe);
                if e.is_nan()
                    || e >= e_best
                    || (certified && recertify(disk, &probe, boundary).is_err())
                {
                    break;
                }
                e_best = e;
                t = t_try;
                std::mem::swap(&mut trial, &mut probe);
                t_try *= 2.0;
            }
            accepted = Some(e_best);
        }
        log.time_ms[3] += lap();
        let Some(e_new) = accepted else {
            // No certified decrease along the Newton direction: keep the last certified
            // iterate. If the direction still promised a real decrease, report a fallback.
            log.fell_back = -slope > options.rel_tol * (energy - 4.0).max(0.0);
            converged = !log.fell_back;
            break;
        };
        std::mem::swap(&mut uv, &mut trial);
        log.iterations += 1;
        // Trust-region-like switch (Chen et al. 2024): a truncated step means the quadratic
        // model was not trusted, so filter the twist by its absolute value next time; a full
        // (or extrapolated) step means the model is good, so clamp (faster near the optimum).
        abs_twist = options.abs_twist && t < 1.0;
        log.steps.push(t);
        log.flip_free_steps.push(t_flip);
        log.decrements.push(-slope);
        log.energies.push(e_new);
        log.min_double_area
            .push(min_double_area(&uv, &disk.triangles));
        // Relative decrease of the excess over the isometric lower bound 4 (σ² + σ⁻² ≥ 2):
        // relative to E itself the constant 4 would stop developable patches early.
        let rel = (energy - e_new) / (energy - 4.0).max(f64::MIN_POSITIVE);
        energy = e_new;
        if !certified && prob.pen_w > 0.0 {
            // Overlap repair: done once the map is certified with every repaired vertex at
            // least half the clearance outside; else add the newly penetrating vertices.
            let clear = prob.pen_pairs.iter().all(|&[p, a, b]| {
                signed_gap(&uv, p, a, b)
                    .is_none_or(|(sd, _)| sd <= -options.repair_clearance * prob.pen_margin)
            });
            if clear && recertify(disk, &uv, boundary).is_ok() {
                converged = true;
                break;
            }
            // Give up early when the number of crossing boundary edges stops falling: the
            // caller then starts from the Tutte map, and every repair step is time lost.
            let crossings = crossing_edges(&uv, boundary).len();
            if crossings < fewest_crossings {
                fewest_crossings = crossings;
                stalled = 0;
            } else {
                stalled += 1;
                if stalled >= REPAIR_PATIENCE {
                    break;
                }
            }
            if add_penetrations(&uv, boundary, &mut prob) {
                energy = prob.energy(&uv);
                continue;
            }
        }
        if rel < options.rel_tol {
            converged = true;
            break;
        }
    }
    log.hit_budget = !converged && !log.fell_back && log.iterations >= options.max_iters;
    Ok((uv, log))
}

/// Which initial map [`initial_map`] chose.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum InitialMap {
    /// The free-boundary LSCM passed the certificate.
    Lscm,
    /// The overlapping LSCM after the overlap repair (`repair_iters`: locally injective
    /// symmetric Dirichlet steps with a penetration penalty) passed the certificate.
    RepairedLscm,
    /// Tutte map onto a circle (the certified fallback).
    CircleTutte,
}

/// The certified initial map of [`SymmetricDirichlet`], scaled to the 3D area: the LSCM if
/// it passes the exact certificate; else (`repair_iters > 0`) the repaired LSCM if it
/// passes; else the circle Tutte map (`init_weights`, then uniform).
pub fn initial_map(
    disk: &TriMesh,
    boundary: &[VertexId],
    options: &SdOptions,
) -> Result<(Vec<Point2<f64>>, InitialMap), ParamError> {
    initial_map_with(
        disk,
        boundary,
        options,
        &OnceCell::new(),
        &mut SdProfile::default(),
    )
}

/// [`initial_map`] with the linear system shared with the optimisation that follows; fills
/// the start-up part of `prof`.
fn initial_map_with(
    disk: &TriMesh,
    boundary: &[VertexId],
    options: &SdOptions,
    system: &OnceCell<VertexSystem>,
    prof: &mut SdProfile,
) -> Result<(Vec<Point2<f64>>, InitialMap), ParamError> {
    let clock = std::time::Instant::now();
    let ms = |c: std::time::Instant| c.elapsed().as_secs_f64() * 1e3;
    if options.free_boundary_init {
        let lscm = VertexSystem::get(system, disk)
            .map_err(ParamError::Solver)
            .and_then(|s| lscm_on(disk, boundary, s));
        if let Ok(mut uv) = lscm {
            scale_to_area(disk, &mut uv);
            let lscm_ok = certify(disk, &uv, boundary).is_ok();
            prof.lscm_ms = ms(clock);
            if lscm_ok {
                return Ok((uv, InitialMap::Lscm));
            }
            if options.repair_iters > 0 {
                let clock = std::time::Instant::now();
                let o = SdOptions {
                    max_iters: options.repair_iters,
                    ..*options
                };
                let repaired = newton(disk, boundary, &uv, &o, false, system);
                let mut out = None;
                if let Ok((mut r, log)) = repaired {
                    prof.repair = Some(log);
                    scale_to_area(disk, &mut r);
                    if certify(disk, &r, boundary).is_ok() {
                        out = Some(r);
                    }
                }
                prof.repair_ms = ms(clock);
                if let Some(r) = out {
                    return Ok((r, InitialMap::RepairedLscm));
                }
            }
        }
    }
    Ok((
        certified_tutte(disk, boundary, options.init_weights)?.0,
        InitialMap::CircleTutte,
    ))
}

impl Parameterizer for SymmetricDirichlet {
    fn name(&self) -> &'static str {
        "sd"
    }

    fn parameterize(
        &self,
        disk: &TriMesh,
        boundary: &[VertexId],
    ) -> Result<Parameterization, ParamError> {
        self.parameterize_profiled(disk, boundary).map(|r| r.0)
    }
}

/// Where the time of one [`SymmetricDirichlet::parameterize_profiled`] call went.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SdProfile {
    /// The initial map chosen.
    pub init: Option<InitialMap>,
    /// Newton setup, LSCM and its certificate, ms.
    pub lscm_ms: f64,
    /// Overlap repair and the certificate of its result, ms (0 when not run).
    pub repair_ms: f64,
    /// Log of the overlap repair, when it ran.
    pub repair: Option<SdLog>,
    /// Whole initial map (including any Tutte fallback), ms.
    pub init_ms: f64,
    /// Log of the certified Newton optimisation.
    pub newton: SdLog,
    /// Certified Newton optimisation, ms.
    pub newton_ms: f64,
}

impl SymmetricDirichlet {
    /// [`Parameterizer::parameterize`], also returning where the time went.
    pub fn parameterize_profiled(
        &self,
        disk: &TriMesh,
        boundary: &[VertexId],
    ) -> Result<(Parameterization, SdProfile), ParamError> {
        validate_disk(disk, boundary)?;
        let mut prof = SdProfile::default();
        let clock = std::time::Instant::now();
        let system = OnceCell::new();
        let (uv0, kind) = initial_map_with(disk, boundary, &self.options, &system, &mut prof)?;
        prof.init = Some(kind);
        prof.init_ms = clock.elapsed().as_secs_f64() * 1e3;
        let clock = std::time::Instant::now();
        // If the optimiser cannot run at all (e.g. a certified Tutte triangle too thin for a
        // finite float energy, or a failed factorisation), the certified Tutte map is returned.
        // `initial_map_with` certified `uv0`.
        let (mut uv, log) = match newton(disk, boundary, &uv0, &self.options, true, &system) {
            Ok(r) => r,
            Err(_) => (
                uv0,
                SdLog {
                    fell_back: true,
                    ..Default::default()
                },
            ),
        };
        prof.newton_ms = clock.elapsed().as_secs_f64() * 1e3;
        let mut fell_back = log.fell_back;
        // Isometric in the mean: rescale so the 2D area equals the 3D area; a uniform scale
        // keeps orientations in exact arithmetic, and the certificate is re-checked.
        let unscaled = uv.clone();
        scale_to_area(disk, &mut uv);
        if certify(disk, &uv, boundary).is_err() {
            uv = unscaled;
            fell_back = true;
        }
        let mut report = distortion(disk, &uv);
        report.iterations = log.iterations;
        report.hit_budget = log.hit_budget;
        report.fell_back = fell_back;
        prof.newton = log;
        Ok((Parameterization { uv, report }, prof))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, SymmetricEigen};

    fn energy_of(f: &Matrix2<f64>) -> f64 {
        sd_in_f(f, false, false).map_or(f64::INFINITY, |x| x.0)
    }

    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let f = Matrix2::new(1.3, 0.4, -0.2, 0.7);
        let (_, g, _) = sd_in_f(&f, true, false).unwrap();
        let h = 1e-6;
        for k in 0..4 {
            let mut fp = f;
            let mut fm = f;
            fp[(k / 2, k % 2)] += h;
            fm[(k / 2, k % 2)] -= h;
            let fd = (energy_of(&fp) - energy_of(&fm)) / (2.0 * h);
            assert!(
                (fd - g[k]).abs() < 1e-6 * (1.0 + g[k].abs()),
                "{k}: {fd} {}",
                g[k]
            );
        }
        // Unprojected Hessian (twist ≥ 0 here) against differences of the gradient.
        let f = Matrix2::new(1.5, 0.1, 0.05, 1.4);
        let (_, _, hs) = sd_in_f(&f, true, false).unwrap();
        for k in 0..4 {
            let mut fp = f;
            let mut fm = f;
            fp[(k / 2, k % 2)] += h;
            fm[(k / 2, k % 2)] -= h;
            let gp = sd_in_f(&fp, false, false).unwrap().1;
            let gm = sd_in_f(&fm, false, false).unwrap().1;
            for r in 0..4 {
                let fd = (gp[r] - gm[r]) / (2.0 * h);
                assert!(
                    (fd - hs[(r, k)]).abs() < 1e-5,
                    "{r},{k}: {fd} {}",
                    hs[(r, k)]
                );
            }
        }
    }

    #[test]
    fn analytic_projection_equals_eigenvalue_clamping() {
        for f in [
            Matrix2::new(0.3, 0.1, -0.05, 0.2),
            Matrix2::new(0.8, -0.3, 0.4, 0.5),
            Matrix2::new(2.0, 0.0, 0.0, 0.1),
            Matrix2::new(1.0, 0.0, 0.0, 1.0),
        ] {
            let (_, _, hp) = sd_in_f(&f, true, false).unwrap();
            // Rebuild the raw Hessian: undo the projection by clamping eigenvalues ourselves.
            let eig = SymmetricEigen::new(hp);
            assert!(
                eig.eigenvalues.iter().all(|&l| l > -1e-9),
                "{:?}",
                eig.eigenvalues
            );
            // The projection only changes the negative part: hp − h_raw is PSD of rank ≤ 1
            // and hp equals the clamped eigen-decomposition of h_raw.
            let j = f.determinant();
            let n = f.norm_squared();
            let twist = 2.0 - 2.0 * (n - j) / (j * j * j);
            let (cs, sn) = (f[(0, 0)] + f[(1, 1)], f[(1, 0)] - f[(0, 1)]);
            let r = cs.hypot(sn);
            let q = Vector4::new(-sn / r, -cs / r, cs / r, -sn / r) / 2f64.sqrt();
            let raw = if twist < 0.0 {
                hp - q * q.transpose() * (-twist)
            } else {
                hp
            };
            // q is an eigenvector of the raw Hessian with eigenvalue `twist`.
            let hq = raw * q;
            assert!((hq - q * twist).norm() < 1e-8 * (1.0 + twist.abs()), "{f}");
            let e = SymmetricEigen::new(raw);
            let clamped = e.eigenvectors
                * Matrix4::from_diagonal(&e.eigenvalues.map(|l| l.max(0.0)))
                * e.eigenvectors.transpose();
            assert!((clamped - hp).norm() < 1e-8 * hp.norm(), "{f}");
        }
    }

    #[test]
    fn collision_bound_stops_a_vertex_at_the_opposite_edge() {
        // Boundary square 0..4 plus vertex 4 on the bottom edge's midline, moving up.
        // Loop (0,0) (2,0) (2,2) (1,1.5) (0,2): vertex 3 at (1, 1.5) moving down by 2 per
        // unit step reaches the bottom edge (0,0)-(2,0) at t = 0.75.
        let uv = [
            Point2::new(0.0, 0.0),
            Point2::new(2.0, 0.0),
            Point2::new(2.0, 2.0),
            Point2::new(1.0, 1.5),
            Point2::new(0.0, 2.0),
        ];
        let boundary: Vec<VertexId> = (0..5).map(VertexId::new).collect();
        let mut dir = vec![0.0; 10];
        dir[7] = -2.0;
        let t = max_collision_free_step(&uv, &dir, &boundary, 10.0);
        assert!((t - 0.75).abs() < 1e-12, "{t}");
        // Moving sideways instead, it never meets a non-incident edge within the horizon.
        dir[7] = 0.0;
        dir[6] = 0.1;
        assert_eq!(max_collision_free_step(&uv, &dir, &boundary, 1.0), 1.0);
        // A vertex passing beside an edge's line but outside the segment is not a collision.
        dir[6] = 0.0;
        dir[7] = 0.0;
        dir[0] = -1.0; // v0 moves left along the x axis: the line of edge (1,2) is x = 2
        assert_eq!(max_collision_free_step(&uv, &dir, &boundary, 5.0), 5.0);
    }

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
    }

    #[test]
    fn quadratic_roots() {
        assert_eq!(smallest_positive_root(1.0, -3.0, 2.0), Some(1.0));
        assert_eq!(smallest_positive_root(0.0, -2.0, 1.0), Some(0.5));
        assert_eq!(smallest_positive_root(1.0, 0.0, 1.0), None);
        assert_eq!(smallest_positive_root(1.0, 3.0, 2.0), None);
    }
}
