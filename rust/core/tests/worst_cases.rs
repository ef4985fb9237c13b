//! Small inputs that used to take minutes (issue 15, `scripts/worst_cases.py`), scaled down,
//! with the bounds that keep them small: what each bound promises, in values.

mod common;
use common::*;
use glam::DVec3;
use penumbra::direct::exact::area_light as exact_area_light;
use penumbra::geom::Plane;
use penumbra::regions::relation::Relation;
use penumbra::scene::json::SettingsJson;
use penumbra::scene::settings::PenumbraVisibility;
use std::f64::consts::{PI, TAU};

fn settings() -> SettingsJson {
    SettingsJson {
        indirect: Some(false),
        lighting_only: Some(true),
        ..Default::default()
    }
}

/// The worst-case scripts' light: 0.6 × 0.6 at height 3, facing down, radiance 1.
fn lamp() -> Vec<[f64; 3]> {
    quad([0., 0., 3.], 0.3, 0.3, false)
}

fn disk(n: usize, r: f64, z: f64) -> Vec<[f64; 3]> {
    (0..n)
        .map(|k| {
            let a = TAU * k as f64 / n as f64;
            [r * a.cos(), r * a.sin(), z]
        })
        .collect()
}

/// A 400-gon disk over a floor: its shadow is that of its simplified outline
/// (`geom::simplify`, within 1e-3 of its size), both in the mesh and in the light. At every
/// floor vertex the baked light differs from the exact one (the exact 400-gon subtracted from
/// the light) by less than the band between the two outlines can hide: that band is at most
/// δ = 1e-3 · 1.2 wide, k = 3 times wider seen on the light from the floor (light at 3,
/// disk at 1), and lies along a convex curve, which inside the light is no longer than the
/// light's perimeter P = 2.4; so it hides at most k·δ·P = 8.6e-3 of the light's area A =
/// 0.36, 2.4 % of it, times the integrand's spread over the light (under 1.3 here).
#[test]
fn a_many_edged_occluder_changes_the_light_by_less_than_its_simplification_band() {
    let occluder = disk(400, 0.6, 1.0);
    let s = scene(
        vec![
            mesh("Floor", vec![quad([0., 0., 0.], 2., 2., true)]),
            mesh("Disk", vec![occluder.clone()]),
        ],
        vec![area_light("Lamp", lamp())],
        settings(),
    );
    let b = bake(&s);
    let light: Vec<DVec3> = lamp().into_iter().map(DVec3::from).collect();
    let plane = Plane::from_polygon(&light).unwrap();
    let occ: Vec<DVec3> = occluder.into_iter().map(DVec3::from).collect();
    let floor = &b.meshes[0];
    let (mut worst, mut penumbra) = (0.0f64, 0);
    for (p, c) in floor.positions.iter().zip(&floor.colors) {
        let p = DVec3::from(*p);
        let e = |rel, blockers: &[&[DVec3]]| {
            exact_area_light(
                p,
                DVec3::Z,
                &light,
                &plane,
                DVec3::ONE,
                rel,
                blockers,
                PenumbraVisibility::Exact,
                0,
            )
            .x
        };
        let full = e(Relation::Lit, &[]);
        let want = e(Relation::Penumbra, &[&occ]);
        if want > 1e-3 * full && want < (1.0 - 1e-3) * full {
            penumbra += 1;
        }
        worst = worst.max((c[0] * PI - want).abs() / full);
    }
    assert!(penumbra > 500, "{penumbra} penumbra vertices");
    // The bound above: 2.4 % × 1.3; measured: 0.36 %.
    assert!(
        worst < 0.024 * 1.3,
        "worst error {worst:e} of the unoccluded light"
    );
    assert!(
        worst < 5e-3,
        "worst error {worst:e} of the unoccluded light"
    );
    // The mesh follows ~50 outline edges, not 400: a few thousand vertices.
    assert!(floor.positions.len() < 8_000, "{}", floor.positions.len());
}

/// 400 small quads over a floor (quads2000 scaled down). Delaunay refinement used to run
/// away along the floor's sides through its frame's origin, where points clipped onto a
/// side lie 1e-17 off it and the triangulation saw a zigzag (`mesh::shift_away_from_zero`),
/// splitting the side into thousands of pieces, a triangle each (on quads2000 it filled its
/// whole allowance, four times the arrangement's vertices). Without them the floor has
/// about two triangles a vertex, as a planar mesh should.
#[test]
fn refinement_under_many_shadows_completes_with_two_triangles_per_vertex() {
    let side = 20;
    let step = 3.0 / side as f64;
    let quads: Vec<Vec<[f64; 3]>> = (0..side * side)
        .map(|k| {
            let (i, j) = ((k % side) as f64, (k / side) as f64);
            let z = 0.5 + 0.3 * ((k * 7919) % 13) as f64 / 13.0;
            quad(
                [-1.5 + (i + 0.5) * step, -1.5 + (j + 0.5) * step, z],
                0.3 * step,
                0.3 * step,
                true,
            )
        })
        .collect();
    let s = scene(
        vec![
            mesh("Floor", vec![quad([0., 0., 0.], 2., 2., true)]),
            mesh("Quads", quads),
        ],
        vec![area_light("Lamp", lamp())],
        settings(),
    );
    let b = bake(&s);
    let floor = &b.meshes[0];
    let (nv, nt) = (floor.positions.len(), floor.triangles.len());
    // Before the fix: 61.9k floor vertices, 9.4k of them on its boundary, 1.85 triangles a
    // vertex; after: 65.6k, 453 and 1.99.
    assert!(
        nt as f64 > 1.95 * nv as f64,
        "{nt} triangles on {nv} vertices"
    );
    let on_boundary = floor
        .positions
        .iter()
        .filter(|p| p[0].abs().max(p[1].abs()) > 2.0 - 1e-9)
        .count();
    assert!(
        on_boundary < 2_000,
        "{on_boundary} of {nv} vertices on the boundary"
    );
}
