//! Options of Algorithm 1 and the research extension points it runs.

use crate::boundary::BoundaryOptions;
use crate::features::FeatureRule;
use crate::fidelity::FidelityOptions;
use crate::improve::Improver;
use crate::metric::SizeOptions;
use crate::option_error::OptionError;
use crate::param::Parameterizer;
use crate::patches::PatchStrategy;
use crate::registry::{MetricSizes, Params, Registry, RegistryError};
use crate::remesh2d::{PlanarRemesher, TransferMethod};
use serde::Serialize;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

pub use crate::quality::TargetLength;

/// Options of Algorithm 1, with their defaults.
#[derive(Clone, Debug, Serialize)]
pub struct RemeshOptions {
    /// Seed of the one RNG every stage draws from. Default 1.
    pub seed: u64,
    /// Target metric edge length. Default `Factor(1.5)` (1.5·L_avg, as the paper's Table 1).
    pub target: TargetLength,
    /// How the 3D metric is carried to the plane. Default [`TransferMethod::default`].
    #[serde(skip)]
    pub transfer: TransferMethod,
    /// Run the exact self-intersection test on the final mesh. Default `true`.
    pub check_self_intersections: bool,
    /// Where offending patches are written when a certificate fails. Default `None`.
    #[serde(serialize_with = "lossy_path")]
    pub debug_dir: Option<PathBuf>,
    /// Stop after this many patches: the run then ends `Ok` with the unreached faces kept as
    /// they were, [`super::RemeshReport::budget_exhausted`] set and a
    /// [`super::Warning::PatchBudget`]. Default `None` (no budget).
    pub max_patches: Option<usize>,
    /// Stop at the first failed patch attempt instead of shrinking the patch and retrying
    /// (for invariant-checking runs that want every failure to be an error). Default `false`.
    pub strict: bool,
    /// Geometric fidelity control (our addition, [`crate::fidelity`]): patches whose lifted
    /// triangles deviate from the reference by more than `max_deviation` are remeshed again
    /// with the metric scaled up there; `max_deviation` also bounds how far the finishing
    /// passes may move the surface.
    pub fidelity: FidelityOptions,
    /// How many times Algorithm 1 covers the surface (our addition; 1 = the paper). Each
    /// further sweep marks every face unprocessed and runs the loop again on the working
    /// mesh, so the previous sweep's seams (fixed patch boundaries) are remeshed. Default 1.
    pub sweeps: usize,
    /// Carry the 3D metric to the plane per triangle corner (`J_tᵀ M(v) J_t`, exact for the
    /// piecewise-linear parameterization) instead of per vertex (Jacobians averaged around
    /// the vertex); see [`crate::remesh2d::PlanarMetricField::with_corner_metrics`]. Only with
    /// [`TransferMethod::JacobianPullback`]. Default `false` (paper-notes.md, Algorithm 1:
    /// it cuts thin tips).
    pub corner_pullback: bool,
    /// Input vertices whose angle defect `|2π − Σθ|` is at least this many radians are kept
    /// as vertices of the output (our addition, see [`crate::patches::corner_vertices`]): no
    /// patch contains them in its interior and the relocation pass does not move them.
    /// `None` keeps no vertex (the paper). Default `Some(1.0)`.
    pub corner_defect: Option<f64>,
    /// Feature lines (our addition, [`crate::features`]): the input edges this rule picks are
    /// resampled to the metric and kept as edges of the output (no patch crosses them, no
    /// pass moves or flips them). Default [`FeatureRule::Auto`]: a CAD part's creases, few or
    /// none of an organic mesh's edges; [`FeatureRule::Off`] is the paper (paper-notes
    /// "Feature lines").
    pub features: FeatureRule,
    /// Fit the curvature metric on each side of the feature lines ([`crate::metric::creases`])
    /// instead of across them (the paper's fit). [`super::Remesher`] reads it when it computes
    /// the curvature metric; [`super::remesh`] takes the field as given. Default off.
    pub crease_metric: bool,
    /// Bounds and gradation of the metric's sizes ([`crate::metric::sizes`]), in the units of
    /// the field given to [`super::remesh`] ([`super::Remesher`] takes them in file units).
    /// All off by default.
    pub sizes: SizeOptions,
    /// The input's boundary (ours, [`crate::boundary`]): resampled to the metric on the input's
    /// boundary curves, corners kept (default), or kept vertex for vertex.
    pub boundary: BoundaryOptions,
    /// Whether to run the coarse-input profile ([`RemeshOptions::coarse_profile`]): `Auto`
    /// (default) runs it when the distance tolerance rather than the metric sets the output's
    /// size: the a-priori fidelity scaling multiplies the expected face count
    /// ([`super::expected_faces`]) by at least [`COARSE_RATIO`].
    pub coarse_input: CoarseInput,
    /// Patches per batch of Algorithm 1's loop (ours, for parallel patches; see the
    /// [`super`] module docs): up to this many patches are chosen one after another on the same
    /// working mesh, each kept a vertex apart from the others, remeshed at the same time (one
    /// thread each, as rayon has them) and stitched in order. The output depends on this number
    /// and the seed, never on the thread count. 1 = one patch at a time (the paper). Default
    /// [`DEFAULT_BATCH`].
    pub batch: usize,
    /// The most output faces one region is expected to make (ours; see the [`super`] module
    /// docs and paper-notes "Regions"): a mesh expected to make more is split into regions by
    /// recursive coordinate bisection, each face weighing the output faces it should make
    /// (at least [`MIN_FACE_WEIGHT`](super::MIN_FACE_WEIGHT)); the regions run Algorithm 1
    /// and the improvers at the same time with their cuts frozen, and the bands around the
    /// cuts are remeshed after. The output depends on this number and the seed, never on the
    /// thread count. 0 = one region (the paper's loop on the whole mesh). Default
    /// [`DEFAULT_REGION_FACES`](super::DEFAULT_REGION_FACES).
    pub region_faces: usize,
    /// The face budget, a multiple of the larger of the input's face count and the expected
    /// output (default [`FACE_BUDGET`]); past it the fidelity control stops refining and no
    /// further sweep starts (a warning, not an error).
    pub face_budget: f64,
    /// The work budget, in faces handled by patch attempts (each attempt's patch faces plus
    /// its candidate's faces, once per fidelity round), as a multiple of the same base as the
    /// face budget (default [`WORK_BUDGET`]). Past it the fidelity control stops refining, no
    /// further sweep starts and the improvers' patch passes (Algorithm 2) stop; past twice it
    /// no further patch of the loop starts and the faces not reached are kept as they were.
    /// Both end `Ok` with [`Warning::WorkBudget`](super::Warning::WorkBudget).
    pub work_budget: f64,
    /// Asks a running job to stop (e.g. Ctrl-C in the Python package); not an option of the
    /// result, so it is not reported. Default: never set.
    #[serde(skip)]
    pub cancel: Cancel,
}

/// A stop request shared with another thread: [`super::remesh`] looks at it after every
/// patch and before the improvers, and then ends with [`super::PipelineError::Cancelled`].
/// Clones share the flag, so the caller keeps one and the options carry the other.
#[derive(Clone, Debug, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// Ask the run to stop at its next check.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether [`Cancel::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// `Err(Cancelled)` once cancelled, naming how many patches were done.
    pub fn check(&self, patches: usize) -> Result<(), super::PipelineError> {
        match self.is_cancelled() {
            true => Err(super::PipelineError::Cancelled { patches }),
            false => Ok(()),
        }
    }
}

/// The default of [`RemeshOptions::batch`]: one patch at a time, the paper's loop (why not
/// more: notes/doc-comments.md).
pub const DEFAULT_BATCH: usize = 1;

/// The face budget of a run, as a multiple of the larger of the input's face count and the
/// output expected with the a-priori fidelity scaling ([`super::Plan::expected_fidelity`]).
/// Past it the fidelity control stops refining and no further sweep starts
/// ([`Warning::FaceBudget`](super::Warning::FaceBudget)), so that a run whose refinement
/// runs away ends with a warning instead of running for hours (why 12:
/// notes/doc-comments.md).
pub const FACE_BUDGET: f64 = 12.0;

/// The work budget of a run ([`RemeshOptions::work_budget`]): faces handled by patch attempts,
/// as a multiple of the larger of the input's face count and the expected output. With the
/// per-patch certificates local, a run's time follows this count; the shared meshes and the
/// CGAL corpus stay far below it (BENCHMARKS.md, "Work"), so it only stops runs that would
/// otherwise go on for many minutes.
pub const WORK_BUDGET: f64 = 400.0;

/// [`CoarseInput::Auto`] runs the coarse-input profile when the a-priori fidelity scaling
/// multiplies the expected output face count ([`super::expected_faces`]) by at least this much.
pub const COARSE_RATIO: f64 = 2.0;

/// [`CoarseInput::Auto`] leaves the profile off when the input has more than this many times
/// the faces the a-priori fidelity scaling expects of the output: its edges are then shorter
/// than the output's on average (by √2 at this ratio), so the first sweep's seams are not the
/// long input edges the profile's further sweeps are for. Of the inputs measured only CGAL's
/// cheese is that dense (3.5×; the coarse ones 1.1–1.4×, paper-notes "Coarse inputs").
pub const DENSE_INPUT_RATIO: f64 = 2.0;

/// When [`super::remesh`] uses [`RemeshOptions::coarse_profile`] (paper-notes "Coarse inputs").
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub enum CoarseInput {
    /// When the a-priori fidelity scaling multiplies [`super::expected_faces`] by at least
    /// [`COARSE_RATIO`].
    #[default]
    Auto,
    /// Always.
    On,
    /// Never (the options as given).
    Off,
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
            corner_defect: Some(1.0),
            features: FeatureRule::Auto,
            crease_metric: false,
            coarse_input: CoarseInput::Auto,
            boundary: BoundaryOptions::default(),
            sizes: SizeOptions::default(),
            batch: DEFAULT_BATCH,
            region_faces: super::DEFAULT_REGION_FACES,
            face_budget: FACE_BUDGET,
            work_budget: WORK_BUDGET,
            cancel: Cancel::default(),
        }
    }
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

    /// Errors for option values no run can use, naming the option.
    pub fn validate(&self) -> Result<(), OptionError> {
        let out_of_range = |option, value, range| OptionError::OutOfRange {
            option,
            value,
            range,
        };
        if self.batch == 0 {
            return Err(OptionError::TooFew {
                option: "the patch batch",
                value: 0,
                min: 1,
            });
        }
        if self.work_budget.is_nan() || self.work_budget <= 0.0 {
            let w = self.work_budget;
            return Err(out_of_range("work budget", w, "a number > 0"));
        }
        if self.face_budget.is_nan() || self.face_budget <= 0.0 {
            let f = self.face_budget;
            return Err(out_of_range("face budget", f, "a number > 0"));
        }
        let eps = self.fidelity.max_deviation;
        if !(eps.is_finite() && eps >= 0.0) {
            let range = "a finite number ≥ 0";
            return Err(out_of_range("fidelity tolerance", eps, range));
        }
        if let Some(d) = self.corner_defect {
            if d.is_nan() || d <= 0.0 {
                let range = "a positive number of radians";
                return Err(out_of_range("corner angle defect", d, range));
            }
        }
        self.sizes.validate()?;
        let b = self.boundary.corner_angle;
        if !(b.is_finite() && b > 0.0 && b <= 180.0) {
            let range = "in (0, 180] degrees";
            return Err(out_of_range("boundary corner angle", b, range));
        }
        self.features.validate()?;
        Ok(())
    }
}

/// The research extension points, with the paper's methods as defaults. Built by name from
/// the registries ([`crate::patches::STRATEGIES`], [`crate::param::PARAMETERIZERS`],
/// [`crate::remesh2d::REMESHERS`], [`crate::improve::IMPROVERS`], or a [`Registries`] with
/// rows of one's own) or directly.
pub struct Stages {
    /// Sec. 3.2.
    pub patches: Box<dyn PatchStrategy>,
    /// Sec. 3.3, embedding.
    pub parameterizer: Box<dyn Parameterizer>,
    /// Sec. 3.3, planar remeshing.
    pub remesher: Box<dyn PlanarRemesher>,
    /// Sec. 3.4, after the loop, in this order (default [`default_improvers`]).
    pub improvers: Vec<Box<dyn Improver>>,
}

/// The names of the improvers a run takes by default, in order: every row of
/// [`crate::improve::IMPROVERS`].
pub fn default_improver_names() -> Vec<&'static str> {
    crate::registry::names(crate::improve::IMPROVERS)
}

/// The default improvers: every row of [`crate::improve::IMPROVERS`] in order, each with its
/// default options (a test holds that every row builds).
pub fn default_improvers() -> Vec<Box<dyn Improver>> {
    crate::improve::IMPROVERS
        .iter()
        .filter_map(|e| crate::improve::improver(e.name, Params::default()).ok())
        .collect()
}

/// One registry per extension point: the built-in rows ([`Registries::default`]) and any
/// added with [`Registry::with`].
#[derive(Default)]
pub struct Registries {
    /// Patch strategies.
    pub strategies: Registry<dyn PatchStrategy>,
    /// Parameterizers.
    pub parameterizers: Registry<dyn Parameterizer>,
    /// Planar remeshers.
    pub remeshers: Registry<dyn PlanarRemesher>,
    /// Improvers.
    pub improvers: Registry<dyn Improver>,
}

/// A row chosen by name, with its `KEY=VALUE` options.
pub type Choice<'a> = (&'a str, Params);

impl Default for Stages {
    /// The first row of each built-in table with its defaults, and every improver: the
    /// paper's stages, for the curvature metric.
    fn default() -> Self {
        Stages::for_sizes(MetricSizes::Relative)
    }
}

impl Stages {
    /// The default stages for a metric with `sizes`: the first row of each built-in table with
    /// its defaults for such a metric (with absolute sizes, cone patches that trim ragged
    /// expansions and [`crate::remesh2d::LctOptions::for_absolute_sizes`]), and every
    /// improver.
    pub fn for_sizes(sizes: MetricSizes) -> Stages {
        use crate::registry::build_default;
        // The built-in tables' first rows build with their defaults for both kinds of sizes
        // (the contract checks hold it, `contract::registry_row`).
        const BUILDS: &str = "the first row of a built-in table builds with its defaults";
        Stages {
            patches: build_default(crate::patches::STRATEGIES, sizes).expect(BUILDS),
            parameterizer: build_default(crate::param::PARAMETERIZERS, sizes).expect(BUILDS),
            remesher: build_default(crate::remesh2d::REMESHERS, sizes).expect(BUILDS),
            improvers: default_improvers(),
        }
    }

    /// The stages of built-in registry rows by name, each with its `KEY=VALUE` options, for a
    /// metric with `sizes`, and the default improvers (replace [`Stages::improvers`] to change
    /// them, e.g. with [`crate::improve::improver`]).
    pub fn from_registry(
        strategy: Choice<'_>,
        parameterizer: Choice<'_>,
        remesher: Choice<'_>,
        sizes: MetricSizes,
    ) -> Result<Stages, RegistryError> {
        Stages::from_registries(
            &Registries::default(),
            strategy,
            parameterizer,
            remesher,
            sizes,
        )
    }

    /// [`Stages::from_registry`] from `registries` (which may hold rows of one's own).
    pub fn from_registries(
        registries: &Registries,
        strategy: Choice<'_>,
        parameterizer: Choice<'_>,
        remesher: Choice<'_>,
        sizes: MetricSizes,
    ) -> Result<Stages, RegistryError> {
        Ok(Stages {
            patches: registries.strategies.build(strategy.0, strategy.1, sizes)?,
            parameterizer: registries.parameterizers.build(
                parameterizer.0,
                parameterizer.1,
                sizes,
            )?,
            remesher: registries.remeshers.build(remesher.0, remesher.1, sizes)?,
            improvers: default_improvers(),
        })
    }

    /// The three stages of a patch, borrowed.
    pub fn loop_stages(&self) -> crate::improve::LoopStages<'_> {
        crate::improve::LoopStages {
            patches: self.patches.as_ref(),
            parameterizer: self.parameterizer.as_ref(),
            remesher: self.remesher.as_ref(),
        }
    }

    /// The improvers' names, in order.
    pub fn improver_names(&self) -> Vec<String> {
        self.improvers
            .iter()
            .map(|i| i.name().to_string())
            .collect()
    }

    /// The names in the report: strategy, parameterizer, remesher.
    pub fn names(&self) -> [String; 3] {
        self.loop_stages().names()
    }
}

/// A path in a report: a path the OS accepts need not be UTF-8, and is written lossily.
fn lossy_path<S: serde::Serializer>(path: &Option<PathBuf>, s: S) -> Result<S::Ok, S::Error> {
    serde::Serialize::serialize(&path.as_ref().map(|p| p.to_string_lossy()), s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_stages_are_the_first_rows_and_every_improver() {
        let built: Vec<_> = default_improvers().iter().map(|i| i.name()).collect();
        assert_eq!(built, default_improver_names());
        assert_eq!(Stages::default().improver_names(), default_improver_names());
        for sizes in MetricSizes::ALL {
            let s = Stages::for_sizes(sizes);
            let firsts = [
                crate::patches::STRATEGIES[0].name,
                crate::param::PARAMETERIZERS[0].name,
                crate::remesh2d::REMESHERS[0].name,
            ];
            assert_eq!(s.names(), firsts.map(String::from));
        }
    }

    /// A stop asked from the progress callback ends the run after that patch, typed, and a
    /// clone of the options shares the flag with the caller's copy.
    #[test]
    fn a_cancelled_run_stops_after_the_patch_that_saw_it() {
        let options = RemeshOptions::default();
        let stop = options.cancel.clone();
        let mesh = crate::mesh::generators::plate(1.0, 6);
        let mut seen = 0;
        let result = super::super::Remesher::new(options).run_with(&mesh, None, |_| {
            seen += 1;
            stop.cancel();
        });
        assert!(
            matches!(
                result,
                Err(super::super::PipelineError::Cancelled { patches: 1 })
            ),
            "expected Cancelled after 1 patch, got {:?}",
            result.err()
        );
        assert_eq!(seen, 1);
    }
}
