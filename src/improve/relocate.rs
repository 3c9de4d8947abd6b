//! The vertex position update on the surface: vertices moved towards the point that makes
//! their faces equilateral in the metric (or their neighbours' centroid) and projected back
//! onto the reference, each move a certified candidate.

use super::geometry::{metric_optimal_point, point_triangle_distance};
use super::SurfaceContext;
use crate::ids::VertexId;
use crate::invariants::{candidate_embedded_local, is_degenerate_triangle, FaceGrid};
use crate::mesh::{bbox_of, SurfaceLocation, Topology, TriMesh};
use crate::stitch::WorkingMesh;
use nalgebra::{Matrix3, Point3, Vector3};

/// The vertex position update (Sec. 3.4) on the surface, after the loop: every vertex off the input boundary is
/// moved towards the centroid of its neighbours (full, half or quarter step) and projected
/// onto the reference (its location follows), when the smallest metric quality of its faces
/// rises, its new faces pass the candidate certificates (not degenerate, not flipped, locally
/// embedded), and no watched point — its old position and the corners of the reference faces
/// under it and its neighbours — ends farther from the fan than `tol` unless it already was,
/// and then not farther than before (tips and creases are not cut off). Three sweeps over the
/// vertices. The seams between patches are where this matters: their vertices were fixed
/// patch-boundary vertices. Returns the number of moves.
pub fn vertex_position_update(ctx: &SurfaceContext<'_>, work: &mut WorkingMesh) -> usize {
    let SurfaceContext {
        field,
        flip_test,
        embedded_input,
        tol,
        pinned: corners,
        ..
    } = *ctx;
    use crate::quality::{face_metric, triangle_quality};
    let topo = Topology::build(&work.mesh);
    let mut metrics: Vec<Matrix3<f64>> = work.locations.iter().map(|l| field.eval_at(l)).collect();
    let mut moved = 0;
    let mut grid = FaceGrid::new(&work.mesh);
    // `settled[v]`: no candidate of v improved its fan at its last visit and nothing in its
    // closed 1-ring has moved since, so the same candidates would score the same again.
    let mut settled = vec![false; work.mesh.n_vertices()];
    for _pass in 0..3 {
        for vi in 0..work.mesh.n_vertices() {
            let v = VertexId::new(vi);
            let fan = topo.vertex_faces(v);
            if settled[vi]
                || fan.is_empty()
                || topo.is_boundary_vertex(v)
                || corners.get(vi).copied().unwrap_or(false)
            {
                continue;
            }
            let fan_q = |mesh: &TriMesh, metrics: &[Matrix3<f64>]| {
                fan.iter()
                    .map(|f| {
                        let t = mesh.triangles[f.idx()];
                        triangle_quality(
                            t.map(|u| mesh.positions[u.idx()]),
                            &face_metric(metrics, t),
                        )
                        .q
                    })
                    .fold(f64::INFINITY, f64::min)
            };
            let before = fan_q(&work.mesh, &metrics);
            let nbrs = topo.vertex_neighbors(v);
            let old = work.mesh.positions[vi];
            let c = nbrs.iter().fold(Vector3::zeros(), |acc, u| {
                acc + work.mesh.positions[u.idx()].coords
            }) / nbrs.len() as f64;
            let mut accepted = false;
            // Targets: the metric-optimal point (full and half step), then the centroid
            // (full, half, quarter step); tried best first by the fan's smallest quality.
            let mut targets: Vec<Point3<f64>> = Vec::with_capacity(5);
            if let Some(opt) = metric_optimal_point(&work.mesh, fan, v, &metrics[vi]) {
                targets.push(opt);
                targets.push(Point3::from((old.coords + opt.coords) * 0.5));
            }
            for step in [1.0, 0.5, 0.25] {
                targets.push(Point3::from(old.coords + (c - old.coords) * step));
            }
            let old_loc = work.locations[vi];
            let old_m = metrics[vi];
            let mut scored: Vec<(f64, SurfaceLocation, Point3<f64>)> = targets
                .iter()
                .map(|target| {
                    let (loc, p) = field.project(target);
                    work.mesh.positions[vi] = p;
                    metrics[vi] = field.eval_at(&loc);
                    (fan_q(&work.mesh, &metrics), loc, p)
                })
                .filter(|(q, _, _)| *q > before)
                .collect();
            work.mesh.positions[vi] = old;
            metrics[vi] = old_m;
            scored.sort_by(|a, b| b.0.total_cmp(&a.0));
            if scored.is_empty() {
                settled[vi] = true;
                continue;
            }
            // Reference vertices under the fan (corners of the reference faces at the fan's
            // vertices' locations) and their distance to the fan now: no move may push one
            // of them farther than `tol` away unless it already was (then not farther).
            let mut watch: Vec<Point3<f64>> = std::iter::once(v)
                .chain(nbrs.iter().copied())
                .flat_map(|u| field.reference().face(work.locations[u.idx()].face))
                .map(|r| field.reference().positions[r.idx()])
                .collect();
            watch.push(old);
            let fan_dist = |mesh: &TriMesh, x: &Point3<f64>| {
                fan.iter()
                    .map(|f| {
                        let t = mesh.triangles[f.idx()].map(|u| mesh.positions[u.idx()]);
                        point_triangle_distance(x, &t)
                    })
                    .fold(f64::INFINITY, f64::min)
            };
            let watch_before: Vec<f64> = watch.iter().map(|x| fan_dist(&work.mesh, x)).collect();
            for (_, loc, p) in scored {
                work.mesh.positions[vi] = p;
                work.locations[vi] = loc;
                metrics[vi] = field.eval_at(&loc);
                let tris: Vec<[Point3<f64>; 3]> = fan
                    .iter()
                    .map(|f| work.mesh.triangles[f.idx()].map(|u| work.mesh.positions[u.idx()]))
                    .collect();
                let mut ok = tris
                    .iter()
                    .all(|t| !is_degenerate_triangle(t) && !flip_test.is_flipped_anywhere(t))
                    && watch.iter().zip(&watch_before).all(|(x, b)| {
                        let d = fan_dist(&work.mesh, x);
                        d <= b.max(tol)
                    });
                if ok && embedded_input {
                    let new_tris: Vec<[VertexId; 3]> =
                        fan.iter().map(|f| work.mesh.triangles[f.idx()]).collect();
                    ok = candidate_embedded_local(&work.mesh, &grid, fan, &new_tris);
                }
                if ok {
                    for (f, t) in fan.iter().zip(&tris) {
                        if let Some((lo, hi)) = bbox_of(t.iter().copied()) {
                            grid.insert(f.idx(), &lo, &hi);
                        }
                    }
                    accepted = true;
                    break;
                }
                work.mesh.positions[vi] = old;
                work.locations[vi] = old_loc;
                metrics[vi] = old_m;
            }
            if accepted {
                moved += 1;
                settled[vi] = false;
                for u in &nbrs {
                    settled[u.idx()] = false;
                }
            }
        }
    }
    moved
}
