//! What the shooter and the blocker search hand each other: a receiver face in one shot
//! (`Pair`), and what could stand between it and the shooter (`Blockers`, per vertex group;
//! `FaceBlockers`, per shooter face). Kept apart from both so that `shooter` (which makes
//! shots) and `blockers` (which extends `Shooter` with the search) import it, not each other.

use glam::DVec3;

use crate::geom::Plane;

/// A receiver face and what could stand between it and a shooter face.
pub(super) type Reached = (u32, FaceBlockers);

pub(super) enum FaceBlockers {
    Listed(Vec<u32>),
    Many,
}

/// A receiver face in one shot: the shooter clipped to the receiving side's half-space, and
/// which faces could block the rays between them.
pub(super) struct Pair<'s> {
    pub(super) face: u32,
    /// The receiving side's plane: the face's, or turned round for its back.
    pub(super) plane: Plane,
    pub(super) poly: Vec<DVec3>,
    /// Bounds of `poly`.
    pub(super) lo: DVec3,
    pub(super) hi: DVec3,
    /// A point of `poly`, for when no sample of the patch lies in front of the face.
    pub(super) inner: DVec3,
    /// `None`: nothing can block. `Some(Some(list))`: only these (for the whole face).
    /// `Some(None)`: ask the BVH.
    pub(super) known: Option<Option<&'s [u32]>>,
}

pub(super) enum Blockers {
    None,
    /// Faces that could block, each with the range of the patch's distances from its
    /// plane: a vertex on the same side as all of the patch needs no ray tested against it.
    Listed(Vec<(u32, f64, f64)>),
    Any,
}
