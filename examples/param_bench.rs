//! Benchmark of the default parameterizer (Sec. 3.3): Tutte initialisation and symmetric
//! Dirichlet optimisation on disks of growing size. Run with
//! `cargo run --release --example param_bench`. Not a timed test: it prints a table.

use conemesh::mesh::generators;
use conemesh::param::{
    circle_boundary, disk_boundary, distortion, optimize_with_log, scale_to_area, tutte_embedding,
    SdOptions, TutteWeights,
};
use conemesh::TriMesh;
use std::time::Instant;

/// A strongly curved cap of an icosphere with about `faces` faces: the faces whose corners
/// all lie within a geodesic radius of the north pole.
fn sphere_cap(faces: usize) -> TriMesh {
    let s = generators::icosphere(1.0, 6);
    let mut zs: Vec<f64> = s
        .triangles
        .iter()
        .map(|t| {
            t.iter()
                .map(|v| s.position(*v).z)
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    zs.sort_unstable_by(|a, b| b.total_cmp(a));
    let zmin = zs[faces.min(zs.len() - 1)];
    let keep: Vec<[usize; 3]> = s
        .triangles
        .iter()
        .filter(|t| t.iter().all(|v| s.position(*v).z > zmin))
        .map(|t| [t[0].idx(), t[1].idx(), t[2].idx()])
        .collect();
    TriMesh::from_indices(s.positions.clone(), &keep)
        .expect("cap")
        .without_unreferenced_vertices()
        .0
}

fn main() {
    if std::env::var("SEQ").is_ok() {
        faer::set_global_parallelism(faer::Par::Seq);
    }
    let cases: Vec<(String, TriMesh)> = vec![
        (
            "cylinder 40x25".into(),
            generators::cylinder_piece(1.0, 3.0, 2.0, 50, 25),
        ),
        (
            "cone 50x50".into(),
            generators::cone_piece(0.5, 3.0, 0.3, 2.0, 50, 50),
        ),
        ("sphere cap 1k".into(), sphere_cap(1000)),
        ("sphere cap 5k".into(), sphere_cap(5000)),
        ("sphere cap 20k".into(), sphere_cap(20000)),
    ];
    println!(
        "| patch | faces | tutte ms | optimise ms | iterations | energy | max conformal | mean conformal |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    // The default initial weights; MEANVALUE=1 to compare.
    let weights = if std::env::var("MEANVALUE").is_ok() {
        TutteWeights::MeanValue
    } else {
        SdOptions::default().init_weights
    };
    for (name, m) in cases {
        let b = disk_boundary(&m).expect("disk");
        if let Ok(only) = std::env::var("ONLY") {
            if !name.contains(only.as_str()) {
                continue;
            }
        }
        let reps: usize = std::env::var("REPS")
            .ok()
            .and_then(|r| r.parse().ok())
            .unwrap_or(10);
        let (mut t_tutte, mut t_opt) = (f64::INFINITY, f64::INFINITY);
        let mut last = None;
        for _ in 0..reps {
            let t0 = Instant::now();
            let circle = circle_boundary(&m, &b, 1.0);
            let mut uv = tutte_embedding(&m, &b, &circle, weights).expect("tutte");
            scale_to_area(&m, &mut uv);
            let t1 = Instant::now();
            let (uv, log) = optimize_with_log(&m, &b, &uv, &SdOptions::default()).expect("sd");
            let t2 = Instant::now();
            t_tutte = t_tutte.min((t1 - t0).as_secs_f64() * 1e3);
            t_opt = t_opt.min((t2 - t1).as_secs_f64() * 1e3);
            last = Some((uv, log));
        }
        let (uv, log) = last.expect("ran");
        let r = distortion(&m, &uv);
        println!(
            "| {name} | {} | {t_tutte:.1} | {t_opt:.1} | {} | {:.5} | {:.4} | {:.4} |",
            m.n_faces(),
            log.iterations,
            r.symmetric_dirichlet,
            r.max_conformal,
            r.mean_conformal
        );
        eprintln!(
            "  {name}: setup/assemble/factor+solve/line search ms = {:?}, factorizations {}",
            log.time_ms, log.factorizations
        );
    }
}
