//! The white furnace through the whole pipeline: a closed box whose faces all have albedo ρ
//! and emission Le, no lights: the radiance is Le / (1 − ρ) everywhere.

mod common;
use common::*;
use penumbra::scene::json::{PerPolygon, SettingsJson};

#[test]
fn closed_emissive_box_reaches_le_over_one_minus_rho() {
    for (rho, le) in [(0.5, 1.0), (0.8, 0.25)] {
        let mut room = mesh(
            "Room",
            cuboid([0., 0., 0.], [1., 1.3, 0.8])
                .into_iter()
                .map(|mut p| {
                    p.reverse();
                    p
                })
                .collect(),
        );
        room.albedo = Some(PerPolygon::Uniform([rho; 3]));
        room.emission = Some(PerPolygon::Uniform([le; 3]));
        let s = scene(
            vec![room],
            vec![],
            SettingsJson {
                convergence: Some(1e-4),
                element_size: Some(0.1),
                ..Default::default()
            },
        );
        let b = bake(&s);
        let want = le / (1.0 - rho);
        let c = &b.meshes[0].colors;
        let worst = c
            .iter()
            .flat_map(|x| x.iter())
            .map(|&x| ((x - want) / want).abs())
            .fold(0.0, f64::max);
        let mean = c.iter().map(|x| x[0]).sum::<f64>() / c.len() as f64;
        assert!(
            worst < 2e-3,
            "rho {rho}: worst relative error {worst:e}, mean {mean} want {want}"
        );
        assert!(b.stats.unshot_fraction < 1e-4);
    }
}
