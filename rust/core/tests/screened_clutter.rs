//! Clutter on a table under an area light: the table top screens most boxes from the floor
//! (their shadow polygons there are left out), nested umbrae are cut from the arrangement
//! and nested hidden parts from the visible-light boolean. None of that may change a light
//! value or a relation code: floor vertices are compared with the exact visible light
//! computed from every face of the scene as a blocker, and the relations with visibility
//! sampling.

mod common;
use common::*;
use glam::DVec3;
use penumbra::direct::exact::area_light as exact_area_light;
use penumbra::geom::Plane;
use penumbra::regions::relation::Relation;
use penumbra::scene::json::SettingsJson;
use penumbra::scene::settings::PenumbraVisibility;
use std::f64::consts::PI;

fn clutter_scene() -> penumbra::SceneJson {
    let mut clutter = Vec::new();
    // Middle of the table (screened), over its edge (not screened: its shadow passes beside
    // the top), overlapping one another, and one tall enough to shade its neighbours.
    for (lo, hi) in [
        ([-0.1, -0.1, 0.75], [0.0, 0.0, 0.85]),
        ([-0.05, -0.05, 0.75], [0.05, 0.02, 0.8]),
        ([0.55, 0.1, 0.75], [0.65, 0.2, 0.82]),
        ([-0.3, 0.2, 0.75], [-0.25, 0.25, 1.0]),
        ([-0.35, 0.18, 0.75], [-0.28, 0.3, 0.78]),
    ] {
        clutter.extend(cuboid(lo, hi));
    }
    let mut light = area_light("Lamp", quad([0.2, 0.1, 2.5], 0.3, 0.3, false));
    light.radiance = Some([2.0; 3]);
    scene(
        vec![
            mesh("Floor", vec![quad([0.0, 0.0, 0.0], 2.0, 2.0, true)]),
            mesh("Table", cuboid([-0.6, -0.4, 0.7], [0.6, 0.4, 0.75])),
            mesh("Clutter", clutter),
        ],
        vec![light],
        SettingsJson {
            indirect: Some(false),
            lighting_only: Some(true),
            // The light at the vertices themselves, which screening must not change.
            vertex_values: Some("exact".into()),
            ..Default::default()
        },
    )
}

#[test]
fn floor_light_matches_all_faces_as_blockers() {
    let s = clutter_scene();
    let b = bake(&s);
    let lv: Vec<DVec3> = s.lights[0]
        .polygon
        .as_ref()
        .unwrap()
        .iter()
        .map(|v| DVec3::from_array(*v))
        .collect();
    let plane = Plane::from_polygon(&lv).unwrap();
    let faces: Vec<Vec<DVec3>> = s.meshes[1..]
        .iter()
        .flat_map(|m| {
            m.polygons.iter().map(|p| {
                p.iter()
                    .map(|&i| DVec3::from_array(m.positions[i as usize]))
                    .collect()
            })
        })
        .collect();
    let blockers: Vec<&[DVec3]> = faces.iter().map(|f| f.as_slice()).collect();
    let floor = &b.meshes[0];
    let (mut worst, mut shaded) = (0.0f64, 0);
    let top = floor.colors.iter().fold(0.0f64, |m, c| m.max(c[0]));
    for (p, c) in floor.positions.iter().zip(&floor.colors) {
        let p = DVec3::from_array(*p);
        let e = exact_area_light(
            p,
            DVec3::Z,
            &lv,
            &plane,
            DVec3::splat(2.0),
            Relation::Penumbra,
            &blockers,
            PenumbraVisibility::Exact,
            0,
        );
        let want = e.x / PI;
        let unoccluded = exact_area_light(
            p,
            DVec3::Z,
            &lv,
            &plane,
            DVec3::splat(2.0),
            Relation::Lit,
            &[],
            PenumbraVisibility::Exact,
            0,
        )
        .x / PI;
        if want < unoccluded * (1.0 - 1e-6) {
            shaded += 1;
        }
        worst = worst.max((c[0] - want).abs() / top);
    }
    assert!(shaded > 100, "only {shaded} shaded floor vertices");
    assert!(
        worst < 1e-9,
        "floor light off by {worst:e} of the brightest vertex"
    );
}

#[test]
fn relations_match_sampled_visibility() {
    let s = clutter_scene();
    let b = bake(&s);
    let checked = check_relations(&s, &b, 7);
    assert!(checked.iter().sum::<usize>() > 0, "{checked:?}");
}
