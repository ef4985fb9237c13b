//! Emissive faces light the scene directly, as area lights (issue 14): with indirect light
//! off a floor under an emitting quad gets the closed-form irradiance, shadow included; a
//! thin emitter lights both sides; the light is not counted twice with indirect light on;
//! and the output's relations stay one per input light.

mod common;
use common::*;
use penumbra::geom::lambert::polygon_irradiance;
use penumbra::scene::json::{PerPolygon, SettingsJson};

fn glowing(name: &str, polys: Vec<Vec<[f64; 3]>>, le: f64) -> penumbra::scene::json::MeshJson {
    let mut m = mesh(name, polys);
    m.albedo = Some(PerPolygon::Uniform([0.0; 3]));
    m.emission = Some(PerPolygon::Uniform([le; 3]));
    m
}

fn settings(indirect: bool) -> SettingsJson {
    SettingsJson {
        indirect: Some(indirect),
        lighting_only: Some(true),
        // The light at the vertices themselves, against the closed form there.
        vertex_values: Some("exact".into()),
        ..Default::default()
    }
}

#[test]
fn emissive_quad_lights_the_floor_like_an_area_light() {
    let le = 3.0;
    let s = scene(
        vec![
            mesh("Floor", vec![quad([0., 0., 0.], 3., 3., true)]),
            mesh("Occluder", vec![quad([0., 0., 1.], 0.4, 0.4, true)]),
            glowing("Panel", vec![quad([0., 0., 2.], 0.5, 0.5, false)], le),
        ],
        vec![],
        settings(false),
    );
    let b = bake(&s);
    let floor = &b.meshes[0];
    let mut worst: f64 = 0.0;
    for (v, c) in floor.positions.iter().zip(&floor.colors) {
        let (x, y) = (v[0], v[1]);
        let (full, hid) = square_over_square(x, y);
        // Lighting only: E / π.
        let want = le * (full - hid) / std::f64::consts::PI;
        worst = worst.max((c[0] - want).abs() / (le * full / std::f64::consts::PI));
    }
    assert!(worst < 1e-6, "{worst}");
    // No input light, so no relation codes.
    assert!(floor.relation.iter().all(|r| r.is_empty()));
}

#[test]
fn thin_emitter_lights_both_sides_and_a_solid_only_its_outside() {
    // A vertical quad in the plane x = 0 over a floor: Cycles emits from both sides, so the
    // floor at x = ±1 gets the same light.
    let panel = vec![
        [0., -0.5, 0.5],
        [0., 0.5, 0.5],
        [0., 0.5, 1.5],
        [0., -0.5, 1.5],
    ];
    let panel_json = panel.clone();
    let s = scene(
        vec![
            mesh("Floor", vec![quad([0., 0., 0.], 3., 3., true)]),
            glowing("Panel", vec![panel_json], 1.0),
        ],
        vec![],
        settings(false),
    );
    let b = bake(&s);
    let f = &b.meshes[0];
    let quad3: Vec<glam::DVec3> = panel.iter().map(|p| glam::DVec3::from_array(*p)).collect();
    let (mut front, mut back) = (0, 0);
    for (v, c) in f.positions.iter().zip(&f.colors) {
        let p = glam::DVec3::from_array(*v);
        if p.x.abs() < 1e-6 {
            continue;
        }
        let want = polygon_irradiance(p, glam::DVec3::Z, &quad3) / std::f64::consts::PI;
        assert!(
            (c[0] - want).abs() < 1e-6 * want.max(1e-3),
            "{p}: {} vs {want}",
            c[0]
        );
        if p.x > 0.0 {
            front += 1
        } else {
            back += 1
        }
    }
    assert!(front > 100 && back > 100, "{front} {back}");

    // A glowing closed cube: one light per face, no back lights into the cube.
    let cube = cuboid([-0.3, -0.3, 0.5], [0.3, 0.3, 1.1]);
    let s = scene(
        vec![
            mesh("Floor", vec![quad([0., 0., 0.], 3., 3., true)]),
            glowing("Cube", cube, 1.0),
        ],
        vec![],
        settings(false),
    );
    let sc = penumbra::scene::validate(&s).unwrap();
    assert_eq!(sc.lights.len(), 6);
    assert!(sc.lights.iter().all(|l| l.from_face.is_some()));
}

#[test]
fn emission_is_not_counted_twice_with_indirect_light() {
    // The panel reflects nothing (albedo 0) and the floor sees nothing else: indirect light
    // adds nothing, so the two bakes must agree.
    let meshes = vec![
        mesh("Floor", vec![quad([0., 0., 0.], 2., 2., true)]),
        glowing("Panel", vec![quad([0.2, 0., 1.5], 0.4, 0.3, false)], 2.0),
    ];
    let off = bake(&scene(meshes.clone(), vec![], settings(false)));
    let on = bake(&scene(meshes, vec![], settings(true)));
    let (f0, f1) = (&off.meshes[0], &on.meshes[0]);
    assert_eq!(f0.positions, f1.positions);
    let peak = f0.colors.iter().map(|c| c[0]).fold(0.0, f64::max);
    assert!(peak > 0.05);
    for (a, b) in f0.colors.iter().zip(&f1.colors) {
        assert!((a[0] - b[0]).abs() <= 1e-9 * peak, "{} vs {}", a[0], b[0]);
    }
}
