//! The standalone 2D anisotropic mesher (Sec. 3.3, LCT): a square and an L-shaped domain under
//! three analytic metrics. `cargo run --release --example remesh2d -- [--json] [--big]`
//! (`--big`: also time a ~20,000-triangle output).

use conemesh::remesh2d::{demo_cases, run_demo_case, DemoDomain, DemoMetric};
use std::io::Write;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let json = args.iter().any(|a| a == "--json");
    let big = args.iter().any(|a| a == "--big");
    let mut cases: Vec<(DemoDomain, DemoMetric, f64)> = demo_cases()
        .into_iter()
        .map(|(d, m)| (d, m, m.target_length()))
        .collect();
    if big {
        cases.push((DemoDomain::Square, DemoMetric::UniformIsotropic, 0.0107));
    }
    let mut rows = Vec::new();
    let mut out = std::io::stdout().lock();
    if !json {
        writeln!(
            out,
            "{:<8} {:<15} {:>6} {:>6} {:>6} {:>6} {:>11} {:>11} {:>8} {:>8}",
            "domain", "metric", "L", "V", "F", "q_min", "q_avg", "θ_min", "θ_avg", "in-range"
        )?;
    }
    for (d, m, l) in cases {
        let t0 = Instant::now();
        let (_, q) = run_demo_case(d, m, l)?;
        let secs = t0.elapsed().as_secs_f64();
        if json {
            rows.push(serde_json::json!({
                "domain": d.name(), "metric": m.name(), "target_length": l, "seconds": secs,
                "quality": q,
            }));
        } else {
            writeln!(
                out,
                "{:<8} {:<15} {:>6} {:>6} {:>6} {:>6.3} {:>11.3} {:>10.2}° {:>7.2}° {:>7.1}%   ({secs:.2} s)",
                d.name(),
                m.name(),
                l,
                q.n_vertices,
                q.n_faces,
                q.q_min,
                q.q_avg,
                q.theta_min_deg,
                q.theta_avg_deg,
                100.0 * q.edges_in_range
            )?;
        }
    }
    if json {
        writeln!(out, "{}", serde_json::to_string_pretty(&rows)?)?;
    }
    Ok(())
}
