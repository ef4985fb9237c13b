//! Thin surfaces reflect from both sides (issue 14): a single plane lit from behind sends
//! that light on into the half-space behind it, as Cycles' two-sided diffuse surfaces do.
//!
//! The scene has a closed form: a black floor under a large plane facing up, and a sun
//! shining up through the gap at angle θ. Only the plane's back is lit, `E·cos θ` outside
//! the floor's own shadow (the floor shifted by tan θ), so it leaves with radiance
//! `ρ·E·cos θ / π` there and nothing in the shadow. The floor gets that through Lambert's
//! exact factors to the plane and to the shadow rectangle, and nothing else: the floor
//! is black, so no light goes round twice.
//!
//! Each test runs with both indirect solvers (`SOLVERS`), to the same bounds.

mod common;
use common::*;
use penumbra::scene::json::{LightJson, SettingsJson};

const THETA: f64 = 0.3;
const RHO: f64 = 0.8;
const SUN: f64 = 3.0;
/// Half-sizes: the plane at height 1, the floor at 0.
const PLANE: f64 = 3.0;
const FLOOR: f64 = 0.5;
/// The indirect solvers, as `settings.indirect_solver` names them.
const SOLVERS: [Option<&str>; 2] = [Some("progressive"), Some("hierarchical")];

fn sun() -> LightJson {
    LightJson {
        name: "Sun".into(),
        direction: Some([THETA.sin(), 0.0, THETA.cos()]),
        irradiance: Some([SUN; 3]),
        ..Default::default()
    }
}

fn settings(patch_size: f64, solver: Option<&str>) -> SettingsJson {
    SettingsJson {
        indirect: Some(true),
        indirect_solver: solver.map(String::from),
        lighting_only: Some(true),
        patch_size: Some(patch_size),
        element_size: Some(0.1),
        ..Default::default()
    }
}

fn floor() -> penumbra::scene::json::MeshJson {
    let mut floor = mesh("Floor", vec![quad([0., 0., 0.], FLOOR, FLOOR, true)]);
    floor.albedo = Some(penumbra::scene::json::PerPolygon::Uniform([0.0; 3]));
    floor
}

/// What the floor shows (E/π) at (x, y): the plane's back minus the floor's shadow on it.
fn expected(x: f64, y: f64) -> f64 {
    let radiance = RHO * SUN * THETA.cos() / std::f64::consts::PI;
    let shift = THETA.tan();
    let plane = rect(x, y, [-PLANE, PLANE, -PLANE, PLANE], 1.0);
    let shadow = rect(x, y, [-FLOOR + shift, FLOOR + shift, -FLOOR, FLOOR], 1.0);
    radiance * (plane - shadow) / std::f64::consts::PI
}

/// The floor's worst relative error against `expected` over its vertices, and the mean of
/// `expected` there.
fn floor_error(b: &penumbra::Bake) -> (f64, f64) {
    let f = &b.meshes[0];
    let want: Vec<f64> = f.positions.iter().map(|p| expected(p[0], p[1])).collect();
    let mean = want.iter().sum::<f64>() / want.len() as f64;
    let worst = f
        .colors
        .iter()
        .zip(&want)
        .map(|(c, w)| (c[0] - w).abs() / mean)
        .fold(0.0, f64::max);
    (worst, mean)
}

#[test]
fn plane_lit_from_behind_lights_the_floor_from_its_back() {
    for solver in SOLVERS {
        let mut plane = mesh("Plane", vec![quad([0., 0., 1.], PLANE, PLANE, true)]);
        plane.albedo = Some(penumbra::scene::json::PerPolygon::Uniform([RHO; 3]));
        let s = scene(vec![floor(), plane], vec![sun()], settings(0.1, solver));
        let b = bake(&s);
        let (worst, mean) = floor_error(&b);
        eprintln!(
            "{solver:?} plane from behind: floor mean {mean:.5}, worst error {worst:.4} of it"
        );
        assert!(mean > 0.05, "{solver:?} {mean}");
        assert!(worst < 0.02, "{solver:?} {worst}");
        // Cycles bakes the front only, and so do we: the plane's front sees no light.
        assert!(b.meshes[1].colors.iter().all(|c| c[0] == 0.0), "{solver:?}");
    }
}

/// A closed box reflects from its front only: the same light on its underside (a front,
/// facing down) gives the floor the same as the plane's back; its top's back, inside the
/// box, sends nothing.
#[test]
fn closed_box_reflects_from_its_outside_only() {
    for solver in SOLVERS {
        let mut slab = mesh("Slab", cuboid([-PLANE, -PLANE, 1.0], [PLANE, PLANE, 1.2]));
        slab.albedo = Some(penumbra::scene::json::PerPolygon::Uniform([RHO; 3]));
        let s = scene(vec![floor(), slab], vec![sun()], settings(0.1, solver));
        let b = bake(&s);
        let (worst, mean) = floor_error(&b);
        eprintln!("{solver:?} box from below: floor mean {mean:.5}, worst error {worst:.4} of it");
        assert!(worst < 0.02, "{solver:?} {worst}");
    }
}

/// A box standing on the plane covers the plane's front under it (`coplanar_contacts`),
/// not its back: the floor under the plane gets the same light with or without the box.
#[test]
fn a_box_on_the_plane_covers_its_front_not_its_back() {
    let plane = || {
        let mut p = mesh("Plane", vec![quad([0., 0., 1.], PLANE, PLANE, true)]);
        p.albedo = Some(penumbra::scene::json::PerPolygon::Uniform([RHO; 3]));
        p
    };
    for solver in SOLVERS {
        let without = bake(&scene(
            vec![floor(), plane()],
            vec![sun()],
            settings(0.2, solver),
        ));
        let stand = mesh("Box", cuboid([0.0, -0.6, 1.0], [0.8, 0.6, 1.5]));
        let with = bake(&scene(
            vec![floor(), plane(), stand],
            vec![sun()],
            settings(0.2, solver),
        ));
        let (a, b) = (&without.meshes[0], &with.meshes[0]);
        assert_eq!(a.positions, b.positions);
        let top = a.colors.iter().map(|c| c[0]).fold(0.0, f64::max);
        assert!(top > 0.0, "{solver:?}");
        let diff = a
            .colors
            .iter()
            .zip(&b.colors)
            .map(|(x, y)| (x[0] - y[0]).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{solver:?} box on plane: largest difference {:.2e} of the brightest",
            diff / top
        );
        for (x, y) in a.colors.iter().zip(&b.colors) {
            assert!((x[0] - y[0]).abs() <= 1e-3 * top, "{solver:?} {x:?} {y:?}");
        }
    }
}
