//! The objective the Newton iterations minimise over the map `uv` of one disk: the
//! area-weighted mean symmetric Dirichlet energy `Σ_t A_t E_t / Σ_t A_t` (triangles of zero
//! 3D area left out), plus the boundary barrier (certified optimisation) or the overlap
//! repair penalty (repair of the LSCM start); its gradient and projected Hessian.

use super::super::distortion::{jacobian, TriangleFrame};
use super::super::sparse::Pattern;
use super::barrier::BoundaryBarrier;
use super::energy::{self, TwistFilter};
use super::repair::RepairPenalty;
use crate::ids::{FaceId, VertexId};
use crate::param::ParamError;
use nalgebra::Point2;

/// The objective of one disk.
pub(super) struct Objective<'a> {
    pub(super) tris: &'a [[VertexId; 3]],
    pub(super) frames: Vec<TriangleFrame>,
    /// `Σ_t A_t` (positive).
    pub(super) total_area: f64,
    pub(super) barrier: BoundaryBarrier<'a>,
    pub(super) repair: Option<RepairPenalty<'a>>,
}

impl<'a> Objective<'a> {
    /// The disk's boundary loop.
    pub(super) fn boundary(&self) -> &'a [VertexId] {
        self.barrier.boundary
    }

    /// The objective at `uv`; ∞ if a triangle is flipped (float) or a boundary vertex
    /// touches a boundary edge.
    pub(super) fn energy(&self, uv: &[Point2<f64>]) -> f64 {
        let mut e = 0.0;
        for (t, fr) in self.tris.iter().zip(&self.frames) {
            if fr.area <= 0.0 {
                continue;
            }
            let f = jacobian(fr, [uv[t[0].idx()], uv[t[1].idx()], uv[t[2].idx()]]);
            match energy::energy(&f) {
                Some(et) => e += fr.area * et,
                None => return f64::INFINITY,
            }
        }
        e /= self.total_area;
        e = self.barrier.add_energy(uv, e);
        if e == f64::INFINITY {
            return e;
        }
        match &self.repair {
            Some(r) => r.add_energy(uv, e),
            None => e,
        }
    }

    /// Gradient (`grad`, dof `2v + c`) and projected Hessian (`vals`, in `pat` order) at
    /// `uv`. Errors when a triangle is flipped or a boundary vertex touches an edge.
    pub(super) fn assemble(
        &self,
        uv: &[Point2<f64>],
        pat: &Pattern,
        grad: &mut [f64],
        vals: &mut [f64],
        twist_filter: TwistFilter,
    ) -> Result<(), ParamError> {
        grad.iter_mut().for_each(|x| *x = 0.0);
        vals.iter_mut().for_each(|x| *x = 0.0);
        for (ti, (t, fr)) in self.tris.iter().zip(&self.frames).enumerate() {
            if fr.area <= 0.0 {
                continue;
            }
            let f = jacobian(fr, [uv[t[0].idx()], uv[t[1].idx()], uv[t[2].idx()]]);
            let (_, gf, hf) =
                energy::derivatives(&f, twist_filter).ok_or_else(|| ParamError::Flipped {
                    face: FaceId::new(ti),
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
        self.barrier.add_derivatives(uv, pat, grad, vals)?;
        if let Some(r) = &self.repair {
            r.add_derivatives(uv, pat, grad, vals);
        }
        Ok(())
    }
}
