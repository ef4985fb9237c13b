//! Element size over a receiver, graded by the distance to the lights it faces. Linear
//! interpolation of the Lambert field between element vertices errs by about (h / r)² of
//! the value, r the distance to the light: where a receiver comes close to a light (a wall
//! meeting the ceiling that holds the lamp) elements must shrink with r, while far from
//! every light the settings' sizes are plenty.

use glam::{DVec2, DVec3};

use crate::scene::settings::Settings;
use crate::scene::{Face, Light, LightKind};

/// Elements at most this fraction of the distance to the light.
const PER_DISTANCE: f64 = 1.0 / 20.0;
/// Grading stops at these fractions of `element_size` (lit, penumbra). (A cap on penumbra
/// elements at a quarter of the light's shortest edge was tried: on Data 2 it raised the
/// element count from 17k to 27k for no gain in error.)
const LIT_FLOOR: f64 = 1.0 / 8.0;
const PENUMBRA_FLOOR: f64 = 1.0 / 64.0;
/// Elements across a narrow gap are at most this many times its width: the hierarchy's
/// leaves there are that fine too (`hierarchy::GAP_WIDTHS`), and its vertices must show
/// how the light fades from the gap's mouth.
const GAP_WIDTHS: f64 = 4.0;

/// A light as seen from one receiver: a ball that holds it.
#[derive(Debug, Clone, Copy)]
struct Source {
    /// Index into the scene's lights.
    light: usize,
    centre: DVec3,
    radius: f64,
}

/// Sizes over one receiver face.
#[derive(Debug, Clone)]
pub struct Sizing {
    frame: crate::geom::Frame,
    sources: Vec<Source>,
    coarse: f64,
    fine: f64,
}

impl Sizing {
    pub fn new(face: &Face, lights: &[Light], settings: &Settings) -> Self {
        let mut sources = Vec::new();
        if !settings.uniform {
            for (i, l) in lights.iter().enumerate() {
                match &l.kind {
                    LightKind::Area { verts, plane, .. } => {
                        let faces_light = verts.iter().any(|v| face.plane.dist(*v) > 0.0)
                            && face.verts.iter().any(|v| plane.dist(*v) > 0.0);
                        if !faces_light || verts.is_empty() {
                            continue;
                        }
                        let centre = verts.iter().copied().sum::<DVec3>() / verts.len() as f64;
                        let radius = verts
                            .iter()
                            .map(|v| (*v - centre).length())
                            .fold(0.0, f64::max);
                        sources.push(Source {
                            light: i,
                            centre,
                            radius,
                        });
                    }
                    LightKind::Point {
                        position, radius, ..
                    } => {
                        // A round light is a ball of its radius (`scene::disc`).
                        if face.plane.dist(*position) > -radius {
                            sources.push(Source {
                                light: i,
                                centre: *position,
                                radius: *radius,
                            });
                        }
                    }
                    LightKind::Sun { .. } => {}
                }
            }
        }
        Sizing {
            frame: face.frame,
            sources,
            coarse: settings.element_size,
            fine: settings.penumbra_element_size,
        }
    }

    /// A lower bound of the distance from any point within `reach` of `p` to a light that
    /// `seen` says reaches it.
    fn distance(&self, p: DVec2, reach: f64, seen: &dyn Fn(usize) -> bool) -> f64 {
        let x = self.frame.to_3d(p);
        self.sources
            .iter()
            .filter(|s| seen(s.light))
            .map(|s| (x - s.centre).length() - s.radius - reach)
            .fold(f64::INFINITY, f64::min)
            .max(0.0)
    }

    /// Element size within `reach` of `p` outside penumbra, where `seen(light)` tells the
    /// lights that reach the region (in umbra of all, the field is only the smooth indirect
    /// light, and the largest size does).
    pub fn lit(&self, p: DVec2, reach: f64, seen: &dyn Fn(usize) -> bool) -> f64 {
        (self.distance(p, reach, seen) * PER_DISTANCE).clamp(self.coarse * LIT_FLOOR, self.coarse)
    }

    /// Element size for penumbra within `reach` of `p`: never coarser than lit ones there.
    pub fn penumbra(&self, p: DVec2, reach: f64, seen: &dyn Fn(usize) -> bool) -> f64 {
        self.fine
            .min(self.lit(p, reach, seen))
            .max(self.coarse * PENUMBRA_FLOOR)
    }

    /// Element size across a narrow gap `w` wide (`shadows::gaps`): the light bounced into
    /// it fades within a few widths of its mouth, whatever the light outside does.
    pub fn gap(&self, w: f64) -> f64 {
        (GAP_WIDTHS * w).clamp(self.coarse * PENUMBRA_FLOOR, self.coarse)
    }

    /// The receiver's frame.
    pub fn frame(&self) -> &crate::geom::Frame {
        &self.frame
    }

    /// The smallest size this receiver can ask for.
    pub fn smallest(&self) -> f64 {
        let lit = if self.sources.is_empty() {
            self.coarse
        } else {
            self.coarse * LIT_FLOOR
        };
        self.fine.min(lit).max(self.coarse * PENUMBRA_FLOOR)
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::geom::Plane;
    use crate::scene::json::SettingsJson;
    use crate::scene::test::face;

    #[test]
    fn sizes_follow_the_distance_to_the_light_within_their_bounds() {
        let v = |x, y, z| DVec3::new(x, y, z);
        let floor = face(
            &[
                v(-10.0, -10.0, 0.0),
                v(10.0, -10.0, 0.0),
                v(10.0, 10.0, 0.0),
                v(-10.0, 10.0, 0.0),
            ],
            DVec3::ONE,
            DVec3::ZERO,
        );
        // A 0.2-wide light at height 4 facing down: its ball has radius 0.1·√2.
        let lv = vec![
            v(-0.1, -0.1, 4.0),
            v(-0.1, 0.1, 4.0),
            v(0.1, 0.1, 4.0),
            v(0.1, -0.1, 4.0),
        ];
        let light = Light {
            name: "L".into(),
            index: 0,
            kind: LightKind::Area {
                plane: Plane::from_polygon(&lv).unwrap(),
                verts: lv,
                radiance: DVec3::ONE,
            },
            from_face: None,
        };
        let settings = Settings::from_json(
            &SettingsJson {
                element_size: Some(0.5),
                ..Default::default()
            },
            30.0,
        )
        .unwrap();
        let s = Sizing::new(&floor, &[light], &settings);
        let all = |_: usize| true;
        let none = |_: usize| false;
        let under = floor.frame.to_2d(v(0.0, 0.0, 0.0));
        let r = 0.1 * 2f64.sqrt();
        assert!((s.lit(under, 0.0, &all) - (4.0 - r) / 20.0).abs() < 1e-12);
        // Anywhere within 1 of the point: 1 nearer at most.
        assert!((s.lit(under, 1.0, &all) - (3.0 - r) / 20.0).abs() < 1e-12);
        // Never below element_size / 8, nor above element_size (14.7 from the corner).
        assert_eq!(s.lit(under, 3.0, &all), 0.5 / 8.0);
        let far = floor.frame.to_2d(v(10.0, 10.0, 0.0));
        assert_eq!(s.lit(far, 0.0, &all), 0.5);
        // Umbra of the only light: the largest size.
        assert_eq!(s.lit(under, 0.0, &none), 0.5);
        // Penumbra: the setting (element_size / 2), never above the lit size there.
        assert_eq!(s.penumbra(far, 0.0, &all), 0.25);
        assert_eq!(s.penumbra(under, 0.0, &all), s.lit(under, 0.0, &all));
        assert_eq!(s.smallest(), 0.5 / 8.0);
    }
}
