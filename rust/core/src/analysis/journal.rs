//! Trajectories of a rigid rotor on one journal bearing, in the fixed frame, without balls
//! (bearing.md sections 3 and 4: Yen's (2005) scenarios and the classical checks).
//!
//! # Equations
//!
//! Journal centre `c (x, y)`, time `tau = w t`, `' = d/dtau`. Newton for the rotor of mass
//! `M`, divided by `M c w^2`:
//!
//! ```text
//! q'' = f(q, q', tau) / m  +  g_n e_g  +  rho_u (cos(tau + phi_u), sin(tau + phi_u))
//!       +  a g_n exp(-s (tau - tau_c)^2) e_i
//! ```
//!
//! * `f` the film force in `F_S = mu w L R^3 / c^2` ([`crate::model::bearing`]);
//! * `m = M c w^2 / F_S = M c^3 w / (mu L R^3)`, the classical **bearing mass parameter**
//!   (the same `m` as [`crate::model::bearing::rigid_rotor_stability`]'s critical mass);
//!   it grows like `w`, so at fixed geometry a speed sweep is a sweep of `m` and of `g_n`;
//! * `g_n = W / (M c w^2) = g / (c w^2)` the gravity load along `e_g` (angle
//!   `gravity_direction`; Yen's (2005) `x` points down, angle 0). The static load on the film
//!   is `m g_n = W / F_S`, so the Sommerfeld number is `S = 1 / (pi m g_n)`;
//! * `rho_u = e_u / c` the mass unbalance (force `M e_u w^2` turning with the journal): a
//!   rotating load of `rho_u / g_n` times the weight;
//! * Yen's (2005) impulse `F = a W exp(-s (tau - tau_c)^2)` along `e_i` (`a` over the weight,
//!   so it needs gravity; Yen's (2005) is `a = 5`, `s = 2`, `tau_c = 3` at 500 rad/s).
//!
//! # Spin-up
//!
//! `w` is the reference speed the units are made with. The journal turns at
//! `w s(tau)` with `s` given by [`SpinUp`]: 1 from the start ([`SpinUp::Sudden`], Yen's
//! (2005) sudden start) or a linear run-up ([`SpinUp::Ramp`]). The film force at speed
//! `s w` is `s F(X, V / s)` with `F` the force at `w`: Reynolds' right-hand side
//! `6 s dH/dtheta + 12 dH/dtau` is `s` times the one at `w` with the velocity over `s`,
//! and every cavitation model here (clipping, complementarity) commutes with a positive
//! factor. The unbalance's mass centre at angle `theta(tau) = int s` adds
//! `rho_u (s^2 u - s' u_perp)`, `u = (cos, sin)(theta + phi_u)`, `u_perp = J u`; the grooves
//! of a grooved journal turn by `theta`. Gravity, `m` and `g_n` keep their reference
//! values (`g_n = g / (c w^2)` at the reference speed).
//!
//! Dimensional conversion ([`RotorOnBearing::from_dimensions`]): with radius `R`, length
//! `L`, clearance `c`, viscosity `mu`, rotor mass `M` (carried by this bearing), speed `w`,
//! unbalance `e_u` and gravity `g`: `m = M c^3 w / (mu L R^3)`, `g_n = g / (c w^2)`,
//! `rho_u = e_u / c`; time `t = tau / w`, position `c q`, force `F_S f`.
//!
//! # Outcomes
//!
//! A run ends [`Outcome::Completed`] at its last time, [`Outcome::Contact`] when the
//! eccentricity reaches `eps_contact` (the time found by bisection on the step's dense
//! output), [`Outcome::Stiff`] when the explicit integrator's steps are held down by
//! stability for `stiff_steps` steps in a row (the squeeze film's radial damping grows
//! like `(1 - eps^2)^(-5/2)`; [`Method::Implicit`] integrates through it) or
//! [`Outcome::Failed`] (step underflow, step budget, a film that cannot be solved); the
//! trajectory up to then is kept. Only invalid input and cancellation are errors.

use crate::error::{check_range, Error, Result};
use crate::model::bearing::{Bearing, Dimensions, FilmSolver, JournalState};
use crate::numerics::ode::{check_times, Dopri5, Options, Stats};
use crate::numerics::rosenbrock::Rosenbrock23;

/// Yen's (2005) impulse: `amplitude` times the weight, `exp(-sharpness (tau - center)^2)`,
/// along `direction` (radians in the fixed frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Impulse {
    pub amplitude: f64,
    pub center: f64,
    pub sharpness: f64,
    pub direction: f64,
}

/// How the journal's speed reaches the reference speed `w` (module docs, "Spin-up").
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum SpinUp {
    /// At `w` from the start.
    #[default]
    Sudden,
    /// `s = start + (1 - start) tau / duration` on `[0, duration]`, `start` before, 1 after.
    Ramp { start: f64, duration: f64 },
}

impl SpinUp {
    pub fn validate(&self) -> Result<()> {
        if let SpinUp::Ramp { start, duration } = *self {
            check_range("spin_up.start", start, 0.0, false, 1.0, true)?;
            check_range("spin_up.duration", duration, 0.0, true, 1e12, false)?;
        }
        Ok(())
    }

    /// `(s, s', theta)` at `tau`: the speed over `w`, its rate, and the journal's angle
    /// (`theta(0) = 0`).
    #[inline]
    pub fn at(&self, tau: f64) -> (f64, f64, f64) {
        match *self {
            SpinUp::Sudden => (1.0, 0.0, tau),
            SpinUp::Ramp { start, duration } => {
                let rate = (1.0 - start) / duration;
                if tau <= 0.0 {
                    (start, 0.0, start * tau)
                } else if tau < duration {
                    (
                        start + rate * tau,
                        rate,
                        start * tau + 0.5 * rate * tau * tau,
                    )
                } else {
                    (1.0, 0.0, 0.5 * (1.0 + start) * duration + (tau - duration))
                }
            }
        }
    }
}

/// A rigid rotor carried by one journal bearing, nondimensional (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct RotorOnBearing {
    pub bearing: Bearing,
    /// Bearing mass parameter `m = M c w^2 / F_S`.
    pub mass: f64,
    /// `g_n = W / (M c w^2)`.
    pub gravity: f64,
    /// Direction of gravity in the fixed frame (radians; 0 = Yen's (2005) `x`, down).
    pub gravity_direction: f64,
    /// `rho_u = e_u / c`.
    pub unbalance: f64,
    /// Phase `phi_u` of the unbalance at `tau = 0` (radians).
    pub unbalance_phase: f64,
    pub impulse: Option<Impulse>,
    /// The journal's speed profile ([`SpinUp::Sudden`]: `w` throughout).
    pub spin_up: SpinUp,
}

/// Which integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// Dormand–Prince 5(4) with a stiffness diagnostic (outcome [`Outcome::Stiff`]).
    #[default]
    Explicit,
    /// Rosenbrock 2(3) (`ode23s`), L-stable: for runs that approach the wall.
    Implicit,
}

/// Settings of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RotorOptions {
    pub rtol: f64,
    pub atol: f64,
    pub max_steps: usize,
    /// Eccentricity at which the run ends with [`Outcome::Contact`].
    pub eps_contact: f64,
    /// Explicit method: the run ends as [`Outcome::Stiff`] when its steps are held by
    /// stability (Hairer's test, 15 steps in a row) at a size that needs more than this
    /// many steps to finish.
    pub stiff_steps: usize,
    pub method: Method,
    /// Finite grooved films: precondition with an old factor to this relative residual
    /// ([`FilmSolver::set_factor_reuse`]); `None` factors every evaluation.
    pub factor_reuse: Option<f64>,
}

impl Default for RotorOptions {
    fn default() -> Self {
        RotorOptions {
            rtol: 1e-6,
            atol: 1e-9,
            max_steps: 2_000_000,
            eps_contact: 0.98,
            stiff_steps: 100_000,
            method: Method::Explicit,
            factor_reuse: Some(1e-10),
        }
    }
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    Completed,
    Contact,
    Stiff,
    Failed,
}

impl Outcome {
    pub fn name(&self) -> &'static str {
        match self {
            Outcome::Completed => "completed",
            Outcome::Contact => "contact",
            Outcome::Stiff => "stiff",
            Outcome::Failed => "failed",
        }
    }
}

/// A simulated trajectory: rows at the requested times reached, plus the contact point.
#[derive(Debug, Clone, PartialEq)]
pub struct RotorTrajectory {
    pub t: Vec<f64>,
    /// `(x, y, x', y')` per row.
    pub y: Vec<[f64; 4]>,
    /// Film force per row: `(f_x, f_y, f_radial, f_tangential)` in `F_S`.
    pub force: Vec<[f64; 4]>,
    pub outcome: Outcome,
    /// Time the integration reached (the contact time for contact).
    pub t_end: f64,
    pub contact_time: Option<f64>,
    /// Stiff: the eccentricity where the steps collapsed and the step size they collapsed to.
    pub stiff_at: Option<(f64, f64)>,
    pub message: String,
    pub stats: Stats,
    /// Film force evaluations (the integrator's and the output rows').
    pub force_evals: usize,
}

impl RotorOnBearing {
    pub fn validate(&self) -> Result<()> {
        self.bearing.validate()?;
        check_range("mass_parameter", self.mass, 0.0, true, f64::INFINITY, true)?;
        check_range("gravity", self.gravity, 0.0, false, f64::INFINITY, true)?;
        check_range("unbalance", self.unbalance, 0.0, false, f64::INFINITY, true)?;
        self.spin_up.validate()?;
        for (name, v) in [
            ("gravity_direction", self.gravity_direction),
            ("unbalance_phase", self.unbalance_phase),
        ] {
            if !v.is_finite() {
                return Err(Error::param(name, format!("must be finite, got {v}")));
            }
        }
        if let Some(imp) = &self.impulse {
            check_range(
                "impulse.amplitude",
                imp.amplitude,
                0.0,
                false,
                f64::INFINITY,
                true,
            )?;
            check_range(
                "impulse.sharpness",
                imp.sharpness,
                0.0,
                true,
                f64::INFINITY,
                true,
            )?;
            for (name, v) in [
                ("impulse.center", imp.center),
                ("impulse.direction", imp.direction),
            ] {
                if !v.is_finite() {
                    return Err(Error::param(name, format!("must be finite, got {v}")));
                }
            }
            if imp.amplitude > 0.0 && self.gravity == 0.0 {
                return Err(Error::param_range(
                    "impulse.amplitude",
                    "is a multiple of the weight W, so it needs gravity > 0",
                    "gravity > 0 with an impulse",
                ));
            }
        }
        Ok(())
    }

    /// From lab quantities (SI): `mass` in kg carried by this bearing, `omega` rad/s, `e_u`
    /// and the dimensions in m, viscosity in Pa s, `g` in m/s^2. The bearing's `L/D` must
    /// be the dimensions' (checked to 1e-9).
    pub fn from_dimensions(
        bearing: Bearing,
        dims: &Dimensions,
        mass: f64,
        omega: f64,
        e_u: f64,
        g: f64,
    ) -> Result<Self> {
        let dims = Dimensions::new(dims.radius, dims.length, dims.clearance, dims.viscosity)?;
        check_range("mass", mass, 0.0, true, f64::INFINITY, true)?;
        check_range("speed", omega, 0.0, true, f64::INFINITY, true)?;
        check_range("unbalance", e_u, 0.0, false, f64::INFINITY, true)?;
        check_range("g", g, 0.0, false, f64::INFINITY, true)?;
        if (dims.lambda() - bearing.lambda).abs() > 1e-9 * bearing.lambda {
            return Err(Error::param_range(
                "length",
                format!(
                    "L / D = {} from the dimensions differs from the bearing's length_ratio {}",
                    dims.lambda(),
                    bearing.lambda
                ),
                format!(
                    "length = {} (2 radius length_ratio)",
                    2.0 * dims.radius * bearing.lambda
                ),
            ));
        }
        let c = dims.clearance;
        let rotor = RotorOnBearing {
            bearing,
            mass: mass * c * omega * omega / dims.force_scale(omega),
            gravity: g / (c * omega * omega),
            gravity_direction: 0.0,
            unbalance: e_u / c,
            unbalance_phase: 0.0,
            impulse: None,
            spin_up: SpinUp::Sudden,
        };
        rotor.validate()?;
        Ok(rotor)
    }

    /// The static load on the film, `m g_n e_g`, in `F_S` (what [`crate::model::bearing::equilibrium`] takes).
    pub fn static_load(&self) -> [f64; 2] {
        let w = self.mass * self.gravity;
        let (s, c) = self.gravity_direction.sin_cos();
        [w * c, w * s]
    }

    /// The journal's static equilibrium under the weight, `(x, y)` (Newton on the film,
    /// [`crate::model::bearing::equilibrium`]).
    pub fn equilibrium(&self) -> Result<[f64; 2]> {
        self.validate()?;
        if self.gravity == 0.0 {
            return Ok([0.0, 0.0]);
        }
        let e =
            crate::model::bearing::equilibrium(&mut self.bearing.solver()?, self.static_load())?;
        Ok([e.x, e.y])
    }

    /// The applied accelerations (gravity, unbalance, impulse) at `tau`.
    pub fn applied(&self, tau: f64) -> [f64; 2] {
        let (gs, gc) = self.gravity_direction.sin_cos();
        let (s, ds, th) = self.spin_up.at(tau);
        let (us, uc) = (th + self.unbalance_phase).sin_cos();
        // the mass centre's acceleration relative to the journal's, -d^2/dtau^2 of rho_u u
        let (ur, ut) = (self.unbalance * s * s, self.unbalance * ds);
        let mut a = [
            self.gravity * gc + ur * uc + ut * us,
            self.gravity * gs + ur * us - ut * uc,
        ];
        if let Some(imp) = &self.impulse {
            let d = tau - imp.center;
            let k = imp.amplitude * self.gravity * (-imp.sharpness * d * d).exp();
            let (is, ic) = imp.direction.sin_cos();
            a[0] += k * ic;
            a[1] += k * is;
        }
        a
    }
}

/// The right-hand side with the film solver; a failed evaluation (the journal outside the
/// clearance inside a trial stage, an unsolvable film) returns NaN so that the integrator
/// shrinks the step, and keeps the error for the report.
struct Rhs<'a> {
    rotor: &'a RotorOnBearing,
    solver: FilmSolver,
    evals: usize,
    last_error: Option<Error>,
}

/// The film force `(f_x, f_y, f_radial, f_tangential)` at `tau` for the journal at
/// `y = (x, y, x', y')` turning at `spin.at(tau)`: `s F(X, V / s)` (module docs). At rest
/// (`s = 0`) the limit, the pure squeeze film, is taken at `s` far below `|V|`.
pub fn film_force(solver: &mut FilmSolver, spin: &SpinUp, tau: f64, y: &[f64]) -> Result<[f64; 4]> {
    let (s, _, th) = spin.at(tau);
    let s = s.max(1e-12 * y[2].hypot(y[3])).max(f64::MIN_POSITIVE);
    let st = JournalState {
        x: y[0],
        y: y[1],
        vx: y[2] / s,
        vy: y[3] / s,
        tau: th,
    };
    let f = solver.force(&st, false)?;
    Ok([s * f.fx, s * f.fy, s * f.f_radial, s * f.f_tangential])
}

impl Rhs<'_> {
    fn eval(&mut self, tau: f64, y: &[f64], dy: &mut [f64]) {
        self.evals += 1;
        dy[0] = y[2];
        dy[1] = y[3];
        match film_force(&mut self.solver, &self.rotor.spin_up, tau, y) {
            Ok(f) => {
                let a = self.rotor.applied(tau);
                dy[2] = f[0] / self.rotor.mass + a[0];
                dy[3] = f[1] / self.rotor.mass + a[1];
            }
            Err(e) => {
                self.last_error = Some(e);
                dy[2] = f64::NAN;
                dy[3] = f64::NAN;
            }
        }
    }
}

/// What the observer of accepted steps decided.
struct Watch<'a> {
    t_eval: &'a [f64],
    idx: usize,
    rows_t: Vec<f64>,
    rows_y: Vec<[f64; 4]>,
    eps_contact: f64,
    contact: Option<f64>,
    stiff_steps: usize,
    t1: f64,
    stiff_run: usize,
    calm: usize,
    stiff_start_eps: f64,
    stiff: Option<(f64, f64)>,
    t_reached: f64,
    accepted: usize,
    last_h: f64,
}

impl Watch<'_> {
    /// One accepted step `[ta, tb]`; `interp` the dense output, `hrho` the stiffness
    /// indicator (NaN when the method has none). Returns whether to go on.
    fn step(
        &mut self,
        ta: f64,
        tb: f64,
        interp: &dyn Fn(f64, &mut [f64]),
        end: &[f64],
        hrho: f64,
    ) -> bool {
        let eps = |v: &[f64]| v[0].hypot(v[1]);
        self.accepted += 1;
        self.last_h = tb - ta;
        let mut t_stop = tb;
        if eps(end) >= self.eps_contact {
            let (mut lo, mut hi) = (ta, tb);
            let mut v = [0.0; 4];
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                interp(mid, &mut v);
                if eps(&v) >= self.eps_contact {
                    hi = mid;
                } else {
                    lo = mid;
                }
                if hi - lo <= 4.0 * f64::EPSILON * hi.abs().max(1.0) {
                    break;
                }
            }
            self.contact = Some(hi);
            t_stop = hi;
        }
        while self.idx < self.t_eval.len() && self.t_eval[self.idx] <= t_stop {
            let mut v = [0.0; 4];
            interp(self.t_eval[self.idx], &mut v);
            self.rows_t.push(self.t_eval[self.idx]);
            self.rows_y.push(v);
            self.idx += 1;
        }
        self.t_reached = t_stop;
        if let Some(tc) = self.contact {
            let mut v = [0.0; 4];
            interp(tc, &mut v);
            if self.rows_t.last() != Some(&tc) {
                self.rows_t.push(tc);
                self.rows_y.push(v);
            }
            return false;
        }
        // Hairer's test, as the integrator's own, but ending the run after `stiff_steps`.
        if hrho > 3.25 {
            if self.stiff_run == 0 {
                self.stiff_start_eps = eps(end);
            }
            self.calm = 0;
            self.stiff_run += 1;
            // A settled orbit is stability-limited too, at steps of order one: only a step
            // held so small that finishing would take more than `stiff_steps` is a crawl.
            let left = (self.t1 - tb) / (tb - ta);
            if self.stiff_run >= 15 && left > self.stiff_steps as f64 {
                self.stiff = Some((self.stiff_start_eps, tb - ta));
                return false;
            }
        } else {
            self.calm += 1;
            if self.calm >= 6 {
                self.stiff_run = 0;
            }
        }
        true
    }
}

/// Simulates `rotor` from `y0 = (x, y, x', y')` at `tau = t0`, with rows at `t_eval`
/// (increasing, from `t0`). See the module docs for the outcomes.
pub fn simulate_rotor(
    rotor: &RotorOnBearing,
    y0: [f64; 4],
    t0: f64,
    t_eval: &[f64],
    opts: &RotorOptions,
) -> Result<RotorTrajectory> {
    rotor.validate()?;
    check_range("eps_contact", opts.eps_contact, 0.0, true, 1.0, true)?;
    if opts.stiff_steps == 0 {
        return Err(Error::param_range("stiff_steps", "must be >= 1", ">= 1"));
    }
    if opts.max_steps == 0 {
        return Err(Error::param_range("max_steps", "must be >= 1", ">= 1"));
    }
    if let Some(tol) = opts.factor_reuse {
        check_range("factor_reuse", tol, 0.0, true, 1.0, true)?;
    }
    if let Some(i) = y0.iter().position(|v| !v.is_finite()) {
        return Err(Error::param(
            "x0",
            format!("entry {i} is not finite ({})", y0[i]),
        ));
    }
    let eps0 = y0[0].hypot(y0[1]);
    if eps0 >= opts.eps_contact {
        return Err(Error::param_range(
            "x0",
            format!(
                "the start's eccentricity {eps0} is at or past eps_contact = {}",
                opts.eps_contact
            ),
            format!("x^2 + y^2 < eps_contact^2 = {}", opts.eps_contact.powi(2)),
        ));
    }
    if t_eval.is_empty() {
        return Err(Error::param("t_eval", "needs at least one time"));
    }
    check_times(t0, t_eval)?;
    if t_eval.windows(2).any(|w| w[1] <= w[0]) || t_eval[0] < t0 {
        return Err(Error::param("t_eval", "must increase from t0"));
    }
    let t1 = *t_eval.last().expect("non-empty");
    let ode_opts = Options {
        max_steps: opts.max_steps,
        ..Options::new(opts.rtol, opts.atol)
    };
    ode_opts.validate(4)?;
    let mut solver = rotor.bearing.solver()?;
    solver.set_factor_reuse(opts.factor_reuse);
    let mut rhs = Rhs {
        rotor,
        solver,
        evals: 0,
        last_error: None,
    };
    let mut watch = Watch {
        t_eval,
        idx: 0,
        rows_t: vec![],
        rows_y: vec![],
        eps_contact: opts.eps_contact,
        contact: None,
        stiff_steps: opts.stiff_steps,
        t1: *t_eval.last().expect("checked non-empty"),
        stiff_run: 0,
        calm: 0,
        stiff_start_eps: eps0,
        stiff: None,
        t_reached: t0,
        accepted: 0,
        last_h: 0.0,
    };
    while watch.idx < t_eval.len() && t_eval[watch.idx] == t0 {
        watch.rows_t.push(t0);
        watch.rows_y.push(y0);
        watch.idx += 1;
    }
    let result = match opts.method {
        Method::Explicit => Dopri5::new(4).integrate(
            |t, y, dy| rhs.eval(t, y, dy),
            t0,
            &y0,
            t1,
            &ode_opts,
            |ta, tb, d| watch.step(ta, tb, &|t, o| d.eval(t, o), d.end(), d.stiffness()),
        ),
        Method::Implicit => Rosenbrock23::new(4).integrate(
            |t, y, dy| rhs.eval(t, y, dy),
            t0,
            &y0,
            t1,
            &ode_opts,
            |ta, tb, d| watch.step(ta, tb, &|t, o| d.eval(t, o), d.end(), f64::NAN),
        ),
    };
    let (outcome, stats, message) = match result {
        Err(Error::Cancelled) => return Err(Error::Cancelled),
        Err(e @ Error::InvalidParameter { .. }) => return Err(e),
        Err(e) => {
            let why = match &rhs.last_error {
                Some(f) => format!("{e} (last film error: {f})"),
                None => e.to_string(),
            };
            let outcome = if matches!(e, Error::Stiff(_)) {
                // The integrator's own test (a stiff stretch with more than 1e6 steps left).
                watch.stiff = Some((watch.stiff_start_eps, watch.last_h));
                Outcome::Stiff
            } else {
                Outcome::Failed
            };
            let stats = Stats {
                accepted: watch.accepted,
                ..Stats::default()
            };
            (outcome, stats, why)
        }
        Ok((_, _, stats)) => {
            if let Some(tc) = watch.contact {
                (
                    Outcome::Contact,
                    stats,
                    format!("eccentricity reached {} at tau = {tc}", opts.eps_contact),
                )
            } else if let Some((e, h)) = watch.stiff {
                (
                    Outcome::Stiff,
                    stats,
                    format!(
                        "the explicit steps collapsed to {h:.3e} (held by stability from eccentricity {e:.4}; more than {} steps to finish): the squeeze film near the wall is stiff; use the implicit method",
                        opts.stiff_steps
                    ),
                )
            } else {
                (Outcome::Completed, stats, String::new())
            }
        }
    };
    let t_end = match outcome {
        Outcome::Completed => t1,
        _ => watch.t_reached,
    };
    let mut force = Vec::with_capacity(watch.rows_t.len());
    let mut evals = rhs.evals;
    for (t, y) in watch.rows_t.iter().zip(&watch.rows_y) {
        evals += 1;
        force.push(film_force(&mut rhs.solver, &rotor.spin_up, *t, y).unwrap_or([f64::NAN; 4]));
    }
    Ok(RotorTrajectory {
        t: watch.rows_t,
        y: watch.rows_y,
        force,
        outcome,
        t_end,
        contact_time: watch.contact,
        stiff_at: watch.stiff,
        message,
        stats,
        force_evals: evals,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::bearing::{equilibrium, FilmModel};

    fn short_rotor(mass: f64, gravity: f64) -> RotorOnBearing {
        RotorOnBearing {
            bearing: Bearing::plain(0.5, FilmModel::Short),
            mass,
            gravity,
            gravity_direction: 0.0,
            unbalance: 0.0,
            unbalance_phase: 0.0,
            impulse: None,
            spin_up: SpinUp::Sudden,
        }
    }

    fn times(t1: f64, n: usize) -> Vec<f64> {
        (0..=n).map(|i| t1 * i as f64 / n as f64).collect()
    }

    #[test]
    fn settles_on_the_static_equilibrium() {
        // Heavy load, low mass: eps ~ 0.8, stable at every speed.
        let rotor = short_rotor(1.0, 2.0);
        let eq = equilibrium(&mut rotor.bearing.solver().unwrap(), rotor.static_load()).unwrap();
        for method in [Method::Explicit, Method::Implicit] {
            let opts = RotorOptions {
                method,
                ..Default::default()
            };
            let tr = simulate_rotor(&rotor, [0.0, 0.3, 0.0, 0.0], 0.0, &times(200.0, 10), &opts)
                .unwrap();
            assert_eq!(tr.outcome, Outcome::Completed, "{}", tr.message);
            let y = tr.y.last().unwrap();
            assert!(
                (y[0] - eq.x).abs() < 1e-4 && (y[1] - eq.y).abs() < 1e-4,
                "{method:?} {y:?} {eq:?}"
            );
        }
    }

    #[test]
    fn a_large_unbalance_ends_in_contact_with_its_time() {
        // Far above the rigid-body critical speed the journal orbits about the mass centre,
        // at radius ~ rho_u = 3 > 1: the film (at most ~600 F_S at eps 0.98 for L/D = 0.5)
        // cannot hold m (rho_u - 0.98) ~ 2000 F_S.
        let mut rotor = short_rotor(1000.0, 0.0);
        rotor.unbalance = 3.0;
        let tr = simulate_rotor(
            &rotor,
            [0.1, 0.0, 0.0, 0.0],
            0.0,
            &times(100.0, 100),
            &RotorOptions::default(),
        )
        .unwrap();
        assert_eq!(tr.outcome, Outcome::Contact, "{}", tr.message);
        let tc = tr.contact_time.unwrap();
        let last = tr.y.last().unwrap();
        assert_eq!(*tr.t.last().unwrap(), tc);
        assert!((last[0].hypot(last[1]) - 0.98).abs() < 1e-9);
        assert!(tr.t.iter().all(|&t| t <= tc));
    }

    #[test]
    fn explicit_steps_held_by_the_wall_are_reported_as_stiff() {
        // A light rotor pressed to the wall by a steady load: eps ~ 0.97, where the
        // squeeze film makes the explicit step tiny; the implicit method sails through.
        let rotor = short_rotor(1e-4, 2.5e6);
        let opts = RotorOptions {
            stiff_steps: 10_000,
            eps_contact: 0.995,
            ..Default::default()
        };
        let tr = simulate_rotor(&rotor, [0.9, 0.0, 0.0, 0.0], 0.0, &times(50.0, 5), &opts).unwrap();
        assert_eq!(
            tr.outcome,
            Outcome::Stiff,
            "{} {:?}",
            tr.message,
            tr.y.last()
        );
        assert!(tr.stiff_at.unwrap().0 > 0.9);
        let imp = RotorOptions {
            method: Method::Implicit,
            ..opts
        };
        let tr = simulate_rotor(&rotor, [0.9, 0.0, 0.0, 0.0], 0.0, &times(50.0, 5), &imp).unwrap();
        assert_eq!(tr.outcome, Outcome::Completed, "{}", tr.message);
        assert!(tr.stats.accepted < 10_000, "{:?}", tr.stats);
    }

    #[test]
    fn dimensions_convert_to_the_mass_parameter() {
        let dims = Dimensions::new(0.01, 0.02, 1e-5, 0.01).unwrap();
        let r = RotorOnBearing::from_dimensions(
            Bearing::plain(1.0, FilmModel::Short),
            &dims,
            0.5,
            500.0,
            1e-6,
            9.81,
        )
        .unwrap();
        // m = M c^3 w / (mu L R^3), g_n = g / (c w^2), rho_u = e_u / c.
        assert!((r.mass - 0.5 * 1e-15 * 500.0 / (0.01 * 0.02 * 1e-6)).abs() < 1e-12 * r.mass);
        assert!((r.gravity - 9.81 / (1e-5 * 2.5e5)).abs() < 1e-12);
        assert!((r.unbalance - 0.1).abs() < 1e-12);
        let bad = RotorOnBearing::from_dimensions(
            Bearing::plain(0.5, FilmModel::Short),
            &dims,
            0.5,
            500.0,
            0.0,
            9.81,
        );
        assert!(matches!(bad, Err(Error::InvalidParameter { name, .. }) if name == "length"));
    }

    #[test]
    fn ramp_law_and_its_angle() {
        let r = SpinUp::Ramp {
            start: 0.2,
            duration: 10.0,
        };
        // s = 0.2 + 0.08 tau, theta = 0.2 tau + 0.04 tau^2 up to tau = 10, then slope 1
        let (s, ds, th) = r.at(5.0);
        assert!((s - 0.6).abs() < 1e-14 && (ds - 0.08).abs() < 1e-14 && (th - 2.0).abs() < 1e-13);
        let (s, ds, th) = r.at(12.0);
        assert!(s == 1.0 && ds == 0.0 && (th - 8.0).abs() < 1e-13);
        assert_eq!(SpinUp::Sudden.at(3.0), (1.0, 0.0, 3.0));
    }

    #[test]
    fn film_at_a_fraction_of_the_speed_is_the_scaled_film() {
        // The short bearing's pressure is linear in (s dH/dtheta, dH/dtau) before clipping:
        // at half speed with no squeeze the force is half the force at w.
        let mut solver = Bearing::plain(0.5, FilmModel::Short).solver().unwrap();
        let half = SpinUp::Ramp {
            start: 0.5,
            duration: 1.0,
        };
        let y = [0.3, 0.1, 0.0, 0.0];
        let f_half = film_force(&mut solver, &half, 0.0, &y).unwrap();
        let f_full = film_force(&mut solver, &SpinUp::Sudden, 0.0, &y).unwrap();
        for i in 0..4 {
            assert!((f_half[i] - 0.5 * f_full[i]).abs() < 1e-12 * f_full[0].abs().max(1.0));
        }
        // at rest with no squeeze, no film force
        let rest = SpinUp::Ramp {
            start: 0.0,
            duration: 1.0,
        };
        let f0 = film_force(&mut solver, &rest, 0.0, &y).unwrap();
        assert!(f0.iter().all(|v| v.abs() < 1e-200), "{f0:?}");
    }

    #[test]
    fn bad_input_names_the_parameter() {
        let name = |r: Result<RotorTrajectory>| match r {
            Err(Error::InvalidParameter { name, .. }) => name,
            other => panic!("{other:?}"),
        };
        let t = times(1.0, 2);
        let o = RotorOptions::default();
        assert_eq!(
            name(simulate_rotor(
                &short_rotor(-1.0, 1.0),
                [0.0; 4],
                0.0,
                &t,
                &o
            )),
            "mass_parameter"
        );
        assert_eq!(
            name(simulate_rotor(
                &short_rotor(1.0, 1.0),
                [0.99, 0.0, 0.0, 0.0],
                0.0,
                &t,
                &o
            )),
            "x0"
        );
        let mut r = short_rotor(1.0, 0.0);
        r.impulse = Some(Impulse {
            amplitude: 5.0,
            center: 3.0,
            sharpness: 2.0,
            direction: 0.0,
        });
        assert_eq!(
            name(simulate_rotor(&r, [0.0; 4], 0.0, &t, &o)),
            "impulse.amplitude"
        );
        let mut r = short_rotor(1.0, 1.0);
        r.spin_up = SpinUp::Ramp {
            start: 1.0,
            duration: 1.0,
        };
        assert_eq!(
            name(simulate_rotor(&r, [0.0; 4], 0.0, &t, &o)),
            "spin_up.start"
        );
        r.spin_up = SpinUp::Ramp {
            start: 0.0,
            duration: 0.0,
        };
        assert_eq!(
            name(simulate_rotor(&r, [0.0; 4], 0.0, &t, &o)),
            "spin_up.duration"
        );
        let o2 = RotorOptions {
            eps_contact: 1.0,
            ..Default::default()
        };
        assert_eq!(
            name(simulate_rotor(
                &short_rotor(1.0, 1.0),
                [0.0; 4],
                0.0,
                &t,
                &o2
            )),
            "eps_contact"
        );
    }
}
