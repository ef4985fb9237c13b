//! A uniform world (issue 14): light from every direction that no face hides, `E = π·L·(1 −
//! occlusion)`. An open floor gets exactly `π·L`; beside a wall, `π·L` minus what the wall
//! hides, which is Lambert's exact factor to the wall polygon.

mod common;
use common::*;
use glam::DVec3;
use penumbra::geom::lambert::polygon_irradiance;
use penumbra::scene::json::SettingsJson;

fn settings(world: [f64; 3]) -> SettingsJson {
    SettingsJson {
        indirect: Some(false),
        lighting_only: Some(true),
        world: Some(world),
        ..Default::default()
    }
}

#[test]
fn open_floor_under_a_world_gets_its_radiance() {
    // No lights at all: the world alone is a valid light.
    let s = scene(
        vec![mesh("Floor", vec![quad([0., 0., 0.], 2., 2., true)])],
        vec![],
        settings([0.2, 0.3, 0.4]),
    );
    let b = bake(&s);
    for c in &b.meshes[0].colors {
        // Lighting only is E/π = L.
        for (got, want) in c.iter().zip([0.2, 0.3, 0.4]) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
    }
}

#[test]
fn a_wall_hides_its_own_view_factor_of_the_world() {
    // A 4 × 2 wall standing at y = 0.5 facing −y; floor points in front of it.
    let wall = vec![[-2., 0.5, 0.], [-2., 0.5, 2.], [2., 0.5, 2.], [2., 0.5, 0.]];
    let wall3: Vec<DVec3> = wall.iter().map(|p| DVec3::from_array(*p)).collect();
    let s = scene(
        vec![
            mesh("Floor", vec![quad([0., -1., 0.], 2., 1.5, true)]),
            mesh("Wall", vec![wall]),
        ],
        vec![],
        SettingsJson {
            visibility_rays: Some(256),
            ..settings([1.0, 1.0, 1.0])
        },
    );
    let b = bake(&s);
    let f = &b.meshes[0];
    let mut worst: f64 = 0.0;
    let mut n = 0;
    for (v, c) in f.positions.iter().zip(&f.colors) {
        let p = DVec3::from_array(*v);
        // Away from the floor's rim and the wall's foot, where the factor changes fast.
        if p.y > 0.25 || p.x.abs() > 1.0 || p.y < -2.0 {
            continue;
        }
        let hidden = polygon_irradiance(p, DVec3::Z, &wall3) / std::f64::consts::PI;
        let want = 1.0 - hidden;
        worst = worst.max((c[0] - want).abs());
        n += 1;
    }
    // 1,024 fixed directions: a quadrature, accurate to a few tenths of a percent here.
    assert!(n > 50);
    assert!(worst < 0.01, "{worst}");
}

#[test]
fn bad_world_is_refused_on_one_line() {
    let s = scene(
        vec![mesh("Floor", vec![quad([0., 0., 0.], 2., 2., true)])],
        vec![],
        settings([f64::NAN, 0.0, 0.0]),
    );
    let e = penumbra::scene::validate(&s).unwrap_err().to_string();
    assert!(e.contains("world") && !e.contains('\n'), "{e}");
}
