//! Lightmaps against closed forms: exact texel means of the direct light on a floor.

use std::f64::consts::PI;

use glam::DVec3;

use super::*;
use crate::geom::lambert::polygon_irradiance;
use crate::{bake_scene_json, Bake};

const ALBEDO: f64 = 0.8;

/// The unit floor with UV = (x, y), under `lights`, with `extra` meshes (JSON text).
fn bake_floor(lights: &str, extra: &str, element_size: f64) -> (SceneJson, Bake) {
    let text = format!(
        r#"{{"format": "penumbra-scene", "version": 1,
            "meshes": [{{"name": "Floor",
                         "positions": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]],
                         "polygons": [[0,1,2,3]], "albedo": [{ALBEDO},{ALBEDO},{ALBEDO}],
                         "uv": [[0,0],[1,0],[1,1],[0,1]]}}{extra}],
            "lights": [{lights}],
            "settings": {{"indirect": false, "element_size": {element_size},
                          "lightmap_resolution": 8, "lightmap_margin": 2}}}}"#
    );
    let json = SceneJson::from_str(&text).unwrap();
    let bake = bake_scene_json(&text, &Progress::new()).unwrap();
    (json, bake)
}

/// Mean of `f` over the rectangle `[x0, x1] × [y0, y1]` by the midpoint rule on an n×n grid
/// (error ~ (size/n)² · f''/24: far below the tolerances here for smooth `f`).
fn mean(f: impl Fn(DVec3) -> f64, x0: f64, x1: f64, y0: f64, y1: f64, n: usize) -> f64 {
    let mut s = 0.0;
    for j in 0..n {
        for i in 0..n {
            let x = x0 + (x1 - x0) * (i as f64 + 0.5) / n as f64;
            let y = y0 + (y1 - y0) * (j as f64 + 0.5) / n as f64;
            s += f(DVec3::new(x, y, 0.0));
        }
    }
    s / (n * n) as f64
}

fn texel(lm: &Lightmap, i: usize, j: usize) -> DVec3 {
    let c = lm.rgb[j * lm.width + i];
    DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64)
}

#[test]
fn a_lit_texel_is_the_exact_mean_of_the_lambert_field() {
    // A square light 2 m above the floor's centre, facing down, radiance 1.
    let light: Vec<DVec3> = [(0.4, 0.4), (0.4, 0.6), (0.6, 0.6), (0.6, 0.4)]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 2.0))
        .collect();
    let lights = format!(
        r#"{{"name": "Area", "radiance": [1,1,1], "polygon": {:?}}}"#,
        light.iter().map(|p| p.to_array()).collect::<Vec<_>>()
    );
    let (json, bake) = bake_floor(&lights, "", 0.02);
    let lm = scene_lightmaps(&json, &bake, &Progress::new()).unwrap()[0]
        .clone()
        .unwrap();
    assert_eq!((lm.width, lm.height), (8, 8));
    let field = |p: DVec3| ALBEDO * polygon_irradiance(p, DVec3::Z, &light) / PI;
    for (i, j) in [(3, 3), (0, 0), (6, 2), (7, 7)] {
        let (x0, y0) = (i as f64 / 8.0, j as f64 / 8.0);
        let want = mean(field, x0, x0 + 0.125, y0, y0 + 0.125, 200);
        let got = texel(&lm, i, j);
        assert!(
            ((got.x - want) / want).abs() < 1e-4,
            "texel {i},{j}: {} vs {want}",
            got.x
        );
        assert_eq!(lm.coverage[j * 8 + i], 1.0);
    }
}

#[test]
fn a_half_shadowed_texel_holds_the_area_weighted_mean_of_its_sides() {
    // A point light 2 m up; a plate at 1 m covering x < 0.46 throws a hard shadow edge
    // on the floor at x = 0.5 + 2 (0.46 − 0.5) = 0.42, across texel column 3 ([0.375, 0.5]).
    let lp = DVec3::new(0.5, 0.5, 2.0);
    let lights = r#"{"name": "Bulb", "point": [0.5, 0.5, 2.0], "intensity": [1,1,1]}"#;
    let plate = r#", {"name": "Plate", "positions": [[-1,-1,1],[0.46,-1,1],[0.46,2,1],[-1,2,1]],
                     "polygons": [[0,1,2,3]]}"#;
    let (json, bake) = bake_floor(lights, plate, 0.02);
    let lm = scene_lightmaps(&json, &bake, &Progress::new()).unwrap()[0]
        .clone()
        .unwrap();
    let field = |p: DVec3| {
        let d = lp - p;
        ALBEDO * d.z / d.length().powi(3) / PI
    };
    let xs = 0.42;
    for j in [1, 3, 6] {
        let (y0, y1) = (j as f64 / 8.0, (j + 1) as f64 / 8.0);
        // Umbra side 0; lit side its own mean, weighted by its share of the texel.
        let lit = mean(field, xs, 0.5, y0, y1, 200) * (0.5 - xs) / 0.125;
        let got = texel(&lm, 3, j).x;
        assert!(((got - lit) / lit).abs() < 1e-3, "row {j}: {got} vs {lit}");
        // The neighbours are wholly in shadow and wholly lit.
        assert!(texel(&lm, 2, j).x.abs() < 1e-9);
        let full = mean(field, 0.5, 0.625, y0, y1, 200);
        assert!(((texel(&lm, 4, j).x - full) / full).abs() < 1e-3);
    }
}

fn quad_layout_bake(
    uv: &[[f64; 2]],
) -> (Vec<[f64; 3]>, Vec<u32>, Vec<u32>, Vec<[f64; 2]>, BakedMesh) {
    let positions = vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]];
    let baked = BakedMesh {
        name: "Floor".into(),
        positions: positions.clone(),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        colors: vec![[1.0, 0.5, 0.25]; 4],
        source_polygon: vec![0, 0],
        relation: vec![vec![], vec![]],
    };
    (positions, vec![0, 4], vec![0, 1, 2, 3], uv.to_vec(), baked)
}

fn run(uv: &[[f64; 2]], res: i64, margin: i64) -> Result<Lightmap, BakeError> {
    let (positions, starts, corners, uvs, baked) = quad_layout_bake(uv);
    let layout = UvLayout {
        positions: &positions,
        starts: &starts,
        corners: &corners,
        uvs: &uvs,
    };
    let s = LightmapSettings::new(res, margin)?;
    rasterise("mesh \"Floor\"", &layout, &baked, s, &Progress::new())
}

#[test]
fn margins_are_filled_by_dilation_and_partial_texels_keep_their_mean() {
    // The quad covers UV [0.33, 0.67]²: at 10 texels, columns 3..7 (3 and 6 in part).
    let uv = [[0.33, 0.33], [0.67, 0.33], [0.67, 0.67], [0.33, 0.67]];
    let lm = run(&uv, 10, 1).unwrap();
    let at = |i: usize, j: usize| lm.rgb[j * 10 + i];
    for j in 0..10 {
        for i in 0..10 {
            let inside = (3..7).contains(&i) && (3..7).contains(&j);
            let ring = (2..8).contains(&i) && (2..8).contains(&j);
            let cov = lm.coverage[j * 10 + i];
            assert_eq!(cov > 0.0, inside, "{i},{j}");
            if ring {
                assert_eq!(at(i, j), [1.0, 0.5, 0.25], "{i},{j}");
            } else {
                assert_eq!(at(i, j), [0.0; 3], "{i},{j} is beyond the margin");
            }
        }
    }
    assert!((lm.coverage[3 * 10 + 3] - 0.49).abs() < 1e-6);
    assert!((lm.coverage[4 * 10 + 3] - 0.7).abs() < 1e-6);
}

#[test]
fn bad_input_is_one_line_naming_the_object_and_field() {
    let good = [[0.1, 0.1], [0.9, 0.1], [0.9, 0.9], [0.1, 0.9]];
    for (res, field) in [
        (0, "lightmap_resolution"),
        (1_000_000, "lightmap_resolution"),
    ] {
        let e = run(&good, res, 16).unwrap_err().to_string();
        assert!(e.contains(field) && !e.contains('\n'), "{e}");
    }
    let e = run(&good, 16, -1).unwrap_err().to_string();
    assert!(e.contains("lightmap_margin"), "{e}");
    let e = run(&good[..3], 16, 16).unwrap_err().to_string();
    assert!(
        e.starts_with("mesh \"Floor\": uv:") && e.contains("one per polygon corner"),
        "{e}"
    );
    let e = run(
        &[[0.1, 0.1], [f64::NAN, 0.1], [0.9, 0.9], [0.1, 0.9]],
        16,
        16,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("uv[1]") && e.contains("not finite"), "{e}");
    // All four corners on a line: no UV area.
    let e = run(&[[0.1, 0.1], [0.5, 0.5], [0.9, 0.9], [0.3, 0.3]], 16, 16)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no area") && e.contains("polygon 0"), "{e}");
}

#[test]
fn overlapping_uv_faces_are_refused() {
    // Two quads side by side in space, both unwrapped onto the same UV square.
    let positions = vec![
        [0., 0., 0.],
        [1., 0., 0.],
        [1., 1., 0.],
        [0., 1., 0.],
        [2., 0., 0.],
        [2., 1., 0.],
    ];
    let sq = [[0.1, 0.1], [0.6, 0.1], [0.6, 0.6], [0.1, 0.6]];
    let uvs: Vec<[f64; 2]> = sq.iter().chain(&sq).copied().collect();
    let layout = UvLayout {
        positions: &positions,
        starts: &[0, 4, 8],
        corners: &[0, 1, 2, 3, 1, 4, 5, 2],
        uvs: &uvs,
    };
    let baked = BakedMesh::default();
    let e = rasterise(
        "mesh \"Floor\"",
        &layout,
        &baked,
        LightmapSettings::default(),
        &Progress::new(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("polygons 0 and 1 overlap"), "{e}");
}

#[test]
fn a_bake_of_another_mesh_is_refused() {
    let good = [[0.1, 0.1], [0.9, 0.1], [0.9, 0.9], [0.1, 0.9]];
    let (positions, starts, corners, uvs, mut baked) = quad_layout_bake(&good);
    baked.source_polygon[1] = 5;
    let layout = UvLayout {
        positions: &positions,
        starts: &starts,
        corners: &corners,
        uvs: &uvs,
    };
    let e = rasterise(
        "mesh \"Floor\"",
        &layout,
        &baked,
        LightmapSettings::default(),
        &Progress::new(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("source_polygon[1]"), "{e}");
}

#[test]
fn concave_and_non_planar_polygons_cover_exactly_their_uv_area() {
    // An L (concave: ear-clipped) and a bent quad (non-planar: its two triangles on their
    // own planes), both with UV = (x, y) / 4: the covered area must be the UV area.
    let text = r#"{"format": "penumbra-scene", "version": 1,
        "meshes": [{"name": "Floor",
            "positions": [[0,0,0],[4,0,0],[4,1,0],[1,1,0],[1,4,0],[0,4,0],
                          [2,2,0],[4,2,0],[4,4,0.3],[2,4,0]],
            "polygons": [[0,1,2,3,4,5],[6,7,8,9]],
            "uv": [[0,0],[1,0],[1,0.25],[0.25,0.25],[0.25,1],[0,1],
                   [0.5,0.5],[1,0.5],[1,1],[0.5,1]]}],
        "lights": [{"name": "Sun", "direction": [0.1, 0.2, -1], "irradiance": [1,1,1]}],
        "settings": {"indirect": false, "lightmap_resolution": 16, "lightmap_margin": 0}}"#;
    let json = SceneJson::from_str(text).unwrap();
    let bake = bake_scene_json(text, &Progress::new()).unwrap();
    let lm = scene_lightmaps(&json, &bake, &Progress::new()).unwrap()[0]
        .clone()
        .unwrap();
    let covered: f64 = lm.coverage.iter().map(|&c| c as f64).sum();
    // L: 4·1 + 1·3 = 7 m² = 7/16 of the UV square; quad: 1/4 of it; 256 texels.
    let want = (7.0 / 16.0 + 0.25) * 256.0;
    assert!((covered - want).abs() < 1e-3, "{covered} vs {want}");
    // The L's notch (x, y in (1, 2)) is empty.
    for j in 5..8 {
        for i in 5..8 {
            assert_eq!(lm.coverage[j * 16 + i], 0.0, "{i},{j}");
        }
    }
    // The sun lights every covered texel.
    for (c, rgb) in lm.coverage.iter().zip(&lm.rgb) {
        assert_eq!(*c > 0.0, rgb[0] > 0.0);
    }
}
