//! The precision contract at work on the scenes that used to lose geometry silently: each
//! either bakes with every polygon covered, or is refused on one line naming a polygon.
//! Never exit 0 with lost geometry.

use penumbra::scene::json::{LightJson, MeshJson, SceneJson, SettingsJson};
use penumbra::Progress;

fn no_indirect(mut s: SceneJson) -> SceneJson {
    s.settings.indirect = Some(false);
    s
}

/// Bakes `s`; Ok(triangles per mesh) or the one-line error.
fn outcome(s: &SceneJson) -> Result<Vec<usize>, String> {
    let scene = penumbra::scene::validate(s).map_err(|e| e.to_string())?;
    let bake = penumbra::bake(&scene, &Progress::new()).map_err(|e| e.to_string())?;
    Ok(bake.meshes.iter().map(|m| m.triangles.len()).collect())
}

/// Either every mesh got triangles (and `coverage::check` passed inside `bake`), or one line
/// naming a polygon.
fn bakes_whole_or_refused(name: &str, s: &SceneJson) -> bool {
    match outcome(s) {
        Ok(tris) => {
            assert!(tris.iter().all(|&n| n > 0), "{name}: {tris:?}");
            true
        }
        Err(e) => {
            assert_eq!(e.lines().count(), 1, "{name}: {e}");
            assert!(e.contains("polygons["), "{name}: {e}");
            assert!(e.starts_with("mesh \""), "{name}: {e}");
            false
        }
    }
}

fn quad(lo: [f64; 2], hi: [f64; 2], z: f64) -> Vec<[f64; 3]> {
    vec![
        [lo[0], lo[1], z],
        [hi[0], lo[1], z],
        [hi[0], hi[1], z],
        [lo[0], hi[1], z],
    ]
}

fn mesh(name: &str, polys: Vec<Vec<[f64; 3]>>) -> MeshJson {
    penumbra::scenes::polygons_mesh(name, polys, None)
}

/// A 1 m box (its top and sides) standing on a floor reaching ±1e12, under an area light.
fn box_on_a_huge_floor() -> SceneJson {
    let b = |z: f64| quad([-0.5, -0.5], [0.5, 0.5], z);
    let mut light = quad([-0.3, -0.3], [0.3, 0.3], 3.0);
    light.reverse();
    SceneJson {
        format: "penumbra-scene".into(),
        version: 1,
        meshes: vec![
            mesh("Floor", vec![quad([-1e12, -1e12], [1e12, 1e12], 0.0)]),
            mesh("Box", vec![b(1.0)]),
        ],
        lights: vec![LightJson {
            name: "Lamp".into(),
            polygon: Some(light),
            radiance: Some([10.0; 3]),
            ..LightJson::default()
        }],
        settings: SettingsJson {
            indirect: Some(false),
            ..SettingsJson::default()
        },
    }
}

#[test]
fn one_metre_box_on_a_1e12_floor() {
    let s = box_on_a_huge_floor();
    assert!(!bakes_whole_or_refused("box on 1e12 floor", &s));
}

#[test]
fn chair_with_its_floor_corner_far_away() {
    for x in [-1e9, -1e10] {
        let mut s = no_indirect(penumbra::scenes::chair());
        s.meshes[0].positions[0][0] = x;
        let name = format!("chair, floor corner at x = {x:e}");
        assert!(
            !bakes_whole_or_refused(&name, &s),
            "{name} should be refused"
        );
    }
    // Nearer, the stretched floor is inside the contract and bakes whole.
    let mut s = no_indirect(penumbra::scenes::chair());
    s.meshes[0].positions[0][0] = -1e3;
    assert!(bakes_whole_or_refused(
        "chair, floor corner at x = -1e3",
        &s
    ));
}

#[test]
fn chair_scaled_down_and_moved_far_away() {
    let mut s = no_indirect(penumbra::scenes::chair());
    let map = |p: &mut [f64; 3]| {
        for (k, x) in p.iter_mut().enumerate() {
            *x = *x * 1e-3 + if k == 0 { 1e11 } else { 0.0 };
        }
    };
    for m in &mut s.meshes {
        m.positions.iter_mut().for_each(map);
    }
    for l in &mut s.lights {
        l.polygon.iter_mut().flatten().for_each(map);
    }
    assert!(!bakes_whole_or_refused("chair 1e-3 at 1e11", &s));
}

/// Just inside the contract (reach / smallest polygon about 5e5): bakes, every polygon covered.
#[test]
fn chair_moved_to_the_edge_of_the_contract_bakes_whole() {
    let mut s = no_indirect(penumbra::scenes::chair());
    for m in &mut s.meshes {
        m.positions.iter_mut().for_each(|p| p[0] += 3e4);
    }
    for l in &mut s.lights {
        l.polygon.iter_mut().flatten().for_each(|p| p[0] += 3e4);
    }
    assert!(bakes_whole_or_refused("chair at 3e4", &s));
}

#[test]
fn refusal_is_exit_2_on_the_command_line() {
    let dir = std::env::temp_dir().join(format!("penumbra-precision-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("box.json");
    std::fs::write(&p, serde_json::to_string(&box_on_a_huge_floor()).unwrap()).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(["bake", p.to_str().unwrap(), "-o", "/dev/null"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("\"Box\"") && err.contains("precision"),
        "{err}"
    );
}
