//! Deterministic scatter for sample points: the same points for any thread count, and no
//! lattice that falls in step with a regular blocker.

/// SplitMix64's finaliser: a cheap, well-spread 64-bit hash.
pub fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The top 53 bits of `h` as a number in [0, 1).
pub fn unit(h: u64) -> f64 {
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// A hasher for the maps the bake builds and queries by the hundred thousand, keyed by ids
/// (`subdivide`'s edges and midpoints) or by the bits of coordinates (the light cache of
/// `mesh::refine`): the standard library's keyed SipHash costs several times as much per
/// small key (it was a sixth of a direct-only bake of data1, `perf`) and guards against
/// adversarial keys that ids and coordinates cannot be. Its iteration order is also the same
/// from run to run.
#[derive(Clone, Copy, Default)]
pub struct IdHasher(u64);

impl std::hash::Hasher for IdHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut b = [0u8; 8];
            b[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(b));
        }
    }

    fn write_u32(&mut self, x: u32) {
        self.write_u64(x as u64);
    }

    fn write_u64(&mut self, x: u64) {
        // One multiply-rotate step per word (as rustc's FxHasher), and `mix` at the end, so
        // that the low bits a table's bucket takes depend on every bit of the key.
        self.0 = (self.0.rotate_left(29) ^ x).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }

    fn write_i64(&mut self, x: i64) {
        self.write_u64(x as u64);
    }

    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }

    fn finish(&self) -> u64 {
        mix(self.0)
    }
}

/// `HashMap` with `IdHasher`.
pub type IdMap<K, V> = std::collections::HashMap<K, V, std::hash::BuildHasherDefault<IdHasher>>;
/// `HashSet` with `IdHasher`.
pub type IdSet<K> = std::collections::HashSet<K, std::hash::BuildHasherDefault<IdHasher>>;

#[cfg(test)]
mod test {
    use super::*;
    use std::hash::{BuildHasher, BuildHasherDefault};

    #[test]
    fn id_pairs_spread_over_the_buckets() {
        // Edge keys of a grid mesh: pairs of nearby ids. The low bits (a table's bucket)
        // of their hashes must not pile up.
        let b = BuildHasherDefault::<IdHasher>::default();
        let mut buckets = vec![0u32; 1024];
        let mut n = 0;
        for a in 0..2000u32 {
            for d in [1u32, 2, 45] {
                buckets[(b.hash_one((a, a + d)) & 1023) as usize] += 1;
                n += 1;
            }
        }
        // Keys thrown at random would fill the fullest of 1024 buckets to about 2.4 × the
        // mean here (Poisson, mean 5.9); keys that piled up would fill it far more.
        let mean = n as f64 / 1024.0;
        let worst = *buckets.iter().max().unwrap() as f64;
        assert!(worst < 3.0 * mean, "{worst} against a mean of {mean}");
        // And a map keyed by them finds what it holds.
        let mut m: IdMap<(u32, u32), u32> = IdMap::default();
        for a in 0..1000u32 {
            m.insert((a, a + 1), a);
        }
        assert!((0..1000u32).all(|a| m[&(a, a + 1)] == a));
        assert!(!m.contains_key(&(1, 0)));
    }
}
