//! `conemesh remesh`: Algorithm 1 end to end, with the report and the Table-1 row.

use anyhow::{bail, Context};
use conemesh::metric::{MetricField, MetricOptions, Normalization};
use conemesh::pipeline::{self, CoarseInput, Progress, RemeshOptions, Stages};
use conemesh::quality::{EvalOptions, EvalReport, TargetLength};
use conemesh::TriMesh;
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
    /// Patch strategy: `cone` (the paper) or `kring`.
    #[arg(long, default_value = "cone")]
    pub strategy: String,
    /// Cone patches: rings of already-remeshed faces each patch expands into (Sec. 4.2).
    #[arg(long)]
    pub expand_rings: Option<usize>,
    /// Cone patches: largest patch, in faces (no limit by default, as in the paper).
    #[arg(long)]
    pub max_patch_faces: Option<usize>,
    /// Write the full report (options, certificates, per-stage times, quality) as JSON.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Write quality histograms (PNG) into this directory.
    #[arg(long)]
    pub plots: Option<PathBuf>,
    /// Write the metric at the output vertices (Medit .sol, file units).
    #[arg(long)]
    pub write_metric: Option<PathBuf>,
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
    /// Keep input vertices whose angle defect |2π − angle sum| is at least this many radians
    /// (tips, cone points, corners) as output vertices. 0 keeps none (the paper).
    #[arg(long, default_value_t = 1.0)]
    pub corner_defect: f64,
    /// Keep input edges whose two faces' normals differ by more than this many degrees as
    /// feature lines: split to the target length and kept as output edges. 0 keeps none
    /// (the paper).
    #[arg(long, default_value_t = 0.0)]
    pub feature_angle: f64,
    /// The coarse-input profile (3 sweeps, finer fidelity control; paper-notes "Coarse
    /// inputs"): `auto` runs it when the distance tolerance rather than the metric sets the
    /// output's size (the a-priori fidelity scaling at least doubles the expected face count;
    /// the report says whether it ran), `on` always, `off` never.
    #[arg(long, value_enum, default_value_t = Coarse::Auto)]
    pub coarse: Coarse,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Run `conemesh remesh`.
pub fn run(args: RemeshArgs) -> anyhow::Result<ExitCode> {
    let t_start = Instant::now();
    let (name, file_mesh) = match &args.mesh {
        Some(p) => {
            let loaded =
                conemesh::io::read_mesh(p).with_context(|| format!("reading {}", p.display()))?;
            (p.display().to_string(), loaded.mesh)
        }
        None => (
            "built-in torus".to_string(),
            conemesh::mesh::generators::default_surface(),
        ),
    };
    let short_name = args
        .mesh
        .as_ref()
        .and_then(|p| p.file_stem())
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "torus".into());
    // A user metric has one tensor per vertex of the file, in file order.
    let file_metric = match &args.metric {
        Some(p) => Some(
            conemesh::io::sol::read_sol(p, file_mesh.n_vertices())
                .with_context(|| format!("reading metric {}", p.display()))?,
        ),
        None => None,
    };
    // Unreferenced vertices carry no surface; drop them. The compaction keeps the order of the
    // other vertices, and the user metric follows them through the map.
    let (file_mesh, map) = file_mesh.without_unreferenced_vertices();
    let user_metric = file_metric.map(|m| {
        let mut kept = vec![nalgebra::Matrix3::zeros(); file_mesh.n_vertices()];
        for (old, new) in map.iter().enumerate() {
            if let Some(n) = new {
                kept[n.idx()] = m[old];
            }
        }
        kept
    });
    let norm = Normalization::of(&file_mesh);
    let reference = norm.apply(&file_mesh);
    let field = match &user_metric {
        Some(m) => MetricField::new(
            reference,
            m.iter().map(|m| norm.metric_to_unit(m)).collect(),
        )?,
        None => MetricField::from_curvature(reference, &MetricOptions::default())?,
    };
    let patches: Box<dyn conemesh::patches::PatchStrategy> = if args.strategy == "cone" {
        let mut o = conemesh::patches::ConeOptions::default();
        if let Some(r) = args.expand_rings {
            o.expand_rings = r;
        }
        o.max_faces = args.max_patch_faces.or(o.max_faces);
        Box::new(conemesh::patches::ConePatches { options: o })
    } else {
        strategy(&args.strategy)?
    };
    let stages = Stages {
        patches,
        ..Stages::default()
    };
    let options = RemeshOptions {
        seed: args.seed,
        // A metric length is the same in file units and in unit space (Normalization).
        target: match args.ltar {
            Some(l) => TargetLength::Absolute(l),
            None => TargetLength::Factor(args.ltar_factor),
        },
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
        sweeps: args.sweeps,
        corner_defect: (args.corner_defect != 0.0).then_some(args.corner_defect),
        feature_angle: (args.feature_angle != 0.0).then_some(args.feature_angle),
        coarse_input: match args.coarse {
            Coarse::Auto => CoarseInput::Auto,
            Coarse::On => CoarseInput::On,
            Coarse::Off => CoarseInput::Off,
        },
        ..RemeshOptions::default()
    };
    let total = field.reference().n_faces() as u64;
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::new(total);
        // A constant template; should it ever be refused, keep indicatif's default style.
        if let Ok(style) = ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} input faces covered, {msg}",
        ) {
            b.set_style(style.progress_chars("=> "));
        }
        b
    };
    let result = pipeline::remesh(&field, &stages, &options, |p: Progress| {
        bar.set_position((p.total - p.unprocessed) as u64);
        bar.set_message(format!("{} patches", p.patches));
    });
    bar.finish_and_clear();
    let result = result?;
    let out_unit = &result.mesh;
    // Back to file units; input vertices keep their file coordinates bit for bit.
    let out_file = to_file_units(
        out_unit,
        &result.locations,
        field.reference(),
        &file_mesh,
        &norm,
    );
    // The certificates were taken in unit space; mapping back to file units rounds the new
    // vertices, so the mesh that is written is certified again (exact): no degenerate face,
    // and no self-intersection where the unit-space output had none.
    conemesh::invariants::certify_no_degenerate_faces(&out_file)
        .context("the output in file units (after mapping back from unit space)")?;
    if result.report.certificate.no_self_intersections == 1 {
        conemesh::invariants::certify_no_self_intersections(&out_file)
            .context("the output in file units (after mapping back from unit space)")?;
    }
    let elapsed = t_start.elapsed().as_secs_f64();
    // The yardstick, independent of the remesher: `conemesh eval` on the written output.
    let eval_opts = EvalOptions {
        target: match args.ltar {
            Some(l) => TargetLength::Absolute(l),
            None => TargetLength::Factor(args.ltar_factor),
        },
        self_intersections: false, // certified exactly by the pipeline already
        ..EvalOptions::default()
    };
    let eval =
        conemesh::quality::evaluate(&file_mesh, &out_file, user_metric.as_deref(), &eval_opts)?;
    println!(
        "{name}: {} faces → {} faces in {} patches, {elapsed:.2} s",
        result.report.faces_in, result.report.faces_out, result.report.patches
    );
    println!("{}", EvalReport::table_header());
    println!("{}", eval.table_row(&short_name));
    let c = &result.report.certificate;
    println!(
        "certified after each of {} patches: disk, bijective, planar, manifold, oriented, same topology, boundary kept, no degenerate/flipped faces; final self-intersections: {}",
        result.report.patches,
        match (c.no_self_intersections, c.input_self_intersecting_pairs) {
            (1, _) => "none (exact)".to_string(),
            (_, Some(n)) => format!(
                "{} pairs, but the input itself self-intersects ({n} pairs)",
                c.self_intersecting_pairs
            ),
            _ => "not checked".to_string(),
        }
    );
    let r = &result.report;
    if r.coarse_input {
        let why = if r.options.coarse_input == CoarseInput::On {
            "forced by --coarse on".to_string()
        } else {
            format!(
                "the distance tolerance, not the metric, sets the size here: expected faces {:.0} in the metric, {:.0} with the fidelity scaling; --coarse off for the options as given",
                r.expected_faces, r.expected_faces_fidelity
            )
        };
        println!(
            "coarse-input profile ran ({} sweeps, fidelity floor {} of the mean input edge, {} rounds, persistent factors): {why}",
            r.options.sweeps, r.options.fidelity.min_edge_ratio, r.options.fidelity.rounds
        );
    }
    let fb = &result.report.fallbacks;
    if fb.kept_faces > 0 || fb.shrinks > 0 {
        eprintln!(
            "warning: {} patch attempt(s) failed their certificates and were retried smaller; {} face(s) (of the input, or of an earlier sweep) could not be remeshed and were kept as they were (details: --report, `fallbacks`)",
            fb.failures.len(),
            fb.kept_faces
        );
    }
    // Everything is computed; write the outputs (each atomically), the mesh first.
    conemesh::io::write_mesh(&args.output, &out_file)
        .with_context(|| format!("writing {}", args.output.display()))?;
    println!("wrote {}", args.output.display());
    if let Some(p) = &args.write_metric {
        let m: Vec<_> = result
            .locations
            .iter()
            .map(|l| norm.metric_from_unit(&field.eval_at(l)))
            .collect();
        conemesh::io::sol::write_sol(p, &m, false)
            .with_context(|| format!("writing {}", p.display()))?;
    }
    if let Some(p) = &args.report {
        let json = serde_json::json!({
            "input": name,
            "output": args.output,
            "seconds": elapsed,
            "peak_rss_mib": peak_rss_mib(),
            "run": result.report,
            "eval": eval,
        });
        conemesh::io::write_bytes_atomic(p, serde_json::to_string_pretty(&json)?.as_bytes())
            .with_context(|| format!("writing {}", p.display()))?;
    }
    if let Some(dir) = &args.plots {
        conemesh::report::write_quality_plots(
            dir,
            &short_name,
            &[
                ("input", &eval.input_quality),
                ("output", &eval.output_quality),
            ],
        )
        .with_context(|| format!("writing plots into {}", dir.display()))?;
    }
    Ok(ExitCode::SUCCESS)
}

/// This process's peak resident memory in MiB (`VmHWM` of `/proc/self/status`, in kB; `None`
/// where there is no such file, i.e. off Linux).
fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

fn strategy(name: &str) -> anyhow::Result<Box<dyn conemesh::patches::PatchStrategy>> {
    match conemesh::patches::strategy_by_name(name) {
        Some(s) => Ok(s),
        None => bail!(
            "unknown patch strategy `{name}` (known: {})",
            conemesh::patches::STRATEGY_NAMES.join(", ")
        ),
    }
}

/// Map the unit-space result back to file units. A vertex that sits exactly on an input
/// vertex (one-hot barycentric location, bit-identical unit position) gets that vertex's file
/// coordinates bit for bit; every other vertex is mapped by the inverse normalization.
fn to_file_units(
    out: &TriMesh,
    locations: &[conemesh::SurfaceLocation],
    reference: &TriMesh,
    file_mesh: &TriMesh,
    norm: &Normalization,
) -> TriMesh {
    let positions = out
        .positions
        .iter()
        .zip(locations)
        .map(|(p, loc)| {
            for k in 0..3 {
                if loc.bary[k] == 1.0 {
                    let v = reference.triangles[loc.face.idx()][k];
                    if reference.positions[v.idx()] == *p {
                        return file_mesh.positions[v.idx()];
                    }
                }
            }
            norm.from_unit(p)
        })
        .collect();
    TriMesh {
        positions,
        triangles: out.triangles.clone(),
    }
}
