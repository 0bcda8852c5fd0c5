//! Two-parameter curves of periodic bifurcations: `ballbal.continuation.periodic_curve`'s
//! native half (core: `ballbal_core::bifurcation::po_curves`).

use crate::continuation::ContinuationArgs;
use crate::convert::{dispatch, slice, ModelArgs, PeriodicArgs};
use crate::errors::{not_autonomous, CoreResult};
use crate::run::guarded_progress;
use crate::tables::solution_dict;
use ballbal_core::bifurcation::po_curves::{
    periodic_curve as core_curve, PoCurveKind, PoCurveOptions,
};
use ballbal_core::hb::{HbSolution, Status};
use ballbal_core::periodic::require_autonomous;
use ballbal_core::{Dynamics, Error};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Continues the curve of `kind` (`"fold"`, `"branch_point"`, `"period_doubling"`,
/// `"neimark_sacker"`, or an alias the core's `Event::parse` reads) through the event solution
/// `start = (omega, coeffs, winding)` of `model` (at the event's parameter values) in
/// `(parameter, parameter2)`; `range` bounds `parameter2`, `range1` `parameter`. Returns
/// `{"kind", "together", "points": [dict], "special": [dict], "stop": str}`; an `NS`
/// `neimark_sacker` curve's points carry `"theta"`, the critical pair's angle; each special point its
/// multiplier certificate (`"status"`, `"gap"`, `"residual"`, `"own_residual"`,
/// `"error"`).
#[allow(
    clippy::too_many_arguments,
    reason = "a #[pyfunction]'s arguments are the Python call's keywords"
)]
#[pyfunction]
#[pyo3(signature = (model, kind, parameter, parameter2, start, range, range1, continuation, options, locate_tol, progress=None))]
pub fn periodic_curve<'py>(
    py: Python<'py>,
    model: ModelArgs,
    kind: &str,
    parameter: &str,
    parameter2: &str,
    start: (f64, PyReadonlyArray1<'py, f64>, Vec<f64>),
    range: (f64, f64),
    range1: (f64, f64),
    continuation: ContinuationArgs,
    options: PeriodicArgs,
    locate_tol: f64,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let always_scene = matches!(model, ModelArgs::Scene(_));
    let m = model.build(always_scene).py()?;
    dispatch!(&m, x => require_autonomous(x)).map_err(|e| not_autonomous(e, "periodic_curve"))?;
    let k = PoCurveKind::parse(kind).py()?;
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
    let opts = PoCurveOptions {
        arc: continuation.options(range),
        p1_range: range1,
        periodic: popts,
        locate_tol,
    };
    let names = [parameter.to_string(), parameter2.to_string()];
    let c = guarded_progress(
        py,
        progress.as_ref(),
        || dispatch!(&m, x => core_curve(x, [&names[0], &names[1]], k, &start, &opts)),
    )?;
    let out = PyDict::new(py);
    let mut points = Vec::with_capacity(c.points.len());
    for pt in c.points {
        let hill = match (&pt.result.floquet, &pt.result.hill) {
            (None, Some((_, s))) => Some(*s),
            _ => None,
        };
        let d = solution_dict(py, pt.result, n_balls)?;
        if let Some(s) = hill {
            // Without a monodromy, the verdict reported is Hill's (as on a branch).
            d.set_item("stability", s.as_str())?;
        }
        d.set_item("p1", pt.p[0])?;
        d.set_item("p2", pt.p[1])?;
        d.set_item("test", pt.g)?;
        if let Some(t) = pt.theta {
            d.set_item("theta", t)?;
        }
        for (name, v) in pt.tests {
            d.set_item(format!("test_{name}"), v)?;
        }
        points.push(d);
    }
    let mut special = Vec::with_capacity(c.special.len());
    for s in c.special {
        let d = PyDict::new(py);
        d.set_item("type", s.kind)?;
        d.set_item("p1", s.p[0])?;
        d.set_item("p2", s.p[1])?;
        d.set_item("omega", s.omega)?;
        d.set_item("row", s.row)?;
        let c = s.certificate;
        d.set_item("status", c.status.as_str())?;
        d.set_item("gap", c.gap)?;
        d.set_item("residual", c.residual)?;
        d.set_item("own_residual", c.own_residual)?;
        d.set_item("error", c.error)?;
        special.push(d);
    }
    out.set_item("kind", c.kind.as_str())?;
    out.set_item("together", c.together)?;
    out.set_item("points", points)?;
    out.set_item("special", special)?;
    out.set_item("stop", format!("{}/{}", c.stop[0], c.stop[1]))?;
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(periodic_curve, m)?)?;
    Ok(())
}
