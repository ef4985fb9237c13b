//! A spot's cone edge on a receiver: the lines where the cone meets the receiver's plane
//! (conics), as polylines of [`CONE_SIDES`] chords, handed on as discontinuity edges of the
//! spot's light so that the element size does not blur the edge.
//!
//! Cycles' cone mask (`direct::exact::spot_mask`) is a smoothstep in the cosine across the
//! band from the cone's half-angle to the blend's inner angle: with blend > 0 the light has a
//! kink (D2, with a jump in curvature) on both band edges, and both conics are meshed. With
//! blend = 0 the edge is a jump (D0): two conics a hair inside and outside the edge, a
//! quarter of the penumbra element size apart on the receiver, confine the jump to that band
//! (every element beside it has all its vertices on one side).

use glam::{DVec2, DVec3};

use crate::geom::polygon::clip_segment_convex;
use crate::geom::Frame;
use crate::scene::{Face, Spot};

/// Chords per conic: the polyline is within 1 − cos(π/256) ≈ 7.5e-5 of the conic's size.
pub const CONE_SIDES: usize = 256;

/// The cone-edge segments of a spot at `apex` on receiver `r` (2-D, in `r`'s frame), `band`
/// the width of the band standing for a hard edge. A spot of `radius` > 0 (a disc, whose mask
/// is averaged over the disc: `direct::round::spot_over_disc`) gets the conics bounding the
/// blurred band instead.
pub fn cone_edges(
    apex: DVec3,
    spot: &Spot,
    radius: f64,
    r: &Face,
    band: f64,
    out: &mut Vec<[DVec2; 2]>,
) {
    let h = r.plane.dist(apex);
    if !(h > 0.0) {
        return;
    }
    let outer = spot.cos_half_angle.clamp(-1.0, 1.0).acos();
    let angles: Vec<f64> = if radius > 0.0 {
        // A round spot: the disc blurs the mask over its own angular size, largest at the
        // receiver's point nearest the light; the light is smooth between these two.
        let a = (radius / h).atan();
        let inner = spot.cos_half_angle + (1.0 - spot.cos_half_angle) * spot.blend;
        vec![inner.clamp(-1.0, 1.0).acos() - a, outer + a]
    } else if spot.blend > 0.0 {
        let inner = spot.cos_half_angle + (1.0 - spot.cos_half_angle) * spot.blend;
        vec![outer, inner.clamp(-1.0, 1.0).acos()]
    } else {
        // A band a hundredth of an element wide where the cone meets the plane square on; wider at a
        // slant, where the same angle spans more of the plane.
        let d = (0.01 * band / h).min(0.1 * outer);
        vec![outer - d, outer + d]
    };
    let f = Frame::new(apex, spot.direction);
    for psi in angles {
        if !(psi > 0.0 && psi < std::f64::consts::PI) {
            continue;
        }
        let (s, c) = psi.sin_cos();
        let hit = |k: usize| {
            let phi = std::f64::consts::TAU * k as f64 / CONE_SIDES as f64;
            let w = f.n * c + (f.u * phi.cos() + f.v * phi.sin()) * s;
            let den = -r.plane.n.dot(w);
            (den > 1e-9).then(|| r.frame.to_2d(apex + w * (h / den)))
        };
        let mut prev = hit(0);
        for k in 1..=CONE_SIDES {
            let next = hit(k % CONE_SIDES);
            if let (Some(a), Some(b)) = (prev, next) {
                if let Some((t0, t1)) = clip_segment_convex(a, b, &r.poly2, 0.0, 0.0) {
                    if t1 > t0 {
                        out.push([a + (b - a) * t0, a + (b - a) * t1]);
                    }
                }
            }
            prev = next;
        }
    }
}
