//! The resource model from the command line: a bake whose estimate exceeds `max_memory` (or
//! `max_elements`) is refused at validation, before any stage allocates, with exit 2 and one
//! line naming the setting; `--max-memory` sets the budget.

use std::process::Command;

fn penumbra() -> Command {
    Command::new(env!("CARGO_BIN_EXE_penumbra"))
}

/// A `side` × `side` floor with a small occluder and an area light above it, and `settings`.
fn scene(name: &str, side: f64, settings: &str, uv: bool) -> std::path::PathBuf {
    let h = side / 2.0;
    let uv = if uv {
        r#","uv":[[0,0],[1,0],[1,1],[0,1]]"#
    } else {
        ""
    };
    let text = format!(
        r#"{{"format":"penumbra-scene","version":1,
 "meshes":[{{"name":"Floor","positions":[[-{h},-{h},0],[{h},-{h},0],[{h},{h},0],[-{h},{h},0]],"polygons":[[0,1,2,3]]{uv}}},
           {{"name":"Box","positions":[[-0.4,-0.4,1],[0.4,-0.4,1],[0.4,0.4,1],[-0.4,0.4,1]],"polygons":[[0,1,2,3]]}}],
 "lights":[{{"name":"Area","polygon":[[-0.5,-0.5,2],[-0.5,0.5,2],[0.5,0.5,2],[0.5,-0.5,2]],"radiance":[1,1,1]}}],
 "settings":{settings}}}"#
    );
    let dir = std::env::temp_dir().join(format!("penumbra-resources-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn bake(p: &std::path::Path, extra: &[&str]) -> (i32, String) {
    let out = penumbra()
        .args(["bake", p.to_str().unwrap(), "-o", "/dev/null"])
        .args(extra)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).trim().to_string();
    (out.status.code().unwrap_or(-1), err)
}

fn one_line(err: &str) {
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn tiny_elements_on_a_big_scene_are_refused_naming_the_setting() {
    // 1 km floor at 1 cm elements: about 2.3e10 elements, terabytes. max_elements raised so
    // that only the memory budget stands in the way.
    let p = scene(
        "km.json",
        1000.0,
        r#"{"indirect":false,"element_size":0.01,"max_elements":1000000000000000}"#,
        false,
    );
    let (code, err) = bake(&p, &[]);
    assert_eq!(code, 2, "{err}");
    one_line(&err);
    assert!(err.contains("settings.element_size"), "{err}");
    assert!(err.contains("max_memory"), "{err}");
}

#[test]
fn max_memory_from_the_flag_and_the_setting() {
    // 4 m floor at 1 cm: about 370k elements, some 100 MiB: over 64 MiB, under 1 GiB.
    let fine = r#"{"indirect":false,"element_size":0.01}"#;
    let p = scene("fine.json", 4.0, fine, false);
    let (code, err) = bake(&p, &["--max-memory", "64M"]);
    assert_eq!(code, 2, "{err}");
    one_line(&err);
    assert!(
        err.contains("settings.element_size") && err.contains("64.0 MiB"),
        "{err}"
    );

    let p = scene(
        "fine-json.json",
        4.0,
        r#"{"indirect":false,"element_size":0.01,"max_memory":67108864}"#,
        false,
    );
    let (code, err) = bake(&p, &[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("max_memory = 64.0 MiB"), "{err}");

    // The same scene at the default element size fits in 64 MiB and bakes.
    let p = scene("coarse.json", 4.0, r#"{"indirect":false}"#, false);
    let (code, err) = bake(&p, &["--max-memory", "64MiB"]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn huge_lightmaps_are_refused_naming_lightmap_resolution() {
    // One 16384² lightmap: 4 GiB of texels at least, over a 1 GiB budget.
    let p = scene("lightmap.json", 4.0, r#"{"indirect":false}"#, true);
    let (code, err) = bake(&p, &["--lightmap", "16384", "--max-memory", "1G"]);
    assert_eq!(code, 2, "{err}");
    one_line(&err);
    assert!(err.contains("settings.lightmap_resolution"), "{err}");
}

#[test]
fn bad_budgets_are_one_line_and_exit_2() {
    let p = scene("ok.json", 4.0, r#"{"indirect":false}"#, false);
    for bad in ["abc", "0", "0.5", "1e400", "12X"] {
        let (code, err) = bake(&p, &["--max-memory", bad]);
        assert_eq!(code, 2, "{bad}: {err}");
        one_line(&err);
        assert!(err.contains("--max-memory"), "{bad}: {err}");
    }
    let p = scene("small.json", 4.0, r#"{"max_memory":1000}"#, false);
    let (code, err) = bake(&p, &[]);
    assert_eq!(code, 2, "{err}");
    one_line(&err);
    assert!(err.contains("settings.max_memory"), "{err}");
}
