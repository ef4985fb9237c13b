//! Random geometry: the fuzzer's bytes become a floor and a few boxes, quads and triangles
//! at a random scale and offset, under one light of any kind (area, point, round point or
//! sphere, spot with a cone, blend and radius, sun with or without an angle). Some meshes
//! may have no output, and indirect light may be on, so that scenery is meshed coarsely.
//! Every such scene must bake with nothing lost (`coverage::check` runs inside `bake`, so a
//! "geometry lost" error is a failure) or be refused on one line by the precision
//! contract; colours finite and ≥ 0.
#![no_main]

use libfuzzer_sys::fuzz_target;
use penumbra::scene::json::{LightJson, MeshJson, SceneJson, SettingsJson, SpotJson};
use penumbra::{BakeError, Progress};

/// Reads the input as a stream of small numbers.
struct Bytes<'a>(&'a [u8]);
impl Bytes<'_> {
    fn u8(&mut self) -> u8 {
        let Some((&b, rest)) = self.0.split_first() else {
            return 0;
        };
        self.0 = rest;
        b
    }
    /// In [a, b], quantised to 1/65535 of the range (exact repeats make coplanar and
    /// touching cases common).
    fn range(&mut self, a: f64, b: f64) -> f64 {
        let v = u16::from_le_bytes([self.u8(), self.u8()]) as f64 / 65535.0;
        a + (b - a) * v
    }
}

fn mesh(name: String, polys: Vec<Vec<[f64; 3]>>) -> MeshJson {
    let mut positions = Vec::new();
    let mut polygons = Vec::new();
    for p in polys {
        let at = positions.len() as i64;
        polygons.push((0..p.len() as i64).map(|k| at + k).collect());
        positions.extend(p);
    }
    MeshJson {
        name,
        positions,
        polygons,
        albedo: None,
        emission: None,
        uv: None,
        output: None,
    }
}

fn cuboid(lo: [f64; 3], hi: [f64; 3]) -> Vec<Vec<[f64; 3]>> {
    let p = |i: usize| {
        [
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]
    };
    // Outward-facing, counter-clockwise seen from outside.
    [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ]
    .iter()
    .map(|f| f.iter().map(|&i| p(i)).collect())
    .collect()
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let scale = 10f64.powi(b.u8() as i32 % 13 - 6);
    let offset = [
        b.range(-1.0, 1.0) * 10f64.powi(b.u8() as i32 % 13),
        b.range(-1.0, 1.0) * 10f64.powi(b.u8() as i32 % 13),
        0.0,
    ];
    let floor = vec![vec![
        [-2.0, -2.0, 0.0],
        [2.0, -2.0, 0.0],
        [2.0, 2.0, 0.0],
        [-2.0, 2.0, 0.0],
    ]];
    let mut meshes = vec![mesh("Floor".into(), floor)];
    for k in 0..(b.u8() % 5) {
        let c = [b.range(-1.5, 1.5), b.range(-1.5, 1.5), b.range(-0.5, 1.5)];
        let polys = match b.u8() % 3 {
            0 => {
                let s = [b.range(0.0, 1.0), b.range(0.0, 1.0), b.range(0.0, 1.0)];
                cuboid(c, [c[0] + s[0], c[1] + s[1], c[2] + s[2]])
            }
            1 => {
                let (w, h) = (b.range(0.0, 1.0), b.range(0.0, 1.0));
                vec![vec![
                    c,
                    [c[0] + w, c[1], c[2]],
                    [c[0] + w, c[1] + h, c[2]],
                    [c[0], c[1] + h, c[2]],
                ]]
            }
            _ => (0..1 + b.u8() % 4)
                .map(|_| {
                    (0..3)
                        .map(|_| {
                            [
                                c[0] + b.range(-0.5, 0.5),
                                c[1] + b.range(-0.5, 0.5),
                                c[2] + b.range(-0.5, 0.5),
                            ]
                        })
                        .collect()
                })
                .collect(),
        };
        let mut m = mesh(format!("M{k}"), polys);
        m.output = (b.u8() % 4 == 0).then_some(false);
        meshes.push(m);
    }
    let radius = b.range(0.0, 0.4);
    let spot = |b: &mut Bytes| SpotJson {
        direction: [b.range(-0.5, 0.5), b.range(-0.5, 0.5), -1.0],
        angle: b.range(0.1, 3.0),
        blend: b.range(0.0, 1.0),
    };
    let light = match b.u8() % 7 {
        3 => LightJson {
            name: "L".into(),
            point: Some([b.range(-1.0, 1.0), b.range(-1.0, 1.0), b.range(0.0, 3.0)]),
            intensity: Some([1.0; 3]),
            radius: Some(radius),
            sphere: Some(b.u8() % 2 == 0),
            ..Default::default()
        },
        4 => LightJson {
            name: "L".into(),
            point: Some([b.range(-1.0, 1.0), b.range(-1.0, 1.0), b.range(0.0, 3.0)]),
            intensity: Some([1.0; 3]),
            spot: Some(spot(&mut b)),
            ..Default::default()
        },
        5 => LightJson {
            name: "L".into(),
            point: Some([b.range(-1.0, 1.0), b.range(-1.0, 1.0), b.range(0.0, 3.0)]),
            intensity: Some([1.0; 3]),
            spot: Some(spot(&mut b)),
            radius: Some(radius),
            ..Default::default()
        },
        6 => LightJson {
            name: "L".into(),
            direction: Some([b.range(-1.0, 1.0), b.range(-1.0, 1.0), -1.0]),
            irradiance: Some([1.0; 3]),
            angle: Some(b.range(0.0, 0.5)),
            ..Default::default()
        },
        0 => LightJson {
            name: "L".into(),
            polygon: Some(vec![
                [-0.3, -0.3, 2.5],
                [-0.3, 0.3, 2.5],
                [0.3, 0.3, 2.5],
                [0.3, -0.3, 2.5],
            ]),
            radiance: Some([1.0; 3]),
            ..Default::default()
        },
        1 => LightJson {
            name: "L".into(),
            point: Some([b.range(-1.0, 1.0), b.range(-1.0, 1.0), b.range(0.0, 3.0)]),
            intensity: Some([1.0; 3]),
            ..Default::default()
        },
        _ => LightJson {
            name: "L".into(),
            direction: Some([b.range(-1.0, 1.0), b.range(-1.0, 1.0), -1.0]),
            irradiance: Some([1.0; 3]),
            ..Default::default()
        },
    };
    let mut s = SceneJson {
        format: "penumbra-scene".into(),
        version: 1,
        meshes,
        lights: vec![light],
        settings: SettingsJson {
            // Indirect light only now and then: it is the slow stage, and scenery meshing
            // (meshes without output) happens only with it on.
            indirect: Some(b.u8() % 8 == 0),
            patch_size: Some(0.5 * scale),
            threads: Some(1),
            element_size: Some(0.5 * scale),
            ..Default::default()
        },
    };
    let map = |p: &mut [f64; 3]| {
        for k in 0..3 {
            p[k] = p[k] * scale + offset[k];
        }
    };
    for m in &mut s.meshes {
        m.positions.iter_mut().for_each(map);
    }
    for l in &mut s.lights {
        l.polygon.iter_mut().flatten().for_each(map);
        l.point.iter_mut().for_each(map);
        l.radius = l.radius.map(|r| r * scale);
    }
    let result = penumbra::scene::validate(&s).and_then(|sc| penumbra::bake(&sc, &Progress::new()));
    match result {
        Ok(bake) => {
            for m in &bake.meshes {
                assert!(m
                    .colors
                    .iter()
                    .flatten()
                    .all(|c| c.is_finite() && *c >= 0.0));
            }
        }
        Err(e @ BakeError::Invalid { .. }) => {
            let msg = e.to_string();
            assert!(!msg.contains("geometry lost"), "{msg}");
            assert_eq!(msg.lines().count(), 1, "{msg}");
        }
        Err(e) => assert_eq!(e.to_string().lines().count(), 1, "{e}"),
    }
});
