//! Basins of attraction: where starts from given ball angles (at rest in the ground
//! frame, Tien's (2011) set-up of its figures 4-15 and 4-16) settle, each simulated for
//! `t_end` time units and labelled by the motion seen over the last `window`.
//!
//! The labels, for two balls: the perfect balance (rest with `x = y = 0`), another
//! equilibrium (rest elsewhere), merged R-R (both balls rotate and their gap
//! `|wrap(b1 - b2)|` stays below `merge_tol`), separated R-R (both rotate, apart: their
//! gap oscillates or they pass each other), R-O, O-O; `other` is any motion of another
//! number of balls (the `pattern` says which balls rotate); `not_settled` a motion
//! whose rotation pattern or mean ball rates differ between the two halves of the
//! window, or whose oscillation still grows; `failed` an integration that failed.
//!
//! The periods come from whole-turn crossings of a rotating ball (one to
//! [`MAX_TURNS`] turns per period: Tien's (2011) balls rotating separately take two)
//! and from mean crossings of `x` otherwise ([`super::attractors`]' detector); a motion
//! without a regular period (a torus: two separated balls whose gap is modulated) keeps
//! its label and has no period. A start that is not settled after `t_end` (see
//! [`Outcome::needs_more`]) is simulated further, `t_end` at a time, up to
//! `extend_factor * t_end`. Every start is simulated on its own, so the labels do not
//! depend on the thread count or on which other starts run.

use super::attractors::{oscillation_period, turn_period, Oscillation};
use crate::cancel;
use crate::equilibria::wrap;
use crate::error::{check_range, Error, Result};
use crate::model::{first_order_rhs, Dynamics};
use crate::ode::{Dopri5, Options};
use rayon::prelude::*;
use std::f64::consts::PI;

/// How a start is simulated and judged.
#[derive(Debug, Clone)]
pub struct BasinOptions {
    /// Time simulated (Tien (2011): 1000).
    pub t_end: f64,
    /// The last part of `[0, t_end]` the motion is judged on; it must hold at least one
    /// turn of a rotating ball per half.
    pub window: f64,
    pub rtol: f64,
    pub atol: f64,
    /// Largest `|x + i y|` of a rest state called the perfect balance (every other
    /// equilibrium of the planar model is at a distance of order `mu / |Omega^2 - 1|`).
    pub rest_tol: f64,
    /// Largest gap `|wrap(b1 - b2)|` over the window of a merged pair.
    pub merge_tol: f64,
    /// Settle check: simulate again for `settle_factor * t_end` and report whether the
    /// label is the same.
    pub settle_factor: Option<f64>,
    /// End a start's simulation before `t_end` once its attractor is clear (a
    /// converged periodic orbit, a clean decay to rest); the label is the one the full
    /// run gives. A speed sweep turns it off: its state must be the one after the dwell.
    pub early_stop: bool,
    /// Longest total time a start is simulated, in units of `t_end`: a start whose
    /// motion is not settled after `t_end` (see [`Outcome::needs_more`]) is simulated
    /// further, `t_end` at a time, from where it stopped, until it is or this total is
    /// reached. 1: no extension.
    pub extend_factor: f64,
}

impl Default for BasinOptions {
    fn default() -> Self {
        BasinOptions {
            t_end: 1000.0,
            window: 300.0,
            rtol: 1e-6,
            atol: 1e-8,
            rest_tol: 0.05,
            merge_tol: 0.5,
            settle_factor: None,
            early_stop: true,
            extend_factor: 8.0,
        }
    }
}

/// Largest `extend_factor`: a start that has not settled in 64 times Tien's (2011) 1000
/// time units is a torus or chaos, not a slow transient.
pub const MAX_EXTEND_FACTOR: f64 = 64.0;

impl BasinOptions {
    pub fn validate(&self) -> Result<()> {
        check_range("t_end", self.t_end, 0.0, true, 1e6, false)?;
        check_range("window", self.window, 0.0, true, self.t_end, false)?;
        check_range("rtol", self.rtol, 0.0, true, 1.0, true)?;
        check_range("atol", self.atol, 0.0, true, 1.0, true)?;
        check_range("rest_tol", self.rest_tol, 0.0, true, f64::INFINITY, true)?;
        check_range("merge_tol", self.merge_tol, 0.0, true, PI, false)?;
        if let Some(f) = self.settle_factor {
            check_range("settle_factor", f, 1.0, true, 100.0, false)?;
        }
        check_range(
            "extend_factor",
            self.extend_factor,
            1.0,
            false,
            MAX_EXTEND_FACTOR,
            false,
        )?;
        Ok(())
    }
}

/// The basin classes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Label {
    PerfectBalance,
    OtherEquilibrium,
    MergedRR,
    SeparatedRR,
    RO,
    OO,
    Other,
    NotSettled,
    Failed,
}

impl Label {
    /// The name tables use.
    pub fn as_str(self) -> &'static str {
        match self {
            Label::PerfectBalance => "perfect_balance",
            Label::OtherEquilibrium => "other_equilibrium",
            Label::MergedRR => "merged_R-R",
            Label::SeparatedRR => "separated_R-R",
            Label::RO => "R-O",
            Label::OO => "O-O",
            Label::Other => "other",
            Label::NotSettled => "not_settled",
            Label::Failed => "failed",
        }
    }
}

/// Where one start went.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub label: Label,
    /// Which balls rotate ("R-R", "R-O", ...; empty when at rest or unknown).
    pub pattern: String,
    /// Mean ball rate over the window: the rotating balls' mean lag `-(b_end -
    /// b_start) / window` (the `omega` of a periodic R solution), 0 with none rotating,
    /// NaN when failed.
    pub omega: f64,
    /// Each ball's mean rate `-(b_end - b_start) / window`.
    pub rates: Vec<f64>,
    /// Period of a periodic motion, when regular.
    pub period: Option<f64>,
    /// Each ball's whole turns per `period` (negative: lagging the disk, as the
    /// `winding` of a periodic solution); empty without a period.
    pub windings: Vec<i64>,
    /// The period repeats over the window's last three periods, each to
    /// [`STRICT_PERIOD_TOL`], with a whole number of turns of every rotating ball (the
    /// `period` alone may come from the looser test of the last two turns to 2 %, which
    /// also passes a slowly converging orbit or a weakly modulated torus).
    pub period_strict: bool,
    /// How many extensions of `t_end` the start needed (see
    /// [`BasinOptions::extend_factor`]).
    pub extensions: usize,
    /// Time simulated in all (less than `t_end` when the start came to rest early).
    pub t_stop: f64,
    /// With the settle check: the label after the longer run.
    pub long_label: Option<Label>,
    /// The state at `t_stop` (a speed sweep carries it on to the next step).
    pub y_end: Vec<f64>,
}

impl Outcome {
    /// Whether the motion is not settled yet and is worth simulating further: a
    /// `not_settled` label, or a moving class (rotating or oscillating) whose period
    /// does not repeat strictly (see [`STRICT_PERIOD_TOL`]). A torus is extended too,
    /// up to the longest time: the torus test (steady mean rates and gap) is no proof,
    /// on Tien's (2011) Omega 1.2 grid it passes separated rotations still converging to
    /// their two-turn orbit after 800 time units.
    pub fn needs_more(&self) -> bool {
        match self.label {
            Label::NotSettled => true,
            Label::Failed | Label::PerfectBalance | Label::OtherEquilibrium => false,
            _ => !self.period_strict,
        }
    }

    /// What kind of motion the start ended on: `rest`, `periodic` (a regular period: a
    /// periodic orbit to link), `quasi_periodic` (moving without a regular period: a
    /// torus, or a motion that did not repeat within the longest time allowed),
    /// `not_settled` or `failed`.
    pub fn motion(&self) -> &'static str {
        match self.label {
            Label::NotSettled => "not_settled",
            Label::Failed => "failed",
            Label::PerfectBalance | Label::OtherEquilibrium => "rest",
            _ if self.period.is_some() => "periodic",
            _ => "quasi_periodic",
        }
    }
}

/// Tien's (2011) start: at rest in the ground frame (`x = y = x' = y' = 0`,
/// `b_i' = -Omega`) with ball angles `balls`.
pub fn ground_rest_start<D: Dynamics + ?Sized>(model: &D, balls: &[f64]) -> Vec<f64> {
    let d = model.ndof();
    let o = model.first_ball();
    let mut y = vec![0.0; 2 * d];
    for (i, &b) in balls.iter().enumerate() {
        y[o + i] = b;
        y[d + o + i] = -model.base_spin();
    }
    y
}

/// Samples of the window, every `DT`.
const DT: f64 = 0.1;
/// Samples of the early stop's checks: coarser, they only have to see the motion's
/// shape (the outcome's rates and period then come from whole-turn crossings
/// interpolated between them).
const PROBE_DT: f64 = 0.2;

/// Classifies the start `y0` (with the settle check if asked). `Err` only when
/// cancelled. With `opts.early_stop` the simulation may end before `t_end` once the
/// attractor is clear (see [`EarlyStop`]); the settle check's longer run never does.
pub fn classify_start<D: Dynamics + ?Sized>(
    model: &D,
    y0: &[f64],
    opts: &BasinOptions,
) -> Result<Outcome> {
    let mut out = judge(model, y0, opts.t_end, opts, opts.early_stop)?;
    // Extensions continue from the state reached, each judged as a start of its own (a
    // fresh integrator; autonomous equations, so only the time origin moves).
    let mut total = out.t_stop;
    let longest = opts.extend_factor * opts.t_end;
    while out.needs_more() && total + opts.t_end <= longest * (1.0 + 1e-12) {
        let y = std::mem::take(&mut out.y_end);
        let mut next = judge(model, &y, opts.t_end, opts, opts.early_stop)?;
        next.extensions = out.extensions + 1;
        total += next.t_stop;
        out = next;
    }
    out.t_stop = total;
    if let Some(f) = opts.settle_factor {
        out.long_label = Some(judge(model, y0, f * opts.t_end, opts, false)?.label);
    }
    Ok(out)
}

/// Samples `(t, state)` every `DT`, flat (one allocation for the whole window).
#[derive(Default)]
struct Samples {
    t: Vec<f64>,
    y: Vec<f64>,
    w: usize,
}

impl Samples {
    fn new(w: usize) -> Self {
        Samples {
            t: vec![],
            y: vec![],
            w,
        }
    }
    fn push(&mut self, t: f64, y: &[f64]) {
        self.t.push(t);
        self.y.extend_from_slice(y);
    }
    fn len(&self) -> usize {
        self.t.len()
    }
    fn at(&self, k: usize) -> &[f64] {
        &self.y[k * self.w..(k + 1) * self.w]
    }
    /// Drops the samples before `t0` once they are the larger part (moving the rest
    /// down less often).
    fn drop_before(&mut self, t0: f64) {
        let k = self.t.partition_point(|&t| t < t0);
        if 2 * k > self.t.len() {
            self.t.drain(..k);
            self.y.drain(..k * self.w);
        }
    }
    /// The samples from index `k0` on.
    fn from(&self, k0: usize) -> Window<'_> {
        Window {
            t: &self.t[k0..],
            y: &self.y[k0 * self.w..],
            w: self.w,
        }
    }
}

/// A run of samples the label is read from.
#[derive(Clone, Copy)]
struct Window<'a> {
    t: &'a [f64],
    y: &'a [f64],
    w: usize,
}

impl Window<'_> {
    fn len(&self) -> usize {
        self.t.len()
    }
    fn at(&self, k: usize) -> &[f64] {
        &self.y[k * self.w..(k + 1) * self.w]
    }
}

/// Early stopping of a start whose attractor is already clear. At checkpoints every
/// `CHECK_STEP` time units the motion over the last `check` time units is labelled as
/// the final window would be, and the simulation stops when
/// - that label is a rotating one (merged R-R, separated R-R, R-O, other), the same as
///   at the previous checkpoint, and the Poincare section at the whole turns of a
///   rotating ball has converged (the last two returns differ by less than
///   `SECTION_TOL` in every coordinate and contract): the motion is on a periodic orbit,
///   which every later window labels alike; the balls' turns per return must give the
///   same rotation pattern, and the balls' largest gap over the last return must lie
///   clear of `merge_tol`;
/// - or it is a rest label, at this and the previous checkpoint, with the velocities
///   over the second half of the window below `REST_DECAY` times those of the first
///   (the final window's test is 0.8), no ball turning, and `|x + i y|` clear of
///   `rest_tol` by twice its spread over the second half;
/// - or two balls rotate apart, read so over a whole final window at `TORUS_RUNS`
///   checkpoints in a row with steady rates and gap ([`torus_is_clear`]), and that
///   window's turns repeat with a regular period of several turns (a torus, with no
///   period, runs on to `t_end`).
///
/// Anything else (not settled, O-O, a slow decay) runs to `t_end` as without early
/// stopping. The tests compare the labels with full runs (and with long simulations).
struct EarlyStop {
    /// Length of the window judged at a checkpoint.
    check: f64,
    next_check: f64,
    probe: Samples,
    next_probe: u64,
    /// Per ball, the last three returns to a whole turn: `(t, state)`.
    returns: Vec<Vec<(f64, Vec<f64>)>>,
    prev_label: Option<Label>,
    /// Consecutive checkpoints with the same label.
    runs: usize,
    /// Consecutive checkpoints whose whole final window reads separated R-R.
    torus_runs: usize,
    y_prev: Vec<f64>,
}

const CHECK_STEP: f64 = 25.0;
const SECTION_TOL: f64 = 1e-4;
const REST_DECAY: f64 = 0.7;
const TORUS_RUNS: usize = 5;
const TORUS_RATE: f64 = 0.07;
const TORUS_GAP: f64 = 0.1;

impl EarlyStop {
    fn new(check: f64, y0: &[f64]) -> Self {
        EarlyStop {
            check,
            next_check: check,
            probe: Samples::new(y0.len()),
            next_probe: 0,
            returns: vec![],
            prev_label: None,
            runs: 0,
            torus_runs: 0,
            y_prev: y0.to_vec(),
        }
    }

    /// Records the step `[ta, tb]`'s samples and whole-turn returns.
    fn observe(
        &mut self,
        tb: f64,
        dense: &crate::ode::Dense<'_>,
        d: usize,
        o: usize,
        tmp: &mut [f64],
    ) {
        let n = d - o;
        if self.returns.is_empty() {
            self.returns = vec![vec![]; n];
        }
        loop {
            let t = self.next_probe as f64 * PROBE_DT;
            if t > tb {
                break;
            }
            dense.eval(t, tmp);
            self.probe.push(t, tmp);
            self.next_probe += 1;
        }
        let (ta, _) = dense.span();
        let y1 = dense.end();
        for i in 0..n {
            let (a, b) = (self.y_prev[o + i], y1[o + i]);
            let (ka, kb) = ((a / (2.0 * PI)).floor(), (b / (2.0 * PI)).floor());
            if ka == kb {
                continue;
            }
            // The crossing of the level between the two: Newton on the cubic Hermite
            // interpolant of the angle and its rate at the step's ends (accurate to
            // the step's fourth power, far below the section tolerance), then one dense
            // evaluation of the whole state there.
            let level = 2.0 * PI * ka.max(kb);
            let h = tb - ta;
            let (p0, p1) = (a - level, b - level);
            let (m0, m1) = (h * self.y_prev[d + o + i], h * y1[d + o + i]);
            let herm = |s: f64| {
                let (s2, s3) = (s * s, s * s * s);
                let v = (2.0 * s3 - 3.0 * s2 + 1.0) * p0
                    + (s3 - 2.0 * s2 + s) * m0
                    + (-2.0 * s3 + 3.0 * s2) * p1
                    + (s3 - s2) * m1;
                let dv = (6.0 * s2 - 6.0 * s) * p0
                    + (3.0 * s2 - 4.0 * s + 1.0) * m0
                    + (-6.0 * s2 + 6.0 * s) * p1
                    + (3.0 * s2 - 2.0 * s) * m1;
                (v, dv)
            };
            let mut sc = p0 / (p0 - p1);
            for _ in 0..8 {
                let (v, dv) = herm(sc);
                if dv == 0.0 {
                    break;
                }
                let next = (sc - v / dv).clamp(0.0, 1.0);
                let done = (next - sc).abs() < 1e-13;
                sc = next;
                if done {
                    break;
                }
            }
            let tc = ta + sc * h;
            dense.eval(tc, tmp);
            let r = &mut self.returns[i];
            if r.len() == 3 {
                r.remove(0);
            }
            r.push((tc, tmp.to_vec()));
        }
        self.y_prev.copy_from_slice(y1);
    }

    /// At a checkpoint: the outcome to stop with, if the attractor is clear.
    fn decide(
        &mut self,
        t: f64,
        y: &[f64],
        d: usize,
        o: usize,
        t_end: f64,
        opts: &BasinOptions,
    ) -> Option<Outcome> {
        let n = d - o;
        let k0 = self.probe.t.partition_point(|&s| s < t - self.check);
        let win = self.probe.from(k0);
        let cand = label_window(win, PROBE_DT, y, t, d, o, opts);
        let runs = if self.prev_label == Some(cand.label) {
            self.runs + 1
        } else {
            1
        };
        let mut cand = cand;
        let mut clear = runs >= 2
            && match cand.label {
                Label::PerfectBalance | Label::OtherEquilibrium => {
                    match rest_is_clear(win, d, t_end, opts) {
                        Some(l) => {
                            cand.label = l;
                            true
                        }
                        None => false,
                    }
                }
                Label::MergedRR | Label::SeparatedRR | Label::RO | Label::Other
                    if cand.pattern.contains('R') =>
                {
                    // A converged section is the stronger test of a regular period.
                    let c = self.orbit_is_clear(&cand, t - self.check, win, d, o, opts);
                    cand.period_strict |= c && cand.period.is_some();
                    c
                }
                _ => false,
            };
        self.prev_label = Some(cand.label);
        self.runs = runs;
        // A torus has no periodic orbit to converge to: it is judged over a whole
        // final window, as the final judgement does.
        if !clear && n == 2 && t >= opts.window && cand.pattern == "R-R" {
            let k1 = self.probe.t.partition_point(|&s| s < t - opts.window);
            let long = self.probe.from(k1);
            let whole = label_window(long, PROBE_DT, y, t, d, o, opts);
            self.torus_runs = if whole.label == Label::SeparatedRR {
                self.torus_runs + 1
            } else {
                0
            };
            // What looks like a torus may be an orbit of several turns per period
            // still converging (Tien's (2011) separated rotations at Omega 1.2): stop
            // only once its period repeats; a torus runs on to `t_end`.
            if self.torus_runs >= TORUS_RUNS && whole.period_strict && torus_is_clear(long, o, opts)
            {
                cand = whole;
                clear = true;
            }
        } else {
            self.torus_runs = 0;
        }
        self.next_check += CHECK_STEP;
        // The torus test looks at a whole final window.
        self.probe.drop_before(self.next_check - opts.window - 1.0);
        clear.then_some(cand)
    }

    fn orbit_is_clear(
        &self,
        cand: &Outcome,
        since: f64,
        win: Window<'_>,
        d: usize,
        o: usize,
        opts: &BasinOptions,
    ) -> bool {
        let n = d - o;
        let rot: Vec<bool> = cand.pattern.split('-').map(|p| p == "R").collect();
        let Some(i) = rot.iter().position(|&r| r) else {
            return false;
        };
        let r = &self.returns[i];
        if r.len() < 3 || r[0].0 < since {
            return false;
        }
        let dist = |p: &[f64], q: &[f64]| {
            let mut m = 0.0f64;
            for k in 0..o {
                m = m.max((p[k] - q[k]).abs());
            }
            for k in d..2 * d {
                m = m.max((p[k] - q[k]).abs());
            }
            for j in 0..n {
                m = m.max(wrap((p[o + j] - p[o + i]) - (q[o + j] - q[o + i])).abs());
            }
            m
        };
        let (d1, d2) = (dist(&r[0].1, &r[1].1), dist(&r[1].1, &r[2].1));
        if !(d2 < SECTION_TOL && (d2 <= d1 || d2 < 1e-9)) {
            return false;
        }
        // Turns per return give the pattern of the orbit itself.
        for (j, &rotates) in rot.iter().enumerate() {
            let turns = ((r[2].1[o + j] - r[1].1[o + j]) / (2.0 * PI)).round();
            if (turns != 0.0) != rotates {
                return false;
            }
        }
        if n == 2 && rot.iter().all(|&x| x) {
            let (ta, tb) = (r[1].0, r[2].0);
            let gap = (0..win.len())
                .filter(|&k| win.t[k] >= ta - PROBE_DT && win.t[k] <= tb + PROBE_DT)
                .map(|k| wrap(win.at(k)[o] - win.at(k)[o + 1]).abs())
                .fold(0.0, f64::max);
            let merged = cand.label == Label::MergedRR;
            if merged != (gap < opts.merge_tol)
                || (gap - opts.merge_tol).abs() < 0.05 * opts.merge_tol
            {
                return false;
            }
        }
        true
    }
}

/// The rest test of [`EarlyStop`] and the rest label the full run ends with: the
/// velocities decay clearly, and `|x + i y|` lies clear of `rest_tol`, or (the perfect
/// balance) its envelope decays so that, continued at the rate measured between the
/// window's halves, it is below `rest_tol / 2` at `t_end`.
fn rest_is_clear(win: Window<'_>, d: usize, t_end: f64, opts: &BasinOptions) -> Option<Label> {
    let m = win.len();
    if m < 4 {
        return None;
    }
    let h = m / 2;
    let vmax = |a: usize, b: usize| {
        (a..b)
            .flat_map(|k| win.at(k)[d..].iter().map(|v| v.abs()))
            .fold(0.0, f64::max)
    };
    let (v1, v2) = (vmax(0, h), vmax(h, m));
    if v2 >= REST_DECAY * v1 && v2 >= 1e-7 {
        return None;
    }
    let z = |k: usize| win.at(k)[0].hypot(win.at(k)[1]);
    let (z1, z2) = (
        (0..h).map(z).fold(0.0, f64::max),
        (h..m).map(z).fold(0.0, f64::max),
    );
    if z2 < REST_DECAY * z1 {
        let half = win.t[m - 1] - win.t[h];
        let left = (t_end - win.t[m - 1]) / half;
        if z2 * (z2 / z1).powf(left) < 0.5 * opts.rest_tol {
            return Some(Label::PerfectBalance);
        }
    }
    let last = win.at(m - 1);
    let spread = (h..m)
        .map(|k| (win.at(k)[0] - last[0]).hypot(win.at(k)[1] - last[1]))
        .fold(0.0, f64::max);
    let zl = z(m - 1);
    if (zl - opts.rest_tol).abs() <= 2.0 * spread + 1e-3 * opts.rest_tol {
        return None;
    }
    Some(if zl < opts.rest_tol {
        Label::PerfectBalance
    } else {
        Label::OtherEquilibrium
    })
}

/// The torus test of [`EarlyStop`], over a whole final window: two balls rotating apart (their gap modulated, no
/// periodic orbit to converge to) for `TORUS_RUNS` checkpoints, with steady mean rates
/// (the halves of the window agree to `TORUS_RATE`, where the final judgement allows
/// 10 %; a torus modulates them by 3 to 6 % at Tien's (2011) Omega 1.2), a gap beyond `1.2 merge_tol` in the second half whose largest value has stopped
/// growing (the halves agree to `TORUS_GAP`: the torus has settled, so its mean rates
/// are those of later windows), and an undiminished
/// vibration (a rotation dying out on its way to rest takes `|x + i y|` down).
fn torus_is_clear(win: Window<'_>, o: usize, opts: &BasinOptions) -> bool {
    let m = win.len();
    if m < 4 {
        return false;
    }
    let h = m / 2;
    for i in 0..2 {
        let r1 = (win.at(h)[o + i] - win.at(0)[o + i]) / (win.t[h] - win.t[0]);
        let r2 = (win.at(m - 1)[o + i] - win.at(h)[o + i]) / (win.t[m - 1] - win.t[h]);
        if (r1 - r2).abs() > TORUS_RATE * r1.abs().max(r2.abs()) {
            return false;
        }
    }
    let gap = |a: usize, b: usize| {
        (a..b)
            .map(|k| wrap(win.at(k)[o] - win.at(k)[o + 1]).abs())
            .fold(0.0, f64::max)
    };
    let (g1, g2) = (gap(0, h), gap(h, m));
    let z = |k: usize| win.at(k)[0].hypot(win.at(k)[1]);
    let (z1, z2) = (
        (0..h).map(z).fold(0.0, f64::max),
        (h..m).map(z).fold(0.0, f64::max),
    );
    g2 > 1.2 * opts.merge_tol && (g2 - g1).abs() < TORUS_GAP * g2 && z2 > 0.95 * z1
}

/// Most whole turns of a rotating ball per period looked for (Tien's (2011) separated
/// rotations take two).
const MAX_TURNS: usize = 4;
/// Relative agreement of the durations of one period with the next that calls a
/// period regular: far above the crossing times' interpolation error (about 1e-5 of a
/// turn), far below the few per cent a torus modulates a turn by.
pub const STRICT_PERIOD_TOL: f64 = 1e-3;
/// Periods compared by the strict test.
const STRICT_PERIODS: usize = 3;
/// Largest distance from a whole number of a rotating ball's turns per period.
const WINDING_TOL: f64 = 0.1;

/// `(turns per period, period)` of a rotating ball from the times it crossed whole
/// turns: the fewest turns `m` (up to [`MAX_TURNS`]) after which the last
/// [`STRICT_PERIODS`] periods' turn durations repeat, each to [`STRICT_PERIOD_TOL`].
fn strict_turn_period(crossings: &[f64]) -> Option<(usize, f64)> {
    let tau: Vec<f64> = crossings.windows(2).map(|w| w[1] - w[0]).collect();
    let k = crossings.len();
    (1..=MAX_TURNS)
        .take_while(|&m| tau.len() >= STRICT_PERIODS * m)
        .find(|&m| {
            (tau.len() - (STRICT_PERIODS - 1) * m..tau.len())
                .all(|j| (tau[j] - tau[j - m]).abs() <= STRICT_PERIOD_TOL * tau[j])
        })
        .map(|m| (m, crossings[k - 1] - crossings[k - 1 - m]))
}

/// Whether the upward crossings of `x` through its mean over the second half of the
/// samples `(t, x, x')` repeat with the period `p` over the last [`STRICT_PERIODS`]
/// periods, each to [`STRICT_PERIOD_TOL`].
fn oscillation_repeats(xs: &[(f64, f64, f64)], p: f64) -> bool {
    let half = xs.len() / 2;
    let tail = &xs[half..];
    if tail.len() < 2 {
        return false;
    }
    let mean = tail.iter().map(|q| q.1).sum::<f64>() / tail.len() as f64;
    let ups: Vec<f64> = tail
        .windows(2)
        .filter(|w| w[0].1 < mean && w[1].1 >= mean)
        .map(|w| w[0].0 + (mean - w[0].1) / (w[1].1 - w[0].1) * (w[1].0 - w[0].0))
        .collect();
    let Some(&last) = ups.last() else {
        return false;
    };
    // The crossing one period before each of the last periods' ends.
    let back = |t: f64| {
        ups.iter()
            .copied()
            .find(|&u| (t - u - p).abs() <= STRICT_PERIOD_TOL * p)
    };
    let mut t = last;
    for _ in 0..STRICT_PERIODS {
        match back(t) {
            Some(u) => t = u,
            None => return false,
        }
    }
    true
}

fn judge<D: Dynamics + ?Sized>(
    model: &D,
    y0: &[f64],
    t_end: f64,
    opts: &BasinOptions,
    early: bool,
) -> Result<Outcome> {
    let d = model.ndof();
    let o = model.first_ball();
    let n = d - o;
    let t_w = t_end - opts.window.min(t_end);
    let iopts = Options::new(opts.rtol, opts.atol);
    let mut solver = Dopri5::new(2 * d);
    let mut samples = Samples::new(2 * d);
    let mut next = t_w;
    let mut tmp = vec![0.0; 2 * d];
    let mut at_rest = false;
    // The early stop's checks look at half the final window (at least one turn per
    // half of it for the slowest rotation the final window recognises).
    let check = 0.5 * opts.window;
    let mut stop = (early && opts.window < t_end).then(|| EarlyStop::new(check, y0));
    let mut early_out: Option<Outcome> = None;
    let res = solver.integrate(
        |t: f64, y: &[f64], dy: &mut [f64]| first_order_rhs(model, t, y, dy),
        0.0,
        y0,
        t_end,
        &iopts,
        |_, tb, dense| {
            while next <= tb {
                dense.eval(next, &mut tmp);
                samples.push(next, &tmp);
                next += DT;
            }
            // As `attractors::classify`: a start at rest relative to the disk has
            // fallen into an equilibrium; stop there.
            at_rest = tb > 50.0 && dense.end()[d..].iter().all(|v| v.abs() < 1e-7);
            if let Some(s) = stop.as_mut() {
                s.observe(tb, dense, d, o, &mut tmp);
                if !at_rest && tb >= s.next_check && tb < t_w {
                    let t_c = (s.next_probe - 1) as f64 * PROBE_DT;
                    let y_c = s.probe.at(s.probe.len() - 1).to_vec();
                    if let Some(out) = s.decide(t_c, &y_c, d, o, t_end, opts) {
                        early_out = Some(out);
                        return false;
                    }
                }
            }
            !at_rest
        },
    );
    let failed = |t_stop| Outcome {
        label: Label::Failed,
        pattern: String::new(),
        omega: f64::NAN,
        rates: vec![f64::NAN; n],
        period: None,
        windings: vec![],
        period_strict: false,
        extensions: 0,
        t_stop,
        long_label: None,
        y_end: vec![],
    };
    let (t_stop, y_end) = match res {
        Ok((t, y, _)) => (t, y),
        Err(Error::Cancelled) => return Err(Error::Cancelled),
        Err(_) => return Ok(failed(f64::NAN)),
    };
    if y_end.iter().any(|v| !v.is_finite()) {
        return Ok(failed(t_stop));
    }
    if let Some(mut out) = early_out {
        out.t_stop = t_stop;
        out.y_end = y_end;
        return Ok(out);
    }
    if at_rest || samples.len() < 4 {
        return Ok(rest_outcome(&y_end, t_stop, n, opts));
    }
    Ok(label_window(
        samples.from(0),
        DT,
        &y_end,
        t_stop,
        d,
        o,
        opts,
    ))
}

fn rest_outcome(y: &[f64], t_stop: f64, n: usize, opts: &BasinOptions) -> Outcome {
    let label = if y[0].hypot(y[1]) < opts.rest_tol {
        Label::PerfectBalance
    } else {
        Label::OtherEquilibrium
    };
    Outcome {
        label,
        pattern: String::new(),
        omega: 0.0,
        rates: vec![0.0; n],
        period: None,
        windings: vec![],
        period_strict: false,
        extensions: 0,
        t_stop,
        long_label: None,
        y_end: y.to_vec(),
    }
}

/// The label of the motion sampled in `samples` (at least 4 of them), ending in `y_end`.
fn label_window(
    samples: Window<'_>,
    dt: f64,
    y_end: &[f64],
    t_stop: f64,
    d: usize,
    o: usize,
    opts: &BasinOptions,
) -> Outcome {
    // the balls' angles are the state's last coordinates, from `o` on
    let n = d - o;
    let rest = |y: &[f64]| rest_outcome(y, t_stop, n, opts);
    let y_end = y_end.to_vec();
    let m = samples.len();
    if m < 4 {
        return rest(&y_end);
    }
    let h = m / 2;
    let span = |a: usize, b: usize| samples.t[b] - samples.t[a];
    let turns =
        |i: usize, a: usize, b: usize| (samples.at(b)[o + i] - samples.at(a)[o + i]) / (2.0 * PI);
    // A ball rotates when it makes at least one turn in each half of the window.
    let rot1: Vec<bool> = (0..n).map(|i| turns(i, 0, h).abs() >= 1.0).collect();
    let rot2: Vec<bool> = (0..n).map(|i| turns(i, h, m - 1).abs() >= 1.0).collect();
    let rates: Vec<f64> = (0..n)
        .map(|i| -turns(i, 0, m - 1) * 2.0 * PI / span(0, m - 1))
        .collect();
    let pattern: String = rot2
        .iter()
        .map(|&r| if r { "R" } else { "O" })
        .collect::<Vec<_>>()
        .join("-");
    let unsettled = |pattern: String| Outcome {
        label: Label::NotSettled,
        pattern,
        omega: f64::NAN,
        rates: rates.clone(),
        period: None,
        windings: vec![],
        period_strict: false,
        extensions: 0,
        t_stop,
        long_label: None,
        y_end: y_end.clone(),
    };
    if rot1 != rot2 {
        return unsettled(String::new());
    }
    let n_rot = rot2.iter().filter(|&&r| r).count();
    if n_rot > 0 {
        // The rotating balls' mean rates must agree between the halves (a ball slowing
        // down towards rest, or speeding up, is a transient). A torus modulates them by
        // a few per cent.
        for i in (0..n).filter(|&i| rot2[i]) {
            let r1 = turns(i, 0, h) / span(0, h);
            let r2 = turns(i, h, m - 1) / span(h, m - 1);
            if (r1 - r2).abs() > 0.1 * r1.abs().max(r2.abs()) {
                return unsettled(pattern);
            }
        }
        // Whole-turn crossings of each rotating ball: its period and, over whole
        // turns, its mean rate (free of the within-turn wobble a plain difference over
        // the window would carry).
        let crossings_of = |i: usize| {
            let mut c = vec![];
            for k in 1..m {
                let (a, b) = (samples.at(k - 1)[o + i], samples.at(k)[o + i]);
                let (ka, kb) = ((a / (2.0 * PI)).floor(), (b / (2.0 * PI)).floor());
                if ka != kb {
                    let level = 2.0 * PI * ka.max(kb);
                    c.push(samples.t[k - 1] + (level - a) / (b - a) * dt);
                }
            }
            c
        };
        let mut rates = rates.clone();
        let mut period = None;
        let mut strict = None;
        for i in (0..n).filter(|&i| rot2[i]) {
            let c = crossings_of(i);
            if c.len() >= 2 {
                let turns = (c.len() - 1) as f64 * 2.0 * PI;
                rates[i] = rates[i].signum() * turns / (c[c.len() - 1] - c[0]);
            }
            if period.is_none() && strict.is_none() {
                strict = strict_turn_period(&c);
                period = turn_period(&c).map(|p| p.1);
            }
        }
        // The period is the first rotating ball's; every other rotating ball must turn
        // a whole number of times per period too (to `WINDING_TOL`, above the bias of
        // its rate counted over whole turns rather than whole periods), else the
        // motion does not repeat with it.
        let strict = strict.filter(|&(_, p)| {
            (0..n).filter(|&i| rot2[i]).all(|i| {
                let w = rates[i].abs() * p / (2.0 * PI);
                w.round() >= 1.0 && (w - w.round()).abs() <= WINDING_TOL
            })
        });
        let period_strict = strict.is_some();
        let mut windings = vec![];
        if let Some((m, p)) = strict {
            period = Some(p);
            if m > 1 {
                // A period of several turns: the mean rates over whole periods, free of
                // the unequal turns' bias a count of whole turns has.
                let first = (0..n).find(|&i| rot2[i]).unwrap_or(0);
                for i in (0..n).filter(|&i| rot2[i]) {
                    let w = if i == first {
                        m as f64
                    } else {
                        (rates[i].abs() * p / (2.0 * PI)).round()
                    };
                    rates[i] = rates[i].signum() * w * 2.0 * PI / p;
                }
            }
        }
        if let Some(p) = period {
            windings = (0..n)
                .map(|i| {
                    if rot2[i] {
                        -(rates[i] * p / (2.0 * PI)).round() as i64
                    } else {
                        0
                    }
                })
                .collect();
        }
        let omega = (0..n).filter(|&i| rot2[i]).map(|i| rates[i]).sum::<f64>() / n_rot as f64;
        let label = match (n, n_rot) {
            (2, 2) => {
                let gap = (0..m)
                    .map(|k| wrap(samples.at(k)[o] - samples.at(k)[o + 1]).abs())
                    .fold(0.0, f64::max);
                if gap < opts.merge_tol {
                    Label::MergedRR
                } else {
                    Label::SeparatedRR
                }
            }
            (2, 1) => Label::RO,
            _ => Label::Other,
        };
        return Outcome {
            label,
            pattern,
            omega,
            rates,
            period,
            windings,
            period_strict,
            extensions: 0,
            t_stop,
            long_label: None,
            y_end,
        };
    }
    // No ball rotates: at rest, on the way to rest, or oscillating.
    let vmax = |a: usize, b: usize| {
        (a..b)
            .flat_map(|k| samples.at(k)[d..].iter().map(|v| v.abs()))
            .fold(0.0, f64::max)
    };
    let (v1, v2) = (vmax(0, h), vmax(h, m));
    // Decaying by a fifth or more over half the window: a transient into an
    // equilibrium (the approach to a limit cycle does not take the velocities down).
    if v2 < 1e-6 || v2 < 0.8 * v1 {
        return rest(&y_end);
    }
    if v2 > 1.05 * v1 {
        return unsettled(pattern); // still growing
    }
    let xs: Vec<(f64, f64, f64)> = (0..m)
        .map(|k| (samples.t[k], samples.at(k)[0], samples.at(k)[d]))
        .collect();
    let period = match oscillation_period(&xs) {
        Oscillation::Period(_, p) => Some(p),
        Oscillation::Rest => return rest(&y_end),
        Oscillation::Irregular => None,
    };
    // The oscillation's own test compares the last two periods to 1 %; the strict
    // test asks the last three for `STRICT_PERIOD_TOL`.
    let period_strict = period.is_some_and(|p| oscillation_repeats(&xs, p));
    Outcome {
        label: if n == 2 { Label::OO } else { Label::Other },
        pattern,
        omega: 0.0,
        rates,
        period,
        windings: period.map(|_| vec![0; n]).unwrap_or_default(),
        period_strict,
        extensions: 0,
        t_stop,
        long_label: None,
        y_end,
    }
}

/// Classifies every start (`starts[k]`: the ball angles, at rest in the ground frame)
/// on `threads` threads, each on its own; polls this thread's cancellation token
/// (handed on to rayon's threads) and returns `Err(Cancelled)` once it is set.
pub fn basin_starts<D: Dynamics + Sync + ?Sized>(
    model: &D,
    starts: &[Vec<f64>],
    opts: &BasinOptions,
) -> Result<Vec<Outcome>> {
    opts.validate()?;
    let n = model.ndof() - model.first_ball();
    if let Some(s) = starts.iter().find(|s| s.len() != n) {
        return Err(Error::param(
            "starts",
            format!("every start needs {n} ball angles, got {}", s.len()),
        ));
    }
    if starts.iter().flatten().any(|v| !v.is_finite()) {
        return Err(Error::param("starts", "ball angles must be finite"));
    }
    let tok = cancel::current();
    starts
        .par_iter()
        .map(|b| {
            cancel::with(tok.clone(), || {
                cancel::check()?;
                classify_start(model, &ground_rest_start(model, b), opts)
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::equilibria::{equilibria, EquilibriumKind};
    use crate::Planar;

    fn standard(omega: f64) -> Planar {
        Planar::new(0.2, 0.05, &[0.05], 50.0, omega, &[0.7, 0.7]).unwrap()
    }

    #[test]
    fn labels_of_the_standard_bistable_case() {
        // Omega 1.35 (figure 4-16): balls started close together stay merged on the
        // R-R orbit; far apart they settle on the perfect balance, which
        // equilibria() calls stable there.
        let p = standard(1.35);
        let pb = equilibria(&p)
            .into_iter()
            .find(|e| e.kind == EquilibriumKind::PerfectBalance)
            .unwrap();
        assert_eq!(pb.verdict, crate::equilibria::Verdict::Stable);
        let o = BasinOptions::default();
        let near = classify_start(&p, &ground_rest_start(&p, &[0.3, 0.5]), &o).unwrap();
        assert_eq!(near.label, Label::MergedRR);
        let per = near.period.expect("periodic");
        // The balls lag one turn per period of the motion.
        assert!((2.0 * PI / per - near.omega).abs() < 1e-3 * near.omega);
        let far = classify_start(&p, &ground_rest_start(&p, &[1.0, -1.0]), &o).unwrap();
        assert_eq!(far.label, Label::PerfectBalance);
    }

    #[test]
    fn separated_rotations_take_two_turns_per_period() {
        // Omega 1.2 (figure 4-15): balls started apart rotate separately, with turns
        // that alternate between two durations (about 21.9 and 32.1 time units, measured
        // from a simulation at rtol 1e-10): a period of two turns, windings (-2, -2).
        let p = standard(1.2);
        let o = BasinOptions::default();
        // the first start of the default 12 x 12 grid
        let start = ground_rest_start(&p, &[PI / 24.0, PI / 8.0]);
        let out = classify_start(&p, &start, &o).unwrap();
        assert_eq!(out.label, Label::SeparatedRR);
        assert!(out.period_strict);
        assert_eq!(out.windings, vec![-2, -2]);
        let per = out.period.expect("periodic");
        assert!((per - (21.8831 + 32.1102)).abs() < 1e-3 * per, "{per}");
        assert_eq!(out.motion(), "periodic");
    }

    #[test]
    fn strict_periods_need_three_repeats() {
        // turns alternating 2 and 3 time units: two turns per period of 5
        let mut c = vec![0.0];
        for k in 0..8 {
            let last = *c.last().unwrap();
            c.push(last + if k % 2 == 0 { 2.0 } else { 3.0 });
        }
        assert_eq!(strict_turn_period(&c), Some((2, 5.0)));
        // durations drifting by 1 % a turn (a torus, say) repeat with no period
        let drift: Vec<f64> = (0..12)
            .map(|k| f64::from(k) * (1.0 + 0.01 * f64::from(k)))
            .collect();
        assert_eq!(strict_turn_period(&drift), None);
        // too few turns to see three periods of two
        assert_eq!(strict_turn_period(&c[..6]), None);
    }

    #[test]
    fn a_cancelled_grid_stops() {
        let p = standard(1.2);
        let tok = cancel::Token::new();
        tok.cancel();
        let starts = vec![vec![0.3, 0.5]; 4];
        let r = cancel::with(Some(tok), || {
            basin_starts(&p, &starts, &BasinOptions::default())
        });
        assert!(matches!(r, Err(Error::Cancelled)));
    }

    #[test]
    fn options_are_checked_by_name() {
        let p = standard(1.2);
        let o = BasinOptions {
            window: 2000.0,
            ..Default::default()
        };
        let e = basin_starts(&p, &[vec![0.0, 1.0]], &o).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { ref name, .. } if name == "window"));
        for f in [0.5, 65.0, f64::NAN] {
            let o = BasinOptions {
                extend_factor: f,
                ..Default::default()
            };
            let e = basin_starts(&p, &[vec![0.0, 1.0]], &o).unwrap_err();
            assert!(
                matches!(e, Error::InvalidParameter { ref name, .. } if name == "extend_factor")
            );
        }
        let e = basin_starts(&p, &[vec![0.0]], &BasinOptions::default()).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { ref name, .. } if name == "starts"));
    }
}
