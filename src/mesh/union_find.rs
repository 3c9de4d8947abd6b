//! Disjoint sets over `0..n`, for the components and fans of the topology and the
//! certificates.

/// Disjoint sets over `0..n` with path halving. The smaller root wins a union, so the roots
/// (and any labels derived from them) do not depend on the order of the unions.
#[derive(Clone, Debug, Default)]
pub struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    /// `n` singletons.
    pub fn new(n: usize) -> UnionFind {
        let mut u = UnionFind::default();
        u.reset(n);
        u
    }

    /// Back to `n` singletons, reusing the storage.
    pub fn reset(&mut self, n: usize) {
        self.parent.clear();
        self.parent.extend(0..n as u32);
    }

    /// The root of `x`'s set.
    pub fn find(&mut self, x: usize) -> usize {
        let mut x = x as u32;
        while self.parent[x as usize] != x {
            let p = self.parent[x as usize];
            self.parent[x as usize] = self.parent[p as usize];
            x = p;
        }
        x as usize
    }

    /// Join the sets of `a` and `b`.
    pub fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.parent[hi] = lo as u32;
        }
    }

    /// The number of sets.
    pub fn count(&mut self) -> usize {
        (0..self.parent.len())
            .filter(|&i| self.find(i) == i)
            .count()
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn unions_join_and_the_smallest_root_wins() {
        let mut u = super::UnionFind::new(6);
        assert_eq!(u.count(), 6);
        u.union(4, 2);
        u.union(5, 4);
        u.union(1, 0);
        assert_eq!(u.count(), 3);
        assert_eq!(u.find(5), 2);
        assert_eq!(u.find(1), 0);
        assert_ne!(u.find(3), u.find(2));
        u.reset(2);
        assert_eq!(u.count(), 2);
    }
}
