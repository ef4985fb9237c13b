//! The memory watchdog: what the estimate before baking cannot foresee (here refinement to
//! a tolerance of 1e-5, down to a penumbra element size far below the coarse size the
//! estimate counts) still ends as one clean
//! `max_memory` error once the bake has grown past the budget, not as a machine that swaps.
//! Its own test binary: the watchdog looks at the whole process's memory.

use penumbra::{BakeError, Progress};

#[test]
fn a_bake_growing_past_max_memory_stops_with_a_setting_error() {
    let text = r#"{"format":"penumbra-scene","version":1,
     "meshes":[{"name":"Floor","positions":[[-2,-2,0],[2,-2,0],[2,2,0],[-2,2,0]],"polygons":[[0,1,2,3]]},
               {"name":"Box","positions":[[-0.4,-0.4,1],[0.4,-0.4,1],[0.4,0.4,1],[-0.4,0.4,1]],"polygons":[[0,1,2,3]]}],
     "lights":[{"name":"Area","polygon":[[-0.5,-0.5,2],[-0.5,0.5,2],[0.5,0.5,2],[0.5,-0.5,2]],"radiance":[1,1,1]}],
     "settings":{"indirect":false,"element_size":0.5,"penumbra_element_size":0.002,
                 "tolerance":1e-5,"max_memory":16777216}}"#;
    let json = penumbra::SceneJson::from_str(text).unwrap();
    // The estimate (coarse elements only) fits in 16 MiB...
    let scene = penumbra::scene::validate(&json).unwrap();
    // ...the penumbrae at 2 mm do not.
    let e = penumbra::bake(&scene, &Progress::new()).unwrap_err();
    let BakeError::Setting { field, .. } = &e else {
        panic!("not a setting error: {e}");
    };
    assert_eq!(field, "max_memory", "{e}");
    let msg = e.to_string();
    assert_eq!(msg.lines().count(), 1, "{msg}");
    assert!(msg.contains("over max_memory = 16 MiB"), "{msg}");
}
