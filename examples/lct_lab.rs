//! Planar remesher experiments: constant metrics of several anisotropy ratios and directions
//! on the unit square, boundary resampled to the metric, remeshed by a registered planar
//! remesher. `cargo run --release --example lct_lab -- [KEY=VALUE ...]` (remesher options).
use conemesh::registry::Params;
use conemesh::remesh2d::{planar_quality, resample_polygon, triangulate_polygon, Metric2d};
use nalgebra::{Matrix2, Point2, Rotation2};
use rand::SeedableRng;

struct Constant(Matrix2<f64>);
impl Metric2d for Constant {
    fn metric(&self, _p: &Point2<f64>) -> Matrix2<f64> {
        self.0
    }
}

fn main() {
    let opts: Vec<String> = std::env::args().skip(1).collect();
    let remesher =
        conemesh::remesh2d::planar_remesher("lct", Params::parse(&opts).expect("KEY=VALUE"))
            .expect("options");
    let corners = [
        Point2::new(0.0, 0.0),
        Point2::new(1.0, 0.0),
        Point2::new(1.0, 1.0),
        Point2::new(0.0, 1.0),
    ];
    let (mut qs, mut ts, mut rs) = (0.0, 0.0f64, 0.0);
    let mut n = 0.0;
    for (ratio, angle) in [
        (1.0, 0.0),
        (10.0, 0.0),
        (10.0, 30.0),
        (30.0, 0.0),
        (100.0, 0.0),
        (100.0, 20.0),
    ] {
        let h_along: f64 = 0.1;
        let h_across = h_along / ratio;
        let r = Rotation2::new(f64::to_radians(angle)).into_inner();
        let m =
            r * Matrix2::new(
                1.0 / (h_across * h_across),
                0.0,
                0.0,
                1.0 / (h_along * h_along),
            ) * r.transpose();
        // Keep the output near 4,000 triangles: scale the square.
        let area = 4000.0 * (3f64.sqrt() / 4.0) * h_across * h_along;
        let s = area.sqrt();
        let aspect: f64 = std::env::var("ASPECT")
            .ok()
            .and_then(|a| a.parse().ok())
            .unwrap_or(1.0);
        let c: Vec<Point2<f64>> = corners
            .iter()
            .map(|p| Point2::new(p.x * s * aspect.sqrt(), p.y * s / aspect.sqrt()))
            .collect();
        let metric = Constant(m);
        let boundary = resample_polygon(&c, &metric, 1.0);
        let dom = triangulate_polygon(&boundary, &[]).expect("domain");
        let t0 = std::time::Instant::now();
        let out = remesher
            .remesh(
                &dom,
                &metric,
                1.0,
                &mut rand_chacha::ChaCha8Rng::seed_from_u64(1),
            )
            .expect("remesh");
        let q = planar_quality(&out, &metric, 1.0);
        println!("ratio {ratio:>5} angle {angle:>4}: F {:>6} q_min {:.3} q_avg {:.3} θ_min {:>6.2} θ_avg {:.2} L {:.3} in-range {:.1}% {:.2}s", out.triangles.len(), q.q_min, q.q_avg, q.theta_min_deg, q.theta_avg_deg, q.edge_mean, 100.0 * q.edges_in_range, t0.elapsed().as_secs_f64());
        qs += q.q_avg;
        ts = ts.max(-q.theta_min_deg);
        rs += q.edges_in_range;
        n += 1.0;
    }
    println!(
        "mean q_avg {:.3}, worst θ_min {:.2}, mean in-range {:.1}%",
        qs / n,
        -ts,
        100.0 * rs / n
    );
}
