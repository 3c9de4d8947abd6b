//! `conemesh remesh`: Algorithm 1 end to end, with the report and the Table-1 row. The
//! arguments and the whole job are the library's ([`conemesh::job`]); this file reads the
//! input, prints, and commits the files the job staged.

use anyhow::Context;
pub use conemesh::job::RemeshArgs;
use conemesh::job::{JobError, JobInput, Outcome, ProgressBar, Source};
use conemesh::quality::EvalReport;
use std::process::ExitCode;
use std::time::Instant;

/// Run `conemesh remesh`.
pub fn run(args: RemeshArgs) -> anyhow::Result<ExitCode> {
    let t_start = Instant::now();
    args.check_output_paths(true)?;
    if let Some(n) = args.threads {
        set_threads(n)?;
    }
    let (input, name, source) = read_input(&args, t_start)?;
    let prepared = input
        .prepare(args.repair_options().as_ref())
        .with_context(|| format!("repairing {name}"))?;
    if let Some(log) = &prepared.repair {
        eprintln!("repair: {}", log.summary());
    }
    let job = args.job(prepared.metric.is_some())?;
    let bar = ProgressBar::new(args.quiet, prepared.mesh.n_faces());
    let result = job.remesh(prepared, |p| bar.show(p));
    bar.finish();
    let outcome = result.map_err(|e| match e {
        JobError::Remesh(e) => anyhow::Error::new(e).context(match &args.metric {
            Some(m) => format!("remeshing {name} with metric {}", m.display()),
            None => format!("remeshing {name}"),
        }),
        e => e.into(),
    })?;
    print_summary(&outcome, &name, source.short_name());
    for w in &outcome.remeshed.warnings {
        eprintln!("warning: {w}");
    }
    // Everything is computed; write the outputs as one transaction (issue 20): each is staged
    // beside its destination and all are renamed into place only when all were written, so a
    // failure leaves every destination as it was and no temporary behind.
    let mut outputs = conemesh::io::Outputs::new();
    outcome.stage_files(&mut outputs, &args.files(true), &source)?;
    super::commit(outputs)?;
    println!("wrote {}", args.output.display());
    Ok(ExitCode::SUCCESS)
}

/// The input file (or the built-in torus) and `--metric`, read; the reader's warnings
/// printed unless `--quiet`. Returns the job's input, the input's name as printed, and its
/// source for the report.
fn read_input(args: &RemeshArgs, started: Instant) -> anyhow::Result<(JobInput, String, Source)> {
    let (name, mesh, repeated, polygons) = match &args.mesh {
        Some(p) => {
            let loaded = conemesh::io::read_mesh_with(p, &args.read_options())
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
    let input = JobInput {
        mesh,
        metric,
        repeated_index_faces: repeated,
        started,
    };
    let source = Source::File {
        name: name.clone(),
        short_name,
        polygons_triangulated: polygons,
    };
    Ok((input, name, source))
}

/// The run in a few lines on stdout: sizes and time, the Table-1 row, the certificates, the
/// improvers, the faces left with small angles, the coarse-input profile.
fn print_summary(outcome: &Outcome, name: &str, short_name: &str) {
    let r = &outcome.remeshed.unit.report;
    let elapsed = outcome.seconds;
    println!(
        "{name}: {} faces → {} faces in {} patches, {elapsed:.2} s",
        r.faces_in, r.faces_out, r.patches
    );
    println!("{}", EvalReport::table_header());
    println!("{}", outcome.eval.table_row(short_name));
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
}

/// `--threads N`: the size of rayon's global pool (before any parallel work of the process).
pub fn set_threads(n: usize) -> anyhow::Result<()> {
    anyhow::ensure!(n >= 1, "--threads must be at least 1 (got {n})");
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build_global()
        .map_err(|e| anyhow::anyhow!("cannot start {n} worker threads: {e}"))
}
