//! Thin pyo3 binding over `ballbal-core`, split by concern: [`errors`] (the one mapping
//! of core errors to `ballbal.exceptions`), [`convert`] (the Python model and option
//! dataclasses read by attribute), [`entries`] (the entry points), [`tables`] (result
//! dicts and scan columns, with the one periodic-solution schema) and [`run`] (core work
//! off the GIL, with panics contained and Ctrl-C working). This file only builds the
//! module.

mod basins;
mod bearing;
mod checks;
mod collocation;
mod continuation;
mod convert;
mod entries;
mod eq_continuation;
mod errors;
mod groove;
mod po_continuation;
mod po_curves;
mod po_switch;
mod rotor;
mod run;
mod tables;

use errors::panic_text;
use pyo3::prelude::*;
use std::panic::catch_unwind;

/// Loads NumPy's C API now, at import. `numpy` loads it on the first array it makes and
/// panics if that fails, and it runs Python code to do so (`numpy.lib.NumpyVersion`):
/// on the first native call of a process a Ctrl-C pending from the work just done
/// raised `KeyboardInterrupt` inside it and reached Python as a `PanicException`.
fn load_numpy_api(py: Python<'_>) -> PyResult<()> {
    // The same Python steps first, where an exception (a Ctrl-C during the import)
    // is raised as itself.
    let version = py.import("numpy")?.getattr("__version__")?;
    py.import("numpy.lib")?
        .getattr("NumpyVersion")?
        .call1((version,))?;
    let mut last = String::new();
    // A signal can still land in the microseconds between: its exception is gone by then
    // (consumed by numpy's `expect`), but it is named in the panic message.
    for _ in 0..3 {
        match catch_unwind(|| numpy::npyffi::is_numpy_2(py)) {
            Ok(_) => return Ok(()),
            Err(p) => {
                let msg = panic_text(&*p);
                if msg.contains("KeyboardInterrupt") {
                    return Err(pyo3::exceptions::PyKeyboardInterrupt::new_err(
                        "interrupted while loading NumPy's C API",
                    ));
                }
                last = msg;
            }
        }
    }
    Err(pyo3::exceptions::PyImportError::new_err(format!(
        "ballbal: cannot load NumPy's C API: {last}"
    )))
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    load_numpy_api(m.py())?;
    m.add_function(wrap_pyfunction!(entries::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(entries::validate, m)?)?;
    m.add_function(wrap_pyfunction!(entries::equilibria, m)?)?;
    m.add_function(wrap_pyfunction!(entries::balanced_states, m)?)?;
    m.add_function(wrap_pyfunction!(entries::balance_map, m)?)?;
    m.add_function(wrap_pyfunction!(entries::periodic, m)?)?;
    m.add_function(wrap_pyfunction!(entries::orbit_closure, m)?)?;
    m.add_function(wrap_pyfunction!(entries::scan, m)?)?;
    m.add_function(wrap_pyfunction!(entries::default_chunk, m)?)?;
    m.add_function(wrap_pyfunction!(entries::certificate_seconds, m)?)?;
    m.add_function(wrap_pyfunction!(entries::scan_stage_seconds, m)?)?;
    m.add_function(wrap_pyfunction!(entries::hb_stage_profile, m)?)?;
    m.add_function(wrap_pyfunction!(entries::hb_stage_seconds, m)?)?;
    m.add_function(wrap_pyfunction!(entries::scan_work_counts, m)?)?;
    m.add_function(wrap_pyfunction!(entries::scan_profile, m)?)?;
    m.add_function(wrap_pyfunction!(entries::scan_wave_order, m)?)?;
    m.add_function(wrap_pyfunction!(entries::parameters, m)?)?;
    m.add_function(wrap_pyfunction!(entries::parse_parameter, m)?)?;
    m.add_function(wrap_pyfunction!(entries::ball_parameter_name, m)?)?;
    m.add_function(wrap_pyfunction!(entries::parameter_keys, m)?)?;
    m.add_function(wrap_pyfunction!(entries::check_axes, m)?)?;
    m.add_function(wrap_pyfunction!(tables::scan_schema, m)?)?;
    m.add_function(wrap_pyfunction!(bearing::validate_bearing, m)?)?;
    checks::register(m)?;
    collocation::register(m)?;
    rotor::register(m)?;
    m.add_function(wrap_pyfunction!(bearing::bearing_force, m)?)?;
    m.add_function(wrap_pyfunction!(bearing::bearing_equilibrium, m)?)?;
    m.add_function(wrap_pyfunction!(bearing::bearing_coefficients, m)?)?;
    m.add_function(wrap_pyfunction!(bearing::bearing_stability, m)?)?;
    basins::register(m)?;
    eq_continuation::register(m)?;
    po_switch::register(m)?;
    po_curves::register(m)?;
    m.add_function(wrap_pyfunction!(groove::groove_study, m)?)?;
    m.add_function(wrap_pyfunction!(po_continuation::periodic_branch, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
