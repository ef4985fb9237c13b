//! Plain Python data (dicts, lists, numbers, numpy scalars and arrays) to and from
//! `serde_json::Value`, so that lights and settings go through the core's own serde types
//! and get exactly the scene JSON's rules (unknown fields refused, same field names).

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde_json::{Map, Number, Value};

use crate::error::{invalid, Error};

/// `object`/`field` name the value in errors; `field` grows as the walk descends.
pub fn to_value(obj: &Bound<'_, PyAny>, object: &str, field: &str) -> Result<Value, Error> {
    if obj.is_none() {
        return Ok(Value::Null);
    }
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if obj.is_instance_of::<PyInt>() {
        if let Ok(i) = obj.extract::<i64>() {
            return Ok(Value::from(i));
        }
        if let Ok(u) = obj.extract::<u64>() {
            return Ok(Value::from(u));
        }
        return Err(invalid(object, field, "integer out of range"));
    }
    if let Ok(f) = obj.cast::<PyFloat>() {
        return number(f.value(), object, field);
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(Value::String(s.to_string()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut map = Map::new();
        for (k, v) in d.iter() {
            let key: String = k
                .extract()
                .map_err(|_| invalid(object, field, format!("key {k} is not a string")))?;
            let sub = join(field, &key);
            map.insert(key, to_value(&v, object, &sub)?);
        }
        return Ok(Value::Object(map));
    }
    // numpy arrays and scalars: `tolist` gives plain Python data of the same shape.
    if !obj.is_instance_of::<PyList>()
        && !obj.is_instance_of::<PyTuple>()
        && obj.hasattr("tolist").unwrap_or(false)
    {
        let plain = obj
            .call_method0("tolist")
            .map_err(|e| invalid(object, field, format!("tolist() failed: {e}")))?;
        return to_value(&plain, object, field);
    }
    if let Ok(iter) = obj.try_iter() {
        let mut items = Vec::new();
        for (i, item) in iter.enumerate() {
            let item = item.map_err(|e| invalid(object, field, e.to_string()))?;
            items.push(to_value(&item, object, &format!("{field}[{i}]"))?);
        }
        return Ok(Value::Array(items));
    }
    // Anything else numeric (a mathutils scalar, a Decimal): its float value.
    if let Ok(f) = obj.extract::<f64>() {
        return number(f, object, field);
    }
    let ty = obj
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_default();
    Err(invalid(
        object,
        field,
        format!("a {ty} is not a number, string, list or dict"),
    ))
}

fn number(f: f64, object: &str, field: &str) -> Result<Value, Error> {
    Number::from_f64(f)
        .map(Value::Number)
        .ok_or_else(|| invalid(object, field, format!("{f} is not a finite number")))
}

fn join(field: &str, key: &str) -> String {
    if field.is_empty() {
        key.to_string()
    } else {
        format!("{field}.{key}")
    }
}

pub fn to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => {
            if let Some(i) = n.as_i64() {
                i.into_pyobject(py)?.into_any()
            } else if let Some(u) = n.as_u64() {
                u.into_pyobject(py)?.into_any()
            } else {
                n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any()
            }
        }
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(a) => {
            let list = PyList::empty(py);
            for x in a {
                list.append(to_py(py, x)?)?;
            }
            list.into_any()
        }
        Value::Object(m) => {
            let d = PyDict::new(py);
            for (k, x) in m {
                d.set_item(k, to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}
