//! The symmetric Dirichlet energy of one triangle (Smith & Schaefer 2015) as a function of
//! its Jacobian `F`: `E(F) = σ1² + σ2² + σ1⁻² + σ2⁻²`, which for a 2×2 matrix is
//! `‖F‖² (1 + det(F)⁻²)`; 4 at an isometry, ∞ on a flip.
//!
//! The 4×4 Hessian in `vec F` (row-major `a, b, c, d`) is projected to be positive
//! semi-definite analytically: for this isotropic energy only the twist eigenvalue
//! `(Ψ1 + Ψ2)/(σ1 + σ2) = 2 − 2(‖F‖² − J)/J³` can be negative (Smith, de Goes & Kim 2019),
//! and its eigenvector `vec(R90 · R)` (R the polar rotation of F) is known in closed form,
//! so no eigen-solver is needed.

use nalgebra::{Matrix2, Matrix4, Vector4};

/// What the projection does with a negative twist eigenvalue.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(super) enum TwistFilter {
    /// Clamp it to 0 (exact PSD projection; converges faster near the optimum).
    Clamp,
    /// Replace it by its absolute value (the "abs" filter of Chen et al. 2024: far from the
    /// optimum the clamped model over-trusts the twist direction).
    Abs,
}

/// `E(F)`; `None` when `det F ≤ 0` or is NaN (infinite energy).
#[inline]
pub(super) fn energy(f: &Matrix2<f64>) -> Option<f64> {
    let (a, b, c, d) = (f[(0, 0)], f[(0, 1)], f[(1, 0)], f[(1, 1)]);
    let j = a * d - b * c;
    if j.is_nan() || j <= 0.0 {
        return None;
    }
    let n = a * a + b * b + c * c + d * d;
    let ij2 = 1.0 / (j * j);
    Some(n * (1.0 + ij2))
}

/// `E(F)`, its gradient and its projected Hessian with respect to `vec(F)`; `None` when
/// `det F ≤ 0` or is NaN.
#[inline]
pub(super) fn derivatives(
    f: &Matrix2<f64>,
    twist_filter: TwistFilter,
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
    let twist = 2.0 - 2.0 * (n - j) * ij3;
    if twist < 0.0 {
        let (cs, sn) = (a + d, c - b);
        let r = cs.hypot(sn);
        if r > 0.0 {
            let (cs, sn) = (cs / r, sn / r);
            let q = Vector4::new(-sn, -cs, cs, -sn) * std::f64::consts::FRAC_1_SQRT_2;
            let lift = match twist_filter {
                TwistFilter::Abs => -2.0 * twist,
                TwistFilter::Clamp => -twist,
            };
            h += q * q.transpose() * lift;
        }
    }
    Some((e, grad, h))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SymmetricEigen;

    fn energy_of(f: &Matrix2<f64>) -> f64 {
        energy(f).unwrap_or(f64::INFINITY)
    }

    fn gradient_of(f: &Matrix2<f64>) -> Vector4<f64> {
        derivatives(f, TwistFilter::Clamp).unwrap().1
    }

    #[test]
    fn energy_is_four_at_an_isometry_and_infinite_on_a_flip() {
        let (c, s) = (0.6, 0.8);
        assert!((energy_of(&Matrix2::new(c, -s, s, c)) - 4.0).abs() < 1e-15);
        assert_eq!(energy(&Matrix2::new(1.0, 0.0, 0.0, -1.0)), None);
        assert_eq!(energy(&Matrix2::new(1.0, 2.0, 0.5, 1.0)), None);
        // The value agrees with the one `derivatives` returns.
        let f = Matrix2::new(1.3, 0.4, -0.2, 0.7);
        assert_eq!(energy(&f), derivatives(&f, TwistFilter::Abs).map(|x| x.0));
    }

    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let f = Matrix2::new(1.3, 0.4, -0.2, 0.7);
        let g = gradient_of(&f);
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
        let (_, _, hs) = derivatives(&f, TwistFilter::Clamp).unwrap();
        for k in 0..4 {
            let mut fp = f;
            let mut fm = f;
            fp[(k / 2, k % 2)] += h;
            fm[(k / 2, k % 2)] -= h;
            let (gp, gm) = (gradient_of(&fp), gradient_of(&fm));
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
            let (_, _, hp) = derivatives(&f, TwistFilter::Clamp).unwrap();
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
            // The absolute-value filter puts |twist| on the same eigenvector.
            let (_, _, ha) = derivatives(&f, TwistFilter::Abs).unwrap();
            assert!(
                (ha * q - q * twist.abs()).norm() < 1e-8 * (1.0 + twist.abs()),
                "{f}"
            );
        }
    }
}
