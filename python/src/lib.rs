//! The native module `dhcd._dhcd` of the Python package (see `python/dhcd/__init__.pyi` for
//! the documented API and `docs/PYTHON.md`). A thin layer: numpy arrays in, the library's
//! calls with the GIL released, numpy arrays out, library errors as `ValueError` (`OSError`
//! for files that cannot be read).
//!
//! Precision: a float64 vertex array builds an `f64` hierarchy (answers exact for the
//! doubles), any other real array an `f32` one; an update must then be of the same float
//! type (float32 for `f32`, float64 for `f64`: the other is a `ValueError`, never a silent
//! rounding), and other real dtypes (integers, float16, ...) are converted to the
//! hierarchy's precision.
//!
//! Copies: a C-contiguous `(n, 3)` vertex array of the hierarchy's float type is read in
//! place (the library then copies it once into its own vertex order); any other vertex array
//! is first converted once by numpy. Faces are converted to `u32` once, at construction.
//!
//! Continuous collision detection (`ccd`, `vertex_face_ccd`, `edge_edge_ccd`) takes float64
//! positions only, for hierarchies of either precision: any other dtype is a `ValueError`,
//! never converted (the answers are exact for the doubles given; the caller converts, and
//! sees what is rounded).
//!
//! Layout: one file per query family (`collide`, `proximity`, `ccd`, `contact`, `step`), each
//! with its result class, the one conversion of each library result into it, and its
//! functions, so a new pair query touches one file; `hierarchy` and `scene` hold the two
//! classes (a `Scene` query method parses its arguments there and returns its family's
//! result); `arrays` the numpy conversions in; `interrupt` Ctrl-C and the result limit. Here:
//! errors, scalar arguments, the module-level functions and the module.
#![forbid(unsafe_code)]

mod arrays;
mod ccd;
mod collide;
mod contact;
mod hierarchy;
mod interrupt;
mod proximity;
mod scene;
mod step;

use std::path::PathBuf;

use dhcd::distance::{EdgeEdge, PointTriangle};
use dhcd::{Counters, Error, Method, Options, Par, Precision};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::exceptions::{
    PyFileNotFoundError, PyKeyboardInterrupt, PyMemoryError, PyOSError, PyValueError,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A library error as a Python exception: `OSError` (`FileNotFoundError` for a missing file)
/// when a file cannot be read (or is not a regular file, or is over the size limit),
/// `ValueError` for everything else (bad input).
fn to_py(e: Error) -> PyErr {
    match &e {
        Error::Io { path, .. } if !path.exists() => {
            PyFileNotFoundError::new_err((2, e.to_string(), path.display().to_string()))
        }
        Error::Io { .. } | Error::FileTooLarge { .. } => PyOSError::new_err(e.to_string()),
        Error::OutOfMemory { .. } => PyMemoryError::new_err(e.to_string()),
        Error::Cancelled => PyKeyboardInterrupt::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

fn value_error(message: String) -> PyErr {
    PyValueError::new_err(message)
}

/// An integer argument; one beyond 64 bits is a `ValueError` like any other bad value
/// (Python would raise `OverflowError`).
fn int_arg(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<i64> {
    obj.extract::<i64>().map_err(|e| {
        if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(obj.py()) {
            value_error(format!("{what} {obj} is out of range"))
        } else {
            e
        }
    })
}

/// The thread count of a query, checked where every thread count is (`Par::threads`): `1`
/// (the default, `None` here) the calling thread, `0` all cores, `n` a pool of at most the
/// machine's threads; above `dhcd::Par::MAX_THREADS`, or negative, a `ValueError`.
fn par(threads: Option<&Bound<'_, PyAny>>) -> PyResult<Par> {
    let threads = match threads {
        None => 1,
        Some(t) => int_arg(t, "threads")?,
    };
    let n = usize::try_from(threads)
        .map_err(|_| value_error(format!("threads must not be negative, got {threads}")))?;
    Par::threads(n).map_err(to_py)
}

fn options(levels: Option<&Bound<'_, PyAny>>) -> PyResult<Options> {
    let levels = match levels.map(|l| int_arg(l, "levels")).transpose()? {
        None => None,
        Some(n) if n > 0 => Some(n as usize),
        Some(n) => return Err(value_error(format!("levels must be positive, got {n}"))),
    };
    let options = Options {
        levels,
        ..Options::default()
    };
    options.shape().check().map_err(to_py)?;
    Ok(options)
}

fn method(name: &str) -> PyResult<Method> {
    name.parse::<Method>().map_err(to_py)
}

fn counters(py: Python<'_>, c: Counters) -> PyResult<Py<PyDict>> {
    let d = PyDict::new(py);
    d.set_item("bv_tests", c.bv_tests)?;
    d.set_item("prim_tests", c.prim_tests)?;
    d.set_item("bv_updates", c.bv_updates)?;
    d.set_item("contacts", c.contacts)?;
    Ok(d.unbind())
}

/// A distance argument: a real number (its range is the library's to check); one beyond
/// the `float` range is a `ValueError` like any other bad distance.
fn distance_arg(obj: &Bound<'_, PyAny>) -> PyResult<f64> {
    obj.extract::<f64>().map_err(|e| {
        if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(obj.py()) {
            value_error(format!("distance {obj} is out of range"))
        } else {
            e
        }
    })
}

/// A real-number argument (`what` names it in messages; its range is the library's to
/// check); one beyond the `float` range is a `ValueError` like any other bad value.
fn real_arg(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<f64> {
    obj.extract::<f64>().map_err(|e| {
        if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(obj.py()) {
            value_error(format!("{what} {obj} is out of range"))
        } else {
            e
        }
    })
}

/// Sets the most result pairs one query may return (`None`: no limit; default 2**25); a
/// query that would return more raises `ValueError` naming the count reached and the limit.
#[pyfunction]
#[pyo3(signature = (n))]
pub(crate) fn set_max_pairs(n: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
    let n = match n {
        None => u64::MAX,
        Some(n) => {
            let v = int_arg(n, "max_pairs")?;
            u64::try_from(v)
                .map_err(|_| value_error(format!("max_pairs must not be negative, got {v}")))?
        }
    };
    interrupt::set_max_pairs(n);
    Ok(())
}

/// The most result pairs one query may return (`None`: no limit).
#[pyfunction]
pub(crate) fn max_pairs() -> Option<u64> {
    Some(interrupt::max_pairs()).filter(|&n| n != u64::MAX)
}

/// `(vertices, faces)` as numpy arrays: vertices float32 or float64, faces int64.
type MeshArrays<'py> = (Bound<'py, PyAny>, Bound<'py, PyArray2<i64>>);

/// `(vertices, faces)` of an OBJ, STL or PLY file: vertices `(n, 3)` float32 (`precision
/// = "f32"`, the default) or float64 at full precision (`"f64"`: PLY doubles and OBJ
/// decimals as written), faces int64 `(m, 3)`. Only regular files of at most
/// `max_file_bytes` (default 1 GiB) are read.
#[pyfunction]
#[pyo3(signature = (path, max_file_bytes = None, precision = "f32"))]
pub(crate) fn load_mesh<'py>(
    py: Python<'py>,
    path: PathBuf,
    max_file_bytes: Option<&Bound<'py, PyAny>>,
    precision: &str,
) -> PyResult<MeshArrays<'py>> {
    let precision: Precision = precision.parse().map_err(to_py)?;
    let limits = match max_file_bytes {
        None => dhcd::io::Limits::default(),
        Some(m) => dhcd::io::Limits {
            max_file_bytes: u64::try_from(int_arg(m, "max_file_bytes")?).map_err(|_| {
                value_error(format!("max_file_bytes must not be negative, got {m}"))
            })?,
        },
    };
    let mesh = py
        .detach(|| dhcd::io::load_as(&path, &limits, precision))
        .map_err(to_py)?;
    let f: Vec<i64> = mesh
        .triangles()
        .iter()
        .flatten()
        .map(|&i| i64::from(i))
        .collect();
    let shape = |n: usize| (n, 3);
    let internal = |e: numpy::ndarray::ShapeError| value_error(format!("internal error: {e}"));
    let v = match mesh.positions_f64() {
        Some(p) => Array2::from_shape_vec(shape(p.len()), p.as_flattened().to_vec())
            .map_err(internal)?
            .into_pyarray(py)
            .into_any(),
        None => {
            let p = mesh.positions();
            Array2::from_shape_vec(shape(p.len()), p.as_flattened().to_vec())
                .map_err(internal)?
                .into_pyarray(py)
                .into_any()
        }
    };
    let f = Array2::from_shape_vec(shape(mesh.triangle_count()), f).map_err(internal)?;
    Ok((v, f.into_pyarray(py)))
}

/// IPC's names of the point-triangle distance types, indexed by their numbers (the
/// `vf_type` / `fv_type` values).
fn point_triangle_types() -> Vec<&'static str> {
    let names: Vec<&str> = PointTriangle::ALL.iter().map(|t| t.ipc_name()).collect();
    debug_assert!(PointTriangle::ALL
        .iter()
        .enumerate()
        .all(|(k, &t)| t as usize == k));
    names
}

/// IPC's names of the edge-edge distance types, indexed by their numbers (`ee_type`).
fn edge_edge_types() -> Vec<&'static str> {
    let names: Vec<&str> = EdgeEdge::ALL.iter().map(|t| t.ipc_name()).collect();
    debug_assert!(EdgeEdge::ALL
        .iter()
        .enumerate()
        .all(|(k, &t)| t as usize == k));
    names
}

/// The module's classes and functions other than the contact set's and the step size's,
/// under one name each for the module's list of exports (the families' modules are named
/// like their main functions: `ccd`, `collide`, `proximity`).
mod exports {
    pub(crate) use super::ccd::{ccd, edge_edge_ccd, vertex_face_ccd, Impacts};
    pub(crate) use super::collide::{collide, contact_segments, Contacts};
    pub(crate) use super::hierarchy::Hierarchy;
    pub(crate) use super::proximity::{proximity, self_proximity, Proximity};
    pub(crate) use super::scene::Scene;
    pub(crate) use super::{load_mesh, max_pairs, set_max_pairs};
}

/// Collision detection between deformable triangle meshes (Distance Hierarchy, sphere and
/// AABB hierarchies, exact contacts); the native part of the `dhcd` package.
#[pymodule(name = "_dhcd")]
mod dhcd_native {
    // In the order of `dhcd._dhcd.__all__` (the comments keep rustfmt from sorting them).
    #[pymodule_export]
    use super::contact::{
        contact_set, distance_gradient, distance_hessian, distance_sq, self_contact_set, ContactSet,
    };
    #[pymodule_export]
    use super::step::collision_free_stepsize;
    // The other classes and functions.
    #[pymodule_export]
    use super::exports::{
        ccd, collide, contact_segments, edge_edge_ccd, load_mesh, max_pairs, proximity,
        self_proximity, set_max_pairs, vertex_face_ccd, Contacts, Hierarchy, Impacts, Proximity,
        Scene,
    };

    #[pymodule_init]
    fn init(m: &pyo3::Bound<'_, pyo3::types::PyModule>) -> pyo3::PyResult<()> {
        use pyo3::types::PyModuleMethods;
        let names: Vec<&str> = dhcd::Method::ALL.iter().map(|k| k.name()).collect();
        m.add("METHODS", names)?;
        m.add("POINT_TRIANGLE_TYPES", super::point_triangle_types())?;
        m.add("EDGE_EDGE_TYPES", super::edge_edge_types())
    }
}
