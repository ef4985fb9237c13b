//! A spot's cone edge is a mesh edge (issue 14): the baked light, interpolated over the
//! output triangles, matches the analytic value within 1 % at points just inside and just
//! outside the edge, for a hard cone (blend 0) and at both ends of a blend band.

mod common;
use common::*;
use glam::{DVec2, DVec3};
use penumbra::scene::json::{LightJson, SettingsJson, SpotJson};
use std::f64::consts::PI;

const APEX: [f64; 3] = [0.2, 0.1, 2.0];

/// The baked value at `p` on the floor (z = 0), linear over the triangle holding it.
fn sample(b: &penumbra::BakedMesh, p: DVec2) -> f64 {
    for t in &b.triangles {
        let v: Vec<DVec2> = t
            .iter()
            .map(|&i| DVec2::new(b.positions[i as usize][0], b.positions[i as usize][1]))
            .collect();
        let d = (v[1] - v[0]).perp_dot(v[2] - v[0]);
        let l1 = (v[2] - v[1]).perp_dot(p - v[1]) / d;
        let l2 = (v[0] - v[2]).perp_dot(p - v[2]) / d;
        let l3 = 1.0 - l1 - l2;
        if l1 >= -1e-12 && l2 >= -1e-12 && l3 >= -1e-12 {
            return l1 * b.colors[t[0] as usize][0]
                + l2 * b.colors[t[1] as usize][0]
                + l3 * b.colors[t[2] as usize][0];
        }
    }
    panic!("{p} is off the floor")
}

/// Where the ray from the apex at angle `psi` from the axis, turned `phi` about it, meets the
/// floor.
fn on_floor(axis: DVec3, psi: f64, phi: f64) -> DVec2 {
    let f = penumbra::geom::Frame::new(DVec3::ZERO, axis);
    let w = axis * psi.cos() + (f.u * phi.cos() + f.v * phi.sin()) * psi.sin();
    let a = DVec3::from_array(APEX);
    let x = a + w * (a.z / -w.z);
    DVec2::new(x.x, x.y)
}

fn bake_spot(blend: f64) -> (penumbra::BakedMesh, DVec3, f64) {
    let axis = DVec3::new(0.2, -0.1, -1.0).normalize();
    let angle = 70f64.to_radians();
    let s = scene(
        vec![mesh("Floor", vec![quad([0., 0., 0.], 3., 3., true)])],
        vec![LightJson {
            name: "Spot".into(),
            point: Some(APEX),
            intensity: Some([10.0; 3]),
            spot: Some(SpotJson {
                direction: axis.to_array(),
                angle,
                blend,
            }),
            ..Default::default()
        }],
        SettingsJson {
            indirect: Some(false),
            lighting_only: Some(true),
            ..Default::default()
        },
    );
    let b = bake(&s);
    (b.meshes[0].clone(), axis, 0.5 * angle)
}

/// Lighting only: I · mask · cos / d² / π with the given mask.
fn analytic(p: DVec2, mask: f64) -> f64 {
    let a = DVec3::from_array(APEX);
    let d = a - DVec3::new(p.x, p.y, 0.0);
    10.0 * mask * (d.z / d.length()) / d.length_squared() / PI
}

#[test]
fn a_hard_cone_edge_is_sharp_on_the_floor() {
    let (floor, axis, half) = bake_spot(0.0);
    // 5 mm either side of the edge, measured along the floor.
    for k in 0..24 {
        let phi = 2.0 * PI * (k as f64 + 0.3) / 24.0;
        let edge = on_floor(axis, half, phi);
        let out_dir = (on_floor(axis, half + 1e-3, phi) - edge).normalize();
        let inside = edge - out_dir * 5e-3;
        let outside = edge + out_dir * 5e-3;
        assert_full_inside_dark_outside(&floor, inside, outside);
    }
}

/// The baked light at `inside` is the unmasked analytic value within 1 %, and at `outside`
/// under 1 % of it.
fn assert_full_inside_dark_outside(floor: &penumbra::BakedMesh, inside: DVec2, outside: DVec2) {
    let want = analytic(inside, 1.0);
    let got = sample(floor, inside);
    assert!(
        (got - want).abs() < 0.01 * want,
        "inside {inside}: {got} vs {want}"
    );
    let got = sample(floor, outside);
    assert!(got.abs() < 0.01 * want, "outside {outside}: {got}");
}

#[test]
fn a_blend_band_has_mesh_edges_at_both_ends() {
    let blend = 0.3;
    let (floor, axis, half) = bake_spot(blend);
    let c = half.cos();
    let inner = (c + (1.0 - c) * blend).acos();
    for k in 0..24 {
        let phi = 2.0 * PI * (k as f64 + 0.3) / 24.0;
        let o = on_floor(axis, half, phi);
        let i = on_floor(axis, inner, phi);
        let dir = (o - i).normalize();
        let (inside, outside) = (i - dir * 5e-3, o + dir * 5e-3);
        assert_full_inside_dark_outside(&floor, inside, outside);
    }
}
