//! Shampine's modified Rosenbrock pair of orders 2 and 3 (`ode23s`: Shampine & Reichelt,
//! "The MATLAB ODE suite", SIAM J. Sci. Comput. 18, 1997), L-stable, with a
//! finite-difference Jacobian: the implicit option for small stiff systems (a journal near
//! the bearing wall, whose squeeze film damps like `(1 - eps^2)^(-5/2)`). Each step costs
//! one LU of `W = I - h d J` and `n + 3` evaluations of `f`.
//!
//! ```text
//! d = 1 / (2 + sqrt 2),  e32 = 6 + sqrt 2,  T = df/dt
//! k1 = W^-1 (f(t, y) + h d T)
//! k2 = W^-1 (f(t + h/2, y + h k1 / 2) - k1) + k1
//! y1 = y + h k2                                      (order 2, the result)
//! k3 = W^-1 (f(t + h, y1) - e32 (k2 - f1) - 2 (k1 - f0) + h d T)
//! err = h (k1 - 2 k2 + k3) / 6                       (against the order-3 solution)
//! ```
//!
//! Error control as [`super::ode`]'s (scipy's RMS norm), step ratio `0.9 err^(-1/3)` within
//! `[0.2, 5]`; dense output is the scheme's own continuous extension
//! `y(t + s h) = y + h (s (1 - s) k1 + s (s - 2 d) k2) / (1 - 2 d)`.

// The stages index several arrays in lockstep, as in `ode.rs`.
#![allow(clippy::needless_range_loop)]

use super::ode::{Options, Stats};
use crate::cancel;
use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};

const D: f64 = 0.292_893_218_813_452_5; // 1 / (2 + sqrt 2)
const E32: f64 = 7.414_213_562_373_095; // 6 + sqrt 2

/// Dense output of one accepted step.
pub struct RosDense<'a> {
    t0: f64,
    h: f64,
    y: &'a [f64],
    y_new: &'a [f64],
    k1: &'a [f64],
    k2: &'a [f64],
}

impl RosDense<'_> {
    pub fn end(&self) -> &[f64] {
        self.y_new
    }

    pub fn eval(&self, t: f64, out: &mut [f64]) {
        let s = (t - self.t0) / self.h;
        let a = s * (1.0 - s) / (1.0 - 2.0 * D);
        let b = s * (s - 2.0 * D) / (1.0 - 2.0 * D);
        for i in 0..out.len() {
            out[i] = self.y[i] + self.h * (a * self.k1[i] + b * self.k2[i]);
        }
    }
}

/// The Rosenbrock 2(3) integrator for `n` states.
pub struct Rosenbrock23 {
    n: usize,
}

impl Rosenbrock23 {
    pub fn new(n: usize) -> Self {
        Rosenbrock23 { n }
    }

    /// Integrates from `t0` towards `t1`, calling `observe(t_a, t_b, dense)` after each
    /// accepted step (return `false` to stop). Same contract as [`super::ode::Dopri5::integrate`].
    pub fn integrate<F, O>(
        &mut self,
        mut f: F,
        t0: f64,
        y0: &[f64],
        t1: f64,
        opts: &Options,
        mut observe: O,
    ) -> Result<(f64, Vec<f64>, Stats)>
    where
        F: FnMut(f64, &[f64], &mut [f64]),
        O: FnMut(f64, f64, &RosDense<'_>) -> bool,
    {
        let n = self.n;
        assert_eq!(y0.len(), n);
        opts.validate(n)?;
        let atol = |i: usize| {
            if opts.atol.len() == 1 {
                opts.atol[0]
            } else {
                opts.atol[i]
            }
        };
        let mut stats = Stats::default();
        let mut t = t0;
        let mut y = y0.to_vec();
        if t1 == t0 {
            return Ok((t, y, stats));
        }
        let dir = if t1 > t0 { 1.0 } else { -1.0 };
        let mut f0 = vec![0.0; n];
        f(t, &y, &mut f0);
        stats.rhs_evals += 1;
        let mut h = match opts.first_step {
            Some(h) => h.abs(),
            None => {
                // Shampine's choice: the step at which the first-order term meets rtol.
                let mut r: f64 = 0.0;
                for i in 0..n {
                    r = r.max(f0[i].abs() / (atol(i) + opts.rtol * y[i].abs()));
                }
                let h = 0.8 * opts.rtol.powf(1.0 / 3.0) / r.max(1e-300);
                h.min((t1 - t0).abs()).max(1e-10 * (t1 - t0).abs())
            }
        };
        let (mut jac, mut ft) = (DMatrix::<f64>::zeros(n, n), vec![0.0; n]);
        let (mut tmp, mut f1, mut f2) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let mut y_new = vec![0.0; n];
        let mut need_jac = true;
        let mut rejected_last = false;
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
            if need_jac {
                // Forward differences: W-method accuracy is enough for the step and its estimate.
                for j in 0..n {
                    let dj = 1.5e-8 * y[j].abs().max(1e-3);
                    tmp.copy_from_slice(&y);
                    tmp[j] += dj;
                    f(t, &tmp, &mut f1);
                    for i in 0..n {
                        jac[(i, j)] = (f1[i] - f0[i]) / dj;
                    }
                }
                let dt = 1.5e-8 * t.abs().max(1.0);
                f(t + dt, &y, &mut f1);
                for i in 0..n {
                    ft[i] = (f1[i] - f0[i]) / dt;
                }
                stats.rhs_evals += n + 1;
                need_jac = false;
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
                hs = t1 - t;
                last = true;
            }
            let w = DMatrix::<f64>::identity(n, n) - &jac * (hs * D);
            let lu = w.lu();
            let solve = |b: Vec<f64>| lu.solve(&DVector::from_vec(b)).map(|v| v.data.into());
            let k1: Option<Vec<f64>> = solve((0..n).map(|i| f0[i] + hs * D * ft[i]).collect());
            let ok = k1.as_ref().is_some_and(|k| k.iter().all(|v| v.is_finite()));
            let mut en = f64::INFINITY;
            let mut k2v = vec![0.0; n];
            let k1v = k1.unwrap_or_else(|| vec![f64::NAN; n]);
            if ok {
                for i in 0..n {
                    tmp[i] = y[i] + 0.5 * hs * k1v[i];
                }
                f(t + 0.5 * hs, &tmp, &mut f1);
                if let Some(k) = solve((0..n).map(|i| f1[i] - k1v[i]).collect()) {
                    for i in 0..n {
                        k2v[i] = k[i] + k1v[i];
                        y_new[i] = y[i] + hs * k2v[i];
                    }
                    f(t + hs, &y_new, &mut f2);
                    let b3: Vec<f64> = (0..n)
                        .map(|i| {
                            f2[i] - E32 * (k2v[i] - f1[i]) - 2.0 * (k1v[i] - f0[i]) + hs * D * ft[i]
                        })
                        .collect();
                    if let Some(k3) = solve(b3) {
                        let mut s = 0.0;
                        for i in 0..n {
                            let e = hs / 6.0 * (k1v[i] - 2.0 * k2v[i] + k3[i]);
                            let sc = atol(i) + opts.rtol * y[i].abs().max(y_new[i].abs());
                            s += (e / sc).powi(2);
                        }
                        en = (s / n as f64).sqrt();
                        if y_new.iter().any(|v| !v.is_finite()) {
                            en = f64::NAN;
                        }
                    }
                }
                stats.rhs_evals += 2;
            }
            if !en.is_finite() {
                h *= 0.2;
                stats.rejected += 1;
                rejected_last = true;
                continue;
            }
            if en <= 1.0 {
                stats.accepted += 1;
                let t_new = if last { t1 } else { t + hs };
                let dense = RosDense {
                    t0: t,
                    h: hs,
                    y: &y,
                    y_new: &y_new,
                    k1: &k1v,
                    k2: &k2v,
                };
                let go_on = observe(t, t_new, &dense);
                t = t_new;
                y.copy_from_slice(&y_new);
                f0.copy_from_slice(&f2);
                need_jac = true;
                if last || !go_on {
                    return Ok((t, y, stats));
                }
                let mut fac = if en == 0.0 {
                    5.0
                } else {
                    (0.9 * en.powf(-1.0 / 3.0)).min(5.0)
                };
                if rejected_last {
                    fac = fac.min(1.0);
                }
                rejected_last = false;
                h *= fac;
            } else {
                h *= (0.9 * en.powf(-1.0 / 3.0)).max(0.2);
                stats.rejected += 1;
                rejected_last = true;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixed_step_error(h: f64) -> f64 {
        // y'' = -y + sin(2t) with y(0) = 1, y'(0) = 0 has y = cos t + (2 sin t - sin 2t) / 3:
        // non-autonomous, so the df/dt term is exercised too.
        let opts = Options {
            rtol: 1e10,
            atol: vec![1e10],
            first_step: Some(h),
            max_step: h,
            max_steps: 1_000_000,
        };
        let (_, y, _) = Rosenbrock23::new(2)
            .integrate(
                |t, y: &[f64], dy: &mut [f64]| {
                    dy[0] = y[1];
                    dy[1] = -y[0] + (2.0 * t).sin();
                },
                0.0,
                &[1.0, 0.0],
                2.0,
                &opts,
                |_, _, _| true,
            )
            .unwrap();
        let exact = 2f64.cos() + (2.0 * 2f64.sin() - 4f64.sin()) / 3.0;
        (y[0] - exact).abs()
    }

    #[test]
    fn second_order_convergence() {
        let (e1, e2) = (fixed_step_error(0.02), fixed_step_error(0.01));
        let order = (e1 / e2).log2();
        assert!(
            (order - 2.0).abs() < 0.15,
            "observed order {order} ({e1}, {e2})"
        );
    }

    #[test]
    fn stiff_problem_takes_few_steps_and_is_accurate() {
        // Prothero–Robinson with lambda = 1e7: the explicit pair needs ~1e7 steps per unit time.
        let lam = 1e7;
        let mut ts = vec![];
        let (_, y, st) = Rosenbrock23::new(1)
            .integrate(
                |t, y: &[f64], dy: &mut [f64]| dy[0] = -lam * (y[0] - t.cos()) - t.sin(),
                0.0,
                &[1.0],
                10.0,
                &Options::new(1e-6, 1e-9),
                |_, tb, d| {
                    let mut o = [0.0];
                    d.eval(tb, &mut o);
                    ts.push((tb, o[0]));
                    true
                },
            )
            .unwrap();
        assert!((y[0] - 10f64.cos()).abs() < 1e-5, "{}", y[0]);
        assert!(st.accepted < 20_000, "{st:?}");
        // The dense output meets the step's end.
        let (tb, yb) = *ts.last().unwrap();
        assert!((tb - 10.0).abs() < 1e-12 && (yb - y[0]).abs() < 1e-14);
    }

    #[test]
    fn meets_tolerance_on_a_smooth_problem() {
        let mut out = vec![];
        Rosenbrock23::new(2)
            .integrate(
                |_, y: &[f64], dy: &mut [f64]| {
                    dy[0] = y[1];
                    dy[1] = -y[0];
                },
                0.0,
                &[1.0, 0.0],
                5.0,
                &Options::new(1e-8, 1e-10),
                |ta, tb, d| {
                    let tm = 0.5 * (ta + tb);
                    let mut o = [0.0; 2];
                    d.eval(tm, &mut o);
                    out.push((tm, o[0]));
                    true
                },
            )
            .unwrap();
        let worst = out
            .iter()
            .map(|(t, v)| (v - t.cos()).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-5, "{worst}");
    }
}
