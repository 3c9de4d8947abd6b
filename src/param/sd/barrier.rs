//! The boundary barrier of ref. \[30\] (Su et al.): for every boundary vertex `p` and boundary
//! edge `ab` not incident to it, the triangle-inequality gap `d = |p−a| + |p−b| − |a−b|`
//! (zero exactly when `p` touches the edge) adds `w (ε/d − 1)²` while `d < ε`. Its Hessian
//! is the Gauss–Newton term on the 2×2 diagonal blocks only, so the sparsity pattern never
//! changes (and it stays PSD, so the Newton direction stays a descent direction).

use super::super::sparse::Pattern;
use super::ParamError;
use crate::ids::{EdgeKey, VertexId};
use nalgebra::{Point2, Vector2};

/// The barrier of one disk's boundary.
pub(super) struct BoundaryBarrier<'a> {
    /// The boundary loop.
    pub(super) boundary: &'a [VertexId],
    /// Activation distance `ε` on the gap (0: no term is ever active).
    pub(super) eps: f64,
    /// Weight `w` of one term.
    pub(super) weight: f64,
}

impl BoundaryBarrier<'_> {
    /// The active terms `(p, a, b, d)` (vertex indices, gap clamped at 0). Vertices are
    /// sorted by x; each edge looks up the x-range of its ellipse `{d < ε}`, whose
    /// half-width beyond the segment is at most `√(Lε + ε²)/2`.
    fn active_pairs(&self, uv: &[Point2<f64>]) -> Vec<(usize, usize, usize, f64)> {
        let (boundary, eps) = (self.boundary, self.eps);
        let m = boundary.len();
        let mut out = Vec::new();
        if m < 4 || eps <= 0.0 {
            return out;
        }
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

    /// `e` plus the barrier energy of `uv`; ∞ when a boundary vertex touches an edge.
    pub(super) fn add_energy(&self, uv: &[Point2<f64>], mut e: f64) -> f64 {
        for (_, _, _, d) in self.active_pairs(uv) {
            if d <= 0.0 {
                return f64::INFINITY;
            }
            e += self.weight * (self.eps / d - 1.0).powi(2);
        }
        e
    }

    /// Add the barrier's gradient to `grad` and its Gauss–Newton blocks to `vals`.
    pub(super) fn add_derivatives(
        &self,
        uv: &[Point2<f64>],
        pat: &Pattern,
        grad: &mut [f64],
        vals: &mut [f64],
    ) -> Result<(), ParamError> {
        for (p, a, b, d) in self.active_pairs(uv) {
            if d <= 0.0 {
                return Err(ParamError::BoundaryTouch {
                    vertex: VertexId::new(p),
                    edge: EdgeKey::new(VertexId::new(a), VertexId::new(b)),
                });
            }
            let r = self.eps / d;
            let d1 = self.weight * 2.0 * (r - 1.0) * (-r / d);
            let d2 = self.weight * (2.0 * r * r / (d * d) + 4.0 * r * (r - 1.0) / (d * d));
            for (v, gv) in gap_gradient(uv, p, a, b) {
                grad[2 * v] += d1 * gv.x;
                grad[2 * v + 1] += d1 * gv.y;
                pat.add_diag_outer(vals, v, d2, [gv.x, gv.y]);
            }
        }
        Ok(())
    }
}

/// Gradient of the gap `|p − a| + |p − b| − |a − b|` with respect to `p`, `a` and `b`.
fn gap_gradient(uv: &[Point2<f64>], p: usize, a: usize, b: usize) -> [(usize, Vector2<f64>); 3] {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::TriMesh;
    use crate::param::sparse::VertexSystem;

    #[test]
    fn barrier_sees_only_near_non_incident_pairs_and_its_gradient_is_exact() {
        // A unit square with a V notch from the top whose tip, vertex 3, is 0.05 above the
        // bottom edge (0, 1): the only pair within ε = 0.02 of gap.
        let mut uv = vec![
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(1.0, 1.0),
            Point2::new(0.5, 0.05),
            Point2::new(0.0, 1.0),
        ];
        let pos = uv
            .iter()
            .map(|p| nalgebra::Point3::new(p.x, p.y, 0.0))
            .collect();
        let disk = TriMesh::from_indices(pos, &[[0, 1, 3], [1, 2, 3], [0, 3, 4]]).unwrap();
        let boundary: Vec<VertexId> = (0..5).map(VertexId::new).collect();
        let bar = BoundaryBarrier {
            boundary: &boundary,
            eps: 0.02,
            weight: 1.0,
        };
        let pairs = bar.active_pairs(&uv);
        assert_eq!(pairs.len(), 1, "{pairs:?}");
        let (p, a, b, d) = pairs[0];
        assert_eq!((p, a, b), (3, 0, 1));
        assert!((d - (2.0 * 0.5f64.hypot(0.05) - 1.0)).abs() < 1e-14, "{d}");
        // The assembled gradient against central differences of the energy.
        let sys = VertexSystem::new(&disk).unwrap();
        let mut grad = vec![0.0; 10];
        let mut vals = vec![0.0; sys.pattern.nnz()];
        bar.add_derivatives(&uv, &sys.pattern, &mut grad, &mut vals)
            .unwrap();
        let (h, scale) = (1e-8, grad.iter().fold(0.0f64, |m, g| m.max(g.abs())));
        assert!(scale > 1.0, "{grad:?}");
        for v in 0..5 {
            for c in 0..2 {
                let x0 = uv[v][c];
                uv[v][c] = x0 + h;
                let ep = bar.add_energy(&uv, 0.0);
                uv[v][c] = x0 - h;
                let em = bar.add_energy(&uv, 0.0);
                uv[v][c] = x0;
                let fd = (ep - em) / (2.0 * h);
                let g = grad[2 * v + c];
                assert!((fd - g).abs() < 1e-7 * scale, "v{v} c{c}: {fd} {g}");
            }
        }
        // The Gauss–Newton blocks are PSD: non-negative diagonal entries.
        assert!((0..10).all(|d| vals[sys.pattern.diag_slot(d)] >= 0.0));
        // Touching is infinite energy.
        uv[3] = Point2::new(0.5, 0.0);
        assert_eq!(bar.add_energy(&uv, 0.0), f64::INFINITY);
    }
}
