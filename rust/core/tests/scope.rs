//! A mesh with `"output": false` takes part in the bake (it casts shadows and reflects light)
//! but gets no triangles (issue 14: the add-on sends unselected scenery this way).

mod common;
use common::*;
use penumbra::scene::json::SettingsJson;

fn meshes(occluder_output: Option<bool>) -> Vec<penumbra::scene::json::MeshJson> {
    let mut occ = mesh("Occluder", cuboid([-0.3, -0.3, 0.6], [0.3, 0.3, 0.9]));
    occ.output = occluder_output;
    vec![mesh("Floor", vec![quad([0., 0., 0.], 2., 2., true)]), occ]
}

#[test]
fn scenery_without_output_shades_the_floor_the_same() {
    let mut light = area_light("Light", quad([0.1, 0., 2.], 0.4, 0.4, false));
    light.radiance = Some([4.0; 3]);
    for indirect in [false, true] {
        let settings = SettingsJson {
            indirect: Some(indirect),
            ..Default::default()
        };
        let with = bake(&scene(meshes(None), vec![light.clone()], settings.clone()));
        let without = bake(&scene(meshes(Some(false)), vec![light.clone()], settings));
        assert_eq!(with.meshes[0].positions, without.meshes[0].positions);
        assert_eq!(with.meshes[0].colors, without.meshes[0].colors);
        // The shadow is there: the floor under the occluder is darker than its rim.
        let dark = without.meshes[0]
            .colors
            .iter()
            .map(|c| c[0])
            .fold(f64::MAX, f64::min);
        let bright = without.meshes[0]
            .colors
            .iter()
            .map(|c| c[0])
            .fold(0.0, f64::max);
        assert!(dark < 0.5 * bright, "{dark} {bright}");
        assert!(!with.meshes[1].triangles.is_empty());
        assert_eq!(without.meshes.len(), 2);
        assert!(without.meshes[1].triangles.is_empty() && without.meshes[1].positions.is_empty());
    }
}
