//! A method of each research extension point written outside the crate, as a researcher would:
//! a patch strategy, a parameterizer, a planar remesher and an improver, each one type and one
//! registry row ([`conemesh::registry::Entry`]) added to a [`conemesh::registry::Registry`].
//! Every row, built-in or added, passes the contract checks of `conemesh::contract`, and the
//! added rows are built by name like the built-in ones.
//!
//! Also: the run's stages reach the improvers, so `--strategy kring` builds Algorithm 2's
//! patches.

use conemesh::contract::{self, ContractViolation, ImproverCase, StageFailure, StrategyCase};
use conemesh::ids::{FaceId, VertexId};
use conemesh::improve::{ImproveRun, Improver, ImproverCounts, LoopStages, RunError, IMPROVERS};
use conemesh::mesh::{generators, PlanarDomain, PlanarMesh, TriMesh};
use conemesh::param::{ParamError, Parameterization, Parameterizer, Tutte, TutteWeights};
use conemesh::patches::expand::expand_rings;
use conemesh::patches::{
    finish_patch, pick_seed_vertex, unprocessed_ring, DiskPatch, Patch, PatchContext, PatchError,
    PatchStrategy,
};
use conemesh::pipeline::{Registries, RemeshOptions, Remesher, Stages};
use conemesh::quality::TriangleQuality;
use conemesh::registry::{Entry, MetricSizes, OptionDoc, Params, RegistryError, Stage};
use conemesh::remesh2d::{DemoMetric, Metric2d, PlanarRemesher, Remesh2dError};
use rand_chacha::ChaCha8Rng;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

// ------------------------------------------------------------------ a patch strategy

/// Breadth-first disks: from the seed's lowest unprocessed face, add adjacent unprocessed
/// faces (ids in order) until `faces` faces, then one ring of processed ones.
#[derive(Clone, Debug)]
struct Breadth {
    faces: usize,
}

impl Default for Breadth {
    fn default() -> Self {
        Breadth { faces: 40 }
    }
}

impl PatchStrategy for Breadth {
    fn name(&self) -> &'static str {
        "breadth"
    }

    fn next_patch(
        &self,
        ctx: &PatchContext<'_>,
        rng: &mut ChaCha8Rng,
    ) -> Result<Option<Patch>, PatchError> {
        let Some(seed_vertex) = pick_seed_vertex(ctx, rng) else {
            return Ok(None);
        };
        let Some(&seed_face) = unprocessed_ring(ctx, seed_vertex).first() else {
            return Ok(None);
        };
        let unprocessed = |g: FaceId| !ctx.processed[g.idx()];
        let mut disk = DiskPatch::new(ctx, seed_face);
        while disk.len() < self.faces {
            let added = disk
                .adjacent_faces(unprocessed)
                .into_iter()
                .filter(|f| disk.try_add(*f).is_ok())
                .count();
            if added == 0 {
                break;
            }
        }
        expand_rings(&mut disk, ctx.processed, 1);
        finish_patch(&disk, ctx, seed_vertex, seed_face, None, None).map(Some)
    }
}

static BREADTH: Entry<dyn PatchStrategy> = Entry {
    name: "breadth",
    summary: "breadth-first disks of a given size (a test's strategy)",
    options: &[OptionDoc {
        name: "faces",
        doc: "faces grown before the expansion",
        default: |_| Breadth::default().faces.to_string(),
    }],
    build: |p, _| {
        let mut b = Breadth::default();
        if let Some(n) = p.take_checked("faces", "a positive number", |n: usize| n > 0)? {
            b.faces = n;
        }
        Ok(Box::new(b))
    },
};

// ------------------------------------------------------------------ a parameterizer

/// Tutte's uniform map turned by a quarter turn (still bijective, still counter-clockwise).
struct Turned;

impl Parameterizer for Turned {
    fn name(&self) -> &'static str {
        "turned"
    }

    fn parameterize(
        &self,
        disk: &TriMesh,
        boundary: &[VertexId],
    ) -> Result<Parameterization, ParamError> {
        let tutte = Tutte {
            weights: TutteWeights::Uniform,
        };
        let mut map = tutte.parameterize(disk, boundary)?;
        for p in &mut map.uv {
            *p = nalgebra::Point2::new(-p.y, p.x);
        }
        Ok(map)
    }
}

static TURNED: Entry<dyn Parameterizer> = Entry {
    name: "turned",
    summary: "Tutte's uniform map turned by 90° (a test's parameterizer)",
    options: &[],
    build: |_, _| Ok(Box::new(Turned)),
};

// ------------------------------------------------------------------ a planar remesher

/// Keeps the domain's own triangulation (every vertex where it was).
struct Keep;

impl PlanarRemesher for Keep {
    fn name(&self) -> &'static str {
        "keep"
    }

    fn remesh(
        &self,
        domain: &PlanarDomain,
        _metric: &dyn Metric2d,
        _target_length: f64,
        _rng: &mut ChaCha8Rng,
    ) -> Result<PlanarMesh, Remesh2dError> {
        Ok(PlanarMesh {
            points: domain.points.clone(),
            triangles: domain.triangles.clone(),
            origin: (0..domain.points.len() as u32).map(Some).collect(),
        })
    }
}

static KEEP: Entry<dyn PlanarRemesher> = Entry {
    name: "keep",
    summary: "the domain's own triangulation (a test's planar remesher)",
    options: &[],
    build: |_, _| Ok(Box::new(Keep)),
};

// ------------------------------------------------------------------ an improver

/// One patch pass of the run's stages over the faces whose quality is below `q`, keeping a
/// candidate only when its worst quality is not lower.
struct WorstFirst {
    q: f64,
}

impl Improver for WorstFirst {
    fn name(&self) -> &'static str {
        "worst-first"
    }

    fn validate(&self) -> Result<(), conemesh::option_error::OptionError> {
        match self.q > 0.0 && self.q <= 1.0 {
            true => Ok(()),
            false => Err(conemesh::option_error::OptionError::OutOfRange {
                option: "q",
                value: self.q,
                range: "in (0, 1]",
            }),
        }
    }

    fn improve(
        &self,
        stages: LoopStages<'_>,
        run: &mut dyn ImproveRun,
        rng: &mut conemesh::Rng,
    ) -> Result<ImproverCounts, RunError> {
        let targets: Vec<bool> = run.face_qualities().iter().map(|t| t.q < self.q).collect();
        let q_min = |ts: &[TriangleQuality]| ts.iter().map(|t| t.q).fold(f64::INFINITY, f64::min);
        let accept = |old: &[TriangleQuality], new: &[TriangleQuality]| q_min(new) >= q_min(old);
        let pass = run.patch_pass(stages, &targets, Some(20), &accept, rng)?;
        Ok(ImproverCounts {
            passes: 1,
            patches: pass.patches,
            rejected: pass.rejected,
            budget_exhausted: pass.budget_exhausted,
            ..ImproverCounts::default()
        })
    }
}

static WORST_FIRST: Entry<dyn Improver> = Entry {
    name: "worst-first",
    summary: "one certified patch pass over the faces below q (a test's improver)",
    options: &[OptionDoc {
        name: "q",
        doc: "improve the faces whose quality is below this",
        default: |_| "0.3".into(),
    }],
    build: |p, _| {
        let q = p.take_checked("q", "a number in (0, 1]", |q: f64| q > 0.0 && q <= 1.0)?;
        Ok(Box::new(WorstFirst {
            q: q.unwrap_or(0.3),
        }))
    },
};

// ------------------------------------------------------------------ the checks

fn registries() -> Registries {
    let r = Registries::default();
    Registries {
        strategies: r.strategies.with(BREADTH).expect("a new name"),
        parameterizers: r.parameterizers.with(TURNED).expect("a new name"),
        remeshers: r.remeshers.with(KEEP).expect("a new name"),
        improvers: r.improvers.with(WORST_FIRST).expect("a new name"),
    }
}

/// Every row's own contract (builds with its defaults for both kinds of sizes, under its
/// name, and takes its documented defaults).
fn rows_keep_their_contract<T: ?Sized + Stage>(rows: &[Entry<T>]) {
    for row in rows {
        if let Err(e) = contract::registry_row(row) {
            panic!("{} `{}`: {e}", T::KIND, row.name);
        }
    }
}

fn built<T: ?Sized + Stage>(reg: &conemesh::registry::Registry<T>, name: &str) -> Box<T> {
    reg.build(name, Params::default(), MetricSizes::Relative)
        .unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_method_of_each_kind_from_outside_the_crate_is_one_row_and_keeps_its_contract() {
    let reg = registries();
    rows_keep_their_contract(reg.strategies.rows());
    rows_keep_their_contract(reg.parameterizers.rows());
    rows_keep_their_contract(reg.remeshers.rows());
    rows_keep_their_contract(reg.improvers.rows());
    // The rows added last; the defaults are still the built-in first rows.
    assert_eq!(
        reg.strategies.rows().last().map(|e| e.name),
        Some("breadth")
    );
    assert_eq!(reg.strategies.rows()[0].name, "cone");

    // The strategy covers a torus and a partly processed disk.
    let breadth = built(&reg.strategies, "breadth");
    for (mesh, partial) in [
        (generators::torus(1.0, 0.35, 20, 9), false),
        (generators::disk(1.0, 4, 6), true),
    ] {
        let case = StrategyCase {
            processed: (0..mesh.n_faces()).map(|f| partial && f % 3 == 0).collect(),
            mesh: &mesh,
            corners: None,
            feature_edges: None,
            seed: 5,
        };
        let n = contract::patch_strategy(breadth.as_ref(), &case).expect("breadth keeps it");
        assert!(n > 1, "{n} patches");
    }

    // The parameterizer maps a disk bijectively and refuses an annulus.
    let disk = generators::disk(1.0, 3, 6);
    let boundary = conemesh::param::disk_boundary(&disk).expect("a disk");
    let turned = built(&reg.parameterizers, "turned");
    contract::parameterizer(turned.as_ref(), &disk, &boundary).expect("turned keeps it");

    // The planar remesher on the demo square.
    let corners = conemesh::remesh2d::DemoDomain::Square.corners();
    let metric = DemoMetric::UniformIsotropic;
    let polygon = conemesh::remesh2d::resample_polygon(&corners, &metric, 0.25);
    let domain = conemesh::remesh2d::triangulate_polygon(&polygon, &[]).expect("a domain");
    let keep = built(&reg.remeshers, "keep");
    contract::planar_remesher(keep.as_ref(), &domain, &metric, 0.25, 3).expect("keep keeps it");

    // The improver, and every built-in one, on a remeshed torus.
    let mesh = generators::torus(1.0, 0.35, 24, 10);
    let case = ImproverCase {
        mesh: &mesh,
        seed: 2,
    };
    for row in reg.improvers.rows() {
        let improver = built(&reg.improvers, row.name);
        let counts =
            contract::improver(improver, &case).unwrap_or_else(|e| panic!("{}: {e}", row.name));
        if row.name == "worst-first" {
            assert_eq!(counts.passes, 1);
        }
    }

    // The added rows are stages by name, with options, like the built-in ones.
    let stages = Stages::from_registries(
        &reg,
        ("breadth", Params::parse(&["faces=30"]).expect("parses")),
        ("turned", Params::default()),
        ("keep", Params::default()),
        MetricSizes::Relative,
    )
    .expect("builds");
    assert_eq!(
        stages.names(),
        ["breadth", "turned", "keep"].map(String::from)
    );
    assert!(matches!(
        reg.strategies.build("breadth", Params::parse(&["faces=0"]).expect("parses"), MetricSizes::Relative),
        Err(conemesh::registry::RegistryError::BadValue { option, .. }) if option == "faces"
    ));
    // A row's name is taken once.
    assert!(registries().strategies.with(BREADTH).is_err());
}

/// A row whose constructor builds a method of another name is refused by the contract (the
/// name in reports and `--improver-opt NAME.KEY` is the row's).
#[test]
fn a_row_that_builds_another_name_is_caught() {
    static MISNAMED: Entry<dyn PlanarRemesher> = Entry {
        name: "misnamed",
        summary: "builds `keep`",
        options: &[],
        build: |_, _| Ok(Box::new(Keep)),
    };
    let e = contract::registry_row(&MISNAMED).expect_err("another name");
    assert!(
        matches!(
            e,
            ContractViolation::Failed {
                name: "misnamed",
                source: StageFailure::Build(RegistryError::WrongName { built: "keep", .. }),
            }
        ),
        "{e}"
    );
    // And a documented default the constructor does not take.
    static BAD_DEFAULT: Entry<dyn Parameterizer> = Entry {
        name: "turned",
        summary: "documents a default it refuses",
        options: &[OptionDoc {
            name: "angle",
            doc: "the turn",
            default: |_| "a quarter".into(),
        }],
        build: |p, _| {
            p.take::<f64>("angle", "degrees")?;
            Ok(Box::new(Turned))
        },
    };
    let e = contract::registry_row(&BAD_DEFAULT).expect_err("refused default");
    assert!(
        matches!(
            &e,
            ContractViolation::Failed {
                source: StageFailure::Default {
                    source: RegistryError::BadValue { option, .. },
                    ..
                },
                ..
            } if option == "angle"
        ),
        "{e}"
    );
}

// ------------------------------------------------------------------ the run's stages

/// A strategy that counts the patches built by the strategies it hands out for Algorithm 2
/// ([`PatchStrategy::widened`]), and records which strategy those are.
struct Recording {
    inner: Box<dyn PatchStrategy>,
    widened_patches: Arc<AtomicUsize>,
    widened_names: Arc<std::sync::Mutex<Vec<&'static str>>>,
    counts: bool,
}

impl PatchStrategy for Recording {
    fn name(&self) -> &'static str {
        self.inner.name()
    }

    fn next_patch(
        &self,
        ctx: &PatchContext<'_>,
        rng: &mut ChaCha8Rng,
    ) -> Result<Option<Patch>, PatchError> {
        let p = self.inner.next_patch(ctx, rng)?;
        if self.counts && p.is_some() {
            self.widened_patches.fetch_add(1, Ordering::Relaxed);
        }
        Ok(p)
    }

    fn widened(&self, rings: usize) -> Option<Box<dyn PatchStrategy>> {
        let inner = self.inner.widened(rings)?;
        if let Ok(mut names) = self.widened_names.lock() {
            names.push(inner.name());
        }
        Some(Box::new(Recording {
            inner,
            widened_patches: self.widened_patches.clone(),
            widened_names: self.widened_names.clone(),
            counts: true,
        }))
    }
}

/// `--strategy kring` (the stages `conemesh remesh` builds from the registry) reaches
/// Algorithm 2: its patches are k-ring disks, one ring wider each pass.
#[test]
fn the_runs_strategy_builds_algorithm_2s_patches() {
    let mut stages = Stages::from_registry(
        ("kring", Params::default()),
        ("sd", Params::default()),
        ("lct", Params::default()),
        MetricSizes::Relative,
    )
    .expect("builds");
    let eq5 = conemesh::improve::improver("eq5", Params::parse(&["q=0.8"]).expect("parses"))
        .expect("builds");
    assert_eq!(IMPROVERS.iter().filter(|e| e.name == "eq5").count(), 1);
    let widened_patches = Arc::new(AtomicUsize::new(0));
    let widened_names = Arc::new(std::sync::Mutex::new(Vec::new()));
    stages.patches = Box::new(Recording {
        inner: stages.patches,
        widened_patches: widened_patches.clone(),
        widened_names: widened_names.clone(),
        counts: false,
    });
    stages.improvers = vec![eq5];
    let mesh = generators::torus(1.0, 0.35, 24, 10);
    let out = Remesher::new(RemeshOptions::default())
        .with_stages(stages)
        .run(&mesh)
        .expect("remeshes");
    let r = &out.unit.report;
    assert_eq!(r.stages[0], "kring");
    let a2 = r
        .improvement
        .as_ref()
        .and_then(|i| i.step("eq5"))
        .expect("Algorithm 2 ran");
    assert!(a2.counts.patches > 0, "{:?}", a2.counts);
    // Algorithm 2's patches came from the run's kring strategy, widened (a patch refused
    // for its batch is asked for again, so there may be more than it counts).
    assert!(widened_patches.load(Ordering::Relaxed) >= a2.counts.patches);
    let names = widened_names.lock().expect("not poisoned").clone();
    assert_eq!(names.len(), a2.counts.passes);
    assert!(names.iter().all(|n| *n == "kring"), "{names:?}");
}
