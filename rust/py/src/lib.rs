//! Thin pyo3 binding over `ballbal-core`. Every entry point releases the GIL around the
//! numerical work and turns core errors into `ValueError`; a Rust panic is caught and
//! raised as `RuntimeError` so that it never unwinds into Python.

use ballbal_core::equilibria::equilibria as core_equilibria;
use ballbal_core::floquet::FloquetOptions;
use ballbal_core::hb::{HbOptions, HbSolution, Status};
use ballbal_core::ode::Options;
use ballbal_core::periodic::{
    closure_error, parse_pattern, pattern_string, periodic as core_periodic, PeriodicOptions,
};
use ballbal_core::simulate::simulate as core_simulate;
use ballbal_core::{Dynamics, Error, Planar};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::panic::{catch_unwind, AssertUnwindSafe};

fn to_py(e: Error) -> PyErr {
    match e {
        Error::InvalidParameter { .. } | Error::NotAutonomous { .. } => {
            PyValueError::new_err(e.to_string())
        }
        Error::Integration(_) => PyRuntimeError::new_err(e.to_string()),
    }
}

/// Runs `f` without the GIL and with panics contained.
fn guarded<T: Send, F: FnOnce() -> Result<T, Error> + Send>(py: Python<'_>, f: F) -> PyResult<T> {
    py.detach(|| catch_unwind(AssertUnwindSafe(f)))
        .map_err(|p| {
            let msg = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown".into());
            PyRuntimeError::new_err(format!(
                "internal error in ballbal core (please report): {msg}"
            ))
        })?
        .map_err(to_py)
}

fn planar(
    mu: f64,
    zeta: f64,
    zeta_b: Vec<f64>,
    delta: f64,
    omega: f64,
    eta: Vec<f64>,
) -> PyResult<Planar> {
    Planar::new(mu, zeta, &zeta_b, delta, omega, &eta).map_err(to_py)
}

fn slice<'a>(a: &'a PyReadonlyArray1<'_, f64>, name: &str) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|_| PyValueError::new_err(format!("{name}: must be a contiguous float64 array")))
}

/// Integrates from `y0` and returns `(y, accepted_steps, rejected_steps, rhs_evals)`,
/// `y` of shape `(len(t_eval), 2 (n + 2))`.
#[pyfunction]
#[pyo3(signature = (mu, zeta, zeta_b, delta, omega, eta, y0, t0, t_eval, rtol, atol))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    mu: f64,
    zeta: f64,
    zeta_b: Vec<f64>,
    delta: f64,
    omega: f64,
    eta: Vec<f64>,
    y0: PyReadonlyArray1<'py, f64>,
    t0: f64,
    t_eval: PyReadonlyArray1<'py, f64>,
    rtol: f64,
    atol: Vec<f64>,
) -> PyResult<(Bound<'py, PyAny>, usize, usize, usize)> {
    let p = planar(mu, zeta, zeta_b, delta, omega, eta)?;
    let y0 = slice(&y0, "y0")?.to_vec();
    let te = slice(&t_eval, "t_eval")?.to_vec();
    let opts = Options {
        rtol,
        atol,
        ..Default::default()
    };
    let traj = guarded(py, || core_simulate(&p, &y0, t0, &te, &opts))?;
    let cols = y0.len();
    let flat: Vec<f64> = traj.y.into_iter().flatten().collect();
    let arr = PyArray1::from_vec(py, flat).reshape([te.len(), cols])?;
    Ok((
        arr.into_any(),
        traj.stats.accepted,
        traj.stats.rejected,
        traj.stats.rhs_evals,
    ))
}

/// All equilibria with their stability, as a list of dicts.
#[pyfunction]
fn equilibria<'py>(
    py: Python<'py>,
    mu: f64,
    zeta: f64,
    zeta_b: Vec<f64>,
    delta: f64,
    omega: f64,
    eta: Vec<f64>,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let p = planar(mu, zeta, zeta_b, delta, omega, eta)?;
    let eqs = guarded(py, || Ok(core_equilibria(&p)))?;
    let mut out = vec![];
    for e in eqs {
        let d = PyDict::new(py);
        d.set_item("kind", e.kind)?;
        d.set_item("q", PyArray1::from_vec(py, e.q))?;
        d.set_item("residual", e.residual)?;
        d.set_item(
            "eig_re",
            PyArray1::from_vec(py, e.eigenvalues.iter().map(|z| z.0).collect()),
        )?;
        d.set_item(
            "eig_im",
            PyArray1::from_vec(py, e.eigenvalues.iter().map(|z| z.1).collect()),
        )?;
        d.set_item("index", e.index)?;
        d.set_item("stability", e.verdict.as_str())?;
        d.set_item("neutral", e.neutral)?;
        d.set_item("routh_hurwitz", e.routh_hurwitz)?;
        d.set_item("char_poly", PyArray1::from_vec(py, e.char_poly))?;
        out.push(d);
    }
    Ok(out)
}

fn solution_dict<'py>(
    py: Python<'py>,
    r: ballbal_core::periodic::Periodic,
) -> PyResult<Bound<'py, PyDict>> {
    let s = r.sol;
    let d = PyDict::new(py);
    let ok = s.status == Status::Converged;
    d.set_item("status", s.status.as_str())?;
    d.set_item("type", pattern_string(&s.winding))?;
    d.set_item("omega", if ok { Some(s.omega) } else { None })?;
    d.set_item("last_omega", s.omega)?;
    let l = 2 * s.n_harm + 1;
    let ndof = s.winding.len();
    d.set_item(
        "coeffs",
        PyArray1::from_vec(py, s.coeffs).reshape([ndof, l])?,
    )?;
    d.set_item("winding", PyArray1::from_vec(py, s.winding))?;
    d.set_item("N", s.n_harm)?;
    d.set_item("samples", s.samples)?;
    d.set_item("residual", s.residual)?;
    d.set_item("step", s.step)?;
    d.set_item("iterations", s.iterations)?;
    d.set_item("pivot_ratio", s.pivot_ratio)?;
    if let Some(f) = r.floquet {
        d.set_item(
            "mult_re",
            PyArray1::from_vec(py, f.multipliers.iter().map(|z| z.0).collect()),
        )?;
        d.set_item(
            "mult_im",
            PyArray1::from_vec(py, f.multipliers.iter().map(|z| z.1).collect()),
        )?;
        d.set_item("trivial_error", f.trivial_error)?;
        d.set_item("max_modulus", f.max_modulus)?;
        d.set_item("stability", f.stability.as_str())?;
        d.set_item("floquet_steps", f.steps)?;
    } else {
        d.set_item("stability", "undetermined")?;
    }
    d.set_item("floquet_error", r.floquet_error)?;
    Ok(d)
}

/// Solver options shared by `periodic` and `scan`, validated before any work starts.
#[allow(clippy::too_many_arguments)]
fn periodic_options(
    n_harm: usize,
    samples: Option<usize>,
    tol: f64,
    step_tol: f64,
    max_iter: usize,
    floquet: bool,
    f_rtol: f64,
    f_atol: f64,
    margin: f64,
    settle: f64,
    window: f64,
) -> PyResult<PeriodicOptions> {
    let hb = HbOptions {
        n_harm,
        samples,
        tol,
        step_tol,
        max_iter,
    };
    hb.validate().map_err(to_py)?;
    Options::new(f_rtol, f_atol).validate(1).map_err(to_py)?;
    if !(settle > 0.0 && window > 0.0 && settle.is_finite() && window.is_finite()) {
        return Err(PyValueError::new_err(
            "settle, window: must be finite and > 0",
        ));
    }
    Ok(PeriodicOptions {
        hb,
        floquet: floquet.then_some(FloquetOptions {
            rtol: f_rtol,
            atol: f_atol,
            margin,
        }),
        guess: ballbal_core::periodic::GuessOptions {
            settle,
            window,
            ..Default::default()
        },
    })
}

/// Periodic solution of the given pattern by Newton–IHB, with Floquet multipliers.
#[pyfunction]
#[pyo3(signature = (mu, zeta, zeta_b, delta, omega, eta, pattern, n_harm, samples, tol, step_tol, max_iter,
                    guess_omega, guess_coeffs, floquet, f_rtol, f_atol, margin, settle, window))]
#[allow(clippy::too_many_arguments)]
fn periodic<'py>(
    py: Python<'py>,
    mu: f64,
    zeta: f64,
    zeta_b: Vec<f64>,
    delta: f64,
    omega: f64,
    eta: Vec<f64>,
    pattern: &str,
    n_harm: usize,
    samples: Option<usize>,
    tol: f64,
    step_tol: f64,
    max_iter: usize,
    guess_omega: Option<f64>,
    guess_coeffs: Option<PyReadonlyArray1<'py, f64>>,
    floquet: bool,
    f_rtol: f64,
    f_atol: f64,
    margin: f64,
    settle: f64,
    window: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let p = planar(mu, zeta, zeta_b, delta, omega, eta)?;
    let rotating = parse_pattern(pattern, p.n_balls()).map_err(to_py)?;
    let opts = periodic_options(
        n_harm, samples, tol, step_tol, max_iter, floquet, f_rtol, f_atol, margin, settle, window,
    )?;
    let d = p.ndof();
    let guess = match (guess_omega, guess_coeffs) {
        (Some(w), Some(c)) => {
            let c = slice(&c, "guess coefficients")?.to_vec();
            if c.len() % d != 0 || (c.len() / d) % 2 != 1 {
                return Err(PyValueError::new_err(format!(
                    "guess coefficients: need shape (n + 2, 2 N + 1) = ({d}, odd), got {} values",
                    c.len()
                )));
            }
            if !(w.is_finite() && w > 0.0) || c.iter().any(|v| !v.is_finite()) {
                return Err(PyValueError::new_err(
                    "guess: omega must be > 0 and every coefficient finite",
                ));
            }
            let mut winding = vec![0.0; d];
            for (i, &r) in rotating.iter().enumerate() {
                winding[2 + i] = if r { -1.0 } else { 0.0 };
            }
            let nh = (c.len() / d - 1) / 2;
            Some(HbSolution::start(w, c, winding, nh, Status::NoGuess))
        }
        (None, None) => None,
        _ => {
            return Err(PyValueError::new_err(
                "guess: give both omega and coefficients, or neither",
            ))
        }
    };
    let r = guarded(py, || {
        Ok(core_periodic(&p, &rotating, guess.as_ref(), &opts))
    })?;
    solution_dict(py, r)
}

/// The "NI" check: max distance after one simulated period from the orbit's own state.
#[pyfunction]
#[pyo3(signature = (mu, zeta, zeta_b, delta, omega, eta, sol_omega, coeffs, winding, rtol, atol))]
#[allow(clippy::too_many_arguments)]
fn orbit_closure(
    py: Python<'_>,
    mu: f64,
    zeta: f64,
    zeta_b: Vec<f64>,
    delta: f64,
    omega: f64,
    eta: Vec<f64>,
    sol_omega: f64,
    coeffs: PyReadonlyArray1<'_, f64>,
    winding: Vec<f64>,
    rtol: f64,
    atol: f64,
) -> PyResult<f64> {
    let p = planar(mu, zeta, zeta_b, delta, omega, eta)?;
    let c = slice(&coeffs, "coeffs")?.to_vec();
    let d = winding.len();
    if d == 0 || c.len() % d != 0 || (c.len() / d) % 2 != 1 {
        return Err(PyValueError::new_err(
            "coeffs: need (n + 2) x (2 N + 1) values",
        ));
    }
    let n_harm = (c.len() / d - 1) / 2;
    let sol = HbSolution::start(sol_omega, c, winding, n_harm, Status::Converged);
    guarded(py, || closure_error(&p, &sol, rtol, atol))
}

/// Parallel two-parameter scan; returns a dict of flat columns (one entry per row).
#[pyfunction]
#[pyo3(signature = (mu, zeta, zeta_b, delta, omega, eta, names, values0, values1, patterns,
                    n_harm, samples, tol, step_tol, max_iter, floquet, f_rtol, f_atol, margin,
                    settle, window, threads))]
#[allow(clippy::too_many_arguments)]
fn scan<'py>(
    py: Python<'py>,
    mu: f64,
    zeta: f64,
    zeta_b: Vec<f64>,
    delta: f64,
    omega: f64,
    eta: Vec<f64>,
    names: (String, String),
    values0: Vec<f64>,
    values1: Vec<f64>,
    patterns: Vec<String>,
    n_harm: usize,
    samples: Option<usize>,
    tol: f64,
    step_tol: f64,
    max_iter: usize,
    floquet: bool,
    f_rtol: f64,
    f_atol: f64,
    margin: f64,
    settle: f64,
    window: f64,
    threads: usize,
) -> PyResult<Bound<'py, PyDict>> {
    use ballbal_core::scan::{scan as core_scan, ScanSpec};
    let p = planar(mu, zeta, zeta_b, delta, omega, eta)?;
    let rots = patterns
        .iter()
        .map(|s| parse_pattern(s, p.n_balls()))
        .collect::<Result<Vec<_>, _>>()
        .map_err(to_py)?;
    if rots.is_empty() {
        return Err(PyValueError::new_err(
            "patterns: give at least one solution type",
        ));
    }
    let opts = periodic_options(
        n_harm, samples, tol, step_tol, max_iter, floquet, f_rtol, f_atol, margin, settle, window,
    )?;
    let rows = guarded(py, || {
        core_scan(&ScanSpec {
            base: &p,
            names: [&names.0, &names.1],
            values: [&values0, &values1],
            patterns: &rots,
            opts,
            threads,
        })
    })?;
    let d = PyDict::new(py);
    let n = rows.len();
    let c = |name: &str, v: Vec<f64>| d.set_item(name, PyArray1::from_vec(py, v));
    c(&names.0, rows.iter().map(|r| values0[r.i]).collect())?;
    c(&names.1, rows.iter().map(|r| values1[r.j]).collect())?;
    fn conv(r: &ballbal_core::scan::ScanRow) -> Option<&ballbal_core::periodic::Periodic> {
        r.result
            .as_ref()
            .filter(|x| x.sol.status == Status::Converged)
    }
    // A float column of converged rows, NaN elsewhere (Python turns NaN into null).
    let per_row = |f: &dyn Fn(&ballbal_core::periodic::Periodic) -> Option<f64>| -> Vec<f64> {
        rows.iter()
            .map(|r| conv(r).and_then(f).unwrap_or(f64::NAN))
            .collect()
    };
    c("omega", per_row(&|x| Some(x.sol.omega)))?;
    c("residual", per_row(&|x| Some(x.sol.residual)))?;
    c("iterations", per_row(&|x| Some(x.sol.iterations as f64)))?;
    c("seconds", rows.iter().map(|r| r.seconds).collect())?;
    c(
        "max_modulus",
        per_row(&|x| x.floquet.as_ref().map(|f| f.max_modulus)),
    )?;
    c(
        "trivial_error",
        per_row(&|x| x.floquet.as_ref().map(|f| f.trivial_error)),
    )?;
    let mults: Vec<(Vec<f64>, Vec<f64>)> = rows
        .iter()
        .map(|r| match conv(r).and_then(|x| x.floquet.as_ref()) {
            Some(f) => (
                f.multipliers.iter().map(|z| z.0).collect(),
                f.multipliers.iter().map(|z| z.1).collect(),
            ),
            None => (vec![], vec![]),
        })
        .collect();
    d.set_item(
        "mult_re",
        mults.iter().map(|m| m.0.clone()).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "mult_im",
        mults.iter().map(|m| m.1.clone()).collect::<Vec<_>>(),
    )?;
    let strs = |f: &dyn Fn(&ballbal_core::scan::ScanRow) -> String| {
        rows.iter().map(f).collect::<Vec<String>>()
    };
    d.set_item("type", strs(&|r| patterns[r.pattern].clone()))?;
    d.set_item(
        "status",
        strs(&|r| match &r.result {
            Some(x) => x.sol.status.as_str().to_string(),
            None => "no_solution".to_string(),
        }),
    )?;
    d.set_item(
        "stability",
        strs(&|r| {
            conv(r)
                .and_then(|x| x.floquet.as_ref())
                .map_or("undetermined", |f| f.stability.as_str())
                .to_string()
        }),
    )?;
    d.set_item("origin", strs(&|r| r.origin.to_string()))?;
    d.set_item(
        "pb_exists",
        rows.iter().map(|r| r.pb_exists).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "pb_stable",
        rows.iter().map(|r| r.pb_stable).collect::<Vec<_>>(),
    )?;
    d.set_item("N", n_harm)?;
    d.set_item("rows", n)?;
    Ok(d)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(equilibria, m)?)?;
    m.add_function(wrap_pyfunction!(periodic, m)?)?;
    m.add_function(wrap_pyfunction!(orbit_closure, m)?)?;
    m.add_function(wrap_pyfunction!(scan, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
