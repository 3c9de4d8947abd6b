//! Closest-point queries on a triangle mesh: parry's BVH over the triangles and its exact
//! point-triangle projection (the distance to the triangle, not to its vertices). Used by
//! the distance measures, the flip certificate and the fidelity control.

use super::TriMesh;
use crate::ids::FaceId;
use nalgebra::Point3;
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::TriMesh as PTriMesh;
use std::sync::Arc;

/// Closest-point queries on a triangle mesh (parry BVH + point-triangle projection).
#[derive(Clone)]
pub struct SurfaceProjector {
    bvh: Option<Arc<PTriMesh>>,
}

impl SurfaceProjector {
    /// Index the triangles of `mesh`. A mesh without faces gives a projector that finds
    /// nothing.
    pub fn new(mesh: &TriMesh) -> Self {
        let indices: Vec<[u32; 3]> = mesh.index_triangles();
        SurfaceProjector {
            bvh: parry_trimesh(&mesh.positions, indices).map(Arc::new),
        }
    }

    /// Queries on an index built already (a metric field's), sharing it.
    pub fn sharing(bvh: Arc<PTriMesh>) -> Self {
        SurfaceProjector { bvh: Some(bvh) }
    }

    /// The closest point of the surface to `p`, the face it lies on, and the distance.
    /// `None` for an empty surface or a non-finite `p`.
    pub fn closest(&self, p: &Point3<f64>) -> Option<(FaceId, Point3<f64>, f64)> {
        let bvh = self.bvh.as_ref()?;
        if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
            return None;
        }
        let q = PVec::new(p.x, p.y, p.z);
        let (proj, (tri, _loc)) =
            bvh.project_local_point_and_get_location_with_max_dist(q, false, f64::MAX)?;
        let c = Point3::new(proj.point.x, proj.point.y, proj.point.z);
        Some((FaceId(tri), c, (c - p).norm()))
    }
}

/// parry's triangle mesh (with its BVH) over `positions` and `triangles`; `None` without
/// triangles or when parry refuses them.
pub fn parry_trimesh(positions: &[Point3<f64>], triangles: Vec<[u32; 3]>) -> Option<PTriMesh> {
    if triangles.is_empty() {
        return None;
    }
    let vertices: Vec<PVec> = positions.iter().map(|p| PVec::new(p.x, p.y, p.z)).collect();
    PTriMesh::new(vertices, triangles).ok()
}
