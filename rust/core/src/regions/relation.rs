//! Light relations of regions (paper 2.4, Table 1): 2 bits a light.

/// How a region sees one light.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
#[repr(u8)]
pub enum Relation {
    /// Not processed yet (only transiently).
    #[default]
    Unprocessed = 0,
    /// The whole light is visible from every point.
    Lit = 1,
    /// Part of the light may be hidden.
    Penumbra = 2,
    /// No part of the light is visible from any point.
    Umbra = 3,
}

impl Relation {
    pub fn code(self) -> u8 {
        self as u8
    }
    pub fn from_code(c: u8) -> Self {
        match c & 3 {
            1 => Relation::Lit,
            2 => Relation::Penumbra,
            3 => Relation::Umbra,
            _ => Relation::Unprocessed,
        }
    }
}

/// Relations of one region to any number of lights, packed 2 bits a light as in the paper's
/// Table 1 (16 lights in 4 bytes).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct RelationSet {
    bits: Vec<u64>,
    n: usize,
}

impl RelationSet {
    pub fn new(n_lights: usize) -> Self {
        RelationSet {
            bits: vec![0; n_lights.div_ceil(32)],
            n: n_lights,
        }
    }
    pub fn len(&self) -> usize {
        self.n
    }
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }
    pub fn get(&self, light: usize) -> Relation {
        Relation::from_code((self.bits[light / 32] >> (2 * (light % 32))) as u8)
    }
    pub fn set(&mut self, light: usize, r: Relation) {
        let w = &mut self.bits[light / 32];
        let s = 2 * (light % 32);
        *w = (*w & !(3u64 << s)) | ((r.code() as u64) << s);
    }
    /// Memory the packed codes take, in bytes.
    pub fn packed_bytes(&self) -> usize {
        self.n.div_ceil(4)
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn packs_two_bits_per_light_across_words() {
        let mut s = RelationSet::new(70);
        for i in 0..70 {
            s.set(i, Relation::from_code((i % 3 + 1) as u8));
        }
        s.set(33, Relation::Umbra);
        for i in 0..70 {
            let want = if i == 33 {
                Relation::Umbra
            } else {
                Relation::from_code((i % 3 + 1) as u8)
            };
            assert_eq!(s.get(i), want);
        }
        assert_eq!(RelationSet::new(16).packed_bytes(), 4);
    }
}
