//! Tests of the indirect stage against closed forms and the white furnace.

use super::*;
use crate::indirect::patches::test::grid_elements;
use crate::indirect::test::{furnace, plate_factor, plates, quad, scene, v};
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
    // The plate's shadow on the floor is there (points under it darker than in the open).
    let expect = PI * 0.2 / 0.4;
    assert!(runs[0].irradiance.iter().any(|e| e.x < 0.9 * expect));
}

#[test]
fn many_occluders_go_through_the_bvh() {
    // Eighty overlapping slats in one plane (more than a shot lists by hand) close the gap
    // between the plates: not a ray gets through. With every other slat gone, light does.
    let h = 1.0;
    let emitter = quad(v(0., 0., h), DVec3::Y, DVec3::X, 0.0, DVec3::ONE);
    let receiver = quad(DVec3::ZERO, DVec3::X, DVec3::Y, 0.5, DVec3::ZERO);
    let slat = |i: usize| {
        let x = -2.0 + 0.05 * i as f64;
        quad(
            v(x, 0.0, 0.5),
            v(0.03, 0.0, 0.0),
            v(0.0, 2.0, 0.0),
            0.5,
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
