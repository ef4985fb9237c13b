//! What one receiver vertex gets from a shot: the exact point-to-polygon form factor times
//! the visible fraction of the patch.

use std::f64::consts::PI;

use glam::DVec3;

use super::pair::{Blockers, Pair};
use super::shooter::{Group, Shooter};
use super::{FEW_RAYS_BELOW, MAX_LISTED_OCCLUDERS, ONE_RAY_BELOW};
use crate::geom::Plane;
use crate::indirect::patches::Patch;

impl Shooter<'_> {
    /// Everything the shots sent to vertex `v`, computed there alone (`shot_all`: the
    /// radiosity each patch shot over the whole bake): for a vertex whose interpolated
    /// value is unsure.
    pub(super) fn gathered(&self, v: u32, shot_all: &[DVec3]) -> DVec3 {
        let f = self.el.vertex_face[v as usize];
        let x = self.points[v as usize];
        let group = Group {
            start: 0,
            end: 0,
            lo: x,
            hi: x,
        };
        let mut sum = DVec3::ZERO;
        for (patch, &b) in self.patches.iter().zip(shot_all) {
            if b == DVec3::ZERO {
                continue;
            }
            let plane = patch.plane;
            let known = self.face_blockers(patch.face, patch.back);
            let Some(pair) = self.pair(&patch.poly, patch.face, &plane, f, known) else {
                continue;
            };
            let blockers = if self.one_ray(patch, &pair, &group) {
                Blockers::Any
            } else {
                self.blockers(patch.face, &patch.poly, &plane, &pair, &group)
            };
            sum += b * self.receive(patch, &plane, &pair, &blockers, v, b);
        }
        sum
    }

    /// Form factor from vertex `v` to the shooter times the fraction of it in view: the
    /// vertex gets `b` times this. (`b` only decides how hard to look.)
    pub(super) fn receive(
        &self,
        patch: &Patch,
        plane: &Plane,
        pair: &Pair,
        blockers: &Blockers,
        v: u32,
        b: DVec3,
    ) -> f64 {
        let (x, n) = (self.points[v as usize], self.el.normals[v as usize]);
        self.receive_at(patch, plane, pair, blockers, x, n, b)
    }

    /// `receive` at any point `x` with unit normal `n` on the receiving side of `pair`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn receive_at(
        &self,
        patch: &Patch,
        plane: &Plane,
        pair: &Pair,
        blockers: &Blockers,
        x: DVec3,
        n: DVec3,
        b: DVec3,
    ) -> f64 {
        if plane.dist(x) <= self.tol {
            return 0.0;
        }
        let ff = form_factor(x, n, &pair.poly);
        if !(ff > 0.0) {
            return 0.0;
        }
        let e = b * ff;
        // Of a listed blocker's plane, the vertex must lie on the other side from part of
        // the patch for any ray to cross it; the others are left out for this vertex, and
        // with none left the patch is in full view.
        let mut near = [(0u32, 0.0f64); MAX_LISTED_OCCLUDERS];
        let mut n_near = 0;
        if let Blockers::Listed(list) = blockers {
            let tol = self.occ.tolerance();
            for &(o, lo, hi) in list {
                let da = self.occ.plane_dist(o, x);
                if (da > tol && lo < -tol) || (da < -tol && hi > tol) {
                    near[n_near] = (o, da);
                    n_near += 1;
                }
            }
        }
        let near = &near[..n_near];
        let vis = match blockers {
            Blockers::None => 1.0,
            Blockers::Listed(_) if near.is_empty() => 1.0,
            blockers => {
                let size = patch.radius / (patch.centroid - x).length();
                let level = if e.max_element() < self.negligible || size < ONE_RAY_BELOW {
                    0
                } else if size < FEW_RAYS_BELOW {
                    1
                } else {
                    2
                };
                let skip = [patch.face, pair.face];
                let blocked = |s: DVec3| match blockers {
                    Blockers::Listed(_) => self.occ.segment_blocked_from(x, s, near),
                    _ => self.occ.segment_blocked_skip(x, s, &skip),
                };
                // Each ray counts by its own point-to-point form factor, cosθ·cosθ'/r², not
                // one each (Wallace, Elmquist & Haines 1989): with the near half of a patch
                // hidden, an unweighted count would keep twice too much light.
                let np = plane.n;
                let (mut seen, mut total) = (0.0, 0.0);
                for &s in &patch.samples[level] {
                    let d = s - x;
                    let w = n.dot(d) * -np.dot(d) / d.length_squared().powi(2);
                    if w > 0.0 {
                        total += w;
                        if !blocked(s) {
                            seen += w;
                        }
                    }
                }
                if !(total > 0.0) {
                    (!blocked(pair.inner)) as u8 as f64
                } else {
                    seen / total
                }
            }
        };
        ff * vis
    }
}

/// Irradiance at `x` (unit normal `n`) from a polygon of unit radiance, over π: the
/// point-to-polygon form factor by Lambert's formula, ½·Σ θ_k (n·Γ_k) / π, with θ_k the
/// angle the k-th edge subtends at `x` and Γ_k the unit normal of the plane through `x`
/// and that edge. The polygon must run counter-clockwise seen from its front, with `x` in
/// front of it and the polygon in front of `x` (clip it to `x`'s tangent plane first).
pub(super) fn form_factor(x: DVec3, n: DVec3, poly: &[DVec3]) -> f64 {
    let mut s = 0.0;
    let Some(last) = poly.last() else { return 0.0 };
    let mut a = *last - x;
    for q in poly {
        let b = *q - x;
        let c = a.cross(b);
        let l = c.length();
        // θ from atan2 stays accurate for edges seen nearly end-on, where acos of the
        // normalised dot product loses all its digits.
        if l > 0.0 {
            s += l.atan2(a.dot(b)) * n.dot(c) / l;
        }
        a = b;
    }
    // Seen from its front the polygon runs clockwise, so each n·Γ_k is negative.
    (-s / (2.0 * PI)).max(0.0)
}
