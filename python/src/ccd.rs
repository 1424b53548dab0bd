//! Continuous collision detection over a step: the `Impacts` result (its one conversion from
//! each of the library's results: `Impacts::new`, `Impacts::of_scene`), `ccd`, the parser of
//! a step query's positional arguments ([`step_args`], shared with `collision_free_stepsize`),
//! the CCD query of the keyword arguments, and the batched single-pair `vertex_face_ccd` and
//! `edge_edge_ccd`.

use dhcd::ccd::CcdOptions;
use dhcd::{CcdMode, CcdQuery, Counters, Motion};
use numpy::ndarray::Array2;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::arrays::{ccd_positions, float64_rows, rows_of};
use crate::hierarchy::Hierarchy;
use crate::{counters, interrupt, par, real_arg, to_py, value_error};

/// The CCD query of the keyword arguments (checked by the library's query).
pub(crate) fn ccd_query(
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
pub(crate) enum StepArgs<'py> {
    One(Bound<'py, Hierarchy>, [PyReadonlyArray2<'py, f64>; 2]),
    Two([Bound<'py, Hierarchy>; 2], [PyReadonlyArray2<'py, f64>; 4]),
}

pub(crate) fn step_args<'py>(args: &Bound<'py, PyTuple>, call: &str) -> PyResult<StepArgs<'py>> {
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
pub(crate) fn ccd(
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
pub(crate) struct Impacts {
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

/// A row of `N` indices: the object ids `[a, b]` (if any) before each side's indices,
/// `[a?, x.., b?, y..]`.
// PERF: a fixed array; a row collected into a `Vec` first was a heap allocation a pair.
fn id_row<const N: usize>(ids: Option<[u64; 2]>, x: &[u64], y: &[u64]) -> [u64; N] {
    let (a, b) = match ids {
        Some([a, b]) => (Some(a), Some(b)),
        None => (None, None),
    };
    let mut items = a
        .into_iter()
        .chain(x.iter().copied())
        .chain(b)
        .chain(y.iter().copied());
    let row = std::array::from_fn(|_| items.next().expect("row width"));
    assert!(items.next().is_none(), "row width");
    row
}

/// The rows of one walk's impacts with object ids `[a, b]` in front of each side's indices
/// (`None`: a single mesh's query, no ids): vertex-face, face-vertex, edge-edge.
fn impact_rows<const V: usize, const E: usize>(
    r: &dhcd::Impacts,
    ids: Option<[u64; 2]>,
    (vf, fv, ee): &mut (TimeRows<V>, TimeRows<V>, TimeRows<E>),
) {
    let i = u64::from;
    vf.extend(
        r.vertex_face
            .iter()
            .map(|x| (id_row(ids, &[i(x.vertex)], &[i(x.triangle)]), x.toi)),
    );
    fv.extend(
        r.face_vertex
            .iter()
            .map(|x| (id_row(ids, &[i(x.triangle)], &[i(x.vertex)]), x.toi)),
    );
    ee.extend(
        r.edge_edge
            .iter()
            .map(|x| (id_row(ids, &x.a.map(i), &x.b.map(i)), x.toi)),
    );
}

impl Impacts {
    fn new(py: Python<'_>, r: dhcd::Impacts) -> PyResult<Self> {
        let mut rows: (TimeRows<2>, TimeRows<2>, TimeRows<4>) = Default::default();
        impact_rows(&r, None, &mut rows);
        Self::of_rows(py, rows, r.toi, r.counters)
    }

    /// A scene's result flattened with object ids (as
    /// [`scene_proximity_columns`](crate::proximity::scene_proximity_columns)), each list sorted by
    /// its rows.
    pub(crate) fn of_scene(py: Python<'_>, r: dhcd::SceneImpacts) -> PyResult<Self> {
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
pub(crate) fn vertex_face_ccd<'py>(
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
pub(crate) fn edge_edge_ccd<'py>(
    py: Python<'py>,
    x0: &Bound<'py, PyAny>,
    x1: &Bound<'py, PyAny>,
    min_distance: Option<&Bound<'py, PyAny>>,
    t_max: Option<&Bound<'py, PyAny>>,
) -> PyResult<Batch<'py>> {
    batch_ccd(py, dhcd::ccd::edge_edge_until, x0, x1, min_distance, t_max)
}
