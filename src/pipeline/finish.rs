//! After the loop of Algorithm 1 and its improvers: the certificates of the
//! whole output, and the report.

use super::context::{LoopState, RunContext};
use super::error::PipelineError;
use super::records::{
    FaceSummary, RegionsReport, RemeshReport, RemeshResult, SeamQuality, Sizes, SmallAngles,
    VertexKind, Warning,
};
use super::replace::certify_boundary;
use crate::ids::{EdgeKey, PatchId, VertexId, VertexMap};
use crate::invariants::{self, FacePair, InvariantError, Offenders, TopologySignature};
use crate::mesh::Topology;
use crate::pipeline::options::CoarseInput;
use std::time::Instant;

/// The certificates of the whole output: the working mesh once more (the per-patch manifold
/// check was local, by induction, and the passes changed it since), every corner and
/// feature-line piece where the run put it, and (exact) no self-intersections; then the mesh
/// is compacted.
pub fn certify_output(ctx: &RunContext<'_>, state: &mut LoopState) -> Result<(), PipelineError> {
    certify_whole(ctx, state)?;
    let mut kinds = vertex_kinds(ctx, state);
    let map = state.work.compact();
    state.bound.compact(&map, 1.0);
    kinds.compact(&map, VertexKind::Interior);
    state.vertex_kinds = kinds;
    let t0 = Instant::now();
    if ctx.plan.options.check_self_intersections {
        let pairs = invariants::self_intersections(&state.work.mesh);
        let cert = &mut state.counters.cert;
        if pairs.is_empty() {
            cert.no_self_intersections = 1;
        } else if ctx.input_pairs == 0 {
            // An embedded input must give an embedded output.
            return Err(PipelineError::Final(InvariantError::SelfIntersections(
                Offenders(pairs.into_iter().map(|(a, b)| FacePair(a, b)).collect()),
            )));
        } else {
            // An input that itself self-intersects (cow.off does, at 118 face pairs) cannot
            // give an embedded output that lies on it; that is reported, not an error.
            cert.self_intersecting_pairs = pairs.len();
            cert.input_self_intersecting_pairs = Some(ctx.input_pairs);
        }
    }
    state.counters.times.final_check = t0.elapsed().as_secs_f64();
    Ok(())
}

/// What holds each working-mesh vertex in place: kept corners (cone points by their input
/// ids, which the working mesh keeps until [`crate::stitch::WorkingMesh::compact`]; boundary
/// corners by their curve point), feature-line vertices, boundary vertices.
fn vertex_kinds(ctx: &RunContext<'_>, state: &LoopState) -> VertexMap<VertexKind> {
    (0..state.work.mesh.n_vertices())
        .map(|v| {
            let id = VertexId::new(v);
            let curve = state.work.curve.get(id).copied().flatten();
            let curve_corner = curve.is_some_and(|p| ctx.curves.is_corner_point(&p));
            if ctx.corners.get(id).copied().unwrap_or(false) || curve_corner {
                VertexKind::Corner
            } else if state.features.is_pinned(id) {
                VertexKind::Feature
            } else if curve.is_some() || state.topo.is_boundary_vertex(id) {
                VertexKind::Boundary
            } else {
                VertexKind::Interior
            }
        })
        .collect()
}

/// The working mesh once more, whole (its topology built again): an oriented manifold with
/// the run's topology, its boundary ([`certify_boundary`]), every corner and feature-line piece
/// where the run put it. The run's end, and each region's ([`super::regions`]).
pub fn certify_whole(ctx: &RunContext<'_>, state: &mut LoopState) -> Result<(), PipelineError> {
    let t0 = Instant::now();
    state.topo = Topology::build(&state.work.mesh);
    let pid = PatchId::new(state.patches);
    let fail = |e: InvariantError| PipelineError::Certificate {
        patch: pid,
        seed: None,
        violation: e,
        debug_file: None,
    };
    let (mesh, topo) = (&state.work.mesh, &state.topo);
    invariants::certify_manifold(mesh, topo).map_err(fail)?;
    invariants::certify_oriented(mesh, topo).map_err(fail)?;
    ctx.signature
        .certify_same(&TopologySignature::of(topo))
        .map_err(fail)?;
    certify_boundary(ctx, state).map_err(fail)?;
    certify_corners(ctx, state)?;
    certify_features(state)?;
    state.counters.times.certify += t0.elapsed().as_secs_f64();
    Ok(())
}

/// Every corner is still a vertex of the working mesh, where the input had it (in a region's
/// run: where the region's run started).
pub fn certify_corners(ctx: &RunContext<'_>, state: &LoopState) -> Result<(), PipelineError> {
    let mesh = &state.work.mesh;
    let start = match &ctx.frozen {
        Some(cut) => &cut.positions,
        None => &ctx.quality_field.reference().positions,
    };
    let mut used = vec![false; mesh.n_vertices()];
    mesh.triangles
        .iter()
        .flatten()
        .for_each(|v| used[v.idx()] = true);
    let lost = |v: VertexId| !used[v.idx()] || mesh.positions[v.idx()] != start[v.idx()];
    match (0..ctx.corners.len())
        .map(VertexId::new)
        .find(|&v| ctx.corners[v] && lost(v))
    {
        Some(v) => Err(PipelineError::CornerLost(v)),
        None => Ok(()),
    }
}

/// Every feature-line piece is still an edge of the working mesh, its vertices unmoved.
pub fn certify_features(state: &LoopState) -> Result<(), PipelineError> {
    let features = &state.features;
    if features.edges.is_empty() {
        return Ok(());
    }
    let mesh = &state.work.mesh;
    let edges = crate::quality::unique_edges(mesh);
    let mut pieces: Vec<EdgeKey> = features.edges.iter().copied().collect();
    pieces.sort_unstable();
    match pieces.into_iter().find(|e| {
        edges.binary_search(e).is_err()
            || [e.0, e.1]
                .iter()
                .any(|v| features.positions.get(v) != mesh.positions.get(v.idx()))
    }) {
        Some(e) => Err(PipelineError::FeatureLost(e)),
        None => Ok(()),
    }
}

/// The faces touching a seam (an edge whose two faces came from different patches, or from a
/// patch and the input) against the rest, in the unscaled metric.
fn seam_quality(
    work: &crate::stitch::WorkingMesh,
    face_patch: &[Option<PatchId>],
    metrics: &[nalgebra::Matrix3<f64>],
) -> SeamQuality {
    let mesh = &work.mesh;
    let topo = Topology::build(mesh);
    let mut seam = vec![false; mesh.n_faces()];
    for f in mesh.faces() {
        for i in 0..3 {
            if let Some(g) = topo.neighbor(f, i) {
                if face_patch.get(f.idx()) != face_patch.get(g.idx()) {
                    seam[f.idx()] = true;
                }
            }
        }
    }
    split_quality(mesh, metrics, &seam)
}

/// The faces flagged in `on` against the others, in the unscaled metric.
fn split_quality(
    mesh: &crate::mesh::TriMesh,
    metrics: &[nalgebra::Matrix3<f64>],
    on: &[bool],
) -> SeamQuality {
    use crate::quality::{face_metric, triangle_quality};
    let summary = |flag: bool| {
        let qs: Vec<_> = mesh
            .faces()
            .filter(|f| on[f.idx()] == flag)
            .map(|f| triangle_quality(mesh.face_points(f), &face_metric(metrics, mesh.face(f))))
            .collect();
        let n = qs.len();
        let nf = n.max(1) as f64;
        FaceSummary {
            faces: n,
            q_min: qs
                .iter()
                .map(|q| q.q)
                .fold(f64::INFINITY, f64::min)
                .min(1.0),
            q_avg: qs.iter().map(|q| q.q).sum::<f64>() / nf,
            theta_min: qs.iter().map(|q| q.min_angle()).fold(180.0, f64::min),
            theta_avg: qs.iter().map(|q| q.min_angle()).sum::<f64>() / nf,
        }
    };
    SeamQuality {
        seam: summary(true),
        rest: summary(false),
    }
}

/// Edge lengths against L_tar in the unscaled metric: all edges, and those whose endpoints
/// were not made in a metric the fidelity control scaled up.
fn sizes_on_target(ctx: &RunContext<'_>, state: &LoopState) -> Sizes {
    use crate::quality::edge_conformity_where;
    let mesh = &state.work.mesh;
    let metrics = state.vertex_metrics(ctx);
    let free = |v: VertexId| state.bound.get(v).copied().unwrap_or(1.0) <= 1.0 + 1e-9;
    let l = ctx.plan.l_tar;
    let all = edge_conformity_where(mesh, &metrics, l, |_| true);
    let unbound = edge_conformity_where(mesh, &metrics, l, |e| free(e.0) && free(e.1));
    Sizes {
        bound_edges: all.edges - unbound.edges,
        bound_vertices: (0..mesh.n_vertices())
            .filter(|&v| !free(VertexId::new(v)))
            .count(),
        faces_added_by_fidelity: (ctx.plan.expected_fidelity - ctx.plan.expected).max(0.0),
        all,
        unbound,
    }
}

/// The result of the run: the compacted mesh, its locations and provenance, and the report.
pub fn into_result(ctx: &RunContext<'_>, state: LoopState) -> RemeshResult {
    let plan = ctx.plan;
    let reference = ctx.quality_field.reference();
    let warnings = run_warnings(ctx, &state);
    let surface_counts = state.improvement.iter().flat_map(|i| &i.steps).fold(
        crate::improve::ImproverCounts::default(),
        |mut c, s| {
            c.flips += s.counts.flips;
            c.moves += s.counts.moves;
            c
        },
    );
    let metrics = state.vertex_metrics(ctx);
    let seams = seam_quality(&state.work, state.face_patch.as_slice(), &metrics);
    let regions = regions_report(&state, &metrics);
    let sizes = sizes_on_target(ctx, &state);
    let out_topo = Topology::build(&state.work.mesh);
    let boundary_distance = crate::boundary::curve_distance(
        reference,
        &ctx.reference_topology,
        &state.work.mesh,
        &out_topo,
    );
    let small_angles = SmallAngles::of(&state.work.mesh, &metrics, state.vertex_kinds.as_slice());
    let report = RemeshReport {
        small_angles,
        improvement: state.improvement,
        seams,
        regions,
        sizes,
        boundary_distance,
        options: plan.options.clone(),
        stages: ctx.stages.names(),
        improvers: ctx.improvers.iter().map(|i| i.name().to_string()).collect(),
        l_avg: plan.l_avg,
        l_tar: plan.l_tar,
        patches: state.patches,
        loop_patches: state.loop_patches,
        loop_batches: state.batches,
        work: state.counters.work,
        budget_exhausted: state.budget_exhausted,
        times: state.counters.times,
        wall: state.wall,
        certificate: state.counters.cert,
        fallbacks: state.fallbacks,
        patch_records: state.records,
        faces_in: reference.n_faces(),
        faces_out: state.work.mesh.n_faces(),
        vertices_out: state.work.mesh.n_vertices(),
        edge_flips: surface_counts.flips,
        vertex_moves: surface_counts.moves,
        corners: ctx.corners.iter().filter(|c| **c).count(),
        feature_edges: state.features.input_edges,
        feature_pieces: state.features.edges.len(),
        expected_faces: plan.expected,
        expected_faces_fidelity: plan.expected_fidelity,
        coarse_input: plan.coarse,
        warnings,
    };
    RemeshResult {
        mesh: state.work.mesh,
        locations: state.work.locations.into_vec(),
        face_patch: state.face_patch.into_vec(),
        curve: state.work.curve.into_vec(),
        curves: ctx.curves.clone(),
        report,
        remesh_metric: ctx.field().vertex_metrics().to_vec(),
    }
}

/// The run's warnings, in the report's order: the coarse profile, failed attempts, the
/// budgets that stopped or limited it, and an input that intersects itself.
fn run_warnings(ctx: &RunContext<'_>, state: &LoopState) -> Vec<Warning> {
    let plan = ctx.plan;
    let cert = &state.counters.cert;
    let mut warnings = Vec::new();
    if plan.coarse {
        warnings.push(Warning::CoarseProfile {
            forced: plan.options.coarse_input == CoarseInput::On,
            expected_faces: plan.expected,
            expected_faces_fidelity: plan.expected_fidelity,
        });
    }
    if !state.fallbacks.failures.is_empty() || state.fallbacks.kept_faces > 0 {
        warnings.push(Warning::FailedAttempts {
            attempts: state.fallbacks.failures.len(),
            kept_faces: state.fallbacks.kept_faces,
        });
    }
    if let Some((patches, faces)) = state.over_face_budget_at {
        warnings.push(Warning::FaceBudget {
            patches,
            faces,
            budget: (plan.options.face_budget
                * plan.expected_fidelity.max(state.faces_per_sweep as f64))
                as usize,
        });
    }
    if let Some((patches, work)) = state.over_work_budget_at {
        warnings.push(Warning::WorkBudget {
            patches,
            work,
            budget: state.work_budget(ctx) as usize,
            stopped: state.work_stopped,
            unprocessed: state.work.unprocessed(),
        });
    }
    if state.budget_exhausted {
        warnings.push(Warning::PatchBudget {
            patches: state.patches,
            unprocessed: state.work.unprocessed(),
        });
    }
    for s in state
        .improvement
        .iter()
        .flat_map(|i| &i.steps)
        .filter(|s| s.counts.budget_exhausted)
    {
        warnings.push(Warning::ImproverBudget {
            improver: s.name.clone(),
            patches: s.counts.patches,
        });
    }
    if let Some(input_pairs) = cert.input_self_intersecting_pairs {
        warnings.push(Warning::InputSelfIntersects {
            input_pairs,
            output_pairs: cert.self_intersecting_pairs,
        });
    }
    warnings
}

/// The regions' count, and the quality across their cuts when there were several.
fn regions_report(state: &LoopState, metrics: &[nalgebra::Matrix3<f64>]) -> RegionsReport {
    RegionsReport {
        count: state.regions.map_or(1, |r| r.0),
        declined_cut_edge: state.regions_declined,
        cuts: state.regions.map(|(_, band_from)| {
            let band: Vec<bool> = (state.face_patch.iter())
                .map(|p| p.is_some_and(|p| p.idx() >= band_from))
                .collect();
            split_quality(&state.work.mesh, metrics, &band)
        }),
    }
}
