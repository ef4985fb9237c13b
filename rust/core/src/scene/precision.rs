//! The precision contract: the range of scenes whose geometry the bake can keep exactly.
//!
//! Decisions go through exact predicates, but constructed points (clip points, crossings,
//! points moved into a receiver's 2-D frame) are rounded to `f64`, which leaves an absolute
//! error of about `R · 2⁻⁵²` where R is the *reach* of the scene: its distance from the
//! origin plus its size. The arrangement and the weld merge points closer than about 1e-9 of
//! a polygon's size (never less than 1e-9 of the scene), so a polygon keeps its shape only
//! while that snapping distance stays well above the rounding:
//!
//! ```text
//!     reach / smallest polygon ≤ MAX_RANGE = 1e6
//! ```
//!
//! (1e-9 / 2⁻⁵² ≈ 4.5e6, with a margin for the few roundings a constructed point goes
//! through.) Inside this range the bake is exact up to that snapping; outside it, points of
//! the small polygon would merge or cross, so the scene is refused up front, naming the
//! smallest polygon. Examples: a 10 m room with 1 cm details may sit up to 10 km from the
//! origin; a 1 m box on a 10⁹ m floor (reach 10⁹ m) is refused. Move the scene near the
//! origin, or drop the tiny polygons, to bake it.
//!
//! Whatever slips through anyway is caught after the bake by `coverage::check`.

use glam::DVec3;

use super::{Face, MeshInfo};
use crate::BakeError;

/// Largest `reach / smallest polygon` a bake accepts (see the module note).
pub const MAX_RANGE: f64 = 1e6;

/// Refuses a scene outside the contract, naming its smallest polygon. `lo`/`hi` bound the
/// whole scene (meshes and lights).
pub fn check(meshes: &[MeshInfo], faces: &[Face], lo: DVec3, hi: DVec3) -> Result<(), BakeError> {
    let reach = lo.abs().max(hi.abs()).max_element() + (hi - lo).length();
    if !(reach > 0.0) {
        return Ok(());
    }
    // The smallest polygon: a polygon's size is its largest convex piece's (its pieces are
    // consecutive in `faces`).
    let mut smallest: Option<(f64, usize, u32)> = None;
    for (mi, m) in meshes.iter().enumerate() {
        let mut at = m.face_start;
        while at < m.face_end {
            let p = faces[at].source_polygon;
            let mut size = 0.0f64;
            while at < m.face_end && faces[at].source_polygon == p {
                size = size.max(faces[at].extent(0.0));
                at += 1;
            }
            if smallest.is_none_or(|(s, _, _)| size < s) {
                smallest = Some((size, mi, p));
            }
        }
    }
    let Some((size, mi, p)) = smallest else {
        return Ok(());
    };
    if reach <= MAX_RANGE * size {
        return Ok(());
    }
    Err(BakeError::invalid(
        format!("mesh {:?} (meshes[{mi}])", meshes[mi].name),
        format!("polygons[{p}]"),
        format!(
            "{} across is too small for a scene that reaches {} from the origin (at most 1/{MAX_RANGE:e} of it: the precision contract in the README); move the scene nearer the origin or remove the polygon",
            num(size),
            num(reach)
        ),
    ))
}

fn num(x: f64) -> String {
    if (1e-3..1e5).contains(&x) {
        format!("{}", (x * 1e4).round() / 1e4)
    } else {
        format!("{x:.3e}")
    }
}

#[cfg(test)]
mod test {
    use crate::scene::json::SceneJson;
    use crate::scene::validate;

    /// A floor of half-size `floor` and a `box_size` cube on it, everything shifted by `offset`.
    fn scene(floor: f64, box_size: f64, offset: [f64; 3]) -> String {
        let p = |x: f64, y: f64, z: f64| {
            format!(
                "[{:e},{:e},{:e}]",
                x + offset[0],
                y + offset[1],
                z + offset[2]
            )
        };
        let (f, b) = (floor, box_size);
        format!(
            r#"{{"format":"penumbra-scene","version":1,"meshes":[
              {{"name":"Floor","positions":[{},{},{},{}],"polygons":[[0,1,2,3]]}},
              {{"name":"Box","positions":[{},{},{},{}],"polygons":[[0,1,2,3]]}}],
             "lights":[{{"name":"Sun","direction":[0.1,0.2,-1],"irradiance":[1,1,1]}}],
             "settings":{{"indirect":false}}}}"#,
            p(-f, -f, 0.0),
            p(f, -f, 0.0),
            p(f, f, 0.0),
            p(-f, f, 0.0),
            p(0.0, 0.0, b),
            p(b, 0.0, b),
            p(b, b, b),
            p(0.0, b, b),
        )
    }

    fn check(text: &str) -> Result<(), String> {
        validate(&SceneJson::from_str(text).unwrap())
            .map(|_| ())
            .map_err(|e| e.to_string())
    }

    #[test]
    fn ordinary_scenes_are_inside() {
        check(&scene(2.0, 0.01, [0.0; 3])).unwrap();
        check(&scene(2.0, 0.5, [1e4, 0.0, 0.0])).unwrap();
        check(&scene(2e3, 0.01, [0.0; 3])).unwrap();
    }

    #[test]
    fn small_box_on_a_huge_floor_is_refused_naming_the_box() {
        let e = check(&scene(1e12, 1.0, [0.0; 3])).unwrap_err();
        assert!(
            e.starts_with(r#"mesh "Box" (meshes[1]): polygons[0]: 1.4142 across is too small"#),
            "{e}"
        );
        assert_eq!(e.lines().count(), 1);
    }

    #[test]
    fn far_from_the_origin_is_refused() {
        let e = check(&scene(2e-3, 1e-3, [1e11, 0.0, 0.0])).unwrap_err();
        assert!(
            e.contains(r#""Box""#) && e.contains("precision contract"),
            "{e}"
        );
        assert!(check(&scene(2.0, 0.05, [-1e9, 0.0, 0.0])).is_err());
    }
}
