//! Geometric fidelity of a remeshed patch (our addition to Algorithm 1; paper-notes.md,
//! "Fidelity control").
//!
//! The curvature metric of Sec. 3.1 bounds the chord error only where the estimated curvature
//! is right: with `M = diag(|k₁|, |k₂|)` an edge of metric length `L` has physical length
//! `L/√|k|` and sagitta `|k|·ℓ²/8 = L²/8`, the same everywhere. At sharp tips, rims and
//! creases the quadric fit over a few rings underestimates `|k|` and the remeshed patch cuts
//! them off. This module measures, for a lifted candidate patch, how far it is from the
//! reference surface in both directions, triangle by triangle, and scales the transferred
//! metric up where a triangle deviates by more than the tolerance, so that the planar
//! remesher makes smaller triangles there. The scaling is isotropic (a scalar factor on the
//! tensor), so the triangles keep the metric's anisotropy and their shape quality in it.

use crate::ids::VertexId;
use crate::mesh::TriMesh;
use crate::metric::MetricField;
use crate::quality::parry_trimesh;
use crate::remesh2d::{PlanarMesh, PlanarMetricField};
use nalgebra::{Matrix2, Point2, Point3, Vector3};
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::TrianglePointLocation;
use serde::Serialize;

/// Options of the fidelity control.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FidelityOptions {
    /// Largest accepted distance between a patch and the reference surface, in unit space
    /// (i.e. relative to the input's bounding-box diagonal). `0` disables the control.
    pub max_deviation: f64,
    /// Remeshing rounds after the first one, at most.
    pub rounds: usize,
    /// Largest factor by which one round scales a vertex tensor.
    pub max_factor: f64,
    /// No scaling makes the metric's shortest edge shorter than this fraction of the input's
    /// mean edge length: the input is piecewise linear, and triangles much finer than its
    /// own follow it no better (on a flat plate with sharp rims they only multiply).
    pub min_edge_ratio: f64,
    /// Keep, per working-mesh vertex, the factor a patch's extra rounds scaled the metric by,
    /// so a later patch over the same area (its overlap rings, a further sweep) starts from
    /// that refinement instead of the a-priori metric. Default `false` (each patch starts
    /// afresh); the coarse-input profile turns it on.
    pub persist: bool,
}

impl Default for FidelityOptions {
    fn default() -> Self {
        FidelityOptions {
            max_deviation: 0.0035,
            rounds: 2,
            max_factor: 16.0,
            min_edge_ratio: 0.5,
            persist: false,
        }
    }
}

/// Area-weighted vertex normals of `mesh` (unnormalised; zero on isolated vertices).
pub fn vertex_normals(mesh: &TriMesh) -> Vec<Vector3<f64>> {
    let mut n = vec![Vector3::zeros(); mesh.n_vertices()];
    for t in &mesh.triangles {
        let [a, b, c] = [t[0], t[1], t[2]].map(|v| mesh.positions[v.idx()]);
        let fnrm = (b - a).cross(&(c - a));
        for v in t {
            n[v.idx()] += fnrm;
        }
    }
    n
}

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
        bbox(patch.positions),
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

fn bbox(points: &[Point3<f64>]) -> Option<(Point3<f64>, Point3<f64>)> {
    let first = points.first()?;
    Some(
        points
            .iter()
            .fold((*first, *first), |(lo, hi), q| (lo.inf(q), hi.sup(q))),
    )
}

/// Scale the transferred metric (one tensor per vertex of the initial 2D mesh) up around the
/// deviating triangles of `planar`: the vertices of the initial triangles under a deviating
/// triangle (its corners and centroid, located exactly) get the factor `(d/eps)²` (the
/// distance of a cut-off tip or crease shrinks linearly with the edge length, a smooth
/// sagitta quadratically; the square covers both), capped at `max_factor`; their neighbours
/// in the initial mesh get its square root, a one-ring gradation. No tensor is scaled beyond
/// a shortest edge `l_tar/√λ_max` of `min_edge`. Returns how many tensors were scaled.
#[allow(clippy::too_many_arguments)]
pub fn scale_metric(
    metrics: &mut [Matrix2<f64>],
    field: &PlanarMetricField,
    planar: &PlanarMesh,
    deviating: &[(usize, f64)],
    eps: f64,
    max_factor: f64,
    l_tar: f64,
    min_edge: f64,
) -> usize {
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

/// A-priori fidelity scaling of the vertex metrics (our addition; paper-notes.md "Fidelity
/// control"): the factor `s(v) ≥ 1` by which `M(v)` is multiplied so that the part of the
/// reference surface a triangle of metric size `l_tar` around `v` would span rises at most
/// `4·eps` above `v`'s tangent plane.
///
/// For a smooth surface this height is `|k|ℓ²/2` over a radius `ℓ`, four times the sagitta
/// `|k|ℓ²/8` of a chord of length `ℓ`, so `4·eps` bounds the chord error by `eps` wherever
/// the curvature fit is right (and does not scale there); at a tip, rim or crease that the
/// fit smooths away the height is measured, not estimated. The neighbourhood is the set of
/// vertices reached by a breadth-first walk over mesh edges that stays inside the ball of
/// radius `r = l_tar/√λ_max(M(v))` (the metric's shortest edge, at most 5 % of the
/// diagonal; at most 400 vertices) and below the height bound; the factor is `(r / d)²` (at
/// most 25) for the distance `d` of the nearest point, on the edges leaving the walked
/// vertices towards a vertex whose normal is within 60° of `v`'s, where the surface rises
/// above `4·eps`, i.e. the ball shrinks until it excludes
/// it; never beyond the factor that would make the shortest edge shorter than `min_edge`. Factors are then graded so that neighbours
/// differ by at most `grade²` (a size ratio of `grade` per edge).
pub fn a_priori_scale(
    reference: &TriMesh,
    topo: &crate::mesh::Topology,
    metrics: &[nalgebra::Matrix3<f64>],
    l_tar: f64,
    eps: f64,
    min_edge: f64,
) -> Vec<f64> {
    use rayon::prelude::*;
    const MAX_VISIT: usize = 400;
    const GRADE: f64 = 1.2;
    // Unit space (bounding-box diagonal 1).
    const MAX_RADIUS: f64 = 0.05;
    const MAX_FACTOR: f64 = 25.0;
    let normals = vertex_normals(reference);
    let n = reference.n_vertices();
    let height_max = 4.0 * eps;
    let mut s: Vec<f64> = (0..n)
        .into_par_iter()
        .map(|vi| {
            let v = VertexId::new(vi);
            let nv = normals[vi];
            let nn = nv.norm();
            if nn.is_nan() || nn <= 0.0 || topo.vertex_faces(v).is_empty() {
                return 1.0;
            }
            let nv = nv / nn;
            // The ball's radius is the metric's shortest edge, l_tar / √λ_max: across the
            // direction of strongest curvature, where tips, rims and creases are cut; the
            // long axis of an anisotropic metric follows the weak curvature by design.
            let lmax = metrics[vi].symmetric_eigenvalues().max();
            if lmax.is_nan() || lmax <= 0.0 {
                return 1.0;
            }
            // Where the curvature is at its floor (flat parts) the nominal edge is longer than
            // the model; patches bound the real triangles long before, so the ball is capped.
            let radius = (l_tar / lmax.sqrt()).min(MAX_RADIUS);
            let x0 = reference.positions[vi];
            let mut seen = std::collections::HashSet::from([v]);
            let mut queue = std::collections::VecDeque::from([v]);
            let mut nearest_high = f64::INFINITY;
            // Heights are linear along an edge, so the surface first rises above `height_max`
            // on an edge (u, w) leaving a vertex u that is still below it at the parameter
            // t = (height_max − |h_u|) / (|h_w| − |h_u|) (in the direction of w's sign).
            while let Some(u) = queue.pop_front() {
                let du = reference.positions[u.idx()] - x0;
                let hu = du.dot(&nv);
                for w in topo.vertex_neighbors(u) {
                    let dw = reference.positions[w.idx()] - x0;
                    let hw = dw.dot(&nv);
                    // Only where the surface still faces v's way (normals within 60°): past a
                    // crease the surface turns away, and triangles that end on the crease
                    // follow it exactly, so it is no reason to refine v.
                    let nw = normals[w.idx()];
                    let facing = nw.dot(&nv) >= 0.5 * nw.norm();
                    if hw.abs() > height_max && facing {
                        let target = height_max.copysign(hw);
                        let t = ((target - hu) / (hw - hu)).clamp(0.0, 1.0);
                        let d = (du + (dw - du) * t).norm();
                        if d <= radius {
                            nearest_high = nearest_high.min(d);
                        }
                        continue;
                    }
                    if dw.norm() > radius || seen.len() >= MAX_VISIT || !seen.insert(w) {
                        continue;
                    }
                    queue.push_back(w);
                }
            }
            if nearest_high.is_finite() && nearest_high > 0.0 {
                let cap = (radius / min_edge).powi(2).clamp(1.0, MAX_FACTOR);
                return (radius / nearest_high).powi(2).min(cap);
            }
            1.0
        })
        .collect();
    // Gradation: a factor may exceed a neighbour's by at most GRADE² (Jacobi passes, so the
    // result does not depend on the vertex order).
    for _ in 0..8 {
        let prev = s.clone();
        let mut changed = false;
        for t in &reference.triangles {
            let m = t.iter().map(|v| prev[v.idx()]).fold(1.0, f64::max) / (GRADE * GRADE);
            for v in t {
                if s[v.idx()] < m {
                    s[v.idx()] = m;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    s
}

/// The a-priori factors of [`a_priori_scale`] carried onto the vertices of a patch of the
/// working mesh. The transferred metric is sampled only at the patch's vertices; once earlier
/// patches have replaced the input there, no patch vertex may sit on a tip or rim whose
/// factor is large, and the interpolated factor misses it. So every reference vertex with a
/// factor above 1 that lies in the patch's box is projected onto the patch, and the corners
/// of the face it lands on (within that face's longest edge, else it belongs to another part
/// of the surface) take at least its factor. Returns one factor per patch vertex (≥ 1).
pub fn patch_vertex_factors(field: &MetricField, scale: &[f64], patch: &TriMesh) -> Vec<f64> {
    let mut out = vec![1.0f64; patch.n_vertices()];
    let Some((lo, hi)) = bbox(&patch.positions) else {
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
    let tris: Vec<[u32; 3]> = patch
        .triangles
        .iter()
        .map(|t| [t[0].0, t[1].0, t[2].0])
        .collect();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{generators, Topology};
    use crate::metric::{MetricField, MetricOptions, Normalization};

    /// A flat disk of radius 0.5 in z = 0 with its centre vertex raised to `height`: a tent
    /// whose apex a coarse remesh would cut off.
    fn tent(height: f64) -> TriMesh {
        let mut m = generators::disk(0.5, 8, 24);
        let c = (0..m.n_vertices())
            .min_by(|&a, &b| {
                m.positions[a]
                    .coords
                    .norm()
                    .total_cmp(&m.positions[b].coords.norm())
            })
            .expect("vertices");
        m.positions[c].z = height;
        m
    }

    fn field(m: &TriMesh) -> MetricField {
        MetricField::from_curvature(Normalization::of(m).apply(m), &MetricOptions::default())
            .expect("metric")
    }

    #[test]
    fn smooth_sphere_needs_no_scaling_unless_the_target_is_too_coarse() {
        let sphere = generators::icosphere(1.0, 4);
        let m = Normalization::of(&sphere).apply(&sphere);
        let f = field(&m);
        let topo = Topology::build(&m);
        // Unit space: r = 1/(2√3) (the bbox diagonal of the unit sphere is 2√3), k = 1/r.
        // Over the ball of radius ℓ = L/√k (< 0.05, the cap) the sphere rises k ℓ²/2 = L²/2
        // above a tangent plane: with L = 0.09 that is 0.00405, below 4·eps for eps = 0.002
        // and above it for eps = 0.0008.
        let fine = a_priori_scale(&m, &topo, f.vertex_metrics(), 0.09, 0.002, 1e-6);
        assert!(fine.iter().all(|&s| s == 1.0));
        let coarse = a_priori_scale(&m, &topo, f.vertex_metrics(), 0.09, 0.0008, 1e-6);
        assert!(coarse.iter().all(|&s| s > 1.0));
    }

    #[test]
    fn a_tent_apex_is_refined_and_the_far_plane_is_not() {
        let m = Normalization::of(&tent(0.3)).apply(&tent(0.3));
        let f = field(&m);
        let topo = Topology::build(&m);
        let s = a_priori_scale(&m, &topo, f.vertex_metrics(), 0.3, 0.005, 1e-6);
        let apex = (0..m.n_vertices())
            .max_by(|&a, &b| m.positions[a].z.total_cmp(&m.positions[b].z))
            .expect("vertices");
        assert!(s[apex] > 4.0, "apex factor {}", s[apex]);
        // Vertices on the outer ring lie in the plane far from the apex.
        let far: Vec<usize> = (0..m.n_vertices())
            .filter(|&v| (m.positions[v] - m.positions[apex]).xy().norm() > 0.3)
            .collect();
        assert!(!far.is_empty());
        assert!(far.iter().all(|&v| s[v] < s[apex]));
        // Gradation: neighbours differ by at most 1.2² (Jacobi passes may stop early only
        // when nothing changes).
        for t in &m.triangles {
            for a in t {
                for b in t {
                    assert!(s[a.idx()] <= s[b.idx()] * 1.44 + 1e-12);
                }
            }
        }
    }

    #[test]
    fn deviations_see_a_cut_off_apex_and_nothing_on_the_reference_itself() {
        // Apex height (unit space 0.035) below the spoke length (0.044): the cut-off apex is
        // closer to the patch than the patch's longest edge, so it counts.
        let reference = tent(0.05);
        let f = field(&reference);
        let unit = f.reference().clone();
        let normals = vertex_normals(&unit);
        let boundary: std::collections::HashSet<VertexId> = Topology::build(&unit)
            .boundary_loops()
            .iter()
            .flatten()
            .copied()
            .collect();
        let fixed: Vec<bool> = (0..unit.n_vertices())
            .map(|v| boundary.contains(&VertexId::new(v)))
            .collect();
        let tris: Vec<[u32; 3]> = unit
            .triangles
            .iter()
            .map(|t| [t[0].0, t[1].0, t[2].0])
            .collect();
        let same = deviations(
            &f,
            &normals,
            &LiftedPatch {
                positions: &unit.positions,
                fixed: &fixed,
                triangles: &tris,
            },
            1e-9,
        );
        assert!(same.is_empty(), "{same:?}");
        // The same connectivity with the apex pushed down into the plane: the apex is cut off
        // by the full tent height (in unit space).
        let mut cut = unit.positions.clone();
        let apex = (0..cut.len())
            .max_by(|&a, &b| cut[a].z.total_cmp(&cut[b].z))
            .expect("vertices");
        let h = cut[apex].z - cut[(apex + 1) % cut.len()].z;
        cut[apex].z -= h;
        let dev = deviations(
            &f,
            &normals,
            &LiftedPatch {
                positions: &cut,
                fixed: &fixed,
                triangles: &tris,
            },
            0.01,
        );
        assert!(!dev.is_empty());
        let worst = dev.iter().map(|d| d.1).fold(0.0, f64::max);
        assert!(
            (worst - h).abs() < 1e-9 * h.max(1.0) || worst <= h,
            "worst {worst}, h {h}"
        );
        assert!(worst > 0.5 * h, "worst {worst}, h {h}");
        // Every deviating triangle touches the apex's neighbourhood.
        for (t, _) in &dev {
            let near = tris[*t]
                .iter()
                .any(|&v| (cut[v as usize] - cut[apex]).xy().norm() < 0.2);
            assert!(near, "triangle {t} far from the apex");
        }
    }

    #[test]
    fn patch_vertices_take_the_factor_of_the_reference_vertex_beneath() {
        let reference = tent(0.0); // flat
        let f = field(&reference);
        let unit = f.reference().clone();
        let mut scale = vec![1.0; unit.n_vertices()];
        let hot = 5;
        scale[hot] = 9.0;
        let out = patch_vertex_factors(&f, &scale, &unit);
        // On the reference itself the hot vertex projects onto one of its own faces.
        assert_eq!(out[hot], 9.0);
        let touched = out.iter().filter(|&&s| s == 9.0).count();
        assert!((1..=3).contains(&touched) || touched == 3, "{touched}");
        assert!(out.iter().all(|&s| s == 1.0 || s == 9.0));
    }
}
