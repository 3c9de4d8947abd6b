//! Algorithm 1: the loop over patches.
//!
//! ```text
//! while an unprocessed face remains:
//!     P  = strategy.next_patch(working mesh, processed, rng)       // Sec. 3.2  (certify_disk)
//!     uv = parameterizer.parameterize(P)                            // Sec. 3.3  (certify_bijective)
//!     M2 = transfer_metric(P, uv, M at the reference locations)     // Eq. 4
//!     P' = remesher.remesh(uv domain, M2, L_tar)                     // LCT       (certify_planar)
//!     lift P' by barycentric location in the initial 2D mesh and
//!         project onto the reference surface                         // "Mapping back"
//!     certify the candidate (no degenerate or flipped new face)
//!     stitch P' into the working mesh, mark its faces processed     // manifold, oriented,
//!                                                                    // same topology, boundary
//! at the end: no self-intersections (exact)
//! ```
//!
//! Everything runs in the unit-diagonal space of the metric field's reference mesh
//! (`crate::metric::Normalization`); the caller maps the result back to file units.

use crate::fidelity::{self, FidelityOptions, LiftedPatch};
use crate::ids::{EdgeKey, FaceId, PatchId, VertexId};
use crate::invariants::{self, InvariantError, Offenders};
use crate::lift::{lift, PatchFrame};
use crate::mesh::{SurfaceLocation, Topology, TriMesh};
use crate::metric::MetricField;
use crate::param::{DistortionReport, Parameterizer, SymmetricDirichlet};
use crate::patches::{extract_patch, ConePatches, DiskPatch, PatchContext, PatchStrategy};
use crate::quality::FlipTest;
use crate::remesh2d::{
    pullback_corners, transfer_metric, Lct, PlanarDomain, PlanarMetricField, PlanarRemesher,
    TransferMethod,
};
use crate::stitch::{stitch, Replacement, WorkingMesh};
use nalgebra::{Matrix3, Point3, Vector3};
use rand::SeedableRng;
use serde::Serialize;
use std::collections::HashSet;
use std::path::PathBuf;
use std::time::Instant;
use thiserror::Error;

/// Errors of Algorithm 1. Every variant names the patch, its seed and the offending elements.
#[derive(Debug, Error)]
pub enum PipelineError {
    /// A stage failed on a patch.
    #[error("patch {patch} (seed {seed}): {stage} failed: {message}")]
    Stage {
        /// which patch
        patch: PatchId,
        /// its seed vertex
        seed: VertexId,
        /// which stage
        stage: &'static str,
        /// what failed
        message: String,
    },
    /// A certificate on the working mesh failed after a patch was stitched.
    #[error("after patch {patch} (seed {seed}): {violation}{}", debug_note(.debug_file))]
    Certificate {
        /// which patch (`p0` before the first one)
        patch: PatchId,
        /// its seed vertex
        seed: VertexId,
        /// the violated invariant, naming the elements
        violation: InvariantError,
        /// where the offending patch was written
        debug_file: Option<PathBuf>,
    },
    /// The final mesh self-intersects.
    #[error("final mesh: {0}")]
    Final(InvariantError),
    /// The strategy returned a patch without an unprocessed face (the loop would not end).
    #[error(
        "patch {patch} (seed {seed}) contains no unprocessed face; the strategy must make progress"
    )]
    NoProgress {
        /// which patch
        patch: PatchId,
        /// its seed
        seed: VertexId,
    },
    /// The strategy returned no patch while faces were still unprocessed.
    #[error(
        "patch strategy `{strategy}` returned no patch with {unprocessed} faces still unprocessed"
    )]
    StrategyStopped {
        /// the strategy's name
        strategy: &'static str,
        /// faces left
        unprocessed: usize,
    },
    /// The strategy returned a patch with a corner vertex in its interior (the contract of
    /// [`PatchStrategy`] with [`crate::patches::PatchContext::corners`]).
    #[error(
        "patch {patch} (seed {seed}) contains the corner vertex {vertex} in its interior; the strategy must keep corners on patch boundaries"
    )]
    CornerInterior {
        /// which patch
        patch: PatchId,
        /// its seed
        seed: VertexId,
        /// the corner vertex
        vertex: VertexId,
    },
    /// The patch strategy returned a patch that crosses a feature line (contrary to
    /// [`crate::patches::PatchContext::feature_edges`]).
    #[error(
        "patch {patch} (seed {seed}) contains the feature-line edge {edge} in its interior; the strategy must keep feature edges on patch boundaries"
    )]
    FeatureInterior {
        /// which patch
        patch: PatchId,
        /// its seed
        seed: VertexId,
        /// the feature edge
        edge: EdgeKey,
    },
    /// A corner vertex of the input ([`RemeshOptions::corner_defect`]) is not in the output
    /// at its input position.
    #[error("final mesh: the input's corner vertex {0} was removed or moved")]
    CornerLost(VertexId),
    /// A piece of a feature line ([`RemeshOptions::feature_angle`]) is not an edge of the
    /// output, or one of its vertices moved.
    #[error("final mesh: the feature-line edge {0} was removed or moved")]
    FeatureLost(EdgeKey),
    /// The patch budget ran out.
    #[error("stopped after {0} patches (--max-patches) with {1} faces unprocessed")]
    Budget(usize, usize),
    /// Invalid input or options.
    #[error("{0}")]
    Input(String),
}

fn debug_note(p: &Option<PathBuf>) -> String {
    match p {
        Some(p) => format!(" (offending patch written to {})", p.display()),
        None => String::new(),
    }
}

pub use crate::quality::TargetLength;

/// Options of Algorithm 1.
#[derive(Clone, Debug, Serialize)]
pub struct RemeshOptions {
    /// Seed of the one RNG every stage draws from.
    pub seed: u64,
    /// Target metric edge length.
    pub target: TargetLength,
    /// How the 3D metric is carried to the plane (Eq. 4 by default).
    #[serde(skip)]
    pub transfer: TransferMethod,
    /// Run the exact self-intersection test on the final mesh.
    pub check_self_intersections: bool,
    /// Where offending patches are written when a certificate fails.
    pub debug_dir: Option<PathBuf>,
    /// Stop after this many patches (error), to bound runaway runs.
    pub max_patches: Option<usize>,
    /// Stop at the first failed patch attempt instead of shrinking the patch and retrying
    /// (for invariant-checking runs that want every failure to be an error).
    pub strict: bool,
    /// Geometric fidelity control (our addition, [`crate::fidelity`]): patches whose lifted
    /// triangles deviate from the reference by more than `max_deviation` are remeshed again
    /// with the metric scaled up there.
    pub fidelity: FidelityOptions,
    /// How many times Algorithm 1 covers the surface (our addition; 1 = the paper). Each
    /// further sweep marks every face unprocessed and runs the loop again on the working
    /// mesh, so the previous sweep's seams (fixed patch boundaries) are remeshed.
    pub sweeps: usize,
    /// Carry the 3D metric to the plane per triangle corner (`J_tᵀ M(v) J_t`, exact for the
    /// piecewise-linear parameterization) instead of per vertex (Jacobians averaged around
    /// the vertex); see [`PlanarMetricField::with_corner_metrics`]. Only with the default
    /// [`TransferMethod::JacobianPullback`]. Default `false`: on coarse, strongly curved
    /// inputs the averaged Jacobians lose quality between the plane and the surface
    /// (decimated-knight, faces off the patch boundary: q 0.851 in the plane but 0.791 on the
    /// surface; with corners 0.806 / 0.815; paper-notes.md, Algorithm 1), but with corners the
    /// screwdriver's blade tip is cut again (Hausdorff 0.78 % → 1.83 % of the diagonal).
    pub corner_pullback: bool,
    /// After the loop, flip edges whose flip raises the smaller metric quality of their two
    /// faces (our addition; see `flip_pass`). Every flip is certified like a patch's new
    /// faces (not degenerate, not flipped, locally embedded) and keeps the surface within
    /// the fidelity tolerance. Default `true`.
    pub edge_flips: bool,
    /// After the flips, move vertices towards their neighbours' centroid on the reference
    /// surface where the worst face around them improves, then flip again (our addition;
    /// see `smooth_pass`). Default `true`.
    pub relocate: bool,
    /// Input vertices whose angle defect `|2π − Σθ|` is at least this many radians are kept
    /// as vertices of the output (our addition, see [`crate::patches::corner_vertices`]): no
    /// patch contains them in its interior and the relocation pass does not move them.
    /// `None` keeps no vertex (the paper). Default `Some(1.0)`.
    pub corner_defect: Option<f64>,
    /// Feature lines (our addition, [`crate::features`]): input edges whose faces' normals
    /// differ by more than this many degrees are split to the target length and kept as
    /// edges of the output (no patch crosses them, no pass moves or flips them). `None`
    /// keeps none (the paper).
    pub feature_angle: Option<f64>,
    /// Whether to run the coarse-input profile ([`RemeshOptions::coarse_profile`]): `Auto`
    /// (default) runs it when the distance tolerance rather than the metric sets the output's
    /// size: the a-priori fidelity scaling multiplies the expected face count
    /// ([`expected_faces`]) by at least [`COARSE_RATIO`].
    pub coarse_input: CoarseInput,
}

/// [`CoarseInput::Auto`] runs the coarse-input profile when the a-priori fidelity scaling
/// multiplies the expected output face count ([`expected_faces`]) by at least this much.
pub const COARSE_RATIO: f64 = 2.0;

/// When [`remesh`] uses [`RemeshOptions::coarse_profile`] (paper-notes "Coarse inputs").
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub enum CoarseInput {
    /// When the a-priori fidelity scaling multiplies [`expected_faces`] by at least
    /// [`COARSE_RATIO`].
    #[default]
    Auto,
    /// Always.
    On,
    /// Never (the options as given).
    Off,
}

impl RemeshOptions {
    /// The options for an input coarser than its output (our addition, paper-notes "Coarse
    /// inputs"): at least 3 sweeps, because the first sweep's fixed patch boundaries are the
    /// input's edges, longer than the output's; the fidelity control's factors kept between
    /// patches ([`FidelityOptions::persist`]), so the further sweeps do not start again from
    /// the a-priori metric; its refinement floor at most 0.2 of the input's mean edge (0.5 is
    /// about the output's own edge length on such an input, where the control could not
    /// refine at all) and at least 4 rounds per patch.
    pub fn coarse_profile(&self) -> RemeshOptions {
        let mut o = self.clone();
        o.sweeps = o.sweeps.max(3);
        o.fidelity.persist = true;
        o.fidelity.min_edge_ratio = o.fidelity.min_edge_ratio.min(0.2);
        o.fidelity.rounds = o.fidelity.rounds.max(4);
        o
    }
}

/// The number of faces an output of `reference` should have: its area in the metric (the
/// mean of the vertex tensors `metrics[v]·scale[v]` per face; `scale` empty = 1) over the area
/// √3/4·L_tar² of an equilateral triangle of side `l_tar`.
pub fn expected_faces(
    reference: &TriMesh,
    metrics: &[Matrix3<f64>],
    scale: &[f64],
    l_tar: f64,
) -> f64 {
    let s = |v: VertexId| scale.get(v.idx()).copied().unwrap_or(1.0);
    let area: f64 = reference
        .faces()
        .map(|f| {
            let t = reference.face(f);
            let m = t
                .iter()
                .map(|v| metrics[v.idx()] * s(*v))
                .sum::<Matrix3<f64>>()
                / 3.0;
            let q = crate::quality::metric_sqrt(&m);
            let [a, b, c] = reference.face_points(f);
            0.5 * (q * (b - a)).cross(&(q * (c - a))).norm()
        })
        .sum();
    area / (3f64.sqrt() / 4.0 * l_tar * l_tar)
}

impl Default for RemeshOptions {
    fn default() -> Self {
        RemeshOptions {
            seed: 1,
            target: TargetLength::Factor(1.5),
            transfer: TransferMethod::default(),
            check_self_intersections: true,
            debug_dir: None,
            max_patches: None,
            strict: false,
            fidelity: FidelityOptions::default(),
            sweeps: 1,
            corner_pullback: false,
            edge_flips: true,
            relocate: true,
            corner_defect: Some(1.0),
            feature_angle: None,
            coarse_input: CoarseInput::Auto,
        }
    }
}

/// The research extension points, with the paper's methods as defaults.
pub struct Stages {
    /// Sec. 3.2.
    pub patches: Box<dyn PatchStrategy>,
    /// Sec. 3.3, embedding.
    pub parameterizer: Box<dyn Parameterizer>,
    /// Sec. 3.3, planar remeshing.
    pub remesher: Box<dyn PlanarRemesher>,
}

impl Default for Stages {
    fn default() -> Self {
        Stages {
            patches: Box::new(ConePatches::default()),
            parameterizer: Box::new(SymmetricDirichlet::default()),
            remesher: Box::new(Lct::default()),
        }
    }
}

/// Wall time per stage, seconds.
#[derive(Clone, Debug, Default, Serialize)]
pub struct StageTimes {
    /// Patch generation and certify_disk.
    pub patches: f64,
    /// Parameterization (includes its certificate).
    pub param: f64,
    /// Metric transfer.
    pub transfer: f64,
    /// Planar remeshing (includes its certificate).
    pub remesh2d: f64,
    /// Lifting and projection.
    pub lift: f64,
    /// Fidelity measurement (the extra remeshing rounds count under `remesh2d` / `lift`).
    pub fidelity: f64,
    /// Stitching.
    pub stitch: f64,
    /// Working-mesh certificates after every patch.
    pub certify: f64,
    /// Final self-intersection test.
    pub final_check: f64,
}

/// How many times each certificate was checked and held (a failed check is either an error
/// or, for a patch attempt, a recorded failure followed by a retry). Per accepted patch:
/// `manifold`, `oriented`, `same_topology`, `boundary_preserved` once each (also for kept
/// patches); per attempt that reached the stage: `disk`, `bijective`, `planar`; per remeshed
/// (not kept) patch: `no_degenerate`, `no_flips` and, for an embedded input,
/// `locally_embedded`.
#[derive(Clone, Debug, Default, Serialize, PartialEq, Eq)]
pub struct Certificate {
    /// Patches certified to be topological disks.
    pub disk: usize,
    /// Parameterizations certified bijective (exact orient2d, simple boundary).
    pub bijective: usize,
    /// Planar remeshes certified (positive, same boundary, disk): the first remesh of each
    /// attempt.
    pub planar: usize,
    /// The fidelity control's further planar remeshes of an attempt, each certified like
    /// `planar`.
    pub planar_refined: usize,
    /// Working mesh edge- and vertex-manifold after the patch.
    pub manifold: usize,
    /// Working mesh consistently oriented after the patch.
    pub oriented: usize,
    /// Genus, components and boundary loops equal the input's after the patch.
    pub same_topology: usize,
    /// The input's boundary vertices and edges unchanged after the patch.
    pub boundary_preserved: usize,
    /// No new face degenerate (exact) after the patch.
    pub no_degenerate: usize,
    /// No new face flipped against the reference after the patch.
    pub no_flips: usize,
    /// Candidates certified free of local self-intersections (exact; only for an embedded
    /// input).
    pub locally_embedded: usize,
    /// Final mesh free of self-intersections (exact), 0 if not checked.
    pub no_self_intersections: usize,
    /// Self-intersecting face pairs of the output; non-zero only when the input itself
    /// self-intersects (otherwise the run fails).
    pub self_intersecting_pairs: usize,
    /// Self-intersecting face pairs of the input, computed only when the output has some.
    pub input_self_intersecting_pairs: Option<usize>,
    /// Patches whose parameterizer fell back to its last certified iterate.
    pub param_fallbacks: usize,
}

/// Per-patch record.
#[derive(Clone, Debug, Serialize)]
pub struct PatchRecord {
    /// Patch id.
    pub id: u32,
    /// Seed vertex (working-mesh id at the time).
    pub seed: u32,
    /// Faces replaced.
    pub faces_in: usize,
    /// Of which unprocessed before.
    pub unprocessed_in: usize,
    /// Faces produced.
    pub faces_out: usize,
    /// Cone angle in degrees, if the strategy fits one.
    pub cone_angle_deg: Option<f64>,
    /// Distortion of its parameterization.
    pub distortion: DistortionReport,
    /// Failed attempts before this one (each shrank the patch).
    pub retries: usize,
    /// Even the smallest attempt failed: the faces were kept unchanged.
    pub kept: bool,
    /// Extra remeshing rounds of the fidelity control.
    pub fidelity_rounds: usize,
}

/// The outcome of Algorithm 1.
#[derive(Clone, Debug)]
pub struct RemeshResult {
    /// The remeshed surface (unit-diagonal space, compacted).
    pub mesh: TriMesh,
    /// Reference location of every output vertex.
    pub locations: Vec<SurfaceLocation>,
    /// Which patch produced each output face (`None`: an input face no patch replaced, i.e.
    /// kept unchanged). Diagnostics: where the seams and kept faces are.
    pub face_patch: Vec<Option<PatchId>>,
    /// What was done and certified.
    pub report: RemeshReport,
}

/// The report of a run (serialised into `--report`).
#[derive(Clone, Debug, Serialize)]
pub struct RemeshReport {
    /// Options used.
    pub options: RemeshOptions,
    /// Strategy / parameterizer / remesher names.
    pub stages: [String; 3],
    /// Mean metric edge length of the input (L_avg).
    pub l_avg: f64,
    /// Target metric edge length (L_tar).
    pub l_tar: f64,
    /// Number of patches.
    pub patches: usize,
    /// Per-stage times.
    pub times: StageTimes,
    /// Certificates.
    pub certificate: Certificate,
    /// What the retry ladder did.
    pub fallbacks: Fallbacks,
    /// Per-patch records.
    pub patch_records: Vec<PatchRecord>,
    /// Input and output sizes.
    pub faces_in: usize,
    /// Output faces.
    pub faces_out: usize,
    /// Output vertices.
    pub vertices_out: usize,
    /// Edges flipped by the final flip pass ([`RemeshOptions::edge_flips`]).
    pub edge_flips: usize,
    /// Vertex moves of the final relocation pass ([`RemeshOptions::relocate`]).
    pub vertex_moves: usize,
    /// Input vertices kept as corners ([`RemeshOptions::corner_defect`]); each is certified
    /// to be a vertex of the output at its input position.
    pub corners: usize,
    /// Input edges kept as feature lines ([`RemeshOptions::feature_angle`]).
    pub feature_edges: usize,
    /// The pieces they were split into; each is certified to be an edge of the output, its
    /// vertices where the split put them.
    pub feature_pieces: usize,
    /// [`expected_faces`] of the input at L_tar in the metric alone.
    pub expected_faces: f64,
    /// The same with the a-priori fidelity scaling (before any coarse-input profile).
    pub expected_faces_fidelity: f64,
    /// Whether the coarse-input profile ran (`options` then holds the profile's values).
    pub coarse_input: bool,
}

/// Progress reported after every patch.
#[derive(Copy, Clone, Debug)]
pub struct Progress {
    /// Patches done.
    pub patches: usize,
    /// Faces of the working mesh still unprocessed (strictly decreasing).
    pub unprocessed: usize,
    /// Faces at the start.
    pub total: usize,
}

/// Topological signature compared after every patch: per component (faces-independent)
/// genus and boundary loops, sorted, plus the component count.
fn topology_signature(topo: &Topology) -> Vec<(Option<u32>, usize)> {
    let mut s: Vec<_> = topo
        .components()
        .iter()
        .map(|c| (c.genus, c.boundary_loops))
        .collect();
    s.sort();
    s
}

/// The sizes a run starts from (see [`sizing`]).
struct Sizing {
    l_avg: f64,
    l_tar: f64,
    eps: f64,
    min_edge: f64,
    fid_scale: Vec<f64>,
    expected: f64,
    expected_fidelity: f64,
}

/// L_avg, L_tar, the fidelity tolerance, the a-priori fidelity scaling and the expected output
/// face counts without and with it, for `options` as given; errors for an empty input, a
/// target length or a tolerance that is not a finite positive number.
fn sizing(field: &MetricField, options: &RemeshOptions) -> Result<Sizing, PipelineError> {
    let reference = field.reference();
    if reference.n_faces() == 0 {
        return Err(PipelineError::Input("the input mesh has no faces".into()));
    }
    let l_avg = crate::quality::edge_length_average(reference, field.vertex_metrics());
    let l_tar = match options.target {
        TargetLength::Factor(f) => f * l_avg,
        TargetLength::Absolute(l) => l,
    };
    if !(l_tar.is_finite() && l_tar > 0.0) {
        return Err(PipelineError::Input(format!(
            "target edge length {l_tar} is not a positive finite number (L_avg = {l_avg})"
        )));
    }
    let eps = options.fidelity.max_deviation;
    if !(eps.is_finite() && eps >= 0.0) {
        return Err(PipelineError::Input(format!(
            "fidelity tolerance {eps} is not a finite number ≥ 0"
        )));
    }
    let expected = expected_faces(reference, field.vertex_metrics(), &[], l_tar);
    // A target far below the input's size would run for hours and exhaust memory: refuse it
    // up front, naming the count.
    if expected.is_nan() || expected > MAX_EXPECTED_FACES {
        return Err(PipelineError::Input(format!(
            "target edge length {l_tar:e} is too small for this input: the output would have about \
             {expected:.3e} faces (more than {MAX_EXPECTED_FACES:e})"
        )));
    }
    let (min_edge, fid_scale) = a_priori(field, options, l_tar);
    Ok(Sizing {
        l_avg,
        l_tar,
        eps,
        min_edge,
        expected,
        expected_fidelity: expected_faces(reference, field.vertex_metrics(), &fid_scale, l_tar),
        fid_scale,
    })
}

/// Largest expected output ([`expected_faces`] in the metric at L_tar) a run accepts.
pub const MAX_EXPECTED_FACES: f64 = 1e8;

/// A-priori fidelity scaling (our addition, `crate::fidelity::a_priori_scale`): the metric is
/// scaled up isotropically where a triangle of the target size would cut off more of the
/// reference than the tolerance allows. L_tar is from the unscaled metric, as is every
/// quality measure. Returns the refinement floor and the factor per reference vertex (empty
/// when the control is off).
fn a_priori(field: &MetricField, o: &RemeshOptions, l_tar: f64) -> (f64, Vec<f64>) {
    let reference = field.reference();
    let min_edge = o.fidelity.min_edge_ratio * mean_edge_length(reference);
    let eps = o.fidelity.max_deviation;
    let fid_scale = if eps > 0.0 {
        let topo = Topology::build(reference);
        fidelity::a_priori_scale(
            reference,
            &topo,
            field.vertex_metrics(),
            l_tar,
            eps,
            min_edge,
        )
    } else {
        Vec::new()
    };
    (min_edge, fid_scale)
}

/// The expected output face counts of a run with `options` ([`expected_faces`] at its L_tar,
/// in the metric alone and with the a-priori fidelity scaling) and whether
/// [`CoarseInput::Auto`] would run the coarse-input profile.
pub fn coarse_input_estimate(
    field: &MetricField,
    options: &RemeshOptions,
) -> Result<(f64, f64, bool), PipelineError> {
    let s = sizing(field, options)?;
    Ok((
        s.expected,
        s.expected_fidelity,
        s.expected_fidelity >= COARSE_RATIO * s.expected,
    ))
}

/// Run Algorithm 1 on the metric field's reference mesh.
///
/// Randomness: one ChaCha8 stream seeded with `options.seed`, drawn only by the patch
/// strategy and the planar remesher, in patch order, so the output depends on the seed only
/// (not on thread count).
pub fn remesh(
    field: &MetricField,
    stages: &Stages,
    options: &RemeshOptions,
    mut on_progress: impl FnMut(Progress),
) -> Result<RemeshResult, PipelineError> {
    let reference = field.reference();
    let Sizing {
        l_avg,
        l_tar,
        eps,
        mut min_edge,
        mut fid_scale,
        expected,
        expected_fidelity,
    } = sizing(field, options)?;
    // An input where the distance tolerance, not the metric, sets the output's size runs the
    // coarse-input profile (our addition; paper-notes "Coarse inputs").
    let coarse = match options.coarse_input {
        CoarseInput::On => true,
        CoarseInput::Off => false,
        CoarseInput::Auto => expected_fidelity >= COARSE_RATIO * expected,
    };
    let profile;
    let options = if coarse {
        profile = options.coarse_profile();
        (min_edge, fid_scale) = a_priori(field, &profile, l_tar);
        &profile
    } else {
        options
    };
    let scaled_field;
    // The metric every quality measure uses (the unscaled one).
    let quality_field = field;
    let field = if !fid_scale.is_empty() {
        let metrics = field
            .vertex_metrics()
            .iter()
            .zip(&fid_scale)
            .map(|(m, f)| m * *f)
            .collect();
        scaled_field = MetricField::new(reference.clone(), metrics)
            .map_err(|e| PipelineError::Input(format!("fidelity-scaled metric: {e}")))?;
        &scaled_field
    } else {
        field
    };
    let mut rng = crate::Rng::seed_from_u64(options.seed);
    let flip_test = FlipTest::new(reference);
    let ref_normals = fidelity::vertex_normals(reference);
    // Candidates are checked for local self-intersections only when the input is embedded
    // (an input that self-intersects cannot be replaced by an embedded surface on it).
    let input_pairs = if options.check_self_intersections {
        invariants::self_intersections(reference).len()
    } else {
        0
    };
    let embedded_input = options.check_self_intersections && input_pairs == 0;
    let mut work = WorkingMesh::from_reference(reference);
    let ref_topo = Topology::build(reference);
    // The input must be an oriented 2-manifold (with boundary): say so up front, naming the
    // elements, rather than failing later inside a patch.
    invariants::certify_manifold(reference, &ref_topo)
        .and_then(|()| invariants::certify_oriented(reference, &ref_topo))
        .map_err(|e| {
            PipelineError::Input(format!("the input mesh is not an oriented manifold: {e}"))
        })?;
    let signature = topology_signature(&ref_topo);
    // Cone points of the input stay vertices of the output (working-mesh vertex ids of the
    // input are stable during the loop; new vertices are never corners).
    let corners: Vec<bool> = match options.corner_defect {
        Some(d) if d.is_nan() || d <= 0.0 => {
            return Err(PipelineError::Input(format!(
                "corner angle defect must be a positive number of radians, got {d}"
            )))
        }
        Some(d) => crate::patches::corner_vertices(reference, &ref_topo, d),
        None => Vec::new(),
    };
    let n_corners = corners.iter().filter(|c| **c).count();
    // Feature lines: split to the target length before the loop (new vertices on the input
    // edges), then kept as patch boundaries.
    let sharp = match options.feature_angle {
        Some(a) if !(a.is_finite() && a > 0.0 && a < 180.0) => {
            return Err(PipelineError::Input(format!(
                "feature angle must be between 0 and 180 degrees, got {a}"
            )))
        }
        Some(a) => crate::features::sharp_edges(reference, &ref_topo, a),
        None => Vec::new(),
    };
    let features = match sharp.is_empty() {
        true => crate::features::FeatureLines::default(),
        false => {
            // Pieces of about L_tar in the metric the planar remesher sees (the scaled one).
            let m = field.vertex_metrics();
            let counts: Vec<f64> = sharp
                .iter()
                .map(|e| {
                    let d = reference.positions[e.1.idx()] - reference.positions[e.0.idx()];
                    let mm = (m[e.0.idx()] + m[e.1.idx()]) * 0.5;
                    (d.dot(&(mm * d)).max(0.0).sqrt() / l_tar).round().max(1.0)
                })
                .collect();
            let new_vertices: f64 = counts.iter().map(|k| k - 1.0).sum();
            if new_vertices.is_nan() || new_vertices > crate::features::MAX_NEW_VERTICES as f64 {
                return Err(PipelineError::Input(format!(
                    "feature lines would need {new_vertices:.3e} new vertices at L_tar = {l_tar:e} \
                     (more than {}): the target length is too small for the input's {} feature edges",
                    crate::features::MAX_NEW_VERTICES,
                    sharp.len()
                )));
            }
            let with_k: Vec<_> = sharp
                .iter()
                .zip(&counts)
                .map(|(e, k)| (*e, *k as usize))
                .collect();
            crate::features::split_feature_edges(&mut work, reference, &with_k)
        }
    };
    // Vertices no pass may move: corners and feature-line vertices.
    let pinned: Vec<bool> = (0..work.mesh.n_vertices())
        .map(|v| corners.get(v).copied().unwrap_or(false) || features.is_pinned(VertexId::new(v)))
        .collect();
    let feature_edges = (!features.edges.is_empty()).then_some(&features.edges);
    // The fidelity control's factor per working-mesh vertex (`PatchFactors`).
    let mut vfactor: Vec<f64> = vec![1.0; work.mesh.n_vertices()];
    // Provenance of every working-mesh face, kept parallel to its triangles (`stitch` drops
    // the patch's faces in order and appends the new ones).
    let mut face_patch: Vec<Option<PatchId>> = vec![None; work.mesh.n_faces()];
    // The input's boundary edges, by vertex ids (input vertices are never renumbered during
    // the loop and boundary vertices are never moved: the remesher keeps patch boundaries).
    let input_boundary: Vec<EdgeKey> = ref_topo
        .boundary_loops()
        .iter()
        .flat_map(|l| (0..l.len()).map(move |i| EdgeKey::new(l[i], l[(i + 1) % l.len()])))
        .collect();
    let total = work.mesh.n_faces();
    let mut times = StageTimes::default();
    let mut cert = Certificate::default();
    let mut records = Vec::new();
    let mut topo = if work.mesh.n_faces() == reference.n_faces() {
        ref_topo.clone()
    } else {
        Topology::build(&work.mesh)
    };

    let mut n_patch = 0usize;
    let mut fallback = Fallbacks::default();

    let mut sweep = 1usize;
    loop {
        if work.unprocessed() == 0 {
            if sweep >= options.sweeps {
                break;
            }
            // A further sweep (our addition): every face is unprocessed again, so the new
            // patches' fixed boundaries run through the previous sweep's remeshed faces
            // (edges near L_tar) instead of the input's edges, and the previous seams end up
            // inside new patches.
            sweep += 1;
            work.processed.iter_mut().for_each(|p| *p = false);
        }
        if let Some(max) = options.max_patches {
            if n_patch >= max {
                return Err(PipelineError::Budget(n_patch, work.unprocessed()));
            }
        }
        let pid = PatchId::new(n_patch);
        // (a) next patch from the strategy.
        let t0 = Instant::now();
        let ctx = PatchContext {
            mesh: &work.mesh,
            topology: &topo,
            processed: &work.processed,
            feature_edges,
            corners: Some(&corners),
        };
        let patch = match stages.patches.next_patch(&ctx, &mut rng) {
            Ok(Some(p)) => p,
            Ok(None) => {
                return Err(PipelineError::StrategyStopped {
                    strategy: stages.patches.name(),
                    unprocessed: work.unprocessed(),
                })
            }
            Err(e) => {
                return Err(PipelineError::Stage {
                    patch: pid,
                    seed: VertexId(u32::MAX),
                    stage: "patch generation",
                    message: e.to_string(),
                })
            }
        };
        times.patches += t0.elapsed().as_secs_f64();
        let seed = patch.seed_vertex;
        let mut faces = patch.faces.clone();
        let failures_before = fallback.failures.len();
        // Retry ladder: a patch whose stages fail (no certified map, remesher error, a lifted
        // face flipped or degenerate) is shrunk to a smaller disk around an unprocessed face
        // and tried again; a patch of MIN_PATCH_FACES that still fails keeps its faces as they
        // are (marked processed). Either way every face that enters the working mesh is
        // certified, and the unprocessed count strictly decreases (termination).
        // Vertices of the faces the patch removes (its boundary and interior): with the new
        // faces' vertices, every vertex whose fan changed (the manifold certificate below).
        let mut touched: Vec<VertexId> = Vec::new();
        let (new_faces, outcome) = loop {
            let unprocessed_in = faces.iter().filter(|f| !work.processed[f.idx()]).count();
            if unprocessed_in == 0 {
                return Err(PipelineError::NoProgress { patch: pid, seed });
            }
            // The disk certificate is a hard error: a strategy (or the shrinking) that
            // returns a non-disk is a bug, not a numerical accident.
            let t0 = Instant::now();
            invariants::certify_disk(&work.mesh, &faces).map_err(|e| {
                PipelineError::Certificate {
                    patch: pid,
                    seed,
                    violation: e,
                    debug_file: write_debug(options, pid, "patch", &work.mesh, &faces),
                }
            })?;
            cert.disk += 1;
            if let Some(vertex) = interior_corner(&work.mesh, &topo, &faces, &corners) {
                return Err(PipelineError::CornerInterior {
                    patch: pid,
                    seed,
                    vertex,
                });
            }
            if let Some(edge) =
                feature_edges.and_then(|fe| interior_feature(&work.mesh, &faces, fe))
            {
                return Err(PipelineError::FeatureInterior {
                    patch: pid,
                    seed,
                    edge,
                });
            }
            times.patches += t0.elapsed().as_secs_f64();
            let attempt = remesh_patch(
                field,
                stages,
                options,
                &work,
                &topo,
                &flip_test,
                &ref_normals,
                &fid_scale,
                &vfactor,
                min_edge,
                embedded_input,
                &faces,
                l_tar,
                &mut rng,
                &mut times,
                &mut cert,
            );
            match attempt {
                Ok((replacement, distortion, fidelity_rounds, factors)) => {
                    let t0 = Instant::now();
                    touched = faces
                        .iter()
                        .filter(|f| f.idx() < work.mesh.n_faces())
                        .flat_map(|f| work.mesh.triangles[f.idx()])
                        .collect();
                    let new_faces = stitch(&mut work, &faces, &replacement).map_err(|e| {
                        PipelineError::Stage {
                            patch: pid,
                            seed,
                            stage: "stitching",
                            message: e.to_string(),
                        }
                    })?;
                    times.stitch += t0.elapsed().as_secs_f64();
                    if options.fidelity.persist {
                        for (v, f) in factors.existing {
                            vfactor[v.idx()] = vfactor[v.idx()].max(f);
                        }
                        vfactor.extend(factors.new);
                    } else {
                        vfactor.resize(work.mesh.n_vertices(), 1.0);
                    }
                    if vfactor.len() != work.mesh.n_vertices() {
                        return Err(PipelineError::Stage {
                            patch: pid,
                            seed,
                            stage: "fidelity factors",
                            message: format!(
                                "{} factors for {} vertices after stitching",
                                vfactor.len(),
                                work.mesh.n_vertices()
                            ),
                        });
                    }
                    let mut gone = vec![false; face_patch.len()];
                    for f in &faces {
                        gone[f.idx()] = true;
                    }
                    let mut k = 0;
                    face_patch.retain(|_| {
                        k += 1;
                        !gone[k - 1]
                    });
                    face_patch.resize(work.mesh.n_faces(), Some(pid));
                    break (
                        new_faces,
                        PatchRecord {
                            id: pid.0,
                            seed: seed.0,
                            faces_in: faces.len(),
                            unprocessed_in,
                            faces_out: replacement.triangles.len(),
                            cone_angle_deg: patch.cone.map(|c| c.angle.to_degrees()),
                            distortion,
                            retries: 0,
                            kept: false,
                            fidelity_rounds,
                        },
                    );
                }
                Err(failure) => {
                    fallback
                        .failures
                        .push(format!("{pid} ({} faces): {failure}", faces.len()));
                    if options.strict {
                        return Err(failure.into_error(pid, seed, options, &work, &faces));
                    }
                    if faces.len() <= MIN_PATCH_FACES {
                        // Keep the faces: mark them processed, unchanged.
                        for f in &faces {
                            work.processed[f.idx()] = true;
                        }
                        fallback.kept_faces += unprocessed_in;
                        break (
                            faces.clone(),
                            PatchRecord {
                                id: pid.0,
                                seed: seed.0,
                                faces_in: faces.len(),
                                unprocessed_in,
                                faces_out: faces.len(),
                                cone_angle_deg: None,
                                distortion: DistortionReport::default(),
                                retries: 0,
                                kept: true,
                                fidelity_rounds: 0,
                            },
                        );
                    }
                    fallback.shrinks += 1;
                    faces = shrink_patch(
                        &work,
                        &topo,
                        &faces,
                        patch.seed_face,
                        faces.len() / 2,
                        &corners,
                        feature_edges,
                    );
                }
            }
        };
        let mut record = outcome;
        record.retries = fallback.failures.len() - failures_before;

        // (g) certify the working mesh after the patch (hard errors: these are bugs).
        let t0 = Instant::now();
        topo = Topology::build(&work.mesh);
        let fail = |e: InvariantError, work: &WorkingMesh| PipelineError::Certificate {
            patch: pid,
            seed,
            violation: e,
            debug_file: write_debug(options, pid, "stitched", &work.mesh, &new_faces),
        };
        // Local: the input was certified whole before the loop, and only the touched
        // vertices' fans changed (`certify_manifold_at`); the whole mesh again after the loop.
        touched.extend(
            new_faces
                .iter()
                .filter(|f| f.idx() < work.mesh.n_faces())
                .flat_map(|f| work.mesh.triangles[f.idx()]),
        );
        touched.sort_unstable();
        touched.dedup();
        invariants::certify_manifold_at(&work.mesh, &topo, &touched).map_err(|e| fail(e, &work))?;
        debug_assert!(
            invariants::certify_manifold(&work.mesh, &topo).is_ok(),
            "{pid}: the local manifold certificate passed, the whole-mesh one fails"
        );
        cert.manifold += 1;
        invariants::certify_oriented(&work.mesh, &topo).map_err(|e| fail(e, &work))?;
        cert.oriented += 1;
        let sig = topology_signature(&topo);
        if sig != signature {
            return Err(fail(
                InvariantError::TopologyChanged {
                    what: "(genus, boundary loops) per component".into(),
                    before: format!("{signature:?}"),
                    after: format!("{sig:?}"),
                },
                &work,
            ));
        }
        cert.same_topology += 1;
        certify_input_boundary(&work.mesh, &topo, reference, &input_boundary)
            .map_err(|e| fail(e, &work))?;
        cert.boundary_preserved += 1;
        times.certify += t0.elapsed().as_secs_f64();

        records.push(record);
        n_patch += 1;
        on_progress(Progress {
            patches: n_patch,
            unprocessed: work.unprocessed() + (options.sweeps.max(1) - sweep) * total,
            total: total * options.sweeps.max(1),
        });
    }

    let mut edge_flips = 0usize;
    let mut vertex_moves = 0usize;
    if options.edge_flips || options.relocate {
        let t0 = Instant::now();
        let tol = if eps > 0.0 {
            eps
        } else {
            FidelityOptions::default().max_deviation
        };
        let flips = |work: &mut WorkingMesh| {
            flip_pass(
                quality_field,
                &flip_test,
                work,
                embedded_input,
                tol,
                feature_edges,
            )
        };
        if options.edge_flips {
            edge_flips = flips(&mut work);
        }
        if options.relocate {
            vertex_moves = smooth_pass(
                quality_field,
                &flip_test,
                &mut work,
                embedded_input,
                tol,
                &pinned,
            );
            edge_flips += flips(&mut work);
        }
        times.certify += t0.elapsed().as_secs_f64();
    }
    {
        // The whole working mesh once more, after the loop and the passes (the flips replace
        // two faces by two over the same quadrilateral and the moves keep the connectivity;
        // the per-patch manifold check was local, by induction): certify it anyway.
        let t0 = Instant::now();
        topo = Topology::build(&work.mesh);
        let pid = PatchId::new(n_patch);
        let fail = |e: InvariantError| PipelineError::Certificate {
            patch: pid,
            seed: VertexId(u32::MAX),
            violation: e,
            debug_file: None,
        };
        invariants::certify_manifold(&work.mesh, &topo).map_err(fail)?;
        invariants::certify_oriented(&work.mesh, &topo).map_err(fail)?;
        let sig = topology_signature(&topo);
        if sig != signature {
            return Err(fail(InvariantError::TopologyChanged {
                what: "(genus, boundary loops) per component, after the loop".into(),
                before: format!("{signature:?}"),
                after: format!("{sig:?}"),
            }));
        }
        certify_input_boundary(&work.mesh, &topo, reference, &input_boundary).map_err(fail)?;
        times.certify += t0.elapsed().as_secs_f64();
    }
    // Every corner is still a vertex of the working mesh, where the input had it.
    let t0 = Instant::now();
    let used = {
        let mut u = vec![false; work.mesh.n_vertices()];
        work.mesh
            .triangles
            .iter()
            .flatten()
            .for_each(|v| u[v.idx()] = true);
        u
    };
    if let Some(v) = (0..corners.len())
        .find(|&v| corners[v] && (!used[v] || work.mesh.positions[v] != reference.positions[v]))
    {
        return Err(PipelineError::CornerLost(VertexId::new(v)));
    }
    // Every feature-line piece is still an edge of the working mesh, its vertices unmoved.
    if !features.edges.is_empty() {
        let edges = crate::quality::unique_edges(&work.mesh);
        let mut pieces: Vec<EdgeKey> = features.edges.iter().copied().collect();
        pieces.sort_unstable();
        if let Some(e) = pieces.into_iter().find(|e| {
            edges.binary_search(e).is_err()
                || [e.0, e.1]
                    .iter()
                    .any(|v| features.positions.get(v) != work.mesh.positions.get(v.idx()))
        }) {
            return Err(PipelineError::FeatureLost(e));
        }
    }
    times.certify += t0.elapsed().as_secs_f64();
    work.compact();
    let t0 = Instant::now();
    if options.check_self_intersections {
        let pairs = invariants::self_intersections(&work.mesh);
        if pairs.is_empty() {
            cert.no_self_intersections = 1;
        } else {
            // An input that itself self-intersects (cow.off does, at 118 face pairs) cannot
            // give an embedded output that lies on it; that is reported, not an error. An
            // embedded input must give an embedded output.
            if input_pairs == 0 {
                return Err(PipelineError::Final(InvariantError::SelfIntersections(
                    Offenders(
                        pairs
                            .into_iter()
                            .map(|(a, b)| invariants::FacePair(a, b))
                            .collect(),
                    ),
                )));
            }
            cert.self_intersecting_pairs = pairs.len();
            cert.input_self_intersecting_pairs = Some(input_pairs);
        }
    }
    times.final_check = t0.elapsed().as_secs_f64();
    let report = RemeshReport {
        options: options.clone(),
        stages: [
            stages.patches.name().to_string(),
            stages.parameterizer.name().to_string(),
            stages.remesher.name().to_string(),
        ],
        l_avg,
        l_tar,
        patches: n_patch,
        times,
        certificate: cert,
        fallbacks: fallback,
        patch_records: records,
        faces_in: reference.n_faces(),
        faces_out: work.mesh.n_faces(),
        vertices_out: work.mesh.n_vertices(),
        edge_flips,
        vertex_moves,
        corners: n_corners,
        feature_edges: features.input_edges,
        feature_pieces: features.edges.len(),
        expected_faces: expected,
        expected_faces_fidelity: expected_fidelity,
        coarse_input: coarse,
    };
    Ok(RemeshResult {
        mesh: work.mesh,
        locations: work.locations,
        face_patch,
        report,
    })
}

/// Smallest patch the retry ladder shrinks to before keeping the faces unchanged.
pub const MIN_PATCH_FACES: usize = 8;

/// What the retry ladder did (see [`remesh`]).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Fallbacks {
    /// Patches shrunk after a failed attempt.
    pub shrinks: usize,
    /// Unprocessed faces (of the input, or of an earlier sweep) kept unchanged because even a
    /// minimal patch failed.
    pub kept_faces: usize,
    /// Every failed attempt: patch, size and reason.
    pub failures: Vec<String>,
}

/// A recoverable failure of one patch attempt.
struct Failure {
    stage: &'static str,
    message: String,
    violation: Option<InvariantError>,
    candidate: Option<Box<Replacement>>,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.stage, self.message)
    }
}

impl Failure {
    fn stage(stage: &'static str, e: impl std::fmt::Display) -> Failure {
        Failure {
            stage,
            message: e.to_string(),
            violation: None,
            candidate: None,
        }
    }
    fn certificate(stage: &'static str, e: InvariantError) -> Failure {
        Failure {
            stage,
            message: e.to_string(),
            violation: Some(e),
            candidate: None,
        }
    }
    fn into_error(
        self,
        pid: PatchId,
        seed: VertexId,
        options: &RemeshOptions,
        work: &WorkingMesh,
        faces: &[FaceId],
    ) -> PipelineError {
        let patch_file = write_debug(options, pid, self.stage, &work.mesh, faces);
        let cand = self
            .candidate
            .as_ref()
            .and_then(|c| write_candidate(options, pid, work, c));
        match self.violation {
            Some(v) => PipelineError::Certificate {
                patch: pid,
                seed,
                violation: v,
                debug_file: cand.or(patch_file),
            },
            None => PipelineError::Stage {
                patch: pid,
                seed,
                stage: self.stage,
                message: self.message,
            },
        }
    }
}

/// Stages (b)–(f) of Algorithm 1 for one disk patch of the working mesh: parameterize
/// (certified bijective), transfer the metric (Eq. 4), remesh in 2D with the boundary fixed
/// (certified), lift onto the reference surface, and certify the new faces (none degenerate,
/// none flipped).
#[allow(clippy::too_many_arguments)]
fn remesh_patch(
    field: &MetricField,
    stages: &Stages,
    options: &RemeshOptions,
    work: &WorkingMesh,
    topo: &Topology,
    flip_test: &FlipTest,
    ref_normals: &[Vector3<f64>],
    fid_scale: &[f64],
    vfactor: &[f64],
    min_edge: f64,
    embedded_input: bool,
    faces: &[FaceId],
    l_tar: f64,
    rng: &mut crate::Rng,
    times: &mut StageTimes,
    cert: &mut Certificate,
) -> Result<(Replacement, DistortionReport, usize, PatchFactors), Failure> {
    let reference = field.reference();
    let disk =
        extract_patch(&work.mesh, faces).map_err(|e| Failure::stage("patch extraction", e))?;

    // (b) bijective parameterization, certified (the parameterizer certifies; we check again
    // because it is a research extension point).
    let t0 = Instant::now();
    let param = stages
        .parameterizer
        .parameterize(&disk.mesh, &disk.boundary)
        .map_err(|e| Failure::stage("parameterization", e))?;
    invariants::certify_bijective(&param.uv, &disk.mesh.triangles, &disk.boundary)
        .map_err(|e| Failure::certificate("parameterization", e))?;
    cert.bijective += 1;
    if param.report.fell_back {
        cert.param_fallbacks += 1;
    }
    times.param += t0.elapsed().as_secs_f64();

    // (c) metric transfer (Eq. 4): the 3D metric is read from the reference field at each
    // patch vertex's reference location and carried to the plane.
    let t0 = Instant::now();
    let boost = if fid_scale.is_empty() {
        Vec::new()
    } else {
        fidelity::patch_vertex_factors(field, fid_scale, &disk.mesh)
    };
    let metrics3d: Vec<Matrix3<f64>> = disk
        .to_global
        .iter()
        .enumerate()
        .map(|(i, g)| {
            let loc = &work.locations[g.idx()];
            // What earlier patches' fidelity rounds needed here (1 when none).
            let m = field.eval_at(loc) * vfactor.get(g.idx()).copied().unwrap_or(1.0).max(1.0);
            // The field already carries the interpolated a-priori factor; raise it to the
            // largest factor of the reference vertices under this vertex's faces.
            match boost.get(i) {
                Some(&b) if b > 1.0 => {
                    let t = reference.face(loc.face);
                    let here: f64 = (0..3).map(|k| loc.bary[k] * fid_scale[t[k].idx()]).sum();
                    m * (b / here).max(1.0)
                }
                _ => m,
            }
        })
        .collect();
    let metrics2d = transfer_metric(&disk.mesh, &param.uv, &metrics3d, options.transfer)
        .map_err(|e| Failure::stage("metric transfer", e))?;
    let corners = if options.corner_pullback && options.transfer == TransferMethod::JacobianPullback
    {
        Some(
            pullback_corners(&disk.mesh, &param.uv, &metrics3d)
                .map_err(|e| Failure::stage("metric transfer", e))?,
        )
    } else {
        None
    };
    // The fidelity control scales the vertex tensors by scalars; the corner tensors follow
    // by the same factor (ratio of traces).
    let base_trace: Vec<f64> = metrics2d.iter().map(|m| m.trace()).collect();
    let tris_u32: Vec<[u32; 3]> = disk
        .mesh
        .triangles
        .iter()
        .map(|t| [t[0].0, t[1].0, t[2].0])
        .collect();
    times.transfer += t0.elapsed().as_secs_f64();

    // (d) planar remeshing with the patch boundary fixed, certified; (e) map back:
    // barycentric location in the initial 2D mesh, then onto the reference. Repeated with the
    // metric scaled up where the lifted patch deviates from the reference by more than the
    // fidelity tolerance (our addition, `crate::fidelity`).
    let domain = PlanarDomain {
        points: param.uv.clone(),
        triangles: tris_u32.clone(),
        boundary: disk.boundary.iter().map(|v| v.0).collect(),
        constrained_edges: Vec::new(),
    };
    let frame = PatchFrame {
        triangles: &disk.mesh.triangles,
        positions: &disk.mesh.positions,
        to_global: &disk.to_global,
    };
    let mut metrics2d = metrics2d;
    let mut rounds = 0usize;
    let (replacement, patch_factors) = loop {
        let t0 = Instant::now();
        let mut planar_field =
            PlanarMetricField::new(param.uv.clone(), tris_u32.clone(), metrics2d.clone())
                .map_err(|e| Failure::stage("metric transfer", e))?;
        if let Some(c) = &corners {
            let factor: Vec<f64> = metrics2d
                .iter()
                .zip(&base_trace)
                .map(|(m, b)| if *b > 0.0 { m.trace() / b } else { 1.0 })
                .collect();
            let scaled = c
                .iter()
                .zip(&tris_u32)
                .map(|(c, t)| [0, 1, 2].map(|k| c[k] * factor[t[k] as usize]))
                .collect();
            planar_field = planar_field
                .with_corner_metrics(scaled)
                .map_err(|e| Failure::stage("metric transfer", e))?;
        }
        let planar = stages
            .remesher
            .remesh(&domain, &planar_field, l_tar, rng)
            .map_err(|e| Failure::stage("planar remeshing", e))?;
        invariants::certify_planar(&domain, &planar)
            .map_err(|e| Failure::certificate("planar remeshing", e))?;
        if rounds == 0 {
            cert.planar += 1;
        } else {
            cert.planar_refined += 1;
        }
        times.remesh2d += t0.elapsed().as_secs_f64();

        let t0 = Instant::now();
        let replacement = lift(
            &planar,
            &frame,
            |p| planar_field.locate(p),
            |p| field.project(p).0,
            reference,
        )
        .map_err(|e| Failure::stage("mapping back", e))?;
        times.lift += t0.elapsed().as_secs_f64();

        // The factor by which the rounds so far scaled the metric, at every vertex of the
        // initial mesh and (interpolated) at every new vertex, times what it carried in.
        let factors = |metrics2d: &[nalgebra::Matrix2<f64>]| {
            if !options.fidelity.persist {
                return PatchFactors {
                    existing: Vec::new(),
                    new: Vec::new(),
                };
            }
            let total: Vec<f64> = (0..metrics2d.len())
                .map(|i| {
                    let r = if base_trace[i] > 0.0 {
                        metrics2d[i].trace() / base_trace[i]
                    } else {
                        1.0
                    };
                    r.max(1.0)
                        * vfactor
                            .get(disk.to_global[i].idx())
                            .copied()
                            .unwrap_or(1.0)
                            .max(1.0)
                })
                .collect();
            let new: Vec<f64> = planar
                .points
                .iter()
                .zip(&planar.origin)
                .filter(|(_, o)| o.is_none())
                .map(|(p, _)| match planar_field.locate(p) {
                    Some((t, b)) => (0..3)
                        .map(|k| b[k] * total[tris_u32[t][k] as usize])
                        .sum::<f64>()
                        .max(1.0),
                    None => 1.0,
                })
                .collect();
            PatchFactors {
                existing: disk.to_global.iter().copied().zip(total).collect(),
                new,
            }
        };
        let eps = options.fidelity.max_deviation;
        if eps.is_nan() || eps <= 0.0 || rounds >= options.fidelity.rounds {
            break (replacement, factors(&metrics2d));
        }
        let t0 = Instant::now();
        let mut next_new = 0usize;
        let positions: Vec<Point3<f64>> = planar
            .origin
            .iter()
            .map(|o| match o {
                Some(o) => disk.mesh.positions[*o as usize],
                None => {
                    next_new += 1;
                    replacement.new_positions[next_new - 1]
                }
            })
            .collect();
        let fixed: Vec<bool> = planar.origin.iter().map(Option::is_some).collect();
        let deviating = fidelity::deviations(
            field,
            ref_normals,
            &LiftedPatch {
                positions: &positions,
                fixed: &fixed,
                triangles: &planar.triangles,
            },
            eps,
        );
        let scaled = if deviating.is_empty() {
            0
        } else {
            fidelity::scale_metric(
                &mut metrics2d,
                &planar_field,
                &planar,
                &deviating,
                eps,
                options.fidelity.max_factor,
                l_tar,
                min_edge,
            )
        };
        times.fidelity += t0.elapsed().as_secs_f64();
        if scaled == 0 {
            break (replacement, factors(&metrics2d));
        }
        rounds += 1;
    };

    // (f) certify the candidate's new faces before touching the working mesh.
    let t0 = Instant::now();
    let checked = certify_replacement(flip_test, work, topo, faces, &replacement);
    times.certify += t0.elapsed().as_secs_f64();
    if let Err(e) = checked {
        let mut f = Failure::certificate("lifted faces", e);
        f.candidate = Some(Box::new(replacement));
        return Err(f);
    }
    cert.no_degenerate += 1;
    cert.no_flips += 1;
    if embedded_input {
        let t0 = Instant::now();
        let checked = certify_candidate_embedded(work, faces, &replacement);
        times.certify += t0.elapsed().as_secs_f64();
        if let Err(e) = checked {
            let mut f = Failure::certificate("lifted faces", e);
            f.candidate = Some(Box::new(replacement));
            return Err(f);
        }
        cert.locally_embedded += 1;
    }
    Ok((replacement, param.report, rounds, patch_factors))
}

/// The fidelity control's metric factors after a patch (our addition): at the patch's vertices
/// (working-mesh ids) and at its new vertices (in [`Replacement::new_positions`] order). Kept
/// per working-mesh vertex, so a later patch over the same area (the overlap rings, a further
/// sweep) starts from the refinement this one needed instead of from the a-priori metric.
struct PatchFactors {
    existing: Vec<(VertexId, f64)>,
    new: Vec<f64>,
}

/// Mean length of the edges of `mesh` (each interior edge counted from both faces).
fn mean_edge_length(mesh: &TriMesh) -> f64 {
    let (sum, n) = mesh.faces().fold((0.0, 0usize), |(s, n), f| {
        let [a, b, c] = mesh.face_points(f);
        (s + (b - a).norm() + (c - b).norm() + (a - c).norm(), n + 3)
    });
    if n == 0 {
        0.0
    } else {
        sum / n as f64
    }
}

/// Metric edge flips after the loop (our addition). The patches' boundaries are fixed while
/// they are remeshed, so the triangles along the seams between patches are the worst of the
/// output (decimated-knight and cow: q ≈ 0.65-0.76 on seam faces against 0.84-0.85 inside
/// patches). An interior edge `ab` with faces `abc`, `bad` is replaced by `cd` when the
/// smaller quality (Sec. 4.1, metric of the reference at the vertices' locations, as `eval`)
/// of the two faces strictly increases, `cd` is not an edge yet, the new faces are neither
/// degenerate (exact) nor flipped against the reference (conservative test), do not intersect
/// the faces around them (exact, embedded input only), and the two diagonals pass within
/// `tol` of each other (the flip moves the surface by at most that much). Passes repeat
/// until nothing flips (at most 8). Returns the number of flips.
fn flip_pass(
    field: &MetricField,
    flip_test: &FlipTest,
    work: &mut WorkingMesh,
    embedded_input: bool,
    tol: f64,
    feature_edges: Option<&HashSet<EdgeKey>>,
) -> usize {
    use crate::quality::{face_metric, triangle_quality};
    let metrics: Vec<Matrix3<f64>> = work.locations.iter().map(|l| field.eval_at(l)).collect();
    let q = |mesh: &TriMesh, t: [VertexId; 3]| {
        triangle_quality(
            t.map(|v| mesh.positions[v.idx()]),
            &face_metric(&metrics, t),
        )
        .q
    };
    let mut total = 0;
    let mut grid = FaceGrid::new(&work.mesh);
    for _pass in 0..8 {
        let mut edge_faces: std::collections::HashMap<EdgeKey, Vec<usize>> =
            std::collections::HashMap::new();
        for (f, t) in work.mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                edge_faces
                    .entry(EdgeKey::new(t[k], t[(k + 1) % 3]))
                    .or_default()
                    .push(f);
            }
        }
        let mut edges: Vec<EdgeKey> = edge_faces
            .iter()
            .filter(|(e, fs)| fs.len() == 2 && !feature_edges.is_some_and(|fe| fe.contains(e)))
            .map(|(e, _)| *e)
            .collect();
        edges.sort();
        let mut touched = vec![false; work.mesh.n_faces()];
        // Quality of each face, computed once per pass (a face is looked at from each of its
        // three edges; a flipped face is `touched` and not looked at again in this pass).
        let mut face_q: Vec<Option<f64>> = vec![None; work.mesh.n_faces()];
        let mut new_edges: HashSet<EdgeKey> = HashSet::new();
        let mut flipped = 0;
        for e in edges {
            let fs = &edge_faces[&e];
            let (f1, f2) = (fs[0], fs[1]);
            if touched[f1] || touched[f2] {
                continue;
            }
            // Orient: f1 = (a, b, c) with the directed edge a→b, f2 = (b, a, d).
            let t1 = work.mesh.triangles[f1];
            let t2 = work.mesh.triangles[f2];
            let Some(k) = (0..3).find(|&k| EdgeKey::new(t1[k], t1[(k + 1) % 3]) == e) else {
                continue;
            };
            let (a, b, c) = (t1[k], t1[(k + 1) % 3], t1[(k + 2) % 3]);
            let Some(d) = t2.iter().copied().find(|v| *v != a && *v != b) else {
                continue;
            };
            if c == d || !(0..3).any(|j| t2[j] == b && t2[(j + 1) % 3] == a) {
                continue;
            }
            let cd = EdgeKey::new(c, d);
            if edge_faces.contains_key(&cd) || new_edges.contains(&cd) {
                continue;
            }
            let mut cached =
                |f: usize, t: [VertexId; 3]| *face_q[f].get_or_insert_with(|| q(&work.mesh, t));
            let (q1, q2) = (cached(f1, t1), cached(f2, t2));
            let n1 = [a, d, c];
            let n2 = [d, b, c];
            let (r1, r2) = (q(&work.mesh, n1), q(&work.mesh, n2));
            // The smaller quality must rise (maximising the sum instead gave +0.002 q_avg on
            // cow and knight but lower q_min).
            if r1.min(r2).partial_cmp(&q1.min(q2)) != Some(std::cmp::Ordering::Greater) {
                continue;
            }
            let p = |v: VertexId| work.mesh.positions[v.idx()];
            if segment_distance(p(a), p(b), p(c), p(d)) > tol {
                continue;
            }
            let tris = [n1.map(p), n2.map(p)];
            if tris
                .iter()
                .any(|t| collinear(t) || flip_test.is_flipped_anywhere(t))
            {
                continue;
            }
            if embedded_input
                && !candidate_embedded_local(
                    &work.mesh,
                    &grid,
                    &[FaceId::new(f1), FaceId::new(f2)],
                    &[n1, n2],
                )
            {
                continue;
            }
            work.mesh.triangles[f1] = n1;
            work.mesh.triangles[f2] = n2;
            if let Some((lo, hi)) = bbox_of([a, b, c, d].iter().map(|v| p(*v))) {
                grid.insert(f1, &lo, &hi);
                grid.insert(f2, &lo, &hi);
            }
            touched[f1] = true;
            touched[f2] = true;
            new_edges.insert(cd);
            flipped += 1;
        }
        total += flipped;
        if flipped == 0 {
            break;
        }
    }
    total
}

/// Vertex relocation after the loop (our addition): every vertex off the input boundary is
/// moved towards the centroid of its neighbours (full, half or quarter step) and projected
/// onto the reference (its location follows), when the smallest metric quality of its faces
/// rises, its new faces pass the candidate certificates (not degenerate, not flipped, locally
/// embedded), and no watched point — its old position and the corners of the reference faces
/// under it and its neighbours — ends farther from the fan than `tol` unless it already was,
/// and then not farther than before (tips and creases are not cut off). Three sweeps over the
/// vertices. The seams between patches are where this matters: their vertices were fixed
/// patch-boundary vertices. Returns the number of moves.
fn smooth_pass(
    field: &MetricField,
    flip_test: &FlipTest,
    work: &mut WorkingMesh,
    embedded_input: bool,
    tol: f64,
    corners: &[bool],
) -> usize {
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
                    .all(|t| !collinear(t) && !flip_test.is_flipped_anywhere(t))
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

/// The metric-optimal position of `v` (our addition, the anisotropic counterpart of the
/// centroid): for every face `(v, a, b)` of its fan the apex that makes the face equilateral
/// in the metric `m` at `v` (restricted to the fan's tangent plane), averaged over the fan.
/// `None` when the plane or the metric there is degenerate.
fn metric_optimal_point(
    mesh: &TriMesh,
    fan: &[FaceId],
    v: VertexId,
    m: &Matrix3<f64>,
) -> Option<Point3<f64>> {
    use nalgebra::{Matrix2, Vector2};
    let n = fan
        .iter()
        .fold(Vector3::zeros(), |acc, f| acc + mesh.face_normal_raw(*f))
        .try_normalize(1e-300)?;
    let e1 = n
        .cross(&Vector3::x())
        .try_normalize(1e-6)
        .or_else(|| n.cross(&Vector3::y()).try_normalize(1e-6))?;
    let e2 = n.cross(&e1);
    let m2 = Matrix2::new(
        e1.dot(&(m * e1)),
        e1.dot(&(m * e2)),
        e2.dot(&(m * e1)),
        e2.dot(&(m * e2)),
    );
    // Metric coordinates y = Lᵀx with M₂ = L Lᵀ (det L > 0 keeps orientations).
    let l = m2.cholesky()?.l();
    let lt = l.transpose();
    let lt_inv = lt.try_inverse()?;
    let o = mesh.positions[v.idx()];
    let to2 = |p: &Point3<f64>| lt * Vector2::new((p - o).dot(&e1), (p - o).dot(&e2));
    let mut sum = Vector2::zeros();
    for f in fan {
        let t = mesh.triangles[f.idx()];
        let k = t.iter().position(|u| *u == v)?;
        let (a, b) = (
            to2(&mesh.positions[t[(k + 1) % 3].idx()]),
            to2(&mesh.positions[t[(k + 2) % 3].idx()]),
        );
        // (p, a, b) counter-clockwise: p to the left of a → b.
        let d = b - a;
        sum += (a + b) * 0.5 + Vector2::new(-d.y, d.x) * (3f64.sqrt() / 2.0);
    }
    let x = lt_inv * (sum / fan.len() as f64);
    let p = o + e1 * x.x + e2 * x.y;
    p.coords.iter().all(|c| c.is_finite()).then_some(p)
}

/// Euclidean distance from `p` to the triangle `t` (parry's point-triangle projection).
fn point_triangle_distance(p: &Point3<f64>, t: &[Point3<f64>; 3]) -> f64 {
    use parry3d_f64::math::Vector as PVec;
    use parry3d_f64::query::PointQuery;
    let v = |x: &Point3<f64>| PVec::new(x.x, x.y, x.z);
    parry3d_f64::shape::Triangle::new(v(&t[0]), v(&t[1]), v(&t[2]))
        .distance_to_local_point(v(p), false)
}

/// Distance between the segments `ab` and `cd` (sampled closest-point iteration is not
/// needed: the exact minimum over the clamped parameters).
fn segment_distance(a: Point3<f64>, b: Point3<f64>, c: Point3<f64>, d: Point3<f64>) -> f64 {
    let (u, v, w) = (b - a, d - c, a - c);
    let (aa, bb, cc, dd, ee) = (u.dot(&u), u.dot(&v), v.dot(&v), u.dot(&w), v.dot(&w));
    let den = aa * cc - bb * bb;
    let mut s = if den > 1e-300 {
        ((bb * ee - cc * dd) / den).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = if cc > 0.0 { (bb * s + ee) / cc } else { 0.0 };
    if t < 0.0 {
        t = 0.0;
        s = if aa > 0.0 {
            (-dd / aa).clamp(0.0, 1.0)
        } else {
            0.0
        };
    } else if t > 1.0 {
        t = 1.0;
        s = if aa > 0.0 {
            ((bb - dd) / aa).clamp(0.0, 1.0)
        } else {
            0.0
        };
    }
    ((a + u * s) - (c + v * t)).norm()
}

/// A corner vertex all of whose faces are in `faces` (interior to the patch), if any.
fn interior_corner(
    mesh: &TriMesh,
    topo: &Topology,
    faces: &[FaceId],
    corners: &[bool],
) -> Option<VertexId> {
    let mut count: std::collections::HashMap<VertexId, usize> = std::collections::HashMap::new();
    for &f in faces {
        for v in mesh.face(f) {
            if corners.get(v.idx()).copied().unwrap_or(false) {
                *count.entry(v).or_default() += 1;
            }
        }
    }
    let mut inside: Vec<VertexId> = count
        .into_iter()
        .filter(|(v, n)| !topo.is_boundary_vertex(*v) && *n == topo.vertex_faces(*v).len())
        .map(|(v, _)| v)
        .collect();
    inside.sort_unstable();
    inside.first().copied()
}

/// A feature edge shared by two faces of the patch (so inside it), the smallest if several.
fn interior_feature(
    mesh: &TriMesh,
    faces: &[FaceId],
    feature_edges: &HashSet<EdgeKey>,
) -> Option<EdgeKey> {
    let mut count: std::collections::HashMap<EdgeKey, u32> = std::collections::HashMap::new();
    for f in faces {
        let t = mesh.triangles[f.idx()];
        for k in 0..3 {
            *count.entry(EdgeKey::new(t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    count
        .into_iter()
        .filter(|(e, c)| *c >= 2 && feature_edges.contains(e))
        .map(|(e, _)| e)
        .min()
}

/// A smaller disk inside `faces`: grown face by face (breadth first, exact disk rule) from
/// `seed_face` if it is unprocessed, else from the first unprocessed face, up to `target`
/// faces. Deterministic.
fn shrink_patch(
    work: &WorkingMesh,
    topo: &Topology,
    faces: &[FaceId],
    seed_face: FaceId,
    target: usize,
    corners: &[bool],
    feature_edges: Option<&HashSet<EdgeKey>>,
) -> Vec<FaceId> {
    let inside: HashSet<FaceId> = faces.iter().copied().collect();
    let start = if inside.contains(&seed_face) && !work.processed[seed_face.idx()] {
        seed_face
    } else {
        match faces.iter().find(|f| !work.processed[f.idx()]) {
            Some(f) => *f,
            None => return faces.to_vec(),
        }
    };
    let ctx = PatchContext {
        mesh: &work.mesh,
        topology: topo,
        processed: &work.processed,
        feature_edges,
        corners: Some(corners),
    };
    let mut disk = DiskPatch::new(&ctx, start);
    let mut queue = std::collections::VecDeque::from([start]);
    while let Some(f) = queue.pop_front() {
        if disk.len() >= target.max(1) {
            break;
        }
        for i in 0..3 {
            if let Some(g) = topo.neighbor(f, i) {
                if inside.contains(&g) && !disk.contains(g) && disk.try_add(g).is_ok() {
                    queue.push_back(g);
                    if disk.len() >= target.max(1) {
                        break;
                    }
                }
            }
        }
    }
    disk.sorted_faces()
}

/// The new faces of a candidate replacement: none degenerate (exact), none flipped against
/// the reference surface (normal more than 90° from the normal of the reference face closest
/// to the face's centroid).
fn certify_replacement(
    flip_test: &FlipTest,
    work: &WorkingMesh,
    topo: &Topology,
    patch_faces: &[FaceId],
    r: &Replacement,
) -> Result<(), InvariantError> {
    use crate::stitch::PatchVertex;
    // A new edge between two existing (patch boundary) vertices must not already be an edge
    // of the working mesh outside the patch: a disk patch can touch itself from outside (two
    // boundary vertices joined by an outside edge), and a planar chord between them would
    // give that edge four faces after stitching.
    let in_patch: HashSet<FaceId> = patch_faces.iter().copied().collect();
    let mut duplicated = Vec::new();
    for t in &r.triangles {
        for k in 0..3 {
            if let (PatchVertex::Existing(a), PatchVertex::Existing(b)) = (t[k], t[(k + 1) % 3]) {
                let has_edge = |f: &&FaceId| work.mesh.triangles[f.idx()].contains(&b);
                let faces_a = topo.vertex_faces(a);
                // An edge of the patch itself (its boundary edges) is fine.
                let patch_edge = faces_a
                    .iter()
                    .filter(has_edge)
                    .any(|f| in_patch.contains(f));
                let outside = faces_a
                    .iter()
                    .filter(has_edge)
                    .any(|f| !in_patch.contains(f));
                if outside && !patch_edge {
                    duplicated.push(invariants::EdgeFaces(EdgeKey::new(a, b), 4));
                }
            }
        }
    }
    if !duplicated.is_empty() {
        duplicated.sort_by_key(|e| e.0);
        duplicated.dedup();
        return Err(InvariantError::NonManifoldEdges(Offenders(duplicated)));
    }
    let pos = |v: &PatchVertex| match *v {
        PatchVertex::Existing(g) => work.mesh.positions[g.idx()],
        PatchVertex::New(i) => r.new_positions[i as usize],
    };
    let mut degenerate = Vec::new();
    let mut flipped = Vec::new();
    for (i, t) in r.triangles.iter().enumerate() {
        let p = [pos(&t[0]), pos(&t[1]), pos(&t[2])];
        // Index in the stitched mesh is unknown yet: report the replacement index as a face id
        // of the candidate.
        let f = FaceId::new(i);
        if collinear(&p) {
            degenerate.push(f);
            continue;
        }
        if flip_test.is_flipped_anywhere(&p) {
            flipped.push(f);
        }
    }
    if !degenerate.is_empty() {
        return Err(InvariantError::DegenerateFaces(Offenders(degenerate)));
    }
    if !flipped.is_empty() {
        return Err(InvariantError::FlippedFaces(Offenders(flipped)));
    }
    Ok(())
}

/// Exact local self-intersection test of a candidate: the new faces against each other and
/// against the working-mesh faces (outside the patch) whose bounding boxes meet the new faces'
/// bounding box. Pairs of two old faces are not the candidate's doing and are ignored. Face ids
/// in the error: `f0..` are the candidate's triangles, larger ids the old faces in the order
/// they were gathered.
fn certify_candidate_embedded(
    work: &WorkingMesh,
    patch_faces: &[FaceId],
    r: &Replacement,
) -> Result<(), InvariantError> {
    let (positions, new_tris) = candidate_arrays(work, r);
    let Some((lo, hi)) = bbox_of(new_tris.iter().flatten().map(|v| positions[v.idx()])) else {
        return Ok(());
    };
    let in_patch: HashSet<FaceId> = patch_faces.iter().copied().collect();
    let n_new = new_tris.len();
    let mut tris = new_tris;
    for (f, t) in work.mesh.triangles.iter().enumerate() {
        if in_patch.contains(&FaceId::new(f)) {
            continue;
        }
        if let Some((a, b)) = bbox_of(t.iter().map(|v| positions[v.idx()])) {
            if (0..3).all(|k| a[k] <= hi[k] && b[k] >= lo[k]) {
                tris.push(*t);
            }
        }
    }
    let local = TriMesh {
        positions,
        triangles: tris,
    };
    let pairs: Vec<invariants::FacePair> = invariants::self_intersections(&local)
        .into_iter()
        .filter(|(a, b)| a.idx() < n_new || b.idx() < n_new)
        .map(|(a, b)| invariants::FacePair(a, b))
        .collect();
    if pairs.is_empty() {
        Ok(())
    } else {
        Err(InvariantError::SelfIntersections(Offenders(pairs)))
    }
}

/// A uniform grid over face bounding boxes, for the local self-intersection checks of the
/// post-loop passes (a linear scan per flip or move made them O(F) each: 17 s of armadillo's
/// run). A face is listed in every cell its box overlaps; boxes that grow (a moved vertex, a
/// flipped pair) are added again without removing the old entries, so a query returns a
/// superset of the faces whose current box overlaps, which the caller filters exactly.
struct FaceGrid {
    cell: f64,
    cells: std::collections::HashMap<[i64; 3], Vec<u32>>,
}

impl FaceGrid {
    fn new(mesh: &TriMesh) -> FaceGrid {
        let cell = (2.0 * mean_edge_length(mesh)).max(1e-12);
        let mut g = FaceGrid {
            cell,
            cells: std::collections::HashMap::new(),
        };
        for (f, t) in mesh.triangles.iter().enumerate() {
            if let Some((lo, hi)) = bbox_of(t.iter().map(|v| mesh.positions[v.idx()])) {
                g.insert(f, &lo, &hi);
            }
        }
        g
    }

    fn key(&self, p: &Point3<f64>) -> [i64; 3] {
        [0, 1, 2].map(|k| (p[k] / self.cell).floor() as i64)
    }

    fn insert(&mut self, f: usize, lo: &Point3<f64>, hi: &Point3<f64>) {
        let (a, b) = (self.key(lo), self.key(hi));
        for i in a[0]..=b[0] {
            for j in a[1]..=b[1] {
                for k in a[2]..=b[2] {
                    self.cells.entry([i, j, k]).or_default().push(f as u32);
                }
            }
        }
    }

    /// Faces listed in the cells the box overlaps, sorted, without repeats.
    fn query(&self, lo: &Point3<f64>, hi: &Point3<f64>) -> Vec<usize> {
        let (a, b) = (self.key(lo), self.key(hi));
        let mut out = Vec::new();
        for i in a[0]..=b[0] {
            for j in a[1]..=b[1] {
                for k in a[2]..=b[2] {
                    if let Some(fs) = self.cells.get(&[i, j, k]) {
                        out.extend(fs.iter().map(|f| *f as usize));
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// [`certify_candidate_embedded`] for a replacement without new vertices (a flip or a move,
/// with the working mesh already holding the moved positions), with the faces near the
/// candidate taken from `grid`: the same faces in the same order, so the same verdict.
fn candidate_embedded_local(
    mesh: &TriMesh,
    grid: &FaceGrid,
    replaced: &[FaceId],
    new_tris: &[[VertexId; 3]],
) -> bool {
    let p = |v: &VertexId| mesh.positions[v.idx()];
    let Some((lo, hi)) = bbox_of(new_tris.iter().flatten().map(p)) else {
        return true;
    };
    let mut tris: Vec<[VertexId; 3]> = new_tris.to_vec();
    for f in grid.query(&lo, &hi) {
        if f >= mesh.n_faces() || replaced.contains(&FaceId::new(f)) {
            continue;
        }
        let t = mesh.triangles[f];
        if let Some((a, b)) = bbox_of(t.iter().map(p)) {
            if (0..3).all(|k| a[k] <= hi[k] && b[k] >= lo[k]) {
                tris.push(t);
            }
        }
    }
    // Compact the vertices (ids only matter by equality in the exact test).
    let mut local: std::collections::HashMap<VertexId, VertexId> = std::collections::HashMap::new();
    let mut positions = Vec::new();
    let triangles = tris
        .iter()
        .map(|t| {
            t.map(|v| {
                *local.entry(v).or_insert_with(|| {
                    positions.push(p(&v));
                    VertexId::new(positions.len() - 1)
                })
            })
        })
        .collect();
    let n_new = new_tris.len();
    invariants::self_intersections(&TriMesh {
        positions,
        triangles,
    })
    .into_iter()
    .all(|(a, b)| a.idx() >= n_new && b.idx() >= n_new)
}

/// The working mesh's positions followed by the candidate's new vertices, and the candidate's
/// triangles in those ids (new vertex `i` is `n_vertices + i`).
fn candidate_arrays(
    work: &WorkingMesh,
    r: &Replacement,
) -> (Vec<nalgebra::Point3<f64>>, Vec<[VertexId; 3]>) {
    use crate::stitch::PatchVertex;
    let mut positions = work.mesh.positions.clone();
    let base = positions.len() as u32;
    positions.extend_from_slice(&r.new_positions);
    let triangles = r
        .triangles
        .iter()
        .map(|t| {
            t.map(|v| match v {
                PatchVertex::Existing(g) => g,
                PatchVertex::New(i) => VertexId(base + i),
            })
        })
        .collect();
    (positions, triangles)
}

fn bbox_of(
    mut pts: impl Iterator<Item = nalgebra::Point3<f64>>,
) -> Option<(nalgebra::Point3<f64>, nalgebra::Point3<f64>)> {
    let first = pts.next()?;
    Some(pts.fold((first, first), |(lo, hi), p| (lo.inf(&p), hi.sup(&p))))
}

/// Exact: the three points are collinear iff all three coordinate projections are.
fn collinear(p: &[nalgebra::Point3<f64>; 3]) -> bool {
    use crate::predicates::{orient2d, Sign};
    use nalgebra::Point2;
    let proj = |i: usize, j: usize| {
        orient2d(
            &Point2::new(p[0][i], p[0][j]),
            &Point2::new(p[1][i], p[1][j]),
            &Point2::new(p[2][i], p[2][j]),
        ) == Sign::Zero
    };
    proj(0, 1) && proj(1, 2) && proj(2, 0)
}

/// Every boundary edge of the input is still a boundary edge of the working mesh, between the
/// same vertices at the same positions (bit for bit).
fn certify_input_boundary(
    mesh: &TriMesh,
    topo: &Topology,
    reference: &TriMesh,
    input_boundary: &[EdgeKey],
) -> Result<(), InvariantError> {
    if input_boundary.is_empty() {
        return Ok(());
    }
    let now: HashSet<EdgeKey> = topo
        .boundary_loops()
        .iter()
        .flat_map(|l| (0..l.len()).map(move |i| EdgeKey::new(l[i], l[(i + 1) % l.len()])))
        .collect();
    let mut moved = Vec::new();
    let mut missing = Vec::new();
    for e in input_boundary {
        for v in [e.0, e.1] {
            if mesh.positions[v.idx()] != reference.positions[v.idx()] {
                moved.push(v);
            }
        }
        if !now.contains(e) {
            missing.push(*e);
        }
    }
    if !moved.is_empty() {
        moved.sort();
        moved.dedup();
        return Err(InvariantError::BoundaryVerticesMoved(Offenders(moved)));
    }
    if !missing.is_empty() {
        return Err(InvariantError::BoundaryEdgesMissing(Offenders(missing)));
    }
    Ok(())
}

/// Write a candidate replacement (the lifted remesh of a patch) as OBJ into the debug
/// directory, next to the patch it would replace.
fn write_candidate(
    options: &RemeshOptions,
    patch: PatchId,
    work: &WorkingMesh,
    r: &Replacement,
) -> Option<PathBuf> {
    let dir = options.debug_dir.as_ref()?;
    let (positions, triangles) = candidate_arrays(work, r);
    let (sub, _) = TriMesh {
        positions,
        triangles,
    }
    .without_unreferenced_vertices();
    let path = dir.join(format!("conemesh-failed-{patch}-candidate.obj"));
    crate::io::write_mesh(&path, &sub).ok()?;
    Some(path)
}

/// Write the offending patch (faces of `mesh`) as OBJ into the debug directory.
fn write_debug(
    options: &RemeshOptions,
    patch: PatchId,
    what: &str,
    mesh: &TriMesh,
    faces: &[FaceId],
) -> Option<PathBuf> {
    let dir = options.debug_dir.as_ref()?;
    let sub = TriMesh {
        positions: mesh.positions.clone(),
        triangles: faces.iter().map(|f| mesh.triangles[f.idx()]).collect(),
    };
    let (sub, _) = sub.without_unreferenced_vertices();
    let path = dir.join(format!("conemesh-failed-{patch}-{what}.obj"));
    crate::io::write_mesh(&path, &sub).ok()?;
    Some(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two skinny triangles over the long diagonal of a flat rhombus, or of a ridge folded
    /// `lift` up along the short diagonal.
    fn rhombus(lift: f64) -> (MetricField, WorkingMesh, FlipTest) {
        let reference = TriMesh {
            positions: vec![
                Point3::new(-1.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(0.0, 0.3, lift),
                Point3::new(0.0, -0.3, lift),
            ],
            triangles: vec![
                [VertexId(0), VertexId(1), VertexId(2)],
                [VertexId(1), VertexId(0), VertexId(3)],
            ],
        };
        let field = MetricField::new(reference.clone(), vec![Matrix3::identity(); 4])
            .expect("identity metric");
        let work = WorkingMesh::from_reference(&reference);
        let flip_test = FlipTest::new(&reference);
        (field, work, flip_test)
    }

    /// The grid-based local check gives the same verdict as the full scan, on moves that
    /// push a torus vertex through the opposite side of the tube (intersecting) and on small
    /// moves (not intersecting).
    #[test]
    fn local_embedding_check_agrees_with_the_full_scan() {
        use crate::stitch::PatchVertex;
        let torus = crate::mesh::generators::torus(1.0, 0.3, 24, 12);
        let mut work = WorkingMesh::from_reference(&torus);
        let topo = Topology::build(&work.mesh);
        let grid = FaceGrid::new(&work.mesh);
        let (mut hits, mut misses) = (0, 0);
        for vi in (0..work.mesh.n_vertices()).step_by(7) {
            let v = VertexId::new(vi);
            let fan = topo.vertex_faces(v).to_vec();
            let old = work.mesh.positions[vi];
            // Towards the tube's centre line: 2.5 pierces the far wall, 0.05 stays near.
            let centre = Point3::from(Vector3::new(old.x, old.y, 0.0).normalize());
            for t in [0.05, 2.5] {
                work.mesh.positions[vi] = old + (centre - old) * t;
                let new_tris: Vec<[VertexId; 3]> =
                    fan.iter().map(|f| work.mesh.triangles[f.idx()]).collect();
                let r = Replacement {
                    new_positions: Vec::new(),
                    new_locations: Vec::new(),
                    triangles: new_tris
                        .iter()
                        .map(|t| t.map(PatchVertex::Existing))
                        .collect(),
                };
                let full = certify_candidate_embedded(&work, &fan, &r).is_ok();
                let local = candidate_embedded_local(&work.mesh, &grid, &fan, &new_tris);
                assert_eq!(full, local, "v{vi} t {t}");
                if full {
                    misses += 1
                } else {
                    hits += 1
                }
            }
            work.mesh.positions[vi] = old;
        }
        assert!(
            hits > 0 && misses > 0,
            "both verdicts exercised: {hits} / {misses}"
        );
    }

    /// A hexagon fan that is regular in the metric diag(4, 1, 0) (so squashed in x): with the
    /// centre displaced, the metric-optimal point is the centre again, while the plain
    /// centroid of a non-symmetric fan would not be.
    #[test]
    fn metric_optimal_point_recentres_an_anisotropic_fan() {
        let m = Matrix3::from_diagonal(&Vector3::new(4.0, 1.0, 0.0));
        let mut positions = vec![Point3::new(0.1, -0.2, 0.0)];
        for k in 0..6 {
            let a = std::f64::consts::FRAC_PI_3 * k as f64;
            positions.push(Point3::new(0.5 * a.cos(), a.sin(), 0.0));
        }
        let triangles = (0..6)
            .map(|k| [VertexId(0), VertexId(1 + k), VertexId(1 + (k + 1) % 6)])
            .collect();
        let mesh = TriMesh {
            positions,
            triangles,
        };
        let fan: Vec<FaceId> = (0..6).map(FaceId::new).collect();
        let p = metric_optimal_point(&mesh, &fan, VertexId(0), &m).expect("point");
        assert!(p.coords.norm() < 1e-12, "{p}");
        // A degenerate tangent metric gives no point.
        assert!(metric_optimal_point(&mesh, &fan, VertexId(0), &Matrix3::zeros()).is_none());
    }

    /// A flat unit square in the identity metric (restricted to the plane): its area over
    /// that of an equilateral triangle of side L; a scale of 4 everywhere quadruples it.
    #[test]
    fn expected_faces_of_a_flat_square() {
        let m = TriMesh {
            positions: vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(1.0, 1.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
            ],
            triangles: vec![
                [VertexId(0), VertexId(1), VertexId(2)],
                [VertexId(0), VertexId(2), VertexId(3)],
            ],
        };
        let id = vec![Matrix3::identity(); 4];
        let l = 0.1;
        let want = 1.0 / (3f64.sqrt() / 4.0 * l * l);
        let got = expected_faces(&m, &id, &[], l);
        assert!((got - want).abs() < 1e-9 * want, "{got} vs {want}");
        let got4 = expected_faces(&m, &id, &[4.0; 4], l);
        assert!((got4 - 4.0 * want).abs() < 1e-9 * want, "{got4}");
    }

    /// The skinny pair is flipped to the short diagonal (q rises from 0.29 to 0.65) and the
    /// result is still an oriented disk over the same four vertices.
    #[test]
    fn flip_pass_flips_a_skinny_pair_on_a_flat_rhombus() {
        let (field, mut work, flip_test) = rhombus(0.0);
        let q_min = |w: &WorkingMesh| {
            crate::quality::face_qualities(&w.mesh, &[Matrix3::identity(); 4])
                .iter()
                .map(|q| q.q)
                .fold(f64::INFINITY, f64::min)
        };
        let before = q_min(&work);
        assert_eq!(
            flip_pass(&field, &flip_test, &mut work, true, 0.01, None),
            1
        );
        let after = q_min(&work);
        assert!(after > before + 0.3, "q_min {before} -> {after}");
        let edges: HashSet<EdgeKey> = work
            .mesh
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| EdgeKey::new(t[k], t[(k + 1) % 3])))
            .collect();
        assert!(edges.contains(&EdgeKey::new(VertexId(2), VertexId(3))));
        assert!(!edges.contains(&EdgeKey::new(VertexId(0), VertexId(1))));
        let topo = Topology::build(&work.mesh);
        assert!(topo.is_oriented_manifold());
        assert_eq!(topo.boundary_loops().len(), 1);
        // Nothing left to improve.
        assert_eq!(
            flip_pass(&field, &flip_test, &mut work, true, 0.01, None),
            0
        );
    }

    /// The same skinny pair is not flipped when its diagonal is a feature-line edge.
    #[test]
    fn flip_pass_never_flips_a_feature_edge() {
        let (field, mut work, flip_test) = rhombus(0.0);
        let before = work.mesh.triangles.clone();
        let feature: HashSet<EdgeKey> = [EdgeKey::new(VertexId(0), VertexId(1))].into();
        assert_eq!(
            flip_pass(&field, &flip_test, &mut work, true, 0.01, Some(&feature)),
            0
        );
        assert_eq!(work.mesh.triangles, before);
    }

    /// On a ridge the flip would cut the surface by the ridge height (0.05 > tol 0.01): kept.
    #[test]
    fn flip_pass_keeps_a_ridge_beyond_the_tolerance() {
        let (field, mut work, flip_test) = rhombus(0.05);
        let before = work.mesh.triangles.clone();
        assert_eq!(
            flip_pass(&field, &flip_test, &mut work, true, 0.01, None),
            0
        );
        assert_eq!(work.mesh.triangles, before);
        // With a tolerance above the ridge height the same flip is made.
        assert_eq!(flip_pass(&field, &flip_test, &mut work, true, 0.1, None), 1);
    }

    /// A flat hexagonal fan whose centre sits near one corner: relocation moves it towards
    /// the middle and the worst triangle improves; on a pyramid whose apex is off-centre the
    /// apex may move only while the old apex stays within `tol` of the surface.
    fn hexagon(apex: Point3<f64>) -> TriMesh {
        let mut positions = vec![apex];
        let mut triangles = Vec::new();
        for i in 0..6 {
            let a = i as f64 * std::f64::consts::PI / 3.0;
            positions.push(Point3::new(a.cos(), a.sin(), 0.0));
            triangles.push([VertexId(0), VertexId(1 + i), VertexId(1 + (i + 1) % 6)]);
        }
        TriMesh {
            positions,
            triangles,
        }
    }

    #[test]
    fn smooth_pass_centres_a_fan_and_keeps_a_tip() {
        let q_min = |m: &TriMesh| {
            crate::quality::face_qualities(m, &vec![Matrix3::identity(); m.n_vertices()])
                .iter()
                .map(|q| q.q)
                .fold(f64::INFINITY, f64::min)
        };
        for (apex, tol) in [
            (Point3::new(0.6, 0.1, 0.0), 0.01),
            (Point3::new(0.3, 0.0, 0.4), 0.01),
        ] {
            let reference = hexagon(apex);
            let field = MetricField::new(reference.clone(), vec![Matrix3::identity(); 7])
                .expect("identity metric");
            let flip_test = FlipTest::new(&reference);
            let mut work = WorkingMesh::from_reference(&reference);
            let before = q_min(&work.mesh);
            let moves = smooth_pass(&field, &flip_test, &mut work, true, tol, &[]);
            let p = work.mesh.positions[0];
            let d = work
                .mesh
                .faces()
                .map(|f| point_triangle_distance(&apex, &work.mesh.face_points(f)))
                .fold(f64::INFINITY, f64::min);
            assert!(
                d <= tol,
                "apex {apex}: the old apex is {d} from the surface"
            );
            if apex.z == 0.0 {
                assert!(moves > 0 && p.coords.norm() < 0.3, "centre at {p}");
                assert!(q_min(&work.mesh) > before + 0.2);
            } else {
                // Any move of a sharp apex cuts it: kept.
                assert_eq!(p, apex);
            }
        }
    }

    #[test]
    fn segment_distance_of_crossing_and_skew_segments() {
        let p = |x, y, z| Point3::new(x, y, z);
        let d = segment_distance(
            p(-1., 0., 0.),
            p(1., 0., 0.),
            p(0., -1., 0.5),
            p(0., 1., 0.5),
        );
        assert!((d - 0.5).abs() < 1e-15);
        let d = segment_distance(p(0., 0., 0.), p(1., 0., 0.), p(2., 1., 0.), p(3., 1., 0.));
        assert!((d - 2f64.sqrt()).abs() < 1e-15);
    }
}
