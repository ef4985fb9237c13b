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
use penumbra::scene::json::{PerPolygon, SettingsJson};

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
