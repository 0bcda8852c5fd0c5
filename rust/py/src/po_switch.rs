//! Branch switching entries (`ballbal.continuation.switch`): the core's
//! `bifurcation::switch` on a periodic solution (period doubling, branch point) or an
//! equilibrium (Hopf point), in a named parameter.

use crate::convert::{dispatch, slice, ModelArgs, PeriodicArgs};
use crate::errors::CoreResult;
use crate::run::guarded;
use crate::tables::solution_dict;
use ballbal_core::bifurcation::switch::{
    switch_hopf as core_hopf, switch_periodic as core_periodic, Switch, Switched,
};
use ballbal_core::Error;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `(solution dict, parameter value, critical multiplier or eigenvalue (re, im))`.
type Out<'py> = (Bound<'py, PyDict>, f64, (f64, f64));

fn out<'py>(py: Python<'py>, s: Switched, n_balls: usize) -> PyResult<Out<'py>> {
    Ok((solution_dict(py, s.periodic, n_balls)?, s.p, s.critical))
}

/// The first solution of the branch leaving the periodic solution `(omega, coeffs,
/// winding)` at a period doubling (`kind = "period_doubling"`) or branch point
/// (`"branch_point"`; the core's `Event::parse` reads AUTO's `PD`, `BP` too).
#[allow(
    clippy::too_many_arguments,
    reason = "a #[pyfunction]'s arguments are the Python call's keywords"
)]
#[pyfunction]
#[pyo3(signature = (model, parameter, omega, coeffs, winding, kind, amplitude, options))]
pub fn switch_periodic<'py>(
    py: Python<'py>,
    model: ModelArgs,
    parameter: &str,
    omega: f64,
    coeffs: PyReadonlyArray1<'py, f64>,
    winding: Vec<f64>,
    kind: &str,
    amplitude: f64,
    options: PeriodicArgs,
) -> PyResult<Out<'py>> {
    let m = model.build(false).py()?;
    let kind = Switch::parse(kind).py()?;
    let opts = options.to_core_for(&m)?;
    let d = winding.len();
    let c = slice(&coeffs, "coeffs")?.to_vec();
    if d == 0
        || !c.len().is_multiple_of(d)
        || (c.len() / d) % 2 != 1
        || omega.is_nan()
        || omega <= 0.0
    {
        return Err(Error::param(
            "solution",
            "needs a converged periodic solution",
        ))
        .py();
    }
    let n_harm = (c.len() / d - 1) / 2;
    let sol = ballbal_core::hb::HbSolution::start(
        omega,
        c,
        winding,
        n_harm,
        ballbal_core::hb::Status::Converged,
    );
    let s = guarded(
        py,
        || dispatch!(&m, x => core_periodic(x, parameter, &sol, kind, amplitude, &opts)),
    )?;
    out(py, s, m.n_balls())
}

/// The first oscillating orbit born at the Hopf point of the equilibrium `q`.
#[pyfunction]
pub fn switch_hopf<'py>(
    py: Python<'py>,
    model: ModelArgs,
    parameter: &str,
    q: Vec<f64>,
    amplitude: f64,
    options: PeriodicArgs,
) -> PyResult<Out<'py>> {
    let m = model.build(false).py()?;
    let opts = options.to_core_for(&m)?;
    let s = guarded(
        py,
        || dispatch!(&m, x => core_hopf(x, parameter, &q, amplitude, &opts)),
    )?;
    out(py, s, m.n_balls())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(switch_periodic, m)?)?;
    m.add_function(wrap_pyfunction!(switch_hopf, m)?)?;
    Ok(())
}
