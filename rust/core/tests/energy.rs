//! Energy in a closed room: every watt the light emits is absorbed somewhere, so the power the
//! surfaces absorb, Σ (1 − ρ)·E·A over the bake's triangles, must be the light's π·L·A.
//! Regression: with four table legs standing in a room (room-78's, without the top) the bake
//! absorbed 101.5 % of it. A pair of nodes whose decision rays all passed was kept with
//! visibility 1, so a leg in its shaft was missed there while the leg took its own share of
//! the same light; pairs whose first rays were all blocked were dropped, though 12.5 % visible
//! on average. The empty room absorbs 99.9 % (the linear interpolation of a concave field
//! lies a little under it), which bounds how close the sum can come.

mod common;

use common::*;
use glam::DVec3;
use penumbra::scene::json::{PerPolygon, SceneJson, SettingsJson};

/// Power absorbed over power emitted, per channel, for a room of albedo 0.75 with legs of
/// albedo 0.55 under a 0.6 × 0.6 ceiling light.
fn absorbed_share(legs: &[[f64; 2]]) -> [f64; 3] {
    let mut room = mesh(
        "Room",
        cuboid([-2.0, -2.0, 0.0], [2.0, 2.0, 2.6])
            .into_iter()
            .map(|mut p| {
                p.reverse();
                p
            })
            .collect(),
    );
    room.albedo = Some(PerPolygon::Uniform([0.75; 3]));
    let mut meshes = vec![room];
    for (i, &[x, y]) in legs.iter().enumerate() {
        let mut leg = mesh(
            &format!("Leg{i}"),
            cuboid([x - 0.03, y - 0.03, 0.0], [x + 0.03, y + 0.03, 0.7]),
        );
        leg.albedo = Some(PerPolygon::Uniform([0.55; 3]));
        meshes.push(leg);
    }
    let light = area_light("Lamp", quad([0.3, 0.2, 2.55], 0.3, 0.3, false));
    let power = std::f64::consts::PI * 0.36;
    let albedo = [0.75, 0.55];
    let s = scene(meshes, vec![light], SettingsJson::default());
    let baked = bake(&s);
    let mut absorbed = [0.0; 3];
    for (m, bm) in baked.meshes.iter().enumerate() {
        let rho = albedo[m.min(1)];
        for t in &bm.triangles {
            let a = tri_area(&bm.positions, *t);
            for (c, sum) in absorbed.iter_mut().enumerate() {
                let radiance = t.iter().map(|&v| bm.colors[v as usize][c]).sum::<f64>() / 3.0;
                // Outgoing radiance ρ·E/π: E = π·radiance/ρ.
                *sum += (1.0 - rho) * std::f64::consts::PI * radiance / rho * a;
            }
        }
    }
    absorbed.map(|x| x / power)
}

#[test]
fn a_closed_room_with_legs_absorbs_what_its_light_emits() {
    let empty = absorbed_share(&[]);
    let legs = absorbed_share(&[[-0.55, -0.35], [0.55, -0.35], [0.55, 0.35], [-0.55, 0.35]]);
    eprintln!("absorbed / emitted: empty {empty:?}, legs {legs:?}");
    // Measured: empty 0.9988, with the legs 0.9967 (1.0145 before the second look).
    for x in empty.into_iter().chain(legs) {
        assert!((x - 1.0).abs() < 0.005, "{x}");
    }
}

/// Power absorbed over power emitted, per channel, for a built-in scene lit by polygon
/// lights alone, baked with `lighting_only` (colours E/π).
fn absorbed_in(mut s: SceneJson) -> [f64; 3] {
    s.settings.lighting_only = Some(true);
    let mut power = DVec3::ZERO;
    for l in &s.lights {
        let p: Vec<DVec3> = l
            .polygon
            .as_ref()
            .expect("polygon lights")
            .iter()
            .map(|&x| DVec3::from_array(x))
            .collect();
        power +=
            DVec3::from_array(l.radiance.expect("radiance")) * (std::f64::consts::PI * area3(&p));
    }
    // Each polygon's albedo as the bake takes it (defaults included), from its faces.
    let sc = penumbra::scene::validate(&s).expect("valid scene");
    let albedo: std::collections::HashMap<(u32, u32), DVec3> = sc
        .faces
        .iter()
        .map(|f| ((f.mesh, f.source_polygon), f.albedo))
        .collect();
    let baked = bake(&s);
    let mut absorbed = DVec3::ZERO;
    for (m, bm) in baked.meshes.iter().enumerate() {
        for (t, &poly) in bm.triangles.iter().zip(&bm.source_polygon) {
            let rho = albedo[&(m as u32, poly)];
            let e = t
                .iter()
                .map(|&v| DVec3::from_array(bm.colors[v as usize]))
                .sum::<DVec3>()
                * (std::f64::consts::PI / 3.0);
            absorbed += (DVec3::ONE - rho) * e * tri_area(&bm.positions, *t);
        }
    }
    (absorbed / power).to_array()
}

/// Regression: a cluster link sends all its faces' light with one visibility, and among
/// boxes standing close together that mean was mostly their sides', hidden by the boxes
/// beside them: the lit tops passed on too little to the room (room-78's largest box top
/// sent 0.59 of its light to the room where rays from it found 0.92). A partly hidden
/// cluster source is now split before its receiver, and looks weigh their segments by how
/// bright their source end is.
#[test]
fn clutter_on_a_table_passes_on_its_light() {
    let got = absorbed_in(penumbra::scenes::by_name("room-78").expect("built in"));
    eprintln!("absorbed / emitted: {got:?}");
    // Measured: 0.99634, 0.99625, 0.99558 (before: 0.99554, 0.99526, 0.99445).
    for x in got {
        assert!(x > 0.9950 && x < 1.0, "{x}");
    }
}
