//! Shared geometry: planes, 2-D frames on planes, convex polygon clipping, bounding-volume
//! queries. Geometric *decisions* that must be exact go through `robust` predicates; the
//! clipping here computes coordinates and is allowed to round.

pub mod box_grid;
pub mod bvh;
pub mod edge_soup;
pub mod frame;
pub mod hash;
pub mod lambert;
pub mod plane;
pub mod polygon;
pub mod polygon_factor;
pub mod raycast;
pub mod simplify;
pub mod union_find;

pub use frame::Frame;
pub use plane::Plane;

use glam::DVec3;

/// How far to move a point lying on a surface's edge into the surface, `l` being its distance
/// to a point well inside: far enough (`floor`, a few plane tolerances) that the point is off
/// every plane it lay in, so it takes the limit of light from inside the surface; a millionth
/// of the way otherwise, never past half of it.
pub fn hair(l: f64, floor: f64) -> f64 {
    (1e-6 * l).max(floor).min(0.5 * l)
}

/// A convex planar polygon in 3-D, as the visibility index (`raycast`) takes it.
pub trait PlanarPolygon {
    fn verts(&self) -> &[DVec3];
    fn plane(&self) -> Plane;
}
