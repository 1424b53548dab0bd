//! Many deformable objects: the `Scene` class, its objects (by id or name) and its queries.
//! A query method parses its arguments here ([`Scene::updates`], [`Scene::motions`]), runs
//! the library's scene query and returns its family's result through that family's one
//! conversion (`Contacts::of_scene`, `scene_proximity_columns`, `Impacts::of_scene`,
//! `ContactSet::new`).

use std::collections::{HashMap, HashSet};

use dhcd::{check_positions, check_positions_f64, Error, Motion, ObjectId, Par, Precision};
use numpy::PyReadonlyArray2;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyList, PyMapping, PyString, PyTuple};

use crate::arrays::{ccd_positions, faces, rows_of, Positions, Vertices};
use crate::ccd::{ccd_query, Impacts};
use crate::collide::Contacts;
use crate::proximity::{scene_proximity_columns, Proximity};
use crate::step::step_options;
use crate::{contact, distance_arg, int_arg, interrupt, method, options, par, to_py, value_error};

/// Many deformable objects of one method; object ids are ints from 0 up, never reused.
#[pyclass(module = "dhcd")]
pub(crate) struct Scene {
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

    /// The entries of a query over a step (`ccd`; a mapping or an iterable of pairs): each
    /// object and its float64 positions at t = 0 and t = 1, borrowed (alive, read-only) while
    /// the result lives.
    fn motions<'py>(&self, motions: &Bound<'py, PyAny>) -> PyResult<Vec<MotionArrays<'py>>> {
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
        Ok(arrays)
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

/// One object's float64 positions at t = 0 and t = 1.
type MotionArrays<'py> = (
    ObjectId,
    PyReadonlyArray2<'py, f64>,
    PyReadonlyArray2<'py, f64>,
);

/// The entries of [`Scene::motions`] as motions.
fn as_motions<'a>(arrays: &'a [MotionArrays<'_>]) -> PyResult<Vec<(ObjectId, Motion<'a>)>> {
    arrays
        .iter()
        .map(|(id, x0, x1)| Ok((*id, Motion::new(rows_of(x0, "x0")?, rows_of(x1, "x1")?))))
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
        Contacts::of_scene(py, c)
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
        Contacts::of_scene(py, c)
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
            Ok(scene_proximity_columns(scene.proximity(d, par)?))
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
        let arrays = self.motions(motions)?;
        let motions = as_motions(&arrays)?;
        let scene = &mut self.scene;
        let r = interrupt::run(py, par, |control| {
            scene.set_control(control.clone());
            scene.ccd(&motions, &q, par)
        })?;
        Impacts::of_scene(py, r)
    }

    /// The collision-free step size of the whole scene over one step: `motions` as in
    /// `ccd`; the largest fraction of the step that keeps every pair at least
    /// `min_distance + (1 - rescaling) (d0 - min_distance)` apart.
    #[pyo3(
        signature = (motions, *, min_distance = None, rescaling = None, threads = None),
        text_signature = "(self, motions, *, min_distance=0.0, rescaling=0.8, threads=1)"
    )]
    fn collision_free_stepsize(
        &mut self,
        py: Python<'_>,
        motions: &Bound<'_, PyAny>,
        min_distance: Option<&Bound<'_, PyAny>>,
        rescaling: Option<&Bound<'_, PyAny>>,
        threads: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<f64> {
        let options = step_options(min_distance, rescaling)?;
        let par = par(threads)?;
        let arrays = self.motions(motions)?;
        let motions = as_motions(&arrays)?;
        let scene = &mut self.scene;
        let r = interrupt::run(py, par, |control| {
            scene.set_control(control.clone());
            scene.collision_free_stepsize(&motions, &options, par)
        })?;
        Ok(r.step)
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
