//! The working triangulation of one LCT round: a triangle list with a half-edge map, and the
//! elementary queries and edits the passes share.

use super::{eval, LctOptions};
use crate::predicates::{orient2d, Sign};
use crate::remesh2d::{clamp_spd, Metric2d, PlanarMesh, Remesh2dError};
use nalgebra::{Matrix2, Point2};
use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

/// The density pass leaves the vertex count alone within this fraction of its target.
pub(super) const DENSITY_SLACK: f64 = 0.02;

/// A fast hasher for the packed `u64` half-edge keys (multiplicative, Fx-style).
#[derive(Default)]
pub(super) struct KeyHasher(u64);

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

pub(super) type KeyMap = HashMap<u64, u32, BuildHasherDefault<KeyHasher>>;

#[inline]
pub(super) fn key(a: u32, b: u32) -> u64 {
    ((a as u64) << 32) | b as u64
}

/// The triangle energy `|T|/8 · Σ_e eᵀ M̄ e` (module doc); `|T|` signed.
#[inline]
pub(super) fn tri_energy(p: [Point2<f64>; 3], m: &Matrix2<f64>) -> f64 {
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
pub(super) struct Work<'a> {
    pub(super) pts: Vec<Point2<f64>>,
    pub(super) origin: Vec<Option<u32>>,
    pub(super) vm: Vec<Matrix2<f64>>,
    pub(super) fixed: Vec<bool>,
    pub(super) valive: Vec<bool>,
    pub(super) tris: Vec<[u32; 3]>,
    pub(super) alive: Vec<bool>,
    pub(super) touched: Vec<bool>,
    pub(super) he: KeyMap,
    pub(super) vt: Vec<u32>,
    pub(super) locked: HashSet<(u32, u32)>,
    pub(super) metric: &'a dyn Metric2d,
    pub(super) l: f64,
    pub(super) split: f64,
    pub(super) collapse: f64,
    pub(super) guard: f64,
    pub(super) at_centroid: bool,
}

impl<'a> Work<'a> {
    pub(super) fn new(
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

    pub(super) fn add_tri(&mut self, t: [u32; 3]) -> u32 {
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

    pub(super) fn remove_tri(&mut self, i: u32) {
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
    pub(super) fn set_tri(&mut self, i: u32, t: [u32; 3]) {
        self.remove_tri(i);
        self.alive[i as usize] = true;
        self.tris[i as usize] = t;
        for k in 0..3 {
            self.he.insert(key(t[k], t[(k + 1) % 3]), i);
            self.vt[t[k] as usize] = i;
        }
    }

    pub(super) fn add_vertex(&mut self, p: Point2<f64>) -> Result<u32, Remesh2dError> {
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
    pub(super) fn rotated(&self, t: u32, v: u32) -> [u32; 3] {
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
    pub(super) fn star(&self, v: u32) -> Option<Vec<u32>> {
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

    pub(super) fn edge_len(&self, a: u32, b: u32) -> f64 {
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

    pub(super) fn is_locked(&self, a: u32, b: u32) -> bool {
        self.locked.contains(&(a.min(b), a.max(b)))
    }

    pub(super) fn positive(&self, t: [u32; 3]) -> bool {
        orient2d(
            &self.pts[t[0] as usize],
            &self.pts[t[1] as usize],
            &self.pts[t[2] as usize],
        ) == Sign::Positive
    }

    /// The tensor `M_T` of a triangle: the metric at its centroid (`at_centroid`), else the
    /// mean of its vertex tensors.
    pub(super) fn tri_metric(&self, t: [u32; 3]) -> Matrix2<f64> {
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

    pub(super) fn sample(&self, p: &Point2<f64>) -> Option<Matrix2<f64>> {
        clamp_spd(&self.metric.metric(p))
    }

    /// The metric quality `q = 2√3·a/(p·h)` of triangle `t` in its tensor `M_T`.
    pub(super) fn quality(&self, t: [u32; 3]) -> f64 {
        crate::remesh2d::stats::sides_and_quality(
            &t.map(|i| self.pts[i as usize]),
            &self.tri_metric(t),
        )
        .1
    }

    pub(super) fn energy(&self, t: [u32; 3]) -> f64 {
        tri_energy(t.map(|i| self.pts[i as usize]), &self.tri_metric(t))
    }

    /// Interior, unlocked edges `(a, b)` with `a < b` and their metric lengths, filtered by
    /// `keep(len)`, sorted by `order` of length then by key (deterministic).
    pub(super) fn edges_where(
        &self,
        keep: impl Fn(f64) -> bool,
        longest_first: bool,
    ) -> Vec<(f64, u32, u32)> {
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

    pub(super) fn clear_touched(&mut self) {
        self.touched.iter_mut().for_each(|t| *t = false);
    }

    /// The metric area of the triangulation, `Σ |T|·√det M_T`.
    pub(super) fn metric_area(&self) -> f64 {
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
    pub(super) fn vertex_count(&self) -> usize {
        self.valive.iter().filter(|a| **a).count()
    }

    /// The compacted mesh.
    pub(super) fn finish(self) -> PlanarMesh {
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
