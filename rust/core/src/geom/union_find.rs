//! Disjoint sets over `0..n` (union–find). The smaller index always represents its set, so
//! the result never depends on the order of the unions: a receiver corner inserted first
//! stays the representative of whatever is merged into it, and components come out
//! numbered by their first member.

#[derive(Debug, Clone, Default)]
pub struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    /// `n` singletons.
    pub fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    /// Adds singletons up to `n` elements (nothing if there are already as many).
    pub fn grow(&mut self, n: usize) {
        if self.parent.len() < n {
            let from = self.parent.len() as u32;
            self.parent.extend(from..n as u32);
        }
    }

    /// The representative of `i`, halving the path on the way. An index beyond the sets is
    /// its own singleton.
    pub fn find(&mut self, mut i: u32) -> u32 {
        while let Some(&p) = self.parent.get(i as usize) {
            if p == i {
                break;
            }
            let g = self.parent[p as usize];
            self.parent[i as usize] = g;
            i = g;
        }
        i
    }

    /// The representative of `i` without changing anything (for shared borrows).
    pub fn root(&self, mut i: u32) -> u32 {
        while let Some(&p) = self.parent.get(i as usize) {
            if p == i {
                break;
            }
            i = p;
        }
        i
    }

    /// Merges the sets of `a` and `b` (growing to hold both); true if they were apart.
    pub fn union(&mut self, a: u32, b: u32) -> bool {
        self.grow(a.max(b) as usize + 1);
        let (ra, rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        self.parent[ra.max(rb) as usize] = ra.min(rb);
        true
    }

    /// Sets that are their own representative.
    pub fn count_sets(&mut self) -> usize {
        (0..self.parent.len() as u32)
            .filter(|&i| self.find(i) == i)
            .count()
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn smallest_member_represents_whatever_the_order() {
        let mut a = UnionFind::new(6);
        a.union(5, 3);
        a.union(3, 4);
        a.union(1, 2);
        let mut b = UnionFind::new(6);
        b.union(1, 2);
        b.union(4, 5);
        b.union(5, 3);
        for i in 0..6 {
            assert_eq!(a.find(i), b.find(i));
        }
        assert_eq!(a.find(5), 3);
        assert_eq!(a.root(2), 1);
        assert_eq!(a.count_sets(), 3);
        assert!(!a.union(4, 5));
    }

    #[test]
    fn grows_on_demand() {
        let mut u = UnionFind::default();
        assert_eq!(u.root(7), 7);
        assert!(u.union(9, 2));
        assert_eq!(u.find(9), 2);
        assert_eq!(u.find(5), 5);
    }
}
