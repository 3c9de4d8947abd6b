//! The vertex position update on the surface: vertices moved towards the point that makes
//! their faces equilateral in the metric (or their neighbours' centroid) and projected back
//! onto the reference, each move a certified candidate.

use super::geometry::{metric_optimal_point, point_triangle_distance};
use super::SurfaceContext;
use crate::boundary::CurvePoint;
use crate::ids::{FaceId, VertexId};
use crate::invariants::{candidate_embedded_local, is_degenerate_triangle, FaceGrid};
use crate::mesh::{bbox_of, SurfaceLocation, Topology, TriMesh};
use crate::quality::{face_metric, triangle_q};
use crate::stitch::WorkingMesh;
use nalgebra::{Matrix3, Point3, Vector3};

/// The vertex position update (Sec. 3.4) on the surface, after the loop: every vertex off the
/// input boundary is moved towards the point that makes its faces equilateral in the metric
/// (full or half step, the metric-optimal point of `geometry.rs`) or towards the centroid of
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
    // Boundary neighbours (previous, next along the loop) of every boundary vertex.
    let mut along: std::collections::HashMap<VertexId, (VertexId, VertexId)> =
        std::collections::HashMap::new();
    for l in topo.boundary_loops() {
        let n = l.len();
        for i in 0..n {
            along.insert(l[i], (l[(i + n - 1) % n], l[(i + 1) % n]));
        }
    }
    let mut moved = 0;
    for _pass in 0..3 {
        for vi in 0..work.mesh.n_vertices() {
            let v = VertexId::new(vi);
            if state.settled[vi]
                || topo.vertex_faces(v).is_empty()
                || ctx.pinned.get(vi).copied().unwrap_or(false)
                || !ctx.in_scope(v)
            {
                continue;
            }
            let done = match along.get(&v) {
                Some(&nbrs) if ctx.slide_boundary => slide(ctx, &topo, work, &mut state, v, nbrs),
                Some(_) => continue,
                None => relocate(ctx, &topo, work, &mut state, v),
            };
            if done {
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
            triangle_q(t.map(|u| mesh.positions[u.idx()]), &face_metric(metrics, t))
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

/// A candidate position of a vertex: where, its reference location, and its point on a
/// boundary curve when it slides along one.
#[derive(Copy, Clone)]
struct Candidate {
    position: Point3<f64>,
    location: SurfaceLocation,
    curve: Option<CurvePoint>,
}

/// Try to move the inner vertex `v`: towards the metric-optimal point (full and half step),
/// then the centroid of its neighbours (full, half, quarter step), projected onto the
/// reference.
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
    let old = work.mesh.positions[vi];
    let c = nbrs.iter().fold(Vector3::zeros(), |acc, u| {
        acc + work.mesh.positions[u.idx()].coords
    }) / nbrs.len() as f64;
    let mut targets: Vec<Point3<f64>> = Vec::with_capacity(5);
    if let Some(opt) = metric_optimal_point(&work.mesh, fan, v, &state.metrics[vi]) {
        targets.push(opt);
        targets.push(Point3::from((old.coords + opt.coords) * 0.5));
    }
    for step in [1.0, 0.5, 0.25] {
        targets.push(Point3::from(old.coords + (c - old.coords) * step));
    }
    let candidates: Vec<Candidate> = targets
        .iter()
        .map(|t| {
            let (location, position) = ctx.field.project(t);
            Candidate {
                position,
                location,
                curve: None,
            }
        })
        .collect();
    try_candidates(ctx, topo, work, state, v, &candidates, &[])
}

/// A boundary vertex sliding between its neighbours also tries `SLIDE_SWEEP − 1` evenly spaced
/// places of the span ([`slide`]).
const SLIDE_SWEEP: usize = 8;

/// The fan quality under which [`slide`] sweeps the span whatever the pieces' lengths
/// (Algorithm 2's default threshold).
const SLIDE_SWEEP_BELOW_Q: f64 = 0.5;

/// The lengths (× L_tar, in the metric) both boundary pieces keep at a place of the sweep
/// where no face of the fan is bad: the boundary's resampling range (issue 17's 0.7–1.4).
const SLIDE_SWEEP_PIECES: (f64, f64) = (0.7, 1.4);

/// Try to slide the boundary vertex `v` along its input curve, between its boundary
/// neighbours `prev` and `next`: to where its two boundary edges have equal metric length,
/// half way there, and `SLIDE_SWEEP − 1` evenly spaced places between the neighbours (where
/// both pieces stay on target, or anywhere when its fan holds a bad face); best fan first.
/// Corners never slide.
fn slide(
    ctx: &SurfaceContext<'_>,
    topo: &Topology,
    work: &mut WorkingMesh,
    state: &mut Relocation,
    v: VertexId,
    (prev, next): (VertexId, VertexId),
) -> bool {
    let Some(curves) = ctx.curves else {
        return false;
    };
    let point = |u: VertexId| work.curve.get(u).copied().flatten();
    let (Some(p), Some(pa), Some(pb)) = (point(v), point(prev), point(next)) else {
        return false;
    };
    if curves.is_corner_point(&p) || pa.curve != p.curve || pb.curve != p.curve {
        return false;
    }
    let l = p.curve as usize;
    let total = curves.length(l);
    let (sa, sv) = (curves.arc(&pa), curves.arc(&p));
    let da = (sv - sa).rem_euclid(total);
    let span = da + (curves.arc(&pb) - sv).rem_euclid(total);
    if !(span > 0.0 && span < total) {
        return false;
    }
    let reference = ctx.field.reference();
    let m = state.metrics[v.idx()];
    let (xa, xb) = (
        work.mesh.positions[prev.idx()],
        work.mesh.positions[next.idx()],
    );
    let len = |x: &Point3<f64>, y: &Point3<f64>| {
        let d = y - x;
        d.dot(&(m * d)).max(0.0).sqrt()
    };
    let at = |f: f64| curves.at_arc(l, sa + f * span);
    // Bisection for the fraction where the two boundary edges are equally long in the metric.
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        let x = curves.position(reference, &at(mid));
        if len(&xa, &x) < len(&x, &xb) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let f_now = da / span;
    let f_bal = 0.5 * (lo + hi);
    let candidate = |f: f64| {
        let cp = at(f);
        Candidate {
            position: curves.position(reference, &cp),
            location: curves.location(&cp),
            curve: Some(cp),
        }
    };
    let mut candidates: Vec<Candidate> = [f_bal, 0.5 * (f_now + f_bal)]
        .into_iter()
        .filter(|f| *f > 0.0 && *f < 1.0)
        .map(candidate)
        .collect();
    // Also a sweep of the span: beside a kept corner whose one face is an ear, the best place
    // is where the ear is isoceles, far from the balance point. A place of the sweep keeps
    // both boundary pieces within [`SLIDE_SWEEP_PIECES`] L_tar, so that the boundary stays
    // resampled to the metric, unless a face of the fan is bad.
    if ctx.slide_sweep {
        let bad =
            fan_quality(&work.mesh, &state.metrics, topo.vertex_faces(v)) < SLIDE_SWEEP_BELOW_Q;
        let (lo_piece, hi_piece) = SLIDE_SWEEP_PIECES;
        let on_target = |x: &Point3<f64>| {
            [len(&xa, x), len(x, &xb)]
                .iter()
                .all(|l| (lo_piece * ctx.l_tar..=hi_piece * ctx.l_tar).contains(l))
        };
        candidates.extend(
            (1..SLIDE_SWEEP)
                .map(|k| candidate(k as f64 / SLIDE_SWEEP as f64))
                .filter(|c| bad || on_target(&c.position)),
        );
    }
    // The input curve's vertices between the neighbours: the new chords must not pass
    // farther from them than the tolerance.
    let between: Vec<Point3<f64>> = curves
        .vertices_between(l, sa, sa + span)
        .map(|u| reference.positions[u.idx()])
        .collect();
    try_candidates(ctx, topo, work, state, v, &candidates, &between)
}

/// Move `v` to the best of `candidates` that raises its fan's smallest quality and passes the
/// certificates (not degenerate, not flipped, locally embedded, and no watched point — its old
/// position, the corners of the reference faces under it and its neighbours, and `extra` —
/// farther from the fan than the tolerance unless it already was, then not farther). Returns
/// whether `v` moved; settles it when no candidate scored better.
fn try_candidates(
    ctx: &SurfaceContext<'_>,
    topo: &Topology,
    work: &mut WorkingMesh,
    state: &mut Relocation,
    v: VertexId,
    candidates: &[Candidate],
    extra: &[Point3<f64>],
) -> bool {
    let vi = v.idx();
    let fan = topo.vertex_faces(v);
    let nbrs = topo.vertex_neighbors(v);
    let before = fan_quality(&work.mesh, &state.metrics, fan);
    let old = work.mesh.positions[vi];
    let old_loc = work.locations[v];
    let old_curve = work.curve.get(v).copied().flatten();
    let old_m = state.metrics[vi];
    let mut scored: Vec<(f64, Candidate)> = candidates
        .iter()
        .map(|c| {
            work.mesh.positions[vi] = c.position;
            state.metrics[vi] = ctx.field.eval_at(&c.location);
            (fan_quality(&work.mesh, &state.metrics, fan), *c)
        })
        .filter(|(q, _)| *q > before)
        .collect();
    work.mesh.positions[vi] = old;
    state.metrics[vi] = old_m;
    scored.sort_by(|a, b| b.0.total_cmp(&a.0));
    if scored.is_empty() {
        state.settled[vi] = true;
        return false;
    }
    let reference = ctx.field.reference();
    let mut watch: Vec<Point3<f64>> = std::iter::once(v)
        .chain(nbrs.iter().copied())
        .flat_map(|u| reference.face(work.locations[u].face))
        .map(|r| reference.positions[r.idx()])
        .collect();
    watch.push(old);
    watch.extend_from_slice(extra);
    let watch_before: Vec<f64> = watch
        .iter()
        .map(|x| fan_distance(&work.mesh, fan, x))
        .collect();
    for (_, c) in scored {
        work.mesh.positions[vi] = c.position;
        work.locations[v] = c.location;
        state.metrics[vi] = ctx.field.eval_at(&c.location);
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
            if c.curve.is_some() {
                work.curve[v] = c.curve;
            }
            return true;
        }
        work.mesh.positions[vi] = old;
        work.locations[v] = old_loc;
        state.metrics[vi] = old_m;
        if let Some(slot) = work.curve.get_mut(v) {
            *slot = old_curve;
        }
    }
    false
}
