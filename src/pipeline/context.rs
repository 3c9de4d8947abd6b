//! The state of a run: [`RunContext`], what every patch reads and nothing changes, and
//! [`LoopState`], the working mesh with everything kept in step with it.

use super::error::PipelineError;
use super::options::Stages;
use super::records::{Certificate, Fallbacks, PatchRecord, Progress, StageTimes};
use super::sizing::Plan;
use crate::boundary::BoundaryCurves;
use crate::features::FeatureLines;
use crate::fidelity::VertexFactors;
use crate::ids::{EdgeKey, FaceMap, PatchId, VertexId, VertexMap};
use crate::improve::{Improver, LoopStages};
use crate::invariants::{self, FlipTest, TopologySignature};
use crate::mesh::Topology;
use crate::metric::MetricField;
use crate::patches::PatchContext;
use crate::stitch::WorkingMesh;
use nalgebra::Vector3;
use std::collections::HashSet;
use std::sync::Arc;

/// What every patch of a run reads: the metric, the plan, the stages, and what was certified
/// or derived from the input once.
pub struct RunContext<'a> {
    /// The metric every quality is measured in (the input's, unscaled).
    pub quality_field: &'a MetricField,
    /// The sizes and the effective options.
    pub plan: &'a Plan,
    /// The stages each patch goes through.
    pub stages: LoopStages<'a>,
    /// The improvers after the loop, in order.
    pub improvers: &'a [Box<dyn Improver>],
    /// The flip certificate against the reference (shared with the contexts of Algorithm 2's
    /// passes, which would otherwise index the reference again).
    pub flip_test: Arc<FlipTest>,
    /// Area-weighted vertex normals of the reference (the fidelity control's; shared with
    /// the regions' contexts).
    pub ref_normals: Arc<VertexMap<Vector3<f64>>>,
    /// Self-intersecting face pairs of the input (0 when not checked).
    pub input_pairs: usize,
    /// Candidates are checked for local self-intersections: the check is on and the input
    /// is embedded (an input that self-intersects cannot be replaced by an embedded surface
    /// on it).
    pub embedded_input: bool,
    /// The input's topology, certified an oriented manifold (shared with the regions').
    pub reference_topology: Arc<Topology>,
    /// The topology every working mesh must keep.
    pub signature: TopologySignature,
    /// The input's boundary edges.
    pub input_boundary: Vec<EdgeKey>,
    /// `corners[v]`: input vertex `v` is kept as a corner (its working-mesh id is stable;
    /// new vertices are never corners).
    pub corners: VertexMap<bool>,
    /// The input's boundary curves, with their corners.
    pub curves: BoundaryCurves,
    /// Algorithm 2 runs (its patches keep their boundary chains as they are).
    pub improving: bool,
    /// In a region's run: its cuts, kept bit for bit ([`super::regions`]); `None` in the
    /// run on the whole mesh.
    pub frozen: Option<Arc<FrozenCut>>,
}

/// The cuts of a region's run ([`super::regions`]): the edges where the region meets the
/// others, which no patch, chain or pass may change, and their vertices, which are corners.
#[derive(Clone, Debug, Default)]
pub struct FrozenCut {
    /// The cut edges, by the region's vertex ids, sorted.
    pub edges: Vec<EdgeKey>,
    /// `vertices[v]`: the region's vertex `v` lies on a cut (past the end: a new vertex).
    pub vertices: Vec<bool>,
    /// Where each of the region's vertices was when the region's run started.
    pub positions: Vec<nalgebra::Point3<f64>>,
}

impl FrozenCut {
    /// `a`–`b` is a cut edge.
    pub fn is_cut_edge(&self, a: VertexId, b: VertexId) -> bool {
        self.edges.binary_search(&EdgeKey::new(a, b)).is_ok()
    }

    /// `v` lies on a cut.
    pub fn is_cut_vertex(&self, v: VertexId) -> bool {
        self.vertices.get(v.idx()).copied().unwrap_or(false)
    }
}

impl<'a> RunContext<'a> {
    /// Derive the context of a run on `field`'s reference; `reference_topology` is its
    /// topology, already certified an oriented manifold.
    pub fn new(
        field: &'a MetricField,
        reference_topology: Topology,
        plan: &'a Plan,
        stages: &'a Stages,
    ) -> RunContext<'a> {
        let reference = field.reference();
        let o = &plan.options;
        let input_pairs = match o.check_self_intersections {
            true => invariants::self_intersections(reference).len(),
            false => 0,
        };
        let corners = match o.corner_defect {
            Some(d) => VertexMap::from_vec(crate::patches::corner_vertices(
                reference,
                &reference_topology,
                d,
            )),
            None => VertexMap::default(),
        };
        let curves = BoundaryCurves::new(
            reference,
            &reference_topology,
            o.boundary.corner_angle,
            o.corner_defect,
        );
        RunContext {
            curves,
            quality_field: field,
            plan,
            stages: stages.loop_stages(),
            improvers: &stages.improvers,
            flip_test: Arc::new(FlipTest::with_index(
                Arc::clone(field.shared_reference()),
                field.projector(),
            )),
            ref_normals: Arc::new(VertexMap::from_vec(reference.area_weighted_normals())),
            input_pairs,
            embedded_input: o.check_self_intersections && input_pairs == 0,
            signature: TopologySignature::of(&reference_topology),
            input_boundary: invariants::boundary_edges(&reference_topology),
            reference_topology: Arc::new(reference_topology),
            corners,
            improving: false,
            frozen: None,
        }
    }

    /// The same run with other stages for Algorithm 2 (whose patches keep their boundary
    /// chains as they are).
    pub fn for_improvement<'b>(&'b self, stages: LoopStages<'b>) -> RunContext<'b> {
        RunContext {
            quality_field: self.quality_field,
            plan: self.plan,
            stages,
            improvers: &[],
            flip_test: self.flip_test.clone(),
            ref_normals: self.ref_normals.clone(),
            input_pairs: self.input_pairs,
            embedded_input: self.embedded_input,
            reference_topology: self.reference_topology.clone(),
            signature: self.signature.clone(),
            input_boundary: self.input_boundary.clone(),
            corners: self.corners.clone(),
            curves: self.curves.clone(),
            improving: true,
            frozen: self.frozen.clone(),
        }
    }

    /// The metric the patches are remeshed in (with the a-priori fidelity scaling).
    pub fn field(&self) -> &MetricField {
        self.plan.remesh_field(self.quality_field)
    }

    /// Faces processed over all sweeps.
    fn total_faces(&self, per_sweep: usize) -> usize {
        per_sweep * self.plan.options.sweeps.max(1)
    }
}

/// The a-priori fidelity factor at a point of the reference (1 when the control is off).
pub fn a_priori_at(
    fid_scale: &[f64],
    reference: &crate::mesh::TriMesh,
    loc: &crate::mesh::SurfaceLocation,
) -> f64 {
    if fid_scale.is_empty() {
        return 1.0;
    }
    let t = reference.face(loc.face);
    (0..3).map(|k| loc.bary[k] * fid_scale[t[k].idx()]).sum()
}

/// The working mesh and everything kept in step with it while the loop runs.
pub struct LoopState {
    /// The mesh being remeshed, its vertices' reference locations and processed flags.
    pub work: WorkingMesh,
    /// Its topology (rebuilt after every patch).
    pub topo: Topology,
    /// The feature lines split into it before the loop.
    pub features: FeatureLines,
    /// `pinned[v]`: corners and feature-line vertices, which no pass moves.
    pub pinned: VertexMap<bool>,
    /// The fidelity factor per working-mesh vertex (carried between patches with
    /// [`crate::fidelity::FidelityOptions::persist`]).
    pub factors: VertexFactors,
    /// By how much the fidelity control scaled the metric where each working-mesh vertex was
    /// made (the a-priori factor at its location times its patch's rounds): above 1 the
    /// tolerance, not the metric, set the size there.
    pub bound: VertexMap<f64>,
    /// Which patch produced each working-mesh face (`None`: an input face).
    pub face_patch: FaceMap<Option<PatchId>>,
    /// Faces of the working mesh when the loop started (one sweep's work).
    pub faces_per_sweep: usize,
    /// The share of the run's expected output this loop makes (1; a region's faces over
    /// the whole mesh's in a region's run), which scales its budgets.
    pub budget_share: f64,
    /// The current sweep (1-based).
    pub sweep: usize,
    /// Patches done (Algorithm 1's and the improvers').
    pub patches: usize,
    /// Patches of Algorithm 1's loop (set when it ends).
    pub loop_patches: usize,
    /// Batches of Algorithm 1's loop.
    pub batches: usize,
    /// The patch budget ran out.
    pub budget_exhausted: bool,
    /// The working mesh outgrew its face budget (times the expected output): the fidelity
    /// control no longer refines and no further sweep starts.
    pub over_face_budget: bool,
    /// (patches, faces) when it did.
    pub over_face_budget_at: Option<(usize, usize)>,
    /// Over the work budget: patches made and work done when it happened
    /// ([`LoopState::note_work_budget`]).
    pub over_work_budget_at: Option<(usize, usize)>,
    /// Over twice the work budget: no further patch starts.
    pub work_stopped: bool,
    /// Times and certificate counts.
    pub counters: Counters,
    /// Wall-clock time of the run's phases so far.
    pub wall: super::records::PhaseTimes,
    /// Per-patch records.
    pub records: Vec<PatchRecord>,
    /// What the retry ladder did.
    pub fallbacks: Fallbacks,
    /// What Algorithm 2 did, when it ran.
    pub improvement: Option<super::records::ImprovementReport>,
    /// `blocked[f]` while a batch is chosen: face `f` shares a vertex with a patch already in
    /// the batch ([`PatchContext::blocked`]); empty between batches.
    pub blocked: FaceMap<bool>,
    /// Where this loop's streams start: 0 for the run on the whole mesh (a batch's patch in
    /// slot `s` draws stream `s + 1`), `(r + 1) · 2³²` for region r's loop
    /// ([`super::regions`]), so no two loops share a stream.
    pub streams: u64,
    /// The regions were declined: this quantile of their cut edges' lengths (over L_tar) was
    /// above [`crate::pipeline::MAX_CUT_EDGE`].
    pub regions_declined: Option<f64>,
    /// Regions the loop ran in, and the first patch of the band's loop after them (`None`:
    /// one region).
    pub regions: Option<(usize, usize)>,
    /// The vertices the improvers may change (the bands around the regions' cuts, after the
    /// regions' runs; past the end: vertices made since, in scope); `None`: all.
    pub scope: Option<VertexMap<bool>>,
    /// Where the working mesh's faces lie, for the candidates' self-intersection certificate
    /// (when the input is embedded); built again before each pass of patches
    /// ([`LoopState::index_faces`]).
    pub near: Option<crate::invariants::NearFaces>,
    /// What holds each vertex of the compacted output in place (set by
    /// [`super::finish::certify_output`]; empty before).
    pub vertex_kinds: VertexMap<super::records::VertexKind>,
}

/// Per-stage times and certificate counts of a run.
#[derive(Default)]
pub struct Counters {
    /// Wall time per stage.
    pub times: StageTimes,
    /// Certificates checked and held.
    pub cert: Certificate,
    /// Faces handled by patch attempts ([`super::RemeshOptions::work_budget`]).
    pub work: usize,
}

impl Counters {
    /// Add another patch's counters (times add up: the stage times of a batch's patches,
    /// which run at the same time, are summed).
    pub fn absorb(&mut self, other: Counters) {
        self.times.add(&other.times);
        self.cert.add(&other.cert);
        self.work += other.work;
    }
}

impl LoopState {
    /// The working mesh at the start: the reference, with its feature lines split to the
    /// target length.
    pub fn new(ctx: &RunContext<'_>) -> Result<LoopState, PipelineError> {
        let reference = ctx.quality_field.reference();
        let mut work = WorkingMesh::from_reference(reference);
        for v in reference.vertices() {
            work.curve[v] = ctx.curves.point_at_vertex(v);
        }
        let features = crate::features::split_to_target(
            &mut work,
            reference,
            &ctx.reference_topology,
            &ctx.plan.feature_edges,
            ctx.corners.as_slice(),
            &crate::features::PieceTarget {
                metrics: ctx.field().vertex_metrics(),
                l_tar: ctx.plan.l_tar,
                max_deviation: ctx.plan.options.fidelity.max_deviation,
            },
            &ctx.flip_test,
        )?;
        let pinned = (0..work.mesh.n_vertices())
            .map(VertexId::new)
            .map(|v| ctx.corners.get(v).copied().unwrap_or(false) || features.is_pinned(v))
            .collect();
        let topo = match features.edges.is_empty() {
            true => (*ctx.reference_topology).clone(),
            false => {
                // The stage's certificate: the collapses kept an oriented manifold without
                // degenerate faces (exact) and the input's topology.
                let topo = Topology::build(&work.mesh);
                let (live, _) = work.mesh.without_unreferenced_vertices();
                invariants::certify_manifold(&work.mesh, &topo)
                    .and_then(|()| invariants::certify_oriented(&work.mesh, &topo))
                    .and_then(|()| no_new_degenerate_face(reference, &work.mesh))
                    .and_then(|()| invariants::certify_same_topology(reference, &live))
                    .map_err(PipelineError::FeatureLines)?;
                topo
            }
        };
        let bound = work
            .locations
            .iter()
            .map(|l| a_priori_at(&ctx.plan.fid_scale, reference, l))
            .collect();
        Ok(LoopState::from_parts(work, topo, features, pinned, bound))
    }

    /// A loop's state at its start: `work` (nothing processed by this loop yet, unless the
    /// caller marks it), its topology, feature lines, pinned vertices and fidelity bounds.
    pub fn from_parts(
        work: WorkingMesh,
        topo: Topology,
        features: FeatureLines,
        pinned: VertexMap<bool>,
        bound: VertexMap<f64>,
    ) -> LoopState {
        LoopState {
            bound,
            factors: VertexFactors::ones(work.mesh.n_vertices()),
            face_patch: FaceMap::filled(work.mesh.n_faces(), None),
            faces_per_sweep: work.mesh.n_faces(),
            budget_share: 1.0,
            sweep: 1,
            patches: 0,
            loop_patches: 0,
            batches: 0,
            budget_exhausted: false,
            over_face_budget: false,
            over_face_budget_at: None,
            over_work_budget_at: None,
            work_stopped: false,
            counters: Counters::default(),
            wall: Default::default(),
            records: Vec::new(),
            fallbacks: Fallbacks::default(),
            improvement: None,
            blocked: FaceMap::default(),
            scope: None,
            streams: 0,
            regions: None,
            regions_declined: None,
            near: None,
            vertex_kinds: VertexMap::default(),
            work,
            topo,
            features,
            pinned,
        }
    }

    /// Algorithm 1's loop condition: true while an unprocessed face remains, starting a
    /// further sweep (every face unprocessed again) when one ends and more are asked for, and
    /// false once the patch budget is spent.
    pub fn face_remains(&mut self, ctx: &RunContext<'_>) -> bool {
        let o = &ctx.plan.options;
        if self.work.unprocessed() == 0 {
            if self.sweep >= o.sweeps || self.over_face_budget || self.over_work_budget() {
                return false;
            }
            // A further sweep (our addition): the new patches' fixed boundaries run through
            // the previous sweep's remeshed faces (edges near L_tar) instead of the input's
            // edges, and the previous seams end up inside new patches.
            self.sweep += 1;
            self.work.processed.iter_mut().for_each(|p| *p = false);
        }
        if o.max_patches.is_some_and(|max| self.patches >= max) {
            self.budget_exhausted = true;
            return false;
        }
        !self.work_stopped
    }

    /// The work budget in faces handled: [`super::RemeshOptions::work_budget`] times the
    /// face budget's base.
    pub fn work_budget(&self, ctx: &RunContext<'_>) -> f64 {
        let base = self.expected_share(ctx).max(self.faces_per_sweep as f64);
        ctx.plan.options.work_budget * base
    }

    /// The expected output with the a-priori scaling, times this loop's share of it.
    fn expected_share(&self, ctx: &RunContext<'_>) -> f64 {
        match self.budget_share == 1.0 {
            true => ctx.plan.expected_fidelity,
            false => ctx.plan.expected_fidelity * self.budget_share,
        }
    }

    /// Whether the run is over its work budget (no refinement, no further sweep, no improver
    /// patch pass).
    pub fn over_work_budget(&self) -> bool {
        self.over_work_budget_at.is_some()
    }

    /// Note whether the work done is over the run's work budget, and over twice it (then no
    /// further patch starts). The count, unlike a clock, is the same on every machine and
    /// thread count, so the output still depends on the seed only.
    pub fn note_work_budget(&mut self, ctx: &RunContext<'_>) {
        let (work, budget) = (self.counters.work, self.work_budget(ctx));
        if !self.over_work_budget() && work as f64 > budget {
            self.over_work_budget_at = Some((self.patches, work));
        }
        if work as f64 > 2.0 * budget {
            self.work_stopped = true;
        }
    }

    /// Note whether the working mesh is over the run's face budget:
    /// [`super::RemeshOptions::face_budget`] times the larger of the input's face count and the output expected with the a-priori fidelity
    /// scaling. A run's cost grows with its faces; where the fidelity control keeps
    /// refining without reaching its tolerance (a crease no feature line follows, cut by
    /// every chord), this bounds it, and the run ends `Ok` with a warning.
    pub fn note_face_budget(&mut self, ctx: &RunContext<'_>) {
        let base = self.expected_share(ctx).max(self.faces_per_sweep as f64);
        if !self.over_face_budget
            && self.work.mesh.n_faces() as f64 > ctx.plan.options.face_budget * base
        {
            self.over_face_budget = true;
            self.over_face_budget_at = Some((self.patches, self.work.mesh.n_faces()));
        }
    }

    /// The unscaled metric (what `eval` measures in) at every working-mesh vertex's reference
    /// location.
    pub fn vertex_metrics(&self, ctx: &RunContext<'_>) -> Vec<nalgebra::Matrix3<f64>> {
        self.work
            .locations
            .iter()
            .map(|l| ctx.quality_field.eval_at(l))
            .collect()
    }

    /// Every per-face and per-vertex map of the loop has one entry per element of the
    /// working mesh (checked after each stitched batch in debug builds).
    pub fn in_step(&self) -> bool {
        let (nv, nf) = (self.work.mesh.n_vertices(), self.work.mesh.n_faces());
        self.work.locations.len() == nv
            && self.work.curve.len() == nv
            && self.work.processed.len() == nf
            && self.bound.len() == nv
            && self.pinned.len() == nv
            && self.face_patch.len() == nf
    }

    /// What the strategy sees.
    pub fn patch_context<'s>(&'s self, ctx: &'s RunContext<'_>) -> PatchContext<'s> {
        PatchContext {
            mesh: &self.work.mesh,
            topology: &self.topo,
            processed: self.work.processed.as_slice(),
            feature_edges: self.feature_edges(),
            corners: Some(ctx.corners.as_slice()),
            blocked: (!self.blocked.is_empty()).then_some(self.blocked.as_slice()),
        }
    }

    /// Reserve `faces` (a patch taken into the batch): every face sharing a vertex with them
    /// is blocked for the batch's later patches.
    pub fn block_around(&mut self, faces: &[crate::ids::FaceId]) {
        self.blocked.resize(self.work.mesh.n_faces(), false);
        for f in faces {
            for v in self.work.mesh.triangles[f.idx()] {
                for &g in self.topo.vertex_faces(v) {
                    self.blocked[g] = true;
                }
            }
        }
    }

    /// Index the working mesh's faces for the candidates' certificate (vertices may have moved
    /// since the last index: the surface passes move them in place).
    pub fn index_faces(&mut self, ctx: &RunContext<'_>) {
        self.near = ctx
            .embedded_input
            .then(|| crate::invariants::NearFaces::new(&self.work.mesh));
    }

    /// The feature-line pieces, when there are any.
    pub fn feature_edges(&self) -> Option<&HashSet<EdgeKey>> {
        (!self.features.edges.is_empty()).then_some(&self.features.edges)
    }

    /// Progress after the current patch.
    pub fn progress(&self, ctx: &RunContext<'_>) -> Progress {
        let sweeps = ctx.plan.options.sweeps.max(1);
        Progress {
            patches: self.patches,
            unprocessed: self.work.unprocessed() + (sweeps - self.sweep) * self.faces_per_sweep,
            total: ctx.total_faces(self.faces_per_sweep),
        }
    }
}

/// No face of `work` has exactly zero area unless it is a face of the input unchanged (same
/// corners, same order): a zero-area input face is the loop's to remesh, not the feature-line
/// stage's doing.
fn no_new_degenerate_face(
    reference: &crate::mesh::TriMesh,
    work: &crate::mesh::TriMesh,
) -> Result<(), invariants::InvariantError> {
    let input: HashSet<[VertexId; 3]> = invariants::degenerate_faces(reference)
        .into_iter()
        .map(|f| reference.triangles[f.idx()])
        .collect();
    let new: Vec<crate::ids::FaceId> = invariants::degenerate_faces(work)
        .into_iter()
        .filter(|f| !input.contains(&work.triangles[f.idx()]))
        .collect();
    match new.is_empty() {
        true => Ok(()),
        false => Err(invariants::InvariantError::DegenerateFaces(
            invariants::Offenders(new),
        )),
    }
}
