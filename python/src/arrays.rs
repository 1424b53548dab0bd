//! numpy arrays in: vertex arrays in the hierarchy's precision ([`Vertices`], read in place
//! when they can be), faces and contact pairs as `u32` indices, and float64 arrays taken as
//! they are (CCD positions: never converted).

use dhcd::{Error, Mesh, Precision};
use numpy::PyReadonlyArray2;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::{to_py, value_error};

/// Real numbers and integers, as numpy's dtype kind letters and in words.
pub(crate) const REAL: (&str, &str) = ("fiu", "a real number type");
const INTEGER: (&str, &str) = ("iu", "an integer type");

/// `numpy.asarray(obj)`, or `TypeError` when `obj` is of a Python type that is no array at
/// all (`None`, a string, a dict); `what` names it in messages. (An array of the wrong shape
/// or dtype is a `ValueError`, raised by the caller.)
pub(crate) fn array_of_numbers<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let wrong_type = || -> PyResult<PyErr> {
        let kind = obj.get_type().name()?;
        Ok(PyTypeError::new_err(format!(
            "{what} must be an array of numbers, got {kind}"
        )))
    };
    if obj.is_none() || obj.is_instance_of::<PyString>() || obj.is_instance_of::<PyDict>() {
        return Err(wrong_type()?);
    }
    let np = obj.py().import("numpy")?;
    let arr = np
        .call_method1("asarray", (obj,))
        .map_err(|e| value_error(format!("{what}: cannot convert to an array ({e})")))?;
    Ok(arr)
}

/// `numpy.asarray(obj)` checked to be a 2-D array with 3 columns whose dtype is one of
/// `kinds` (`REAL` or `INTEGER`); `what` names it in messages.
pub(crate) fn numeric_n3<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
    (kinds, kinds_text): (&str, &str),
) -> PyResult<Bound<'py, PyAny>> {
    let arr = array_of_numbers(obj, what)?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if shape.len() != 2 || shape[1] != 3 {
        let shape = arr.getattr("shape")?.repr()?;
        return Err(value_error(format!(
            "{what} must be an (n, 3) array, got shape {shape}"
        )));
    }
    let dtype = arr.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    if !kinds.contains(kind.as_str()) {
        let name = dtype.str()?;
        return Err(value_error(format!(
            "{what} has dtype {name}, which is not {kinds_text}"
        )));
    }
    Ok(arr)
}

/// Vertex positions in a precision: a C-contiguous view of the caller's array when it is one
/// of that float type, else a copy made by numpy.
pub(crate) enum Vertices<'py> {
    F32(PyReadonlyArray2<'py, f32>),
    F64(PyReadonlyArray2<'py, f64>),
}

/// Borrowed positions of either precision.
#[derive(Clone, Copy)]
pub(crate) enum Positions<'a> {
    F32(&'a [[f32; 3]]),
    F64(&'a [[f64; 3]]),
}

impl<'py> Vertices<'py> {
    /// The vertices of a new mesh: float64 arrays (any byte order) in `f64`, every other
    /// real dtype in `f32` (float32 read as it is, the others converted).
    pub(crate) fn new(obj: &Bound<'py, PyAny>) -> PyResult<Self> {
        let arr = numeric_n3(obj, "vertices", REAL)?;
        let precision = float_precision(&arr)?.unwrap_or(Precision::F32);
        Self::convert(arr, precision)
    }

    /// New positions for a hierarchy or object of `precision`: a float32 or float64 array
    /// of the other precision is the library's `PrecisionMismatch`; other real dtypes are
    /// converted to `precision`.
    pub(crate) fn update(obj: &Bound<'py, PyAny>, precision: Precision) -> PyResult<Self> {
        let arr = numeric_n3(obj, "vertices", REAL)?;
        match float_precision(&arr)? {
            Some(got) if got != precision => Err(to_py(Error::PrecisionMismatch {
                expected: precision,
                got,
            })),
            _ => Self::convert(arr, precision),
        }
    }

    fn convert(arr: Bound<'py, PyAny>, precision: Precision) -> PyResult<Self> {
        let np = arr.py().import("numpy")?;
        // No copy if `arr` is already of that type (native byte order) and C-contiguous.
        Ok(match precision {
            Precision::F64 => Self::F64(
                np.call_method1("ascontiguousarray", (arr, "float64"))?
                    .extract()?,
            ),
            _ => Self::F32(
                np.call_method1("ascontiguousarray", (arr, "float32"))?
                    .extract()?,
            ),
        })
    }

    pub(crate) fn positions(&self) -> PyResult<Positions<'_>> {
        let err = |e| value_error(format!("vertices: {e}"));
        Ok(match self {
            Self::F32(a) => Positions::F32(bytemuck::cast_slice(a.as_slice().map_err(err)?)),
            Self::F64(a) => Positions::F64(bytemuck::cast_slice(a.as_slice().map_err(err)?)),
        })
    }
}

impl Positions<'_> {
    /// A validated mesh of these positions (its precision theirs).
    pub(crate) fn mesh(self, faces: Vec<[u32; 3]>) -> dhcd::Result<Mesh> {
        match self {
            Positions::F32(p) => Mesh::new(p.to_vec(), faces),
            Positions::F64(p) => Mesh::new_f64(p.to_vec(), faces),
        }
    }
}

/// The precision of a float32 or float64 array (any byte order); `None` for other dtypes.
fn float_precision(arr: &Bound<'_, PyAny>) -> PyResult<Option<Precision>> {
    let dtype = arr.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    let size: usize = dtype.getattr("itemsize")?.extract()?;
    Ok(match (kind.as_str(), size) {
        ("f", 4) => Some(Precision::F32),
        ("f", 8) => Some(Precision::F64),
        _ => None,
    })
}

/// Faces as `u32` triangles (negative or too large indices are errors here; indices beyond
/// the vertex count are the library's `IndexOutOfRange`).
pub(crate) fn faces(obj: &Bound<'_, PyAny>) -> PyResult<Vec<[u32; 3]>> {
    index_rows(&numeric_n3(obj, "faces", INTEGER)?, "face")
}

/// Contact pairs `(K, 2)` from Python: non-negative integers below 2^32.
pub(crate) fn pairs(obj: &Bound<'_, PyAny>) -> PyResult<Vec<[u32; 2]>> {
    let np = obj.py().import("numpy")?;
    let arr = np
        .call_method1("asarray", (obj,))
        .map_err(|e| value_error(format!("pairs: cannot convert to an array ({e})")))?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    let empty = shape.first() == Some(&0);
    // `[]` (shape (0,)) is an empty list of pairs too.
    let well_shaped = shape.len() == 2 && shape[1] == 2 || empty && shape.len() <= 2;
    if !well_shaped {
        let shape = arr.getattr("shape")?.repr()?;
        return Err(value_error(format!(
            "pairs must be a (K, 2) array, got shape {shape}"
        )));
    }
    if empty {
        return Ok(Vec::new());
    }
    if !"iu".contains(kind.as_str()) {
        return Err(value_error(format!(
            "pairs must be integers, got dtype kind {kind:?}"
        )));
    }
    index_rows(&arr, "pair")
}

/// The rows of a 2-D integer array of `N` columns as `u32` indices; a value outside
/// `0..2^32` is an error naming the `item` (row) it is in.
fn index_rows<const N: usize>(arr: &Bound<'_, PyAny>, item: &str) -> PyResult<Vec<[u32; N]>> {
    let np = arr.py().import("numpy")?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    // int64 holds every valid index; uint64 values beyond it would wrap, so refuse them here.
    let size: usize = arr.getattr("size")?.extract()?;
    if kind == "u" && size > 0 && arr.call_method0("max")?.gt(u32::MAX)? {
        return Err(value_error(format!(
            "a {item} has an index above 2^32 - 1, which is out of range"
        )));
    }
    let a: PyReadonlyArray2<'_, i64> = np
        .call_method1("ascontiguousarray", (arr, "int64"))?
        .extract()?;
    a.as_array()
        .rows()
        .into_iter()
        .enumerate()
        .map(|(k, row)| {
            let mut out = [0u32; N];
            for (o, &v) in out.iter_mut().zip(row.iter()) {
                *o = u32::try_from(v).map_err(|_| {
                    value_error(format!("{item} {k} has index {v}, which is out of range"))
                })?;
            }
            Ok(out)
        })
        .collect()
}

/// `numpy.asarray(obj)` checked to be a float64 array of shape `(n, *tail)`, as a
/// C-contiguous float64 array (the caller's when it already is one; a copy of the same
/// values when its byte order or strides differ). Any other dtype is an error naming
/// `what`, never a conversion.
pub(crate) fn float64_rows<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
    tail: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let arr = array_of_numbers(obj, what)?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if shape.len() != tail.len() + 1 || shape[1..] != *tail {
        let want: Vec<String> = std::iter::once("n".to_string())
            .chain(tail.iter().map(|d| d.to_string()))
            .collect();
        let got = arr.getattr("shape")?.repr()?;
        return Err(value_error(format!(
            "{what} must be an ({}) array, got shape {got}",
            want.join(", ")
        )));
    }
    if float_precision(&arr)? != Some(Precision::F64) {
        let dtype = arr.getattr("dtype")?.str()?;
        return Err(value_error(format!(
            "{what} has dtype {dtype}; CCD positions must be float64 (no conversion: convert \
             explicitly, e.g. with .astype(numpy.float64))"
        )));
    }
    let np = obj.py().import("numpy")?;
    np.call_method1("ascontiguousarray", (arr, "float64"))
}

/// CCD positions of one mesh at one time: a float64 `(n, 3)` array.
pub(crate) fn ccd_positions<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<PyReadonlyArray2<'py, f64>> {
    float64_rows(obj, what, &[3])?.extract()
}

/// A read-only float64 array as rows of `[f64; N]`.
pub(crate) fn rows_of<'a, const N: usize>(
    a: &'a PyReadonlyArray2<'_, f64>,
    what: &str,
) -> PyResult<&'a [[f64; N]]>
where
    [f64; N]: bytemuck::Pod,
{
    let flat = a
        .as_slice()
        .map_err(|e| value_error(format!("{what}: {e}")))?;
    Ok(bytemuck::cast_slice(flat))
}
