//! Vertex position optimisation (LCT step 3): Newton on the 1-ring energy, and the polish.

use super::work::{tri_energy, Work};
use super::{eval, LctOptions};
use crate::predicates::{orient2d, Sign};
use crate::remesh2d::Remesh2dError;
use nalgebra::{Matrix2, Point2, Vector2};
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;

impl Work<'_> {
    /// Vertex position optimisation: every free vertex, in a seeded random order, moves to
    /// the minimiser of its 1-ring energy `Σ_T E_T(x)` (tensors frozen at the current
    /// positions): Newton steps on the cubic `E_T = A_T(x)·S_T(x)/8`, with the positive
    /// "frozen area" Hessian `Σ 4 A_T M̄_T` when the true one is not positive definite; each
    /// step halves until the energy decreases and every 1-ring triangle is positive (exact).
    pub(super) fn smooth_pass(
        &mut self,
        options: &LctOptions,
        apex: bool,
        rng: &mut ChaCha8Rng,
    ) -> Result<(), Remesh2dError> {
        let mut order: Vec<u32> = (0..self.pts.len() as u32)
            .filter(|&v| self.valive[v as usize] && !self.fixed[v as usize])
            .collect();
        order.shuffle(rng);
        let (start, incident) = self.vertex_triangles();
        for v in order {
            let star = &incident[start[v as usize] as usize..start[v as usize + 1] as usize];
            if star.len() < 3 {
                continue;
            }
            let ring: Vec<[u32; 3]> = star.iter().map(|&t| self.rotated(t, v)).collect();
            let tens: Vec<Tensor> = ring
                .iter()
                .map(|t| {
                    (
                        self.pts[t[1] as usize],
                        self.pts[t[2] as usize],
                        self.tri_metric(*t),
                    )
                })
                .collect();
            let x0 = self.pts[v as usize];
            let x = match apex {
                true => apex_start(&tens, x0),
                false => newton(&tens, x0, options.newton_steps),
            };
            if x != x0 {
                self.pts[v as usize] = x;
                self.vm[v as usize] = eval(self.metric, &x)?;
                self.origin[v as usize] = None;
            }
        }
        Ok(())
    }

    /// Vertex → alive triangles as offsets and a flat list (CSR), once per pass (smoothing
    /// does not change the connectivity). A free vertex is interior, so its star is closed;
    /// order does not matter to the pass.
    fn vertex_triangles(&self) -> (Vec<u32>, Vec<u32>) {
        let n = self.pts.len();
        let mut start = vec![0u32; n + 1];
        for (i, t) in self.tris.iter().enumerate() {
            if self.alive[i] {
                for &x in t {
                    start[x as usize + 1] += 1;
                }
            }
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut incident = vec![0u32; start[n] as usize];
        for (i, t) in self.tris.iter().enumerate() {
            if self.alive[i] {
                for &x in t {
                    incident[fill[x as usize] as usize] = i as u32;
                    fill[x as usize] += 1;
                }
            }
        }
        (start, incident)
    }
}

/// A 1-ring triangle `(x, p, q)` of the moving vertex `x`: `p`, `q` and its tensor.
type Tensor = (Point2<f64>, Point2<f64>, Matrix2<f64>);

/// The 1-ring energy `Σ_T E_T(x)`.
fn ring_energy(tens: &[Tensor], x: &Point2<f64>) -> f64 {
    tens.iter()
        .map(|(p, q, m)| tri_energy([*x, *p, *q], m))
        .sum()
}

/// The polish's move: towards [`apex_target`], halved until every 1-ring triangle is
/// positive (exact); `x0` when none is within 12 halvings.
fn apex_start(tens: &[Tensor], x0: Point2<f64>) -> Point2<f64> {
    let Some(xn) = apex_target(tens) else {
        return x0;
    };
    let step = xn - x0;
    let mut t = 1.0;
    for _ in 0..12 {
        let xn = x0 + step * t;
        if tens
            .iter()
            .all(|(p, q, _)| orient2d(&xn, p, q) == Sign::Positive)
        {
            return xn;
        }
        t *= 0.5;
    }
    x0
}

/// Up to `steps` Newton steps from `x` on the 1-ring energy, each halved until the energy
/// decreases and every 1-ring triangle stays positive (exact); stops at the first step that
/// finds no such point.
fn newton(tens: &[Tensor], mut x: Point2<f64>, steps: usize) -> Point2<f64> {
    let mut e = ring_energy(tens, &x);
    for _ in 0..steps {
        let mut g = Vector2::zeros();
        let mut h = Matrix2::zeros();
        let mut h0 = Matrix2::zeros();
        for (p, q, m) in tens {
            let area = 0.5 * (p - x).perp(&(q - x));
            let ga = 0.5 * Vector2::new(p.y - q.y, q.x - p.x);
            let (ep, eq) = (x - p, x - q);
            let s = ep.dot(&(m * ep)) + eq.dot(&(m * eq)) + (p - q).dot(&(m * (p - q)));
            let gs = 2.0 * m * (ep + eq);
            g += (area * gs + s * ga) / 8.0;
            h += (4.0 * area * m + ga * gs.transpose() + gs * ga.transpose()) / 8.0;
            h0 += 4.0 * area.abs() * m / 8.0;
        }
        let pd = h.determinant() > 0.0 && h.trace() > 0.0;
        let step = if pd { h.try_inverse() } else { None }
            .or_else(|| h0.try_inverse())
            .map(|hi| -(hi * g));
        let Some(step) = step else { break };
        if !step.iter().all(|s| s.is_finite()) {
            break;
        }
        let mut t = 1.0;
        let mut moved = false;
        for _ in 0..12 {
            let xn = x + step * t;
            let ok = tens
                .iter()
                .all(|(p, q, _)| orient2d(&xn, p, q) == Sign::Positive);
            if ok {
                let en = ring_energy(tens, &xn);
                if en < e {
                    x = xn;
                    e = en;
                    moved = true;
                    break;
                }
            }
            t *= 0.5;
        }
        if !moved {
            break;
        }
    }
    x
}

/// The mean over the 1-ring triangles `(x, p, q)` of the apex that makes each one equilateral
/// in its tensor: with `M = L Lᵀ` and `y = Lᵀ x`, the apex is
/// `y = (y_p + y_q)/2 + √3/2 · rot90(y_q − y_p)` mapped back.
fn apex_target(tens: &[Tensor]) -> Option<Point2<f64>> {
    let mut acc = Vector2::zeros();
    for (p, q, m) in tens {
        let l = m.cholesky()?.l();
        let lt = l.transpose();
        let lti = lt.try_inverse()?;
        let (yp, yq) = (lt * p.coords, lt * q.coords);
        let d = yq - yp;
        let y = (yp + yq) * 0.5 + Vector2::new(-d.y, d.x) * (3f64.sqrt() / 2.0);
        acc += lti * y;
    }
    let c = acc / tens.len() as f64;
    c.iter().all(|x| x.is_finite()).then(|| Point2::from(c))
}
