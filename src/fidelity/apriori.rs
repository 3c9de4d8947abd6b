//! The a-priori fidelity scaling, from the input's geometry before the loop.

use crate::ids::VertexId;
use crate::mesh::TriMesh;

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
    let normals = reference.area_weighted_normals();
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
    // Gradation: a factor may exceed a neighbour's by at most GRADE².
    crate::mesh::grade_factors(reference, &mut s, GRADE * GRADE, 8);
    s
}
