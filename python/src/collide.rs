//! Intersecting face pairs: the `Contacts` result (its one conversion from each of the
//! library's results: `Contacts::new` for a pair or one mesh, `Contacts::of_scene`),
//! `collide`, `Hierarchy.self_collide` and `contact_segments`.

use dhcd::Counters;
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray2, PyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::pairs;
use crate::hierarchy::Hierarchy;
use crate::{counters, par, to_py, value_error};

/// The result of a query: `.pairs` (a sorted `(K, 2)` or `(K, 4)` int64 array) and
/// `.counters` (a dict: `bv_tests`, `prim_tests`, `bv_updates`, `contacts`).
#[pyclass(module = "dhcd", frozen)]
pub(crate) struct Contacts {
    #[pyo3(get)]
    pairs: Py<PyArray2<i64>>,
    #[pyo3(get)]
    counters: Py<PyDict>,
}

impl Contacts {
    /// A pair's or one mesh's contacts: rows `[face of a, face of b]` (`[i, j]` for one mesh).
    fn new(py: Python<'_>, c: dhcd::Contacts) -> PyResult<Self> {
        Self::of_rows(py, widen(c.pairs), c.counters)
    }

    /// A scene's contacts: rows `[object_a, face_a, object_b, face_b]`.
    pub(crate) fn of_scene(py: Python<'_>, c: dhcd::SceneContacts) -> PyResult<Self> {
        Self::of_rows(py, c.pairs, c.counters)
    }

    /// The result of its rows (sorted by the library) and counters.
    fn of_rows<const N: usize>(py: Python<'_>, rows: Vec<[u64; N]>, c: Counters) -> PyResult<Self> {
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

fn widen(pairs: Vec<[u32; 2]>) -> Vec<[u64; 2]> {
    pairs.into_iter().map(|p| p.map(u64::from)).collect()
}

/// `Hierarchy.self_collide`: intersecting face pairs `[i, j]`, `i < j`, of one mesh, sharing
/// no vertex.
pub(crate) fn self_collide(
    py: Python<'_>,
    h: &mut Hierarchy,
    threads: Option<&Bound<'_, PyAny>>,
) -> PyResult<Contacts> {
    let par = par(threads)?;
    let (h, ws) = (&mut h.h, &mut h.ws);
    let c = py.detach(|| h.self_collide(ws, par));
    Contacts::new(py, c)
}

/// Intersecting face pairs `[face of a, face of b]` between two hierarchies of one method.
#[pyfunction]
#[pyo3(signature = (a, b, threads = None), text_signature = "(a, b, threads=1)")]
pub(crate) fn collide(
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
    Contacts::new(py, c)
}

/// The intersection segment of each pair, in the current poses: a `(K, 2, 3)` float32 array.
#[pyfunction]
pub(crate) fn contact_segments<'py>(
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
