//! `conemesh patches [MESH] [--seed N] [--strategy NAME] [-o OUT.ply] [--json R.json]`:
//! cover a mesh with certified disk patches (Sec. 3.2, no remeshing) and report them.

use conemesh::io::{read_mesh, MeshAttributes, Outputs, WriteOptions};
use conemesh::mesh::generators;
use conemesh::metric::Normalization;
use conemesh::patches::{cover, CoverOptions};
use conemesh::registry::Params;
use rand::SeedableRng;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Arguments of `conemesh patches`.
#[derive(clap::Args, Debug)]
pub struct PatchesArgs {
    /// Input mesh (.obj, .off, .ply, .stl, .mesh); the built-in torus when omitted.
    pub mesh: Option<PathBuf>,
    /// Seed of the random number generator (seed vertices).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Patch strategy, by registry name (`conemesh stages` lists them).
    #[arg(long, default_value = "cone")]
    pub strategy: String,
    /// An option of the patch strategy, `KEY=VALUE` (repeatable).
    #[arg(long, value_name = "KEY=VALUE")]
    pub strategy_opt: Vec<String>,
    /// Write the mesh with a per-face `patch` property and colour (PLY recommended).
    #[arg(short = 'o', long)]
    pub output: Option<PathBuf>,
    /// Write per-patch statistics as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

/// A distinct colour per patch (golden-ratio hue walk).
fn colour(i: usize) -> [u8; 3] {
    let h = (i as f64 * 0.618_033_988_75).fract() * 6.0;
    let (s, v) = (0.65, 0.95);
    let f = h.fract();
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    let (r, g, b) = match h as u32 {
        0 => (v, t, p),
        1 => (q, v, p),
        2 => (p, v, t),
        3 => (p, q, v),
        4 => (t, p, v),
        _ => (v, p, q),
    };
    [(r * 255.0) as u8, (g * 255.0) as u8, (b * 255.0) as u8]
}

/// Run `conemesh patches`.
pub fn run(args: PatchesArgs) -> anyhow::Result<ExitCode> {
    let files: Vec<(&str, &PathBuf)> = [
        args.output.as_ref().map(|p| ("-o", p)),
        args.json.as_ref().map(|p| ("--json", p)),
    ]
    .into_iter()
    .flatten()
    .collect();
    for (i, (flag, p)) in files.iter().enumerate() {
        super::check_file_output(flag, p)?;
        let earlier = files[..i].iter().map(|(f, q)| (*f, *q));
        for (other, q) in earlier.chain(args.mesh.as_ref().map(|m| ("the input", m))) {
            if super::same_path(p, q) {
                anyhow::bail!("{flag} {} is the same path as {other}", p.display());
            }
        }
    }
    let (mesh, name) = match &args.mesh {
        Some(p) => {
            let loaded =
                read_mesh(p).map_err(|e| anyhow::anyhow!("cannot read the input mesh: {e}"))?;
            for w in &loaded.warnings {
                eprintln!("warning: {w}");
            }
            (loaded.mesh, p.display().to_string())
        }
        None => (generators::default_surface(), "built-in torus".to_string()),
    };
    let strategy = conemesh::patches::strategy(&args.strategy, Params::parse(&args.strategy_opt)?)?;
    // The pipeline's working units (bounding-box diagonal 1).
    let work = Normalization::of(&mesh).apply(&mesh);
    let mut rng = conemesh::Rng::seed_from_u64(args.seed);
    let t0 = Instant::now();
    let run = cover(&work, strategy.as_ref(), &CoverOptions::default(), &mut rng)?;
    let secs = t0.elapsed().as_secs_f64();
    let n = run.patches.len();
    let total: usize = run.stats.iter().map(|s| s.faces).sum();
    let max = run.stats.iter().map(|s| s.faces).max().unwrap_or(0);
    let mean = total as f64 / n.max(1) as f64;
    if !run.complete {
        anyhow::bail!(
            "{name}: the `{}` strategy stopped after {n} patches with faces still uncovered; nothing written",
            run.strategy
        );
    }
    println!(
        "{name}: {} faces covered by {n} `{}` patches (seed {}), faces per patch mean {mean:.1}, max {max}; {:.3} s; every patch certified a disk",
        mesh.n_faces(),
        run.strategy,
        args.seed,
        secs
    );
    // The mesh and the JSON as one transaction (issue 20): both or neither.
    let mut outputs = Outputs::new();
    if let Some(out) = &args.output {
        // -1: a face no patch covered (only when the patch budget ran out).
        let ids: Vec<i64> = run
            .patch_of_face
            .iter()
            .map(|p| p.map_or(-1, |p| p.0 as i64))
            .collect();
        let attrs = MeshAttributes {
            face_ints: vec![("patch".to_string(), ids)],
            face_colors: Some(
                run.patch_of_face
                    .iter()
                    .map(|p| p.map_or([128, 128, 128], |p| colour(p.idx())))
                    .collect(),
            ),
            ..Default::default()
        };
        outputs
            .mesh(out, &mesh, &attrs, &WriteOptions::default())
            .map_err(|e| anyhow::anyhow!("cannot write the output mesh: {e}"))?;
    }
    if let Some(js) = &args.json {
        let report = serde_json::json!({
            "mesh": name,
            "strategy": run.strategy,
            "seed": args.seed,
            "faces": mesh.n_faces(),
            "patches": n,
            "mean_faces_per_patch": mean,
            "max_faces_per_patch": max,
            "seconds": secs,
            "complete": run.complete,
            "stats": run.stats,
        });
        outputs
            .bytes(js, serde_json::to_string_pretty(&report)?.as_bytes())
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", js.display()))?;
    }
    let written: Vec<String> = outputs
        .destinations()
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    super::commit(outputs)?;
    for w in written {
        println!("wrote {w}");
    }
    Ok(ExitCode::SUCCESS)
}
