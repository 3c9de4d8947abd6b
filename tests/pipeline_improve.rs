//! The improvers after the loop (Sec. 3.4), Algorithm 2 above all, through the library:
//! certified like Algorithm 1, never worse at the bottom, counted, reproducible; and the
//! `Improver` extension point from outside the crate.

use conemesh::improve::{
    Algorithm2, ImproveOptions, ImproveRun, Improver, ImproverCounts, LoopStages, RunError,
    SurfacePasses,
};
use conemesh::invariants::certify_boundary_on_curves;
use conemesh::mesh::Topology;
use conemesh::pipeline::{RemeshOptions, Remesher, Stages};

mod common;

/// The default stages with Algorithm 2 (threshold `q`) after the surface passes.
fn with_improve(q: f64) -> Stages {
    Stages {
        improvers: vec![
            Box::new(SurfacePasses::default()),
            Box::new(Algorithm2 {
                options: ImproveOptions {
                    q_threshold: q,
                    ..ImproveOptions::default()
                },
            }),
        ],
        ..Stages::default()
    }
}

fn seeded(seed: u64) -> RemeshOptions {
    RemeshOptions {
        seed,
        ..RemeshOptions::default()
    }
}

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn the_screwdriver_loses_small_angles_and_stays_certified() {
    let input = common::load("screwdriver.off");
    // Without feature lines: with the automatic rule Algorithm 1 alone already reaches θ_min
    // 20.9° on the screwdriver, and this test is about what Algorithm 2 does to small angles.
    let options = RemeshOptions {
        features: conemesh::features::FeatureRule::Off,
        ..seeded(1)
    };
    let out = Remesher::new(options)
        .with_stages(with_improve(0.7))
        .run(&input)
        .expect("remeshes");
    let r = &out.unit.report;
    assert_eq!(r.improvers, ["surface", "eq5"]);
    let all = r.improvement.as_ref().expect("the improvers ran");
    let surface = all.step("surface").expect("surface passes ran");
    let a2 = all.step("eq5").expect("Algorithm 2 ran");
    let (before, after, c) = (&surface.after, &a2.after, &a2.counts);
    // It found faces to improve, in counted passes and patches.
    assert!(c.patches > 0 && c.passes >= 1 && c.passes <= 3, "{a2:?}");
    assert!(!c.budget_exhausted);
    // Never worse at the bottom, and better here (measured: θ_min 11.8° → 21.3°, q_min
    // 0.287 → 0.440, faces below 20° 5 → 0).
    assert!(after.theta_min > before.theta_min + 5.0, "{a2:?}");
    assert!(after.q_min > before.q_min + 0.1, "{a2:?}");
    assert!(after.below_20 < before.below_20, "{a2:?}");
    assert!(c.rejected < c.patches, "{a2:?}");
    assert!(after.q_avg >= before.q_avg - 0.002, "{a2:?}");
    assert_eq!(after.faces, out.mesh.n_faces());
    assert_eq!(&all.after, after);
    // Certified as Algorithm 1's patches: every patch (both algorithms) counted once for
    // the manifold and topology certificates, no flips, no self-intersections.
    let c = &r.certificate;
    assert_eq!(c.manifold, r.patches);
    assert_eq!(c.same_topology, r.patches);
    assert_eq!(c.self_intersecting_pairs, 0);
    let q = conemesh::quality::flips(&out.input, &out.mesh);
    assert!(q.is_empty(), "flipped faces {q:?}");
    let topo = Topology::build(&out.unit.mesh);
    certify_boundary_on_curves(
        &out.unit.curves,
        &out.input,
        &out.mesh,
        &topo,
        &out.unit.curve,
    )
    .expect("boundary on the input's curves");
    // Without it the run makes fewer patches and ends at the surface passes' row.
    let plain = Remesher::new(seeded(1)).run(&input).expect("remeshes");
    let p = plain.unit.report.improvement.as_ref().expect("surface ran");
    let defaults = conemesh::pipeline::default_improver_names();
    assert_eq!(plain.unit.report.improvers, defaults);
    if !defaults.contains(&"eq5") {
        assert!(plain.unit.report.patches < r.patches);
        assert_eq!(p.after, surface.after);
    }
}

/// A research improver written outside the crate: one patch pass over every face through
/// the run's own stages, whose every candidate it refuses.
struct RefuseEverything;

impl Improver for RefuseEverything {
    fn name(&self) -> &'static str {
        "refuse-everything"
    }
    fn improve(
        &self,
        stages: LoopStages<'_>,
        run: &mut dyn ImproveRun,
        rng: &mut conemesh::Rng,
    ) -> Result<ImproverCounts, RunError> {
        let all = vec![true; run.working_mesh().mesh.n_faces()];
        let pass = run.patch_pass(stages, &all, None, &|_, _| false, rng)?;
        Ok(ImproverCounts {
            passes: 1,
            patches: pass.patches,
            rejected: pass.rejected,
            budget_exhausted: pass.budget_exhausted,
            ..ImproverCounts::default()
        })
    }
}

#[test]
fn an_improver_from_outside_the_crate_runs_certified_and_its_refusals_keep_the_mesh() {
    let input = conemesh::mesh::generators::default_surface();
    let options = || RemeshOptions {
        max_patches: None,
        ..seeded(3)
    };
    let plain = Remesher::new(options())
        .with_stages(Stages {
            improvers: vec![],
            ..Stages::default()
        })
        .run(&input)
        .expect("plain");
    assert!(plain.unit.report.improvement.is_none());
    let refused = Remesher::new(options())
        .with_stages(Stages {
            improvers: vec![Box::new(RefuseEverything)],
            ..Stages::default()
        })
        .run(&input)
        .expect("with the research improver");
    let r = &refused.unit.report;
    let step = r
        .improvement
        .as_ref()
        .and_then(|i| i.step("refuse-everything"));
    let step = step.expect("it ran");
    // It made patches over the whole surface, each certified (a patch counts once for the
    // manifold certificate) and each refused, so the mesh is Algorithm 1's, bytes and all.
    assert!(step.counts.patches > 0, "{step:?}");
    assert_eq!(step.counts.rejected, step.counts.patches);
    assert_eq!(r.patches, plain.unit.report.patches + step.counts.patches);
    assert_eq!(r.certificate.manifold, r.patches);
    assert_eq!(refused.mesh.positions, plain.mesh.positions);
    assert_eq!(refused.mesh.triangles, plain.mesh.triangles);
    // A bad option of an improver is refused before any work, naming it.
    let bad = Remesher::new(options())
        .with_stages(Stages {
            improvers: vec![Box::new(Algorithm2 {
                options: ImproveOptions {
                    rings: 0,
                    ..ImproveOptions::default()
                },
            })],
            ..Stages::default()
        })
        .run(&input);
    assert!(
        matches!(
            &bad,
            Err(conemesh::pipeline::PipelineError::ImproverOption {
                improver: "eq5",
                source: conemesh::option_error::OptionError::TooFew {
                    option: "improvement rings",
                    ..
                },
            })
        ),
        "{:?}",
        bad.err()
    );
}

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn same_seed_same_bytes_with_the_improvement() {
    let input = common::load("3holes.off");
    let run = || {
        Remesher::new(seeded(2))
            .with_stages(with_improve(0.8))
            .run(&input)
            .expect("runs")
    };
    let (a, b) = (run(), run());
    assert_eq!(a.mesh.positions, b.mesh.positions);
    assert_eq!(a.mesh.triangles, b.mesh.triangles);
    let imp = a.unit.report.improvement.expect("ran");
    let (before, after) = (imp.steps[0].after, imp.steps[1].after);
    // A patch is replaced only when neither its smallest quality nor its smallest angle
    // drops, so the mesh's cannot.
    assert!(after.theta_min >= before.theta_min, "{imp:?}");
    assert!(after.q_min >= before.q_min, "{imp:?}");
}

#[test]
fn the_cli_reports_and_plots_the_step_and_refuses_bad_values() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out_mesh = dir.path().join("out.obj");
    let report = dir.path().join("r.json");
    let plots = dir.path().join("plots");
    let run = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_conemesh"))
            .arg("remesh")
            .arg("-o")
            .arg(&out_mesh)
            .arg("--quiet")
            .args(extra)
            .output()
            .expect("runs")
    };
    let o = run(&[
        "--improver-opt",
        "eq5.q=0.9",
        "--report",
        report.to_str().unwrap(),
        "--plots",
        plots.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let imp = &doc["run"]["improvement"];
    assert_eq!(imp["steps"][1]["name"], "eq5", "{imp}");
    assert!(
        imp["steps"][1]["counts"]["patches"].as_u64().unwrap() > 0,
        "{imp}"
    );
    let hist: Vec<u64> = imp["after"]["hist_min_angles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect();
    assert_eq!(
        hist.iter().sum::<u64>(),
        imp["after"]["faces"].as_u64().unwrap()
    );
    assert!(plots.join("hist_min_angles_improve.png").is_file());
    for (bad, named) in [
        (&["--improver-opt", "eq5.q=1.5"][..], "`q`"),
        (&["--improver-opt", "eq5.w=nan"], "`w`"),
        (&["--improver-opt", "eq5.rings=0"], "`rings`"),
        (&["--improver-opt", "eq5.q=2"], "`q`"),
        (
            &["--improvers", "surface", "--improver-opt", "eq5.q=0.5"],
            "does not run",
        ),
        (&["--improver-opt", "surface.q=0.5"], "no option `q`"),
        (&["--improver-opt", "eq5q=0.5"], "NAME.KEY=VALUE"),
        (
            &["--improvers", "surface,laplace"],
            "unknown improver `laplace`",
        ),
    ] {
        std::fs::remove_file(&out_mesh).ok();
        let o = run(bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(named), "{bad:?}: {err}");
        assert!(!out_mesh.exists(), "no output for {bad:?}");
    }
}
