//! Continuation of equilibria (`ballbal.continuation`): branches with events, switching
//! at a branch point, two-parameter bifurcation curves. Glue only: the core's
//! `bifurcation::equilibria` does the work, off the GIL.

use crate::continuation::{controls, ContinuationArgs};
use crate::convert::{dispatch, Model, ModelArgs};
use crate::errors::{not_autonomous, CoreResult};
use crate::run::guarded_progress;
use crate::tables::equilibrium_dict;
use ballbal_core::bifurcation::equilibria::{
    branch, branch_both_ways, curve, switch, CurveKind, EqBranch, EqCurve, EqOptions, EqSystem,
};
use ballbal_core::bifurcation::event::Event;
use ballbal_core::bifurcation::event::VOCABULARY;
use ballbal_core::continuation::ArcStop;
use ballbal_core::equilibria::EquilibriumKind;
use ballbal_core::model::DiskUnits;
use ballbal_core::numerics::problem::{Parametric, Problem};
use ballbal_core::periodic::require_autonomous;
use ballbal_core::Planar;
use ballbal_core::{Error, Result};
use pyo3::prelude::*;
use pyo3::types::PyDict;

fn model(m: &ModelArgs) -> PyResult<Model> {
    let built = m.build(false).py()?;
    if let Model::Scene(s) = &built {
        require_autonomous(s).map_err(|e| not_autonomous(e, "equilibrium continuation"))?;
    }
    Ok(built)
}

fn options(m: &Model, args: &ContinuationArgs, range: (f64, f64)) -> EqOptions {
    EqOptions {
        arc: args.options(range),
        // with ball springs the perfect balance is no family
        family: !matches!(m, Model::Scene(s) if s.springs != 0.0),
        ..Default::default()
    }
}

fn stop_str(s: &ArcStop) -> String {
    match s {
        ArcStop::MaxPoints => "max_points".into(),
        ArcStop::Boundary => "boundary".into(),
        ArcStop::StepTooSmall => "step_too_small".into(),
        ArcStop::Finished(w) => w.clone(),
        ArcStop::Failed(w) => format!("failed: {w}"),
    }
}

fn kind_from(name: &str) -> Result<EquilibriumKind> {
    Ok(match name {
        "perfect_balance" => EquilibriumKind::PerfectBalance,
        "balanced" => EquilibriumKind::Balanced,
        "together" => EquilibriumKind::Together,
        "opposite" => EquilibriumKind::Opposite,
        "unbalanced" => EquilibriumKind::Unbalanced,
        "partial_balance" => EquilibriumKind::PartialBalance,
        "imbalance_side" => EquilibriumKind::ImbalanceSide,
        other => {
            return Err(Error::param_range(
                "start",
                format!("unknown equilibrium kind {other:?}"),
                "perfect_balance, balanced, together, opposite, unbalanced, partial_balance, \
                 imbalance_side",
            ))
        }
    })
}

fn check_q(q: &[f64], d: usize) -> Result<()> {
    if q.len() != d || q.iter().any(|v| !v.is_finite()) {
        return Err(Error::param(
            "start",
            format!("needs {d} finite coordinates, got {}", q.len()),
        ));
    }
    Ok(())
}

/// The balancer in the disk's units (`ballbal.continuation.DiskUnits`' fields): when
/// given, the continued parameters are these units' own and the model is rebuilt from them.
#[derive(FromPyObject)]
pub struct DiskUnitsArgs {
    omega0: f64,
    m0: f64,
    e: f64,
    #[pyo3(attribute("C0"))]
    c0: f64,
    #[pyo3(attribute("D0"))]
    d0: f64,
    n: usize,
}

impl DiskUnitsArgs {
    fn core(&self) -> Result<DiskUnits> {
        DiskUnits::new(self.omega0, self.m0, self.e, self.c0, self.d0, self.n)
    }
}

/// The equilibrium family in `names`: the model's own parameters, or the disk's units'.
fn family<'a, D: Parametric>(
    d: &'a D,
    seed: Option<&DiskUnitsArgs>,
    names: &[&str],
) -> Result<Family<'a, D>> {
    Ok(match seed {
        None => Family::Model(EqSystem::family(d, names)?),
        Some(s) => Family::Seed(EqSystem::disk_units(s.core()?, names)?),
    })
}

enum Family<'a, D> {
    Model(EqSystem<'a, D>),
    Seed(EqSystem<'static, Planar>),
}

/// `$e` with `$s` the family's system (each arm its own monomorphisation).
macro_rules! with_family {
    ($f:expr, $s:ident => $e:expr) => {
        match $f {
            Family::Model($s) => $e,
            Family::Seed($s) => $e,
        }
    };
}

fn run_branch<D: Parametric>(
    d: &D,
    seed: Option<&DiskUnitsArgs>,
    parameter: &str,
    q: &[f64],
    kind: EquilibriumKind,
    both: bool,
    opts: &EqOptions,
) -> Result<EqBranch> {
    check_q(q, d.ndof())?;
    with_family!(family(d, seed, &[parameter])?, sys => {
        let mut sys = sys;
        let p0 = Problem::param(&sys);
        if both {
            branch_both_ways(&mut sys, q, p0, kind, opts)
        } else {
            branch(&mut sys, q, p0, kind, None, opts)
        }
    })
}

fn run_switch<D: Parametric>(
    d: &D,
    seed: Option<&DiskUnitsArgs>,
    parameter: &str,
    x: &[f64],
    p: f64,
    tangent: &[f64],
    opts: &EqOptions,
) -> Result<EqBranch> {
    check_q(x, d.ndof())?;
    if tangent.len() != x.len() + 1 {
        return Err(Error::param("event", "tangent of the wrong length"));
    }
    with_family!(family(d, seed, &[parameter])?, sys => {
        let mut sys = sys;
        switch(&mut sys, x, p, tangent, opts)
    })
}

/// `start`: the event's equilibrium and its value of the first parameter.
fn run_curve<D: Parametric>(
    d: &D,
    seed: Option<&DiskUnitsArgs>,
    kind: CurveKind,
    names: (&str, &str),
    (q, p1): (&[f64], f64),
    together: bool,
    opts: &EqOptions,
) -> Result<EqCurve> {
    check_q(q, d.ndof())?;
    if names.0 == names.1 {
        return Err(Error::param(
            "parameter2",
            format!("must differ from the branch's parameter {:?}", names.0),
        ));
    }
    let p2 = match seed {
        None => d.param_value(names.1)?,
        Some(s) => s.core()?.param_value(names.1)?,
    };
    with_family!(family(d, seed, &[names.0, names.1])?, sys => {
        let sys = if together { sys.on_together()? } else { sys };
        curve(sys, kind, q, p1, p2, opts)
    })
}

fn branch_dict(py: Python<'_>, b: EqBranch) -> PyResult<Bound<'_, PyDict>> {
    let out = PyDict::new(py);
    let mut points = vec![];
    for pt in b.points {
        let d = equilibrium_dict(py, pt.eq)?;
        d.set_item("p", pt.p)?;
        d.set_item("x", pt.x)?;
        d.set_item("tangent", pt.tangent)?;
        d.set_item("test_fold", pt.fold)?;
        d.set_item("test_branch_point", pt.bp)?;
        d.set_item("test_hopf", pt.hopf)?;
        points.push(d);
    }
    let mut events = vec![];
    for e in b.events {
        let d = equilibrium_dict(py, e.eq)?;
        d.set_item("type", e.kind.as_str())?;
        d.set_item("row", e.row)?;
        d.set_item("p", e.p)?;
        d.set_item("x", e.x)?;
        d.set_item("tangent", e.tangent)?;
        d.set_item("test", e.test)?;
        d.set_item("omega", e.omega)?;
        events.push(d);
    }
    out.set_item("points", points)?;
    out.set_item("events", events)?;
    let stop = match &b.stop_back {
        None => stop_str(&b.stop),
        Some(back) => format!("{}/{}", stop_str(back), stop_str(&b.stop)),
    };
    out.set_item("stop", stop)?;
    Ok(out)
}

fn curve_dict(py: Python<'_>, c: EqCurve) -> PyResult<Bound<'_, PyDict>> {
    let out = PyDict::new(py);
    let mut points = vec![];
    for pt in c.points {
        let d = equilibrium_dict(py, pt.eq)?;
        d.set_item("p1", pt.p[0])?;
        d.set_item("p2", pt.p[1])?;
        d.set_item("omega", pt.omega)?;
        d.set_item("test", pt.g)?;
        points.push(d);
    }
    let mut special = vec![];
    for s in c.special {
        let d = PyDict::new(py);
        d.set_item("type", s.kind)?;
        d.set_item("p1", s.p[0])?;
        d.set_item("p2", s.p[1])?;
        d.set_item("q", s.q)?;
        d.set_item("row", s.row)?;
        special.push(d);
    }
    out.set_item("kind", c.kind.as_str())?;
    out.set_item("points", points)?;
    out.set_item("special", special)?;
    out.set_item(
        "stop",
        format!("{}/{}", stop_str(&c.stop[0]), stop_str(&c.stop[1])),
    )?;
    Ok(out)
}

/// A branch of equilibria from `q` (the model's equilibrium of kind `kind`) in
/// `parameter` over `range`, with user points at the parameter values `at`, stopping at
/// the first event named in `stop`: a dict of `points`, `events` and `stop`.
#[allow(
    clippy::too_many_arguments,
    reason = "a #[pyfunction]'s arguments are the Python call's keywords"
)]
#[pyfunction]
#[pyo3(signature = (model, parameter, q, kind, range, options, both=false, disk_units=None, at=None, stop=None, progress=None))]
pub fn equilibrium_branch<'py>(
    py: Python<'py>,
    model: ModelArgs,
    parameter: String,
    q: Vec<f64>,
    kind: String,
    range: (f64, f64),
    options: ContinuationArgs,
    both: bool,
    disk_units: Option<DiskUnitsArgs>,
    at: Option<Vec<f64>>,
    stop: Option<Vec<String>>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = self::model(&model)?;
    let k = kind_from(&kind).py()?;
    let mut opts = options_checked(&m, &options, range)?;
    opts.controls = controls(at, stop)?;
    let b = guarded_progress(
        py,
        progress.as_ref(),
        || dispatch!(&m, d => run_branch(d, disk_units.as_ref(), &parameter, &q, k, both, &opts)),
    )?;
    branch_dict(py, b)
}

/// The other branch through a branch point `(x, p)` reached along `tangent`.
#[allow(
    clippy::too_many_arguments,
    reason = "a #[pyfunction]'s arguments are the Python call's keywords"
)]
#[pyfunction]
#[pyo3(signature = (model, parameter, x, p, tangent, range, options, disk_units=None, progress=None))]
pub fn equilibrium_switch<'py>(
    py: Python<'py>,
    model: ModelArgs,
    parameter: String,
    x: Vec<f64>,
    p: f64,
    tangent: Vec<f64>,
    range: (f64, f64),
    options: ContinuationArgs,
    disk_units: Option<DiskUnitsArgs>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = self::model(&model)?;
    let opts = options_checked(&m, &options, range)?;
    let b = guarded_progress(
        py,
        progress.as_ref(),
        || dispatch!(&m, d => run_switch(d, disk_units.as_ref(), &parameter, &x, p, &tangent, &opts)),
    )?;
    branch_dict(py, b)
}

/// The curve of the event `kind` (`"fold"`: the saddle-node curve, `"hopf"`,
/// `"branch_point"`: the pitchfork curve; or an alias `Event::parse` reads) through the event
/// `(q, p1)` in `(parameter, parameter2)`, `range` bounding `parameter2`; `together`:
/// on the balls-together subspace.
#[allow(
    clippy::too_many_arguments,
    reason = "a #[pyfunction]'s arguments are the Python call's keywords"
)]
#[pyfunction]
#[pyo3(signature = (model, kind, parameter, parameter2, q, p1, together, range, options, disk_units=None, progress=None))]
pub fn equilibrium_curve<'py>(
    py: Python<'py>,
    model: ModelArgs,
    kind: String,
    parameter: String,
    parameter2: String,
    q: Vec<f64>,
    p1: f64,
    together: bool,
    range: (f64, f64),
    options: ContinuationArgs,
    disk_units: Option<DiskUnitsArgs>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = self::model(&model)?;
    let k = match Event::parse(&kind, "event").py()? {
        Event::Fold => CurveKind::Fold,
        Event::Hopf => CurveKind::Hopf,
        // of the balls-together branch, the one continued: the pitchfork
        Event::BranchPoint => CurveKind::Pitchfork,
        other => {
            return Err(Error::param_range(
                "event",
                format!("an equilibrium has no {} curve", other.name()),
                "fold, hopf, branch_point",
            ))
            .py()
        }
    };
    let opts = options_checked(&m, &options, range)?;
    let c = guarded_progress(
        py,
        progress.as_ref(),
        || dispatch!(&m, d => run_curve(d, disk_units.as_ref(), k, (&parameter, &parameter2), (&q, p1), together, &opts)),
    )?;
    curve_dict(py, c)
}

fn options_checked(m: &Model, args: &ContinuationArgs, range: (f64, f64)) -> PyResult<EqOptions> {
    if range.0 >= range.1 || !range.0.is_finite() || !range.1.is_finite() {
        return Err(Error::param(
            "range",
            format!("needs finite lo < hi, got ({}, {})", range.0, range.1),
        ))
        .py();
    }
    let o = options(m, args, range);
    o.arc.validate().py()?;
    Ok(o)
}

/// The events' vocabulary: `(name, aliases, meaning)` for every event, in the order
/// the docs list them (the core's `bifurcation::event::VOCABULARY`).
#[pyfunction]
pub fn event_vocabulary() -> Vec<(&'static str, Vec<&'static str>, &'static str)> {
    VOCABULARY
        .iter()
        .map(|e| (e.name, e.aliases.to_vec(), e.meaning))
        .collect()
}

/// The canonical name of the event called `text` (a name or an alias, any case); an
/// unknown one is an error about `parameter`.
#[pyfunction]
#[pyo3(signature = (text, parameter="event"))]
pub fn event_name(text: &str, parameter: &str) -> PyResult<&'static str> {
    Event::parse(text, parameter).map(|e| e.name()).py()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(event_vocabulary, m)?)?;
    m.add_function(wrap_pyfunction!(event_name, m)?)?;
    m.add_function(wrap_pyfunction!(equilibrium_branch, m)?)?;
    m.add_function(wrap_pyfunction!(equilibrium_switch, m)?)?;
    m.add_function(wrap_pyfunction!(equilibrium_curve, m)?)?;
    Ok(())
}
