//! Scene builders shared by the integration tests.
#![allow(dead_code)]

use glam::DVec3;
use penumbra::geom::polygon::clip_polygon_3d;
use penumbra::geom::Plane;
use penumbra::scene::json::{LightJson, MeshJson, SceneJson, SettingsJson};
use penumbra::{Bake, Progress};

pub fn quad(c: [f64; 3], hx: f64, hy: f64, up: bool) -> Vec<[f64; 3]> {
    let mut v = vec![
        [c[0] - hx, c[1] - hy, c[2]],
        [c[0] + hx, c[1] - hy, c[2]],
        [c[0] + hx, c[1] + hy, c[2]],
        [c[0] - hx, c[1] + hy, c[2]],
    ];
    if !up {
        v.reverse();
    }
    v
}

pub fn mesh(name: &str, polys: Vec<Vec<[f64; 3]>>) -> MeshJson {
    penumbra::scenes::polygons_mesh(name, polys, None)
}

pub fn area_light(name: &str, polygon: Vec<[f64; 3]>) -> LightJson {
    LightJson {
        name: name.into(),
        polygon: Some(polygon),
        radiance: Some([1.0; 3]),
        ..Default::default()
    }
}

pub fn point_light(name: &str, p: [f64; 3]) -> LightJson {
    LightJson {
        name: name.into(),
        point: Some(p),
        intensity: Some([1.0; 3]),
        ..Default::default()
    }
}

pub fn scene(meshes: Vec<MeshJson>, lights: Vec<LightJson>, settings: SettingsJson) -> SceneJson {
    SceneJson {
        format: "penumbra-scene".into(),
        version: 1,
        meshes,
        lights,
        settings,
    }
}

pub fn bake(s: &SceneJson) -> Bake {
    let sc = penumbra::scene::validate(s).expect("valid scene");
    penumbra::bake(&sc, &Progress::new()).expect("bake")
}

pub fn tri_area(p: &[[f64; 3]], t: [u32; 3]) -> f64 {
    let a = glam::DVec3::from_array(p[t[0] as usize]);
    let b = glam::DVec3::from_array(p[t[1] as usize]);
    let c = glam::DVec3::from_array(p[t[2] as usize]);
    (b - a).cross(c - a).length() * 0.5
}

pub struct Rng(pub u64);
impl Rng {
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

pub fn area3(p: &[DVec3]) -> f64 {
    if p.len() < 3 {
        return 0.0;
    }
    penumbra::geom::plane::newell_normal(p).length() * 0.5
}

/// The part of light polygon `l` hidden from `p` by convex polygon `o`: `l` clipped by the
/// planes through p and each edge of o (o's side) and by o's plane (the side away from p).
pub fn blocked(p: DVec3, l: &[DVec3], o: &[DVec3]) -> Vec<DVec3> {
    let Some(op) = Plane::from_polygon(o) else {
        return vec![];
    };
    let dp = op.dist(p);
    if dp.abs() < 1e-12 {
        return vec![];
    }
    let c = o.iter().copied().sum::<DVec3>() / o.len() as f64;
    let mut b = l.to_vec();
    for i in 0..o.len() {
        let n = (o[i] - p).cross(o[(i + 1) % o.len()] - p);
        if n.length() == 0.0 {
            return vec![];
        }
        let mut h = Plane::from_point_normal(p, n);
        if h.dist(c) < 0.0 {
            h = h.flipped();
        }
        b = clip_polygon_3d(&b, &h, 0.0);
    }
    let far = if dp > 0.0 { op.flipped() } else { op };
    clip_polygon_3d(&b, &far, 0.0)
}

pub fn segment_hits(p: DVec3, q: DVec3, o: &[DVec3]) -> bool {
    let Some(op) = Plane::from_polygon(o) else {
        return false;
    };
    let (a, b) = (op.dist(p), op.dist(q));
    if a * b >= 0.0 {
        return false;
    }
    let x = p + (q - p) * (a / (a - b));
    let n = op.n;
    (0..o.len()).all(|i| (o[(i + 1) % o.len()] - o[i]).cross(x - o[i]).dot(n) >= 0.0)
}

/// Checks every triangle's relation codes against exact visibility at three interior
/// points; returns how many (point, light) pairs had each code.
pub fn check_relations(s: &SceneJson, b: &Bake, seed: u64) -> [usize; 4] {
    let mut checked = [0usize; 4];
    let polys: Vec<(usize, usize, Vec<DVec3>)> = s
        .meshes
        .iter()
        .enumerate()
        .flat_map(|(mi, m)| {
            m.polygons.iter().enumerate().map(move |(pi, p)| {
                (
                    mi,
                    pi,
                    p.iter()
                        .map(|&i| DVec3::from_array(m.positions[i as usize]))
                        .collect(),
                )
            })
        })
        .collect();
    for (mi, bm) in b.meshes.iter().enumerate() {
        for (t, tri) in bm.triangles.iter().enumerate() {
            let src = bm.source_polygon[t] as usize;
            let recv = &polys
                .iter()
                .find(|(m, p, _)| *m == mi && *p == src)
                .unwrap()
                .2;
            let rplane = Plane::from_polygon(recv).unwrap();
            let v: Vec<DVec3> = tri
                .iter()
                .map(|&i| DVec3::from_array(bm.positions[i as usize]))
                .collect();
            if area3(&v) < 1e-10 {
                continue;
            }
            for w in [
                [1. / 3., 1. / 3., 1. / 3.],
                [0.6, 0.2, 0.2],
                [0.2, 0.2, 0.6],
            ] {
                let p = v[0] * w[0] + v[1] * w[1] + v[2] * w[2];
                for (li, l) in s.lights.iter().enumerate() {
                    let code = bm.relation[t][li];
                    checked[code as usize] += 1;
                    let occluders = polys.iter().filter(|(m, pi, _)| !(*m == mi && *pi == src));
                    if let Some(pos) = l.point {
                        let pos = DVec3::from_array(pos);
                        let hidden = rplane.dist(pos) <= 0.0
                            || occluders.clone().any(|(_, _, o)| segment_hits(p, pos, o));
                        assert_eq!(
                            code,
                            if hidden { 3 } else { 1 },
                            "seed {seed} mesh {mi} tri {t} point light"
                        );
                        continue;
                    }
                    let lv: Vec<DVec3> = l
                        .polygon
                        .as_ref()
                        .unwrap()
                        .iter()
                        .map(|x| DVec3::from_array(*x))
                        .collect();
                    let lplane = Plane::from_polygon(&lv).unwrap();
                    let lf = clip_polygon_3d(&lv, &rplane, 0.0);
                    let la = area3(&lf);
                    if la <= 1e-12 || lplane.dist(p) <= 0.0 {
                        assert_eq!(code, 3, "seed {seed} mesh {mi} tri {t}: light behind");
                        continue;
                    }
                    let occ_ids: Vec<(usize, usize)> =
                        occluders.clone().map(|(m, pi, _)| (*m, *pi)).collect();
                    let hidden: Vec<f64> = occluders
                        .map(|(_, _, o)| area3(&blocked(p, &lf, o)))
                        .collect();
                    let arg = hidden
                        .iter()
                        .enumerate()
                        .fold((0, 0.0), |a, (i, &h)| if h > a.1 { (i, h) } else { a })
                        .0;
                    let max = hidden.iter().cloned().fold(0.0, f64::max);
                    match code {
                            1 => assert!(max <= 1e-9 * la, "seed {seed} mesh {mi} tri {t} light {li}: lit but {max} of {la} hidden by {:?} {} at {p}", occ_ids.get(arg), s.meshes[occ_ids[arg].0].name),
                            3 => assert!(
                                max >= la * (1.0 - 1e-9) || all_samples_blocked(p, &lf, polys.iter().filter(|(m, pi, _)| !(*m == mi && *pi == src)).map(|x| &x.2)),
                                "seed {seed} mesh {mi} tri {t} light {li}: umbra but only {max} of {la} hidden"
                            ),
                            2 => assert!(max > 0.0, "seed {seed} mesh {mi} tri {t} light {li}: penumbra but nothing hidden"),
                            c => panic!("code {c}"),
                        }
                }
            }
        }
    }
    checked
}

/// The elements of every input polygon cover exactly its area, and no triangle is inverted
/// relative to the polygon's facing.
pub fn check_coverage(s: &SceneJson, b: &Bake) {
    for (mi, m) in s.meshes.iter().enumerate() {
        let bm = &b.meshes[mi];
        let mut got = vec![0.0; m.polygons.len()];
        for (t, tri) in bm.triangles.iter().enumerate() {
            let v: Vec<DVec3> = tri
                .iter()
                .map(|&i| DVec3::from_array(bm.positions[i as usize]))
                .collect();
            let poly: Vec<DVec3> = m.polygons[bm.source_polygon[t] as usize]
                .iter()
                .map(|&i| DVec3::from_array(m.positions[i as usize]))
                .collect();
            let n = penumbra::geom::plane::newell_normal(&poly);
            let tn = (v[1] - v[0]).cross(v[2] - v[0]);
            assert!(tn.dot(n) >= 0.0, "mesh {mi} triangle {t} is flipped");
            got[bm.source_polygon[t] as usize] += tn.length() * 0.5;
        }
        for (pi, p) in m.polygons.iter().enumerate() {
            let poly: Vec<DVec3> = p
                .iter()
                .map(|&i| DVec3::from_array(m.positions[i as usize]))
                .collect();
            let want = area3(&poly);
            assert!(
                (got[pi] - want).abs() <= 1e-9 * want.max(1e-300),
                "mesh {mi} polygon {pi}: elements cover {} of {}",
                got[pi],
                want
            );
        }
    }
}

/// A closed axis-aligned box (outward faces) as polygons.
pub fn cuboid(lo: [f64; 3], hi: [f64; 3]) -> Vec<Vec<[f64; 3]>> {
    penumbra::scenes::cuboid(lo, hi, false)
}

#[allow(unused_imports)]
pub use penumbra::scenes::uv_sphere;

/// Every one of a spread of points on the light (its vertices pulled a hair inside, and a
/// grid over its fan) is hidden from p by some polygon: the union of occluders hides it.
pub fn all_samples_blocked<'a>(
    p: DVec3,
    l: &[DVec3],
    occ: impl Iterator<Item = &'a Vec<DVec3>> + Clone,
) -> bool {
    let c = l.iter().copied().sum::<DVec3>() / l.len() as f64;
    let mut samples = vec![c];
    for i in 0..l.len() {
        let (a, b) = (l[i], l[(i + 1) % l.len()]);
        for u in 0..6 {
            for v in 0..6 - u {
                let (fu, fv) = ((u as f64 + 0.25) / 6.0, (v as f64 + 0.25) / 6.0);
                samples.push(c + (a - c) * fu + (b - c) * fv);
            }
        }
        samples.push(a + (c - a) * 1e-6);
    }
    samples
        .iter()
        .all(|&q| occ.clone().any(|o| segment_hits(p, q, o)))
}

/// Positions that occur more than once in a mesh (to 1e-9): D0 rows.
pub fn duplicated(bm: &penumbra::BakedMesh) -> usize {
    let mut pos: Vec<[i64; 3]> = bm
        .positions
        .iter()
        .map(|p| p.map(|x| (x * 1e9).round() as i64))
        .collect();
    let n = pos.len();
    pos.sort();
    pos.dedup();
    n - pos.len()
}

/// Irradiance from a unit-radiance rectangle at height h whose corner is straight above the
/// point, extending a × b (the classic corner form factor, times π).
pub fn corner(a: f64, b: f64, h: f64) -> f64 {
    let (a, b) = (a / h, b / h);
    let (sa, sb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
    0.5 * (a / sa * (b / sa).atan() + b / sb * (a / sb).atan())
}

pub fn signed_corner(x: f64, y: f64, h: f64) -> f64 {
    x.signum() * y.signum() * corner(x.abs(), y.abs(), h)
}

/// Irradiance at (px, py, 0) from the unit-radiance rectangle [x0,x1]×[y0,y1] at height h.
pub fn rect(px: f64, py: f64, [x0, x1, y0, y1]: [f64; 4], h: f64) -> f64 {
    if x1 <= x0 || y1 <= y0 {
        return 0.0;
    }
    let g = |x: f64, y: f64| signed_corner(x - px, y - py, h);
    g(x1, y1) - g(x0, y1) - g(x1, y0) + g(x0, y0)
}

/// The square-over-floor scene's closed form at the floor point (x, y, 0): the irradiance
/// from the unit-radiance light [−0.5, 0.5]² at z = 2, and the part of it the occluder
/// [−0.4, 0.4]² at z = 1 hides (light points l with (p + l)/2 inside the occluder).
pub fn square_over_square(x: f64, y: f64) -> (f64, f64) {
    let full = rect(x, y, [-0.5, 0.5, -0.5, 0.5], 2.0);
    let hid = rect(
        x,
        y,
        [
            (-0.8 - x).max(-0.5),
            (0.8 - x).min(0.5),
            (-0.8 - y).max(-0.5),
            (0.8 - y).min(0.5),
        ],
        2.0,
    );
    (full, hid)
}

/// The worst-case scripts' light: 0.6 × 0.6 at height 3, facing down, radiance 1.
pub fn lamp() -> Vec<[f64; 3]> {
    quad([0., 0., 3.], 0.3, 0.3, false)
}

/// `side` × `side` small quads at 13 heights in 0.5–0.8 over a 4 × 4 floor, under the lamp
/// (quads2000 is 45 × 45).
pub fn quads(side: usize) -> Vec<Vec<[f64; 3]>> {
    let step = 3.0 / side as f64;
    (0..side * side)
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
        .collect()
}

/// The quads over the floor under `lamp` (tests/worst_cases.rs, tests/tolerance.rs).
pub fn quads_scene(side: usize, settings: SettingsJson) -> SceneJson {
    scene(
        vec![
            mesh("Floor", vec![quad([0., 0., 0.], 2., 2., true)]),
            mesh("Quads", quads(side)),
        ],
        vec![area_light("Lamp", lamp())],
        settings,
    )
}
