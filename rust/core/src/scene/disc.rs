//! Round lights: a point or spot light with a radius, and a sun with an angle. Cycles lights a
//! receiver point `p` from each of them through a uniform disc facing `p`:
//!
//! * a point of radius r with soft falloff (Blender's default): the disc of radius r centred
//!   on the light, facing `p`, of radiance I/(πr²); unoccluded and wholly above `p`'s horizon
//!   it gives I·cos/(d² + r²);
//! * a sphere (soft falloff off): the sphere's silhouette seen from `p`, a disc of radius
//!   r·√(1 − r²/d²) centred r²/d of the way from the centre towards `p`, of radiance I/(πr²);
//!   unoccluded and wholly above the horizon it gives I·cos/d², a point light's value;
//! * a sun of angular diameter 2h: a disc at infinity seen under half-angle h, of radiance
//!   E⊥/(π sin²h); wholly above the horizon it gives E⊥·cos.
//!
//! The direct stage takes the disc facing each vertex (`facing`), as a polygon of
//! [`DISC_SIDES`] sides, and clips it against the occluders like an area light. The shadow
//! stage cannot have a light per receiver point; it uses one disc per occluder (`proxy`),
//! large enough that from every point its shadow reaches, the cone through it holds the cone
//! through that point's own disc. Its penumbra then holds the true penumbra and its umbra lies
//! in the true umbra, so the relations stay exact (lit is lit, umbra is umbra) and only the
//! mesh edges of the penumbra sit outside the true ones, by the enlargement `proxy` states.

use glam::{DVec2, DVec3};

use super::LightKind;
use crate::geom::{Frame, Plane};

/// Sides of the polygon standing in for a disc. A regular N-gon with the disc's area differs
/// from the disc by less than the ring between the inscribed and the circumscribed N-gons,
/// N(tan π/N − sin π/N · cos π/N)/π ≤ π²/N² of its area: 0.43 % at 48. That bounds the
/// error of the visible fraction of a partly hidden disc (the unhidden value is the disc's
/// closed form), for a disc small seen from the point.
pub const DISC_SIDES: usize = 48;

/// Sides of the shadow stage's proxy polygon, circumscribed about the proxy disc: its corners
/// reach 2 % beyond the disc (1/cos(π/16)), a penumbra that much wider, where 48 sides would
/// triple every proxy's shadow volumes (an umbra volume has planes per light vertex).
pub const PROXY_SIDES: usize = 16;

/// How far (in scene diagonals) the shadow stage puts a sun's disc; the disc is enlarged by
/// the scene's size so that every point's own cone stays inside it (about 1/1000 of its
/// radius per diagonal).
const SUN_DISTANCE: f64 = 1e3;

/// A uniform disc light facing a receiver point.
#[derive(Debug, Clone, PartialEq)]
pub struct Disc {
    pub centre: DVec3,
    /// Unit normal of its front (towards the receiver point).
    pub normal: DVec3,
    pub radius: f64,
    /// W·sr⁻¹·m⁻² per channel.
    pub radiance: DVec3,
}

impl Disc {
    /// A regular [`DISC_SIDES`]-gon with the disc's area, counter-clockwise about `normal`.
    pub fn polygon(&self) -> Vec<DVec3> {
        let n = DISC_SIDES as f64;
        let tau = std::f64::consts::TAU;
        self.regular(
            DISC_SIDES,
            self.radius * (tau / (n * (tau / n).sin())).sqrt(),
        )
    }

    /// The regular [`PROXY_SIDES`]-gon around the disc (its edges touch the circle): a proxy
    /// must hold the whole disc.
    pub fn circumscribed(&self) -> Vec<DVec3> {
        let n = PROXY_SIDES;
        self.regular(n, self.radius / (std::f64::consts::PI / n as f64).cos())
    }

    /// A regular `sides`-gon of circumradius `big`, counter-clockwise about `normal`.
    fn regular(&self, sides: usize, big: f64) -> Vec<DVec3> {
        let n = sides as f64;
        let tau = std::f64::consts::TAU;
        let f = Frame::new(self.centre, self.normal);
        (0..sides)
            .map(|k| {
                let t = tau * k as f64 / n;
                f.to_3d(DVec2::new(big * t.cos(), big * t.sin()))
            })
            .collect()
    }

    pub fn plane(&self) -> Plane {
        Plane::from_point_normal(self.centre, self.normal)
    }

    /// The disc as an area light (the polygon around it) for the shadow stage's volumes.
    pub fn area_light(&self) -> LightKind {
        LightKind::Area {
            verts: self.circumscribed(),
            plane: self.plane(),
            radiance: self.radiance,
        }
    }
}

/// Whether the light has a round shape (a radius or an angle above zero).
pub fn is_round(kind: &LightKind) -> bool {
    match kind {
        LightKind::Point { radius, .. } => *radius > 0.0,
        LightKind::Sun { half_angle, .. } => *half_angle > 0.0,
        LightKind::Area { .. } => false,
    }
}

/// The disc through which a round light lights `p`; `None` for other lights and at the
/// light's centre. `reach`: a distance beyond every occluder seen from `p` (the sun's disc
/// is put there).
pub fn facing(kind: &LightKind, p: DVec3, reach: f64) -> Option<Disc> {
    match kind {
        LightKind::Point {
            position,
            intensity,
            radius,
            sphere,
            ..
        } if *radius > 0.0 => {
            let d = p - *position;
            let dl = d.length();
            if !(dl > 0.0) {
                return None;
            }
            let (r, r2) = (*radius, radius * radius);
            let radiance = *intensity / (std::f64::consts::PI * r2);
            let (centre, radius) = if *sphere && dl > r {
                (
                    *position + d * (r2 / (dl * dl)),
                    r * (1.0 - r2 / (dl * dl)).sqrt(),
                )
            } else {
                (*position, r)
            };
            Some(Disc {
                centre,
                normal: d / dl,
                radius,
                radiance,
            })
        }
        LightKind::Sun {
            direction,
            irradiance,
            half_angle,
        } if *half_angle > 0.0 => {
            let s = half_angle.sin();
            Some(Disc {
                centre: p - *direction * reach,
                normal: *direction,
                radius: reach * half_angle.tan(),
                radiance: *irradiance / (std::f64::consts::PI * s * s),
            })
        }
        _ => None,
    }
}

/// The closed form of a round light's unoccluded irradiance at `p` (unit normal `n`) when
/// its disc lies wholly above `p`'s horizon, else `None` (then only the polygon tells).
pub fn unoccluded(kind: &LightKind, p: DVec3, n: DVec3) -> Option<DVec3> {
    match kind {
        LightKind::Point {
            position,
            intensity,
            radius,
            sphere,
            ..
        } => {
            let d = *position - p;
            let d2 = d.length_squared();
            let dl = d2.sqrt();
            let h = n.dot(d);
            let cos = h / dl;
            let r = *radius;
            if *sphere && dl > r {
                // The silhouette is above the horizon exactly when the sphere is.
                (h >= r).then(|| *intensity * (cos / d2))
            } else {
                let sin = (1.0 - cos * cos).max(0.0).sqrt();
                (h >= r * sin && dl > 0.0).then(|| *intensity * (cos / (d2 + r * r)))
            }
        }
        LightKind::Sun {
            direction,
            irradiance,
            half_angle,
        } => {
            let cos = -n.dot(*direction);
            (cos >= half_angle.sin()).then(|| *irradiance * cos)
        }
        LightKind::Area { .. } => None,
    }
}

/// What the shadow stage uses for a round light and one occluder.
#[derive(Debug, Clone, PartialEq)]
pub enum Proxy {
    /// A disc whose penumbra holds the light's penumbra and whose umbra lies in its umbra.
    Disc(Disc),
    /// The occluder is too near the light (or too large seen from it) for such a disc: it
    /// may shadow anything (every receiver in front gets it as a penumbra blocker).
    Everywhere,
}

/// The shadow stage's disc for a round light and a convex occluder with vertices `occ`,
/// `nearest` (a lower bound of) the occluder's distance to the light's centre, `centre` and
/// `diag` the scene's bounding-box centre and diagonal.
///
/// Point light of radius r: a point `p` the occluder shadows lies within angle
/// β = β_O + asin(r/ρ) of the axis from the centre to the occluder (β_O the occluder's
/// angular radius about that axis, ρ = `nearest`, and p is at least ρ away), and its own disc
/// is seen under a half-angle α ≤ α(ρ) (atan(r/d) soft, asin(r/d) sphere). A disc of radius
/// R on the axis, perpendicular to it, is met by every ray of that cone within
/// d·sin α / cos(α + β) of its centre (the farthest point of the cone's ellipse on the
/// plane, in the plane through the axis and `p`), and d·sin α ≤ r; so R = r / cos(α + β).
/// Beyond 80° the disc would be huge: [`Proxy::Everywhere`].
///
/// Sun of half-angle h: one disc for all occluders, perpendicular to the sun at
/// [`SUN_DISTANCE`] diagonals from the scene's centre, of radius (D + diag/2)·tan h + diag/2,
/// which holds the cone of every point of the scene's box.
pub fn proxy(kind: &LightKind, occ: &[DVec3], nearest: f64, centre: DVec3, diag: f64) -> Proxy {
    match kind {
        LightKind::Sun {
            direction,
            irradiance,
            half_angle,
        } => {
            let d = SUN_DISTANCE * diag;
            Proxy::Disc(Disc {
                centre: centre - *direction * d,
                normal: *direction,
                radius: (d + 0.5 * diag) * half_angle.tan() + 0.5 * diag,
                radiance: *irradiance,
            })
        }
        LightKind::Point {
            position,
            intensity,
            radius,
            sphere,
            ..
        } => {
            let r = *radius;
            let oc = occ.iter().copied().sum::<DVec3>() / occ.len().max(1) as f64;
            let axis = (oc - *position).normalize_or_zero();
            if axis == DVec3::ZERO || !(nearest > r * (1.0 + 1e-6)) {
                return Proxy::Everywhere;
            }
            let beta_o = occ
                .iter()
                .map(|v| {
                    let w = *v - *position;
                    w.cross(axis).length().atan2(w.dot(axis))
                })
                .fold(0.0, f64::max);
            let s = r / nearest;
            let alpha = if *sphere { s.asin() } else { s.atan() };
            let total = alpha + beta_o + s.asin();
            if !(total < 80f64.to_radians()) {
                return Proxy::Everywhere;
            }
            Proxy::Disc(Disc {
                centre: *position,
                normal: axis,
                radius: r / total.cos(),
                radiance: *intensity,
            })
        }
        LightKind::Area { .. } => Proxy::Everywhere,
    }
}

/// Distance from `p` to the convex planar polygon `poly` (exact up to rounding).
pub fn polygon_distance(p: DVec3, poly: &[DVec3]) -> f64 {
    let n = poly.len();
    let edge = |a: DVec3, b: DVec3| {
        let ab = b - a;
        let t = ((p - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
        (p - (a + ab * t)).length()
    };
    let nearest_edge = (0..n)
        .map(|i| edge(poly[i], poly[(i + 1) % n]))
        .fold(f64::INFINITY, f64::min);
    let Some(plane) = Plane::from_polygon(poly) else {
        return nearest_edge;
    };
    // Inside every edge's side plane (convex, counter-clockwise about the plane's normal):
    // the nearest point is the projection.
    let inside = (0..n).all(|i| {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        (b - a).cross(p - a).dot(plane.n) >= 0.0
    });
    if inside {
        plane.dist(p).abs()
    } else {
        nearest_edge
    }
}

#[cfg(test)]
mod test;
