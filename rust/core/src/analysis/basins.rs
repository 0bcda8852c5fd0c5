//! Basins of attraction: where starts from given ball angles (at rest in the ground
//! frame, the thesis' set-up of its figures 4-15 and 4-16) settle, each simulated for
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
//! The periods come from [`super::attractors`]' detectors (whole-turn crossings of a
//! rotating ball, mean crossings of `x` otherwise); a motion without a regular period
//! (a torus: two separated balls whose gap is modulated) keeps its label and has no
//! period. Every start is simulated on its own, so the labels do not depend on the
//! thread count or on which other starts run.

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
    /// Time simulated (the thesis: 1000).
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
        }
    }
}

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
    /// Time simulated (less than `t_end` when the start came to rest early).
    pub t_stop: f64,
    /// With the settle check: the label after the longer run.
    pub long_label: Option<Label>,
    /// The state at `t_stop` (a speed sweep carries it on to the next step).
    pub y_end: Vec<f64>,
}

/// The thesis' start: at rest in the ground frame (`x = y = x' = y' = 0`,
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

/// Classifies the start `y0` (with the settle check if asked). `Err` only when
/// cancelled.
pub fn classify_start<D: Dynamics + ?Sized>(
    model: &D,
    y0: &[f64],
    opts: &BasinOptions,
) -> Result<Outcome> {
    let mut out = judge(model, y0, opts.t_end, opts)?;
    if let Some(f) = opts.settle_factor {
        out.long_label = Some(judge(model, y0, f * opts.t_end, opts)?.label);
    }
    Ok(out)
}

fn judge<D: Dynamics + ?Sized>(
    model: &D,
    y0: &[f64],
    t_end: f64,
    opts: &BasinOptions,
) -> Result<Outcome> {
    let d = model.ndof();
    let o = model.first_ball();
    let n = d - o;
    let t_w = t_end - opts.window.min(t_end);
    let iopts = Options::new(opts.rtol, opts.atol);
    let mut solver = Dopri5::new(2 * d);
    let mut samples: Vec<(f64, Vec<f64>)> = vec![];
    let mut next = t_w;
    let mut tmp = vec![0.0; 2 * d];
    let mut at_rest = false;
    let res = solver.integrate(
        |t: f64, y: &[f64], dy: &mut [f64]| first_order_rhs(model, t, y, dy),
        0.0,
        y0,
        t_end,
        &iopts,
        |_, tb, dense| {
            while next <= tb {
                dense.eval(next, &mut tmp);
                samples.push((next, tmp.clone()));
                next += DT;
            }
            // As `attractors::classify`: a start at rest relative to the disk has
            // fallen into an equilibrium; stop there.
            at_rest = tb > 50.0 && dense.end()[d..].iter().all(|v| v.abs() < 1e-7);
            !at_rest
        },
    );
    let failed = |t_stop| Outcome {
        label: Label::Failed,
        pattern: String::new(),
        omega: f64::NAN,
        rates: vec![f64::NAN; n],
        period: None,
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
    let rest = |y: &[f64]| {
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
            t_stop,
            long_label: None,
            y_end: y.to_vec(),
        }
    };
    if at_rest || samples.len() < 4 {
        return Ok(rest(&y_end));
    }
    let m = samples.len();
    let h = m / 2;
    let span = |a: usize, b: usize| samples[b].0 - samples[a].0;
    let turns =
        |i: usize, a: usize, b: usize| (samples[b].1[o + i] - samples[a].1[o + i]) / (2.0 * PI);
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
        t_stop,
        long_label: None,
        y_end: y_end.clone(),
    };
    if rot1 != rot2 {
        return Ok(unsettled(String::new()));
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
                return Ok(unsettled(pattern));
            }
        }
        // Whole-turn crossings of each rotating ball: its period and, over whole
        // turns, its mean rate (free of the within-turn wobble a plain difference over
        // the window would carry).
        let crossings_of = |i: usize| {
            let mut c = vec![];
            for w in samples.windows(2) {
                let (a, b) = (w[0].1[o + i], w[1].1[o + i]);
                let (ka, kb) = ((a / (2.0 * PI)).floor(), (b / (2.0 * PI)).floor());
                if ka != kb {
                    let level = 2.0 * PI * ka.max(kb);
                    c.push(w[0].0 + (level - a) / (b - a) * DT);
                }
            }
            c
        };
        let mut rates = rates.clone();
        let mut period = None;
        for i in (0..n).filter(|&i| rot2[i]) {
            let c = crossings_of(i);
            if c.len() >= 2 {
                let turns = (c.len() - 1) as f64 * 2.0 * PI;
                rates[i] = rates[i].signum() * turns / (c[c.len() - 1] - c[0]);
            }
            if period.is_none() {
                period = turn_period(&c).map(|p| p.1);
            }
        }
        let omega = (0..n).filter(|&i| rot2[i]).map(|i| rates[i]).sum::<f64>() / n_rot as f64;
        let label = match (n, n_rot) {
            (2, 2) => {
                let gap = samples
                    .iter()
                    .map(|s| wrap(s.1[o] - s.1[o + 1]).abs())
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
        return Ok(Outcome {
            label,
            pattern,
            omega,
            rates,
            period,
            t_stop,
            long_label: None,
            y_end,
        });
    }
    // No ball rotates: at rest, on the way to rest, or oscillating.
    let vmax = |a: usize, b: usize| {
        samples[a..b]
            .iter()
            .flat_map(|s| s.1[d..].iter().map(|v| v.abs()))
            .fold(0.0, f64::max)
    };
    let (v1, v2) = (vmax(0, h), vmax(h, m));
    // Decaying by a fifth or more over half the window: a transient into an
    // equilibrium (the approach to a limit cycle does not take the velocities down).
    if v2 < 1e-6 || v2 < 0.8 * v1 {
        return Ok(rest(&y_end));
    }
    if v2 > 1.05 * v1 {
        return Ok(unsettled(pattern)); // still growing
    }
    let xs: Vec<(f64, f64, f64)> = samples.iter().map(|s| (s.0, s.1[0], s.1[d])).collect();
    let period = match oscillation_period(&xs) {
        Oscillation::Period(_, p) => Some(p),
        Oscillation::Rest => return Ok(rest(&y_end)),
        Oscillation::Irregular => None,
    };
    Ok(Outcome {
        label: if n == 2 { Label::OO } else { Label::Other },
        pattern,
        omega: 0.0,
        rates,
        period,
        t_stop,
        long_label: None,
        y_end,
    })
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

    fn thesis(omega: f64) -> Planar {
        Planar::new(0.2, 0.05, &[0.05], 50.0, omega, &[0.7, 0.7]).unwrap()
    }

    #[test]
    fn labels_of_the_thesis_bistable_case() {
        // Omega 1.35 (figure 4-16): balls started close together stay merged on the
        // R-R orbit; far apart they settle on the perfect balance, which
        // equilibria() calls stable there.
        let p = thesis(1.35);
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
    fn a_cancelled_grid_stops() {
        let p = thesis(1.2);
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
        let p = thesis(1.2);
        let o = BasinOptions {
            window: 2000.0,
            ..Default::default()
        };
        let e = basin_starts(&p, &[vec![0.0, 1.0]], &o).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { ref name, .. } if name == "window"));
        let e = basin_starts(&p, &[vec![0.0]], &BasinOptions::default()).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { ref name, .. } if name == "starts"));
    }
}
