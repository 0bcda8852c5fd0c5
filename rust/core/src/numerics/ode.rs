//! Dormand–Prince 5(4) (RK45) with scipy-compatible error control and Hairer's
//! 4th-order dense output, so results at requested times do not force tiny steps.
//!
//! Conventions follow `scipy.integrate.solve_ivp(method="RK45")`: the local error is
//! measured in the RMS norm of `err_i / (atol_i + rtol * max(|y_i|, |y_new_i|))`, the
//! step grows by at most 10 and shrinks by at most 5, with safety factor 0.9, and the
//! first step is chosen by the same heuristic (Hairer, Norsett & Wanner, II.4).

// Stage loops index several arrays in lockstep; iterators would obscure the tableau.
#![allow(clippy::needless_range_loop)]

use crate::cancel;
use crate::error::{Error, Result};

const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// Hairer's dense-output coefficients for DOPRI5.
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// Hairer & Wanner's stiffness test for DOPRI5 (Solving ODEs II, IV.2; `dopri5.f`): a
/// step is stability-limited when `h rho > 3.25`, `rho ~ |f(y7) - f(y6)| / |y7 - y6|`
/// estimating the dominant eigenvalue from the last two stages; the problem is stiff
/// after `STIFF_RUN` such accepted steps with fewer than `STIFF_CALM` in a row between.
const STIFF_HRHO: f64 = 3.25;
const STIFF_RUN: usize = 15;
const STIFF_CALM: usize = 6;
/// A stiff stretch is only an error when finishing at its step size would take more
/// steps than this (seconds of work): an explicit method that is merely stability-limited
/// for a short time still gives the right answer, just with small steps.
const STIFF_STEPS_LEFT: f64 = 1e6;
/// After this many steps the integrator forecasts, from its average step so far, the
/// steps still needed, and stops when they exceed `FORECAST_FACTOR` times `max_steps`
/// (an error in a second instead of after the whole step budget: a motion far faster
/// than the time span, or a time span far too long).
const FORECAST_AFTER: usize = 20_000;
const FORECAST_FACTOR: f64 = 10.0;

/// Tolerances and limits, named as in scipy.
#[derive(Debug, Clone)]
pub struct Options {
    pub rtol: f64,
    /// One value for all components, or one per component.
    pub atol: Vec<f64>,
    /// Initial step; `None` selects it automatically.
    pub first_step: Option<f64>,
    pub max_step: f64,
    pub max_steps: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            rtol: 1e-6,
            atol: vec![1e-9],
            first_step: None,
            max_step: f64::INFINITY,
            max_steps: 10_000_000,
        }
    }
}

impl Options {
    pub fn new(rtol: f64, atol: f64) -> Self {
        Options {
            rtol,
            atol: vec![atol],
            ..Default::default()
        }
    }

    pub fn validate(&self, n: usize) -> Result<()> {
        if !(self.rtol.is_finite() && self.rtol > 0.0) {
            return Err(Error::param(
                "rtol",
                format!("must be a finite number > 0, got {}", self.rtol),
            ));
        }
        if self.atol.len() != 1 && self.atol.len() != n {
            return Err(Error::param(
                "atol",
                format!(
                    "needs 1 value or one per state ({n}), got {}",
                    self.atol.len()
                ),
            ));
        }
        if self.atol.iter().any(|a| !(a.is_finite() && *a >= 0.0)) {
            return Err(Error::param("atol", "must be finite and >= 0"));
        }
        if !(self.max_step > 0.0) {
            return Err(Error::param("max_step", "must be > 0"));
        }
        Ok(())
    }

    #[inline]
    fn atol(&self, i: usize) -> f64 {
        if self.atol.len() == 1 {
            self.atol[0]
        } else {
            self.atol[i]
        }
    }
}

/// Counters of one integration.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    pub accepted: usize,
    pub rejected: usize,
    pub rhs_evals: usize,
}

/// Everything the step loop carries from one step to the next: an integration resumed
/// from it ([`Dopri5::resume`]) takes exactly the steps the original would have taken
/// had it been asked for a later end time.
#[derive(Debug, Clone)]
pub struct Checkpoint {
    /// Where the integration started (its step forecast averages over `t - start`).
    start: f64,
    t: f64,
    y: Vec<f64>,
    /// `f(t, y)`: the first stage of the next step (FSAL).
    k0: Vec<f64>,
    h: f64,
    rejected_last: bool,
    stiff_run: usize,
    calm: usize,
    stats: Stats,
}

impl Checkpoint {
    pub fn time(&self) -> f64 {
        self.t
    }
}

/// Reusable stage storage for one state dimension.
pub struct Dopri5 {
    n: usize,
    k: [Vec<f64>; 7],
    y_new: Vec<f64>,
    tmp: Vec<f64>,
    err: Vec<f64>,
    /// The dense output's coefficients of the current step (see [`Dense::eval`]).
    cont: std::cell::RefCell<Vec<f64>>,
    /// The state just before the last integration first had to shorten a step to land
    /// on its end time: everything up to there is what an integration to a later end
    /// would have done too.
    before_end: Option<Checkpoint>,
}

impl Dopri5 {
    pub fn new(n: usize) -> Self {
        let z = || vec![0.0; n];
        Dopri5 {
            n,
            k: [z(), z(), z(), z(), z(), z(), z()],
            y_new: z(),
            tmp: z(),
            err: z(),
            cont: std::cell::RefCell::new(vec![0.0; 4 * n]),
            before_end: None,
        }
    }

    /// The state of the last integration just before it first shortened a step to end
    /// on its end time (`None` if it stopped before that). Taken: a second call gives
    /// `None`.
    pub fn take_checkpoint(&mut self) -> Option<Checkpoint> {
        self.before_end.take()
    }

    fn rms_scaled(&self, v: &[f64], y: &[f64], opts: &Options) -> f64 {
        let mut s = 0.0;
        for i in 0..self.n {
            let sc = opts.atol(i) + opts.rtol * y[i].abs();
            let r = v[i] / sc;
            s += r * r;
        }
        (s / self.n as f64).sqrt()
    }

    fn initial_step<F>(&mut self, f: &mut F, t0: f64, y0: &[f64], dir: f64, opts: &Options) -> f64
    where
        F: FnMut(f64, &[f64], &mut [f64]),
    {
        // scipy's select_initial_step, order 4 error estimator.
        let f0 = self.k[0].clone();
        let d0 = self.rms_scaled(y0, y0, opts);
        let d1 = self.rms_scaled(&f0, y0, opts);
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        for i in 0..self.n {
            self.tmp[i] = y0[i] + dir * h0 * f0[i];
        }
        let tmp = self.tmp.clone();
        f(t0 + dir * h0, &tmp, &mut self.err);
        for i in 0..self.n {
            self.err[i] -= f0[i];
        }
        let diff = self.err.clone();
        let d2 = self.rms_scaled(&diff, y0, opts) / h0;
        let h1 = if d1 <= 1e-15 && d2 <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(1.0 / 5.0)
        };
        (100.0 * h0).min(h1).min(opts.max_step)
    }

    /// Integrates from `t0` towards `t1` and calls `observe(t_a, t_b, dense)` after every
    /// accepted step, where `dense.eval(t, out)` interpolates inside `[t_a, t_b]`.
    /// `observe` returns `false` to stop early. Returns the final time reached and the state.
    pub fn integrate<F, O>(
        &mut self,
        mut f: F,
        t0: f64,
        y0: &[f64],
        t1: f64,
        opts: &Options,
        observe: O,
    ) -> Result<(f64, Vec<f64>, Stats)>
    where
        F: FnMut(f64, &[f64], &mut [f64]),
        O: FnMut(f64, f64, &Dense<'_>) -> bool,
    {
        assert_eq!(y0.len(), self.n);
        opts.validate(self.n)?;
        self.before_end = None;
        let mut stats = Stats::default();
        if t1 == t0 {
            return Ok((t0, y0.to_vec(), stats));
        }
        let dir = if t1 > t0 { 1.0 } else { -1.0 };
        f(t0, y0, &mut self.k[0]);
        stats.rhs_evals += 1;
        let h = match opts.first_step {
            Some(h) => h.abs(),
            None => {
                stats.rhs_evals += 1;
                self.initial_step(&mut f, t0, y0, dir, opts)
            }
        };
        let from = Checkpoint {
            start: t0,
            t: t0,
            y: y0.to_vec(),
            k0: vec![],
            h,
            rejected_last: false,
            stiff_run: 0,
            calm: 0,
            stats,
        };
        self.steps(f, from, t1, opts, observe)
    }

    /// Continues an integration of the same right-hand side, with the same options,
    /// from `cp` (taken from an integration that ended at an earlier time) to `t1`, in
    /// the direction it went: bit for bit the steps and dense output an integration
    /// from the original start to `t1` takes after `cp`.
    pub fn resume<F, O>(
        &mut self,
        f: F,
        cp: &Checkpoint,
        t1: f64,
        opts: &Options,
        observe: O,
    ) -> Result<(f64, Vec<f64>, Stats)>
    where
        F: FnMut(f64, &[f64], &mut [f64]),
        O: FnMut(f64, f64, &Dense<'_>) -> bool,
    {
        assert_eq!(cp.y.len(), self.n);
        opts.validate(self.n)?;
        self.before_end = None;
        if t1 == cp.t {
            return Ok((cp.t, cp.y.clone(), cp.stats.clone()));
        }
        self.k[0].copy_from_slice(&cp.k0);
        self.steps(f, cp.clone(), t1, opts, observe)
    }

    /// The step loop from `at` (whose `k0` is already in `self.k[0]`) to `t1`.
    fn steps<F, O>(
        &mut self,
        mut f: F,
        at: Checkpoint,
        t1: f64,
        opts: &Options,
        mut observe: O,
    ) -> Result<(f64, Vec<f64>, Stats)>
    where
        F: FnMut(f64, &[f64], &mut [f64]),
        O: FnMut(f64, f64, &Dense<'_>) -> bool,
    {
        let Checkpoint {
            start: t0,
            mut t,
            mut y,
            mut h,
            mut rejected_last,
            mut stiff_run,
            mut calm,
            mut stats,
            ..
        } = at;
        let dir = if t1 > t { 1.0 } else { -1.0 };
        let n = self.n;
        loop {
            if (stats.accepted + stats.rejected) % 8 == 0 {
                cancel::check()?;
            }
            if stats.accepted + stats.rejected >= opts.max_steps {
                return Err(Error::Integration(format!(
                    "more than max_steps = {} steps before t = {t1} (reached t = {t})",
                    opts.max_steps
                )));
            }
            let min_step = 10.0 * (f64::EPSILON * t.abs()).max(f64::MIN_POSITIVE);
            h = h.min(opts.max_step);
            if h < min_step {
                return Err(Error::Integration(format!(
                    "step size underflow at t = {t}"
                )));
            }
            let mut hs = h * dir;
            let mut last = false;
            if dir * (t + hs - t1) >= 0.0 {
                if self.before_end.is_none() {
                    self.before_end = Some(Checkpoint {
                        start: t0,
                        t,
                        y: y.clone(),
                        k0: self.k[0].clone(),
                        h,
                        rejected_last,
                        stiff_run,
                        calm,
                        stats: stats.clone(),
                    });
                }
                hs = t1 - t;
                last = true;
            }
            self.stages(&mut f, t, &y, hs);
            stats.rhs_evals += 6;
            // Error estimate.
            for i in 0..n {
                self.err[i] = hs
                    * (E1 * self.k[0][i]
                        + E3 * self.k[2][i]
                        + E4 * self.k[3][i]
                        + E5 * self.k[4][i]
                        + E6 * self.k[5][i]
                        + E7 * self.k[6][i]);
            }
            let mut s = 0.0;
            let mut finite = true;
            for i in 0..n {
                let sc = opts.atol(i) + opts.rtol * y[i].abs().max(self.y_new[i].abs());
                let r = self.err[i] / sc;
                finite &= self.y_new[i].is_finite();
                s += r * r;
            }
            let en = (s / n as f64).sqrt();
            if !finite || !en.is_finite() {
                // Treat a blow-up inside the step like a huge error: shrink hard.
                h *= 0.2;
                stats.rejected += 1;
                rejected_last = true;
                continue;
            }
            if en <= 1.0 {
                let mut fac = if en == 0.0 {
                    10.0
                } else {
                    (0.9 * en.powf(-0.2)).min(10.0)
                };
                if rejected_last {
                    fac = fac.min(1.0);
                }
                let t_new = if last { t1 } else { t + hs };
                stats.accepted += 1;
                // `tmp` still holds the sixth stage's state (y6), `k[5]` = f(y6), k[6] = f(y7).
                let (mut num, mut den) = (0.0, 0.0);
                for i in 0..n {
                    let a = self.k[6][i] - self.k[5][i];
                    let b = self.y_new[i] - self.tmp[i];
                    num += a * a;
                    den += b * b;
                }
                if den > 0.0 && hs.abs() * (num / den).sqrt() > STIFF_HRHO {
                    calm = 0;
                    stiff_run += 1;
                    let left = (t1 - t_new).abs() / hs.abs();
                    if stiff_run >= STIFF_RUN && !last && left > STIFF_STEPS_LEFT {
                        return Err(Error::Stiff(format!(
                            "the step size is held at {:.3e} by stability (h rho > {STIFF_HRHO} on {stiff_run} steps) at t = {t_new}; {left:.2e} more steps to t = {t1}",
                            hs.abs()
                        )));
                    }
                } else {
                    calm += 1;
                    if calm >= STIFF_CALM {
                        stiff_run = 0;
                    }
                }
                if stats.accepted >= FORECAST_AFTER && stats.accepted % 1024 == 0 && !last {
                    let need = (t1 - t_new).abs() / ((t_new - t0).abs() / stats.accepted as f64);
                    if need > FORECAST_FACTOR * opts.max_steps as f64 {
                        return Err(Error::Integration(format!(
                            "at the average step so far ({:.3e}) reaching t = {t1} needs about {need:.2e} more steps, far more than max_steps = {} (reached t = {t_new})",
                            (t_new - t0).abs() / stats.accepted as f64,
                            opts.max_steps
                        )));
                    }
                }
                // Dense output is formed only when the observer interpolates.
                let dense = Dense {
                    t0: t,
                    h: hs,
                    y: &y,
                    y_new: &self.y_new,
                    k: &self.k,
                    cont: &self.cont,
                    ready: std::cell::Cell::new(false),
                };
                let go_on = observe(t, t_new, &dense);
                t = t_new;
                y.copy_from_slice(&self.y_new);
                // FSAL: the last stage is the next step's first.
                let (a, b) = self.k.split_at_mut(6);
                a[0].copy_from_slice(&b[0]);
                rejected_last = false;
                if last || !go_on {
                    return Ok((t, y, stats));
                }
                h *= fac;
            } else {
                h *= (0.9 * en.powf(-0.2)).max(0.2);
                stats.rejected += 1;
                rejected_last = true;
            }
        }
    }

    fn stages<F>(&mut self, f: &mut F, t: f64, y: &[f64], h: f64)
    where
        F: FnMut(f64, &[f64], &mut [f64]),
    {
        let n = self.n;
        let [k0, k1, k2, k3, k4, k5, k6] = &mut self.k;
        let tmp = &mut self.tmp[..n];
        let y = &y[..n];
        for i in 0..n {
            tmp[i] = y[i] + h * (A21 * k0[i]);
        }
        f(t + C2 * h, tmp, k1);
        for i in 0..n {
            tmp[i] = y[i] + h * (A31 * k0[i] + A32 * k1[i]);
        }
        f(t + C3 * h, tmp, k2);
        for i in 0..n {
            tmp[i] = y[i] + h * (A41 * k0[i] + A42 * k1[i] + A43 * k2[i]);
        }
        f(t + C4 * h, tmp, k3);
        for i in 0..n {
            tmp[i] = y[i] + h * (A51 * k0[i] + A52 * k1[i] + A53 * k2[i] + A54 * k3[i]);
        }
        f(t + C5 * h, tmp, k4);
        for i in 0..n {
            tmp[i] =
                y[i] + h * (A61 * k0[i] + A62 * k1[i] + A63 * k2[i] + A64 * k3[i] + A65 * k4[i]);
        }
        f(t + h, tmp, k5);
        let yn = &mut self.y_new[..n];
        for i in 0..n {
            yn[i] =
                y[i] + h * (A71 * k0[i] + A73 * k2[i] + A74 * k3[i] + A75 * k4[i] + A76 * k5[i]);
        }
        f(t + h, yn, k6);
    }
}

/// Dense output of one accepted step (Hairer's continuous extension of DOPRI5).
pub struct Dense<'a> {
    t0: f64,
    h: f64,
    y: &'a [f64],
    y_new: &'a [f64],
    k: &'a [Vec<f64>; 7],
    /// The continuous extension's four coefficient vectors, formed on the step's first
    /// [`Dense::eval`]: an observer that samples a step many times (a seed's observation
    /// at every 0.05 time units, several samples per step) would otherwise form them
    /// again for each sample, three quarters of an evaluation's arithmetic.
    cont: &'a std::cell::RefCell<Vec<f64>>,
    ready: std::cell::Cell<bool>,
}

impl Dense<'_> {
    /// The state at the end of the step (no interpolation needed).
    pub fn end(&self) -> &[f64] {
        self.y_new
    }

    /// Hairer's stiffness indicator `|h| rho` of this step, `rho ~ |f(y7) - f(y6)| / |y7 - y6|`
    /// (the dominant eigenvalue seen by the last two stages; above about 3.25 the step is
    /// held by stability, not accuracy). Recomputes `y6` from the stages, so observers that
    /// want a stiffness diagnostic pay for it and the stepping loop does not.
    pub fn stiffness(&self) -> f64 {
        let (h, k) = (self.h, self.k);
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..self.y.len() {
            let y6 = self.y[i]
                + h * (A61 * k[0][i]
                    + A62 * k[1][i]
                    + A63 * k[2][i]
                    + A64 * k[3][i]
                    + A65 * k[4][i]);
            let a = k[6][i] - k[5][i];
            let b = self.y_new[i] - y6;
            num += a * a;
            den += b * b;
        }
        if den > 0.0 {
            h.abs() * (num / den).sqrt()
        } else {
            0.0
        }
    }

    /// Start time and signed step of this step.
    pub fn span(&self) -> (f64, f64) {
        (self.t0, self.h)
    }

    pub fn eval(&self, t: f64, out: &mut [f64]) {
        let th = (t - self.t0) / self.h;
        let th1 = 1.0 - th;
        let n = self.y.len();
        let mut c = self.cont.borrow_mut();
        if !self.ready.get() {
            let (h, k) = (self.h, self.k);
            let (ydiff, rest) = c.split_at_mut(n);
            let (bspl, rest) = rest.split_at_mut(n);
            let (c3, c4) = rest.split_at_mut(n);
            for i in 0..n {
                ydiff[i] = self.y_new[i] - self.y[i];
                bspl[i] = h * k[0][i] - ydiff[i];
                c3[i] = ydiff[i] - h * k[6][i] - bspl[i];
                c4[i] = h
                    * (D1 * k[0][i]
                        + D3 * k[2][i]
                        + D4 * k[3][i]
                        + D5 * k[4][i]
                        + D6 * k[5][i]
                        + D7 * k[6][i]);
            }
            self.ready.set(true);
        }
        let (ydiff, rest) = c.split_at(n);
        let (bspl, rest) = rest.split_at(n);
        let (c3, c4) = rest.split_at(n);
        for i in 0..out.len() {
            out[i] = self.y[i] + th * (ydiff[i] + th1 * (bspl[i] + th * (c3[i] + th1 * c4[i])));
        }
    }
}

/// Integrates and returns the state at each of `t_eval` (strictly monotone, starting at
/// or after `t0` in the direction of integration).
pub fn solve_at<F>(
    f: F,
    t0: f64,
    y0: &[f64],
    t_eval: &[f64],
    opts: &Options,
) -> Result<(Vec<Vec<f64>>, Stats)>
where
    F: FnMut(f64, &[f64], &mut [f64]),
{
    sample_at(t0, y0, t_eval, |solver, t1, observe| {
        solver.integrate(f, t0, y0, t1, opts, observe)
    })
}

/// [`solve_at`] continued from a checkpoint of an earlier integration of `f` with the
/// same options (every time in `t_eval` at or past the checkpoint's): the states an
/// integration from that integration's start would give, without its first part.
pub fn solve_at_from<F>(
    f: F,
    cp: &Checkpoint,
    t_eval: &[f64],
    opts: &Options,
) -> Result<(Vec<Vec<f64>>, Stats)>
where
    F: FnMut(f64, &[f64], &mut [f64]),
{
    sample_at(cp.t, &cp.y, t_eval, |solver, t1, observe| {
        solver.resume(f, cp, t1, opts, observe)
    })
}

type Observer<'o> = &'o mut dyn FnMut(f64, f64, &Dense<'_>) -> bool;

/// The states at `t_eval` (checked, starting at or after `t0`) of the integration
/// `run(solver, last time, observer)` starting at `(t0, y0)`.
fn sample_at<R>(t0: f64, y0: &[f64], t_eval: &[f64], run: R) -> Result<(Vec<Vec<f64>>, Stats)>
where
    R: FnOnce(&mut Dopri5, f64, Observer<'_>) -> Result<(f64, Vec<f64>, Stats)>,
{
    let n = y0.len();
    if t_eval.is_empty() {
        return Ok((vec![], Stats::default()));
    }
    check_times(t0, t_eval)?;
    let t1 = *t_eval.last().unwrap();
    let dir = if t1 >= t0 { 1.0 } else { -1.0 };
    let mut out: Vec<Vec<f64>> = Vec::with_capacity(t_eval.len());
    let mut idx = 0;
    while idx < t_eval.len() && t_eval[idx] == t0 {
        out.push(y0.to_vec());
        idx += 1;
    }
    let mut solver = Dopri5::new(n);
    let (_, _, stats) = run(&mut solver, t1, &mut |_, tb, dense| {
        while idx < t_eval.len() && dir * (t_eval[idx] - tb) <= 0.0 {
            let mut v = vec![0.0; n];
            dense.eval(t_eval[idx], &mut v);
            out.push(v);
            idx += 1;
        }
        true
    })?;
    Ok((out, stats))
}

/// `Err(Error::Stiff)` when integrating from `y0` towards `t1` proves stiff within the
/// first `steps` steps, `Ok` otherwise (other failures are left to the integration that
/// needs the answer to report). A cheap test before analyses that swallow integration
/// failures (a guess simulation that fails is just "no guess").
pub fn probe_stiffness<F>(
    f: F,
    t0: f64,
    y0: &[f64],
    t1: f64,
    opts: &Options,
    steps: usize,
) -> Result<()>
where
    F: FnMut(f64, &[f64], &mut [f64]),
{
    let opts = Options {
        max_steps: steps,
        ..opts.clone()
    };
    match Dopri5::new(y0.len()).integrate(f, t0, y0, t1, &opts, |_, _, _| true) {
        Err(e @ (Error::Stiff(_) | Error::Cancelled)) => Err(e),
        _ => Ok(()),
    }
}

/// Output times must be finite, strictly monotone, and not before `t0`.
pub fn check_times(t0: f64, t_eval: &[f64]) -> Result<()> {
    if !t0.is_finite() {
        return Err(Error::param("t0", format!("must be finite, got {t0}")));
    }
    if let Some(bad) = t_eval.iter().find(|t| !t.is_finite()) {
        return Err(Error::param("t_eval", format!("must be finite, got {bad}")));
    }
    let dir = if t_eval.last().copied().unwrap_or(t0) >= t0 {
        1.0
    } else {
        -1.0
    };
    let mut prev = t0;
    for (i, &t) in t_eval.iter().enumerate() {
        let ok = if i == 0 {
            dir * (t - prev) >= 0.0
        } else {
            dir * (t - prev) > 0.0
        };
        if !ok {
            return Err(Error::param(
                "t_eval",
                format!("must be strictly monotone and start at or after t0 = {t0}; entry {i} = {t} breaks the order"),
            ));
        }
        prev = t;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Harmonic oscillator y'' = -y with exact solution (cos t, -sin t).
    fn osc(_t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = y[1];
        dy[1] = -y[0];
    }

    /// Van der Pol: nonlinear, so a step sequence that differed anywhere would show in
    /// the last bits.
    fn vdp(_t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = y[1];
        dy[1] = 2.0 * (1.0 - y[0] * y[0]) * y[1] - y[0];
    }

    #[test]
    fn resuming_from_the_checkpoint_repeats_the_longer_integration_bit_for_bit() {
        let opts = Options::new(1e-6, 1e-9);
        let y0 = [2.0, 0.0];
        let times: Vec<f64> = (0..=40).map(|i| 7.3 + 0.31 * i as f64).collect();
        let (whole, stats) = solve_at(vdp, 0.0, &y0, &times, &opts).unwrap();
        let mut first = Dopri5::new(2);
        first
            .integrate(vdp, 0.0, &y0, 7.3, &opts, |_, _, _| true)
            .unwrap();
        let cp = first.take_checkpoint().unwrap();
        assert!(cp.time() < 7.3 && cp.time() > 6.0);
        assert!(first.take_checkpoint().is_none());
        let (resumed, stats2) = solve_at_from(vdp, &cp, &times, &opts).unwrap();
        assert_eq!(whole, resumed);
        // the counters carry on too (max_steps counts from the original start)
        assert_eq!(stats.accepted, stats2.accepted);
        // an integration stopped by its observer before the end has no checkpoint
        first
            .integrate(vdp, 0.0, &y0, 7.3, &opts, |_, tb, _| tb < 3.0)
            .unwrap();
        assert!(first.take_checkpoint().is_none());
        // times before the checkpoint are refused, not extrapolated
        assert!(solve_at_from(vdp, &cp, &[1.0, 8.0], &opts).is_err());
    }

    fn err_with_fixed_step(h: f64) -> f64 {
        // Huge tolerances force every step to be accepted at exactly h.
        let opts = Options {
            rtol: 1e10,
            atol: vec![1e10],
            first_step: Some(h),
            max_step: h,
            max_steps: 1_000_000,
        };
        let mut s = Dopri5::new(2);
        let (t, y, _) = s
            .integrate(osc, 0.0, &[1.0, 0.0], 2.0, &opts, |_, _, _| true)
            .unwrap();
        assert!((t - 2.0).abs() < 1e-15);
        ((y[0] - 2f64.cos()).powi(2) + (y[1] + 2f64.sin()).powi(2)).sqrt()
    }

    #[test]
    fn fifth_order_convergence() {
        let e1 = err_with_fixed_step(0.1);
        let e2 = err_with_fixed_step(0.05);
        let order = (e1 / e2).log2();
        assert!((order - 5.0).abs() < 0.3, "observed order {order}");
    }

    #[test]
    fn dense_output_is_fourth_order_accurate() {
        let opts = Options::new(1e-10, 1e-12);
        let ts: Vec<f64> = (1..200).map(|i| i as f64 * 0.0501).collect();
        let (ys, _) = solve_at(osc, 0.0, &[1.0, 0.0], &ts, &opts).unwrap();
        for (t, y) in ts.iter().zip(&ys) {
            assert!((y[0] - t.cos()).abs() < 1e-8, "t={t} {} {}", y[0], t.cos());
        }
    }

    #[test]
    fn step_control_meets_tolerance_and_scales() {
        // Global error follows the tolerance; tighter rtol takes more steps.
        let mut prev_steps = 0;
        for rtol in [1e-4, 1e-6, 1e-8, 1e-10] {
            let opts = Options::new(rtol, rtol * 1e-3);
            let (ys, st) = solve_at(osc, 0.0, &[1.0, 0.0], &[10.0], &opts).unwrap();
            let err = (ys[0][0] - 10f64.cos()).abs();
            assert!(err < 50.0 * rtol, "rtol {rtol}: err {err}");
            assert!(st.accepted > prev_steps);
            prev_steps = st.accepted;
        }
    }

    #[test]
    fn backward_integration() {
        let opts = Options::new(1e-10, 1e-12);
        let (ys, _) = solve_at(osc, 0.0, &[1.0, 0.0], &[-1.0, -3.0], &opts).unwrap();
        assert!((ys[1][0] - 3f64.cos()).abs() < 1e-8);
        assert!((ys[1][1] - 3f64.sin()).abs() < 1e-8);
    }

    #[test]
    fn rejects_bad_times() {
        let opts = Options::default();
        assert!(solve_at(osc, 0.0, &[1.0, 0.0], &[1.0, 0.5], &opts).is_err());
        assert!(solve_at(osc, 0.0, &[1.0, 0.0], &[f64::NAN], &opts).is_err());
    }

    /// Prothero–Robinson `y' = -lambda (y - cos t) - sin t`, smooth solution `cos t`:
    /// stiff for large lambda, where only stability holds the explicit step down.
    fn prothero(lambda: f64) -> impl FnMut(f64, &[f64], &mut [f64]) {
        move |t, y, dy| dy[0] = -lambda * (y[0] - t.cos()) - t.sin()
    }

    #[test]
    fn stiffness_is_detected_quickly() {
        let opts = Options::new(1e-6, 1e-9);
        let t = std::time::Instant::now();
        let r = solve_at(prothero(1e7), 0.0, &[1.0], &[100.0], &opts);
        assert!(matches!(r, Err(Error::Stiff(_))), "{r:?}");
        assert!(t.elapsed().as_secs_f64() < 1.0);
    }

    #[test]
    fn mild_or_short_stiffness_is_not_an_error() {
        let opts = Options::new(1e-6, 1e-9);
        // Stiff, but finishing costs far fewer steps than the limit: integrated.
        let (ys, _) = solve_at(prothero(1e4), 0.0, &[1.0], &[10.0], &opts).unwrap();
        assert!((ys[0][0] - 10f64.cos()).abs() < 1e-6);
        // Not stiff at all.
        let (ys, _) = solve_at(osc, 0.0, &[1.0, 0.0], &[1e4], &opts).unwrap();
        assert!(ys[0][0].is_finite());
    }

    #[test]
    fn hopeless_step_budgets_fail_early() {
        // A fast rotation whose steps are limited by accuracy, not stability: not stiff,
        // but 1e3 time units need ~1e9 steps against a budget of 1e7.
        let t = std::time::Instant::now();
        let r = solve_at(
            |_, y: &[f64], dy: &mut [f64]| {
                dy[0] = 1e6 * y[1];
                dy[1] = -1e6 * y[0];
            },
            0.0,
            &[1.0, 0.0],
            &[1000.0],
            &Options::new(1e-6, 1e-9),
        );
        assert!(matches!(r, Err(Error::Integration(_))), "{r:?}");
        assert!(t.elapsed().as_secs_f64() < 2.0);
        // An absurd time span for a plain oscillator.
        let r = solve_at(osc, 0.0, &[1.0, 0.0], &[1e300], &Options::default());
        assert!(matches!(r, Err(Error::Integration(_))), "{r:?}");
    }

    #[test]
    fn a_cancelled_token_stops_the_integration() {
        let tok = crate::cancel::Token::new();
        tok.cancel();
        let r = crate::cancel::with(Some(tok), || {
            solve_at(osc, 0.0, &[1.0, 0.0], &[1e9], &Options::default())
        });
        assert_eq!(r.unwrap_err(), Error::Cancelled);
    }

    #[test]
    fn stiff_blowup_reports_error_not_panic() {
        let opts = Options {
            max_steps: 1000,
            ..Options::new(1e-6, 1e-9)
        };
        let r = solve_at(|_, y, dy| dy[0] = y[0] * y[0], 0.0, &[1.0], &[2.0], &opts);
        assert!(r.is_err());
    }
}
