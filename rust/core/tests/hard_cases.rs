//! The hard cases of the issue, each its own test: every one must bake without panicking,
//! cover each input polygon exactly, and give relation codes that exact visibility confirms.

mod common;
use common::*;
use penumbra::scene::json::SettingsJson;

fn settings(h: f64) -> SettingsJson {
    SettingsJson {
        element_size: Some(h),
        penumbra_element_size: Some(h / 4.0),
        indirect: Some(false),
        ..Default::default()
    }
}

fn check(s: &penumbra::SceneJson) -> penumbra::Bake {
    let b = bake(s);
    check_coverage(s, &b);
    check_relations(s, &b, 0);
    b
}

fn floor() -> penumbra::scene::json::MeshJson {
    mesh("Floor", vec![quad([0., 0., 0.], 2., 2., true)])
}

#[test]
fn contact_shadow_splits_vertex_rows() {
    // A box standing on the floor, lit from the side so light reaches right up to its foot.
    let s = scene(
        vec![
            floor(),
            mesh("Box", cuboid([-0.3, -0.3, 0.0], [0.3, 0.3, 0.6])),
        ],
        vec![area_light("L", quad([1.0, 0.2, 1.5], 0.3, 0.3, false))],
        settings(0.3),
    );
    let b = check(&s);
    let fl = &b.meshes[0];
    // Vertices on the box's foot come in pairs (one per side) where light meets shadow.
    let dup = duplicated(fl);
    assert!(
        dup >= 4,
        "expected duplicated vertices along the contact line, got {dup}"
    );
}

#[test]
fn occluder_edge_parallel_and_nearly_parallel_to_light_edge() {
    for angle in [0.0f64, 1e-9, 1e-6] {
        let (c, si) = (angle.cos(), angle.sin());
        let occ: Vec<[f64; 3]> = quad([0., 0., 1.], 0.4, 0.4, true)
            .into_iter()
            .map(|p| [p[0] * c - p[1] * si, p[0] * si + p[1] * c, p[2]])
            .collect();
        let s = scene(
            vec![floor(), mesh("Occ", vec![occ])],
            vec![area_light("L", quad([0., 0., 2.], 0.5, 0.5, false))],
            settings(0.3),
        );
        check(&s);
    }
}

#[test]
fn tiny_light() {
    // Light 1e-3 of the occluder's size.
    let s = scene(
        vec![
            floor(),
            mesh("Occ", vec![quad([0., 0., 1.], 0.5, 0.5, true)]),
        ],
        vec![area_light("L", quad([0.1, 0., 2.], 5e-4, 5e-4, false))],
        settings(0.3),
    );
    let b = check(&s);
    let codes: std::collections::HashSet<u8> = b.meshes[0].relation.iter().map(|r| r[0]).collect();
    assert!(codes.contains(&1) && codes.contains(&2) && codes.contains(&3));
}

#[test]
fn slivers_and_zero_area_polygons() {
    let mut m = mesh(
        "Occ",
        vec![
            vec![[-0.5, 0.0, 1.0], [0.5, 0.0, 1.0], [0.5, 1e-7, 1.0]],
            vec![[0., 0., 1.2], [0.3, 0., 1.2], [0.3, 0., 1.2]],
        ],
    );
    // A collinear polygon too.
    m.positions
        .extend([[0., 0., 0.5], [0.1, 0.1, 0.5], [0.2, 0.2, 0.5]]);
    m.polygons.push(vec![6, 7, 8]);
    let s = scene(
        vec![floor(), m],
        vec![area_light("L", quad([0., 0., 2.], 0.5, 0.5, false))],
        settings(0.3),
    );
    let sc = penumbra::scene::validate(&s).unwrap();
    assert!(
        sc.warnings
            .iter()
            .any(|w| w.contains("dropped 2 degenerate")),
        "{:?}",
        sc.warnings
    );
    let b = bake(&s);
    check_relations(&s, &b, 0);
    // The sliver is baked (its shadow is a thin penumbra band).
    assert!(b.meshes[1].triangles.len() >= 1);
    assert!(b.meshes[0].relation.iter().any(|r| r[0] == 2));
}

#[test]
fn coplanar_overlapping_faces() {
    let s = scene(
        vec![
            floor(),
            mesh("Decal", vec![quad([0.2, 0.2, 0.0], 0.5, 0.5, true)]),
            mesh("Occ", vec![quad([0., 0., 1.], 0.3, 0.3, true)]),
        ],
        vec![area_light("L", quad([0., 0., 2.], 0.5, 0.5, false))],
        settings(0.3),
    );
    check(&s);
}

#[test]
fn light_intersecting_an_occluder() {
    // A vertical panel passes through the light.
    let panel = vec![
        [-0.3, 0.0, 0.5],
        [0.3, 0.0, 0.5],
        [0.3, 0.0, 2.5],
        [-0.3, 0.0, 2.5],
    ];
    let s = scene(
        vec![
            floor(),
            mesh(
                "Panel",
                vec![panel.clone(), panel.into_iter().rev().collect()],
            ),
        ],
        vec![area_light("L", quad([0., 0., 2.], 0.5, 0.5, false))],
        settings(0.3),
    );
    check(&s);
}

#[test]
fn twenty_lights() {
    let mut lights = Vec::new();
    for k in 0..20 {
        let a = k as f64 * std::f64::consts::TAU / 20.0;
        lights.push(area_light(
            &format!("L{k}"),
            quad(
                [a.cos() * 1.5, a.sin() * 1.5, 2.0 + 0.05 * k as f64],
                0.1,
                0.15,
                false,
            ),
        ));
    }
    let s = scene(
        vec![
            floor(),
            mesh("Occ", vec![quad([0., 0., 0.8], 0.4, 0.3, true)]),
        ],
        lights,
        settings(0.4),
    );
    let b = check(&s);
    assert!(b.meshes[0].relation.iter().all(|r| r.len() == 20));
}

#[test]
fn fifty_occluders_over_one_receiver() {
    let mut rng = Rng(7);
    let mut polys = Vec::new();
    for _ in 0..50 {
        let c = [
            rng.range(-1.5, 1.5),
            rng.range(-1.5, 1.5),
            rng.range(0.3, 1.2),
        ];
        polys.push(quad(
            c,
            rng.range(0.05, 0.2),
            rng.range(0.05, 0.2),
            rng.next() < 0.5,
        ));
    }
    let s = scene(
        vec![floor(), mesh("Occ", polys)],
        vec![area_light("L", quad([0., 0., 2.5], 0.4, 0.4, false))],
        settings(0.4),
    );
    let b = check(&s);
    assert!(b.stats.N_d > 100);
}
