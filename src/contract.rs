//! The contracts of the research extension points, as checks anyone can run on an
//! implementation: [`patch_strategy`], [`parameterizer`], [`planar_remesher`], [`improver`],
//! and on a registry row: [`registry_row`]. The property tests run them over every row of
//! every registry (`proptests/contract.rs`), so a new method added to a registry is checked
//! without writing a test; a researcher can call them on a method before registering it, or
//! on rows of their own (`tests/extension.rs` does, for a method of each kind).
//!
//! Each check exercises the implementation on the inputs given, verifies every promise of
//! the trait's documentation with the exact certificates of [`crate::invariants`], and
//! returns the first broken promise, naming the elements.

use crate::ids::{EdgeKey, FaceId, VertexId};
use crate::improve::{Improver, ImproverCounts};
use crate::invariants::{self, InvariantError};
use crate::mesh::{PlanarDomain, Topology, TriMesh};
use crate::param::Parameterizer;
use crate::patches::{interior_corner, interior_feature, PatchContext, PatchStrategy};
use crate::pipeline::{RemeshOptions, Remesher, Stages};
use crate::registry::{Entry, MetricSizes, Params, RegistryError, Stage};
use crate::remesh2d::{Metric2d, PlanarRemesher};
use crate::Rng;
use rand::SeedableRng;
use std::collections::HashSet;
use thiserror::Error;

/// A broken promise of an extension point.
#[derive(Debug, Error)]
pub enum ContractViolation {
    /// The implementation returned an error where it must succeed.
    #[error("`{name}` failed: {source}")]
    Failed {
        /// the implementation
        name: &'static str,
        /// its error
        source: StageFailure,
    },
    /// A certificate of the result failed.
    #[error("`{name}`: {what}: {violation}")]
    Certificate {
        /// the implementation
        name: &'static str,
        /// which promise
        what: &'static str,
        /// the certificate's error, naming the elements
        violation: InvariantError,
    },
    /// Any other broken promise.
    #[error("`{name}`: {promise}")]
    Broken {
        /// the implementation
        name: &'static str,
        /// what was promised and what happened
        promise: BrokenPromise,
    },
}

/// The error of an implementation that failed where it must succeed
/// ([`ContractViolation::Failed`]), as its stage gave it.
#[derive(Debug, Error)]
pub enum StageFailure {
    /// The registry row does not build with its defaults.
    #[error("{0}")]
    Build(#[source] RegistryError),
    /// The registry row refuses an option given its documented default.
    #[error("its documented default, for {sizes:?} sizes: {source}")]
    Default {
        /// the kind of sizes it was built for
        sizes: MetricSizes,
        /// the registry's error
        source: RegistryError,
    },
    /// The improver's options do not validate.
    #[error("its options do not validate: {0}")]
    Options(#[source] crate::option_error::OptionError),
    /// The run with the improver failed.
    #[error("{0}")]
    Run(#[source] Box<crate::pipeline::PipelineError>),
    /// The patch strategy failed.
    #[error("{0}")]
    Patch(#[source] crate::patches::PatchError),
    /// The parameterizer failed.
    #[error("{0}")]
    Param(#[source] crate::param::ParamError),
    /// The planar remesher failed.
    #[error("{0}")]
    Remesh2d(#[source] crate::remesh2d::Remesh2dError),
}

/// A promise of an extension point's documentation that a result breaks
/// ([`ContractViolation::Broken`]), with the elements and counts that show it.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BrokenPromise {
    /// A registry row lists an option twice.
    #[error("option `{option}` is listed twice")]
    OptionTwice {
        /// the option
        option: &'static str,
    },
    /// The run with an improver has no improvement report.
    #[error("the run has no improvement report")]
    NoImprovementReport,
    /// The run with one improver reports another number of steps.
    #[error("{0} improvement steps for one improver")]
    ImprovementSteps(usize),
    /// The improver's step is under another name.
    #[error("its step is named `{step}`")]
    StepName {
        /// the step's name
        step: String,
    },
    /// The same seed gave a different mesh.
    #[error("the same seed gave a different mesh")]
    NotDeterministic,
    /// The same seed gave a different patch.
    #[error("patch {patch}: the same seed gave a different patch")]
    PatchNotDeterministic {
        /// the patch's number in the run
        patch: usize,
    },
    /// No patch while faces are unprocessed.
    #[error("returned no patch with {unprocessed} faces unprocessed")]
    NoPatch {
        /// the unprocessed faces
        unprocessed: usize,
    },
    /// A patch when every face is processed.
    #[error("returned a patch with every face processed")]
    PatchWhenDone,
    /// More patches than faces.
    #[error("{patches} patches for {faces} faces")]
    TooManyPatches {
        /// patches returned
        patches: usize,
        /// faces of the mesh
        faces: usize,
    },
    /// The returned boundary is not the certified loop of the patch's faces.
    #[error(
        "patch {patch}: the returned boundary ({len} vertices from {first:?}) is not the certified loop of its faces"
    )]
    WrongBoundary {
        /// the patch's number in the run
        patch: usize,
        /// the returned boundary's length
        len: usize,
        /// its first vertex
        first: Option<VertexId>,
    },
    /// The seed face is not a face of the patch, or does not hold the seed vertex.
    #[error(
        "patch {patch}: its seed face {face} (with seed vertex {vertex}) is not one of its faces"
    )]
    SeedOutside {
        /// the patch's number in the run
        patch: usize,
        /// the seed face
        face: FaceId,
        /// the seed vertex
        vertex: VertexId,
    },
    /// `shrink` did not give a smaller part of the patch.
    #[error("patch {patch}: shrink to {target} gave {got} faces, not a smaller part of the patch")]
    BadShrink {
        /// the patch's number in the run
        patch: usize,
        /// the faces asked for
        target: usize,
        /// the faces given
        got: usize,
    },
    /// A face outside the mesh.
    #[error("face {0} is not in the mesh")]
    FaceOutside(FaceId),
    /// Faces not sorted by id, or repeated.
    #[error("faces are not sorted by id without repeats")]
    Unsorted,
    /// A patch of processed faces only.
    #[error("a patch without an unprocessed face")]
    AllProcessed,
    /// A corner vertex inside a patch.
    #[error("the corner vertex {0} is inside a patch")]
    CornerInside(VertexId),
    /// A feature edge inside a patch.
    #[error("the feature edge {0} is inside a patch")]
    FeatureInside(EdgeKey),
    /// Another number of points than vertices.
    #[error("{points} points for {vertices} vertices")]
    PointCount {
        /// points returned
        points: usize,
        /// vertices of the mesh
        vertices: usize,
    },
    /// A point that is not finite.
    #[error("the point of {0} is not finite")]
    NonFinitePoint(VertexId),
    /// A second call gave a different map.
    #[error("a second call gave a different map")]
    DifferentMap,
    /// A map of a mesh that is not a disk.
    #[error("returned a map of a mesh that is not a disk (face {0} removed)")]
    MappedNonDisk(FaceId),
}

/// The contract of a registry row: for either kind of sizes it builds with its defaults, the
/// built implementation's `name()` is the row's name, the options' names are distinct, and
/// every option given its documented default explicitly (`KEY=DEFAULT`) is taken.
pub fn registry_row<T: ?Sized + Stage>(row: &Entry<T>) -> Result<(), ContractViolation> {
    let name = row.name;
    let failed = |source: StageFailure| ContractViolation::Failed { name, source };
    let table = std::slice::from_ref(row);
    for (i, o) in row.options.iter().enumerate() {
        if row.options[..i].iter().any(|p| p.name == o.name) {
            return Err(ContractViolation::Broken {
                name,
                promise: BrokenPromise::OptionTwice { option: o.name },
            });
        }
    }
    for sizes in MetricSizes::ALL {
        crate::registry::build(table, name, Params::default(), sizes)
            .map_err(|e| failed(StageFailure::Build(e)))?;
        for o in row.options {
            let mut given = Params::default();
            given.set(o.name, (o.default)(sizes));
            crate::registry::build(table, name, given, sizes)
                .map_err(|source| failed(StageFailure::Default { sizes, source }))?;
        }
    }
    Ok(())
}

/// What an improver is run on: a mesh remeshed by Algorithm 1 with the default stages and
/// `seed`, then improved.
pub struct ImproverCase<'a> {
    /// A closed or bounded manifold mesh.
    pub mesh: &'a TriMesh,
    /// Seed of the run.
    pub seed: u64,
}

/// The contract of [`Improver`]: its options validate; a run of the default loop stages with
/// it as the only improver ends `Ok` (so every patch it replaced and the whole output passed
/// their certificates); the improvement report has one step, under its name; and the same
/// seed gives the same mesh bit for bit. Returns its counts.
pub fn improver(
    improver: Box<dyn Improver>,
    case: &ImproverCase<'_>,
) -> Result<ImproverCounts, ContractViolation> {
    let name = improver.name();
    let broken = |promise: BrokenPromise| ContractViolation::Broken { name, promise };
    improver.validate().map_err(|e| ContractViolation::Failed {
        name,
        source: StageFailure::Options(e),
    })?;
    let remesher = Remesher::new(RemeshOptions {
        seed: case.seed,
        ..RemeshOptions::default()
    })
    .with_stages(Stages {
        improvers: vec![improver],
        ..Stages::for_sizes(MetricSizes::Relative)
    });
    let run = || {
        remesher
            .run(case.mesh)
            .map_err(|e| ContractViolation::Failed {
                name,
                source: StageFailure::Run(Box::new(e)),
            })
    };
    let out = run()?;
    let Some(report) = &out.unit.report.improvement else {
        return Err(broken(BrokenPromise::NoImprovementReport));
    };
    let [step] = report.steps.as_slice() else {
        return Err(broken(BrokenPromise::ImprovementSteps(report.steps.len())));
    };
    if step.name != name {
        return Err(broken(BrokenPromise::StepName {
            step: step.name.to_string(),
        }));
    }
    let again = run()?;
    if again.mesh.positions != out.mesh.positions || again.mesh.triangles != out.mesh.triangles {
        return Err(broken(BrokenPromise::NotDeterministic));
    }
    Ok(step.counts)
}

/// What a patch strategy is run on: a mesh, the faces already processed, and optionally
/// corners and feature edges it must respect.
pub struct StrategyCase<'a> {
    /// A manifold, consistently oriented mesh.
    pub mesh: &'a TriMesh,
    /// `processed[f]` at the start.
    pub processed: Vec<bool>,
    /// Vertices no patch may contain in its interior.
    pub corners: Option<&'a [bool]>,
    /// Edges no patch may contain in its interior.
    pub feature_edges: Option<&'a HashSet<EdgeKey>>,
    /// Seed of the run.
    pub seed: u64,
}

/// The contract of [`PatchStrategy`], over a whole covering run from `case`: every returned
/// patch is in range, sorted and without repeats, a certified disk whose boundary loop is
/// the returned one (same orientation), contains an unprocessed face and its seed face, has
/// no corner vertex and no feature edge inside; [`PatchStrategy::shrink`] of it is a smaller
/// disk inside it with the same promises; the run is reproducible from its seed and ends
/// (`Ok(None)` exactly when no face is unprocessed) within one patch per face. Returns the
/// number of patches.
pub fn patch_strategy(
    strategy: &dyn PatchStrategy,
    case: &StrategyCase<'_>,
) -> Result<usize, ContractViolation> {
    let name = strategy.name();
    let broken = |promise: BrokenPromise| ContractViolation::Broken { name, promise };
    let topo = Topology::build(case.mesh);
    let mut processed = case.processed.clone();
    let (mut rng, mut again) = (Rng::seed_from_u64(case.seed), Rng::seed_from_u64(case.seed));
    let mut patches = 0;
    loop {
        let ctx = PatchContext {
            mesh: case.mesh,
            topology: &topo,
            processed: &processed,
            feature_edges: case.feature_edges,
            corners: case.corners,
            blocked: None,
        };
        let unprocessed = processed.iter().filter(|p| !**p).count();
        let failed = |e: crate::patches::PatchError| ContractViolation::Failed {
            name,
            source: StageFailure::Patch(e),
        };
        let got = strategy.next_patch(&ctx, &mut rng).map_err(failed)?;
        let twin = strategy.next_patch(&ctx, &mut again).map_err(failed)?;
        if got != twin {
            return Err(broken(BrokenPromise::PatchNotDeterministic {
                patch: patches,
            }));
        }
        let Some(patch) = got else {
            return match unprocessed {
                0 => Ok(patches),
                unprocessed => Err(broken(BrokenPromise::NoPatch { unprocessed })),
            };
        };
        if unprocessed == 0 {
            return Err(broken(BrokenPromise::PatchWhenDone));
        }
        if patches > case.mesh.n_faces() {
            return Err(broken(BrokenPromise::TooManyPatches {
                patches,
                faces: case.mesh.n_faces(),
            }));
        }
        let boundary = check_patch_faces(name, &ctx, &patch.faces)?;
        if !same_loop(&boundary, &patch.boundary) {
            return Err(broken(BrokenPromise::WrongBoundary {
                patch: patches,
                len: patch.boundary.len(),
                first: patch.boundary.first().copied(),
            }));
        }
        if patch.faces.binary_search(&patch.seed_face).is_err()
            || !case.mesh.face(patch.seed_face).contains(&patch.seed_vertex)
        {
            return Err(broken(BrokenPromise::SeedOutside {
                patch: patches,
                face: patch.seed_face,
                vertex: patch.seed_vertex,
            }));
        }
        if patch.faces.len() > 1 {
            let target = patch.faces.len() / 2;
            let smaller = strategy.shrink(&ctx, &patch.faces, patch.seed_face, target);
            let inside: HashSet<FaceId> = patch.faces.iter().copied().collect();
            if smaller.len() >= patch.faces.len() || smaller.iter().any(|f| !inside.contains(f)) {
                return Err(broken(BrokenPromise::BadShrink {
                    patch: patches,
                    target,
                    got: smaller.len(),
                }));
            }
            let mut sorted = smaller.clone();
            sorted.sort_unstable();
            check_patch_faces(name, &ctx, &sorted)?;
        }
        for f in &patch.faces {
            processed[f.idx()] = true;
        }
        patches += 1;
    }
}

/// The promises on one face set of a strategy: in range, sorted without repeats, a certified
/// disk with an unprocessed face, no corner or feature edge inside. Returns its boundary.
fn check_patch_faces(
    name: &'static str,
    ctx: &PatchContext<'_>,
    faces: &[FaceId],
) -> Result<Vec<crate::ids::VertexId>, ContractViolation> {
    let broken = |promise: BrokenPromise| ContractViolation::Broken { name, promise };
    if let Some(f) = faces.iter().find(|f| f.idx() >= ctx.mesh.n_faces()) {
        return Err(broken(BrokenPromise::FaceOutside(*f)));
    }
    if faces.windows(2).any(|w| w[0] >= w[1]) {
        return Err(broken(BrokenPromise::Unsorted));
    }
    if faces.iter().all(|f| ctx.processed[f.idx()]) {
        return Err(broken(BrokenPromise::AllProcessed));
    }
    let boundary = invariants::certify_disk(ctx.mesh, faces).map_err(|violation| {
        ContractViolation::Certificate {
            name,
            what: "patch is a disk",
            violation,
        }
    })?;
    if let Some(v) = ctx
        .corners
        .and_then(|c| interior_corner(ctx.mesh, ctx.topology, faces, c))
    {
        return Err(broken(BrokenPromise::CornerInside(v)));
    }
    if let Some(e) = ctx
        .feature_edges
        .and_then(|fe| interior_feature(ctx.mesh, faces, fe))
    {
        return Err(broken(BrokenPromise::FeatureInside(e)));
    }
    Ok(boundary)
}

/// `a` and `b` are the same cyclic vertex sequence (same start allowed to differ).
fn same_loop<T: PartialEq>(a: &[T], b: &[T]) -> bool {
    a.len() == b.len()
        && (a.is_empty()
            || b.iter()
                .position(|x| *x == a[0])
                .is_some_and(|s| (0..a.len()).all(|i| a[i] == b[(s + i) % b.len()])))
}

/// The contract of [`Parameterizer`] on a disk mesh `disk` with boundary loop `boundary`
/// (surface on the left): it succeeds, gives one finite point per vertex, the map passes the
/// exact bijectivity certificate, and a second call gives the same map bit for bit. Then,
/// given `disk` with one face removed so that it is no longer a disk (an annulus or a pinch),
/// it must refuse with an error rather than return a map.
pub fn parameterizer(
    param: &dyn Parameterizer,
    disk: &TriMesh,
    boundary: &[crate::ids::VertexId],
) -> Result<(), ContractViolation> {
    let name = param.name();
    let broken = |promise: BrokenPromise| ContractViolation::Broken { name, promise };
    let map = param
        .parameterize(disk, boundary)
        .map_err(|e| ContractViolation::Failed {
            name,
            source: StageFailure::Param(e),
        })?;
    if map.uv.len() != disk.n_vertices() {
        return Err(broken(BrokenPromise::PointCount {
            points: map.uv.len(),
            vertices: disk.n_vertices(),
        }));
    }
    if let Some(i) = map
        .uv
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite()))
    {
        return Err(broken(BrokenPromise::NonFinitePoint(VertexId::new(i))));
    }
    invariants::certify_bijective(&map.uv, &disk.triangles, boundary).map_err(|violation| {
        ContractViolation::Certificate {
            name,
            what: "the map is bijective",
            violation,
        }
    })?;
    let again = param
        .parameterize(disk, boundary)
        .map_err(|e| ContractViolation::Failed {
            name,
            source: StageFailure::Param(e),
        })?;
    if again.uv != map.uv {
        return Err(broken(BrokenPromise::DifferentMap));
    }
    // An interior face removed: an annulus, not a disk.
    let topo = Topology::build(disk);
    if let Some(f) = disk
        .faces()
        .find(|&f| disk.face(f).iter().all(|v| !topo.is_boundary_vertex(*v)))
    {
        let mut holed = disk.clone();
        holed.triangles.remove(f.idx());
        if param.parameterize(&holed, boundary).is_ok() {
            return Err(broken(BrokenPromise::MappedNonDisk(f)));
        }
    }
    Ok(())
}

/// The contract of [`PlanarRemesher`] on `domain` in `metric` at `target_length`: it
/// succeeds, the result passes the exact planar certificate (the same polygon tiled by
/// positive triangles, the boundary and constrained edges kept bit for bit, every other
/// vertex strictly inside), and the same seed gives the same mesh.
pub fn planar_remesher(
    remesher: &dyn PlanarRemesher,
    domain: &PlanarDomain,
    metric: &dyn Metric2d,
    target_length: f64,
    seed: u64,
) -> Result<(), ContractViolation> {
    let name = remesher.name();
    let run = |seed: u64| {
        remesher
            .remesh(domain, metric, target_length, &mut Rng::seed_from_u64(seed))
            .map_err(|e| ContractViolation::Failed {
                name,
                source: StageFailure::Remesh2d(e),
            })
    };
    let out = run(seed)?;
    invariants::certify_planar(domain, &out).map_err(|violation| {
        ContractViolation::Certificate {
            name,
            what: "the planar remesh",
            violation,
        }
    })?;
    if run(seed)? != out {
        return Err(ContractViolation::Broken {
            name,
            promise: BrokenPromise::NotDeterministic,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;
    use crate::patches::{Patch, PatchError};

    /// A strategy that breaks the contract by returning the whole mesh, processed or not.
    struct Greedy;
    impl PatchStrategy for Greedy {
        fn name(&self) -> &'static str {
            "greedy"
        }
        fn next_patch(
            &self,
            ctx: &PatchContext<'_>,
            _rng: &mut rand_chacha::ChaCha8Rng,
        ) -> Result<Option<Patch>, PatchError> {
            let faces: Vec<FaceId> = ctx.mesh.faces().collect();
            let boundary = invariants::certify_disk(ctx.mesh, &faces).unwrap_or_default();
            Ok(Some(Patch {
                seed_vertex: ctx.mesh.face(faces[0])[0],
                seed_face: faces[0],
                faces,
                boundary,
                cone: None,
                max_growth_cost: None,
            }))
        }
    }

    #[test]
    fn the_checks_catch_a_broken_strategy() {
        let disk = generators::disk(1.0, 3, 6);
        let case = StrategyCase {
            mesh: &disk,
            processed: vec![false; disk.n_faces()],
            corners: None,
            feature_edges: None,
            seed: 1,
        };
        // The first patch (the whole disk) is fine; the second has no unprocessed face.
        let e = patch_strategy(&Greedy, &case).expect_err("a broken strategy");
        assert!(
            matches!(
                e,
                ContractViolation::Broken {
                    promise: BrokenPromise::PatchWhenDone,
                    ..
                }
            ),
            "{e}"
        );
        // On a torus the whole mesh is not a disk.
        let torus = generators::torus(1.0, 0.4, 12, 6);
        let case = StrategyCase {
            mesh: &torus,
            processed: vec![false; torus.n_faces()],
            ..case
        };
        let e = patch_strategy(&Greedy, &case).expect_err("not a disk");
        assert!(matches!(e, ContractViolation::Certificate { .. }), "{e}");
    }

    #[test]
    fn same_loop_is_cyclic() {
        assert!(same_loop(&[1, 2, 3], &[2, 3, 1]));
        assert!(!same_loop(&[1, 2, 3], &[1, 3, 2]));
        assert!(!same_loop(&[1, 2], &[1, 2, 3]));
    }

    /// A parameterizer that mirrors Tutte's map (every triangle negative) and one that
    /// accepts anything: both are caught.
    #[test]
    fn the_checks_catch_a_broken_parameterizer() {
        use crate::param::{ParamError, Parameterization, Tutte};
        struct Mirror;
        impl Parameterizer for Mirror {
            fn name(&self) -> &'static str {
                "mirror"
            }
            fn parameterize(
                &self,
                disk: &TriMesh,
                boundary: &[crate::ids::VertexId],
            ) -> Result<Parameterization, ParamError> {
                let mut p = Tutte::default().parameterize(disk, boundary)?;
                p.uv.iter_mut().for_each(|q| q.x = -q.x);
                Ok(p)
            }
        }
        let disk = generators::disk(1.0, 3, 6);
        let boundary = crate::param::disk_boundary(&disk).expect("a disk");
        assert!(parameterizer(&Tutte::default(), &disk, &boundary).is_ok());
        let e = parameterizer(&Mirror, &disk, &boundary).expect_err("flipped");
        assert!(matches!(e, ContractViolation::Certificate { .. }), "{e}");
    }

    /// A remesher that drops a boundary vertex is caught.
    #[test]
    fn the_checks_catch_a_broken_remesher() {
        use crate::mesh::PlanarMesh;
        use crate::remesh2d::{DemoMetric, Remesh2dError};
        struct Dropper;
        impl PlanarRemesher for Dropper {
            fn name(&self) -> &'static str {
                "dropper"
            }
            fn remesh(
                &self,
                domain: &PlanarDomain,
                _metric: &dyn Metric2d,
                _l: f64,
                _rng: &mut rand_chacha::ChaCha8Rng,
            ) -> Result<PlanarMesh, Remesh2dError> {
                let mut origin: Vec<Option<u32>> =
                    (0..domain.points.len() as u32).map(Some).collect();
                origin[domain.boundary[0] as usize] = None;
                Ok(PlanarMesh {
                    points: domain.points.clone(),
                    triangles: domain.triangles.clone(),
                    origin,
                })
            }
        }
        let corners = crate::remesh2d::DemoDomain::Square.corners();
        let boundary =
            crate::remesh2d::resample_polygon(&corners, &DemoMetric::UniformIsotropic, 0.25);
        let dom = crate::remesh2d::triangulate_polygon(&boundary, &[]).expect("triangulated");
        let lct = crate::remesh2d::Lct::default();
        assert!(planar_remesher(&lct, &dom, &DemoMetric::UniformIsotropic, 0.25, 3).is_ok());
        let e = planar_remesher(&Dropper, &dom, &DemoMetric::UniformIsotropic, 0.25, 3)
            .expect_err("a boundary vertex lost");
        assert!(matches!(e, ContractViolation::Certificate { .. }), "{e}");
    }
}
