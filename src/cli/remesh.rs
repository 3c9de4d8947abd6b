//! `conemesh remesh`: Algorithm 1 end to end, with the report and the Table-1 row.
//!
//! The Python package (`python/src/lib.rs`) compiles this file too and calls [`options`],
//! [`stages`], [`target`], [`progress_bar`] and [`peak_rss_mib`], so its keywords parse
//! with these clap definitions and cannot drift from the CLI's defaults.

use anyhow::Context;
use conemesh::features::FeatureRule;
use conemesh::param::Parameterizer;
use conemesh::patches::PatchStrategy;
use conemesh::pipeline::{CoarseInput, Progress, RemeshOptions, Remesher, Stages};
use conemesh::quality::{EvalOptions, EvalReport, TargetLength};
use conemesh::registry::{default_name, MetricSizes, Params};
use conemesh::remesh2d::PlanarRemesher;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

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
    #[arg(long, default_value_t = conemesh::fidelity::FidelityOptions::default().max_deviation)]
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
    #[arg(long, default_value_t = conemesh::boundary::BoundaryOptions::default().corner_angle)]
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

/// Run `conemesh remesh`.
pub fn run(args: RemeshArgs) -> anyhow::Result<ExitCode> {
    let t_start = Instant::now();
    check_output_paths(&args, true)?;
    if let Some(n) = args.threads {
        set_threads(n)?;
    }
    // With `--repair` a face that uses a vertex twice is left out (and listed) instead of
    // refusing the file.
    let read = conemesh::io::ReadOptions {
        drop_repeated_indices: args.repair,
    };
    let (name, mesh, repeated, polygons) = match &args.mesh {
        Some(p) => {
            let loaded = conemesh::io::read_mesh_with(p, &read)
                .with_context(|| format!("reading {}", p.display()))?;
            for w in &loaded.warnings {
                if !args.quiet {
                    eprintln!("warning: {w}");
                }
            }
            (
                p.display().to_string(),
                loaded.mesh,
                loaded.repeated_index_faces,
                loaded.polygons_triangulated,
            )
        }
        None => (
            "built-in torus".to_string(),
            conemesh::mesh::generators::default_surface(),
            Vec::new(),
            0,
        ),
    };
    let short_name = args
        .mesh
        .as_ref()
        .and_then(|p| p.file_stem())
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "torus".into());
    // A user metric has one tensor per vertex of the file, in file order.
    let metric = match &args.metric {
        Some(p) => Some(
            conemesh::io::sol::read_sol(p, mesh.n_vertices())
                .with_context(|| format!("reading metric {}", p.display()))?,
        ),
        None => None,
    };
    let RunInput {
        mesh,
        metric,
        repair,
    } = repaired_input(&args, mesh, metric, &name, repeated)?;
    let remesher = Remesher::new(options(&args)).with_stages(stages(&args, metric.is_some())?);
    let bar = progress_bar(args.quiet, mesh.n_faces() as u64);
    let result = remesher.run_with(&mesh, metric.as_deref(), |p: Progress| {
        bar.set_length(p.total as u64);
        bar.set_position((p.total - p.unprocessed) as u64);
        bar.set_message(format!("{} patches", p.patches));
    });
    bar.finish_and_clear();
    let out = result.with_context(|| match &args.metric {
        Some(m) => format!("remeshing {name} with metric {}", m.display()),
        None => format!("remeshing {name}"),
    })?;
    let elapsed = t_start.elapsed().as_secs_f64();
    let eval = evaluate_output(&args, &out)?;
    let r = &out.unit.report;
    println!(
        "{name}: {} faces → {} faces in {} patches, {elapsed:.2} s",
        r.faces_in, r.faces_out, r.patches
    );
    println!("{}", EvalReport::table_header());
    println!("{}", eval.table_row(&short_name));
    let c = &r.certificate;
    println!(
        "certified after each of {} patches: disk, bijective, planar, manifold, oriented, same topology, boundary kept, no degenerate/flipped faces; final self-intersections: {}",
        r.patches,
        match (c.no_self_intersections, c.input_self_intersecting_pairs) {
            (1, _) => "none (exact)".to_string(),
            (_, Some(n)) => format!(
                "{} pairs, but the input itself self-intersects ({n} pairs)",
                c.self_intersecting_pairs
            ),
            _ => "not checked".to_string(),
        }
    );
    if let Some(i) = &r.improvement {
        let (b, a) = (&i.before, &i.after);
        println!(
            "improvers {}: θ_min {:.2}° → {:.2}°, q_min {:.3} → {:.3}, faces below 20° {} → {}, below 25° {} → {}, {:.2} s",
            r.improvers.join(","),
            b.theta_min,
            a.theta_min,
            b.q_min,
            a.q_min,
            b.below_20,
            a.below_20,
            b.below_25,
            a.below_25,
            i.seconds
        );
    }
    let s = &r.small_angles;
    if !s.faces.is_empty() {
        let kept: Vec<String> = (s.faces.iter().filter(|f| f.all_corners))
            .map(|f| f.face.to_string())
            .collect();
        println!(
            "faces below {}° in the metric: {} (at a kept corner {}, a feature line {}, the boundary {}, inside {}){}",
            s.threshold_deg,
            s.faces.len(),
            s.corner,
            s.feature,
            s.boundary,
            s.interior,
            match kept.is_empty() {
                true => String::new(),
                false => format!("; between three kept corners: {}", kept.join(", ")),
            }
        );
    }
    if r.coarse_input {
        println!(
            "coarse-input profile ran ({} sweeps, fidelity floor {} of the mean input edge, {} rounds, persistent factors)",
            r.options.sweeps, r.options.fidelity.min_edge_ratio, r.options.fidelity.rounds
        );
    }
    for w in &out.warnings {
        eprintln!("warning: {w}");
    }
    // Everything is computed; write the outputs as one transaction (issue 20): each is staged
    // beside its destination and all are renamed into place only when all were written, so a
    // failure leaves every destination as it was and no temporary behind.
    let mut outputs = conemesh::io::Outputs::new();
    outputs
        .mesh(
            &args.output,
            &out.mesh,
            &Default::default(),
            &Default::default(),
        )
        .with_context(|| format!("writing {}", args.output.display()))?;
    let json = serde_json::json!({
        "input": name,
        "polygons_triangulated": polygons,
        // A path the OS accepts need not be UTF-8: the report holds it lossily.
        "output": args.output.to_string_lossy(),
        "seconds": elapsed,
        "peak_rss_mib": peak_rss_mib(),
        "repair": repair,
        "run": r,
        "eval": eval,
    });
    stage_side_outputs(&mut outputs, &args, &out, &eval, &json, &short_name)?;
    super::commit(outputs)?;
    println!("wrote {}", args.output.display());
    Ok(ExitCode::SUCCESS)
}

/// The input a run remeshes: the mesh read (repaired with `--repair`), the user's tensors
/// (carried to the repaired vertices), and the repair's log.
pub struct RunInput {
    /// the mesh
    pub mesh: conemesh::TriMesh,
    /// one tensor per vertex of `mesh`
    pub metric: Option<Vec<nalgebra::Matrix3<f64>>>,
    /// what `--repair` changed; `None` without it
    pub repair: Option<conemesh::repair::RepairLog>,
}

/// With `--repair`, the repaired input and the log of changes (one line on stderr), which
/// lists `repeated`, the file faces the reader left out for using a vertex twice; without,
/// the input as read.
pub fn repaired_input(
    args: &RemeshArgs,
    mesh: conemesh::TriMesh,
    metric: Option<Vec<nalgebra::Matrix3<f64>>>,
    name: &str,
    repeated: Vec<conemesh::io::RepeatedIndexFace>,
) -> anyhow::Result<RunInput> {
    if !args.repair {
        return Ok(RunInput {
            mesh,
            metric,
            repair: None,
        });
    }
    let mut r = conemesh::repair::repair(&mesh, &Default::default())
        .with_context(|| format!("repairing {name}"))?;
    r.log.repeated_index_faces = repeated;
    eprintln!("repair: {}", r.log.summary());
    Ok(RunInput {
        metric: metric.map(|m| r.vertex_values(&m)),
        mesh: r.mesh,
        repair: Some(r.log),
    })
}

/// The outputs beside the mesh (`--write-metric`, `--report` with `report` as its document,
/// `--plots`), staged into `outputs` for the one commit.
pub fn stage_side_outputs(
    outputs: &mut conemesh::io::Outputs,
    args: &RemeshArgs,
    out: &conemesh::pipeline::Remeshed,
    eval: &EvalReport,
    report: &serde_json::Value,
    short_name: &str,
) -> anyhow::Result<()> {
    if let Some(p) = &args.write_metric {
        let bytes = conemesh::io::sol::sol_bytes(p, &out.output_metric(), false)?;
        outputs
            .bytes(p, &bytes)
            .with_context(|| format!("writing {}", p.display()))?;
    }
    if let Some(p) = &args.write_input_metric {
        let bytes = conemesh::io::sol::sol_bytes(p, &out.input_metric_unit_target(), false)?;
        outputs
            .bytes(p, &bytes)
            .with_context(|| format!("writing {}", p.display()))?;
    }
    if let Some(p) = &args.write_patches {
        let bytes = conemesh::io::patches::face_patches_bytes(&out.unit.face_patch);
        outputs
            .bytes(p, &bytes)
            .with_context(|| format!("writing {}", p.display()))?;
    }
    if let Some(p) = &args.report {
        outputs
            .bytes(p, serde_json::to_string_pretty(report)?.as_bytes())
            .with_context(|| format!("writing {}", p.display()))?;
    }
    if let Some(dir) = &args.plots {
        let staged = outputs
            .dir(dir)
            .with_context(|| format!("writing plots into {}", dir.display()))?;
        conemesh::report::write_quality_plots(
            &staged,
            short_name,
            &[
                ("input", &eval.input_quality),
                ("output", &eval.output_quality),
            ],
        )
        .with_context(|| format!("writing plots into {}", dir.display()))?;
        let colors = conemesh::render::quality_face_colors(
            &out.mesh,
            &out.output_metric(),
            conemesh::render::ColorBy::Q,
        );
        let picture = dir.join("mesh.png");
        let (img, _) = conemesh::render::render(&out.mesh, &colors, &Default::default())
            .with_context(|| format!("drawing {}", picture.display()))?;
        let bytes = img
            .png()
            .with_context(|| format!("drawing {}", picture.display()))?;
        std::fs::write(staged.join("mesh.png"), bytes)
            .with_context(|| format!("writing {}", picture.display()))?;
        if let Some(i) = &out.unit.report.improvement {
            conemesh::report::write_improvement_plot(
                &staged,
                short_name,
                &i.before.hist_min_angles,
                &i.after.hist_min_angles,
                (i.before.theta_min, i.after.theta_min),
            )
            .with_context(|| format!("writing plots into {}", dir.display()))?;
        }
    }
    Ok(())
}

/// Every output path, checked before any work (issue 20): each file's folder exists, no file
/// output is a directory, `--plots` is not a regular file and its folder exists, and no two
/// outputs (nor an output and the input or the metric) are the same path. `mesh_output`:
/// whether `-o` is one of them (the Python package returns arrays instead).
pub fn check_output_paths(args: &RemeshArgs, mesh_output: bool) -> anyhow::Result<()> {
    let files: Vec<(&str, &PathBuf)> = [
        mesh_output.then_some(("-o", &args.output)),
        args.report.as_ref().map(|p| ("--report", p)),
        args.write_metric.as_ref().map(|p| ("--write-metric", p)),
        args.write_patches.as_ref().map(|p| ("--write-patches", p)),
        args.write_input_metric
            .as_ref()
            .map(|p| ("--write-input-metric", p)),
    ]
    .into_iter()
    .flatten()
    .collect();
    for (flag, p) in &files {
        super::check_file_output(flag, p)?;
    }
    if let Some(d) = &args.plots {
        super::check_plots_folder("--plots", d)?;
        if let Some((flag, _)) = files.iter().find(|(_, p)| super::same_path(p, d)) {
            anyhow::bail!("--plots {} is the same path as {flag}", d.display());
        }
    }
    let inputs: Vec<(&str, &PathBuf)> = [
        args.mesh.as_ref().map(|p| ("the input", p)),
        args.metric.as_ref().map(|p| ("--metric", p)),
    ]
    .into_iter()
    .flatten()
    .collect();
    for (i, (flag, p)) in files.iter().enumerate() {
        for (other, q) in files[..i].iter().chain(&inputs) {
            if super::same_path(p, q) {
                anyhow::bail!("{flag} {} is the same path as {other}", p.display());
            }
        }
    }
    Ok(())
}

/// `--ltar` or `--ltar-factor`. A metric length is the same in file units and in unit space
/// (`Normalization`).
pub fn target(args: &RemeshArgs) -> TargetLength {
    match args.ltar {
        Some(l) => TargetLength::Absolute(l),
        None => TargetLength::Factor(args.ltar_factor),
    }
}

/// The options of Algorithm 1 from the arguments.
pub fn options(args: &RemeshArgs) -> RemeshOptions {
    RemeshOptions {
        seed: args.seed,
        target: target(args),
        check_self_intersections: !args.no_self_intersections,
        fidelity: conemesh::fidelity::FidelityOptions {
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
        sizes: conemesh::metric::SizeOptions {
            hmin: args.hmin,
            hmax: args.hmax,
            hgrad: args.hgrad,
        },
        boundary: conemesh::boundary::BoundaryOptions {
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
pub fn stages(args: &RemeshArgs, user_metric: bool) -> anyhow::Result<Stages> {
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
fn improvers(args: &RemeshArgs) -> anyhow::Result<Vec<Box<dyn conemesh::improve::Improver>>> {
    let names: Vec<String> = match args.improvers.as_deref().map(str::trim) {
        Some("none") | Some("") => Vec::new(),
        Some(list) => list.split(',').map(|n| n.trim().to_string()).collect(),
        None => conemesh::pipeline::default_improver_names()
            .into_iter()
            .map(String::from)
            .collect(),
    };
    let mut params: Vec<Vec<String>> = vec![Vec::new(); names.len()];
    for item in &args.improver_opt {
        let (name, kv) = item
            .split_once('.')
            .filter(|(n, kv)| !n.is_empty() && kv.contains('='))
            .ok_or_else(|| {
                anyhow::anyhow!("--improver-opt `{item}` is not of the form NAME.KEY=VALUE")
            })?;
        let Some(i) = names.iter().position(|n| n == name) else {
            anyhow::bail!(
                "--improver-opt {item} is an option of improver `{name}`, which does not run (improvers: {})",
                match names.is_empty() {
                    true => "none".to_string(),
                    false => names.join(","),
                }
            );
        };
        params[i].push(kv.to_string());
    }
    names
        .iter()
        .zip(params)
        .map(|(name, p)| Ok(conemesh::improve::improver(name, Params::parse(&p)?)?))
        .collect()
}

pub fn progress_bar(quiet: bool, total: u64) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::new(total);
    // A constant template; should it ever be refused, keep indicatif's default style.
    if let Ok(style) = ProgressStyle::with_template(
        "{elapsed_precise} [{bar:40}] {pos}/{len} faces processed, {msg}",
    ) {
        b.set_style(style.progress_chars("=> "));
    }
    b
}

/// This process's peak resident memory in MiB (`VmHWM` of `/proc/self/status`, in kB; `None`
/// where there is no such file, i.e. off Linux).
pub fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// `--threads N`: the size of rayon's global pool (before any parallel work of the process).
pub fn set_threads(n: usize) -> anyhow::Result<()> {
    anyhow::ensure!(n >= 1, "--threads must be at least 1 (got {n})");
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build_global()
        .map_err(|e| anyhow::anyhow!("cannot start {n} worker threads: {e}"))
}

/// The yardstick, independent of the remesher: `conemesh eval` on a run's output against its
/// input, at the run's target (shared with the Python package).
pub fn evaluate_output(
    args: &RemeshArgs,
    out: &conemesh::pipeline::Remeshed,
) -> Result<conemesh::quality::EvalReport, conemesh::quality::EvalError> {
    let eval_opts = EvalOptions {
        target: target(args),
        self_intersections: false, // certified exactly by the pipeline already
        ..EvalOptions::default()
    };
    conemesh::quality::evaluate(
        &out.input,
        &out.mesh,
        out.input_metric.as_deref(),
        &eval_opts,
    )
}
