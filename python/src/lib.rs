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
#![forbid(unsafe_code)]

mod contact;
mod interrupt;
mod step;

use std::collections::{HashMap, HashSet};
use std::path::PathBuf;

use dhcd::ccd::CcdOptions;
use dhcd::distance::{EdgeEdge, PointTriangle};
use dhcd::{check_positions, check_positions_f64};
use dhcd::{
    AnyHierarchy, CcdMode, CcdQuery, Counters, Error, Mesh, Method, Motion, ObjectId, Options, Par,
    Precision, Workspace,
};
use numpy::ndarray::{Array2, Array3};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray2, PyReadonlyArray3,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{
    PyFileNotFoundError, PyKeyboardInterrupt, PyMemoryError, PyOSError, PyTypeError, PyValueError,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyMapping, PyString, PyTuple};

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

/// Real numbers and integers, as numpy's dtype kind letters and in words.
const REAL: (&str, &str) = ("fiu", "a real number type");
const INTEGER: (&str, &str) = ("iu", "an integer type");

/// `numpy.asarray(obj)`, or `TypeError` when `obj` is of a Python type that is no array at
/// all (`None`, a string, a dict); `what` names it in messages. (An array of the wrong shape
/// or dtype is a `ValueError`, raised by the caller.)
fn array_of_numbers<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyAny>> {
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
fn numeric_n3<'py>(
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
enum Vertices<'py> {
    F32(PyReadonlyArray2<'py, f32>),
    F64(PyReadonlyArray2<'py, f64>),
}

/// Borrowed positions of either precision.
#[derive(Clone, Copy)]
enum Positions<'a> {
    F32(&'a [[f32; 3]]),
    F64(&'a [[f64; 3]]),
}

impl<'py> Vertices<'py> {
    /// The vertices of a new mesh: float64 arrays (any byte order) in `f64`, every other
    /// real dtype in `f32` (float32 read as it is, the others converted).
    fn new(obj: &Bound<'py, PyAny>) -> PyResult<Self> {
        let arr = numeric_n3(obj, "vertices", REAL)?;
        let precision = float_precision(&arr)?.unwrap_or(Precision::F32);
        Self::convert(arr, precision)
    }

    /// New positions for a hierarchy or object of `precision`: a float32 or float64 array
    /// of the other precision is the library's `PrecisionMismatch`; other real dtypes are
    /// converted to `precision`.
    fn update(obj: &Bound<'py, PyAny>, precision: Precision) -> PyResult<Self> {
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

    fn positions(&self) -> PyResult<Positions<'_>> {
        let err = |e| value_error(format!("vertices: {e}"));
        Ok(match self {
            Self::F32(a) => Positions::F32(bytemuck::cast_slice(a.as_slice().map_err(err)?)),
            Self::F64(a) => Positions::F64(bytemuck::cast_slice(a.as_slice().map_err(err)?)),
        })
    }
}

impl Positions<'_> {
    /// A validated mesh of these positions (its precision theirs).
    fn mesh(self, faces: Vec<[u32; 3]>) -> dhcd::Result<Mesh> {
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

/// Faces as `u32` triangles (negative or too large indices are errors here; indices beyond
/// the vertex count are the library's `IndexOutOfRange`).
fn faces(obj: &Bound<'_, PyAny>) -> PyResult<Vec<[u32; 3]>> {
    index_rows(&numeric_n3(obj, "faces", INTEGER)?, "face")
}

/// Contact pairs `(K, 2)` from Python: non-negative integers below 2^32.
fn pairs(obj: &Bound<'_, PyAny>) -> PyResult<Vec<[u32; 2]>> {
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

/// The result of a query: `.pairs` (a sorted `(K, 2)` or `(K, 4)` int64 array) and
/// `.counters` (a dict: `bv_tests`, `prim_tests`, `bv_updates`, `contacts`).
#[pyclass(module = "dhcd", frozen)]
struct Contacts {
    #[pyo3(get)]
    pairs: Py<PyArray2<i64>>,
    #[pyo3(get)]
    counters: Py<PyDict>,
}

impl Contacts {
    fn new<const N: usize>(py: Python<'_>, rows: Vec<[u64; N]>, c: Counters) -> PyResult<Self> {
        let k = rows.len();
        let flat: Vec<i64> = rows.into_iter().flatten().map(|v| v as i64).collect();
        let arr = Array2::from_shape_vec((k, N), flat)
            .map_err(|e| value_error(format!("internal error: {e}")))?;
        Ok(Self {
            pairs: arr.into_pyarray(py).unbind(),
            counters: counters(py, c)?,
        })
    }
}

#[pymethods]
impl Contacts {
    fn __len__(&self, py: Python<'_>) -> usize {
        self.pairs.bind(py).shape()[0]
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let c = self.counters.bind(py);
        Ok(format!(
            "Contacts({} pairs, counters={})",
            self.pairs.bind(py).shape()[0],
            c.repr()?
        ))
    }
}

/// Rows of `N` indices, each with its squared distance and distance type.
type Rows<const N: usize> = Vec<([u64; N], f64, u8)>;

/// The three lists of a proximity result, as rows: vertex-face, face-vertex, edge-edge.
type ProximityRows<const V: usize, const E: usize> = (Rows<V>, Rows<V>, Rows<E>, Counters);

/// A pair query's result as rows (already sorted by the library).
fn proximity_rows(p: dhcd::Proximity) -> ProximityRows<2, 4> {
    let i = u64::from;
    (
        p.vertex_face
            .iter()
            .map(|x| ([i(x.vertex), i(x.triangle)], x.distance_sq, x.kind as u8))
            .collect(),
        p.face_vertex
            .iter()
            .map(|x| ([i(x.triangle), i(x.vertex)], x.distance_sq, x.kind as u8))
            .collect(),
        p.edge_edge
            .iter()
            .map(|x| {
                let row = [i(x.a[0]), i(x.a[1]), i(x.b[0]), i(x.b[1])];
                (row, x.distance_sq, x.kind as u8)
            })
            .collect(),
        p.counters,
    )
}

/// A scene's result flattened with object ids (as the C ABI's `DhcdSceneProximity`), each
/// list sorted by its rows.
fn scene_proximity_rows(p: dhcd::SceneProximity) -> ProximityRows<4, 6> {
    let (mut vf, mut fv, mut ee) = (Vec::new(), Vec::new(), Vec::new());
    let i = u64::from;
    for pair in &p.per_pair {
        let (a, b, q) = (pair.a.0, pair.b.0, &pair.proximity);
        vf.extend(q.vertex_face.iter().map(|x| {
            (
                [a, i(x.vertex), b, i(x.triangle)],
                x.distance_sq,
                x.kind as u8,
            )
        }));
        fv.extend(q.face_vertex.iter().map(|x| {
            (
                [a, i(x.triangle), b, i(x.vertex)],
                x.distance_sq,
                x.kind as u8,
            )
        }));
        ee.extend(q.edge_edge.iter().map(|x| {
            let row = [a, i(x.a[0]), i(x.a[1]), b, i(x.b[0]), i(x.b[1])];
            (row, x.distance_sq, x.kind as u8)
        }));
    }
    // Rows are unique (one per feature pair of one object pair): the order is total.
    vf.sort_unstable_by_key(|r| r.0);
    fv.sort_unstable_by_key(|r| r.0);
    ee.sort_unstable_by_key(|r| r.0);
    (vf, fv, ee, p.counters)
}

/// One list of a proximity result as numpy arrays: `(K, N)` int64 rows, `(K,)` float64
/// squared distances, `(K,)` uint8 types.
type Columns = (Py<PyArray2<i64>>, Py<PyArray1<f64>>, Py<PyArray1<u8>>);

fn columns<const N: usize>(py: Python<'_>, rows: Rows<N>) -> PyResult<Columns> {
    let k = rows.len();
    let flat: Vec<i64> = rows.iter().flat_map(|r| r.0).map(|v| v as i64).collect();
    let idx = Array2::from_shape_vec((k, N), flat)
        .map_err(|e| value_error(format!("internal error: {e}")))?;
    let dist: Vec<f64> = rows.iter().map(|r| r.1).collect();
    let kind: Vec<u8> = rows.iter().map(|r| r.2).collect();
    Ok((
        idx.into_pyarray(py).unbind(),
        dist.into_pyarray(py).unbind(),
        kind.into_pyarray(py).unbind(),
    ))
}

/// The result of a proximity query: every vertex-face, face-vertex and edge-edge pair within
/// the distance, sorted, with squared distances and IPC's distance types (see the stub).
#[pyclass(module = "dhcd", frozen)]
struct Proximity {
    #[pyo3(get)]
    vertex_face: Py<PyArray2<i64>>,
    #[pyo3(get)]
    vf_distance_sq: Py<PyArray1<f64>>,
    #[pyo3(get)]
    vf_type: Py<PyArray1<u8>>,
    #[pyo3(get)]
    face_vertex: Py<PyArray2<i64>>,
    #[pyo3(get)]
    fv_distance_sq: Py<PyArray1<f64>>,
    #[pyo3(get)]
    fv_type: Py<PyArray1<u8>>,
    #[pyo3(get)]
    edge_edge: Py<PyArray2<i64>>,
    #[pyo3(get)]
    ee_distance_sq: Py<PyArray1<f64>>,
    #[pyo3(get)]
    ee_type: Py<PyArray1<u8>>,
    #[pyo3(get)]
    counters: Py<PyDict>,
}

impl Proximity {
    fn new<const V: usize, const E: usize>(
        py: Python<'_>,
        (vf, fv, ee, c): ProximityRows<V, E>,
    ) -> PyResult<Self> {
        let (vertex_face, vf_distance_sq, vf_type) = columns(py, vf)?;
        let (face_vertex, fv_distance_sq, fv_type) = columns(py, fv)?;
        let (edge_edge, ee_distance_sq, ee_type) = columns(py, ee)?;
        Ok(Self {
            vertex_face,
            vf_distance_sq,
            vf_type,
            face_vertex,
            fv_distance_sq,
            fv_type,
            edge_edge,
            ee_distance_sq,
            ee_type,
            counters: counters(py, c)?,
        })
    }

    fn counts(&self, py: Python<'_>) -> [usize; 3] {
        [&self.vertex_face, &self.face_vertex, &self.edge_edge].map(|a| a.bind(py).shape()[0])
    }
}

#[pymethods]
impl Proximity {
    /// The number of pairs of the three lists.
    fn __len__(&self, py: Python<'_>) -> usize {
        self.counts(py).iter().sum()
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let [vf, fv, ee] = self.counts(py);
        Ok(format!(
            "Proximity({vf} vertex-face, {fv} face-vertex, {ee} edge-edge pairs, counters={})",
            self.counters.bind(py).repr()?
        ))
    }
}

/// The bounding-volume hierarchy of one deformable triangle mesh.
#[pyclass(module = "dhcd")]
struct Hierarchy {
    h: AnyHierarchy,
    ws: Workspace,
}

#[pymethods]
impl Hierarchy {
    #[new]
    #[pyo3(signature = (vertices, faces, method = "dh", levels = None))]
    fn new(
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
        method: &str,
        levels: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let m = self::method(method)?;
        let options = self::options(levels)?;
        let v = Vertices::new(vertices)?;
        let f = self::faces(faces)?;
        let positions = v.positions()?;
        let h = py
            .detach(|| AnyHierarchy::new(m, &positions.mesh(f)?, options))
            .map_err(to_py)?;
        Ok(Self {
            h,
            ws: Workspace::default(),
        })
    }

    /// New vertex positions (same shape, the hierarchy's float type); the hierarchy is
    /// refitted (lazily), not rebuilt.
    fn update(&mut self, py: Python<'_>, vertices: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = Vertices::update(vertices, self.h.precision())?;
        let positions = v.positions()?;
        let h = &mut self.h;
        py.detach(|| match positions {
            Positions::F32(p) => h.update_positions(p),
            Positions::F64(p) => h.update_positions_f64(p),
        })
        .map(|_| ())
        .map_err(to_py)
    }

    /// Intersecting face pairs `[i, j]`, `i < j`, of this mesh, sharing no vertex.
    #[pyo3(signature = (threads = None), text_signature = "(self, threads=1)")]
    fn self_collide(
        &mut self,
        py: Python<'_>,
        threads: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Contacts> {
        let par = par(threads)?;
        let (h, ws) = (&mut self.h, &mut self.ws);
        let c = py.detach(|| h.self_collide(ws, par));
        Contacts::new(py, widen(c.pairs), c.counters)
    }

    #[getter]
    fn method(&self) -> &'static str {
        self.h.method().name()
    }

    /// `"f32"` or `"f64"`: the float type the hierarchy was built from and takes.
    #[getter]
    fn precision(&self) -> &'static str {
        self.h.precision().name()
    }

    #[getter]
    fn bytes_per_node(&self) -> usize {
        self.h.bytes_per_node()
    }

    /// The mesh's unique edges, `(E, 2)` int64 (smaller vertex first, sorted): the edge ids
    /// of `ContactSet.edges`.
    fn edges<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        contact::edges(py, self)
    }

    #[getter]
    fn vertex_count(&self) -> usize {
        self.h.tree().vertex_total()
    }

    #[getter]
    fn face_count(&self) -> usize {
        self.h.tree().triangle_total()
    }

    fn __repr__(&self) -> String {
        format!(
            "Hierarchy(method={:?}, precision={:?}, vertex_count={}, face_count={}, nodes={})",
            self.h.method().name(),
            self.h.precision().name(),
            self.h.tree().vertex_total(),
            self.h.tree().triangle_total(),
            self.h.node_count()
        )
    }
}

fn widen(pairs: Vec<[u32; 2]>) -> Vec<[u64; 2]> {
    pairs.into_iter().map(|p| p.map(u64::from)).collect()
}

/// Intersecting face pairs `[face of a, face of b]` between two hierarchies of one method.
#[pyfunction]
#[pyo3(signature = (a, b, threads = None), text_signature = "(a, b, threads=1)")]
fn collide(
    py: Python<'_>,
    a: &Bound<'_, Hierarchy>,
    b: &Bound<'_, Hierarchy>,
    threads: Option<&Bound<'_, PyAny>>,
) -> PyResult<Contacts> {
    let par = par(threads)?;
    if a.is(b) {
        return Err(value_error(
            "collide needs two different hierarchies (use a.self_collide() for one)".into(),
        ));
    }
    let (mut a, mut b) = (a.try_borrow_mut()?, b.try_borrow_mut()?);
    let (a, b) = (&mut *a, &mut *b);
    let c = py
        .detach(|| a.h.collide(&b.h, &mut a.ws, par))
        .map_err(to_py)?;
    Contacts::new(py, widen(c.pairs), c.counters)
}

/// The intersection segment of each pair, in the current poses: a `(K, 2, 3)` float32 array.
#[pyfunction]
fn contact_segments<'py>(
    py: Python<'py>,
    a: &Bound<'py, Hierarchy>,
    b: &Bound<'py, Hierarchy>,
    pairs: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let pairs = self::pairs(pairs)?;
    let (a, b) = (a.try_borrow()?, b.try_borrow()?);
    let (ha, hb) = (&a.h, &b.h);
    let segments = py
        .detach(|| ha.contact_segments(hb, &pairs))
        .map_err(to_py)?;
    let flat: Vec<f32> = segments.iter().flatten().flatten().copied().collect();
    let arr = Array3::from_shape_vec((segments.len(), 2, 3), flat)
        .map_err(|e| value_error(format!("internal error: {e}")))?;
    Ok(arr.into_pyarray(py))
}

/// Every vertex-face, face-vertex and edge-edge pair of `a` and `b` within distance `d`.
#[pyfunction]
#[pyo3(signature = (a, b, d, threads = None), text_signature = "(a, b, d, threads=1)")]
fn proximity(
    py: Python<'_>,
    a: &Bound<'_, Hierarchy>,
    b: &Bound<'_, Hierarchy>,
    d: &Bound<'_, PyAny>,
    threads: Option<&Bound<'_, PyAny>>,
) -> PyResult<Proximity> {
    let d = distance_arg(d)?;
    let par = par(threads)?;
    if a.is(b) {
        return Err(value_error(
            "proximity needs two different hierarchies (use self_proximity for one)".into(),
        ));
    }
    let (mut a, mut b) = (a.try_borrow_mut()?, b.try_borrow_mut()?);
    let (a, b) = (&mut *a, &mut *b);
    let rows = interrupt::run(py, par, |control| {
        a.ws.control = control.clone();
        Ok(proximity_rows(a.h.proximity(&b.h, d, &mut a.ws, par)?))
    })?;
    Proximity::new(py, rows)
}

/// Every vertex-face and edge-edge pair of one mesh within distance `d`.
#[pyfunction]
#[pyo3(signature = (h, d, threads = None), text_signature = "(h, d, threads=1)")]
fn self_proximity(
    py: Python<'_>,
    h: &Bound<'_, Hierarchy>,
    d: &Bound<'_, PyAny>,
    threads: Option<&Bound<'_, PyAny>>,
) -> PyResult<Proximity> {
    let d = distance_arg(d)?;
    let par = par(threads)?;
    let mut h = h.try_borrow_mut()?;
    let h = &mut *h;
    let rows = interrupt::run(py, par, |control| {
        h.ws.control = control.clone();
        Ok(proximity_rows(h.h.self_proximity(d, &mut h.ws, par)?))
    })?;
    Proximity::new(py, rows)
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

/// `numpy.asarray(obj)` checked to be a float64 array of shape `(n, *tail)`, as a
/// C-contiguous float64 array (the caller's when it already is one; a copy of the same
/// values when its byte order or strides differ). Any other dtype is an error naming
/// `what`, never a conversion.
fn float64_rows<'py>(
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
fn ccd_positions<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<PyReadonlyArray2<'py, f64>> {
    float64_rows(obj, what, &[3])?.extract()
}

/// A read-only float64 array as rows of `[f64; N]`.
fn rows_of<'a, const N: usize>(
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

/// The CCD query of the keyword arguments (checked by the library's query).
fn ccd_query(
    min_distance: Option<&Bound<'_, PyAny>>,
    t_max: Option<&Bound<'_, PyAny>>,
    earliest: bool,
) -> PyResult<CcdQuery> {
    Ok(CcdQuery {
        options: ccd_options(min_distance, t_max)?,
        mode: if earliest {
            CcdMode::Earliest
        } else {
            CcdMode::All
        },
    })
}

/// `min_distance` (default 0) and `t_max` (default 1) as options, unchecked.
fn ccd_options(
    min_distance: Option<&Bound<'_, PyAny>>,
    t_max: Option<&Bound<'_, PyAny>>,
) -> PyResult<CcdOptions> {
    let mut o = CcdOptions::default();
    if let Some(d) = min_distance {
        o.min_distance = real_arg(d, "min_distance")?;
    }
    if let Some(t) = t_max {
        o.t_max = real_arg(t, "t_max")?;
    }
    Ok(o)
}

/// The positional arguments of a query over a step: `(h, x0, x1)` for one mesh, or `(a, b,
/// a0, a1, b0, b1)` for two different hierarchies, each motion float64 `(n, 3)` at t = 0 and
/// t = 1; `call` names the query in messages.
enum StepArgs<'py> {
    One(Bound<'py, Hierarchy>, [PyReadonlyArray2<'py, f64>; 2]),
    Two([Bound<'py, Hierarchy>; 2], [PyReadonlyArray2<'py, f64>; 4]),
}

fn step_args<'py>(args: &Bound<'py, PyTuple>, call: &str) -> PyResult<StepArgs<'py>> {
    let hierarchy = |k: usize, what: &str| -> PyResult<Bound<'py, Hierarchy>> {
        let obj = args.get_item(k)?;
        obj.cast::<Hierarchy>().cloned().map_err(|_| {
            let kind = obj
                .get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default();
            PyTypeError::new_err(format!(
                "{call}: {what} must be a dhcd.Hierarchy, got {kind}"
            ))
        })
    };
    let positions = |k: usize, what: &str| ccd_positions(&args.get_item(k)?, what);
    match args.len() {
        3 => Ok(StepArgs::One(
            hierarchy(0, "h")?,
            [positions(1, "x0")?, positions(2, "x1")?],
        )),
        6 => {
            let (a, b) = (hierarchy(0, "a")?, hierarchy(1, "b")?);
            if a.is(&b) {
                return Err(value_error(format!(
                    "{call} needs two different hierarchies for a pair (use {call}(h, x0, x1) \
                     for one)"
                )));
            }
            Ok(StepArgs::Two(
                [a, b],
                [
                    positions(2, "a0")?,
                    positions(3, "a1")?,
                    positions(4, "b0")?,
                    positions(5, "b1")?,
                ],
            ))
        }
        n => Err(PyTypeError::new_err(format!(
            "{call} takes (h, x0, x1) or (a, b, a0, a1, b0, b1), got {n} positional arguments"
        ))),
    }
}

/// Continuous collision detection over a step: `ccd(h, x0, x1)` for one mesh,
/// `ccd(a, b, a0, a1, b0, b1)` for two.
#[pyfunction]
#[pyo3(
    signature = (*args, min_distance = None, earliest = false, t_max = None, threads = None),
    text_signature = "(h, x0, x1, *, min_distance=0.0, earliest=False, t_max=1.0, threads=1)"
)]
fn ccd(
    py: Python<'_>,
    args: &Bound<'_, PyTuple>,
    min_distance: Option<&Bound<'_, PyAny>>,
    earliest: bool,
    t_max: Option<&Bound<'_, PyAny>>,
    threads: Option<&Bound<'_, PyAny>>,
) -> PyResult<Impacts> {
    let q = ccd_query(min_distance, t_max, earliest)?;
    let par = par(threads)?;
    match step_args(args, "ccd")? {
        StepArgs::One(h, [x0, x1]) => {
            let m = Motion::new(rows_of(&x0, "x0")?, rows_of(&x1, "x1")?);
            let mut h = h.try_borrow_mut()?;
            let h = &mut *h;
            let r = interrupt::run(py, par, |control| {
                h.ws.control = control.clone();
                h.h.self_ccd(m, &q, &mut h.ws, par)
            })?;
            Impacts::new(py, r)
        }
        StepArgs::Two([a, b], x) => {
            let ma = Motion::new(rows_of(&x[0], "a0")?, rows_of(&x[1], "a1")?);
            let mb = Motion::new(rows_of(&x[2], "b0")?, rows_of(&x[3], "b1")?);
            let (mut a, mut b) = (a.try_borrow_mut()?, b.try_borrow_mut()?);
            let (a, b) = (&mut *a, &mut *b);
            let r = interrupt::run(py, par, |control| {
                a.ws.control = control.clone();
                a.h.ccd_pair(ma, &b.h, mb, &q, &mut a.ws, par)
            })?;
            Impacts::new(py, r)
        }
    }
}

/// The result of a CCD query: every vertex-face, face-vertex and edge-edge pair that
/// collides during the step, sorted, with its time of impact (see the stub).
#[pyclass(module = "dhcd", frozen)]
struct Impacts {
    #[pyo3(get)]
    vertex_face: Py<PyArray2<i64>>,
    #[pyo3(get)]
    vf_toi: Py<PyArray1<f64>>,
    #[pyo3(get)]
    face_vertex: Py<PyArray2<i64>>,
    #[pyo3(get)]
    fv_toi: Py<PyArray1<f64>>,
    #[pyo3(get)]
    edge_edge: Py<PyArray2<i64>>,
    #[pyo3(get)]
    ee_toi: Py<PyArray1<f64>>,
    /// The earliest time of impact, `inf` when nothing collides.
    #[pyo3(get)]
    toi: f64,
    #[pyo3(get)]
    counters: Py<PyDict>,
}

/// `(K, N)` int64 index rows and `(K,)` float64 times of impact.
type TimeColumns = (Py<PyArray2<i64>>, Py<PyArray1<f64>>);

/// Rows of `N` indices, each with its time of impact.
type TimeRows<const N: usize> = Vec<([u64; N], f64)>;

/// One list of a CCD result as numpy arrays.
fn toi_columns<const N: usize>(py: Python<'_>, rows: TimeRows<N>) -> PyResult<TimeColumns> {
    let k = rows.len();
    let flat: Vec<i64> = rows.iter().flat_map(|r| r.0).map(|v| v as i64).collect();
    let idx = Array2::from_shape_vec((k, N), flat)
        .map_err(|e| value_error(format!("internal error: {e}")))?;
    let toi: Vec<f64> = rows.iter().map(|r| r.1).collect();
    Ok((idx.into_pyarray(py).unbind(), toi.into_pyarray(py).unbind()))
}

/// The rows of one walk's impacts with object ids `[a, b]` in front of each side's indices
/// (`None`: a single mesh's query, no ids): vertex-face, face-vertex, edge-edge.
fn impact_rows<const V: usize, const E: usize>(
    r: &dhcd::Impacts,
    ids: Option<[u64; 2]>,
    (vf, fv, ee): &mut (TimeRows<V>, TimeRows<V>, TimeRows<E>),
) {
    let i = u64::from;
    let ids: Vec<u64> = ids.map(|x| x.to_vec()).unwrap_or_default();
    // `[a?, x, b?, y]`: the object ids (if any) before each side's indices.
    let row = |x: &[u64], y: &[u64]| -> Vec<u64> {
        let (a, b) = (ids.first(), ids.get(1));
        a.into_iter().chain(x).chain(b).chain(y).copied().collect()
    };
    let fixed = |r: Vec<u64>| -> [u64; V] { r.try_into().expect("row width") };
    vf.extend(
        r.vertex_face
            .iter()
            .map(|x| (fixed(row(&[i(x.vertex)], &[i(x.triangle)])), x.toi)),
    );
    fv.extend(
        r.face_vertex
            .iter()
            .map(|x| (fixed(row(&[i(x.triangle)], &[i(x.vertex)])), x.toi)),
    );
    ee.extend(r.edge_edge.iter().map(|x| {
        let r = row(&x.a.map(i), &x.b.map(i));
        (r.try_into().expect("row width"), x.toi)
    }));
}

impl Impacts {
    fn new(py: Python<'_>, r: dhcd::Impacts) -> PyResult<Self> {
        let mut rows: (TimeRows<2>, TimeRows<2>, TimeRows<4>) = Default::default();
        impact_rows(&r, None, &mut rows);
        Self::of_rows(py, rows, r.toi, r.counters)
    }

    /// A scene's result flattened with object ids (as [`scene_proximity_rows`]), each list
    /// sorted by its rows.
    fn of_scene(py: Python<'_>, r: dhcd::SceneImpacts) -> PyResult<Self> {
        let mut rows: (TimeRows<4>, TimeRows<4>, TimeRows<6>) = Default::default();
        for p in &r.per_pair {
            impact_rows(&p.impacts, Some([p.a.0, p.b.0]), &mut rows);
        }
        // Rows are unique (one per feature pair of one object pair): the order is total.
        rows.0.sort_unstable_by_key(|r| r.0);
        rows.1.sort_unstable_by_key(|r| r.0);
        rows.2.sort_unstable_by_key(|r| r.0);
        Self::of_rows(py, rows, r.toi, r.counters)
    }

    fn of_rows<const V: usize, const E: usize>(
        py: Python<'_>,
        (vf, fv, ee): (TimeRows<V>, TimeRows<V>, TimeRows<E>),
        toi: Option<f64>,
        c: Counters,
    ) -> PyResult<Self> {
        let (vertex_face, vf_toi) = toi_columns(py, vf)?;
        let (face_vertex, fv_toi) = toi_columns(py, fv)?;
        let (edge_edge, ee_toi) = toi_columns(py, ee)?;
        Ok(Self {
            vertex_face,
            vf_toi,
            face_vertex,
            fv_toi,
            edge_edge,
            ee_toi,
            toi: toi.unwrap_or(f64::INFINITY),
            counters: counters(py, c)?,
        })
    }

    fn counts(&self, py: Python<'_>) -> [usize; 3] {
        [&self.vertex_face, &self.face_vertex, &self.edge_edge].map(|a| a.bind(py).shape()[0])
    }
}

#[pymethods]
impl Impacts {
    /// The number of pairs of the three lists.
    fn __len__(&self, py: Python<'_>) -> usize {
        self.counts(py).iter().sum()
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let [vf, fv, ee] = self.counts(py);
        Ok(format!(
            "Impacts({vf} vertex-face, {fv} face-vertex, {ee} edge-edge pairs, toi={}, \
             counters={})",
            self.toi,
            self.counters.bind(py).repr()?
        ))
    }
}

/// `(hits, toi)` of a batch of single-pair CCD queries: `(N,)` bool and float64.
type Batch<'py> = (Bound<'py, PyArray1<bool>>, Bound<'py, PyArray1<f64>>);

/// One single-pair CCD test of the library, checked.
type CcdTest =
    fn(&[[f64; 3]; 4], &[[f64; 3]; 4], &CcdOptions, &dyn Fn() -> bool) -> dhcd::Result<Option<f64>>;

/// `(hits, toi)` of a batch of single-pair queries: `x0` and `x1` float64 `(N, 4, 3)`.
fn batch_ccd<'py>(
    py: Python<'py>,
    test: CcdTest,
    x0: &Bound<'py, PyAny>,
    x1: &Bound<'py, PyAny>,
    min_distance: Option<&Bound<'py, PyAny>>,
    t_max: Option<&Bound<'py, PyAny>>,
) -> PyResult<Batch<'py>> {
    let options = ccd_options(min_distance, t_max)?;
    options.validate().map_err(to_py)?;
    let a0: PyReadonlyArray3<'py, f64> = float64_rows(x0, "x0", &[4, 3])?.extract()?;
    let a1: PyReadonlyArray3<'py, f64> = float64_rows(x1, "x1", &[4, 3])?.extract()?;
    let (n0, n1) = (a0.shape()[0], a1.shape()[0]);
    if n0 != n1 {
        return Err(value_error(format!(
            "x0 and x1 must hold the same number of queries, got {n0} and {n1}"
        )));
    }
    let slice = |a: &'_ PyReadonlyArray3<'py, f64>, what: &str| -> PyResult<Vec<[[f64; 3]; 4]>> {
        let flat = a
            .as_slice()
            .map_err(|e| value_error(format!("{what}: {e}")))?;
        Ok(flat
            .chunks_exact(12)
            .map(|q| std::array::from_fn(|p| std::array::from_fn(|c| q[3 * p + c])))
            .collect())
    };
    let (q0, q1) = (slice(&a0, "x0")?, slice(&a1, "x1")?);
    let (hits, tois) = interrupt::batch(py, |stop| {
        let mut hits = Vec::with_capacity(q0.len());
        let mut tois = Vec::with_capacity(q0.len());
        for (k, (p0, p1)) in q0.iter().zip(&q1).enumerate() {
            let toi = test(p0, p1, &options, stop).map_err(|e| format!("query {k}: {e}"))?;
            hits.push(toi.is_some());
            tois.push(toi.unwrap_or(f64::INFINITY));
        }
        Ok((hits, tois))
    })?;
    Ok((hits.into_pyarray(py), tois.into_pyarray(py)))
}

/// Vertex-face CCD of a batch of single pairs: `x0`, `x1` float64 `(N, 4, 3)`, rows
/// `[v, f0, f1, f2]` at t = 0 and t = 1.
#[pyfunction]
#[pyo3(
    signature = (x0, x1, *, min_distance = None, t_max = None),
    text_signature = "(x0, x1, *, min_distance=0.0, t_max=1.0)"
)]
fn vertex_face_ccd<'py>(
    py: Python<'py>,
    x0: &Bound<'py, PyAny>,
    x1: &Bound<'py, PyAny>,
    min_distance: Option<&Bound<'py, PyAny>>,
    t_max: Option<&Bound<'py, PyAny>>,
) -> PyResult<Batch<'py>> {
    batch_ccd(
        py,
        dhcd::ccd::vertex_face_until,
        x0,
        x1,
        min_distance,
        t_max,
    )
}

/// Edge-edge CCD of a batch of single pairs: `x0`, `x1` float64 `(N, 4, 3)`, rows
/// `[a0, a1, b0, b1]` at t = 0 and t = 1.
#[pyfunction]
#[pyo3(
    signature = (x0, x1, *, min_distance = None, t_max = None),
    text_signature = "(x0, x1, *, min_distance=0.0, t_max=1.0)"
)]
fn edge_edge_ccd<'py>(
    py: Python<'py>,
    x0: &Bound<'py, PyAny>,
    x1: &Bound<'py, PyAny>,
    min_distance: Option<&Bound<'py, PyAny>>,
    t_max: Option<&Bound<'py, PyAny>>,
) -> PyResult<Batch<'py>> {
    batch_ccd(py, dhcd::ccd::edge_edge_until, x0, x1, min_distance, t_max)
}

/// Sets the most result pairs one query may return (`None`: no limit; default 2**25); a
/// query that would return more raises `ValueError` naming the count reached and the limit.
#[pyfunction]
#[pyo3(signature = (n))]
fn set_max_pairs(n: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
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
fn max_pairs() -> Option<u64> {
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
fn load_mesh<'py>(
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

/// Many deformable objects of one method; object ids are ints from 0 up, never reused.
#[pyclass(module = "dhcd")]
struct Scene {
    scene: dhcd::Scene,
    /// Names given to `add`, both ways; unique among the live objects.
    ids: HashMap<String, u64>,
    names: HashMap<u64, String>,
    /// The precision of every live object (the library's scene does not report it).
    precisions: HashMap<u64, Precision>,
}

impl Scene {
    /// An object given by id (int) or by the name it was added with (str).
    fn object(&self, id: &Bound<'_, PyAny>) -> PyResult<ObjectId> {
        if id.is_instance_of::<PyString>() {
            let name: String = id.extract()?;
            let name = name.as_str();
            return self
                .ids
                .get(name)
                .map(|&i| ObjectId(i))
                .ok_or_else(|| value_error(format!("no object named {name:?} in the scene")));
        }
        let i = int_arg(id, "object id")?;
        match u64::try_from(i).map(ObjectId) {
            Ok(o) if self.scene.contains(o) => Ok(o),
            _ => Err(value_error(format!("no object with id {i} in the scene"))),
        }
    }

    /// The precision of a live object.
    fn precision(&self, id: ObjectId) -> Precision {
        self.precisions.get(&id.0).copied().unwrap_or_default()
    }

    /// The entries of `update_many` or `step` (a mapping or an iterable of pairs): each
    /// object and its vertex array (in the object's precision), borrowed (alive, read-only)
    /// while the result lives.
    fn updates<'py>(
        &self,
        updates: &Bound<'py, PyAny>,
    ) -> PyResult<Vec<(ObjectId, Vertices<'py>)>> {
        let entries = match updates.cast::<PyMapping>() {
            Ok(m) => m.items()?.into_any(),
            Err(_) => updates.clone(),
        };
        let mut out = Vec::new();
        for (k, entry) in entries.try_iter()?.enumerate() {
            let (id, v) = update_pair(&entry?, k)?;
            let id = self.object(&id)?;
            out.push((id, Vertices::update(&v, self.precision(id))?));
        }
        Ok(out)
    }
}

/// One object's new positions.
type Update<'a> = (ObjectId, Positions<'a>);

/// One object's new `f32` positions, as the library's batch calls take them.
type Update32<'a> = (ObjectId, &'a [[f32; 3]]);

/// The entries of [`Scene::updates`] as positions.
fn as_updates<'a>(entries: &'a [(ObjectId, Vertices<'_>)]) -> PyResult<Vec<Update<'a>>> {
    entries
        .iter()
        .map(|(id, v)| Ok((*id, v.positions()?)))
        .collect()
}

/// `Scene::update_many` for entries of either precision (each already the precision of
/// its object): every entry is checked before any is applied, so on error nothing changes.
/// The library's batch update takes `f32` positions only; `f64` objects are then updated
/// one by one (each `Scene::update_positions_f64` is one object's update, already checked).
fn update_many(scene: &mut dhcd::Scene, updates: &[Update<'_>], par: Par) -> dhcd::Result<()> {
    if let Some(f32s) = as_f32(updates) {
        return scene.update_many(&f32s, par);
    }
    let f32s: Vec<Update32<'_>> = updates
        .iter()
        .filter_map(|&(id, p)| match p {
            Positions::F32(p) => Some((id, p)),
            Positions::F64(_) => None,
        })
        .collect();
    let mut seen = HashSet::new();
    for &(id, _) in updates {
        if !seen.insert(id) {
            return Err(Error::RepeatedObject(id.0));
        }
    }
    for &(id, p) in updates {
        let n = scene.tree(id)?.vertex_total();
        let of = dhcd::Positions::Update;
        match p {
            Positions::F32(p) => check_positions(p, n, of),
            Positions::F64(p) => check_positions_f64(p, n, of),
        }
        .map_err(|e| e.in_object(id.0))?;
    }
    scene.update_many(&f32s, par)?;
    for &(id, p) in updates {
        if let Positions::F64(p) = p {
            scene.update_positions_f64(id, p)?;
        }
    }
    Ok(())
}

/// The entries as the library's batch calls take them, if all are `f32`.
fn as_f32<'a>(updates: &[Update<'a>]) -> Option<Vec<Update32<'a>>> {
    updates
        .iter()
        .map(|&(id, p)| match p {
            Positions::F32(p) => Some((id, p)),
            Positions::F64(_) => None,
        })
        .collect()
}

/// Entry `k` of `Scene.update_many` or `Scene.step`: an `(id or name, vertices)` tuple or list.
fn update_pair<'py>(
    entry: &Bound<'py, PyAny>,
    k: usize,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    two_items(entry, &format!("update {k} must be an (id, vertices) pair"))
}

/// The two items of a tuple or list (`must`: what it must be, for the errors).
fn two_items<'py>(
    entry: &Bound<'py, PyAny>,
    must: &str,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let items = if let Ok(t) = entry.cast::<PyTuple>() {
        t.as_sequence().clone()
    } else if let Ok(l) = entry.cast::<PyList>() {
        l.as_sequence().clone()
    } else {
        let kind = entry.get_type().name()?;
        return Err(PyTypeError::new_err(format!("{must}, got {kind}")));
    };
    if items.len()? != 2 {
        return Err(value_error(format!("{must}, got {} items", items.len()?)));
    }
    Ok((items.get_item(0)?, items.get_item(1)?))
}

#[pymethods]
impl Scene {
    #[new]
    #[pyo3(signature = (method = "dh", levels = None))]
    fn new(method: &str, levels: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        Ok(Self {
            scene: dhcd::Scene::new(self::method(method)?, options(levels)?),
            ids: HashMap::new(),
            names: HashMap::new(),
            precisions: HashMap::new(),
        })
    }

    /// Adds an object (self-collision off; float64 vertices make an `f64` object); returns
    /// its id.
    #[pyo3(signature = (vertices, faces, name = None))]
    fn add(
        &mut self,
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
        name: Option<String>,
    ) -> PyResult<u64> {
        if let Some(n) = &name {
            if self.ids.contains_key(n) {
                return Err(value_error(format!("an object is already named {n:?}")));
            }
        }
        let v = Vertices::new(vertices)?;
        let f = self::faces(faces)?;
        let positions = v.positions()?;
        let scene = &mut self.scene;
        let (id, precision) = py
            .detach(|| {
                let mesh = positions.mesh(f)?;
                Ok((scene.add(&mesh)?, mesh.precision()))
            })
            .map_err(to_py)?;
        self.precisions.insert(id.0, precision);
        if let Some(n) = name {
            self.ids.insert(n.clone(), id.0);
            self.names.insert(id.0, n);
        }
        Ok(id.0)
    }

    /// New vertex positions of an object (by id or name).
    fn update(
        &mut self,
        py: Python<'_>,
        id: &Bound<'_, PyAny>,
        vertices: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let id = self.object(id)?;
        let v = Vertices::update(vertices, self.precision(id))?;
        let positions = v.positions()?;
        let scene = &mut self.scene;
        py.detach(|| match positions {
            Positions::F32(p) => scene.update_positions(id, p),
            Positions::F64(p) => scene.update_positions_f64(id, p),
        })
        .map_err(to_py)
    }

    /// New vertex positions of several objects at once: `updates` a mapping
    /// `{id or name: vertices}` or an iterable of `(id or name, vertices)` pairs.
    #[pyo3(
        signature = (updates, threads = None),
        text_signature = "(self, updates, threads=1)"
    )]
    fn update_many(
        &mut self,
        py: Python<'_>,
        updates: &Bound<'_, PyAny>,
        threads: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let par = par(threads)?;
        let entries = self.updates(updates)?;
        let updates = as_updates(&entries)?;
        let scene = &mut self.scene;
        py.detach(|| update_many(scene, &updates, par))
            .map_err(to_py)
    }

    /// One simulation step: `update_many(updates)` then `contacts()`, in one trip to the
    /// thread pool (cheaper than the two calls with several threads). On error no object
    /// moves.
    #[pyo3(
        signature = (updates, threads = None),
        text_signature = "(self, updates, threads=1)"
    )]
    fn step(
        &mut self,
        py: Python<'_>,
        updates: &Bound<'_, PyAny>,
        threads: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Contacts> {
        let par = par(threads)?;
        let entries = self.updates(updates)?;
        let updates = as_updates(&entries)?;
        let scene = &mut self.scene;
        let c = py
            .detach(|| match as_f32(&updates) {
                // All f32: the library's step, in one trip to the thread pool.
                Some(f32s) => scene.step(&f32s, par),
                None => {
                    update_many(scene, &updates, par)?;
                    Ok(scene.contacts(par))
                }
            })
            .map_err(to_py)?;
        Contacts::new(py, c.pairs, c.counters)
    }

    /// Removes an object (by id or name); its id is never handed out again.
    fn remove(&mut self, id: &Bound<'_, PyAny>) -> PyResult<()> {
        let id = self.object(id)?;
        self.scene.remove(id).map_err(to_py)?;
        self.precisions.remove(&id.0);
        if let Some(n) = self.names.remove(&id.0) {
            self.ids.remove(&n);
        }
        Ok(())
    }

    /// Reports (or stops reporting) an object's self-contacts in `contacts`.
    fn set_self_collision(&mut self, id: &Bound<'_, PyAny>, on: bool) -> PyResult<()> {
        let id = self.object(id)?;
        self.scene.set_self_collision(id, on).map_err(to_py)
    }

    /// Every contact: rows `[object_a, face_a, object_b, face_b]`, sorted.
    #[pyo3(signature = (threads = None), text_signature = "(self, threads=1)")]
    fn contacts(
        &mut self,
        py: Python<'_>,
        threads: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Contacts> {
        let par = par(threads)?;
        let scene = &mut self.scene;
        let c = py.detach(|| scene.contacts(par));
        Contacts::new(py, c.pairs, c.counters)
    }

    /// Every vertex-face, face-vertex and edge-edge pair within distance `d` between two
    /// objects and inside objects with self-collision on, rows with object ids, sorted.
    #[pyo3(signature = (d, threads = None), text_signature = "(self, d, threads=1)")]
    fn proximity(
        &mut self,
        py: Python<'_>,
        d: &Bound<'_, PyAny>,
        threads: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Proximity> {
        let d = distance_arg(d)?;
        let par = par(threads)?;
        let scene = &mut self.scene;
        let rows = interrupt::run(py, par, |control| {
            scene.set_control(control.clone());
            Ok(scene_proximity_rows(scene.proximity(d, par)?))
        })?;
        Proximity::new(py, rows)
    }

    /// Every pair of features within `dhat` between objects and inside objects with
    /// self-collision on, once (a `ContactSet`), in one global numbering: each object's
    /// vertices and edges after those of the objects added before it (`vertex_offset`,
    /// `edge_offset`).
    #[pyo3(signature = (dhat, threads = None), text_signature = "(self, dhat, threads=1)")]
    fn contact_set(
        &mut self,
        py: Python<'_>,
        dhat: &Bound<'_, PyAny>,
        threads: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<contact::ContactSet> {
        let dhat = distance_arg(dhat)?;
        let par = par(threads)?;
        let scene = &mut self.scene;
        let set = interrupt::run(py, par, |control| {
            scene.set_control(control.clone());
            scene.contact_set(dhat, par)
        })?;
        contact::ContactSet::new(py, set)
    }

    /// Where object `id`'s vertices start in the global numbering of `contact_set`.
    fn vertex_offset(&self, id: &Bound<'_, PyAny>) -> PyResult<u64> {
        let id = self.object(id)?;
        self.scene.vertex_offset(id).map_err(to_py)
    }

    /// Where object `id`'s edge ids start in the global numbering of `contact_set`.
    fn edge_offset(&self, id: &Bound<'_, PyAny>) -> PyResult<u64> {
        let id = self.object(id)?;
        self.scene.edge_offset(id).map_err(to_py)
    }

    /// Continuous collision detection of the whole scene over one step: `motions` maps
    /// objects to `(x0, x1)` (float64 `(n, 3)` each); the other objects stay still.
    #[pyo3(
        signature = (motions, *, min_distance = None, earliest = false, t_max = None, threads = None),
        text_signature = "(self, motions, *, min_distance=0.0, earliest=False, t_max=1.0, threads=1)"
    )]
    fn ccd(
        &mut self,
        py: Python<'_>,
        motions: &Bound<'_, PyAny>,
        min_distance: Option<&Bound<'_, PyAny>>,
        earliest: bool,
        t_max: Option<&Bound<'_, PyAny>>,
        threads: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Impacts> {
        let q = ccd_query(min_distance, t_max, earliest)?;
        let par = par(threads)?;
        let entries = match motions.cast::<PyMapping>() {
            Ok(m) => m.items()?.into_any(),
            Err(_) => motions.clone(),
        };
        let mut arrays = Vec::new();
        for (k, entry) in entries.try_iter()?.enumerate() {
            let (id, m) = two_items(
                &entry?,
                &format!("motion {k} must be an (id, (x0, x1)) pair"),
            )?;
            let (x0, x1) = two_items(&m, &format!("motion {k} must be an (x0, x1) pair"))?;
            let id = self.object(&id)?;
            arrays.push((id, ccd_positions(&x0, "x0")?, ccd_positions(&x1, "x1")?));
        }
        let motions: Vec<(ObjectId, Motion<'_>)> = arrays
            .iter()
            .map(|(id, x0, x1)| Ok((*id, Motion::new(rows_of(x0, "x0")?, rows_of(x1, "x1")?))))
            .collect::<PyResult<_>>()?;
        let scene = &mut self.scene;
        let r = interrupt::run(py, par, |control| {
            scene.set_control(control.clone());
            scene.ccd(&motions, &q, par)
        })?;
        Impacts::of_scene(py, r)
    }

    fn __len__(&self) -> usize {
        self.scene.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene(method={:?}, objects={})",
            self.scene.method().name(),
            self.scene.len()
        )
    }
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

/// Collision detection between deformable triangle meshes (Distance Hierarchy, sphere and
/// AABB hierarchies, exact contacts); the native part of the `dhcd` package.
#[pymodule(name = "_dhcd")]
mod dhcd_native {
    #[pymodule_export]
    use super::contact::{
        contact_set, distance_gradient, distance_hessian, distance_sq, self_contact_set, ContactSet,
    };
    #[pymodule_export]
    use super::step::collision_free_stepsize;
    #[pymodule_export]
    use super::{
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
