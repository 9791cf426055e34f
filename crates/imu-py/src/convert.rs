//! NumPy and Python objects in, library types out, and back: shapes are checked here, once, with
//! the argument named. Nothing here computes.
use imukit::Table;
use imukit::io::described::Described;
use imukit::io::description::{Description, Value};
use imukit::io::params::{MAX_DEPTH, ParamValue, SensorTable};
use numpy::ndarray::{Array2, Array3};
use numpy::{
    IntoPyArray, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use crate::errors::shape_error;

/// A table for Python: column names and a (rows, columns) array.
pub(crate) type TableOut<'py> = (Vec<String>, Bound<'py, PyArray2<f64>>);

/// A table for Python with what it holds: column names, a (rows, columns) array and its
/// description's entries (`imukit.Table.description`).
pub(crate) type DescribedOut<'py> = (Vec<String>, Bound<'py, PyArray2<f64>>, Bound<'py, PyDict>);

/// The inputs' descriptions as Python hands them over: `(argument, entries)` for each table
/// argument that carries one.
pub(crate) type DescribedIn<'py> = Vec<(String, Bound<'py, PyDict>)>;

/// A shape as Python writes it: `(5, 2)`.
fn shape(s: &[usize]) -> String {
    match s {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            s.iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The rows of an (N, K) array.
pub(crate) fn rows<const K: usize>(
    name: &str,
    a: &PyReadonlyArray2<'_, f64>,
) -> PyResult<Vec<[f64; K]>> {
    let v = a.as_array();
    if v.ncols() != K {
        return Err(shape_error(format!(
            "{name} must have shape (N, {K}), got {}",
            shape(v.shape())
        )));
    }
    Ok(v.rows()
        .into_iter()
        .map(|r| std::array::from_fn(|k| r[k]))
        .collect())
}

/// A contiguous (N, K) array as one flat slice, row after row.
pub(crate) fn flat_rows<'a, const K: usize>(
    name: &str,
    a: &'a PyReadonlyArray2<'_, f64>,
) -> PyResult<&'a [f64]> {
    let s = a.shape();
    if s[1] != K {
        return Err(shape_error(format!(
            "{name} must have shape (N, {K}), got {}",
            shape(s)
        )));
    }
    a.as_slice()
        .map_err(|_| shape_error(format!("{name} must be C-contiguous")))
}

/// A one-dimensional array as a vector.
pub(crate) fn vector(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    a.as_array().to_vec()
}

/// `got` rows where `expected` are needed (one per time).
pub(crate) fn check_len(name: &str, got: usize, expected: usize) -> PyResult<()> {
    if got == expected {
        Ok(())
    } else {
        Err(shape_error(format!(
            "{name} has {got} rows, expected {expected} (one per time)"
        )))
    }
}

/// Column names and a (rows, columns) array as a library table.
pub(crate) fn table_in(
    name: &str,
    columns: Vec<String>,
    values: &PyReadonlyArray2<'_, f64>,
) -> PyResult<Table> {
    let v = values.as_array();
    if v.ncols() != columns.len() {
        return Err(shape_error(format!(
            "{name} has {} columns but {} column names",
            v.ncols(),
            columns.len()
        )));
    }
    Ok(Table {
        columns,
        data: v.iter().copied().collect(),
    })
}

/// A library table for Python.
pub(crate) fn table_out(py: Python<'_>, t: Table) -> PyResult<TableOut<'_>> {
    let shape = (t.rows(), t.columns.len());
    let arr = Array2::from_shape_vec(shape, t.data).map_err(|e| shape_error(e.to_string()))?;
    Ok((t.columns, arr.into_pyarray(py)))
}

/// A description's entries as a dict (keys without the `imukit.` prefix).
pub(crate) fn description_dict<'py>(
    py: Python<'py>,
    d: &Description,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    if d.is_empty() {
        return Ok(out);
    }
    for (k, v) in d.entries() {
        match v {
            Value::Text(s) => out.set_item(k, s)?,
            Value::Number(x) => out.set_item(k, x)?,
        }
    }
    Ok(out)
}

/// A library table and its description for Python.
pub(crate) fn described_out<'py>(
    py: Python<'py>,
    t: Table,
    d: &Description,
) -> PyResult<DescribedOut<'py>> {
    let dict = description_dict(py, d)?;
    let (columns, values) = table_out(py, t)?;
    Ok((columns, values, dict))
}

/// One table's description from its entries, each checked as a file's would be; `name` is
/// the argument.
pub(crate) fn description_in(name: &str, entries: &Bound<'_, PyDict>) -> PyResult<Description> {
    let mut pairs = Vec::with_capacity(entries.len());
    for (k, v) in entries.iter() {
        let key: String = k.extract().map_err(|_| {
            PyTypeError::new_err(format!("{name}.description: keys must be strings"))
        })?;
        let value = if v.is_instance_of::<PyBool>() {
            return Err(PyTypeError::new_err(format!(
                "{name}.description[{key:?}]: expected a name or a number, got a bool"
            )));
        } else if let Ok(x) = v.extract::<f64>()
            && (v.is_instance_of::<PyFloat>() || v.is_instance_of::<PyInt>())
        {
            Value::Number(x)
        } else if let Ok(text) = v.extract::<String>() {
            Value::Text(text)
        } else {
            return Err(PyTypeError::new_err(format!(
                "{name}.description[{key:?}]: expected a name or a number, got {}",
                v.get_type().name()?
            )));
        };
        pairs.push((key, value));
    }
    Description::from_entries(
        pairs.iter().map(|(k, v)| (k.as_str(), v.clone())),
        &format!("{name}.description"),
    )
    .map_err(crate::errors::refused)
}

/// The descriptions of a job's table arguments, named as messages give them ("the imu
/// table").
pub(crate) fn described_in(named: &DescribedIn<'_>) -> PyResult<Described> {
    let mut out = Vec::with_capacity(named.len());
    for (name, entries) in named {
        out.push((format!("the {name} table"), description_in(name, entries)?));
    }
    Ok(Described::of(out))
}

/// A row-major (rows, cols) array from flat data.
pub(crate) fn array2(
    py: Python<'_>,
    rows: usize,
    cols: usize,
    data: Vec<f64>,
) -> PyResult<Bound<'_, PyArray2<f64>>> {
    Array2::from_shape_vec((rows, cols), data)
        .map(|a| a.into_pyarray(py))
        .map_err(|e| shape_error(e.to_string()))
}

/// Rows of K values as an (N, K) array.
pub(crate) fn rows_out<const K: usize>(
    py: Python<'_>,
    v: Vec<[f64; K]>,
) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let n = v.len();
    array2(py, n, K, v.into_iter().flatten().collect())
}

/// 3×3 matrices from an (N, 3, 3) array.
pub(crate) fn matrices_in(
    name: &str,
    a: &PyReadonlyArray3<'_, f64>,
) -> PyResult<Vec<[[f64; 3]; 3]>> {
    let v = a.as_array();
    if v.shape()[1..] != [3, 3] {
        return Err(shape_error(format!(
            "{name} must have shape (N, 3, 3), got {}",
            shape(v.shape())
        )));
    }
    Ok(v.outer_iter()
        .map(|m| std::array::from_fn(|i| std::array::from_fn(|k| m[[i, k]])))
        .collect())
}

/// 3×3 matrices as an (N, 3, 3) array.
pub(crate) fn matrices_out(
    py: Python<'_>,
    m: Vec<[[f64; 3]; 3]>,
) -> PyResult<Bound<'_, PyArray3<f64>>> {
    let n = m.len();
    Array3::from_shape_vec((n, 3, 3), m.into_iter().flatten().flatten().collect())
        .map(|a| a.into_pyarray(py))
        .map_err(|e| shape_error(e.to_string()))
}

/// A Python value (dict, list, tuple, NumPy array or scalar, number, string, bool) as the
/// library's typed value tree: integers stay integers, `inf` stays infinite. Dict entries whose
/// value is `None` are left out (not given); `path` names the value in messages. Nested deeper
/// than [`MAX_DEPTH`] is refused, naming where, before going further.
pub(crate) fn value_tree(obj: &Bound<'_, PyAny>, path: &str) -> PyResult<ParamValue> {
    tree_at(obj, &At::Root(path), 0)
}

/// Where a value sits in the object handed over (`scenario.imu.lever_arm_m[1]`), written out
/// only for a message: most calls need none, and formatting every key's path was a tenth of a
/// short simulation's call.
enum At<'a> {
    Root(&'a str),
    Key(&'a At<'a>, &'a str),
    Item(&'a At<'a>, usize),
}

impl std::fmt::Display for At<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Root(name) => f.write_str(name),
            Self::Key(parent, key) => write!(f, "{parent}.{key}"),
            Self::Item(parent, k) => write!(f, "{parent}[{k}]"),
        }
    }
}

fn tree_at(obj: &Bound<'_, PyAny>, at: &At<'_>, depth: usize) -> PyResult<ParamValue> {
    if depth > MAX_DEPTH {
        return Err(crate::errors::refused(imukit::Error::Invalid {
            field: at.to_string().into(),
            message: format!("nested deeper than {MAX_DEPTH} levels"),
        }));
    }
    if obj.is_instance_of::<PyBool>() {
        return Ok(ParamValue::Bool(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        // Exact up to 128 bits (every seed, any `u64`, fits); beyond, the nearest number.
        if let Ok(i) = obj.extract::<i128>() {
            return Ok(ParamValue::Integer(i));
        }
        return Ok(ParamValue::Number(obj.extract()?));
    }
    if obj.is_instance_of::<PyFloat>() {
        return Ok(ParamValue::Number(obj.extract()?));
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(ParamValue::Text(obj.extract()?));
    }
    if obj.is_none() {
        return Ok(ParamValue::Null);
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut table = SensorTable::new();
        for (k, v) in d.iter() {
            let key: String = k
                .extract()
                .map_err(|_| PyTypeError::new_err(format!("{at}: keys must be strings")))?;
            if v.is_none() {
                continue;
            }
            let inner = tree_at(&v, &At::Key(at, &key), depth + 1)?;
            table.insert(key, inner);
        }
        return Ok(ParamValue::Table(table));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let items = obj
            .try_iter()?
            .enumerate()
            .map(|(k, v)| tree_at(&v?, &At::Item(at, k), depth + 1))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(ParamValue::List(items));
    }
    // NumPy arrays and scalars: their Python equivalents.
    if obj.hasattr("tolist")? {
        return tree_at(&obj.call_method0("tolist")?, at, depth);
    }
    Err(PyTypeError::new_err(format!(
        "{at}: expected a number, string, bool, list or dict, got {}",
        obj.get_type().name()?
    )))
}

/// A sensor's parameters given as a dict (imukit's or MATLAB's names).
pub(crate) fn sensor_table(
    name: &str,
    obj: Option<&Bound<'_, PyAny>>,
) -> PyResult<Option<SensorTable>> {
    match obj.map(|o| value_tree(o, name)).transpose()? {
        None | Some(ParamValue::Null) => Ok(None),
        Some(ParamValue::Table(t)) => Ok(Some(t)),
        Some(_) => Err(PyTypeError::new_err(format!(
            "{name} must be AccelParams/GyroParams/MagParams or a dict of parameters (imukit or MATLAB names)"
        ))),
    }
}

/// A library choice given by name (any case) for the keyword `field`.
pub(crate) fn choice<T: imukit::choice::Choice>(field: &str, name: &str) -> PyResult<T> {
    T::parse(field, name).map_err(crate::errors::refused)
}

/// An optional library choice given by name for the keyword `field`.
pub(crate) fn choice_opt<T: imukit::choice::Choice>(
    field: &str,
    name: Option<&str>,
) -> PyResult<Option<T>> {
    name.map(|n| choice(field, n)).transpose()
}

/// A count or seed given as a Python int: refused by name when negative (instead of Python's
/// bare `OverflowError` from the conversion).
pub(crate) fn non_negative(name: &str, v: i64) -> PyResult<u64> {
    u64::try_from(v).map_err(|_| {
        crate::errors::refused(imukit::Error::Invalid {
            field: name.into(),
            message: format!("must be ≥ 0, got {v}"),
        })
    })
}

/// `N` numbers given as a Python sequence, named in the error when there are not `N`.
pub(crate) fn fixed<const N: usize>(name: &str, v: &[f64]) -> PyResult<[f64; N]> {
    <[f64; N]>::try_from(v)
        .map_err(|_| shape_error(format!("{name} must have {N} numbers, got {}", v.len())))
}

/// [`fixed`] for an optional argument.
pub(crate) fn fixed_opt<const N: usize>(
    name: &str,
    v: Option<Vec<f64>>,
) -> PyResult<Option<[f64; N]>> {
    v.map(|v| fixed::<N>(name, &v)).transpose()
}
