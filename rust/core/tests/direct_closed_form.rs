//! Direct light on the square-over-floor scene against the closed form: the light (side 1,
//! z = 2) seen from a floor point minus the rectangle the occluder (side 0.8, z = 1) hides,
//! each integrated with the corner formula for a rectangle parallel to the receiver.

mod common;
use common::*;
use std::f64::consts::PI;

#[test]
fn penumbra_values_match_rectangle_difference() {
    let radiance = 3.0;
    let mut light = area_light("Light", quad([0., 0., 2.], 0.5, 0.5, false));
    light.radiance = Some([radiance; 3]);
    let s = scene(
        vec![
            mesh("Floor", vec![quad([0., 0., 0.], 3., 3., true)]),
            mesh("Occluder", vec![quad([0., 0., 1.], 0.4, 0.4, true)]),
        ],
        vec![light],
        penumbra::scene::json::SettingsJson {
            indirect: Some(false),
            lighting_only: Some(true),
            // The light at the vertices themselves, against the closed form there.
            vertex_values: Some("exact".into()),
            ..Default::default()
        },
    );
    let b = bake(&s);
    let floor = &b.meshes[0];
    let mut worst: f64 = 0.0;
    let mut n_pen = 0;
    for (v, c) in floor.positions.iter().zip(&floor.colors) {
        let (x, y) = (v[0], v[1]);
        let (full, hid) = square_over_square(x, y);
        let want = radiance * (full - hid);
        let got = c[0] * PI;
        worst = worst.max((got - want).abs() / (radiance * full));
        if hid > 0.0 && hid < full {
            n_pen += 1;
        }
        assert!(c[0] == c[1] && c[1] == c[2]);
    }
    assert!(n_pen > 200, "only {n_pen} penumbra vertices");
    assert!(worst < 1e-9, "worst relative error {worst:e}");
}
