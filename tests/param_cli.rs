//! `conemesh param`: writes vt / flat output for a disk, refuses a non-disk by name.

use conemesh::io::{read_mesh, write_mesh};
use conemesh::mesh::generators;
use std::process::Command;

fn conemesh() -> Command {
    Command::new(env!("CARGO_BIN_EXE_conemesh"))
}

#[test]
fn param_writes_uv_and_flat_meshes_with_a_certificate() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("cone.off");
    let m = generators::cone_piece(0.5, 2.0, 0.3, 1.5, 12, 6);
    write_mesh(&input, &m).unwrap();
    let out = dir.path().join("cone_uv.obj");
    let o = conemesh()
        .args([
            "param",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("certificate: bijective"), "{stdout}");
    assert!(stdout.contains("symmetric Dirichlet"), "{stdout}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(
        text.lines().filter(|l| l.starts_with("vt ")).count(),
        m.n_vertices()
    );
    let back = read_mesh(&out).unwrap();
    assert_eq!(back.mesh.n_faces(), m.n_faces());

    let flat = dir.path().join("cone_flat.obj");
    let o = conemesh()
        .args([
            "param",
            input.to_str().unwrap(),
            "-o",
            flat.to_str().unwrap(),
            "--flat",
        ])
        .output()
        .unwrap();
    assert!(o.status.success());
    let f = read_mesh(&flat).unwrap().mesh;
    assert!(f.positions.iter().all(|p| p.z == 0.0));
    // Developable: the flat mesh has the 3D area.
    assert!((f.area() - m.area()).abs() < 1e-6 * m.area());
}

#[test]
fn param_refuses_a_non_disk_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("cyl.off");
    write_mesh(&input, &generators::cylinder(1.0, 1.0, 12, 3)).unwrap();
    let out = dir.path().join("x.obj");
    let o = conemesh()
        .args([
            "param",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("not a disk") && err.contains("2 boundary loops"),
        "{err}"
    );
    assert!(!out.exists());
}
