//! Occluders passing through receivers: a box sunk into the floor, a slab crossing it
//! diagonally, two boxes that intersect, a thin leg through the floor. Direct light at every
//! output vertex is checked against a reference computed here by other means (exact
//! visibility along strips of the light, below), relation codes against exact visibility,
//! and the part of a receiver inside a solid must stay dark.

mod common;
use common::*;
use glam::DVec3;
use penumbra::scene::json::{MeshJson, SettingsJson};
use penumbra::{Bake, SceneJson};

fn settings(h: f64) -> SettingsJson {
    SettingsJson {
        element_size: Some(h),
        penumbra_element_size: Some(h / 4.0),
        indirect: Some(false),
        lighting_only: Some(true),
        // The light at the vertices themselves, against the references there.
        vertex_values: Some("exact".into()),
        ..Default::default()
    }
}

fn floor() -> MeshJson {
    mesh("Floor", vec![quad([0., 0., 0.], 1.5, 1.5, true)])
}

/// The light used by the area-light cases: a square at z = 1.5, facing down, off to one side
/// so that shadows fall across the cut lines.
const LIGHT_C: [f64; 3] = [0.5, 0.3, 1.5];
const LIGHT_H: f64 = 0.3;

fn square_light() -> penumbra::scene::json::LightJson {
    area_light("L", quad(LIGHT_C, LIGHT_H, LIGHT_H, false))
}

/// A box of half sizes `h` centred at `c`, turned by `angle` about the y axis.
fn turned_box(c: [f64; 3], h: [f64; 3], angle: f64) -> Vec<Vec<[f64; 3]>> {
    let (s, co) = angle.sin_cos();
    cuboid([-h[0], -h[1], -h[2]], h)
        .into_iter()
        .map(|f| {
            f.into_iter()
                .map(|[x, y, z]| [c[0] + co * x + s * z, c[1] + y, c[2] - s * x + co * z])
                .collect()
        })
        .collect()
}

/// Every input polygon with its mesh and polygon index.
fn polygons(s: &SceneJson) -> Vec<(usize, usize, Vec<DVec3>)> {
    let mut out = Vec::new();
    for (mi, m) in s.meshes.iter().enumerate() {
        for (pi, p) in m.polygons.iter().enumerate() {
            let v = p
                .iter()
                .map(|&i| DVec3::from_array(m.positions[i as usize]))
                .collect();
            out.push((mi, pi, v));
        }
    }
    out
}

/// Reference irradiance at `p` (normal `n`) from the square light of radiance 1, with every
/// polygon in `occ` as occluder. The light is cut into thin strips along a direction `u`
/// parallel to no scene edge (so that the visible length of a strip has kinks but no jumps
/// across strips); on each strip the light points hidden by one convex polygon form one
/// interval (the polygon cut by the plane through p and the strip's line, seen from p), so
/// the visible part of the strip is exact, and the smooth kernel is integrated on it by
/// Gauss–Legendre. Across strips: midpoint rule.
fn area_reference(p: DVec3, n: DVec3, occ: &[&Vec<DVec3>]) -> f64 {
    const STRIPS: usize = 1500;
    let zl = LIGHT_C[2];
    let c = DVec3::from_array(LIGHT_C);
    if p.z >= zl {
        return 0.0;
    }
    let (sa, ca) = 0.3f64.sin_cos();
    let u = DVec3::new(ca, sa, 0.0);
    let w = DVec3::new(-sa, ca, 0.0);
    // 8-point Gauss–Legendre on [-1, 1].
    let gx = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    let gw = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    let kernel = |l: DVec3| {
        let d = l - p;
        let r2 = d.length_squared();
        n.dot(d).max(0.0) * d.z / (r2 * r2)
    };
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .map(|(a, b)| DVec3::new(a * LIGHT_H, b * LIGHT_H, 0.0));
    let t_lo = corners
        .iter()
        .map(|q| q.dot(w))
        .fold(f64::INFINITY, f64::min);
    let t_hi = corners
        .iter()
        .map(|q| q.dot(w))
        .fold(f64::NEG_INFINITY, f64::max);
    // The integral across strips kinks where an occluder's outline seen from p (or the
    // edge of p's front half-space) crosses the light's border, or passes a corner: there
    // the strips' integral has a jump in slope, as steep as the outline is near p's height.
    // A midpoint rule across such a kink errs by the strip width squared times that jump
    // (2e-4 of the light beside the end of a cut line, refinement's vertices found): the
    // strips are cut at every such t, and each piece integrated by Gauss–Legendre.
    let mut breaks = vec![t_lo, t_hi];
    let to_t = |q: DVec3| (q - c).dot(w);
    let square: Vec<DVec3> = corners.iter().map(|q| c + *q).collect();
    let crossings = |a: DVec3, b: DVec3, out: &mut Vec<f64>| {
        for k in 0..4 {
            let (e0, e1) = (square[k], square[(k + 1) % 4]);
            let (d, e) = (b - a, e1 - e0);
            let den = d.x * e.y - d.y * e.x;
            if den.abs() < 1e-300 {
                continue;
            }
            let f = e0 - a;
            let (s, r) = ((f.x * e.y - f.y * e.x) / den, (f.x * d.y - f.y * d.x) / den);
            if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&r) {
                out.push(to_t(a + d * s));
            }
        }
    };
    for o in occ {
        // The part between p's height and the light's, seen from p on the light's plane.
        let mut poly: Vec<DVec3> = o.to_vec();
        for (bound, keep_above) in [(p.z + 1e-12, true), (zl - 1e-12, false)] {
            let inside = |q: &DVec3| if keep_above { q.z > bound } else { q.z < bound };
            let mut next = Vec::new();
            for i in 0..poly.len() {
                let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
                if inside(&a) {
                    next.push(a);
                }
                if inside(&a) != inside(&b) {
                    next.push(a + (b - a) * ((bound - a.z) / (b.z - a.z)));
                }
            }
            poly = next;
        }
        let seen: Vec<DVec3> = poly
            .iter()
            .map(|q| p + (*q - p) * ((zl - p.z) / (q.z - p.z)))
            .collect();
        for i in 0..seen.len() {
            breaks.push(to_t(seen[i]));
            crossings(seen[i], seen[(i + 1) % seen.len()], &mut breaks);
        }
    }
    // Where the light's plane leaves p's front half-space: n·(l − p) = 0 at height zl.
    let horizontal = DVec3::new(n.x, n.y, 0.0);
    if horizontal.length() > 1e-12 {
        let along = DVec3::new(-n.y, n.x, 0.0).normalize();
        let k = -(n.dot(DVec3::new(c.x, c.y, zl) - p)) / horizontal.length_squared();
        let on = DVec3::new(c.x, c.y, zl) + horizontal * k;
        crossings(on - along * 10.0, on + along * 10.0, &mut breaks);
    }
    breaks.retain(|t| t.is_finite() && *t >= t_lo && *t <= t_hi);
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let mut nodes: Vec<(f64, f64)> = Vec::new();
    for piece in breaks.windows(2) {
        let (a, b) = (piece[0], piece[1]);
        let parts = ((STRIPS as f64 / 8.0) * (b - a) / (t_hi - t_lo))
            .ceil()
            .max(1.0) as usize;
        let h = (b - a) / parts as f64;
        for q in 0..parts {
            let (mid, half) = (a + (q as f64 + 0.5) * h, 0.5 * h);
            for (x, wt) in gx.iter().zip(&gw) {
                nodes.push((mid + half * x, wt * half));
                nodes.push((mid - half * x, wt * half));
            }
        }
    }
    let mut total = 0.0;
    for (t, ht) in nodes {
        let base = c + w * t;
        // The strip's extent in s: the line base + s·u inside the square.
        let (mut x0, mut x1) = (f64::NEG_INFINITY, f64::INFINITY);
        for (k, bk) in [(u.x, base.x - c.x), (u.y, base.y - c.y)] {
            let (a, b) = ((-LIGHT_H - bk) / k, (LIGHT_H - bk) / k);
            x0 = x0.max(a.min(b));
            x1 = x1.min(a.max(b));
        }
        if x1 <= x0 {
            continue;
        }
        let m = u.cross(base - p);
        let mut hidden: Vec<(f64, f64)> = Vec::new();
        for o in occ {
            let s: Vec<f64> = o.iter().map(|v| m.dot(*v - p)).collect();
            let mut pts = Vec::new();
            for i in 0..o.len() {
                let k = (i + 1) % o.len();
                if (s[i] > 0.0) != (s[k] > 0.0) {
                    pts.push(o[i] + (o[k] - o[i]) * (s[i] / (s[i] - s[k])));
                }
            }
            if pts.len() < 2 {
                continue;
            }
            // Keep the part between p's height and the light's: only there can it come
            // between p and the light.
            let (lo, hi) = (p.z + 1e-12, zl - 1e-12);
            let (mut a, mut b) = (pts[0], pts[1]);
            if (a.z <= lo && b.z <= lo) || (a.z >= hi && b.z >= hi) {
                continue;
            }
            for bound in [lo, hi] {
                let (da, db) = (a.z - bound, b.z - bound);
                if da * db < 0.0 {
                    let x = a + (b - a) * (da / (da - db));
                    let keep_a = if bound == lo { da > 0.0 } else { da < 0.0 };
                    if keep_a {
                        b = x;
                    } else {
                        a = x;
                    }
                }
            }
            let on_light = |q: DVec3| (p + (q - p) * ((zl - p.z) / (q.z - p.z)) - base).dot(u);
            let (sa, sb) = (on_light(a), on_light(b));
            hidden.push((sa.min(sb), sa.max(sb)));
        }
        hidden.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut visible = Vec::new();
        let mut cur = x0;
        for (a, b) in hidden {
            if a > cur {
                visible.push((cur, a.min(x1)));
            }
            cur = cur.max(b);
        }
        if cur < x1 {
            visible.push((cur, x1));
        }
        // The kernel has a kink where the strip leaves p's front half-space.
        let kink = (n.dot(u).abs() > 1e-15).then(|| -n.dot(base - p) / n.dot(u));
        for (a, b) in visible {
            let mut parts = vec![(a, b)];
            if let Some(k) = kink {
                if a < k && k < b {
                    parts = vec![(a, k), (k, b)];
                }
            }
            for (a, b) in parts {
                if b <= a {
                    continue;
                }
                let (mid, h) = (0.5 * (a + b), 0.5 * (b - a));
                let mut sum = 0.0;
                for (x, wt) in gx.iter().zip(&gw) {
                    sum +=
                        wt * (kernel(base + u * (mid + h * x)) + kernel(base + u * (mid - h * x)));
                }
                total += sum * h * ht;
            }
        }
    }
    total
}

/// Reference irradiance at `p` from a point light of intensity 1.
fn point_reference(p: DVec3, n: DVec3, pos: DVec3, occ: &[&Vec<DVec3>]) -> f64 {
    if occ.iter().any(|o| segment_hits(p, pos, o)) {
        return 0.0;
    }
    let d = pos - p;
    n.dot(d).max(0.0) / d.length().powi(3)
}

/// Points where an edge of some polygon other than the receiver passes through the
/// receiver's plane: the ends and corners of cut lines. Light there depends on the direction
/// of approach even within one side (the occluder is a wedge seen from there), so a vertex
/// has no single value to compare; those vertices are left out.
fn cut_corners(recv: &[DVec3], occ: &[&Vec<DVec3>]) -> Vec<DVec3> {
    let n = penumbra::geom::plane::newell_normal(recv).normalize();
    let dist = |q: DVec3| n.dot(q - recv[0]);
    let mut out = Vec::new();
    for o in occ {
        for i in 0..o.len() {
            let (a, b) = (o[i], o[(i + 1) % o.len()]);
            let (da, db) = (dist(a), dist(b));
            if da.abs() < 1e-12 {
                out.push(a);
            } else if (da > 0.0) != (db > 0.0) && db.abs() >= 1e-12 {
                out.push(a + (b - a) * (da / (da - db)));
            }
        }
    }
    out
}

/// Checks every vertex of every triangle against the reference, evaluated a hair inside
/// that triangle (so on its side of any D0 line), to `tol` of the largest value. Returns the
/// largest value and how many corners were checked.
fn check_vertices(s: &SceneJson, b: &Bake, tol: f64) -> (f64, usize) {
    let polys = polygons(s);
    let mut refs = Vec::new();
    for (mi, bm) in b.meshes.iter().enumerate() {
        for (t, tri) in bm.triangles.iter().enumerate() {
            let src = bm.source_polygon[t] as usize;
            let (_, _, recv) = polys
                .iter()
                .find(|(m, p, _)| *m == mi && *p == src)
                .unwrap();
            let n = penumbra::geom::plane::newell_normal(recv).normalize();
            let occ: Vec<&Vec<DVec3>> = polys
                .iter()
                .filter(|(m, p, _)| !(*m == mi && *p == src))
                .map(|x| &x.2)
                .collect();
            let v: Vec<DVec3> = tri
                .iter()
                .map(|&i| DVec3::from_array(bm.positions[i as usize]))
                .collect();
            let c = (v[0] + v[1] + v[2]) / 3.0;
            let corners = cut_corners(recv, &occ);
            for (k, &vi) in tri.iter().enumerate() {
                if corners.iter().any(|x| (*x - v[k]).length() < 1e-7) {
                    continue;
                }
                let q = v[k] + (c - v[k]) * 1e-7;
                let e = match s.lights[0].point {
                    Some(pos) => point_reference(q, n, DVec3::from_array(pos), &occ),
                    None => area_reference(q, n, &occ),
                };
                let got = bm.colors[vi as usize][0] * std::f64::consts::PI;
                refs.push((e, got, mi, q));
            }
        }
    }
    let max = refs.iter().map(|r| r.0).fold(0.0, f64::max);
    assert!(max > 0.0);
    for (e, got, mi, q) in &refs {
        assert!(
            (e - got).abs() <= tol * max,
            "mesh {mi} vertex at {q}: baked {got}, reference {e} (max {max})"
        );
    }
    (max, refs.len())
}

/// Triangles of `mesh` whose centroid is inside the axis-aligned box lo–hi (strictly, by
/// `margin`) must be umbra for every light and their corners inside it black (but at the
/// ends and corners of cut lines, see `cut_corners`, where the outside's limit may be taken).
fn dark_inside(s: &SceneJson, b: &Bake, mesh: usize, lo: DVec3, hi: DVec3, margin: f64) -> usize {
    let polys = polygons(s);
    let bm = &b.meshes[mesh];
    let mut n = 0;
    for (t, tri) in bm.triangles.iter().enumerate() {
        let src = bm.source_polygon[t] as usize;
        let v: Vec<DVec3> = tri
            .iter()
            .map(|&i| DVec3::from_array(bm.positions[i as usize]))
            .collect();
        let c = (v[0] + v[1] + v[2]) / 3.0;
        if (c - lo).min_element() > margin && (hi - c).min_element() > margin {
            n += 1;
            assert!(
                bm.relation[t].iter().all(|&r| r == 3),
                "triangle {t} inside the solid is not umbra"
            );
            let (_, _, recv) = polys
                .iter()
                .find(|(m, p, _)| *m == mesh && *p == src)
                .unwrap();
            let occ: Vec<&Vec<DVec3>> = polys
                .iter()
                .filter(|(m, p, _)| !(*m == mesh && *p == src))
                .map(|x| &x.2)
                .collect();
            let corners = cut_corners(recv, &occ);
            for (k, &i) in tri.iter().enumerate() {
                // A triangle may reach out of the solid where both sides are umbra (the cut
                // is no discontinuity there): only corners inside must be black.
                let inside =
                    (v[k] - lo).min_element() > -1e-12 && (hi - v[k]).min_element() > -1e-12;
                if !inside || corners.iter().any(|x| (*x - v[k]).length() < 1e-7) {
                    continue;
                }
                assert_eq!(
                    bm.colors[i as usize][0], 0.0,
                    "light leaks inside the solid at {}",
                    v[k]
                );
            }
        }
    }
    n
}

fn check_all(s: &SceneJson) -> (Bake, f64, usize) {
    let b = bake(s);
    check_coverage(s, &b);
    check_relations(s, &b, 0);
    let (max, n) = check_vertices(s, &b, 2e-5);
    (b, max, n)
}

#[test]
fn box_sunk_halfway_into_the_floor_area_light() {
    let s = scene(
        vec![
            floor(),
            mesh("Box", cuboid([-0.3, -0.3, -0.3], [0.3, 0.3, 0.3])),
        ],
        vec![square_light()],
        settings(0.25),
    );
    let (b, _, _) = check_all(&s);
    let lo = DVec3::new(-0.3, -0.3, -1.0);
    let hi = DVec3::new(0.3, 0.3, 1.0);
    assert!(dark_inside(&s, &b, 0, lo, hi, 1e-6) > 0);
    // The floor's cut line is a D0 row: vertices there come in pairs.
    assert!(
        duplicated(&b.meshes[0]) >= 8,
        "{}",
        duplicated(&b.meshes[0])
    );
}

#[test]
fn box_sunk_halfway_into_the_floor_point_light() {
    let s = scene(
        vec![
            floor(),
            mesh("Box", cuboid([-0.3, -0.3, -0.3], [0.3, 0.3, 0.3])),
        ],
        vec![point_light("P", [0.6, 0.4, 1.2])],
        settings(0.25),
    );
    let (b, _, _) = check_all(&s);
    let lo = DVec3::new(-0.3, -0.3, -1.0);
    let hi = DVec3::new(0.3, 0.3, 1.0);
    assert!(dark_inside(&s, &b, 0, lo, hi, 1e-6) > 0);
}

#[test]
fn slab_crossing_the_floor_diagonally() {
    let s = scene(
        vec![
            floor(),
            mesh("Slab", turned_box([0.0, 0.0, 0.0], [0.5, 0.3, 0.05], 0.5)),
        ],
        vec![square_light()],
        settings(0.25),
    );
    check_all(&s);
}

#[test]
fn slab_crossing_the_floor_diagonally_point_light() {
    let s = scene(
        vec![
            floor(),
            mesh("Slab", turned_box([0.0, 0.0, 0.0], [0.5, 0.3, 0.05], -0.6)),
        ],
        vec![point_light("P", [0.4, 0.2, 1.0])],
        settings(0.25),
    );
    check_all(&s);
}

#[test]
fn two_intersecting_boxes() {
    // B passes through A's top and side: both boxes' faces are receivers with cut lines.
    let s = scene(
        vec![
            floor(),
            mesh("A", cuboid([-0.5, -0.3, 0.0], [0.1, 0.3, 0.4])),
            mesh("B", cuboid([-0.1, -0.1, 0.2], [0.3, 0.2, 0.7])),
        ],
        vec![square_light()],
        settings(0.2),
    );
    let (b, _, _) = check_all(&s);
    // A's top inside B stays dark.
    let n = dark_inside(
        &s,
        &b,
        1,
        DVec3::new(-0.1, -0.1, 0.2),
        DVec3::new(0.3, 0.2, 0.7),
        1e-6,
    );
    assert!(n > 0);
}

#[test]
fn thin_leg_through_the_floor_area_light() {
    let s = scene(
        vec![
            floor(),
            mesh("Leg", cuboid([-0.02, -0.02, -0.5], [0.02, 0.02, 0.7])),
        ],
        vec![square_light()],
        settings(0.2),
    );
    let (b, _, _) = check_all(&s);
    dark_inside(
        &s,
        &b,
        0,
        DVec3::new(-0.02, -0.02, -1.0),
        DVec3::new(0.02, 0.02, 1.0),
        1e-9,
    );
}

#[test]
fn thin_leg_through_the_floor_point_light() {
    let s = scene(
        vec![
            floor(),
            mesh("Leg", cuboid([-0.02, -0.02, -0.5], [0.02, 0.02, 0.7])),
        ],
        vec![point_light("P", [0.3, 0.2, 1.0])],
        settings(0.2),
    );
    check_all(&s);
}

#[test]
fn single_face_through_the_floor() {
    // An open quad (not a solid) standing through the floor: its cut line is still D0.
    let s = scene(
        vec![
            floor(),
            mesh(
                "Fin",
                vec![vec![
                    [-0.4, 0.05, -0.2],
                    [0.4, -0.05, -0.2],
                    [0.4, -0.05, 0.5],
                    [-0.4, 0.05, 0.5],
                ]],
            ),
        ],
        vec![square_light()],
        settings(0.25),
    );
    check_all(&s);
}

#[test]
fn reference_is_unoccluded_closed_form() {
    // The strip reference without occluders, under the centre of the square light, against
    // the closed form: four parallel rectangles with a corner above p, each with the
    // point-to-rectangle form factor F, and E = π · L · 4F.
    let p = DVec3::new(LIGHT_C[0], LIGHT_C[1], 0.0);
    let e = area_reference(p, DVec3::Z, &[]);
    let (a, h) = (LIGHT_H, LIGHT_C[2]);
    // Quarter of the square: rectangle a × a with a corner above p.
    let (x, y) = (a / h, a / h);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    let f = (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI);
    let want = 4.0 * std::f64::consts::PI * f;
    assert!((e - want).abs() <= 1e-6 * want, "{e} vs {want}");
}

/// With indirect light on, a box's foot stays an edge of the floor's mesh even where it
/// lies in umbra on both sides: bounced light reaches the floor beside the box and never
/// the floor under it, so no floor triangle may straddle the foot.
#[test]
fn feet_stay_in_the_mesh_for_indirect_light() {
    let floor = mesh("Floor", vec![quad([0.0, 0.0, 0.0], 2.0, 2.0, true)]);
    let cube = mesh("Cube", cuboid([-0.3, -0.3, 0.0], [0.3, 0.3, 0.6]));
    // One small light off to +x: the cube's -x foot is in its umbra on both sides.
    let light = area_light("Lamp", quad([1.5, 0.0, 3.0], 0.1, 0.1, false));
    let settings = SettingsJson {
        element_size: Some(0.25),
        convergence: Some(0.05),
        ..Default::default()
    };
    let b = bake(&scene(vec![floor, cube], vec![light], settings));
    let f = b
        .meshes
        .iter()
        .find(|m| m.name == "Floor")
        .expect("floor baked");
    let side = |p: [f64; 3]| -> i32 {
        let d = 0.3 - p[0].abs().max(p[1].abs());
        if d > 1e-9 {
            1
        } else if d < -1e-9 {
            -1
        } else {
            0
        }
    };
    let mut on_foot = 0;
    for t in &f.triangles {
        let s = t.map(|v| side(f.positions[v as usize]));
        assert!(
            !(s.contains(&1) && s.contains(&-1)),
            "triangle {:?} straddles the cube's foot",
            t.map(|v| f.positions[v as usize])
        );
        on_foot += s.contains(&0) as usize;
    }
    assert!(on_foot > 8);
}

#[test]
fn unlit_side_is_cut_where_a_neighbour_enters_it() {
    // B passes through A's -x side, which faces away from the only light: no light's shadow
    // volumes reach that side, yet bounced light does, and none inside B. Its elements must
    // follow the cut, or the few that span the whole side take the dark of their corners
    // inside B (room-245: 0.09 where Cycles gives 0.90).
    let floor = mesh("Floor", vec![quad([0.0, 0.0, 0.0], 2.0, 2.0, true)]);
    let a = mesh("A", cuboid([-0.3, -0.2, 0.0], [0.1, 0.2, 0.4]));
    let b = mesh("B", cuboid([-0.5, -0.1, 0.0], [-0.2, 0.1, 0.2]));
    let settings = SettingsJson {
        element_size: Some(0.25),
        convergence: Some(0.05),
        ..Default::default()
    };
    let s = scene(vec![floor, a, b], vec![square_light()], settings);
    let side = polygons(&s)
        .into_iter()
        .find(|(m, _, v)| *m == 1 && v.iter().all(|p| (p.x + 0.3).abs() < 1e-12))
        .map(|(_, p, _)| p as u32)
        .expect("A's -x side");
    let baked = bake(&s);
    let am = &baked.meshes[1];
    // +1 outside B, -1 inside, 0 on its boundary (within A's -x plane).
    let where_ = |p: [f64; 3]| -> i32 {
        let d = (0.1 - p[1].abs()).min(0.2 - p[2]);
        if d > 1e-9 {
            -1
        } else if d < -1e-9 {
            1
        } else {
            0
        }
    };
    let (mut outside, mut inside) = (0, 0);
    for (t, tri) in am.triangles.iter().enumerate() {
        if am.source_polygon[t] != side {
            continue;
        }
        let w = tri.map(|v| where_(am.positions[v as usize]));
        assert!(
            !(w.contains(&1) && w.contains(&-1)),
            "triangle {:?} straddles B's cut",
            tri.map(|v| am.positions[v as usize])
        );
        if w.contains(&1) {
            outside += 1;
            // Lit by the floor and the room around: every corner of it, on the cut too.
            for &v in tri {
                assert!(
                    am.colors[v as usize][0] > 0.0,
                    "dark corner {:?} outside B",
                    am.positions[v as usize]
                );
            }
        } else {
            inside += 1;
            for &v in tri {
                assert_eq!(am.colors[v as usize], [0.0; 3], "light inside B");
            }
        }
    }
    assert!(
        outside > 0 && inside > 0,
        "{outside} outside, {inside} inside"
    );
}
