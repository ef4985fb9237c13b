//! What the shadow stage leaves on one receiver: shadow polygons per (light, occluder),
//! contact lines, plane cuts, the parts inside solids and the critical lines. The region
//! stage reads these and nothing else of the shadow stage.

use glam::DVec2;

/// `occluder` value of the polygon that marks the part of a receiver behind an area light's
/// plane (the light emits nothing there).
pub const BEHIND_LIGHT: u32 = u32::MAX;

/// A shadow volume cut down to one receiver.
#[derive(Debug, Clone, PartialEq)]
pub struct ShadowPolygon {
    pub light: u32,
    pub occluder: u32,
    pub umbra: bool,
    /// From a point or sun light: its boundary is a D0 discontinuity.
    pub hard: bool,
    /// Convex, counter-clockwise, in the receiver's frame.
    pub poly: Vec<DVec2>,
}

/// How one light stands to one receiver as a whole.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exposure {
    /// The light cannot reach the receiver's front anywhere.
    Hidden,
    /// Regions decide (shadow polygons).
    Regions,
}

/// Everything the later stages need about the shadows on one receiver.
#[derive(Debug, Clone)]
pub struct ReceiverShadows {
    pub face: u32,
    pub exposure: Vec<Exposure>,
    pub polys: Vec<ShadowPolygon>,
    /// Occluder edges lying on the receiver (contact lines), in its frame: light jumps
    /// across them (D0), so the mesh must not share vertices there.
    pub contacts: Vec<[DVec2; 2]>,
    /// Lines where an occluder face passes through the receiver (`cuts::plane_cut`), in its
    /// frame: D0 like contacts, and the arrangement must split along them.
    pub plane_cuts: Vec<[DVec2; 2]>,
    /// The parts of the receiver inside closed solids (convex, counter-clockwise, in its
    /// frame): no light reaches them.
    pub inside: Vec<Vec<DVec2>>,
    /// VE/EV critical lines inside penumbrae (light index, segment), see `events`.
    pub events: Vec<(u32, [DVec2; 2])>,
    /// Outlines of the parts across a narrow gap from another face (`gaps`), in its frame:
    /// region boundaries for bounced light, not discontinuities.
    pub gaps: Vec<[DVec2; 2]>,
    /// The parts those outlines bound (convex, counter-clockwise), each with the gap's width
    /// (how far the facing face's farthest corner lies from the receiver's plane): their
    /// elements are told apart (`Region::gap`), sized and grouped into leaves by that
    /// width, and refinement gives them links of their own.
    pub gap_parts: Vec<(Vec<DVec2>, f64)>,
}
