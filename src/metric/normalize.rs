//! Unit-diagonal normalization (Sec. 3.1 notes in `paper-notes.md`).
//!
//! The pipeline works on the reference mesh scaled so that its bounding-box diagonal is 1.
//! Curvature scales as 1/size, so the paper's floor `10⁻⁴` on |k| (Sec. 4.1) only has a
//! meaning in fixed units; unit-diagonal units make it the same for every input file.

use crate::mesh::TriMesh;
use nalgebra::{Matrix3, Point3};

/// A similarity `unit = (p − center) · scale` that maps a mesh to bounding-box diagonal 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Normalization {
    /// Bounding-box centre in file units.
    pub center: Point3<f64>,
    /// `1 / bbox diagonal` (file units → unit space); 1 for a mesh of zero extent.
    pub scale: f64,
}

impl Default for Normalization {
    /// The identity (centre at the origin, scale 1).
    fn default() -> Self {
        Normalization {
            center: Point3::origin(),
            scale: 1.0,
        }
    }
}

impl Normalization {
    /// The normalization of `mesh`: bounding-box centre and `1 / diagonal`. A mesh with no
    /// vertices or zero (or non-finite) diagonal gets scale 1, so the map is always invertible.
    pub fn of(mesh: &TriMesh) -> Self {
        let Some((lo, hi)) = mesh.bbox() else {
            return Normalization::default();
        };
        let diag = (hi - lo).norm();
        let center = Point3::from((lo.coords + hi.coords) * 0.5);
        let scale = if diag.is_finite() && diag > 0.0 {
            1.0 / diag
        } else {
            1.0
        };
        Normalization { center, scale }
    }

    /// File units → unit space.
    #[inline]
    pub fn to_unit(&self, p: &Point3<f64>) -> Point3<f64> {
        Point3::from((p - self.center) * self.scale)
    }

    /// Unit space → file units.
    #[inline]
    pub fn from_unit(&self, p: &Point3<f64>) -> Point3<f64> {
        self.center + p.coords / self.scale
    }

    /// A copy of `mesh` with every position mapped to unit space (triangles unchanged).
    pub fn apply(&self, mesh: &TriMesh) -> TriMesh {
        TriMesh {
            positions: mesh.positions.iter().map(|p| self.to_unit(p)).collect(),
            triangles: mesh.triangles.clone(),
        }
    }

    /// A copy of a unit-space `mesh` mapped back to file units.
    pub fn unapply(&self, mesh: &TriMesh) -> TriMesh {
        TriMesh {
            positions: mesh.positions.iter().map(|p| self.from_unit(p)).collect(),
            triangles: mesh.triangles.clone(),
        }
    }

    /// A metric given in file units → the same metric in unit space: `M_unit = M_file / scale²`.
    ///
    /// "The same" means every edge keeps its metric length `√(eᵀ M e)`: a unit-space edge is
    /// `scale · e_file`, so `(scale·e)ᵀ M_unit (scale·e) = eᵀ M_file e`.
    #[inline]
    pub fn metric_to_unit(&self, m: &Matrix3<f64>) -> Matrix3<f64> {
        m / (self.scale * self.scale)
    }

    /// A unit-space metric → file units: `M_file = M_unit · scale²` (inverse of
    /// [`Normalization::metric_to_unit`]).
    #[inline]
    pub fn metric_from_unit(&self, m: &Matrix3<f64>) -> Matrix3<f64> {
        m * (self.scale * self.scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;
    use nalgebra::Vector3;

    #[test]
    fn unit_space_has_unit_diagonal_and_round_trips() {
        let mut m = generators::icosphere(3.0, 1);
        for p in &mut m.positions {
            *p += Vector3::new(10.0, -4.0, 2.5);
        }
        let n = Normalization::of(&m);
        let u = n.apply(&m);
        assert!((u.bbox_diagonal() - 1.0).abs() < 1e-12);
        let (lo, hi) = u.bbox().expect("non-empty");
        assert!(((lo.coords + hi.coords) * 0.5).norm() < 1e-12);
        for (p, q) in m.positions.iter().zip(&n.unapply(&u).positions) {
            assert!((p - q).norm() < 1e-12 * 20.0);
        }
    }

    #[test]
    fn metric_conversion_keeps_metric_lengths() {
        let m = generators::icosphere(7.0, 0);
        let n = Normalization::of(&m);
        let mf = Matrix3::new(2.0, 0.3, 0.1, 0.3, 1.0, 0.0, 0.1, 0.0, 0.5);
        let (a, b) = (Point3::new(1.0, 2.0, 3.0), Point3::new(-1.0, 0.5, 2.0));
        let ef = b - a;
        let eu = n.to_unit(&b) - n.to_unit(&a);
        let lf = (ef.transpose() * mf * ef)[0].sqrt();
        let lu = (eu.transpose() * n.metric_to_unit(&mf) * eu)[0].sqrt();
        assert!((lf - lu).abs() < 1e-12 * lf);
        assert!((n.metric_from_unit(&n.metric_to_unit(&mf)) - mf).norm() < 1e-12);
    }
}
