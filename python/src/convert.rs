//! Arguments from Python (vectors as any iterable of numbers: tuples, lists, numpy arrays) and
//! results to numpy.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::exceptions::{PyMemoryError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyInt, PyString};
use voussoir::block::{Dof, Fixity};
use voussoir::math::Vector;

use crate::errors::bad;

/// Three numbers from any iterable (tuple, list, numpy array). At most four items are read, so
/// that an endless iterable is an error, not an endless loop.
pub fn vec3(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vector> {
    let mut v = Vec::with_capacity(3);
    for item in obj.try_iter()? {
        if v.len() == 3 {
            return Err(bad(format!("{what}: expected 3 numbers (x, y, z), got more")));
        }
        v.push(item?.extract::<f64>()?);
    }
    if v.len() != 3 {
        return Err(bad(format!("{what}: expected 3 numbers (x, y, z), got {}", v.len())));
    }
    Ok(Vector::new(v[0], v[1], v[2]))
}

/// The most items read from an iterable of points or blocks: an endless iterable raises
/// `MemoryError` there instead of growing until the allocator aborts the process.
pub const MAX_ITEMS: usize = 1_000_000;

/// `MemoryError` for an iterable longer than [`MAX_ITEMS`].
pub fn too_many(what: &str) -> PyErr {
    PyMemoryError::new_err(format!(
        "{what}: more than {MAX_ITEMS} items (an endless iterable?); give a list of at most {MAX_ITEMS}"
    ))
}

/// A whole-number argument kept whole (any Python int), so that the function can say which
/// argument is out of range instead of PyO3's `OverflowError` naming none.
pub struct Int(Result<i64, String>);

impl<'a, 'py> FromPyObject<'a, 'py> for Int {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if !obj.is_instance_of::<PyInt>() && !obj.hasattr("__index__")? {
            return Err(PyTypeError::new_err(format!(
                "expected an int, got {}",
                obj.get_type().name()?
            )));
        }
        Ok(Self(obj.extract::<i64>().map_err(|_| obj.to_string())))
    }
}

impl Int {
    /// A block index among `count` blocks (`VoussoirError`, a `ValueError`, naming `what`
    /// otherwise: negative, beyond the blocks, or beyond any int the model holds).
    pub fn block(&self, what: &str, count: usize) -> PyResult<voussoir::block::BlockId> {
        match self.0 {
            Ok(k) if k >= 0 && (k as u64) < count as u64 => Ok(voussoir::block::BlockId(k as u32)),
            Ok(k) if k < 0 => Err(bad(format!(
                "{what} {k} is negative: block indices run from 0 (negative indices are not counted from the end)"
            ))),
            Ok(k) if k <= i64::from(u32::MAX) => Err(bad(format!(
                "{what} {k}: {}",
                voussoir::Error::UnknownBlock {
                    id: voussoir::block::BlockId(k as u32),
                    count
                }
            ))),
            Ok(k) => Err(bad(format!("{what} {k} is out of range: the model has {count} blocks"))),
            Err(ref big) => Err(bad(format!(
                "{what} {big} is out of range: the model has {count} blocks"
            ))),
        }
    }

    /// A whole number in `[0, max]` (`ValueError` naming `what` otherwise).
    pub fn at_most(&self, what: &str, max: u64) -> PyResult<u64> {
        match self.0 {
            Ok(k) if k >= 0 && k as u64 <= max => Ok(k as u64),
            Ok(k) => Err(PyValueError::new_err(format!(
                "{what} = {k}: must be a whole number in [0, {max}]"
            ))),
            Err(ref big) => Err(PyValueError::new_err(format!(
                "{what} = {big}: must be a whole number in [0, {max}]"
            ))),
        }
    }
}

/// An optional vector, zero when `None`.
pub fn vec3_or_zero(obj: Option<&Bound<'_, PyAny>>, what: &str) -> PyResult<Vector> {
    obj.map_or(Ok(Vector::ZERO), |o| vec3(o, what))
}

/// A list of points from an iterable of 3-iterables or an (n, 3) array.
pub fn points(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Vector>> {
    let mut out = Vec::new();
    for (k, item) in obj.try_iter()?.enumerate() {
        if k == MAX_ITEMS {
            return Err(too_many(what));
        }
        out.push(vec3(&item?, &format!("{what}[{k}]"))?);
    }
    Ok(out)
}

fn dof(obj: &Bound<'_, PyAny>) -> PyResult<Dof> {
    if let Ok(s) = obj.cast::<PyString>() {
        return match s.to_cow()?.to_ascii_lowercase().as_str() {
            "free" => Ok(Dof::Free),
            "fixed" => Ok(Dof::Fixed),
            other => Err(bad(format!(
                "degree of freedom {other:?}: expected \"free\", \"fixed\" or a velocity (number)"
            ))),
        };
    }
    if obj.is_none() {
        return Ok(Dof::Free);
    }
    Ok(Dof::Velocity(obj.extract::<f64>()?))
}

fn dofs(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<[Dof; 3]> {
    // At most four read: an endless iterable is an error.
    let v: Vec<Dof> = obj.try_iter()?.take(4).map(|d| dof(&d?)).collect::<PyResult<_>>()?;
    v.try_into()
        .map_err(|v: Vec<Dof>| bad(format!("{what}: expected 3 degrees of freedom, got {}", v.len())))
}

/// A fixity: `True`/`"fixed"` (all six fixed), `False`/`None`/`"free"` (all free), or a dict
/// `{"translation": [d, d, d], "rotation": [d, d, d]}` with each `d` `"free"`, `"fixed"` or a
/// prescribed velocity (m/s, rad/s); a missing key means free.
pub fn fixity(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Fixity> {
    let Some(obj) = obj else {
        return Ok(Fixity::FREE);
    };
    if obj.is_none() {
        return Ok(Fixity::FREE);
    }
    if let Ok(b) = obj.extract::<bool>() {
        return Ok(if b { Fixity::FIXED } else { Fixity::FREE });
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return match s.to_cow()?.to_ascii_lowercase().as_str() {
            "fixed" => Ok(Fixity::FIXED),
            "free" => Ok(Fixity::FREE),
            other => Err(bad(format!(
                "fixity {other:?}: expected \"fixed\", \"free\", a bool or a dict with \"translation\" and \"rotation\""
            ))),
        };
    }
    let d = obj.cast::<PyDict>().map_err(|_| {
        bad("fixity: expected \"fixed\", \"free\", a bool or a dict with \"translation\" and \"rotation\"")
    })?;
    for key in d.keys() {
        let k: String = key.extract()?;
        if k != "translation" && k != "rotation" {
            return Err(bad(format!(
                "fixity: unknown key {k:?} (expected \"translation\", \"rotation\")"
            )));
        }
    }
    let get = |key: &str| -> PyResult<[Dof; 3]> {
        match d.get_item(key)? {
            Some(v) => dofs(&v, &format!("fixity[{key:?}]")),
            None => Ok([Dof::Free; 3]),
        }
    };
    Ok(Fixity {
        translation: get("translation")?,
        rotation: get("rotation")?,
    })
}

/// A fixity as Python data (the dict form of [`fixity`]).
pub fn fixity_to_py<'py>(py: Python<'py>, f: &Fixity) -> PyResult<Bound<'py, PyDict>> {
    let conv = |d: &[Dof; 3]| -> PyResult<Vec<Bound<'py, PyAny>>> {
        d.iter()
            .map(|d| match d {
                Dof::Free => Ok(PyString::new(py, "free").into_any()),
                Dof::Fixed => Ok(PyString::new(py, "fixed").into_any()),
                Dof::Velocity(v) => Ok(v.into_pyobject(py)?.into_any()),
            })
            .collect()
    };
    let out = PyDict::new(py);
    out.set_item("translation", conv(&f.translation)?)?;
    out.set_item("rotation", conv(&f.rotation)?)?;
    Ok(out)
}

/// An (n, 3) array of vectors.
pub fn array_n3<'py>(py: Python<'py>, v: impl Iterator<Item = Vector>) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = v.flat_map(|p| [p.x, p.y, p.z]).collect();
    let n = flat.len() / 3;
    Array2::from_shape_vec((n, 3), flat)
        .expect("3 per row")
        .into_pyarray(py)
}

/// An (n, k) array from rows of k numbers.
pub fn array_nk<'py, const K: usize>(
    py: Python<'py>,
    rows: impl Iterator<Item = [f64; K]>,
) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = rows.flatten().collect();
    let n = flat.len() / K;
    Array2::from_shape_vec((n, K), flat)
        .expect("K per row")
        .into_pyarray(py)
}

/// An (n, 3, 3) array of matrices, row-major.
pub fn array_n33<'py>(py: Python<'py>, m: impl Iterator<Item = [[f64; 3]; 3]>) -> Bound<'py, PyArray3<f64>> {
    let flat: Vec<f64> = m.flat_map(|r| r.into_iter().flatten()).collect();
    let n = flat.len() / 9;
    Array3::from_shape_vec((n, 3, 3), flat)
        .expect("9 per matrix")
        .into_pyarray(py)
}

/// A 1-D array.
pub fn array1<'py, T: numpy::Element>(py: Python<'py>, v: Vec<T>) -> Bound<'py, PyArray1<T>> {
    Array1::from_vec(v).into_pyarray(py)
}

/// A vector as a 1-D array of 3.
pub fn vector<'py>(py: Python<'py>, v: Vector) -> Bound<'py, PyArray1<f64>> {
    array1(py, vec![v.x, v.y, v.z])
}

/// A `serde_json::Value` as Python objects (through `json.loads`, so that numbers, `null`,
/// lists and dicts map as JSON says).
pub fn json_to_py<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| bad(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// `data` as a `voussoir._results.Result` named `kind`: a dict with a short `repr`.
pub fn result<'py>(py: Python<'py>, kind: &str, data: Bound<'py, PyDict>) -> PyResult<Bound<'py, PyAny>> {
    py.import("voussoir._results")?.getattr("Result")?.call1((kind, data))
}

/// A whole-number argument in `[0, max]` (`ValueError` naming `what` otherwise: `material=-1`
/// raised PyO3's `OverflowError` naming nothing when the argument was declared unsigned).
pub fn whole(value: i64, what: &str, max: u64) -> PyResult<u64> {
    Int(Ok(value)).at_most(what, max)
}
