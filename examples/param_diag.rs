//! Diagnostics of the default parameterizer (Sec. 3.3) on the large patches of covering
//! runs: per patch, the Newton iterations, the time split of `SdLog` and the energy / step
//! trajectory. Run with `ONLY=armadillo MINF=3000 cargo run --release --example param_diag`.

#[path = "../tests/common/param_cover.rs"]
mod common;

use common::{load, MESHES};
use conemesh::param::{
    circle_boundary, distortion, optimize_with_log, scale_to_area, tutte_embedding, SdOptions,
    TutteWeights,
};
use conemesh::patches::{cover, extract_patch, ConePatches, CoverOptions};
use rand::SeedableRng;
use std::time::Instant;

fn env_usize(k: &str) -> Option<usize> {
    std::env::var(k).ok().and_then(|s| s.parse().ok())
}

fn main() {
    let only = std::env::var("ONLY").unwrap_or_else(|_| "armadillo".to_string());
    let minf: usize = std::env::var("MINF")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3000);
    let verbose = std::env::var("VERBOSE").is_ok();
    let mut names: Vec<String> = std::fs::read_dir(MESHES)
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().to_string())
                .filter(|n| (n.ends_with(".off") || n.ends_with(".obj")) && n.contains(&only))
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    for name in names {
        let mesh = load(&name);
        let mut rng = conemesh::Rng::seed_from_u64(1);
        let Ok(run) = cover(
            &mesh,
            &ConePatches::default(),
            &CoverOptions::default(),
            &mut rng,
        ) else {
            continue;
        };
        for (pi, p) in run.patches.iter().enumerate() {
            if p.faces.len() < minf || p.faces.len() > env_usize("MAXF").unwrap_or(usize::MAX) {
                continue;
            }
            let Ok(pm) = extract_patch(&mesh, &p.faces) else {
                continue;
            };
            if let Some(reps) = env_usize("LSCMREPS") {
                let mut best = f64::INFINITY;
                for _ in 0..reps {
                    let t = Instant::now();
                    let _ = conemesh::param::lscm(&pm.mesh, &pm.boundary);
                    best = best.min(t.elapsed().as_secs_f64() * 1e3);
                }
                println!(
                    "{name} p{pi} {}f: lscm best of {reps} {best:.2} ms",
                    p.faces.len()
                );
                continue;
            }
            // REPS=n: best-of-n wall time of the default parameterizer (initial map included).
            if let Some(reps) = env_usize("REPS") {
                let mut best = f64::INFINITY;
                let mut rep = None;
                let mut best_prof = None;
                for _ in 0..reps {
                    let t = Instant::now();
                    let mut sd = conemesh::param::SymmetricDirichlet::default();
                    if let Some(x) = env_usize("RI") {
                        sd.options.repair_iters = x;
                    }
                    let env = |k: &str| std::env::var(k).ok().and_then(|s| s.parse::<f64>().ok());
                    if let Some(x) = env("RM") {
                        sd.options.repair_margin = x;
                    }
                    if let Some(x) = env("RT") {
                        sd.options.rel_tol = x;
                    }
                    if let Some(x) = env("BD") {
                        sd.options.barrier_distance = x;
                    }
                    if let Some(x) = env("COLL") {
                        sd.options.collision_bound = x > 0.0;
                    }
                    if let Some(x) = env("SF") {
                        sd.options.step_fraction = x;
                    }
                    if let Some(x) = env("BW") {
                        sd.options.barrier_weight = x;
                    }
                    if let Some(x) = env("RW") {
                        sd.options.repair_weight = x;
                    }
                    if let Some(x) = env("RC") {
                        sd.options.repair_clearance = x;
                    }
                    let r = sd.parameterize_profiled(&pm.mesh, &pm.boundary);
                    let ms = t.elapsed().as_secs_f64() * 1e3;
                    if let Ok((p, prof)) = r {
                        if ms < best {
                            best_prof = Some(prof);
                        }
                        rep = Some(p.report);
                    }
                    best = best.min(ms);
                }
                if let Some(r) = rep {
                    println!(
                        "{name} p{pi} {}f: best of {reps} {best:.1} ms, it {} budget {} meanc {:.4} maxc {:.3} fb {}",
                        p.faces.len(),
                        r.iterations,
                        r.hit_budget,
                        r.mean_conformal,
                        r.max_conformal,
                        r.fell_back
                    );
                }
                if let (Some(pr), true) = (best_prof, verbose) {
                    let l = &pr.newton;
                    println!(
                        "  init {:?} {:.1} ms (lscm {:.1}, repair {:.1} it {:?}), newton {:.1} ms split {:.1?} it {} fact {} armijo {} cert {} coll {}",
                        pr.init,
                        pr.init_ms,
                        pr.lscm_ms,
                        pr.repair_ms,
                        pr.repair.as_ref().map(|r| (r.iterations, r.time_ms.map(|x| (x * 10.0).round() / 10.0))),
                        pr.newton_ms,
                        l.time_ms,
                        l.iterations,
                        l.factorizations,
                        l.armijo_rejections,
                        l.certificate_rejections,
                        l.collision_limited
                    );
                    if let Some(r) = &pr.repair {
                        for i in 0..r.steps.len() {
                            println!(
                                "    repair {:2} E {:.6} step {:.4} flipfree {:.4} minA {:.2e}",
                                i + 1,
                                r.energies[i + 1],
                                r.steps[i],
                                r.flip_free_steps[i],
                                r.min_double_area[i + 1]
                            );
                        }
                    }
                    for i in 0..l.steps.len() {
                        println!(
                            "    {:2} E {:.6} dec/exc {:.2e} rel {:.2e} step {:.4} flipfree {:.4}",
                            i + 1,
                            l.energies[i + 1],
                            l.decrements[i] / (l.energies[i] - 4.0),
                            (l.energies[i] - l.energies[i + 1]) / (l.energies[i] - 4.0),
                            l.steps[i],
                            l.flip_free_steps[i]
                        );
                    }
                }
                continue;
            }
            let t0 = Instant::now();
            let circle = circle_boundary(&pm.mesh, &pm.boundary, 1.0);
            let Ok(mut uv0) = tutte_embedding(&pm.mesh, &pm.boundary, &circle, TutteWeights::Cotan)
            else {
                continue;
            };
            scale_to_area(&pm.mesh, &mut uv0);
            if std::env::var("LSCM").is_ok() {
                match conemesh::param::lscm(&pm.mesh, &pm.boundary) {
                    Ok(mut l) => {
                        scale_to_area(&pm.mesh, &mut l);
                        match conemesh::invariants::certify_bijective(
                            &l,
                            &pm.mesh.triangles,
                            &pm.boundary,
                        ) {
                            Ok(()) => uv0 = l,
                            Err(e) => println!("  LSCM not certified: {e}"),
                        }
                    }
                    Err(e) => println!("  LSCM failed: {e}"),
                }
            }
            if std::env::var("REPAIR").is_ok() {
                let tl = Instant::now();
                let l = conemesh::param::lscm(&pm.mesh, &pm.boundary);
                println!("  lscm {:.1} ms", tl.elapsed().as_secs_f64() * 1e3);
                if let Ok(mut l) = l {
                    scale_to_area(&pm.mesh, &mut l);
                    let mut o = SdOptions {
                        max_iters: env_usize("MI").unwrap_or(100),
                        ..Default::default()
                    };
                    if let Ok(x) = std::env::var("RW") {
                        o.repair_weight = x.parse().unwrap_or(0.0);
                    }
                    if let Ok(x) = std::env::var("RM") {
                        o.repair_margin = x.parse().unwrap_or(0.1);
                    }
                    match conemesh::param::optimize_locally_injective(
                        &pm.mesh,
                        &pm.boundary,
                        &l,
                        &o,
                    ) {
                        Ok((u, log)) => {
                            let c = conemesh::invariants::certify_bijective(
                                &u,
                                &pm.mesh.triangles,
                                &pm.boundary,
                            );
                            let r = distortion(&pm.mesh, &u);
                            if let Ok(dir) = std::env::var("DUMP") {
                                let j = serde_json::json!({
                                    "uv": u.iter().map(|p| [p.x, p.y]).collect::<Vec<_>>(),
                                    "tris": pm.mesh.triangles.iter().map(|t| [t[0].idx(), t[1].idx(), t[2].idx()]).collect::<Vec<_>>(),
                                    "boundary": pm.boundary.iter().map(|v| v.idx()).collect::<Vec<_>>(),
                                });
                                let _ = std::fs::write(
                                    format!("{dir}/{name}_p{pi}.json"),
                                    j.to_string(),
                                );
                            }
                            println!(
                                "  repair: it {} split {:.1?} E {:.4} maxc {:.3} meanc {:.4} ms {:.1} cert {:?}",
                                log.iterations,
                                log.time_ms,
                                log.energies.last().copied().unwrap_or(f64::NAN),
                                r.max_conformal,
                                r.mean_conformal,
                                t0.elapsed().as_secs_f64() * 1e3,
                                c.err().map(|e| e
                                    .to_string()
                                    .chars()
                                    .take(300)
                                    .collect::<String>())
                            );
                        }
                        Err(e) => println!("  repair failed: {e}"),
                    }
                }
            }
            if std::env::var("BLEND").is_ok() {
                let tb = Instant::now();
                let o = SdOptions::default();
                let mut l = conemesh::param::lscm(&pm.mesh, &pm.boundary).unwrap();
                scale_to_area(&pm.mesh, &mut l);
                let (mut us, _) =
                    conemesh::param::optimize_locally_injective(&pm.mesh, &pm.boundary, &l, &o)
                        .unwrap();
                scale_to_area(&pm.mesh, &mut us);
                let t = uv0.clone();
                // Procrustes: rotate/translate us onto t.
                let n = t.len() as f64;
                let ct = t
                    .iter()
                    .fold(nalgebra::Vector2::zeros(), |a, p| a + p.coords)
                    / n;
                let cu = us
                    .iter()
                    .fold(nalgebra::Vector2::zeros(), |a, p| a + p.coords)
                    / n;
                let (mut sc, mut ss) = (0.0, 0.0);
                for (a, b) in us.iter().zip(&t) {
                    let (x, y) = (a.coords - cu, b.coords - ct);
                    sc += x.dot(&y);
                    ss += x.perp(&y);
                }
                let th = ss.atan2(sc);
                let (c, s) = (th.cos(), th.sin());
                for p in us.iter_mut() {
                    let x = p.coords - cu;
                    *p = nalgebra::Point2::from(
                        nalgebra::Vector2::new(c * x.x - s * x.y, s * x.x + c * x.y) + ct,
                    );
                }
                let blend = |lam: f64| -> Vec<nalgebra::Point2<f64>> {
                    t.iter()
                        .zip(&us)
                        .map(|(a, b)| {
                            nalgebra::Point2::from(a.coords * (1.0 - lam) + b.coords * lam)
                        })
                        .collect()
                };
                let ok = |lam: f64| {
                    conemesh::invariants::certify_bijective(
                        &blend(lam),
                        &pm.mesh.triangles,
                        &pm.boundary,
                    )
                    .is_ok()
                };
                let (mut lo, mut hi) = (0.0, 1.0);
                if ok(1.0) {
                    lo = 1.0;
                } else {
                    for _ in 0..env_usize("BS").unwrap_or(8) {
                        let mid = 0.5 * (lo + hi);
                        if ok(mid) {
                            lo = mid
                        } else {
                            hi = mid
                        }
                    }
                }
                let b = blend(lo);
                println!(
                    "  blend lambda {lo:.4} E0 {:.3} ms {:.1}",
                    distortion(&pm.mesh, &b).symmetric_dirichlet,
                    tb.elapsed().as_secs_f64() * 1e3
                );
                uv0 = b;
            }
            // INIT=1: the parameterizer's own initial map.
            if std::env::var("INIT").is_ok() {
                let mut o = SdOptions::default();
                if let Some(x) = env_usize("RI") {
                    o.repair_iters = x;
                }
                if let Ok(x) = std::env::var("RW") {
                    o.repair_weight = x.parse().unwrap_or(100.0);
                }
                if let Ok(x) = std::env::var("RM") {
                    o.repair_margin = x.parse().unwrap_or(0.1);
                }
                match conemesh::param::initial_map(&pm.mesh, &pm.boundary, &o) {
                    Ok((u, kind)) => {
                        println!("  init {kind:?}");
                        uv0 = u;
                    }
                    Err(e) => println!("  init failed: {e}"),
                }
            }
            let t_init = t0.elapsed().as_secs_f64() * 1e3;
            let mut opts = SdOptions::default();
            let env = |k: &str| std::env::var(k).ok().and_then(|s| s.parse::<f64>().ok());
            if let Some(x) = env("BW") {
                opts.barrier_weight = x;
            }
            if let Some(x) = env("BD") {
                opts.barrier_distance = x;
            }
            if let Some(x) = env("RT") {
                opts.rel_tol = x;
            }
            if let Some(x) = env("MI") {
                opts.max_iters = x as usize;
            }
            if let Some(x) = env("ABS") {
                opts.abs_twist = x > 0.0;
            }
            if let Some(x) = env("COLL") {
                opts.collision_bound = x > 0.0;
            }
            if let Some(x) = env("SF") {
                opts.step_fraction = x;
            }
            match optimize_with_log(&pm.mesh, &pm.boundary, &uv0, &opts) {
                Ok((uv, log)) => {
                    let total = t0.elapsed().as_secs_f64() * 1e3;
                    let r = distortion(&pm.mesh, &uv);
                    println!(
                        "{name} p{pi} {}f: {:.0} ms (init {:.1}, setup {:.1} asm {:.1} solve {:.1} ls {:.1}) it {} budget {} E0 {:.3e} E {:.4} maxc {:.3} meanc {:.4} rej {} armijo {} coll {} fact {}",
                        p.faces.len(),
                        total,
                        t_init,
                        log.time_ms[0],
                        log.time_ms[1],
                        log.time_ms[2],
                        log.time_ms[3],
                        log.iterations,
                        log.hit_budget,
                        log.energies[0],
                        log.energies.last().copied().unwrap_or(f64::NAN),
                        r.max_conformal,
                        r.mean_conformal,
                        log.certificate_rejections,
                        log.armijo_rejections,
                        log.collision_limited,
                        log.factorizations
                    );
                    if verbose {
                        for (i, e) in log.energies.iter().enumerate() {
                            println!(
                                "  {i:3} E {e:.6e} minA {:.3e} step {:.4} flipfree {:.4}",
                                log.min_double_area[i],
                                if i > 0 { log.steps[i - 1] } else { 0.0 },
                                if i > 0 {
                                    log.flip_free_steps[i - 1]
                                } else {
                                    0.0
                                }
                            );
                        }
                    }
                }
                Err(e) => println!("{name} p{pi}: {e}"),
            }
        }
    }
}
