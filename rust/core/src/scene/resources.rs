//! The resource model: before any stage allocates, what a bake of this scene with these
//! settings needs at least, against `max_elements` and `max_memory`. A bake the estimate
//! refuses fails at once on one line naming the setting that drives it, instead of growing
//! until the machine swaps.
//!
//! The estimate is a lower bound, so it never refuses a bake that would fit: elements at
//! the coarse `element_size` everywhere (penumbrae, corners and grading near lights only add
//! elements), and the bytes each element costs through meshing, direct light and the
//! output (measured on data1 with indirect light off: 334 bytes per element between
//! 83k and 349k elements, `/usr/bin/time -f %M penumbra bake`; 300 is used). With indirect
//! light on, the patches that shoot it count too: at least one per face and one per
//! `patch_size` square, each holding its polygon, weights and visibility samples.

use crate::scene::json::SettingsJson;
use crate::scene::settings::Settings;
use crate::scene::Face;
use crate::BakeError;

/// Bytes per element (triangle) through meshing, direct light and the output, at least.
const BYTES_PER_ELEMENT: f64 = 300.0;
/// Bytes per element and light: the output's relation code.
const BYTES_PER_ELEMENT_LIGHT: f64 = 1.0;
/// Bytes per lightmap texel: linear RGB and coverage while rasterising, at least.
const BYTES_PER_TEXEL: f64 = 16.0;
/// Bytes per patch besides its visibility samples (polygon, centroid, weights), at least.
const BYTES_PER_PATCH: f64 = 200.0;
/// Bytes per visibility sample point of a patch (three densities: 1, 4 and the setting).
const BYTES_PER_SAMPLE: f64 = 24.0;

/// What a bake needs at least.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Elements (triangles) of the coarsest mesh the settings allow.
    pub elements: f64,
    /// Element vertices × lights: the direct stage's units of work.
    pub vertex_light_pairs: f64,
    /// Texels of the lightmaps the settings ask for.
    pub texels: f64,
    /// Patches shooting indirect light (0 with indirect light off).
    pub patches: f64,
    pub bytes: f64,
}

/// The estimate for `faces` under `lights` lights; `lightmaps` meshes get a lightmap of
/// `json.lightmap_resolution` texels on a side.
pub fn estimate(
    faces: &[Face],
    lights: usize,
    settings: &Settings,
    json: &SettingsJson,
    lightmaps: usize,
) -> Estimate {
    // A triangle of the coarse size covers about sqrt(3)/4 · size².
    let area: f64 = faces.iter().map(|f| f.area).sum();
    let elements = area / (0.433 * settings.element_size * settings.element_size);
    // About two triangles per vertex in a planar triangulation.
    let vertices = elements / 2.0;
    let res = json.lightmap_resolution.unwrap_or(0).max(0) as f64;
    let texels = res * res * lightmaps as f64;
    let patches = if settings.indirect {
        faces.len() as f64 + area / (settings.patch_size * settings.patch_size)
    } else {
        0.0
    };
    let per_patch = BYTES_PER_PATCH + BYTES_PER_SAMPLE * (5.0 + settings.visibility_rays as f64);
    Estimate {
        elements,
        vertex_light_pairs: vertices * lights as f64,
        texels,
        patches,
        bytes: elements * (BYTES_PER_ELEMENT + BYTES_PER_ELEMENT_LIGHT * lights as f64)
            + texels * BYTES_PER_TEXEL
            + patches * per_patch,
    }
}

/// Refuses a bake whose estimate exceeds `max_elements` or `max_memory`, naming the setting
/// that drives it.
pub fn check(est: &Estimate, settings: &Settings) -> Result<(), BakeError> {
    if est.elements > settings.max_elements as f64 {
        return Err(BakeError::setting(
            "element_size",
            format!(
                "{} would make about {:.0} elements, over max_elements = {} (raise element_size or max_elements)",
                settings.element_size, est.elements, settings.max_elements
            ),
        ));
    }
    if est.patches > settings.max_elements as f64 {
        return Err(BakeError::setting(
            "patch_size",
            format!(
                "{} would make about {:.0} patches, over max_elements = {} (raise patch_size or max_elements)",
                settings.patch_size, est.patches, settings.max_elements
            ),
        ));
    }
    if est.bytes > settings.max_memory as f64 {
        let texel_bytes = est.texels * BYTES_PER_TEXEL;
        let patch_bytes = est.patches
            * (BYTES_PER_PATCH + BYTES_PER_SAMPLE * (5.0 + settings.visibility_rays as f64));
        let mesh_bytes = est.bytes - texel_bytes - patch_bytes;
        let (field, what) = if patch_bytes > mesh_bytes && patch_bytes > texel_bytes {
            (
                "patch_size",
                format!(
                    "{} would make about {:.0} patches",
                    settings.patch_size, est.patches
                ),
            )
        } else if mesh_bytes >= texel_bytes {
            (
                "element_size",
                format!(
                    "{} would make about {:.0} elements",
                    settings.element_size, est.elements
                ),
            )
        } else {
            (
                "lightmap_resolution",
                format!("{:.0} lightmap texels", est.texels),
            )
        };
        return Err(BakeError::setting(
            field,
            format!(
                "{what}, needing at least {}, over max_memory = {} (raise {field} or max_memory)",
                gib(est.bytes),
                gib(settings.max_memory as f64)
            ),
        ));
    }
    Ok(())
}

/// Bytes as a person reads them: MiB below a GiB, GiB above.
fn gib(bytes: f64) -> String {
    if bytes < (1u64 << 30) as f64 {
        format!("{:.1} MiB", bytes / (1u64 << 20) as f64)
    } else {
        format!("{:.2} GiB", bytes / (1u64 << 30) as f64)
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::SceneJson;

    /// A 10 m × 10 m floor under a 1 m square light, with `settings` (JSON).
    fn floor(settings: &str) -> SceneJson {
        SceneJson::from_str(&format!(
            r#"{{"format":"penumbra-scene","version":1,
            "meshes":[{{"name":"Floor","positions":[[-5,-5,0],[5,-5,0],[5,5,0],[-5,5,0]],
                        "polygons":[[0,1,2,3]]}}],
            "lights":[{{"name":"Area","polygon":[[-0.5,-0.5,2],[-0.5,0.5,2],[0.5,0.5,2],[0.5,-0.5,2]],
                        "radiance":[1,1,1]}}],
            "settings":{settings}}}"#
        ))
        .unwrap()
    }

    #[test]
    fn estimate_is_the_coarse_mesh_and_its_bytes() {
        let json = floor(r#"{"element_size":0.1,"indirect":false}"#);
        let scene = crate::scene::validate(&json).unwrap();
        let est = estimate(&scene.faces, 1, &scene.settings, &json.settings, 0);
        assert_eq!(est.patches, 0.0);
        // 100 m² / (0.433 · 0.01 m²) elements, 301 bytes each, half as many vertices.
        let elements = 100.0 / (0.433 * 0.01);
        assert!((est.elements - elements).abs() < 1e-6 * elements);
        assert!((est.bytes - elements * 301.0).abs() < 1e-6 * est.bytes);
        assert!((est.vertex_light_pairs - elements / 2.0).abs() < 1e-6 * elements);
    }

    #[test]
    fn indirect_light_counts_its_patches() {
        let json = floor(r#"{"element_size":0.1,"patch_size":0.2}"#);
        let scene = crate::scene::validate(&json).unwrap();
        let est = estimate(&scene.faces, 1, &scene.settings, &json.settings, 0);
        // One per face plus 100 m² / 0.04 m², each 200 bytes and 21 samples of 24 bytes.
        assert!((est.patches - 2501.0).abs() < 1e-6);
        let elements = 100.0 / (0.433 * 0.01);
        let want = elements * 301.0 + 2501.0 * (200.0 + 24.0 * 21.0);
        assert!((est.bytes - want).abs() < 1e-6 * want);
    }

    #[test]
    fn a_tiny_patch_size_is_refused_before_any_patch_is_made() {
        // Issue 15: patch_size 1e-3 on a room grew to 10.6 GB and ignored cancel.
        let json = floor(r#"{"element_size":0.1,"patch_size":0.001}"#);
        let e = crate::scene::validate(&json).unwrap_err().to_string();
        assert!(
            e.starts_with("settings.patch_size: 0.001 would make about 100000001 patches"),
            "{e}"
        );
        let json = floor(r#"{"element_size":0.1,"patch_size":0.006,"max_memory":1073741824}"#);
        let e = crate::scene::validate(&json).unwrap_err().to_string();
        assert!(
            e.starts_with("settings.patch_size: 0.006 would make about"),
            "{e}"
        );
        assert!(e.contains("over max_memory = 1.00 GiB"), "{e}");
    }

    #[test]
    fn refused_in_validation_naming_the_setting() {
        let json = floor(
            r#"{"element_size":0.001,"max_elements":18446744073709551615,"max_memory":1073741824}"#,
        );
        let e = crate::scene::validate(&json).unwrap_err().to_string();
        assert!(
            e.starts_with("settings.element_size: 0.001 would make about 230946882 elements"),
            "{e}"
        );
        assert!(
            e.ends_with("over max_memory = 1.00 GiB (raise element_size or max_memory)"),
            "{e}"
        );
    }
}
