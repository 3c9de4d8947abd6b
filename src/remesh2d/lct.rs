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
//! after split/collapse, and a final polish (equilateral-apex smoothing + max-min flips). Plain
//! LCT stalls at valence defects (q_avg ≈ 0.88–0.91 on the demo); with them every demo case has
//! q_avg ≥ 0.91.

use super::{clamp_spd, Metric2d, PlanarDomain, PlanarMesh, PlanarRemesher, Remesh2dError};
use crate::invariants::certify_planar;
use crate::predicates::{orient2d, Sign};
use nalgebra::{Matrix2, Point2, Vector2};
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

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
    /// the edge midpoint) instead of the mean of the vertex tensors (default false: as good on
    /// the demo cases, and cheaper with a [`super::PlanarMetricField`]).
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
    /// the domain's triangulation (default true), so the result does not inherit the input's
    /// connectivity.
    pub rebuild: bool,
    /// The spacing of the interior vertices kept for the start, times L (default 0.8).
    pub start_spacing: f64,
    /// After split and collapse, bring the vertex count to that of an ideal mesh of the
    /// domain's metric area (default true), so edges have length L on average.
    pub density: bool,
}

impl Default for LctOptions {
    /// The settings for the curvature metric at L_tar = 1.5·L_avg (the paper's protocol, measured
    /// on the 12 shared meshes): start from the patch's own triangulation, split above 4/3 L,
    /// collapse below 4/5 L, no density control.
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
}

/// The start of the rounds: the constrained Delaunay triangulation of the domain's boundary
/// polygon and of those of its interior vertices that are at least `spacing` apart in the
/// metric from the boundary and from each other (taken in id order), as a remesh of `domain`;
/// `None` when spade cannot triangulate it. The result does not inherit the input's
/// connectivity (a regular input grid that is anisotropic in the metric is a fixed point of
/// split, collapse, flip and smoothing), while a fine input gives a well-spaced start.
fn from_boundary(domain: &PlanarDomain, metric: &dyn Metric2d, spacing: f64) -> Option<PlanarMesh> {
    let loop_points: Vec<Point2<f64>> = domain
        .boundary
        .iter()
        .map(|&b| domain.points[b as usize])
        .collect();
    let mut on_boundary = vec![false; domain.points.len()];
    for &b in &domain.boundary {
        on_boundary[b as usize] = true;
    }
    let interior: Vec<u32> = (0..domain.points.len() as u32)
        .filter(|&i| !on_boundary[i as usize])
        .collect();
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
/// from each other in the metric (mean of the two points' tensors), greedily in order.
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
        return Err(Remesh2dError::InvalidDomain(format!(
            "target length {target_length} is not positive"
        )));
    }
    certify_planar(domain, &identity(domain))
        .map_err(|e| Remesh2dError::InvalidDomain(e.to_string()))?;
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
        true => from_boundary(domain, metric, target_length * options.start_spacing)
            .unwrap_or_else(|| identity(domain)),
        false => identity(domain),
    };
    // Fixed/locked status travels with `origin` (input ids) across rounds.
    for round in 0..=options.rounds {
        let mut w = Work::new(&mesh, metric, target_length, &fixed, &locked, options)?;
        if round < options.rounds {
            for _ in 0..options.max_passes {
                if w.split_pass() == 0 {
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
    Ok(mesh)
}

/// The density pass leaves the vertex count alone within this fraction of its target.
const DENSITY_SLACK: f64 = 0.02;

/// A fast hasher for the packed `u64` half-edge keys (multiplicative, Fx-style).
#[derive(Default)]
struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(5) ^ b as u64).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

type KeyMap = HashMap<u64, u32, BuildHasherDefault<KeyHasher>>;

#[inline]
fn key(a: u32, b: u32) -> u64 {
    ((a as u64) << 32) | b as u64
}

/// The triangle energy `|T|/8 · Σ_e eᵀ M̄ e` (module doc); `|T|` signed.
#[inline]
fn tri_energy(p: [Point2<f64>; 3], m: &Matrix2<f64>) -> f64 {
    let area = 0.5 * (p[1] - p[0]).perp(&(p[2] - p[0]));
    let s: f64 = (0..3)
        .map(|i| {
            let e = p[(i + 1) % 3] - p[i];
            e.dot(&(m * e))
        })
        .sum();
    area * s / 8.0
}

/// The working triangulation of one round: a triangle list with a half-edge map.
struct Work<'a> {
    pts: Vec<Point2<f64>>,
    origin: Vec<Option<u32>>,
    vm: Vec<Matrix2<f64>>,
    fixed: Vec<bool>,
    valive: Vec<bool>,
    tris: Vec<[u32; 3]>,
    alive: Vec<bool>,
    touched: Vec<bool>,
    he: KeyMap,
    vt: Vec<u32>,
    locked: HashSet<(u32, u32)>,
    metric: &'a dyn Metric2d,
    l: f64,
    split: f64,
    collapse: f64,
    guard: f64,
    at_centroid: bool,
}

impl<'a> Work<'a> {
    fn new(
        mesh: &PlanarMesh,
        metric: &'a dyn Metric2d,
        l: f64,
        fixed_in: &[bool],
        locked_in: &HashSet<(u32, u32)>,
        options: &LctOptions,
    ) -> Result<Self, Remesh2dError> {
        let n = mesh.points.len();
        let mut inv: HashMap<u32, u32> = HashMap::new();
        let mut fixed = vec![false; n];
        for (i, o) in mesh.origin.iter().enumerate() {
            if let Some(j) = *o {
                inv.insert(j, i as u32);
                fixed[i] = fixed_in[j as usize];
            }
        }
        let locked = locked_in
            .iter()
            .filter_map(|(a, b)| {
                let (x, y) = (*inv.get(a)?, *inv.get(b)?);
                Some((x.min(y), x.max(y)))
            })
            .collect();
        let vm = mesh
            .points
            .iter()
            .map(|p| eval(metric, p))
            .collect::<Result<Vec<_>, _>>()?;
        let mut w = Work {
            pts: mesh.points.clone(),
            origin: mesh.origin.clone(),
            vm,
            fixed,
            valive: vec![true; n],
            tris: Vec::with_capacity(mesh.triangles.len() * 2),
            alive: Vec::new(),
            touched: Vec::new(),
            he: KeyMap::default(),
            vt: vec![u32::MAX; n],
            locked,
            metric,
            l,
            split: options.split_ratio,
            collapse: options.collapse_ratio,
            guard: options.collapse_guard.unwrap_or(options.split_ratio),
            at_centroid: options.tensor_at_centroid,
        };
        w.he.reserve(mesh.triangles.len() * 6);
        for t in &mesh.triangles {
            w.add_tri(*t);
        }
        Ok(w)
    }

    fn add_tri(&mut self, t: [u32; 3]) -> u32 {
        let i = self.tris.len() as u32;
        self.tris.push(t);
        self.alive.push(true);
        self.touched.push(false);
        for k in 0..3 {
            self.he.insert(key(t[k], t[(k + 1) % 3]), i);
            self.vt[t[k] as usize] = i;
        }
        i
    }

    fn remove_tri(&mut self, i: u32) {
        let t = self.tris[i as usize];
        self.alive[i as usize] = false;
        for k in 0..3 {
            let kk = key(t[k], t[(k + 1) % 3]);
            if self.he.get(&kk) == Some(&i) {
                self.he.remove(&kk);
            }
        }
    }

    /// Replace triangle `i` in place (used by flips).
    fn set_tri(&mut self, i: u32, t: [u32; 3]) {
        self.remove_tri(i);
        self.alive[i as usize] = true;
        self.tris[i as usize] = t;
        for k in 0..3 {
            self.he.insert(key(t[k], t[(k + 1) % 3]), i);
            self.vt[t[k] as usize] = i;
        }
    }

    fn add_vertex(&mut self, p: Point2<f64>) -> Result<u32, Remesh2dError> {
        let m = eval(self.metric, &p)?;
        self.pts.push(p);
        self.origin.push(None);
        self.vm.push(m);
        self.fixed.push(false);
        self.valive.push(true);
        self.vt.push(u32::MAX);
        Ok(self.pts.len() as u32 - 1)
    }

    /// Triangle `t` rotated so that `v` comes first.
    fn rotated(&self, t: u32, v: u32) -> [u32; 3] {
        let x = self.tris[t as usize];
        if x[0] == v {
            x
        } else if x[1] == v {
            [x[1], x[2], x[0]]
        } else {
            [x[2], x[0], x[1]]
        }
    }

    /// The triangles around `v`, counter-clockwise (for a boundary vertex: from one boundary
    /// edge to the other). `None` if the vertex's star is inconsistent.
    fn star(&self, v: u32) -> Option<Vec<u32>> {
        let t0 = self.vt[v as usize];
        if t0 == u32::MAX || !self.alive[t0 as usize] || !self.tris[t0 as usize].contains(&v) {
            return None;
        }
        let mut out = vec![t0];
        let mut t = t0;
        loop {
            let [_, _, c] = self.rotated(t, v);
            match self.he.get(&key(v, c)) {
                Some(&nt) if nt == t0 => return Some(out),
                Some(&nt) => {
                    if out.len() > 64 {
                        return None;
                    }
                    out.push(nt);
                    t = nt;
                }
                None => break,
            }
        }
        // Open star: walk clockwise from t0 too.
        let mut back = Vec::new();
        let mut t = t0;
        loop {
            let [_, b, _] = self.rotated(t, v);
            match self.he.get(&key(b, v)) {
                Some(&pt) => {
                    if back.len() > 64 {
                        return None;
                    }
                    back.push(pt);
                    t = pt;
                }
                None => break,
            }
        }
        back.reverse();
        back.extend(out);
        Some(back)
    }

    fn edge_len(&self, a: u32, b: u32) -> f64 {
        let (pa, pb) = (self.pts[a as usize], self.pts[b as usize]);
        let e = pb - pa;
        let m = if self.at_centroid {
            self.sample(&Point2::from((pa.coords + pb.coords) * 0.5))
        } else {
            None
        }
        .unwrap_or_else(|| (self.vm[a as usize] + self.vm[b as usize]) * 0.5);
        e.dot(&(m * e)).max(0.0).sqrt()
    }

    fn is_locked(&self, a: u32, b: u32) -> bool {
        self.locked.contains(&(a.min(b), a.max(b)))
    }

    fn positive(&self, t: [u32; 3]) -> bool {
        orient2d(
            &self.pts[t[0] as usize],
            &self.pts[t[1] as usize],
            &self.pts[t[2] as usize],
        ) == Sign::Positive
    }

    /// The tensor `M_T` of a triangle: the metric at its centroid (`at_centroid`), else the
    /// mean of its vertex tensors.
    fn tri_metric(&self, t: [u32; 3]) -> Matrix2<f64> {
        let p = t.map(|i| self.pts[i as usize]);
        if self.at_centroid {
            if let Some(m) = self.sample(&Point2::from(
                (p[0].coords + p[1].coords + p[2].coords) / 3.0,
            )) {
                return m;
            }
        }
        (self.vm[t[0] as usize] + self.vm[t[1] as usize] + self.vm[t[2] as usize]) / 3.0
    }

    fn sample(&self, p: &Point2<f64>) -> Option<Matrix2<f64>> {
        clamp_spd(&self.metric.metric(p))
    }

    /// The metric quality `q = 2√3·a/(p·h)` of triangle `t` in its tensor `M_T`.
    fn quality(&self, t: [u32; 3]) -> f64 {
        super::stats::sides_and_quality(&t.map(|i| self.pts[i as usize]), &self.tri_metric(t)).1
    }

    fn energy(&self, t: [u32; 3]) -> f64 {
        tri_energy(t.map(|i| self.pts[i as usize]), &self.tri_metric(t))
    }

    /// Interior, unlocked edges `(a, b)` with `a < b` and their metric lengths, filtered by
    /// `keep(len)`, sorted by `order` of length then by key (deterministic).
    fn edges_where(&self, keep: impl Fn(f64) -> bool, longest_first: bool) -> Vec<(f64, u32, u32)> {
        let mut v = Vec::new();
        for (i, t) in self.tris.iter().enumerate() {
            if !self.alive[i] {
                continue;
            }
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if a < b && self.he.contains_key(&key(b, a)) && !self.is_locked(a, b) {
                    let l = self.edge_len(a, b);
                    if keep(l) {
                        v.push((l, a, b));
                    }
                }
            }
        }
        v.sort_by(|x, y| {
            let o = x.0.total_cmp(&y.0);
            let o = if longest_first { o.reverse() } else { o };
            o.then((x.1, x.2).cmp(&(y.1, y.2)))
        });
        v
    }

    fn clear_touched(&mut self) {
        self.touched.iter_mut().for_each(|t| *t = false);
    }

    /// The metric area of the triangulation, `Σ |T|·√det M_T`.
    fn metric_area(&self) -> f64 {
        self.tris
            .iter()
            .zip(&self.alive)
            .filter(|(_, a)| **a)
            .map(|(t, _)| {
                let p = t.map(|i| self.pts[i as usize]);
                let area = 0.5 * (p[1] - p[0]).perp(&(p[2] - p[0]));
                area * self.tri_metric(*t).determinant().max(0.0).sqrt()
            })
            .sum()
    }

    /// Vertices in use.
    fn vertex_count(&self) -> usize {
        self.valive.iter().filter(|a| **a).count()
    }

    /// Edge length adjustment, part 3 (ours): bring the vertex count to `target` (the count of
    /// an ideal mesh of the domain's metric area, see [`remesh_planar`]) by collapsing the
    /// shortest edges below L or splitting the longest above L, so that edges come out at L
    /// on average rather than wherever the split and collapse thresholds leave them.
    fn density_pass(&mut self, target: f64) -> usize {
        let v = self.vertex_count() as f64;
        if v > target * (1.0 + DENSITY_SLACK) {
            self.collapse_shorter_than(self.l, (v - target).round() as usize)
        } else if v < target * (1.0 - DENSITY_SLACK) {
            self.split_longer_than(self.l, (target - v).round() as usize)
        } else {
            0
        }
    }

    /// Edge length adjustment, part 1: split every (non-adjacent) long interior edge at its
    /// midpoint. Returns the number of splits.
    fn split_pass(&mut self) -> usize {
        self.split_longer_than(self.split * self.l, usize::MAX)
    }

    /// Split the (non-adjacent) interior edges longer than `thr`, longest first, at most
    /// `max` of them. Returns the number of splits.
    fn split_longer_than(&mut self, thr: f64, max: usize) -> usize {
        self.clear_touched();
        let cands = self.edges_where(|l| l > thr, true);
        let mut n = 0;
        for (_, a, b) in cands {
            if n >= max {
                break;
            }
            let (Some(&t1), Some(&t2)) = (self.he.get(&key(a, b)), self.he.get(&key(b, a))) else {
                continue;
            };
            if self.touched[t1 as usize] || self.touched[t2 as usize] {
                continue;
            }
            let c = self.rotated(t1, a)[2];
            let d = self.rotated(t2, b)[2];
            let (pa, pb) = (self.pts[a as usize], self.pts[b as usize]);
            let m = Point2::new(0.5 * (pa.x + pb.x), 0.5 * (pa.y + pb.y));
            // Rounding can put the midpoint off the segment: check all four new triangles.
            let ok = orient2d(&pa, &m, &self.pts[c as usize]) == Sign::Positive
                && orient2d(&m, &pb, &self.pts[c as usize]) == Sign::Positive
                && orient2d(&pb, &m, &self.pts[d as usize]) == Sign::Positive
                && orient2d(&m, &pa, &self.pts[d as usize]) == Sign::Positive;
            if !ok {
                continue;
            }
            let Ok(mi) = self.add_vertex(m) else { continue };
            self.remove_tri(t1);
            self.remove_tri(t2);
            for t in [[a, mi, c], [mi, b, c], [b, mi, d], [mi, a, d]] {
                let i = self.add_tri(t);
                self.touched[i as usize] = true;
            }
            n += 1;
        }
        n
    }

    /// Edge length adjustment, part 2: collapse short interior edges onto one endpoint (the
    /// removed endpoint must be free). Refused when the link condition fails, when a
    /// remaining triangle would not be positive (exact), or when a new edge would be longer
    /// than the split threshold. Returns the number of collapses.
    fn collapse_pass(&mut self) -> usize {
        self.collapse_shorter_than(self.collapse * self.l, usize::MAX)
    }

    /// Collapse interior edges shorter than `thr`, shortest first, at most `max` of them.
    fn collapse_shorter_than(&mut self, thr: f64, max: usize) -> usize {
        self.clear_touched();
        let cands = self.edges_where(|l| l < thr, false);
        let mut n = 0;
        for (_, a, b) in cands {
            if n >= max {
                break;
            }
            if !self.valive[a as usize] || !self.valive[b as usize] {
                continue;
            }
            if self.try_collapse(a, b) || self.try_collapse(b, a) {
                n += 1;
            }
        }
        n
    }

    /// Collapse `a` onto `b` (remove `a`).
    fn try_collapse(&mut self, a: u32, b: u32) -> bool {
        if self.fixed[a as usize] {
            return false;
        }
        let (Some(&t1), Some(&t2)) = (self.he.get(&key(a, b)), self.he.get(&key(b, a))) else {
            return false;
        };
        let Some(star_a) = self.star(a) else {
            return false;
        };
        let Some(star_b) = self.star(b) else {
            return false;
        };
        if star_a.iter().any(|&t| self.touched[t as usize]) {
            return false;
        }
        let c = self.rotated(t1, a)[2];
        let d = self.rotated(t2, b)[2];
        // Link condition: the common neighbours of a and b are exactly c and d.
        let ring = |s: &[u32], v: u32| -> Vec<u32> {
            let mut r: Vec<u32> = s
                .iter()
                .flat_map(|&t| self.tris[t as usize])
                .filter(|&x| x != v)
                .collect();
            r.sort_unstable();
            r.dedup();
            r
        };
        let ra = ring(&star_a, a);
        let rb = ring(&star_b, b);
        let common: Vec<u32> = ra
            .iter()
            .filter(|x| rb.binary_search(x).is_ok())
            .copied()
            .collect();
        let mut cd = [c, d];
        cd.sort_unstable();
        if common != cd {
            return false;
        }
        let limit = self.guard * self.l;
        let mut new_tris = Vec::with_capacity(star_a.len());
        for &t in &star_a {
            if t == t1 || t == t2 {
                continue;
            }
            let nt = self.tris[t as usize].map(|x| if x == a { b } else { x });
            if !self.positive(nt) {
                return false;
            }
            new_tris.push(nt);
        }
        // The removed vertex's metric stays out of the new edges: measure with b's.
        let pb = self.pts[b as usize];
        for &x in &ra {
            if x != b {
                let e = self.pts[x as usize] - pb;
                let m = (self.vm[x as usize] + self.vm[b as usize]) * 0.5;
                if e.dot(&(m * e)).sqrt() > limit {
                    return false;
                }
            }
        }
        for &t in &star_a {
            self.remove_tri(t);
        }
        for nt in new_tris {
            let i = self.add_tri(nt);
            self.touched[i as usize] = true;
        }
        self.valive[a as usize] = false;
        true
    }

    /// Connectivity update: flip interior unlocked edges of strictly convex quads (exact
    /// `orient2d`) when the LCT energy strictly decreases, until no flip applies. Each flip
    /// lowers the total energy, so this ends; a cap of 20 flips per triangle guards anyway.
    fn flip_all(&mut self) -> usize {
        self.flip_with(false)
    }

    /// Flips as in [`Work::flip_all`]; with `maxmin`, the criterion is instead that the smaller
    /// metric quality `q` of the two triangles strictly increases (the final polish).
    fn flip_with(&mut self, maxmin: bool) -> usize {
        let mut queue: Vec<(u32, u32)> = Vec::new();
        for (i, t) in self.tris.iter().enumerate() {
            if self.alive[i] {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    if a < b {
                        queue.push((a, b));
                    }
                }
            }
        }
        let cap = 20 * self.tris.len();
        let mut n = 0;
        while let Some((a, b)) = queue.pop() {
            if n >= cap {
                break;
            }
            if self.is_locked(a, b) {
                continue;
            }
            let (Some(&t1), Some(&t2)) = (self.he.get(&key(a, b)), self.he.get(&key(b, a))) else {
                continue;
            };
            let c = self.rotated(t1, a)[2];
            let d = self.rotated(t2, b)[2];
            if c == d || self.he.contains_key(&key(c, d)) || self.he.contains_key(&key(d, c)) {
                continue;
            }
            let (n1, n2) = ([a, d, c], [d, b, c]);
            if !self.positive(n1) || !self.positive(n2) {
                continue;
            }
            let better = if maxmin {
                let old = self.quality([a, b, c]).min(self.quality([b, a, d]));
                let new = self.quality(n1).min(self.quality(n2));
                new > old + 1e-9
            } else {
                let old = self.energy([a, b, c]) + self.energy([b, a, d]);
                let new = self.energy(n1) + self.energy(n2);
                new < old * (1.0 - 1e-10)
            };
            if !better {
                continue;
            }
            self.set_tri(t1, n1);
            self.set_tri(t2, n2);
            n += 1;
            for (x, y) in [(a, d), (d, b), (b, c), (c, a)] {
                queue.push((x.min(y), x.max(y)));
            }
        }
        n
    }

    /// Valence-regularising flips (Botsch–Kobbelt style): flip an interior unlocked edge of a
    /// strictly convex quad when it lowers `Σ (valence − target)²` over the quad's four corners
    /// (target 6 inside; on the boundary `round(θ/60°) + 1`, θ the corner angle in the vertex's
    /// tensor) and does not lower the smaller metric quality of the pair below
    /// `valence_quality_guard` times its old value.
    fn valence_flips(&mut self, guard: f64) -> usize {
        let n = self.pts.len();
        let mut val = vec![0i32; n];
        let mut target = vec![6i32; n];
        for (&k, _) in self.he.iter() {
            let (a, b) = ((k >> 32) as u32, k as u32);
            if !self.he.contains_key(&key(b, a)) || a < b {
                val[a as usize] += 1;
                val[b as usize] += 1;
            }
        }
        for v in 0..n as u32 {
            if !self.valive[v as usize] || !self.fixed[v as usize] {
                continue;
            }
            let Some(star) = self.star(v) else { continue };
            let first = self.rotated(star[0], v)[1];
            let last = self.rotated(star[star.len() - 1], v)[2];
            let closed =
                self.he.contains_key(&key(v, last)) && self.he.contains_key(&key(first, v));
            if closed && self.he.contains_key(&key(last, v)) {
                continue; // an interior constrained vertex: target 6
            }
            let m = self.vm[v as usize];
            let pv = self.pts[v as usize];
            let (e1, e2) = (self.pts[first as usize] - pv, self.pts[last as usize] - pv);
            let (l1, l2) = (e1.dot(&(m * e1)).sqrt(), e2.dot(&(m * e2)).sqrt());
            let c = (e1.dot(&(m * e2)) / (l1 * l2)).clamp(-1.0, 1.0);
            // The corner angle is the CCW sweep from `first` to `last` (it may exceed 180°).
            let mut th = c.acos();
            if e1.perp(&e2) < 0.0 {
                th = 2.0 * std::f64::consts::PI - th;
            }
            target[v as usize] = ((th / (std::f64::consts::PI / 3.0)).round() as i32).max(1) + 1;
        }
        let mut count = 0;
        let edges: Vec<(u32, u32)> = self
            .he
            .keys()
            .map(|&k| ((k >> 32) as u32, k as u32))
            .filter(|(a, b)| a < b)
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .collect();
        for (a, b) in edges {
            if self.is_locked(a, b) {
                continue;
            }
            let (Some(&t1), Some(&t2)) = (self.he.get(&key(a, b)), self.he.get(&key(b, a))) else {
                continue;
            };
            let c = self.rotated(t1, a)[2];
            let d = self.rotated(t2, b)[2];
            if c == d || self.he.contains_key(&key(c, d)) || self.he.contains_key(&key(d, c)) {
                continue;
            }
            let dev = |x: u32, dv: i32| {
                let e = val[x as usize] + dv - target[x as usize];
                e * e
            };
            let before = dev(a, 0) + dev(b, 0) + dev(c, 0) + dev(d, 0);
            let after = dev(a, -1) + dev(b, -1) + dev(c, 1) + dev(d, 1);
            if after >= before {
                continue;
            }
            let (n1, n2) = ([a, d, c], [d, b, c]);
            if !self.positive(n1) || !self.positive(n2) {
                continue;
            }
            let old = self.quality([a, b, c]).min(self.quality([b, a, d]));
            let new = self.quality(n1).min(self.quality(n2));
            if new < guard * old {
                continue;
            }
            self.set_tri(t1, n1);
            self.set_tri(t2, n2);
            val[a as usize] -= 1;
            val[b as usize] -= 1;
            val[c as usize] += 1;
            val[d as usize] += 1;
            count += 1;
        }
        count
    }

    /// Vertex position optimisation: every free vertex, in a seeded random order, moves to
    /// the minimiser of its 1-ring energy `Σ_T E_T(x)` (tensors frozen at the current
    /// positions): Newton steps on the cubic `E_T = A_T(x)·S_T(x)/8`, with the positive
    /// "frozen area" Hessian `Σ 4 A_T M̄_T` when the true one is not positive definite; each
    /// step halves until the energy decreases and every 1-ring triangle is positive (exact).
    fn smooth_pass(
        &mut self,
        options: &LctOptions,
        apex: bool,
        rng: &mut ChaCha8Rng,
    ) -> Result<(), Remesh2dError> {
        let mut order: Vec<u32> = (0..self.pts.len() as u32)
            .filter(|&v| self.valive[v as usize] && !self.fixed[v as usize])
            .collect();
        order.shuffle(rng);
        // Vertex → triangles, once per pass (smoothing does not change the connectivity). A free
        // vertex is interior, so its star is closed; order does not matter below.
        let n = self.pts.len();
        let mut start = vec![0u32; n + 1];
        for (i, t) in self.tris.iter().enumerate() {
            if self.alive[i] {
                for &x in t {
                    start[x as usize + 1] += 1;
                }
            }
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut incident = vec![0u32; start[n] as usize];
        for (i, t) in self.tris.iter().enumerate() {
            if self.alive[i] {
                for &x in t {
                    incident[fill[x as usize] as usize] = i as u32;
                    fill[x as usize] += 1;
                }
            }
        }
        for v in order {
            let star = &incident[start[v as usize] as usize..start[v as usize + 1] as usize];
            if star.len() < 3 {
                continue;
            }
            let ring: Vec<[u32; 3]> = star.iter().map(|&t| self.rotated(t, v)).collect();
            let tens: Vec<(Point2<f64>, Point2<f64>, Matrix2<f64>)> = ring
                .iter()
                .map(|t| {
                    (
                        self.pts[t[1] as usize],
                        self.pts[t[2] as usize],
                        self.tri_metric(*t),
                    )
                })
                .collect();
            let energy = |x: &Point2<f64>| -> f64 {
                tens.iter()
                    .map(|(p, q, m)| tri_energy([*x, *p, *q], m))
                    .sum()
            };
            let x0 = self.pts[v as usize];
            let mut x = x0;
            if apex {
                if let Some(xn) = apex_target(&tens) {
                    let step = xn - x0;
                    let mut t = 1.0;
                    for _ in 0..12 {
                        let xn = x0 + step * t;
                        if tens
                            .iter()
                            .all(|(p, q, _)| orient2d(&xn, p, q) == Sign::Positive)
                        {
                            x = xn;
                            break;
                        }
                        t *= 0.5;
                    }
                }
            }
            let mut e = energy(&x);
            for _ in 0..if apex { 0 } else { options.newton_steps } {
                let mut g = Vector2::zeros();
                let mut h = Matrix2::zeros();
                let mut h0 = Matrix2::zeros();
                for (p, q, m) in &tens {
                    let area = 0.5 * (p - x).perp(&(q - x));
                    let ga = 0.5 * Vector2::new(p.y - q.y, q.x - p.x);
                    let (ep, eq) = (x - p, x - q);
                    let s = ep.dot(&(m * ep)) + eq.dot(&(m * eq)) + (p - q).dot(&(m * (p - q)));
                    let gs = 2.0 * m * (ep + eq);
                    g += (area * gs + s * ga) / 8.0;
                    h += (4.0 * area * m + ga * gs.transpose() + gs * ga.transpose()) / 8.0;
                    h0 += 4.0 * area.abs() * m / 8.0;
                }
                let pd = h.determinant() > 0.0 && h.trace() > 0.0;
                let step = if pd { h.try_inverse() } else { None }
                    .or_else(|| h0.try_inverse())
                    .map(|hi| -(hi * g));
                let Some(step) = step else { break };
                if !step.iter().all(|s| s.is_finite()) {
                    break;
                }
                let mut t = 1.0;
                let mut moved = false;
                for _ in 0..12 {
                    let xn = x + step * t;
                    let ok = tens
                        .iter()
                        .all(|(p, q, _)| orient2d(&xn, p, q) == Sign::Positive);
                    if ok {
                        let en = energy(&xn);
                        if en < e {
                            x = xn;
                            e = en;
                            moved = true;
                            break;
                        }
                    }
                    t *= 0.5;
                }
                if !moved {
                    break;
                }
            }
            if x != x0 {
                self.pts[v as usize] = x;
                self.vm[v as usize] = eval(self.metric, &x)?;
                self.origin[v as usize] = None;
            }
        }
        Ok(())
    }

    /// The compacted mesh.
    fn finish(self) -> PlanarMesh {
        let mut map = vec![u32::MAX; self.pts.len()];
        let mut points = Vec::new();
        let mut origin = Vec::new();
        let mut triangles = Vec::new();
        for (i, t) in self.tris.iter().enumerate() {
            if !self.alive[i] {
                continue;
            }
            let nt = t.map(|v| {
                if map[v as usize] == u32::MAX {
                    map[v as usize] = points.len() as u32;
                    points.push(self.pts[v as usize]);
                    origin.push(self.origin[v as usize]);
                }
                map[v as usize]
            });
            triangles.push(nt);
        }
        PlanarMesh {
            points,
            triangles,
            origin,
        }
    }
}

/// The mean over the 1-ring triangles `(x, p, q)` of the apex that makes each one equilateral
/// in its tensor: with `M = L Lᵀ` and `y = Lᵀ x`, the apex is
/// `y = (y_p + y_q)/2 + √3/2 · rot90(y_q − y_p)` mapped back.
fn apex_target(tens: &[(Point2<f64>, Point2<f64>, Matrix2<f64>)]) -> Option<Point2<f64>> {
    let mut acc = Vector2::zeros();
    for (p, q, m) in tens {
        let l = m.cholesky()?.l();
        let lt = l.transpose();
        let lti = lt.try_inverse()?;
        let (yp, yq) = (lt * p.coords, lt * q.coords);
        let d = yq - yp;
        let y = (yp + yq) * 0.5 + Vector2::new(-d.y, d.x) * (3f64.sqrt() / 2.0);
        acc += lti * y;
    }
    let c = acc / tens.len() as f64;
    c.iter().all(|x| x.is_finite()).then(|| Point2::from(c))
}

/// Evaluate the metric, clamped to SPD ([`clamp_spd`]).
fn eval(metric: &dyn Metric2d, p: &Point2<f64>) -> Result<Matrix2<f64>, Remesh2dError> {
    clamp_spd(&metric.metric(p)).ok_or(Remesh2dError::MetricNotSpd { x: p.x, y: p.y })
}
