//! The flip certificate: a face is flipped when it faces away from the reference surface.

use crate::ids::FaceId;
use crate::mesh::{SurfaceProjector, TriMesh};
use nalgebra::{Point3, Vector3};
use parry3d_f64::math::Vector as PVec;
use std::sync::Arc;

/// The flip test of the quality issue: a face is flipped when its normal points more than 90°
/// away from the normal of the input face closest to its centroid.
///
/// Two verdicts: [`FlipTest::is_flipped`] uses the one closest face the BVH returns (the
/// yardstick's definition, as the peers' evaluator); [`FlipTest::is_flipped_anywhere`] is the
/// conservative verdict used by the pipeline's per-patch certificate: where the centroid's
/// closest point lies on an input edge or vertex (a sharp crease, several input faces at the
/// same distance, within a relative 1e-9 — a measurement tolerance on distances), the face is
/// flipped if it points away from ANY of them. So a certified output has no flip under any
/// tie-break.
///
/// The decision is the sign of the float dot product of the two (unnormalised) face normals,
/// strictly negative = flipped: a float decision on normals, not an exact predicate. Zero-area
/// faces (zero normal) are never reported here (the degenerate-face certificate catches them).
pub struct FlipTest {
    proj: SurfaceProjector,
    input: Arc<TriMesh>,
    /// The faces around each input vertex: those of `v` are
    /// `vertex_faces[vertex_start[v]..vertex_start[v + 1]]` (one allocation, not one per vertex).
    vertex_start: Vec<u32>,
    vertex_faces: Vec<FaceId>,
}

impl FlipTest {
    /// Index the input surface.
    pub fn new(input: &TriMesh) -> FlipTest {
        FlipTest::with_index(Arc::new(input.clone()), SurfaceProjector::new(input))
    }

    /// The test against `input`, sharing it and its closest-point index `proj` (a metric
    /// field's, say) instead of copying them.
    pub fn with_index(input: Arc<TriMesh>, proj: SurfaceProjector) -> FlipTest {
        let mut vertex_start = vec![0u32; input.n_vertices() + 1];
        for t in &input.triangles {
            for v in t {
                vertex_start[v.idx() + 1] += 1;
            }
        }
        for v in 0..input.n_vertices() {
            vertex_start[v + 1] += vertex_start[v];
        }
        let mut next = vertex_start.clone();
        let mut vertex_faces = vec![FaceId(0); 3 * input.n_faces()];
        for (f, t) in input.triangles.iter().enumerate() {
            for v in t {
                vertex_faces[next[v.idx()] as usize] = FaceId::new(f);
                next[v.idx()] += 1;
            }
        }
        FlipTest {
            proj,
            input,
            vertex_start,
            vertex_faces,
        }
    }

    /// Flipped against the closest input face (ties broken by the BVH).
    pub fn is_flipped(&self, p: &[Point3<f64>; 3]) -> bool {
        let n_out: Vector3<f64> = (p[1] - p[0]).cross(&(p[2] - p[0]));
        let c = Point3::from((p[0].coords + p[1].coords + p[2].coords) / 3.0);
        match self.proj.closest(&c) {
            Some((fin, _, _)) => n_out.dot(&self.input.face_normal_raw(fin)) < 0.0,
            None => false,
        }
    }

    /// Flipped against any of the input faces closest to the centroid (conservative).
    pub fn is_flipped_anywhere(&self, p: &[Point3<f64>; 3]) -> bool {
        let n_out: Vector3<f64> = (p[1] - p[0]).cross(&(p[2] - p[0]));
        let c = Point3::from((p[0].coords + p[1].coords + p[2].coords) / 3.0);
        let Some((fin, _, d)) = self.proj.closest(&c) else {
            return false;
        };
        if n_out.dot(&self.input.face_normal_raw(fin)) < 0.0 {
            return true;
        }
        // Equally close faces share a vertex with the closest one (closest point on an edge or
        // vertex of it).
        let tol = d * 1e-9 + f64::MIN_POSITIVE;
        for v in self.input.face(fin) {
            let around =
                self.vertex_start[v.idx()] as usize..self.vertex_start[v.idx() + 1] as usize;
            for &g in &self.vertex_faces[around] {
                if g == fin {
                    continue;
                }
                let [a, b, e] = self.input.face_points(g);
                let tri = parry3d_f64::shape::Triangle::new(
                    PVec::new(a.x, a.y, a.z),
                    PVec::new(b.x, b.y, b.z),
                    PVec::new(e.x, e.y, e.z),
                );
                use parry3d_f64::query::PointQuery;
                let dg = tri.distance_to_local_point(PVec::new(c.x, c.y, c.z), false);
                if dg <= d + tol && n_out.dot(&self.input.face_normal_raw(g)) < 0.0 {
                    return true;
                }
            }
        }
        false
    }
}
