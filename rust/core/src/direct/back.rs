//! Direct light on the back of a thin surface, at given points.
//!
//! Cycles' diffuse surfaces reflect from both sides: a single plane lit from behind sends
//! that light on into the half-space behind it (`indirect::back`). The back has no element
//! mesh and no relations (the shadow stage works on fronts), so each point asks the ray
//! index for the faces that could stand between it and each light that reaches it, and
//! takes the light's exact visible part with those as blockers (`exact`, `round`): the same
//! value a front vertex in penumbra gets. The world light is the same ambient occlusion the
//! fronts get (`world`).

use glam::DVec3;
use rayon::prelude::*;

use super::{light_irradiance, world};
use crate::geom::raycast::Occluders;
use crate::geom::Plane;
use crate::progress::Progress;
use crate::regions::relation::Relation;
use crate::scene::{LightKind, Scene};
use crate::BakeError;

/// Direct irradiance (lights and world) at each point `points[i]` on the back of face
/// `faces[i]` (whose back normal is the face's normal turned round).
pub(crate) fn back_irradiance(
    scene: &Scene,
    occ: &Occluders,
    points: &[DVec3],
    faces: &[u32],
    progress: &Progress,
) -> Result<Vec<DVec3>, BakeError> {
    let world = scene.settings.world;
    let dirs = if world != DVec3::ZERO {
        world::directions(scene.settings.visibility_rays)
    } else {
        Vec::new()
    };
    let out: Vec<DVec3> = points
        .par_iter()
        .zip(faces)
        .with_min_len(16)
        .map(|(&p, &f)| {
            if progress.is_cancelled() {
                return DVec3::ZERO;
            }
            let back = scene.faces[f as usize].plane.flipped();
            let mut e = lights_at(scene, occ, p, f, &back);
            if !dirs.is_empty() {
                e += world::world_at(world, p, back.n, &dirs, occ);
            }
            e
        })
        .collect();
    progress.check()?;
    Ok(out)
}

/// Light from every light at `p` on face `f`, facing along `back.n`.
fn lights_at(scene: &Scene, occ: &Occluders, p: DVec3, f: u32, back: &Plane) -> DVec3 {
    let n = back.n;
    let mut e = DVec3::ZERO;
    let mut list: Vec<u32> = Vec::new();
    for light in &scene.lights {
        // The face's own emission is not light falling on it.
        if light.from_face == Some(f) {
            continue;
        }
        let disc = crate::scene::disc::facing(&light.kind, p, 2.0 * scene.diagonal());
        let disc = disc.as_ref();
        let open = light_irradiance(scene, light, p, p, n, Relation::Lit, &[], &[], disc);
        if open == DVec3::ZERO {
            continue;
        }
        // Where the light can be: the box around it and p holds every segment between them.
        let shape: Vec<DVec3> = match (&light.kind, disc) {
            (_, Some(d)) => d.polygon(),
            (LightKind::Area { verts, .. }, None) => verts.clone(),
            (LightKind::Point { position, .. }, None) => vec![*position],
            (LightKind::Sun { direction, .. }, None) => {
                vec![p - direction.normalize_or_zero() * (2.0 * scene.diagonal())]
            }
        };
        let (lo, hi) = shape
            .iter()
            .fold((p, p), |(lo, hi), x| (lo.min(*x), hi.max(*x)));
        let mut planes = vec![*back];
        if let LightKind::Area { plane, .. } = &light.kind {
            planes.push(*plane);
        }
        list.clear();
        occ.candidates(lo, hi, &planes, &[f], &mut list);
        if list.is_empty() {
            e += open;
            continue;
        }
        let polys: Vec<&[DVec3]> = list
            .iter()
            .map(|&o| scene.faces[o as usize].verts.as_slice())
            .collect();
        e += light_irradiance(
            scene,
            light,
            p,
            p,
            n,
            Relation::Penumbra,
            &polys,
            &polys,
            disc,
        );
    }
    e
}
