//! The command-line contract: exit 0 and a bake JSON on success; exit 2 and one line naming
//! the object and field on bad input; never a panic trace.

use std::process::Command;

fn penumbra() -> Command {
    Command::new(env!("CARGO_BIN_EXE_penumbra"))
}

fn write(name: &str, text: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const GOOD: &str = r#"{"format":"penumbra-scene","version":1,
 "meshes":[{"name":"Floor","positions":[[-2,-2,0],[2,-2,0],[2,2,0],[-2,2,0]],"polygons":[[0,1,2,3]]},
           {"name":"Occluder","positions":[[-0.4,-0.4,1],[0.4,-0.4,1],[0.4,0.4,1],[-0.4,0.4,1]],"polygons":[[0,1,2,3]]}],
 "lights":[{"name":"Area","polygon":[[-0.5,-0.5,2],[-0.5,0.5,2],[0.5,0.5,2],[0.5,-0.5,2]],"radiance":[1,1,1]}],
 "settings":{"indirect":false}}"#;

fn run_bad(text: &str) -> (i32, String) {
    let p = write(&format!("bad{}.json", text.len()), text);
    let out = penumbra()
        .args(["bake", p.to_str().unwrap(), "-o", "/dev/null"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    (out.status.code().unwrap_or(-1), err)
}

#[test]
fn bakes_a_scene() {
    let p = write("good.json", GOOD);
    let o = p.with_extension("out.json");
    let out = penumbra()
        .args(["bake", p.to_str().unwrap(), "--output", o.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bake: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&o).unwrap()).unwrap();
    assert_eq!(bake["format"], "penumbra-bake");
    assert_eq!(bake["meshes"][0]["name"], "Floor");
    let tris = bake["meshes"][0]["triangles"].as_array().unwrap();
    assert!(tris.len() > 50);
    assert_eq!(
        bake["meshes"][0]["relation"].as_array().unwrap().len(),
        tris.len()
    );
    assert!(bake["stats"]["N_d"].as_u64().unwrap() >= 8);
}

#[test]
fn bad_input_is_one_line_and_exit_2() {
    let cases = [
        (
            GOOD.replace(
                "[[0,1,2,3]]},\n           {\"name\":\"Occluder\"",
                "[[0,1,2,7]]},\n           {\"name\":\"Occluder\"",
            ),
            "mesh \"Floor\" (meshes[0]): polygons[0][3]: index 7 is out of range",
        ),
        (
            GOOD.replace("[-0.5,0.5,2],[0.5,0.5,2]", "[-0.5,-0.5,2],[-0.5,-0.5,2]"),
            "light \"Area\" (lights[0]): polygon",
        ),
        (
            GOOD.replace("\"radiance\":[1,1,1]", "\"radiance\":[1,-1,1]"),
            "light \"Area\" (lights[0]): radiance: channel 1 is -1",
        ),
        (
            GOOD.replace("\"version\":1", "\"version\":7"),
            "version 7 is not supported",
        ),
        (
            GOOD.replace("\"indirect\":false", "\"indirekt\":false"),
            "unknown field `indirekt`",
        ),
        (
            GOOD.replace("\"indirect\":false", "\"element_size\":-1"),
            "settings.element_size: -1 must be a positive",
        ),
        (
            GOOD.replace("\"indirect\":false", "\"element_size\":1e-5"),
            "settings.element_size: 0.00001 would make about",
        ),
        (
            GOOD.replace("\"indirect\":false", "\"element_size\":1e-9"),
            "settings.element_size: 0.000000001 is below 1e-7",
        ),
        (GOOD.replace("[-2,-2,0]", "[-2,-2,1e400]"), "scene format"),
        (
            GOOD.replace("\"lights\":[{", "\"lights\":[],\"x\":[{"),
            "unknown field",
        ),
    ];
    for (text, want) in cases {
        let (code, err) = run_bad(&text);
        assert_eq!(code, 2, "{want}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "one line please: {err}");
        assert!(err.contains(want), "expected {want:?} in {err:?}");
        assert!(
            !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
            "{err}"
        );
    }
}

#[test]
fn missing_file_is_exit_2() {
    let out = penumbra()
        .args(["bake", "/nonexistent/scene.json", "-o", "/dev/null"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/scene.json"));
}

#[test]
fn builtin_scenes_bake() {
    for name in ["data1", "data2", "chair", "cornell", "room"] {
        let p =
            std::env::temp_dir().join(format!("penumbra-cli-{name}-{}.json", std::process::id()));
        let out = penumbra()
            .args(["scene", name, "-o", p.to_str().unwrap()])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(0));
        let mut s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
        s["settings"]["indirect"] = serde_json::Value::Bool(false);
        std::fs::write(&p, s.to_string()).unwrap();
        let out = penumbra()
            .args(["bake", p.to_str().unwrap(), "-o", "/dev/null"])
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(0),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[test]
fn writes_binary_gltf() {
    let p = write("good-glb.json", GOOD);
    let o = p.with_extension("glb");
    let out = penumbra()
        .args(["bake", p.to_str().unwrap(), "-o", o.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let b = std::fs::read(&o).unwrap();
    assert_eq!(&b[0..4], b"glTF");
    assert_eq!(
        u32::from_le_bytes(b[8..12].try_into().unwrap()) as usize,
        b.len()
    );
    let jlen = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
    assert_eq!(&b[16..20], b"JSON");
    let doc: serde_json::Value = serde_json::from_slice(&b[20..20 + jlen]).unwrap();
    assert_eq!(doc["nodes"][0]["name"], "Floor_baked");
    assert_eq!(doc["meshes"].as_array().unwrap().len(), 2);
    let bin_len = u32::from_le_bytes(b[20 + jlen..24 + jlen].try_into().unwrap()) as usize;
    assert_eq!(
        doc["buffers"][0]["byteLength"].as_u64().unwrap() as usize,
        bin_len
    );
}

/// A reader that closes the pipe early (`| head -c 10`) is a write failure: exit 1, and no
/// "internal error" on stderr.
#[test]
fn broken_pipe_on_stdout_is_exit_1_quietly() {
    use std::process::Stdio;
    let p = write("pipe.json", GOOD);
    let mut child = penumbra()
        .args(["bake", p.to_str().unwrap(), "--output", "-"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Close our end before the bake is written: every write then fails with EPIPE.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("internal error"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn threads_bounded_like_the_setting() {
    let p = write("threads.json", GOOD);
    for t in ["0", "1025", "100000", "many"] {
        let out = penumbra()
            .args([
                "bake",
                p.to_str().unwrap(),
                "-o",
                "/dev/null",
                "--threads",
                t,
            ])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "--threads {t}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "--threads {t}: {err}");
        assert!(err.contains("--threads"), "--threads {t}: {err}");
        assert!(err.contains("(see --help)"), "--threads {t}: {err}");
    }
    let out = penumbra()
        .args([
            "bake",
            p.to_str().unwrap(),
            "-o",
            "/dev/null",
            "--threads",
            "1024",
        ])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Clap's usage block is replaced by one line naming the problem and pointing at --help.
#[test]
fn argument_errors_are_one_line_and_exit_2() {
    let cases: [&[&str]; 6] = [
        &[],
        &["bake"],
        &["bake", "scene.json"],
        &["bake", "scene.json", "-o", "x", "--frobnicate"],
        &["frobnicate"],
        &["scene", "--output"],
    ];
    for args in cases {
        let out = penumbra().args(args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("penumbra: error: "), "{args:?}: {err}");
        assert!(err.trim_end().ends_with("(see --help)"), "{args:?}: {err}");
    }
    // The missing argument is named, not left to the usage block.
    let out = penumbra().args(["bake", "scene.json"]).output().unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("--output"));
    // Help still prints in full, exit 0.
    let out = penumbra().arg("--help").output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stdout).contains("bake"));
}

#[test]
fn tolerance_flag_checked_like_the_setting() {
    let p = write("tolerance.json", GOOD);
    for t in ["0", "2", "NaN"] {
        let out = penumbra()
            .args([
                "bake",
                p.to_str().unwrap(),
                "-o",
                "/dev/null",
                "--tolerance",
                t,
            ])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "--tolerance {t}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "--tolerance {t}: {err}");
        assert!(err.contains("tolerance"), "--tolerance {t}: {err}");
    }
    let out = penumbra()
        .args([
            "bake",
            p.to_str().unwrap(),
            "-o",
            "/dev/null",
            "--tolerance",
            "0.03",
        ])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
