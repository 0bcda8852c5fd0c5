//! Checks run when a Python object is made (its `__post_init__`), so that a bad value
//! is refused there and not at the first analysis: each builds the core value the
//! analyses would build and runs the core's own checks, nothing more.

use crate::basins::BasinArgs;
use crate::continuation::ContinuationArgs;
use crate::convert::{self, BalancerArgs, FloquetArgs, GuessArgs, HarmonicBalanceArgs};
use crate::errors::CoreResult;
use pyo3::prelude::*;

/// A `ballbal.Balancer` (what `validate` checks of a model, without trying it as a
/// scene first).
#[pyfunction]
pub fn validate_balancer(balancer: BalancerArgs) -> PyResult<()> {
    balancer.planar().py().map(|_| ())
}

/// A `ballbal.options.HarmonicBalance` on its own.
#[pyfunction]
pub fn validate_harmonic_balance(options: HarmonicBalanceArgs) -> PyResult<()> {
    convert::validate_harmonic_balance(&options)
}

/// A `ballbal.options.Floquet` on its own.
#[pyfunction]
pub fn validate_floquet(options: FloquetArgs) -> PyResult<()> {
    convert::validate_floquet(&options)
}

/// A `ballbal.options.GuessSearch` on its own.
#[pyfunction]
pub fn validate_guess(options: GuessArgs) -> PyResult<()> {
    convert::validate_guess(&options)
}

/// A `ballbal.options.PeriodicOptions` (or a `ScanOptions`' mathematical part), whole.
#[pyfunction]
pub fn validate_periodic_options(options: convert::PeriodicArgs) -> PyResult<()> {
    options.to_core().map(|_| ())
}

/// A `ballbal.Continuation`: its step control, over an unbounded parameter window (the
/// window is the analysis' argument, checked there).
#[pyfunction]
pub fn validate_continuation(options: ContinuationArgs) -> PyResult<()> {
    options
        .options((f64::NEG_INFINITY, f64::INFINITY))
        .validate()
        .py()
}

/// A `ballbal.BasinOptions`.
#[pyfunction]
pub fn validate_basin_options(options: BasinArgs) -> PyResult<()> {
    options.to_core().validate().py()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(validate_balancer, m)?)?;
    m.add_function(wrap_pyfunction!(validate_harmonic_balance, m)?)?;
    m.add_function(wrap_pyfunction!(validate_floquet, m)?)?;
    m.add_function(wrap_pyfunction!(validate_guess, m)?)?;
    m.add_function(wrap_pyfunction!(validate_periodic_options, m)?)?;
    m.add_function(wrap_pyfunction!(validate_continuation, m)?)?;
    m.add_function(wrap_pyfunction!(validate_basin_options, m)?)?;
    Ok(())
}
