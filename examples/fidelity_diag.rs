//! Where does the two-sided Hausdorff distance of a remesh come from? Prints the worst sample
//! points of each side with the local curvature (5-ring and 2-ring fits) and crease angle of the
//! input there. `cargo run --release --example fidelity_diag -- INPUT OUTPUT [N]`.

use conemesh::mesh::SurfaceProjector;
use conemesh::metric::{principal_curvatures, CurvatureOptions, Normalization};
use conemesh::{FaceId, TriMesh};
use nalgebra::Point3;

fn load(p: &str) -> TriMesh {
    let m = conemesh::io::read_mesh(std::path::Path::new(p))
        .expect("read")
        .mesh;
    m.without_unreferenced_vertices().0
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let input = load(&a[1]);
    let output = load(&a[2]);
    let n: usize = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(8);
    let norm = Normalization::of(&input);
    let (ui, uo) = (norm.apply(&input), norm.apply(&output));
    let pc5 = principal_curvatures(&ui, &CurvatureOptions::default()).expect("pc");
    let pc2 = principal_curvatures(&ui, &CurvatureOptions { radius: 2 }).expect("pc");
    let pi = SurfaceProjector::new(&ui);
    let po = SurfaceProjector::new(&uo);
    // Dense samples, deterministic: a regular grid of N = $DIAG_N (default 5) steps per face
    // side, edges included (the largest distances of a piecewise-flat input sit on its
    // creases, i.e. on face edges).
    let steps: usize = std::env::var("DIAG_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(5);
    let samples = |m: &TriMesh| -> Vec<Point3<f64>> {
        let mut v = m.positions.clone();
        for f in m.faces() {
            let [p, q, r] = m.face_points(f);
            for i in 0..=steps {
                for j in 0..=(steps - i) {
                    let (u, w) = (i as f64 / steps as f64, j as f64 / steps as f64);
                    v.push(Point3::from(
                        p.coords * (1.0 - u - w) + q.coords * u + r.coords * w,
                    ));
                }
            }
        }
        v
    };
    let nearest_vertex = |m: &TriMesh, f: FaceId, c: &Point3<f64>| {
        let t = m.triangles[f.idx()];
        *t.iter()
            .min_by(|x, y| {
                (m.positions[x.idx()] - c)
                    .norm()
                    .total_cmp(&(m.positions[y.idx()] - c).norm())
            })
            .expect("3")
    };
    for (name, from, to) in [("input→output", &ui, &po), ("output→input", &uo, &pi)] {
        let mut d: Vec<(f64, Point3<f64>)> = samples(from)
            .into_iter()
            .filter_map(|p| to.closest(&p).map(|(_, _, d)| (d, p)))
            .collect();
        d.sort_by(|x, y| y.0.total_cmp(&x.0));
        println!("== {name}: max {:.3} % diag", 100.0 * d[0].0);
        let mut shown: Vec<Point3<f64>> = Vec::new();
        for (dist, p) in d {
            if shown.len() >= n {
                break;
            }
            if shown.iter().any(|s| (s - p).norm() < 0.03) {
                continue;
            }
            shown.push(p);
            let (fi, ci, _) = pi.closest(&p).expect("closest");
            let v = nearest_vertex(&ui, fi, &ci);
            let (k5, k2) = (&pc5[v.idx()], &pc2[v.idx()]);
            // output edge length around the closest output face
            let (fo, _, _) = po.closest(&p).expect("closest");
            let [x, y, z] = uo.face_points(fo);
            let h = (x - y).norm().max((y - z).norm()).max((z - x).norm());
            println!(
                "  {:.3}%  at ({:.3},{:.3},{:.3}) {v}  k5=({:.1},{:.1}) k2=({:.1},{:.1})  out-edge {:.4} chord k5 {:.3}% k2 {:.3}%",
                100.0 * dist, p.x, p.y, p.z, k5.k1, k5.k2, k2.k1, k2.k2, h,
                100.0 * k5.k1.abs().max(k5.k2.abs()) * h * h / 8.0,
                100.0 * k2.k1.abs().max(k2.k2.abs()) * h * h / 8.0,
            );
        }
    }
}
