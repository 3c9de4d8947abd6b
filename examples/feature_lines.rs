//! The feature lines `--feature-angle auto` picks on a mesh, one chain per line: edges, length
//! (fraction of the bounding-box diagonal), smallest and mean dihedral angle, largest turn
//! between consecutive edges, whether it is closed, and how many of its ends are free (no other
//! feature edge there, not on the boundary). Diagnostics for the automatic rule (issue 20).
//! `cargo run --release --example feature_lines -- MESH [RULE]`

use conemesh::features::{feature_chains, FeatureRule};
use conemesh::mesh::Topology;
use std::collections::HashMap;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let Some(path) = a.get(1) else {
        eprintln!("usage: feature_lines MESH [RULE]");
        std::process::exit(2);
    };
    let rule = FeatureRule::parse(a.get(2).map_or("auto", |s| s.as_str())).expect("rule");
    let mesh = match conemesh::io::read_mesh(std::path::Path::new(path)) {
        Ok(m) => m.mesh.without_unreferenced_vertices().0,
        Err(e) => {
            eprintln!("{path}: {e}");
            std::process::exit(2);
        }
    };
    let topo = Topology::build(&mesh);
    let sharp = rule.edges(&mesh, &topo);
    // Dihedral angle (between normals, degrees) of every interior edge.
    let mut dihedral = HashMap::new();
    for f in mesh.faces() {
        let t = mesh.face(f);
        for i in 0..3 {
            if let Some(g) = topo.neighbor(f, i) {
                let c = mesh
                    .face_normal(f)
                    .dot(&mesh.face_normal(g))
                    .clamp(-1.0, 1.0);
                dihedral.insert(
                    conemesh::ids::EdgeKey::new(t[i], t[(i + 1) % 3]),
                    c.acos().to_degrees(),
                );
            }
        }
    }
    let diag = mesh.bbox_diagonal();
    // Feature edges at each vertex: a chain's end where only its own edge meets is free.
    let mut degree: HashMap<conemesh::ids::VertexId, usize> = HashMap::new();
    for e in &sharp {
        *degree.entry(e.0).or_default() += 1;
        *degree.entry(e.1).or_default() += 1;
    }
    let chains = feature_chains(&mesh, &topo, &sharp, &[]);
    println!(
        "{path}: {} feature edges in {} chains",
        sharp.len(),
        chains.len()
    );
    for c in &chains {
        let p = |k: usize| mesh.positions[c[k].idx()];
        let len: f64 = (1..c.len()).map(|k| (p(k) - p(k - 1)).norm()).sum();
        let angles: Vec<f64> = c
            .windows(2)
            .map(|w| dihedral[&conemesh::ids::EdgeKey::new(w[0], w[1])])
            .collect();
        let turn = (1..c.len() - 1)
            .map(|k| (p(k) - p(k - 1)).angle(&(p(k + 1) - p(k))).to_degrees())
            .fold(0.0, f64::max);
        println!(
            "edges {:4} length {:.4} dihedral min {:5.1} mean {:5.1} turn max {:5.1} closed {} free ends {}",
            c.len() - 1,
            len / diag,
            angles.iter().copied().fold(f64::INFINITY, f64::min),
            angles.iter().sum::<f64>() / angles.len() as f64,
            turn,
            c.first() == c.last(),
            [c[0], c[c.len() - 1]]
                .iter()
                .filter(|v| degree.get(v) == Some(&1) && !topo.is_boundary_vertex(**v))
                .count()
        );
    }
}
