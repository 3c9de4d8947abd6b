//! Issue 7 "Done when": parameterize every patch of the covering runs of all shared meshes
//! (cone patches, seed 1, unit-diagonal mesh) with the default symmetric Dirichlet
//! parameterizer (Sec. 3.3) and certify each map exactly (`certify_bijective`).
//! Run with `cargo run --release --example param_cover -- [--json]`; prints a table (or
//! JSON), then times the patches nearest 5,000 faces. Not a test: see `tests/param_cover.rs`.

#[path = "../tests/common/param_cover.rs"]
mod common;

use common::{param_patch, run_mesh, MeshRun, MESHES};

fn main() {
    let json = std::env::args().any(|a| a == "--json");
    let mut names: Vec<String> = match std::fs::read_dir(MESHES) {
        Ok(d) => d
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().to_string())
            .filter(|n| n.ends_with(".off") || n.ends_with(".obj"))
            .collect(),
        Err(e) => {
            eprintln!("cannot read {MESHES}: {e}");
            std::process::exit(2);
        }
    };
    names.sort();
    if let Ok(only) = std::env::var("ONLY") {
        names.retain(|n| n.contains(only.as_str()));
    }
    let mut runs: Vec<MeshRun> = Vec::new();
    // (|faces − 5000|, mesh index, patch faces) of every patch, for the 5k timing.
    let mut near5k = Vec::new();
    let mut meshes = Vec::new();
    let mut failures = 0usize;
    for name in &names {
        match run_mesh(name) {
            Ok((run, mesh, faces)) => {
                for r in run.patches.iter().filter(|p| p.error.is_some()) {
                    failures += 1;
                    eprintln!(
                        "FAIL {name} patch {} ({} faces): {}",
                        r.patch,
                        r.faces,
                        r.error.as_deref().unwrap_or("")
                    );
                }
                let mi = meshes.len();
                for (i, f) in faces.iter().enumerate() {
                    near5k.push((f.len().abs_diff(5000), mi, i));
                }
                meshes.push((mesh, faces));
                eprintln!(
                    "{name}: {} patches, cover {:.0} ms",
                    run.patches.len(),
                    run.cover_ms
                );
                runs.push(run);
            }
            Err(e) => {
                failures += 1;
                eprintln!("FAIL {e}");
            }
        }
    }
    // Re-time the (up to) three patches nearest 5,000 faces: best of 5 runs each.
    near5k.sort();
    let mut timing = Vec::new();
    for &(_, mi, pi) in near5k.iter().take(3) {
        let (mesh, faces) = &meshes[mi];
        let rows: Vec<_> = (0..5).map(|_| param_patch(mesh, pi, &faces[pi])).collect();
        let best = rows.iter().map(|r| r.ms).fold(f64::INFINITY, f64::min);
        let iters = rows[0].report.as_ref().map_or(0, |r| r.iterations);
        timing.push(serde_json::json!({
            "mesh": runs[mi].mesh, "patch": pi, "faces": faces[pi].len(),
            "best_ms": best, "iterations": iters,
        }));
    }
    if json {
        let out = serde_json::json!({
            "meshes": runs.iter().map(|r| serde_json::json!({
                "mesh": r.mesh, "faces": r.faces, "cover_ms": r.cover_ms,
                "summary": r.summary(), "patches": r.patches,
            })).collect::<Vec<_>>(),
            "near_5000_faces": timing,
        });
        println!("{}", serde_json::to_string_pretty(&out).unwrap_or_default());
    } else {
        println!(
            "| mesh | patches | certified | mean conformal (area-weighted) | worst max conformal | fallbacks | budget hits | param time ms | largest patch (faces) | its ms |"
        );
        println!("|---|---|---|---|---|---|---|---|---|---|");
        for r in &runs {
            let s = r.summary();
            println!(
                "| {} | {} | {} | {:.4} | {:.3} | {} | {} | {:.0} | {} | {:.1} |",
                r.mesh,
                s.patches,
                s.certified,
                s.mean_conformal_area_weighted,
                s.worst_max_conformal,
                s.fallbacks,
                s.budget_hits,
                s.total_param_ms,
                s.largest_patch_faces,
                s.largest_patch_ms
            );
        }
        println!();
        println!("Patches nearest 5,000 faces (best of 5):");
        for t in &timing {
            println!(
                "- {} patch {}: {} faces, {:.1} ms, {} iterations",
                t["mesh"].as_str().unwrap_or(""),
                t["patch"],
                t["faces"],
                t["best_ms"].as_f64().unwrap_or(f64::NAN),
                t["iterations"]
            );
        }
    }
    if failures > 0 {
        eprintln!("{failures} failures");
        std::process::exit(1);
    }
}
