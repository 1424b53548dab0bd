//! Feature pairs within a distance: the `Proximity` result, built from columns (the one
//! conversion of each of the library's results: [`proximity_columns`] for a pair or one
//! mesh, [`scene_proximity_columns`] for a scene, both made with the GIL released),
//! `proximity` and `self_proximity`.

use dhcd::Counters;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::hierarchy::Hierarchy;
use crate::{counters, distance_arg, interrupt, par, value_error};

/// One list of a proximity result, column by column: `N` indices a row (flat, row-major),
/// the squared distances and the distance types. Built without the GIL; handed to numpy
/// without a copy ([`Columns::into_numpy`]).
pub(crate) struct Columns<const N: usize> {
    indices: Vec<i64>,
    distance_sq: Vec<f64>,
    kind: Vec<u8>,
}

impl<const N: usize> Columns<N> {
    /// The columns of `rows` (indices, squared distance, type), in their order.
    fn of(rows: impl ExactSizeIterator<Item = ([i64; N], f64, u8)>) -> Self {
        let k = rows.len();
        let mut c = Self {
            indices: Vec::with_capacity(N * k),
            distance_sq: Vec::with_capacity(k),
            kind: Vec::with_capacity(k),
        };
        for (row, d2, kind) in rows {
            c.indices.extend_from_slice(&row);
            c.distance_sq.push(d2);
            c.kind.push(kind);
        }
        c
    }

    /// As numpy arrays: `(K, N)` int64 rows, `(K,)` float64 squared distances, `(K,)` uint8
    /// types.
    fn into_numpy(self, py: Python<'_>) -> PyResult<NumpyColumns> {
        let k = self.distance_sq.len();
        let idx = Array2::from_shape_vec((k, N), self.indices)
            .map_err(|e| value_error(format!("internal error: {e}")))?;
        Ok((
            idx.into_pyarray(py).unbind(),
            self.distance_sq.into_pyarray(py).unbind(),
            self.kind.into_pyarray(py).unbind(),
        ))
    }
}

/// The three lists of a proximity result, as columns: vertex-face, face-vertex, edge-edge.
pub(crate) type ProximityColumns<const V: usize, const E: usize> =
    (Columns<V>, Columns<V>, Columns<E>, Counters);

/// An original index as numpy's index type.
fn id(v: u32) -> i64 {
    i64::from(v)
}

/// A pair query's result as columns (already sorted by the library).
// PERF: one pass from the library's rows to the columns; through tuples of `u64` rows
// first, the conversion of cloth-ball's 419,335 pairs took 15 ms of the call's 141 ms.
fn proximity_columns(p: dhcd::Proximity) -> ProximityColumns<2, 4> {
    (
        Columns::of(
            p.vertex_face
                .iter()
                .map(|x| ([id(x.vertex), id(x.triangle)], x.distance_sq, x.kind as u8)),
        ),
        Columns::of(
            p.face_vertex
                .iter()
                .map(|x| ([id(x.triangle), id(x.vertex)], x.distance_sq, x.kind as u8)),
        ),
        Columns::of(p.edge_edge.iter().map(|x| {
            let row = [id(x.a[0]), id(x.a[1]), id(x.b[0]), id(x.b[1])];
            (row, x.distance_sq, x.kind as u8)
        })),
        p.counters,
    )
}

/// A scene's result flattened with object ids (as the C ABI's `DhcdSceneProximity`), each
/// list sorted by its rows.
pub(crate) fn scene_proximity_columns(p: dhcd::SceneProximity) -> ProximityColumns<4, 6> {
    let (mut vf, mut fv, mut ee) = (Vec::new(), Vec::new(), Vec::new());
    for pair in &p.per_pair {
        let (a, b, q) = (pair.a.0 as i64, pair.b.0 as i64, &pair.proximity);
        vf.extend(q.vertex_face.iter().map(|x| {
            (
                [a, id(x.vertex), b, id(x.triangle)],
                x.distance_sq,
                x.kind as u8,
            )
        }));
        fv.extend(q.face_vertex.iter().map(|x| {
            (
                [a, id(x.triangle), b, id(x.vertex)],
                x.distance_sq,
                x.kind as u8,
            )
        }));
        ee.extend(q.edge_edge.iter().map(|x| {
            let row = [a, id(x.a[0]), id(x.a[1]), b, id(x.b[0]), id(x.b[1])];
            (row, x.distance_sq, x.kind as u8)
        }));
    }
    // Rows are unique (one per feature pair of one object pair): the order is total.
    vf.sort_unstable_by_key(|r| r.0);
    fv.sort_unstable_by_key(|r| r.0);
    ee.sort_unstable_by_key(|r| r.0);
    (
        Columns::of(vf.into_iter()),
        Columns::of(fv.into_iter()),
        Columns::of(ee.into_iter()),
        p.counters,
    )
}

/// One list of a proximity result as numpy arrays (see [`Columns::into_numpy`]).
type NumpyColumns = (Py<PyArray2<i64>>, Py<PyArray1<f64>>, Py<PyArray1<u8>>);

/// The result of a proximity query: every vertex-face, face-vertex and edge-edge pair within
/// the distance, sorted, with squared distances and IPC's distance types (see the stub).
#[pyclass(module = "dhcd", frozen)]
pub(crate) struct Proximity {
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
    pub(crate) fn new<const V: usize, const E: usize>(
        py: Python<'_>,
        (vf, fv, ee, c): ProximityColumns<V, E>,
    ) -> PyResult<Self> {
        let (vertex_face, vf_distance_sq, vf_type) = vf.into_numpy(py)?;
        let (face_vertex, fv_distance_sq, fv_type) = fv.into_numpy(py)?;
        let (edge_edge, ee_distance_sq, ee_type) = ee.into_numpy(py)?;
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

/// Every vertex-face, face-vertex and edge-edge pair of `a` and `b` within distance `d`.
#[pyfunction]
#[pyo3(signature = (a, b, d, threads = None), text_signature = "(a, b, d, threads=1)")]
pub(crate) fn proximity(
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
        Ok(proximity_columns(a.h.proximity(&b.h, d, &mut a.ws, par)?))
    })?;
    Proximity::new(py, rows)
}

/// Every vertex-face and edge-edge pair of one mesh within distance `d`.
#[pyfunction]
#[pyo3(signature = (h, d, threads = None), text_signature = "(h, d, threads=1)")]
pub(crate) fn self_proximity(
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
        Ok(proximity_columns(h.h.self_proximity(d, &mut h.ws, par)?))
    })?;
    Proximity::new(py, rows)
}
