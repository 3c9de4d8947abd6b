//! `conemesh remesh --write-input-metric`: the metric the run remeshes to, at every vertex of
//! the input file, in MMG's `-ltar 1` convention. One SPD tensor per vertex of the file (an
//! unreferenced one too); on each vertex's tangent plane exactly the user's tensor over L_tar²
//! when the fidelity control is off, and the curvature metric of Sec. 4.1 over L_tar² (the
//! library's own estimate) times an isotropic factor ≥ 1 when it is on.

use conemesh::io::sol::{read_sol, write_sol};
use conemesh::mesh::generators;
use conemesh::metric::{curvature_metric, tangent_frame, MetricOptions, Normalization};
use conemesh::TriMesh;
use nalgebra::{Matrix3, Point3, Vector3};
use std::path::Path;
use std::process::Command;

type R = Result<(), Box<dyn std::error::Error>>;

fn remesh(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .arg("remesh")
        .args(args)
        .output()
        .expect("run conemesh remesh")
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// A torus in file units far from unit space (radii 3 and 1, centred at (5, -2, 1)), so the
/// file-unit conversion is exercised, plus one unreferenced vertex at the end of the file.
fn torus_file(dir: &Path) -> Result<(TriMesh, std::path::PathBuf), Box<dyn std::error::Error>> {
    let mut mesh = generators::torus(3.0, 1.0, 40, 14);
    for p in &mut mesh.positions {
        *p += Vector3::new(5.0, -2.0, 1.0);
    }
    mesh.positions.push(Point3::new(50.0, 50.0, 50.0));
    let path = dir.join("torus.off");
    conemesh::io::write_mesh(&path, &mesh)?;
    Ok((mesh, path))
}

/// The tangent block `[t1ᵀMt1, t1ᵀMt2, t2ᵀMt2]` of `m` on the plane of unit normal `n`.
fn tangent_block(m: &Matrix3<f64>, n: &Vector3<f64>) -> [f64; 3] {
    let (t1, t2) = tangent_frame(n);
    [t1.dot(&(m * t1)), t1.dot(&(m * t2)), t2.dot(&(m * t2))]
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-9 * scale
}

/// Every tensor is SPD in 3D, and the vertex normal is an eigenvector with the largest
/// tangent eigenvalue (the finer tangent size), as `conemesh::metric::unit_target_metric`
/// completes it.
fn assert_spd_with_normal_part(w: &[Matrix3<f64>], normals: &[Vector3<f64>]) {
    for (v, (w, n)) in w.iter().zip(normals).enumerate() {
        let eig = w.symmetric_eigenvalues();
        assert!(eig.min() > 0.0, "v{v}: not SPD, eigenvalues {eig:?}");
        if n.norm() > 0.5 {
            let [a, b, c] = tangent_block(w, n);
            let lmax = nalgebra::Matrix2::new(a, b, b, c)
                .symmetric_eigenvalues()
                .max();
            let along = n.dot(&(w * n));
            assert!(
                close(along, lmax, lmax),
                "v{v}: normal part {along} vs {lmax}"
            );
            assert!(
                (w * n - n * along).norm() <= 1e-9 * lmax,
                "v{v}: n not an eigenvector"
            );
        }
    }
}

/// A user metric in file units, anisotropic on the surface (sizes 0.5 around the big circle,
/// 0.3 around the tube) with a normal part of its own (size 0.05) that the run ignores.
fn user_metric(mesh: &TriMesh) -> Vec<Matrix3<f64>> {
    mesh.positions
        .iter()
        .map(|p| {
            let q = p.coords - Vector3::new(5.0, -2.0, 1.0);
            let around = Vector3::new(-q.y, q.x, 0.0);
            if around.norm() < 1e-9 || q.norm() > 10.0 {
                return Matrix3::identity(); // the unreferenced vertex
            }
            let around = around.normalize();
            let centre = Vector3::new(q.x, q.y, 0.0).normalize() * 3.0;
            let normal = (q - centre).normalize();
            let tube = normal.cross(&around);
            around * around.transpose() / 0.25
                + tube * tube.transpose() / 0.09
                + normal * normal.transpose() / 0.0025
        })
        .collect()
}

/// With the user's metric, `--ltar L` and `--hausd 0` (no fidelity scaling, no size
/// controls), the written tensors are the user's over L² on each vertex's tangent plane.
#[test]
fn a_user_metric_comes_back_over_ltar_squared_on_the_tangent_plane() -> R {
    let dir = tempfile::tempdir()?;
    let (mesh, input) = torus_file(dir.path())?;
    let metric = user_metric(&mesh);
    let sol = dir.path().join("user.sol");
    write_sol(&sol, &metric, false)?;
    let normals = mesh.vertex_normals();
    for ltar in [1.0, 2.0] {
        let written = dir.path().join(format!("input-{ltar}.sol"));
        let o = remesh(&[
            s(&input),
            "--metric",
            s(&sol),
            "--ltar",
            &ltar.to_string(),
            "--hausd",
            "0",
            "-o",
            s(&dir.path().join("out.obj")),
            "--write-input-metric",
            s(&written),
            "--quiet",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let w = read_sol(&written, mesh.n_vertices())?;
        assert_eq!(
            w.len(),
            mesh.n_vertices(),
            "one tensor per vertex of the file"
        );
        assert_spd_with_normal_part(&w, &normals);
        for (v, n) in normals.iter().enumerate().filter(|(_, n)| n.norm() > 0.5) {
            let got = tangent_block(&w[v], n);
            let want = tangent_block(&metric[v], n).map(|x| x / (ltar * ltar));
            let scale = want[0].abs().max(want[2].abs());
            for k in 0..3 {
                assert!(
                    close(got[k], want[k], scale),
                    "L_tar {ltar}, v{v}: tangent block {got:?}, the user's over L_tar² {want:?}"
                );
            }
        }
    }
    Ok(())
}

/// With the curvature metric, the written tensors on the tangent plane are the library's
/// curvature metric (unit space, as the pipeline estimates it) in file units over the run's
/// L_tar²: exactly so with `--hausd 0`, times one isotropic factor ≥ 1 per vertex with the
/// fidelity control on (the a-priori scaling refines, never coarsens).
#[test]
fn the_curvature_metric_comes_back_with_the_runs_ltar_and_fidelity_factors() -> R {
    let dir = tempfile::tempdir()?;
    let (mesh, input) = torus_file(dir.path())?;
    let (kept, _) = mesh.without_unreferenced_vertices();
    let norm = Normalization::of(&kept);
    let curvature = curvature_metric(&norm.apply(&kept), &MetricOptions::default())?;
    let normals = mesh.vertex_normals();
    let mut scaled_somewhere = false;
    for hausd in ["0", "0.001"] {
        let written = dir.path().join(format!("input-{hausd}.sol"));
        let report = dir.path().join(format!("report-{hausd}.json"));
        let o = remesh(&[
            s(&input),
            "--hausd",
            hausd,
            "-o",
            s(&dir.path().join("out.obj")),
            "--report",
            s(&report),
            "--write-input-metric",
            s(&written),
            "--quiet",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report)?)?;
        let l_tar = json["run"]["l_tar"].as_f64().expect("l_tar in the report");
        let w = read_sol(&written, mesh.n_vertices())?;
        assert_eq!(w.len(), mesh.n_vertices());
        assert_spd_with_normal_part(&w, &normals);
        // The torus's vertices come first in the file, so its vertex v is the compacted v.
        for (v, c) in curvature.iter().enumerate() {
            let n = &normals[v];
            let want = tangent_block(&norm.metric_from_unit(c), n).map(|x| x / (l_tar * l_tar));
            let got = tangent_block(&w[v], n);
            let f = got[0] / want[0];
            let scale = want[0].abs().max(want[2].abs());
            if hausd == "0" {
                assert!(close(f, 1.0, 1.0), "v{v}: factor {f} with the control off");
            } else {
                assert!(f >= 1.0 - 1e-9, "v{v}: factor {f} < 1");
                scaled_somewhere |= f > 1.0 + 1e-6;
            }
            for k in 0..3 {
                assert!(
                    close(got[k], f * want[k], f * scale),
                    "hausd {hausd}, v{v}: {got:?} is not {f} × {want:?}"
                );
            }
        }
    }
    assert!(
        scaled_somewhere,
        "a tolerance of 0.1 % of the diagonal refines this coarse torus somewhere"
    );
    Ok(())
}

/// The path is checked with the other outputs before any work.
#[test]
fn the_input_metric_path_is_checked_before_the_run() -> R {
    let dir = tempfile::tempdir()?;
    let (_, input) = torus_file(dir.path())?;
    let out = dir.path().join("out.obj");
    let o = remesh(&[
        s(&input),
        "-o",
        s(&out),
        "--write-input-metric",
        s(&out),
        "--quiet",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--write-input-metric") && err.contains("same path as -o"),
        "{err}"
    );
    assert!(!out.exists(), "nothing written");
    Ok(())
}
