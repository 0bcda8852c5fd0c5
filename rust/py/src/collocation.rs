//! Collocation's options (`ballbal.options.Collocation`) and the evaluation of a
//! collocation orbit a `PeriodicSolution` carries (its mesh and point values).

use crate::convert::slice;
use crate::errors::CoreResult;
use ballbal_core::numerics::collocation::{jump_of, CollocOptions, CollocOrbit};
use ballbal_core::Error;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;

/// `ballbal.options.Collocation`.
#[derive(FromPyObject)]
pub struct CollocArgs {
    ntst: usize,
    ncol: usize,
    tol: f64,
    step_tol: f64,
    max_iter: usize,
    adapt: usize,
}

impl CollocArgs {
    /// The core's options, checked by the core.
    pub fn to_core(&self) -> PyResult<CollocOptions> {
        let o = CollocOptions {
            ntst: self.ntst,
            ncol: self.ncol,
            tol: self.tol,
            step_tol: self.step_tol,
            max_iter: self.max_iter,
            adapt: self.adapt,
        };
        o.validate().py()?;
        Ok(o)
    }
}

/// A `ballbal.options.Collocation` on its own.
#[pyfunction]
pub fn validate_collocation(options: CollocArgs) -> PyResult<()> {
    options.to_core().map(|_| ())
}

/// The first-order states `(q, q')` at times `t` (shape `(len(t), 2 d)`) of the
/// collocation orbit with mesh `mesh` (scaled time, `0 .. 1`), point values `states`
/// (`NTST NCOL + 1` rows of `2 d`, flattened), `period` and the coordinates' `winding`.
#[pyfunction]
pub fn collocation_states<'py>(
    py: Python<'py>,
    mesh: PyReadonlyArray1<'py, f64>,
    states: PyReadonlyArray1<'py, f64>,
    period: f64,
    winding: Vec<f64>,
    t: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let mesh = slice(&mesh, "mesh")?.to_vec();
    let u = slice(&states, "states")?.to_vec();
    let times = slice(&t, "t")?;
    let n = 2 * winding.len();
    let ntst = mesh.len().saturating_sub(1);
    let points = u.len() / n.max(1);
    if n == 0 || ntst == 0 || u.len() % n != 0 || (points - 1) % ntst != 0 || points < 2 {
        return Err(Error::param(
            "states",
            format!(
                "need NTST NCOL + 1 rows of {n} values for a mesh of {} points, got {}",
                mesh.len(),
                u.len()
            ),
        ))
        .py();
    }
    let ordered = orbit_mesh_ok(&mesh);
    if !ordered || !(period > 0.0 && period.is_finite()) {
        return Err(Error::param(
            "mesh",
            format!(
                "needs an increasing mesh from 0 to 1 and a finite period > 0, got period {period}"
            ),
        ))
        .py();
    }
    let orbit = CollocOrbit {
        ncol: (points - 1) / ntst,
        n,
        mesh,
        u,
        period,
        jump: jump_of(&winding),
    };
    let mut out = Vec::with_capacity(times.len() * n);
    for &tt in times {
        out.extend(orbit.state(tt));
    }
    Ok(PyArray1::from_vec(py, out)
        .reshape([times.len(), n])?
        .into_any())
}

/// Whether `mesh` runs from 0 to 1, increasing.
fn orbit_mesh_ok(mesh: &[f64]) -> bool {
    mesh.first() == Some(&0.0) && mesh.last() == Some(&1.0) && mesh.windows(2).all(|w| w[0] < w[1])
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(validate_collocation, m)?)?;
    m.add_function(wrap_pyfunction!(collocation_states, m)?)?;
    Ok(())
}
