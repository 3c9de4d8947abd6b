//! Region-parallel Algorithm 1 (ours; paper-notes "Regions"): domain decomposition, as
//! tucanos' parallel remesher does it, with the paper's own seam rule at a larger scale.
//!
//! ```text
//! split the working mesh into regions of at most R faces (recursive coordinate bisection)
//! three levels, each level's pieces at the same time (rayon), each piece:
//!     Algorithm 1 and the improvers on the piece's faces alone, its cuts frozen
//!     certify the piece (manifold, oriented, topology, cuts kept, corners, feature lines)
//!   1. the regions
//!   2. the band of BAND_RINGS rings around the cuts, less the junctions' discs, in strips
//!   3. the junctions (where three regions or more met), with the strips' ends
//! merge each level's pieces back by their vertices' ids in the whole mesh
//! the improvers again where the strips and junctions were frozen; Algorithm 1 on what is left
//! ```
//!
//! A region's run reads the whole run's plan, metric, reference surface, boundary curves and
//! flip certificate (read-only, shared); only its working mesh is its own. Its cut edges are
//! kept bit for bit: every cut vertex is a corner (pinned, an anchor of every boundary chain),
//! and no cut edge is a chain's. Each region draws from its own ChaCha8 streams (the seed's,
//! [`REGION_STREAMS`] apart), so the output depends on the seed and R, not on the threads.

use super::context::{FrozenCut, LoopState, RunContext};
use super::error::PipelineError;
use crate::features::FeatureLines;
use crate::ids::{EdgeKey, FaceId, FaceMap, PatchId, VertexId, VertexMap};
use crate::invariants::{self, TopologySignature};
use crate::mesh::{Topology, TriMesh, UnionFind};
use crate::stitch::WorkingMesh;
use nalgebra::Point3;
use rand::SeedableRng;
use rayon::prelude::*;
use std::sync::Arc;

/// The default of [`super::RemeshOptions::region_faces`]: the most output faces one region
/// is expected to make (each input face weighing the faces an output on target makes of it).
/// Large enough that a region's patches are far from its cuts for most of its faces, small
/// enough that a region's per-patch costs (stitching, certificates) stay bounded whatever the
/// mesh's size.
pub const DEFAULT_REGION_FACES: usize = 6_000;

/// Streams per region: region r's loop draws ChaCha8 stream `(r + 1) · REGION_STREAMS`, and
/// a batch's patch in slot s of it `(r + 1) · REGION_STREAMS + s + 1`, far from the whole
/// run's (`s + 1`) and from every other region's.
const REGION_STREAMS: u64 = 1 << 32;

/// Rings of faces around every cut that the strips and junctions remesh after the regions:
/// the regions' patches grade from the cut's input edges to the target size near it.
pub const BAND_RINGS: usize = 5;

/// The least weight an input face counts for in the regions' bound (each face weighs the
/// faces an output on target makes of it): a region holds at most 1/`MIN_FACE_WEIGHT` times
/// the bound in input faces, however coarse the output there.
pub const MIN_FACE_WEIGHT: f64 = 0.25;

/// The faces of `mesh` split into regions of weight at most `max_weight` by recursive
/// coordinate bisection of the face centroids: each split cuts a set at its weighted median
/// along the longest side of its centroids' bounding box (ties broken by face id), so the
/// regions depend on the mesh, the weights and the bound only. Each region's faces are in
/// increasing id order. One region holding every face when `max_weight` is 0 or the whole
/// weight is no more.
pub fn partition(mesh: &TriMesh, weights: &[f64], max_weight: f64) -> Vec<Vec<FaceId>> {
    let all: Vec<FaceId> = mesh.faces().collect();
    let total: f64 = weights.iter().sum();
    if max_weight <= 0.0 || total <= max_weight || all.len() < 2 {
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
    bisect(&centroids, weights, all, max_weight, &mut out);
    for r in &mut out {
        r.sort_unstable();
    }
    out
}

fn bisect(
    centroids: &[Point3<f64>],
    weights: &[f64],
    mut faces: Vec<FaceId>,
    max: f64,
    out: &mut Vec<Vec<FaceId>>,
) {
    let total: f64 = faces.iter().map(|f| weights[f.idx()]).sum();
    if total <= max || faces.len() < 2 {
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
    faces.sort_unstable_by(|a, b| {
        centroids[a.idx()][axis]
            .total_cmp(&centroids[b.idx()][axis])
            .then(a.cmp(b))
    });
    // The weighted median, with at least one face on each side.
    let mut acc = 0.0;
    let mut mid = faces.len() - 1;
    for (i, f) in faces.iter().enumerate() {
        acc += weights[f.idx()];
        if acc >= 0.5 * total {
            mid = i + 1;
            break;
        }
    }
    let mid = mid.clamp(1, faces.len() - 1);
    let upper = faces.split_off(mid);
    bisect(centroids, weights, faces, max, out);
    bisect(centroids, weights, upper, max, out);
}

/// Each face's weight for [`partition`]: the faces an output on target makes of it (its area
/// in the metric the patches are remeshed in, over the area of an equilateral triangle of
/// side L_tar), at least [`MIN_FACE_WEIGHT`]. The region size then follows the metric and the
/// target, not the input's resolution.
fn face_weights(
    ctx: &RunContext<'_>,
    work: &WorkingMesh,
    metrics: &[nalgebra::Matrix3<f64>],
) -> Vec<f64> {
    let ideal = 3f64.sqrt() / 4.0 * ctx.plan.l_tar * ctx.plan.l_tar;
    work.mesh
        .faces()
        .map(|f| {
            let t = work.mesh.face(f);
            let m = t
                .iter()
                .map(|v| metrics[v.idx()])
                .sum::<nalgebra::Matrix3<f64>>()
                / 3.0;
            (super::sizing::metric_area(work.mesh.face_points(f), &m) / ideal).max(MIN_FACE_WEIGHT)
        })
        .collect()
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
        locations: whole_of.iter().map(|&v| whole.locations[v]).collect(),
        processed: faces.iter().map(|&f| whole.processed[f]).collect(),
        curve: whole_of
            .iter()
            .map(|&v| whole.curve.get(v).copied().flatten())
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
struct RegionRun {
    region: RegionMesh,
    state: LoopState,
}

/// The levels of a run with regions; each level's regions draw their own streams.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Level {
    /// The regions of the partition, every face unprocessed.
    Regions = 0,
    /// The band around the cuts, in pieces split at the junctions.
    Strips = 1,
    /// The junctions, where three or more regions met, with the ends of the strips.
    Junctions = 2,
}

impl Level {
    fn name(self) -> &'static str {
        match self {
            Level::Regions => "region",
            Level::Strips => "strip",
            Level::Junctions => "junction",
        }
    }
}

/// Split the whole run's working mesh into regions when it is expected to make more than
/// [`super::RemeshOptions::region_faces`] output faces and remesh it in three levels of independent
/// pieces, each level's at the same time: the regions, then the band around their cuts split
/// at the junctions into strips, then the junctions. Returns the number of regions (1:
/// nothing was done, the loop runs on the whole mesh as in the paper).
pub fn run_regions(ctx: &RunContext<'_>, state: &mut LoopState) -> Result<usize, PipelineError> {
    let o = &ctx.plan.options;
    // A patch budget counts the run's patches in order; regions would spend it at once.
    if o.max_patches.is_some() {
        return Ok(1);
    }
    // The metric the patches are remeshed in, at every vertex (the weights and the cuts').
    let field = ctx.field();
    let metrics: Vec<nalgebra::Matrix3<f64>> = (state.work.locations.as_slice().par_iter())
        .map(|l| field.eval_at(l))
        .collect();
    let weights = face_weights(ctx, &state.work, &metrics);
    let parts = partition(&state.work.mesh, &weights, o.region_faces as f64);
    if parts.len() < 2 {
        return Ok(1);
    }
    // Cuts are frozen at the working mesh's resolution: where it is coarser than the output
    // (the input's edges longer than the target in the metric), a region would keep edges the
    // output cannot have along its cuts. Then the run keeps one region.
    let cut = cut_edge_length(ctx, state, &metrics, &parts, CUT_QUANTILE);
    if cut > MAX_CUT_EDGE {
        state.regions_declined = Some(cut);
        return Ok(1);
    }
    let clock = std::time::Instant::now();
    state.work.processed.iter_mut().for_each(|p| *p = false);
    let cuts = run_groups(ctx, state, &parts, Level::Regions)?;
    state.wall.regions = clock.elapsed().as_secs_f64();
    let clock = std::time::Instant::now();
    let band_from = state.patches;
    // Junctions: vertices on the cuts of three regions or more.
    let mut seen_in = vec![0u8; state.work.mesh.n_vertices()];
    for region_cut in &cuts {
        for v in region_cut {
            seen_in[v.idx()] = seen_in[v.idx()].saturating_add(1);
        }
    }
    let cut: Vec<VertexId> = cuts.iter().flatten().copied().collect();
    let junctions: Vec<VertexId> = (0..seen_in.len())
        .filter(|&v| seen_in[v] >= 3)
        .map(VertexId::new)
        .collect();
    // The strips: the band minus the junctions' discs, in connected pieces.
    let mesh = &state.work.mesh;
    let band = faces_near(mesh, &cut, BAND_RINGS, 2);
    let disc = faces_near(mesh, &junctions, JUNCTION_RINGS, 1);
    let strip_faces: Vec<bool> = band.iter().zip(&disc).map(|(b, d)| *b && !d).collect();
    let strips = components(mesh, &state.topo, &strip_faces);
    // (Faces a level leaves out stay unprocessed, for the next level or the loop after.)
    mark_unprocessed(state.work.processed.as_mut_slice(), &strip_faces);
    let mut frozen = run_groups(ctx, state, &strips, Level::Strips)?;
    // The junctions, with the strips' ends (their cuts there were frozen).
    let mesh = &state.work.mesh;
    let disc = faces_near(mesh, &junctions, JUNCTION_RINGS + BAND_RINGS, 1);
    let discs = components(mesh, &state.topo, &disc);
    mark_unprocessed(state.work.processed.as_mut_slice(), &disc);
    frozen.extend(run_groups(ctx, state, &discs, Level::Junctions)?);
    // What the strips and junctions kept frozen is where the improvers run once more (their
    // vertices were pinned in every piece); the loop after takes any face still unprocessed.
    let frozen: Vec<VertexId> = frozen.into_iter().flatten().collect();
    let scope = vertices_near(&state.work.mesh, &frozen, 0);
    state.scope = Some(scope);
    state.sweep = o.sweeps.max(state.sweep);
    state.regions = Some((parts.len(), band_from));
    state.wall.band = clock.elapsed().as_secs_f64();
    Ok(parts.len())
}

fn mark_unprocessed(processed: &mut [bool], on: &[bool]) {
    for (p, o) in processed.iter_mut().zip(on) {
        *p &= !o;
    }
}

/// Regions are used only when at least [`CUT_QUANTILE`] of their cut edges are no longer than
/// this many L_tar in the metric the patches are remeshed in.
pub const MAX_CUT_EDGE: f64 = 1.2;

/// See [`MAX_CUT_EDGE`].
pub const CUT_QUANTILE: f64 = 0.9;

/// The `quantile` of the lengths of the edges between two regions of `parts`, in the metric
/// the patches are remeshed in, over L_tar.
fn cut_edge_length(
    ctx: &RunContext<'_>,
    state: &LoopState,
    metrics: &[nalgebra::Matrix3<f64>],
    parts: &[Vec<FaceId>],
    quantile: f64,
) -> f64 {
    let mesh = &state.work.mesh;
    let mut region_of = vec![0u32; mesh.n_faces()];
    for (r, faces) in parts.iter().enumerate() {
        faces.iter().for_each(|f| region_of[f.idx()] = r as u32);
    }
    let mut lengths: Vec<f64> = Vec::new();
    for f in mesh.faces() {
        for k in 0..3 {
            let Some(g) = state.topo.neighbor(f, k) else {
                continue;
            };
            if region_of[g.idx()] <= region_of[f.idx()] {
                continue;
            }
            let t = mesh.triangles[f.idx()];
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let m = (metrics[a.idx()] + metrics[b.idx()]) / 2.0;
            let d = mesh.position(b) - mesh.position(a);
            lengths.push((d.transpose() * m * d)[0].max(0.0).sqrt() / ctx.plan.l_tar);
        }
    }
    if lengths.is_empty() {
        return 0.0;
    }
    lengths.sort_by(|a, b| a.total_cmp(b));
    let i = ((quantile * lengths.len() as f64) as usize).min(lengths.len() - 1);
    lengths[i]
}

/// Rings of faces around the junctions that the strips leave out, and that the junctions'
/// pieces remesh with [`BAND_RINGS`] more (the strips' ends).
pub const JUNCTION_RINGS: usize = 8;

/// `flags[v]` for the vertices within `rings` rings of `seeds`.
fn vertices_near(mesh: &TriMesh, seeds: &[VertexId], rings: usize) -> VertexMap<bool> {
    let mut near = VertexMap::filled(mesh.n_vertices(), false);
    for &v in seeds {
        near[v] = true;
    }
    for _ in 0..rings {
        let mut grown = near.clone();
        for t in &mesh.triangles {
            if t.iter().any(|&v| near[v]) {
                t.iter().for_each(|&v| grown[v] = true);
            }
        }
        near = grown;
    }
    near
}

/// `flags[f]` for the faces with at least `corners` vertices within `rings` rings of `seeds`.
fn faces_near(mesh: &TriMesh, seeds: &[VertexId], rings: usize, corners: usize) -> Vec<bool> {
    let near = vertices_near(mesh, seeds, rings);
    mesh.triangles
        .iter()
        .map(|t| t.iter().filter(|&&v| near[v]).count() >= corners)
        .collect()
}

/// The faces flagged in `on`, in pieces connected across edges, each in increasing id order,
/// the pieces in the order of their smallest face.
fn components(mesh: &TriMesh, topo: &Topology, on: &[bool]) -> Vec<Vec<FaceId>> {
    let mut uf = UnionFind::new(mesh.n_faces());
    for f in mesh.faces().filter(|f| on[f.idx()]) {
        for k in 0..3 {
            if let Some(g) = topo.neighbor(f, k).filter(|g| on[g.idx()]) {
                uf.union(f.idx(), g.idx());
            }
        }
    }
    let mut piece_of: rustc_hash::FxHashMap<usize, usize> = Default::default();
    let mut pieces: Vec<Vec<FaceId>> = Vec::new();
    for f in mesh.faces().filter(|f| on[f.idx()]) {
        let root = uf.find(f.idx());
        let k = *piece_of.entry(root).or_insert_with(|| {
            pieces.push(Vec::new());
            pieces.len() - 1
        });
        pieces[k].push(f);
    }
    pieces
}

/// Leave out of their regions the faces that make a region touch itself at a vertex: at
/// every vertex where a region's faces form two fans or more, the faces of all but the
/// largest fan (ties: the one with the smallest face id) get `u32::MAX`, again until no such
/// vertex is left (regions only shrink, so this ends).
fn drop_pinches(mesh: &TriMesh, topo: &Topology, region_of: &mut [u32]) {
    let mut check: Vec<VertexId> = mesh
        .vertices()
        .filter(|&v| {
            let fs = topo.vertex_faces(v);
            fs.iter()
                .any(|f| region_of[f.idx()] != region_of[fs[0].idx()])
        })
        .collect();
    while !check.is_empty() {
        let mut next = Vec::new();
        for &v in &check {
            let fs = topo.vertex_faces(v);
            let mut labels: Vec<u32> = fs
                .iter()
                .map(|f| region_of[f.idx()])
                .filter(|r| *r != u32::MAX)
                .collect();
            labels.sort_unstable();
            labels.dedup();
            for r in labels {
                let mine: Vec<FaceId> = fs
                    .iter()
                    .copied()
                    .filter(|f| region_of[f.idx()] == r)
                    .collect();
                let fans = fans_at(mesh, v, &mine);
                if fans.len() < 2 {
                    continue;
                }
                let keep = (0..fans.len())
                    .max_by_key(|&i| (fans[i].len(), std::cmp::Reverse(fans[i][0])))
                    .unwrap_or(0);
                for (_, fan) in fans.iter().enumerate().filter(|(i, _)| *i != keep) {
                    for f in fan {
                        region_of[f.idx()] = u32::MAX;
                        next.extend(mesh.triangles[f.idx()]);
                    }
                }
            }
        }
        next.sort_unstable();
        next.dedup();
        check = next;
    }
}

/// The faces `faces` around vertex `v` in fans: joined when they share an edge at `v`; each
/// fan's faces in increasing id order, the fans in the order of their smallest face.
fn fans_at(mesh: &TriMesh, v: VertexId, faces: &[FaceId]) -> Vec<Vec<FaceId>> {
    let mut sorted = faces.to_vec();
    sorted.sort_unstable();
    let mut uf = UnionFind::new(sorted.len());
    let others = |f: FaceId| {
        let t = mesh.triangles[f.idx()];
        let k = t.iter().position(|w| *w == v).unwrap_or(0);
        [t[(k + 1) % 3], t[(k + 2) % 3]]
    };
    for i in 0..sorted.len() {
        for j in i + 1..sorted.len() {
            let (a, b) = (others(sorted[i]), others(sorted[j]));
            if a.iter().any(|x| b.contains(x)) {
                uf.union(i, j);
            }
        }
    }
    let mut root_fan: Vec<(usize, usize)> = Vec::new();
    let mut fans: Vec<Vec<FaceId>> = Vec::new();
    for (i, &f) in sorted.iter().enumerate() {
        let root = uf.find(i);
        match root_fan.iter().find(|(r, _)| *r == root) {
            Some(&(_, k)) => fans[k].push(f),
            None => {
                root_fan.push((root, fans.len()));
                fans.push(vec![f]);
            }
        }
    }
    fans
}

/// Run disjoint face sets of the whole working mesh as regions at the same time, each with
/// its cuts frozen, and merge them back. Returns, per group, the whole mesh's vertices on its
/// cuts.
fn run_groups(
    ctx: &RunContext<'_>,
    state: &mut LoopState,
    groups: &[Vec<FaceId>],
    level: Level,
) -> Result<Vec<Vec<VertexId>>, PipelineError> {
    if groups.is_empty() {
        return Ok(Vec::new());
    }
    let mut region_of = vec![u32::MAX; state.work.mesh.n_faces()];
    for (r, faces) in groups.iter().enumerate() {
        for f in faces {
            region_of[f.idx()] = r as u32;
        }
    }
    // A region that touches itself at a vertex would have copies of it there, which the
    // candidates' exact intersection test sees as two vertices at one point: the faces of
    // its smaller fans there are left out (unprocessed, for a later level or the loop).
    drop_pinches(&state.work.mesh, &state.topo, &mut region_of);
    let mut kept: Vec<Vec<FaceId>> = vec![Vec::new(); groups.len()];
    for (f, r) in region_of.iter().enumerate() {
        if *r != u32::MAX {
            kept[*r as usize].push(FaceId::new(f));
        }
    }
    let groups = &kept;
    let whole_faces = state.work.mesh.n_faces() as f64;
    let runs: Vec<RegionRun> = groups
        .par_iter()
        .enumerate()
        .map(|(r, faces)| {
            let region = extract(&state.work, &state.topo, &region_of, r as u32, faces);
            let share = faces.len() as f64 / whole_faces;
            // Stream blocks: 2²⁰ regions per level at most.
            let index = ((level as usize) << 20) + r;
            run_region(ctx, state, region, index, share, level == Level::Regions).map_err(|e| {
                match e {
                    // A stop request is the run's, not the piece's.
                    PipelineError::Cancelled { .. } => e,
                    e => PipelineError::Region {
                        level: level.name(),
                        index: r,
                        faces: faces.len(),
                        source: Box::new(e),
                    },
                }
            })
        })
        .collect::<Result<_, _>>()?;
    Ok(merge(state, &region_of, runs))
}

/// Algorithm 1 and the improvers on one region, and its certificates.
fn run_region(
    ctx: &RunContext<'_>,
    whole: &LoopState,
    region: RegionMesh,
    index: usize,
    share: f64,
    first_level: bool,
) -> Result<RegionRun, PipelineError> {
    let topo = Topology::build(&region.work.mesh);
    let cut = Arc::new(region.cut.clone());
    let n = region.whole.len();
    let from_whole = |flags: &VertexMap<bool>| -> VertexMap<bool> {
        (0..n)
            .map(|l| cut.vertices[l] || flags.get(region.whole[l]).copied().unwrap_or(false))
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
    let bound = region.whole.iter().map(|&v| whole.bound[v]).collect();
    let mut state = LoopState::from_parts(region.work.clone(), topo, features, pinned, bound);
    state.budget_share = share;
    // The further sweeps (the coarse-input profile) are the first level's; the strips and
    // junctions remesh their pieces once.
    state.sweep = match first_level {
        true => whole.sweep,
        false => ctx.plan.options.sweeps.max(whole.sweep),
    };
    state.index_faces(&rctx);
    state.streams = (index as u64 + 1) * REGION_STREAMS;
    let mut rng = crate::Rng::seed_from_u64(ctx.plan.options.seed);
    rng.set_stream(state.streams);
    super::patch_loop(&rctx, &mut state, &mut rng, &mut |_| {})?;
    super::improvement::run(&rctx, &mut state, &mut rng)?;
    // The piece whole: manifold, oriented, its topology, its cuts kept and its other
    // boundary on the input's curves, corners and feature lines where they were.
    super::finish::certify_whole(&rctx, &mut state)?;
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

/// Put the regions' meshes back into the whole: the whole mesh's vertices keep their ids
/// (those the regions removed are left unreferenced, for the final compaction), each
/// region's new vertices are appended in region order; the faces in no region stay first, in
/// their order, then the regions' faces in region order, processed. Everything kept in step
/// with the working mesh follows. Returns, per region, the whole mesh's vertices on its cuts.
fn merge(state: &mut LoopState, region_of: &[u32], runs: Vec<RegionRun>) -> Vec<Vec<VertexId>> {
    let w = &mut state.work;
    let mut triangles = Vec::with_capacity(w.mesh.n_faces());
    let mut processed = FaceMap::from_vec(Vec::with_capacity(w.mesh.n_faces()));
    let mut face_patch = FaceMap::from_vec(Vec::with_capacity(w.mesh.n_faces()));
    for (f, t) in w.mesh.triangles.iter().enumerate() {
        if region_of[f] == u32::MAX {
            triangles.push(*t);
            processed.push(w.processed[FaceId::new(f)]);
            face_patch.push(state.face_patch.get(FaceId::new(f)).copied().flatten());
        }
    }
    let mut cuts = Vec::with_capacity(runs.len());
    for run in runs {
        let RegionRun { region, state: rs } = run;
        let n0 = region.whole.len();
        let mut map: Vec<VertexId> = region.whole.clone();
        for l in n0..rs.work.mesh.n_vertices() {
            map.push(VertexId::new(w.mesh.n_vertices()));
            w.mesh.positions.push(rs.work.mesh.positions[l]);
            w.locations.push(rs.work.locations[VertexId::new(l)]);
            w.curve
                .push(rs.work.curve.get(VertexId::new(l)).copied().flatten());
            state
                .bound
                .push(rs.bound.get(VertexId::new(l)).copied().unwrap_or(1.0));
            state.pinned.push(false);
            state.factors.push(rs.factors.get(VertexId::new(l)));
        }
        let mut on_cut = Vec::new();
        for (l, &v) in map.iter().enumerate().take(n0) {
            // The region's passes may have moved a vertex it shares with no other region (its
            // cut vertices are frozen, so this writes them back unchanged): its faces were
            // certified at the new place.
            w.mesh.positions[v.idx()] = rs.work.mesh.positions[l];
            w.locations[v] = rs.work.locations[VertexId::new(l)];
            w.curve[v] = rs.work.curve.get(VertexId::new(l)).copied().flatten();
            state.factors.raise(v, rs.factors.get(VertexId::new(l)));
            if region.cut.vertices[l] {
                on_cut.push(v);
            }
        }
        on_cut.sort_unstable();
        on_cut.dedup();
        cuts.push(on_cut);
        let offset = state.patches;
        triangles.extend(
            rs.work
                .mesh
                .triangles
                .iter()
                .map(|t| t.map(|v| map[v.idx()])),
        );
        processed.extend(std::iter::repeat_n(true, rs.work.mesh.n_faces()));
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
    w.processed = processed;
    state.face_patch = face_patch;
    state.topo = Topology::build(&w.mesh);
    cuts
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
        let ones = vec![1.0; mesh.n_faces()];
        let parts = partition(&mesh, &ones, 700.0);
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
        assert_eq!(parts, partition(&mesh, &ones, 700.0));
        assert_eq!(partition(&mesh, &ones, 0.0).len(), 1);
        assert_eq!(partition(&mesh, &ones, mesh.n_faces() as f64).len(), 1);
        // Weights move the cuts: a heavy half is cut into more regions than a light one.
        let heavy: Vec<f64> = mesh
            .faces()
            .map(|f| match mesh.face_points(f)[0].x > 0.0 {
                true => 4.0,
                false => 1.0,
            })
            .collect();
        let weighted = partition(&mesh, &heavy, 1400.0);
        for p in &weighted {
            let w: f64 = p.iter().map(|f| heavy[f.idx()]).sum();
            assert!(w <= 1400.0 || p.len() == 1, "a region of weight {w}");
        }
        let on_heavy_side =
            |p: &Vec<FaceId>| p.iter().filter(|f| heavy[f.idx()] > 1.0).count() * 2 > p.len();
        let (h, l) = (
            weighted.iter().filter(|p| on_heavy_side(p)).count(),
            weighted.iter().filter(|p| !on_heavy_side(p)).count(),
        );
        assert!(h > l, "{h} regions on the heavy side, {l} on the light one");
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

    /// After `drop_pinches` no region touches itself at a vertex, and only faces that were in
    /// a region left it: on the 2×2 grid whose region 0 is two quads meeting at the centre, and
    /// on a sphere's regions with one region's faces thinned out.
    #[test]
    fn drop_pinches_leaves_one_fan_per_region_at_every_vertex() {
        let plate = generators::plate(1.0, 2);
        let checker: Vec<u32> = plate
            .faces()
            .map(|f| {
                let [a, b, c] = plate.face_points(f);
                let m = (a.coords + b.coords + c.coords) / 3.0;
                u32::from((m.x > 0.5) != (m.y > 0.5))
            })
            .collect();
        let sphere = generators::icosphere(1.0, 3);
        let mut thinned = vec![u32::MAX; sphere.n_faces()];
        let ones = vec![1.0; sphere.n_faces()];
        for (r, faces) in partition(&sphere, &ones, 200.0).iter().enumerate() {
            for f in faces {
                // Every third face of region 0 left out: pinches all over it.
                if r != 0 || f.idx() % 3 != 0 {
                    thinned[f.idx()] = r as u32;
                }
            }
        }
        for (mesh, before) in [(&plate, checker), (&sphere, thinned)] {
            let topo = Topology::build(mesh);
            let mut after = before.clone();
            drop_pinches(mesh, &topo, &mut after);
            for (b, a) in before.iter().zip(&after) {
                assert!(a == b || *a == u32::MAX, "a face changed region");
            }
            for v in mesh.vertices() {
                let fs = topo.vertex_faces(v);
                for &f in fs {
                    let r = after[f.idx()];
                    if r == u32::MAX {
                        continue;
                    }
                    let mine: Vec<FaceId> =
                        fs.iter().copied().filter(|g| after[g.idx()] == r).collect();
                    assert_eq!(fans_at(mesh, v, &mine).len(), 1, "{v}: region {r} pinched");
                }
            }
            assert!(after.iter().any(|r| *r != u32::MAX));
        }
    }

    /// The merge writes back where a region moved the vertices it shares with no other
    /// region (its faces were certified there), and keeps its cut vertices where they were.
    #[test]
    fn merge_keeps_the_moves_a_region_made() {
        let mesh = generators::plate(1.0, 4);
        let topo = Topology::build(&mesh);
        let n = mesh.n_vertices();
        let mut whole = LoopState::from_parts(
            WorkingMesh::from_reference(&mesh),
            topo.clone(),
            crate::features::FeatureLines::default(),
            VertexMap::filled(n, false),
            VertexMap::filled(n, 1.0),
        );
        // Region 0 is the left half; the right half is in no region and stays as it is.
        let region_of: Vec<u32> = (mesh.faces())
            .map(|f| {
                let [a, b, c] = mesh.face_points(f);
                match (a.x + b.x + c.x) / 3.0 < 0.5 {
                    true => 0,
                    false => u32::MAX,
                }
            })
            .collect();
        let faces: Vec<FaceId> = mesh.faces().filter(|f| region_of[f.idx()] == 0).collect();
        let region = extract(&whole.work, &topo, &region_of, 0, &faces);
        let nl = region.whole.len();
        let mut rs = LoopState::from_parts(
            region.work.clone(),
            Topology::build(&region.work.mesh),
            crate::features::FeatureLines::default(),
            VertexMap::filled(nl, false),
            VertexMap::filled(nl, 1.0),
        );
        let inner = (0..nl)
            .find(|&l| {
                let p = region.work.mesh.positions[l];
                !region.cut.vertices[l] && p.x > 0.0 && p.y > 0.0 && p.y < 1.0
            })
            .expect("a vertex inside the region");
        let cut = (0..nl)
            .find(|&l| region.cut.vertices[l])
            .expect("a cut vertex");
        let moved = rs.work.mesh.positions[inner] + nalgebra::Vector3::new(0.01, 0.02, 0.0);
        rs.work.mesh.positions[inner] = moved;
        let (v_inner, v_cut) = (region.whole[inner], region.whole[cut]);
        let cut_before = whole.work.mesh.positions[v_cut.idx()];
        merge(
            &mut whole,
            &region_of,
            vec![RegionRun { region, state: rs }],
        );
        assert_eq!(whole.work.mesh.positions[v_inner.idx()], moved);
        assert_eq!(whole.work.mesh.positions[v_cut.idx()], cut_before);
        assert_eq!(whole.work.mesh.n_faces(), mesh.n_faces());
    }
}
