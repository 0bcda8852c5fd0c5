//! Continuation of periodic solutions in one parameter: `ballbal.continuation.
//! periodic_branch`'s native half (core: `ballbal_core::bifurcation::po_branch`).

use crate::collocation::CollocArgs;
use crate::continuation::{controls, ContinuationArgs};
use crate::convert::{dispatch, slice, ModelArgs, PeriodicArgs};
use crate::errors::{not_autonomous, CoreResult};
use crate::run::guarded_progress;
use crate::tables::solution_dict;
use ballbal_core::analysis::colloc_periodic::Method;
use ballbal_core::bifurcation::po_branch::{
    periodic_branch as core_branch, periodic_branch_both_ways, PoBranchOptions, PoPoint,
};
use ballbal_core::hb::{HbSolution, Status};
use ballbal_core::numerics::collocation::CollocOptions;
use ballbal_core::periodic::require_autonomous;
use ballbal_core::{Dynamics, Error};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A point's dict: `periodic()`'s solution dict plus the parameter, the arclength data
/// and the test functions.
fn point_dict<'py>(py: Python<'py>, pt: PoPoint, n_balls: usize) -> PyResult<Bound<'py, PyDict>> {
    let stability = pt.stability().as_str();
    let hill = pt.result.floquet.is_none() && pt.result.hill.is_some();
    let d = solution_dict(py, pt.result, n_balls)?;
    if hill {
        // Without a monodromy, the verdict the branch reports is Hill's.
        d.set_item("stability", stability)?;
    }
    d.set_item("p", pt.p)?;
    d.set_item("dp_ds", pt.arc.dp_ds())?;
    d.set_item("det_sign", pt.arc.det_sign)?;
    d.set_item("test_fold", pt.tests.lp)?;
    d.set_item("test_branch_point", pt.tests.bp)?;
    d.set_item("test_branch_point_multipliers", pt.tests.bp_multipliers)?;
    d.set_item("test_period_doubling", pt.tests.pd)?;
    d.set_item("test_neimark_sacker", pt.tests.ns)?;
    d.set_item("test_infinite_period", pt.tests.ip)?;
    d.set_item("method", pt.method.as_str())?;
    d.set_item(
        "event",
        pt.events
            .iter()
            .map(|e| e.as_str())
            .collect::<Vec<_>>()
            .join(","),
    )?;
    Ok(d)
}

/// Continues the periodic solution `start = (omega, coeffs, winding)` of `model` in
/// `parameter` over `p_range` (`both`: both ways from the start, joined into one branch),
/// with user points at the parameter values `at`, stopping at the first event named in
/// `stop` or where the period reaches `stop_period`, by `method` ("hb", "collocation" or
/// "auto", collocation with `collocation`'s options); returns `{"points": [dict],
/// "events": [dict], "stop": str}`.
#[allow(
    clippy::too_many_arguments,
    reason = "a #[pyfunction]'s arguments are the Python call's keywords"
)]
#[pyfunction]
#[pyo3(signature = (model, parameter, start, p_range, continuation, options, min_omega, event_tol, both=false, at=None, stop=None, stop_period=None, method="hb", collocation=None, progress=None))]
pub fn periodic_branch<'py>(
    py: Python<'py>,
    model: ModelArgs,
    parameter: &str,
    start: (f64, PyReadonlyArray1<'py, f64>, Vec<f64>),
    p_range: (f64, f64),
    continuation: ContinuationArgs,
    options: PeriodicArgs,
    min_omega: f64,
    event_tol: f64,
    both: bool,
    at: Option<Vec<f64>>,
    stop: Option<Vec<String>>,
    stop_period: Option<f64>,
    method: &str,
    collocation: Option<CollocArgs>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let method = Method::parse(method).py()?;
    let collocation = match &collocation {
        Some(c) => c.to_core()?,
        None => CollocOptions::default(),
    };
    // A scene is continued as a scene even with every effect off (as a scan does).
    let always_scene = matches!(model, ModelArgs::Scene(_));
    let m = model.build(always_scene).py()?;
    dispatch!(&m, x => require_autonomous(x)).map_err(|e| not_autonomous(e, "periodic_branch"))?;
    let n_balls = m.n_balls();
    let popts = options.to_core_for(&m)?;
    let (omega, coeffs, winding) = start;
    let coeffs = slice(&coeffs, "start")?.to_vec();
    let d = dispatch!(&m, x => x.ndof());
    if winding.len() != d
        || coeffs.is_empty()
        || !coeffs.len().is_multiple_of(d)
        || (coeffs.len() / d) % 2 != 1
    {
        return Err(Error::param(
            "start",
            format!("coefficients and winding do not fit a model with {d} coordinates"),
        ))
        .py();
    }
    let nh = (coeffs.len() / d - 1) / 2;
    let start = HbSolution::start(omega, coeffs, winding, nh, Status::NoGuess);
    let opts = PoBranchOptions {
        arc: continuation.options(p_range),
        periodic: popts,
        min_omega,
        event_tol,
        controls: controls(at, stop)?,
        stop_period,
        method,
        collocation,
    };
    let name = parameter.to_string();
    let b = guarded_progress(py, progress.as_ref(), || {
        if both {
            dispatch!(&m, x => periodic_branch_both_ways(x, &name, &start, &opts))
        } else {
            dispatch!(&m, x => core_branch(x, &name, &start, &opts))
        }
    })?;
    let out = PyDict::new(py);
    let mut points = Vec::with_capacity(b.points.len());
    for pt in b.points {
        points.push(point_dict(py, pt, n_balls)?);
    }
    let mut events = Vec::with_capacity(b.events.len());
    for e in b.events {
        let d = point_dict(py, e.point, n_balls)?;
        d.set_item("event_type", e.kind.as_str())?;
        d.set_item("event_p", e.p)?;
        d.set_item("test", e.test)?;
        d.set_item("index", e.index)?;
        events.push(d);
    }
    out.set_item("points", points)?;
    out.set_item("events", events)?;
    out.set_item("stop", b.stop)?;
    Ok(out)
}
