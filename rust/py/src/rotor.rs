//! A rigid rotor on one journal bearing (fixed frame, no balls): `ballbal.bearing`'s
//! `RotorOnBearing` read by attribute into the core's
//! [`ballbal_core::analysis::journal::RotorOnBearing`], simulated off the GIL.

use crate::bearing::BearingArgs;
use crate::errors::CoreResult;
use crate::run::guarded;
use ballbal_core::analysis::journal::{
    simulate_rotor as core_simulate_rotor, Impulse, Method, RotorOnBearing, RotorOptions, SpinUp,
};
use ballbal_core::model::bearing::Dimensions;
use ballbal_core::Error;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `ballbal.bearing.Impulse`'s fields (direction in degrees).
#[derive(FromPyObject)]
pub struct ImpulseArgs {
    amplitude: f64,
    center: f64,
    sharpness: f64,
    direction: f64,
}

/// `ballbal.bearing.SpinUp`'s fields (a linear run-up).
#[derive(FromPyObject)]
pub struct SpinUpArgs {
    start: f64,
    duration: f64,
}

/// `ballbal.bearing.RotorOnBearing`'s fields (angles in degrees).
#[derive(FromPyObject)]
pub struct RotorArgs {
    bearing: BearingArgs,
    mass_parameter: f64,
    gravity: f64,
    gravity_direction: f64,
    unbalance: f64,
    unbalance_phase: f64,
    impulse: Option<ImpulseArgs>,
    spin_up: Option<SpinUpArgs>,
}

impl RotorArgs {
    fn to_core(&self) -> Result<RotorOnBearing, Error> {
        let r = RotorOnBearing {
            bearing: self.bearing.to_core()?,
            mass: self.mass_parameter,
            gravity: self.gravity,
            gravity_direction: self.gravity_direction.to_radians(),
            unbalance: self.unbalance,
            unbalance_phase: self.unbalance_phase.to_radians(),
            impulse: self.impulse.as_ref().map(|i| Impulse {
                amplitude: i.amplitude,
                center: i.center,
                sharpness: i.sharpness,
                direction: i.direction.to_radians(),
            }),
            spin_up: self
                .spin_up
                .as_ref()
                .map_or(SpinUp::Sudden, |s| SpinUp::Ramp {
                    start: s.start,
                    duration: s.duration,
                }),
        };
        r.validate()?;
        Ok(r)
    }
}

/// Checks a `RotorOnBearing` the way the core does.
#[pyfunction]
pub fn validate_rotor(rotor: RotorArgs) -> PyResult<()> {
    rotor.to_core().py().map(|_| ())
}

/// The journal's static equilibrium `(x, y)` under the rotor's weight.
#[pyfunction]
pub fn rotor_equilibrium(py: Python<'_>, rotor: RotorArgs) -> PyResult<(f64, f64)> {
    let r = rotor.to_core().py()?;
    let q = guarded(py, || r.equilibrium())?;
    Ok((q[0], q[1]))
}

/// `(mass_parameter, gravity, unbalance)` from lab quantities (SI), the core's conversion.
#[allow(
    clippy::too_many_arguments,
    reason = "a #[pyfunction]'s arguments are the Python call's keywords"
)]
#[pyfunction]
#[pyo3(signature = (bearing, radius, length, clearance, viscosity, mass, speed, unbalance, g))]
pub fn rotor_from_dimensions(
    bearing: BearingArgs,
    radius: f64,
    length: f64,
    clearance: f64,
    viscosity: f64,
    mass: f64,
    speed: f64,
    unbalance: f64,
    g: f64,
) -> PyResult<(f64, f64, f64)> {
    let b = bearing.to_core().py()?;
    let dims = Dimensions::new(radius, length, clearance, viscosity).py()?;
    let r = RotorOnBearing::from_dimensions(b, &dims, mass, speed, unbalance, g).py()?;
    Ok((r.mass, r.gravity, r.unbalance))
}

/// Simulates from `x0 = (x, y, x', y')` at `t0` with rows at `t_eval`; returns a dict of
/// arrays (`tau`, `state` (rows x 4), `force` (rows x 4: fx, fy, radial, tangential)) and
/// the run's outcome, end time, contact time, step counts and message.
#[allow(
    clippy::too_many_arguments,
    reason = "a #[pyfunction]'s arguments are the Python call's keywords"
)]
#[pyfunction]
#[pyo3(signature = (rotor, x0, t0, t_eval, rtol, atol, max_steps, eps_contact, stiff_steps, method, factor_reuse))]
pub fn simulate_rotor<'py>(
    py: Python<'py>,
    rotor: RotorArgs,
    x0: (f64, f64, f64, f64),
    t0: f64,
    t_eval: PyReadonlyArray1<'py, f64>,
    rtol: f64,
    atol: f64,
    max_steps: usize,
    eps_contact: f64,
    stiff_steps: usize,
    method: &str,
    factor_reuse: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let r = rotor.to_core().py()?;
    let method = match method {
        "explicit" => Method::Explicit,
        "implicit" => Method::Implicit,
        other => {
            return Err(Error::param_range(
                "method",
                format!("unknown method {other:?}"),
                "explicit, implicit",
            ))
            .py()
        }
    };
    let te = t_eval.as_slice()?.to_vec();
    let opts = RotorOptions {
        rtol,
        atol,
        max_steps,
        eps_contact,
        stiff_steps,
        method,
        factor_reuse,
    };
    let y0 = [x0.0, x0.1, x0.2, x0.3];
    let tr = guarded(py, || core_simulate_rotor(&r, y0, t0, &te, &opts))?;
    let rows = tr.t.len();
    let d = PyDict::new(py);
    d.set_item("tau", PyArray1::from_vec(py, tr.t))?;
    d.set_item(
        "state",
        PyArray1::from_vec(py, tr.y.into_iter().flatten().collect()).reshape([rows, 4])?,
    )?;
    d.set_item(
        "force",
        PyArray1::from_vec(py, tr.force.into_iter().flatten().collect()).reshape([rows, 4])?,
    )?;
    d.set_item("outcome", tr.outcome.name())?;
    d.set_item("t_end", tr.t_end)?;
    d.set_item("contact_time", tr.contact_time)?;
    d.set_item("stiff_eccentricity", tr.stiff_at.map(|s| s.0))?;
    d.set_item("stiff_step", tr.stiff_at.map(|s| s.1))?;
    d.set_item("message", tr.message)?;
    d.set_item("accepted_steps", tr.stats.accepted)?;
    d.set_item("rejected_steps", tr.stats.rejected)?;
    d.set_item("rhs_evals", tr.stats.rhs_evals)?;
    d.set_item("force_evals", tr.force_evals)?;
    Ok(d)
}

/// Adds this file's functions to the module (one line in `lib.rs`).
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(validate_rotor, m)?)?;
    m.add_function(wrap_pyfunction!(rotor_equilibrium, m)?)?;
    m.add_function(wrap_pyfunction!(rotor_from_dimensions, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_rotor, m)?)?;
    Ok(())
}
