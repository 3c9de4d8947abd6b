//! Algorithm 1 end to end (issue 9): certificates hold, the loop terminates, runs are
//! reproducible, quality is reported.

use conemesh::mesh::generators;
use conemesh::metric::{MetricField, MetricOptions, Normalization};
use conemesh::patches::{ConePatches, Patch, PatchContext, PatchError, PatchStrategy};
use conemesh::pipeline::{remesh, RemeshOptions, RemeshResult, Stage, Stages};
use conemesh::{Topology, TriMesh};
use rand_chacha::ChaCha8Rng;
use std::sync::{Arc, Mutex};

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
    // Progress is reported once per batch of Algorithm 1's loop (the improvers' patches come
    // after): at least one patch, at most `batch` patches each. With regions, once when they
    // are done, then per batch of the loop after them.
    let patches = result.report.loop_patches;
    match result.report.regions.count {
        1 => assert!(
            calls <= patches && calls * options.batch >= patches,
            "{calls} reports for {patches} patches"
        ),
        _ => assert!(
            calls >= 1 && calls <= patches,
            "{calls} reports for {patches} patches"
        ),
    }
    assert!(result.report.loop_patches <= mesh.n_faces());
    (field, result)
}

/// How many failed attempts (the typed records of `report.fallbacks.failures`) got past each
/// certificate before failing. An attempt runs, in order: certify_disk, parameterization
/// (+ certify_bijective), metric transfer, planar remeshing (+ certify_planar), mapping back,
/// lifted-face certificates.
fn failures_past(r: &RemeshResult) -> (usize, usize) {
    let mut past_param = 0;
    let mut past_planar = 0;
    for f in &r.report.fallbacks.failures {
        match f.stage {
            Stage::PatchExtraction | Stage::Parameterization => {}
            Stage::MetricTransfer | Stage::PlanarRemeshing => past_param += 1,
            Stage::MappingBack | Stage::LiftedFaces => {
                past_param += 1;
                past_planar += 1;
            }
            other => panic!("a failed attempt cannot stop at `{other}`: {f}"),
        }
    }
    (past_param, past_planar)
}

fn assert_certified(input: &TriMesh, field: &MetricField, r: &RemeshResult) {
    let c = &r.report.certificate;
    let n = r.report.patches;
    assert!(n > 0);
    assert_eq!(r.report.patch_records.len(), n);
    // Really remeshed: most input faces replaced (an output equal to the input, every patch
    // kept, would pass the certificates below).
    assert!(
        r.report.fallbacks.kept_faces * 20 <= input.n_faces(),
        "{} of {} input faces kept unchanged",
        r.report.fallbacks.kept_faces,
        input.n_faces()
    );
    assert!(r.report.patch_records.iter().filter(|p| !p.kept).count() * 2 > n);
    assert_ne!(
        r.mesh.n_faces(),
        input.n_faces(),
        "face count unchanged: not remeshed?"
    );
    // Patches whose every attempt failed keep their faces unchanged (the retry ladder's last
    // rung): they pass the working-mesh certificates but not the per-candidate ones.
    let kept = r.report.patch_records.iter().filter(|p| p.kept).count();
    let failures = r.report.fallbacks.failures.len();
    let retries: usize = r.report.patch_records.iter().map(|p| p.retries).sum();
    assert_eq!(
        retries, failures,
        "per-patch retries add up to the failures"
    );
    let kept_faces: usize = r
        .report
        .patch_records
        .iter()
        .filter(|p| p.kept)
        .map(|p| p.unprocessed_in)
        .sum();
    assert_eq!(kept_faces, r.report.fallbacks.kept_faces);
    let (past_param, past_planar) = failures_past(r);
    let remeshed = n - kept;
    // Once per patch, on the working mesh.
    for (name, count) in [
        ("manifold", c.manifold),
        ("oriented", c.oriented),
        ("same_topology", c.same_topology),
        ("boundary_preserved", c.boundary_preserved),
    ] {
        assert_eq!(
            count, n,
            "certificate {name} held {count} times for {n} patches"
        );
    }
    // Once per attempt (every attempt certifies its disk first).
    assert_eq!(
        c.disk,
        remeshed + failures,
        "disk certificate: {remeshed} remeshed patches + {failures} failed attempts"
    );
    // Once per attempt that got that far.
    assert_eq!(c.bijective, remeshed + past_param, "bijective");
    assert_eq!(c.planar, remeshed + past_planar, "planar");
    assert_eq!(c.no_degenerate, remeshed, "no_degenerate");
    assert_eq!(c.no_flips, remeshed, "no_flips");
    assert_eq!(c.no_self_intersections, 1);
    // Independent re-check of the final mesh with the foundation's certificates.
    let topo = Topology::build(&r.mesh);
    assert!(topo.is_oriented_manifold());
    conemesh::invariants::certify_same_topology(field.reference(), &r.mesh)
        .expect("same topology as the input");
    conemesh::invariants::certify_boundary_on_curves(
        &r.curves,
        field.reference(),
        &r.mesh,
        &topo,
        &r.curve,
    )
    .expect("the boundary lies on the input's boundary curves, corners kept");
    assert!(conemesh::invariants::self_intersections(&r.mesh).is_empty());
    assert!(conemesh::quality::flips(field.reference(), &r.mesh).is_empty());
    assert_eq!(r.report.faces_in, input.n_faces());
    assert_eq!(r.report.faces_out, r.mesh.n_faces());
    // Every output vertex lies on the reference surface at its recorded location.
    assert_eq!(r.locations.len(), r.mesh.n_vertices());
    for (p, loc) in r.mesh.positions.iter().zip(&r.locations) {
        let q = loc.position(field.reference());
        assert!((p - q).norm() <= 1e-12, "vertex off its reference location");
    }
}

/// A strategy that delegates to the paper's [`ConePatches`] and records, before every
/// batch (the first request of a batch sees no blocked faces), how many faces of the working
/// mesh are still unprocessed, and counts all requests.
struct Recording {
    inner: ConePatches,
    unprocessed: Arc<Mutex<Vec<usize>>>,
    requests: Arc<Mutex<usize>>,
}

impl PatchStrategy for Recording {
    fn name(&self) -> &'static str {
        "recording-cone"
    }
    fn next_patch(
        &self,
        ctx: &PatchContext<'_>,
        rng: &mut ChaCha8Rng,
    ) -> Result<Option<Patch>, PatchError> {
        if ctx.blocked.is_none() {
            let left = ctx.processed.iter().filter(|p| !**p).count();
            self.unprocessed.lock().expect("not poisoned").push(left);
        }
        *self.requests.lock().expect("not poisoned") += 1;
        self.inner.next_patch(ctx, rng)
    }
}

fn assert_terminates(mesh: &TriMesh, seed: u64) {
    let norm = Normalization::of(mesh);
    let field =
        MetricField::from_curvature(norm.apply(mesh), &MetricOptions::default()).expect("metric");
    let unprocessed = Arc::new(Mutex::new(Vec::new()));
    let requests = Arc::new(Mutex::new(0usize));
    let stages = Stages {
        patches: Box::new(Recording {
            inner: ConePatches::default(),
            unprocessed: unprocessed.clone(),
            requests: requests.clone(),
        }),
        // Algorithm 1's loop alone: the improvers take the run's strategy too (Algorithm 2's
        // patches), and their requests are not the loop's.
        improvers: Vec::new(),
        ..Stages::default()
    };
    let options = RemeshOptions {
        seed,
        ..RemeshOptions::default()
    };
    let r = remesh(&field, &stages, &options, |_| {}).expect("remesh succeeds");
    let seen = unprocessed.lock().expect("not poisoned").clone();
    // The strategy is asked at least once per patch and opens each batch (never again once
    // nothing is left); each batch takes between 1 and `batch` patches.
    let asked = *requests.lock().expect("not poisoned");
    let patches = r.report.loop_patches;
    assert!(asked >= patches, "{asked} requests for {patches} patches");
    assert!(seen.len() <= patches && seen.len() * options.batch >= patches);
    assert_eq!(
        seen[0],
        mesh.n_faces(),
        "all faces unprocessed at the start"
    );
    for (i, w) in seen.windows(2).enumerate() {
        assert!(
            w[1] < w[0],
            "batch {} did not reduce the unprocessed count ({} -> {})",
            i,
            w[0],
            w[1]
        );
    }
    // Each patch consumes at least one input face, so the loop is bounded by the input size.
    assert!(
        r.report.loop_patches <= mesh.n_faces(),
        "{} patches for {} input faces",
        r.report.loop_patches,
        mesh.n_faces()
    );
    for rec in &r.report.patch_records {
        assert!(rec.unprocessed_in >= 1, "patch {} without progress", rec.id);
    }
    assert_certified(mesh, &field, &r);
}

#[test]
fn the_loop_terminates_unprocessed_count_strictly_decreases() {
    assert_terminates(&generators::torus(1.0, 0.35, 32, 12), 11);
    assert_terminates(&generators::disk(1.0, 8, 24), 4);
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
