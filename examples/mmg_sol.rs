//! Writes the MMG metric of PEERS.md for a mesh: the curvature metric of Sec. 3.1 divided by
//! L_tar² (L_tar = F · L_avg), with the normal eigenvalue set to the larger tangent one,
//! for the input scaled to bounding-box diagonal 1 (as PEERS.md measured MMG: its `-hausd`
//! default is absolute), written as `OUT.mesh` + `OUT.sol` (Medit; ASCII tensor order of
//! `io::sol`). Score MMG's output with `conemesh eval --input OUT.mesh --output RESULT.mesh`.
//! `cargo run --release --example mmg_sol -- MESH OUT [F]`.
use conemesh::metric::{MetricField, MetricOptions, Normalization};
use nalgebra::{Matrix3, SymmetricEigen};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let mesh = conemesh::io::read_mesh(std::path::Path::new(&a[1]))
        .expect("mesh")
        .mesh;
    let f: f64 = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(1.5);
    let norm = Normalization::of(&mesh);
    let unit = norm.apply(&mesh);
    let field =
        MetricField::from_curvature(unit.clone(), &MetricOptions::default()).expect("metric");
    let eval = conemesh::quality::evaluate(
        &mesh,
        &mesh,
        None,
        &conemesh::quality::EvalOptions {
            self_intersections: false,
            ..Default::default()
        },
    )
    .expect("eval");
    let l_tar = f * eval.l_avg;
    let m: Vec<Matrix3<f64>> = field
        .vertex_metrics()
        .iter()
        .map(|m| {
            let e = SymmetricEigen::new((m + m.transpose()) * 0.5);
            let lmax = e.eigenvalues.max();
            let vals = e.eigenvalues.map(|l| {
                if l < 1e-12 * lmax.max(1e-300) {
                    lmax
                } else {
                    l
                }
            });
            let m = e.eigenvectors * Matrix3::from_diagonal(&vals) * e.eigenvectors.transpose();
            m / (l_tar * l_tar)
        })
        .collect();
    conemesh::io::write_mesh(std::path::Path::new(&format!("{}.mesh", a[2])), &unit)
        .expect("write");
    conemesh::io::sol::write_sol(std::path::Path::new(&format!("{}.sol", a[2])), &m, false)
        .expect("write");
    eprintln!("L_avg {} L_tar {}", eval.l_avg, l_tar);
}
