//! Any bytes as scene JSON: parsing and validation either give a scene or one error line,
//! never a panic; a scene that validates (kept tiny, so each run is quick) bakes or is
//! refused, with finite colours ≥ 0.
#![no_main]

use libfuzzer_sys::fuzz_target;
use penumbra::{Progress, SceneJson};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let json = match SceneJson::from_str(text) {
        Ok(j) => j,
        Err(e) => {
            assert_eq!(e.to_string().lines().count(), 1, "{e}");
            return;
        }
    };
    let mut scene = match penumbra::scene::validate(&json) {
        Ok(s) => s,
        Err(e) => {
            assert_eq!(e.to_string().lines().count(), 1, "{e}");
            return;
        }
    };
    // Bound the work per input: a handful of polygons and lights, no indirect light.
    if scene.faces.len() > 64 || scene.lights.len() > 4 {
        return;
    }
    scene.settings.indirect = false;
    scene.settings.threads = Some(1);
    if let Ok(b) = penumbra::bake(&scene, &Progress::new()) {
        for m in &b.meshes {
            assert!(m
                .colors
                .iter()
                .flatten()
                .all(|c| c.is_finite() && *c >= 0.0));
        }
    }
});
