//! Projected Newton on the [`Objective`] with a free boundary (Sec. 3.3).
//!
//! Each iteration: assemble the gradient and projected Hessian on the fixed pattern, solve
//! with a small diagonal shift (translations, and at an isometry rotations, are in the
//! Hessian's null space), take as first trial `step_fraction` times the smaller of the
//! flip-free and the boundary-collision bounds, backtrack (Armijo; in certified mode a trial
//! must also pass the exact certificate), and extrapolate while a full step keeps paying.

use super::super::distortion::triangle_frames;
use super::super::sparse::{Llt, Pattern, VertexSystem};
use super::barrier::BoundaryBarrier;
use super::bounds::{max_collision_free_step, max_flip_free_step};
use super::energy::TwistFilter;
use super::objective::Objective;
use super::repair::{RepairPenalty, RepairStep};
use super::SdOptions;
use crate::ids::{FaceId, VertexId};
use crate::mesh::TriMesh;
use crate::param::{recertify, LinearSystem, ParamError};
use faer::Mat;
use nalgebra::Point2;
use std::cell::OnceCell;
use std::time::Instant;

/// Iteration log of [`super::optimize_with_log`]. Index 0 is the initial map.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SdLog {
    /// Objective (mean symmetric Dirichlet energy + barrier) of every accepted iterate.
    pub energies: Vec<f64>,
    /// Smallest doubled signed triangle area of every accepted iterate (float).
    pub min_double_area: Vec<f64>,
    /// Accepted step length (fraction of the Newton step) of each iteration.
    pub steps: Vec<f64>,
    /// Largest flip-free step (before `step_fraction`) of each iteration.
    pub flip_free_steps: Vec<f64>,
    /// Newton decrement `−∇E·d` of each iteration's direction `d` (twice the decrease the
    /// quadratic model predicts for the full step).
    pub decrements: Vec<f64>,
    /// Line-search trials rejected by the Armijo test (or an infinite energy).
    pub armijo_rejections: usize,
    /// Newton iterations taken.
    pub iterations: usize,
    /// The budget ran out before the stopping rule was met.
    pub hit_budget: bool,
    /// A step was wanted but no trial passed the certificate: the last certified iterate
    /// was returned.
    pub fell_back: bool,
    /// Trials rejected by the exact certificate (after passing the float tests).
    pub certificate_rejections: usize,
    /// Wall time in milliseconds: [setup (pattern, symbolic factorisation), assembly,
    /// numeric factorisation and solve, line search with certification].
    pub time_ms: [f64; 4],
    /// Numeric Cholesky factorisations (more than one per iteration when the regularising
    /// shift had to grow).
    pub factorizations: usize,
    /// Iterations whose first trial step was capped by the boundary-collision bound.
    pub collision_limited: usize,
}

/// Which guarantee the iterations keep.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(super) enum Mode {
    /// Every iterate certified bijective: boundary barrier, collision bound, exact
    /// certificate on every trial. The start must be certified.
    Certified,
    /// Locally injective only (float-positive triangles via a finite energy; no barrier,
    /// no collision bound, no certificate), with the overlap-repair penalty when
    /// `repair_weight > 0`: the repair of the LSCM start, certified by the caller.
    LocallyInjective,
}

/// Projected Newton from `uv0` in `mode`, on the shared `system` of `disk` (built here if
/// the cell is empty). Returns the last accepted iterate and the log.
pub(super) fn newton(
    disk: &TriMesh,
    boundary: &[VertexId],
    uv0: &[Point2<f64>],
    options: &SdOptions,
    mode: Mode,
    system: &OnceCell<VertexSystem>,
) -> Result<(Vec<Point2<f64>>, SdLog), ParamError> {
    let objective = objective(disk, boundary, options, mode);
    if objective.total_area <= 0.0 {
        let log = SdLog {
            energies: vec![f64::INFINITY],
            min_double_area: vec![min_double_area(uv0, &disk.triangles)],
            ..Default::default()
        };
        return Ok((uv0.to_vec(), log));
    }
    let mut clock = Lap::start();
    let system = VertexSystem::get(system, disk).map_err(|failure| ParamError::Solver {
        system: LinearSystem::VertexPattern,
        failure,
    })?;
    let mut state = Newton::new(disk, options, mode, objective, system, uv0);
    state.log.time_ms[0] += clock.lap();
    state.start()?;
    let converged = state.run()?;
    let log = &mut state.log;
    log.hit_budget = !converged && !log.fell_back && log.iterations >= options.max_iters;
    Ok((state.uv, state.log))
}

/// The objective of `mode`: the barrier only when certified, the repair penalty only when
/// locally injective with a positive weight.
fn objective<'a>(
    disk: &'a TriMesh,
    boundary: &'a [VertexId],
    options: &SdOptions,
    mode: Mode,
) -> Objective<'a> {
    let frames = triangle_frames(disk);
    let total_area: f64 = frames.iter().map(|f| f.area).sum();
    let certified = mode == Mode::Certified;
    let per_face = |w: f64| w / disk.n_faces() as f64;
    let barrier = BoundaryBarrier {
        boundary,
        eps: if certified {
            options.barrier_distance * disk.mean_edge_length()
        } else {
            0.0
        },
        weight: per_face(options.barrier_weight),
    };
    let repair_weight = if certified {
        0.0
    } else {
        per_face(options.repair_weight)
    };
    let repair = (repair_weight > 0.0).then(|| {
        RepairPenalty::new(
            boundary,
            repair_weight,
            options.repair_margin * disk.mean_edge_length(),
            options.repair_clearance,
        )
    });
    Objective {
        tris: &disk.triangles,
        frames,
        total_area,
        barrier,
        repair,
    }
}

/// Wall-clock laps for [`SdLog::time_ms`].
struct Lap(Instant);

impl Lap {
    fn start() -> Lap {
        Lap(Instant::now())
    }

    /// Milliseconds since the last lap (or the start).
    fn lap(&mut self) -> f64 {
        let now = Instant::now();
        let dt = (now - self.0).as_secs_f64() * 1e3;
        self.0 = now;
        dt
    }
}

/// The first trial step of an iteration and the bounds it came from.
struct StepBounds {
    /// Largest flip-free step.
    flip_free: f64,
    /// `step_fraction ×` the flip-free bound: how far extrapolation may go.
    safe: f64,
    /// First trial: `step_fraction ×` the smaller bound, capped at 1.
    first: f64,
}

/// The state of one Newton run.
struct Newton<'a> {
    disk: &'a TriMesh,
    options: &'a SdOptions,
    mode: Mode,
    objective: Objective<'a>,
    pattern: &'a Pattern,
    llt: Llt<'a>,
    /// The last accepted iterate and its objective.
    uv: Vec<Point2<f64>>,
    energy: f64,
    /// Line-search scratch: the backtracking trial and the extrapolation probe.
    trial: Vec<Point2<f64>>,
    probe: Vec<Point2<f64>>,
    /// Gradient, Hessian values, and the Hessian with the regularising shift.
    grad: Vec<f64>,
    hessian: Vec<f64>,
    shifted: Vec<f64>,
    /// Projection of the twist mode in the next assembly.
    twist_filter: TwistFilter,
    log: SdLog,
    clock: Lap,
}

impl<'a> Newton<'a> {
    fn new(
        disk: &'a TriMesh,
        options: &'a SdOptions,
        mode: Mode,
        objective: Objective<'a>,
        system: &'a VertexSystem,
        uv0: &[Point2<f64>],
    ) -> Newton<'a> {
        let pattern = &system.pattern;
        Newton {
            disk,
            options,
            mode,
            objective,
            pattern,
            llt: Llt::new(system),
            uv: uv0.to_vec(),
            energy: f64::INFINITY,
            trial: uv0.to_vec(),
            probe: uv0.to_vec(),
            grad: vec![0.0; pattern.dim()],
            hessian: vec![0.0; pattern.nnz()],
            shifted: vec![0.0; pattern.nnz()],
            twist_filter: TwistFilter::Clamp,
            log: SdLog::default(),
            clock: Lap::start(),
        }
    }

    fn certified(&self) -> bool {
        self.mode == Mode::Certified
    }

    /// Find the start's repair pairs and evaluate it. Errors in locally injective mode when
    /// the start has a flipped or degenerate triangle.
    fn start(&mut self) -> Result<(), ParamError> {
        if let Some(r) = &mut self.objective.repair {
            r.add_penetrations(&self.uv);
        }
        self.energy = self.objective.energy(&self.uv);
        if !self.certified() && !self.energy.is_finite() {
            let face = self.disk.triangles.iter().position(|t| {
                let (a, b, c) = (
                    self.uv[t[0].idx()],
                    self.uv[t[1].idx()],
                    self.uv[t[2].idx()],
                );
                (b - a).perp(&(c - a)) <= 0.0
            });
            return Err(ParamError::FlippedStart {
                face: face.map(FaceId::new),
            });
        }
        self.log.energies.push(self.energy);
        self.log
            .min_double_area
            .push(min_double_area(&self.uv, &self.disk.triangles));
        Ok(())
    }

    /// Iterate until a stopping rule or the budget; returns whether a stopping rule (not
    /// the budget, a repair stall or a fallback) ended it.
    fn run(&mut self) -> Result<bool, ParamError> {
        let o = self.options;
        while self.log.iterations < o.max_iters {
            let (dir, slope) = self.direction()?;
            // NaN-safe: a NaN slope also means no usable descent direction.
            if slope.is_nan() || slope >= 0.0 {
                return Ok(true);
            }
            let bounds = self.step_bounds(&dir);
            let Some((e_new, t)) = self.line_search(&dir, slope, &bounds) else {
                // No certified decrease along the Newton direction: keep the last certified
                // iterate. If the direction still promised a real decrease, report a fallback.
                self.log.fell_back = -slope > o.rel_tol * (self.energy - 4.0).max(0.0);
                return Ok(!self.log.fell_back);
            };
            let rel = self.accept(e_new, t, bounds.flip_free, slope);
            if let Some(repair) = &mut self.objective.repair {
                match repair.after_step(self.disk, &self.uv) {
                    RepairStep::Done => return Ok(true),
                    RepairStep::Stalled => return Ok(false),
                    RepairStep::NewPairs => {
                        self.energy = self.objective.energy(&self.uv);
                        continue;
                    }
                    RepairStep::Continue => {}
                }
            }
            if rel < o.rel_tol {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// The Newton direction at the current iterate and its slope `∇E·d`.
    fn direction(&mut self) -> Result<(Vec<f64>, f64), ParamError> {
        self.clock.lap();
        self.objective.assemble(
            &self.uv,
            self.pattern,
            &mut self.grad,
            &mut self.hessian,
            self.twist_filter,
        )?;
        self.log.time_ms[1] += self.clock.lap();
        let dir = self.regularised_solve()?;
        let slope: f64 = dir.iter().zip(&self.grad).map(|(d, g)| d * g).sum();
        self.log.time_ms[2] += self.clock.lap();
        Ok((dir, slope))
    }

    /// Solve `(H + μ I) d = −∇E`, `μ = 1e-8 ×` the mean diagonal, grown ×100 until the
    /// Cholesky factorisation succeeds.
    fn regularised_solve(&mut self) -> Result<Vec<f64>, ParamError> {
        let (pat, vals) = (self.pattern, &self.hessian);
        let dim = pat.dim();
        let trace: f64 = (0..dim).map(|d| vals[pat.diag_slot(d)]).sum();
        let mut mu = 1e-8 * (trace / dim as f64);
        for _ in 0..8 {
            self.shifted.copy_from_slice(vals);
            for d in 0..dim {
                self.shifted[pat.diag_slot(d)] += mu;
            }
            self.log.factorizations += 1;
            let mut sol = Mat::<f64>::zeros(dim, 1);
            for i in 0..dim {
                sol[(i, 0)] = -self.grad[i];
            }
            if self.llt.solve(&self.shifted, &mut sol).is_ok() {
                return Ok((0..dim).map(|i| sol[(i, 0)]).collect());
            }
            mu *= 100.0;
        }
        Err(ParamError::Solver {
            system: LinearSystem::NewtonHessian,
            failure: crate::param::SolveFailure::NotPositiveDefinite,
        })
    }

    /// The flip-free bound and, when certified, the boundary-collision bound over the steps
    /// the first trial can reach (the extrapolation beyond it is judged by the certificate
    /// alone). Not in the overlap repair: resolving an overlap moves vertices across edges.
    fn step_bounds(&mut self, dir: &[f64]) -> StepBounds {
        let o = self.options;
        let flip_free = max_flip_free_step(&self.uv, dir, &self.disk.triangles);
        let horizon = flip_free.min(1.0 / o.step_fraction.max(f64::MIN_POSITIVE));
        let mut collision_free = horizon;
        if o.collision_bound && self.certified() {
            let boundary = self.objective.boundary();
            collision_free = max_collision_free_step(&self.uv, dir, boundary, horizon);
            self.log.time_ms[2] += self.clock.lap();
        }
        if collision_free < horizon {
            self.log.collision_limited += 1;
        }
        StepBounds {
            flip_free,
            safe: o.step_fraction * flip_free,
            first: (o.step_fraction * collision_free).min(1.0),
        }
    }

    /// Backtracking from the first trial, then extrapolation after a full step. Returns the
    /// accepted objective and step (the iterate is left in `self.trial`), or `None` when no
    /// trial was accepted.
    fn line_search(&mut self, dir: &[f64], slope: f64, b: &StepBounds) -> Option<(f64, f64)> {
        let accepted = self.backtrack(dir, slope, b.first).map(|(e, t)| {
            if t == 1.0 {
                self.extrapolate(dir, e, b.safe)
            } else {
                (e, t)
            }
        });
        self.log.time_ms[3] += self.clock.lap();
        accepted
    }

    /// Armijo backtracking (halving, at most 40 trials) from step `t`; a trial must also
    /// pass the certificate when certified.
    fn backtrack(&mut self, dir: &[f64], slope: f64, mut t: f64) -> Option<(f64, f64)> {
        for _ in 0..40 {
            step_to(&self.uv, dir, t, &mut self.trial);
            let e = self.objective.energy(&self.trial);
            if e <= self.energy + self.options.armijo * t * slope {
                if !self.certified() || self.passes_certificate(&self.trial) {
                    return Some((e, t));
                }
                self.log.certificate_rejections += 1;
            } else {
                self.log.armijo_rejections += 1;
            }
            t *= 0.5;
        }
        None
    }

    /// After an accepted full step: far from the optimum the energy is dominated by
    /// compressed triangles (`E ≈ J⁻²`), where a full Newton step only grows `J` by 4/3; so
    /// while the flip-free bound allows, keep doubling the step as long as the energy drops.
    fn extrapolate(&mut self, dir: &[f64], mut e_best: f64, safe: f64) -> (f64, f64) {
        let mut t = 1.0;
        let mut t_try = 2.0;
        while t_try <= safe && t_try <= 1024.0 {
            step_to(&self.uv, dir, t_try, &mut self.probe);
            let e = self.objective.energy(&self.probe);
            if e.is_nan()
                || e >= e_best
                || (self.certified() && !self.passes_certificate(&self.probe))
            {
                break;
            }
            e_best = e;
            t = t_try;
            std::mem::swap(&mut self.trial, &mut self.probe);
            t_try *= 2.0;
        }
        (e_best, t)
    }

    fn passes_certificate(&self, uv: &[Point2<f64>]) -> bool {
        recertify(self.disk, uv, self.objective.boundary()).is_ok()
    }

    /// Make the accepted trial the iterate and log it. Returns the relative decrease of the
    /// excess over the isometric lower bound 4 (`σ² + σ⁻² ≥ 2`): relative to `E` itself the
    /// constant 4 would stop developable patches early.
    fn accept(&mut self, e_new: f64, t: f64, flip_free: f64, slope: f64) -> f64 {
        std::mem::swap(&mut self.uv, &mut self.trial);
        let log = &mut self.log;
        log.iterations += 1;
        // Trust-region-like switch (Chen et al. 2024): a truncated step means the quadratic
        // model was not trusted, so filter the twist by its absolute value next time; a full
        // (or extrapolated) step means the model is good, so clamp (faster near the optimum).
        self.twist_filter = if self.options.abs_twist && t < 1.0 {
            TwistFilter::Abs
        } else {
            TwistFilter::Clamp
        };
        log.steps.push(t);
        log.flip_free_steps.push(flip_free);
        log.decrements.push(-slope);
        log.energies.push(e_new);
        log.min_double_area
            .push(min_double_area(&self.uv, &self.disk.triangles));
        let rel = (self.energy - e_new) / (self.energy - 4.0).max(f64::MIN_POSITIVE);
        self.energy = e_new;
        rel
    }
}

/// `out = uv + t · dir`.
fn step_to(uv: &[Point2<f64>], dir: &[f64], t: f64, out: &mut [Point2<f64>]) {
    for (v, (p, q)) in uv.iter().zip(out.iter_mut()).enumerate() {
        *q = Point2::new(p.x + t * dir[2 * v], p.y + t * dir[2 * v + 1]);
    }
}

/// Smallest doubled signed triangle area of `uv` (float).
fn min_double_area(uv: &[Point2<f64>], tris: &[[VertexId; 3]]) -> f64 {
    tris.iter()
        .map(|t| {
            let (a, b, c) = (uv[t[0].idx()], uv[t[1].idx()], uv[t[2].idx()]);
            (b - a).perp(&(c - a))
        })
        .fold(f64::INFINITY, f64::min)
}
