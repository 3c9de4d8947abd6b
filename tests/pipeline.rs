//! Algorithm 1 end to end (issue 9): certificates hold, the loop terminates, runs are
//! reproducible, quality is reported.

use conemesh::mesh::generators;
use conemesh::metric::{MetricField, MetricOptions, Normalization};
use conemesh::pipeline::{remesh, RemeshOptions, RemeshResult, Stages};
use conemesh::{Topology, TriMesh};

fn run(mesh: &TriMesh, seed: u64) -> (MetricField, RemeshResult) {
    let norm = Normalization::of(mesh);
    let field =
        MetricField::from_curvature(norm.apply(mesh), &MetricOptions::default()).expect("metric");
    let options = RemeshOptions {
        seed,
        ..RemeshOptions::default()
    };
    let mut calls = 0usize;
    let mut last_unprocessed = usize::MAX;
    let result = remesh(&field, &Stages::default(), &options, |p| {
        // Termination argument: every patch strictly reduces the unprocessed face count.
        assert!(
            p.unprocessed < last_unprocessed,
            "no progress at patch {}",
            p.patches
        );
        last_unprocessed = p.unprocessed;
        calls += 1;
    })
    .expect("remesh succeeds with all certificates");
    assert_eq!(calls, result.report.patches);
    assert!(result.report.patches <= mesh.n_faces());
    (field, result)
}

fn assert_certified(input: &TriMesh, field: &MetricField, r: &RemeshResult) {
    let c = &r.report.certificate;
    let n = r.report.patches;
    assert!(n > 0);
    for (name, count) in [
        ("disk", c.disk),
        ("bijective", c.bijective),
        ("planar", c.planar),
        ("manifold", c.manifold),
        ("oriented", c.oriented),
        ("same_topology", c.same_topology),
        ("boundary_preserved", c.boundary_preserved),
        ("no_degenerate", c.no_degenerate),
        ("no_flips", c.no_flips),
    ] {
        assert_eq!(
            count, n,
            "certificate {name} held {count} times for {n} patches"
        );
    }
    assert_eq!(c.no_self_intersections, 1);
    // Independent re-check of the final mesh with the foundation's certificates.
    let topo = Topology::build(&r.mesh);
    assert!(topo.is_oriented_manifold());
    conemesh::invariants::certify_same_topology(&field.reference(), &r.mesh)
        .expect("same topology as the input");
    conemesh::invariants::certify_boundary_preserved(field.reference(), &r.mesh)
        .expect("input boundary kept");
    assert!(conemesh::invariants::self_intersections(&r.mesh).is_empty());
    assert!(conemesh::quality::flips(field.reference(), &r.mesh).is_empty());
    // Every output vertex lies on the reference surface at its recorded location.
    for (p, loc) in r.mesh.positions.iter().zip(&r.locations) {
        let q = loc.position(field.reference());
        assert!((p - q).norm() <= 1e-12, "vertex off its reference location");
    }
    let _ = input;
}

#[test]
fn sphere_is_remeshed_and_certified() {
    let m = generators::icosphere(1.0, 3);
    let (field, r) = run(&m, 1);
    assert_certified(&m, &field, &r);
}

#[test]
fn torus_is_remeshed_and_certified_and_reproducible() {
    let m = generators::torus(1.0, 0.35, 48, 18);
    let (field, a) = run(&m, 7);
    assert_certified(&m, &field, &a);
    let (_, b) = run(&m, 7);
    assert_eq!(a.mesh, b.mesh, "same seed, same output");
}

#[test]
fn genus_two_is_remeshed_and_certified() {
    let m = generators::genus_plate(2, 12);
    let (field, r) = run(&m, 3);
    assert_certified(&m, &field, &r);
}

#[test]
fn disk_with_boundary_keeps_its_boundary() {
    let m = generators::disk(1.0, 12, 32);
    let (field, r) = run(&m, 2);
    assert_certified(&m, &field, &r);
}
