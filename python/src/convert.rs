//! Conversions at the Python boundary: errors to exceptions, dicts to TOML values and
//! back (scenes and transfer functions travel as the dicts their files hold), and
//! `(h, w, 3)` float32 arrays to and from the metrics' images.

use dvr_engine::metrics::Rgb32Image;
use numpy::{PyArray3, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// Bad input from the caller: the message as the CLI prints it.
pub fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A device or driver problem.
pub fn runtime_error(e: impl std::fmt::Display) -> PyErr {
    PyRuntimeError::new_err(e.to_string())
}

/// A Python value (dict, list, tuple, str, bool, int, float) as TOML; `path` names it
/// in errors (`scene["camera"]["position"][1]`).
pub fn to_toml(v: &Bound<'_, PyAny>, path: &str) -> PyResult<toml::Value> {
    if let Ok(d) = v.cast::<PyDict>() {
        let mut table = toml::map::Map::new();
        for (k, item) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                PyTypeError::new_err(format!("{path}: keys must be strings, got {k}"))
            })?;
            if item.is_none() {
                continue; // None means "not given", as an absent key in a file
            }
            let value = to_toml(&item, &format!("{path}[{key:?}]"))?;
            table.insert(key, value);
        }
        return Ok(toml::Value::Table(table));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut out = Vec::new();
        for (i, item) in v.try_iter()?.enumerate() {
            out.push(to_toml(&item?, &format!("{path}[{i}]"))?);
        }
        return Ok(toml::Value::Array(out));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return v.extract().map(toml::Value::Integer).map_err(|_| {
            value_error(format!(
                "{path}: {v} is out of range (whole numbers here fit in 64 bits)"
            ))
        });
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    // numpy scalars and anything else with __float__ (np.float32(0.5) in a camera).
    if let Ok(x) = v.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    Err(PyTypeError::new_err(format!(
        "{path}: {} is not a scene value (dict, list, str, bool, int or float)",
        v.get_type().name()?
    )))
}

/// A TOML value as Python (tables as dicts, arrays as lists).
pub fn from_toml<'py>(py: Python<'py>, v: &toml::Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        toml::Value::String(s) => s.into_pyobject(py)?.into_any(),
        toml::Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        toml::Value::Float(f) => f.into_pyobject(py)?.into_any(),
        toml::Value::Boolean(b) => b.into_pyobject(py)?.to_owned().into_any(),
        toml::Value::Datetime(d) => d.to_string().into_pyobject(py)?.into_any(),
        toml::Value::Array(a) => {
            let list = PyList::empty(py);
            for item in a {
                list.append(from_toml(py, item)?)?;
            }
            list.into_any()
        }
        toml::Value::Table(t) => {
            let dict = PyDict::new(py);
            for (k, item) in t {
                dict.set_item(k, from_toml(py, item)?)?;
            }
            dict.into_any()
        }
    })
}

/// An `(h, w, 3)` float32 image (linear radiance) as the metrics' image type; `name`
/// names the argument in errors.
pub fn image_in(a: &PyReadonlyArray3<'_, f32>, name: &str) -> PyResult<Rgb32Image> {
    let shape = a.shape();
    if shape[2] != 3 || shape[0] == 0 || shape[1] == 0 {
        return Err(value_error(format!(
            "{name}: expected an (h, w, 3) image with h, w >= 1, got shape {shape:?}"
        )));
    }
    let (h, w) = (shape[0], shape[1]);
    let view = a.as_array();
    let mut data = Vec::with_capacity(h * w);
    for y in 0..h {
        for x in 0..w {
            let px = [view[[y, x, 0]], view[[y, x, 1]], view[[y, x, 2]]];
            if px.iter().any(|c| !c.is_finite()) {
                return Err(value_error(format!(
                    "{name}: pixel (row {y}, column {x}) is not finite: {px:?}"
                )));
            }
            data.push(px);
        }
    }
    Ok(Rgb32Image::new(w as u32, h as u32, data))
}

/// RGBA pixels from the renderer (row-major) as an `(h, w, channels)` float32 array:
/// 3 for radiance, 4 for the surface features (whose fourth channel carries a flag or
/// a distance).
pub fn image_out<'py>(
    py: Python<'py>,
    width: u32,
    height: u32,
    rgba: &[[f32; 4]],
    channels: usize,
) -> Bound<'py, PyArray3<f32>> {
    let (w, h) = (width as usize, height as usize);
    let flat: Vec<f32> = rgba
        .iter()
        .flat_map(|p| p[..channels].iter().copied())
        .collect();
    let array = numpy::ndarray::Array3::from_shape_vec((h, w, channels), flat)
        .expect("the renderer reads back width × height pixels");
    PyArray3::from_owned_array(py, array)
}
