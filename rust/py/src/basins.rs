//! Basins of attraction: the entry points of `ballbal.basins`.

use crate::convert::{dispatch, slice, ModelArgs};
use crate::errors::{not_autonomous, CoreResult};
use crate::run::{guarded, run_polled};
use ballbal_core::analysis::attractors::{classify, guess_with_turns, Attractor, GuessOptions};
use ballbal_core::analysis::basins::{basin_starts, BasinOptions, Outcome};
use ballbal_core::periodic::require_autonomous;
use ballbal_core::{cancel, Dynamics, Error};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `ballbal.basins.BasinOptions`.
#[derive(FromPyObject)]
pub struct BasinArgs {
    t_end: f64,
    window: f64,
    rtol: f64,
    atol: f64,
    rest_tol: f64,
    merge_tol: f64,
    settle_factor: Option<f64>,
    early_stop: bool,
    extend_factor: f64,
}

impl BasinArgs {
    pub fn to_core(&self) -> BasinOptions {
        BasinOptions {
            t_end: self.t_end,
            window: self.window,
            rtol: self.rtol,
            atol: self.atol,
            rest_tol: self.rest_tol,
            merge_tol: self.merge_tol,
            settle_factor: self.settle_factor,
            early_stop: self.early_stop,
            extend_factor: self.extend_factor,
        }
    }
}

fn build(model: &ModelArgs) -> PyResult<crate::convert::Model> {
    let m = model.build(false).py()?;
    if let crate::convert::Model::Scene(s) = &m {
        require_autonomous(s).map_err(|e| not_autonomous(e, "basins"))?;
    }
    Ok(m)
}

/// Columns of one chunk of outcomes.
fn columns<'py>(py: Python<'py>, rows: &[Outcome], n: usize) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(
        "label",
        rows.iter().map(|r| r.label.as_str()).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "pattern",
        rows.iter().map(|r| r.pattern.clone()).collect::<Vec<_>>(),
    )?;
    d.set_item("omega", rows.iter().map(|r| r.omega).collect::<Vec<_>>())?;
    d.set_item("period", rows.iter().map(|r| r.period).collect::<Vec<_>>())?;
    d.set_item("t_stop", rows.iter().map(|r| r.t_stop).collect::<Vec<_>>())?;
    d.set_item(
        "motion",
        rows.iter().map(|r| r.motion()).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "extensions",
        rows.iter().map(|r| r.extensions).collect::<Vec<_>>(),
    )?;
    // The state reached: where a class's orbit is fitted from.
    d.set_item(
        "state",
        rows.iter().map(|r| r.y_end.clone()).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "long_label",
        rows.iter()
            .map(|r| r.long_label.map(|l| l.as_str()))
            .collect::<Vec<_>>(),
    )?;
    for i in 0..n {
        d.set_item(
            format!("rate{}", i + 1),
            rows.iter().map(|r| r.rates[i]).collect::<Vec<_>>(),
        )?;
        d.set_item(
            format!("winding{}", i + 1),
            rows.iter()
                .map(|r| r.windings.get(i).copied())
                .collect::<Vec<_>>(),
        )?;
    }
    Ok(d)
}

/// Classifies the starts `starts[c * chunk .. (c + 1) * chunk]` of every chunk `c` in
/// `chunks` on `threads` threads (each start on its own: the labels do not depend on
/// the thread count) and calls `on_chunk(c, columns)` with the GIL as each chunk
/// finishes. Ctrl-C cancels the work and raises `KeyboardInterrupt`; chunks finished
/// before are handed over.
#[allow(
    clippy::too_many_arguments,
    reason = "a #[pyfunction]'s arguments are the Python call's keywords"
)]
#[pyfunction]
#[pyo3(signature = (model, starts, options, threads, chunk, chunks, on_chunk))]
pub fn basins(
    py: Python<'_>,
    model: ModelArgs,
    starts: Vec<Vec<f64>>,
    options: BasinArgs,
    threads: usize,
    chunk: usize,
    chunks: Vec<usize>,
    on_chunk: Bound<'_, PyAny>,
) -> PyResult<()> {
    use rayon::prelude::*;
    let m = build(&model)?;
    let opts = options.to_core();
    opts.validate().py()?;
    if chunk == 0 {
        return Err(Error::param("chunk", "must be >= 1")).py();
    }
    let n = m.n_balls();
    // Checks every start before any work (an empty slice checks nothing).
    dispatch!(&m, d => {
        let probe = BasinOptions { t_end: 1e-9, window: 1e-9, ..opts.clone() };
        let bad = starts.iter().find(|s| s.len() != n || s.iter().any(|v| !v.is_finite()));
        if let Some(b) = bad {
            basin_starts(d, std::slice::from_ref(b), &probe).py()?;
        }
    });
    let total = starts.len().div_ceil(chunk);
    if let Some(&c) = chunks.iter().find(|&&c| c >= total) {
        return Err(Error::param(
            "chunks",
            format!("chunk {c} is out of range 0..{total}"),
        ))
        .py();
    }
    run_polled(
        py,
        |tok, tx: &std::sync::mpsc::Sender<(usize, Vec<Outcome>)>| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map_err(|e| Error::param("threads", e.to_string()))?;
            let tx = std::sync::Mutex::new(tx.clone());
            pool.install(|| {
                chunks.par_iter().try_for_each(|&c| {
                    let part = &starts[c * chunk..((c + 1) * chunk).min(starts.len())];
                    // rayon's threads do not inherit the token: hand it on.
                    let rows = cancel::with(
                        Some(tok.clone()),
                        || dispatch!(&m, d => basin_starts(d, part, &opts)),
                    )?;
                    let _ = tx.lock().expect("sender lock").send((c, rows));
                    Ok(())
                })
            })
        },
        |(c, rows)| {
            let d = columns(py, &rows, n)?;
            on_chunk.call1((c, d)).map(|_| ())
        },
    )
}

/// `(omega, coefficients, rotating)` of a fitted attractor.
type Series<'py> = (f64, Bound<'py, PyArray1<f64>>, Vec<bool>);

/// The series of the attractor reached from `y0` (settle for `settle`, then observe for
/// up to `window`: `attractors::classify`), as `(omega, coefficients, rotating)`, or
/// `None` when the motion is not periodic. A harmonic-balance start for the solution a
/// basin class converges to. With `rotating` (which balls rotate) the period is
/// measured over `turns` whole turns of the first rotating ball
/// (`attractors::guess_with_turns`: an orbit of several turns per period).
#[allow(
    clippy::too_many_arguments,
    reason = "a #[pyfunction]'s arguments are the Python call's keywords"
)]
#[pyfunction]
#[pyo3(signature = (model, y0, n_harm, settle, window, rtol, atol, rotating=None, turns=1))]
pub fn attractor_series<'py>(
    py: Python<'py>,
    model: ModelArgs,
    y0: PyReadonlyArray1<'py, f64>,
    n_harm: usize,
    settle: f64,
    window: f64,
    rtol: f64,
    atol: f64,
    rotating: Option<Vec<bool>>,
    turns: usize,
) -> PyResult<Option<Series<'py>>> {
    let m = build(&model)?;
    let y0 = slice(&y0, "y0")?.to_vec();
    let g = GuessOptions {
        settle,
        window,
        rtol,
        atol,
    };
    g.validate().py()?;
    if n_harm == 0 {
        return Err(Error::param("N", "must be >= 1")).py();
    }
    let dim = dispatch!(&m, d => 2 * d.ndof());
    if y0.len() != dim || y0.iter().any(|v| !v.is_finite()) {
        return Err(Error::param("y0", format!("needs {dim} finite values"))).py();
    }
    let n = dispatch!(&m, d => d.ndof() - d.first_ball());
    if let Some(r) = &rotating {
        if r.len() != n {
            return Err(Error::param(
                "rotating",
                format!("needs {n} values, got {}", r.len()),
            ))
            .py();
        }
    }
    if !(1..=16).contains(&turns) {
        return Err(Error::param(
            "turns",
            format!("must be in [1, 16], got {turns}"),
        ))
        .py();
    }
    if let Some(r) = rotating {
        let s = guarded(py, || {
            Ok(dispatch!(&m, d => guess_with_turns(d, &y0, &r, turns, n_harm, &g)))
        })?;
        return Ok(s.map(|s| (s.omega, PyArray1::from_vec(py, s.coeffs.clone()), r)));
    }
    let a = guarded(py, || Ok(dispatch!(&m, d => classify(d, &y0, n_harm, &g))))?;
    Ok(match a {
        Attractor::Periodic {
            rotating, series, ..
        } => Some((
            series.omega,
            PyArray1::from_vec(py, series.coeffs.clone()),
            rotating,
        )),
        _ => None,
    })
}

/// Classifies the motion from the state `y0` (simulated for `options.t_end`) as
/// `basins` does, without stopping early; returns `(columns of one row, the state reached)`.
#[pyfunction]
pub fn classify_state<'py>(
    py: Python<'py>,
    model: ModelArgs,
    y0: PyReadonlyArray1<'py, f64>,
    options: BasinArgs,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyArray1<f64>>)> {
    let m = build(&model)?;
    // A sweep carries the state after the whole dwell on to its next step.
    let opts = BasinOptions {
        early_stop: false,
        extend_factor: 1.0,
        ..options.to_core()
    };
    opts.validate().py()?;
    let y0 = slice(&y0, "y0")?.to_vec();
    let dim = dispatch!(&m, d => 2 * d.ndof());
    if y0.len() != dim || y0.iter().any(|v| !v.is_finite()) {
        return Err(Error::param("y0", format!("needs {dim} finite values"))).py();
    }
    let mut out = guarded(
        py,
        || dispatch!(&m, d => ballbal_core::analysis::basins::classify_start(d, &y0, &opts)),
    )?;
    let y = std::mem::take(&mut out.y_end);
    let cols = columns(py, std::slice::from_ref(&out), m.n_balls())?;
    Ok((cols, PyArray1::from_vec(py, y)))
}

/// Adds this file's functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(basins, m)?)?;
    m.add_function(wrap_pyfunction!(attractor_series, m)?)?;
    m.add_function(wrap_pyfunction!(classify_state, m)?)?;
    Ok(())
}
