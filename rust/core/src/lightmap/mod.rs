//! Stage 8: the bake field rasterised onto an object's lightmap UVs (DESIGN.md).
//!
//! Each texel holds the mean outgoing radiance over the part of the surface its square
//! covers in UV space: what a path tracer's bake to an image converges to as its samples grow.
//! The bake's field is linear over each element triangle, so the mean is computed exactly:
//! element triangles are cut along the source polygon's UV triangles (`uv`), mapped to texel
//! space, cut along the texel grid and integrated in closed form (`raster`). Texels that no
//! surface touches are filled from their neighbours for `margin` rings (`dilate`).
//!
//! Means are over UV area, as a bake to an image samples it: within one affine UV triangle
//! this is the mean over surface area as well.

mod dilate;
mod overlap;
mod raster;
mod uv;

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::bake::BakedMesh;
use crate::progress::Progress;
use crate::scene::json::{SceneJson, SettingsJson};
use crate::BakeError;

use raster::{Attr, Pieces};
use uv::SourcePolygon;

pub const DEFAULT_RESOLUTION: u32 = 512;
/// Cycles' default bake margin.
pub const DEFAULT_MARGIN: u32 = 16;
pub const MAX_RESOLUTION: u32 = 16384;
pub const MAX_MARGIN: u32 = 1024;

/// Texels on a side and margin rings, checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LightmapSettings {
    pub resolution: u32,
    pub margin: u32,
}

impl Default for LightmapSettings {
    fn default() -> Self {
        LightmapSettings {
            resolution: DEFAULT_RESOLUTION,
            margin: DEFAULT_MARGIN,
        }
    }
}

impl LightmapSettings {
    /// Checks the ranges; errors name the setting (`settings.lightmap_resolution`, …).
    pub fn new(resolution: i64, margin: i64) -> Result<Self, BakeError> {
        if !(1..=MAX_RESOLUTION as i64).contains(&resolution) {
            return Err(BakeError::setting(
                "lightmap_resolution",
                format!("{resolution} is outside [1, {MAX_RESOLUTION}] texels"),
            ));
        }
        if !(0..=MAX_MARGIN as i64).contains(&margin) {
            return Err(BakeError::setting(
                "lightmap_margin",
                format!("{margin} is outside [0, {MAX_MARGIN}] texels"),
            ));
        }
        Ok(LightmapSettings {
            resolution: resolution as u32,
            margin: margin as u32,
        })
    }

    /// From scene JSON settings; `None` when the scene asks for no lightmaps.
    pub fn from_json(s: &SettingsJson) -> Result<Option<Self>, BakeError> {
        match s.lightmap_resolution {
            None => Ok(None),
            Some(r) => Self::new(r, s.lightmap_margin.unwrap_or(DEFAULT_MARGIN as i64)).map(Some),
        }
    }
}

/// An object's polygons with a UV per polygon corner (Blender's loops), in the positions the
/// bake was made from.
#[derive(Debug, Clone, Copy)]
pub struct UvLayout<'a> {
    pub positions: &'a [[f64; 3]],
    /// Polygon `k`'s corners are `corners[starts[k]..starts[k + 1]]` (`starts` has one more
    /// entry than there are polygons, and starts at 0).
    pub starts: &'a [u32],
    pub corners: &'a [u32],
    /// One per corner.
    pub uvs: &'a [[f64; 2]],
}

/// A float RGB image, linear, row-major with row 0 at v = 0 (the bottom, as Blender stores
/// pixels), and the fraction of each texel the surface covers (0 for margin and empty texels).
#[derive(Debug, Clone, PartialEq)]
pub struct Lightmap {
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<[f32; 3]>,
    pub coverage: Vec<f32>,
}

/// The lightmap of one baked object. `obj` names it in errors (e.g. `mesh "Floor"`).
pub fn rasterise(
    obj: &str,
    layout: &UvLayout,
    baked: &BakedMesh,
    settings: LightmapSettings,
    progress: &Progress,
) -> Result<Lightmap, BakeError> {
    let sources = check_layout(obj, layout)?;
    check_baked(obj, baked, sources.len())?;
    progress.check()?;

    let size = settings.resolution as usize;
    let scale = DVec2::splat(size as f64);
    let pieces = baked
        .triangles
        .par_chunks(4096)
        .zip(baked.source_polygon.par_chunks(4096))
        .map(|(tris, src)| {
            let mut out = Pieces::new();
            let mut buf = [Vec::new(), Vec::new()];
            for (t, &s) in tris.iter().zip(src) {
                let pts = t.map(|v| DVec3::from(baked.positions[v as usize]));
                let cols = t.map(|v| DVec3::from(baked.colors[v as usize]));
                sources[s as usize]
                    .map_element(pts, cols, scale, &mut buf, &mut |p: &[Attr]| out.push(p));
            }
            out
        })
        .reduce(Pieces::new, |mut a, b| {
            a.append(b);
            a
        });
    progress.check()?;

    let bands = raster::accumulate(&pieces, size, size, progress, |acc| {
        let means: Vec<[f32; 3]> = acc
            .iter()
            .map(|t| {
                if t[3] > 0.0 {
                    [t[0] / t[3], t[1] / t[3], t[2] / t[3]].map(|x| x as f32)
                } else {
                    [0.0; 3]
                }
            })
            .collect();
        // A texel's area in texel units is 1; rounding may overshoot it by an ulp or so.
        let cover: Vec<f32> = acc.iter().map(|t| t[3].min(1.0) as f32).collect();
        (means, cover)
    })?;
    drop(pieces);
    let mut rgb = Vec::with_capacity(size * size);
    let mut coverage = Vec::with_capacity(size * size);
    for (m, c) in bands {
        rgb.extend(m);
        coverage.extend(c);
    }
    let mut filled: Vec<bool> = coverage.iter().map(|&c| c > 0.0).collect();
    dilate::dilate(&mut rgb, &mut filled, size, size, settings.margin);
    Ok(Lightmap {
        width: size,
        height: size,
        rgb,
        coverage,
    })
}

/// Checks an object's lightmap UVs (counts, finite values, no zero-area or overlapping UV
/// faces) without a bake, so that bad UVs are reported before a long bake rather than after.
pub fn check_uv(obj: &str, layout: &UvLayout) -> Result<(), BakeError> {
    check_layout(obj, layout).map(|_| ())
}

/// Lightmaps for every scene mesh that carries `uv`, when the settings ask for them
/// (`settings.lightmap_resolution`); meshes without UVs get `None`.
pub fn scene_lightmaps(
    json: &SceneJson,
    bake: &crate::Bake,
    progress: &Progress,
) -> Result<Vec<Option<Lightmap>>, BakeError> {
    let Some(settings) = LightmapSettings::from_json(&json.settings)? else {
        return Ok(vec![None; json.meshes.len()]);
    };
    let mut out = Vec::with_capacity(json.meshes.len());
    for (mi, (m, b)) in json.meshes.iter().zip(&bake.meshes).enumerate() {
        let Some(uvs) = m.uv.as_ref().filter(|_| m.output != Some(false)) else {
            out.push(None);
            continue;
        };
        let obj = format!("mesh {:?} (meshes[{mi}])", m.name);
        let (starts, corners) =
            flat_polygons(&m.polygons, m.positions.len()).map_err(|(k, i)| {
                BakeError::invalid(
                    &obj,
                    format!("polygons[{k}]"),
                    format!("index {i} is out of range"),
                )
            })?;
        let layout = UvLayout {
            positions: &m.positions,
            starts: &starts,
            corners: &corners,
            uvs,
        };
        out.push(Some(rasterise(&obj, &layout, b, settings, progress)?));
    }
    Ok(out)
}

/// Scene JSON polygons as `(starts, corners)` for `UvLayout`; `Err((polygon, index))` for an
/// index outside `0..n_positions`.
pub fn flat_polygons(
    polygons: &[Vec<i64>],
    n_positions: usize,
) -> Result<(Vec<u32>, Vec<u32>), (usize, i64)> {
    let mut starts = Vec::with_capacity(polygons.len() + 1);
    let mut corners = Vec::new();
    starts.push(0u32);
    for (k, p) in polygons.iter().enumerate() {
        for &i in p {
            if i < 0 || i as usize >= n_positions {
                return Err((k, i));
            }
            corners.push(i as u32);
        }
        starts.push(corners.len() as u32);
    }
    Ok((starts, corners))
}

/// Checks the layout and cuts its polygons into UV triangles. Zero-area and overlapping UV
/// polygons are errors naming the polygon.
fn check_layout(obj: &str, l: &UvLayout) -> Result<Vec<SourcePolygon>, BakeError> {
    if l.starts.first() != Some(&0)
        || l.starts.windows(2).any(|w| w[1] < w[0])
        || *l.starts.last().unwrap() as usize != l.corners.len()
    {
        return Err(BakeError::invalid(
            obj,
            "polygons",
            "polygon starts do not match the corner count",
        ));
    }
    if l.uvs.len() != l.corners.len() {
        return Err(BakeError::invalid(
            obj,
            "uv",
            format!(
                "has {} UVs, expected one per polygon corner ({})",
                l.uvs.len(),
                l.corners.len()
            ),
        ));
    }
    if let Some(k) = l.uvs.iter().position(|u| !u.iter().all(|x| x.is_finite())) {
        return Err(BakeError::invalid(
            obj,
            format!("uv[{k}]"),
            format!("{:?} is not finite", l.uvs[k]),
        ));
    }
    if let Some(k) = l
        .corners
        .iter()
        .position(|&c| c as usize >= l.positions.len())
    {
        return Err(BakeError::invalid(
            obj,
            format!("corners[{k}]"),
            format!(
                "index {} is out of range (the mesh has {} positions)",
                l.corners[k],
                l.positions.len()
            ),
        ));
    }
    let positions: Vec<DVec3> = l.positions.iter().map(|p| DVec3::from(*p)).collect();
    let sources: Vec<SourcePolygon> = l
        .starts
        .par_windows(2)
        .map(|w| {
            let (a, b) = (w[0] as usize, w[1] as usize);
            let uvs: Vec<DVec2> = l.uvs[a..b].iter().map(|u| DVec2::from(*u)).collect();
            SourcePolygon::new(&positions, &l.corners[a..b], &uvs)
        })
        .collect();
    for (pi, s) in sources.iter().enumerate() {
        // A polygon with surface but (part of) no UV area would crush its light into a line.
        if s.tris.iter().any(|t| t.uv_area().abs() <= MIN_UV_AREA) {
            return Err(BakeError::invalid(
                obj,
                format!("uv (polygon {pi})"),
                "the UV face has no area: unwrap the lightmap UVs again",
            ));
        }
    }
    let tris: Vec<(u32, [DVec2; 3])> = sources
        .iter()
        .enumerate()
        .flat_map(|(pi, s)| s.tris.iter().map(move |t| (pi as u32, t.uv)))
        .collect();
    if let Some((a, b)) = overlap::find_overlap(&tris) {
        return Err(BakeError::invalid(
            obj,
            "uv",
            format!("UV faces of polygons {a} and {b} overlap: lightmap UVs must not overlap"),
        ));
    }
    Ok(sources)
}

/// UV area (of the unit square) below which a face counts as having none: far below a
/// texel at the largest resolution (1/16384² ≈ 3.7e-9).
const MIN_UV_AREA: f64 = 1e-14;

fn check_baked(obj: &str, b: &BakedMesh, n_polygons: usize) -> Result<(), BakeError> {
    if b.source_polygon.len() != b.triangles.len() || b.colors.len() != b.positions.len() {
        return Err(BakeError::invalid(
            obj,
            "bake",
            "triangles, source polygons, colours and positions do not match in length",
        ));
    }
    if let Some(k) = b
        .triangles
        .iter()
        .position(|t| t.iter().any(|&v| v as usize >= b.positions.len()))
    {
        return Err(BakeError::invalid(
            obj,
            format!("bake triangles[{k}]"),
            "vertex index out of range",
        ));
    }
    if let Some(k) = b
        .source_polygon
        .iter()
        .position(|&s| s as usize >= n_polygons)
    {
        return Err(BakeError::invalid(
            obj,
            format!("bake source_polygon[{k}]"),
            format!(
                "polygon {} is out of range: the UV layout has {n_polygons} polygons \
                 (is it the mesh that was baked?)",
                b.source_polygon[k]
            ),
        ));
    }
    if let Some(k) = b
        .colors
        .iter()
        .chain(&b.positions)
        .position(|c| !c.iter().all(|x| x.is_finite()))
    {
        return Err(BakeError::invalid(
            obj,
            "bake",
            format!("value {k} of colours/positions is not finite"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod test;
