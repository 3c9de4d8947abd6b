//! `conemesh eval`: score a remeshed surface against its input (Sec. 4.1, Table 1). Parses,
//! calls [`conemesh::quality::evaluate`], prints one Table-1 line, writes JSON and plots.

use anyhow::Context;
use conemesh::quality::{evaluate, EvalOptions, TargetLength};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `conemesh eval`.
#[derive(clap::Args, Debug)]
pub struct EvalArgs {
    /// The input (reference) surface; its bounding-box diagonal is the unit of every measure.
    #[arg(long)]
    pub input: PathBuf,
    /// The surface to score (e.g. a remeshed input; the input itself gives its own quality).
    #[arg(long)]
    pub output: PathBuf,
    /// L_tar = F · L_avg, L_avg the mean metric edge length of the input [default: 1.5].
    #[arg(long, value_name = "F", conflicts_with = "ltar")]
    pub ltar_factor: Option<f64>,
    /// Absolute target edge length L_tar (metric length, input file units).
    #[arg(long, value_name = "L")]
    pub ltar: Option<f64>,
    /// Per-input-vertex metric tensors (Medit .sol, file units) instead of the curvature metric.
    #[arg(long, value_name = "M.sol")]
    pub metric: Option<PathBuf>,
    /// Fit the curvature metric on each side of the feature lines that `--feature-angle`
    /// picks (as `remesh --crease-metric`) instead of across them.
    #[arg(long)]
    pub crease_metric: bool,
    /// The feature lines of `--crease-metric` (as `remesh --feature-angle`: `auto`, an angle in
    /// degrees, or `off`).
    #[arg(long, default_value = "auto", value_parser = conemesh::features::FeatureRule::parse)]
    pub feature_angle: conemesh::features::FeatureRule,
    /// Write the full report as JSON.
    #[arg(long, value_name = "R.json")]
    pub json: Option<PathBuf>,
    /// Write PNG histograms of q, all angles and smallest angles into this folder.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// Random samples per surface for Hausdorff / RMS (on top of all vertices).
    #[arg(long, default_value_t = 100_000)]
    pub samples: usize,
    /// Seed of the sampling.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Skip the (exact) self-intersection search.
    #[arg(long)]
    pub no_self_intersections: bool,
    /// Name in the first column [default: the output's file stem].
    #[arg(long)]
    pub name: Option<String>,
    /// Print only the row, without the header line.
    #[arg(long)]
    pub no_header: bool,
}

/// Run `conemesh eval`.
pub fn run(args: EvalArgs) -> anyhow::Result<ExitCode> {
    let t0 = std::time::Instant::now();
    // Before reading anything: the count alone decides.
    if args.samples > conemesh::quality::MAX_SAMPLES {
        anyhow::bail!(
            "--samples {}: at most {} random samples per surface are taken",
            args.samples,
            conemesh::quality::MAX_SAMPLES
        );
    }
    check_output_paths(&args)?;
    let input = conemesh::io::read_mesh(&args.input)
        .with_context(|| format!("reading input {}", args.input.display()))?
        .mesh;
    let output = conemesh::io::read_mesh(&args.output)
        .with_context(|| format!("reading output {}", args.output.display()))?
        .mesh;
    let metric = match &args.metric {
        Some(p) => Some(
            conemesh::io::sol::read_sol(p, input.n_vertices())
                .with_context(|| format!("reading metric {}", p.display()))?,
        ),
        None => None,
    };
    let target = match (args.ltar, args.ltar_factor) {
        (Some(l), _) => {
            anyhow::ensure!(l > 0.0 && l.is_finite(), "--ltar must be positive, got {l}");
            TargetLength::Absolute(l)
        }
        (None, f) => {
            let f = f.unwrap_or(1.5);
            anyhow::ensure!(
                f > 0.0 && f.is_finite(),
                "--ltar-factor must be positive, got {f}"
            );
            TargetLength::Factor(f)
        }
    };
    let opts = EvalOptions {
        target,
        samples: args.samples,
        seed: args.seed,
        self_intersections: !args.no_self_intersections,
        metric: conemesh::metric::MetricOptions {
            features: match args.crease_metric {
                true => args.feature_angle,
                false => conemesh::features::FeatureRule::Off,
            },
            ..Default::default()
        },
    };
    let report = evaluate(&input, &output, metric.as_deref(), &opts)
        .with_context(|| format!("evaluating {}", args.output.display()))?;
    let name = args.name.clone().unwrap_or_else(|| {
        args.output
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    });
    if !args.no_header {
        println!("{}", conemesh::quality::EvalReport::table_header());
    }
    println!("{}", report.table_row(&name));

    // The JSON and the plots as one transaction (issue 20): both or neither.
    let mut outputs = conemesh::io::Outputs::new();
    let mut plot_files = Vec::new();
    if let Some(dir) = &args.plots {
        let same = args.input == args.output;
        let series: Vec<(&str, &conemesh::quality::QualityStats)> = if same {
            vec![("input", &report.input_quality)]
        } else {
            vec![
                ("input", &report.input_quality),
                ("output", &report.output_quality),
            ]
        };
        let staged = outputs
            .dir(dir)
            .with_context(|| format!("writing plots to {}", dir.display()))?;
        plot_files = conemesh::report::write_quality_plots(&staged, &name, &series)
            .with_context(|| format!("writing plots to {}", dir.display()))?
            .iter()
            .filter_map(|p| p.file_name().map(|f| dir.join(f)))
            .collect();
    }
    if let Some(path) = &args.json {
        let doc = serde_json::json!({
            "name": name,
            "input_file": args.input.display().to_string(),
            "output_file": args.output.display().to_string(),
            "metric_file": args.metric.as_ref().map(|p| p.display().to_string()),
            "samples": args.samples,
            "seed": args.seed,
            "plots": plot_files.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            "wall_seconds": t0.elapsed().as_secs_f64(),
            "report": report,
        });
        outputs
            .bytes(path, serde_json::to_string_pretty(&doc)?.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    super::commit(outputs)?;
    eprintln!(
        "L_avg {:.6}, L_tar {:.6} (unit space, diagonal 1); metric: {}; {:.2} s",
        report.l_avg,
        report.l_tar,
        report.metric_source,
        t0.elapsed().as_secs_f64()
    );
    Ok(ExitCode::SUCCESS)
}

/// The output paths, checked before any work (issue 20): `--json` is not a folder and its
/// folder exists, `--plots` is not a file and its parent exists, and `--json` is none of the
/// inputs.
fn check_output_paths(args: &EvalArgs) -> anyhow::Result<()> {
    if let Some(p) = &args.json {
        super::check_file_output("--json", p)?;
        for (what, q) in [
            Some(("--input", &args.input)),
            Some(("--output", &args.output)),
            args.metric.as_ref().map(|m| ("--metric", m)),
        ]
        .into_iter()
        .flatten()
        {
            if super::same_path(p, q) {
                anyhow::bail!("--json {} is the same path as {what}", p.display());
            }
        }
    }
    if let Some(d) = &args.plots {
        super::check_plots_folder("--plots", d)?;
    }
    Ok(())
}
