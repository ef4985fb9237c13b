//! The paper's canonical configuration with a known answer: unit light square at z=2,
//! occluder square of side 0.8 at z=1, floor at z=0. By similar triangles the umbra is
//! |x|,|y| ≤ 0.3 and the penumbra reaches |x|,|y| < 1.3.

mod common;
use common::*;

fn square_scene(scale: f64) -> penumbra::SceneJson {
    let s = |v: Vec<[f64; 3]>| {
        v.into_iter()
            .map(|p| p.map(|x| x * scale))
            .collect::<Vec<_>>()
    };
    scene(
        vec![
            mesh("Floor", vec![s(quad([0., 0., 0.], 3., 3., true))]),
            mesh("Occluder", vec![s(quad([0., 0., 1.], 0.4, 0.4, true))]),
        ],
        vec![area_light("Light", s(quad([0., 0., 2.], 0.5, 0.5, false)))],
        Default::default(),
    )
}

fn check_square(scale: f64) {
    let b = bake(&square_scene(scale));
    let floor = &b.meshes[0];
    assert_eq!(floor.name, "Floor");
    assert!(floor.triangles.len() > 100);
    let mut area = [0.0; 4];
    let tol = 1e-9 * scale;
    for (t, tri) in floor.triangles.iter().enumerate() {
        let code = floor.relation[t][0];
        let pts: Vec<[f64; 3]> = tri.iter().map(|&i| floor.positions[i as usize]).collect();
        let max_abs = |p: &[f64; 3]| p[0].abs().max(p[1].abs());
        let (lo, hi) = pts.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
            (lo.min(max_abs(p)), hi.max(max_abs(p)))
        });
        match code {
            3 => assert!(hi <= 0.3 * scale + tol, "umbra triangle reaches {hi}"),
            2 => assert!(
                lo >= 0.3 * scale - tol && hi <= 1.3 * scale + tol,
                "penumbra triangle spans {lo}..{hi}"
            ),
            1 => assert!(lo >= 1.3 * scale - tol, "lit triangle reaches in to {lo}"),
            c => panic!("unexpected relation code {c}"),
        }
        area[code as usize] += tri_area(&floor.positions, *tri);
    }
    let s2 = scale * scale;
    assert!(
        (area[3] - 0.36 * s2).abs() < 1e-9 * s2,
        "umbra area {}",
        area[3]
    );
    assert!(
        (area[2] - (2.6f64.powi(2) - 0.36) * s2).abs() < 1e-9 * s2,
        "penumbra area {}",
        area[2]
    );
    assert!(
        (area[1] - (36.0 - 2.6f64.powi(2)) * s2).abs() < 1e-9 * s2,
        "lit area {}",
        area[1]
    );
    // The occluder's top faces the light: lit.
    assert!(b.meshes[1].relation.iter().all(|r| r[0] == 1));
    // Penumbra elements are never coarser than lit ones (both shrink near the light).
    let mean = |code: u8| {
        let (s, n) = floor
            .triangles
            .iter()
            .zip(&floor.relation)
            .filter(|(_, r)| r[0] == code)
            .fold((0.0, 0), |(s, n), (t, _)| {
                (s + tri_area(&floor.positions, *t), n + 1)
            });
        s / n as f64
    };
    assert!(
        mean(2) <= mean(1),
        "penumbra {} vs lit {}",
        mean(2),
        mean(1)
    );
}

#[test]
fn square_over_floor() {
    check_square(1.0);
}

#[test]
fn square_over_floor_tiny_and_huge() {
    check_square(1e-3);
    check_square(1e4);
}
