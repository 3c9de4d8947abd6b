//! The size controls MMG users expect (ours; the paper has none): bounds on the metric's edge
//! sizes (`hmin`, `hmax`) and a gradation (`hgrad`) that keeps the anisotropy's directions.
//!
//! An edge of metric length L_tar along the unit tangent `d` has length `h = L_tar/√(dᵀMd)`.
//! `hmin`/`hmax` clamp the sizes of the principal directions on the tangent plane:
//! `λ ← clamp(λ, L_tar²/hmax², L_tar²/hmin²)`. The gradation bounds how fast sizes grow from
//! vertex to vertex: along an edge `pq` of metric length `ℓ` (in `M_q`), `M_p` is raised so
//! that sizes at `p` are at most `(1 + ℓ·ln β)` times those at `q` (Alauzet 2010, "Size
//! gradation control of anisotropic meshes"), in `M_p`'s own principal directions
//! (`λ_i ← max(λ_i, η²·e_iᵀ M_q e_i)`, `η = 1/(1 + ℓ ln β)`), so every tensor keeps its
//! directions and only its sizes shrink; passes over the edges repeat until nothing changes.

use crate::mesh::TriMesh;
use crate::option_error::OptionError;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use serde::Serialize;

/// Bounds and gradation of the metric's sizes (all off by default).
#[derive(Copy, Clone, Debug, Default, PartialEq, Serialize)]
pub struct SizeOptions {
    /// Smallest edge size, in the input's units (MMG's `-hmin`). Default none.
    pub hmin: Option<f64>,
    /// Largest edge size, in the input's units (MMG's `-hmax`). Default none.
    pub hmax: Option<f64>,
    /// Largest size ratio between neighbouring vertices per unit of metric length, β > 1
    /// (MMG's `-hgrad`; 1.3 is MMG's default when on). Default none (no gradation).
    pub hgrad: Option<f64>,
}

impl SizeOptions {
    /// True when any control is on.
    pub fn any(&self) -> bool {
        self.hmin.is_some() || self.hmax.is_some() || self.hgrad.is_some()
    }

    /// Errors for values no run can use, naming the option.
    pub fn validate(&self) -> Result<(), OptionError> {
        let pos = |x: f64| x.is_finite() && x > 0.0;
        let size = |option, value| OptionError::OutOfRange {
            option,
            value,
            range: "a positive size",
        };
        if let Some(h) = self.hmin.filter(|h| !pos(*h)) {
            return Err(size("hmin", h));
        }
        if let Some(h) = self.hmax.filter(|h| !pos(*h)) {
            return Err(size("hmax", h));
        }
        if let (Some(a), Some(b)) = (self.hmin, self.hmax) {
            if a > b {
                return Err(OptionError::Crossed {
                    low: "hmin",
                    low_value: a,
                    high: "hmax",
                    high_value: b,
                });
            }
        }
        if let Some(g) = self.hgrad.filter(|g| !(g.is_finite() && *g > 1.0)) {
            return Err(OptionError::OutOfRange {
                option: "hgrad",
                value: g,
                range: "a number above 1",
            });
        }
        Ok(())
    }
}

/// Passes over the edges of the gradation, at most.
const MAX_GRADATION_PASSES: usize = 64;

/// The metric of `mesh` (one tensor per vertex, in the mesh's units) with the sizes of
/// `opts` applied at target length `l_tar`; `scale` converts the options' sizes (input units)
/// to the mesh's units. Tensors keep their directions; only their eigenvalues change.
pub fn apply_sizes(
    mesh: &TriMesh,
    metrics: &[Matrix3<f64>],
    l_tar: f64,
    scale: f64,
    opts: &SizeOptions,
) -> Vec<Matrix3<f64>> {
    let lo = opts.hmax.map(|h| (l_tar / (h * scale)).powi(2));
    let hi = opts.hmin.map(|h| (l_tar / (h * scale)).powi(2));
    let normals = mesh.vertex_normals();
    let mut out: Vec<Matrix3<f64>> = metrics
        .iter()
        .zip(&normals)
        .map(|(m, n)| clamp_tangent(m, n, lo, hi))
        .collect();
    if let Some(beta) = opts.hgrad {
        grade(mesh, &mut out, beta.ln());
    }
    out
}

/// `m` with the eigenvalues of its tangent directions (those not along `n`) clamped to
/// `[lo, hi]`; the normal eigenvalue is left as it is.
fn clamp_tangent(
    m: &Matrix3<f64>,
    n: &Vector3<f64>,
    lo: Option<f64>,
    hi: Option<f64>,
) -> Matrix3<f64> {
    let e = SymmetricEigen::new((m + m.transpose()) * 0.5);
    // The eigenvector most aligned with the normal is the normal one.
    let k = (0..3)
        .max_by(|&i, &j| {
            let a = e.eigenvectors.column(i).dot(n).abs();
            let b = e.eigenvectors.column(j).dot(n).abs();
            a.total_cmp(&b)
        })
        .unwrap_or(2);
    let vals = Vector3::from_fn(|i, _| {
        let l = e.eigenvalues[i];
        if i == k {
            l
        } else {
            let l = lo.map_or(l, |lo| l.max(lo));
            hi.map_or(l, |hi| l.min(hi))
        }
    });
    let r = e.eigenvectors * Matrix3::from_diagonal(&vals) * e.eigenvectors.transpose();
    (r + r.transpose()) * 0.5
}

/// The gradation of the module docs, in place, over the mesh's edges.
fn grade(mesh: &TriMesh, metrics: &mut [Matrix3<f64>], ln_beta: f64) {
    let topo = crate::mesh::Topology::build(mesh);
    let edges = topo.edges();
    for _ in 0..MAX_GRADATION_PASSES {
        let mut changed = false;
        for e in edges {
            let (a, b) = (e.0.idx(), e.1.idx());
            let d = mesh.positions[b] - mesh.positions[a];
            for (p, q) in [(a, b), (b, a)] {
                let mq = metrics[q];
                let l = d.dot(&(mq * d)).max(0.0).sqrt();
                let eta2 = (1.0 / (1.0 + l * ln_beta)).powi(2);
                if let Some(m) = raised(&metrics[p], &mq, eta2) {
                    metrics[p] = m;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
}

/// `M_p` with each eigenvalue raised to `η²·e_iᵀ M_q e_i` along its own eigenvector `e_i`
/// where that is larger (by more than a relative 1e-9, so the passes end); `None` when none is.
fn raised(mp: &Matrix3<f64>, mq: &Matrix3<f64>, eta2: f64) -> Option<Matrix3<f64>> {
    let e = SymmetricEigen::new((mp + mp.transpose()) * 0.5);
    let mut vals = e.eigenvalues;
    let mut changed = false;
    for i in 0..3 {
        let v = e.eigenvectors.column(i);
        let want = eta2 * v.dot(&(mq * v));
        if want > vals[i] * (1.0 + 1e-9) && want > 0.0 {
            vals[i] = want;
            changed = true;
        }
    }
    changed.then(|| {
        let r = e.eigenvectors * Matrix3::from_diagonal(&vals) * e.eigenvectors.transpose();
        (r + r.transpose()) * 0.5
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    /// A strip of 10 unit squares along x in the plane z = 0.
    fn strip() -> TriMesh {
        let mut pos = Vec::new();
        for i in 0..=10 {
            pos.push(Point3::new(i as f64, 0.0, 0.0));
            pos.push(Point3::new(i as f64, 1.0, 0.0));
        }
        let tris: Vec<[usize; 3]> = (0..10)
            .flat_map(|i| [[2 * i, 2 * i + 2, 2 * i + 3], [2 * i, 2 * i + 3, 2 * i + 1]])
            .collect();
        TriMesh::from_indices(pos, &tris).expect("strip")
    }

    fn size_along(m: &Matrix3<f64>, d: Vector3<f64>, l_tar: f64) -> f64 {
        l_tar / d.dot(&(m * d)).sqrt()
    }

    #[test]
    fn bounds_clamp_the_tangent_sizes_and_keep_directions() {
        let m = strip();
        // Sizes 0.01 along x, 10 along y; normal eigenvalue 0.
        let t = Matrix3::from_diagonal(&Vector3::new(1e4, 1e-2, 0.0));
        let metrics = vec![t; m.n_vertices()];
        let o = SizeOptions {
            hmin: Some(0.1),
            hmax: Some(2.0),
            hgrad: None,
        };
        let out = apply_sizes(&m, &metrics, 1.0, 1.0, &o);
        for x in &out {
            assert!((size_along(x, Vector3::x(), 1.0) - 0.1).abs() < 1e-12);
            assert!((size_along(x, Vector3::y(), 1.0) - 2.0).abs() < 1e-12);
            assert!(x[(2, 2)].abs() < 1e-12, "the normal part stays 0");
            assert!(x[(0, 1)].abs() < 1e-12, "directions kept");
        }
        // In input units twice as large as the mesh's (scale 0.5): the sizes halve.
        let out = apply_sizes(&m, &metrics, 1.0, 0.5, &o);
        assert!((size_along(&out[0], Vector3::x(), 1.0) - 0.05).abs() < 1e-12);
        assert!(o.validate().is_ok());
        let refused = |o: SizeOptions| o.validate().expect_err("refused");
        assert!(matches!(
            refused(SizeOptions {
                hmin: Some(3.0),
                ..o
            }),
            OptionError::Crossed { low: "hmin", low_value, high_value, .. }
                if low_value == 3.0 && high_value == 2.0
        ));
        assert!(matches!(
            refused(SizeOptions {
                hgrad: Some(1.0),
                ..o
            }),
            OptionError::OutOfRange {
                option: "hgrad",
                ..
            }
        ));
        assert!(matches!(
            refused(SizeOptions {
                hmax: Some(f64::NAN),
                ..o
            }),
            OptionError::OutOfRange { option: "hmax", .. }
        ));
    }

    #[test]
    fn gradation_bounds_the_growth_of_sizes_and_keeps_directions() {
        let m = strip();
        // Size 0.1 at the left end (x = 0), 5 elsewhere, isotropic in the plane.
        let metrics: Vec<Matrix3<f64>> = m
            .positions
            .iter()
            .map(|p| {
                let h: f64 = if p.x == 0.0 { 0.1 } else { 5.0 };
                Matrix3::from_diagonal(&Vector3::new(1.0 / (h * h), 1.0 / (h * h), 0.0))
            })
            .collect();
        let beta = 1.5f64;
        let o = SizeOptions {
            hgrad: Some(beta),
            ..SizeOptions::default()
        };
        let out = apply_sizes(&m, &metrics, 1.0, 1.0, &o);
        // Sizes now grow along x, none above the original, none shrunk at the fine end.
        let h: Vec<f64> = (0..=10)
            .map(|i| size_along(&out[2 * i], Vector3::x(), 1.0))
            .collect();
        assert!((h[0] - 0.1).abs() < 1e-12);
        assert!(h.windows(2).all(|w| w[1] >= w[0] - 1e-12), "{h:?}");
        assert!(h[1] < 1.0 && h[10] <= 5.0 + 1e-12, "{h:?}");
        // Along every edge pq: size(p) ≤ size(q)·(1 + ℓ_q ln β) (up to the pass tolerance).
        for i in 0..10 {
            let (p, q) = (2 * i + 2, 2 * i);
            let d = m.positions[p] - m.positions[q];
            let l = d.dot(&(out[q] * d)).sqrt();
            let bound = size_along(&out[q], Vector3::x(), 1.0) * (1.0 + l * beta.ln());
            assert!(size_along(&out[p], Vector3::x(), 1.0) <= bound * (1.0 + 1e-6));
        }
        for x in &out {
            assert!(x[(0, 1)].abs() < 1e-9 && x[(2, 2)].abs() < 1e-9);
        }
    }
}
