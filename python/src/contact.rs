//! The contact set and the geometry of contacts: `self_contact_set`, `contact_set`, the
//! `ContactSet` result (numpy columns, derivatives on demand), `Hierarchy.edges()`, and the
//! batched per-type functions `distance_sq`, `distance_gradient`, `distance_hessian`.

use dhcd::contact::{ContactType, NONE};
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::{array_of_numbers, float64_rows, numeric_n3, REAL};
use crate::hierarchy::Hierarchy;
use crate::{counters, distance_arg, interrupt, par, to_py, value_error};

/// Every pair of features within `dhat`, once, with the IPC Toolkit's collision type (see
/// the stub for the columns).
#[pyclass(module = "dhcd", frozen)]
pub(crate) struct ContactSet {
    set: dhcd::ContactSet,
    #[pyo3(get)]
    vertices: Py<PyArray2<i64>>,
    #[pyo3(get, name = "type")]
    kind: Py<PyArray1<u8>>,
    #[pyo3(get)]
    distance_sq: Py<PyArray1<f64>>,
    #[pyo3(get)]
    weights: Py<PyArray2<f64>>,
    #[pyo3(get)]
    mollified: Py<PyArray1<bool>>,
    #[pyo3(get)]
    edges: Py<PyArray2<i64>>,
    #[pyo3(get)]
    counters: Py<PyDict>,
}

/// `u32` ids with [`NONE`] as `-1`.
fn ids(v: u32) -> i64 {
    if v == NONE {
        -1
    } else {
        i64::from(v)
    }
}

fn table<T: numpy::Element, const N: usize>(
    py: Python<'_>,
    rows: impl ExactSizeIterator<Item = [T; N]>,
) -> PyResult<Py<PyArray2<T>>> {
    let k = rows.len();
    let flat: Vec<T> = rows.flatten().collect();
    let a = Array2::from_shape_vec((k, N), flat)
        .map_err(|e| value_error(format!("internal error: {e}")))?;
    Ok(a.into_pyarray(py).unbind())
}

impl ContactSet {
    pub(crate) fn new(py: Python<'_>, set: dhcd::ContactSet) -> PyResult<Self> {
        let c = &set.contacts;
        Ok(Self {
            vertices: table(py, c.iter().map(|c| c.vertices.map(ids)))?,
            kind: c
                .iter()
                .map(|c| c.kind as u8)
                .collect::<Vec<_>>()
                .into_pyarray(py)
                .unbind(),
            distance_sq: c
                .iter()
                .map(|c| c.distance_sq)
                .collect::<Vec<_>>()
                .into_pyarray(py)
                .unbind(),
            weights: table(py, c.iter().map(|c| c.weights))?,
            mollified: c
                .iter()
                .map(|c| c.mollified)
                .collect::<Vec<_>>()
                .into_pyarray(py)
                .unbind(),
            edges: table(py, c.iter().map(|c| c.edges.map(ids)))?,
            counters: counters(py, set.counters)?,
            set,
        })
    }
}

#[pymethods]
impl ContactSet {
    fn __len__(&self) -> usize {
        self.set.len()
    }

    fn __repr__(&self) -> String {
        let mut n = [0usize; 4];
        for c in &self.set.contacts {
            n[c.kind as usize] += 1;
        }
        let mollified = self.set.contacts.iter().filter(|c| c.mollified).count();
        format!(
            "ContactSet({} contacts: {} PP, {} PE, {} PT, {} EE of which {mollified} mollified)",
            self.set.len(),
            n[0],
            n[1],
            n[2],
            n[3]
        )
    }

    /// `(K, 12)` float64: the gradient of each row's squared distance with respect to its
    /// four vertices' coordinates (zero in unused slots).
    fn gradient<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let g = py.detach(|| self.set.gradients());
        Ok(table(py, g.into_iter())?.into_bound(py))
    }

    /// `(K, 12, 12)` float64: the Hessian of each row's squared distance.
    fn hessian<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let h = py.detach(|| self.set.hessians());
        hessians(py, h)
    }
}

fn hessians(py: Python<'_>, h: Vec<[[f64; 12]; 12]>) -> PyResult<Bound<'_, PyArray3<f64>>> {
    let k = h.len();
    let flat: Vec<f64> = h.into_iter().flatten().flatten().collect();
    let a = Array3::from_shape_vec((k, 12, 12), flat)
        .map_err(|e| value_error(format!("internal error: {e}")))?;
    Ok(a.into_pyarray(py))
}

/// A rest-position argument: `None`, or a real `(n, 3)` array (converted to float64).
fn rest_arg(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Vec<[f64; 3]>>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let arr = numeric_n3(obj, "rest", REAL)?;
    let np = obj.py().import("numpy")?;
    let a: numpy::PyReadonlyArray2<'_, f64> = np
        .call_method1("ascontiguousarray", (arr, "float64"))?
        .extract()?;
    let flat = a
        .as_slice()
        .map_err(|e| value_error(format!("rest: {e}")))?;
    Ok(Some(
        flat.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect(),
    ))
}

/// Every pair of features of one mesh within `dhat`, once (see `ContactSet`).
#[pyfunction]
#[pyo3(
    signature = (h, dhat, rest = None, threads = None),
    text_signature = "(h, dhat, rest=None, threads=1)"
)]
pub(crate) fn self_contact_set(
    py: Python<'_>,
    h: &Bound<'_, Hierarchy>,
    dhat: &Bound<'_, PyAny>,
    rest: Option<&Bound<'_, PyAny>>,
    threads: Option<&Bound<'_, PyAny>>,
) -> PyResult<ContactSet> {
    let dhat = distance_arg(dhat)?;
    let rest = rest_arg(rest)?;
    let par = par(threads)?;
    let mut h = h.try_borrow_mut()?;
    let h = &mut *h;
    let set = interrupt::run(py, par, |control| {
        h.ws.control = control.clone();
        h.h.self_contact_set(dhat, rest.as_deref(), &mut h.ws, par)
    })?;
    ContactSet::new(py, set)
}

/// Every pair of features of `a` and `b` within `dhat`, once; vertices numbered `a`'s first,
/// then `b`'s (offset by `a.vertex_count()`), edges likewise.
#[pyfunction]
#[pyo3(
    signature = (a, b, dhat, rest_a = None, rest_b = None, threads = None),
    text_signature = "(a, b, dhat, rest_a=None, rest_b=None, threads=1)"
)]
pub(crate) fn contact_set(
    py: Python<'_>,
    a: &Bound<'_, Hierarchy>,
    b: &Bound<'_, Hierarchy>,
    dhat: &Bound<'_, PyAny>,
    rest_a: Option<&Bound<'_, PyAny>>,
    rest_b: Option<&Bound<'_, PyAny>>,
    threads: Option<&Bound<'_, PyAny>>,
) -> PyResult<ContactSet> {
    let dhat = distance_arg(dhat)?;
    let (rest_a, rest_b) = (rest_arg(rest_a)?, rest_arg(rest_b)?);
    let par = par(threads)?;
    if a.is(b) {
        return Err(value_error(
            "contact_set needs two different hierarchies (use self_contact_set for one)".into(),
        ));
    }
    let (mut a, b) = (a.try_borrow_mut()?, b.try_borrow()?);
    let (a, b) = (&mut *a, &*b);
    let set = interrupt::run(py, par, |control| {
        a.ws.control = control.clone();
        a.h.contact_set(
            &b.h,
            dhat,
            [rest_a.as_deref(), rest_b.as_deref()],
            &mut a.ws,
            par,
        )
    })?;
    ContactSet::new(py, set)
}

/// A batch of rows: the types and each row's four vertex slots.
type Batch = (Vec<ContactType>, Vec<[[f64; 3]; 4]>);

/// The types and positions of a batch: `types` `(K,)` integers 0..=3, `x` float64
/// `(K, 4, 3)`.
fn batch_args(types: &Bound<'_, PyAny>, x: &Bound<'_, PyAny>) -> PyResult<Batch> {
    let np = types.py().import("numpy")?;
    let t = array_of_numbers(types, "types")?;
    let t: Vec<i64> = np
        .call_method1("ascontiguousarray", (t, "int64"))?
        .call_method0("ravel")?
        .extract()?;
    let types = t
        .iter()
        .map(|&c| {
            u8::try_from(c)
                .map_err(|_| dhcd::Error::UnknownContactType(u8::MAX))
                .and_then(ContactType::from_code)
                .map_err(|_| {
                    value_error(format!(
                        "unknown contact type {c} (expected 0 point-point, 1 point-edge, 2 \
                         point-triangle or 3 edge-edge)"
                    ))
                })
        })
        .collect::<PyResult<Vec<_>>>()?;
    let a: PyReadonlyArray3<'_, f64> = float64_rows(x, "x", &[4, 3])?.extract()?;
    if a.shape()[0] != types.len() {
        return Err(value_error(format!(
            "types has {} rows but x has {}",
            types.len(),
            a.shape()[0]
        )));
    }
    let flat = a.as_slice().map_err(|e| value_error(format!("x: {e}")))?;
    let x = flat
        .chunks_exact(12)
        .map(|q| std::array::from_fn(|p| std::array::from_fn(|c| q[3 * p + c])))
        .collect();
    Ok((types, x))
}

/// `(K,)` float64: the squared distance of each row's type (0 PP, 1 PE, 2 PT, 3 EE) at
/// `x` `(K, 4, 3)`.
#[pyfunction]
pub(crate) fn distance_sq<'py>(
    py: Python<'py>,
    types: &Bound<'py, PyAny>,
    x: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (t, x) = batch_args(types, x)?;
    let d = dhcd::contact::distance_sq(&t, &x).map_err(to_py)?;
    Ok(d.into_pyarray(py))
}

/// `(K, 12)` float64: the gradient of each row's squared distance.
#[pyfunction]
pub(crate) fn distance_gradient<'py>(
    py: Python<'py>,
    types: &Bound<'py, PyAny>,
    x: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (t, x) = batch_args(types, x)?;
    let g = dhcd::contact::distance_gradient(&t, &x).map_err(to_py)?;
    Ok(table(py, g.into_iter())?.into_bound(py))
}

/// `(K, 12, 12)` float64: the Hessian of each row's squared distance.
#[pyfunction]
pub(crate) fn distance_hessian<'py>(
    py: Python<'py>,
    types: &Bound<'py, PyAny>,
    x: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (t, x) = batch_args(types, x)?;
    let h = py
        .detach(|| dhcd::contact::distance_hessian(&t, &x))
        .map_err(to_py)?;
    hessians(py, h)
}

/// The mesh's unique edges as an `(E, 2)` int64 array (smaller vertex first, sorted): the
/// edge ids of `ContactSet.edges`.
pub(crate) fn edges<'py>(py: Python<'py>, h: &Hierarchy) -> PyResult<Bound<'py, PyArray2<i64>>> {
    let e = h.h.tree().edges();
    Ok(table(py, e.iter().map(|e| e.map(i64::from)))?.into_bound(py))
}
