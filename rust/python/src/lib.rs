//! `penumbra._core`: the Python face of the `penumbra` crate. Thin by design: conversion of
//! Python data in (`scene`), of the bake out (`bake_result`), the threaded job (`job`) and
//! the error mapping (`error`); every algorithm lives in the core.

mod bake_result;
mod error;
mod job;
mod lightmap;
mod scene;
mod value;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use error::BakeError;
use job::BakeJob;

/// Starts a bake on a Rust thread and returns at once with its `BakeJob`.
///
/// `scene` is scene JSON text, or a dict `{"meshes": [...], "lights": [...], "settings": {...}}`
/// whose meshes are `{"name", "positions" (N,3), "polygon_vertices" (flat), "polygon_counts"
/// (P,), "albedo" (P,3) or (3,), "emission" (optional, same)}` and whose lights and settings
/// are as in scene JSON.
#[pyfunction]
fn start_bake(scene: &Bound<'_, PyAny>) -> PyResult<BakeJob> {
    let json = scene::from_py(scene)?;
    Ok(BakeJob::start(json)?)
}

/// Bakes and waits (GIL released); returns the same dict as `BakeJob.result()`.
#[pyfunction]
fn bake<'py>(py: Python<'py>, scene: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    start_bake(scene)?.result(py)
}

/// Checks a scene as the bake would, without baking; raises `BakeError` on bad input and
/// returns the warnings (e.g. degenerate polygons dropped).
#[pyfunction]
fn validate(py: Python<'_>, scene: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
    let json = scene::from_py(scene)?;
    let scene = py
        .detach(|| penumbra::scene::validate(&json))
        .map_err(error::Error::from)?;
    Ok(scene.warnings)
}

/// The scene JSON text a Python scene (dict of arrays) stands for: what the CLI would read.
#[pyfunction]
fn scene_json(scene: &Bound<'_, PyAny>) -> PyResult<String> {
    let json = scene::from_py(scene)?;
    serde_json::to_string(&json).map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("BakeError", m.py().get_type::<BakeError>())?;
    m.add_class::<BakeJob>()?;
    m.add_function(wrap_pyfunction!(start_bake, m)?)?;
    m.add_function(wrap_pyfunction!(bake, m)?)?;
    m.add_function(wrap_pyfunction!(validate, m)?)?;
    m.add_function(wrap_pyfunction!(scene_json, m)?)?;
    m.add_function(wrap_pyfunction!(lightmap::lightmap, m)?)?;
    m.add_function(wrap_pyfunction!(lightmap::check_lightmap_uv, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
