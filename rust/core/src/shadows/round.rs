//! Round lights in the shadow stage: each occluder casts the shadow of its own proxy disc
//! (`scene::disc::proxy`), an area light whose penumbra holds the round light's and whose
//! umbra lies in it, so a round light's penumbrae are meshed like an area light's. The sun's
//! proxy is one disc for all occluders.

use glam::{DVec2, DVec3};

use crate::geom::{Frame, Plane};
use crate::scene::disc::{is_round, polygon_distance, proxy, Proxy};
use crate::scene::solids::Occluder;
use crate::scene::{LightKind, Scene};

/// What stands in for a round light in one occluder's shadow.
#[derive(Debug, Clone, PartialEq)]
pub enum Stand {
    /// The proxy disc as an area light: penumbra and umbra.
    Disc(LightKind),
    /// An occluder too large seen from the light for a disc (a wall around it), but outside
    /// the cube around the light's ball: a segment from a point outside the cube to the ball
    /// enters the cube through a face the point is in front of, and meets the occluder before
    /// it. So the penumbrae of the cube's six faces (area lights facing out) hold the light's
    /// penumbra; no umbra is claimed.
    Cube(Vec<LightKind>),
    /// Nearer the light than the cube's corners: it may shadow anything in front of it.
    Everywhere,
}

/// Per occluder, what stands in for a round light (a sun's one disc is shared by all).
pub enum Proxies {
    Shared(Stand),
    PerOccluder(Vec<Stand>),
}

impl Proxies {
    /// `None` for a light that is not round.
    pub fn new(scene: &Scene, kind: &LightKind, outlines: &[Vec<DVec3>]) -> Option<Self> {
        if !is_round(kind) {
            return None;
        }
        let centre = 0.5 * (scene.bounds_min + scene.bounds_max);
        let diag = scene.diagonal();
        if let LightKind::Sun { .. } = kind {
            return Some(Proxies::Shared(match proxy(kind, &[], 0.0, centre, diag) {
                Proxy::Disc(d) => Stand::Disc(d.area_light()),
                Proxy::Everywhere => Stand::Everywhere,
            }));
        }
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
                match (proxy(kind, verts, near, centre, diag), kind) {
                    (Proxy::Disc(d), _) => Stand::Disc(d.area_light()),
                    (
                        Proxy::Everywhere,
                        LightKind::Point {
                            position, radius, ..
                        },
                    ) if near > radius * 3f64.sqrt() * (1.0 + 1e-6) => {
                        Stand::Cube(cube_faces(*position, *radius))
                    }
                    (Proxy::Everywhere, _) => Stand::Everywhere,
                }
            })
            .collect();
        Some(Proxies::PerOccluder(per))
    }

    pub fn get(&self, oi: u32) -> &Stand {
        match self {
            Proxies::Shared(s) => s,
            Proxies::PerOccluder(v) => &v[oi as usize],
        }
    }
}

/// The six faces of the cube of half-side `r` around `c`, as area lights facing out.
fn cube_faces(c: DVec3, r: f64) -> Vec<LightKind> {
    [
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        -DVec3::X,
        -DVec3::Y,
        -DVec3::Z,
    ]
    .iter()
    .map(|&n| {
        let f = Frame::new(c + n * r, n);
        let verts: Vec<DVec3> = [(-r, -r), (r, -r), (r, r), (-r, r)]
            .iter()
            .map(|&(u, v)| f.to_3d(DVec2::new(u, v)))
            .collect();
        LightKind::Area {
            plane: Plane::from_point_normal(c + n * r, n),
            verts,
            radiance: DVec3::ZERO,
        }
    })
    .collect()
}
