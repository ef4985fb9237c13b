//! Direct light from a round light (a point or spot with a radius, a sun with an angle; see
//! `scene::disc`): the disc facing the receiver point, partly hidden exactly like an area
//! light's polygon.
//!
//! Unhidden and wholly above the horizon the disc's closed form is used. In a penumbra that
//! value is scaled by the visible fraction of the disc's polygon (visible over unhidden
//! Lambert integrals), so the light is continuous where a penumbra meets a lit region and
//! the polygon's error is only that of the fraction (`scene::disc::DISC_SIDES`). A disc
//! reaching below the horizon has no closed form: the polygon's integral is the value.

use glam::DVec3;

use super::exact::{area_light, segment_blocked, spot_mask};
use crate::regions::relation::Relation;
use crate::scene::disc::{unoccluded, Disc};
use crate::scene::settings::PenumbraVisibility;
use crate::scene::{LightKind, Spot};

/// Irradiance at `p` (unit normal `n`) from round light `kind` seen through `disc` (its disc
/// facing `p`), with `blockers` the convex occluders that may hide part of it (looked at in
/// penumbra only). A spot's cone is not applied here.
#[allow(clippy::too_many_arguments)]
pub fn round_light(
    p: DVec3,
    n: DVec3,
    kind: &LightKind,
    disc: &Disc,
    relation: Relation,
    blockers: &[&[DVec3]],
    mode: PenumbraVisibility,
    samples: u32,
) -> DVec3 {
    if relation == Relation::Umbra {
        return DVec3::ZERO;
    }
    let poly = disc.polygon();
    let plane = disc.plane();
    let closed = unoccluded(kind, p, n);
    let all = |radiance| {
        area_light(
            p,
            n,
            &poly,
            &plane,
            radiance,
            Relation::Lit,
            &[],
            mode,
            samples,
        )
    };
    if relation == Relation::Lit || blockers.is_empty() {
        return closed.unwrap_or_else(|| all(disc.radiance));
    }
    let seen = area_light(
        p,
        n,
        &poly,
        &plane,
        DVec3::ONE,
        relation,
        blockers,
        mode,
        samples,
    )
    .x;
    match closed {
        Some(c) => {
            let whole = all(DVec3::ONE).x;
            if whole > 0.0 {
                c * (seen / whole).clamp(0.0, 1.0)
            } else {
                DVec3::ZERO
            }
        }
        None => disc.radiance * seen,
    }
}

/// A round spot: Cycles applies the cone mask per point `l` of the disc, for the direction
/// from `l` to the receiver point `p` (`spot_light_attenuation` of each sampled direction),
/// so the disc blurs the cone's edge over its own angular size. Where the mask is the same
/// over the whole disc it multiplies [`round_light`]; elsewhere (the blurred band) the
/// unhidden light is scaled by the integrand-weighted mean of mask × visibility over the
/// disc, by a midpoint rule over [`MASK_RINGS`] × [`MASK_SECTORS`] equal-area cells, each
/// cell's segment to `p` tested exactly against the blockers.
#[allow(clippy::too_many_arguments)]
pub fn round_spot(
    p: DVec3,
    n: DVec3,
    kind: &LightKind,
    disc: &Disc,
    spot: &Spot,
    apex: DVec3,
    relation: Relation,
    blockers: &[&[DVec3]],
    mode: PenumbraVisibility,
    samples: u32,
) -> DVec3 {
    if relation == Relation::Umbra {
        return DVec3::ZERO;
    }
    if let Some(m) = constant_mask(spot, disc, apex, p) {
        return if m > 0.0 {
            m * round_light(p, n, kind, disc, relation, blockers, mode, samples)
        } else {
            DVec3::ZERO
        };
    }
    let all = round_light(p, n, kind, disc, Relation::Lit, &[], mode, samples);
    let hide: &[&[DVec3]] = if relation == Relation::Lit {
        &[]
    } else {
        blockers
    };
    all * mask_fraction(spot, disc, p, n, hide)
}

/// Rings and sectors of the midpoint rule over the disc in [`mask_fraction`].
const MASK_RINGS: usize = 24;
const MASK_SECTORS: usize = 48;

/// The mask when it is the same over the whole disc seen from `p`: the mask falls with the
/// angle from the axis, so equal values at the directions nearest and farthest from it.
fn constant_mask(spot: &Spot, disc: &Disc, apex: DVec3, p: DVec3) -> Option<f64> {
    let to_p = p - apex;
    if !(to_p.length() > 0.0) {
        return Some(spot_mask(spot, to_p));
    }
    let centre = to_p.normalize().dot(spot.direction).clamp(-1.0, 1.0).acos();
    let alpha = (disc.radius / (p - disc.centre).length()).atan();
    let side = spot.direction.any_orthonormal_vector();
    let at = |a: f64| {
        let a = a.clamp(0.0, std::f64::consts::PI);
        spot_mask(spot, spot.direction * a.cos() + side * a.sin())
    };
    let (lo, hi) = (at(centre - alpha), at(centre + alpha));
    (lo == hi).then_some(lo)
}

/// Integrand-weighted mean over the disc of the cone mask (direction from each disc point to
/// `p`) times visibility past `blockers`.
pub fn mask_fraction(spot: &Spot, disc: &Disc, p: DVec3, n: DVec3, blockers: &[&[DVec3]]) -> f64 {
    let f = crate::geom::Frame::new(disc.centre, disc.normal);
    let (mut all, mut seen) = (0.0, 0.0);
    for i in 0..MASK_RINGS {
        let rho = disc.radius * ((i as f64 + 0.5) / MASK_RINGS as f64).sqrt();
        for j in 0..MASK_SECTORS {
            let t = std::f64::consts::TAU * (j as f64 + 0.5) / MASK_SECTORS as f64;
            let l = f.to_3d(glam::DVec2::new(rho * t.cos(), rho * t.sin()));
            let w = p - l;
            let r2 = w.length_squared();
            let wt = (-n.dot(w)).max(0.0) * disc.normal.dot(w).max(0.0) / (r2 * r2);
            if !(wt > 0.0) {
                continue;
            }
            all += wt;
            let m = spot_mask(spot, w);
            if m > 0.0 && !blockers.iter().any(|o| segment_blocked(p, l, o)) {
                seen += wt * m;
            }
        }
    }
    if all > 0.0 {
        seen / all
    } else {
        0.0
    }
}

#[cfg(test)]
mod test;
