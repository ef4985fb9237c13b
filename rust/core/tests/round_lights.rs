//! Round lights (issue 14): a point light with a radius (soft falloff and sphere) and a sun
//! with an angle cast penumbrae. Every floor vertex of the discontinuity-meshed bake carries
//! exactly the light of the disc facing it, clipped by all of the box's faces (the relations
//! the proxy discs give are conservative), and the penumbra is meshed (triangles with relation
//! code 2, and vertices inside it).

mod common;
use common::*;
use glam::DVec3;
use penumbra::direct::round::round_light;
use penumbra::regions::relation::Relation;
use penumbra::scene::disc::facing;
use penumbra::scene::json::{LightJson, SettingsJson};
use penumbra::scene::settings::PenumbraVisibility;
use penumbra::scene::LightKind;
use std::f64::consts::PI;

fn settings() -> SettingsJson {
    SettingsJson {
        indirect: Some(false),
        lighting_only: Some(true),
        // The light at the vertices themselves, against the references there.
        vertex_values: Some("exact".into()),
        // Finer than the sun's penumbra (0.09 wide under the box's top edge).
        penumbra_element_size: Some(0.03),
        ..Default::default()
    }
}

/// Floor 6 × 6 at z = 0 and a box [−0.5, 0.5]² × [0, 1] (on the floor, not touching it
/// exactly: lifted 0.2 so the shadow has both a penumbra and an umbra all round).
/// The exact irradiance (red) a round light gives the floor point `p` in relation `rel`,
/// with `blockers` hiding part of the disc facing it.
fn floor_light(kind: &LightKind, p: DVec3, rel: Relation, blockers: &[&[DVec3]]) -> f64 {
    let disc = facing(kind, p, 100.0).unwrap();
    round_light(
        p,
        DVec3::Z,
        kind,
        &disc,
        rel,
        blockers,
        PenumbraVisibility::Exact,
        0,
    )
    .x
}

fn check(light: LightJson) -> (f64, usize) {
    let box_polys = cuboid([-0.5, -0.5, 0.2], [0.5, 0.5, 1.0]);
    let s = scene(
        vec![
            mesh("Floor", vec![quad([0., 0., 0.], 3., 3., true)]),
            mesh("Box", box_polys.clone()),
        ],
        vec![light],
        settings(),
    );
    let sc = penumbra::scene::validate(&s).unwrap();
    let b = bake(&s);
    let floor = &b.meshes[0];
    let occ: Vec<Vec<DVec3>> = box_polys
        .iter()
        .map(|p| p.iter().map(|v| DVec3::from_array(*v)).collect())
        .collect();
    let blockers: Vec<&[DVec3]> = occ.iter().map(|o| o.as_slice()).collect();
    let kind = &sc.lights[0].kind;
    let (mut worst, mut peak, mut partial) = (0.0f64, 0.0f64, 0);
    for (v, c) in floor.positions.iter().zip(&floor.colors) {
        let p = DVec3::from_array(*v);
        let e = |rel, b: &[&[DVec3]]| floor_light(kind, p, rel, b);
        let want = e(Relation::Penumbra, &blockers) / PI;
        let all = e(Relation::Lit, &[]) / PI;
        if want > 0.02 * all && want < 0.98 * all {
            partial += 1;
        }
        peak = peak.max(all);
        worst = worst.max((c[0] - want).abs());
    }
    let pen = floor.relation.iter().filter(|r| r[0] == 2).count();
    assert!(pen > 0, "no penumbra triangles");
    (worst / peak, partial)
}

#[test]
fn soft_point_light_penumbra() {
    let (err, partial) = check(LightJson {
        name: "Bulb".into(),
        point: Some([0.3, 0.2, 2.5]),
        intensity: Some([10.0; 3]),
        radius: Some(0.2),
        ..Default::default()
    });
    assert!(err < 1e-9, "{err}");
    assert!(partial > 50, "{partial}");
}

#[test]
fn sphere_light_penumbra() {
    let (err, partial) = check(LightJson {
        name: "Ball".into(),
        point: Some([0.3, 0.2, 2.5]),
        intensity: Some([10.0; 3]),
        radius: Some(0.2),
        sphere: Some(true),
        ..Default::default()
    });
    assert!(err < 1e-9, "{err}");
    assert!(partial > 50, "{partial}");
}

#[test]
fn sun_with_an_angle_penumbra() {
    let (err, partial) = check(LightJson {
        name: "Sun".into(),
        direction: Some([0.4, 0.3, -1.0]),
        irradiance: Some([3.0; 3]),
        angle: Some(5f64.to_radians()),
        ..Default::default()
    });
    assert!(err < 1e-9, "{err}");
    assert!(partial > 50, "{partial}");
}

/// A point light inside a closed room: the walls around it are too large seen from the light
/// for one proxy disc (they take the cube's faces instead), and still every floor vertex gets
/// exactly the disc's visible light.
#[test]
fn soft_point_light_in_a_room() {
    let room = penumbra::scenes::cuboid([-2., -2., 0.], [2., 2., 2.6], true);
    let box_polys = cuboid([-0.5, -0.5, 0.2], [0.5, 0.5, 1.0]);
    let floor = room[0].clone();
    let s = scene(
        vec![
            mesh("Floor", vec![floor]),
            mesh("Walls", room[1..].to_vec()),
            mesh("Box", box_polys.clone()),
        ],
        vec![LightJson {
            name: "Bulb".into(),
            point: Some([0.3, 0.2, 2.0]),
            intensity: Some([10.0; 3]),
            radius: Some(0.2),
            ..Default::default()
        }],
        settings(),
    );
    let sc = penumbra::scene::validate(&s).unwrap();
    let b = bake(&s);
    let occ: Vec<Vec<DVec3>> = box_polys
        .iter()
        .chain(&room[1..])
        .map(|p| p.iter().map(|v| DVec3::from_array(*v)).collect())
        .collect();
    let blockers: Vec<&[DVec3]> = occ.iter().map(|o| o.as_slice()).collect();
    let kind = &sc.lights[0].kind;
    let (mut worst, mut peak) = (0.0f64, 0.0f64);
    for (v, c) in b.meshes[0].positions.iter().zip(&b.meshes[0].colors) {
        let p = DVec3::from_array(*v);
        let e = |rel, b: &[&[DVec3]]| floor_light(kind, p, rel, b);
        peak = peak.max(e(Relation::Lit, &[]) / PI);
        worst = worst.max((c[0] - e(Relation::Penumbra, &blockers) / PI).abs());
    }
    assert!(worst < 1e-9 * peak, "{}", worst / peak);
    assert!(b.meshes[0].relation.iter().any(|r| r[0] == 2));
}

#[test]
fn a_sun_angle_or_a_sphere_where_it_does_not_belong_is_refused() {
    let bad = [
        LightJson {
            name: "S".into(),
            direction: Some([0., 0., -1.]),
            irradiance: Some([1.0; 3]),
            angle: Some(4.0),
            ..Default::default()
        },
        LightJson {
            name: "S".into(),
            point: Some([0., 0., 1.]),
            intensity: Some([1.0; 3]),
            angle: Some(0.1),
            ..Default::default()
        },
        LightJson {
            name: "S".into(),
            point: Some([0., 0., 1.]),
            intensity: Some([1.0; 3]),
            sphere: Some(true),
            ..Default::default()
        },
    ];
    for (l, field) in bad.into_iter().zip(["angle", "angle", "sphere"]) {
        let s = scene(
            vec![mesh("Floor", vec![quad([0., 0., 0.], 1., 1., true)])],
            vec![l],
            settings(),
        );
        let e = penumbra::scene::validate(&s).unwrap_err().to_string();
        assert!(e.contains(field), "{e}");
    }
}

/// The bench's scene of round lights in an unbaked room: the walls get no triangles, and
/// every light casts a penumbra on the outputs.
#[test]
fn the_mixed_bench_scene_bakes() {
    let mut s = penumbra::scenes::by_name("mixed").expect("built-in");
    s.settings.indirect = Some(false);
    let b = bake(&s);
    assert_eq!(b.meshes[0].name, "Room");
    assert!(b.meshes[0].triangles.is_empty());
    for li in 0..s.lights.len() {
        assert!(
            b.meshes[1..]
                .iter()
                .any(|m| m.relation.iter().any(|r| r[li] == 2)),
            "light {li} casts no penumbra"
        );
    }
}
