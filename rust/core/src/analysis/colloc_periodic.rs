//! Single periodic solutions by orthogonal collocation ([`crate::numerics::collocation`]),
//! certified as harmonic-balance results are, and the choice between the two
//! discretisations that `periodic()` makes.
//!
//! Harmonic balance stays the first try: it is the cheaper and more accurate
//! discretisation while an orbit is smooth. Near the infinite-period end of a rotating
//! branch the orbit lingers in a slow phase and crosses the rest in a fast jump; the
//! series then needs more harmonics than asked for, and its own certificates say so
//! (`truncated`, `not_closed`, or `N = "auto"` missing its target at `N_max`). Those are
//! the results [`by_method`] hands to collocation under [`Method::Auto`]; a result that
//! harmonic balance certified is returned unchanged.

use crate::analysis::attractors::{guess_from_state, initial_states};
use crate::analysis::periodic::{Periodic, PeriodicOptions};
use crate::floquet::{bounded_verdict, judge, Floquet, FloquetOptions};
use crate::hb::{fit_coefficients, HbSolution, Status};
use crate::model::{first_order_rhs, Dynamics};
use crate::numerics::collocation::{
    multipliers_checked, solve, CollocOptions, CollocOrbit, CollocSolution, CollocStatus,
};
use crate::ode::{solve_at, Options};

/// Which discretisation `periodic()` solves with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Harmonic balance only (what `periodic()` always did).
    Hb,
    /// Collocation, started from the harmonic-balance search's series (or a simulation).
    Collocation,
    /// Harmonic balance, and collocation where its certificates refuse the series.
    Auto,
}

impl Method {
    pub fn parse(name: &str) -> crate::Result<Self> {
        match name {
            "hb" => Ok(Method::Hb),
            "collocation" => Ok(Method::Collocation),
            "auto" => Ok(Method::Auto),
            other => Err(crate::Error::param_range(
                "method",
                format!("must be \"hb\", \"collocation\" or \"auto\", got {other:?}"),
                "\"hb\", \"collocation\" or \"auto\"",
            )),
        }
    }
}

/// Harmonics of the series fitted to a collocation orbit (its `coeffs`, for the
/// spectrum and as a start for branches): harmonic balance's default `N_max`.
pub const FITTED_HARMONICS: usize = 32;

/// Largest closure ([`piecewise_closure`]) of a collocation orbit; above it the result
/// is `NotClosed`. Measured 2026-11-28 on the merged R-R branch (`mu 0.2, zeta 0.05,
/// zeta_b 0.1, delta 50, eta (1, 1)`) at Omega 1.2, 0.95, 0.93, 0.92, NCOL 4: NTST 50
/// and 100 close to 2e-11..7e-7 (periods within 2e-12 of each other); NTST 20 to
/// 2.5e-8..7.6e-5 (0.92, period off by 9e-9), NTST 4 to 10 to 2.1e-4..0.1 (periods off by
/// 4e-8..1e-3; 1.2 at NTST 10: 3.8e-6, period off by 9e-10). The bound separates the
/// meshes that resolve these orbits to ~1e-8 in the period from those that do not;
/// NTST 20 near Omega 0.92 is within a factor 1.3 of it.
pub const COLLOC_MAX_CLOSURE: f64 = 1e-4;

/// A collocation result in `periodic()`'s form: the certified [`Periodic`] (its series
/// fitted to the orbit, see [`FITTED_HARMONICS`]) and the orbit itself.
#[derive(Debug, Clone)]
pub struct CollocPeriodic {
    pub periodic: Periodic,
    /// The orbit on its mesh (also for a solve that did not converge: its last iterate).
    pub orbit: Option<CollocOrbit>,
}

/// `periodic()`'s result by `method`: `hb` (harmonic balance's result, already computed
/// by the caller) unchanged for [`Method::Hb`] and, under [`Method::Auto`], wherever
/// harmonic balance certified its series ([`hb_refused`] says where not). Otherwise the
/// orbit by collocation from the user's `guess` (all its harmonics), then `hb`'s series
/// where Newton converged on it, or, where neither converges and there is no guess, from
/// a simulated start; under `Auto` a collocation solve that fails its certificates leaves
/// `hb`'s result as it was.
pub fn by_method<D: Dynamics + ?Sized>(
    p: &D,
    ball_winding: &[f64],
    hb: Periodic,
    guess: Option<&HbSolution>,
    method: Method,
    copts: &CollocOptions,
    opts: &PeriodicOptions,
) -> (Periodic, Option<CollocOrbit>) {
    match method {
        Method::Hb => return (hb, None),
        Method::Auto if !hb_refused(&hb, guess.is_some()) => return (hb, None),
        _ => {}
    }
    // Harmonic balance's series only where Newton converged on it (the certificates
    // aside): a diverged iterate is no orbit's shape.
    let converged = matches!(
        hb.sol.status,
        Status::Converged | Status::Truncated | Status::NotClosed
    );
    let starts: Vec<&HbSolution> = guess
        .into_iter()
        .chain(converged.then_some(&hb.sol))
        .collect();
    // With a guess, as harmonic balance, no simulated search; nor where harmonic
    // balance's search found no start: its simulations were these.
    let simulate = guess.is_none() && hb.sol.status != Status::NoGuess;
    let c = collocation_periodic(p, ball_winding, &starts, simulate, copts, opts);
    if method == Method::Auto && c.periodic.sol.status != Status::Converged {
        return (hb, None);
    }
    (c.periodic, c.orbit)
}

/// Whether harmonic balance's own certificates say its series cannot hold the orbit at
/// the harmonics it had: a converged series refused by the tail or closure certificate,
/// or `N = "auto"` short of its target at `N_max`; and, from a user's guess (`guessed`),
/// a Newton solve that failed (near the infinite-period end a series of the neighbour's
/// harmonics diverges where collocation from the same guess converges: Omega 0.9175 from
/// the orbit at 0.92 on the merged R-R branch). Without a guess, a search that found no
/// start or diverged is not handed over: its simulated starts are the ones collocation
/// would get (`method = "collocation"` still tries them).
pub fn hb_refused(r: &Periodic, guessed: bool) -> bool {
    match r.sol.status {
        Status::Converged => r.target_met == Some(false),
        Status::Truncated | Status::NotClosed => true,
        Status::Diverged | Status::Singular | Status::MaxIterations => guessed,
        _ => false,
    }
}

/// A periodic orbit of the pattern with windings `ball_winding` by collocation, from the
/// first of the series `starts` (with a finite frequency) from which Newton converges,
/// otherwise (with `simulate`) from the model's simulated starts, certified by
/// [`certify_orbit`].
pub fn collocation_periodic<D: Dynamics + ?Sized>(
    p: &D,
    ball_winding: &[f64],
    starts: &[&HbSolution],
    simulate: bool,
    copts: &CollocOptions,
    opts: &PeriodicOptions,
) -> CollocPeriodic {
    let usable = |s: &HbSolution| {
        s.omega.is_finite() && s.omega > 0.0 && s.coeffs.iter().all(|c| c.is_finite())
    };
    let start = starts.last().copied();
    let mut tried: Option<CollocSolution> = None;
    for s in starts.iter().filter(|s| usable(s)) {
        match solve(p, &CollocOrbit::from_hb(s, copts.ntst, copts.ncol), copts) {
            Ok(sol) if sol.status == CollocStatus::Converged => {
                return certify_orbit(p, sol, opts);
            }
            Ok(sol) => {
                tried.get_or_insert(sol);
            }
            Err(e) => return failed(p, ball_winding, start, None, Some(e.to_string())),
        }
    }
    // A simulated start: the attractor's series fitted with many harmonics, so that the
    // slow phase and the jump of a long-period orbit survive the fit.
    if simulate && ball_winding.iter().all(|w| w.abs() <= 1.0) && !crate::cancel::cancelled() {
        let rotating: Vec<bool> = ball_winding.iter().map(|w| *w != 0.0).collect();
        for y0 in initial_states(p) {
            if crate::cancel::cancelled() {
                break;
            }
            let Some(g) = guess_from_state(p, &y0, Some(&rotating), FITTED_HARMONICS, &opts.guess)
            else {
                continue;
            };
            match solve(p, &CollocOrbit::from_hb(&g, copts.ntst, copts.ncol), copts) {
                Ok(sol) if sol.status == CollocStatus::Converged => {
                    return certify_orbit(p, sol, opts);
                }
                Ok(sol) => {
                    tried.get_or_insert(sol);
                }
                Err(e) => return failed(p, ball_winding, start, None, Some(e.to_string())),
            }
        }
    }
    failed(p, ball_winding, start, tried, None)
}

/// The result of a collocation solve that did not converge (or could not run).
fn failed<D: Dynamics + ?Sized>(
    p: &D,
    ball_winding: &[f64],
    start: Option<&HbSolution>,
    tried: Option<CollocSolution>,
    why: Option<String>,
) -> CollocPeriodic {
    let d = p.ndof();
    let mut winding = vec![0.0; d];
    winding[p.first_ball()..].copy_from_slice(ball_winding);
    let status = match tried.as_ref().map(|s| s.status) {
        None if start.is_none() => Status::NoGuess,
        None => Status::Diverged,
        Some(CollocStatus::MaxIterations) => Status::MaxIterations,
        Some(_) => Status::Diverged,
    };
    let n_harm = start.map_or(FITTED_HARMONICS, |s| s.n_harm);
    let mut sol = HbSolution::start(
        f64::NAN,
        vec![f64::NAN; d * (2 * n_harm + 1)],
        winding,
        n_harm,
        status,
    );
    if let Some(t) = &tried {
        sol.residual = t.residual;
        sol.iterations = t.iterations;
    }
    CollocPeriodic {
        periodic: Periodic {
            sol,
            closure: None,
            floquet: None,
            floquet_error: why,
            target_met: None,
            hill: None,
            tail: f64::NAN,
            omega_error: None,
        },
        orbit: tried.map(|t| t.orbit),
    }
}

/// The series of `FITTED_HARMONICS` harmonics fitted to a collocation orbit (sampled at
/// harmonic balance's default samples for that many), with the orbit's frequency.
pub fn fitted_series(orbit: &CollocOrbit, winding: &[f64]) -> HbSolution {
    let d = winding.len();
    let s = crate::hb::default_samples(FITTED_HARMONICS);
    let mut samples = Vec::with_capacity(s * d);
    for i in 0..s {
        let y = orbit.state(orbit.period * i as f64 / s as f64);
        samples.extend_from_slice(&y[..d]);
    }
    let coeffs = fit_coefficients(&samples, d, winding, FITTED_HARMONICS);
    let mut sol = HbSolution::start(
        2.0 * std::f64::consts::PI / orbit.period,
        coeffs,
        winding.to_vec(),
        FITTED_HARMONICS,
        Status::Converged,
    );
    sol.samples = s;
    sol
}

/// The closure of a collocation orbit: the period integrated in its mesh intervals, each
/// from the orbit's state at the interval's start (Dormand–Prince at `rtol 1e-10, atol
/// 1e-12`), and the largest max-norm distance of an interval's end from the orbit's
/// state there. One simulated period from a single state, as harmonic balance's "NI" check
/// does, would grow with the unstable multipliers (up to 1e7 on unstable R-R orbits);
/// restarting at every mesh point measures the orbit's own error for the same
/// integration length.
pub fn piecewise_closure<D: Dynamics + ?Sized>(p: &D, orbit: &CollocOrbit) -> crate::Result<f64> {
    let n = orbit.n;
    let (mut y0, mut y1, mut dy) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut worst = 0.0f64;
    for j in 0..orbit.ntst() {
        if crate::cancel::cancelled() {
            return Err(crate::Error::Cancelled);
        }
        let (s0, s1) = (orbit.mesh[j], orbit.mesh[j + 1]);
        orbit.eval(s0, &mut y0, &mut dy);
        orbit.eval(s1, &mut y1, &mut dy);
        let dt = (s1 - s0) * orbit.period;
        let (ys, _) = solve_at(
            |t: f64, y: &[f64], dy: &mut [f64]| first_order_rhs(p, t, y, dy),
            0.0,
            &y0,
            &[dt],
            &Options::new(1e-10, 1e-12),
        )?;
        worst = ys[0]
            .iter()
            .zip(&y1)
            .fold(worst, |a, (u, v)| a.max((u - v).abs()));
    }
    Ok(worst)
}

/// A converged collocation orbit certified as `periodic()` certifies a series: its
/// closure ([`piecewise_closure`], above [`COLLOC_MAX_CLOSURE`]: `NotClosed`, no
/// multipliers), then, with Floquet options, the multipliers of the discretised monodromy
/// (AUTO's) with a bound on the leading non-trivial modulus' error: twice its difference
/// to the monodromy integrated along the orbit at the Floquet options' `rtol`
/// ([`multipliers_checked`]), plus the integrated one's trivial multiplier's error (its
/// own error measure, as the finer series' is in
/// [`crate::periodic::bound_verdict`]). The verdict is [`bounded_verdict`]'s: none unless
/// the bound is smaller than the distance to 1.
pub fn certify_orbit<D: Dynamics + ?Sized>(
    p: &D,
    sol: CollocSolution,
    opts: &PeriodicOptions,
) -> CollocPeriodic {
    let d = p.ndof();
    let winding: Vec<f64> = sol.orbit.jump[..d]
        .iter()
        .map(|j| (j / (2.0 * std::f64::consts::PI)).round())
        .collect();
    let mut series = fitted_series(&sol.orbit, &winding);
    series.residual = sol.residual;
    series.iterations = sol.iterations;
    let tail = series.tail_ratio_on(p.layout().support());
    let (closure, mut floquet_error) = match piecewise_closure(p, &sol.orbit) {
        Ok(c) => (Some(c), None),
        Err(e) => (None, Some(e.to_string())),
    };
    if !closure.is_some_and(|c| c <= COLLOC_MAX_CLOSURE) {
        series.status = Status::NotClosed;
    }
    let floquet = match (&opts.floquet, series.status) {
        (Some(fo), Status::Converged) => match bounded_multipliers(p, &sol, fo) {
            Ok(f) => Some(f),
            Err(e) => {
                floquet_error = Some(e.to_string());
                None
            }
        },
        _ => None,
    };
    CollocPeriodic {
        periodic: Periodic {
            sol: series,
            closure,
            floquet,
            floquet_error,
            target_met: None,
            hill: None,
            tail,
            omega_error: None,
        },
        orbit: Some(sol.orbit),
    }
}

/// The discretised multipliers judged against their bound (see [`certify_orbit`]).
fn bounded_multipliers<D: Dynamics + ?Sized>(
    p: &D,
    sol: &CollocSolution,
    fo: &FloquetOptions,
) -> crate::Result<Floquet> {
    let m = multipliers_checked(p, sol, fo.rtol)?;
    let own = judge(&m.integrated, 0.0, f64::INFINITY).trivial_error;
    let err = m.modulus_error + own;
    let j = judge(&m.multipliers, fo.margin, fo.max_trivial);
    Ok(Floquet {
        stability: bounded_verdict(&m.multipliers, fo, None, None, err),
        trivial: j.trivial,
        trivial_error: j.trivial_error,
        separation_error: None,
        max_modulus: j.max_modulus,
        steps: 0,
        rhs_evals: 0,
        method_error: None,
        modulus_error: Some(err),
        modulus_error_against: None,
        multipliers: m.multipliers,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::periodic::periodic;
    use crate::floquet::Stability;
    use crate::model::Planar;

    fn balancer(omega: f64) -> Planar {
        Planar::new(0.2, 0.05, &[0.1], 50.0, omega, &[1.0, 1.0]).unwrap()
    }

    fn opts() -> PeriodicOptions {
        PeriodicOptions {
            floquet: Some(FloquetOptions::default()),
            ..Default::default()
        }
    }

    /// At Omega 1.2 harmonic balance certifies its N = 3 series: "auto" keeps it. Forced
    /// collocation gives the orbit of harmonic balance at N = 24 (period to 1e-8), closed
    /// to 1e-6, with a stable verdict whose bound is below the distance to 1.
    #[test]
    fn smooth_orbit_auto_keeps_hb_and_collocation_agrees() {
        let p = balancer(1.2);
        let o = opts();
        let hb = periodic(&p, &[true, true], None, &o);
        assert_eq!(hb.sol.status, Status::Converged);
        let c = CollocOptions::default();
        let (kept, orbit) = by_method(&p, &[-1.0, -1.0], hb.clone(), None, Method::Auto, &c, &o);
        assert!(orbit.is_none());
        assert_eq!(kept.sol.omega, hb.sol.omega);
        let (col, orbit) = by_method(&p, &[-1.0, -1.0], hb, None, Method::Collocation, &c, &o);
        assert!(orbit.is_some());
        assert_eq!(col.sol.status, Status::Converged);
        let fine = PeriodicOptions {
            hb: crate::hb::HbOptions {
                n_harm: 24,
                tol: 1e-12,
                ..Default::default()
            },
            ..o.clone()
        };
        let r24 = periodic(&p, &[true, true], None, &fine);
        let rel = (col.sol.period() / r24.sol.period() - 1.0).abs();
        assert!(
            rel < 1e-8,
            "period {} vs {}",
            col.sol.period(),
            r24.sol.period()
        );
        assert!(col.closure.unwrap() < 1e-6, "{:?}", col.closure);
        let f = col.floquet.unwrap();
        assert_eq!(f.stability, Stability::Stable);
        assert!(f.modulus_error.unwrap() < 1.0 - f.max_modulus);
    }

    /// At Omega 0.93 the N = 3 series is refused by its certificates: "auto" solves by
    /// collocation (NTST 20 here), and the orbit closes. Its discretised leading multiplier
    /// is far from the integrated one (~1e-8) at this NTST, and the bound says so: no
    /// verdict.
    #[test]
    fn slow_orbit_auto_switches_to_collocation() {
        let p = balancer(0.93);
        let o = opts();
        let hb = periodic(&p, &[true, true], None, &o);
        assert!(hb_refused(&hb, false), "{:?}", hb.sol.status);
        let c = CollocOptions::default();
        let (r, orbit) = by_method(&p, &[-1.0, -1.0], hb, None, Method::Auto, &c, &o);
        assert!(orbit.is_some());
        assert_eq!(r.sol.status, Status::Converged);
        assert!(r.sol.period() > 300.0, "{}", r.sol.period());
        println!(
            "closure {:?} floquet {:?}",
            r.closure,
            r.floquet
                .as_ref()
                .map(|f| (f.max_modulus, f.modulus_error, f.stability))
        );
    }

    #[test]
    fn method_names_are_checked() {
        assert_eq!(Method::parse("auto").unwrap(), Method::Auto);
        let e = Method::parse("shooting").unwrap_err();
        assert!(matches!(&e, crate::Error::InvalidParameter { name, .. } if name == "method"));
    }
}
