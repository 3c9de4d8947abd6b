//! The library does the whole job (the house issue): [`Remesher`] from a mesh in file units
//! to a certified mesh in file units, the same bytes as `conemesh remesh`; typed failures,
//! warnings and the patch budget; the registries reached from the command line.

use conemesh::boundary::BoundaryOptions;
use conemesh::ids::VertexId;
use conemesh::invariants::{
    certify_boundary_on_curves, certify_boundary_preserved, certify_no_degenerate_faces,
    certify_no_self_intersections, certify_same_topology,
};
use conemesh::mesh::{generators, TriMesh};
use conemesh::param::{LinearSystem, ParamError, Parameterization, Parameterizer, SolveFailure};
use conemesh::pipeline::{
    PipelineError, RemeshOptions, Remesher, Stage, StageError, Stages, Warning,
};
use nalgebra::{Matrix3, Point3};
use std::path::Path;
use std::process::Command;

/// A torus far from the origin and not of unit size, so that the unit-space round trip
/// matters.
fn file_torus() -> TriMesh {
    let mut m = generators::torus(1.0, 0.35, 28, 12);
    for p in &mut m.positions {
        *p = Point3::new(12.5 * p.x + 100.0, 12.5 * p.y - 40.0, 12.5 * p.z + 3.0);
    }
    m
}

fn conemesh(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .args(args)
        .output()
        .expect("run conemesh")
}

#[test]
fn the_remesher_returns_a_certified_file_unit_mesh_identical_to_the_cli() {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = file_torus();
    let out = Remesher::new(RemeshOptions {
        seed: 4,
        ..RemeshOptions::default()
    })
    .run(&input)
    .expect("remeshes");
    let m = &out.mesh;
    assert!(m.n_faces() > 100 && m.n_faces() != input.n_faces());
    certify_no_degenerate_faces(m).expect("no degenerate face in file units");
    certify_no_self_intersections(m).expect("embedded in file units");
    certify_same_topology(&input, m).expect("a torus");
    // In file units: every output vertex lies within a small distance of the input.
    let proj = conemesh::mesh::SurfaceProjector::new(&input);
    let worst = m
        .positions
        .iter()
        .map(|p| proj.closest(p).expect("a closest point").2)
        .fold(0.0, f64::max);
    assert!(worst < 0.01 * input.bbox_diagonal(), "{worst}");
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
    assert_eq!(out.output_metric().len(), m.n_vertices());
    // The CLI adds nothing: the same bytes.
    let (inp, cli_out, lib_out) = (
        dir.path().join("in.obj"),
        dir.path().join("cli.obj"),
        dir.path().join("lib.obj"),
    );
    conemesh::io::write_mesh(&inp, &input).expect("write input");
    conemesh::io::write_mesh(&lib_out, m).expect("write output");
    let o = conemesh(&[
        "remesh",
        inp.to_str().expect("utf-8"),
        "-o",
        cli_out.to_str().expect("utf-8"),
        "--seed",
        "4",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        std::fs::read(&cli_out).expect("cli output"),
        std::fs::read(&lib_out).expect("library output")
    );
}

/// A flat disk with a boundary, a constant user metric, unreferenced vertices in the file:
/// the boundary is resampled on the input's curve (kept bit for bit when asked), the metric follows the compaction, errors name the
/// problem.
#[test]
fn a_user_metric_through_the_library() {
    let mut disk = generators::disk(3.0, 6, 10);
    // Two unreferenced vertices at the front: every referenced id shifts.
    disk.positions.insert(0, Point3::new(50.0, 0.0, 0.0));
    disk.positions.insert(0, Point3::new(-50.0, 0.0, 0.0));
    for t in &mut disk.triangles {
        *t = t.map(|v| VertexId(v.0 + 2));
    }
    let n = disk.n_vertices();
    let iso = Matrix3::identity() / (0.3f64 * 0.3);
    let metric = vec![iso; n];
    let remesher = Remesher::new(RemeshOptions {
        target: conemesh::pipeline::TargetLength::Absolute(1.0),
        ..RemeshOptions::default()
    });
    let out = remesher
        .run_with_metric(&disk, &metric)
        .expect("remeshes in the user metric");
    assert_eq!(
        out.input.n_vertices(),
        n - 2,
        "unreferenced vertices dropped"
    );
    assert_eq!(out.input_metric.as_ref().map(Vec::len), Some(n - 2));
    let topo = conemesh::mesh::Topology::build(&out.mesh);
    certify_boundary_on_curves(
        &out.unit.curves,
        &out.input,
        &out.mesh,
        &topo,
        &out.unit.curve,
    )
    .expect("boundary resampled on the input's boundary curve");
    // With resampling off the input's boundary vertices stay bit for bit.
    let kept = Remesher::new(RemeshOptions {
        target: conemesh::pipeline::TargetLength::Absolute(1.0),
        boundary: BoundaryOptions {
            resample: false,
            ..BoundaryOptions::default()
        },
        ..RemeshOptions::default()
    })
    .run_with_metric(&disk, &metric)
    .expect("remeshes with the boundary kept");
    certify_boundary_preserved(&kept.input, &kept.mesh).expect("boundary kept");
    // Edges near 0.3 in file units: about (area / (0.433·0.09)) faces.
    let expected = std::f64::consts::PI * 9.0 / (3f64.sqrt() / 4.0 * 0.09);
    let f = out.mesh.n_faces() as f64;
    assert!(
        f > 0.7 * expected && f < 2.5 * expected,
        "{f} faces, {expected:.0} expected"
    );
    match remesher.run_with_metric(&disk, &metric[1..]) {
        Err(PipelineError::MetricCount { tensors, vertices }) => {
            assert_eq!((tensors + 1, vertices), (metric.len(), disk.n_vertices()))
        }
        other => panic!("a short metric must be refused: {:?}", other.map(|_| ())),
    }
    let mut bad = metric.clone();
    bad[7] = -Matrix3::identity();
    match remesher.run_with_metric(&disk, &bad) {
        // Named as in the file (v7), not in the compacted mesh (v5).
        Err(PipelineError::Metric(e)) => assert!(
            matches!(e, conemesh::metric::MetricError::NotSpd { vertex: 7, .. }),
            "{e}"
        ),
        other => panic!("a negative metric must be refused: {:?}", other.map(|_| ())),
    }
}

/// A parameterizer that always fails: every attempt fails at the parameterization stage with
/// its typed error, the faces are kept, and the run says so.
struct Refuses;
impl Parameterizer for Refuses {
    fn name(&self) -> &'static str {
        "refuses"
    }
    fn parameterize(
        &self,
        _disk: &TriMesh,
        _boundary: &[VertexId],
    ) -> Result<Parameterization, ParamError> {
        Err(ParamError::Solver {
            system: LinearSystem::Tutte,
            failure: SolveFailure::NotPositiveDefinite,
        })
    }
}

#[test]
fn failed_attempts_are_typed_records_and_strict_runs_keep_the_source() {
    let input = generators::torus(1.0, 0.35, 20, 9);
    let stages = || Stages {
        parameterizer: Box::new(Refuses),
        ..Stages::default()
    };
    // Without feature lines: the 9-sided tube's 40° rings would be resampled before the loop,
    // and the faces kept would then not be the input's.
    let no_features = || RemeshOptions {
        features: conemesh::features::FeatureRule::Off,
        ..RemeshOptions::default()
    };
    let out = Remesher::new(no_features())
        .with_stages(stages())
        .run(&input)
        .expect("every patch kept, still certified");
    let r = &out.unit.report;
    assert!(!r.fallbacks.failures.is_empty());
    for f in &r.fallbacks.failures {
        assert_eq!(f.stage, Stage::Parameterization);
        assert!(
            matches!(f.error, StageError::Param(ParamError::Solver { .. })),
            "{f}"
        );
    }
    assert_eq!(r.fallbacks.kept_faces, input.n_faces());
    assert!(out.warnings.iter().any(|w| matches!(
        w,
        Warning::FailedAttempts { kept_faces, .. } if *kept_faces == input.n_faces()
    )));
    let json = serde_json::to_value(r).expect("serialises");
    assert_eq!(
        json["fallbacks"]["failures"][0]["stage"],
        "parameterization"
    );
    // Strict: the first failure is the error, with the stage's error as its source.
    let strict = Remesher::new(RemeshOptions {
        strict: true,
        ..no_features()
    })
    .with_stages(stages())
    .run(&input);
    match strict {
        Err(e @ PipelineError::Stage { .. }) => {
            let PipelineError::Stage { stage, seed, .. } = &e else {
                unreachable!()
            };
            assert_eq!(*stage, Stage::Parameterization);
            assert!(seed.is_some());
            let source = std::error::Error::source(&e).expect("a source");
            assert!(
                matches!(
                    source.downcast_ref::<StageError>(),
                    Some(StageError::Param(ParamError::Solver { .. }))
                ),
                "{source}"
            );
        }
        other => panic!("strict run: {:?}", other.map(|_| ())),
    }
}

#[test]
fn running_out_of_the_patch_budget_is_an_ok_with_a_warning() {
    let input = generators::torus(1.0, 0.35, 28, 12);
    let out = Remesher::new(RemeshOptions {
        max_patches: Some(2),
        ..RemeshOptions::default()
    })
    .run(&input)
    .expect("a budget is not an error");
    let r = &out.unit.report;
    assert!(r.budget_exhausted);
    assert_eq!(r.patches, 2);
    let kept = out.unit.face_patch.iter().filter(|p| p.is_none()).count();
    assert!(kept > 0, "faces no patch reached are the input's");
    assert!(out.warnings.iter().any(|w| matches!(
        w,
        Warning::PatchBudget { patches: 2, unprocessed } if *unprocessed > 0
    )));
    certify_same_topology(&input, &out.mesh).expect("still a torus");
    certify_no_self_intersections(&out.mesh).expect("still embedded");
}

#[test]
fn the_cli_reaches_every_registry() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = |n: &str| dir.path().join(n).to_str().expect("utf-8").to_string();
    conemesh::io::write_mesh(
        Path::new(&path("in.obj")),
        &generators::torus(1.0, 0.4, 20, 9),
    )
    .expect("write");
    let ok = conemesh(&[
        "remesh",
        &path("in.obj"),
        "-o",
        &path("kring.obj"),
        "--strategy",
        "kring",
        "--strategy-opt",
        "rings=4",
        "--param",
        "tutte",
        "--param-opt",
        "weights=uniform",
        "--remesher-opt",
        "rounds=4",
        "--improvers",
        "eq5,surface",
        "--improver-opt",
        "surface.relocate=false",
        "--improver-opt",
        "eq5.q=0.9",
        "--report",
        &path("kring.json"),
        "--quiet",
    ]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(path("kring.json")).expect("report")).expect("json");
    assert_eq!(
        report["run"]["stages"],
        serde_json::json!(["kring", "tutte", "lct"])
    );
    assert_eq!(
        report["run"]["improvers"],
        serde_json::json!(["eq5", "surface"])
    );
    // With relocation off the surface passes only flip.
    assert_eq!(report["run"]["vertex_moves"], 0);
    for (args, says) in [
        (
            vec!["--strategy", "spiral"],
            "unknown patch strategy `spiral` (known: cone, kring)",
        ),
        (vec!["--param", "magic"], "unknown parameterizer `magic`"),
        (vec!["--remesher", "cvt"], "unknown planar remesher `cvt`"),
        (
            vec!["--strategy-opt", "colour=red"],
            "has no option `colour`",
        ),
        (
            vec!["--remesher-opt", "rounds=-3"],
            "`-3` is not a number of rounds",
        ),
        (vec!["--param-opt", "weights"], "not of the form KEY=VALUE"),
        (
            vec!["--strategy", "kring", "--expand-rings", "x"],
            "invalid value",
        ),
    ] {
        let (inp, out) = (path("in.obj"), path("refused.obj"));
        let mut a = vec!["remesh", &inp, "-o", &out, "--quiet"];
        a.extend(args.iter().copied());
        let o = conemesh(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{a:?} must fail");
        assert!(err.contains(says), "{a:?}: {err}");
        assert!(!Path::new(&out).exists(), "{a:?} wrote an output");
    }
    let stages = conemesh(&["stages"]);
    let text = String::from_utf8_lossy(&stages.stdout);
    for name in [
        "cone",
        "kring",
        "sd",
        "tutte",
        "lct",
        "expand_rings",
        "weights",
        "rounds",
    ] {
        assert!(
            text.contains(name),
            "`conemesh stages` lists {name}:\n{text}"
        );
    }
}

/// The report's `wall` gives each phase's wall-clock time: every phase took some time, and
/// together they fit inside the time the caller measured around the run.
#[test]
fn the_report_gives_each_phase_its_wall_clock_time() {
    let input = file_torus();
    let clock = std::time::Instant::now();
    let out = Remesher::new(RemeshOptions::default())
        .run(&input)
        .expect("remeshes");
    let outside = clock.elapsed().as_secs_f64();
    let w = out.unit.report.wall;
    let phases = [w.setup, w.patch_loop, w.improve, w.finish];
    assert!(phases.iter().all(|&t| t > 0.0), "{w:?}");
    assert!(
        phases.iter().sum::<f64>() <= outside,
        "{w:?} against {outside} s"
    );
    // The patch loop's wall time is no more than its stages' times summed over patches (one
    // thread per patch here: batch 1).
    let t = &out.unit.report.times;
    let stages = t.patches + t.param + t.transfer + t.remesh2d + t.lift + t.fidelity + t.stitch;
    assert!(stages <= w.patch_loop + w.improve + w.finish, "{t:?} {w:?}");
}
