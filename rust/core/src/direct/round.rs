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

use super::exact::area_light;
use crate::regions::relation::Relation;
use crate::scene::disc::{unoccluded, Disc};
use crate::scene::settings::PenumbraVisibility;
use crate::scene::LightKind;

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

#[cfg(test)]
mod test;
