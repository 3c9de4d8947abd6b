//! Edge length adjustment (Sec. 3.3, LCT step 1): density, split and collapse passes.

use super::work::{key, Work, DENSITY_SLACK};
use crate::predicates::{orient2d, Sign};
use nalgebra::Point2;

impl Work<'_> {
    /// Edge length adjustment, part 3 (ours): bring the vertex count to `target` (the count of
    /// an ideal mesh of the domain's metric area, see [`remesh_planar`]) by collapsing the
    /// shortest edges below L or splitting the longest above L, so that edges come out at L
    /// on average rather than wherever the split and collapse thresholds leave them.
    pub(super) fn density_pass(&mut self, target: f64) -> usize {
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
    pub(super) fn split_pass(&mut self) -> usize {
        self.split_longer_than(self.split * self.l, usize::MAX)
    }

    /// Split the (non-adjacent) interior edges longer than `thr`, longest first, at most
    /// `max` of them. Returns the number of splits.
    pub(super) fn split_longer_than(&mut self, thr: f64, max: usize) -> usize {
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
    pub(super) fn collapse_pass(&mut self) -> usize {
        self.collapse_shorter_than(self.collapse * self.l, usize::MAX)
    }

    /// Collapse interior edges shorter than `thr`, shortest first, at most `max` of them.
    pub(super) fn collapse_shorter_than(&mut self, thr: f64, max: usize) -> usize {
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
    pub(super) fn try_collapse(&mut self, a: u32, b: u32) -> bool {
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
}
