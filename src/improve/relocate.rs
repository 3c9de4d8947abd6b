//! The vertex position update on the surface: vertices moved towards the point that makes
//! their faces equilateral in the metric (or their neighbours' centroid) and projected back
//! onto the reference, each move a certified candidate.

use super::geometry::{metric_optimal_point, point_triangle_distance};
use super::SurfaceContext;
use crate::ids::{FaceId, VertexId};
use crate::invariants::{candidate_embedded_local, is_degenerate_triangle, FaceGrid};
use crate::mesh::{bbox_of, SurfaceLocation, Topology, TriMesh};
use crate::quality::{face_metric, triangle_quality};
use crate::stitch::WorkingMesh;
use nalgebra::{Matrix3, Point3, Vector3};

/// The vertex position update (Sec. 3.4) on the surface, after the loop: every vertex off the
/// input boundary is moved towards the point that makes its faces equilateral in the metric
/// (full or half step, [`super::geometry`]'s metric-optimal point) or towards the centroid of
/// its neighbours (full, half or quarter step), best first, and projected
/// onto the reference (its location follows), when the smallest metric quality of its faces
/// rises, its new faces pass the candidate certificates (not degenerate, not flipped, locally
/// embedded), and no watched point — its old position and the corners of the reference faces
/// under it and its neighbours — ends farther from the fan than `tol` unless it already was,
/// and then not farther than before (tips and creases are not cut off). Three sweeps over the
/// vertices. The seams between patches are where this matters: their vertices were fixed
/// patch-boundary vertices. Returns the number of moves.
pub fn vertex_position_update(ctx: &SurfaceContext<'_>, work: &mut WorkingMesh) -> usize {
    let topo = Topology::build(&work.mesh);
    let metrics: Vec<Matrix3<f64>> = work
        .locations
        .iter()
        .map(|l| ctx.field.eval_at(l))
        .collect();
    let mut state = Relocation {
        grid: FaceGrid::new(&work.mesh),
        metrics,
        settled: vec![false; work.mesh.n_vertices()],
    };
    let mut moved = 0;
    for _pass in 0..3 {
        for vi in 0..work.mesh.n_vertices() {
            let v = VertexId::new(vi);
            if state.settled[vi]
                || topo.vertex_faces(v).is_empty()
                || topo.is_boundary_vertex(v)
                || ctx.pinned.get(vi).copied().unwrap_or(false)
            {
                continue;
            }
            if relocate(ctx, &topo, work, &mut state, v) {
                moved += 1;
                state.settled[vi] = false;
                for u in topo.vertex_neighbors(v) {
                    state.settled[u.idx()] = false;
                }
            }
        }
    }
    moved
}

/// What the relocation keeps between vertices.
struct Relocation {
    /// Faces by bounding box, for the local self-intersection checks.
    grid: FaceGrid,
    /// The metric at every vertex's location.
    metrics: Vec<Matrix3<f64>>,
    /// `settled[v]`: no candidate of v improved its fan at its last visit and nothing in its
    /// closed 1-ring has moved since, so the same candidates would score the same again.
    settled: Vec<bool>,
}

/// The smallest metric quality of the faces `fan`.
fn fan_quality(mesh: &TriMesh, metrics: &[Matrix3<f64>], fan: &[FaceId]) -> f64 {
    fan.iter()
        .map(|f| {
            let t = mesh.triangles[f.idx()];
            triangle_quality(t.map(|u| mesh.positions[u.idx()]), &face_metric(metrics, t)).q
        })
        .fold(f64::INFINITY, f64::min)
}

/// Distance from `x` to the nearest face of `fan`.
fn fan_distance(mesh: &TriMesh, fan: &[FaceId], x: &Point3<f64>) -> f64 {
    fan.iter()
        .map(|f| {
            let t = mesh.triangles[f.idx()].map(|u| mesh.positions[u.idx()]);
            point_triangle_distance(x, &t)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Try to move `v`: the candidate positions that raise its fan's smallest quality, best
/// first, until one passes the certificates. Returns whether `v` moved (else it is settled
/// when no candidate scored better).
fn relocate(
    ctx: &SurfaceContext<'_>,
    topo: &Topology,
    work: &mut WorkingMesh,
    state: &mut Relocation,
    v: VertexId,
) -> bool {
    let vi = v.idx();
    let fan = topo.vertex_faces(v);
    let nbrs = topo.vertex_neighbors(v);
    let before = fan_quality(&work.mesh, &state.metrics, fan);
    let old = work.mesh.positions[vi];
    let c = nbrs.iter().fold(Vector3::zeros(), |acc, u| {
        acc + work.mesh.positions[u.idx()].coords
    }) / nbrs.len() as f64;
    // Targets: the metric-optimal point (full and half step), then the centroid (full,
    // half, quarter step); tried best first by the fan's smallest quality.
    let mut targets: Vec<Point3<f64>> = Vec::with_capacity(5);
    if let Some(opt) = metric_optimal_point(&work.mesh, fan, v, &state.metrics[vi]) {
        targets.push(opt);
        targets.push(Point3::from((old.coords + opt.coords) * 0.5));
    }
    for step in [1.0, 0.5, 0.25] {
        targets.push(Point3::from(old.coords + (c - old.coords) * step));
    }
    let old_loc = work.locations[vi];
    let old_m = state.metrics[vi];
    let mut scored: Vec<(f64, SurfaceLocation, Point3<f64>)> = targets
        .iter()
        .map(|target| {
            let (loc, p) = ctx.field.project(target);
            work.mesh.positions[vi] = p;
            state.metrics[vi] = ctx.field.eval_at(&loc);
            (fan_quality(&work.mesh, &state.metrics, fan), loc, p)
        })
        .filter(|(q, _, _)| *q > before)
        .collect();
    work.mesh.positions[vi] = old;
    state.metrics[vi] = old_m;
    scored.sort_by(|a, b| b.0.total_cmp(&a.0));
    if scored.is_empty() {
        state.settled[vi] = true;
        return false;
    }
    // Reference vertices under the fan (corners of the reference faces at the fan's vertices'
    // locations) and their distance to the fan now: no move may push one of them farther than
    // `tol` away unless it already was (then not farther).
    let reference = ctx.field.reference();
    let mut watch: Vec<Point3<f64>> = std::iter::once(v)
        .chain(nbrs.iter().copied())
        .flat_map(|u| reference.face(work.locations[u.idx()].face))
        .map(|r| reference.positions[r.idx()])
        .collect();
    watch.push(old);
    let watch_before: Vec<f64> = watch
        .iter()
        .map(|x| fan_distance(&work.mesh, fan, x))
        .collect();
    for (_, loc, p) in scored {
        work.mesh.positions[vi] = p;
        work.locations[vi] = loc;
        state.metrics[vi] = ctx.field.eval_at(&loc);
        let tris: Vec<[Point3<f64>; 3]> = fan
            .iter()
            .map(|f| work.mesh.triangles[f.idx()].map(|u| work.mesh.positions[u.idx()]))
            .collect();
        let mut ok = tris
            .iter()
            .all(|t| !is_degenerate_triangle(t) && !ctx.flip_test.is_flipped_anywhere(t))
            && watch
                .iter()
                .zip(&watch_before)
                .all(|(x, b)| fan_distance(&work.mesh, fan, x) <= b.max(ctx.tol));
        if ok && ctx.embedded_input {
            let new_tris: Vec<[VertexId; 3]> =
                fan.iter().map(|f| work.mesh.triangles[f.idx()]).collect();
            ok = candidate_embedded_local(&work.mesh, &state.grid, fan, &new_tris);
        }
        if ok {
            for (f, t) in fan.iter().zip(&tris) {
                if let Some((lo, hi)) = bbox_of(t.iter().copied()) {
                    state.grid.insert(f.idx(), &lo, &hi);
                }
            }
            return true;
        }
        work.mesh.positions[vi] = old;
        work.locations[vi] = old_loc;
        state.metrics[vi] = old_m;
    }
    false
}
