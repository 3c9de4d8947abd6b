//! The arguments of a remesh job, spelled as `conemesh remesh`'s flags: the command line
//! parses them with this one clap definition, and the Python package turns its keywords into
//! the same flags, so a keyword's default is the flag's default by construction. The
//! builders below turn them into the job's options, stages, files and repair.

use super::files::OutputFiles;
use super::Job;
use crate::features::FeatureRule;
use crate::io::paths::OutputPathError;
use crate::param::Parameterizer;
use crate::patches::PatchStrategy;
use crate::pipeline::{CoarseInput, RemeshOptions, Remesher, Stages};
use crate::quality::TargetLength;
use crate::registry::{default_name, MetricSizes, Params, RegistryError};
use crate::remesh2d::PlanarRemesher;
use crate::repair::RepairOptions;
use std::path::{Path, PathBuf};

/// `--coarse`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coarse {
    /// When the distance tolerance sets the output's size.
    Auto,
    /// Always.
    On,
    /// Never.
    Off,
}

/// Arguments of `conemesh remesh`.
// The field docs are the flags' help text, where `[2]` is a default, not a link.
#[allow(rustdoc::broken_intra_doc_links)]
#[derive(clap::Args, Debug)]
pub struct RemeshArgs {
    /// Input mesh (OBJ, OFF, PLY, STL, Medit .mesh). Without it, a built-in torus.
    pub mesh: Option<PathBuf>,
    /// Output mesh; the format follows the extension.
    #[arg(short, long, default_value = "remeshed.obj")]
    pub output: PathBuf,
    /// Target metric edge length as a multiple of the input's mean metric edge length.
    #[arg(long, default_value_t = 1.5, conflicts_with = "ltar")]
    pub ltar_factor: f64,
    /// Absolute target metric edge length (in the mesh's own units).
    #[arg(long)]
    pub ltar: Option<f64>,
    /// A user metric (Medit .sol, one symmetric tensor per input vertex, file units) instead
    /// of the curvature metric.
    #[arg(long)]
    pub metric: Option<PathBuf>,
    /// Seed of the run's one RNG.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Patch strategy (Sec. 3.2), by registry name (`conemesh stages` lists them; the
    /// default is the table's first row).
    #[arg(long, default_value_t = default_name::<dyn PatchStrategy>().to_string())]
    pub strategy: String,
    /// An option of the patch strategy, `KEY=VALUE` (repeatable).
    #[arg(long, value_name = "KEY=VALUE")]
    pub strategy_opt: Vec<String>,
    /// Parameterizer (Sec. 3.3), by registry name.
    #[arg(long, default_value_t = default_name::<dyn Parameterizer>().to_string())]
    pub param: String,
    /// An option of the parameterizer, `KEY=VALUE` (repeatable).
    #[arg(long, value_name = "KEY=VALUE")]
    pub param_opt: Vec<String>,
    /// Planar remesher (Sec. 3.3), by registry name.
    #[arg(long, default_value_t = default_name::<dyn PlanarRemesher>().to_string())]
    pub remesher: String,
    /// An option of the planar remesher, `KEY=VALUE` (repeatable).
    #[arg(long, value_name = "KEY=VALUE")]
    pub remesher_opt: Vec<String>,
    /// Rings of already-remeshed faces each patch expands into (Sec. 4.2); the same as
    /// `--strategy-opt expand_rings=R`.
    #[arg(long)]
    pub expand_rings: Option<usize>,
    /// Largest patch grown, in faces; the same as `--strategy-opt max_faces=N`.
    #[arg(long)]
    pub max_patch_faces: Option<usize>,
    /// Stop after this many patches; the faces not reached are kept as they were (reported).
    #[arg(long)]
    pub max_patches: Option<usize>,
    /// Write the full report (options, certificates, per-stage times, quality) as JSON.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Write quality histograms (PNG) into this directory (with improvers, also the smallest
    /// angles before and after them), and `mesh.png`, the picture of the output
    /// coloured by q in the run's metric, faces with a smallest angle below 20° in magenta
    /// (as `conemesh render --color q` with `--write-metric`'s tensors).
    #[arg(long)]
    pub plots: Option<PathBuf>,
    /// Write the patch that made each output face (one line per face: the patch id in order
    /// of creation, or `-` for an input face no patch replaced), for `render --color patch
    /// --patches FILE`.
    #[arg(long, value_name = "FILE")]
    pub write_patches: Option<PathBuf>,
    /// Write the metric at the output vertices (Medit .sol, file units): the metric the mesh
    /// was built to, a user's tensors restricted to the surface's tangent plane.
    #[arg(long)]
    pub write_metric: Option<PathBuf>,
    /// Write the metric the run remeshes to at the input vertices (Medit .sol, file units,
    /// one tensor per vertex of the input file, of the repaired input with `--repair`): the
    /// curvature or user metric with the size controls and the a-priori fidelity scaling,
    /// over L_tar² (MMG's `-ltar 1`: an edge on target has length 1) and SPD in 3D, so MMG
    /// can be run on the input with it.
    #[arg(long, value_name = "FILE.sol")]
    pub write_input_metric: Option<PathBuf>,
    /// Directory for offending patches when a certificate fails (default: the output's).
    #[arg(long)]
    pub debug_dir: Option<PathBuf>,
    /// Skip the final exact self-intersection test.
    #[arg(long)]
    pub no_self_intersections: bool,
    /// Fidelity tolerance, relative to the input's bounding-box diagonal: the metric is
    /// scaled up where a target-size triangle would cut more than this off the surface
    /// (tips, rims, creases). 0 turns the control off (the paper's metric alone).
    #[arg(long, default_value_t = crate::fidelity::FidelityOptions::default().max_deviation)]
    pub hausd: f64,
    /// Sweeps of Algorithm 1 over the surface: each further sweep remeshes the previous
    /// sweep's output with new patches, so the old patch seams get remeshed too.
    #[arg(long, default_value_t = RemeshOptions::default().sweeps)]
    pub sweeps: usize,
    /// Patches remeshed at the same time: Algorithm 1 takes up to this many patches, a vertex
    /// apart, on the same working mesh, remeshes them in parallel and stitches them in order.
    /// The output depends on this number and the seed, not on the thread count; 1 = one patch
    /// at a time.
    #[arg(long, default_value_t = RemeshOptions::default().batch)]
    pub batch: usize,
    /// The most output faces one region is expected to make (each input face counting at
    /// least 1/4): a larger job is split into regions (recursive coordinate bisection) that
    /// are remeshed at the same time with their cuts frozen, then the bands around the cuts
    /// are remeshed. The output depends on this number and the seed, not on the thread count;
    /// 0 = one region (the paper's loop on the whole mesh).
    #[arg(long, default_value_t = RemeshOptions::default().region_faces)]
    pub region_faces: usize,
    /// Worker threads (default: RAYON_NUM_THREADS when set, else one per core). The output is
    /// the same for every thread count.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Keep input vertices whose angle defect |2π − angle sum| is at least this many radians
    /// (tips, cone points, corners) as output vertices. 0 keeps none (the paper).
    #[arg(long, default_value_t = 1.0)]
    pub corner_defect: f64,
    /// Feature lines, kept as output edges (resampled to the metric, vertices exactly on the
    /// input's creases): `auto` (long, smooth crease lines of edges sharper than 40° that stand
    /// out from their faces' other edges), an angle in degrees (every edge sharper than that),
    /// or `off` (or 0: none, the paper).
    #[arg(long, default_value = "auto", value_parser = FeatureRule::parse)]
    pub feature_angle: FeatureRule,
    /// Fit the curvature metric on each side of the feature lines instead of across them
    /// (paper-notes "Feature lines"); score with `eval --crease-metric` and the same
    /// `--feature-angle`.
    #[arg(long)]
    pub crease_metric: bool,
    /// The coarse-input profile (3 sweeps, finer fidelity control; paper-notes "Coarse
    /// inputs"): `auto` runs it when the distance tolerance rather than the metric sets the
    /// output's size (the a-priori fidelity scaling at least doubles the expected face count;
    /// the report says whether it ran), `on` always, `off` never.
    #[arg(long, value_enum, default_value_t = Coarse::Auto)]
    pub coarse: Coarse,
    /// Smallest edge size, in the mesh's units: the metric's sizes are clamped below (MMG's
    /// `-hmin`). Default: none.
    #[arg(long)]
    pub hmin: Option<f64>,
    /// Largest edge size, in the mesh's units (MMG's `-hmax`). Default: none.
    #[arg(long)]
    pub hmax: Option<f64>,
    /// Metric gradation β > 1: sizes grow by at most a factor (1 + ℓ·ln β) over an edge of
    /// metric length ℓ, keeping each tensor's directions (MMG's `-hgrad`, whose default is
    /// 1.3). Default: off.
    #[arg(long)]
    pub hgrad: Option<f64>,
    /// Keep the input's boundary vertices and edges as they are instead of resampling the
    /// boundary curves to the metric.
    #[arg(long)]
    pub keep_boundary: bool,
    /// Boundary vertices where the boundary turns by at least this many degrees are corners
    /// and stay.
    #[arg(long, default_value_t = crate::boundary::BoundaryOptions::default().corner_angle)]
    pub boundary_corner_angle: f64,
    /// The improvers after the loop (Sec. 3.4), in order, by registry name, comma-separated
    /// (`conemesh stages` lists them); `none` for none. Default: every improver, in the order
    /// of the table (`surface,eq5`: the connectivity and vertex position updates on the
    /// surface, then Algorithm 2).
    #[arg(long, value_name = "LIST")]
    pub improvers: Option<String>,
    /// An option of one improver, `NAME.KEY=VALUE` (e.g. `eq5.q=0.7`); repeatable.
    #[arg(long, value_name = "NAME.KEY=VALUE")]
    pub improver_opt: Vec<String>,
    /// Repair the input before remeshing: leave out file faces that use a vertex twice, weld
    /// vertices at bit-identical positions, drop collapsed, zero-area and repeated faces,
    /// orient each component consistently, cut edges with three or more faces and split
    /// vertices with several fans. Coordinates are not moved; the report (`repair`) lists
    /// every change by element.
    #[arg(long)]
    pub repair: bool,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

/// An argument list that does not make a job: a stage or an option the registries refuse,
/// or an improver option that does not fit the improvers that run.
#[derive(Debug, thiserror::Error, Clone, PartialEq, Eq)]
pub enum ArgsError {
    /// A stage name or option the registries refuse.
    #[error(transparent)]
    Registry(#[from] RegistryError),
    /// `--improver-opt ITEM` without a `NAME.` prefix or a `KEY=VALUE`.
    #[error("--improver-opt `{item}` is not of the form NAME.KEY=VALUE")]
    ImproverOptForm {
        /// the item as given
        item: String,
    },
    /// An option of an improver that is not in the run's list.
    #[error(
        "--improver-opt {item} is an option of improver `{name}`, which does not run (improvers: {})",
        match running.is_empty() {
            true => "none".to_string(),
            false => running.join(","),
        }
    )]
    ImproverNotRun {
        /// the `--improver-opt` item as given
        item: String,
        /// the improver it belongs to
        name: String,
        /// the improvers of the run, in order
        running: Vec<String>,
    },
}

impl RemeshArgs {
    /// The job the arguments ask for: Algorithm 1 with [`options`] and [`stages`] (`user_metric`:
    /// whether a user metric is given), repairing the input with `--repair`.
    pub fn job(&self, user_metric: bool) -> Result<Job, ArgsError> {
        Ok(Job {
            remesher: Remesher::new(options(self)).with_stages(stages(self, user_metric)?),
            repair: self.repair_options(),
        })
    }

    /// `--repair`: the default repair; `None` without it.
    pub fn repair_options(&self) -> Option<RepairOptions> {
        self.repair.then(RepairOptions::default)
    }

    /// How the input file is read: with `--repair` a face that uses a vertex twice is left
    /// out (and listed in the repair log) instead of refusing the file.
    pub fn read_options(&self) -> crate::io::ReadOptions {
        crate::io::ReadOptions {
            drop_repeated_indices: self.repair,
        }
    }

    /// The files the run writes; `mesh_output`: whether `-o` is one of them (the Python
    /// package returns arrays instead).
    pub fn files(&self, mesh_output: bool) -> OutputFiles {
        OutputFiles {
            mesh: mesh_output.then(|| self.output.clone()),
            report: self.report.clone(),
            metric: self.write_metric.clone(),
            patches: self.write_patches.clone(),
            input_metric: self.write_input_metric.clone(),
            plots: self.plots.clone(),
        }
    }

    /// Every output path, checked before any work ([`OutputFiles::check`]) against each other
    /// and against the input and `--metric`.
    pub fn check_output_paths(&self, mesh_output: bool) -> Result<(), OutputPathError> {
        let inputs: Vec<(&'static str, &Path)> = [
            self.mesh.as_deref().map(|p| ("the input", p)),
            self.metric.as_deref().map(|p| ("--metric", p)),
        ]
        .into_iter()
        .flatten()
        .collect();
        self.files(mesh_output).check(&inputs)
    }
}

/// `--ltar` or `--ltar-factor`. A metric length is the same in file units and in unit space
/// (`Normalization`).
pub fn target(args: &RemeshArgs) -> TargetLength {
    match args.ltar {
        Some(l) => TargetLength::Absolute(l),
        None => TargetLength::Factor(args.ltar_factor),
    }
}

/// The options of Algorithm 1 from the arguments. Without `--debug-dir`, offending patches
/// go beside the output.
pub fn options(args: &RemeshArgs) -> RemeshOptions {
    RemeshOptions {
        seed: args.seed,
        target: target(args),
        check_self_intersections: !args.no_self_intersections,
        fidelity: crate::fidelity::FidelityOptions {
            max_deviation: args.hausd,
            ..Default::default()
        },
        debug_dir: Some(args.debug_dir.clone().unwrap_or_else(|| {
            args.output
                .parent()
                .filter(|p| !p.as_os_str().is_empty())
                .map(PathBuf::from)
                .unwrap_or_else(|| PathBuf::from("."))
        })),
        max_patches: args.max_patches,
        sweeps: args.sweeps,
        batch: args.batch,
        region_faces: args.region_faces,
        corner_defect: (args.corner_defect != 0.0).then_some(args.corner_defect),
        features: args.feature_angle,
        crease_metric: args.crease_metric,
        sizes: crate::metric::SizeOptions {
            hmin: args.hmin,
            hmax: args.hmax,
            hgrad: args.hgrad,
        },
        boundary: crate::boundary::BoundaryOptions {
            resample: !args.keep_boundary,
            corner_angle: args.boundary_corner_angle,
        },
        coarse_input: match args.coarse {
            Coarse::Auto => CoarseInput::Auto,
            Coarse::On => CoarseInput::On,
            Coarse::Off => CoarseInput::Off,
        },
        ..RemeshOptions::default()
    }
}

/// The extension points by registry name, with their options, for a metric of the kind of
/// sizes a user metric has or not (the rows' defaults for it, as in the library).
pub fn stages(args: &RemeshArgs, user_metric: bool) -> Result<Stages, ArgsError> {
    let mut strategy = Params::parse(&args.strategy_opt)?;
    if let Some(r) = args.expand_rings {
        strategy.set("expand_rings", r);
    }
    if let Some(m) = args.max_patch_faces {
        strategy.set("max_faces", m);
    }
    let mut stages = Stages::from_registry(
        (&args.strategy, strategy),
        (&args.param, Params::parse(&args.param_opt)?),
        (&args.remesher, Params::parse(&args.remesher_opt)?),
        MetricSizes::of_user_metric(user_metric),
    )?;
    stages.improvers = improvers(args)?;
    Ok(stages)
}

/// The improvers of `--improvers` (or the default list), each with its options of
/// `--improver-opt NAME.KEY=VALUE`.
fn improvers(args: &RemeshArgs) -> Result<Vec<Box<dyn crate::improve::Improver>>, ArgsError> {
    let names: Vec<String> = match args.improvers.as_deref().map(str::trim) {
        Some("none") | Some("") => Vec::new(),
        Some(list) => list.split(',').map(|n| n.trim().to_string()).collect(),
        None => crate::pipeline::default_improver_names()
            .into_iter()
            .map(String::from)
            .collect(),
    };
    let mut params: Vec<Vec<String>> = vec![Vec::new(); names.len()];
    for item in &args.improver_opt {
        let (name, kv) = item
            .split_once('.')
            .filter(|(n, kv)| !n.is_empty() && kv.contains('='))
            .ok_or_else(|| ArgsError::ImproverOptForm { item: item.clone() })?;
        let Some(i) = names.iter().position(|n| n == name) else {
            return Err(ArgsError::ImproverNotRun {
                item: item.clone(),
                name: name.to_string(),
                running: names,
            });
        };
        params[i].push(kv.to_string());
    }
    names
        .iter()
        .zip(params)
        .map(|(name, p)| Ok(crate::improve::improver(name, Params::parse(&p)?)?))
        .collect()
}
