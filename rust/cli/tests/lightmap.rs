//! `penumbra bake --lightmap`: EXR lightmaps for meshes with `uv`, and bad lightmap input
//! refused before the bake with exit 2 and one line.

use std::process::Command;

fn penumbra() -> Command {
    Command::new(env!("CARGO_BIN_EXE_penumbra"))
}

fn dir(tag: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("penumbra-lm-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A floor under an occluder and an area light; the floor's UVs are its x, y mapped to
/// [0, 1]² (`uv` supplied as given), the occluder has none.
fn scene(uv: &str) -> String {
    format!(
        r#"{{"format":"penumbra-scene","version":1,
 "meshes":[{{"name":"Floor","positions":[[-2,-2,0],[2,-2,0],[2,2,0],[-2,2,0]],"polygons":[[0,1,2,3]],
            "uv":{uv}}},
           {{"name":"Occluder","positions":[[-0.4,-0.4,1],[0.4,-0.4,1],[0.4,0.4,1],[-0.4,0.4,1]],"polygons":[[0,1,2,3]]}}],
 "lights":[{{"name":"Area","polygon":[[-0.5,-0.5,2],[-0.5,0.5,2],[0.5,0.5,2],[0.5,-0.5,2]],"radiance":[1,1,1]}}],
 "settings":{{"indirect":false}}}}"#
    )
}

const UV: &str = "[[0,0],[1,0],[1,1],[0,1]]";

fn read_exr(path: &std::path::Path) -> (usize, Vec<[f32; 3]>) {
    let img = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![[0.0f32; 3]; res.width() * res.height()]),
        |(w, px): &mut (usize, Vec<[f32; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = [r, g, b];
        },
    )
    .unwrap();
    img.layer_data.channel_data.pixels
}

#[test]
fn writes_an_exr_per_mesh_with_uvs() {
    let d = dir("ok");
    let s = d.join("scene.json");
    std::fs::write(&s, scene(UV)).unwrap();
    let out = penumbra()
        .args(["bake", s.to_str().unwrap(), "-o"])
        .arg(d.join("bake.json"))
        .args(["--lightmap", "32", "--margin", "4"])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!d.join("Occluder_radiosity.exr").exists());
    let (w, px) = read_exr(&d.join("Floor_radiosity.exr"));
    assert_eq!((w, px.len()), (32, 32 * 32));
    // The centre of the floor is in the occluder's umbra, its corners are lit.
    let centre = px[16 * 32 + 16][0];
    let corner = px[0][0];
    assert!(centre.abs() < 1e-6, "{centre}");
    assert!(corner > 1e-3, "{corner}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn bad_lightmap_input_is_exit_2_and_one_line_before_the_bake() {
    let overlapping = "[[0,0],[1,0],[1,1],[0,1]]";
    let d = dir("bad");
    let cases = [
        (UV, "0", "lightmap_resolution"),
        (UV, "1000000", "lightmap_resolution"),
        ("[[0,0],[1,0],[1,1]]", "16", "one per polygon corner"),
        ("[[0,0],[1,1],[0.5,0.5],[0.2,0.2]]", "16", "no area"),
    ];
    for (uv, res, want) in cases {
        let s = d.join("scene.json");
        std::fs::write(&s, scene(uv)).unwrap();
        let out = penumbra()
            .args(["bake", s.to_str().unwrap(), "-o"])
            .arg(d.join("bake.json"))
            .args(["--lightmap", res])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(
            err.contains(want) && err.trim().lines().count() == 1,
            "{err}"
        );
        assert!(!d.join("bake.json").exists(), "failed before the bake");
    }
    // Two polygons on the same UVs.
    let text = scene(overlapping)
        .replace(
            r#""polygons":[[0,1,2,3]],
            "uv""#,
            r#""polygons":[[0,1,2],[0,2,3]],
            "uv""#,
        )
        .replace(
            r#""uv":[[0,0],[1,0],[1,1],[0,1]]"#,
            r#""uv":[[0,0],[1,0],[1,1],[0,0],[1,0],[1,1]]"#,
        );
    let s = d.join("overlap.json");
    std::fs::write(&s, text).unwrap();
    let out = penumbra()
        .args(["bake", s.to_str().unwrap(), "-o"])
        .arg(d.join("bake.json"))
        .args(["--lightmap", "16"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("overlap") && err.contains("Floor"), "{err}");
    std::fs::remove_dir_all(&d).ok();
}
