//! Light from a uniform world around the scene (Blender's Background colour × strength):
//! at each element vertex, the world's radiance times the cosine-weighted part of the
//! hemisphere that no face hides, `E = π·L·(1 − occlusion)`: ambient occlusion times the
//! world. It joins the direct irradiance, so the indirect stage bounces it like any light.
//!
//! The directions are one fixed cosine-weighted set (a Hammersley set mapped onto the
//! hemisphere), the same at every vertex: neighbouring vertices see the same directions, so
//! the result is smooth and repeats bit for bit, and a vertex that nothing hides gets
//! exactly `π·L` (an open floor is `albedo · L`, as in Cycles).

use std::f64::consts::PI;

use glam::DVec3;
use rayon::prelude::*;

use crate::geom::raycast::Occluders;
use crate::mesh::elements::Elements;
use crate::progress::Progress;
use crate::BakeError;

/// Directions per vertex for `visibility_rays` = 1; the setting scales it (16 → 64).
const RAYS_PER_SETTING: u32 = 4;
/// At most this many directions per vertex, whatever the setting.
const MAX_RAYS: u32 = 1024;

/// World irradiance at every element vertex for world radiance `world`.
pub fn world_irradiance(
    world: DVec3,
    el: &Elements,
    occ: &Occluders,
    visibility_rays: u32,
    progress: &Progress,
) -> Result<Vec<DVec3>, BakeError> {
    let dirs = directions(visibility_rays);
    let nv = el.positions.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let out: Vec<DVec3> = (0..nv)
        .into_par_iter()
        .map(|v| {
            let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            if k % 1024 == 0 {
                progress.set_fraction(k as f64 / nv.max(1) as f64);
            }
            if progress.is_cancelled() {
                return DVec3::ZERO;
            }
            let p = el.eval.get(v).copied().unwrap_or(el.positions[v]);
            world_at(world, p, el.normals[v], &dirs, occ)
        })
        .collect();
    progress.check()?;
    Ok(out)
}

/// The directions `world_at` takes for the `visibility_rays` setting.
pub(crate) fn directions(visibility_rays: u32) -> Vec<DVec3> {
    cosine_directions((visibility_rays.saturating_mul(RAYS_PER_SETTING)).clamp(1, MAX_RAYS))
}

/// World irradiance at `p` (unit normal `n`): `dirs` (from `directions`) turned about `n`.
pub(crate) fn world_at(world: DVec3, p: DVec3, n: DVec3, dirs: &[DVec3], occ: &Occluders) -> DVec3 {
    let (t, b, nrm) = basis(n);
    let open = dirs
        .iter()
        .filter(|d| !occ.ray_blocked(p, t * d.x + b * d.y + nrm * d.z))
        .count();
    world * (PI * open as f64 / dirs.len().max(1) as f64)
}

/// `n` unit directions about +Z, cosine-weighted: Hammersley points on the unit square
/// mapped to the disc (area-preserving) and lifted onto the hemisphere (Malley's method).
fn cosine_directions(n: u32) -> Vec<DVec3> {
    (0..n)
        .map(|i| {
            let u = (i as f64 + 0.5) / n as f64;
            let w = radical_inverse(i);
            let r = u.sqrt();
            let phi = 2.0 * PI * w;
            DVec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u).max(0.0).sqrt())
        })
        .collect()
}

/// Van der Corput's sequence in base 2.
fn radical_inverse(i: u32) -> f64 {
    i.reverse_bits() as f64 / 4_294_967_296.0
}

/// An orthonormal frame `(t, b, n)` around the unit normal `n` (Duff et al. 2017).
fn basis(n: DVec3) -> (DVec3, DVec3, DVec3) {
    let s = 1f64.copysign(n.z);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
        DVec3::new(b, s + n.y * n.y * a, -n.y),
        n,
    )
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn directions_are_cosine_weighted_and_the_frame_orthonormal() {
        let d = cosine_directions(4096);
        // E[cos θ] under a cosine-weighted density is 2/3; all unit and above the horizon.
        let mean_cos = d.iter().map(|x| x.z).sum::<f64>() / d.len() as f64;
        assert!((mean_cos - 2.0 / 3.0).abs() < 1e-3, "{mean_cos}");
        assert!(d
            .iter()
            .all(|x| (x.length() - 1.0).abs() < 1e-12 && x.z > 0.0));
        for n in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(0.3, -0.4, 0.5).normalize(),
            DVec3::X,
        ] {
            let (t, b, m) = basis(n);
            assert!(t.dot(b).abs() < 1e-12 && t.dot(m).abs() < 1e-12 && b.dot(m).abs() < 1e-12);
            assert!((t.cross(b) - m).length() < 1e-12);
        }
    }
}
