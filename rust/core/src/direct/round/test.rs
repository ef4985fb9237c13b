//! Round lights partly hidden: values fixed by symmetry.

use std::f64::consts::PI;

use glam::DVec3;

use super::*;
use crate::scene::disc::facing;
use crate::scene::settings::PenumbraVisibility::{Exact, Sampled};
use Relation::{Lit, Penumbra};

/// A half-plane x < 0 at height `z`, wide enough to hide the half of any disc above it.
fn half_plane(z: f64) -> Vec<DVec3> {
    [(-50.0, -50.0), (0.0, -50.0), (0.0, 50.0), (-50.0, 50.0)]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, z))
        .collect()
}

fn eval(kind: &LightKind, p: DVec3, rel: Relation, blockers: &[&[DVec3]], exact: bool) -> DVec3 {
    let disc = facing(kind, p, 20.0).unwrap();
    let mode = if exact { Exact } else { Sampled };
    round_light(p, DVec3::Z, kind, &disc, rel, blockers, mode, 4096)
}

#[test]
fn an_edge_through_the_axis_hides_half_of_a_round_light() {
    let lights = [
        LightKind::Point {
            position: DVec3::new(0.0, 0.0, 2.0),
            intensity: DVec3::ONE,
            spot: None,
            radius: 0.2,
            sphere: false,
        },
        LightKind::Point {
            position: DVec3::new(0.0, 0.0, 2.0),
            intensity: DVec3::ONE,
            spot: None,
            radius: 0.2,
            sphere: true,
        },
        LightKind::Sun {
            direction: -DVec3::Z,
            irradiance: DVec3::ONE,
            half_angle: 2.5f64.to_radians(),
        },
    ];
    let occ = half_plane(1.0);
    let far = half_plane(-1.0); // below the receiver: hides nothing
    let p = DVec3::ZERO;
    for kind in &lights {
        let lit = eval(kind, p, Lit, &[], true).x;
        let want = match kind {
            LightKind::Point { sphere: true, .. } => 1.0 / 4.0,
            LightKind::Point { .. } => 1.0 / (4.0 + 0.04),
            _ => 1.0,
        };
        assert!((lit - want).abs() < 1e-12, "{lit} {want}");
        let half = eval(kind, p, Penumbra, &[&occ], true).x;
        assert!((half - 0.5 * want).abs() < 1e-9 * want, "{half}");
        let none = eval(kind, p, Penumbra, &[&far], true).x;
        assert!((none - want).abs() < 1e-12 * want, "{none}");
        let sampled = eval(kind, p, Penumbra, &[&occ], false).x;
        assert!((sampled - 0.5 * want).abs() < 0.01 * want, "{sampled}");
        // Deep in the shadow: nothing.
        let deep = eval(kind, DVec3::new(-1.0, 0.0, 0.0), Penumbra, &[&occ], true).x;
        assert!(deep == 0.0, "{deep}");
        let _ = PI;
    }
}

#[test]
fn the_penumbra_grows_with_the_radius() {
    // Under the edge of a half-plane at height 1, a point light at height 2: the penumbra on
    // the floor is |x| ≤ r (similar triangles, both heights halve the distance).
    let occ = half_plane(1.0);
    for r in [0.1, 0.3] {
        let kind = LightKind::Point {
            position: DVec3::new(0.0, 0.0, 2.0),
            intensity: DVec3::ONE,
            spot: None,
            radius: r,
            sphere: false,
        };
        let inside = eval(
            &kind,
            DVec3::new(0.9 * r, 0.0, 0.0),
            Penumbra,
            &[&occ],
            true,
        )
        .x;
        let lit = eval(&kind, DVec3::new(0.9 * r, 0.0, 0.0), Lit, &[], true).x;
        assert!(inside > 0.9 * lit && inside < lit, "{inside} {lit}");
        let out = eval(
            &kind,
            DVec3::new(1.1 * r, 0.0, 0.0),
            Penumbra,
            &[&occ],
            true,
        )
        .x;
        let lit_out = eval(&kind, DVec3::new(1.1 * r, 0.0, 0.0), Lit, &[], true).x;
        assert!((out - lit_out).abs() < 1e-12, "{out} {lit_out}");
        let umbra = eval(
            &kind,
            DVec3::new(-1.1 * r, 0.0, 0.0),
            Penumbra,
            &[&occ],
            true,
        )
        .x;
        assert_eq!(umbra, 0.0);
    }
}

/// A hard 30° cone from (0, 0, 2) straight down, from a disc of radius 0.1: its apex, cone
/// and light.
fn hard_spot_30() -> (DVec3, crate::scene::Spot, LightKind) {
    let apex = DVec3::new(0.0, 0.0, 2.0);
    let spot = crate::scene::Spot {
        direction: -DVec3::Z,
        cos_half_angle: 30f64.to_radians().cos(),
        blend: 0.0,
    };
    let kind = LightKind::Point {
        position: apex,
        intensity: DVec3::ONE,
        spot: None,
        radius: 0.1,
        sphere: false,
    };
    (apex, spot, kind)
}

#[test]
fn a_round_spot_blurs_its_cone_edge_over_the_disc() {
    let (apex, spot, kind) = hard_spot_30();
    let at = |x: f64| {
        let p = DVec3::new(x, 0.0, 0.0);
        let disc = facing(&kind, p, 20.0).unwrap();
        let all = eval(&kind, p, Lit, &[], true).x;
        let e = round_spot(p, DVec3::Z, &kind, &disc, &spot, apex, Lit, &[], Exact, 0).x;
        e / all
    };
    let edge = 2.0 * 30f64.to_radians().tan();
    // Far inside and outside: the mask itself, no quadrature.
    assert!((at(0.5 * edge) - 1.0).abs() < 1e-15);
    assert_eq!(at(1.5 * edge), 0.0);
    // On the edge the cone's boundary halves the disc (nearly: it is a conic, not a line).
    let half = at(edge);
    assert!((half - 0.5).abs() < 0.02, "{half}");
    // Monotone across the blurred band.
    let xs: Vec<f64> = (0..21)
        .map(|k| at(edge * (0.85 + 0.015 * k as f64)))
        .collect();
    assert!(xs.windows(2).all(|w| w[1] <= w[0]), "{xs:?}");
    assert!(xs[0] > 0.99 && xs[20] < 0.01, "{xs:?}");
}

#[test]
fn a_shadow_edge_across_a_round_spot_s_cone_edge() {
    // Hard cone of 30° from (0, 0, 2) straight down; from the point on its edge the disc's
    // outer half (x > 0) is inside the cone (its directions to p are steeper), and a half-plane
    // at height 1 through the line of sight hides exactly that half: almost nothing is left,
    // where the product of the two halves would give a quarter.
    let (apex, spot, kind) = hard_spot_30();
    let edge = 2.0 * 30f64.to_radians().tan();
    let p = DVec3::new(edge, 0.0, 0.0);
    let occ: Vec<DVec3> = [
        (0.5 * edge, -50.0),
        (50.0, -50.0),
        (50.0, 50.0),
        (0.5 * edge, 50.0),
    ]
    .iter()
    .map(|&(x, y)| DVec3::new(x, y, 1.0))
    .collect();
    let disc = facing(&kind, p, 20.0).unwrap();
    let all = eval(&kind, p, Lit, &[], true).x;
    let e = round_spot(
        p,
        DVec3::Z,
        &kind,
        &disc,
        &spot,
        apex,
        Penumbra,
        &[&occ],
        Exact,
        0,
    )
    .x;
    assert!(e / all < 0.05, "{}", e / all);
}
