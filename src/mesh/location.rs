//! A point on a triangle mesh: a face and barycentric coordinates.

use super::TriMesh;
use crate::ids::FaceId;
use nalgebra::Point3;
use serde::Serialize;

/// A point on a mesh surface: face `face`, barycentric weights `bary` (summing to 1) of its
/// three corners in triangle order.
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
pub struct SurfaceLocation {
    /// The face containing the point.
    pub face: FaceId,
    /// Barycentric coordinates with respect to the face's corners.
    pub bary: [f64; 3],
}

impl SurfaceLocation {
    /// The 3D position on `mesh`.
    pub fn position(&self, mesh: &TriMesh) -> Point3<f64> {
        let [a, b, c] = mesh.face_points(self.face);
        Point3::from(a.coords * self.bary[0] + b.coords * self.bary[1] + c.coords * self.bary[2])
    }
}
