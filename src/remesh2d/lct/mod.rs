//! The LCT planar remesher (Sec. 3.3, ref. \[5\]: Fu, Liu, Snyder, Guo 2014, "Anisotropic
//! simplicial meshing using local convex functions").
//!
//! Energy (the local convex function energy of \[5\], written in paper-notes.md): every vertex
//! `v` carries the convex function `f_v(x) = ½ (x − v)ᵀ M_v (x − v)`; the energy is the L1 error
//! of its piecewise-linear interpolation, summed over vertices and their 1-rings, which on one
//! triangle `T` (Euclidean area `|T|` in the parameter plane) is in closed form
//!
//! ```text
//! E_T = |T| / 24 · Σ_{v ∈ T} Σ_{edges e of T} eᵀ M_v e  =  |T| / 8 · Σ_e eᵀ M̄_T e,
//! ```
//!
//! with `M̄_T` the mean of the three vertex tensors. The three steps the paper names are applied in
//! a fixed schedule (see [`LctOptions`]): edge length adjustment (split / collapse), connectivity
//! update (energy-decreasing flips of convex quads) and vertex position optimisation (Newton on
//! the 1-ring energy, backtracked so that every 1-ring triangle stays positive by exact
//! `orient2d`). Boundary and constrained vertices and edges never change.
//!
//! Two additions to plain LCT (paper-notes.md, "LCT remeshing"), both switchable: valence flips
//! after split/collapse, and a final polish (equilateral-apex smoothing + max-min flips); they
//! take the mesh past the valence defects where plain LCT stalls (the measurements:
//! notes/doc-comments.md).

use super::{clamp_spd, Metric2d, PlanarDomain, PlanarMesh, PlanarRemesher, Remesh2dError};
use crate::invariants::certify_planar;
use nalgebra::{Matrix2, Point2};
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use std::collections::{HashMap, HashSet};
use work::Work;

mod edges;
mod flips;
mod smooth;
mod work;

/// Options of the LCT remesher, with their defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct LctOptions {
    /// Outer rounds of the schedule (default 8). One round: ≤ `max_passes` split passes,
    /// ≤ `max_passes` collapse passes, valence flips (or energy flips if `valence_flips` is
    /// off), then `smoothing_iters` × (LCT smoothing, energy flips). After the rounds:
    /// `final_smoothing` × (equilateral-apex smoothing, max-min or energy flips).
    pub rounds: usize,
    /// Split interior edges whose metric length exceeds `split_ratio · L` (default 4/3).
    pub split_ratio: f64,
    /// Collapse interior edges whose metric length is below `collapse_ratio · L` (default 4/5).
    pub collapse_ratio: f64,
    /// A collapse is refused when an edge it makes is longer than this times L (default
    /// `None`: `split_ratio`).
    pub collapse_guard: Option<f64>,
    /// Smoothing passes per round, each followed by flips (default 3).
    pub smoothing_iters: usize,
    /// Maximum split passes and collapse passes per round (default 6 each).
    pub max_passes: usize,
    /// Newton steps per vertex and smoothing pass (default 2).
    pub newton_steps: usize,
    /// Final polish passes after the last round: equilateral-apex smoothing + flips (default 6).
    pub final_smoothing: usize,
    /// `M_T` is the metric sampled at the triangle's centroid (and edge lengths use the metric at
    /// the edge midpoint) instead of the mean of the vertex tensors (default false: the mean
    /// needs no metric evaluation, which costs more with a [`super::PlanarMetricField`]).
    pub tensor_at_centroid: bool,
    /// In the final passes, flip by the max-min metric quality criterion instead of the
    /// energy (default true).
    pub final_maxmin_flips: bool,
    /// After split/collapse, flip towards regular valences instead of by energy (default true).
    pub valence_flips: bool,
    /// A valence flip may lower the pair's smaller quality to at most this factor (default 0.5).
    pub valence_quality_guard: f64,
    /// Run [`certify_planar`] after every round, not only at the end (default true).
    pub certify_every_round: bool,
    /// Start from the constrained Delaunay triangulation of the boundary polygon and of the
    /// domain's interior vertices that are `start_spacing · L` apart in the metric, instead of
    /// the domain's triangulation, so the result does not inherit the input's connectivity
    /// (default false; true in [`LctOptions::for_absolute_sizes`]).
    pub rebuild: bool,
    /// The spacing of the interior vertices kept for the start, times L (default 0.8).
    pub start_spacing: f64,
    /// After split and collapse, bring the vertex count to that of an ideal mesh of the
    /// domain's metric area, so edges have length L on average (default false; true in
    /// [`LctOptions::for_absolute_sizes`]).
    pub density: bool,
    /// The most faces a remesh may have (default [`MAX_LCT_FACES`]): a domain whose ideal
    /// mesh ([`super::ideal_faces`]) has more is refused up front, and so is a result with
    /// more. The rounds in between may overshoot, up to [`SPLIT_OVERSHOOT`] times the ideal
    /// count and [`MAX_OVERSHOOT`] times this.
    pub max_faces: f64,
}

/// [`LctOptions::max_faces`]' default: about a gigabyte of working mesh. A patch of the
/// pipeline is far smaller; the pipeline refuses a patch over its own face budget first.
pub const MAX_LCT_FACES: f64 = 4e6;

/// How far the split passes may take a mesh past its base (the larger of the domain's ideal
/// face count, its own face count and [`MIN_TRANSIENT_BASE`]) before LCT stops with
/// [`Remesh2dError::TooDense`].
pub const SPLIT_OVERSHOOT: f64 = 256.0;

/// How far the split passes may take a mesh past [`LctOptions::max_faces`]: a legitimate
/// remesh under a strongly anisotropic metric overshoots the cap within a round before its
/// collapses bring it back, a runaway one does not stop (the measurements: notes/fuzz-hangs.md).
pub const MAX_OVERSHOOT: f64 = 4.0;

/// The floor of the split passes' base: a domain of a few faces with a tiny ideal count may
/// still grow this much (times [`SPLIT_OVERSHOOT`]) on its way.
pub const MIN_TRANSIENT_BASE: f64 = 1000.0;

impl Default for LctOptions {
    /// The settings for the curvature metric at L_tar = 1.5·L_avg (the paper's protocol): start
    /// from the patch's own triangulation, split above 4/3 L, collapse below 4/5 L, no density
    /// control.
    fn default() -> Self {
        LctOptions {
            rounds: 8,
            split_ratio: 4.0 / 3.0,
            collapse_ratio: 4.0 / 5.0,
            collapse_guard: None,
            smoothing_iters: 3,
            max_passes: 6,
            newton_steps: 2,
            final_smoothing: 6,
            valence_flips: true,
            valence_quality_guard: 0.5,
            final_maxmin_flips: true,
            tensor_at_centroid: false,
            certify_every_round: true,
            rebuild: false,
            start_spacing: 0.8,
            density: false,
            max_faces: MAX_LCT_FACES,
        }
    }
}

impl LctOptions {
    /// The settings for a metric whose sizes are absolute (a user's metric at L_tar = 1): start
    /// from the triangulated boundary with the patch's vertices `0.8·L` apart (a regular input
    /// grid that is anisotropic in the metric is a fixed point of the local operations), split
    /// above 1.5 L, and bring the vertex count to that of an ideal mesh, so edges are L on
    /// average (paper-notes.md, "LCT remeshing").
    pub fn for_absolute_sizes() -> LctOptions {
        LctOptions {
            split_ratio: 1.5,
            rebuild: true,
            density: true,
            ..LctOptions::default()
        }
    }
}

/// The paper's planar remesher (default [`PlanarRemesher`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Lct {
    /// Options.
    pub options: LctOptions,
}

impl PlanarRemesher for Lct {
    fn name(&self) -> &'static str {
        "lct"
    }

    fn remesh(
        &self,
        domain: &PlanarDomain,
        metric: &dyn Metric2d,
        target_length: f64,
        rng: &mut ChaCha8Rng,
    ) -> Result<PlanarMesh, Remesh2dError> {
        remesh_planar(domain, metric, target_length, &self.options, rng)
    }

    fn remesh_bounded(
        &self,
        domain: &PlanarDomain,
        metric: &dyn Metric2d,
        target_length: f64,
        max_faces: f64,
        rng: &mut ChaCha8Rng,
    ) -> Result<PlanarMesh, Remesh2dError> {
        let options = LctOptions {
            max_faces: self.options.max_faces.min(max_faces),
            ..self.options.clone()
        };
        remesh_planar(domain, metric, target_length, &options, rng)
    }
}

/// The start of the rounds: the constrained Delaunay triangulation of the domain's boundary
/// polygon and of those of its interior vertices that are at least `spacing` apart in the
/// metric from the boundary and from each other (taken in a seeded random order), as a remesh
/// of `domain`; `None` when spade cannot triangulate it. The result inherits neither the input's
/// connectivity nor its lattice: in id order, a regular grid that is anisotropic in the metric
/// leaves a regular sub-lattice of non-equilateral triangles, a fixed point of split, collapse,
/// flip and smoothing (paper-notes.md, "LCT remeshing").
fn from_boundary(
    domain: &PlanarDomain,
    metric: &dyn Metric2d,
    spacing: f64,
    rng: &mut ChaCha8Rng,
) -> Option<PlanarMesh> {
    let loop_points: Vec<Point2<f64>> = domain
        .boundary
        .iter()
        .map(|&b| domain.points[b as usize])
        .collect();
    let mut on_boundary = vec![false; domain.points.len()];
    for &b in &domain.boundary {
        on_boundary[b as usize] = true;
    }
    let mut interior: Vec<u32> = (0..domain.points.len() as u32)
        .filter(|&i| !on_boundary[i as usize])
        .collect();
    interior.shuffle(rng);
    let kept = spaced(domain, metric, &interior, spacing);
    let points: Vec<Point2<f64>> = kept.iter().map(|&i| domain.points[i as usize]).collect();
    let (cdt, inside) = super::triangulate_polygon_with(&loop_points, &points).ok()?;
    let mut origin: Vec<Option<u32>> = domain.boundary.iter().map(|&b| Some(b)).collect();
    origin.extend(inside.iter().map(|&i| Some(kept[i])));
    (origin.len() == cdt.points.len()).then_some(PlanarMesh {
        points: cdt.points,
        triangles: cdt.triangles,
        origin,
    })
}

/// The candidates (ids of `domain`'s points) at least `spacing` from the boundary vertices and
/// from each other in the metric (mean of the two points' tensors), greedily in the given order.
fn spaced(
    domain: &PlanarDomain,
    metric: &dyn Metric2d,
    candidates: &[u32],
    spacing: f64,
) -> Vec<u32> {
    if candidates.is_empty() || spacing.is_nan() || spacing <= 0.0 {
        return Vec::new();
    }
    let tensor = |i: u32| clamp_spd(&metric.metric(&domain.points[i as usize]));
    // Cells as large as the largest metric ball of radius `spacing`, so that every point
    // closer than `spacing` lies in the 3×3 cells around a candidate.
    let mut cell = 0.0f64;
    let mut tensors: HashMap<u32, Matrix2<f64>> = HashMap::new();
    for &i in domain.boundary.iter().chain(candidates) {
        if let Some(m) = tensor(i) {
            let lmin = m.symmetric_eigenvalues().min();
            if lmin > 0.0 {
                cell = cell.max(spacing / lmin.sqrt());
            }
            tensors.insert(i, m);
        }
    }
    if !(cell.is_finite() && cell > 0.0) {
        return Vec::new();
    }
    let key = |p: &Point2<f64>| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    let mut grid: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
    for &b in &domain.boundary {
        grid.entry(key(&domain.points[b as usize]))
            .or_default()
            .push(b);
    }
    let mut kept = Vec::new();
    for &i in candidates {
        let Some(mi) = tensors.get(&i) else { continue };
        let p = domain.points[i as usize];
        let (cx, cy) = key(&p);
        let far = (cx - 1..=cx + 1).all(|x| {
            (cy - 1..=cy + 1).all(|y| {
                grid.get(&(x, y)).is_none_or(|js| {
                    js.iter().all(|&j| {
                        let m = tensors.get(&j).map_or(*mi, |mj| (mi + mj) * 0.5);
                        let e = domain.points[j as usize] - p;
                        e.dot(&(m * e)) >= spacing * spacing
                    })
                })
            })
        });
        if far {
            grid.entry((cx, cy)).or_default().push(i);
            kept.push(i);
        }
    }
    kept
}

/// The identity remesh of `domain` (every vertex its own origin).
fn identity(domain: &PlanarDomain) -> PlanarMesh {
    PlanarMesh {
        points: domain.points.clone(),
        triangles: domain.triangles.clone(),
        origin: (0..domain.points.len() as u32).map(Some).collect(),
    }
}

/// Remesh `domain` with LCT so that edges have metric length close to `target_length`
/// (Sec. 3.3). The input is certified first ([`certify_planar`] of the identity remesh,
/// failure → [`Remesh2dError::InvalidDomain`]); the output after every round (if
/// `options.certify_every_round`) and at the end (failure → [`Remesh2dError::Invariant`]).
pub fn remesh_planar(
    domain: &PlanarDomain,
    metric: &dyn Metric2d,
    target_length: f64,
    options: &LctOptions,
    rng: &mut ChaCha8Rng,
) -> Result<PlanarMesh, Remesh2dError> {
    if !(target_length.is_finite() && target_length > 0.0) {
        return Err(Remesh2dError::BadTargetLength(target_length));
    }
    certify_planar(domain, &identity(domain)).map_err(Remesh2dError::InvalidDomain)?;
    let max = options.max_faces;
    let ideal = super::ideal_faces(domain, metric, target_length);
    if ideal > max {
        return Err(Remesh2dError::TooDense { faces: ideal, max });
    }
    // Split passes overshoot the ideal count before the collapses bring it back (measured: up
    // to 41× under the analytic suite's 1000:1 metric, and 21× at the end of a round); a mesh
    // far past that is refining a metric too fine in one direction for its domain (its ideal
    // count is small, its splits never stop).
    let transient_base = ideal
        .max(domain.triangles.len() as f64)
        .max(MIN_TRANSIENT_BASE);
    let mut fixed = vec![false; domain.points.len()];
    for &b in &domain.boundary {
        fixed[b as usize] = true;
    }
    let mut locked: HashSet<(u32, u32)> = HashSet::new();
    let nb = domain.boundary.len();
    for k in 0..nb {
        let (a, b) = (domain.boundary[k], domain.boundary[(k + 1) % nb]);
        locked.insert((a.min(b), a.max(b)));
    }
    for &[a, b] in &domain.constrained_edges {
        fixed[a as usize] = true;
        fixed[b as usize] = true;
        locked.insert((a.min(b), a.max(b)));
    }
    let mut mesh = match options.rebuild && domain.constrained_edges.is_empty() {
        true => from_boundary(domain, metric, target_length * options.start_spacing, rng)
            .unwrap_or_else(|| identity(domain)),
        false => identity(domain),
    };
    // Fixed/locked status travels with `origin` (input ids) across rounds.
    for round in 0..=options.rounds {
        let mut w = Work::new(&mesh, metric, target_length, &fixed, &locked, options)?;
        if round < options.rounds {
            for _ in 0..options.max_passes {
                let split = w.split_pass();
                // A disk with V vertices has fewer than 2V faces.
                let faces = 2.0 * w.vertex_count() as f64;
                if faces > (SPLIT_OVERSHOOT * transient_base).min(MAX_OVERSHOOT * max) {
                    return Err(Remesh2dError::TooDense { faces, max });
                }
                if split == 0 {
                    break;
                }
            }
            for _ in 0..options.max_passes {
                if w.collapse_pass() == 0 {
                    break;
                }
            }
            if options.density {
                // An ideal mesh of metric area A has A / (√3/4·L²) faces, and a disk
                // triangulation with b boundary vertices has (F + b + 2) / 2 vertices.
                let faces = w.metric_area() / (3f64.sqrt() / 4.0 * target_length * target_length);
                let target = (faces + domain.boundary.len() as f64 + 2.0) / 2.0;
                for _ in 0..options.max_passes {
                    if w.density_pass(target) == 0 {
                        break;
                    }
                }
            }
            if options.valence_flips {
                w.valence_flips(options.valence_quality_guard);
            } else {
                w.flip_all();
            }
            for _ in 0..options.smoothing_iters {
                w.smooth_pass(options, false, rng)?;
                w.flip_all();
            }
        } else {
            for _ in 0..options.final_smoothing {
                w.smooth_pass(options, true, rng)?;
                w.flip_with(options.final_maxmin_flips);
            }
        }
        mesh = w.finish();
        if options.certify_every_round || round == options.rounds {
            certify_planar(domain, &mesh)?;
        }
    }
    let faces = mesh.triangles.len() as f64;
    match faces > max {
        true => Err(Remesh2dError::TooDense { faces, max }),
        false => Ok(mesh),
    }
}

/// Evaluate the metric, clamped to SPD ([`clamp_spd`]).
fn eval(metric: &dyn Metric2d, p: &Point2<f64>) -> Result<Matrix2<f64>, Remesh2dError> {
    clamp_spd(&metric.metric(p)).ok_or(Remesh2dError::MetricNotSpd { x: p.x, y: p.y })
}
