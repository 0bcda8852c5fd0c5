//! Thin pyo3 binding over `ballbal-core`. Every entry point releases the GIL around the
//! numerical work and turns core errors into `ValueError`; a Rust panic is caught and
//! raised as `RuntimeError` so that it never unwinds into Python.

use ballbal_core::equilibria::{equilibria as core_equilibria, Equilibrium};
use ballbal_core::floquet::{FloquetOptions, MAX_TRIVIAL};
use ballbal_core::hb::{HbOptions, HbSolution, Status};
use ballbal_core::ode::Options;
use ballbal_core::periodic::{
    closure_error, parse_pattern, pattern_string, periodic as core_periodic, require_autonomous,
    PeriodicOptions, MAX_CLOSURE, MAX_TAIL,
};
use ballbal_core::simulate::simulate as core_simulate;
use ballbal_core::{cancel, Dynamics, Error, Planar, Scene, SpringLayout};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The one place where core errors become Python exceptions: the classes of
/// `ballbal.exceptions`, with their fields (`.parameter`, `.allowed`, `.effect`).
fn to_py(e: Error) -> PyErr {
    Python::attach(|py| {
        let text = e.to_string();
        let made = (|| -> PyResult<PyErr> {
            let m = py.import("ballbal.exceptions")?;
            let obj = match e {
                Error::InvalidParameter {
                    name,
                    message,
                    allowed,
                } => {
                    let kw = PyDict::new(py);
                    kw.set_item("allowed", allowed)?;
                    m.getattr("ParameterError")?
                        .call((name, message), Some(&kw))?
                }
                Error::NotAutonomous { effect } => {
                    m.getattr("NotAutonomousError")?.call1((effect,))?
                }
                Error::Integration(_) => m.getattr("IntegrationError")?.call1((text.clone(),))?,
                Error::Stiff(_) => m.getattr("StiffError")?.call1((text.clone(),))?,
                Error::Eigen(_) => m.getattr("EigenSolverError")?.call1((text.clone(),))?,
                Error::Cancelled => {
                    return Ok(pyo3::exceptions::PyKeyboardInterrupt::new_err("cancelled"))
                }
            };
            Ok(PyErr::from_value(obj))
        })();
        // Only if the exceptions module itself cannot be imported (a broken install).
        made.unwrap_or_else(|_| PyRuntimeError::new_err(text))
    })
}

/// How often an entry point waiting for the core looks for Ctrl-C (and other signals).
const POLL: std::time::Duration = std::time::Duration::from_millis(50);

/// Runs `f` without the GIL, with panics contained (as `InternalError`) and with Ctrl-C
/// working: see [`run_polled`]. A cancelled call raises `KeyboardInterrupt` and its
/// partial result is dropped.
fn guarded<T: Send, F: FnOnce() -> Result<T, Error> + Send>(py: Python<'_>, f: F) -> PyResult<T> {
    run_polled(
        py,
        |tok, _: &std::sync::mpsc::Sender<()>| cancel::with(Some(tok.clone()), f),
        |()| Ok(()),
    )
}

/// The one way the binding runs core work: `work` runs on a worker thread (given a
/// cancellation token and a channel), while this thread, without the GIL, waits and
/// checks for signals every [`POLL`] (only the main thread sees them) and hands every
/// message the work sends to `on_msg` with the GIL. A signal's exception (Ctrl-C's
/// `KeyboardInterrupt`), or `on_msg`'s first error, cancels the token; the core's long
/// loops notice it within milliseconds, and that exception is raised once the worker
/// has stopped. A panic in the work becomes `InternalError`.
fn run_polled<T, M, W, H>(py: Python<'_>, work: W, mut on_msg: H) -> PyResult<T>
where
    T: Send,
    M: Send,
    W: FnOnce(&cancel::Token, &std::sync::mpsc::Sender<M>) -> Result<T, Error> + Send,
    H: FnMut(M) -> PyResult<()>,
{
    use std::sync::mpsc;
    let token = cancel::Token::new();
    let (tx, rx) = mpsc::channel::<M>();
    // `detach` needs a `Sync` capture; the receiver is only used from this thread.
    let rx = std::sync::Mutex::new(rx);
    let mut pending: Option<PyErr> = None;
    let worker = std::thread::scope(|s| {
        let tok = &token;
        // The calling thread's stack size: the core was written for it.
        let handle = std::thread::Builder::new()
            .name("ballbal-core".into())
            .stack_size(8 << 20)
            .spawn_scoped(s, move || {
                let tx = tx;
                catch_unwind(AssertUnwindSafe(|| work(tok, &tx)))
            });
        let handle = match handle {
            Ok(h) => h,
            Err(e) => {
                return Err(PyRuntimeError::new_err(format!(
                    "could not start a worker thread: {e}"
                )))
            }
        };
        loop {
            let msg = py.detach(|| rx.lock().expect("receiver lock").recv_timeout(POLL));
            match msg {
                // Messages that arrive after a cancellation are still handed over
                // (a scan's chunks that finish are stored).
                Ok(m) => {
                    if let Err(e) = on_msg(m) {
                        if pending.is_none() {
                            token.cancel();
                            pending = Some(e);
                        }
                    }
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if pending.is_none() {
                        if let Err(e) = py.check_signals() {
                            token.cancel();
                            pending = Some(e);
                        }
                    }
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            }
        }
        Ok(py.detach(|| handle.join()))
    })?;
    if let Some(e) = pending {
        return Err(e);
    }
    match worker {
        Ok(Ok(r)) => r.map_err(to_py),
        Ok(Err(p)) | Err(p) => Err(panic_error(p)),
    }
}

fn panic_error(p: Box<dyn std::any::Any + Send>) -> PyErr {
    let msg = p
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_else(|| "unknown".into());
    let text = format!("internal error in ballbal core (please report): {msg}");
    Python::attach(|py| {
        py.import("ballbal.exceptions")
            .and_then(|m| m.getattr("InternalError"))
            .and_then(|c| c.call1((text.clone(),)))
            .map(PyErr::from_value)
            .unwrap_or_else(|_| PyRuntimeError::new_err(text))
    })
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

/// Effects of a scene: `(springs, ramp (to, start, duration), gravity, impulse
/// (amplitude, t0, sharpness, angle), tilt (a, b, j_t, j_z, zeta_r), spring chain)`;
/// `None` for the plain planar balancer.
type Effects = Option<(
    f64,
    Option<(f64, f64, f64)>,
    f64,
    Option<(f64, f64, f64, f64)>,
    Option<(f64, f64, f64, f64, f64)>,
    bool,
)>;

fn scene(p: &Planar, effects: Effects) -> PyResult<Option<Scene>> {
    use ballbal_core::model::scene::{Impulse, Ramp, Tilt};
    let Some((springs, ramp, gravity, impulse, tilt, chain)) = effects else {
        return Ok(None);
    };
    Scene::new(
        p.clone(),
        springs,
        ramp.map(|(to, start, duration)| Ramp {
            to,
            start,
            duration,
        }),
        gravity,
        impulse.map(|(amplitude, t0, sharpness, angle)| Impulse {
            amplitude,
            t0,
            sharpness,
            angle,
        }),
        tilt.map(|(a, b, j_t, j_z, zeta_r)| Tilt {
            a,
            b,
            j_t,
            j_z,
            zeta_r,
        }),
    )
    .map(|s| {
        Some(s.with_spring_layout(if chain {
            SpringLayout::Chain
        } else {
            SpringLayout::Ring
        }))
    })
    .map_err(to_py)
}

/// Analyses other than simulation need an autonomous scene.
fn autonomous_scene(p: &Planar, effects: Effects, what: &str) -> PyResult<Option<Scene>> {
    let s = scene(p, effects)?;
    if let Some(sc) = &s {
        require_autonomous(sc).map_err(|e| not_autonomous(e, what))?;
    }
    Ok(s)
}

/// `NotAutonomousError` with the analysis named in its message.
fn not_autonomous(e: Error, what: &str) -> PyErr {
    match e {
        Error::NotAutonomous { effect } => Python::attach(|py| {
            let msg = format!(
                "{what}: {}",
                Error::NotAutonomous {
                    effect: effect.clone()
                }
            );
            py.import("ballbal.exceptions")
                .and_then(|m| m.getattr("NotAutonomousError"))
                .and_then(|c| c.call1((effect, msg.clone())))
                .map(PyErr::from_value)
                .unwrap_or_else(|_| PyValueError::new_err(msg))
        }),
        e => to_py(e),
    }
}

fn slice<'a>(a: &'a PyReadonlyArray1<'_, f64>, name: &str) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|_| to_py(Error::param(name, "must be a contiguous float64 array")))
}

/// `(y, theta, accepted_steps, rejected_steps, rhs_evals)` of [`simulate`].
type Simulated<'py> = (
    Bound<'py, PyAny>,
    Bound<'py, PyArray1<f64>>,
    usize,
    usize,
    usize,
);

/// Integrates from `y0` and returns `(y, theta, accepted_steps, rejected_steps,
/// rhs_evals)`, `y` of shape `(len(t_eval), 2 d)`, `theta` the disk's angle at `t_eval`.
#[pyfunction]
#[pyo3(signature = (mu, zeta, zeta_b, delta, omega, eta, y0, t0, t_eval, rtol, atol, effects=None,
                    max_steps=10_000_000))]
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
    effects: Effects,
    max_steps: usize,
) -> PyResult<Simulated<'py>> {
    let p = planar(mu, zeta, zeta_b, delta, omega, eta)?;
    let sc = scene(&p, effects)?;
    let y0 = slice(&y0, "y0")?.to_vec();
    let te = slice(&t_eval, "t_eval")?.to_vec();
    let opts = Options {
        rtol,
        atol,
        max_steps,
        ..Default::default()
    };
    let traj = guarded(py, || match &sc {
        None => core_simulate(&p, &y0, t0, &te, &opts),
        Some(sc) => core_simulate(sc, &y0, t0, &te, &opts),
    })?;
    let cols = y0.len();
    let flat: Vec<f64> = traj.y.into_iter().flatten().collect();
    let arr = PyArray1::from_vec(py, flat).reshape([te.len(), cols])?;
    let theta: Vec<f64> = te
        .iter()
        .map(|&t| match &sc {
            Some(s) => s.spin(t).2,
            None => p.omega_s * t,
        })
        .collect();
    Ok((
        arr.into_any(),
        PyArray1::from_vec(py, theta),
        traj.stats.accepted,
        traj.stats.rejected,
        traj.stats.rhs_evals,
    ))
}

/// Checks the parameters (and effects) the way the core's constructors do, and nothing
/// more: cheap, unlike an analysis (`Balancer.validate()` used to run the whole
/// equilibrium search).
#[pyfunction]
#[pyo3(signature = (mu, zeta, zeta_b, delta, omega, eta, effects=None))]
fn validate(
    mu: f64,
    zeta: f64,
    zeta_b: Vec<f64>,
    delta: f64,
    omega: f64,
    eta: Vec<f64>,
    effects: Effects,
) -> PyResult<()> {
    let p = planar(mu, zeta, zeta_b, delta, omega, eta)?;
    scene(&p, effects).map(|_| ())
}

/// All equilibria with their stability, as a list of dicts.
#[pyfunction]
#[pyo3(signature = (mu, zeta, zeta_b, delta, omega, eta, effects=None))]
#[allow(clippy::too_many_arguments)]
fn equilibria<'py>(
    py: Python<'py>,
    mu: f64,
    zeta: f64,
    zeta_b: Vec<f64>,
    delta: f64,
    omega: f64,
    eta: Vec<f64>,
    effects: Effects,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let p = planar(mu, zeta, zeta_b, delta, omega, eta)?;
    let sc = autonomous_scene(&p, effects, "equilibria")?;
    let eqs = guarded(py, || {
        Ok(match &sc {
            Some(s) => ballbal_core::analysis::balanced::scene_equilibria(s),
            None => core_equilibria(&p),
        })
    })?;
    eqs.into_iter().map(|e| equilibrium_dict(py, e)).collect()
}

/// The balanced state of each scene (planar parameters, effects), in parallel: a dict
/// like `equilibria`'s, or `None` where the balls cannot balance the disk.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn balanced_states<'py>(
    py: Python<'py>,
    points: Vec<((f64, f64, Vec<f64>, f64, f64, Vec<f64>), Effects)>,
) -> PyResult<Vec<Option<Bound<'py, PyDict>>>> {
    use rayon::prelude::*;
    let mut scenes = Vec::with_capacity(points.len());
    for ((mu, zeta, zeta_b, delta, omega, eta), effects) in points {
        let p = planar(mu, zeta, zeta_b, delta, omega, eta)?;
        let sc = match scene(&p, effects)? {
            Some(s) => s,
            None => Scene::new(p, 0.0, None, 0.0, None, None).map_err(to_py)?,
        };
        require_autonomous(&sc).map_err(|e| not_autonomous(e, "balanced_state"))?;
        scenes.push(sc);
    }
    // Each point is solved on its own from the planar perfect balance, so the result
    // does not depend on the thread count.
    let eqs = guarded(py, || {
        // rayon's threads do not inherit the cancellation token: hand it on.
        let tok = cancel::current();
        Ok(scenes
            .par_iter()
            .map(|s| {
                // Each point is short: stop between points once cancelled.
                cancel::with(tok.clone(), || {
                    (!cancel::cancelled())
                        .then(|| ballbal_core::analysis::balanced::balanced_state(s))
                        .flatten()
                })
            })
            .collect::<Vec<_>>())
    })?;
    eqs.into_iter()
        .map(|e| e.map(|e| equilibrium_dict(py, e)).transpose())
        .collect()
}

fn equilibrium_dict(py: Python<'_>, e: Equilibrium) -> PyResult<Bound<'_, PyDict>> {
    {
        let d = PyDict::new(py);
        d.set_item("kind", e.kind.as_str())?;
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
        d.set_item("exhaustive", e.exhaustive)?;
        Ok(d)
    }
}

fn solution_dict<'py>(
    py: Python<'py>,
    r: ballbal_core::periodic::Periodic,
    n_balls: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("target_met", r.target_met)?;
    d.set_item("verdicts_disagree", r.verdicts_disagree())?;
    if let Some((m, st)) = &r.hill {
        d.set_item(
            "hill_re",
            PyArray1::from_vec(py, m.iter().map(|z| z.0).collect()),
        )?;
        d.set_item(
            "hill_im",
            PyArray1::from_vec(py, m.iter().map(|z| z.1).collect()),
        )?;
        d.set_item("hill_stability", st.as_str())?;
    }
    d.set_item("closure", r.closure)?;
    d.set_item(
        "separation_error",
        r.floquet.as_ref().and_then(|f| f.separation_error),
    )?;
    let s = r.sol;
    d.set_item("tail", s.tail_ratio())?;
    // A series that converged but failed a certificate keeps its omega for inspection;
    // its status says why it is not a result.
    let ok = matches!(
        s.status,
        Status::Converged | Status::NotClosed | Status::Truncated
    );
    d.set_item("status", s.status.as_str())?;
    d.set_item("type", pattern_string(&s.winding, n_balls))?;
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

/// Solver options shared by `periodic` and `scan`, validated (in the core) before any
/// work starts; errors name the option.
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
    max_steps: usize,
    settle: f64,
    window: f64,
    guess_rtol: f64,
    guess_atol: f64,
    auto: Option<f64>,
    n_max: usize,
    hill: bool,
    max_closure: f64,
    max_trivial: f64,
    max_tail: f64,
) -> PyResult<PeriodicOptions> {
    let fo = FloquetOptions {
        rtol: f_rtol,
        atol: f_atol,
        margin,
        max_steps,
        max_trivial,
    };
    // Checked even with the Floquet analysis off: a bad value is a mistake either way.
    fo.validate().map_err(to_py)?;
    let opts = PeriodicOptions {
        auto: auto.map(|target| ballbal_core::periodic::AutoHarmonics { target, n_max }),
        hill,
        hb: HbOptions {
            n_harm,
            samples,
            tol,
            step_tol,
            max_iter,
        },
        floquet: floquet.then_some(fo),
        guess: ballbal_core::periodic::GuessOptions {
            settle,
            window,
            rtol: guess_rtol,
            atol: guess_atol,
        },
        max_closure,
        max_tail,
    };
    opts.validate().map_err(to_py)?;
    Ok(opts)
}

/// Periodic solution of the given pattern by Newton–IHB, with Floquet multipliers.
#[pyfunction]
#[pyo3(signature = (mu, zeta, zeta_b, delta, omega, eta, pattern, n_harm, samples, tol, step_tol, max_iter,
                    guess_omega, guess_coeffs, floquet, f_rtol, f_atol, margin, max_steps, settle,
                    window, guess_rtol, auto, n_max, hill, max_closure=MAX_CLOSURE,
                    max_trivial=MAX_TRIVIAL, max_tail=MAX_TAIL, effects=None))]
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
    max_steps: usize,
    settle: f64,
    window: f64,
    guess_rtol: f64,
    auto: Option<f64>,
    n_max: usize,
    hill: bool,
    max_closure: f64,
    max_trivial: f64,
    max_tail: f64,
    effects: Effects,
) -> PyResult<Bound<'py, PyDict>> {
    let p = planar(mu, zeta, zeta_b, delta, omega, eta)?;
    let sc = autonomous_scene(&p, effects, "periodic")?;
    let rotating = parse_pattern(pattern, p.n_balls()).map_err(to_py)?;
    let opts = periodic_options(
        n_harm,
        samples,
        tol,
        step_tol,
        max_iter,
        floquet,
        f_rtol,
        f_atol,
        margin,
        max_steps,
        settle,
        window,
        guess_rtol,
        guess_rtol * 1e-2,
        auto,
        n_max,
        hill,
        max_closure,
        max_trivial,
        max_tail,
    )?;
    let (d, o) = match &sc {
        Some(s) => (s.ndof(), s.first_ball()),
        None => (p.ndof(), 2),
    };
    let guess = match (guess_omega, guess_coeffs) {
        (Some(w), Some(c)) => {
            let c = slice(&c, "guess coefficients")?.to_vec();
            if c.len() % d != 0 || (c.len() / d) % 2 != 1 {
                return Err(PyValueError::new_err(format!(
                    "guess coefficients: need shape (coordinates, 2 N + 1) = ({d}, odd), got {} values",
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
                winding[o + i] = if r { -1.0 } else { 0.0 };
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
        Ok(match &sc {
            None => {
                stiff_guess(&p, guess.is_none(), &opts)?;
                core_periodic(&p, &rotating, guess.as_ref(), &opts)
            }
            Some(sc) => {
                stiff_guess(sc, guess.is_none(), &opts)?;
                core_periodic(sc, &rotating, guess.as_ref(), &opts)
            }
        })
    })?;
    solution_dict(py, r, p.n_balls())
}

/// `Err(Stiff)` when the guess simulations would be too stiff for the explicit
/// integrator: the core counts a failed guess simulation as "no guess", which would hide
/// the reason (after minutes, at these parameters).
fn stiff_guess<D: Dynamics>(m: &D, simulates: bool, opts: &PeriodicOptions) -> Result<(), Error> {
    if !simulates {
        return Ok(());
    }
    let Some(y0) = ballbal_core::periodic::initial_states(m).into_iter().next() else {
        return Ok(());
    };
    ballbal_core::ode::probe_stiffness(
        |t, y, dy| ballbal_core::model::first_order_rhs(m, t, y, dy),
        0.0,
        &y0,
        opts.guess.settle,
        &Options::new(opts.guess.rtol, opts.guess.atol),
        // Stiffness from the parameters shows within the first few dozen steps; more
        // would cost a normal call milliseconds (the whole settle time).
        300,
    )
}

/// The "NI" check: max distance after one simulated period from the orbit's own state.
#[pyfunction]
#[pyo3(signature = (mu, zeta, zeta_b, delta, omega, eta, sol_omega, coeffs, winding, rtol, atol,
                    effects=None))]
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
    effects: Effects,
) -> PyResult<f64> {
    let p = planar(mu, zeta, zeta_b, delta, omega, eta)?;
    let sc = scene(&p, effects)?;
    let c = slice(&coeffs, "coeffs")?.to_vec();
    let d = winding.len();
    if d == 0 || c.len() % d != 0 || (c.len() / d) % 2 != 1 {
        return Err(to_py(Error::param(
            "coeffs",
            format!(
                "need {d} x (2 N + 1) values (one row per coordinate), got {}",
                c.len()
            ),
        )));
    }
    let n_harm = (c.len() / d - 1) / 2;
    let sol = HbSolution::start(sol_omega, c, winding, n_harm, Status::Converged);
    guarded(py, || match &sc {
        None => closure_error(&p, &sol, rtol, atol),
        Some(sc) => closure_error(sc, &sol, rtol, atol),
    })
}

/// Parallel scan of a parameter grid, chunk by chunk. `on_chunk(index, columns)` is
/// called (with the GIL, in this thread) for every finished chunk as soon as it is done;
/// Ctrl-C cancels the remaining work, hands over the chunks that still finish, and then
/// raises `KeyboardInterrupt`.
#[pyfunction]
#[pyo3(signature = (mu, zeta, zeta_b, delta, omega, eta, names, values, patterns,
                    n_harm, samples, tol, step_tol, max_iter, floquet, f_rtol, f_atol, margin,
                    max_steps, settle, window, guess_rtol, auto, n_max, hill, seeds, starts,
                    chunk, max_tail, threads, chunks, on_chunk, effects=None, block=None,
                    max_closure=MAX_CLOSURE, max_trivial=MAX_TRIVIAL))]
#[allow(clippy::too_many_arguments)]
fn scan(
    py: Python<'_>,
    mu: f64,
    zeta: f64,
    zeta_b: Vec<f64>,
    delta: f64,
    omega: f64,
    eta: Vec<f64>,
    names: Vec<String>,
    values: Vec<Vec<f64>>,
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
    max_steps: usize,
    settle: f64,
    window: f64,
    guess_rtol: f64,
    auto: Option<f64>,
    n_max: usize,
    hill: bool,
    seeds: usize,
    starts: usize,
    chunk: usize,
    max_tail: f64,
    threads: usize,
    chunks: Vec<usize>,
    on_chunk: Bound<'_, PyAny>,
    effects: Effects,
    block: Option<usize>,
    max_closure: f64,
    max_trivial: f64,
) -> PyResult<()> {
    use ballbal_core::scan::ScanSpec;
    let lens: Vec<usize> = values.iter().map(Vec::len).collect();
    let block = block.unwrap_or_else(|| ballbal_core::scan::default_chunk(&lens));
    let p = planar(mu, zeta, zeta_b, delta, omega, eta)?;
    let sc = autonomous_scene(&p, effects, "scan")?;
    let rots = patterns
        .iter()
        .map(|s| parse_pattern(s, p.n_balls()))
        .collect::<Result<Vec<_>, _>>()
        .map_err(to_py)?;
    // Seeds only need a guess in Newton's basin: a looser simulation than periodic()'s.
    let opts = periodic_options(
        n_harm,
        samples,
        tol,
        step_tol,
        max_iter,
        floquet,
        f_rtol,
        f_atol,
        margin,
        max_steps,
        settle,
        window,
        guess_rtol,
        guess_rtol * 1e-3,
        auto,
        n_max,
        hill,
        max_closure,
        max_trivial,
        max_tail,
    )?;
    let cols = Columns {
        names: &names,
        values: &values,
        patterns: &patterns,
        n_harm,
    };
    macro_rules! spec {
        ($base:expr) => {
            ScanSpec {
                base: $base,
                names: names.clone(),
                values: values.clone(),
                patterns: rots,
                opts,
                seeds,
                starts,
                block,
                chunk,
                threads,
                max_tail,
            }
        };
    }
    match &sc {
        None => run_scan(py, &spec!(&p), chunks, &cols, &on_chunk),
        Some(s) => run_scan(py, &spec!(s), chunks, &cols, &on_chunk),
    }
}

/// What a chunk's table needs besides its rows.
struct Columns<'a> {
    names: &'a [String],
    values: &'a [Vec<f64>],
    patterns: &'a [String],
    n_harm: usize,
}

/// Runs `spec`'s chunks through [`run_polled`], handing each finished one to `on_chunk`.
/// The scan cancels between rows with the token's flag (not the thread-local token: a
/// row stopped half way would look like a row without a solution).
fn run_scan<D: ballbal_core::scan::Family>(
    py: Python<'_>,
    spec: &ballbal_core::scan::ScanSpec<'_, D>,
    chunks: Vec<usize>,
    cols: &Columns<'_>,
    on_chunk: &Bound<'_, PyAny>,
) -> PyResult<()> {
    use ballbal_core::scan::{scan_chunks, ScanRow};
    run_polled(
        py,
        |tok, tx: &std::sync::mpsc::Sender<(usize, Vec<ScanRow>)>| {
            scan_chunks(spec, &chunks, tok.flag(), &|c, rows| {
                let _ = tx.send((c, rows));
            })
        },
        |(c, rows)| scan_columns(py, cols, &rows).and_then(|d| on_chunk.call1((c, d)).map(|_| ())),
    )
}

/// One chunk's rows as a dict of equally long lists (None where a value does not apply).
fn scan_columns<'py>(
    py: Python<'py>,
    cols: &Columns<'_>,
    rows: &[ballbal_core::scan::ScanRow],
) -> PyResult<Bound<'py, PyDict>> {
    let Columns {
        names,
        values,
        patterns,
        n_harm,
    } = *cols;
    use ballbal_core::periodic::Periodic;
    let d = PyDict::new(py);
    for (k, name) in names.iter().enumerate() {
        d.set_item(
            name,
            rows.iter()
                .map(|r| values[k][r.index[k]])
                .collect::<Vec<_>>(),
        )?;
    }
    let sols: Vec<Option<&Periodic>> = rows.iter().map(|r| r.result.as_ref()).collect();
    // A column over the rows with a solution, None elsewhere.
    fn col<'a, T>(
        sols: &[Option<&'a Periodic>],
        g: impl Fn(&'a Periodic) -> Option<T>,
    ) -> Vec<Option<T>> {
        sols.iter().map(|s| s.and_then(&g)).collect()
    }
    d.set_item(
        "type",
        rows.iter()
            .map(|r| patterns[r.pattern].clone())
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "solution",
        rows.iter().map(|r| r.solution).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "status",
        sols.iter()
            .map(|s| s.map_or("not_found", |x| x.sol.status.as_str()))
            .collect::<Vec<_>>(),
    )?;
    d.set_item("omega", col(&sols, |x| Some(x.sol.omega)))?;
    d.set_item(
        "stability",
        col(&sols, |x| {
            Some(
                x.floquet
                    .as_ref()
                    .map_or("undetermined", |fl| fl.stability.as_str()),
            )
        }),
    )?;
    d.set_item(
        "max_modulus",
        col(&sols, |x| x.floquet.as_ref().map(|fl| fl.max_modulus)),
    )?;
    d.set_item(
        "trivial_error",
        col(&sols, |x| x.floquet.as_ref().map(|fl| fl.trivial_error)),
    )?;
    let part = |k: fn(&(f64, f64)) -> f64| {
        col(&sols, |x| {
            x.floquet
                .as_ref()
                .map(|fl| fl.multipliers.iter().map(k).collect::<Vec<f64>>())
        })
    };
    d.set_item("mult_re", part(|z| z.0))?;
    d.set_item("mult_im", part(|z| z.1))?;
    d.set_item("residual", col(&sols, |x| Some(x.sol.residual)))?;
    d.set_item("tail", col(&sols, |x| Some(x.sol.tail_ratio())))?;
    d.set_item("closure", col(&sols, |x| x.closure))?;
    d.set_item(
        "separation_error",
        col(&sols, |x| {
            x.floquet.as_ref().and_then(|fl| fl.separation_error)
        }),
    )?;
    d.set_item("pivot_ratio", col(&sols, |x| Some(x.sol.pivot_ratio)))?;
    d.set_item("iterations", col(&sols, |x| Some(x.sol.iterations)))?;
    d.set_item(
        "floquet_steps",
        col(&sols, |x| x.floquet.as_ref().map(|fl| fl.steps)),
    )?;
    d.set_item("floquet_error", col(&sols, |x| x.floquet_error.clone()))?;
    d.set_item(
        "N",
        sols.iter()
            .map(|s| s.map_or(n_harm, |x| x.sol.n_harm))
            .collect::<Vec<_>>(),
    )?;
    d.set_item("target_met", col(&sols, |x| x.target_met))?;
    d.set_item(
        "hill_stability",
        col(&sols, |x| x.hill.as_ref().map(|h| h.1.as_str())),
    )?;
    d.set_item("verdicts_disagree", col(&sols, |x| x.verdicts_disagree()))?;
    d.set_item(
        "attempts",
        rows.iter().map(|r| r.attempts).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "seconds",
        rows.iter().map(|r| r.seconds).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "origin",
        rows.iter().map(|r| r.origin.as_str()).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "pb_exists",
        rows.iter().map(|r| r.pb_exists).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "pb_stable",
        rows.iter().map(|r| r.pb_stable).collect::<Vec<_>>(),
    )?;
    Ok(d)
}

/// Seconds this process has spent in certificate checks (all threads; a benchmark's
/// measure of what they cost).
#[pyfunction]
fn certificate_seconds() -> f64 {
    ballbal_core::hb::certificate_seconds()
}

/// Default block (and chunk) length, in values of the last parameter, for grid lengths
/// `lens`: about 1024 points.
#[pyfunction]
fn default_chunk(lens: Vec<usize>) -> PyResult<usize> {
    if lens.is_empty() || lens.contains(&0) {
        return Err(to_py(Error::param("grid", "every parameter needs values")));
    }
    Ok(ballbal_core::scan::default_chunk(&lens))
}

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
                let msg = p
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
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
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(validate, m)?)?;
    m.add_function(wrap_pyfunction!(equilibria, m)?)?;
    m.add_function(wrap_pyfunction!(balanced_states, m)?)?;
    m.add_function(wrap_pyfunction!(periodic, m)?)?;
    m.add_function(wrap_pyfunction!(orbit_closure, m)?)?;
    m.add_function(wrap_pyfunction!(scan, m)?)?;
    m.add_function(wrap_pyfunction!(default_chunk, m)?)?;
    m.add_function(wrap_pyfunction!(certificate_seconds, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
