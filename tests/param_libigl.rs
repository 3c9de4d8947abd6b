//! Cross-validation of the Tutte step against libigl (reference/libigl/harmonic.py):
//! harmonic maps with cotangent and uniform weights and the boundary on the unit circle by
//! arc length agree to 1e-8.

use conemesh::param::{circle_boundary, tutte_embedding, TutteWeights};
use conemesh::{TriMesh, VertexId};
use nalgebra::{Point2, Point3};

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/reference/libigl");

fn numbers(name: &str) -> Vec<Vec<f64>> {
    std::fs::read_to_string(format!("{DIR}/{name}"))
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            l.split_whitespace()
                .map(|x| x.parse().expect("number"))
                .collect()
        })
        .collect()
}

fn read_off(name: &str) -> TriMesh {
    let text = std::fs::read_to_string(format!("{DIR}/{name}")).expect("off");
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| {
            l.split_whitespace()
                .map(|x| x.parse().expect("number"))
                .collect()
        })
        .collect();
    let (nv, nf) = (rows[0][0] as usize, rows[0][1] as usize);
    let pos = rows[1..=nv]
        .iter()
        .map(|r| Point3::new(r[0], r[1], r[2]))
        .collect();
    let tris: Vec<[usize; 3]> = rows[nv + 1..=nv + nf]
        .iter()
        .map(|r| [r[1] as usize, r[2] as usize, r[3] as usize])
        .collect();
    TriMesh::from_indices(pos, &tris).expect("mesh")
}

#[test]
fn tutte_matches_libigl_harmonic_to_1e_8() {
    for mesh in ["paraboloid", "spherecap"] {
        let m = read_off(&format!("harmonic_{mesh}.off"));
        let bnd: Vec<VertexId> = numbers(&format!("harmonic_{mesh}_bnd.txt"))
            .iter()
            .map(|r| VertexId::new(r[0] as usize))
            .collect();
        // Our circle placement is libigl's map_vertices_to_circle.
        let circle = circle_boundary(&m, &bnd, 1.0);
        for (kind, file) in [
            (TutteWeights::Cotan, "cotan"),
            (TutteWeights::Uniform, "uniform"),
        ] {
            let reference: Vec<Point2<f64>> = numbers(&format!("harmonic_{mesh}_{file}.txt"))
                .iter()
                .map(|r| Point2::new(r[0], r[1]))
                .collect();
            for (v, p) in bnd.iter().zip(&circle) {
                assert!(
                    (reference[v.idx()] - p).norm() < 1e-12,
                    "{mesh}: circle at {v}"
                );
            }
            let uv = tutte_embedding(&m, &bnd, &circle, kind).unwrap();
            let worst = uv
                .iter()
                .zip(&reference)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            assert!(worst < 1e-8, "{mesh} {file}: max deviation {worst:e}");
        }
    }
}
