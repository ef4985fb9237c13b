//! Default element sizes come from the meshes' bounds, not the lights': a large area
//! light 100 m above a 1 m floor made the floor's elements 4 m wide (its diagonal over 25),
//! one element for the whole floor.

mod common;

use common::*;
use penumbra::scene::json::SettingsJson;

#[test]
fn a_far_light_does_not_coarsen_the_default_elements() {
    let floor = || mesh("Floor", vec![quad([0.0, 0.0, 0.0], 0.5, 0.5, true)]);
    let size = |z: f64| {
        let light = area_light("L", quad([0.0, 0.0, z], 20.0, 20.0, false));
        let s = scene(vec![floor()], vec![light], SettingsJson::default());
        let sc = penumbra::scene::validate(&s).unwrap();
        (sc.settings.element_size, sc.diagonal())
    };
    let (near, _) = size(1.0);
    let (far, scene_diag) = size(100.0);
    let floor_diag = 2f64.sqrt();
    assert!((near - floor_diag / 25.0).abs() < 1e-12, "{near}");
    assert!((far - floor_diag / 25.0).abs() < 1e-12, "{far}");
    // The scene's own bounds (tolerances, precision) still hold the light.
    assert!(scene_diag > 100.0, "{scene_diag}");
}
