//! Eq. 1-2: the best-fit cone of a set of faces.
//!
//! Minimise `F(n, c) = Σ A_t (⟨n, n_t⟩ − c)²` over unit `n` and `c = cos α`. For a fixed `n`,
//! `∂F/∂c = 0` gives `c = ⟨n, n̄⟩` with `n̄ = Σ A_t n_t / Σ A_t` (the area-weighted mean
//! normal). Substituting, `F(n) = nᵀ C n` with the area-weighted normal covariance
//! `C = Σ A_t (n_t − n̄)(n_t − n̄)ᵀ`, minimised over the unit sphere by the eigenvector of the
//! smallest eigenvalue of `C` (Rayleigh quotient). `F` is invariant under `(n, c) → (−n, −c)`;
//! we pick the sign with `c ≥ 0` (axis towards the mean normal), so `α ∈ [0, π/2]`.
//! Derivation in `paper-notes.md`, section 3.2.

use super::Cone;
use crate::ids::FaceId;
use crate::mesh::TriMesh;
use nalgebra::{Matrix3, Vector3};

/// The cone minimising the area-weighted Eq. 2 objective for unit `normals` with `weights`
/// (areas). Zero total weight or no normals gives the axis `+z` and angle 0.
pub fn fit_cone_normals(normals: &[Vector3<f64>], weights: &[f64]) -> Cone {
    let total: f64 = weights.iter().sum();
    if normals.is_empty() || total.is_nan() || total <= 0.0 {
        return Cone {
            axis: Vector3::z(),
            angle: 0.0,
        };
    }
    let mean: Vector3<f64> = normals
        .iter()
        .zip(weights)
        .map(|(n, w)| n * *w)
        .sum::<Vector3<f64>>()
        / total;
    let mut cov = Matrix3::zeros();
    for (n, w) in normals.iter().zip(weights) {
        let d = n - mean;
        cov += d * d.transpose() * *w;
    }
    let eig = cov.symmetric_eigen();
    // Smallest eigenvalue; ties broken by the lowest index, for determinism.
    let mut k = 0;
    for i in 1..3 {
        if eig.eigenvalues[i] < eig.eigenvalues[k] {
            k = i;
        }
    }
    // Degenerate minimisers, when eigenvalues tie with the smallest (float tolerance: this
    // picks among equally good minimisers, it decides no sign):
    // - three tied (all normals equal, a plane): every `n` is optimal; take the mean normal,
    //   so a plane is the cone with α = 0 around its normal;
    // - two tied (exactly two distinct normals, e.g. the 1-ring of a vertex on a
    //   triangulated cylinder or cone, whose quads are planar): every `n` with
    //   ⟨n, n₁⟩ = ⟨n, n₂⟩ is optimal; take the one orthogonal to the mean normal, `n₁ × n₂`:
    //   the cylinder whose axis is the shared ruling (α = 90°).
    let tie = eig.eigenvalues[k] + 1e-12 * total;
    let tied: Vec<Vector3<f64>> = (0..3)
        .filter(|&i| eig.eigenvalues[i] <= tie)
        .map(|i| eig.eigenvectors.column(i).into_owned())
        .collect();
    let mut axis: Vector3<f64> = match tied.len() {
        3 if mean.norm() > 1e-9 => mean,
        2 => {
            let (e1, e2) = (tied[0], tied[1]);
            let d = e1 * e2.dot(&mean) - e2 * e1.dot(&mean);
            if d.norm() > 1e-9 {
                d
            } else {
                eig.eigenvectors.column(k).into_owned()
            }
        }
        _ => eig.eigenvectors.column(k).into_owned(),
    };
    let l = axis.norm();
    if l > 0.0 {
        axis /= l;
    } else {
        axis = Vector3::z();
    }
    let mut c = axis.dot(&mean);
    if c < 0.0 {
        axis = -axis;
        c = -c;
    }
    Cone {
        axis,
        angle: c.clamp(0.0, 1.0).acos(),
    }
}

/// Eq. 1-2: the cone fitted to `faces` of `mesh` (area-weighted unit face normals).
pub fn fit_cone(mesh: &TriMesh, faces: &[FaceId]) -> Cone {
    let normals: Vec<_> = faces.iter().map(|&f| mesh.face_normal(f)).collect();
    let weights: Vec<_> = faces.iter().map(|&f| mesh.face_area(f)).collect();
    fit_cone_normals(&normals, &weights)
}

/// Eq. 1: `E(P, t) = (⟨n_P, n_t⟩ − cos α_P)²` for a unit normal `n_t`.
#[inline]
pub fn cone_error(cone: &Cone, n_t: &Vector3<f64>) -> f64 {
    let d = cone.axis.dot(n_t) - cone.angle.cos();
    d * d
}

/// Eq. 1 for a face of `mesh`.
#[inline]
pub fn face_cone_error(mesh: &TriMesh, cone: &Cone, f: FaceId) -> f64 {
    cone_error(cone, &mesh.face_normal(f))
}

/// The Eq. 2 objective `(1/A) Σ A_t E(P, t)` of a cone over `faces` (0 for no area).
pub fn cone_objective(mesh: &TriMesh, cone: &Cone, faces: &[FaceId]) -> f64 {
    let (mut s, mut a) = (0.0, 0.0);
    for &f in faces {
        let at = mesh.face_area(f);
        s += at * face_cone_error(mesh, cone, f);
        a += at;
    }
    if a > 0.0 {
        s / a
    } else {
        0.0
    }
}

/// The seed triangle s_P: the face of `candidates` with the least E (ties: lowest id).
pub fn least_error_face(mesh: &TriMesh, cone: &Cone, candidates: &[FaceId]) -> Option<FaceId> {
    let mut best: Option<(f64, FaceId)> = None;
    for &f in candidates {
        let e = face_cone_error(mesh, cone, f);
        best = match best {
            Some((be, bf)) if be < e || (be == e && bf < f) => Some((be, bf)),
            _ => Some((e, f)),
        };
    }
    best.map(|(_, f)| f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use std::f64::consts::PI;

    fn objective(n: &Vector3<f64>, c: f64, normals: &[Vector3<f64>], w: &[f64]) -> f64 {
        normals
            .iter()
            .zip(w)
            .map(|(m, a)| a * (n.dot(m) - c).powi(2))
            .sum::<f64>()
            / w.iter().sum::<f64>()
    }

    /// Brute force: a dense Fibonacci sampling of the sphere times a 1D grid over α.
    fn brute(normals: &[Vector3<f64>], w: &[f64]) -> f64 {
        let ns = 6000;
        let na = 200;
        let golden = PI * (3.0 - 5f64.sqrt());
        let mut best = f64::INFINITY;
        for i in 0..ns {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / ns as f64;
            let r = (1.0 - z * z).sqrt();
            let th = golden * i as f64;
            let n = Vector3::new(r * th.cos(), r * th.sin(), z);
            for j in 0..=na {
                let alpha = PI * j as f64 / na as f64;
                best = best.min(objective(&n, alpha.cos(), normals, w));
            }
        }
        best
    }

    fn random_unit(rng: &mut rand_chacha::ChaCha8Rng) -> Vector3<f64> {
        loop {
            let v = Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let l = v.norm();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }

    #[test]
    fn eigen_solution_beats_brute_force_on_random_normals() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for case in 0..6 {
            let k = 3 + case;
            // Normals near a random cone plus noise, and fully random ones for odd cases.
            let normals: Vec<_> = (0..k).map(|_| random_unit(&mut rng)).collect();
            let w: Vec<f64> = (0..k).map(|_| rng.random_range(0.1..2.0)).collect();
            let cone = fit_cone_normals(&normals, &w);
            let f_fit = objective(&cone.axis, cone.angle.cos(), &normals, &w);
            let f_brute = brute(&normals, &w);
            assert!(
                f_fit <= f_brute + 1e-12,
                "case {case}: fit {f_fit} worse than brute force {f_brute}"
            );
            // The sampling is dense enough to come close to the true minimum.
            assert!(
                f_brute - f_fit < 2e-3,
                "case {case}: brute {f_brute} far above fit {f_fit}"
            );
            assert!((cone.axis.norm() - 1.0).abs() < 1e-12);
            assert!((0.0..=PI / 2.0).contains(&cone.angle));
        }
    }

    #[test]
    fn exact_cone_normals_are_recovered() {
        // Normals of a cone with axis a and angle 40°: E vanishes, the axis is recovered.
        let a = Vector3::new(1.0, 2.0, -0.5).normalize();
        let u = a.cross(&Vector3::x()).normalize();
        let v = a.cross(&u);
        let alpha = 40f64.to_radians();
        let normals: Vec<_> = (0..7)
            .map(|i| {
                let phi = 0.7 * i as f64;
                a * alpha.cos() + (u * phi.cos() + v * phi.sin()) * alpha.sin()
            })
            .collect();
        let cone = fit_cone_normals(&normals, &[1.0; 7]);
        assert!((cone.axis - a).norm() < 1e-9, "{:?}", cone.axis);
        assert!((cone.angle - alpha).abs() < 1e-9);
        for n in &normals {
            assert!(cone_error(&cone, n) < 1e-18);
        }
    }

    #[test]
    fn two_distinct_normals_give_the_cylinder_through_their_ruling() {
        let n1 = Vector3::new(1.0, 0.0, 0.0);
        let n2 = Vector3::new(0.6, 0.8, 0.0);
        let cone = fit_cone_normals(&[n1, n1, n2], &[1.0, 1.0, 1.0]);
        assert!(
            cone.axis.cross(&Vector3::z()).norm() < 1e-9,
            "{:?}",
            cone.axis
        );
        assert!((cone.angle - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
    }

    #[test]
    fn planar_faces_give_zero_angle_along_normal() {
        let n = Vector3::new(0.0, 0.6, 0.8);
        let cone = fit_cone_normals(&[n, n, n], &[1.0, 2.0, 3.0]);
        assert!((cone.axis - n).norm() < 1e-12);
        assert!(cone.angle.abs() < 1e-6);
        let empty = fit_cone_normals(&[], &[]);
        assert_eq!(empty.axis, Vector3::z());
    }
}
