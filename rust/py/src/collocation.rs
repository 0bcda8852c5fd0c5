//! Collocation's options (`ballbal.options.Collocation`) and the evaluation of a
//! collocation orbit a `PeriodicSolution` carries (its mesh and point values).

use crate::convert::{dispatch, slice, ModelArgs};
use crate::errors::CoreResult;
use crate::run::guarded;
use ballbal_core::numerics::collocation::{
    follow, jump_of, solve, CollocOptions, CollocOrbit, CollocStatus,
};
use ballbal_core::Error;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

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
    let times = slice(&t, "t")?;
    let orbit = orbit_of(&mesh, &states, period, &winding)?;
    let n = orbit.n;
    let mut out = Vec::with_capacity(times.len() * n);
    for &tt in times {
        out.extend(orbit.state(tt));
    }
    Ok(PyArray1::from_vec(py, out)
        .reshape([times.len(), n])?
        .into_any())
}

/// The collocation orbit of a mesh, its point values, period and windings, checked.
fn orbit_of(
    mesh: &PyReadonlyArray1<'_, f64>,
    states: &PyReadonlyArray1<'_, f64>,
    period: f64,
    winding: &[f64],
) -> PyResult<CollocOrbit> {
    let mesh = slice(mesh, "mesh")?.to_vec();
    let u = slice(states, "states")?.to_vec();
    let n = 2 * winding.len();
    let ntst = mesh.len().saturating_sub(1);
    let points = u.len() / n.max(1);
    if n == 0
        || ntst == 0
        || !u.len().is_multiple_of(n)
        || points < 2
        || !(points - 1).is_multiple_of(ntst)
    {
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
    if !(orbit_mesh_ok(&mesh) && period > 0.0 && period.is_finite()) {
        return Err(Error::param(
            "mesh",
            format!(
                "needs an increasing mesh from 0 to 1 and a finite period > 0, got period {period}"
            ),
        ))
        .py();
    }
    Ok(CollocOrbit {
        ncol: (points - 1) / ntst,
        n,
        mesh,
        u,
        period,
        jump: jump_of(winding),
    })
}

/// Whether `mesh` runs from 0 to 1, increasing.
fn orbit_mesh_ok(mesh: &[f64]) -> bool {
    mesh.first() == Some(&0.0) && mesh.last() == Some(&1.0) && mesh.windows(2).all(|w| w[0] < w[1])
}

/// Natural continuation of a collocation orbit (the core's `collocation::follow`) in the
/// model parameter `parameter` towards `target`: the orbit given (mesh, point values,
/// period, windings) is solved at the model's value first, then followed with steps of
/// `step`, halved on failure, until `target` or a step below `min_step` (an
/// infinite-period end). Returns lists `param`, `period`, `mesh_error` (the final mesh's
/// error indicator) per point, and `ntst`.
#[allow(
    clippy::too_many_arguments,
    reason = "a #[pyfunction]'s arguments are the Python call's keywords"
)]
#[pyfunction]
pub fn collocation_follow<'py>(
    py: Python<'py>,
    model: ModelArgs,
    parameter: &str,
    mesh: PyReadonlyArray1<'py, f64>,
    states: PyReadonlyArray1<'py, f64>,
    period: f64,
    winding: Vec<f64>,
    target: f64,
    step: f64,
    min_step: f64,
    options: CollocArgs,
) -> PyResult<Bound<'py, PyDict>> {
    let m = model.build(false).py()?;
    let opts = options.to_core()?;
    let orbit = orbit_of(&mesh, &states, period, &winding)?;
    if !target.is_finite() {
        return Err(Error::param(
            "target",
            format!("must be finite, got {target}"),
        ))
        .py();
    }
    let points = guarded(py, || {
        dispatch!(&m, d => {
            let start = solve(d, &orbit, &opts)?;
            if start.status != CollocStatus::Converged {
                return Err(Error::param(
                    "start",
                    format!("the orbit given does not converge here ({:?})", start.status),
                ));
            }
            follow(d, parameter, &start, target, step, min_step, &opts)
        })
    })?;
    let out = PyDict::new(py);
    out.set_item("param", points.iter().map(|p| p.param).collect::<Vec<_>>())?;
    out.set_item(
        "period",
        points
            .iter()
            .map(|p| p.solution.orbit.period)
            .collect::<Vec<_>>(),
    )?;
    out.set_item(
        "mesh_error",
        points
            .iter()
            .map(|p| p.solution.mesh_error)
            .collect::<Vec<_>>(),
    )?;
    out.set_item("ntst", opts.ntst)?;
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(collocation_follow, m)?)?;
    m.add_function(wrap_pyfunction!(validate_collocation, m)?)?;
    m.add_function(wrap_pyfunction!(collocation_states, m)?)?;
    Ok(())
}
