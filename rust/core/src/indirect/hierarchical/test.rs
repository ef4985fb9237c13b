//! Tests of the indirect stage against closed forms and the white furnace.

use super::*;
use crate::indirect::patches::test::grid_elements;
use crate::indirect::receiver::form_factor;
use crate::indirect::test::{corner, furnace, plate_factor, plates, quad, scene, v};
use crate::scene::Face;

fn run(scene: &Scene, k: usize) -> (Elements, IndirectResult) {
    let el = grid_elements(&scene.faces, k);
    let occ = Occluders::new(&scene.faces);
    let direct = vec![DVec3::ZERO; el.positions.len()];
    let r = indirect(scene, &el, &direct, &occ, &Progress::new()).unwrap();
    (el, r)
}

#[test]
fn parallel_plates_match_closed_form() {
    // Emitter 2×2 at height 0.7 facing down; receiver 2×2 below it facing up. The
    // emitter is black, so nothing comes back; the receiver gets π·Le·F.
    let h = 0.7;
    let le = v(1.0, 2.0, 0.5);
    let [emitter, receiver] = plates(h, le, 0.6);
    let sc = scene(vec![emitter, receiver], |s| s.convergence = 1e-6);
    let (el, r) = run(&sc, 12);
    assert!(r.links > 0 && r.leaves == el.triangles.len() as u64);
    let mut checked = 0;
    for (i, x) in el.positions.iter().enumerate() {
        // Vertices on the border take a one-sided mean; the inside is checked. Leaves hold
        // constants, so a vertex is off by the field's curvature over a leaf (most at the
        // steep edge).
        if el.vertex_face[i] != 1 || x.x.abs() > 0.99 || x.y.abs() > 0.99 {
            continue;
        }
        let f = plate_factor(*x, h);
        let e = r.irradiance[i] / (PI * le);
        assert!(
            ((e - DVec3::splat(f)) / f).abs().max_element() < 1.5e-2,
            "{x}: {e} vs {f}"
        );
        checked += 1;
    }
    assert!(checked > 40);
}

/// Elements about `size` across on every face (a grid per face).
fn sized_elements(faces: &[Face], size: f64) -> Elements {
    let mut el = Elements::default();
    for (i, f) in faces.iter().enumerate() {
        let reach = f
            .verts
            .iter()
            .map(|v| (*v - f.verts[0]).length())
            .fold(0.0, f64::max);
        let mut one = grid_elements(
            std::slice::from_ref(f),
            (reach / size).ceil().max(1.0) as usize,
        );
        let off = el.positions.len() as u32;
        one.vertex_face.iter_mut().for_each(|x| *x = i as u32);
        one.tri_face.iter_mut().for_each(|x| *x = i as u32);
        el.positions.extend(one.positions);
        el.normals.extend(one.normals);
        el.vertex_face.extend(one.vertex_face);
        el.triangles
            .extend(one.triangles.iter().map(|t| t.map(|v| v + off)));
        el.tri_face.extend(one.tri_face);
        el.tri_region.extend(one.tri_region);
    }
    el
}

/// The indirect light of `sc` on elements about `size` across (`sized_elements`), with the
/// direct light `direct(face)` at every vertex of each face.
fn bake_sized(sc: &Scene, size: f64, direct: impl Fn(u32) -> DVec3) -> (Elements, IndirectResult) {
    let el = sized_elements(&sc.faces, size);
    let occ = Occluders::new(&sc.faces);
    let direct: Vec<DVec3> = el.vertex_face.iter().map(|&f| direct(f)).collect();
    let r = indirect(sc, &el, &direct, &occ, &Progress::new()).unwrap();
    (el, r)
}

/// Form factor from a point at the origin (facing +z) to the rectangle `[x0, x1] × [y0, y1]`
/// at height `h`, facing down: sums and differences of corner rectangles.
fn rect_factor(x0: f64, x1: f64, y0: f64, y1: f64, h: f64) -> f64 {
    let f = |a: f64, b: f64| corner(a.abs(), b.abs(), h) * a.signum() * b.signum();
    f(x1, y1) - f(x0, y1) - f(x1, y0) + f(x0, y0)
}

#[test]
fn step_emitter_a_few_mm_over_a_receiver() {
    // Two 0.2 squares 5 mm apart; the upper one emits on its x < 0 half only (two faces).
    // Under each half, a receiver point gets π·Le times its factor to the bright half.
    let g = 0.005;
    let le = DVec3::ONE;
    let bright = quad(v(-0.05, 0., g), DVec3::Y * 0.1, DVec3::X * 0.05, 0.0, le);
    let dark = quad(
        v(0.05, 0., g),
        DVec3::Y * 0.1,
        DVec3::X * 0.05,
        0.0,
        DVec3::ZERO,
    );
    let receiver = quad(
        DVec3::ZERO,
        DVec3::X * 0.1,
        DVec3::Y * 0.1,
        0.5,
        DVec3::ZERO,
    );
    let sc = scene(vec![bright, dark, receiver], |s| s.convergence = 1e-4);
    let (el, r) = bake_sized(&sc, 0.01, |_| DVec3::ZERO);
    let nearest = |x: f64| {
        (0..el.positions.len())
            .filter(|&i| el.vertex_face[i] == 2)
            .min_by(|&a, &b| {
                let d = |i: usize| (el.positions[i] - v(x, 0.0, 0.0)).length();
                d(a).total_cmp(&d(b))
            })
            .unwrap()
    };
    for x in [-0.05, -0.02, 0.02, 0.05] {
        let i = nearest(x);
        let p = el.positions[i];
        let want = rect_factor(-0.1 - p.x, -p.x, -0.1 - p.y, 0.1 - p.y, g);
        let got = r.irradiance[i].x / PI;
        eprintln!("x {:.4}: {got:.5} vs {want:.5}", p.x);
        // Within 1 %, or 1 % of the bright side's value where the dark side gets nearly none.
        assert!(
            (got - want).abs() < 0.01 * want.max(0.5),
            "{p}: {got} vs {want}"
        );
    }
}

#[test]
fn box_side_beside_a_glowing_box_sees_its_face_not_a_cluster() {
    // Regression: room-78's boxes standing a few mm apart on a table got 25–40 % too little
    // light on their sides. A pair of objects in each other's near field that carried little
    // against the scene's light was linked as two clusters, and a cluster's link gives all
    // of its faces one direction and one distance. Two black boxes 0.1 across, 5 mm apart;
    // the second one's side facing the first glows (Le = 1), and a bright panel far behind
    // the first box (emitting from both sides, as in Cycles) makes their pair faint. A point
    // on the first box's facing side gets π·Le·F to the glowing side, a parallel rectangle
    // 5 mm away, in closed form (it cannot see the panel, behind its plane).
    let (g, a) = (0.005, 0.05);
    let c = |x: f64, y: f64, z: f64| v(x, y, z);
    let (x, y, z) = (DVec3::X * a, DVec3::Y * a, DVec3::Z * a);
    let black = DVec3::ZERO;
    let box_faces = |x0: f64, glow: DVec3| {
        vec![
            quad(c(x0 + 2.0 * a, 0.0, a), y, z, 0.0, black),
            quad(c(x0, 0.0, a), z, y, 0.0, glow),
            quad(c(x0 + a, a, a), z, x, 0.0, black),
            quad(c(x0 + a, -a, a), x, z, 0.0, black),
            quad(c(x0 + a, 0.0, 2.0 * a), x, y, 0.0, black),
        ]
    };
    let mut faces = box_faces(-2.0 * a, black);
    faces.extend(box_faces(g, DVec3::ONE));
    faces.push(quad(
        v(-3.0, 0.0, a),
        DVec3::Z * 0.25,
        DVec3::Y * 0.25,
        0.0,
        DVec3::splat(1e6),
    ));
    let sc = scene(faces, |s| s.convergence = 1e-3);
    let (el, r) = bake_sized(&sc, 0.02, |_| DVec3::ZERO);
    let mut checked = 0;
    for (i, p) in el.positions.iter().enumerate() {
        // The first box's side facing +x, inside its border.
        if el.vertex_face[i] != 0 || p.y.abs() > 0.8 * a || (p.z - a).abs() > 0.8 * a {
            continue;
        }
        let want = rect_factor(-a - p.y, a - p.y, -p.z, 2.0 * a - p.z, g);
        let got = r.irradiance[i].x / PI;
        assert!((got - want).abs() < 0.01 * want, "{p}: {got} vs {want}");
        checked += 1;
    }
    assert!(checked >= 9, "{checked}");
}

#[test]
fn faint_near_light_keeps_its_shape_for_the_next_bounce() {
    // Regression: a faint pair in each other's near field was linked whole, so its receiver
    // took one irradiance, and sent on the mean of a light that varies across it (room-78:
    // box sides by the table top, lit mostly by the light that the boxes and the table send
    // each other). A grey plate (ρ = 0.5) 0.2 × 0.1 at z = 0; 5 mm above it, facing down, a
    // glowing plate (Le = 1) over its x < 0 half and a black one over its x > 0 half (the
    // grey plate is cut there, as the discontinuity mesh would cut it); a panel 100 times
    // as bright far away, edge-on to all three, makes their pairs faint. The black plate
    // gets only what the grey one reflects: E(y) = ∫ ρ·π·Le·F(x) · g² / (π·|x − y|⁴) dx over
    // the grey plate, F(x) its factor to the glowing plate (closed form), the integral by
    // the midpoint rule on a 0.25 mm grid.
    let (g, rho) = (0.005, 0.5);
    let faces = vec![
        quad(
            v(-0.05, 0.0, 0.0),
            DVec3::X * 0.05,
            DVec3::Y * 0.05,
            rho,
            DVec3::ZERO,
        ),
        quad(
            v(0.05, 0.0, 0.0),
            DVec3::X * 0.05,
            DVec3::Y * 0.05,
            rho,
            DVec3::ZERO,
        ),
        quad(
            v(-0.05, 0.0, g),
            DVec3::Y * 0.05,
            DVec3::X * 0.05,
            0.0,
            DVec3::ONE,
        ),
        quad(
            v(0.05, 0.0, g),
            DVec3::Y * 0.05,
            DVec3::X * 0.05,
            0.0,
            DVec3::ZERO,
        ),
        quad(
            v(30.0, 0.0, 0.5 * g),
            DVec3::X * 0.25,
            DVec3::Y * 0.25,
            0.0,
            DVec3::splat(100.0),
        ),
    ];
    // Leaves of single elements: what is tested is the links' resolution, not the leaves'.
    let sc = scene(faces, |s| {
        s.convergence = 1e-3;
        s.patch_size = 0.004;
    });
    let (el, r) = bake_sized(&sc, 0.004, |_| DVec3::ZERO);
    let step = 2.5e-4;
    let grid: Vec<(f64, f64, f64)> = (0..800)
        .flat_map(|i| {
            (0..400).map(move |j| {
                (
                    -0.1 + (i as f64 + 0.5) * step,
                    -0.05 + (j as f64 + 0.5) * step,
                )
            })
        })
        .map(|(x, y)| {
            (
                x,
                y,
                rho * rect_factor(-0.1 - x, -x, -0.05 - y, 0.05 - y, g),
            )
        })
        .collect();
    let (mut checked, mut worst, mut top) = (0, 0.0f64, 0.0f64);
    for (i, p) in el.positions.iter().enumerate() {
        if el.vertex_face[i] != 3 || p.x < 0.01 || p.x > 0.09 || p.y.abs() > 0.04 {
            continue;
        }
        let want: f64 = grid
            .iter()
            .map(|&(x, y, b)| {
                let r2 = (x - p.x).powi(2) + (y - p.y).powi(2) + g * g;
                b * g * g / (PI * r2 * r2)
            })
            .sum::<f64>()
            * step
            * step;
        let got = r.irradiance[i].x / PI;
        worst = worst.max((got - want).abs());
        top = top.max(want);
        checked += 1;
    }
    assert!(checked >= 100, "{checked}");
    // Against the brightest point (by the cut, 5 mm from the glowing plate's edge), since
    // the light falls a hundredfold across the plate: 1.5 % of it here, 30 % with faint
    // near pairs linked whole.
    assert!(worst < 0.03 * top, "{worst} of {top}");
}

#[test]
#[ignore = "open (issue 11): the hierarchical solver gives the seat above the leg 0.53 against \
            0.71 in the open, and the leg top 0.58; the final gather at the vertices now sees the \
            leg (0.80 before), but the solve's leaves are groups of elements, and one straddling \
            the leg's outline shoots the mean of the dark and the lit seat at the leg top"]
fn narrow_gap_under_a_seat_stays_dark() {
    // Regression: a chair leg's top face 5 mm under the seat got ten times the light it
    // should (the seat's underside shot its mean over the leg). A floor lit uniformly
    // (direct E = 1), a seat 0.45 up facing down, a 4 cm leg top 5 mm under it.
    // The seat above the leg sees the floor only through the gap, beyond atan(2 cm / 5 mm)
    // = 76° from its normal: cos²76° = 6 % of the light it gets in the open; the leg top
    // sees only that part of the seat, so gets about ρ_seat · 6 % of the seat's open value
    // (a little more from the seat around, a little less where the gap is narrower).
    let floor = quad(DVec3::ZERO, DVec3::X, DVec3::Y, 0.8, DVec3::ZERO);
    let seat = quad(
        v(0., 0., 0.45),
        DVec3::Y * 0.2,
        DVec3::X * 0.2,
        0.8,
        DVec3::ZERO,
    );
    let leg = quad(
        v(0., 0., 0.445),
        DVec3::X * 0.02,
        DVec3::Y * 0.02,
        0.8,
        DVec3::ZERO,
    );
    let sc = scene(vec![floor, seat, leg], |s| s.convergence = 1e-3);
    let (el, r) = bake_sized(&sc, 0.01, |f| if f == 0 { DVec3::ONE } else { DVec3::ZERO });
    let mean_on = |face: u32, keep: &dyn Fn(DVec3) -> bool| {
        let xs: Vec<f64> = (0..el.positions.len())
            .filter(|&i| el.vertex_face[i] == face && keep(el.positions[i]))
            .map(|i| r.irradiance[i].x)
            .collect();
        xs.iter().sum::<f64>() / xs.len() as f64
    };
    let seat_open = mean_on(1, &|p| p.x.abs() > 0.1 && p.y.abs() > 0.1);
    let seat_above = mean_on(1, &|p| p.x.abs() < 0.01 && p.y.abs() < 0.01);
    let leg_top = mean_on(2, &|_| true);
    eprintln!("seat open {seat_open:.4} above leg {seat_above:.4} leg top {leg_top:.4}");
    // The seat in the open: the floor (B = 0.8) at a factor near 0.9.
    assert!(seat_open > 0.6 && seat_open < 0.8, "{seat_open}");
    // Patch shooters gave the leg top about ρ_seat times the open seat (0.56 here); the
    // seat above the leg and the leg feed each other (ρ² = 0.64), so both sit above the
    // single-bounce estimate, and the leg, 8 gaps wide, takes light from its edges.
    // Measured: 0.39 and 0.44 of those; the single-bounce estimate is about 0.06 and 0.05
    // (4 rays per link still miss part of the leg's shadow).
    assert!(seat_above < 0.45 * seat_open, "{seat_above} vs {seat_open}");
    assert!(leg_top < 0.55 * 0.8 * seat_open, "{leg_top} vs {seat_open}");
}

#[test]
fn floor_under_a_table_sees_no_ceiling_through_it() {
    // Regression: the floor under a table was 5.5–7.7 % too bright. Links from the ceiling
    // reach floor nodes that run out past the table's edge, each with the table in its shaft
    // and a mean visibility over its node; the final gather gave that mean to every vertex,
    // so the ones under the table saw the ceiling through the table top.
    // A 4×4 ceiling 2.4 up, emitting (Le = 1, facing down), over a black 4×4 floor, and a
    // black 1.2 × 0.8 table top 0.75 up (black: nothing bounces, the floor gets the
    // ceiling's light alone). A floor point sees the ceiling but for the table top's
    // shadow on it, the top projected from the point: E = π·Le·(F_ceiling − F_shadow), both
    // rectangles, in closed form.
    let (ceiling_h, table_h) = (2.4, 0.75);
    let (tx, ty) = (0.6, 0.4);
    let ceiling = quad(
        v(0., 0., ceiling_h),
        DVec3::Y * 2.0,
        DVec3::X * 2.0,
        0.0,
        DVec3::ONE,
    );
    let floor = quad(
        DVec3::ZERO,
        DVec3::X * 2.0,
        DVec3::Y * 2.0,
        0.0,
        DVec3::ZERO,
    );
    let top = quad(
        v(0.1, 0.05, table_h),
        DVec3::X * tx,
        DVec3::Y * ty,
        0.0,
        DVec3::ZERO,
    );
    let sc = scene(vec![ceiling, floor, top], |s| s.convergence = 1e-3);
    let (el, r) = bake_sized(&sc, 0.1, |_| DVec3::ZERO);
    let seen = |p: DVec3| {
        let ceiling = rect_factor(-2.0 - p.x, 2.0 - p.x, -2.0 - p.y, 2.0 - p.y, ceiling_h);
        // The top's corners seen from p, carried up to the ceiling's plane, clipped to it.
        let s = ceiling_h / table_h;
        let (x0, x1) = ((0.1 - tx - p.x) * s, (0.1 + tx - p.x) * s);
        let (y0, y1) = ((0.05 - ty - p.y) * s, (0.05 + ty - p.y) * s);
        let (x0, x1) = (x0.max(-2.0 - p.x), x1.min(2.0 - p.x));
        let (y0, y1) = (y0.max(-2.0 - p.y), y1.min(2.0 - p.y));
        let shadow = if x0 < x1 && y0 < y1 {
            rect_factor(x0, x1, y0, y1, ceiling_h)
        } else {
            0.0
        };
        ceiling - shadow
    };
    let (mut worst, mut sum, mut count) = (0.0f64, 0.0, 0);
    for (i, p) in el.positions.iter().enumerate() {
        let under = (p.x - 0.1).abs() < tx - 0.05 && (p.y - 0.05).abs() < ty - 0.05;
        if el.vertex_face[i] != 1 || !under {
            continue;
        }
        let want = seen(*p);
        let got = r.irradiance[i].x / PI;
        worst = worst.max((got / want - 1.0).abs());
        if (got / want - 1.0).abs() > 0.03 {
            eprintln!("{p}: {got} vs {want}");
        }
        sum += got / want;
        count += 1;
    }
    let mean = sum / count as f64;
    eprintln!("under the table: {count} vertices, mean ratio {mean:.4}, worst {worst:.4}");
    // Measured 1.0097 and 0.094 (with each link's mean visibility: 1.056 and 0.26); 1.0138
    // and 0.119 since most vertices of a leaf interpolate the visibilities its anchors found
    // (`vertices::ANCHORS`; a leaf's first look with 8 rays instead of 16 made it 0.124). A
    // vertex leaves up to `VISIBILITY_SCALE` × convergence (10 %) of its light to the means.
    // Since kept links take their visibility from a second set of rays (`refine`), at
    // least 16 of them: 1.0056 and 0.117. Since a leaf's budget counts its indirect light
    // alone and its vertices take the slope of what it saw (`own_look::slope`): 1.0047 and
    // 0.098.
    assert!(count > 50);
    assert!((mean - 1.0).abs() < 0.02, "{mean}");
    assert!(worst < 0.12, "{worst}");
}

#[test]
fn backrest_sees_the_floor_past_the_seat_edge() {
    // Regression: a chair's backrest was 7 % too dark in its indirect light (chair, against
    // Cycles). Seen from the backrest, the seat's front edge hides more of the floor the lower
    // the point; a leaf's links carry its mean visibility, right at its centre and far off at
    // its top and bottom, and its vertices did not look again: direct light dominates there,
    // and what the means may leave is a share of all of the light. A floor lit uniformly
    // (E = 1, ρ 0.8), a black seat 0.45 up reaching 0.4 out from a black backrest, which has
    // direct light 1 of its own (a lamp not modelled). The floor the backrest sees is the
    // floor less the seat's shadow cast from the point onto it: two rectangles' factors.
    let (hs, d, w) = (0.45, 0.4, 0.25);
    let floor = quad(v(1.0, 0., 0.), DVec3::X, DVec3::Y, 0.8, DVec3::ZERO);
    let seat = quad(
        v(d / 2.0, 0., hs),
        DVec3::X * (d / 2.0),
        DVec3::Y * w,
        0.0,
        DVec3::ZERO,
    );
    let back = quad(
        v(0., 0., hs + 0.25),
        DVec3::Y * w,
        DVec3::Z * 0.25,
        0.0,
        DVec3::ZERO,
    );
    let sc = scene(vec![floor, seat, back], |s| s.convergence = 1e-3);
    let (el, r) = bake_sized(&sc, 0.02, |f| if f == 1 { DVec3::ZERO } else { DVec3::ONE });
    let rect = |x0: f64, x1: f64, y0: f64, y1: f64| {
        [v(x0, y0, 0.), v(x1, y0, 0.), v(x1, y1, 0.), v(x0, y1, 0.)]
    };
    let seen = |p: DVec3| {
        let all = form_factor(p, DVec3::X, &rect(0.0, 2.0, -1.0, 1.0));
        let s = p.z / (p.z - hs);
        let (y0, y1) = (p.y + (-w - p.y) * s, p.y + (w - p.y) * s);
        let shadow = rect(0.0, (d * s).min(2.0), y0.max(-1.0), y1.min(1.0));
        all - form_factor(p, DVec3::X, &shadow)
    };
    let (mut worst, mut sq, mut count) = (0.0f64, 0.0, 0);
    for (i, p) in el.positions.iter().enumerate() {
        if el.vertex_face[i] != 2 || p.y.abs() > w - 0.03 || p.z < hs + 0.01 {
            continue;
        }
        let want = 0.8 * seen(*p);
        let got = r.irradiance[i].x;
        // Against all of the vertex's light, as the error from Cycles is measured.
        let err = (got - want) / (want + 1.0);
        worst = worst.max(err.abs());
        sq += err * err;
        count += 1;
    }
    let rms = (sq / count as f64).sqrt();
    eprintln!("backrest: {count} vertices, rms {rms:.5}, worst {worst:.5}");
    // Measured rms 0.31 % and worst 1.9 %, the error against all the light; with every
    // vertex looking itself at every link the leaf found in part, 0.32 % and 1.4 %. Before
    // the leaves' slopes (and with the direct light in a leaf's budget): 0.55 % and 3.7 %.
    assert!(count > 200);
    assert!(rms < 0.004, "{rms}");
    assert!(worst < 0.025, "{worst}");
}

#[test]
fn shooter_in_shadow_sends_nothing_from_its_umbra() {
    // Regression: the underside of an object over a floor was 33 % too bright, floor
    // patches averaging the lit floor with the object's umbra. A black 0.6 square 0.3 over
    // a floor, facing down; the floor lit (E = 1) except the square's footprint (umbra,
    // its own face). The square's centre gets ρ times its factor to the lit floor.
    let (s, h, rho) = (0.3, 0.3, 0.5);
    let umbra = quad(DVec3::ZERO, DVec3::X * s, DVec3::Y * s, rho, DVec3::ZERO);
    let mut faces = vec![umbra];
    // The lit floor around it out to ±2, as four faces.
    for (c, u, w) in [
        (v(0., 1.15, 0.), DVec3::X * 2.0, DVec3::Y * 0.85),
        (v(0., -1.15, 0.), DVec3::X * 2.0, DVec3::Y * 0.85),
        (v(1.15, 0., 0.), DVec3::X * 0.85, DVec3::Y * s),
        (v(-1.15, 0., 0.), DVec3::X * 0.85, DVec3::Y * s),
    ] {
        faces.push(quad(c, u, w, rho, DVec3::ZERO));
    }
    faces.push(quad(
        v(0., 0., h),
        DVec3::Y * s,
        DVec3::X * s,
        0.0,
        DVec3::ZERO,
    ));
    let sc = scene(faces, |s| s.convergence = 1e-4);
    let (el, r) = bake_sized(&sc, 0.05, |f| {
        if (1..5).contains(&f) {
            DVec3::ONE
        } else {
            DVec3::ZERO
        }
    });
    let i = (0..el.positions.len())
        .filter(|&i| el.vertex_face[i] == 5)
        .min_by(|&a, &b| {
            el.positions[a]
                .length()
                .total_cmp(&el.positions[b].length())
        })
        .unwrap();
    let p = el.positions[i];
    let lit = rect_factor(-2.0 - p.x, 2.0 - p.x, -2.0 - p.y, 2.0 - p.y, h)
        - rect_factor(-s - p.x, s - p.x, -s - p.y, s - p.y, h);
    let want = rho * lit;
    let got = r.irradiance[i].x;
    eprintln!("underside centre {got:.5} vs {want:.5}");
    // Measured 2.9 % low (the final gather takes each link's visibility and disc estimate
    // from the node it was made for); patch shooters were 33 % high here. Since a leaf's
    // budget counts its indirect light alone and its vertices take the slope of what it saw
    // (`own_look::slope`): 0.1 % low.
    assert!((got / want - 1.0).abs() < 0.04, "{got} vs {want}");
}

#[test]
fn blocker_between_plates_casts_full_shadow() {
    let h = 1.0;
    let le = DVec3::ONE;
    let [emitter, receiver] = plates(h, le, 0.5);
    // Facing up: it only sends light back up, the receiver sits in its shadow.
    let blocker = quad(
        v(0., 0., 0.5),
        DVec3::X * 4.0,
        DVec3::Y * 4.0,
        0.5,
        DVec3::ZERO,
    );
    let sc = scene(vec![emitter.clone(), receiver.clone(), blocker], |s| {
        s.patch_size = 1.0
    });
    let (el, r) = run(&sc, 3);
    for (i, e) in r.irradiance.iter().enumerate() {
        match el.vertex_face[i] {
            1 => assert_eq!(*e, DVec3::ZERO),
            _ => assert!(e.x > 0.0),
        }
    }
    // Half the blocker gone (x > 0 open): a receiver point at x0 sees the emitter where
    // x > -x0, by similar triangles; visibility is sampled, so only roughly. Black: a thin
    // face's back reflects the receiver's light (`back`), which is not what this is about.
    let half = quad(
        v(-2.0, 0., 0.5),
        DVec3::X * 2.0,
        DVec3::Y * 4.0,
        0.0,
        DVec3::ZERO,
    );
    // The visible part x ∈ [x1, 1] of the emitter seen from (x0, y0), the emitter's
    // corners at ±1 and height h.
    let visible = |x0: f64, y0: f64, x1: f64| {
        let (a0, a1, b0, b1) = (x1 - x0, 1.0 - x0, -1.0 - y0, 1.0 - y0);
        let f = |a: f64, b: f64| corner(a.abs(), b.abs(), h) * a.signum() * b.signum();
        f(a1, b1) - f(a0, b1) - f(a1, b0) + f(a0, b0)
    };
    let sc = scene(vec![emitter.clone(), receiver.clone(), half.clone()], |s| {
        s.convergence = 1e-4;
    });
    let (el, r) = run(&sc, 12);
    let at = |x: DVec3| {
        r.irradiance[el
            .positions
            .iter()
            .position(|p| (*p - x).length() < 1e-12)
            .unwrap()]
        .x / PI
    };
    // Leaves hold constants: a corner vertex takes the mean of leaves beside it, so the
    // dark corner gets a trace and the open one is a little off.
    let open = visible(1.0, 1.0, -1.0);
    assert!(
        at(v(-1.0, -1.0, 0.0)) < 0.02 * open,
        "{}",
        at(v(-1.0, -1.0, 0.0))
    );
    assert!(
        (at(v(1.0, 1.0, 0.0)) / open - 1.0).abs() < 0.25,
        "{} vs {open}",
        at(v(1.0, 1.0, 0.0))
    );
    for x0 in [-1.0 / 3.0, 1.0 / 3.0] {
        let (got, want) = (at(v(x0, 1.0 / 3.0, 0.0)), visible(x0, 1.0 / 3.0, -x0));
        // Measured 14 % low at x0 = −1/3: the links' visibility is a mean over the node
        // each was made for, and the half-blocker's penumbra crosses those nodes.
        assert!((got / want - 1.0).abs() < 0.2, "{x0}: {got} vs {want}");
    }
}

#[test]
fn white_furnace_gives_le_over_one_minus_rho() {
    // Outgoing radiance L = ρE/π + Le is Le/(1−ρ) everywhere, and E = πL: so
    // E = π·Le/(1−ρ) (all of it indirect: there are no lights).
    let (rho, le) = (0.5, v(1.0, 0.5, 0.25));
    let sc = furnace(rho, le, vec![], |s| {
        s.patch_size = 0.5;
        s.convergence = 1e-4;
    });
    let (_, r) = run(&sc, 4);
    assert!(r.unshot_fraction < 1e-4);
    let expect = PI * le / (1.0 - rho);
    // Each vertex gathers over its leaf's links with its own point factors, which may sum
    // a little over or under 1 (the factors of far sources are second-order estimates).
    let worst = r
        .irradiance
        .iter()
        .map(|e| ((*e - expect) / expect).abs().max_element())
        .fold(0.0, f64::max);
    assert!(worst < 3e-4, "{worst}");

    // Sweeps cut short leave light unshot; the ambient term (each later sweep would add ρ
    // times the one before) restores most of it.
    let mean_off = |ambient: bool| {
        let sc = furnace(rho, le, vec![], |s| {
            s.patch_size = 0.5;
            s.convergence = 1e-4;
            s.max_shots = 4;
            s.ambient = ambient;
        });
        let (_, r) = run(&sc, 4);
        let m = r.irradiance.iter().map(|e| e.x).sum::<f64>() / r.irradiance.len() as f64;
        (m - expect.x).abs() / expect.x
    };
    let (plain, amb) = (mean_off(false), mean_off(true));
    assert!(plain > 1e-2 && amb < 0.1 * plain, "{plain} {amb}");
}

#[test]
fn stops_at_convergence_or_max_shots() {
    let sc = furnace(0.7, DVec3::ONE, vec![], |s| s.convergence = 0.02);
    let (_, r) = run(&sc, 2);
    assert!(r.unshot_fraction < 0.02 && r.unshot_fraction > 0.0);
    let sc2 = furnace(0.7, DVec3::ONE, vec![], |s| {
        s.convergence = 0.02;
        s.max_shots = 3;
    });
    let (_, r2) = run(&sc2, 2);
    assert_eq!(r2.shots, 3);
    assert!(r2.unshot_fraction > 0.02);
    assert!(r.shots > 3);
}

#[test]
fn bit_identical_for_any_thread_count() {
    // A box with a floating plate inside, so that rays are cast.
    let plate = quad(
        v(0.5, 0.4, 0.45),
        v(0.2, 0.05, 0.0),
        v(0.0, 0.2, 0.03),
        0.8,
        DVec3::ZERO,
    );
    let sc = furnace(0.6, v(0.2, 0.3, 0.1), vec![plate], |s| {
        s.patch_size = 0.3;
        s.convergence = 1e-3;
        s.visibility_rays = 9;
    });
    let runs: Vec<IndirectResult> = [1, 4]
        .iter()
        .map(|&n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap()
                .install(|| run(&sc, 5).1)
        })
        .collect();
    assert!(runs[0].shots > 3);
    assert_eq!(runs[0].shots, runs[1].shots);
    let bits = |r: &IndirectResult| {
        r.irradiance
            .iter()
            .flat_map(|e| e.to_array().map(f64::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&runs[0]), bits(&runs[1]));
    // The plate's shadow on the floor is there: the floor under the plate's middle sees its
    // back (ρ = 0.8, lit by the floor: B ≈ 0.78 of the furnace value) over a factor of about
    // 0.2 in place of walls at about 0.97, so it is about 4 % darker than the open floor; the
    // progressive solver gives 2.5 % (1.4888 against 1.5289, grids of 5 to 20), this one
    // 3.2 % (1.4653 against 1.5134). (This once looked at the floor under the plate's corner,
    // half in its shadow, where the two differed by 0.1 % either way; and once asked for any
    // vertex under 0.9 of the furnace value: one on the wall beside the plate had 0.897 from
    // its links' mean visibility, where rays from the vertex find the opposite wall under
    // the plate in full view.)
    let el = grid_elements(&sc.faces, 5);
    let floor_mean = |keep: &dyn Fn(DVec3) -> bool| {
        let xs: Vec<f64> = (0..el.positions.len())
            .filter(|&i| el.vertex_face[i] == 0 && keep(el.positions[i]))
            .map(|i| runs[0].irradiance[i].x)
            .collect();
        xs.iter().sum::<f64>() / xs.len() as f64
    };
    let under = floor_mean(&|p| (p - v(0.6, 0.525, 0.0)).length() < 0.08);
    let open = floor_mean(&|p| !(0.2..0.8).contains(&p.x) || !(0.1..0.7).contains(&p.y));
    eprintln!("under the plate {under:.4}, open floor {open:.4}");
    assert!(
        under < 0.985 * open && under > 0.94 * open,
        "{under} vs {open}"
    );
}

#[test]
fn many_occluders_go_through_the_bvh() {
    // Eighty overlapping slats in one plane (more than a shot lists by hand) close the gap
    // between the plates: not a ray gets through. With every other slat gone, light does.
    // Black slats: their backs would reflect the receiver's light (`back`).
    let h = 1.0;
    let emitter = quad(v(0., 0., h), DVec3::Y, DVec3::X, 0.0, DVec3::ONE);
    let receiver = quad(DVec3::ZERO, DVec3::X, DVec3::Y, 0.5, DVec3::ZERO);
    let slat = |i: usize| {
        let x = -2.0 + 0.05 * i as f64;
        quad(
            v(x, 0.0, 0.5),
            v(0.03, 0.0, 0.0),
            v(0.0, 2.0, 0.0),
            0.0,
            DVec3::ZERO,
        )
    };
    let closed: Vec<Face> = [emitter.clone(), receiver.clone()]
        .into_iter()
        .chain((0..80).map(slat))
        .collect();
    let (el, r) = run(&scene(closed, |s| s.patch_size = 0.5), 12);
    let on_receiver = |r: &IndirectResult| {
        r.irradiance
            .iter()
            .zip(&el.vertex_face)
            .filter(|(_, f)| **f == 1)
            .map(|(e, _)| e.x)
            .collect::<Vec<_>>()
    };
    assert!(on_receiver(&r).iter().all(|e| *e == 0.0));
    let open: Vec<Face> = [emitter, receiver]
        .into_iter()
        .chain((0..80).step_by(2).map(slat))
        .collect();
    let (_, r) = run(&scene(open, |s| s.patch_size = 0.5), 12);
    // Slats 0.06 wide every 0.1 in a plane halfway up hide 60% of the emitter, whatever
    // the direction: 40% of the unblocked π·Le·F gets through.
    // Sixteen rays to a patch sample the slats coarsely: each vertex within 25%, their mean
    // closer.
    let receiver_points = el
        .positions
        .iter()
        .zip(&el.vertex_face)
        .filter(|(_, f)| **f == 1);
    let mut ratios = Vec::new();
    for (e, (x, _)) in on_receiver(&r).iter().zip(receiver_points) {
        // Border vertices take a one-sided mean of leaves (constants): inside only.
        if x.x.abs() > 0.99 || x.y.abs() > 0.99 {
            continue;
        }
        let x = *x - *x * 1e-6;
        let f = plate_factor(x, h);
        ratios.push(e / (PI * f));
    }
    assert!(ratios.iter().all(|r| (r - 0.4).abs() < 0.1), "{ratios:?}");
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    assert!((mean - 0.4).abs() < 0.03, "{mean}");
}

#[test]
fn cancelled_bake_stops() {
    let sc = furnace(0.5, DVec3::ONE, vec![], |s| s.patch_size = 0.5);
    let el = grid_elements(&sc.faces, 2);
    let progress = Progress::new();
    progress.cancel();
    let r = indirect(
        &sc,
        &el,
        &vec![DVec3::ZERO; el.positions.len()],
        &Occluders::new(&sc.faces),
        &progress,
    );
    assert_eq!(r, Err(BakeError::Cancelled));
}

/// `Covers::hold` (a grid over the covers' boxes) answers as trying every cover does, on a
/// face under 200 small covers, some overlapping, at points inside, outside and on their
/// edges.
#[test]
fn covers_by_grid_answer_as_every_cover_does() {
    use crate::geom::hash::{mix, unit};
    let r = |i: u64| unit(mix(i));
    let polys: Vec<Vec<DVec2>> = (0..200u64)
        .map(|i| {
            let c = DVec2::new(10.0 * r(4 * i), 10.0 * r(4 * i + 1));
            let (w, h) = (0.05 + 0.5 * r(4 * i + 2), 0.05 + 0.5 * r(4 * i + 3));
            vec![
                c,
                c + DVec2::new(w, 0.0),
                c + DVec2::new(w, h),
                c + DVec2::new(0.0, h),
            ]
        })
        .collect();
    let covers = Covers::new(vec![Vec::new(), polys.clone()]);
    let (mut inside, mut on_edge) = (0, 0);
    for i in 0..20_000u64 {
        // Every fourth point on the left edge of a cover, where the strict test says no.
        let p = if i % 4 == 0 {
            let q = &polys[(i / 4) as usize % polys.len()];
            q[0] + (q[3] - q[0]) * r(9 * i + 7)
        } else {
            DVec2::new(11.0 * r(9 * i) - 0.5, 11.0 * r(9 * i + 1) - 0.5)
        };
        let every = polys.iter().any(|q| strictly_inside_convex(q, p));
        assert_eq!(covers.hold(1, p), every, "point {p:?}");
        assert!(!covers.hold(0, p));
        inside += every as u32;
        on_edge += (i % 4 == 0 && !every) as u32;
    }
    assert!(inside > 1000, "{inside} points inside");
    assert!(on_edge > 1000, "{on_edge} points on an edge and outside");
}
