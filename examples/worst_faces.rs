//! The worst faces of a remesh, one by one: smallest angle and q in the metric, each corner's
//! angle, whether its vertices are input corners (cone points kept by the corner rule) or on
//! the boundary, and the edge lengths over L_tar. Diagnostics for Algorithm 2 (issue 18).
//! `cargo run --release --example worst_faces -- MESH [N] [--no-improve] [--metric M.sol]
//! [--feature-angle RULE]` (with a metric: L_tar = 1, as `bench --suite analytic`). Vertex
//! tags: C input corner, B boundary, F on an input feature edge.

use conemesh::mesh::Topology;
use conemesh::pipeline::{RemeshOptions, Remesher, Stages};
use conemesh::quality::face_qualities;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let Some(path) = a.get(1) else {
        eprintln!("usage: worst_faces MESH [N] [--no-improve] [--metric M.sol]");
        std::process::exit(2);
    };
    let n: usize = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(12);
    let input = match conemesh::io::read_mesh(std::path::Path::new(path)) {
        Ok(m) => m.mesh,
        Err(e) => {
            eprintln!("{path}: {e}");
            std::process::exit(2);
        }
    };
    let metric_path = a
        .iter()
        .position(|s| s == "--metric")
        .and_then(|i| a.get(i + 1));
    let metric = match metric_path
        .map(|p| conemesh::io::sol::read_sol(std::path::Path::new(p), input.n_vertices()))
    {
        Some(Ok(m)) => Some(m),
        Some(Err(e)) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
        None => None,
    };
    let mut stages = match metric {
        Some(_) => Stages::for_sizes(conemesh::registry::MetricSizes::Absolute),
        None => Stages::default(),
    };
    if a.iter().any(|s| s == "--no-improve") {
        stages.improvers.retain(|i| i.name() != "eq5");
    }
    let options = RemeshOptions {
        target: match metric {
            Some(_) => conemesh::pipeline::TargetLength::Absolute(1.0),
            None => conemesh::pipeline::TargetLength::Factor(1.5),
        },
        features: options_features(&a),
        ..RemeshOptions::default()
    };
    let out =
        match Remesher::new(options)
            .with_stages(stages)
            .run_with(&input, metric.as_deref(), |_| {})
        {
            Ok(o) => o,
            Err(e) => {
                eprintln!("{path}: {e}");
                std::process::exit(1);
            }
        };
    let unit = &out.unit;
    let l_tar = unit.report.l_tar;
    let ref_mesh = out.field.reference();
    let ref_topo = Topology::build(ref_mesh);
    let corners = conemesh::patches::corner_vertices(ref_mesh, &ref_topo, 1.0);
    let corner_pos: Vec<_> = ref_mesh
        .vertices()
        .filter(|v| corners[v.idx()])
        .map(|v| *ref_mesh.position(v))
        .collect();
    let feature_segments: Vec<_> = options_features(&a)
        .edges(ref_mesh, &ref_topo)
        .into_iter()
        .map(|e| (*ref_mesh.position(e.0), *ref_mesh.position(e.1)))
        .collect();
    let mesh = &unit.mesh;
    let topo = Topology::build(mesh);
    let metrics: Vec<_> = unit
        .locations
        .iter()
        .map(|l| out.field.eval_at(l))
        .collect();
    let qs = face_qualities(mesh, &metrics);
    let mut order: Vec<usize> = (0..qs.len()).collect();
    order.sort_by(|&x, &y| qs[x].min_angle().total_cmp(&qs[y].min_angle()));
    println!("L_tar {l_tar:.4}; {} corners kept", corner_pos.len());
    for &f in order.iter().take(n) {
        let fid = conemesh::FaceId::new(f);
        let t = mesh.face(fid);
        let tag = |v: conemesh::VertexId| {
            let p = mesh.position(v);
            let c = corner_pos.iter().any(|c| c == p);
            let b = topo.is_boundary_vertex(v);
            let on_feature = feature_segments.iter().any(|(a, b)| {
                let ab = b - a;
                let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                (p - (a + ab * t)).norm() < 1e-12
            });
            match (c, b, on_feature) {
                (true, _, _) => "C",
                (false, true, _) => "B",
                (_, _, true) => "F",
                _ => "-",
            }
        };
        let m = (metrics[t[0].idx()] + metrics[t[1].idx()] + metrics[t[2].idx()]) / 3.0;
        let len = |i: usize, j: usize| {
            let d = mesh.position(t[j]) - mesh.position(t[i]);
            (d.transpose() * m * d)[(0, 0)].max(0.0).sqrt() / l_tar
        };
        println!(
            "f{f}: θ_min {:.2}° q {:.3} angles {:.1}/{:.1}/{:.1} vertices {}{}{} edges/L_tar {:.2} {:.2} {:.2} patch {:?}",
            qs[f].min_angle(),
            qs[f].q,
            qs[f].angles[0],
            qs[f].angles[1],
            qs[f].angles[2],
            tag(t[0]),
            tag(t[1]),
            tag(t[2]),
            len(0, 1),
            len(1, 2),
            len(2, 0),
            unit.face_patch[f].map(|p| p.idx()),
        );
    }
}

fn options_features(a: &[String]) -> conemesh::features::FeatureRule {
    a.iter()
        .position(|s| s == "--feature-angle")
        .and_then(|i| a.get(i + 1))
        .map(|r| conemesh::features::FeatureRule::parse(r).expect("feature rule"))
        .unwrap_or_default()
}
