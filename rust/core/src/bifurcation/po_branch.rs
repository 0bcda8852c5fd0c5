//! Branches of periodic solutions in one model parameter: pseudo-arclength continuation
//! ([`crate::continuation::Arclength`]) of the harmonic-balance problem
//! ([`HbProblem`], unknowns the coefficients and omega), every point certified and
//! judged as [`crate::periodic::periodic`] does it ([`finish_on_branch`]: closure and
//! tail certificates, Floquet multipliers, trivial and separation checks, the verdict's
//! error bounded against a finer series while the point keeps the branch's harmonics),
//! with the bifurcations located between points (on the multipliers at the branch's
//! harmonics; a trial point of a location gets no bound, its verdict being unused):
//!
//! * fold `LP`: the tangent's parameter component `dp/ds` changes sign;
//! * branch point `BP`: the bordered determinant `det [[F_x, F_p], [t^T]]` changes sign
//!   (for merged balls, the antisymmetric separation multiplier passes +1, and the
//!   separated solutions live in the same harmonic-balance space); a real multiplier
//!   through +1 that neither a fold nor the determinant explains is reported as `BP`
//!   too, located on the multipliers;
//! * period doubling `PD`: a real multiplier through -1 (`prod (lambda + 1)`);
//! * Neimark–Sacker `NS`: a complex pair through the unit circle
//!   (`prod (|lambda|^2 - 1)` over the complex pairs, when their count is the same on
//!   both sides);
//! * infinite period `IP`: on a rotating branch omega falls to 0 (a saddle-node on the
//!   invariant circle of the equilibria, `T ~ C / sqrt|p - p*|`). A fixed number of
//!   harmonics cannot follow it: the branch ends when omega falls below `min_omega`, or
//!   when a point fails its certificate while omega is falling. That point is not
//!   kept; `p*` is fitted on the last three kept points as `T = C / sqrt|p - p*| + D`
//!   (the constant `D`, the time spent away from the bottleneck, matters: without it the
//!   fitted `p*` falls short of the saddle-node's closed form by far more than the fit's
//!   error; docs/measurements.md, "Continuation and bifurcation", has the numbers).
//!
//! Under [`Method::Auto`] the branch hands over to collocation ([`super::po_colloc`])
//! on its way to an infinite-period end, before harmonic balance's series loses the
//! period's accuracy ([`SWITCH_OMEGA_ERROR`]); collocation then locates the `IP` event
//! from the orbits (their slowest speed), not from the fit above.
//!
//! Every test function is continuous along the branch and changes sign exactly at its
//! event; [`crate::continuation::locate`] finds the zero in arclength to `event_tol`,
//! which bounds the error in the parameter (`|dp/ds| <= 1` in the unit tangent).

pub use super::po_colloc::RowMethod;
use super::po_colloc::{collocation_tail, TailStart};
pub use crate::analysis::colloc_periodic::Method;
use crate::bifurcation::event::{check_stop_events, Event};
use crate::continuation::arclength::bordered;
use crate::continuation::curves::join_halves;
use crate::continuation::{
    self, ArcOptions, ArcPoint, ArcStop, Controls, Declared, Level, Spectrum, Start,
};
use crate::error::{Error, Result};
use crate::floquet::Stability;
use crate::hb::{default_samples, solve, HbProblem, HbSolution, Status};
use crate::numerics::collocation::{CollocOptions, CollocOrbit};
use crate::numerics::problem::{ModelAt, Parametric, Problem};
use crate::periodic::{finish_on_branch, multipliers_on_branch, Periodic, PeriodicOptions};

/// Settings of [`periodic_branch`].
#[derive(Debug, Clone)]
pub struct PoBranchOptions {
    /// Step control and the parameter window (`p_min`, `p_max`).
    pub arc: ArcOptions,
    /// Harmonics, certificates and the Floquet / Hill analysis of every point (`auto`
    /// is ignored: a branch keeps one number of harmonics).
    pub periodic: PeriodicOptions,
    /// The branch ends (infinite period) when omega falls below this.
    pub min_omega: f64,
    /// Events are located to this arclength, hence to this in the parameter.
    pub event_tol: f64,
    /// User points and the events to stop at (one of [`PO_STOP_EVENTS`]); its
    /// `stop_level` is set from `stop_period`.
    pub controls: Controls,
    /// The branch ends where the period reaches this (it must exceed the start's), its
    /// last row solved with that period; the stop reason is `"period"`.
    pub stop_period: Option<f64>,
    /// The discretisation: harmonic balance ([`Method::Hb`], pseudo-arclength through
    /// folds), collocation ([`Method::Collocation`], natural continuation in the
    /// parameter: see [`super::po_colloc`]), or harmonic balance switching to collocation
    /// where its series is no longer accurate on the way to an infinite-period end
    /// ([`Method::Auto`]: see [`SWITCH_OMEGA_ERROR`]).
    pub method: Method,
    /// Collocation's mesh and Newton settings.
    pub collocation: CollocOptions,
}

/// Under [`Method::Auto`] the branch leaves harmonic balance for collocation at the
/// first point, with omega falling along the branch, whose frequency bound
/// (`omega_error`, from the finer series the verdict is bounded against) exceeds this
/// fraction of omega, or that fails its certificates, or whose omega falls below
/// `min_omega`. 1e-6 is the period accuracy AUTO-07p's NTST 20 gives on the merged R-R
/// branch of issue 33 at Omega 0.93; harmonic balance at the default `N = 3` passes it
/// near Omega 1.08 there (its omega bound grows as the slow phase sharpens), and its
/// certificates still accept the series down to 0.951, where its period is 0.6 % off.
pub const SWITCH_OMEGA_ERROR: f64 = 1e-6;

/// The events a periodic branch can be asked to stop at (it always stops at an
/// infinite period).
pub const PO_STOP_EVENTS: [Event; 5] = [
    Event::Fold,
    Event::BranchPoint,
    Event::PeriodDoubling,
    Event::NeimarkSacker,
    Event::User,
];

impl Default for PoBranchOptions {
    fn default() -> Self {
        PoBranchOptions {
            arc: ArcOptions::default(),
            periodic: PeriodicOptions::default(),
            min_omega: 1e-3,
            event_tol: 1e-7,
            controls: Controls::default(),
            stop_period: None,
            method: Method::Hb,
            collocation: CollocOptions::default(),
        }
    }
}

impl PoBranchOptions {
    pub fn validate(&self) -> Result<()> {
        if !(self.arc.p_min < self.arc.p_max) || self.arc.p_min.is_nan() {
            return Err(Error::param_range(
                "range",
                format!(
                    "needs lo < hi, got ({}, {})",
                    self.arc.p_min, self.arc.p_max
                ),
                "lo < hi",
            ));
        }
        self.arc.validate()?;
        self.periodic.validate()?;
        self.collocation.validate()?;
        crate::error::check_range("min_omega", self.min_omega, 0.0, false, 1e3, true)?;
        crate::error::check_range("event_tol", self.event_tol, 0.0, true, 1.0, true)?;
        check_stop_events(&self.controls, &PO_STOP_EVENTS)?;
        self.controls.validate(self.arc.p_min, self.arc.p_max)?;
        if let Some(t) = self.stop_period {
            crate::error::check_range("stop_period", t, 0.0, true, f64::MAX, true)?;
        }
        Ok(())
    }
}

/// An event type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PoEventKind {
    Fold,
    BranchPoint,
    PeriodDoubling,
    NeimarkSacker,
    InfinitePeriod,
    /// A point at a parameter value the user asked for ([`Controls::at`]).
    User,
}

impl PoEventKind {
    /// The event in the one vocabulary of all branches.
    pub fn event(self) -> Event {
        match self {
            PoEventKind::Fold => Event::Fold,
            PoEventKind::BranchPoint => Event::BranchPoint,
            PoEventKind::PeriodDoubling => Event::PeriodDoubling,
            PoEventKind::NeimarkSacker => Event::NeimarkSacker,
            PoEventKind::InfinitePeriod => Event::InfinitePeriod,
            PoEventKind::User => Event::User,
        }
    }

    pub fn as_str(&self) -> &'static str {
        self.event().name()
    }
}

/// The test functions at a point (multiplier ones `None` without multipliers).
#[derive(Debug, Clone, Default)]
pub struct PoTests {
    /// `dp/ds`.
    pub lp: f64,
    /// The bordered determinant (rows scaled to unit max-norm: same sign, continuous).
    pub bp: f64,
    /// `prod (lambda - 1) / max(1, |lambda|)` over the non-trivial multipliers.
    pub bp_multipliers: Option<f64>,
    /// `prod (lambda + 1) / max(1, |lambda|)` over the non-trivial multipliers.
    pub pd: Option<f64>,
    /// `prod (|lambda|^2 - 1) / max(1, |lambda|^2)` over the complex pairs.
    pub ns: Option<f64>,
    /// Number of complex pairs among the non-trivial multipliers.
    pub complex_pairs: usize,
    /// The slowest speed along the orbit (collocation rows: [`slowest_speed`]), zero at
    /// an infinite-period end.
    ///
    /// [`slowest_speed`]: crate::numerics::collocation::slowest_speed
    pub ip: Option<f64>,
}

/// One point of a branch.
#[derive(Debug, Clone)]
pub struct PoPoint {
    pub p: f64,
    /// The series, certified and judged as `periodic()` does (a point whose certificate
    /// fails has status `NotClosed` / `Truncated`, no multipliers and no verdict).
    pub result: Periodic,
    pub arc: ArcPoint,
    pub tests: PoTests,
    /// Events located between the previous point and this one.
    pub events: Vec<PoEventKind>,
    /// The discretisation the row was solved with.
    pub method: RowMethod,
}

impl PoPoint {
    pub fn omega(&self) -> f64 {
        self.result.sol.omega
    }
    /// The multipliers the test functions use: the monodromy's, else Hill's.
    pub fn multipliers(&self) -> Option<&[(f64, f64)]> {
        match (&self.result.floquet, &self.result.hill) {
            (Some(f), _) => Some(&f.multipliers),
            (None, Some((m, _))) => Some(m),
            _ => None,
        }
    }
    pub fn stability(&self) -> Stability {
        match (&self.result.floquet, &self.result.hill) {
            (Some(f), _) => f.stability,
            (None, Some((_, s))) => *s,
            _ => Stability::Undetermined,
        }
    }
}

/// A located event.
#[derive(Debug, Clone)]
pub struct PoEvent {
    pub kind: PoEventKind,
    pub p: f64,
    /// The solution at the event (for `IP`, the last point kept).
    pub point: PoPoint,
    /// The test function's value there (for `IP`, the period of the last point kept).
    pub test: f64,
    /// Index of the branch point after the event (for `IP`, one past the last).
    pub index: usize,
}

#[derive(Debug, Clone)]
pub struct PoBranch {
    pub points: Vec<PoPoint>,
    pub events: Vec<PoEvent>,
    /// `"boundary"`, `"max_points"`, `"step_too_small"`, `"infinite_period"`,
    /// `"failed: ..."`, or a stop asked for: `"period"`, the name of the event stopped at.
    pub stop: String,
}

/// What a point needs besides its `ArcPoint`: the model family and the series' shape.
struct Ctx<'a, D> {
    base: &'a D,
    name: &'a str,
    winding: Vec<f64>,
    n_harm: usize,
    samples: usize,
    popts: PeriodicOptions,
    w: Vec<f64>,
}

impl<D: Parametric> Ctx<'_, D> {
    fn series(&self, pt: &ArcPoint) -> HbSolution {
        let n = pt.x.len();
        let omega = pt.x[n - 1];
        HbSolution {
            omega,
            coeffs: pt.x[..n - 1].to_vec(),
            winding: self.winding.clone(),
            n_harm: self.n_harm,
            samples: self.samples,
            residual: pt.residual,
            step: 0.0,
            iterations: pt.iterations,
            status: if omega > 0.0 && omega.is_finite() {
                Status::Converged
            } else {
                Status::Diverged
            },
            pivot_ratio: f64::NAN,
        }
    }

    /// Certificates and multipliers of the point, as `periodic()` gives them (the
    /// verdict bounded at the branch's harmonics: [`finish_on_branch`]).
    fn judge(&self, pt: &ArcPoint) -> Result<Periodic> {
        let m = self.base.with_param(self.name, pt.p)?;
        Ok(finish_on_branch(&m, self.series(pt), &self.popts))
    }

    /// The multipliers of a trial point of an event's location: its test function
    /// reads only them, so its verdict is not bounded ([`multipliers_on_branch`]).
    fn trial(&self, pt: &ArcPoint) -> Result<Periodic> {
        let m = self.base.with_param(self.name, pt.p)?;
        Ok(multipliers_on_branch(&m, self.series(pt), &self.popts))
    }

    fn point<P: Problem + ?Sized>(&self, prob: &mut P, pt: &ArcPoint) -> Result<PoPoint> {
        let result = self.judge(pt)?;
        let mut tests = PoTests {
            lp: pt.dp_ds(),
            bp: bordered_det(prob, pt, &self.w)?,
            ..Default::default()
        };
        let po = PoPoint {
            p: pt.p,
            result,
            arc: pt.clone(),
            tests: PoTests::default(),
            events: vec![],
            method: RowMethod::Hb,
        };
        if let Some(m) = po.multipliers() {
            let t = multiplier_tests(m);
            tests.bp_multipliers = Some(t.0);
            tests.pd = Some(t.1);
            tests.ns = Some(t.2);
            tests.complex_pairs = t.3;
        }
        Ok(PoPoint { tests, ..po })
    }
}

/// The bordered matrix's determinant with each row scaled to unit max-norm (a positive
/// factor: the sign, which changes at a branch point, and continuity are kept, and the
/// value stays in range).
fn bordered_det<P: Problem + ?Sized>(prob: &mut P, pt: &ArcPoint, w: &[f64]) -> Result<f64> {
    let n = prob.size();
    let y: Vec<f64> = pt.x.iter().copied().chain([pt.p]).collect();
    let row: Vec<f64> = w.iter().zip(&pt.tangent).map(|(w, t)| w * t).collect();
    let (mut m, _) = bordered(prob, &y, &row)?;
    for i in 0..=n {
        let s = (0..=n).fold(0.0f64, |a, j| a.max(m[(i, j)].abs()));
        if s > 0.0 {
            for j in 0..=n {
                m[(i, j)] /= s;
            }
        }
    }
    Ok(crate::numerics::linalg::ColumnLu::new(m.as_slice(), n + 1).determinant())
}

/// The index of the trivial multiplier (the one closest to 1; `usize::MAX` without any).
fn trivial_index(m: &[(f64, f64)]) -> usize {
    m.iter()
        .enumerate()
        .min_by(|a, b| {
            let da = (a.1 .0 - 1.0).hypot(a.1 .1);
            let db = (b.1 .0 - 1.0).hypot(b.1 .1);
            da.total_cmp(&db)
        })
        .map_or(usize::MAX, |(i, _)| i)
}

/// `(bp, pd, ns, complex pairs)` from the multipliers, the trivial one (closest to 1)
/// left out. Each factor is divided by a positive scale so that strongly unstable orbits
/// (moduli up to 1e7) keep the products in range.
pub(super) fn multiplier_tests(m: &[(f64, f64)]) -> (f64, f64, f64, usize) {
    let trivial = trivial_index(m);
    let (mut bp, mut pd, mut ns) = ((1.0, 0.0), (1.0, 0.0), 1.0);
    let mut pairs = 0;
    let mul = |a: (f64, f64), b: (f64, f64)| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
    for (i, &(re, im)) in m.iter().enumerate() {
        if i == trivial {
            continue;
        }
        let r = re.hypot(im);
        let s = r.max(1.0);
        bp = mul(bp, ((re - 1.0) / s, im / s));
        pd = mul(pd, ((re + 1.0) / s, im / s));
        // One factor per conjugate pair (the one with im > 0).
        if im > 1e-9 * s {
            ns *= (r * r - 1.0) / (s * s);
            pairs += 1;
        }
    }
    (bp.0, pd.0, ns, pairs)
}

/// [`periodic_branch`] both ways from the start (`opts.arc.forward` ignored): the rows
/// run from the end reached towards decreasing `p` to the end reached towards increasing
/// `p`, the start once, as one branch. The backward half is turned round: its tangents
/// and the test functions that depend on their orientation (`dp/ds`, the bordered
/// determinant) change sign, each point's `events` move to the point that now follows
/// them, and the events' `index`es are renumbered. `stop` is `"<lower end>/<upper
/// end>"`.
pub fn periodic_branch_both_ways<D: Parametric>(
    base: &D,
    name: &str,
    start: &HbSolution,
    opts: &PoBranchOptions,
) -> Result<PoBranch> {
    let mut o = opts.clone();
    o.arc.forward = false;
    let mut back = periodic_branch(base, name, start, &o)?;
    o.arc.forward = true;
    let fwd = periodic_branch(base, name, start, &o)?;
    let turn = |pt: &mut PoPoint| {
        pt.arc.tangent.iter_mut().for_each(|t| *t = -*t);
        pt.arc.det_sign = -pt.arc.det_sign;
        pt.tests.lp = -pt.tests.lp;
        pt.tests.bp = -pt.tests.bp;
    };
    back.points.iter_mut().for_each(turn);
    // An event between back points i - 1 and i lies, in the new order, just before the
    // row of back point i - 1.
    for i in 0..back.points.len().saturating_sub(1) {
        back.points[i].events = std::mem::take(&mut back.points[i + 1].events);
    }
    for e in &mut back.events {
        turn(&mut e.point);
        if matches!(e.kind, PoEventKind::Fold | PoEventKind::BranchPoint) {
            e.test = -e.test;
        }
    }
    let (points, events) = join_halves(
        (back.points, back.events),
        (fwd.points, fwd.events),
        |e: &mut PoEvent| &mut e.index,
    );
    Ok(PoBranch {
        points,
        events,
        stop: format!("{}/{}", back.stop, fwd.stop),
    })
}

/// Continues the periodic solution `start` (a converged series of `base`) in the
/// parameter `name` of `base` over `opts.arc.p_min ..= p_max`, from `base`'s value of
/// it, with `opts.periodic.hb.n_harm` harmonics, by `opts.method`: harmonic balance, or
/// collocation from the start's series ([`super::po_colloc`]), or harmonic balance
/// handing over to collocation ([`SWITCH_OMEGA_ERROR`]; the rows' `method` says which).
/// Without Floquet options a point has no `omega_error`, and `Auto` hands over only
/// where the certificates fail or omega falls below `min_omega`.
pub fn periodic_branch<D: Parametric>(
    base: &D,
    name: &str,
    start: &HbSolution,
    opts: &PoBranchOptions,
) -> Result<PoBranch> {
    opts.validate()?;
    let p0 = base.param_value(name).map_err(|_| {
        Error::param(
            "parameter",
            format!(
                "{name:?} is not a parameter of this model{}",
                crate::model::params::ball_hint(name)
            ),
        )
    })?;
    if !(opts.arc.p_min..=opts.arc.p_max).contains(&p0) {
        return Err(Error::param_range(
            "range",
            format!(
                "must contain the start's {name} = {p0}, got ({}, {})",
                opts.arc.p_min, opts.arc.p_max
            ),
            format!("lo <= {p0} <= hi"),
        ));
    }
    check_start(base, start)?;
    let (popts, n_harm, samples) = branch_options(&opts.periodic);
    let copts = &opts.collocation;
    if opts.method == Method::Collocation {
        let dir = if opts.arc.forward { 1.0 } else { -1.0 };
        let tail = collocation_tail(
            base,
            name,
            &popts,
            opts,
            dir,
            TailStart {
                from_p: p0,
                orbit: CollocOrbit::from_hb(start, copts.ntst, copts.ncol),
                first_p: p0,
                before: None,
                offset: 0,
                h0: opts.arc.ds,
            },
        )?;
        if tail.points.is_empty() {
            return Err(Error::param(
                "start",
                format!("does not converge by collocation at {name} = {p0}"),
            ));
        }
        return Ok(PoBranch {
            points: tail.points,
            events: tail.events,
            stop: tail.stop,
        });
    }
    // The start at the branch's own harmonics and samples.
    let first = solve(base, start, &popts.hb);
    if first.status != Status::Converged {
        return Err(Error::param(
            "start",
            format!(
                "does not converge with N = {n_harm} at {name} = {p0} (status {})",
                first.status.as_str()
            ),
        ));
    }
    let mut prob = HbProblem::new(
        ModelAt::family(base, name, p0),
        &first.winding,
        n_harm,
        samples,
    );
    let n1 = prob.size() + 1;
    let ctx = Ctx {
        base,
        name,
        winding: first.winding.clone(),
        n_harm,
        samples,
        popts,
        w: opts
            .arc
            .weights
            .clone()
            .filter(|w| w.len() == n1)
            .unwrap_or_else(|| vec![1.0; n1]),
    };
    let mut tests = PoTestsDeclared {
        ctx,
        min_omega: opts.min_omega,
        auto: opts.method == Method::Auto,
        switched: None,
    };
    let x0 = first.unknowns();
    let from = Start {
        x: &x0,
        p: p0,
        direction: None,
    };
    let mut controls = opts.controls.clone();
    if let Some(t) = opts.stop_period {
        let t0 = first.period();
        if !(t > t0) {
            return Err(Error::param_range(
                "stop_period",
                format!("{t} does not exceed the start's period {t0}"),
                format!("> {t0}"),
            ));
        }
        // omega, the last unknown, falls through 2 pi / T as the period grows through T
        controls.stop_level = Some(Level {
            index: n1 - 2,
            value: std::f64::consts::TAU / t,
            why: "period",
        });
    }
    let run = continuation::branch(
        &mut prob,
        from,
        &opts.arc,
        opts.event_tol,
        &controls,
        &mut tests,
    )?;
    let (mut points, mut events) = (run.points, run.events);
    let mut stop = ArcStop::text(Some(&run.stop));
    if let (Some(pb), Some(a)) = (tests.switched, points.last().cloned()) {
        let tail = collocation_tail(
            base,
            name,
            &tests.ctx.popts,
            opts,
            (pb - a.p).signum(),
            TailStart {
                from_p: a.p,
                orbit: CollocOrbit::from_hb(&a.result.sol, copts.ntst, copts.ncol),
                first_p: pb,
                offset: points.len(),
                h0: (pb - a.p).abs(),
                before: Some(a),
            },
        )?;
        points.extend(tail.points);
        events.extend(tail.events);
        stop = tail.stop;
    }
    Ok(PoBranch {
        points,
        events,
        stop,
    })
}

/// Multipliers farther than this outside the unit circle count as unstable (a
/// multiplier on the circle, a family's neutral direction, sits at the monodromy's
/// error from it and must not look like a crossing).
const UNSTABLE_MULTIPLIER: f64 = 1e-6;

/// What the step control reads of a point's multipliers (the trivial one, nearest 1,
/// left out): those outside the unit circle, and the modulus minus one of the complex
/// pair nearest it.
fn multiplier_spectrum(m: &[(f64, f64)]) -> Spectrum {
    let trivial = trivial_index(m);
    let others = m.iter().enumerate().filter(|(i, _)| *i != trivial);
    let unstable = others
        .clone()
        .filter(|(_, z)| z.0.hypot(z.1) > 1.0 + UNSTABLE_MULTIPLIER)
        .count();
    let pair = others
        .filter(|(_, z)| z.1.abs() > 1e-9 * z.0.hypot(z.1).max(1.0))
        .map(|(_, z)| z.0.hypot(z.1) - 1.0)
        .fold(f64::NAN, |m, d| {
            if d.abs() < m.abs() || m.is_nan() {
                d
            } else {
                m
            }
        });
    Spectrum { unstable, pair }
}

/// The declared tests of a periodic branch, in [`PoTestsDeclared::NAMES`]' order: `dp/ds`
/// (fold), the bordered determinant (branch point), and on the multipliers: period
/// doubling, Neimark–Sacker, and a real multiplier through +1 that neither of the first
/// two explains (branch point).
struct PoTestsDeclared<'a, D> {
    ctx: Ctx<'a, D>,
    min_omega: f64,
    /// [`Method::Auto`]: hand over to collocation (see [`SWITCH_OMEGA_ERROR`]).
    auto: bool,
    /// Where it handed over: the parameter of the first point not kept.
    switched: Option<f64>,
}

impl<D> PoTestsDeclared<'_, D> {
    const NAMES: [&'static str; 5] = [
        "fold",
        "branch_point",
        "period_doubling",
        "neimark_sacker",
        "branch_point_multipliers",
    ];
    const KINDS: [PoEventKind; 5] = [
        PoEventKind::Fold,
        PoEventKind::BranchPoint,
        PoEventKind::PeriodDoubling,
        PoEventKind::NeimarkSacker,
        PoEventKind::BranchPoint,
    ];
}

fn po_values(t: &PoTests) -> Vec<Option<f64>> {
    vec![Some(t.lp), Some(t.bp), t.pd, t.ns, t.bp_multipliers]
}

impl<D: Parametric, P: Problem + ?Sized> Declared<P> for PoTestsDeclared<'_, D> {
    type Point = PoPoint;
    type Event = PoEvent;

    fn names(&self) -> &'static [&'static str] {
        &Self::NAMES
    }

    fn point(&mut self, prob: &mut P, pt: &ArcPoint) -> Result<PoPoint> {
        self.ctx.point(prob, pt)
    }

    fn arc<'p>(&self, point: &'p PoPoint) -> &'p ArcPoint {
        &point.arc
    }

    fn values(&self, point: &PoPoint) -> Vec<Option<f64>> {
        po_values(&point.tests)
    }

    fn spectrum(&self, point: &PoPoint) -> Option<Spectrum> {
        point.multipliers().map(multiplier_spectrum)
    }

    fn value_at(&mut self, prob: &mut P, _a: &PoPoint, pt: &ArcPoint, i: usize) -> Result<f64> {
        match i {
            0 => Ok(pt.dp_ds()),
            1 => bordered_det(prob, pt, &self.ctx.w),
            // Multiplier test functions: evaluated (monodromy or Hill) at each trial point.
            _ => {
                let r = self.ctx.trial(pt)?;
                let m = match (&r.floquet, &r.hill) {
                    (Some(f), _) => f.multipliers.clone(),
                    (None, Some((m, _))) => m.clone(),
                    _ => return Ok(f64::NAN),
                };
                let t = multiplier_tests(&m);
                Ok([t.1, t.2, t.0][i - 2])
            }
        }
    }

    fn values_at(&mut self, prob: &mut P, b: &PoPoint, pt: &ArcPoint) -> Result<Vec<Option<f64>>> {
        let mut v = vec![Some(pt.dp_ds()), Some(bordered_det(prob, pt, &self.ctx.w)?)];
        let r = self.ctx.trial(pt)?;
        let m = match (&r.floquet, &r.hill) {
            (Some(f), _) => Some(&f.multipliers),
            (None, Some((m, _))) => Some(m),
            _ => None,
        };
        match m.map(|m| multiplier_tests(m)) {
            Some(t) => {
                // The Neimark–Sacker product compares only across the same pairs.
                let ns = (t.3 == b.tests.complex_pairs).then_some(t.2);
                v.extend([Some(t.1), ns, Some(t.0)]);
            }
            None => v.extend([None, None, None]),
        }
        Ok(v)
    }

    fn watched(&self, a: &PoPoint, b: &PoPoint) -> Vec<usize> {
        let (va, vb) = (po_values(&a.tests), po_values(&b.tests));
        let changes = |i: usize| matches!((va[i], vb[i]), (Some(x), Some(y)) if x * y < 0.0);
        let (fold, det_flip) = (changes(0), changes(1));
        let same_pairs = a.tests.complex_pairs == b.tests.complex_pairs;
        (0..5)
            .filter(|&i| changes(i))
            .filter(|&i| i != 3 || same_pairs)
            .filter(|&i| i != 4 || !(fold || det_flip))
            .collect()
    }

    fn event(
        &mut self,
        prob: &mut P,
        i: usize,
        e: &ArcPoint,
        g: f64,
        row: usize,
    ) -> Result<Option<PoEvent>> {
        Ok(Some(PoEvent {
            kind: Self::KINDS[i],
            p: e.p,
            point: self.ctx.point(prob, e)?,
            test: g,
            index: row,
        }))
    }

    /// A Neimark–Sacker pair moves two multipliers across the circle, a user point
    /// none, the others one.
    fn moves(&self, e: &PoEvent) -> usize {
        match e.kind {
            PoEventKind::NeimarkSacker => 2,
            PoEventKind::User => 0,
            _ => 1,
        }
    }

    fn kind(&self, e: &PoEvent) -> &'static str {
        e.kind.as_str()
    }

    /// The user point judged as a row; its test is the parameter's distance from the
    /// value asked for: 0.
    fn user(&mut self, prob: &mut P, e: &ArcPoint, row: usize) -> Result<Option<PoEvent>> {
        Ok(Some(PoEvent {
            kind: PoEventKind::User,
            p: e.p,
            point: self.ctx.point(prob, e)?,
            test: 0.0,
            index: row,
        }))
    }

    fn end(&mut self, points: &[PoPoint], b: &PoPoint) -> Option<(&'static str, Option<PoEvent>)> {
        let prev = points.last()?;
        let certified = b.result.sol.status == Status::Converged;
        let falling = b.omega() < prev.omega();
        let loose = b
            .result
            .omega_error
            .is_some_and(|e| e > SWITCH_OMEGA_ERROR * b.omega());
        if self.auto && falling && (loose || !certified || b.omega() < self.min_omega) {
            self.switched = Some(b.p);
            return Some(("collocation", None));
        }
        (b.omega() < self.min_omega || (!certified && falling))
            .then(|| ("infinite_period", Some(infinite_period(points))))
    }

    /// Events in the order the branch meets them, noted on the row that follows them.
    fn settle(&mut self, a: &PoPoint, b: &mut PoPoint, events: &mut Vec<PoEvent>) {
        events.sort_by(|x, y| {
            let s = |e: &PoEvent| (e.p - a.p).abs();
            s(x).total_cmp(&s(y))
        });
        b.events = events.iter().map(|e| e.kind).collect();
    }
}

/// The `IP` event: `p*` from the last three points kept, fitted as
/// `T = C / sqrt|p - p*| + D` ([`snic_fit`]); with fewer points, or when the three do
/// not fit that form, where `omega^2`, linear in `p`, extrapolates to 0 from the last two.
fn infinite_period(points: &[PoPoint]) -> PoEvent {
    let last = points.last().expect("a point before the end").clone();
    let k = points.len();
    let fitted = (k >= 3)
        .then(|| {
            let at = |i: usize| (points[i].p, points[i].result.sol.period());
            snic_fit([at(k - 3), at(k - 2), at(k - 1)])
        })
        .flatten();
    let p_star = fitted.unwrap_or_else(|| match k {
        0 | 1 => last.p,
        k => {
            let a = &points[k - 2];
            let (w1, w2) = (a.omega().powi(2), last.omega().powi(2));
            if (w2 - w1).abs() > 0.0 {
                last.p - w2 * (last.p - a.p) / (w2 - w1)
            } else {
                last.p
            }
        }
    });
    PoEvent {
        kind: PoEventKind::InfinitePeriod,
        p: p_star,
        test: last.result.sol.period(),
        point: last,
        index: points.len(),
    }
}

/// `p*` such that `T = C / sqrt|p - p*| + D` (with `C > 0`) passes through three
/// `(p, T)` points, monotone in `p` with `T` growing towards the last, `p*` beyond the
/// last. For `p* = p3 + sigma delta` the two secant slopes of `T` against
/// `u = 1 / sqrt|p - p*|` are equal at the answer; their difference is negative as
/// `delta -> 0` (the last slope vanishes) and positive for large `delta` when `T` is
/// convex in `p`, so bisection in `log delta` finds it. `None` when the points do not
/// have that shape.
fn snic_fit(pts: [(f64, f64); 3]) -> Option<f64> {
    let [(p1, t1), (p2, t2), (p3, t3)] = pts;
    let sigma = (p3 - p2).signum();
    let ok = pts.iter().all(|(p, t)| p.is_finite() && t.is_finite())
        && sigma != 0.0
        && (p2 - p1).signum() == sigma
        && t1 < t2
        && t2 < t3;
    if !ok {
        return None;
    }
    let g = |delta: f64| {
        let ps = p3 + sigma * delta;
        let u = |p: f64| 1.0 / (p - ps).abs().sqrt();
        (t3 - t2) / (u(p3) - u(p2)) - (t2 - t1) / (u(p2) - u(p1))
    };
    let span = (p3 - p1).abs();
    let (mut lo, mut hi) = ((span * 1e-9).ln(), (span * 1e3).ln());
    if !(g(lo.exp()) < 0.0 && g(hi.exp()) > 0.0) {
        return None;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid.exp()) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-14 {
            break;
        }
    }
    let delta = (0.5 * (lo + hi)).exp();
    let ps = p3 + sigma * delta;
    let u = |p: f64| 1.0 / (p - ps).abs().sqrt();
    let c = (t3 - t2) / (u(p3) - u(p2));
    (c > 0.0 && ps.is_finite()).then_some(ps)
}

/// `Err` naming `start` unless it is a periodic solution of `base`'s shape with a
/// positive frequency and finite coefficients.
pub(crate) fn check_start<D: crate::Dynamics + ?Sized>(base: &D, start: &HbSolution) -> Result<()> {
    let d = base.ndof();
    if start.winding.len() != d
        || start.coeffs.len() != d * (2 * start.n_harm + 1)
        || !(start.omega > 0.0 && start.omega.is_finite())
        || start.coeffs.iter().any(|c| !c.is_finite())
    {
        return Err(Error::param(
            "start",
            "needs a converged periodic solution of this model (omega > 0, finite coefficients)",
        ));
    }
    Ok(())
}

/// The periodic options a branch or curve solves with: no `auto` (the harmonics stay
/// fixed along it) and the sample count fixed; with the harmonics and samples.
pub(crate) fn branch_options(periodic: &PeriodicOptions) -> (PeriodicOptions, usize, usize) {
    let mut popts = periodic.clone();
    popts.auto = None;
    let n_harm = popts.hb.n_harm;
    let samples = popts.hb.samples.unwrap_or_else(|| default_samples(n_harm));
    popts.hb.samples = Some(samples);
    (popts, n_harm, samples)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::floquet::FloquetOptions;
    use crate::hb::HbOptions;
    use crate::periodic::periodic;
    use crate::Planar;

    pub(in crate::bifurcation) fn opts(
        n: usize,
        lo: f64,
        hi: f64,
        forward: bool,
    ) -> PoBranchOptions {
        PoBranchOptions {
            arc: ArcOptions {
                ds: 0.02,
                ds_max: 0.1,
                ds_min: 1e-6,
                max_points: 300,
                p_min: lo,
                p_max: hi,
                forward,
                ..Default::default()
            },
            periodic: PeriodicOptions {
                hb: HbOptions {
                    n_harm: n,
                    ..Default::default()
                },
                floquet: Some(FloquetOptions::default()),
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// `T = C / sqrt|p - p*| + D` sampled on either side of `p*` gives back `p*`; the
    /// two-point `omega^2` extrapolation it replaces is off by the `D` term.
    #[test]
    fn snic_fit_recovers_the_end_of_a_period_law() {
        for (ps, sigma, d) in [(0.9, -1.0, -100.0), (1.3, 1.0, 40.0), (0.5, -1.0, 0.0)] {
            let t = |p: f64| 50.0 / (p - ps).abs().sqrt() + d;
            let p = [ps - sigma * 0.03, ps - sigma * 0.02, ps - sigma * 0.012];
            let got = snic_fit([(p[0], t(p[0])), (p[1], t(p[1])), (p[2], t(p[2]))]).unwrap();
            assert!((got - ps).abs() < 1e-9, "{got} vs {ps}");
        }
        // Not growing towards the end: no fit.
        assert!(snic_fit([(1.0, 3.0), (0.99, 2.0), (0.98, 1.0)]).is_none());
    }

    #[test]
    fn multiplier_tests_change_sign_at_their_crossings() {
        let base = [(1.0, 0.0), (0.5, 0.0)];
        let with = |z: (f64, f64)| {
            let mut m = base.to_vec();
            m.push(z);
            multiplier_tests(&m)
        };
        assert!(with((-0.9, 0.0)).1 * with((-1.1, 0.0)).1 < 0.0);
        assert!(with((0.9, 0.0)).0 * with((1.1, 0.0)).0 < 0.0);
        let ns = |r: f64| {
            let mut m = base.to_vec();
            m.push((r * 0.6, r * 0.8));
            m.push((r * 0.6, -r * 0.8));
            multiplier_tests(&m)
        };
        assert!(ns(0.9).2 * ns(1.1).2 < 0.0);
        assert_eq!(ns(0.9).3, 1);
        // A complex pair does not change the PD or BP signs.
        assert!(ns(0.9).1 > 0.0 && ns(1.1).1 > 0.0);
    }

    /// Tien's (2011) standard R-R orbit continued up in Omega: every point's residual is
    /// Newton's, and a point re-solved by `periodic()` at its Omega gives the same omega.
    #[test]
    fn branch_points_are_solutions_of_periodic() {
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let o = opts(6, 1.2, 1.3, true);
        let start = periodic(&p, &[true, true], None, &o.periodic);
        assert_eq!(start.sol.status, Status::Converged);
        let b = periodic_branch(&p, "Omega", &start.sol, &o).unwrap();
        assert_eq!(b.stop, "boundary", "{}", b.stop);
        assert_eq!(b.points.last().unwrap().p, 1.3);
        for pt in b.points.iter().step_by(5) {
            let q = p.with_param("Omega", pt.p).unwrap();
            let r = periodic(&q, &[true, true], Some(&pt.result.sol), &o.periodic);
            assert!((r.sol.omega - pt.omega()).abs() < 1e-8);
        }
    }

    #[test]
    fn bad_inputs_name_the_parameter() {
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let o = opts(4, 1.2, 1.3, true);
        let start = periodic(&p, &[true, true], None, &o.periodic);
        let name = |r: Result<PoBranch>| match r {
            Err(Error::InvalidParameter { name, .. }) => name,
            other => panic!("{:?}", other.map(|b| b.stop)),
        };
        assert_eq!(
            name(periodic_branch(&p, "nope", &start.sol, &o)),
            "parameter"
        );
        assert_eq!(
            name(periodic_branch(
                &p,
                "Omega",
                &start.sol,
                &opts(4, 1.3, 1.4, true)
            )),
            "range"
        );
        assert_eq!(
            name(periodic_branch(
                &p,
                "Omega",
                &start.sol,
                &opts(4, 1.3, 1.2, true)
            )),
            "range"
        );
        let mut bad = start.sol.clone();
        bad.omega = -1.0;
        assert_eq!(name(periodic_branch(&p, "Omega", &bad, &o)), "start");
        let mut o2 = o.clone();
        o2.min_omega = f64::NAN;
        assert_eq!(
            name(periodic_branch(&p, "Omega", &start.sol, &o2)),
            "min_omega"
        );
    }
}
