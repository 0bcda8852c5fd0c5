//! Periodic solutions as a user asks for them: a ball pattern (`R` rotating, `O`
//! oscillating) and parameters in, a converged harmonic-balance solution with its
//! Floquet multipliers out. Without a user guess the start comes from a time
//! simulation: settle, detect which balls rotate, measure the period, fit the series.

use crate::error::check_range;
use crate::floquet::{
    bounded_verdict, floquet, hill, hill_verdict, judge, Floquet, FloquetOptions, HillTarget,
    Stability, HILL_MAX, HILL_TOL, HILL_VERDICT_ROOM,
};
use crate::hb::{default_samples, defect_closure, solve, HbOptions, HbSolution, Status};
use crate::model::{first_order_rhs, Dynamics};
use crate::numerics::problem::Parametric;
use crate::ode::{solve_at, Options};
use std::f64::consts::PI;

// The simulated starts and their classification live in `attractors`; these names stay
// here too, where callers of the periodic solve have always found them.
use crate::analysis::attractors::guess_with_turns;
pub use crate::analysis::attractors::{guess_from_state, initial_states, GuessOptions};

/// Which balls rotate (`true`) and which oscillate, from the canonical pattern: one
/// letter per ball, `R` (rotating) or `O` (oscillating), joined by `-` (`"R-O"`; `"R"`
/// for one ball), as `pattern_string` writes it and scan tables store it. Other
/// spellings (`"RR"`, `"r-r"`, `" R-R "`) are refused with the canonical form, so a
/// pattern given and the `type` column it produces are the same string.
pub fn parse_pattern(pattern: &str, n_balls: usize) -> crate::Result<Vec<bool>> {
    let example = vec!["R"; n_balls.max(1)].join("-");
    let allowed = format!("{n_balls} letters R or O joined by '-', e.g. \"{example}\"");
    let letters: Vec<char> = pattern
        .chars()
        .filter(|c| !matches!(c, '-' | ' ' | '_' | '\t'))
        .map(|c| c.to_ascii_uppercase())
        .collect();
    let readable = letters.len() == n_balls && letters.iter().all(|c| *c == 'R' || *c == 'O');
    let canonical = letters
        .iter()
        .map(|c| c.to_string())
        .collect::<Vec<_>>()
        .join("-");
    if readable && canonical == pattern {
        return Ok(letters.into_iter().map(|c| c == 'R').collect());
    }
    let message = if readable {
        format!("write {pattern:?} as \"{canonical}\" (the canonical form)")
    } else {
        format!("must give R (rotating) or O (oscillating) for each of the {n_balls} balls, joined by '-', e.g. \"{example}\", got {pattern:?}")
    };
    Err(crate::Error::param_range("pattern", message, allowed))
}

/// Largest number of whole turns per period a ball may be asked to make: an orbit with
/// more is a long sequence of turns that a harmonic series of modest `N` cannot hold.
pub const MAX_WINDING: i64 = 16;

/// The secular slope of each ball (turns per period, `-1` for the usual rotating ball,
/// 0 for an oscillating one) from a pattern and, optionally, explicit windings: one
/// non-zero integer per `R` ball and 0 per `O` ball, at most [`MAX_WINDING`] in size.
/// A period-doubled R-R orbit is `"R-R"` with windings `[-2, -2]`: each ball winds
/// twice (backwards, lagging the disk) per doubled period.
pub fn parse_windings(
    pattern: &str,
    windings: Option<&[i64]>,
    n_balls: usize,
) -> crate::Result<Vec<f64>> {
    let rotating = parse_pattern(pattern, n_balls)?;
    let Some(w) = windings else {
        return Ok(plain_windings(&rotating));
    };
    let allowed = format!(
        "{n_balls} integers, non-zero (|w| <= {MAX_WINDING}) for each R ball of the pattern and 0 for each O ball"
    );
    if w.len() != n_balls {
        return Err(crate::Error::param_range(
            "windings",
            format!("needs one winding per ball ({n_balls}), got {}", w.len()),
            allowed,
        ));
    }
    for (i, (&wi, &r)) in w.iter().zip(&rotating).enumerate() {
        let ok = if r {
            wi != 0 && wi.abs() <= MAX_WINDING
        } else {
            wi == 0
        };
        if !ok {
            let letter = if r { "R" } else { "O" };
            return Err(crate::Error::param_range(
                "windings",
                format!(
                    "ball {} is {letter} in pattern {pattern:?} but has winding {wi}",
                    i + 1
                ),
                allowed,
            ));
        }
    }
    Ok(w.iter().map(|&v| v as f64).collect())
}

/// The balls' windings of the usual orbit of a pattern: `-1` per rotating ball (one
/// turn per period, lagging the disk), 0 per oscillating one.
pub fn plain_windings(rotating: &[bool]) -> Vec<f64> {
    rotating
        .iter()
        .map(|&r| if r { -1.0 } else { 0.0 })
        .collect()
}

/// Whether the balls' windings are a pattern's usual ones ([`plain_windings`]): one
/// turn per period for each rotating ball, none for the others.
pub fn is_plain(winding: &[f64]) -> bool {
    let rotating: Vec<bool> = winding.iter().map(|w| *w != 0.0).collect();
    *winding == plain_windings(&rotating)
}

/// A solution type as a scan asks for it: a pattern (`"R-R"`), or a pattern with the
/// balls' windings in brackets (`"R-R[-2,-2]"`, the period-doubled R-R orbit;
/// `"O-R[0,-2]"`), checked as [`parse_windings`] checks them. Returns the balls'
/// windings. Windings equal to the pattern's own (`"R-R[-1,-1]"`) are refused with the
/// short form, so that one type has one name.
pub fn parse_solution_type(spec: &str, n_balls: usize) -> crate::Result<Vec<f64>> {
    let Some((pattern, rest)) = spec.split_once('[') else {
        return Ok(plain_windings(&parse_pattern(spec, n_balls)?));
    };
    let allowed = format!(
        "a pattern, optionally followed by {n_balls} windings in brackets, e.g. \"{}[{}]\"",
        vec!["R"; n_balls.max(1)].join("-"),
        vec!["-2"; n_balls.max(1)].join(",")
    );
    parse_pattern(pattern, n_balls)?;
    let inner = rest.strip_suffix(']').ok_or_else(|| {
        crate::Error::param_range("pattern", format!("{spec:?} must end with ']'"), &allowed)
    })?;
    let w: Vec<i64> = inner
        .split(',')
        .map(|x| x.trim().parse::<i64>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            crate::Error::param_range(
                "pattern",
                format!("{spec:?}: the windings must be integers separated by ','"),
                &allowed,
            )
        })?;
    let wound = parse_windings(pattern, Some(&w), n_balls)?;
    if is_plain(&wound) {
        return Err(crate::Error::param_range(
            "pattern",
            format!("write {spec:?} as \"{pattern}\" (these are its usual windings)"),
            allowed,
        ));
    }
    Ok(wound)
}

/// How many times a series with these windings could repeat within its period: the
/// greatest common divisor of the balls' turns (1 when no ball turns).
pub fn repetitions(winding: &[f64]) -> usize {
    fn gcd(a: u64, b: u64) -> u64 {
        if b == 0 {
            a
        } else {
            gcd(b, a % b)
        }
    }
    let g = winding.iter().fold(0u64, |g, w| gcd(g, w.abs() as u64));
    g.max(1) as usize
}

/// Whether the series is an orbit of a shorter period written several times over its
/// own (its windings allow it: [`repetitions`]), as a period-doubled branch becomes at
/// its period doubling.
pub fn is_repeated(sol: &HbSolution) -> bool {
    let m = repetitions(&sol.winding);
    m > 1 && repeats(sol, m)
}

/// Whether the series repeats `m` times per period (only harmonics that are multiples
/// of `m`, windings divisible by `m`): an orbit of period `T / m` written over `T`.
pub fn repeats(sol: &HbSolution, m: usize) -> bool {
    if m <= 1 || sol.winding.iter().any(|w| (w / m as f64).fract() != 0.0) {
        return m <= 1;
    }
    let scale = sol.coeffs.iter().fold(1e-300f64, |a, c| a.max(c.abs()));
    (0..sol.ndof()).all(|j| {
        let c = sol.coord(j);
        (1..=sol.n_harm)
            .filter(|k| k % m != 0)
            .all(|k| c[2 * k - 1].hypot(c[2 * k]) <= 1e-6 * scale)
    })
}

/// The R/O pattern of the balls, which are the last `n_balls` coordinates.
pub fn pattern_string(winding: &[f64], n_balls: usize) -> String {
    winding[winding.len() - n_balls..]
        .iter()
        .map(|w| if *w != 0.0 { "R" } else { "O" })
        .collect::<Vec<_>>()
        .join("-")
}

/// Choose the number of harmonics per solution instead of fixing it.
#[derive(Debug, Clone)]
pub struct AutoHarmonics {
    /// Accuracy asked for: the highest harmonic relative to the motion
    /// ([`HbSolution::tail_ratio`]) and the trivial multiplier's distance from 1 must both
    /// fall below it (the latter not below what the RK45 tolerance allows).
    pub target: f64,
    pub n_max: usize,
}

impl AutoHarmonics {
    pub fn validate(&self, n_harm: usize) -> crate::Result<()> {
        check_range("target", self.target, 0.0, true, 1.0, true)?;
        if self.n_max < n_harm || self.n_max > 256 {
            return Err(crate::Error::param_range(
                "N_max",
                format!("must be in [N, 256] = [{n_harm}, 256], got {}", self.n_max),
                format!("[{n_harm}, 256]"),
            ));
        }
        Ok(())
    }
}

/// Default of [`PeriodicOptions::max_closure`]. Measured (the ignored test
/// `measure_certificates`, and the Tien (2011) maps of tests/test_scan.py): the genuine orbits'
/// integrated defect at N = 3 is at most 4.9 at zeta 0.05 (Omega 1.0, eta 0.6, omega
/// 0.03-0.04, simulated closure 0.14-0.25; typically 1e-5 to 1e-1), 10 to 50 times their
/// simulated closure since the damping forgets old errors; strongly unstable O-O and R-R
/// orbits (multipliers up to 5e7, where a simulated closure is useless) give 1.2 to 4.4.
/// At zeta 0.02 the slowest R-R series (Omega 1.0, eta 0.6 and 0.7) give 9.5 and 5.9 with
/// simulated closures of 0.94 and 0.60: too coarse to call orbits. The series of the
/// issue's reproduction that are no orbits (simulated closure 1.2 to 6) give 23 to 1800 at
/// N = 8 and 47 to 1400 at N = 3.
pub const MAX_CLOSURE: f64 = 6.0;

/// Default of [`PeriodicOptions::max_tail`] (the scan's `max_tail` default too).
pub const MAX_TAIL: f64 = 0.25;

#[derive(Debug, Clone)]
pub struct PeriodicOptions {
    pub hb: HbOptions,
    /// `None` skips the Floquet analysis.
    pub floquet: Option<FloquetOptions>,
    pub guess: GuessOptions,
    /// `Some`: raise N from `hb.n_harm` until the target is met.
    pub auto: Option<AutoHarmonics>,
    /// Also estimate the multipliers by Hill's method and compare the verdicts.
    pub hill: bool,
    /// `(margin, max_trivial)` for Hill's verdict when `floquet` is `None` (with a
    /// monodromy both verdicts use the Floquet options'); `None`: the defaults.
    pub hill_judging: Option<(f64, f64)>,
    /// What Hill's truncation is enlarged for: the multipliers to [`HILL_TOL`], or (a
    /// scan's default) only as far as its verdict needs.
    pub hill_target: HillTarget,
    /// `None`: Hill's cross-check (with `hill`) runs on every converged solution.
    /// `Some(band)`: Hill cross-checks the monodromy only where it leaves the verdict in
    /// some doubt (see [`hill_wanted`]): it failed or gave no verdict, or the leading
    /// non-trivial modulus is within `band` of 1 or within [`HILL_VERDICT_ROOM`] times the
    /// monodromy's own error measures of 1; without a monodromy (`floquet` `None`), not at
    /// all.
    pub hill_band: Option<f64>,
    /// Where the verdict's error bound ([`bound_verdict`]) leaves it open, raise the
    /// harmonics (the result's `N` then differs from the one asked for). `false` keeps
    /// the series asked for and leaves such a verdict undetermined, as a study of one
    /// truncation needs.
    pub refine_verdicts: bool,
    /// Largest integrated ODE defect ([`defect_closure`]) of a converged series; above
    /// it the result is `NotClosed`.
    pub max_closure: f64,
    /// Largest [`HbSolution::tail_ratio`] of a converged series; above it the result
    /// is `Truncated`.
    pub max_tail: f64,
}

impl Default for PeriodicOptions {
    fn default() -> Self {
        PeriodicOptions {
            hb: HbOptions::default(),
            floquet: None,
            guess: GuessOptions::default(),
            auto: None,
            hill: false,
            hill_judging: None,
            hill_target: HillTarget::Multipliers,
            hill_band: None,
            refine_verdicts: true,
            max_closure: MAX_CLOSURE,
            max_tail: MAX_TAIL,
        }
    }
}

/// Most unknowns of one harmonic-balance system, `ndof (2 N + 1) + 1`. Its dense Jacobian
/// takes `8 n^2` bytes (8192 unknowns: 537 MB, and the factorisation works on a copy) and
/// one LU about `2 n^3 / 3` flops (10 balls at N = 256, 6157 unknowns: 3-5 s on the 2-core
/// machine). 64 balls at N = 256 asked for 36 GB and aborted the process when the
/// allocation failed. Ten balls keep N = 256; 64 balls allow N <= 61.
pub const MAX_HB_UNKNOWNS: usize = 8192;

impl PeriodicOptions {
    /// [`Self::validate`], and that the largest harmonic-balance system these options can
    /// build for a model of `ndof` coordinates (`N`, or `N_max` with `N = "auto"`) stays
    /// within [`MAX_HB_UNKNOWNS`]: checked before anything is allocated.
    pub fn validate_for(&self, ndof: usize) -> crate::Result<()> {
        self.validate()?;
        let (name, n) = match &self.auto {
            Some(a) => ("N_max", a.n_max),
            None => ("N", self.hb.n_harm),
        };
        let most = (MAX_HB_UNKNOWNS - 1) / ndof.max(1);
        let n_most = most.saturating_sub(1) / 2;
        if ndof.saturating_mul(2 * n + 1) + 1 > MAX_HB_UNKNOWNS {
            return Err(crate::Error::param_range(
                name,
                format!(
                    "{n} harmonics of {ndof} coordinates make {} unknowns, at most \
                     {MAX_HB_UNKNOWNS} (memory: 8 n^2 bytes); at most {n_most} here",
                    ndof * (2 * n + 1) + 1
                ),
                format!("[1, {n_most}]"),
            ));
        }
        Ok(())
    }

    /// Checks every option before any work starts; errors name the option.
    pub fn validate(&self) -> crate::Result<()> {
        self.hb.validate()?;
        if let Some(f) = &self.floquet {
            f.validate()?;
        }
        self.guess.validate()?;
        if let Some(a) = &self.auto {
            a.validate(self.hb.n_harm)?;
        }
        check_range(
            "max_closure",
            self.max_closure,
            0.0,
            true,
            f64::INFINITY,
            true,
        )?;
        check_range("max_tail", self.max_tail, 0.0, true, f64::INFINITY, true)?;
        if let Some(b) = self.hill_band {
            check_range("hill_band", b, 0.0, false, f64::INFINITY, true)?;
        }
        Ok(())
    }
}

/// Points at which [`certify`] evaluates the defect: twice the collocation samples, so
/// that every gap between two collocation times is probed twice.
fn defect_points(sol: &HbSolution) -> usize {
    2 * sol.samples.max(crate::hb::default_samples(sol.n_harm))
}

/// Certifies a converged series: its status becomes `Equilibrium` if it does not move
/// ([`HbSolution::is_still`]), `Repeated` if it is a shorter orbit written several
/// times ([`is_repeated`]), `Truncated` if the highest harmonic exceeds `max_tail`,
/// `NotClosed` if the integrated defect exceeds `max_closure`.
/// Returns the integrated defect (`None` for a series that did not converge).
pub fn certify<D: Dynamics + ?Sized>(
    p: &D,
    sol: &mut HbSolution,
    opts: &PeriodicOptions,
) -> Option<f64> {
    if sol.status != Status::Converged {
        return None;
    }
    let closure = crate::hb::timed_certificate(|| defect_closure(p, sol, defect_points(sol)));
    if sol.is_still() {
        sol.status = Status::Equilibrium;
    } else if is_repeated(sol) {
        sol.status = Status::Repeated;
    } else if !(sol.tail_ratio_on(p.layout().support()) <= opts.max_tail) {
        sol.status = Status::Truncated;
    } else if !(closure <= opts.max_closure) {
        sol.status = Status::NotClosed;
    }
    Some(closure)
}

#[derive(Debug, Clone)]
pub struct Periodic {
    /// The series; its status says whether it converged *and* passed the certificates
    /// (`NotClosed`, `Truncated`, `Equilibrium` keep the series for inspection).
    pub sol: HbSolution,
    /// Integrated ODE defect of the series ([`defect_closure`]), for every series
    /// Newton converged on.
    pub closure: Option<f64>,
    pub floquet: Option<Floquet>,
    /// Why the Floquet analysis failed, if it did.
    pub floquet_error: Option<String>,
    /// With `auto`: whether the accuracy target was met within `n_max` harmonics.
    pub target_met: Option<bool>,
    /// Hill's-method multipliers and verdict, when asked for and computable.
    pub hill: Option<(Vec<(f64, f64)>, Stability)>,
    /// The series' tail relative to the support's motion ([`HbSolution::tail_ratio_on`]
    /// the model's layout).
    pub tail: f64,
    /// A bound on the error of `sol.omega`, from the series [`bound_verdict`] (on a
    /// branch or curve, [`bound_on_branch`]) compares with (twice the two frequencies'
    /// difference, as the modulus' bound); `None` without that comparison. Near the
    /// infinite-period end of a rotating branch the trivial multiplier's error says
    /// little about the frequency's, this does.
    pub omega_error: Option<f64>,
}

impl Periodic {
    /// Whether the two stability estimates contradict each other (one says stable, the
    /// other unstable); an undetermined verdict contradicts neither.
    pub fn verdicts_disagree(&self) -> Option<bool> {
        let f = self.floquet.as_ref()?.stability;
        let (_, h) = self.hill.as_ref()?;
        Some(matches!(
            (f, *h),
            (Stability::Stable, Stability::Unstable) | (Stability::Unstable, Stability::Stable)
        ))
    }
}

/// `Ok` for an autonomous model; otherwise the error naming the effect that makes it
/// time dependent (harmonic balance, Floquet theory and equilibria need autonomy).
pub fn require_autonomous<D: Dynamics + ?Sized>(model: &D) -> crate::Result<()> {
    match model.time_dependence() {
        None => Ok(()),
        Some(effect) => Err(crate::Error::NotAutonomous { effect }),
    }
}

/// Solves from `guess`, or from a simulated guess of the requested pattern, and runs
/// the Floquet analysis on a converged solution.
pub fn periodic<D: Dynamics + ?Sized>(
    p: &D,
    rotating: &[bool],
    guess: Option<&HbSolution>,
    opts: &PeriodicOptions,
) -> Periodic {
    periodic_wound(p, &plain_windings(rotating), guess, opts)
}

/// [`periodic`] with the balls' windings per period given ([`parse_windings`]). With a
/// winding of more than one turn and no guess, the simulated starts are observed over
/// as many turns of the first rotating ball; a start whose series turns out to repeat
/// within the period (an orbit of a shorter period, written several times) is kept only
/// if no start gives a genuine one, with status `Repeated` (as [`certify`] marks it).
pub fn periodic_wound<D: Dynamics + ?Sized>(
    p: &D,
    ball_winding: &[f64],
    guess: Option<&HbSolution>,
    opts: &PeriodicOptions,
) -> Periodic {
    let rotating: Vec<bool> = ball_winding.iter().map(|w| *w != 0.0).collect();
    let turns = ball_winding
        .iter()
        .find(|w| **w != 0.0)
        .map_or(1, |w| w.abs() as usize);
    if turns > 1 || ball_winding.iter().any(|w| w.abs() > 1.0) {
        let sol = match guess {
            Some(g) => solve(p, g, &opts.hb),
            None => wound_search(p, ball_winding, &rotating, turns, opts),
        };
        return finish(p, sol, opts);
    }
    let rotating = &rotating[..];
    let sol = match guess {
        Some(g) => solve(p, g, &opts.hb),
        None => {
            let mut best: Option<HbSolution> = None;
            for y0 in initial_states(p) {
                if let Some(g) =
                    guess_from_state(p, &y0, Some(rotating), opts.hb.n_harm, &opts.guess)
                {
                    let mut s = solve(p, &g, &opts.hb);
                    // Without N = "auto" the certificate is final here: a start whose
                    // series is no orbit should not stop the search.
                    if opts.auto.is_none() {
                        certify(p, &mut s, opts);
                    }
                    if s.status == Status::Converged {
                        best = Some(s);
                        break;
                    }
                    if best.is_none() {
                        best = Some(s);
                    }
                }
            }
            best.unwrap_or_else(|| no_guess(p, rotating, opts.hb.n_harm))
        }
    };
    finish(p, sol, opts)
}

/// [`periodic_wound`], and when the usual starts find no orbit, also from
/// [`whirl_starts`] (one ball) or [`pattern_whirl_starts`] (a pattern of rotating and
/// resting balls): the starts of `periodic()` (the Python facade) and of homotopy.
/// With a guess, or for other patterns, it is [`periodic_wound`] itself.
pub fn periodic_searched<D: Parametric>(
    p: &D,
    ball_winding: &[f64],
    guess: Option<&HbSolution>,
    opts: &PeriodicOptions,
) -> Periodic {
    let first = periodic_wound(p, ball_winding, guess, opts);
    if guess.is_some()
        || first.sol.status == Status::Converged
        || ball_winding.iter().any(|w| w.abs() > 1.0)
    {
        return first;
    }
    let rotating: Vec<bool> = ball_winding.iter().map(|w| *w != 0.0).collect();
    let whirling = pattern_whirl_starts(p, &rotating);
    for y0 in whirl_starts(p).into_iter().chain(whirling) {
        if crate::cancel::cancelled() {
            break;
        }
        let Some(g) = guess_from_state(p, &y0, Some(&rotating), opts.hb.n_harm, &opts.guess) else {
            continue;
        };
        let mut s = solve(p, &g, &opts.hb);
        if opts.auto.is_none() {
            certify(p, &mut s, opts);
        }
        if s.status == Status::Converged {
            return finish(p, s, opts);
        }
    }
    first
}

/// Starts for one ball whirling with the support at its natural frequency, which the
/// starts at rest in the ground frame ([`initial_states`]) miss: past a few tenths above
/// the resonance a single ball's rotating motion (its ground-frame rate locked just
/// below the natural frequency, the disk whirling with it at resonant amplitude) is
/// stable but reached from rest only from a sliver of ball angles (none of the 16 at
/// Tien's (2011) rig with `eta = 1.85`, `Omega` 1.5 to 1.7, or `eta = 0.99`, `Omega` 1.35).
/// Each start puts the ball at angle `beta` turning at ground rate `s` (1 and 0.95,
/// four angles) and the disk on the linear response to the ball and the imbalance,
/// `Z = mu eta s^2 e^(i beta) / (1 - s^2 + 2 i zeta s) + mu Omega^2 / (1 - Omega^2 + 2 i
/// zeta Omega)` (ground frame at `t = 0`). Empty for other ball counts and for models
/// without `mu`, `zeta` and `eta`.
pub fn whirl_starts<D: Parametric>(p: &D) -> Vec<Vec<f64>> {
    use nalgebra::Complex;
    let o = p.first_ball();
    let d = p.ndof();
    if d != o + 1 {
        return vec![];
    }
    let (Ok(mu), Ok(z), Ok(eta)) = (
        p.param_value("mu"),
        p.param_value("zeta"),
        p.param_value("eta"),
    ) else {
        return vec![];
    };
    let om = p.base_spin();
    let i = Complex::new(0.0, 1.0);
    let zi = mu * om * om / (1.0 - om * om + 2.0 * i * z * om);
    let mut out = vec![];
    for s in [1.0, 0.95] {
        for k in 0..4 {
            let beta = -PI + (k as f64 + 0.1) * PI / 2.0;
            let zb =
                mu * eta * s * s * Complex::from_polar(1.0, beta) / (1.0 - s * s + 2.0 * i * z * s);
            let zz = zi + zb;
            // rotating-frame velocity: the ground velocity less the frame's turn
            let dz = i * om * zi + i * s * zb - i * om * zz;
            let mut y = vec![0.0; 2 * d];
            y[0] = zz.re;
            y[1] = zz.im;
            y[o] = beta;
            y[d] = dz.re;
            y[d + 1] = dz.im;
            y[d + o] = s - om;
            out.push(y);
        }
    }
    out
}

/// Simulation starts for a pattern in which some balls rotate and others do not, built
/// as [`whirl_starts`] builds them for one ball: the stable R-O orbits of Tien's (2011)
/// maps have the rotating ball turning in the ground frame just below the natural
/// frequency (omega close to `Omega - 1`) with the disk whirling at resonant amplitude
/// (|Z| about 6 at `zeta 0.02`), and no start at rest reaches them (of 36 such starts at
/// four points of the map `mu 0.2, zeta 0.02, zeta_b 0.1, delta 50`, 3 to 12 settled on
/// the stable R-O, none at `s = 0.9`; every point was reached from `s = 1` with the
/// resting ball a quarter turn ahead). Each of the four starts puts the first rotating
/// ball at angle `beta` (four angles) turning at ground rate `s = 1` (the natural
/// frequency), the other rotating balls spread evenly behind it at the same rate, the
/// resting balls on the disk a quarter turn ahead of `beta`, and the disk on the linear
/// response to all of them and the imbalance: `mu eta_j s^2 e^(i beta_j) / (1 - s^2 + 2 i zeta s)` per
/// rotating ball, `mu eta_j Omega^2 e^(i gamma_j) / (1 - Omega^2 + 2 i zeta Omega)` per
/// resting one and `mu Omega^2 / (1 - Omega^2 + 2 i zeta Omega)` (ground frame at
/// `t = 0`). Empty unless the pattern mixes rotating and resting balls, without damping
/// (`zeta = 0`), and for models without `mu`, `zeta` and per-ball `eta` or with more
/// coordinates than the disk's two and the balls'.
pub fn pattern_whirl_starts<D: Parametric>(p: &D, rotating: &[bool]) -> Vec<Vec<f64>> {
    use nalgebra::Complex;
    let o = p.first_ball();
    let d = p.ndof();
    let n = rotating.len();
    if o != 2 || d != o + n || rotating.iter().all(|r| *r) || !rotating.iter().any(|r| *r) {
        return vec![];
    }
    let (Ok(mu), Ok(z)) = (p.param_value("mu"), p.param_value("zeta")) else {
        return vec![];
    };
    if z <= 0.0 {
        // Undamped, the resonant response has no finite amplitude to start from.
        return vec![];
    }
    let Ok(eta) = (0..n)
        .map(|j| p.param_value(&crate::model::params::ball_name("eta", j)))
        .collect::<crate::Result<Vec<f64>>>()
    else {
        return vec![];
    };
    let om = p.base_spin();
    let i = Complex::new(0.0, 1.0);
    let spin_gain = om * om / (1.0 - om * om + 2.0 * i * z * om);
    let n_rot = rotating.iter().filter(|r| **r).count();
    let s = 1.0;
    // The resting balls a quarter turn ahead: a quarter turn behind found no stable R-O
    // that ahead missed on the nine Tien (2011) maps, the issue's map and the census' point,
    // at twice the starts' cost.
    const AHEAD: f64 = PI / 2.0;
    let mut out = vec![];
    let whirl_gain = s * s / (1.0 - s * s + 2.0 * i * z * s);
    for k in 0..4 {
        let beta = -PI + (k as f64 + 0.1) * PI / 2.0;
        let mut y = vec![0.0; 2 * d];
        // The disk's response to what turns with it (imbalance, resting balls)
        // and to what whirls at `s` (rotating balls).
        let (mut with_disk, mut whirling) = (mu * spin_gain, Complex::new(0.0, 0.0));
        let mut kr = 0;
        for j in 0..n {
            let angle = if rotating[j] {
                kr += 1;
                let a = beta + 2.0 * PI * (kr - 1) as f64 / n_rot as f64;
                whirling += mu * eta[j] * whirl_gain * Complex::from_polar(1.0, a);
                y[d + o + j] = s - om;
                a
            } else {
                let a = beta + AHEAD;
                with_disk += mu * eta[j] * spin_gain * Complex::from_polar(1.0, a);
                a
            };
            y[o + j] = angle;
        }
        let zz = with_disk + whirling;
        // rotating-frame velocity: the ground velocity less the frame's turn
        let dz = i * om * with_disk + i * s * whirling - i * om * zz;
        y[0] = zz.re;
        y[1] = zz.im;
        y[d] = dz.re;
        y[d + 1] = dz.im;
        out.push(y);
    }
    out
}

/// The simulated search of [`periodic_wound`] for windings of more than one turn.
fn wound_search<D: Dynamics + ?Sized>(
    p: &D,
    ball_winding: &[f64],
    rotating: &[bool],
    turns: usize,
    opts: &PeriodicOptions,
) -> HbSolution {
    let o = p.first_ball();
    // Converged and genuine; converged on a repeated orbit; the first failure.
    let mut repeating: Option<HbSolution> = None;
    let mut failed: Option<HbSolution> = None;
    for y0 in initial_states(p) {
        let Some(g) = guess_with_turns(p, &y0, rotating, turns, opts.hb.n_harm, &opts.guess) else {
            continue;
        };
        if g.winding[o..] != *ball_winding {
            continue;
        }
        let mut s = solve(p, &g, &opts.hb);
        if opts.auto.is_none() {
            certify(p, &mut s, opts);
        }
        if s.status == Status::Converged && !repeats(&s, turns) {
            return s;
        }
        if matches!(s.status, Status::Converged | Status::Repeated) {
            s.status = Status::Repeated;
            repeating.get_or_insert(s);
        } else {
            failed.get_or_insert(s);
        }
    }
    repeating
        .or(failed)
        .unwrap_or_else(|| no_guess_wound(p, ball_winding, opts.hb.n_harm))
}

pub fn finish<D: Dynamics + ?Sized>(p: &D, sol: HbSolution, opts: &PeriodicOptions) -> Periodic {
    finish_certified(p, sol, opts, None)
}

/// [`finish`] at the series' own harmonics, for the points of a branch or curve (and a
/// switched branch's first point), whose continuation needs one truncation throughout.
/// The verdict is bounded as `periodic()`'s is, but against one finer series only
/// ([`bound_on_branch`]): the point keeps its harmonics, and a verdict the bound leaves
/// open stays undetermined.
pub fn finish_on_branch<D: Dynamics + ?Sized>(
    p: &D,
    sol: HbSolution,
    opts: &PeriodicOptions,
) -> Periodic {
    finish_inner(p, sol, opts, None, Bound::OwnHarmonics)
}

/// [`finish_on_branch`] without the verdict's bound: the multipliers of a trial point
/// that only a bifurcation's test function reads (its verdict is not reported). Their
/// verdicts are judged by the trivial multiplier's error alone and `modulus_error` is
/// `None`.
pub fn multipliers_on_branch<D: Dynamics + ?Sized>(
    p: &D,
    sol: HbSolution,
    opts: &PeriodicOptions,
) -> Periodic {
    finish_inner(p, sol, opts, None, Bound::Unbounded)
}

/// How [`finish_inner`] bounds the verdict's error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Bound {
    /// [`bound_verdict`]: refining the series where the bound leaves the verdict open.
    Refining,
    /// [`bound_on_branch`]: the series' own harmonics.
    OwnHarmonics,
    /// No bound (multipliers for test functions only).
    Unbounded,
}

/// [`finish`] of a series whose [`certify`] (with these options) already passed and
/// gave the closure `passed`: without `auto`, that certificate is not computed again.
pub fn finish_certified<D: Dynamics + ?Sized>(
    p: &D,
    sol: HbSolution,
    opts: &PeriodicOptions,
    passed: Option<f64>,
) -> Periodic {
    finish_inner(p, sol, opts, passed, Bound::Refining)
}

fn finish_inner<D: Dynamics + ?Sized>(
    p: &D,
    sol: HbSolution,
    opts: &PeriodicOptions,
    passed: Option<f64>,
    bound: Bound,
) -> Periodic {
    let mut sol = sol;
    let mut target_met = None;
    let run_floquet = |sol: &HbSolution| match (&opts.floquet, sol.status == Status::Converged) {
        (Some(fo), true) => match floquet(p, sol, fo) {
            Ok(f) => (Some(f), None),
            Err(e) => (None, Some(e.to_string())),
        },
        _ => (None, None),
    };
    let (mut fl, mut fl_err);
    let mut closure;
    let mut omega_error = None;
    match (&opts.auto, sol.status == Status::Converged) {
        (Some(a), true) => {
            // The floor below which RK45's own error hides the trivial multiplier's.
            let floor = opts.floquet.as_ref().map_or(0.0, |f| 100.0 * f.rtol);
            loop {
                sol = refine(p, sol, &opts.hb, a);
                (fl, fl_err) = run_floquet(&sol);
                let tail_ok = sol.tail_ratio_on(p.layout().support()) <= a.target;
                let triv_ok = fl
                    .as_ref()
                    .is_none_or(|f| f.trivial_error <= a.target.max(floor));
                if (tail_ok && triv_ok) || sol.n_harm >= a.n_max {
                    target_met = Some(tail_ok && triv_ok);
                    break;
                }
                match more_harmonics(p, &sol, &opts.hb, a) {
                    Some(s) => sol = s,
                    None => {
                        target_met = Some(false);
                        break;
                    }
                }
            }
            closure = certify(p, &mut sol, opts);
            if sol.status != Status::Converged {
                // Multipliers of a series that is no orbit say nothing.
                (fl, fl_err) = (None, None);
                target_met = Some(false);
            }
        }
        _ => {
            // Certificate first: a series that fails it gets no Floquet analysis.
            closure = match sol.status {
                Status::Converged if passed.is_some() => passed,
                Status::Converged => certify(p, &mut sol, opts),
                // Already certified (and refused) by `periodic`'s search: keep its measure.
                Status::NotClosed | Status::Truncated | Status::Equilibrium | Status::Repeated => {
                    Some(defect_closure(p, &sol, defect_points(&sol)))
                }
                _ => None,
            };
            (fl, fl_err) = run_floquet(&sol);
        }
    }
    match (bound, &opts.floquet) {
        (Bound::Refining, Some(fo)) => {
            if let Some(f) = fl.take() {
                let b = bound_verdict(p, sol, f, closure, fo, opts);
                (sol, fl, closure, omega_error) =
                    (b.sol, Some(b.floquet), b.closure, b.omega_error);
                if let Some(why) = b.unbounded {
                    fl_err.get_or_insert(why);
                }
            }
        }
        (Bound::OwnHarmonics, Some(fo)) => {
            if let Some(f) = fl.as_mut() {
                match bound_on_branch(p, &sol, f, fo, &opts.hb) {
                    Ok(bound) => omega_error = bound,
                    Err(why) => {
                        fl_err.get_or_insert(why);
                    }
                }
            }
        }
        _ => {}
    }
    let hill = if opts.hill
        && sol.status == Status::Converged
        && hill_wanted(opts.floquet.is_some(), fl.as_ref(), opts.hill_band)
    {
        let defaults = FloquetOptions::default();
        let (margin, max_trivial) = match (&opts.floquet, opts.hill_judging) {
            (Some(f), _) => (f.margin, f.max_trivial),
            (None, Some(j)) => j,
            (None, None) => (defaults.margin, defaults.max_trivial),
        };
        // The truncation's error estimate widens the margin as the trivial multiplier's
        // error does: a truncation that cannot resolve the exponents gives no verdict.
        match opts.hill_target {
            HillTarget::Multipliers => hill(p, &sol, HILL_TOL, HILL_MAX).ok().map(|h| {
                let v = judge(&h.multipliers, margin.max(h.error), max_trivial);
                (h.multipliers, v.stability)
            }),
            HillTarget::Verdict => hill_verdict(p, &sol, margin, max_trivial, HILL_MAX)
                .ok()
                .map(|(h, v)| (h.multipliers, v.stability)),
        }
    } else {
        None
    };
    let tail = sol.tail_ratio_on(p.layout().support());
    Periodic {
        sol,
        closure,
        floquet: fl,
        floquet_error: fl_err,
        target_met,
        hill,
        tail,
        omega_error,
    }
}

/// Most harmonics [`bound_verdict`] raises a series to before its verdict is left
/// undetermined. At Tien's (2011) hardest verdict (`mu 0.25, zeta 0.08, zeta_b 0.02,
/// delta 20, Omega 1.3584277344`, leading modulus 1.0000036) the modulus is off by 2.4e-5
/// at N = 3, 3.3e-6 at 4, 4e-8 at 5 and 5e-10 at 6: a verdict that N = 27 cannot settle
/// sits within round-off of 1.
pub const BOUND_N_MAX: usize = 27;

/// The harmonics of the series a verdict at `n` harmonics is checked against: half as
/// many again, at least two more (the modulus' error then falls by one to three orders
/// of magnitude on Tien (2011) orbits).
pub fn finer_harmonics(n: usize) -> usize {
    n + n.div_ceil(2).max(2)
}

/// [`bound_verdict`]'s result.
pub struct Bounded {
    pub sol: HbSolution,
    pub floquet: Floquet,
    pub closure: Option<f64>,
    /// Twice `sol.omega`'s difference from the finer series' (as [`Periodic::omega_error`]).
    pub omega_error: Option<f64>,
    /// Why no bound could be computed (the verdict is then undetermined).
    pub unbounded: Option<String>,
}

/// A stability verdict with a bound on the error of the leading non-trivial modulus.
///
/// The trivial multiplier's error measures the integration and the series' closure, not
/// the leading multiplier's: at N = 3 the latter's real error exceeded it in 109 of 456
/// scan rows, up to 195 times, and verdicts within ~2e-3 of 1 came out wrong. So the
/// series is solved again with [`finer_harmonics`] (from itself) and its multipliers
/// computed with the same options. `|rho_N - rho_N'|` measures the truncation error of
/// `rho_N` (spectral convergence leaves `rho_N'` far closer to the truth); the bound is
/// twice that, plus the finer computation's own error measures (its trivial multiplier's
/// error and the Magnus estimate), so that it holds while the error at `N'` is at most
/// half the one at `N`. The verdict is then [`bounded_verdict`]'s.
///
/// Where that (or a trivial multiplier off by more than `max_trivial`) leaves the verdict
/// undetermined, the finer series (certified like any result) becomes the result and is checked against a finer one again, up to
/// [`BOUND_N_MAX`] harmonics (unless [`PeriodicOptions::refine_verdicts`] is off). Where no
/// finer series converges, or its multipliers cannot be computed, there is no bound and the
/// verdict is undetermined.
pub fn bound_verdict<D: Dynamics + ?Sized>(
    p: &D,
    sol: HbSolution,
    fl: Floquet,
    closure: Option<f64>,
    fo: &FloquetOptions,
    opts: &PeriodicOptions,
) -> Bounded {
    let (mut sol, mut fl, mut closure) = (sol, fl, closure);
    let mut omega_error = None;
    let unbounded = loop {
        let m = finer_harmonics(sol.n_harm);
        let (fine, ff, w_err) = match judge_against_finer(p, &sol, &mut fl, m, fo, &opts.hb) {
            Ok(judged) => judged,
            Err(why) => break Some(why),
        };
        omega_error = Some(w_err);
        // Whatever left the verdict open (the bound, or a trivial multiplier off by more
        // than `max_trivial`: both shrink with the truncation error), more harmonics may
        // settle it; a modulus at 1 to round-off stops at `BOUND_N_MAX`.
        if fl.stability != Stability::Undetermined || m > BOUND_N_MAX || !opts.refine_verdicts {
            break None;
        }
        let mut fine = fine;
        let fine_closure = certify(p, &mut fine, opts);
        if fine.status != Status::Converged {
            break None;
        }
        (sol, fl, closure) = (fine, ff, fine_closure);
    };
    Bounded {
        sol,
        floquet: fl,
        closure,
        omega_error,
        unbounded,
    }
}

/// [`bound_verdict`]'s one step: `fl` (the multipliers of `sol`) judged against the
/// series with `m` harmonics solved from `sol` with `hb`'s settings, which is returned
/// with its multipliers and the bound on `sol.omega`'s error it gives (twice the two
/// frequencies' difference, [`Periodic::omega_error`]). The bound is twice the leading non-trivial modulus' difference
/// to that series' plus the latter's own error measures (its trivial multiplier's error
/// and Magnus' estimate), and the verdict [`bounded_verdict`]'s. Without the finer series
/// the verdict is undetermined, and the error says why.
fn judge_against_finer<D: Dynamics + ?Sized>(
    p: &D,
    sol: &HbSolution,
    fl: &mut Floquet,
    m: usize,
    fo: &FloquetOptions,
    hb: &HbOptions,
) -> std::result::Result<(HbSolution, Floquet, f64), String> {
    let (fine, ff) = finer_floquet(p, sol, m, fo, hb).map_err(|why| {
        fl.stability = Stability::Undetermined;
        format!("no error bound: {why}")
    })?;
    let own = ff.trivial_error.max(ff.method_error.unwrap_or(0.0));
    let err = 2.0 * (fl.max_modulus - ff.max_modulus).abs() + own;
    fl.modulus_error = Some(err);
    fl.modulus_error_against = Some(m);
    fl.stability = bounded_verdict(
        &fl.multipliers,
        fo,
        fl.method_error,
        fl.separation_error,
        err,
    );
    let omega_error = 2.0 * (sol.omega - fine.omega).abs();
    Ok((fine, ff, omega_error))
}

/// The verdict of a branch or curve point (`fl`, the multipliers of `sol`), bounded as
/// [`bound_verdict`] bounds `periodic()`'s, against the series with
/// [`finer_harmonics`], but without refining: the point keeps its harmonics (the
/// continuation needs one truncation throughout), the finer series only measures the
/// error, and a verdict the bound leaves open is undetermined. `hb` are the branch's
/// harmonic-balance settings; the finer series gets at least its own default samples
/// (a branch fixes the samples for its own harmonics), as `periodic()`'s finer series
/// has by default.
///
/// A verdict the trivial multiplier's error (or the separation check, or the margin)
/// already leaves undetermined gets no finer series: the bound only widens the margin,
/// so it could not settle it, and skipping it saves the finer solve and its multipliers
/// (`modulus_error` is then `None`). Returns the point's [`Periodic::omega_error`] from
/// the finer series, as `periodic()`'s (`None` without it); `Err` says why there is no
/// bound where the finer series fails (the verdict is then undetermined).
pub fn bound_on_branch<D: Dynamics + ?Sized>(
    p: &D,
    sol: &HbSolution,
    fl: &mut Floquet,
    fo: &FloquetOptions,
    hb: &HbOptions,
) -> std::result::Result<Option<f64>, String> {
    if fl.stability == Stability::Undetermined {
        return Ok(None);
    }
    let m = finer_harmonics(sol.n_harm);
    let hb = HbOptions {
        samples: hb.samples.map(|s| s.max(default_samples(m))),
        ..hb.clone()
    };
    judge_against_finer(p, sol, fl, m, fo, &hb).map(|(_, _, omega_error)| Some(omega_error))
}

/// [`bound_verdict`]'s finer series with `m` harmonics, solved from `sol` with `hb`'s
/// settings, and its multipliers; why not, if it exceeds the size bound, fails to
/// converge (or converges to another winding) or its multipliers cannot be computed.
fn finer_floquet<D: Dynamics + ?Sized>(
    p: &D,
    sol: &HbSolution,
    m: usize,
    fo: &FloquetOptions,
    hb: &HbOptions,
) -> std::result::Result<(HbSolution, Floquet), String> {
    if p.ndof() * (2 * m + 1) + 1 > MAX_HB_UNKNOWNS {
        return Err(format!(
            "a series with {m} harmonics exceeds the size bound"
        ));
    }
    let hb = HbOptions {
        n_harm: m,
        ..hb.clone()
    };
    let fine = solve(p, sol, &hb);
    if fine.status != Status::Converged || fine.winding != sol.winding {
        return Err(format!(
            "the series with {m} harmonics failed (status {})",
            fine.status.as_str()
        ));
    }
    let ff =
        floquet(p, &fine, fo).map_err(|e| format!("the series with {m} harmonics failed ({e})"))?;
    Ok((fine, ff))
}

/// Whether Hill's cross-check is wanted beside the monodromy result `fl` (`None` if the
/// monodromy failed) with [`PeriodicOptions::hill_band`] `band`, when a monodromy was
/// asked for (`monodromy`). Always without a band. With one, Hill cross-checks the
/// monodromy: never without it (no monodromy asked for), and otherwise where it failed,
/// its verdict is undetermined, or its leading non-trivial modulus is within `band` of 1
/// or within [`HILL_VERDICT_ROOM`] times the largest of the monodromy's error measures:
/// the trivial multiplier's error, Magnus' estimate and merged balls' separation error
/// (the room Hill's own verdict demands of its estimate; a NaN one is doubt). Beyond
/// that, an error large enough to move the modulus across 1 would be many times what the
/// monodromy's certificates measured.
pub fn hill_wanted(monodromy: bool, fl: Option<&Floquet>, band: Option<f64>) -> bool {
    let Some(band) = band else {
        return true;
    };
    let Some(f) = fl else {
        return monodromy;
    };
    // f64::max would drop a NaN estimate: a NaN anywhere is doubt.
    let errs = [
        f.trivial_error,
        f.method_error.unwrap_or(0.0),
        f.separation_error.unwrap_or(0.0),
    ];
    if errs.iter().any(|e| e.is_nan()) {
        return true;
    }
    let err = errs.into_iter().fold(0.0, f64::max);
    f.stability == Stability::Undetermined
        || !((f.max_modulus - 1.0).abs() > band.max(HILL_VERDICT_ROOM * err))
}

/// The solution re-solved with half as many harmonics again (at most `n_max`), started
/// from itself; `None` if that solve does not converge.
fn more_harmonics<D: Dynamics + ?Sized>(
    p: &D,
    sol: &HbSolution,
    hb: &HbOptions,
    a: &AutoHarmonics,
) -> Option<HbSolution> {
    let n = sol.n_harm;
    let next = (n + n.div_ceil(2)).clamp(n + 1, a.n_max.max(n + 1));
    let s = solve(
        p,
        sol,
        &HbOptions {
            n_harm: next,
            ..hb.clone()
        },
    );
    (s.status == Status::Converged).then_some(s)
}

/// Raises the harmonics of a converged solution until its highest one is below the
/// target relative to the motion (or `n_max` is reached, or a larger N fails to
/// converge), each solve started from the last.
pub fn refine<D: Dynamics + ?Sized>(
    p: &D,
    sol: HbSolution,
    hb: &HbOptions,
    a: &AutoHarmonics,
) -> HbSolution {
    let mut sol = sol;
    while sol.status == Status::Converged
        && sol.tail_ratio_on(p.layout().support()) > a.target
        && sol.n_harm < a.n_max
    {
        match more_harmonics(p, &sol, hb, a) {
            Some(s) => sol = s,
            // Keep the last converged solution; the caller sees the target unmet.
            None => return sol,
        }
    }
    sol
}

/// Placeholder result for "no starting guess": no coefficients worth reading.
pub fn no_guess<D: Dynamics + ?Sized>(p: &D, rotating: &[bool], n_harm: usize) -> HbSolution {
    let d = p.ndof();
    let mut winding = vec![0.0; d];
    for (i, &r) in rotating.iter().enumerate() {
        winding[p.first_ball() + i] = if r { -1.0 } else { 0.0 };
    }
    HbSolution::start(
        f64::NAN,
        vec![f64::NAN; d * (2 * n_harm + 1)],
        winding,
        n_harm,
        Status::NoGuess,
    )
}

/// [`no_guess`] with the balls' windings given.
pub fn no_guess_wound<D: Dynamics + ?Sized>(
    p: &D,
    ball_winding: &[f64],
    n_harm: usize,
) -> HbSolution {
    let d = p.ndof();
    let mut winding = vec![0.0; d];
    winding[p.first_ball()..].copy_from_slice(ball_winding);
    HbSolution::start(
        f64::NAN,
        vec![f64::NAN; d * (2 * n_harm + 1)],
        winding,
        n_harm,
        Status::NoGuess,
    )
}

/// Tien's (2011) "NI" check: simulate from the solution's state for one period and return
/// the max-norm distance to where the orbit says it should be (angles advanced by whole
/// turns).
pub fn closure_error<D: Dynamics + ?Sized>(
    model: &D,
    sol: &HbSolution,
    rtol: f64,
    atol: f64,
) -> crate::Result<f64> {
    let y0 = sol.state(0.0);
    let t = sol.period();
    let (ys, _) = solve_at(
        |tt: f64, y: &[f64], dy: &mut [f64]| first_order_rhs(model, tt, y, dy),
        0.0,
        &y0,
        &[t],
        &Options::new(rtol, atol),
    )?;
    let d = model.ndof();
    let mut err = 0.0f64;
    for j in 0..2 * d {
        let target = if j < d {
            y0[j] + 2.0 * PI * sol.winding[j]
        } else {
            y0[j]
        };
        err = err.max((ys[0][j] - target).abs());
    }
    Ok(err)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Planar;

    fn judged(lead: f64, trivial_error: f64, method_error: Option<f64>) -> Floquet {
        let j = judge(
            &[(1.0 + trivial_error, 0.0), (lead, 0.0)],
            1e-6,
            crate::floquet::MAX_TRIVIAL,
        );
        Floquet {
            multipliers: vec![(1.0 + trivial_error, 0.0), (lead, 0.0)],
            trivial: j.trivial,
            trivial_error: j.trivial_error,
            separation_error: None,
            max_modulus: j.max_modulus,
            stability: j.stability,
            steps: 0,
            rhs_evals: 0,
            method_error,
            modulus_error: None,
            modulus_error_against: None,
        }
    }

    #[test]
    fn hill_band_selects_the_doubtful_verdicts() {
        let band = Some(0.2);
        // no band: always; no monodromy asked for: never; one that failed: always
        assert!(hill_wanted(true, Some(&judged(0.1, 1e-7, None)), None));
        assert!(!hill_wanted(false, None, band));
        assert!(hill_wanted(true, None, band));
        // clear verdicts beyond the band, on either side of 1
        assert!(!hill_wanted(true, Some(&judged(0.79, 1e-7, None)), band));
        assert!(!hill_wanted(true, Some(&judged(1.21, 1e-7, None)), band));
        assert!(hill_wanted(true, Some(&judged(0.81, 1e-7, None)), band));
        assert!(hill_wanted(true, Some(&judged(1.19, 1e-7, None)), band));
        // ten times the trivial multiplier's error, or Magnus' estimate, widens it
        assert!(hill_wanted(true, Some(&judged(0.5, 0.06, None)), band));
        assert!(!hill_wanted(true, Some(&judged(0.5, 0.04, None)), band));
        assert!(hill_wanted(
            true,
            Some(&judged(0.5, 1e-7, Some(0.06))),
            band
        ));
        // an undetermined verdict far from 1 with small errors (the undetermined rule
        // alone asks for Hill)
        let mut f = judged(0.5, 1e-7, None);
        assert!(!hill_wanted(true, Some(&f), Some(0.0)));
        f.stability = Stability::Undetermined;
        assert!(hill_wanted(true, Some(&f), Some(0.0)));
        // merged balls' separation error widens it too
        let mut f = judged(0.5, 1e-7, None);
        f.separation_error = Some(0.06);
        assert!(hill_wanted(true, Some(&f), band));
        // a non-finite modulus or error estimate is doubtful
        let mut f = judged(0.5, 1e-7, None);
        f.max_modulus = f64::NAN;
        assert!(hill_wanted(true, Some(&f), band));
        assert!(hill_wanted(
            true,
            Some(&judged(0.5, 1e-7, Some(f64::NAN))),
            band
        ));
    }

    /// The band at work on the standard case: Hill runs exactly when the monodromy's
    /// leading modulus lies within the band, and then gives the same verdict.
    #[test]
    fn hill_band_on_the_standard_case() {
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let run = |band: Option<f64>| {
            let opts = PeriodicOptions {
                floquet: Some(FloquetOptions::default()),
                hill: true,
                hill_band: band,
                ..Default::default()
            };
            periodic(&p, &[true, true], None, &opts)
        };
        let all = run(None);
        let f = all.floquet.as_ref().unwrap();
        let dist = (f.max_modulus - 1.0).abs();
        assert!(f.stability != Stability::Undetermined && f.trivial_error < 1e-4);
        let (_, verdict) = all.hill.clone().unwrap();
        assert_eq!(verdict, f.stability);
        let inside = run(Some(dist * 1.01));
        assert_eq!(inside.hill.map(|h| h.1), Some(verdict));
        let outside = run(Some(dist * 0.99));
        assert!(outside.hill.is_none());
        assert_eq!(outside.floquet.unwrap().max_modulus, f.max_modulus);
    }

    #[test]
    fn solution_types_carry_windings_in_brackets() {
        assert_eq!(parse_solution_type("R-O", 2).unwrap(), vec![-1.0, 0.0]);
        assert_eq!(
            parse_solution_type("R-R[-2,-2]", 2).unwrap(),
            vec![-2.0, -2.0]
        );
        assert_eq!(
            parse_solution_type("O-R[0, -2]", 2).unwrap(),
            vec![0.0, -2.0]
        );
        for (bad, name) in [
            ("R-R[-1,-1]", "pattern"),
            ("R-R[-2,-2", "pattern"),
            ("R-R[x,-2]", "pattern"),
            ("R-R[-2]", "windings"),
            ("R-O[-2,-2]", "windings"),
            ("RR[-2,-2]", "pattern"),
        ] {
            let e = parse_solution_type(bad, 2).unwrap_err();
            assert!(
                matches!(&e, crate::Error::InvalidParameter { name: n, .. } if n == name),
                "{bad:?}: {e}"
            );
        }
        assert_eq!(repetitions(&[0.0, 0.0, -2.0, -2.0]), 2);
        assert_eq!(repetitions(&[0.0, 0.0, -2.0, -1.0]), 1);
        assert_eq!(repetitions(&[0.0, 0.0, 0.0, -3.0]), 3);
        assert_eq!(repetitions(&[0.0, 0.0, 0.0, 0.0]), 1);
    }

    #[test]
    fn parse_pattern_takes_only_the_canonical_form() {
        assert_eq!(parse_pattern("R-O", 2).unwrap(), vec![true, false]);
        assert_eq!(parse_pattern("O", 1).unwrap(), vec![false]);
        assert_eq!(parse_pattern("R-R-O", 3).unwrap(), vec![true, true, false]);
        for bad in ["RR", "r-r", " R-R ", "R_R", "R--R", "R-R-", "R- R"] {
            let e = parse_pattern(bad, 2).unwrap_err().to_string();
            assert!(e.contains("\"R-R\""), "{bad:?}: {e}");
        }
        for bad in ["R-X", "R", "R-R-R", "", "Ř-R"] {
            let e = parse_pattern(bad, 2).unwrap_err();
            assert!(
                matches!(&e, crate::Error::InvalidParameter { name, .. } if name == "pattern"),
                "{bad:?}: {e}"
            );
        }
    }

    fn standard(om: f64, eta: f64) -> Planar {
        Planar::new(0.2, 0.05, &[0.05], 50.0, om, &[eta, eta]).unwrap()
    }

    /// A series that does not move solves the harmonic-balance equations at every
    /// `omega`: at the perfect balance of two equal balls (closed form: rotor on the
    /// axis, balls at `+-arccos(-1 / (2 eta))`) the residual is at round-off for any
    /// frequency, so Newton "converging" there (as O-O scans of the zeta 0.02 maps did,
    /// with pivot ratios of 1e8 to 3e10) has found no orbit. The certificate says
    /// `Equilibrium`; the same series with a harmonic of 1e-3 is an orbit candidate the
    /// other certificates judge.
    #[test]
    fn a_series_at_an_equilibrium_is_refused_as_no_orbit() {
        use crate::hb::HbSystem;
        let p = Planar::new(0.2, 0.02, &[0.1], 50.0, 1.3, &[0.7, 0.7]).unwrap();
        let b = (-1.0f64 / (2.0 * 0.7)).acos();
        let n_harm = 3;
        let l = 2 * n_harm + 1;
        let mut coeffs = vec![0.0; 4 * l];
        coeffs[2 * l] = b;
        coeffs[3 * l] = -b;
        let opts = PeriodicOptions::default();
        for omega in [0.37, 0.9, 2.4] {
            let mut s = HbSolution::start(
                omega,
                coeffs.clone(),
                vec![0.0; 4],
                n_harm,
                Status::Converged,
            );
            let mut sys = HbSystem::new(&p, &s.winding, n_harm, crate::hb::default_samples(n_harm));
            let mut x = s.coeffs.clone();
            x.push(omega);
            let mut r = vec![0.0; x.len()];
            sys.assemble(&x, &mut r, None);
            let worst = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(worst < 1e-14, "omega {omega}: residual {worst}");
            assert!(certify(&p, &mut s, &opts).is_some());
            assert_eq!(s.status, Status::Equilibrium, "omega {omega}");
        }
        coeffs[2 * l + 1] = 1e-3;
        let mut s = HbSolution::start(0.9, coeffs, vec![0.0; 4], n_harm, Status::Converged);
        assert!(!s.is_still());
        certify(&p, &mut s, &opts);
        assert_ne!(s.status, Status::Equilibrium);
        // A rotating ball's constant series is a uniform rotation, an orbit whose omega
        // matters: never an equilibrium.
        let mut rr = HbSolution::start(
            0.9,
            vec![0.0; 4 * l],
            vec![0.0, 0.0, -1.0, -1.0],
            n_harm,
            Status::Converged,
        );
        assert!(!rr.is_still());
        certify(&p, &mut rr, &opts);
        assert_ne!(rr.status, Status::Equilibrium);
    }

    /// Tien's (2011) heaviest single ball (eta 1.85) at Omega 1.6: its rotating motion is
    /// stable, but no start at rest in the ground frame reaches it; a start whirling
    /// with the support does. Two balls get no such starts.
    #[test]
    fn one_ball_rotating_motion_from_whirl_starts() {
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.6, &[1.85]).unwrap();
        let opts = PeriodicOptions {
            floquet: Some(FloquetOptions::default()),
            ..PeriodicOptions::default()
        };
        let plain = periodic_wound(&p, &[-1.0], None, &opts);
        assert_eq!(plain.sol.status, Status::NoGuess);
        let r = periodic_searched(&p, &[-1.0], None, &opts);
        assert_eq!(r.sol.status, Status::Converged);
        assert_eq!(
            r.floquet.as_ref().map(|f| f.stability),
            Some(Stability::Stable)
        );
        // the ball's ground-frame rate Omega - omega sits just below the natural frequency
        let ground = 1.6 - r.sol.omega;
        assert!(ground > 0.9 && ground < 1.0, "{ground}");
        assert_eq!(whirl_starts(&p).len(), 8);
        assert!(whirl_starts(&standard(1.6, 1.0)).is_empty());
    }

    /// The issue's reproduction: R-R continued at N = 8 from Omega 1 into the branch's
    /// infinite-period end. Before the certificates every step said `Converged`, and
    /// Omega 0.92 was `Stable` with a trivial error of 0.11. Now every converged step
    /// closes under simulation (the core's RK45 from the series' state, a computation
    /// separate from the series), and no verdict comes with a large trivial error.
    #[test]
    fn continuation_into_the_branch_end_is_certified() {
        let b = |om: f64| Planar::new(0.2, 0.05, &[0.1], 50.0, om, &[1.0, 1.0]).unwrap();
        let opts = PeriodicOptions {
            hb: HbOptions {
                n_harm: 8,
                ..Default::default()
            },
            floquet: Some(FloquetOptions::default()),
            ..Default::default()
        };
        let mut prev = periodic(&b(1.0), &[true, true], None, &opts);
        assert_eq!(prev.sol.status, Status::Converged);
        let (mut closed, mut refused) = (0, 0);
        for k in 1..=19 {
            let w = 1.0 - 0.02 * k as f64;
            let p = b(w);
            let r = periodic(&p, &[true, true], Some(&prev.sol), &opts);
            if r.sol.status == Status::Converged {
                let sim = closure_error(&p, &r.sol, 1e-10, 1e-12).unwrap();
                assert!(sim < 0.05, "Omega {w}: converged but closure {sim}");
                closed += 1;
            } else if matches!(r.sol.status, Status::NotClosed | Status::Truncated) {
                assert!(r.floquet.is_none() && r.closure.is_some());
                refused += 1;
            }
            if let Some(f) = &r.floquet {
                if f.stability != Stability::Undetermined {
                    assert!(f.trivial_error <= MAX_TRIVIAL_FOR_TEST, "Omega {w}: {f:?}");
                }
            }
            prev = r;
        }
        assert!(
            closed >= 2 && refused >= 10,
            "closed {closed} refused {refused}"
        );
    }

    const MAX_TRIVIAL_FOR_TEST: f64 = crate::floquet::MAX_TRIVIAL;

    #[test]
    fn merged_balls_separation_product_is_exp_minus_two_zeta_b_t() {
        // Equal balls on the standard case's R-R orbit move as one (merged); the product
        // of the two separation multipliers is exp(-2 zeta_b T) by Liouville's formula.
        let zeta_b = 0.05;
        let p = Planar::new(0.2, 0.05, &[zeta_b], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let opts = PeriodicOptions {
            hb: HbOptions {
                n_harm: 8,
                ..Default::default()
            },
            floquet: Some(FloquetOptions::default()),
            ..Default::default()
        };
        let r = periodic(&p, &[true, true], None, &opts);
        let f = r.floquet.unwrap();
        assert!(crate::floquet::merged_pair(&r.sol, 2).is_some());
        let sep = f.separation_error.expect("merged balls get the check");
        assert!(sep < 1e-6, "separation error {sep}");
        // Independently of how the core identifies the pair: some pair of the computed
        // multipliers has that product.
        let exact = (-2.0 * zeta_b * r.sol.period()).exp();
        let m = &f.multipliers;
        let best = (0..m.len())
            .flat_map(|i| (i + 1..m.len()).map(move |j| (i, j)))
            .map(|(i, j)| {
                let (re, im) = (
                    m[i].0 * m[j].0 - m[i].1 * m[j].1,
                    m[i].0 * m[j].1 + m[i].1 * m[j].0,
                );
                (re - exact).hypot(im)
            })
            .fold(f64::INFINITY, f64::min);
        assert!(best < 1e-6, "no pair with product {exact}: {m:?}");
        // Unequal balls are not merged: no check.
        let q = Planar::new(0.2, 0.05, &[zeta_b], 50.0, 1.2, &[1.0, 0.9]).unwrap();
        let r = periodic(&q, &[true, true], None, &opts);
        assert_eq!(r.sol.status, Status::Converged);
        assert!(r.floquet.unwrap().separation_error.is_none());
    }

    /// The system's size, `ndof (2 N + 1) + 1` unknowns, is bounded before anything is
    /// allocated: ten balls (12 coordinates) keep N = 256 (6157 unknowns); 64 balls (66
    /// coordinates) allow N = 61 (8119) and not 62 (8251); with N = "auto" its N_max is
    /// the one checked.
    #[test]
    fn harmonic_balance_systems_are_bounded_by_their_unknowns() {
        let at = |n: usize| PeriodicOptions {
            hb: HbOptions {
                n_harm: n,
                ..Default::default()
            },
            ..Default::default()
        };
        let refused = |o: &PeriodicOptions, ndof: usize| match o.validate_for(ndof) {
            Err(crate::Error::InvalidParameter { name, allowed, .. }) => Some((name, allowed)),
            Ok(()) => None,
            Err(e) => panic!("{e}"),
        };
        assert_eq!(refused(&at(256), 12), None);
        assert_eq!(refused(&at(61), 66), None);
        let (name, allowed) = refused(&at(62), 66).unwrap();
        assert_eq!((name.as_str(), allowed.as_deref()), ("N", Some("[1, 61]")));
        let auto = PeriodicOptions {
            auto: Some(AutoHarmonics {
                target: 1e-4,
                n_max: 256,
            }),
            ..at(3)
        };
        assert_eq!(refused(&auto, 66).unwrap().0, "N_max");
        assert_eq!(refused(&auto, 12), None);
    }

    #[test]
    fn options_outside_their_ranges_are_refused_by_name() {
        let name = |o: PeriodicOptions| match o.validate() {
            Err(crate::Error::InvalidParameter { name, .. }) => name,
            other => panic!("{other:?}"),
        };
        let fo = |f: FloquetOptions| PeriodicOptions {
            floquet: Some(f),
            ..Default::default()
        };
        let d = FloquetOptions::default;
        assert!(fo(d()).validate().is_ok());
        assert_eq!(name(fo(FloquetOptions { rtol: 1e300, ..d() })), "rtol");
        assert_eq!(name(fo(FloquetOptions { rtol: 1.0, ..d() })), "rtol");
        assert_eq!(name(fo(FloquetOptions { rtol: 0.0, ..d() })), "rtol");
        assert_eq!(name(fo(FloquetOptions { atol: -1.0, ..d() })), "atol");
        assert_eq!(
            name(fo(FloquetOptions {
                margin: f64::NAN,
                ..d()
            })),
            "margin"
        );
        assert_eq!(
            name(fo(FloquetOptions {
                margin: -1e-3,
                ..d()
            })),
            "margin"
        );
        let g = |settle: f64, window: f64| PeriodicOptions {
            guess: GuessOptions {
                settle,
                window,
                ..Default::default()
            },
            ..Default::default()
        };
        assert_eq!(name(g(1e300, 10.0)), "settle");
        assert_eq!(name(g(10.0, f64::INFINITY)), "window");
        let mut o = PeriodicOptions::default();
        o.hb.tol = f64::NAN;
        assert_eq!(name(o), "tol");
        let mut o = PeriodicOptions::default();
        o.hb.step_tol = -1.0;
        assert_eq!(name(o), "step_tol");
        let o = PeriodicOptions {
            auto: Some(AutoHarmonics {
                target: 2.0,
                n_max: 32,
            }),
            ..Default::default()
        };
        assert_eq!(name(o), "target");
        let o = PeriodicOptions {
            max_closure: f64::NAN,
            ..Default::default()
        };
        assert_eq!(name(o), "max_closure");
    }

    #[test]
    fn rr_standard_case() {
        let p = standard(1.2, 1.0);
        let opts = PeriodicOptions {
            hb: HbOptions {
                n_harm: 8,
                ..Default::default()
            },
            floquet: Some(FloquetOptions::default()),
            ..Default::default()
        };
        let r = periodic(&p, &[true, true], None, &opts);
        assert_eq!(r.sol.status, Status::Converged, "{:?}", r.sol);
        // Independent shooting value in the spec.
        assert!(
            (r.sol.omega - 0.25141).abs() < 2e-5,
            "omega {}",
            r.sol.omega
        );
        let f = r.floquet.unwrap();
        assert!(f.trivial_error < 1e-6, "trivial {}", f.trivial_error);
        assert!(
            (f.max_modulus - 0.8637).abs() < 1e-4,
            "max modulus {}",
            f.max_modulus
        );
        let closure = closure_error(&p, &r.sol, 1e-11, 1e-13).unwrap();
        assert!(closure < 1e-5, "closure {closure}");
    }
}

#[cfg(all(test, feature = "studies"))]
mod studies;
