//! `check` on every shared test mesh: counts, genus, boundary loops and unreferenced vertices
//! as the catalogue (`tests/common/mod.rs`) takes them from `../shared/meshes/README.md`, and
//! an insta snapshot of each check report (reviewable diff when a number changes); the
//! catalogue lists exactly the folder's meshes. Heavy: run with `cargo test --release`.

use conemesh::check::{check_mesh, CheckOptions, CheckReport};
use std::path::PathBuf;

mod common;

use common::{shared_mesh, SHARED_MESHES};

fn check(name: &str) -> CheckReport {
    check_mesh(&common::load(name), &CheckOptions::default())
}

fn assert_readme_topology(name: &str, r: &CheckReport) {
    let m = shared_mesh(name);
    let (genus, loops, unreferenced) = (m.genus, m.boundary_loops, m.unreferenced);
    assert_eq!((r.vertices, r.faces), (m.vertices, m.faces), "{name}");
    assert_eq!(r.components, 1, "{name}");
    assert_eq!(r.component_list[0].genus, Some(genus), "{name}");
    assert_eq!(r.boundary_loops, loops, "{name}");
    assert_eq!(r.unreferenced_vertices, unreferenced, "{name}");
    assert_eq!(r.euler, 2 - 2 * genus as i64 - loops as i64, "{name}");
    // "All are one connected, edge- and vertex-manifold, consistently oriented component."
    assert_eq!(r.non_manifold_edges, 0, "{name}");
    assert_eq!(r.non_manifold_vertices, 0, "{name}");
    assert_eq!(r.inconsistently_oriented_edges, 0, "{name}");
}

fn snapshot(name: &str, r: &CheckReport) {
    let snap = format!("check_{}", name.replace(['.', '-'], "_"));
    insta::with_settings!({
        snapshot_path => concat!(env!("CARGO_MANIFEST_DIR"), "/snapshots"),
        prepend_module_to_snapshot => false,
    }, {
        insta::assert_json_snapshot!(snap, r);
    });
}

macro_rules! shared_mesh_tests {
    ($($test:ident => $file:literal),* $(,)?) => {
        $(
            #[test]
            #[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
            fn $test() {
                let r = check($file);
                assert_readme_topology($file, &r);
                snapshot($file, &r);
            }
        )*
    };
}

shared_mesh_tests! {
    check_3holes => "3holes.off",
    check_armadillo => "armadillo.obj",
    check_bumpy => "bumpy.off",
    check_bunny => "bunny.off",
    check_cow => "cow.off",
    check_decimated_knight => "decimated-knight.off",
    check_fandisk => "fandisk.off",
    check_fertility => "fertility.off",
    check_homer => "homer.obj",
    check_screwdriver => "screwdriver.off",
    check_spot => "spot.obj",
    check_stanford_bunny => "stanford-bunny.obj",
}

/// Every mesh in the shared directory has a test above (a new mesh must be added).
#[test]
fn every_shared_mesh_is_covered() {
    let mut found: Vec<String> = std::fs::read_dir(common::dir())
        .expect("the shared meshes directory is readable")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p: &PathBuf| p.extension().is_some_and(|x| x != "md"))
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    found.sort();
    let expected: Vec<String> = SHARED_MESHES.iter().map(|m| m.file.to_string()).collect();
    assert_eq!(found, expected);
}

/// All shared meshes are valid except `cow.off`, which really self-intersects (crossing
/// faces such as f593×f732, and faces touching along a collinear edge at v2761).
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn shared_meshes_validity() {
    for m in &SHARED_MESHES {
        let name = m.file;
        let r = check(name);
        assert_eq!(r.degenerate_faces, 0, "{name}");
        let pairs = r.self_intersections.as_ref().map_or(0, |s| s.pairs);
        if m.self_intersects {
            assert!(!r.valid && pairs > 0, "{name}");
        } else {
            assert!(r.valid, "{name}: {r}");
        }
    }
}

fn run_cli(args: &[&str]) -> (Option<i32>, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .arg("check")
        .args(args)
        .output()
        .expect("the conemesh binary runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
    )
}

/// Exit codes: 0 valid (built-in torus), 1 invalid (cow.off self-intersects), 2 unreadable.
#[test]
fn cli_exit_codes_and_json() {
    let (code, out) = run_cli(&[]);
    assert_eq!(code, Some(0), "{out}");
    assert!(
        out.contains("genus 1") && out.trim_end().ends_with("valid: yes"),
        "{out}"
    );
    let cow = common::path("cow.off").display().to_string();
    let (code, out) = run_cli(&["--json", &cow]);
    assert_eq!(code, Some(1), "{out}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("--json prints JSON");
    assert_eq!(v["valid"], serde_json::Value::Bool(false));
    assert_eq!(v["self_intersections"]["pairs"], serde_json::json!(118));
    // Without the self-intersection search the cow is valid.
    let (code, out) = run_cli(&["--no-self-intersections", &cow]);
    assert_eq!(code, Some(0), "{out}");
    assert!(
        out.contains("self-intersecting face pairs: not checked"),
        "{out}"
    );
    let (code, _) = run_cli(&["/nonexistent/mesh.off"]);
    assert_eq!(code, Some(2));
    // The OS error is named once (it is part of the message, not a second link of the chain).
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .args(["check", "/nonexistent/mesh.off"])
        .output()
        .expect("the conemesh binary runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.matches("os error").count(), 1, "{err}");
    assert!(err.contains("/nonexistent/mesh.off"), "{err}");
}
