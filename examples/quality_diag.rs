//! Where does the quality deficit (1 − q) of a remesh come from? Runs Algorithm 1 with the
//! CLI's defaults (seed 1, L_tar = 1.5·L_avg) and splits the output faces by provenance:
//! kept input faces, faces on a seam between two patches (an edge shared with a face of
//! another patch), faces near an input self-intersection, faces of shrunk (retried) patches,
//! and the rest. `cargo run --release --example quality_diag -- MESH [radius]`.

use conemesh::mesh::SurfaceProjector;
use conemesh::metric::{MetricField, MetricOptions, Normalization};
use conemesh::pipeline::{remesh, RemeshOptions, Stages};
use conemesh::quality::face_qualities;
use conemesh::{EdgeKey, FaceId, TriMesh};
use nalgebra::Point3;
use std::collections::HashMap;

#[allow(clippy::needless_range_loop)]
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let input = conemesh::io::read_mesh(std::path::Path::new(&a[1]))
        .expect("read")
        .mesh
        .without_unreferenced_vertices()
        .0;
    let radius: f64 = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(0.01);
    let unit = Normalization::of(&input).apply(&input);
    let options = RemeshOptions {
        sweeps: std::env::var("SWEEPS")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(1),
        features: std::env::var("FEATURE")
            .ok()
            .map(|s| conemesh::features::FeatureRule::parse(&s).expect("FEATURE"))
            .unwrap_or_default(),
        ..RemeshOptions::default()
    };
    let field = MetricField::from_curvature(
        unit.clone(),
        &MetricOptions {
            features: options.features,
            ..MetricOptions::default()
        },
    )
    .expect("m");
    let res = remesh(&field, &Stages::default(), &options, |_| {}).expect("run");
    let out = &res.mesh;
    let metrics: Vec<_> = out.positions.iter().map(|p| field.eval(p)).collect();
    let qs = face_qualities(out, &metrics);
    // Seam edges: the two faces come from different patches (or one is a kept input face).
    let mut edge_faces: HashMap<EdgeKey, Vec<usize>> = HashMap::new();
    for (f, t) in out.triangles.iter().enumerate() {
        for k in 0..3 {
            edge_faces
                .entry(EdgeKey::new(t[k], t[(k + 1) % 3]))
                .or_default()
                .push(f);
        }
    }
    let mut on_seam = vec![false; out.n_faces()];
    let mut seam_vertex = vec![false; out.n_vertices()];
    for (e, fs) in &edge_faces {
        if fs.len() == 2 && res.face_patch[fs[0]] != res.face_patch[fs[1]] {
            on_seam[fs[0]] = true;
            on_seam[fs[1]] = true;
            seam_vertex[e.0.idx()] = true;
            seam_vertex[e.1.idx()] = true;
        }
    }
    // Input faces involved in a self-intersection, and a projector onto them.
    let si = conemesh::invariants::self_intersections(&unit);
    let mut si_faces: Vec<FaceId> = si.iter().flat_map(|(x, y)| [*x, *y]).collect();
    si_faces.sort();
    si_faces.dedup();
    let si_mesh = TriMesh {
        positions: unit.positions.clone(),
        triangles: si_faces.iter().map(|f| unit.triangles[f.idx()]).collect(),
    };
    let si_proj = SurfaceProjector::new(&si_mesh);
    if let Ok(path) = std::env::var("SI_DUMP") {
        let txt: String = si_faces
            .iter()
            .map(|f| {
                let [p, q, r] = unit.face_points(*f);
                let c = (p.coords + q.coords + r.coords) / 3.0;
                format!("{} {} {} {}\n", f.0, c.x, c.y, c.z)
            })
            .collect();
        std::fs::write(path, txt).expect("dump");
    }
    let retried: Vec<bool> = res
        .report
        .patch_records
        .iter()
        .map(|r| r.retries > 0)
        .collect();
    let n = out.n_faces() as f64;
    let total_def: f64 = qs.iter().map(|q| 1.0 - q.q).sum();
    let kept_input = res.face_patch.iter().filter(|p| p.is_none()).count();
    println!(
        "{} of the output faces are input faces no patch replaced",
        kept_input
    );
    println!(
        "{}: {} faces, q_avg {:.4}, θ_avg {:.2}, {} patches, {} SI input faces",
        a[1],
        out.n_faces(),
        qs.iter().map(|q| q.q).sum::<f64>() / n,
        qs.iter().map(|q| q.min_angle()).sum::<f64>() / n,
        res.report.patches,
        si_faces.len()
    );
    // Output vertices at an input corner (`RemeshOptions::corner_defect`): exact positions.
    let corner_pos: std::collections::HashSet<[u64; 3]> = {
        let topo = conemesh::Topology::build(&unit);
        let c = conemesh::patches::corner_vertices(&unit, &topo, 1.0);
        (0..unit.n_vertices())
            .filter(|&v| c[v])
            .map(|v| unit.positions[v].coords.map(f64::to_bits).into())
            .collect()
    };
    let at_corner = |v: conemesh::VertexId| {
        let b: [u64; 3] = out.positions[v.idx()].coords.map(f64::to_bits).into();
        corner_pos.contains(&b)
    };
    // Output vertices on a feature line (`FEATURE` degrees): located on a sharp input edge.
    let sharp: std::collections::HashSet<EdgeKey> = options
        .features
        .edges(&unit, &conemesh::Topology::build(&unit))
        .into_iter()
        .collect();
    let on_feature = |v: conemesh::VertexId| {
        let l = res.locations[v.idx()];
        let t = unit.triangles[l.face.idx()];
        (0..3).any(|k| {
            l.bary[(k + 2) % 3] == 0.0 && sharp.contains(&EdgeKey::new(t[k], t[(k + 1) % 3]))
        })
    };
    let classes = [
        "kept",
        "feature",
        "corner fan",
        "near SI",
        "seam edge",
        "seam vertex",
        "retried",
        "interior",
    ];
    let mut stats = vec![(0usize, 0.0f64, 0.0f64, 0usize); classes.len()];
    for (f, t) in out.triangles.iter().enumerate() {
        let [p, q, r] = out.face_points(FaceId::new(f));
        let c = Point3::from((p.coords + q.coords + r.coords) / 3.0);
        let near_si = si_proj
            .closest(&c)
            .map(|(_, _, d)| d < radius)
            .unwrap_or(false);
        let class = if res.face_patch[f].is_none() {
            0
        } else if t.iter().any(|v| on_feature(*v)) {
            1
        } else if t.iter().any(|v| at_corner(*v)) {
            2
        } else if near_si {
            3
        } else if on_seam[f] {
            4
        } else if t.iter().any(|v| seam_vertex[v.idx()]) {
            5
        } else if res.face_patch[f].map(|p| retried[p.idx()]).unwrap_or(false) {
            6
        } else {
            7
        };
        let s = &mut stats[class];
        s.0 += 1;
        s.1 += 1.0 - qs[f].q;
        s.2 += qs[f].min_angle();
        if qs[f].q < 0.5 {
            s.3 += 1;
        }
    }
    println!(
        "{:12} {:>6} {:>7} {:>8} {:>7} {:>6}",
        "class", "faces", "q_avg", "def.share", "θ_avg", "q<0.5"
    );
    for (c, s) in classes.iter().zip(&stats) {
        if s.0 == 0 {
            continue;
        }
        println!(
            "{:12} {:6} {:7.3} {:8.1}% {:7.2} {:6}",
            c,
            s.0,
            1.0 - s.1 / s.0 as f64,
            100.0 * s.1 / total_def,
            s.2 / s.0 as f64,
            s.3
        );
    }
    // Deficit by how much the metric varies across a face: the largest |log eigenvalue| of
    // M_a^{-1/2} M_b M_a^{-1/2} over its vertex pairs (0: the same metric at all corners).
    let variation = |f: usize| -> f64 {
        let t = out.triangles[f];
        let [p, q, r] = out.face_points(FaceId::new(f));
        // An orthonormal basis of the face's plane: the metrics restricted to it (2×2).
        let e1 = (q - p).normalize();
        let n = (q - p).cross(&(r - p));
        let e2 = n.cross(&e1).normalize();
        let restrict = |m: &nalgebra::Matrix3<f64>| {
            nalgebra::Matrix2::new(
                e1.dot(&(m * e1)),
                e1.dot(&(m * e2)),
                e2.dot(&(m * e1)),
                e2.dot(&(m * e2)),
            )
        };
        let mut worst: f64 = 0.0;
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            let ma = restrict(&metrics[t[a].idx()]);
            let mb = restrict(&metrics[t[b].idx()]);
            let ea = nalgebra::SymmetricEigen::new(ma);
            if ea.eigenvalues.iter().any(|x| *x <= 0.0) {
                continue;
            }
            let ia = ea.eigenvectors
                * nalgebra::Matrix2::from_diagonal(&ea.eigenvalues.map(|x| 1.0 / x.sqrt()))
                * ea.eigenvectors.transpose();
            let m = ia * mb * ia;
            let e = nalgebra::SymmetricEigen::new(0.5 * (m + m.transpose())).eigenvalues;
            for x in e.iter() {
                if *x > 0.0 {
                    worst = worst.max(x.ln().abs());
                }
            }
        }
        worst
    };
    let mut by_var = [(0usize, 0.0f64); 5];
    for f in 0..out.n_faces() {
        let v = variation(f);
        let b = [0.25f64, 0.5, 1.0, 2.0]
            .iter()
            .position(|&x| v <= x)
            .unwrap_or(4);
        by_var[b].0 += 1;
        by_var[b].1 += 1.0 - qs[f].q;
    }
    println!(
        "metric variation across the face in its plane (max |ln λ|): faces, q_avg, deficit share"
    );
    for (l, (c, d)) in ["≤0.25", "≤0.5", "≤1", "≤2", ">2"].iter().zip(by_var) {
        if c > 0 {
            println!(
                "  {:5} {:6} {:7.3} {:6.1}%",
                l,
                c,
                1.0 - d / c as f64,
                100.0 * d / total_def
            );
        }
    }
    // Deficit by anisotropy: sqrt of the eigenvalue ratio of the first corner's metric
    // restricted to the face plane (the stretch of the ideal triangle).
    let mut by_an = [(0usize, 0.0f64); 5];
    for f in 0..out.n_faces() {
        let t = out.triangles[f];
        let [p, q, r] = out.face_points(FaceId::new(f));
        let e1 = (q - p).normalize();
        let e2 = (q - p).cross(&(r - p)).cross(&e1).normalize();
        let m = metrics[t[0].idx()];
        let m2 = nalgebra::Matrix2::new(
            e1.dot(&(m * e1)),
            e1.dot(&(m * e2)),
            e2.dot(&(m * e1)),
            e2.dot(&(m * e2)),
        );
        let e = nalgebra::SymmetricEigen::new(m2).eigenvalues;
        let ratio = (e.max() / e.min().max(1e-300)).sqrt();
        let b = [1.5f64, 3.0, 6.0, 12.0]
            .iter()
            .position(|&x| ratio <= x)
            .unwrap_or(4);
        by_an[b].0 += 1;
        by_an[b].1 += 1.0 - qs[f].q;
    }
    println!("metric stretch in the face plane: faces, q_avg, deficit share");
    for (l, (c, d)) in ["≤1.5", "≤3", "≤6", "≤12", ">12"].iter().zip(by_an) {
        if c > 0 {
            println!(
                "  {:5} {:6} {:7.3} {:6.1}%",
                l,
                c,
                1.0 - d / c as f64,
                100.0 * d / total_def
            );
        }
    }
    // Per patch: q sum and face count, with its parameterization distortion (PATCH_DUMP).
    if let Ok(path) = std::env::var("PATCH_DUMP") {
        let np = res.report.patch_records.len();
        let mut acc = vec![(0usize, 0.0f64, 0usize); np];
        for (f, p) in res.face_patch.iter().enumerate() {
            if let Some(p) = p {
                acc[p.idx()].0 += 1;
                acc[p.idx()].1 += qs[f].q;
                if on_seam[f] {
                    acc[p.idx()].2 += 1;
                }
            }
        }
        let mut txt = String::from(
            "patch faces_in faces_out alive q_avg seam sd maxconf meanconf maxarea retries rounds\n",
        );
        for (i, r) in res.report.patch_records.iter().enumerate() {
            let (c, q, sm) = acc[i];
            txt += &format!(
                "{i} {} {} {c} {:.4} {sm} {:.4} {:.4} {:.4} {:.4} {} {}\n",
                r.faces_in,
                r.faces_out,
                if c > 0 { q / c as f64 } else { f64::NAN },
                r.distortion.symmetric_dirichlet,
                r.distortion.max_conformal,
                r.distortion.mean_conformal,
                r.distortion.max_area_distortion,
                r.retries,
                r.fidelity_rounds
            );
        }
        std::fs::write(path, txt).expect("dump");
    }
    // Deficit per patch size bucket (faces produced).
    let mut by_size: HashMap<usize, (usize, f64)> = HashMap::new();
    for (f, p) in res.face_patch.iter().enumerate() {
        let b = match p {
            Some(p) => {
                let n = res.report.patch_records[p.idx()].faces_out;
                [10, 30, 100, 300, 1000, usize::MAX]
                    .iter()
                    .position(|&x| n <= x)
                    .unwrap_or(5)
            }
            None => 6,
        };
        let e = by_size.entry(b).or_default();
        e.0 += 1;
        e.1 += 1.0 - qs[f].q;
    }
    let labels = ["≤10", "≤30", "≤100", "≤300", "≤1000", ">1000", "kept"];
    let mut keys: Vec<_> = by_size.keys().copied().collect();
    keys.sort();
    println!("faces_out of the producing patch: faces, q_avg, deficit share");
    for k in keys {
        let (c, d) = by_size[&k];
        println!(
            "  {:6} {:6} {:7.3} {:6.1}%",
            labels[k],
            c,
            1.0 - d / c as f64,
            100.0 * d / total_def
        );
    }
    // The worst faces, with their unit-space centroid (for crop.py) and provenance.
    let mut idx: Vec<usize> = (0..out.n_faces()).collect();
    idx.sort_by(|x, y| qs[*x].q.total_cmp(&qs[*y].q));
    for &f in idx.iter().take(12) {
        let [p, q, r] = out.face_points(FaceId::new(f));
        let c = (p.coords + q.coords + r.coords) / 3.0;
        println!(
            "  f{f} q {:.3} θ {:.1} patch {:?} seam {} centroid {:.4},{:.4},{:.4}",
            qs[f].q,
            qs[f].min_angle(),
            res.face_patch[f],
            on_seam[f],
            c.x,
            c.y,
            c.z
        );
    }
}
