//! Riemannian metric transfer from the 3D patch to its parameter domain (Sec. 3.3, Eq. 4).
//!
//! Two methods:
//! - [`TransferMethod::Eq4PrincipalFit`], the paper's: restrict the 3D metric to the vertex's
//!   tangent plane, take its principal directions `d1, d2` and eigenvalues `k1, k2`; express the
//!   1-ring vectors `v_i − v` as unit vectors in the frame `(d1, d2)`, the same edges as unit
//!   vectors in the parameter plane, fit the rotation `R` minimising `Σ |R·vv_i − ṽv_i|²`
//!   (Eq. 4, least squares; closed form in 2D), and set `M̂ = D·K·Dᵀ` with `D = R`, `K = diag(k1, k2)`.
//! - [`TransferMethod::JacobianPullback`]: for every triangle, the Jacobian `J` (3×2) of the affine
//!   map from the parameter plane to 3D; each vertex gets the area-weighted (parameter area) mean of
//!   `Jᵀ M_v J` over its incident triangles. This is the exact metric induced by the
//!   piecewise-linear map, so it also accounts for the parameterization's scale distortion,
//!   which Eq. 4 (unit vectors, a rotation only) ignores. It is the default (paper-notes.md).
//!
//! Both return SPD tensors: eigenvalues are clamped below at [`EIGEN_FLOOR_REL`] times the
//! largest one.

use super::Remesh2dError;
use crate::mesh::TriMesh;
use nalgebra::{Matrix2, Matrix3, Point2, SymmetricEigen, Vector2};

/// Relative eigenvalue floor of transferred metrics: every eigenvalue is raised to at least
/// `EIGEN_FLOOR_REL · λ_max` (caps the anisotropy ratio of lengths at 10⁴).
pub const EIGEN_FLOOR_REL: f64 = 1e-8;

/// How the 3D metric is brought into the parameter plane.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Default)]
pub enum TransferMethod {
    /// The paper's Eq. 4: least-squares fit of the principal directions from the 1-ring vectors
    /// mapped into the plane, then `D·K·Dᵀ`.
    Eq4PrincipalFit,
    /// `Jᵀ M J` per triangle, averaged to the vertices by parameter-domain area (default).
    #[default]
    JacobianPullback,
}

/// Make `m` symmetric positive definite: symmetrise, clamp eigenvalues to at least
/// [`EIGEN_FLOOR_REL`]·λ_max. `None` when it is not finite or has no positive eigenvalue.
pub fn clamp_spd(m: &Matrix2<f64>) -> Option<Matrix2<f64>> {
    let s = (m + m.transpose()) * 0.5;
    if !s.iter().all(|x| x.is_finite()) {
        return None;
    }
    let e = SymmetricEigen::new(s);
    let lmax = e.eigenvalues.max();
    if lmax.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let floor = lmax * EIGEN_FLOOR_REL;
    let ev = e.eigenvalues.map(|l| l.max(floor));
    let q = e.eigenvectors;
    let r = q * Matrix2::from_diagonal(&ev) * q.transpose();
    Some((r + r.transpose()) * 0.5)
}

/// Transfer per-vertex 3D metrics of a disk patch to its parameterization (Sec. 3.3, Eq. 4).
///
/// - `disk`: the 3D patch (a topological disk, `n` vertices).
/// - `uv`: the parameter position of every vertex (length `n`), positively oriented triangles.
/// - `metrics3d`: the 3D metric tensor (SPD 3×3) at every vertex (length `n`).
///
/// Returns one SPD 2×2 tensor per vertex (see [`clamp_spd`]). Errors: length mismatch or a
/// degenerate parameter triangle ([`Remesh2dError::InvalidDomain`]), a vertex without a usable
/// tensor ([`Remesh2dError::MetricNotSpd`] at its uv position).
pub fn transfer_metric(
    disk: &TriMesh,
    uv: &[Point2<f64>],
    metrics3d: &[Matrix3<f64>],
    method: TransferMethod,
) -> Result<Vec<Matrix2<f64>>, Remesh2dError> {
    let n = disk.n_vertices();
    if uv.len() != n || metrics3d.len() != n {
        return Err(count_mismatch(n, uv.len(), metrics3d.len()));
    }
    let raw = match method {
        TransferMethod::JacobianPullback => pullback(disk, uv, metrics3d)?,
        TransferMethod::Eq4PrincipalFit => principal_fit(disk, uv, metrics3d),
    };
    raw.iter()
        .enumerate()
        .map(|(i, m)| {
            m.as_ref()
                .and_then(clamp_spd)
                .ok_or(Remesh2dError::MetricNotSpd {
                    x: uv[i].x,
                    y: uv[i].y,
                })
        })
        .collect()
}

/// The exact pullback at every triangle corner: `J_tᵀ M(v) J_t` for each triangle `t` and
/// corner `v`, with `J_t` the Jacobian of the map from the parameter triangle to the 3D one
/// (see [`PlanarMetricField::with_corner_metrics`](super::PlanarMetricField::with_corner_metrics)).
/// Errors as [`transfer_metric`].
pub fn pullback_corners(
    disk: &TriMesh,
    uv: &[Point2<f64>],
    metrics3d: &[Matrix3<f64>],
) -> Result<Vec<[Matrix2<f64>; 3]>, Remesh2dError> {
    let n = disk.n_vertices();
    if uv.len() != n || metrics3d.len() != n {
        return Err(count_mismatch(n, uv.len(), metrics3d.len()));
    }
    disk.faces()
        .map(|f| {
            let [a, b, c] = disk.face(f).map(|v| v.idx());
            let e3 = nalgebra::Matrix3x2::from_columns(&[
                disk.positions[b] - disk.positions[a],
                disk.positions[c] - disk.positions[a],
            ]);
            let e2 = Matrix2::from_columns(&[uv[b] - uv[a], uv[c] - uv[a]]);
            let j = match e2.try_inverse() {
                Some(inv) if e2.determinant() != 0.0 => e3 * inv,
                _ => return Err(Remesh2dError::DegenerateParamTriangle(f)),
            };
            Ok([a, b, c].map(|v| j.transpose() * metrics3d[v] * j))
        })
        .collect()
}

/// `Jᵀ M_v J` averaged over the incident triangles, weighted by parameter area.
fn pullback(
    disk: &TriMesh,
    uv: &[Point2<f64>],
    metrics3d: &[Matrix3<f64>],
) -> Result<Vec<Option<Matrix2<f64>>>, Remesh2dError> {
    let n = disk.n_vertices();
    let mut acc = vec![Matrix2::zeros(); n];
    let mut wsum = vec![0.0; n];
    for f in disk.faces() {
        let [a, b, c] = disk.face(f);
        let (ia, ib, ic) = (a.idx(), b.idx(), c.idx());
        let p = [disk.positions[ia], disk.positions[ib], disk.positions[ic]];
        let e3 = nalgebra::Matrix3x2::from_columns(&[p[1] - p[0], p[2] - p[0]]);
        let e2 = Matrix2::from_columns(&[uv[ib] - uv[ia], uv[ic] - uv[ia]]);
        let area = 0.5 * e2.determinant();
        // A degenerate parameter triangle has no Jacobian; the bijectivity certificate of the
        // parameterization should have refused it already.
        let inv = match e2.try_inverse() {
            Some(inv) if area.is_finite() && area != 0.0 => inv,
            _ => return Err(Remesh2dError::DegenerateParamTriangle(f)),
        };
        let j = e3 * inv;
        let w = area.abs();
        for &v in &[ia, ib, ic] {
            acc[v] += j.transpose() * metrics3d[v] * j * w;
            wsum[v] += w;
        }
    }
    Ok(acc
        .into_iter()
        .zip(wsum)
        .map(|(m, w)| if w > 0.0 { Some(m / w) } else { None })
        .collect())
}

/// Eq. 4: fit the in-plane rotation of the principal frame from the 1-ring, then `D K Dᵀ`.
fn principal_fit(
    disk: &TriMesh,
    uv: &[Point2<f64>],
    metrics3d: &[Matrix3<f64>],
) -> Vec<Option<Matrix2<f64>>> {
    let n = disk.n_vertices();
    let normals = disk.vertex_normals();
    let mut ring: Vec<Vec<usize>> = vec![Vec::new(); n];
    for f in disk.faces() {
        let t = disk.face(f);
        for i in 0..3 {
            let (a, b) = (t[i].idx(), t[(i + 1) % 3].idx());
            ring[a].push(b);
            ring[b].push(a);
        }
    }
    (0..n)
        .map(|v| {
            let nrm = normals[v];
            if nrm.norm() == 0.0 {
                return None;
            }
            // The metric restricted to the tangent plane: its eigenvectors are the principal
            // directions d1, d2 of the paper and its eigenvalues k1, k2 (the third principal
            // direction of a surface metric is the normal, which the plane does not see).
            let (t1, t2) = crate::metric::tangent_frame(&nrm);
            let tm = nalgebra::Matrix3x2::from_columns(&[t1, t2]);
            let m_t = tm.transpose() * metrics3d[v] * tm;
            let eig = SymmetricEigen::new((m_t + m_t.transpose()) * 0.5);
            let k = eig.eigenvalues;
            // Columns: d1, d2 in (t1, t2) coordinates, made a proper rotation so that the frame
            // (d1, d2, d1 × d2) is right-handed like the paper's O and a rotation can fit it.
            let mut dirs = eig.eigenvectors;
            if dirs.determinant() < 0.0 {
                dirs.set_column(1, &(-dirs.column(1)));
            }
            // Least squares over the 1-ring (Eq. 4): R minimising Σ |R a_i − b_i|², a_i the unit
            // edge vector in the (d1, d2) frame, b_i the unit edge vector in the plane. For a
            // rotation the minimiser is the angle atan2(Σ a×b, Σ a·b).
            let (mut sdot, mut scross) = (0.0, 0.0);
            let mut seen = ring[v].clone();
            seen.sort_unstable();
            seen.dedup();
            for &w in &seen {
                let d3 = disk.positions[w] - disk.positions[v];
                let in_t = Vector2::new(d3.dot(&t1), d3.dot(&t2));
                let a = dirs.transpose() * in_t;
                let b = uv[w] - uv[v];
                let (na, nb) = (a.norm(), b.norm());
                if na == 0.0 || nb == 0.0 {
                    continue;
                }
                let (a, b) = (a / na, b / nb);
                sdot += a.dot(&b);
                scross += a.x * b.y - a.y * b.x;
            }
            if sdot == 0.0 && scross == 0.0 {
                return None;
            }
            let th = scross.atan2(sdot);
            let d = Matrix2::new(th.cos(), -th.sin(), th.sin(), th.cos());
            Some(d * Matrix2::from_diagonal(&k) * d.transpose())
        })
        .collect()
}

/// The error of `n` vertices with `uv` positions and `metrics` tensors (one of them not `n`).
fn count_mismatch(n: usize, uv: usize, metrics: usize) -> Remesh2dError {
    let (found, data) = match uv != n {
        true => (uv, "uv positions"),
        false => (metrics, "metrics"),
    };
    Remesh2dError::CountMismatch {
        elements: n,
        of: "vertices",
        found,
        data,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;
    use nalgebra::Vector3;

    fn flat_disk() -> (TriMesh, Vec<Point2<f64>>) {
        let m = generators::disk(1.0, 4, 12);
        let uv = m.positions.iter().map(|p| Point2::new(p.x, p.y)).collect();
        (m, uv)
    }

    /// On an isometric map (flat z = 0 patch, uv = xy) both methods give the 3D metric
    /// restricted to the plane.
    #[test]
    fn isometric_map_restricts_metric() -> Result<(), Remesh2dError> {
        let (m, uv) = flat_disk();
        let r = nalgebra::Rotation3::from_euler_angles(0.0, 0.0, 0.7);
        let base = Matrix3::from_diagonal(&Vector3::new(4.0, 1.0, 9.0));
        let m3 = r.matrix() * base * r.matrix().transpose();
        let metrics = vec![m3; m.n_vertices()];
        let expect = m3.fixed_view::<2, 2>(0, 0).into_owned();
        for method in [
            TransferMethod::Eq4PrincipalFit,
            TransferMethod::JacobianPullback,
        ] {
            let out = transfer_metric(&m, &uv, &metrics, method)?;
            for (i, t) in out.iter().enumerate() {
                assert!(
                    (t - expect).norm() < 1e-9 * expect.norm(),
                    "{method:?} v{i}: {t} vs {expect}"
                );
            }
        }
        Ok(())
    }

    /// A creased patch (two triangles folded 90° along their shared edge, laid flat in the
    /// plane): the corner pullback of the identity metric measures every parameter edge of
    /// its triangle at its exact 3D length, also at the corners on the crease, while the
    /// vertex average of the two Jacobians does not (the upright triangle's parameter edges
    /// are stretched 2× in the plane).
    #[test]
    fn corner_pullback_is_exact_across_a_crease() -> Result<(), Remesh2dError> {
        use crate::ids::VertexId;
        use nalgebra::Point3;
        // Crease along x from (0,0,0) to (1,0,0); one triangle flat (y < 0), one upright (z > 0).
        let disk = TriMesh {
            positions: vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(0.5, 0.0, 1.0),
                Point3::new(0.5, -1.0, 0.0),
            ],
            triangles: vec![
                [VertexId(0), VertexId(1), VertexId(2)],
                [VertexId(1), VertexId(0), VertexId(3)],
            ],
        };
        // A non-isometric but bijective layout: the upright triangle is squashed to half
        // height in the plane.
        let uv = vec![
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(0.5, 0.5),
            Point2::new(0.5, -1.0),
        ];
        let metrics = vec![Matrix3::identity(); 4];
        let corners = pullback_corners(&disk, &uv, &metrics)?;
        let averaged = transfer_metric(&disk, &uv, &metrics, TransferMethod::JacobianPullback)?;
        let mut averaged_error: f64 = 0.0;
        for (t, tri) in disk.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k].idx(), tri[(k + 1) % 3].idx());
                let e2 = uv[b] - uv[a];
                let l3 = (disk.positions[b] - disk.positions[a]).norm();
                for c in 0..3 {
                    let l = e2.dot(&(corners[t][c] * e2)).sqrt();
                    assert!((l - l3).abs() < 1e-12, "t{t} corner {c}: {l} vs {l3}");
                    let v = tri[c].idx();
                    let la = e2.dot(&(averaged[v] * e2)).sqrt();
                    averaged_error = averaged_error.max((la / l3 - 1.0).abs());
                }
            }
        }
        assert!(
            averaged_error > 0.2,
            "the averaged transfer was exact too: {averaged_error}"
        );
        Ok(())
    }

    /// A rotated parameterization (still isometric) rotates the tensor accordingly.
    #[test]
    fn rotated_isometry_rotates_metric() -> Result<(), Remesh2dError> {
        let (m, _) = flat_disk();
        let th: f64 = 0.4;
        let rot = Matrix2::new(th.cos(), -th.sin(), th.sin(), th.cos());
        let uv: Vec<_> = m
            .positions
            .iter()
            .map(|p| Point2::from(rot * Vector2::new(p.x, p.y)))
            .collect();
        let m3 = Matrix3::from_diagonal(&Vector3::new(1.0, 25.0, 3.0));
        let metrics = vec![m3; m.n_vertices()];
        let expect = rot * Matrix2::new(1.0, 0.0, 0.0, 25.0) * rot.transpose();
        for method in [
            TransferMethod::Eq4PrincipalFit,
            TransferMethod::JacobianPullback,
        ] {
            let out = transfer_metric(&m, &uv, &metrics, method)?;
            for t in &out {
                assert!((t - expect).norm() < 1e-8 * expect.norm(), "{method:?}");
            }
        }
        Ok(())
    }

    #[test]
    fn clamp_spd_floors_eigenvalues() {
        let m = Matrix2::new(1.0, 0.0, 0.0, -3.0);
        let c = clamp_spd(&m).map(|c| SymmetricEigen::new(c).eigenvalues.min());
        assert_eq!(c, Some(1e-8));
        assert_eq!(clamp_spd(&Matrix2::new(-1.0, 0.0, 0.0, -1.0)), None);
        assert_eq!(clamp_spd(&Matrix2::new(f64::NAN, 0.0, 0.0, 1.0)), None);
    }

    #[test]
    fn length_mismatch_is_an_error() {
        let (m, uv) = flat_disk();
        let r = transfer_metric(&m, &uv[1..], &[], TransferMethod::default());
        assert!(matches!(
            r,
            Err(Remesh2dError::CountMismatch {
                data: "uv positions",
                ..
            })
        ));
    }
}
