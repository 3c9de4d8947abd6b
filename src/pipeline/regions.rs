//! Region-parallel Algorithm 1 (ours; paper-notes "Regions"): domain decomposition, as
//! tucanos' parallel remesher does it, with the paper's own seam rule at a larger scale.
//!
//! ```text
//! split the working mesh into regions of at most R faces (recursive coordinate bisection)
//! for every region, at the same time:                                  // rayon
//!     Algorithm 1 and the improvers on the region's faces alone, its cuts frozen
//!     certify the region (manifold, oriented, topology, cuts kept, corners, feature lines)
//! merge the regions by their vertices' ids in the whole mesh
//! mark the band of BAND_RINGS rings around every cut unprocessed      // Algorithm 1 goes on
//! ```
//!
//! A region's run reads the whole run's plan, metric, reference surface, boundary curves and
//! flip certificate (read-only, shared); only its working mesh is its own. Its cut edges are
//! kept bit for bit: every cut vertex is a corner (pinned, an anchor of every boundary chain),
//! and no cut edge is a chain's. Each region draws from its own ChaCha8 stream (the seed's,
//! stream = region index + 1), so the output depends on the seed and R, not on the threads.

use super::context::{FrozenCut, LoopState, RunContext};
use super::error::PipelineError;
use crate::features::FeatureLines;
use crate::ids::{EdgeKey, FaceId, PatchId, VertexId};
use crate::invariants::{self, InvariantError, TopologySignature};
use crate::mesh::{Topology, TriMesh, UnionFind};
use crate::stitch::WorkingMesh;
use nalgebra::Point3;
use rand::SeedableRng;
use rayon::prelude::*;
use std::sync::Arc;

/// The default of [`super::RemeshOptions::region_faces`]: the most faces of the working mesh
/// one region holds. Large enough that a region's patches are far from its cuts for most of
/// its faces, small enough that a region's per-patch costs (stitching, certificates) stay
/// bounded whatever the mesh's size.
pub const DEFAULT_REGION_FACES: usize = 12_000;

/// Rings of faces around every cut that Algorithm 1 remeshes again after the merge: the
/// regions' patches grade from the cut's input edges to the target size within about two.
pub const BAND_RINGS: usize = 3;

/// The faces of `mesh` split into regions of at most `max_faces` faces by recursive
/// coordinate bisection of the face centroids: each split halves a set along the longest side
/// of its centroids' bounding box (ties broken by face id), so the regions depend on the mesh
/// and `max_faces` only. Each region's faces are in increasing id order. One region holding
/// every face when `max_faces` is 0 or the mesh is no larger.
pub fn partition(mesh: &TriMesh, max_faces: usize) -> Vec<Vec<FaceId>> {
    let all: Vec<FaceId> = mesh.faces().collect();
    if max_faces == 0 || all.len() <= max_faces {
        return vec![all];
    }
    let centroids: Vec<Point3<f64>> = mesh
        .faces()
        .map(|f| {
            let [a, b, c] = mesh.face_points(f);
            Point3::from((a.coords + b.coords + c.coords) / 3.0)
        })
        .collect();
    let mut out = Vec::new();
    bisect(&centroids, all, max_faces, &mut out);
    for r in &mut out {
        r.sort_unstable();
    }
    out
}

fn bisect(
    centroids: &[Point3<f64>],
    mut faces: Vec<FaceId>,
    max: usize,
    out: &mut Vec<Vec<FaceId>>,
) {
    if faces.len() <= max {
        out.push(faces);
        return;
    }
    let mut lo = Point3::from([f64::INFINITY; 3]);
    let mut hi = Point3::from([f64::NEG_INFINITY; 3]);
    for f in &faces {
        let c = centroids[f.idx()];
        lo = lo.inf(&c);
        hi = hi.sup(&c);
    }
    let ext = hi - lo;
    let axis = (0..3).fold(0, |a, k| if ext[k] > ext[a] { k } else { a });
    let mid = faces.len() / 2;
    faces.select_nth_unstable_by(mid, |a, b| {
        centroids[a.idx()][axis]
            .total_cmp(&centroids[b.idx()][axis])
            .then(a.cmp(b))
    });
    let upper = faces.split_off(mid);
    bisect(centroids, faces, max, out);
    bisect(centroids, upper, max, out);
}

/// One region's working mesh, cut out of the whole.
pub struct RegionMesh {
    /// Its working mesh (its own vertex and face ids; locations and curve points are the
    /// whole run's, on the shared reference).
    pub work: WorkingMesh,
    /// `whole[v]`: the whole mesh's vertex of the region's vertex `v`. A vertex where the
    /// region touches itself only at that vertex (a pinch) is split into one region vertex per
    /// fan, all mapping to the same vertex of the whole.
    pub whole: Vec<VertexId>,
    /// Its cuts.
    pub cut: FrozenCut,
}

/// Cut the faces `faces` (of region `r` in `region_of`) out of the whole working mesh.
pub fn extract(
    whole: &WorkingMesh,
    topo: &Topology,
    region_of: &[u32],
    r: u32,
    faces: &[FaceId],
) -> RegionMesh {
    let slot: rustc_hash::FxHashMap<FaceId, usize> =
        faces.iter().enumerate().map(|(i, &f)| (f, i)).collect();
    // Corners (face slot, k) of the same vertex joined across the region's edges: one class
    // per fan of the vertex inside the region.
    let mut uf = UnionFind::new(3 * faces.len());
    for (i, &f) in faces.iter().enumerate() {
        for k in 0..3 {
            // Half-edge k runs from corner k to corner k + 1.
            let Some(g) = topo.neighbor(f, k) else {
                continue;
            };
            if region_of[g.idx()] != r {
                continue;
            }
            let j = slot[&g];
            let t = whole.mesh.triangles[f.idx()];
            let u = whole.mesh.triangles[g.idx()];
            for (a, v) in [(k, t[k]), ((k + 1) % 3, t[(k + 1) % 3])] {
                if let Some(b) = u.iter().position(|w| *w == v) {
                    uf.union(3 * i + a, 3 * j + b);
                }
            }
        }
    }
    let mut local_of_class: rustc_hash::FxHashMap<usize, VertexId> = Default::default();
    let mut whole_of: Vec<VertexId> = Vec::new();
    let mut triangles = Vec::with_capacity(faces.len());
    for (i, &f) in faces.iter().enumerate() {
        let t = whole.mesh.triangles[f.idx()];
        let mut l = [VertexId(0); 3];
        for k in 0..3 {
            let class = uf.find(3 * i + k);
            l[k] = *local_of_class.entry(class).or_insert_with(|| {
                whole_of.push(t[k]);
                VertexId::new(whole_of.len() - 1)
            });
        }
        triangles.push(l);
    }
    let n = whole_of.len();
    let mut cut_vertex = vec![false; n];
    let mut edges = Vec::new();
    for (i, &f) in faces.iter().enumerate() {
        for k in 0..3 {
            if topo.neighbor(f, k).is_some_and(|g| region_of[g.idx()] != r) {
                let (a, b) = (triangles[i][k], triangles[i][(k + 1) % 3]);
                edges.push(EdgeKey::new(a, b));
                cut_vertex[a.idx()] = true;
                cut_vertex[b.idx()] = true;
            }
        }
    }
    edges.sort_unstable();
    let positions: Vec<Point3<f64>> = whole_of.iter().map(|v| *whole.mesh.position(*v)).collect();
    let work = WorkingMesh {
        mesh: TriMesh {
            positions: positions.clone(),
            triangles,
        },
        locations: whole_of.iter().map(|v| whole.locations[v.idx()]).collect(),
        processed: faces.iter().map(|f| whole.processed[f.idx()]).collect(),
        curve: whole_of
            .iter()
            .map(|v| whole.curve.get(v.idx()).copied().flatten())
            .collect(),
    };
    RegionMesh {
        work,
        whole: whole_of,
        cut: FrozenCut {
            edges,
            vertices: cut_vertex,
            positions,
        },
    }
}

/// What a region's run leaves for the merge.
pub struct RegionRun {
    region: RegionMesh,
    state: LoopState,
}

/// Split the whole run's working mesh into regions when it is larger than
/// [`super::RemeshOptions::region_faces`], run them at the same time, merge them into `state`
/// and leave the band around the cuts unprocessed for the loop that follows. Returns the
/// number of regions (1: nothing was done, the loop runs on the whole mesh as in the paper).
pub fn run_regions(ctx: &RunContext<'_>, state: &mut LoopState) -> Result<usize, PipelineError> {
    let o = &ctx.plan.options;
    // A patch budget counts the run's patches in order; regions would spend it at once.
    if o.max_patches.is_some() {
        return Ok(1);
    }
    let parts = partition(&state.work.mesh, o.region_faces);
    if parts.len() < 2 {
        return Ok(1);
    }
    let mut region_of = vec![0u32; state.work.mesh.n_faces()];
    for (r, faces) in parts.iter().enumerate() {
        for f in faces {
            region_of[f.idx()] = r as u32;
        }
    }
    let whole_faces = state.work.mesh.n_faces() as f64;
    let runs: Vec<RegionRun> = parts
        .par_iter()
        .enumerate()
        .map(|(r, faces)| {
            let region = extract(&state.work, &state.topo, &region_of, r as u32, faces);
            let share = faces.len() as f64 / whole_faces;
            run_region(ctx, state, region, r, share)
        })
        .collect::<Result<_, _>>()?;
    let regions = runs.len();
    merge(ctx, state, runs);
    Ok(regions)
}

/// Algorithm 1 and the improvers on one region, and its certificates.
fn run_region(
    ctx: &RunContext<'_>,
    whole: &LoopState,
    region: RegionMesh,
    index: usize,
    share: f64,
) -> Result<RegionRun, PipelineError> {
    let topo = Topology::build(&region.work.mesh);
    let cut = Arc::new(region.cut.clone());
    let n = region.whole.len();
    let from_whole = |flags: &[bool]| -> Vec<bool> {
        (0..n)
            .map(|l| cut.vertices[l] || flags.get(region.whole[l].idx()).copied().unwrap_or(false))
            .collect()
    };
    let corners = from_whole(&ctx.corners);
    let rctx = RunContext {
        quality_field: ctx.quality_field,
        plan: ctx.plan,
        stages: ctx.stages,
        improvers: ctx.improvers,
        flip_test: ctx.flip_test.clone(),
        ref_normals: ctx.ref_normals.clone(),
        input_pairs: ctx.input_pairs,
        embedded_input: ctx.embedded_input,
        reference_topology: ctx.reference_topology.clone(),
        signature: TopologySignature::of(&topo),
        input_boundary: invariants::boundary_edges(&topo),
        corners,
        curves: ctx.curves.clone(),
        improving: ctx.improving,
        frozen: Some(cut.clone()),
    };
    let features = region_features(&whole.features, &region);
    let pinned = from_whole(&whole.pinned);
    let bound = region.whole.iter().map(|v| whole.bound[v.idx()]).collect();
    let mut state = LoopState::from_parts(region.work.clone(), topo, features, pinned, bound);
    state.budget_share = share;
    state.sweep = whole.sweep;
    state.index_faces(&rctx);
    let mut rng = crate::Rng::seed_from_u64(ctx.plan.options.seed);
    rng.set_stream(index as u64 + 1);
    super::patch_loop(&rctx, &mut state, &mut rng, &mut |_| {})?;
    super::improvement::run(&rctx, &mut state, &mut rng)?;
    certify_region(&rctx, &mut state)?;
    Ok(RegionRun { region, state })
}

/// The whole mesh's feature-line pieces that are edges of the region, by its vertex ids.
fn region_features(whole: &FeatureLines, region: &RegionMesh) -> FeatureLines {
    let mut out = FeatureLines {
        input_edges: whole.input_edges,
        ..Default::default()
    };
    if whole.edges.is_empty() {
        return out;
    }
    let n = region.whole.len();
    out.pinned = (0..n).map(|l| whole.is_pinned(region.whole[l])).collect();
    for t in &region.work.mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let e = EdgeKey::new(region.whole[a.idx()], region.whole[b.idx()]);
            if whole.edges.contains(&e) {
                out.edges.insert(EdgeKey::new(a, b));
                for v in [a, b] {
                    if let Some(p) = whole.positions.get(&region.whole[v.idx()]) {
                        out.positions.insert(v, *p);
                    }
                }
            }
        }
    }
    out
}

/// A region's certificates after its loop and improvers: an oriented manifold with the
/// region's topology, its boundary kept ([`certify_region_boundary`]), its corners and
/// feature lines where they were.
fn certify_region(ctx: &RunContext<'_>, state: &mut LoopState) -> Result<(), PipelineError> {
    let t0 = std::time::Instant::now();
    state.topo = Topology::build(&state.work.mesh);
    let fail = |e: InvariantError| PipelineError::Certificate {
        patch: PatchId::new(state.patches),
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
    super::replace::certify_boundary(ctx, state).map_err(fail)?;
    super::finish::certify_corners(ctx, state)?;
    super::finish::certify_features(state)?;
    state.counters.times.certify += t0.elapsed().as_secs_f64();
    Ok(())
}

/// After the band's loop: the improvers, which ran in the regions, run again on the band
/// alone, widened to the faces the band's patches made (they reach past the band by their
/// overlap rings) and [`BAND_RINGS`] rings around them.
pub fn scope_band(state: &mut LoopState, band_from: usize) {
    let mesh = &state.work.mesh;
    let mut scope = state.scope.take().unwrap_or_default();
    scope.resize(mesh.n_vertices(), false);
    for (t, p) in mesh.triangles.iter().zip(&state.face_patch) {
        if p.is_some_and(|p| p.idx() >= band_from) {
            t.iter().for_each(|v| scope[v.idx()] = true);
        }
    }
    for _ in 0..BAND_RINGS {
        let mut grown = scope.clone();
        for t in &mesh.triangles {
            if t.iter().any(|v| scope[v.idx()]) {
                t.iter().for_each(|v| grown[v.idx()] = true);
            }
        }
        scope = grown;
    }
    state.scope = Some(scope);
}

/// Put the regions' meshes back into the whole: the whole mesh's vertices keep their ids
/// (those the regions removed are left unreferenced, for the final compaction), each
/// region's new vertices are appended in region order, and the faces are the regions' in
/// region order. Everything kept in step with the working mesh follows, and the band of
/// [`BAND_RINGS`] rings around the cuts is left unprocessed.
fn merge(ctx: &RunContext<'_>, state: &mut LoopState, runs: Vec<RegionRun>) {
    let mut triangles = Vec::new();
    let mut face_patch = Vec::new();
    let mut cut_vertices = Vec::new();
    let w = &mut state.work;
    for run in runs {
        let RegionRun { region, state: rs } = run;
        let n0 = region.whole.len();
        let mut map: Vec<VertexId> = region.whole.clone();
        for l in n0..rs.work.mesh.n_vertices() {
            map.push(VertexId::new(w.mesh.n_vertices()));
            w.mesh.positions.push(rs.work.mesh.positions[l]);
            w.locations.push(rs.work.locations[l]);
            w.curve.push(rs.work.curve.get(l).copied().flatten());
            state.bound.push(rs.bound.get(l).copied().unwrap_or(1.0));
            state.pinned.push(false);
            state.factors.push(rs.factors.get(VertexId::new(l)));
        }
        for (l, &v) in map.iter().enumerate().take(n0) {
            state.factors.raise(v, rs.factors.get(VertexId::new(l)));
            if region.cut.vertices[l] {
                cut_vertices.push(v);
            }
        }
        let offset = state.patches;
        triangles.extend(
            rs.work
                .mesh
                .triangles
                .iter()
                .map(|t| t.map(|v| map[v.idx()])),
        );
        face_patch.extend(
            rs.face_patch
                .iter()
                .map(|p| p.map(|p| PatchId::new(p.idx() + offset))),
        );
        state.patches += rs.patches;
        state.batches += rs.batches;
        state.counters.absorb(rs.counters);
        state.records.extend(rs.records.into_iter().map(|mut r| {
            r.id = PatchId::new(r.id.idx() + offset);
            r
        }));
        state.fallbacks.shrinks += rs.fallbacks.shrinks;
        state.fallbacks.kept_faces += rs.fallbacks.kept_faces;
        state.fallbacks.failures.extend(rs.fallbacks.failures);
        state.budget_exhausted |= rs.budget_exhausted;
        state.over_face_budget |= rs.over_face_budget;
        state.over_face_budget_at = state.over_face_budget_at.or(rs.over_face_budget_at);
        state.over_work_budget_at = state.over_work_budget_at.or(rs.over_work_budget_at);
        state.work_stopped |= rs.work_stopped;
    }
    w.mesh.triangles = triangles;
    w.processed = vec![true; w.mesh.n_faces()];
    state.face_patch = face_patch;
    state.topo = Topology::build(&w.mesh);
    // The band: BAND_RINGS rings of faces around the cut vertices.
    let mut near = vec![false; w.mesh.n_vertices()];
    for v in &cut_vertices {
        near[v.idx()] = true;
    }
    for _ in 0..BAND_RINGS {
        let mut grown = near.clone();
        for t in &w.mesh.triangles {
            if t.iter().any(|v| near[v.idx()]) {
                t.iter().for_each(|v| grown[v.idx()] = true);
            }
        }
        near = grown;
    }
    for (f, t) in w.mesh.triangles.iter().enumerate() {
        if t.iter().filter(|v| near[v.idx()]).count() >= 2 {
            w.processed[f] = false;
        }
    }
    state.scope = Some(near);
    // The band is the last pass of the run: no further sweep starts after it.
    state.sweep = ctx.plan.options.sweeps.max(state.sweep);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;

    /// Every face in exactly one region, none over the bound, ids increasing in each, and the
    /// same regions every time.
    #[test]
    fn partition_covers_every_face_once_within_the_bound() {
        let mesh = generators::icosphere(1.0, 4);
        let parts = partition(&mesh, 700);
        assert!(parts.len() >= mesh.n_faces() / 700);
        let mut seen = vec![0; mesh.n_faces()];
        for p in &parts {
            assert!(
                !p.is_empty() && p.len() <= 700,
                "a region of {} faces",
                p.len()
            );
            assert!(p.windows(2).all(|w| w[0] < w[1]));
            p.iter().for_each(|f| seen[f.idx()] += 1);
        }
        assert!(seen.iter().all(|n| *n == 1));
        assert_eq!(parts, partition(&mesh, 700));
        assert_eq!(partition(&mesh, 0).len(), 1);
        assert_eq!(partition(&mesh, mesh.n_faces()).len(), 1);
    }

    /// A region that touches itself only at a vertex gets one vertex per fan there (a
    /// manifold region mesh), both mapping to the whole mesh's vertex; the edges it shares
    /// with the other region are its cuts, their vertices cut vertices.
    #[test]
    fn extract_splits_pinches_and_finds_the_cuts() {
        // A 2×2 grid of quads (8 faces): the region is the lower-left and upper-right quads,
        // which meet only at the centre vertex 4.
        let mesh = generators::plate(1.0, 2);
        let topo = Topology::build(&mesh);
        let centre = (0..mesh.n_vertices())
            .find(|&v| {
                let p = mesh.positions[v];
                (p.x - 0.5).abs() < 1e-12 && (p.y - 0.5).abs() < 1e-12
            })
            .map(VertexId::new)
            .expect("a centre vertex");
        let cell = |f: FaceId| {
            let [a, b, c] = mesh.face_points(f);
            let m = (a.coords + b.coords + c.coords) / 3.0;
            (m.x > 0.5, m.y > 0.5)
        };
        let region_of: Vec<u32> = mesh
            .faces()
            .map(|f| match cell(f) {
                (false, false) | (true, true) => 0,
                _ => 1,
            })
            .collect();
        let faces: Vec<FaceId> = mesh.faces().filter(|f| region_of[f.idx()] == 0).collect();
        assert_eq!(faces.len(), 4);
        let r = extract(
            &WorkingMesh::from_reference(&mesh),
            &topo,
            &region_of,
            0,
            &faces,
        );
        let local_topo = Topology::build(&r.work.mesh);
        assert!(local_topo.is_oriented_manifold(), "the pinch was not split");
        let copies = r.whole.iter().filter(|v| **v == centre).count();
        assert_eq!(copies, 2, "one region vertex per fan at the pinch");
        // Each quad shares two edges with the other region: 4 cut edges, all with the centre.
        assert_eq!(r.cut.edges.len(), 4);
        for e in &r.cut.edges {
            assert!(r.whole[e.0.idx()] == centre || r.whole[e.1.idx()] == centre);
            assert!(r.cut.is_cut_vertex(e.0) && r.cut.is_cut_vertex(e.1));
        }
        // The outer corners of the plate are on no cut.
        assert!((0..r.whole.len()).any(|l| !r.cut.vertices[l]));
    }
}
