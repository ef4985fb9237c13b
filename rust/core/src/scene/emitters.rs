//! Emissive faces as area lights. An Emission material on a panel, a screen or a neon strip
//! lights the scene as Cycles shows it only if the direct stage knows it: then its shadows
//! are sharp and discontinuity-meshed like an area light's, and it lights the scene with
//! indirect light turned off. Each emitting face (a convex piece of its polygon) becomes one
//! area light of the face's radiance, and a second one facing the other way when the face
//! is a thin surface, because Cycles emits from both sides of a mesh; a face of a closed
//! solid only sends its back light into the solid, where nothing receives it.
//!
//! The faces stay faces: they receive, reflect and occlude as before; the indirect stage
//! leaves out the emission that these lights already deliver (`Light::from_face`).

use super::solids::Occluder;
use super::{Face, Light, LightKind, MeshInfo};
use crate::geom::Plane;

/// Emissive faces past this count stay indirect-only emitters (one warning): every light
/// costs a shadow pass over all receivers, so a mesh with thousands of glowing faces would
/// cost thousands of passes.
pub const MAX_EMITTER_LIGHTS: usize = 256;

/// The area lights standing for the emissive faces, indexed from `first_index` on.
pub fn emitter_lights(
    meshes: &[MeshInfo],
    faces: &[Face],
    face_occluder: &[u32],
    occluders: &[Occluder],
    first_index: usize,
    warnings: &mut Vec<String>,
) -> Vec<Light> {
    let emitting: Vec<usize> = (0..faces.len())
        .filter(|&f| faces[f].emission.max_element() > 0.0)
        .collect();
    if emitting.len() > MAX_EMITTER_LIGHTS {
        warnings.push(format!(
            "{} emissive faces: only the first {MAX_EMITTER_LIGHTS} light the scene directly \
             (with sharp shadows); the rest emit through indirect light only",
            emitting.len()
        ));
    }
    let mut lights = Vec::new();
    for &f in emitting.iter().take(MAX_EMITTER_LIGHTS) {
        let face = &faces[f];
        let mesh = &meshes[face.mesh as usize].name;
        let name = format!("{mesh} polygon {} (emission)", face.source_polygon);
        lights.push(Light {
            name: name.clone(),
            index: first_index + lights.len(),
            kind: LightKind::Area {
                verts: face.verts.clone(),
                plane: face.plane,
                radiance: face.emission,
            },
            from_face: Some(f as u32),
        });
        let thin = matches!(occluders[face_occluder[f] as usize], Occluder::Face(_));
        if thin {
            let verts: Vec<_> = face.verts.iter().rev().copied().collect();
            lights.push(Light {
                name: format!("{name} back"),
                index: first_index + lights.len(),
                kind: LightKind::Area {
                    verts,
                    plane: Plane {
                        n: -face.plane.n,
                        d: -face.plane.d,
                    },
                    radiance: face.emission,
                },
                from_face: Some(f as u32),
            });
        }
    }
    lights
}
