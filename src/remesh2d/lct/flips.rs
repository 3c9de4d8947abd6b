//! Connectivity update (LCT step 2): energy flips, max-min flips and valence flips.

use super::work::{key, Work};

impl Work<'_> {
    /// Connectivity update: flip interior unlocked edges of strictly convex quads (exact
    /// `orient2d`) when the LCT energy strictly decreases, until no flip applies. Each flip
    /// lowers the total energy, so this ends; a cap of 20 flips per triangle guards anyway.
    pub(super) fn flip_all(&mut self) -> usize {
        self.flip_with(false)
    }

    /// Flips as in [`Work::flip_all`]; with `maxmin`, the criterion is instead that the smaller
    /// metric quality `q` of the two triangles strictly increases (the final polish).
    pub(super) fn flip_with(&mut self, maxmin: bool) -> usize {
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
            let Some((t1, t2, c, d)) = self.flippable(a, b) else {
                continue;
            };
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
    pub(super) fn valence_flips(&mut self, guard: f64) -> usize {
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
            let Some((t1, t2, c, d)) = self.flippable(a, b) else {
                continue;
            };
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

    /// The two triangles `(a, b, c)` and `(b, a, d)` of the interior unlocked edge `(a, b)`
    /// and their apexes, when flipping it to `(c, d)` would not duplicate an edge.
    fn flippable(&self, a: u32, b: u32) -> Option<(u32, u32, u32, u32)> {
        if self.is_locked(a, b) {
            return None;
        }
        let (&t1, &t2) = (self.he.get(&key(a, b))?, self.he.get(&key(b, a))?);
        let c = self.rotated(t1, a)[2];
        let d = self.rotated(t2, b)[2];
        let exists = self.he.contains_key(&key(c, d)) || self.he.contains_key(&key(d, c));
        (c != d && !exists).then_some((t1, t2, c, d))
    }
}
