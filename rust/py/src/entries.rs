//! The native entry points. Each takes the Python model (`ballbal.Balancer` or
//! `ballbal.Scene`) and option dataclasses as they are, builds and validates the core
//! model once, chooses planar or scene once ([`dispatch!`]) and runs the core off the
//! GIL.

use crate::collocation::CollocArgs;
use crate::convert::{dispatch, slice, Model, ModelArgs, PeriodicArgs};
use crate::errors::{not_autonomous, CoreResult};
use crate::run::{guarded, run_polled};
use crate::tables::{equilibrium_dict, scan_columns, solution_dict, Columns};
use ballbal_core::analysis::colloc_periodic::{by_method, Method};
use ballbal_core::analysis::constructed::periodic_discover;
use ballbal_core::analysis::homotopy::source_of;
use ballbal_core::equilibria::equilibria as core_equilibria;
use ballbal_core::hb::{HbSolution, Status};
use ballbal_core::numerics::collocation::CollocOptions;
use ballbal_core::ode::Options;
use ballbal_core::periodic::{
    closure_error, parse_solution_type, parse_windings, periodic_searched, require_autonomous,
    PeriodicOptions,
};
use ballbal_core::scan::{Family, ScanRow, ScanSpec};
use ballbal_core::simulate::simulate as core_simulate;
use ballbal_core::{cancel, Dynamics, Error, Scene};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The model, built for an analysis that needs an autonomous one (`what` names it in
/// the error).
fn autonomous(model: &ModelArgs, always_scene: bool, what: &str) -> PyResult<Model> {
    let m = model.build(always_scene).py()?;
    if let Model::Scene(s) = &m {
        require_autonomous(s).map_err(|e| not_autonomous(e, what))?;
    }
    Ok(m)
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
#[pyo3(signature = (model, y0, t0, t_eval, rtol, atol, max_steps))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    model: ModelArgs,
    y0: PyReadonlyArray1<'py, f64>,
    t0: f64,
    t_eval: PyReadonlyArray1<'py, f64>,
    rtol: f64,
    atol: Vec<f64>,
    max_steps: usize,
) -> PyResult<Simulated<'py>> {
    let m = model.build(false).py()?;
    let y0 = slice(&y0, "y0")?.to_vec();
    let te = slice(&t_eval, "t_eval")?.to_vec();
    let opts = Options {
        rtol,
        atol,
        max_steps,
        ..Default::default()
    };
    let traj = guarded(
        py,
        || dispatch!(&m, d => core_simulate(d, &y0, t0, &te, &opts)),
    )?;
    let cols = y0.len();
    let flat: Vec<f64> = traj.y.into_iter().flatten().collect();
    let arr = PyArray1::from_vec(py, flat).reshape([te.len(), cols])?;
    let theta: Vec<f64> = te
        .iter()
        .map(|&t| match &m {
            Model::Scene(s) => s.spin(t).2,
            Model::Planar(p) => p.omega_s * t,
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

/// Checks the model the way the core's constructors do, and nothing more: cheap,
/// unlike an analysis.
#[pyfunction]
pub fn validate(model: ModelArgs) -> PyResult<()> {
    model.build(false).py().map(|_| ())
}

/// All equilibria with their stability, as a list of dicts.
#[pyfunction]
pub fn equilibria<'py>(py: Python<'py>, model: ModelArgs) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let m = autonomous(&model, false, "equilibria")?;
    let eqs = guarded(py, || {
        Ok(match &m {
            Model::Scene(s) => ballbal_core::analysis::balanced::scene_equilibria(s),
            Model::Planar(p) => core_equilibria(p),
        })
    })?;
    eqs.into_iter().map(|e| equilibrium_dict(py, e)).collect()
}

/// The balanced state of each model, in parallel: a dict like `equilibria`'s, or
/// `None` where the balls cannot balance the disk.
#[pyfunction]
pub fn balanced_states<'py>(
    py: Python<'py>,
    models: Vec<ModelArgs>,
) -> PyResult<Vec<Option<Bound<'py, PyDict>>>> {
    let mut scenes = Vec::with_capacity(models.len());
    for m in &models {
        match autonomous(m, true, "balanced_state")? {
            Model::Scene(s) => scenes.push(s),
            Model::Planar(_) => unreachable!("built as a scene"),
        }
    }
    let eqs = each_scene(
        py,
        &scenes,
        ballbal_core::analysis::balanced::balanced_state,
    )?;
    eqs.into_iter()
        .map(|e| e.flatten().map(|e| equilibrium_dict(py, e)).transpose())
        .collect()
}

/// `f` on every scene in parallel, off the GIL. Each point is solved on its own, so the
/// result does not depend on the thread count. Points are short: once cancelled, the
/// points not yet started are skipped (`None`), and `guarded` raises the interrupt.
fn each_scene<T: Send>(
    py: Python<'_>,
    scenes: &[Scene],
    f: impl Fn(&Scene) -> T + Sync,
) -> PyResult<Vec<Option<T>>> {
    use rayon::prelude::*;
    guarded(py, || {
        // rayon's threads do not inherit the cancellation token: hand it on.
        let tok = cancel::current();
        Ok(scenes
            .par_iter()
            .map(|s| cancel::with(tok.clone(), || (!cancel::cancelled()).then(|| f(s))))
            .collect())
    })
}

/// One point of [`balance_map`]: its status and the balanced state, if any.
type MapPoint<'py> = (&'static str, Option<Bound<'py, PyDict>>);

/// The balanced state over a grid (`balance_map`): each point is the model with the
/// named parameters set (in the core, by the parameter registry's names), solved on its
/// own in parallel. Per point `("ok", dict)`, `("no_balance", None)` where the balls
/// cannot balance the planar disk, or `("not_converged", None)` where they can but the
/// continuation to the scene failed.
#[pyfunction]
pub fn balance_map<'py>(
    py: Python<'py>,
    model: ModelArgs,
    names: Vec<String>,
    points: Vec<Vec<f64>>,
) -> PyResult<Vec<MapPoint<'py>>> {
    use ballbal_core::analysis::balanced::balanced_state;
    let Model::Scene(base) = autonomous(&model, true, "balance_map")? else {
        unreachable!("built as a scene")
    };
    let mut scenes = Vec::with_capacity(points.len());
    for pt in &points {
        if pt.len() != names.len() {
            return Err(Error::param("axes", "one value per axis at every point")).py();
        }
        let mut s = base.clone();
        for (n, &v) in names.iter().zip(pt) {
            s = s.with_param(n, v).py()?;
        }
        // a parameter can switch an effect on (grooves cut into a bearing's sleeve)
        require_autonomous(&s).map_err(|e| not_autonomous(e, "balance_map"))?;
        scenes.push(s);
    }
    let found = each_scene(py, &scenes, |s| match balanced_state(s) {
        Some(e) => ("ok", Some(e)),
        None => {
            // the planar disk of this point, no effects: can it balance?
            let plain = Scene::new(s.planar.clone(), 0.0, None, 0.0, None, None)
                .ok()
                .and_then(|p| balanced_state(&p));
            match plain {
                Some(_) => ("not_converged", None),
                None => ("no_balance", None),
            }
        }
    })?;
    found
        .into_iter()
        // every point ran: a cancelled run raised in `each_scene`
        .map(|p| {
            let (st, e) = p.expect("every point ran");
            Ok((st, e.map(|e| equilibrium_dict(py, e)).transpose()?))
        })
        .collect()
}

/// A start for Newton from `(omega, coefficients)`, checked against the model.
pub(crate) fn start(m: &Model, ball_winding: &[f64], w: f64, c: &[f64]) -> PyResult<HbSolution> {
    let (d, o) = dispatch!(m, x => (x.ndof(), x.first_ball()));
    if !c.len().is_multiple_of(d) || (c.len() / d) % 2 != 1 {
        return Err(Error::param(
            "guess",
            format!(
                "coefficients: need shape (coordinates, 2 N + 1) = ({d}, odd), got {} values",
                c.len()
            ),
        ))
        .py();
    }
    if !(w.is_finite() && w > 0.0) || c.iter().any(|v| !v.is_finite()) {
        return Err(Error::param(
            "guess",
            "omega must be > 0 and every coefficient finite",
        ))
        .py();
    }
    let mut winding = vec![0.0; d];
    winding[o..].copy_from_slice(ball_winding);
    let nh = (c.len() / d - 1) / 2;
    Ok(HbSolution::start(
        w,
        c.to_vec(),
        winding,
        nh,
        Status::NoGuess,
    ))
}

/// Periodic solution of the given pattern by Newton–IHB, with Floquet multipliers;
/// `guess` is `(omega, coefficients)` or `None` (a simulated start); `windings` the
/// balls' turns per period (`None`: -1 for each `R`, 0 for each `O`).
/// `homotopy`: `(parameter, value)` starts to follow from when simulation finds no
/// orbit here (`analysis::homotopy`), and whether to try them before the constructed
/// starts (`analysis::constructed`) or after; the dict's `guess_source` says how it
/// was found.
#[pyfunction]
#[pyo3(signature = (model, pattern, options, guess=None, windings=None, homotopy=None, method="hb", collocation=None))]
#[allow(clippy::too_many_arguments)]
pub fn periodic<'py>(
    py: Python<'py>,
    model: ModelArgs,
    pattern: &str,
    options: PeriodicArgs,
    guess: Option<(f64, PyReadonlyArray1<'py, f64>)>,
    windings: Option<Vec<i64>>,
    homotopy: Option<(Vec<(String, f64)>, bool)>,
    method: &str,
    collocation: Option<CollocArgs>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = autonomous(&model, false, "periodic")?;
    let ball_winding = parse_windings(pattern, windings.as_deref(), m.n_balls()).py()?;
    let opts = options.to_core_for(&m)?;
    let method = Method::parse(method).py()?;
    let copts = match &collocation {
        Some(c) => c.to_core()?,
        None => CollocOptions::default(),
    };
    let guess = match &guess {
        Some((w, c)) => Some(start(&m, &ball_winding, *w, slice(c, "guess")?)?),
        None => None,
    };
    let (first, last) = match &homotopy {
        Some((starts, true)) => (Some(starts.as_slice()), None),
        Some((starts, false)) => (None, Some(starts.as_slice())),
        None => (None, None),
    };
    let (r, orbit, source) = guarded(py, || {
        dispatch!(&m, d => {
            stiff_guess(d, guess.is_none(), &opts)?;
            let (hb, source) = match &guess {
                None => periodic_discover(d, &ball_winding, first, last, &opts),
                Some(g) => (periodic_searched(d, &ball_winding, Some(g), &opts), source_of(true)),
            };
            let (r, orbit) = by_method(d, &ball_winding, hb, guess.as_ref(), method, &copts, &opts);
            Ok((r, orbit, source))
        })
    })?;
    let bounded = r
        .floquet
        .as_ref()
        .is_some_and(|f| f.modulus_error.is_some());
    let out = solution_dict(py, r, m.n_balls())?;
    out.set_item("guess_source", source)?;
    match orbit {
        Some(o) => {
            out.set_item("method", "collocation")?;
            if bounded {
                out.set_item(
                    "modulus_error_source",
                    format!("NTST {} collocation vs integrated", o.ntst()),
                )?;
            }
            out.set_item("ntst", o.ntst())?;
            out.set_item("mesh", PyArray1::from_vec(py, o.mesh))?;
            let rows = o.u.len() / o.n;
            out.set_item(
                "mesh_states",
                PyArray1::from_vec(py, o.u).reshape([rows, o.n])?,
            )?;
        }
        None => out.set_item("method", "hb")?,
    }
    Ok(out)
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
pub fn orbit_closure(
    py: Python<'_>,
    model: ModelArgs,
    omega: f64,
    coeffs: PyReadonlyArray1<'_, f64>,
    winding: Vec<f64>,
    rtol: f64,
    atol: f64,
) -> PyResult<f64> {
    let m = model.build(false).py()?;
    let c = slice(&coeffs, "coeffs")?.to_vec();
    let d = winding.len();
    if d == 0 || !c.len().is_multiple_of(d) || (c.len() / d) % 2 != 1 {
        return Err(Error::param(
            "coeffs",
            format!(
                "need {d} x (2 N + 1) values (one row per coordinate), got {}",
                c.len()
            ),
        ))
        .py();
    }
    let n_harm = (c.len() / d - 1) / 2;
    let sol = HbSolution::start(omega, c, winding, n_harm, Status::Converged);
    guarded(
        py,
        || dispatch!(&m, x => closure_error(x, &sol, rtol, atol)),
    )
}

/// Parallel scan of a parameter grid, chunk by chunk. `options` is a
/// `ballbal.ScanOptions` (its `block`: values of the last axis per continuation block,
/// `None` for the default). `on_chunk(index, columns)` is called (with the GIL, in this
/// thread) for every finished chunk as soon as it is done; Ctrl-C cancels the remaining
/// work, hands over the chunks that still finish, and then raises `KeyboardInterrupt`.
/// A scene is scanned as a scene even with every effect off (an axis may switch one on).
#[pyfunction]
#[pyo3(signature = (model, names, values, patterns, options, chunk, threads, chunks, on_chunk))]
#[allow(clippy::too_many_arguments)]
pub fn scan(
    py: Python<'_>,
    model: ModelArgs,
    names: Vec<String>,
    values: Vec<Vec<f64>>,
    patterns: Vec<String>,
    options: Bound<'_, PyAny>,
    chunk: usize,
    threads: usize,
    chunks: Vec<usize>,
    on_chunk: Bound<'_, PyAny>,
) -> PyResult<()> {
    let lens: Vec<usize> = values.iter().map(Vec::len).collect();
    let args: PeriodicArgs = options.extract()?;
    let block: Option<usize> = options.getattr("block")?.extract()?;
    let block = block.unwrap_or_else(|| ballbal_core::scan::default_chunk(&lens));
    let always_scene = matches!(model, ModelArgs::Scene(_));
    let m = autonomous(&model, always_scene, "scan")?;
    let rots = patterns
        .iter()
        .map(|s| parse_solution_type(s, m.n_balls()))
        .collect::<Result<Vec<_>, _>>()
        .py()?;
    let opts = args.to_core_for(&m)?;
    let n_harm = opts.hb.n_harm;
    let cols = Columns {
        names: &names,
        values: &values,
        patterns: &patterns,
        n_harm,
    };
    dispatch!(&m, base => {
        let spec = ScanSpec {
            base,
            names: names.clone(),
            values: values.clone(),
            patterns: rots,
            max_tail: opts.max_tail,
            opts,
            seeds: args.guess.seeds,
            starts: args.guess.starts,
            block,
            chunk,
            threads,
        };
        run_scan(py, &spec, chunks, &cols, &on_chunk)
    })
}

/// Runs `spec`'s chunks through [`run_polled`], handing each finished one to `on_chunk`.
/// The scan cancels between rows with the token's flag (not the thread-local token: a
/// row stopped half way would look like a row without a solution).
fn run_scan<D: Family>(
    py: Python<'_>,
    spec: &ScanSpec<'_, D>,
    chunks: Vec<usize>,
    cols: &Columns<'_>,
    on_chunk: &Bound<'_, PyAny>,
) -> PyResult<()> {
    use ballbal_core::scan::scan_chunks;
    run_polled(
        py,
        |tok, tx: &std::sync::mpsc::Sender<(usize, Vec<ScanRow>)>| {
            scan_chunks(spec, &chunks, tok.flag(), &|c, rows| {
                let _ = tx.send((c, rows));
            })
        },
        |(c, rows)| {
            let t = std::time::Instant::now();
            let r = scan_columns(py, cols, &rows).and_then(|d| on_chunk.call1((c, d)).map(|_| ()));
            TABLE_NS.fetch_add(
                t.elapsed().as_nanos() as u64,
                std::sync::atomic::Ordering::Relaxed,
            );
            r
        },
    )
}

static TABLE_NS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Seconds this process's scans spent per stage: perfect-balance checks, seeds,
/// continuation and rows in the core (summed over blocks, see the core's
/// `stage_seconds`), then the columns and the Python callback per chunk (table
/// building, on the calling thread). A benchmark's measure.
#[pyfunction]
pub fn scan_stage_seconds() -> Vec<f64> {
    let mut v = ballbal_core::scan::stage_seconds().to_vec();
    v.push(TABLE_NS.load(std::sync::atomic::Ordering::Relaxed) as f64 * 1e-9);
    v
}

/// Where this process's scans' threads waited (see the core's `scan::profile`): per
/// stage (balance, seeds, waves, glue, rows) `[wall, bound, span, steps, tasks, busy of
/// pool thread 0, 1, ...]`, seconds summed over blocks. A benchmark's measure.
#[pyfunction]
pub fn scan_profile() -> Vec<Vec<f64>> {
    ballbal_core::scan::profile::profile()
}

/// Whether the continuation waves start their biggest target points first (the
/// default; the table is the same either way). A benchmark's switch.
#[pyfunction]
pub fn scan_wave_order(longest_first: bool) {
    ballbal_core::continuation::lattice::set_longest_first(longest_first);
}

/// Work this process's scans did (see the core's `work_counts`): harmonic-balance
/// solves from seeds and from continuation attempts, certificates, solutions finished
/// (Floquet analyses), certificates spared. A benchmark's measure.
#[pyfunction]
pub fn scan_work_counts() -> Vec<u64> {
    ballbal_core::scan::work_counts().to_vec()
}

/// Seconds this process has spent in certificate checks (all threads; a benchmark's
/// measure of what they cost).
#[pyfunction]
pub fn certificate_seconds() -> f64 {
    ballbal_core::hb::certificate_seconds()
}

/// Switches the harmonic-balance solve's per-stage timers on or off and resets them
/// (off by default; a benchmark's measure, see `hb_stage_seconds`).
#[pyfunction]
pub fn hb_stage_profile(on: bool) {
    ballbal_core::hb::stage_profile(on)
}

/// Seconds spent since `hb_stage_profile(True)` in the harmonic-balance residual
/// (sampling, model, projection), the model's Jacobians at the samples, the Galerkin
/// projection of the Jacobian and the LU solve, then the counts of solves, Newton
/// iterations and residual evaluations.
#[pyfunction]
pub fn hb_stage_seconds() -> Vec<f64> {
    ballbal_core::hb::stage_seconds().to_vec()
}

/// Default block (and chunk) length, in values of the last parameter, for grid lengths
/// `lens`: about 1024 points.
#[pyfunction]
pub fn default_chunk(lens: Vec<usize>) -> PyResult<usize> {
    if lens.is_empty() || lens.contains(&0) {
        return Err(Error::param("grid", "every parameter needs values")).py();
    }
    Ok(ballbal_core::scan::default_chunk(&lens))
}

/// The parameter registry (`ballbal_core::model::params::REGISTRY`), one dict per
/// parameter in the registry's order: `name` (as errors name it), `key` (as scans and
/// `with_param` take it, None when it cannot be varied by name), `owner` (the
/// component), `planar` (owned by the planar balancer), `per_ball`, and the range
/// `lo`, `lo_open`, `hi`, `hi_open`.
#[pyfunction]
pub fn parameters(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    use ballbal_core::model::params::{PLANAR_OWNERS, REGISTRY};
    REGISTRY
        .iter()
        .map(|s| {
            let d = PyDict::new(py);
            d.set_item("name", s.name)?;
            d.set_item("key", s.key)?;
            d.set_item("owner", s.owner)?;
            d.set_item("planar", PLANAR_OWNERS.contains(&s.owner))?;
            d.set_item("per_ball", s.per_ball)?;
            d.set_item("lo", s.range.lo)?;
            d.set_item("lo_open", s.range.lo_open)?;
            d.set_item("hi", s.range.hi)?;
            d.set_item("hi_open", s.range.hi_open)?;
            Ok(d)
        })
        .collect()
}

/// A parameter name as the core reads it: `(key, ball)` with `ball` the index from 0 of
/// a per-ball name (`"eta2"` -> `("eta", 1)`), `None` for every ball or a parameter
/// that is not per ball; the core's error (with its hint for `eta[1]`) for a name it
/// does not know.
#[pyfunction]
pub fn parse_parameter(name: &str) -> PyResult<(&'static str, Option<usize>)> {
    use ballbal_core::model::params::{key_list, unknown, ParamRef, REGISTRY};
    let owners: Vec<&str> = REGISTRY.iter().map(|s| s.owner).collect();
    let p = ParamRef::parse(name)
        .ok_or_else(|| unknown(name, "registry", &key_list(&owners)))
        .py()?;
    let s = p.id.spec();
    Ok((s.key.unwrap_or(s.name), p.ball))
}

/// The name of the ball at index `ball` (from 0) of the per-ball parameter `key`:
/// `ball_parameter_name("eta", 0)` is `"eta1"`.
#[pyfunction]
pub fn ball_parameter_name(key: &str, ball: usize) -> String {
    ballbal_core::model::params::ball_name(key, ball)
}

/// The model built as a scan builds it (a scene stays a scene).
fn scanned_model(model: &ModelArgs) -> PyResult<Model> {
    model.build(matches!(model, ModelArgs::Scene(_))).py()
}

/// Refuses the first of `names` the model cannot vary, with the core's error (the one
/// a scan of it would stop with), before any work or file is started.
#[pyfunction]
pub fn check_axes(model: ModelArgs, names: Vec<String>) -> PyResult<()> {
    let m = scanned_model(&model)?;
    for n in &names {
        dispatch!(&m, d => d.check_param(n)).py()?;
    }
    Ok(())
}

/// The registry's keys the model takes by name (its per-ball parameters as one key for
/// every ball; `eta1`, `eta2`, ... also take one ball), in the registry's order.
#[pyfunction]
pub fn parameter_keys(model: ModelArgs) -> PyResult<Vec<&'static str>> {
    use ballbal_core::model::params::REGISTRY;
    let m = scanned_model(&model)?;
    Ok(REGISTRY
        .iter()
        .filter_map(|s| s.key)
        .filter(|k| dispatch!(&m, d => d.check_param(k)).is_ok())
        .collect())
}
