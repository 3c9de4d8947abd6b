//! The metric field of the reference surface (Sec. 4.1, "Riemannian metric generation"): a
//! tensor per reference vertex, evaluated anywhere by projecting onto the nearest reference
//! face and interpolating the three vertex tensors barycentrically,
//! `M_v = b₀ M₀ + b₁ M₁ + b₂ M₂`. It is the one way later stages ask for the metric.

use super::{curvature_metric, MetricError, MetricOptions, SpdDefect};
use crate::ids::FaceId;
use crate::mesh::{SurfaceLocation, SurfaceProjector, TriMesh};
use nalgebra::{Matrix2, Matrix3, Point3, Vector3};
use parry3d_f64::math::Vector as PVector;
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::TriMesh as ParryTriMesh;
use std::sync::Arc;

/// Relative tolerance of the symmetry and positive-semi-definiteness checks of
/// [`MetricField::new`] (relative to the largest absolute entry / eigenvalue).
pub const SPD_RELATIVE_TOLERANCE: f64 = 1e-9;

/// The restriction to the tangent plane must have its smallest eigenvalue above this fraction of
/// the tensor's largest eigenvalue (strictly positive definite, up to round-off).
pub const TANGENT_PD_RELATIVE_TOLERANCE: f64 = 1e-12;

/// A Riemannian metric field on a reference surface: per-vertex symmetric tensors plus a BVH
/// (parry3d-f64) for closest-point queries. `Send + Sync`; cheap queries from many threads.
/// The reference, its face normals and the BVH are shared (`Arc`) by every field made from
/// this one with [`MetricField::with_metrics`]: on a surface of a million faces each copy of
/// them costs a few hundred MB.
#[derive(Clone)]
pub struct MetricField {
    reference: Arc<TriMesh>,
    metrics: Vec<Matrix3<f64>>,
    face_normals: Arc<Vec<Vector3<f64>>>,
    bvh: Arc<ParryTriMesh>,
}

impl std::fmt::Debug for MetricField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MetricField")
            .field("vertices", &self.reference.n_vertices())
            .field("faces", &self.reference.n_faces())
            .finish_non_exhaustive()
    }
}

/// `vertex_metrics` checked against `reference` (one tensor per vertex, each valid for its
/// vertex normal) and symmetrised.
fn checked_metrics(
    reference: &TriMesh,
    vertex_metrics: Vec<Matrix3<f64>>,
) -> Result<Vec<Matrix3<f64>>, MetricError> {
    if vertex_metrics.len() != reference.n_vertices() {
        return Err(MetricError::CountMismatch {
            expected: reference.n_vertices(),
            found: vertex_metrics.len(),
        });
    }
    let normals = reference.vertex_normals();
    for (v, (m, n)) in vertex_metrics.iter().zip(&normals).enumerate() {
        validate_vertex_metric(v, m, n)?;
    }
    Ok(vertex_metrics
        .into_iter()
        .map(|m| (m + m.transpose()) * 0.5)
        .collect())
}

/// Check one vertex tensor (see [`MetricField::new`]); `normal` may be zero (check skipped).
pub fn validate_vertex_metric(
    vertex: usize,
    m: &Matrix3<f64>,
    normal: &Vector3<f64>,
) -> Result<(), MetricError> {
    if !m.iter().all(|x| x.is_finite()) {
        return Err(MetricError::NonFinite { vertex });
    }
    let scale = m.iter().fold(0.0f64, |s, x| s.max(x.abs()));
    let asym = (m - m.transpose())
        .iter()
        .fold(0.0f64, |s, x| s.max(x.abs()));
    if asym > SPD_RELATIVE_TOLERANCE * scale {
        return Err(MetricError::NotSpd {
            vertex,
            defect: SpdDefect::NotSymmetric { asymmetry: asym },
        });
    }
    let sym = (m + m.transpose()) * 0.5;
    let eig = sym.symmetric_eigenvalues();
    let lmax = eig.iter().fold(0.0f64, |s, x| s.max(x.abs()));
    let lmin = eig.min();
    if lmin < -SPD_RELATIVE_TOLERANCE * lmax {
        return Err(MetricError::NotSpd {
            vertex,
            defect: SpdDefect::NegativeEigenvalue {
                eigenvalues: [eig[0], eig[1], eig[2]],
            },
        });
    }
    let nl = normal.norm();
    if nl > 0.0 && nl.is_finite() {
        let (t1, t2) = super::tangent_frame(&(normal / nl));
        let b = Matrix2::new(
            t1.dot(&(sym * t1)),
            t1.dot(&(sym * t2)),
            t2.dot(&(sym * t1)),
            t2.dot(&(sym * t2)),
        );
        let be = b.symmetric_eigenvalues();
        let bmin = be.min();
        if !(bmin > 0.0 && bmin > TANGENT_PD_RELATIVE_TOLERANCE * lmax) {
            // Positive but beyond the conditioning the predicates and the planar stage can
            // carry is not the same error as indefinite: say which.
            let eigenvalues = [be[0], be[1]];
            let defect = match bmin > 0.0 {
                true => SpdDefect::IllConditioned { eigenvalues },
                false => SpdDefect::TangentIndefinite { eigenvalues },
            };
            return Err(MetricError::NotSpd { vertex, defect });
        }
    }
    Ok(())
}

fn to_parry(p: &Point3<f64>) -> PVector {
    PVector::new(p.x, p.y, p.z)
}

/// Barycentric coordinates of the point `q` (already on or near the triangle) in `[a, b, c]`,
/// clamped to the triangle and summing to 1. A degenerate triangle gives its nearest corner.
fn barycentric(q: &Point3<f64>, [a, b, c]: [Point3<f64>; 3]) -> [f64; 3] {
    let (v0, v1, v2) = (b - a, c - a, q - a);
    let (d00, d01, d11) = (v0.dot(&v0), v0.dot(&v1), v1.dot(&v1));
    let (d20, d21) = (v2.dot(&v0), v2.dot(&v1));
    let denom = d00 * d11 - d01 * d01;
    if denom > 0.0 && denom.is_finite() {
        let v = (d11 * d20 - d01 * d21) / denom;
        let w = (d00 * d21 - d01 * d20) / denom;
        let mut bc = [(1.0 - v - w).max(0.0), v.max(0.0), w.max(0.0)];
        let s = bc[0] + bc[1] + bc[2];
        if s > 0.0 && s.is_finite() {
            bc.iter_mut().for_each(|x| *x /= s);
            return bc;
        }
    }
    let d = [(q - a).norm(), (q - b).norm(), (q - c).norm()];
    let mut k = 0;
    for i in 1..3 {
        if d[i] < d[k] {
            k = i;
        }
    }
    let mut bc = [0.0; 3];
    bc[k] = 1.0;
    bc
}

impl MetricField {
    /// A field from per-vertex tensors on `reference` (unit space in the pipeline; the field
    /// itself is unit-agnostic).
    ///
    /// Validates, naming the vertex: one tensor per vertex ([`MetricError::CountMismatch`]);
    /// finite entries ([`MetricError::NonFinite`]); symmetric and positive semi-definite within
    /// the relative tolerance [`SPD_RELATIVE_TOLERANCE`]; and positive definite on the tangent
    /// plane (orthogonal complement of the reference's area-weighted vertex normal), with the
    /// smallest eigenvalue there above [`TANGENT_PD_RELATIVE_TOLERANCE`] × the largest eigenvalue
    /// ([`MetricError::NotSpd`]). The eigenvalue along the normal may be 0, as in the curvature
    /// metric of Sec. 4.1. Vertices without a normal (unreferenced, or only degenerate faces)
    /// skip the tangent check. The stored tensors are the symmetric parts of the inputs.
    pub fn new(reference: TriMesh, vertex_metrics: Vec<Matrix3<f64>>) -> Result<Self, MetricError> {
        reference.validate()?;
        let metrics = checked_metrics(&reference, vertex_metrics)?;
        let bvh = ParryTriMesh::new(
            reference.positions.iter().map(to_parry).collect(),
            reference.index_triangles(),
        )
        .map_err(MetricError::Bvh)?;
        let face_normals = reference
            .faces()
            .map(|f| reference.face_normal(f))
            .collect();
        Ok(MetricField {
            reference: Arc::new(reference),
            metrics,
            face_normals: Arc::new(face_normals),
            bvh: Arc::new(bvh),
        })
    }

    /// Other tensors on the same reference (validated as [`MetricField::new`]), sharing its
    /// mesh, normals and BVH.
    pub fn with_metrics(&self, vertex_metrics: Vec<Matrix3<f64>>) -> Result<Self, MetricError> {
        Ok(MetricField {
            metrics: checked_metrics(&self.reference, vertex_metrics)?,
            ..self.clone_shared()
        })
    }

    /// This field's shared parts with no tensors; filled in by the caller.
    fn clone_shared(&self) -> Self {
        MetricField {
            reference: Arc::clone(&self.reference),
            metrics: Vec::new(),
            face_normals: Arc::clone(&self.face_normals),
            bvh: Arc::clone(&self.bvh),
        }
    }

    /// A field from a user's tensors (validated as [`MetricField::new`]), restricted to the
    /// surface: each tensor `M` becomes `P M P` with `P = I − n nᵀ` for the vertex normal `n`,
    /// its block on the tangent plane. A user metric (a Medit `.sol` made for MMG) is SPD in
    /// 3D with a large eigenvalue along the normal; left in, that eigenvalue leaks into the
    /// tangent directions of every face that is not exactly perpendicular to the vertex normal
    /// (a cylinder with 60 sectors and sizes 0.03/0.3: +27 % on the circumferential
    /// eigenvalue), so the triangles would follow a metric the user did not give. Vertices
    /// without a normal keep their tensor.
    pub fn from_surface_tensors(
        reference: TriMesh,
        vertex_metrics: Vec<Matrix3<f64>>,
    ) -> Result<Self, MetricError> {
        let field = MetricField::new(reference, vertex_metrics)?;
        let normals = field.reference.vertex_normals();
        let metrics = field
            .metrics
            .iter()
            .zip(&normals)
            .map(|(m, n)| match n.norm() > 0.5 {
                true => {
                    let p = Matrix3::identity() - n * n.transpose();
                    let t = p * m * p;
                    (t + t.transpose()) * 0.5
                }
                false => *m,
            })
            .collect();
        Ok(MetricField { metrics, ..field })
    }

    /// The curvature metric of Sec. 4.1 on `reference` ([`curvature_metric`]; expects the
    /// unit-space mesh), wrapped in a field.
    pub fn from_curvature(reference: TriMesh, opts: &MetricOptions) -> Result<Self, MetricError> {
        let metrics = curvature_metric(&reference, opts)?;
        MetricField::new(reference, metrics)
    }

    /// The reference surface.
    pub fn reference(&self) -> &TriMesh {
        &self.reference
    }

    /// The reference surface, shared.
    pub fn shared_reference(&self) -> &Arc<TriMesh> {
        &self.reference
    }

    /// Closest-point queries on the reference surface, sharing this field's BVH.
    pub fn projector(&self) -> SurfaceProjector {
        SurfaceProjector::sharing(Arc::clone(&self.bvh))
    }

    /// This field and `other` share one reference and one BVH.
    pub fn shares_index_with(&self, other: &MetricField) -> bool {
        Arc::ptr_eq(&self.reference, &other.reference) && Arc::ptr_eq(&self.bvh, &other.bvh)
    }

    /// The tensor of every reference vertex, in vertex order.
    pub fn vertex_metrics(&self) -> &[Matrix3<f64>] {
        &self.metrics
    }

    /// Closest point of the reference surface to `p` (exact closest point on the nearest face,
    /// via parry's BVH), as a location (face + barycentric coordinates clamped to the face,
    /// summing to 1) and its position. A non-finite `p` yields a corner of face `f0`.
    pub fn project(&self, p: &Point3<f64>) -> (SurfaceLocation, Point3<f64>) {
        let (proj, (tri, _)) = (self.bvh).project_local_point_and_get_location(to_parry(p), false);
        let face = if (tri as usize) < self.reference.n_faces() {
            FaceId(tri)
        } else {
            FaceId(0)
        };
        let q = Point3::new(proj.point.x, proj.point.y, proj.point.z);
        let bary = barycentric(&q, self.reference.face_points(face));
        let loc = SurfaceLocation { face, bary };
        (loc, loc.position(&self.reference))
    }

    /// Reference faces whose bounding boxes meet the axis-aligned box `[lo, hi]` (parry's
    /// BVH), ascending. Used to find the part of the reference surface under a patch.
    pub fn faces_in_box(&self, lo: &Point3<f64>, hi: &Point3<f64>) -> Vec<FaceId> {
        let aabb = parry3d_f64::bounding_volume::Aabb::new(to_parry(lo), to_parry(hi));
        let mut faces: Vec<FaceId> = self
            .bvh
            .bvh()
            .intersect_aabb(&aabb)
            .filter(|&f| (f as usize) < self.reference.n_faces())
            .map(FaceId)
            .collect();
        faces.sort_unstable();
        faces.dedup();
        faces
    }

    /// The metric at a surface location: `Σ bᵢ Mᵢ` over the face's corners (Sec. 4.1).
    /// Exactly the vertex tensor at a corner (`bary = [1, 0, 0]`).
    pub fn eval_at(&self, loc: &SurfaceLocation) -> Matrix3<f64> {
        let t = self.reference.face(loc.face);
        self.metrics[t[0].idx()] * loc.bary[0]
            + self.metrics[t[1].idx()] * loc.bary[1]
            + self.metrics[t[2].idx()] * loc.bary[2]
    }

    /// The metric at any point: [`MetricField::project`] then [`MetricField::eval_at`].
    pub fn eval(&self, p: &Point3<f64>) -> Matrix3<f64> {
        self.eval_at(&self.project(p).0)
    }

    /// Unit normal of a reference face (zero for a face of zero area).
    pub fn face_normal(&self, f: FaceId) -> Vector3<f64> {
        self.face_normals[f.idx()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_is_send_and_sync() {
        fn check<T: Send + Sync>() {}
        check::<MetricField>();
    }

    #[test]
    fn barycentric_clamps_and_sums_to_one() {
        let t = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ];
        let b = barycentric(&Point3::new(0.25, 0.25, 0.0), t);
        assert!((b[0] - 0.5).abs() < 1e-15 && (b[1] - 0.25).abs() < 1e-15);
        let b = barycentric(&Point3::new(2.0, -1.0, 0.0), t);
        assert!(b.iter().all(|x| *x >= 0.0) && (b.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        let degenerate = [t[0], t[1], Point3::new(2.0, 0.0, 0.0)];
        assert_eq!(
            barycentric(&Point3::new(0.9, 0.0, 0.0), degenerate),
            [0.0, 1.0, 0.0]
        );
    }

    #[test]
    fn fields_with_other_metrics_share_the_reference_and_its_index() {
        let sphere = crate::mesh::generators::icosphere(1.0, 2);
        let n = sphere.n_vertices();
        let field = MetricField::new(sphere, vec![Matrix3::identity(); n]).expect("identity");
        let scaled = field
            .with_metrics(vec![Matrix3::identity() * 4.0; n])
            .expect("scaled identity");
        assert!(field.shares_index_with(&scaled));
        assert_eq!(scaled.vertex_metrics()[0], Matrix3::identity() * 4.0);
        assert_eq!(field.vertex_metrics()[0], Matrix3::identity());
        let p = Point3::new(0.3, 0.2, 2.0);
        assert_eq!(field.project(&p).1, scaled.project(&p).1);
        // The same checks as a new field: the count, and SPD on the tangent plane.
        assert!(matches!(
            field.with_metrics(vec![Matrix3::identity(); n - 1]),
            Err(MetricError::CountMismatch { .. })
        ));
        let mut bad = vec![Matrix3::identity(); n];
        bad[3] = -Matrix3::identity();
        assert!(field.with_metrics(bad).is_err());
    }
}
