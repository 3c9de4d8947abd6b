//! The standalone 2D mesher's table (`examples/remesh2d.rs`): an insta snapshot (rounded to 3
//! digits) and the targets, q_avg ≥ 0.90 and θ_avg ≥ 50° on every analytic case.

use conemesh::remesh2d::{demo_cases, run_demo_case, Remesh2dError};

#[test]
fn example_table_meets_targets_and_matches_snapshot() -> Result<(), Remesh2dError> {
    let mut rows = Vec::new();
    for (d, m) in demo_cases() {
        let (_, q) = run_demo_case(d, m, m.target_length())?;
        assert!(q.q_avg >= 0.90, "{} {}: {q:?}", d.name(), m.name());
        assert!(q.theta_avg_deg >= 50.0, "{} {}: {q:?}", d.name(), m.name());
        assert!(q.edges_in_range >= 0.90, "{} {}: {q:?}", d.name(), m.name());
        rows.push(format!(
            "{:<8} {:<15} L={:<5} V={:<5} F={:<5} q={:.3}/{:.3} θ={:.1}°/{:.1}° in-range={:.3}",
            d.name(),
            m.name(),
            m.target_length(),
            q.n_vertices,
            q.n_faces,
            q.q_min,
            q.q_avg,
            q.theta_min_deg,
            q.theta_avg_deg,
            q.edges_in_range
        ));
    }
    rows.sort();
    insta::with_settings!({
        snapshot_path => concat!(env!("CARGO_MANIFEST_DIR"), "/snapshots"),
        prepend_module_to_snapshot => false,
    }, {
        insta::assert_snapshot!("remesh2d_example_table", rows.join("\n"));
    });
    Ok(())
}
