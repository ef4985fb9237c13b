//! Lights that cannot light anything: a valid scene, but the bake would come out black where
//! the user expected light, so each such light gets a warning (not an error: a light switched
//! off, or one pointed away on purpose, is a legitimate scene).
//!
//! Receivers are one-sided (they gather light on their front, counter-clockwise side) and an
//! area light emits from its front only, so "reaches" here is the necessary condition for any
//! light at all: some of the light in front of the receiver's plane, and (area light) some of
//! the receiver in front of the light's plane. Occlusion is not considered: a light hidden
//! behind a wall is a scene the user can see for themselves.

use glam::DVec3;

use super::{Face, Light, LightKind};

/// Warnings for lights with zero power, and lights that reach no receiver's front.
pub fn light_warnings(lights: &[Light], faces: &[Face]) -> Vec<String> {
    let mut out = Vec::new();
    for l in lights {
        let obj = format!("light {:?} (lights[{}])", l.name, l.index);
        let (power, field) = match &l.kind {
            LightKind::Area { radiance, .. } => (*radiance, "radiance"),
            LightKind::Point { intensity, .. } => (*intensity, "intensity"),
            LightKind::Sun { irradiance, .. } => (*irradiance, "irradiance"),
        };
        if power.max_element() <= 0.0 {
            out.push(format!("{obj}: {field} is zero: the light gives no light"));
            continue;
        }
        if faces.iter().any(|f| reaches(&l.kind, f)) {
            continue;
        }
        out.push(match &l.kind {
            LightKind::Sun { .. } => format!(
                "{obj}: direction: the sun is below the horizon of every receiver (it shines on no polygon's front)"
            ),
            LightKind::Area { .. } => format!(
                "{obj}: polygon: the light faces away from every receiver (no polygon's front is in front of it)"
            ),
            LightKind::Point { .. } => format!(
                "{obj}: point: the light is behind every receiver (no polygon's front faces it)"
            ),
        });
    }
    out
}

/// Whether `light` can put any light on the front of `face`, occlusion aside.
fn reaches(light: &LightKind, face: &Face) -> bool {
    // A margin relative to the face's size: a light lying in a receiver's plane lights it at
    // grazing angle zero, i.e. not at all.
    let eps = 1e-12 * face.extent(0.0).max(f64::MIN_POSITIVE);
    let in_front_of_face = |p: DVec3| face.plane.dist(p) > eps;
    match light {
        LightKind::Sun { direction, .. } => face.plane.n.dot(*direction) < 0.0,
        LightKind::Point { position, spot, .. } => {
            in_front_of_face(*position)
                && spot.as_ref().is_none_or(|s| {
                    // The cone reaches the face's plane only if some vertex, or the plane's
                    // point nearest the cone's axis, is inside the cone's half space; a
                    // cheap test that never claims "no" wrongly: some vertex ahead of the
                    // spot's apex plane, along its axis.
                    face.verts
                        .iter()
                        .any(|v| (*v - *position).dot(s.direction) > 0.0)
                })
        }
        LightKind::Area { verts, plane, .. } => {
            verts.iter().any(|v| in_front_of_face(*v))
                && face.verts.iter().any(|v| plane.dist(*v) > eps)
        }
    }
}

#[cfg(test)]
mod test {
    use crate::scene::json::SceneJson;
    use crate::scene::validate;

    fn scene(lights: &str) -> String {
        format!(
            r#"{{"format":"penumbra-scene","version":1,
            "meshes":[{{"name":"Floor","positions":[[-1,-1,0],[1,-1,0],[1,1,0],[-1,1,0]],"polygons":[[0,1,2,3]]}}],
            "lights":[{lights}],"settings":{{"indirect":false}}}}"#
        )
    }

    fn warnings(lights: &str) -> Vec<String> {
        validate(&SceneJson::from_str(&scene(lights)).unwrap())
            .unwrap()
            .warnings
    }

    #[test]
    fn lights_that_reach_the_floor_give_no_warning() {
        for l in [
            r#"{"name":"Sun","direction":[0.3,0,-1],"irradiance":[1,1,1]}"#,
            r#"{"name":"Bulb","point":[0,0,2],"intensity":[1,1,1]}"#,
            r#"{"name":"Spot","point":[0,0,2],"intensity":[1,1,1],"spot":{"direction":[0,0,-1],"angle":0.5}}"#,
            // Wound clockwise from above: its front faces down.
            r#"{"name":"Panel","polygon":[[-0.2,-0.2,1],[-0.2,0.2,1],[0.2,0.2,1],[0.2,-0.2,1]],"radiance":[1,1,1]}"#,
        ] {
            assert_eq!(warnings(l), Vec::<String>::new(), "{l}");
        }
    }

    #[test]
    fn sun_below_the_horizon_of_every_receiver_warns() {
        let w = warnings(r#"{"name":"Sun","direction":[0,0.2,1],"irradiance":[1,1,1]}"#);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(
            w[0].starts_with(r#"light "Sun" (lights[0]): direction: the sun is below the horizon"#)
        );
        // Grazing (parallel to the floor) lights nothing either.
        assert_eq!(
            warnings(r#"{"name":"Sun","direction":[1,0,0],"irradiance":[1,1,1]}"#).len(),
            1
        );
    }

    #[test]
    fn area_light_facing_away_warns() {
        // Counter-clockwise from above: it emits upwards, away from the floor.
        let w = warnings(
            r#"{"name":"Panel","polygon":[[-0.2,-0.2,1],[0.2,-0.2,1],[0.2,0.2,1],[-0.2,0.2,1]],"radiance":[1,1,1]}"#,
        );
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].contains(r#""Panel""#) && w[0].contains("faces away from every receiver"));
        // Below the floor and facing down: behind the floor's front.
        let w = warnings(
            r#"{"name":"Under","polygon":[[-0.2,-0.2,-1],[-0.2,0.2,-1],[0.2,0.2,-1],[0.2,-0.2,-1]],"radiance":[1,1,1]}"#,
        );
        assert_eq!(w.len(), 1, "{w:?}");
    }

    #[test]
    fn point_behind_and_spot_pointing_away_warn() {
        let w = warnings(r#"{"name":"Bulb","point":[0,0,-2],"intensity":[1,1,1]}"#);
        assert!(
            w.len() == 1 && w[0].contains("behind every receiver"),
            "{w:?}"
        );
        let w = warnings(
            r#"{"name":"Spot","point":[0,0,2],"intensity":[1,1,1],"spot":{"direction":[0,0,1],"angle":0.5}}"#,
        );
        assert_eq!(w.len(), 1, "{w:?}");
    }

    #[test]
    fn zero_power_warns_per_kind() {
        for (l, field) in [
            (
                r#"{"name":"L","direction":[0,0,-1],"irradiance":[0,0,0]}"#,
                "irradiance",
            ),
            (
                r#"{"name":"L","point":[0,0,2],"intensity":[0,0,0]}"#,
                "intensity",
            ),
            (
                r#"{"name":"L","polygon":[[-0.2,-0.2,1],[-0.2,0.2,1],[0.2,0.2,1],[0.2,-0.2,1]],"radiance":[0,0,0]}"#,
                "radiance",
            ),
        ] {
            let w = warnings(l);
            assert_eq!(
                w,
                vec![format!(
                    r#"light "L" (lights[0]): {field} is zero: the light gives no light"#
                )]
            );
        }
    }

    #[test]
    fn warnings_reach_the_bake() {
        let text = scene(r#"{"name":"Sun","direction":[0,0,1],"irradiance":[1,1,1]}"#);
        let bake = crate::bake_scene_json(&text, &crate::Progress::new()).unwrap();
        assert_eq!(bake.warnings.len(), 1, "{:?}", bake.warnings);
        assert!(bake.warnings[0].contains("below the horizon"));
    }
}
