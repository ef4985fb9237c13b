//! Tests of direct light against closed forms and quadrature.

use super::*;
use crate::geom::lambert::test::{parallel_rect, quadrature};
use PenumbraVisibility as Vis;
use PenumbraVisibility::{Exact, Sampled};
use Relation::{Lit, Penumbra, Umbra, Unprocessed};

type Rect = [f64; 4];
const LIGHT: Rect = [-0.5, 0.5, -0.5, 0.5];
const OCC: Rect = [-0.4, 0.4, -0.4, 0.4];
const OCC2: Rect = [0.0, 0.6, -0.3, 0.3];
const Z: DVec3 = DVec3::Z;

/// [x0,x1]×[y0,y1] at height z, counter-clockwise about +z, or about −z when `down`.
fn rect(r: Rect, z: f64, down: bool) -> Vec<DVec3> {
    let corners = [(r[0], r[2]), (r[1], r[2]), (r[1], r[3]), (r[0], r[3])];
    let mut v: Vec<DVec3> = corners.iter().map(|&(x, y)| DVec3::new(x, y, z)).collect();
    if down {
        v.reverse();
    }
    v
}

type Blockers<'a> = &'a [&'a [DVec3]];

/// Irradiance per unit radiance from light `l` (its plane from its winding).
fn eval_with(l: &[DVec3], p: DVec3, n: DVec3, r: Relation, b: Blockers, m: Vis, s: u32) -> f64 {
    let plane = Plane::from_polygon(l).unwrap();
    area_light(p, n, l, &plane, DVec3::ONE, r, b, m, s).x
}

/// The same from the scene's light: side 1 at height 2, facing down.
fn eval(p: DVec3, n: DVec3, r: Relation, b: Blockers, m: Vis, s: u32) -> f64 {
    eval_with(&rect(LIGHT, 2.0, true), p, n, r, b, m, s)
}

/// Closed form: irradiance per unit radiance at p (facing +z) from `r` at height 2.
fn e_rect(p: DVec3, r: Rect) -> f64 {
    if r[0] >= r[1] || r[2] >= r[3] {
        return 0.0;
    }
    parallel_rect(r[0] - p.x, r[1] - p.x, r[2] - p.y, r[3] - p.y, 2.0 - p.z)
}

/// The part of the light hidden from floor point p by an axis-aligned occluder at height
/// z: its shadow on the light's plane by similar triangles, cut to the light.
fn hidden(p: DVec3, o: Rect, z: f64) -> Rect {
    let f = |i: usize, px: f64| px + 2.0 / z * (o[i] - px);
    isect([f(0, p.x), f(1, p.x), f(2, p.y), f(3, p.y)], LIGHT)
}

fn isect(a: Rect, b: Rect) -> Rect {
    let (lo, hi) = (|i: usize| a[i].max(b[i]), |i: usize| a[i].min(b[i]));
    [lo(0), hi(1), lo(2), hi(3)]
}

/// [y0,y1]×[z0,z1] in the plane x = const.
fn wall(r: Rect, x: f64) -> Vec<DVec3> {
    let yz = rect(r, x, false);
    yz.iter().map(|v| DVec3::new(v.z, v.x, v.y)).collect()
}

fn rel_err(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn square_over_floor_matches_similar_triangles() {
    let l = rect(LIGHT, 2.0, true);
    let plane = Plane::from_polygon(&l).unwrap();
    assert!((plane.n + Z).length() < 1e-15, "the light faces down");
    let rad = DVec3::new(1.0, 2.0, 0.5);
    for (x, y) in [(0.5, 0.0), (0.7, 0.45), (1.0, -0.9), (-0.35, 0.1)] {
        let p = DVec3::new(x, y, 0.0);
        let h = hidden(p, OCC, 1.0);
        let want = e_rect(p, LIGHT) - e_rect(p, h);
        assert!(want > 0.0 && e_rect(p, h) > 0.0, "{p} is not in penumbra");
        for down in [false, true] {
            let o = rect(OCC, 1.0, down);
            let e = area_light(p, Z, &l, &plane, rad, Penumbra, &[&o], Exact, 0);
            let err = (e / rad - DVec3::splat(want)).abs().max_element() / want;
            assert!(err < 1e-9, "{p}: {e} vs {want}");
        }
    }
}

#[test]
fn two_overlapping_blockers_by_inclusion_exclusion() {
    let (o1, o2) = (rect(OCC, 1.0, false), rect(OCC2, 1.5, true));
    for p in [DVec3::new(0.6, 0.2, 0.0), DVec3::new(0.9, -0.3, 0.0)] {
        let (h1, h2) = (hidden(p, OCC, 1.0), hidden(p, OCC2, 1.5));
        let both = isect(h1, h2);
        assert!(e_rect(p, both) > 0.0, "no overlap at {p}");
        let want = e_rect(p, LIGHT) - e_rect(p, h1) - e_rect(p, h2) + e_rect(p, both);
        let e = eval(p, Z, Penumbra, &[&o1, &o2], Exact, 0);
        assert!(rel_err(e, want) < 1e-9, "{p}: {e} vs {want}");
        assert_eq!(eval(p, Z, Unprocessed, &[&o1, &o2], Exact, 0), e);
    }
}

#[test]
fn umbra_lit_and_back_side() {
    let o = rect(OCC, 1.0, false);
    // Under the occluder's middle the whole light is hidden even when asked for penumbra.
    let p = DVec3::new(0.1, -0.2, 0.0);
    assert!(eval(p, Z, Penumbra, &[&o], Exact, 0) <= 1e-12 * e_rect(p, LIGHT));
    assert_eq!(eval(p, Z, Umbra, &[&o], Exact, 0), 0.0);
    // Far out the occluder hides nothing; lit regions skip it altogether.
    let p = DVec3::new(2.0, 0.3, 0.0);
    assert!(rel_err(eval(p, Z, Lit, &[&o], Exact, 0), e_rect(p, LIGHT)) < 1e-12);
    assert!(rel_err(eval(p, Z, Penumbra, &[&o], Exact, 0), e_rect(p, LIGHT)) < 1e-12);
    // Behind the light or on its plane: nothing, whatever the receiver faces.
    assert_eq!(eval(DVec3::new(0.0, 0.0, 3.0), -Z, Lit, &[], Exact, 0), 0.0);
    let on_plane = DVec3::new(3.0, 0.0, 2.0);
    assert_eq!(eval(on_plane, -DVec3::X, Lit, &[], Exact, 0), 0.0);
}

#[test]
fn contact_coplanar_and_crossing_occluders() {
    let p = DVec3::new(0.5, 0.0, 0.0);
    let full = e_rect(p, LIGHT);
    let floor = rect([-5.0, 5.0, -5.0, 5.0], 0.0, false);
    let ceiling = rect([-5.0, 5.0, -5.0, 5.0], 2.0, true);
    let wall_through_p = wall([-1.0, 1.0, 0.0, 1.9], 0.5);
    let collinear = [0.0, 0.1, 0.2].map(|x| DVec3::new(x, 0.0, 1.0)).to_vec();
    let all = [&floor, &ceiling, &wall_through_p, &collinear];
    for mode in [Exact, Sampled] {
        for b in all {
            let e = eval(p, Z, Penumbra, &[b], mode, 256);
            assert!(rel_err(e, full) < 1e-12, "{mode:?} {b:?}: {e} vs {full}");
        }
        let e = eval(p, Z, Penumbra, &all.map(|b| b.as_slice()), mode, 256);
        assert!(rel_err(e, full) < 1e-12, "{mode:?} all: {e}");
    }
    // A wall in x = 0 crossing the light: from p it hides exactly the strip x ∈ [−1/6, 0)
    // of the light (segments reach x = 0 at height ≥ 1.5 only from there). TOUCH moves
    // that edge by 1e-10 relative.
    let wall = wall([-1.0, 1.0, 1.5, 2.5], 0.0);
    let want = e_rect(p, [-0.5, -1.0 / 6.0, -0.5, 0.5]) + e_rect(p, [0.0, 0.5, -0.5, 0.5]);
    let e = eval(p, Z, Penumbra, &[&wall], Exact, 0);
    assert!(rel_err(e, want) < 1e-9, "{e} vs {want}");
    let b = [wall.as_slice(), &rect(OCC, 1.0, false), &ceiling];
    let e = eval(p, Z, Penumbra, &b, Exact, 0);
    assert!(e.is_finite() && e >= 0.0 && e < want);
}

#[test]
fn sampled_converges_to_exact() {
    let (o1, o2) = (rect(OCC, 1.0, false), rect(OCC2, 1.5, true));
    let tilted = DVec3::new(0.3, -0.2, 1.0).normalize();
    let cases: [(DVec3, DVec3, &[&[DVec3]]); 2] = [
        (DVec3::new(0.7, 0.45, 0.0), Z, &[&o1]),
        (DVec3::new(0.6, 0.2, 0.0), tilted, &[&o1, &o2]),
    ];
    for (p, n, b) in cases {
        let exact = eval(p, n, Penumbra, b, Exact, 0);
        let errs = [16, 256, 4096].map(|s| rel_err(eval(p, n, Penumbra, b, Sampled, s), exact));
        // Measured: 3.3e-2, 3.5e-3, 1.6e-3 and 3.1e-2, 3.1e-2, 6.7e-3.
        assert!(errs[2] < 1e-2 && errs[2] < errs[0], "{p}: errors {errs:?}");
    }
}

/// Seeded random configurations: tilted triangles and quads anywhere between the floor and
/// above the light, crossing it or each other. Exact must stay within the sampled
/// estimate's noise, and neither may leave [0, unoccluded] or turn NaN.
#[test]
fn random_occluders_agree_with_sampling() {
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = |lo: f64, hi: f64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        lo + (hi - lo) * (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..40 {
        let p = DVec3::new(rnd(-1.5, 1.5), rnd(-1.5, 1.5), 0.0);
        let n = DVec3::new(rnd(-0.5, 0.5), rnd(-0.5, 0.5), 1.0).normalize();
        let occ: Vec<Vec<DVec3>> = (0..3)
            .map(|_| {
                let c = DVec3::new(rnd(-1.0, 1.0), rnd(-1.0, 1.0), rnd(0.2, 2.3));
                let (u, v) = (
                    DVec3::new(rnd(-0.6, 0.6), rnd(-0.6, 0.6), rnd(-0.6, 0.6)),
                    DVec3::new(rnd(-0.6, 0.6), rnd(-0.6, 0.6), rnd(-0.6, 0.6)),
                );
                let quad = [c - u - v, c + u - v, c + u + v, c - u + v];
                quad[..if rnd(0.0, 1.0) < 0.5 { 3 } else { 4 }].to_vec()
            })
            .collect();
        let b: Vec<&[DVec3]> = occ.iter().map(|o| o.as_slice()).collect();
        let full = eval(p, n, Lit, &[], Exact, 0);
        let exact = eval(p, n, Penumbra, &b, Exact, 0);
        let sampled = eval(p, n, Penumbra, &b, Sampled, 4096);
        assert!(exact >= 0.0 && exact <= full && sampled >= 0.0 && sampled <= full);
        assert!(
            (exact - sampled).abs() < 5e-3 * full,
            "{p} {n}: {exact} vs {sampled} of {full}"
        );
    }
}

#[test]
fn scale_and_translation_invariance() {
    let p = DVec3::new(0.6, 0.2, 0.0);
    let tilted = DVec3::new(0.3, -0.2, 1.0).normalize();
    let scene = [(LIGHT, 2.0, true), (OCC, 1.0, false), (OCC2, 1.5, true)];
    let run = |s: f64, t: DVec3, k: usize| {
        let place = |(r, z, down): (Rect, f64, bool)| {
            rect(r, z, down)
                .iter()
                .map(|v| *v * s + t)
                .collect::<Vec<_>>()
        };
        let [l, o1, o2] = scene.map(place);
        let b = [o1.as_slice(), &o2];
        eval_with(&l, p * s + t, tilted, Penumbra, &b[..k], Exact, 0)
    };
    // Far from the world origin (1e3 times the scene's size) only the position's own
    // rounding (1e-16 of it) is lost, as the work is done relative to the light.
    let far = DVec3::new(1e3, -2e3, 5e2);
    for k in [1, 2] {
        let e1 = run(1.0, DVec3::ZERO, k);
        for s in [1e-3, 1e4] {
            assert!(rel_err(run(s, DVec3::ZERO, k), e1) < 1e-9, "scale {s}, {k}");
            assert!(
                rel_err(run(s, far * s, k), e1) < 1e-9,
                "moved, scale {s}, {k}"
            );
        }
    }
}

#[test]
fn tiny_light_behind_a_large_occluder() {
    // Light 1e-3 wide, occluder 1 wide: the penumbra on the floor is 1e-3 wide too. From
    // p the occluder's edge cuts the light at x = −2e-4 (similar triangles).
    let s = 1e-3;
    let l = rect([-s / 2.0, s / 2.0, -s / 2.0, s / 2.0], 2.0, true);
    let p = DVec3::new(1.0002, 0.0, 0.0);
    let e = eval_with(&l, p, Z, Penumbra, &[&rect(LIGHT, 1.0, false)], Exact, 0);
    let visible = DVec3::new(-2e-4, -s / 2.0, 2.0);
    let want = quadrature(p, Z, visible, DVec3::X * 7e-4, DVec3::Y * s, 1);
    assert!(rel_err(e, want) < 1e-9, "{e} vs {want}");
}

#[test]
fn point_light_inverse_square_cosine_and_shadow() {
    let pos = DVec3::new(1.0, 0.0, 2.0);
    let i = DVec3::new(10.0, 5.0, 1.0);
    let at = |pos: DVec3, r: Relation, b: Blockers| point_light(DVec3::ZERO, Z, pos, i, None, r, b);
    let e = at(pos, Lit, &[]);
    assert!((e - i * (2.0 / 5f64.sqrt() / 5.0)).length() < 1e-14);
    assert_eq!(at(DVec3::new(1.0, 0.0, -2.0), Lit, &[]), DVec3::ZERO);
    let o = rect([-1.0, 2.0, -1.0, 1.0], 1.0, false);
    assert_eq!(at(pos, Penumbra, &[&o]), DVec3::ZERO);
    assert_eq!(at(pos, Umbra, &[]), DVec3::ZERO);
    // Lit means no test, and a bulb on the ceiling is not shadowed by the ceiling.
    assert_eq!(at(pos, Lit, &[&o]), e);
    let ceiling = rect([-5.0, 5.0, -5.0, 5.0], 2.0, true);
    assert_eq!(at(pos, Penumbra, &[&ceiling]), e);
}

#[test]
fn spot_cone_and_blend_as_cycles() {
    let cos_half = 30f64.to_radians().cos();
    let spot = Spot {
        direction: -Z,
        cos_half_angle: cos_half,
        blend: 0.5,
    };
    let pos = DVec3::new(0.0, 0.0, 2.0);
    let at = |x: f64| point_light(x * DVec3::X, Z, pos, DVec3::ONE, Some(&spot), Lit, &[]).x;
    assert!((at(0.0) - 0.25).abs() < 1e-15, "on axis: full");
    assert_eq!(at(2.0), 0.0, "45° is outside a 30° half angle");
    // Just inside the cone edge the mask is small but not zero: smoothstep of f ≈ 0.013.
    let edge = at(2.0 * 29.9f64.to_radians().tan());
    assert!(edge > 0.0 && edge < 1e-3 * 0.25, "{edge}");
    // In the blend band: the cosine a quarter of the way in gives smoothstep(¼) = 5/32.
    let width = (1.0 - cos_half) * 0.5;
    for (f, mask) in [(0.25, 5.0 / 32.0), (0.5, 0.5), (1.0, 1.0), (-0.1, 0.0)] {
        let x = (cos_half + f * width).min(1.0);
        let px = 2.0 * (1.0 - x * x).sqrt() / x;
        let r2 = px * px + 4.0;
        let want = mask * (2.0 / r2.sqrt()) / r2;
        assert!((at(px) - want).abs() < 1e-12, "f = {f}");
    }
    let hard = Spot { blend: 0.0, ..spot };
    assert_eq!(spot_mask(&hard, DVec3::new(0.1, 0.0, -1.0)), 1.0);
    assert_eq!(spot_mask(&hard, DVec3::new(1.0, 0.0, -1.0)), 0.0);
}

#[test]
fn sun_cosine_and_ray_shadow() {
    let dir = DVec3::new(0.0, -1.0, -1.0).normalize();
    let at =
        |d: DVec3, r: Relation, b: Blockers| sun_light(DVec3::ZERO, Z, d, 3.0 * DVec3::ONE, r, b).x;
    let e = at(dir, Lit, &[]);
    assert!((e - 3.0 / 2f64.sqrt()).abs() < 1e-15);
    assert_eq!(at(-dir, Lit, &[]), 0.0);
    // An occluder up the ray (toward +y, +z) shadows; one below the receiver does not.
    let up = rect([-0.5, 0.5, 0.5, 1.5], 1.0, false);
    let down = rect([-0.5, 0.5, -1.5, -0.5], -1.0, false);
    assert_eq!(at(dir, Penumbra, &[&up]), 0.0);
    assert_eq!(at(dir, Lit, &[&up]), e);
    assert_eq!(at(dir, Penumbra, &[&down]), e);
}

#[test]
fn segment_test_is_exact_on_fan_diagonals_and_contact() {
    let sq = rect([-1.0, 1.0, -1.0, 1.0], 1.0, false);
    let hits = |a: DVec3, b: DVec3| segment_blocked(a, b, &sq);
    // Through the fan's diagonal (o0–o2), exactly: blocked.
    assert!(hits(DVec3::ZERO, DVec3::new(0.0, 0.0, 2.0)));
    assert!(hits(DVec3::new(-0.5, -0.5, 0.0), DVec3::new(0.5, 0.5, 2.0)));
    // Ending on the polygon or passing beside it: not blocked.
    assert!(!hits(DVec3::ZERO, DVec3::new(0.0, 0.0, 1.0)));
    assert!(!hits(DVec3::ZERO, DVec3::new(3.0, 0.0, 2.0)));
}

/// Irradiance per unit radiance at `p` from the union of axis-aligned rectangles in the
/// light's plane, exactly: the plane cut along every rectangle side into cells, each cell
/// covered by some rectangle counted once by its closed form.
fn e_union(p: DVec3, rects: &[Rect]) -> f64 {
    let mut xs: Vec<f64> = rects.iter().flat_map(|r| [r[0], r[1]]).collect();
    let mut ys: Vec<f64> = rects.iter().flat_map(|r| [r[2], r[3]]).collect();
    xs.sort_by(f64::total_cmp);
    ys.sort_by(f64::total_cmp);
    let mut e = 0.0;
    for x in xs.windows(2) {
        for y in ys.windows(2) {
            let (cx, cy) = (0.5 * (x[0] + x[1]), 0.5 * (y[0] + y[1]));
            let covered = rects.iter().any(|r| {
                r[0] < r[1] && r[2] < r[3] && r[0] < cx && cx < r[1] && r[2] < cy && cy < r[3]
            });
            if covered {
                e += e_rect(p, [x[0], x[1], y[0], y[1]]);
            }
        }
    }
    e
}

/// Many small occluders over a floor (quads2000): their hidden parts are summed as
/// disjoint pieces, each part minus the ones before it. Side by side at one height the
/// parts are disjoint; at three heights they overlap; a small occluder high up hides a part
/// nested in a lower one's. Every case is the light minus the exact union.
#[test]
fn many_small_occluders_hide_their_union_exactly() {
    let square = |x: f64, y: f64, h: f64| [x - h, x + h, y - h, y + h];
    let grid = |z: f64, shift: f64, h: f64| -> Vec<(Rect, f64)> {
        (0..4)
            .flat_map(|i| (0..4).map(move |j| (i, j)))
            .map(|(i, j)| {
                let c = |k: i32| -0.36 + 0.24 * k as f64 + shift;
                (square(c(i), c(j), h), z)
            })
            .collect()
    };
    let disjoint = grid(1.0, 0.0, 0.05);
    let mut overlapping = grid(1.0, 0.0, 0.05);
    overlapping.extend(grid(0.9, 0.04, 0.05));
    overlapping.extend(grid(1.1, -0.03, 0.06));
    let mut nested = grid(1.0, 0.0, 0.05);
    nested.push((square(0.12, 0.12, 0.01), 1.3));
    for (case, occ) in [
        ("disjoint", &disjoint),
        ("overlapping", &overlapping),
        ("nested", &nested),
    ] {
        let polys: Vec<Vec<DVec3>> = occ.iter().map(|(r, z)| rect(*r, *z, false)).collect();
        let refs: Vec<&[DVec3]> = polys.iter().map(|v| v.as_slice()).collect();
        for (x, y) in [(0.0, 0.0), (0.07, -0.05), (-0.31, 0.22), (0.5, 0.45)] {
            let p = DVec3::new(x, y, 0.0);
            let parts: Vec<Rect> = occ.iter().map(|(r, z)| hidden(p, *r, *z)).collect();
            let want = e_rect(p, LIGHT) - e_union(p, &parts);
            let hidden_sum: f64 = parts.iter().map(|r| e_rect(p, *r)).sum();
            match case {
                "overlapping" => assert!(
                    hidden_sum > e_union(p, &parts) * (1.0 + 1e-6),
                    "{case} at {p}: the parts do not overlap"
                ),
                "nested" if p == DVec3::ZERO => {
                    let small = parts[parts.len() - 1];
                    let inside = |r: &Rect| {
                        r[0] < small[0] && small[1] < r[1] && r[2] < small[2] && small[3] < r[3]
                    };
                    assert!(parts[..parts.len() - 1].iter().any(inside), "not nested");
                }
                _ => {}
            }
            let got = eval(p, Z, Penumbra, &refs, Exact, 0);
            assert!(
                (got - want).abs() < 1e-12 * e_rect(p, LIGHT),
                "{case} at {p}: {got} vs {want}"
            );
        }
    }
}
