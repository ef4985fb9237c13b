//! Light relations of regions (paper 2.4, Table 1). The paper packs them 2 bits a light; a
//! region here holds one byte a light (`Vec<Relation>`): regions are few next to elements
//! (N_f2 is 0.1–5 % of N_e on the built-in scenes), so packing would save under a byte per
//! element and cost a shift at every read.

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
