//! Feature pairs within a distance: the `Proximity` result, built from rows (the one
//! conversion of each of the library's results: [`proximity_rows`] for a pair or one mesh,
//! [`scene_proximity_rows`] for a scene, both made with the GIL released), `proximity` and
//! `self_proximity`.

use dhcd::Counters;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::hierarchy::Hierarchy;
use crate::{counters, distance_arg, interrupt, par, value_error};

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
pub(crate) fn scene_proximity_rows(p: dhcd::SceneProximity) -> ProximityRows<4, 6> {
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
        Ok(proximity_rows(a.h.proximity(&b.h, d, &mut a.ws, par)?))
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
        Ok(proximity_rows(h.h.self_proximity(d, &mut h.ws, par)?))
    })?;
    Proximity::new(py, rows)
}
