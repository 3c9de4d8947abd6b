//! Review 6: a target length far below the input's edges, with feature lines on, must be an
//! input error (the run's contract: a certified mesh or a named error), not a panic in
//! `split_feature_edges` (`(1..k).collect()` with k = round(ℓ_M / L_tar) ≈ 1e19 → "capacity
//! overflow"). Without `feature_angle` the same options do not panic up front.

use conemesh::metric::{MetricField, MetricOptions, Normalization};
use conemesh::mesh::generators;
use conemesh::pipeline::{remesh, PipelineError, RemeshOptions, Stages};
use conemesh::quality::TargetLength;

#[test]
fn review_tiny_target_with_feature_lines_is_an_error_not_a_panic() {
    let m = generators::lens(50f64.to_radians(), 8, 40);
    let m = Normalization::of(&m).apply(&m);
    let f = MetricField::from_curvature(m, &MetricOptions::default()).expect("metric");
    let o = RemeshOptions {
        feature_angle: Some(60.0),
        target: TargetLength::Absolute(1e-20),
        ..RemeshOptions::default()
    };
    let got = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        remesh(&f, &Stages::default(), &o, |_| {}).map(|_| ())
    }));
    match got {
        Err(_) => panic!("remesh panicked (split_feature_edges: capacity overflow)"),
        Ok(Err(PipelineError::Input(_))) => {}
        Ok(other) => panic!("expected an input error, got {other:?}"),
    }
}
