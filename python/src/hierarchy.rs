//! The hierarchy of one mesh: the `Hierarchy` class (build, update, properties). Its query
//! methods call the families' files (`self_collide`: `collide`, `edges`: `contact`).

use dhcd::{AnyHierarchy, Workspace};
use numpy::PyArray2;
use pyo3::prelude::*;

use crate::arrays::{faces, Positions, Vertices};
use crate::collide::{self, Contacts};
use crate::{contact, method, options, to_py};

/// The bounding-volume hierarchy of one deformable triangle mesh.
#[pyclass(module = "dhcd")]
pub(crate) struct Hierarchy {
    pub(crate) h: AnyHierarchy,
    pub(crate) ws: Workspace,
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
        collide::self_collide(py, self, threads)
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
