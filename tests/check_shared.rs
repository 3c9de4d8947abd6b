//! `check` on every shared test mesh: genus and boundary loops as listed in
//! `../shared/meshes/README.md`, and an insta snapshot of each check report (reviewable
//! diff when a number changes). Heavy: run with `cargo test --release`.

use conemesh::check::{check_mesh, CheckOptions, CheckReport};
use std::path::{Path, PathBuf};

const MESHES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/meshes");

/// Expected (genus, boundary loops, unreferenced vertices) per mesh, from the README table.
const EXPECTED: &[(&str, u32, usize, usize)] = &[
    ("3holes.off", 3, 0, 0),
    ("armadillo.obj", 0, 0, 0),
    ("bumpy.off", 0, 0, 0),
    ("bunny.off", 0, 0, 0),
    ("cow.off", 0, 0, 0),
    ("decimated-knight.off", 0, 0, 0),
    ("fandisk.off", 0, 0, 0),
    ("fertility.off", 4, 0, 0),
    ("homer.obj", 0, 0, 0),
    ("screwdriver.off", 0, 0, 0),
    ("spot.obj", 0, 0, 0),
    ("stanford-bunny.obj", 0, 5, 1113),
];

fn check(name: &str) -> CheckReport {
    let path = Path::new(MESHES).join(name);
    let loaded = conemesh::io::read_mesh(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    check_mesh(&loaded.mesh, &CheckOptions::default())
}

fn assert_readme_topology(name: &str, r: &CheckReport) {
    let &(_, genus, loops, unreferenced) = EXPECTED
        .iter()
        .find(|e| e.0 == name)
        .unwrap_or_else(|| panic!("{name} is not in EXPECTED"));
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
    let mut found: Vec<String> = std::fs::read_dir(MESHES)
        .expect("../shared/meshes exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p: &PathBuf| p.extension().is_some_and(|x| x != "md"))
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    found.sort();
    let expected: Vec<String> = EXPECTED.iter().map(|e| e.0.to_string()).collect();
    assert_eq!(found, expected);
}

/// All shared meshes are valid except `cow.off`, which really self-intersects (crossing
/// faces such as f593×f732, and faces touching along a collinear edge at v2761).
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn shared_meshes_validity() {
    for &(name, ..) in EXPECTED {
        let r = check(name);
        assert_eq!(r.degenerate_faces, 0, "{name}");
        let pairs = r.self_intersections.as_ref().map_or(0, |s| s.pairs);
        if name == "cow.off" {
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
    let cow = format!("{MESHES}/cow.off");
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
