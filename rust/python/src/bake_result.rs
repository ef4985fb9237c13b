//! A finished bake as Python data: per mesh a dict of numpy arrays, plus stats and warnings.

use numpy::{PyArray1, PyArrayMethods};
use penumbra::{Bake, BakedMesh};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::value::to_py;

pub fn to_py_dict<'py>(
    py: Python<'py>,
    bake: &Bake,
    n_lights: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let meshes = PyList::empty(py);
    for m in &bake.meshes {
        meshes.append(mesh(py, m, n_lights)?)?;
    }
    let out = PyDict::new(py);
    out.set_item("meshes", meshes)?;
    let stats = serde_json::to_value(&bake.stats)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    out.set_item("stats", to_py(py, &stats)?)?;
    out.set_item("warnings", PyList::new(py, &bake.warnings)?)?;
    Ok(out)
}

fn mesh<'py>(py: Python<'py>, m: &BakedMesh, n_lights: usize) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", &m.name)?;
    let positions = PyArray1::from_slice(py, m.positions.as_flattened());
    d.set_item("positions", positions.reshape([m.positions.len(), 3])?)?;
    let triangles = PyArray1::from_slice(py, m.triangles.as_flattened());
    d.set_item("triangles", triangles.reshape([m.triangles.len(), 3])?)?;
    // Python's contract is float32 colours (what Blender stores), whatever the core keeps.
    let colors: Vec<f32> = m.colors.as_flattened().iter().map(|&c| c as f32).collect();
    d.set_item(
        "colors",
        PyArray1::from_vec(py, colors).reshape([m.colors.len(), 3])?,
    )?;
    d.set_item(
        "source_polygon",
        PyArray1::from_slice(py, &m.source_polygon),
    )?;
    // Rows all have one code per light; an empty mesh still gets the (0, n_lights) shape.
    let width = m.relation.first().map_or(n_lights, Vec::len);
    let flat: Vec<u8> = m.relation.iter().flat_map(|r| r.iter().copied()).collect();
    if flat.len() != width * m.relation.len() {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "mesh {:?}: relation rows differ in length",
            m.name
        )));
    }
    d.set_item(
        "relation",
        PyArray1::from_vec(py, flat).reshape([m.relation.len(), width])?,
    )?;
    Ok(d)
}
