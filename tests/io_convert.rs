//! `conemesh convert` through every format on a shared mesh: counts kept, positions bit-exact
//! except through binary STL, no temporary files left, an existing OUT untouched on failure.

use conemesh::io::read_mesh;
use std::path::Path;
use std::process::Command;

mod common;

fn convert(args: &[&std::ffi::OsStr]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .arg("convert")
        .args(args)
        .output()
        .expect("run conemesh")
}

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn convert_chain_keeps_the_mesh() {
    let src = &common::path("decimated-knight.off");
    let original = read_mesh(src).expect("shared mesh").mesh;
    let tmp = tempfile::tempdir().expect("tempdir");
    let chain = [
        ("a.ply", &["--binary"][..]),
        ("b.ply", &["--big-endian"][..]),
        ("c.obj", &[][..]),
        ("d.mesh", &[][..]),
        ("e.ply", &[][..]),
        ("f.off", &[][..]),
    ];
    let mut prev = src.to_path_buf();
    for (name, flags) in chain {
        let out = tmp.path().join(name);
        let mut args: Vec<&std::ffi::OsStr> = vec![prev.as_os_str(), out.as_os_str()];
        args.extend(flags.iter().map(std::ffi::OsStr::new));
        let o = convert(&args);
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let m = read_mesh(&out).expect("converted").mesh;
        assert_eq!(m, original, "{name}");
        prev = out;
    }
    // Binary STL: same faces, f32 coordinates.
    let stl = tmp.path().join("g.stl");
    let o = convert(&[prev.as_os_str(), stl.as_os_str(), "--binary".as_ref()]);
    assert!(o.status.success());
    let m = read_mesh(&stl).expect("stl").mesh;
    assert_eq!(m.n_faces(), original.n_faces());
    assert_eq!(
        std::fs::read(&stl).expect("stl bytes").len(),
        84 + 50 * original.n_faces()
    );
    let names: Vec<String> = std::fs::read_dir(tmp.path())
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(names.is_empty(), "{names:?}");
}

#[test]
fn failed_convert_leaves_an_existing_output_untouched() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let out = tmp.path().join("out.obj");
    std::fs::write(&out, "keep me").expect("write");
    let bad = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/bad-inputs/off-nan.off"
    ));
    let o = convert(&[bad.as_os_str(), out.as_os_str()]);
    assert!(!o.status.success());
    assert_eq!(
        std::fs::read_to_string(&out).expect("still there"),
        "keep me"
    );
    // A directory that does not exist: an OS error naming the path, nothing created.
    let good = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/bad-inputs/topo-nonmanifold-edge.off"
    ));
    let missing = tmp.path().join("no/such/dir/out.ply");
    let o = convert(&[good.as_os_str(), missing.as_os_str()]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("no/such/dir/out.ply"));
}
