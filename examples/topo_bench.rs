//! Time `Topology::build` and the manifold certificate on a mesh (the per-patch cost of
//! Algorithm 1's certificates). `cargo run --release --example topo_bench -- MESH [REPS]`.
use conemesh::mesh::Topology;
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let mesh = conemesh::io::read_mesh(std::path::Path::new(&a[1]))
        .expect("mesh")
        .mesh;
    let reps: usize = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(20);
    let t0 = Instant::now();
    let mut topo = Topology::build(&mesh);
    for _ in 1..reps {
        topo = Topology::build(&mesh);
    }
    let build = t0.elapsed().as_secs_f64() / reps as f64;
    let t0 = Instant::now();
    for _ in 0..reps {
        conemesh::invariants::certify_manifold(&mesh, &topo).expect("manifold");
    }
    let manifold = t0.elapsed().as_secs_f64() / reps as f64;
    println!(
        "{} faces: build {:.2} ms, certify_manifold {:.2} ms",
        mesh.n_faces(),
        1e3 * build,
        1e3 * manifold
    );
}
