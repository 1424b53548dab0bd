//! The collision-free step size of a line search: `collision_free_stepsize(h, x0, x1)` for
//! one mesh, `collision_free_stepsize(a, b, a0, a1, b0, b1)` for two (`Scene` has its own,
//! in `scene.rs`, with the same keyword arguments).

use dhcd::contact::StepOptions;
use dhcd::Motion;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::arrays::rows_of;
use crate::ccd::{step_args, StepArgs};
use crate::{interrupt, par, real_arg, to_py};

/// The step-size rule's keyword arguments (`None`: the defaults), checked.
pub(crate) fn step_options(
    min_distance: Option<&Bound<'_, PyAny>>,
    rescaling: Option<&Bound<'_, PyAny>>,
) -> PyResult<StepOptions> {
    let mut options = StepOptions::default();
    if let Some(d) = min_distance {
        options.min_distance = real_arg(d, "min_distance")?;
    }
    if let Some(r) = rescaling {
        options.rescaling = real_arg(r, "rescaling")?;
    }
    options.validate().map_err(to_py)?;
    Ok(options)
}

/// The largest fraction of the step `x0 -> x1` (in `[0, 1]`) that keeps every pair of
/// features at least `min_distance + (1 - rescaling) (d0 - min_distance)` apart, `d0` its
/// distance at `x0` (see the stub).
#[pyfunction]
#[pyo3(
    signature = (*args, min_distance = None, rescaling = None, threads = None),
    text_signature = "(h, x0, x1, min_distance=0.0, rescaling=0.8, threads=1)"
)]
pub(crate) fn collision_free_stepsize(
    py: Python<'_>,
    args: &Bound<'_, PyTuple>,
    min_distance: Option<&Bound<'_, PyAny>>,
    rescaling: Option<&Bound<'_, PyAny>>,
    threads: Option<&Bound<'_, PyAny>>,
) -> PyResult<f64> {
    let options = step_options(min_distance, rescaling)?;
    let par = par(threads)?;
    let step = match step_args(args, "collision_free_stepsize")? {
        StepArgs::One(h, [x0, x1]) => {
            let m = Motion::new(rows_of(&x0, "x0")?, rows_of(&x1, "x1")?);
            let mut h = h.try_borrow_mut()?;
            let h = &mut *h;
            interrupt::run(py, par, |control| {
                h.ws.control = control.clone();
                h.h.collision_free_stepsize(m, &options, &mut h.ws, par)
            })?
        }
        StepArgs::Two([a, b], x) => {
            let ma = Motion::new(rows_of(&x[0], "a0")?, rows_of(&x[1], "a1")?);
            let mb = Motion::new(rows_of(&x[2], "b0")?, rows_of(&x[3], "b1")?);
            let (mut a, b) = (a.try_borrow_mut()?, b.try_borrow()?);
            let (a, b) = (&mut *a, &*b);
            interrupt::run(py, par, |control| {
                a.ws.control = control.clone();
                a.h.collision_free_stepsize_pair(ma, &b.h, mb, &options, &mut a.ws, par)
            })?
        }
    };
    Ok(step.step)
}
