//! Per-triangle Jacobians of a 2D map of a 3D disk and the distortion report (Sec. 3.3:
//! "embedded ... with low distortion").

use super::DistortionReport;
use crate::mesh::TriMesh;
use nalgebra::{Matrix2, Point2};

/// The rest shape of one 3D triangle in its own orthonormal frame.
///
/// With `U = [u1 − u0, u2 − u0]` (2×2, columns) the map's Jacobian on the triangle is
/// `F = U · inv_rest`; `grad[k]` is the row `∂F_{i·}/∂u_{k,i}` (the same for both rows).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TriangleFrame {
    /// 3D area (0 for a degenerate triangle, which is then left out of the energy).
    pub area: f64,
    /// Inverse of the rest edge matrix `[x1 − x0, x2 − x0]` in the local frame.
    pub inv_rest: Matrix2<f64>,
    /// `G` rows: derivative of a row of `F` with respect to the same coordinate of corner k.
    pub grad: [[f64; 2]; 3],
}

/// Rest frames of all triangles of `disk`.
pub fn triangle_frames(disk: &TriMesh) -> Vec<TriangleFrame> {
    disk.faces()
        .map(|f| {
            let [x0, x1, x2] = disk.face_points(f);
            let (e1, e2) = (x1 - x0, x2 - x0);
            let l1 = e1.norm();
            let cross = e1.cross(&e2).norm();
            let rest = Matrix2::new(l1, e1.dot(&e2) / l1, 0.0, cross / l1);
            match rest.try_inverse() {
                Some(b) if l1 > 0.0 && cross > 0.0 && b.iter().all(|x| x.is_finite()) => {
                    TriangleFrame {
                        area: 0.5 * cross,
                        inv_rest: b,
                        grad: [
                            [-b[(0, 0)] - b[(1, 0)], -b[(0, 1)] - b[(1, 1)]],
                            [b[(0, 0)], b[(0, 1)]],
                            [b[(1, 0)], b[(1, 1)]],
                        ],
                    }
                }
                _ => TriangleFrame {
                    area: 0.0,
                    inv_rest: Matrix2::zeros(),
                    grad: [[0.0; 2]; 3],
                },
            }
        })
        .collect()
}

/// Jacobian `F` of the map on one triangle.
#[inline]
pub(crate) fn jacobian(fr: &TriangleFrame, u: [Point2<f64>; 3]) -> Matrix2<f64> {
    let (e1, e2) = (u[1] - u[0], u[2] - u[0]);
    Matrix2::new(e1.x, e2.x, e1.y, e2.y) * fr.inv_rest
}

/// Signed singular values `(σ1, σ2)` of a 2×2 matrix: `σ1 ≥ |σ2|`, `σ2 < 0` when the
/// matrix reverses orientation.
#[inline]
pub(crate) fn signed_singular_values(f: &Matrix2<f64>) -> (f64, f64) {
    let (a, b, c, d) = (f[(0, 0)], f[(0, 1)], f[(1, 0)], f[(1, 1)]);
    let s = (a + d).hypot(c - b);
    let t = (a - d).hypot(b + c);
    (0.5 * (s + t), 0.5 * (s - t))
}

/// Distortion of the map `uv` of `disk`: area-weighted symmetric Dirichlet energy
/// (`σ1² + σ2² + σ1⁻² + σ2⁻²`, 4 for an isometry), the largest and area-weighted mean
/// singular-value ratio `σ1/σ2`, and the largest `|log(σ1 σ2)|`. Triangles that are flipped
/// or degenerate in the plane give infinite values. The iteration fields are left at 0.
pub fn distortion(disk: &TriMesh, uv: &[Point2<f64>]) -> DistortionReport {
    let frames = triangle_frames(disk);
    let (mut area, mut sd, mut mean_c) = (0.0, 0.0, 0.0);
    let (mut max_c, mut max_a) = (1.0f64, 0.0f64);
    for (t, fr) in disk.triangles.iter().zip(&frames) {
        if fr.area <= 0.0 {
            continue;
        }
        let f = jacobian(fr, [uv[t[0].idx()], uv[t[1].idx()], uv[t[2].idx()]]);
        let (s1, s2) = signed_singular_values(&f);
        let (e, c, a) = if s2 > 0.0 {
            (
                s1 * s1 + s2 * s2 + 1.0 / (s1 * s1) + 1.0 / (s2 * s2),
                s1 / s2,
                (s1 * s2).ln().abs(),
            )
        } else {
            (f64::INFINITY, f64::INFINITY, f64::INFINITY)
        };
        area += fr.area;
        sd += fr.area * e;
        mean_c += fr.area * c;
        max_c = max_c.max(c);
        max_a = max_a.max(a);
    }
    let area = if area > 0.0 { area } else { 1.0 };
    DistortionReport {
        symmetric_dirichlet: sd / area,
        max_conformal: max_c,
        mean_conformal: mean_c / area,
        max_area_distortion: max_a,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;

    #[test]
    fn identity_map_of_a_flat_disk_is_an_isometry() {
        let m = generators::disk(2.0, 4, 6);
        let uv: Vec<_> = m.positions.iter().map(|p| Point2::new(p.x, p.y)).collect();
        let r = distortion(&m, &uv);
        assert!((r.symmetric_dirichlet - 4.0).abs() < 1e-12, "{r:?}");
        assert!((r.max_conformal - 1.0).abs() < 1e-12);
        assert!(r.max_area_distortion < 1e-12);
        // Stretch x by 2: σ = (2, 1) everywhere.
        let uv2: Vec<_> = uv.iter().map(|p| Point2::new(2.0 * p.x, p.y)).collect();
        let r = distortion(&m, &uv2);
        assert!((r.max_conformal - 2.0).abs() < 1e-12);
        assert!((r.symmetric_dirichlet - (4.0 + 1.0 + 0.25 + 1.0)).abs() < 1e-12);
        assert!((r.max_area_distortion - 2f64.ln()).abs() < 1e-12);
        // Mirror: infinite distortion.
        let uv3: Vec<_> = uv.iter().map(|p| Point2::new(-p.x, p.y)).collect();
        assert!(distortion(&m, &uv3).max_conformal.is_infinite());
    }
}
