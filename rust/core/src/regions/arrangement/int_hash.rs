//! A hash for the arrangement's integer keys (grid cells, vertex pairs).
//!
//! std's SipHash resists keys chosen to collide, which nothing here needs, and costs
//! several times a multiply–rotate hash on a pair of integers: on quads2000's floor (300k
//! crossing points snapped through a hash grid, 400k edges merged by vertex pair) it was
//! a fifth of the arrangement's time.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// The multiply–rotate hash of rustc's `FxHasher`: each integer written is folded in by a
/// rotate, an xor and a multiply by a large odd constant.
#[derive(Default, Clone, Copy)]
pub(super) struct IntHasher(u64);

const K: u64 = 0x517c_c1b7_2722_0a95;

impl IntHasher {
    #[inline]
    fn add(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(K);
    }
}

impl Hasher for IntHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.add(b as u64);
        }
    }
    #[inline]
    fn write_u32(&mut self, x: u32) {
        self.add(x as u64);
    }
    #[inline]
    fn write_u64(&mut self, x: u64) {
        self.add(x);
    }
    #[inline]
    fn write_i64(&mut self, x: i64) {
        self.add(x as u64);
    }
    #[inline]
    fn write_usize(&mut self, x: usize) {
        self.add(x as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

/// A `HashMap` keyed by integers (or tuples of them) through [`IntHasher`].
pub(super) type IntMap<K, V> = HashMap<K, V, BuildHasherDefault<IntHasher>>;

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn neighbouring_cells_spread_over_the_table() {
        // Grid keys differ by one in a coordinate; their hashes must differ in the bits a
        // table uses (the low ones for the bucket, the top seven for the control byte).
        let h = |k: (i64, i64)| {
            let mut s = IntHasher::default();
            std::hash::Hash::hash(&k, &mut s);
            s.finish()
        };
        let mut low = std::collections::HashSet::new();
        let mut top = std::collections::HashSet::new();
        for i in -8..8 {
            for j in -8..8 {
                low.insert(h((i, j)) & 0xff);
                top.insert(h((i, j)) >> 57);
            }
        }
        assert!(low.len() > 150, "{} of 256 low bytes", low.len());
        assert!(top.len() > 100, "{} of 128 top values", top.len());
    }

    #[test]
    fn a_map_finds_what_it_holds() {
        let mut m: IntMap<(u32, u32), usize> = IntMap::default();
        for i in 0..1000u32 {
            m.insert((i, i * 7 + 1), i as usize);
        }
        assert!((0..1000u32).all(|i| m[&(i, i * 7 + 1)] == i as usize));
        assert!(!m.contains_key(&(1, 1)));
    }
}
