//! `lightmap()`: one baked mesh rasterised onto its object's lightmap UVs, as numpy images.

use numpy::{PyArray1, PyArrayMethods};
use penumbra::lightmap::{check_uv, rasterise, LightmapSettings, UvLayout};
use penumbra::{BakedMesh, Progress};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::error::{invalid, Error};
use crate::scene::{array_f64, ints};

/// Rasterises one baked mesh onto the UVs of the mesh it was baked from.
///
/// `source` is the scene mesh dict that went into the bake (`name`, `positions`,
/// `polygon_vertices`, `polygon_counts`) plus `uv`: one UV per polygon corner, shape (L, 2),
/// in the order of `polygon_vertices` (Blender's loops). `baked` is that mesh's entry of
/// `BakeJob.result()["meshes"]`. Returns `(rgb, coverage)`: float32 arrays of shape
/// (resolution, resolution, 3) and (resolution, resolution), row 0 at v = 0 (Blender's
/// pixel order); `coverage` is the fraction of each texel the surface covers (0 in the
/// margin). Raises `BakeError` naming the mesh and field on bad input. The GIL is released
/// while it runs.
/// An object's polygons and lightmap UVs read from a scene mesh dict.
struct Source {
    obj: String,
    positions: Vec<[f64; 3]>,
    starts: Vec<u32>,
    corners: Vec<u32>,
    uvs: Vec<[f64; 2]>,
}

impl Source {
    fn from_py(source: &Bound<'_, PyDict>) -> Result<Self, Error> {
        let name: String = source
            .get_item("name")
            .ok()
            .flatten()
            .and_then(|n| n.extract().ok())
            .unwrap_or_default();
        let obj = format!("mesh {name:?}");
        let get = |key: &str| -> Result<Bound<'_, PyAny>, Error> {
            source
                .get_item(key)
                .ok()
                .flatten()
                .ok_or_else(|| invalid(&obj, key, "missing"))
        };
        let positions = rows(&get("positions")?, &obj, "positions", 3)?;
        let counts = ints(&get("polygon_counts")?, &obj, "polygon_counts")?;
        let corners = ints(&get("polygon_vertices")?, &obj, "polygon_vertices")?;
        let uvs = rows(&get("uv")?, &obj, "uv", 2)?;
        let mut starts = Vec::with_capacity(counts.len() + 1);
        starts.push(0u32);
        for (p, &c) in counts.iter().enumerate() {
            if c < 0 {
                return Err(invalid(
                    &obj,
                    &format!("polygon_counts[{p}]"),
                    "is negative",
                ));
            }
            starts.push(starts[p] + c as u32);
        }
        Ok(Source {
            positions: positions.into_iter().map(|r| [r[0], r[1], r[2]]).collect(),
            starts,
            corners: corners
                .iter()
                .map(|&c| u32::try_from(c).unwrap_or(u32::MAX))
                .collect(),
            uvs: uvs.into_iter().map(|r| [r[0], r[1]]).collect(),
            obj,
        })
    }

    fn layout(&self) -> UvLayout<'_> {
        UvLayout {
            positions: &self.positions,
            starts: &self.starts,
            corners: &self.corners,
            uvs: &self.uvs,
        }
    }
}

/// Checks lightmap settings and an object's lightmap UVs (`source` as for `lightmap()`)
/// without a bake: raises `BakeError` naming the mesh and field (UV count, non-finite,
/// zero-area or overlapping UV faces, resolution or margin out of range).
#[pyfunction]
#[pyo3(signature = (source, resolution = 512, margin = 16))]
pub fn check_lightmap_uv(
    py: Python<'_>,
    source: &Bound<'_, PyDict>,
    resolution: i64,
    margin: i64,
) -> PyResult<()> {
    let src = Source::from_py(source)?;
    py.detach(|| {
        LightmapSettings::new(resolution, margin)?;
        check_uv(&src.obj, &src.layout())
    })
    .map_err(Error::from)?;
    Ok(())
}

/// Rasterises one baked mesh onto the UVs of the mesh it was baked from.
///
/// `source` is the scene mesh dict that went into the bake (`name`, `positions`,
/// `polygon_vertices`, `polygon_counts`) plus `uv`: one UV per polygon corner, shape (L, 2),
/// in the order of `polygon_vertices` (Blender's loops). `baked` is that mesh's entry of
/// `BakeJob.result()["meshes"]`. Returns `(rgb, coverage)`: float32 arrays of shape
/// (resolution, resolution, 3) and (resolution, resolution), row 0 at v = 0 (Blender's
/// pixel order); `coverage` is the fraction of each texel the surface covers (0 in the
/// margin). Raises `BakeError` naming the mesh and field on bad input. The GIL is released
/// while it runs.
#[pyfunction]
#[pyo3(signature = (source, baked, resolution = 512, margin = 16))]
pub fn lightmap<'py>(
    py: Python<'py>,
    source: &Bound<'py, PyDict>,
    baked: &Bound<'py, PyDict>,
    resolution: i64,
    margin: i64,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let src = Source::from_py(source)?;
    let obj = &src.obj;
    let get = |key: &str| -> Result<Bound<'py, PyAny>, Error> {
        baked
            .get_item(key)
            .ok()
            .flatten()
            .ok_or_else(|| invalid(obj, &format!("baked {key}"), "missing"))
    };
    let index = |x: f64| {
        if x >= 0.0 && x < u32::MAX as f64 {
            x as u32
        } else {
            u32::MAX
        }
    };
    let baked = BakedMesh {
        name: String::new(),
        positions: rows(&get("positions")?, obj, "baked positions", 3)?,
        triangles: rows(&get("triangles")?, obj, "baked triangles", 3)?
            .into_iter()
            .map(|t| t.map(index))
            .collect(),
        colors: rows(&get("colors")?, obj, "baked colors", 3)?,
        source_polygon: ints(&get("source_polygon")?, obj, "baked source_polygon")?
            .iter()
            .map(|&s| u32::try_from(s).unwrap_or(u32::MAX))
            .collect(),
        relation: Vec::new(),
    };
    let lm = py
        .detach(|| {
            let settings = LightmapSettings::new(resolution, margin)?;
            rasterise(obj, &src.layout(), &baked, settings, &Progress::new())
        })
        .map_err(Error::from)?;
    let (w, h) = (lm.width, lm.height);
    let rgb = PyArray1::from_slice(py, lm.rgb.as_flattened()).reshape([h, w, 3])?;
    let coverage = PyArray1::from_vec(py, lm.coverage).reshape([h, w])?;
    Ok((rgb.into_any(), coverage.into_any()))
}

/// Rows of `n` numbers (any numeric dtype); an empty array is no rows. Integer-valued
/// arrays (triangles) come through f64 exactly below 2^53.
fn rows(
    obj: &Bound<'_, PyAny>,
    object: &str,
    field: &str,
    n: usize,
) -> Result<Vec<[f64; 3]>, Error> {
    let (shape, data) = array_f64(obj, object, field)?;
    let empty = data.is_empty() && shape.first() == Some(&0);
    if !(shape.len() == 2 && shape[1] == n) && !empty {
        return Err(invalid(
            object,
            field,
            format!("expected shape (N, {n}), got {shape:?}"),
        ));
    }
    Ok(data
        .chunks_exact(n)
        .map(|c| {
            let mut r = [0.0; 3];
            r[..n].copy_from_slice(c);
            r
        })
        .collect())
}
