//! What a run of Algorithm 1 reports: per-stage times, certificate counts, per-patch records,
//! the failed attempts of the retry ladder, typed warnings, and the report that `--report`
//! serialises.

use super::error::{Stage, StageError};
use super::options::RemeshOptions;
use crate::ids::{PatchId, VertexId};
use crate::mesh::{SurfaceLocation, TriMesh};
use crate::param::DistortionReport;
use serde::ser::SerializeStruct;
use serde::Serialize;
use std::fmt;

/// Wall-clock seconds of a run's phases, as a clock on the wall sees them, whatever the
/// thread count ([`StageTimes`] sums the stages of a batch's patches, which may run at the
/// same time).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct PhaseTimes {
    /// The input's certificates, the plan, the context and the working mesh before the loop.
    pub setup: f64,
    /// The regions' runs at the same time, and their merge (0 with one region).
    pub regions: f64,
    /// The band around the regions' cuts: its strips, then its junctions, each level's
    /// pieces at the same time (0 with one region).
    pub band: f64,
    /// Algorithm 1's loop over patches (with regions: over the bands around the cuts).
    pub patch_loop: f64,
    /// The improvers after the loop (Sec. 3.4).
    pub improve: f64,
    /// The output's certificates and the report.
    pub finish: f64,
}

/// Time per stage, seconds: the patches of a batch run at the same time, and their stage
/// times are summed, so with several threads the loop's stages add up to more than its wall
/// time.
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
    /// Working-mesh certificates after every patch and of the whole output.
    pub certify: f64,
    /// The improvers after the loop (Sec. 3.4; Algorithm 2's patches also count in the stages
    /// above).
    pub improve: f64,
    /// Final self-intersection test.
    pub final_check: f64,
}

impl StageTimes {
    /// Add `other`'s times stage by stage.
    pub fn add(&mut self, other: &StageTimes) {
        self.patches += other.patches;
        self.param += other.param;
        self.transfer += other.transfer;
        self.remesh2d += other.remesh2d;
        self.lift += other.lift;
        self.fidelity += other.fidelity;
        self.stitch += other.stitch;
        self.certify += other.certify;
        self.improve += other.improve;
        self.final_check += other.final_check;
    }
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
    /// The boundary certificate held after the patch: every boundary vertex on the input's
    /// boundary curves, corners kept (resampling, the default), or the input's boundary vertices
    /// and edges unchanged (`BoundaryOptions::resample` off). The name predates resampling and
    /// stays so that reports keep their keys.
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
    /// Free boundary chains resampled on the input's boundary curves.
    pub chains: usize,
}

impl Certificate {
    /// Add `other`'s counts (the output's own counts, `input_self_intersecting_pairs`
    /// included, are `self`'s).
    pub fn add(&mut self, other: &Certificate) {
        self.disk += other.disk;
        self.bijective += other.bijective;
        self.planar += other.planar;
        self.planar_refined += other.planar_refined;
        self.manifold += other.manifold;
        self.oriented += other.oriented;
        self.same_topology += other.same_topology;
        self.boundary_preserved += other.boundary_preserved;
        self.no_degenerate += other.no_degenerate;
        self.no_flips += other.no_flips;
        self.locally_embedded += other.locally_embedded;
        self.no_self_intersections += other.no_self_intersections;
        self.self_intersecting_pairs += other.self_intersecting_pairs;
        self.param_fallbacks += other.param_fallbacks;
        self.chains += other.chains;
    }
}

/// Per-patch record.
#[derive(Clone, Debug, Serialize)]
pub struct PatchRecord {
    /// Patch id.
    pub id: PatchId,
    /// Seed vertex (working-mesh id at the time).
    pub seed: VertexId,
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

/// One failed attempt of the retry ladder: which patch, how many faces it had, the stage
/// that failed and its typed error.
#[derive(Clone, Debug)]
pub struct FailedAttempt {
    /// The patch.
    pub patch: PatchId,
    /// Its size at this attempt (each retry shrinks it).
    pub faces: usize,
    /// The stage that failed.
    pub stage: Stage,
    /// Why.
    pub error: StageError,
}

impl fmt::Display for FailedAttempt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ({} faces): {}: {}",
            self.patch, self.faces, self.stage, self.error
        )
    }
}

impl Serialize for FailedAttempt {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut st = s.serialize_struct("FailedAttempt", 5)?;
        st.serialize_field("patch", &self.patch)?;
        st.serialize_field("faces", &self.faces)?;
        st.serialize_field("stage", &self.stage)?;
        st.serialize_field("certificate", &self.error.is_certificate())?;
        st.serialize_field("error", &self.error.to_string())?;
        st.end()
    }
}

/// What the retry ladder did (see [`super::remesh`]).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Fallbacks {
    /// Patches shrunk after a failed attempt.
    pub shrinks: usize,
    /// Unprocessed faces (of the input, or of an earlier sweep) kept unchanged because even a
    /// minimal patch failed.
    pub kept_faces: usize,
    /// Every failed attempt.
    pub failures: Vec<FailedAttempt>,
}

/// Something the user should know about a finished, certified run.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Warning {
    /// Patch attempts failed their certificates and were retried smaller; some faces may have
    /// been kept as they were.
    FailedAttempts {
        /// failed attempts
        attempts: usize,
        /// faces kept unchanged
        kept_faces: usize,
    },
    /// [`RemeshOptions::max_patches`] ran out: the faces no patch reached are the input's.
    PatchBudget {
        /// patches made
        patches: usize,
        /// faces left unprocessed (kept as they were)
        unprocessed: usize,
    },
    /// The input self-intersects, so the output (which lies on it) does too.
    InputSelfIntersects {
        /// self-intersecting face pairs of the input
        input_pairs: usize,
        /// of the output
        output_pairs: usize,
    },
    /// An improver's budget ran out (its faces below target stay as they are; the output is
    /// certified as any other).
    ImproverBudget {
        /// the improver
        improver: String,
        /// patches it made
        patches: usize,
    },
    /// The working mesh outgrew the face budget ([`super::FACE_BUDGET`]): from then on the
    /// fidelity control did not refine and no further sweep started, so the distance to the
    /// input may exceed the tolerance.
    FaceBudget {
        /// patches made when it happened
        patches: usize,
        /// faces of the working mesh then
        faces: usize,
        /// the budget
        budget: usize,
    },
    /// The run went over its work budget ([`super::WORK_BUDGET`]): from then on the fidelity
    /// control did not refine, no further sweep started and the improvers' patch passes
    /// stopped; past twice the budget no further patch of the loop started.
    WorkBudget {
        /// patches made when it happened
        patches: usize,
        /// faces handled by patch attempts then
        work: usize,
        /// the budget
        budget: usize,
        /// whether the run went past twice the budget and stopped starting patches
        stopped: bool,
        /// faces no patch reached (kept as they were)
        unprocessed: usize,
    },
    /// The coarse-input profile ran ([`RemeshOptions::coarse_profile`]).
    CoarseProfile {
        /// `--coarse on` forced it (else the automatic rule chose it)
        forced: bool,
        /// [`super::expected_faces`] in the metric alone
        expected_faces: f64,
        /// the same with the a-priori fidelity scaling
        expected_faces_fidelity: f64,
    },
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::FailedAttempts {
                attempts,
                kept_faces,
            } => write!(
                f,
                "{attempts} patch attempt(s) failed their certificates and were retried smaller; \
                 {kept_faces} face(s) (of the input, or of an earlier sweep) could not be remeshed \
                 and were kept as they were (details: --report, `fallbacks`)"
            ),
            Warning::FaceBudget {
                patches,
                faces,
                budget,
            } => write!(
                f,
                "the run outgrew its face budget ({faces} faces after {patches} patches, budget \
                 {budget}): the fidelity control stopped refining and no further sweep ran, so \
                 the distance to the input may exceed --hausd (sharp creases? try \
                 --feature-angle)"
            ),
            Warning::PatchBudget {
                patches,
                unprocessed,
            } => write!(
                f,
                "the patch budget ran out after {patches} patches: {unprocessed} face(s) were \
                 not reached and are kept as they were"
            ),
            Warning::WorkBudget {
                patches,
                work,
                budget,
                stopped,
                unprocessed,
            } => {
                write!(
                    f,
                    "the run went over its work budget ({work} faces handled by patch attempts \
                     after {patches} patches, budget {budget}): from then on the fidelity control \
                     stopped refining, no further sweep ran and the improvers' patch passes stopped"
                )?;
                match stopped {
                    true => write!(
                        f,
                        "; past twice the budget no further patch started and {unprocessed} \
                         face(s) were kept as they were"
                    ),
                    false => Ok(()),
                }
            }
            Warning::ImproverBudget { improver, patches } => write!(
                f,
                "improver `{improver}` ran out of its budget after {patches} patches; the faces \
                 it did not reach are kept as they were"
            ),
            Warning::InputSelfIntersects {
                input_pairs,
                output_pairs,
            } => write!(
                f,
                "the input itself self-intersects ({input_pairs} face pairs); the output, which \
                 lies on it, has {output_pairs}"
            ),
            Warning::CoarseProfile { forced: true, .. } => {
                write!(f, "coarse-input profile ran: forced by --coarse on")
            }
            Warning::CoarseProfile {
                expected_faces,
                expected_faces_fidelity,
                ..
            } => write!(
                f,
                "coarse-input profile ran: the distance tolerance, not the metric, sets the size \
                 here: expected faces {expected_faces:.0} in the metric, \
                 {expected_faces_fidelity:.0} with the fidelity scaling; --coarse off for the \
                 options as given"
            ),
        }
    }
}

/// Quality of a set of faces in the metric (Sec. 4.1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct FaceSummary {
    /// Faces.
    pub faces: usize,
    /// Smallest q.
    pub q_min: f64,
    /// Mean q.
    pub q_avg: f64,
    /// Smallest angle (degrees).
    pub theta_min: f64,
    /// Mean of each face's smallest angle (degrees).
    pub theta_avg: f64,
}

/// Whether the seams between patches leave a trace: the faces touching a former patch
/// boundary (an edge between faces of two patches, or of a patch and a kept input face)
/// against the rest.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct AngleSummary {
    /// Faces.
    pub faces: usize,
    /// Smallest metric quality.
    pub q_min: f64,
    /// Mean metric quality.
    pub q_avg: f64,
    /// Smallest angle (degrees).
    pub theta_min: f64,
    /// Mean of each face's smallest angle (degrees).
    pub theta_avg: f64,
    /// Faces whose smallest angle is below 10°.
    pub below_10: usize,
    /// Below 20°.
    pub below_20: usize,
    /// Below 25°.
    pub below_25: usize,
    /// Below 30°.
    pub below_30: usize,
    /// Faces per 10° bin of their smallest angle (`[0°, 10°)`, …), as `eval`'s histogram.
    pub hist_min_angles: [usize; 18],
}

/// What the improvers after the loop (Sec. 3.4, [`super::Stages::improvers`]) did: the
/// Table-1 row before the first and after the last (in the unscaled metric), each improver's
/// record, and their time.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ImprovementReport {
    /// Before the first improver (Algorithm 1's output).
    pub before: AngleSummary,
    /// After the last.
    pub after: AngleSummary,
    /// One record per improver, in the order they ran.
    pub steps: Vec<ImproverRecord>,
    /// Wall time of all of them.
    pub seconds: f64,
}

impl ImprovementReport {
    /// The record of improver `name`, if it ran.
    pub fn step(&self, name: &str) -> Option<&ImproverRecord> {
        self.steps.iter().find(|s| s.name == name)
    }
}

/// What one improver did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ImproverRecord {
    /// Its name (registry row).
    pub name: String,
    /// Its counts (flips, moves, passes, patches, rejected, budget).
    pub counts: crate::improve::ImproverCounts,
    /// The Table-1 row after it.
    pub after: AngleSummary,
    /// Its wall time (Algorithm 2's patches are also counted in the stage times).
    pub seconds: f64,
}

/// How the run was split into regions ([`RemeshReport::regions`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RegionsReport {
    /// Regions (1: the loop ran on the whole mesh).
    pub count: usize,
    /// With several: the faces the band's patches made, where the cuts were (`seam`), against
    /// the regions' faces (`rest`), in the unscaled metric.
    pub cuts: Option<SeamQuality>,
    /// The mesh was large enough for regions, but the run kept one: the 90th percentile of
    /// the cut edges' lengths, over L_tar in the metric, was this (above
    /// [`MAX_CUT_EDGE`](crate::pipeline::MAX_CUT_EDGE): the input is coarser than the output
    /// there, and frozen cuts would keep edges too long for it).
    pub declined_cut_edge: Option<f64>,
}

/// The smallest angle, in degrees and in the metric, below which a face is reported (the
/// paper's Fig. 6 marks these faces).
pub const SMALL_ANGLE_DEG: f64 = 20.0;

/// What holds a vertex of the output in place, from the most held to the least.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum VertexKind {
    /// A kept input corner (`--corner-defect`, or a boundary corner): never moved.
    Corner,
    /// On a feature line: moved along it only by resampling, never by the improvers.
    Feature,
    /// On the boundary: on the input's boundary curve.
    Boundary,
    /// Free.
    #[default]
    Interior,
}

/// A face below [`SMALL_ANGLE_DEG`] and why it may be there: the most held kind among its
/// vertices (a face with a kept corner is the corner's, then a feature line's, then the
/// boundary's).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SmallAngleFace {
    /// The face in the output mesh.
    pub face: crate::ids::FaceId,
    /// Its smallest angle in the metric, in degrees.
    pub angle_deg: f64,
    /// The most held kind among its three vertices.
    pub cause: VertexKind,
    /// All three of its vertices are kept input corners: no pass may change it.
    pub all_corners: bool,
}

/// The faces below [`SMALL_ANGLE_DEG`] in the metric, smallest angle first, and how many
/// there are of each cause.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SmallAngles {
    /// The threshold, in degrees.
    pub threshold_deg: f64,
    /// Each such face.
    pub faces: Vec<SmallAngleFace>,
    /// Faces with a kept corner.
    pub corner: usize,
    /// Faces with a feature-line vertex (and no corner).
    pub feature: usize,
    /// Faces with a boundary vertex (and no corner or feature-line vertex).
    pub boundary: usize,
    /// The other faces.
    pub interior: usize,
}

impl SmallAngles {
    /// The faces of `mesh` below [`SMALL_ANGLE_DEG`] under `vertex_metrics`, each with the
    /// most held kind of its vertices (`kinds`, per vertex).
    pub fn of(
        mesh: &crate::mesh::TriMesh,
        vertex_metrics: &[nalgebra::Matrix3<f64>],
        kinds: &[VertexKind],
    ) -> SmallAngles {
        let qs = crate::quality::face_qualities(mesh, vertex_metrics);
        let kind = |v: crate::ids::VertexId| kinds.get(v.idx()).copied().unwrap_or_default();
        let mut faces: Vec<SmallAngleFace> = (mesh.faces().zip(&qs))
            .filter(|(_, q)| q.min_angle() < SMALL_ANGLE_DEG)
            .map(|(f, q)| {
                let t = mesh.face(f);
                SmallAngleFace {
                    face: f,
                    angle_deg: q.min_angle(),
                    cause: t.iter().map(|&v| kind(v)).min().unwrap_or_default(),
                    all_corners: t.iter().all(|&v| kind(v) == VertexKind::Corner),
                }
            })
            .collect();
        faces.sort_by(|a, b| {
            a.angle_deg
                .total_cmp(&b.angle_deg)
                .then(a.face.cmp(&b.face))
        });
        let count = |k: VertexKind| faces.iter().filter(|f| f.cause == k).count();
        SmallAngles {
            threshold_deg: SMALL_ANGLE_DEG,
            corner: count(VertexKind::Corner),
            feature: count(VertexKind::Feature),
            boundary: count(VertexKind::Boundary),
            interior: count(VertexKind::Interior),
            faces,
        }
    }
}

/// The faces touching a patch seam against the rest (see [`RemeshReport::seams`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SeamQuality {
    /// Faces with an edge on a seam.
    pub seam: FaceSummary,
    /// All other faces.
    pub rest: FaceSummary,
}

/// Edge lengths against L_tar, and where the fidelity tolerance rather than the metric set
/// them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Sizes {
    /// Every edge (unit space, unscaled metric; as `conemesh eval`).
    pub all: crate::quality::Conformity,
    /// The edges between vertices made where the fidelity control did not scale the metric.
    pub unbound: crate::quality::Conformity,
    /// Edges with an endpoint where the tolerance bound.
    pub bound_edges: usize,
    /// Vertices made where the tolerance bound.
    pub bound_vertices: usize,
    /// Faces the a-priori fidelity scaling adds to the expected output
    /// ([`RemeshReport::expected_faces_fidelity`] − [`RemeshReport::expected_faces`]).
    pub faces_added_by_fidelity: f64,
}

/// The report of a run (serialised into `--report`).
#[derive(Clone, Debug, Serialize)]
pub struct RemeshReport {
    /// Options used (after the coarse-input profile, when it ran).
    pub options: RemeshOptions,
    /// The faces below 20° in the metric, each with its cause.
    pub small_angles: SmallAngles,
    /// The improvers after the loop (Sec. 3.4), when any ran.
    pub improvement: Option<ImprovementReport>,
    /// Strategy / parameterizer / remesher names.
    pub stages: [String; 3],
    /// The improvers' names, in the order they ran.
    pub improvers: Vec<String>,
    /// Mean metric edge length of the input (L_avg).
    pub l_avg: f64,
    /// Target metric edge length (L_tar).
    pub l_tar: f64,
    /// Number of patches, Algorithm 1's and the improvers' (each certified).
    pub patches: usize,
    /// Those of Algorithm 1's loop.
    pub loop_patches: usize,
    /// The batches they came in ([`RemeshOptions::batch`]): with several threads, the patches
    /// of a batch ran at the same time.
    pub loop_batches: usize,
    /// Faces handled by patch attempts, the loop's and the improvers'
    /// ([`RemeshOptions::work_budget`]).
    pub work: usize,
    /// The patch budget ([`RemeshOptions::max_patches`]) ran out before every face was
    /// processed.
    pub budget_exhausted: bool,
    /// Per-stage times (summed over a batch's patches).
    pub times: StageTimes,
    /// Wall-clock time of each phase of the run.
    pub wall: PhaseTimes,
    /// Certificates.
    pub certificate: Certificate,
    /// What the retry ladder did.
    pub fallbacks: Fallbacks,
    /// Per-patch records.
    pub patch_records: Vec<PatchRecord>,
    /// Input faces.
    pub faces_in: usize,
    /// Output faces.
    pub faces_out: usize,
    /// Output vertices.
    pub vertices_out: usize,
    /// Edges flipped by the improvers' connectivity updates on the surface
    /// ([`crate::improve::SurfacePasses`]).
    pub edge_flips: usize,
    /// Vertex moves of their vertex position updates on the surface.
    pub vertex_moves: usize,
    /// Input vertices kept as corners ([`RemeshOptions::corner_defect`]); each is certified
    /// to be a vertex of the output at its input position.
    pub corners: usize,
    /// Input edges kept as feature lines ([`RemeshOptions::features`]).
    pub feature_edges: usize,
    /// The pieces they were split into; each is certified to be an edge of the output, its
    /// vertices where the split put them.
    pub feature_pieces: usize,
    /// [`super::expected_faces`] of the input at L_tar in the metric alone.
    pub expected_faces: f64,
    /// The same with the a-priori fidelity scaling (before any coarse-input profile).
    pub expected_faces_fidelity: f64,
    /// Whether the coarse-input profile ran (`options` then holds the profile's values).
    pub coarse_input: bool,
    /// Everything the user should know about this run.
    pub warnings: Vec<Warning>,
    /// Faces along the seams between patches against the rest.
    pub seams: SeamQuality,
    /// The regions the loop ran in ([`RemeshOptions::region_faces`]).
    pub regions: RegionsReport,
    /// Edge lengths against L_tar, and where the fidelity tolerance set them.
    pub sizes: Sizes,
    /// Distances between the input's boundary curves and the output's boundary (unit space).
    pub boundary_distance: crate::boundary::CurveDistance,
}

/// The outcome of Algorithm 1 (unit-diagonal space; [`super::Remesher`] maps it back to file
/// units).
#[derive(Clone, Debug)]
pub struct RemeshResult {
    /// The remeshed surface (unit-diagonal space, compacted).
    pub mesh: TriMesh,
    /// Reference location of every output vertex.
    pub locations: Vec<SurfaceLocation>,
    /// Which patch produced each output face (`None`: an input face no patch replaced, i.e.
    /// kept unchanged). Diagnostics: where the seams and kept faces are.
    pub face_patch: Vec<Option<PatchId>>,
    /// Where each output vertex lies on the input's boundary curves (`None` inside).
    pub curve: Vec<Option<crate::boundary::CurvePoint>>,
    /// The input's boundary curves (vertex ids of the input, shared by the file-unit mesh).
    pub curves: crate::boundary::BoundaryCurves,
    /// What was done and certified.
    pub report: RemeshReport,
    /// The metric the patches were remeshed in, at every reference vertex (unit space): the
    /// run's metric (the size controls applied) with the a-priori fidelity factors
    /// ([`super::Plan::remesh_field`]), before the fidelity control's local refinements.
    pub remesh_metric: Vec<nalgebra::Matrix3<f64>>,
}

/// Progress reported after every patch.
#[derive(Copy, Clone, Debug)]
pub struct Progress {
    /// Patches done.
    pub patches: usize,
    /// Faces still to process over all sweeps (strictly decreasing).
    pub unprocessed: usize,
    /// Faces to process over all sweeps at the start.
    pub total: usize,
}
