//! The default parameterizer of Sec. 3.3: a certified initial map, then the area-weighted
//! symmetric Dirichlet energy minimised with a free boundary by projected Newton, with the
//! boundary barrier of ref. \[30\] and an exact certificate after every accepted step.
//!
//! * Energy per triangle (Smith & Schaefer 2015), `‖F‖² (1 + det(F)⁻²)`, and its
//!   analytically projected Hessian: [`energy`].
//! * Boundary barrier (ref. \[30\], Su et al.) on the triangle-inequality gap: [`barrier`].
//! * The objective over the whole map, assembled on a sparsity pattern fixed at start with
//!   one symbolic Cholesky reused every step (`super::sparse`): [`objective`].
//! * Newton iterations and line search: [`mod@newton`]; its step bounds (flip-free and
//!   boundary-collision): [`bounds`].
//! * Start: the free-boundary LSCM when certified; else the LSCM after the overlap repair
//!   ([`repair`]) when that is certified; else the Tutte map ([`init`]). The repair steps are
//!   part of computing the start: only the certified start and the iterates after it count.
//! * Stopping: a step whose decrease is below `rel_tol` of the excess `E − 4`.

mod barrier;
mod bounds;
mod energy;
mod init;
mod newton;
mod objective;
mod repair;

pub use init::{initial_map, InitialMap};
pub use newton::SdLog;

use super::tutte::{scale_to_area, TutteWeights};
use super::{certify, distortion, validate_disk, ParamError, Parameterization, Parameterizer};
use crate::ids::VertexId;
use crate::mesh::TriMesh;
use init::initial_map_with;
use nalgebra::Point2;
use newton::{newton, Mode};
use std::cell::OnceCell;
use std::time::Instant;

/// Options of [`SymmetricDirichlet`] (defaults in brackets).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SdOptions {
    /// Weights of the Tutte initial map [`TutteWeights::Cotan`] (clamped positive, so Tutte's
    /// theorem applies; symmetric, so solved by sparse Cholesky, ~5× faster than the LU that
    /// mean-value weights need; uniform weights are the certified fallback).
    pub init_weights: TutteWeights,
    /// Start from the free-boundary least-squares conformal map ([`super::lscm()`]) when it
    /// passes the exact certificate, else from the Tutte map [true]. The circle boundary of
    /// the Tutte map squeezes triangles of curved patches to ~1e-7 of their area, and the
    /// optimisation from there needs many more iterations and can end in a worse local
    /// minimum with the boundary pressed against itself.
    pub free_boundary_init: bool,
    /// Newton iteration budget \[100\]; running out is reported (`hit_budget`), not an error.
    pub max_iters: usize,
    /// Stop when a step decreases the energy excess `E − 4` over an isometry by less than
    /// this fraction [1e-4].
    pub rel_tol: f64,
    /// Fraction of the largest flip-free step tried first [0.9].
    pub step_fraction: f64,
    /// Armijo sufficient-decrease constant [1e-4].
    pub armijo: f64,
    /// Barrier activation distance `ε` on the triangle-inequality gap, as a fraction of the
    /// mean 3D edge length [0.02].
    pub barrier_distance: f64,
    /// Weight of one barrier term relative to one average triangle's energy share [1.0].
    pub barrier_weight: f64,
    /// Hessian projection of the twist mode: `true` replaces a negative eigenvalue by its
    /// absolute value after an iteration whose step was truncated (Chen et al. 2024,
    /// "trust-region eigenvalue filtering": far from the rest shape the clamped Hessian
    /// over-trusts the twist direction, and the Armijo test then halves most steps) and
    /// clamps it to 0 after a full step; `false` always clamps [true].
    pub abs_twist: bool,
    /// Cap every first trial step at `step_fraction` times the largest step along which no
    /// boundary vertex meets a non-incident boundary edge (swept vertex–edge test), so the
    /// certificate rarely rejects a trial for a self-touching boundary [true].
    pub collision_bound: bool,
    /// Overlap repair of an LSCM that is not certified (its boundary overlaps itself, mostly
    /// where narrow slits of a ragged cover patch close): up to this many locally injective
    /// Newton steps from it on the symmetric Dirichlet energy plus a penalty pushing every
    /// penetrating boundary vertex `repair_margin` back out of the edge it crossed (no
    /// barrier, no certificate during the steps; stops early once certified, or when the
    /// number of crossing boundary edges has not fallen for 6 steps). The result is used
    /// only if it passes the exact certificate, else the Tutte map; 0 disables \[30\].
    pub repair_iters: usize,
    /// Weight of one overlap-repair term relative to one average triangle's energy share
    /// (0: plain locally injective steps) \[100\].
    pub repair_weight: f64,
    /// Clearance the overlap repair aims for, as a fraction of the mean 3D edge length [0.2].
    pub repair_margin: f64,
    /// The overlap repair stops once the map is certified with every repaired vertex at
    /// least this fraction of `repair_margin` outside the edge it crossed \[0.5\].
    pub repair_clearance: f64,
}

impl Default for SdOptions {
    fn default() -> Self {
        SdOptions {
            init_weights: TutteWeights::Cotan,
            free_boundary_init: true,
            max_iters: 100,
            rel_tol: 1e-4,
            step_fraction: 0.9,
            armijo: 1e-4,
            barrier_distance: 0.02,
            barrier_weight: 1.0,
            abs_twist: true,
            collision_bound: true,
            repair_iters: 30,
            repair_weight: 100.0,
            repair_margin: 0.2,
            repair_clearance: 0.5,
        }
    }
}

/// Symmetric Dirichlet parameterizer (name `"sd"`), the default [`Parameterizer`].
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct SymmetricDirichlet {
    /// Options.
    pub options: SdOptions,
}

/// Where the time of one [`SymmetricDirichlet::parameterize_profiled`] call went.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SdProfile {
    /// The initial map chosen.
    pub init: Option<InitialMap>,
    /// Linear-system setup, LSCM and its certificate, ms.
    pub lscm_ms: f64,
    /// Overlap repair and the certificate of its result, ms (0 when not run).
    pub repair_ms: f64,
    /// Log of the overlap repair, when it ran.
    pub repair: Option<SdLog>,
    /// Whole initial map (including any Tutte fallback), ms.
    pub init_ms: f64,
    /// Log of the certified Newton optimisation.
    pub newton: SdLog,
    /// Certified Newton optimisation, ms.
    pub newton_ms: f64,
}

/// Minimise the symmetric Dirichlet energy of the certified map `uv0` of `disk` (free
/// boundary, projected Newton, boundary barrier, certified line search; see the module
/// docs). Returns the last accepted iterate, which passes `certify_bijective`, and the log.
/// Errors: `NotCertified` if `uv0` itself does not pass the certificate, `Solver` if the
/// sparse factorisation fails.
pub fn optimize_with_log(
    disk: &TriMesh,
    boundary: &[VertexId],
    uv0: &[Point2<f64>],
    options: &SdOptions,
) -> Result<(Vec<Point2<f64>>, SdLog), ParamError> {
    certify(disk, uv0, boundary)?;
    newton(
        disk,
        boundary,
        uv0,
        options,
        Mode::Certified,
        &OnceCell::new(),
    )
}

/// [`optimize_with_log`] without the global part: locally injective projected Newton (no
/// barrier, no collision bound, no certificate; triangles stay float-positive), with the
/// overlap-repair penalty when `options.repair_weight > 0` (see `SdOptions::repair_iters`;
/// then it stops once the map is certified). The result may still overlap itself.
/// Errors: `NotCertified` if a triangle of `uv0` is not float-positive.
pub fn optimize_locally_injective(
    disk: &TriMesh,
    boundary: &[VertexId],
    uv0: &[Point2<f64>],
    options: &SdOptions,
) -> Result<(Vec<Point2<f64>>, SdLog), ParamError> {
    newton(
        disk,
        boundary,
        uv0,
        options,
        Mode::LocallyInjective,
        &OnceCell::new(),
    )
}

impl Parameterizer for SymmetricDirichlet {
    fn name(&self) -> &'static str {
        "sd"
    }

    fn parameterize(
        &self,
        disk: &TriMesh,
        boundary: &[VertexId],
    ) -> Result<Parameterization, ParamError> {
        self.parameterize_profiled(disk, boundary).map(|r| r.0)
    }
}

impl SymmetricDirichlet {
    /// [`Parameterizer::parameterize`], also returning where the time went.
    pub fn parameterize_profiled(
        &self,
        disk: &TriMesh,
        boundary: &[VertexId],
    ) -> Result<(Parameterization, SdProfile), ParamError> {
        validate_disk(disk, boundary)?;
        let mut prof = SdProfile::default();
        let clock = Instant::now();
        // One pattern and symbolic factorisation for the LSCM, the repair and the
        // optimisation of this disk.
        let system = OnceCell::new();
        let (uv0, kind) = initial_map_with(disk, boundary, &self.options, &system, &mut prof)?;
        prof.init = Some(kind);
        prof.init_ms = clock.elapsed().as_secs_f64() * 1e3;
        let clock = Instant::now();
        // If the optimiser cannot run at all (e.g. a certified Tutte triangle too thin for a
        // finite float energy, or a failed factorisation), the certified start is returned
        // (`initial_map_with` certified it).
        let optimized = newton(
            disk,
            boundary,
            &uv0,
            &self.options,
            Mode::Certified,
            &system,
        );
        let (mut uv, log) = optimized.unwrap_or_else(|_| {
            let log = SdLog {
                fell_back: true,
                ..Default::default()
            };
            (uv0, log)
        });
        prof.newton_ms = clock.elapsed().as_secs_f64() * 1e3;
        let mut fell_back = log.fell_back;
        // Isometric in the mean: rescale so the 2D area equals the 3D area; a uniform scale
        // keeps orientations in exact arithmetic, and the certificate is re-checked.
        let unscaled = uv.clone();
        scale_to_area(disk, &mut uv);
        if certify(disk, &uv, boundary).is_err() {
            uv = unscaled;
            fell_back = true;
        }
        let mut report = distortion(disk, &uv);
        report.iterations = log.iterations;
        report.hit_budget = log.hit_budget;
        report.fell_back = fell_back;
        prof.newton = log;
        Ok((Parameterization { uv, report }, prof))
    }
}
