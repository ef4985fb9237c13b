//! Every distance the pipeline treats as "the same place", in one value built once from the
//! scene's size (its bounding-box diagonal) and handed to each stage. Decisions go through
//! exact predicates (`robust`); these tolerances only absorb the rounding of *constructed*
//! points (clip points, intersections, projections), which lie within ~1e-16 of their
//! coordinates of the exact ones: each tolerance sits orders of magnitude above that and
//! orders of magnitude below any feature the mesher keeps.

use crate::scene::Face;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// The scene's diagonal, which the rest are fractions of.
    pub scene: f64,
    /// Coincidence in the shadow stage (1e-12 of the scene): a point this close to a plane is
    /// on it; a clipped polygon with less area than its square is empty.
    pub eps: f64,
    /// Contact (1e3 · eps): an occluder vertex this close to a receiver's plane touches it, so
    /// its edges there are contact lines (D0); a critical line shorter than this is none.
    pub touch: f64,
    /// A shadow edge this close to a receiver's boundary edge is that edge (1e-10 of the
    /// scene).
    pub boundary: f64,
    /// Least distance of a D0-row vertex's evaluation point from its line (1e-9 of the
    /// scene): enough for the exact side tests of the light stages to see its own side.
    pub d0_offset: f64,
    /// A tenth of `d0_offset`: whatever lies closer than this to a D0 line is on the line,
    /// not on one of its sides (the indirect stage tells the rows apart by it).
    pub d0_side: f64,
    /// Output vertices of one mesh closer than this (1e-9 of the scene) are welded.
    pub weld: f64,
    /// A triangle flatter than this (1e-12 of the scene) is dropped; a penumbra point this
    /// close to an occluder's plane is on it.
    pub flat: f64,
}

impl Tolerances {
    /// The tolerances of a scene whose bounding-box diagonal is `diag`.
    pub fn new(diag: f64) -> Self {
        let scene = diag.max(1e-300);
        let eps = 1e-12 * scene;
        Tolerances {
            scene,
            eps,
            touch: 1e3 * eps,
            boundary: 1e-10 * scene,
            d0_offset: 1e-9 * scene,
            d0_side: 1e-10 * scene,
            weld: 1e-9 * scene,
            flat: 1e-12 * scene,
        }
    }

    /// The arrangement's snapping distance on receiver `f`: 1e-9 of the face's own size, so
    /// that a small face far from a large one keeps its detail.
    pub fn snap(&self, f: &Face) -> f64 {
        1e-9 * f.extent(self.scene)
    }
}
