//! Meshing driven by a tolerance on the light (issue 13): the baked direct light, linearly
//! interpolated over each element, stays within `tolerance × (exact + floor)` of the exact
//! light at random points of every element; a smaller tolerance never gives a larger error;
//! and each triangle at a box's foot corner carries the light's limit from its own side.
//! The reference is `direct::exact::area_light` with every face that can stand between the
//! point and the light as a blocker, independent of the bake's regions and relations.

mod common;
use common::*;
use glam::DVec3;
use penumbra::direct::exact;
use penumbra::regions::relation::Relation;
use penumbra::scene::json::{SceneJson, SettingsJson};
use penumbra::scene::settings::PenumbraVisibility;
use penumbra::scene::solids::Occluder;
use penumbra::scene::{LightKind, Scene};

/// Refinement's lower size bound, as `mesh::refine::LOWER_BOUND` (of
/// `penumbra_element_size`) and `RECEIVER_LOWER` (of the receiver's extent).
const LOWER_BOUND: f64 = 1.0 / 16.0;
const RECEIVER_LOWER: f64 = 1.0 / 64.0;

/// The floor of the bound, as `mesh::refine::FLOOR`: a fraction of the brightest vertex of
/// the receiver (here of the source polygon, whose brightest is at least the piece's).
const FLOOR: f64 = 0.01;

/// Exact direct irradiance at `q` (normal `n`), with the blockers that can matter.
fn exact_light(sc: &Scene, q: DVec3, n: DVec3) -> DVec3 {
    let mut e = DVec3::ZERO;
    for l in &sc.lights {
        let LightKind::Area {
            verts,
            plane,
            radiance,
        } = &l.kind
        else {
            panic!("built-in scenes have area lights only");
        };
        let (mut lo, mut hi) = (q, q);
        for v in verts {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        let blockers: Vec<&[DVec3]> = sc
            .faces
            .iter()
            .filter(|f| {
                let in_box = f
                    .verts
                    .iter()
                    .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), v| {
                        (a.min(*v), b.max(*v))
                    });
                in_box.0.cmple(hi).all()
                    && in_box.1.cmpge(lo).all()
                    && f.verts.iter().any(|v| (*v - q).dot(n) > 1e-9)
                    && f.verts.iter().any(|v| plane.dist(*v) > 1e-9)
            })
            .map(|f| f.verts.as_slice())
            .collect();
        e += exact::area_light(
            q,
            n,
            verts,
            plane,
            *radiance,
            Relation::Penumbra,
            &blockers,
            PenumbraVisibility::Exact,
            64,
        );
    }
    e
}

fn buried(sc: &Scene, q: DVec3, margin: f64) -> bool {
    sc.occluders.iter().any(|o| match o {
        Occluder::Solid { solid, .. } => solid.planes.iter().all(|f| f.dist(q) < -margin),
        Occluder::Face(_) => false,
    })
}

/// `q` lies against another face turned the other way (the seat under the backrest
/// standing on it): a contact no one sees.
fn covered(sc: &Scene, q: DVec3, n: DVec3, margin: f64) -> bool {
    sc.faces.iter().any(|g| {
        g.plane.n.dot(n) < -0.999 && g.plane.dist(q).abs() < margin && {
            let p = g.frame.to_2d(q);
            let k = g.poly2.len();
            (0..k).all(|i| (g.poly2[(i + 1) % k] - g.poly2[i]).perp_dot(p - g.poly2[i]) > 0.0)
        }
    })
}

fn preset(s: &SceneJson, tolerance: f64, fractions: (f64, f64)) -> SceneJson {
    let sc = penumbra::scene::validate(s).expect("valid scene");
    let diag = (sc.bounds_max - sc.bounds_min).length();
    let mut s = s.clone();
    s.settings = SettingsJson {
        indirect: Some(false),
        lighting_only: Some(true),
        tolerance: Some(tolerance),
        element_size: Some(fractions.0 * diag),
        penumbra_element_size: Some(fractions.1 * diag),
        ..SettingsJson::default()
    };
    s
}

/// Small seeded generator (xorshift).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

struct Measured {
    /// Largest error over the allowed error, over the elements the bound binds.
    worst: f64,
    /// Elements checked, and skipped at the lower size bound or as slivers.
    checked: usize,
    skipped: usize,
    slivers: usize,
    hidden: usize,
    /// RMS and max of |interpolated − exact| / (exact + floor).
    rms: f64,
    /// Where the worst error was: the element's corners, interpolated and exact light.
    worst_at: String,
}

/// At one random point of every element (skipping those that reached the lower size bound,
/// which refinement may not split), the error over `tolerance × (exact + floor)`.
fn measure(s: &SceneJson, seed: u64) -> Measured {
    let sc = penumbra::scene::validate(s).expect("valid scene");
    let tolerance = sc.settings.tolerance;
    let b = bake(s);
    let mut rng = Rng(seed);
    let (mut worst, mut checked, mut skipped, mut slivers, mut sum2) = (0.0f64, 0, 0, 0, 0.0);
    let mut hidden = 0;
    let mut worst_at = String::new();
    // Narrower than the arrangement's merge distance (~1e-9 of the scene): a triangle along a
    // constraint that rounding kinked, standing for no area and no discontinuity.
    let thin = 1e-9 * (sc.bounds_max - sc.bounds_min).length();
    for m in &b.meshes {
        let e: Vec<DVec3> = m
            .colors
            .iter()
            .map(|c| DVec3::from_array(*c) * std::f64::consts::PI)
            .collect();
        let npoly = m.source_polygon.iter().max().map_or(0, |x| *x as usize + 1);
        // Refinement's lower size bound per receiver (`mesh::refine::lower_bound`), here
        // from the source polygon's box diagonal, which is at least the receiver's extent in
        // its plane: the bound used here is never below refinement's.
        let mut boxes = vec![(DVec3::INFINITY, DVec3::NEG_INFINITY); npoly];
        for (t, tri) in m.triangles.iter().enumerate() {
            let b = &mut boxes[m.source_polygon[t] as usize];
            for &v in tri {
                let p = DVec3::from_array(m.positions[v as usize]);
                *b = (b.0.min(p), b.1.max(p));
            }
        }
        let lower: Vec<f64> = boxes
            .iter()
            .map(|(lo, hi)| {
                (sc.settings.penumbra_element_size * LOWER_BOUND)
                    .min((*hi - *lo).length() * RECEIVER_LOWER)
            })
            .collect();
        let mut floor = vec![DVec3::ZERO; npoly];
        for (t, tri) in m.triangles.iter().enumerate() {
            let f = &mut floor[m.source_polygon[t] as usize];
            for &v in tri {
                *f = f.max(e[v as usize] * FLOOR);
            }
        }
        for (t, tri) in m.triangles.iter().enumerate() {
            let p = tri.map(|v| DVec3::from_array(m.positions[v as usize]));
            let shortest = (p[1] - p[0])
                .length()
                .min((p[2] - p[1]).length())
                .min((p[0] - p[2]).length());
            if shortest < 2.0 * lower[m.source_polygon[t] as usize] {
                skipped += 1;
                continue;
            }
            let cross = (p[1] - p[0]).cross(p[2] - p[0]);
            let longest = (p[1] - p[0])
                .length()
                .max((p[2] - p[1]).length())
                .max((p[0] - p[2]).length());
            if cross.length() < thin * longest {
                slivers += 1;
                continue;
            }
            let n = cross.normalize();
            let (mut u, mut v) = (rng.next(), rng.next());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let w = [1.0 - u - v, u, v];
            let q = p[0] * w[0] + p[1] * w[1] + p[2] * w[2];
            let interp: DVec3 = (0..3).map(|k| e[tri[k] as usize] * w[k]).sum();
            // Inside a solid, or under a face lying on it (the seat under the backrest): no
            // one sees it.
            if buried(&sc, q, thin) || covered(&sc, q, n, thin) {
                hidden += 1;
                continue;
            }
            let exact = exact_light(&sc, q, n);
            let denom = exact.abs() + floor[m.source_polygon[t] as usize];
            let rel = ((interp - exact).abs() / denom.max(DVec3::splat(1e-300))).max_element();
            if rel / tolerance > worst {
                worst_at = format!(
                    "mesh {} polygon {} {p:?}: {interp} vs exact {exact} at {q}",
                    m.name, m.source_polygon[t]
                );
            }
            worst = worst.max(rel / tolerance);
            sum2 += rel * rel;
            checked += 1;
        }
    }
    Measured {
        worst,
        checked,
        skipped,
        slivers,
        hidden,
        rms: (sum2 / checked.max(1) as f64).sqrt(),
        worst_at,
    }
}

/// Fitted vertex values' RMS error at most this fraction of exact ones' (at medium: data1
/// 0.75, cornell 0.65).
const FITTED_RMS: f64 = 0.8;

const PRESETS: [(&str, f64, (f64, f64)); 3] = [
    ("draft", 0.03, (1.0 / 12.0, 1.0 / 40.0)),
    ("medium", 0.01, (1.0 / 25.0, 1.0 / 125.0)),
    ("high", 0.003, (1.0 / 50.0, 1.0 / 400.0)),
];

fn meets_tolerance(name: &str) {
    let s = penumbra::scenes::by_name(name).expect("built-in scene");
    scene_meets_tolerance(name, &s);
}

fn scene_meets_tolerance(name: &str, s: &SceneJson) {
    scene_meets_tolerance_at(name, s, &[0, 1, 2]);
}

/// `scene_meets_tolerance` for the presets numbered `which` in `PRESETS`.
fn scene_meets_tolerance_at(name: &str, s: &SceneJson, which: &[usize]) {
    for (k, (preset_name, tolerance, fractions)) in PRESETS.iter().enumerate() {
        if !which.contains(&k) {
            continue;
        }
        let m = measure(&preset(s, *tolerance, *fractions), 7 + k as u64);
        eprintln!(
            "{name} {preset_name}: worst {:.3} of the bound, rms {:.2e}, {} elements checked, {} at the lower bound, {} slivers, {} inside solids; worst in {}",
            m.worst, m.rms, m.checked, m.skipped, m.slivers, m.hidden, m.worst_at
        );
        assert!(m.checked > 100, "{name} {preset_name}: too few elements");
        assert!(
            m.worst <= 1.0,
            "{name} {preset_name}: error {:.3} × the tolerance",
            m.worst
        );
    }
}

#[test]
fn data1_meets_its_tolerance() {
    meets_tolerance("data1");
}

#[test]
fn chair_meets_its_tolerance() {
    meets_tolerance("chair");
}

#[test]
fn cornell_meets_its_tolerance() {
    meets_tolerance("cornell");
}

#[test]
fn data2_meets_its_tolerance() {
    meets_tolerance("data2");
}

#[test]
fn room_meets_its_tolerance() {
    meets_tolerance("room");
}

/// A leg under a seat that overhangs it, lit from the side: the seat's shadow edge crosses
/// the leg's face, whose light drops to nothing within a few millimetres of its vertical
/// edges (light comes round the corner). The face's elements there have their long edges on
/// the receiver's boundary (they were never split: chair 16× the tolerance), or are thin
/// strips along it (they were taken as flat, rounding-made triangles and left whole).
#[test]
fn leg_under_an_overhang_meets_its_tolerance() {
    let mut chair = cuboid([0.175, 0.175, 0.0], [0.225, 0.225, 0.45]);
    chair.extend(cuboid([-0.25, -0.25, 0.45], [0.25, 0.25, 0.5]));
    let s = scene(
        vec![
            mesh("Floor", vec![quad([0., 0., 0.], 1., 1., true)]),
            mesh("Chair", chair),
        ],
        vec![area_light("Key", quad([0.6, -0.5, 2.0], 0.2, 0.2, false))],
        SettingsJson::default(),
    );
    scene_meets_tolerance("leg", &s);
}

/// Clutter: small boxes a few millimetres apart on a table, under a light off to one side.
/// Their faces catch each other's penumbrae, a few millimetres wide. With a lower size bound
/// set by the scene alone (1/800 of its diagonal), the elements across those penumbrae could
/// not be split: room-78's clutter faces were 2.5× the light at some probes, with exact
/// corners. The bound now shrinks with the receiver (`mesh::refine::RECEIVER_LOWER`): draft
/// went from 55× the tolerance to 0.38×, medium is 0.88×.
#[test]
fn clutter_meets_its_tolerance() {
    scene_meets_tolerance_at("clutter", &clutter(), &[0, 1]);
}

/// At the high preset, the light along the line where a box stands on the table curves so
/// that a long boundary edge's midpoint passed while its element failed elsewhere: split only
/// where samples failed, the elements along it grew flatter each pass (apexes 6e-5 … 1e-7
/// above the line) until they counted as flat (`mesh::refine::FLAT`) and were left whole,
/// 6.2× the tolerance. A failing element is now also cut across its longest edge: 0.40×.
#[test]
fn clutter_meets_its_tolerance_at_high() {
    scene_meets_tolerance_at("clutter", &clutter(), &[2]);
}

fn clutter() -> SceneJson {
    let mut boxes = cuboid([0.0, 0.0, 0.0], [0.03, 0.03, 0.03]);
    boxes.extend(cuboid([0.033, 0.004, 0.0], [0.06, 0.028, 0.05]));
    boxes.extend(cuboid([0.005, 0.034, 0.0], [0.025, 0.05, 0.02]));
    scene(
        vec![
            mesh("Table", vec![quad([0.03, 0.03, 0.0], 0.6, 0.6, true)]),
            mesh("Clutter", boxes),
        ],
        vec![area_light(
            "Lamp",
            quad([0.25, 0.15, 0.8], 0.15, 0.15, false),
        )],
        SettingsJson::default(),
    )
}

#[test]
fn smaller_tolerance_never_larger_error() {
    for name in ["data1", "cornell"] {
        let s = penumbra::scenes::by_name(name).expect("built-in scene");
        let mut last = f64::INFINITY;
        for tolerance in [0.03, 0.01, 0.003, 0.001] {
            let m = measure(&preset(&s, tolerance, PRESETS[1].2), 11);
            eprintln!(
                "{name} tolerance {tolerance}: rms relative error {:.3e}",
                m.rms
            );
            assert!(
                m.rms <= last,
                "{name}: tolerance {tolerance} gives rms {:.3e} > {last:.3e}",
                m.rms
            );
            last = m.rms;
        }
    }
}

/// Vertex values fitted to the light over their elements (`vertex_values: "fitted"`, the
/// default) err less than the exact light at the vertices, on the same mesh, at random
/// points of every element against the exact light.
#[test]
fn fitted_vertex_values_err_less_than_exact_ones() {
    for name in ["data1", "cornell"] {
        let s = penumbra::scenes::by_name(name).expect("built-in scene");
        let fitted = preset(&s, 0.01, PRESETS[1].2);
        let mut exact = fitted.clone();
        exact.settings.vertex_values = Some("exact".into());
        let (f, e) = (measure(&fitted, 5), measure(&exact, 5));
        eprintln!("{name}: rms {:.3e} fitted, {:.3e} exact", f.rms, e.rms);
        assert_eq!(f.checked, e.checked, "{name}: the fit changed the mesh");
        assert!(
            f.rms < FITTED_RMS * e.rms,
            "{name}: rms {:.3e} fitted against {:.3e} exact",
            f.rms,
            e.rms
        );
    }
}

/// A box standing on a floor under a light off to one side: at the foot corner the light
/// depends on the direction one comes from. Every triangle around the corner carries, at
/// the corner, the exact light's limit from its own inside within 1e-6 relative.
#[test]
fn box_foot_corner_takes_each_sides_limit() {
    let s = scene(
        vec![
            mesh("Floor", vec![quad([0., 0., 0.], 2., 2., true)]),
            mesh("Box", cuboid([-0.5, -0.5, 0.0], [0.5, 0.5, 1.0])),
        ],
        vec![area_light("Light", quad([0.9, 0.6, 2.5], 0.4, 0.4, false))],
        SettingsJson {
            indirect: Some(false),
            lighting_only: Some(true),
            ..SettingsJson::default()
        },
    );
    let sc = penumbra::scene::validate(&s).expect("valid scene");
    let b = bake(&s);
    let floor = &b.meshes[0];
    let mut around = 0;
    for c in [[0.5, 0.5], [0.5, -0.5], [-0.5, 0.5], [-0.5, -0.5]] {
        let corner = DVec3::new(c[0], c[1], 0.0);
        for tri in &floor.triangles {
            let p = tri.map(|v| DVec3::from_array(floor.positions[v as usize]));
            let Some(k) = (0..3).find(|&k| (p[k] - corner).length() < 1e-12) else {
                continue;
            };
            around += 1;
            // The triangle's value at the corner, against the exact light a hair inside
            // along the way to its centroid (1e-7: far above the exact evaluator's snapping
            // at ~1e-9 of the scene, far below where the light's radial change shows).
            let centroid = (p[0] + p[1] + p[2]) / 3.0;
            let q = corner + (centroid - corner).normalize() * 1e-7;
            let interp = DVec3::from_array(floor.colors[tri[k] as usize]) * std::f64::consts::PI;
            let exact = exact_light(&sc, q, DVec3::Z);
            let err = (interp - exact).abs().max_element();
            assert!(
                err <= 1e-6 * exact.max_element() + 1e-12,
                "corner {c:?}: triangle {p:?}: interpolated {interp} vs exact {exact}"
            );
        }
    }
    assert!(around >= 16, "only {around} triangles at the box's corners");
}

/// A floor under 400 small quads at mixed heights (tests/worst_cases.rs's scene): its
/// discontinuity edges outnumber its lattice many times over (a dense receiver), so
/// Delaunay refinement leaves those edges whole and refinement to the tolerance alone puts
/// vertices where the light needs them. Splitting every encroached edge as well gave the
/// floor 86k vertices, against 51k without; room-8328's floor grew from 206k to 1.03M.
#[test]
fn floor_under_many_shadows_meets_its_tolerance() {
    let s = quads_scene(
        20,
        SettingsJson {
            indirect: Some(false),
            lighting_only: Some(true),
            ..SettingsJson::default()
        },
    );
    // Measured: worst 0.44 and 0.42 of the bound at 3 % and 1 % (0.42 at 0.3 %, too slow
    // for the suite).
    for tolerance in [0.03, 0.01] {
        let mut s = s.clone();
        s.settings.tolerance = Some(tolerance);
        let m = measure(&s, 5);
        eprintln!(
            "floor under 400 quads at {tolerance}: worst {:.3} of the bound, rms {:.2e}, {} checked, {} at the lower bound; worst in {}",
            m.worst, m.rms, m.checked, m.skipped, m.worst_at
        );
        assert!(m.checked > 10_000, "{tolerance}: too few elements");
        assert!(
            m.worst <= 1.0,
            "{tolerance}: error {:.3} × the tolerance",
            m.worst
        );
    }
}
