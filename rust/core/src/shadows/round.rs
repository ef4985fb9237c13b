//! Round lights in the shadow stage: each occluder casts the shadow of its own proxy disc
//! (`scene::disc::proxy`), an area light whose penumbra holds the round light's and whose
//! umbra lies in it, so a round light's penumbrae are meshed like an area light's. The sun's
//! proxy is one disc for all occluders.

use glam::DVec3;

use crate::scene::disc::{is_round, polygon_distance, proxy, Proxy};
use crate::scene::solids::Occluder;
use crate::scene::{LightKind, Scene};

/// Per occluder, what stands in for a round light: `Some(area light)` or `None` (the
/// occluder may shadow anything in front of the light).
pub struct Proxies(Vec<Option<LightKind>>);

impl Proxies {
    /// `None` for a light that is not round.
    pub fn new(scene: &Scene, kind: &LightKind, outlines: &[Vec<DVec3>]) -> Option<Self> {
        if !is_round(kind) {
            return None;
        }
        let centre = 0.5 * (scene.bounds_min + scene.bounds_max);
        let diag = scene.diagonal();
        let nearest = |occ: &Occluder, c: DVec3| {
            occ.faces()
                .iter()
                .map(|&f| polygon_distance(c, &scene.faces[f as usize].verts))
                .fold(f64::INFINITY, f64::min)
        };
        let per = scene
            .occluders
            .iter()
            .zip(outlines)
            .map(|(o, verts)| {
                let near = match kind {
                    LightKind::Point { position, .. } => nearest(o, *position),
                    _ => f64::INFINITY,
                };
                match proxy(kind, verts, near, centre, diag) {
                    Proxy::Disc(d) => Some(d.area_light()),
                    Proxy::Everywhere => None,
                }
            })
            .collect();
        Some(Proxies(per))
    }

    pub fn get(&self, oi: u32) -> Option<&LightKind> {
        self.0[oi as usize].as_ref()
    }
}
