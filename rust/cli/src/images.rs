//! Lightmap images on disk: OpenEXR, 32-bit float RGB, linear. EXR because a lightmap holds
//! radiance, not display values: it goes above 1 and must stay linear, which an 8-bit PNG
//! cannot hold; Blender, Godot, Unity and three.js all read EXR directly.

use std::path::{Path, PathBuf};

use penumbra::lightmap::Lightmap;

/// The file a mesh's lightmap goes to: `<dir>/<name>_radiosity.exr`, with characters that
/// are unsafe in file names replaced by `_` (the add-on names images the same way).
pub fn lightmap_path(dir: &Path, mesh_name: &str) -> PathBuf {
    let safe: String = mesh_name
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || "-_. ".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    dir.join(format!("{safe}_radiosity.exr"))
}

/// Writes `lm` as an RGB float EXR. The lightmap's row 0 is at v = 0 (the bottom); an
/// image file's first row is its top, so rows are flipped on the way out.
pub fn write_exr(path: &Path, lm: &Lightmap) -> Result<(), String> {
    let (w, h) = (lm.width, lm.height);
    exr::prelude::write_rgb_file(path, w, h, |x, y| {
        let c = lm.rgb[(h - 1 - y) * w + x];
        (c[0], c[1], c[2])
    })
    .map_err(|e| format!("{}: {e}", path.display()))
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn written_images_read_back_with_v_up() {
        let lm = Lightmap {
            width: 3,
            height: 2,
            rgb: (0..6).map(|i| [i as f32, 0.5, 2.0]).collect(),
            coverage: vec![1.0; 6],
        };
        let dir = std::env::temp_dir().join(format!("penumbra-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = lightmap_path(&dir, "Floor/1");
        assert!(path.ends_with("Floor_1_radiosity.exr"));
        write_exr(&path, &lm).unwrap();
        let img = exr::prelude::read_first_rgba_layer_from_file(
            &path,
            |res, _| vec![[0.0f32; 3]; res.width() * res.height()],
            |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * 3 + pos.x()] = [r, g, b];
            },
        )
        .unwrap();
        let px = &img.layer_data.channel_data.pixels;
        // The file's top row is the lightmap's last row (v = 1).
        assert_eq!(px[0], [3.0, 0.5, 2.0]);
        assert_eq!(px[5], [2.0, 0.5, 2.0]);
        std::fs::remove_dir_all(&dir).ok();
    }
}
