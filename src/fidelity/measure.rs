//! Measuring a lifted patch against the reference surface, and scaling the transferred metric
//! up where it deviates.

use crate::ids::VertexId;
use crate::mesh::{bbox_of, parry_trimesh, TriMesh};
use crate::metric::MetricField;
use crate::remesh2d::{PlanarMesh, PlanarMetricField};
use nalgebra::{Matrix2, Point2, Point3, Vector3};
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::TrianglePointLocation;

/// A lifted candidate patch in the planar mesh's numbering: `positions[i]` is the 3D point of
/// planar vertex `i`, `fixed[i]` whether it is a kept patch-boundary vertex.
pub struct LiftedPatch<'a> {
    /// 3D position of every planar vertex.
    pub positions: &'a [Point3<f64>],
    /// Kept (patch boundary) vertices.
    pub fixed: &'a [bool],
    /// The planar triangles (same indices as `positions`).
    pub triangles: &'a [[u32; 3]],
}

/// Triangles of `patch` that are farther than `eps` from the reference surface, with their
/// largest measured distance, in ascending triangle order.
///
/// Two directions, as the two-sided Hausdorff distance of the yardstick:
/// - patch → reference: the centroid and the midpoints of the edges that are not between two
///   fixed vertices (those edges cannot change) are projected onto the reference;
/// - reference → patch: every reference vertex in the patch's bounding box (grown by its
///   longest edge) is projected onto the patch; it counts for the triangle it lands in unless
///   it lands on a fixed vertex or on an edge between two fixed vertices (then it lies beyond
///   the patch boundary, under a neighbouring part of the mesh), the triangle faces away
///   from the vertex's normal by more than 120° (the other side of a thin part) or the distance exceeds the
///   triangle's longest edge (another part of the surface).
///
/// Triangles with an edge between two fixed vertices are not measured (see below).
pub fn deviations(
    field: &MetricField,
    normals: &[Vector3<f64>],
    patch: &LiftedPatch<'_>,
    eps: f64,
) -> Vec<(usize, f64)> {
    let reference = field.reference();
    let mut worst = vec![0.0f64; patch.triangles.len()];
    let p = |i: u32| patch.positions[i as usize];
    let fixed = |i: u32| patch.fixed[i as usize];
    let mut longest = 0.0f64;
    // A triangle with an edge between two fixed vertices lies against the patch boundary:
    // its deviation may come from that boundary edge, which this patch cannot change (a
    // later, overlapping patch can), so it is not measured.
    let on_boundary: Vec<bool> = patch
        .triangles
        .iter()
        .map(|t| (0..3).any(|k| fixed(t[k]) && fixed(t[(k + 1) % 3])))
        .collect();
    let edge_max: Vec<f64> = patch
        .triangles
        .iter()
        .map(|tri| {
            let [a, b, c] = tri.map(p);
            (b - a).norm().max((c - b).norm()).max((a - c).norm())
        })
        .collect();
    for (t, tri) in patch.triangles.iter().enumerate() {
        longest = longest.max(edge_max[t]);
        if on_boundary[t] {
            continue;
        }
        let [a, b, c] = tri.map(p);
        let mut samples = vec![Point3::from((a.coords + b.coords + c.coords) / 3.0)];
        for k in 0..3 {
            let (u, v) = (tri[k], tri[(k + 1) % 3]);
            if !(fixed(u) && fixed(v)) {
                samples.push(Point3::from((p(u).coords + p(v).coords) * 0.5));
            }
        }
        for s in samples {
            let (_, q) = field.project(&s);
            worst[t] = worst[t].max((q - s).norm());
        }
    }

    // reference → patch
    if let (Some((lo, hi)), Some(bvh)) = (
        bbox_of(patch.positions.iter().copied()),
        parry_trimesh(patch.positions, patch.triangles.to_vec()),
    ) {
        let grow = Vector3::repeat(longest);
        let mut ref_vertices: Vec<VertexId> = field
            .faces_in_box(&(lo - grow), &(hi + grow))
            .into_iter()
            .flat_map(|f| reference.face(f))
            .collect();
        ref_vertices.sort_unstable();
        ref_vertices.dedup();
        for r in ref_vertices {
            let x = reference.positions[r.idx()];
            let (proj, (t, loc)) =
                bvh.project_local_point_and_get_location(PVec::new(x.x, x.y, x.z), false);
            let t = t as usize;
            let Some(tri) = patch.triangles.get(t) else {
                continue;
            };
            if on_boundary[t] {
                continue;
            }
            let beyond = match loc {
                TrianglePointLocation::OnVertex(i) => fixed(tri[i as usize % 3]),
                // parry's edge numbering: 0 = AB, 1 = BC, 2 = AC.
                TrianglePointLocation::OnEdge(e, _) => {
                    let (u, v) = match e {
                        0 => (tri[0], tri[1]),
                        1 => (tri[1], tri[2]),
                        _ => (tri[0], tri[2]),
                    };
                    fixed(u) && fixed(v)
                }
                _ => false,
            };
            if beyond {
                continue;
            }
            let [a, b, c] = tri.map(p);
            // The other side of a thin part faces the opposite way (cosine near -1); a vertex
            // on a rim or tip that the patch cuts off meets it at about 90°, and counts.
            let nt = (b - a).cross(&(c - a));
            let nr = normals[r.idx()];
            if nt.dot(&nr) <= -0.5 * nt.norm() * nr.norm() {
                continue;
            }
            let q = Point3::new(proj.point.x, proj.point.y, proj.point.z);
            let d = (q - x).norm();
            // A triangle that cuts off a tip or a crease is at most about its own size away
            // from it; farther reference vertices belong to another part of the surface.
            if d <= edge_max[t] {
                worst[t] = worst[t].max(d);
            }
        }
    }
    worst
        .into_iter()
        .enumerate()
        .filter(|&(_, d)| d > eps)
        .collect()
}

/// The bounds of [`scale_metric`].
#[derive(Copy, Clone, Debug)]
pub struct ScaleLimits {
    /// The tolerance the deviations are measured against.
    pub eps: f64,
    /// Largest factor of one round.
    pub max_factor: f64,
    /// Target metric edge length.
    pub l_tar: f64,
    /// No tensor is scaled beyond a shortest edge `l_tar/√λ_max` of this length.
    pub min_edge: f64,
}

/// Scale the transferred metric (one tensor per vertex of the initial 2D mesh) up around the
/// deviating triangles of `planar`: the vertices of the initial triangles under a deviating
/// triangle (its corners and centroid, located exactly) get the factor `(d/eps)²` (the
/// distance of a cut-off tip or crease shrinks linearly with the edge length, a smooth
/// sagitta quadratically; the square covers both), capped at `max_factor`; their neighbours
/// in the initial mesh get its square root, a one-ring gradation. No tensor is scaled beyond
/// a shortest edge `l_tar/√λ_max` of `min_edge`. Returns how many tensors were scaled.
pub fn scale_metric(
    metrics: &mut [Matrix2<f64>],
    field: &PlanarMetricField,
    planar: &PlanarMesh,
    deviating: &[(usize, f64)],
    limits: &ScaleLimits,
) -> usize {
    let ScaleLimits {
        eps,
        max_factor,
        l_tar,
        min_edge,
    } = *limits;
    let mut factor = vec![1.0f64; metrics.len()];
    let init = field.triangles();
    for &(t, d) in deviating {
        let s = (d / eps).powi(2).clamp(1.0, max_factor);
        let Some(tri) = planar.triangles.get(t) else {
            continue;
        };
        let corners = tri.map(|i| planar.points[i as usize]);
        let centroid =
            Point2::from((corners[0].coords + corners[1].coords + corners[2].coords) / 3.0);
        for q in corners.iter().chain(std::iter::once(&centroid)) {
            if let Some((it, _)) = field.locate(q) {
                for v in init[it] {
                    factor[v as usize] = factor[v as usize].max(s);
                }
            }
        }
    }
    // One ring of gradation.
    let mut graded = factor.clone();
    for t in init {
        let m = t.iter().map(|&v| factor[v as usize]).fold(1.0, f64::max);
        for &v in t {
            graded[v as usize] = graded[v as usize].max(m.sqrt());
        }
    }
    // Cap: the scaled tensor's shortest edge l_tar/√λ_max stays ≥ min_edge.
    let lmax_allowed = (l_tar / min_edge).powi(2);
    let mut n = 0;
    for (m, f) in metrics.iter_mut().zip(graded) {
        let lmax = m.symmetric_eigenvalues().max();
        let f = f.min(lmax_allowed / lmax);
        if f > 1.0 {
            *m *= f;
            n += 1;
        }
    }
    n
}

/// The a-priori factors of [`super::a_priori_scale`] carried onto the vertices of a patch of the
/// working mesh. The transferred metric is sampled only at the patch's vertices; once earlier
/// patches have replaced the input there, no patch vertex may sit on a tip or rim whose
/// factor is large, and the interpolated factor misses it. So every reference vertex with a
/// factor above 1 that lies in the patch's box is projected onto the patch, and the corners
/// of the face it lands on (within that face's longest edge, else it belongs to another part
/// of the surface) take at least its factor. Returns one factor per patch vertex (≥ 1).
pub fn patch_vertex_factors(field: &MetricField, scale: &[f64], patch: &TriMesh) -> Vec<f64> {
    let mut out = vec![1.0f64; patch.n_vertices()];
    let Some((lo, hi)) = bbox_of(patch.positions.iter().copied()) else {
        return out;
    };
    let reference = field.reference();
    let mut high: Vec<VertexId> = field
        .faces_in_box(&lo, &hi)
        .into_iter()
        .flat_map(|f| reference.face(f))
        .filter(|v| scale.get(v.idx()).is_some_and(|&s| s > 1.0))
        .collect();
    if high.is_empty() {
        return out;
    }
    high.sort_unstable();
    high.dedup();
    let tris: Vec<[u32; 3]> = patch.index_triangles();
    let Some(bvh) = parry_trimesh(&patch.positions, tris) else {
        return out;
    };
    for r in high {
        let x = reference.positions[r.idx()];
        let (proj, (t, _)) =
            bvh.project_local_point_and_get_location(PVec::new(x.x, x.y, x.z), false);
        let Some(tri) = patch.triangles.get(t as usize) else {
            continue;
        };
        let [a, b, c] = patch.face_points(crate::ids::FaceId(t));
        let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
        let q = Point3::new(proj.point.x, proj.point.y, proj.point.z);
        if (q - x).norm() > longest {
            continue;
        }
        for v in tri {
            out[v.idx()] = out[v.idx()].max(scale[r.idx()]);
        }
    }
    out
}
