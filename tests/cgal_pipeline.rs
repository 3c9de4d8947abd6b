//! CGAL agrees with conemesh on the outputs of `conemesh remesh` (issues 5 and 9).
//!
//! For the remeshed fertility, 3holes and a generated torus, the outside witness
//! `reference/cgal/build/conemesh-cgal-check` (CGAL 5.5, exact Epick predicates) must find:
//! a valid, closed, triangle-only polygon mesh without degenerate faces or self-intersections,
//! with the input's Euler characteristic, components and boundary cycles; and its approximate
//! Hausdorff distance (both directions) must agree with `quality::approximation_error`
//! within the stated sampling errors. `conemesh check OUT --json` must say valid and agree
//! with CGAL on the counts.
//!
//! The checker is found through `CONEMESH_CGAL_CHECK` or at its build path and built with
//! CMake when missing (the finder is copied from `tests/cgal_crossval.rs`); if it cannot be
//! built the tests FAIL naming `libcgal-dev` / `cmake`: they never pass silently.
//!
//! Hausdorff tolerance. Both tools report maxima over samples of the exact point-to-surface
//! distance, which is 1-Lipschitz, so both under-estimate the true one-sided distance `d`:
//! - CGAL samples on a grid of spacing H (its `error_bound`): `cgal <= d <= cgal + H`;
//! - conemesh samples every vertex plus N area-weighted uniform points per surface. The
//!   maximiser `x` of the distance is missed by at most the distance to the nearest sample.
//!   A disk of radius r = 3·sqrt(A/N) around `x` (A = surface area) is empty of all N samples
//!   with probability about exp(-N·π·r²/A) = exp(-9π) ≈ 5e-13 (a half disk next to an edge:
//!   exp(-9π/2) ≈ 7e-7; within r of a vertex the vertex sample itself covers `x`). So
//!   `d - δ <= conemesh <= d` with δ = 3·sqrt(A/N) (and the seed is fixed, so the test is
//!   deterministic).
//!
//! Hence `cgal - δ <= conemesh <= cgal + H`, both up to a relative 1e-9 for the float
//! evaluation of the point-triangle distances (different but equally exact formulas).
//!
//! That lower bound is rigorous but weak (δ is of the order of the distance itself), so the
//! test also asserts the practical agreement `conemesh >= (1 - 5 %)·cgal`: both tools sample
//! every vertex exactly, the one-sided maxima of a remesh whose vertices lie on the input sit
//! at or next to vertices and edges, and with N = 10⁶ samples and H = 0.0005·diagonal the
//! observed gap is at most 1.6 % (3holes input→output, fertility output→input; fertility
//! input→output is identical to the last digit). 5 % is about three times that: a broken
//! sampler, a swapped direction or a unit mix-up still fails.

use conemesh::mesh::generators;
use conemesh::quality::approximation_error;
use conemesh::{io, Topology, TriMesh};
use rand::SeedableRng;
use serde_json::Value;
use std::path::Path;
use std::process::Command;

mod common;

#[path = "common/cgal.rs"]
mod cgal;
use cgal::run_checker;

// ---------------------------------------------------------------------------------------
// The runs.

fn read(path: &Path) -> TriMesh {
    io::read_mesh(path)
        .unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
        .mesh
}

/// `conemesh remesh INPUT -o OUT --seed 1 --quiet`.
fn remesh_cli(input: &Path, out: &Path) {
    let o = Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .arg("remesh")
        .arg(input)
        .arg("-o")
        .arg(out)
        .args(["--seed", "1", "--quiet"])
        .output()
        .expect("run conemesh remesh");
    assert!(
        o.status.success(),
        "conemesh remesh {} failed:\n{}\n{}",
        input.display(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// `conemesh check OUT --json`.
fn check_cli(mesh: &Path) -> Value {
    let o = Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .arg("check")
        .arg(mesh)
        .arg("--json")
        .output()
        .expect("run conemesh check");
    let json: Value = serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!(
            "conemesh check --json printed no JSON ({e}): {}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        )
    });
    assert!(
        o.status.success(),
        "conemesh check {} exits non-zero (invalid): {json}",
        mesh.display()
    );
    json
}

fn num(v: &Value, field: &str) -> f64 {
    v[field]
        .as_f64()
        .unwrap_or_else(|| panic!("field {field} is not a number in {v}"))
}

/// Remesh `input` with the CLI and cross-check the output with CGAL and `conemesh check`.
fn cross_check(case: &str, input: &Path, dir: &Path) {
    let out = dir.join(format!("{case}-remeshed.off"));
    remesh_cli(input, &out);

    let cin = run_checker(input, &[]);
    // A grid 4× finer than the checker's default (0.002 × diagonal): H = 0.0005 × diagonal.
    let spacing = format!("{:e}", GRID_FRACTION * read(input).bbox_diagonal());
    let cout = run_checker(
        &out,
        &[
            "--hausdorff",
            input.to_str().expect("utf-8 path"),
            "--grid-spacing",
            &spacing,
        ],
    );
    eprintln!("{case}: CGAL on the output: {cout}");

    // Validity, closedness, topology: CGAL on the output vs CGAL (and conemesh) on the input.
    assert_eq!(
        cin["valid_polygon_mesh"],
        Value::Bool(true),
        "{case}: input"
    );
    for (field, want) in [
        ("valid_polygon_mesh", Value::Bool(true)),
        ("triangle_only", Value::Bool(true)),
        ("closed", Value::Bool(true)),
        ("self_intersects", Value::Bool(false)),
        ("self_intersecting_pairs", Value::Array(vec![])),
        ("degenerate_faces", Value::Array(vec![])),
    ] {
        assert_eq!(
            cout[field], want,
            "{case}: CGAL says {field} = {}",
            cout[field]
        );
    }
    for field in [
        "euler_characteristic",
        "connected_components",
        "boundary_cycles",
    ] {
        assert!(cin[field].is_number(), "{case}: input {field}");
        assert_eq!(
            cout[field], cin[field],
            "{case}: {field} of the output differs from the input's"
        );
    }
    let input_mesh = read(input);
    let output_mesh = read(&out);
    let tin = Topology::build(&input_mesh);
    assert_eq!(
        cin["connected_components"],
        Value::from(tin.components().len()),
        "{case}: CGAL and conemesh disagree on the input's components"
    );
    assert_eq!(
        cout["faces"],
        Value::from(output_mesh.n_faces()),
        "{case}: CGAL read a different face count"
    );

    // `conemesh check OUT --json` says valid and agrees with CGAL on the counts.
    let ours = check_cli(&out);
    assert_eq!(
        ours["valid"],
        Value::Bool(true),
        "{case}: conemesh check: {ours}"
    );
    assert_eq!(ours["faces"], cout["faces"], "{case}: faces");
    assert_eq!(ours["components"], cout["connected_components"], "{case}");
    assert_eq!(ours["euler"], cout["euler_characteristic"], "{case}");
    assert_eq!(ours["boundary_loops"], cout["boundary_cycles"], "{case}");
    assert_eq!(ours["degenerate_faces"], Value::from(0), "{case}");
    assert_eq!(
        ours["self_intersections"]["pairs"],
        Value::from(0),
        "{case}: conemesh check self-intersections: {}",
        ours["self_intersections"]
    );

    // Hausdorff distance, both directions, file units.
    let h = &cout["hausdorff"];
    let (out_to_in, in_to_out, bound) = (
        num(h, "mesh_to_other"),
        num(h, "other_to_mesh"),
        num(h, "error_bound"),
    );
    const N: usize = 1_000_000;
    let mut rng = conemesh::Rng::seed_from_u64(7);
    let d = approximation_error(&input_mesh, &output_mesh, N, &mut rng);
    let delta = |m: &TriMesh| 3.0 * (m.area() / N as f64).sqrt();
    for (what, ours, theirs, dl) in [
        (
            "input→output",
            d.hausdorff_a_to_b,
            in_to_out,
            delta(&input_mesh),
        ),
        (
            "output→input",
            d.hausdorff_b_to_a,
            out_to_in,
            delta(&output_mesh),
        ),
    ] {
        let rel = 1e-9 * theirs.max(ours);
        eprintln!(
            "{case}: {what}: conemesh {ours:.6e}, CGAL {theirs:.6e} (H {bound:.2e}, δ {dl:.2e})"
        );
        assert!(
            ours <= theirs + bound + rel && ours >= theirs - dl - rel,
            "{case}: {what} Hausdorff: conemesh {ours} vs CGAL {theirs} \
             (allowed [CGAL − δ, CGAL + H] with H {bound}, δ {dl})"
        );
        assert!(
            ours >= (1.0 - AGREEMENT) * theirs,
            "{case}: {what} Hausdorff: conemesh {ours} more than {AGREEMENT} below CGAL {theirs}"
        );
    }
    // Issue 9's goal (Hausdorff ≤ 1 % of the input's bbox diagonal) is reported, not asserted:
    // it is a quality target that some meshes miss (fertility: about 1 %, see the issue notes),
    // while this test is about the two tools agreeing.
    let diag = input_mesh.bbox_diagonal();
    eprintln!(
        "{case}: Hausdorff (CGAL) {:.4} % of the diagonal (+ H {:.4} %)",
        100.0 * out_to_in.max(in_to_out) / diag,
        100.0 * bound / diag
    );
}

/// CGAL's Hausdorff grid spacing as a fraction of the input's bounding-box diagonal.
const GRID_FRACTION: f64 = 0.0005;
/// Practical relative agreement of the two Hausdorff estimates (see the module docs).
const AGREEMENT: f64 = 0.05;

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn cgal_agrees_on_remeshed_fertility() {
    let dir = tempfile::tempdir().expect("tempdir");
    cross_check("fertility", &common::path("fertility.off"), dir.path());
}

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn cgal_agrees_on_remeshed_3holes() {
    let dir = tempfile::tempdir().expect("tempdir");
    cross_check("3holes", &common::path("3holes.off"), dir.path());
}

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn cgal_agrees_on_remeshed_torus() {
    let dir = tempfile::tempdir().expect("tempdir");
    let input = dir.path().join("torus.off");
    io::write_mesh(&input, &generators::torus(1.0, 0.35, 48, 18)).expect("write torus");
    cross_check("torus", &input, dir.path());
}
