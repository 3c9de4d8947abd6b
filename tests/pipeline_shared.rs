//! Algorithm 1 end to end on shared meshes (issue 9), through the library: every
//! certificate holds, the output keeps the input's topology and open boundary loops, has no
//! flipped face and no self-intersection; the Table-1 quality row of the file-unit output is
//! snapshotted (rounded to 3 significant digits) together with a SHA-256 of the OBJ bytes
//! written for seed 1, so any change of the output shows as a reviewable diff.
//!
//! One `#[test]` per mesh so that they run in parallel; release only.

use conemesh::invariants::{certify_boundary_on_curves, certify_same_topology, self_intersections};
use conemesh::metric::{MetricField, MetricOptions, Normalization};
use conemesh::pipeline::{remesh, RemeshOptions, RemeshReport, Stages};
use conemesh::quality::{evaluate, flips, EvalOptions, EvalReport};
use conemesh::Topology;
use sha2::{Digest, Sha256};
use std::time::Instant;

mod common;

const SEED: u64 = 1;

/// 3 significant digits (0 stays 0), so the snapshot is stable to float noise.
fn r3(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let m = 10f64.powi(2 - x.abs().log10().floor() as i32);
    (x * m).round() / m
}

fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Run the pipeline on one shared mesh, assert every certificate (and the catalogue's
/// boundary loops on input and output), snapshot the summary; returns the run's report and
/// the evaluation of its file-unit output.
fn remesh_shared(name: &str) -> (RemeshReport, EvalReport) {
    let boundary_loops = common::shared_mesh(name).boundary_loops;
    let file_mesh = common::load_referenced(name);
    let input_topo = Topology::build(&file_mesh);
    assert_eq!(
        input_topo.boundary_loops().len(),
        boundary_loops,
        "{name}: input boundary loops"
    );
    let norm = Normalization::of(&file_mesh);
    let t0 = Instant::now();
    let field = MetricField::from_curvature(norm.apply(&file_mesh), &MetricOptions::default())
        .expect("curvature metric");
    let options = RemeshOptions {
        seed: SEED,
        ..RemeshOptions::default()
    };
    let result = remesh(&field, &Stages::default(), &options, |_| {})
        .unwrap_or_else(|e| panic!("{name}: remesh failed: {e}"));
    let secs = t0.elapsed().as_secs_f64();
    let r = &result.report;
    let c = &r.certificate;
    let n = r.patches;
    let kept = r.patch_records.iter().filter(|p| p.kept).count();

    // Certificates: once per patch on the working mesh, once per remeshed (not kept) patch
    // on the candidate, once per attempt for the disk; the final exact self-intersection test.
    assert!(n > 0 && n <= file_mesh.n_faces(), "{name}: {n} patches");
    for (what, count) in [
        ("manifold", c.manifold),
        ("oriented", c.oriented),
        ("same_topology", c.same_topology),
        ("boundary_preserved", c.boundary_preserved),
    ] {
        assert_eq!(
            count, n,
            "{name}: {what} held {count} times for {n} patches"
        );
    }
    // A candidate that passed these two and then crossed the faces around it (exact) was
    // certified too, and retried smaller.
    let crossed = r
        .fallbacks
        .failures
        .iter()
        .filter(|f| {
            matches!(
                f.error,
                conemesh::pipeline::StageError::Certificate(
                    conemesh::invariants::InvariantError::SelfIntersections(_)
                )
            )
        })
        .count();
    assert_eq!(c.no_degenerate, n - kept + crossed, "{name}: no_degenerate");
    assert_eq!(c.no_flips, n - kept + crossed, "{name}: no_flips");
    assert_eq!(
        c.disk,
        n - kept + r.fallbacks.failures.len(),
        "{name}: disk certified once per attempt"
    );
    assert!(c.bijective >= n - kept && c.planar >= n - kept && c.planar <= c.bijective);
    assert_eq!(
        c.no_self_intersections, 1,
        "{name}: final self-intersection test"
    );

    // Independent re-checks on the unit-space output against the unit-space reference.
    let reference = field.reference();
    let out_topo = Topology::build(&result.mesh);
    assert!(out_topo.is_oriented_manifold(), "{name}: oriented manifold");
    certify_same_topology(reference, &result.mesh)
        .unwrap_or_else(|e| panic!("{name}: topology changed: {e}"));
    certify_boundary_on_curves(
        &result.curves,
        reference,
        &result.mesh,
        &out_topo,
        &result.curve,
    )
    .unwrap_or_else(|e| panic!("{name}: boundary not on the input's curves: {e}"));
    assert_eq!(out_topo.boundary_loops().len(), boundary_loops, "{name}");
    let flipped = flips(reference, &result.mesh);
    assert!(
        flipped.is_empty(),
        "{name}: {} flipped faces",
        flipped.len()
    );
    let si = self_intersections(&result.mesh);
    assert!(
        si.is_empty(),
        "{name}: self-intersections {:?}",
        &si[..si.len().min(5)]
    );

    // The quality row, measured in file units like `conemesh eval` (its own exact
    // self-intersection search runs on the file-unit coordinates).
    let out_file = norm.unapply(&result.mesh);
    let eval = evaluate(&file_mesh, &out_file, None, &EvalOptions::default()).expect("eval");
    assert!(eval.flips.is_empty(), "{name}: eval flips");
    assert!(
        eval.self_intersections.is_empty(),
        "{name}: self-intersections in file units"
    );
    assert!(eval.topology_kept, "{name}: {:?}", eval.topology_detail);

    let dir = tempfile::tempdir().expect("tempdir");
    let obj = dir.path().join("out.obj");
    conemesh::io::write_mesh(&obj, &out_file).expect("write OBJ");
    let hash = sha256_hex(&std::fs::read(&obj).expect("read back OBJ"));

    let q = &eval.output_quality;
    eprintln!(
        "{name}: {} -> {} faces, {n} patches ({kept} kept, {} failed attempts), \
         q {:.3}/{:.3}, θ {:.2}°/{:.2}°, Hausdorff {:.4}% of diag, {secs:.2} s remesh",
        r.faces_in,
        r.faces_out,
        r.fallbacks.failures.len(),
        q.q_min,
        q.q_avg,
        q.theta_min,
        q.theta_avg,
        100.0 * eval.distance.hausdorff_rel,
    );
    let summary = serde_json::json!({
        "mesh": name,
        "seed": SEED,
        "faces_in": r.faces_in,
        "faces_out": r.faces_out,
        "vertices_out": r.vertices_out,
        "patches": n,
        "kept_patches": kept,
        "q_min": r3(q.q_min),
        "q_avg": r3(q.q_avg),
        "theta_min_deg": r3(q.theta_min),
        "theta_avg_deg": r3(q.theta_avg),
        "hausdorff_rel": r3(eval.distance.hausdorff_rel),
        "flips": eval.flips.len(),
        "boundary_loops": boundary_loops,
        "obj_sha256": hash,
    });
    let snap = format!("pipeline_{}", name.replace(['.', '-'], "_"));
    insta::with_settings!({
        snapshot_path => concat!(env!("CARGO_MANIFEST_DIR"), "/snapshots"),
        prepend_module_to_snapshot => false,
    }, {
        insta::assert_json_snapshot!(snap, summary);
    });
    (result.report, eval)
}

/// One release-only test per mesh, so that they run in parallel.
macro_rules! end_to_end_tests {
    ($($test:ident => $file:literal),* $(,)?) => {
        $(
            #[test]
            #[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
            fn $test() {
                remesh_shared($file);
            }
        )*
    };
}

end_to_end_tests! {
    fertility_end_to_end => "fertility.off",
    three_holes_end_to_end => "3holes.off",
    screwdriver_end_to_end => "screwdriver.off",
    // The catalogue's 5 open boundary loops, kept.
    stanford_bunny_keeps_its_five_open_boundaries => "stanford-bunny.obj",
}

/// decimated-knight (1,000 faces, piecewise flat): the run finds that the distance tolerance,
/// not the metric, sets its size, runs the coarse-input profile, and meets issue 9's targets
/// (measured by `eval` against the input at 1.5·L_avg), which the paper's settings miss
/// (`tests/pipeline_coarse.rs`).
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn decimated_knight_meets_the_targets_with_the_coarse_profile() {
    let (r, eval) = remesh_shared("decimated-knight.off");
    assert!(r.coarse_input, "the coarse-input profile ran");
    assert!(r.expected_faces_fidelity >= 2.0 * r.expected_faces);
    assert_eq!(r.options.sweeps, 3);
    assert!(r.options.fidelity.persist);
    let q = &eval.output_quality;
    assert!(q.q_avg >= 0.85, "q_avg {}", q.q_avg);
    assert!(q.theta_avg >= 47.0, "θ_avg {}", q.theta_avg);
    assert!(eval.flips.is_empty());
    assert!(
        eval.distance.hausdorff_rel <= 0.01,
        "Hausdorff {}",
        eval.distance.hausdorff_rel
    );
}
