//! Built-in scenes (the paper's test data, the Cornell box, the demo room) for the CLI's `scene`
//! command, the benchmarks and the tests. Each returns scene JSON v1 (see the README) in Blender's conventions:
//! metres, Z up, polygons counter-clockwise seen from their front.

use std::f64::consts::{PI, TAU};

use crate::scene::json::{LightJson, MeshJson, PerPolygon, SceneJson, SettingsJson};

type P = [f64; 3];

fn mesh(name: &str, polys: Vec<Vec<P>>, albedo: [f64; 3]) -> MeshJson {
    polygons_mesh(name, polys, Some(albedo))
}

/// A mesh of separate polygons (no shared vertices), with one albedo for all or the
/// format's default.
pub fn polygons_mesh(name: &str, polys: Vec<Vec<P>>, albedo: Option<[f64; 3]>) -> MeshJson {
    let mut positions = Vec::new();
    let mut polygons = Vec::new();
    for p in polys {
        let start = positions.len() as i64;
        polygons.push((0..p.len() as i64).map(|i| start + i).collect());
        positions.extend(p);
    }
    MeshJson {
        name: name.into(),
        positions,
        polygons,
        albedo: albedo.map(PerPolygon::Uniform),
        emission: None,
        uv: None,
        output: None,
    }
}

/// A horizontal rectangle, facing up or down, split into nx × ny quads.
fn grid(c: P, hx: f64, hy: f64, nx: usize, ny: usize, up: bool) -> Vec<Vec<P>> {
    let mut out = Vec::new();
    for i in 0..nx {
        for j in 0..ny {
            let x0 = c[0] - hx + 2.0 * hx * i as f64 / nx as f64;
            let x1 = c[0] - hx + 2.0 * hx * (i + 1) as f64 / nx as f64;
            let y0 = c[1] - hy + 2.0 * hy * j as f64 / ny as f64;
            let y1 = c[1] - hy + 2.0 * hy * (j + 1) as f64 / ny as f64;
            let mut q = vec![
                [x0, y0, c[2]],
                [x1, y0, c[2]],
                [x1, y1, c[2]],
                [x0, y1, c[2]],
            ];
            if !up {
                q.reverse();
            }
            out.push(q);
        }
    }
    out
}

/// A closed box, faces outward (or inward, for a room).
pub fn cuboid(lo: P, hi: P, inward: bool) -> Vec<Vec<P>> {
    let [x0, y0, z0] = lo;
    let [x1, y1, z1] = hi;
    let mut f = vec![
        vec![[x0, y0, z0], [x0, y1, z0], [x1, y1, z0], [x1, y0, z0]],
        vec![[x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]],
        vec![[x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1]],
        vec![[x1, y1, z0], [x0, y1, z0], [x0, y1, z1], [x1, y1, z1]],
        vec![[x1, y0, z0], [x1, y1, z0], [x1, y1, z1], [x1, y0, z1]],
        vec![[x0, y1, z0], [x0, y0, z0], [x0, y0, z1], [x0, y1, z1]],
    ];
    if inward {
        for p in &mut f {
            p.reverse();
        }
    }
    f
}

/// A UV sphere with `seg` segments and `rings` rings (triangle fans at the poles).
pub fn uv_sphere(c: P, r: f64, seg: usize, rings: usize) -> Vec<Vec<P>> {
    let pt = |i: usize, j: usize| -> P {
        let th = PI * j as f64 / rings as f64;
        let ph = TAU * (i % seg) as f64 / seg as f64;
        // One vertex per pole, as Blender makes it (sin π is not exactly 0).
        if j == 0 || j == rings {
            return [c[0], c[1], c[2] + if j == 0 { r } else { -r }];
        }
        [
            c[0] + r * th.sin() * ph.cos(),
            c[1] + r * th.sin() * ph.sin(),
            c[2] + r * th.cos(),
        ]
    };
    let mut out = Vec::new();
    for j in 0..rings {
        for i in 0..seg {
            let (a, b, cc, d) = (pt(i, j), pt(i + 1, j), pt(i + 1, j + 1), pt(i, j + 1));
            if j == 0 {
                out.push(vec![a, d, cc]);
            } else if j == rings - 1 {
                out.push(vec![a, d, b]);
            } else {
                out.push(vec![a, d, cc, b]);
            }
        }
    }
    out
}

fn square_light(name: &str, c: P, side: f64, power: f64) -> LightJson {
    let h = side / 2.0;
    // Facing down: clockwise seen from above.
    let polygon = vec![
        [c[0] - h, c[1] - h, c[2]],
        [c[0] - h, c[1] + h, c[2]],
        [c[0] + h, c[1] + h, c[2]],
        [c[0] + h, c[1] - h, c[2]],
    ];
    // Blender's convention for an area light of power P and area A: L = P / (π A).
    let l = power / (PI * side * side);
    LightJson {
        name: name.into(),
        polygon: Some(polygon),
        radiance: Some([l; 3]),
        ..Default::default()
    }
}

fn wrap(meshes: Vec<MeshJson>, lights: Vec<LightJson>, settings: SettingsJson) -> SceneJson {
    SceneJson {
        format: "penumbra-scene".into(),
        version: 1,
        meshes,
        lights,
        settings,
    }
}

/// Paper Data 1 analogue: a box room (inward walls) with a box occluder under one area light.
pub fn data1() -> SceneJson {
    wrap(
        vec![
            mesh(
                "Room",
                cuboid([-2., -2., 0.], [2., 2., 3.], true),
                [0.7, 0.7, 0.7],
            ),
            mesh(
                "Block",
                cuboid([-0.5, -0.4, 0.6], [0.5, 0.4, 1.0], false),
                [0.8, 0.5, 0.3],
            ),
        ],
        vec![square_light("Ceiling", [0., 0., 2.95], 0.8, 400.0)],
        SettingsJson::default(),
    )
}

/// Paper Data 2 analogue: a 32×16 UV sphere over a floor under a very small light
/// (0.06 wide). `seg` × `rings` may be raised for the scaling series.
pub fn data2(seg: usize, rings: usize) -> SceneJson {
    wrap(
        vec![
            mesh(
                "Floor",
                grid([0., 0., 0.], 4., 4., 1, 1, true),
                [0.8, 0.8, 0.8],
            ),
            mesh(
                "Sphere",
                uv_sphere([0., 0., 1.5], 1.0, seg, rings),
                [0.8, 0.2, 0.2],
            ),
        ],
        vec![square_light("Small", [0.5, 0.3, 4.0], 0.06, 50.0)],
        SettingsJson::default(),
    )
}

/// Paper Table 3 analogue: a chair of boxes under two lights.
pub fn chair() -> SceneJson {
    let mut parts = Vec::new();
    for (x, y) in [(-0.2, -0.2), (0.2, -0.2), (0.2, 0.2), (-0.2, 0.2)] {
        parts.extend(cuboid(
            [x - 0.025, y - 0.025, 0.0],
            [x + 0.025, y + 0.025, 0.45],
            false,
        ));
    }
    parts.extend(cuboid([-0.25, -0.25, 0.45], [0.25, 0.25, 0.5], false));
    parts.extend(cuboid([-0.25, 0.2, 0.5], [0.25, 0.25, 1.0], false));
    wrap(
        vec![
            mesh(
                "Floor",
                grid([0., 0., 0.], 2., 2., 1, 1, true),
                [0.8, 0.8, 0.8],
            ),
            mesh("Chair", parts, [0.6, 0.4, 0.2]),
        ],
        vec![
            square_light("Key", [0.6, -0.5, 2.0], 0.4, 150.0),
            square_light("Fill", [-0.8, 0.4, 2.2], 0.6, 80.0),
        ],
        SettingsJson::default(),
    )
}

/// A Cornell box (1 m): white floor, ceiling and back, red left, green right, two blocks.
pub fn cornell() -> SceneJson {
    let room = cuboid([0., 0., 0.], [1., 1., 1.], true);
    // cuboid order: bottom, top, front(y0), back(y1), right(x1), left(x0).
    let (white, red, green) = ([0.73, 0.73, 0.73], [0.65, 0.05, 0.05], [0.12, 0.45, 0.15]);
    let mut shell = mesh(
        "Box",
        vec![
            room[0].clone(),
            room[1].clone(),
            room[3].clone(),
            room[4].clone(),
            room[5].clone(),
        ],
        white,
    );
    shell.albedo = Some(PerPolygon::PerPolygon(vec![
        white, white, white, green, red,
    ]));
    wrap(
        vec![
            shell,
            mesh(
                "Short",
                cuboid([0.55, 0.15, 0.0], [0.85, 0.45, 0.3], false),
                white,
            ),
            mesh(
                "Tall",
                cuboid([0.15, 0.45, 0.0], [0.45, 0.75, 0.6], false),
                white,
            ),
        ],
        vec![square_light("Lamp", [0.5, 0.5, 0.999], 0.25, 30.0)],
        SettingsJson::default(),
    )
}

/// A room with a table and a chair under an area light (paper Fig. 11), with `clutter`
/// extra boxes on the table for the scaling series (each adds 6 faces).
pub fn room(clutter: usize) -> SceneJson {
    let mut table = Vec::new();
    table.extend(cuboid([-0.6, -0.4, 0.7], [0.6, 0.4, 0.75], false));
    for (x, y) in [(-0.55, -0.35), (0.55, -0.35), (0.55, 0.35), (-0.55, 0.35)] {
        table.extend(cuboid(
            [x - 0.03, y - 0.03, 0.0],
            [x + 0.03, y + 0.03, 0.7],
            false,
        ));
    }
    let mut stuff = Vec::new();
    let mut s = 0x2545_F491_4F6C_DD1Du64;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..clutter {
        let (x, y) = (-0.55 + 1.1 * rnd(), -0.35 + 0.7 * rnd());
        let (w, d, h) = (0.01 + 0.04 * rnd(), 0.01 + 0.04 * rnd(), 0.01 + 0.1 * rnd());
        stuff.extend(cuboid(
            [x - w, y - d, 0.75],
            [x + w, y + d, 0.75 + h],
            false,
        ));
    }
    let mut meshes = vec![
        mesh(
            "Room",
            cuboid([-2., -2., 0.], [2., 2., 2.6], true),
            [0.75, 0.75, 0.72],
        ),
        mesh("Table", table, [0.55, 0.35, 0.2]),
    ];
    if !stuff.is_empty() {
        meshes.push(mesh("Clutter", stuff, [0.3, 0.5, 0.7]));
    }
    wrap(
        meshes,
        vec![square_light("Ceiling", [0.3, 0.2, 2.55], 0.6, 300.0)],
        SettingsJson::default(),
    )
}

/// Round lights in an unbaked room (issue 14): a floor, a table and a block (the outputs) in
/// an open-topped room whose walls only cast shadows and reflect (`output: false`), lit by a
/// point light of radius 0.2, a spot of radius 0.1 with a blend, and a sun of angle 5°
/// through the open top.
pub fn mixed() -> SceneJson {
    let room = cuboid([-2., -2., 0.], [2., 2., 2.6], true);
    let mut walls = mesh("Room", room[2..].to_vec(), [0.75, 0.75, 0.72]);
    walls.output = Some(false);
    let mut table = cuboid([-0.6, -0.4, 0.7], [0.6, 0.4, 0.75], false);
    for (x, y) in [(-0.55, -0.35), (0.55, -0.35), (0.55, 0.35), (-0.55, 0.35)] {
        table.extend(cuboid(
            [x - 0.03, y - 0.03, 0.0],
            [x + 0.03, y + 0.03, 0.7],
            false,
        ));
    }
    let point = |name: &str, c: P, power: f64, radius: f64| LightJson {
        name: name.into(),
        point: Some(c),
        // Blender's convention: intensity = power / 4π.
        intensity: Some([power / (4.0 * PI); 3]),
        radius: Some(radius),
        ..Default::default()
    };
    let mut spot = point("Spot", [1.2, 0.9, 2.3], 150.0, 0.1);
    spot.spot = Some(crate::scene::json::SpotJson {
        direction: [-1.2, -0.9, -1.6],
        angle: 50f64.to_radians(),
        blend: 0.2,
    });
    let sun = LightJson {
        name: "Sun".into(),
        direction: Some([0.35, 0.25, -1.0]),
        irradiance: Some([2.0, 1.9, 1.7]),
        angle: Some(5f64.to_radians()),
        ..Default::default()
    };
    wrap(
        vec![
            walls,
            mesh("Floor", vec![room[0].clone()], [0.6, 0.6, 0.6]),
            mesh("Table", table, [0.55, 0.35, 0.2]),
            mesh(
                "Block",
                cuboid([0.8, -1.3, 0.0], [1.3, -0.8, 0.6], false),
                [0.5, 0.5, 0.55],
            ),
        ],
        vec![point("Bulb", [-0.9, 0.7, 1.8], 80.0, 0.2), spot, sun],
        SettingsJson::default(),
    )
}

/// Looks a built-in scene up by name: one of `NAMES`, or `data2-SEGxRINGS` (a finer
/// sphere) or `room-N` (N clutter boxes of 12 triangles each on the table).
pub fn by_name(name: &str) -> Option<SceneJson> {
    if let Some(rest) = name.strip_prefix("data2-") {
        let (a, b) = rest.split_once('x')?;
        let (seg, rings): (usize, usize) = (a.parse().ok()?, b.parse().ok()?);
        return (seg >= 3 && rings >= 2 && seg * rings <= 4_000_000).then(|| data2(seg, rings));
    }
    if let Some(n) = name.strip_prefix("room-") {
        let n: usize = n.parse().ok()?;
        return (n <= 1_000_000).then(|| room(n));
    }
    Some(match name {
        "data1" => data1(),
        "data2" => data2(32, 16),
        "chair" => chair(),
        "cornell" => cornell(),
        "room" => room(0),
        "mixed" => mixed(),
        _ => return None,
    })
}

pub const NAMES: [&str; 8] = [
    "data1",
    "data2",
    "chair",
    "cornell",
    "room",
    "mixed",
    "data2-SEGxRINGS",
    "room-N",
];
