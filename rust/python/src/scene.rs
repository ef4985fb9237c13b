//! A scene from Python: scene JSON text, or a dict whose meshes are numpy arrays in
//! Blender's layout (vertex positions, polygon vertex indices flattened as Blender's loops,
//! per-polygon counts). Both end as the core's `SceneJson`; all value checks stay in the core.

use numpy::{AllowTypeChange, PyArrayLikeDyn, PyUntypedArrayMethods};
use penumbra::scene::json::{
    LightJson, MeshJson, PerPolygon, SceneJson, SettingsJson, SCENE_FORMAT, SCENE_VERSION,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use serde_json::Value;

use crate::error::{invalid, Error};
use crate::value::to_value;

const SCENE_KEYS: &[&str] = &["format", "version", "meshes", "lights", "settings"];
const MESH_KEYS: &[&str] = &[
    "name",
    "positions",
    "polygon_vertices",
    "polygon_counts",
    "albedo",
    "emission",
    "uv",
    "output",
];

pub fn from_py(scene: &Bound<'_, PyAny>) -> Result<SceneJson, Error> {
    if let Ok(text) = scene.cast::<PyString>() {
        return Ok(SceneJson::from_str(&text.to_string())?);
    }
    let dict = scene
        .cast::<PyDict>()
        .map_err(|_| invalid("scene", "", "expected scene JSON text or a dict"))?;
    check_keys(dict, SCENE_KEYS, "scene")?;
    if let Some(f) = dict.get_item("format").ok().flatten() {
        let f: String = f
            .extract()
            .map_err(|_| invalid("scene", "format", "not a string"))?;
        if f != SCENE_FORMAT {
            return Err(penumbra::BakeError::Format(format!(
                "format is {f:?}, expected {SCENE_FORMAT:?}"
            ))
            .into());
        }
    }
    if let Some(v) = dict.get_item("version").ok().flatten() {
        let v: u32 = v
            .extract()
            .map_err(|_| invalid("scene", "version", "not an integer"))?;
        if v != SCENE_VERSION {
            return Err(penumbra::BakeError::Format(format!(
                "version {v} is not supported (this build reads version {SCENE_VERSION})"
            ))
            .into());
        }
    }
    let mut meshes = Vec::new();
    if let Some(list) = dict.get_item("meshes").ok().flatten() {
        for (i, m) in iter(&list, "scene", "meshes")?.enumerate() {
            meshes.push(mesh(&m?, i)?);
        }
    }
    let mut lights = Vec::new();
    if let Some(list) = dict.get_item("lights").ok().flatten() {
        for (i, l) in iter(&list, "scene", "lights")?.enumerate() {
            lights.push(light(&l?, i)?);
        }
    }
    let settings = match dict.get_item("settings").ok().flatten() {
        Some(s) if !s.is_none() => {
            let v = to_value(&s, "settings", "")?;
            penumbra::scene::strict::settings_from_value(&v)?
        }
        _ => SettingsJson::default(),
    };
    Ok(SceneJson {
        format: SCENE_FORMAT.into(),
        version: SCENE_VERSION,
        meshes,
        lights,
        settings,
    })
}

fn iter<'py>(
    obj: &Bound<'py, PyAny>,
    object: &str,
    field: &str,
) -> Result<impl Iterator<Item = Result<Bound<'py, PyAny>, Error>>, Error> {
    let object = object.to_string();
    let field2 = field.to_string();
    let it = obj
        .try_iter()
        .map_err(|_| invalid(&object, field, "expected a list"))?;
    Ok(it.map(move |x| x.map_err(|e| invalid(&object, &field2, e.to_string()))))
}

fn check_keys(d: &Bound<'_, PyDict>, allowed: &[&str], object: &str) -> Result<(), Error> {
    for k in d.keys() {
        let k: String = k
            .extract()
            .map_err(|_| invalid(object, "", "keys must be strings"))?;
        if !allowed.contains(&k.as_str()) {
            return Err(invalid(
                object,
                &k,
                format!("unknown field (expected one of {})", allowed.join(", ")),
            ));
        }
    }
    Ok(())
}

fn mesh(obj: &Bound<'_, PyAny>, index: usize) -> Result<MeshJson, Error> {
    let here = format!("meshes[{index}]");
    let d = obj
        .cast::<PyDict>()
        .map_err(|_| invalid(&here, "", "expected a dict"))?;
    let name: String = match d.get_item("name").ok().flatten() {
        Some(n) => n
            .extract()
            .map_err(|_| invalid(&here, "name", "not a string"))?,
        None => return Err(invalid(&here, "name", "missing")),
    };
    let object = format!("mesh {name:?} ({here})");
    check_keys(d, MESH_KEYS, &object)?;
    let get = |key: &str| -> Result<Bound<'_, PyAny>, Error> {
        d.get_item(key)
            .ok()
            .flatten()
            .ok_or_else(|| invalid(&object, key, "missing"))
    };

    let positions = rows3(&get("positions")?, &object, "positions")?;
    let counts = ints(&get("polygon_counts")?, &object, "polygon_counts")?;
    let flat = ints(&get("polygon_vertices")?, &object, "polygon_vertices")?;
    let mut polygons = Vec::with_capacity(counts.len());
    let mut at = 0usize;
    for (p, &c) in counts.iter().enumerate() {
        let c = usize::try_from(c).map_err(|_| {
            invalid(
                &object,
                &format!("polygon_counts[{p}]"),
                format!("{c} is negative"),
            )
        })?;
        let Some(slice) = flat.get(at..at + c) else {
            return Err(invalid(
                &object,
                "polygon_counts",
                format!(
                    "the counts add up to more than the {} polygon_vertices",
                    flat.len()
                ),
            ));
        };
        polygons.push(slice.to_vec());
        at += c;
    }
    if at != flat.len() {
        return Err(invalid(
            &object,
            "polygon_counts",
            format!(
                "the counts add up to {at}, but there are {} polygon_vertices",
                flat.len()
            ),
        ));
    }
    let albedo = match d.get_item("albedo").ok().flatten() {
        Some(a) if !a.is_none() => Some(per_polygon(&a, &object, "albedo")?),
        _ => None,
    };
    let emission = match d.get_item("emission").ok().flatten() {
        Some(a) if !a.is_none() => Some(per_polygon(&a, &object, "emission")?),
        _ => None,
    };
    Ok(MeshJson {
        name,
        positions,
        polygons,
        albedo,
        emission,
        uv: match d.get_item("uv").ok().flatten() {
            Some(a) if !a.is_none() => Some(uv_rows(&a, &object)?),
            _ => None,
        },
        output: match d.get_item("output").ok().flatten() {
            Some(a) if !a.is_none() => Some(a.extract::<bool>().map_err(|_| {
                Error::from(penumbra::BakeError::invalid(
                    &object,
                    "output",
                    "must be True or False",
                ))
            })?),
            _ => None,
        },
    })
}

fn light(obj: &Bound<'_, PyAny>, index: usize) -> Result<LightJson, Error> {
    let name = obj
        .get_item("name")
        .ok()
        .and_then(|n| n.extract::<String>().ok())
        .unwrap_or_default();
    let object = format!("light {name:?} (lights[{index}])");
    let v: Value = to_value(obj, &object, "")?;
    Ok(penumbra::scene::strict::light_from_value(&v, index)?)
}

/// A real-valued array (lists too) as f64, with its shape. Complex, boolean, string and
/// object dtypes are refused: numpy would otherwise drop an imaginary part or read `True`
/// as 1 without a word.
pub(crate) fn array_f64(
    obj: &Bound<'_, PyAny>,
    object: &str,
    field: &str,
) -> Result<(Vec<usize>, Vec<f64>), Error> {
    let (kind, size) = dtype_kind(obj, object, field)?;
    if !matches!(kind, 'f' | 'i' | 'u') && size > 0 {
        return Err(invalid(
            object,
            field,
            format!(
                "expected real numbers, got dtype kind {kind:?} ({})",
                kind_name(kind)
            ),
        ));
    }
    let a: PyArrayLikeDyn<'_, f64, AllowTypeChange> = obj
        .extract()
        .map_err(|e| invalid(object, field, format!("not a numeric array: {e}")))?;
    let shape = a.shape().to_vec();
    Ok((shape, a.as_array().iter().copied().collect()))
}

fn rows3(obj: &Bound<'_, PyAny>, object: &str, field: &str) -> Result<Vec<[f64; 3]>, Error> {
    let (shape, data) = array_f64(obj, object, field)?;
    let empty = data.is_empty() && shape.first() == Some(&0);
    if !(shape.len() == 2 && shape[1] == 3) && !empty {
        return Err(invalid(
            object,
            field,
            format!("expected shape (N, 3), got {shape:?}"),
        ));
    }
    Ok(data.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

fn per_polygon(obj: &Bound<'_, PyAny>, object: &str, field: &str) -> Result<PerPolygon, Error> {
    let (shape, data) = array_f64(obj, object, field)?;
    match shape.as_slice() {
        [3] => Ok(PerPolygon::Uniform([data[0], data[1], data[2]])),
        [_, 3] | [0] => Ok(PerPolygon::PerPolygon(
            data.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        )),
        _ => Err(invalid(
            object,
            field,
            format!("expected shape (3,) or (P, 3), got {shape:?}"),
        )),
    }
}

/// Indices: an integer dtype only (a float index would be truncated by a cast), and unsigned
/// values past `i64::MAX` reported as written instead of wrapping to negative numbers.
pub(crate) fn ints(obj: &Bound<'_, PyAny>, object: &str, field: &str) -> Result<Vec<i64>, Error> {
    let (kind, size) = dtype_kind(obj, object, field)?;
    if size == 0 {
        return Ok(Vec::new()); // `[]` is float64 to numpy; empty is empty
    }
    let flat = |shape: &[usize]| {
        if shape.len() != 1 {
            return Err(invalid(
                object,
                field,
                format!("expected a flat array, got shape {shape:?}"),
            ));
        }
        Ok(())
    };
    match kind {
        'i' => {
            let a: PyArrayLikeDyn<'_, i64, AllowTypeChange> = obj
                .extract()
                .map_err(|e| invalid(object, field, format!("not an integer array: {e}")))?;
            flat(a.shape())?;
            Ok(a.as_array().iter().copied().collect())
        }
        'u' => {
            let a: PyArrayLikeDyn<'_, u64, AllowTypeChange> = obj
                .extract()
                .map_err(|e| invalid(object, field, format!("not an integer array: {e}")))?;
            flat(a.shape())?;
            a.as_array()
                .iter()
                .enumerate()
                .map(|(k, &u)| {
                    i64::try_from(u).map_err(|_| {
                        invalid(
                            object,
                            &format!("{field}[{k}]"),
                            format!("index {u} is out of range"),
                        )
                    })
                })
                .collect()
        }
        _ => Err(invalid(
            object,
            field,
            format!(
                "expected integers, got dtype kind {kind:?} ({})",
                kind_name(kind)
            ),
        )),
    }
}

/// numpy's dtype kind of `obj` as an array (`np.asarray`), and its size.
fn dtype_kind(obj: &Bound<'_, PyAny>, object: &str, field: &str) -> Result<(char, usize), Error> {
    let arr = obj
        .py()
        .import("numpy")
        .and_then(|np| np.getattr("asarray"))
        .and_then(|f| f.call1((obj,)))
        .map_err(|e| invalid(object, field, format!("not a numeric array: {e}")))?;
    let kind: String = arr
        .getattr("dtype")
        .and_then(|d| d.getattr("kind"))
        .and_then(|k| k.extract())
        .map_err(|e| invalid(object, field, format!("not a numeric array: {e}")))?;
    let size: usize = arr
        .getattr("size")
        .and_then(|s| s.extract())
        .map_err(|e| invalid(object, field, format!("not a numeric array: {e}")))?;
    Ok((kind.chars().next().unwrap_or('?'), size))
}

fn kind_name(kind: char) -> &'static str {
    match kind {
        'b' => "boolean",
        'i' => "signed integer",
        'u' => "unsigned integer",
        'f' => "floating point",
        'c' => "complex",
        'U' | 'S' => "string",
        'O' => "Python objects",
        _ => "not numeric",
    }
}

/// Lightmap UVs, one (u, v) per polygon corner.
fn uv_rows(obj: &Bound<'_, PyAny>, object: &str) -> Result<Vec<[f64; 2]>, Error> {
    let (shape, data) = array_f64(obj, object, "uv")?;
    let empty = data.is_empty() && shape.first() == Some(&0);
    if !(shape.len() == 2 && shape[1] == 2) && !empty {
        return Err(invalid(
            object,
            "uv",
            format!("expected shape (L, 2), got {shape:?}"),
        ));
    }
    Ok(data.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
}
