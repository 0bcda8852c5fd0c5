//! Hydrodynamic journal bearing: the film-force engine (plain and herringbone-grooved).
//!
//! Nondimensionalisation (bearing.md section 1): `theta` angle on the bearing,
//! `zeta = z / R` in `[-lambda, lambda]` with `lambda = L / D`, film `H = h / c`,
//! pressure `P = p c^2 / (mu w R^2)`, time `tau = w t`. The journal centre is at
//! `c (x, y)` in the fixed frame with velocity `c w (x', y')`, and
//!
//! ```text
//! d/dtheta (H^3 dP/dtheta) + d/dzeta (H^3 dP/dzeta) = 6 dH/dtheta + 12 dH/dtau
//! H = 1 - x cos theta - y sin theta + delta_g G(theta, zeta)
//! ```
//!
//! Forces are in units of `F_S = mu w L R^3 / c^2`, i.e. `F / F_S` is the mean over
//! `zeta` of `-(integral of) P n dtheta`: the long bearing's force per unit length in
//! `mu w R^3 / c^2` is `F / F_S` directly, and the short bearing's `F0 = mu w R L^3 / c^2`
//! is `(2 lambda)^2 F_S`.
//!
//! Layout: this file holds the description and validation; [`short`] and [`long`] the
//! closed forms, [`finite`] the finite-volume Reynolds solver, [`narrow`] narrow-groove
//! theory (the smoothed film of many grooves, on the same grid), [`linear`] the static
//! equilibrium, linearised coefficients and whirl threshold.

pub mod finite;
pub mod linear;
pub mod long;
pub mod narrow;
pub mod short;
#[cfg(all(test, feature = "studies"))]
mod studies;
pub mod study;
#[cfg(test)]
mod tests;

use crate::error::{check_range, Error, Result};
use crate::model::ParamId;
use std::f64::consts::PI;

pub use finite::FiniteSolver;
pub use linear::{
    equilibrium, linear_coefficients, linear_coefficients_fd, rigid_rotor_stability, Equilibrium,
    LinearCoefficients, WhirlStability,
};
pub use narrow::NarrowSolver;

/// Which surface carries the grooves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GrooveSide {
    /// Stationary sleeve (Yen's (2005) configuration): the film is steady in the fixed frame
    /// for a fixed journal position.
    Sleeve,
    /// Rotating journal: the groove pattern turns with the journal angle `tau`.
    Journal,
}

/// Symmetric herringbone grooves.
///
/// Groove phase `psi = theta - tau_g + s |zeta| cot(beta)`, groove where
/// `frac(N_g psi / 2 pi) < gamma`; `s = +1` for sleeve grooves, `-1` for journal grooves, so
/// that the apex (at the mid-plane) points in the direction in which the smooth surface
/// moves relative to the grooved one and the grooves pump towards the mid-plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grooves {
    /// Number of grooves `N_g` (>= 1).
    pub count: usize,
    /// Groove angle `beta` in radians, measured **from the circumferential direction**, in (0, pi/2].
    pub angle: f64,
    /// Depth ratio `delta_g = c_g / c` (>= 0).
    pub depth: f64,
    /// Width ratio `gamma = groove width / pitch`, in (0, 1).
    pub width: f64,
    /// Grooved fraction of the length, in (0, 1]: grooves occupy `|zeta| <= fraction * lambda`
    /// (centred on the apex at the mid-plane, smooth lands at both ends).
    pub length_fraction: f64,
    pub side: GrooveSide,
}

impl Grooves {
    pub fn validate(&self) -> Result<()> {
        if self.count == 0 {
            return Err(Error::param_range(
                "grooves.count",
                "must be at least 1",
                "integer >= 1",
            ));
        }
        check_range(
            "grooves.angle",
            self.angle.to_degrees(),
            0.0,
            true,
            90.0,
            true,
        )?;
        ParamId::GrooveDepth.check_named("grooves.depth_ratio", self.depth)?;
        check_range("grooves.width_ratio", self.width, 0.0, true, 1.0, true)?;
        check_range(
            "grooves.grooved_length",
            self.length_fraction,
            0.0,
            true,
            1.0,
            false,
        )?;
        Ok(())
    }

    /// Chirality sign `s` of the groove phase (see the type's documentation).
    pub(crate) fn chirality(&self) -> f64 {
        match self.side {
            GrooveSide::Sleeve => 1.0,
            GrooveSide::Journal => -1.0,
        }
    }
}

/// Cavitation model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Cavitation {
    /// Solve the linear problem, then clip `P <- max(P, 0)` (Yen's (2005) model).
    #[default]
    HalfSommerfeld,
    /// Swift–Stieber: the complementarity problem `P >= 0`, flow residual `>= 0`,
    /// product zero (primal–dual active set on the finite-volume system).
    Reynolds,
    /// Full Sommerfeld: negative pressures kept (tests only).
    None,
}

/// Which approximation of the Reynolds equation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FilmModel {
    /// Ocvirk's short bearing (axial flow only), closed form with squeeze.
    Short,
    /// Infinitely long bearing (circumferential flow only), closed-form pressure.
    Long,
    /// Finite-volume solve on `n_theta x n_zeta` cells.
    Finite { n_theta: usize, n_zeta: usize },
    /// Vohr & Chow's narrow-groove theory: the grooves smoothed into an anisotropic film,
    /// solved on `n_theta x n_zeta` cells that need not resolve them (no grooves: the plain
    /// finite film).
    NarrowGroove { n_theta: usize, n_zeta: usize },
}

/// A journal bearing, nondimensional.
#[derive(Debug, Clone, PartialEq)]
pub struct Bearing {
    /// `L / D`.
    pub lambda: f64,
    pub grooves: Option<Grooves>,
    pub cavitation: Cavitation,
    pub model: FilmModel,
}

/// Smallest number of cells per groove pitch the finite solver accepts.
pub const MIN_CELLS_PER_PITCH: usize = 8;

impl Bearing {
    /// A plain bearing with the half-Sommerfeld condition.
    pub fn plain(lambda: f64, model: FilmModel) -> Self {
        Bearing {
            lambda,
            grooves: None,
            cavitation: Cavitation::HalfSommerfeld,
            model,
        }
    }

    pub fn validate(&self) -> Result<()> {
        check_range("length_ratio", self.lambda, 0.0, true, f64::INFINITY, true)?;
        if let Some(g) = &self.grooves {
            g.validate()?;
        }
        match self.model {
            FilmModel::Short | FilmModel::Long => {
                if self.grooves.is_some_and(|g| g.depth > 0.0) {
                    return Err(Error::param_range(
                        "model",
                        "the short and long closed forms describe plain bearings only; use 'finite' for grooves",
                        "finite, narrow_groove",
                    ));
                }
                if self.cavitation == Cavitation::Reynolds {
                    return Err(Error::param_range(
                        "cavitation",
                        "the short and long closed forms have no Reynolds (complementarity) condition",
                        "half_sommerfeld, none",
                    ));
                }
            }
            FilmModel::Finite { n_theta, n_zeta } => {
                check_grid(n_theta, n_zeta)?;
                if let Some(g) = &self.grooves {
                    if n_theta % g.count != 0 || n_theta / g.count < MIN_CELLS_PER_PITCH {
                        return Err(Error::param_range(
                            "grid.n_theta",
                            format!(
                                "must be a multiple of the groove count {} with at least {} cells per groove pitch, got {n_theta}",
                                g.count, MIN_CELLS_PER_PITCH
                            ),
                            format!("multiple of {} and >= {}", g.count, g.count * MIN_CELLS_PER_PITCH),
                        ));
                    }
                    let per_pitch = (n_theta / g.count) as f64;
                    if g.width * per_pitch < 1.0 || (1.0 - g.width) * per_pitch < 1.0 {
                        return Err(Error::param_range(
                            "grid.n_theta",
                            format!(
                                "{per_pitch} cells per pitch cannot resolve a groove width ratio of {}; refine the grid",
                                g.width
                            ),
                            "at least one cell across each groove and each land",
                        ));
                    }
                }
            }
            FilmModel::NarrowGroove { n_theta, n_zeta } => check_grid(n_theta, n_zeta)?,
        }
        Ok(())
    }

    /// A solver for this bearing (validates; the finite model keeps its symbolic
    /// factorisation and tables between evaluations).
    pub fn solver(&self) -> Result<FilmSolver> {
        self.validate()?;
        let kind = match self.model {
            FilmModel::Short => SolverKind::Short,
            FilmModel::Long => SolverKind::Long,
            FilmModel::Finite { n_theta, n_zeta } => {
                SolverKind::Finite(Box::new(FiniteSolver::new(self, n_theta, n_zeta)?))
            }
            FilmModel::NarrowGroove { n_theta, n_zeta } => match self.grooves {
                Some(_) => SolverKind::Narrow(Box::new(NarrowSolver::new(self, n_theta, n_zeta)?)),
                None => SolverKind::Finite(Box::new(FiniteSolver::new(self, n_theta, n_zeta)?)),
            },
        };
        Ok(FilmSolver {
            bearing: self.clone(),
            kind,
        })
    }
}

/// Physical dimensions, for converting to and from the nondimensional film.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dimensions {
    pub radius: f64,
    pub length: f64,
    pub clearance: f64,
    pub viscosity: f64,
}

impl Dimensions {
    pub fn new(radius: f64, length: f64, clearance: f64, viscosity: f64) -> Result<Self> {
        check_range("radius", radius, 0.0, true, f64::INFINITY, true)?;
        check_range("length", length, 0.0, true, f64::INFINITY, true)?;
        check_range("clearance", clearance, 0.0, true, radius, true)?;
        check_range("viscosity", viscosity, 0.0, true, f64::INFINITY, true)?;
        Ok(Dimensions {
            radius,
            length,
            clearance,
            viscosity,
        })
    }

    /// `lambda = L / D`.
    pub fn lambda(&self) -> f64 {
        self.length / (2.0 * self.radius)
    }

    /// `F_S = mu w L R^3 / c^2` at spin `omega` (rad/s).
    pub fn force_scale(&self, omega: f64) -> f64 {
        self.viscosity * omega * self.length * self.radius.powi(3) / self.clearance.powi(2)
    }

    /// Pressure scale `mu w R^2 / c^2`.
    pub fn pressure_scale(&self, omega: f64) -> f64 {
        self.viscosity * omega * self.radius.powi(2) / self.clearance.powi(2)
    }

    /// Sommerfeld number `S = mu N L D (R/c)^2 / W` with `N = omega / 2 pi` rev/s.
    pub fn sommerfeld(&self, omega: f64, load: f64) -> f64 {
        let n = omega / (2.0 * PI);
        self.viscosity
            * n
            * self.length
            * 2.0
            * self.radius
            * (self.radius / self.clearance).powi(2)
            / load
    }
}

/// Journal state in the fixed frame (units `c` and `c w`), and the journal angle `tau`
/// (only grooves on the journal depend on it).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JournalState {
    pub x: f64,
    pub y: f64,
    pub vx: f64,
    pub vy: f64,
    pub tau: f64,
}

impl JournalState {
    pub fn at(x: f64, y: f64) -> Self {
        JournalState {
            x,
            y,
            ..Default::default()
        }
    }
}

/// The closed forms' line-of-centres frame (see [`short`]): `x + i y = eps e^{i phi}`, and
/// the squeeze-plus-wedge right-hand side `g = A sin t + B cos t` in the angle `t = theta - phi`.
pub(crate) struct LineOfCentres {
    pub eps: f64,
    pub phi: f64,
    sin: f64,
    cos: f64,
    pub big_a: f64,
    pub big_b: f64,
}

impl LineOfCentres {
    pub fn of(s: &JournalState) -> Self {
        let (a, b) = (6.0 * s.x - 12.0 * s.vy, -6.0 * s.y - 12.0 * s.vx);
        let eps = s.x.hypot(s.y);
        let phi = if eps > 0.0 { s.y.atan2(s.x) } else { 0.0 };
        let (sp, cp) = phi.sin_cos();
        LineOfCentres {
            eps,
            phi,
            sin: sp,
            cos: cp,
            big_a: a * cp - b * sp,
            big_b: a * sp + b * cp,
        }
    }

    /// Radial and tangential components (along and across the line of centres) as fixed-frame `(x, y)`.
    pub fn to_fixed(&self, radial: f64, tangential: f64) -> (f64, f64) {
        (
            radial * self.cos - tangential * self.sin,
            radial * self.sin + tangential * self.cos,
        )
    }
}

/// The film pressure on the cell centres, `values[i * n_zeta + j]` at `(theta[i], zeta[j])`.
#[derive(Debug, Clone, PartialEq)]
pub struct PressureField {
    pub n_theta: usize,
    pub n_zeta: usize,
    pub theta: Vec<f64>,
    pub zeta: Vec<f64>,
    pub values: Vec<f64>,
}

/// Film force on the journal and what goes with it.
#[derive(Debug, Clone, PartialEq)]
pub struct FilmForce {
    /// Force components in the fixed frame, units `F_S`.
    pub fx: f64,
    pub fy: f64,
    /// Radial component along the line of centres, positive **towards the bearing centre**
    /// (restoring), as the textbooks' `F_r` (so Ocvirk's `F_r = F0 eps^2 / (1 - eps^2)^2 > 0`).
    pub f_radial: f64,
    /// Tangential component, positive along `e_t = (-sin phi, cos phi)` (the direction of
    /// rotation seen from the line of centres).
    pub f_tangential: f64,
    /// Eccentricity ratio `eps = sqrt(x^2 + y^2)`.
    pub eccentricity: f64,
    /// Direction `phi` of the journal centre (of the minimum film), radians.
    pub position_angle: f64,
    /// Attitude angle between the force's line of action (reversed) and the line of
    /// centres: `atan2(f_tangential, f_radial)`.
    pub attitude: f64,
    /// Sommerfeld number of the film force as the load: `S = mu N L D (R/c)^2 / W =
    /// 1 / (pi |F| / F_S)`.
    pub sommerfeld: f64,
    /// Peak pressure, units `mu w R^2 / c^2`.
    pub p_max: f64,
    /// Minimum film `h_min / c` over the lands, `1 - eps`.
    pub h_min: f64,
    pub pressure: Option<PressureField>,
}

impl FilmForce {
    pub(crate) fn from_xy(state: &JournalState, fx: f64, fy: f64, p_max: f64) -> Self {
        let eps = state.x.hypot(state.y);
        let phi = if eps > 0.0 {
            state.y.atan2(state.x)
        } else {
            0.0
        };
        let (s, c) = phi.sin_cos();
        let f_radial = -(fx * c + fy * s);
        let f_tangential = -fx * s + fy * c;
        FilmForce {
            fx,
            fy,
            f_radial,
            f_tangential,
            eccentricity: eps,
            position_angle: phi,
            attitude: f_tangential.atan2(f_radial),
            sommerfeld: 1.0 / (PI * fx.hypot(fy)),
            p_max,
            h_min: 1.0 - eps,
            pressure: None,
        }
    }
}

enum SolverKind {
    Short,
    Long,
    Finite(Box<FiniteSolver>),
    Narrow(Box<NarrowSolver>),
}

/// Evaluates the film force of one bearing, reusing whatever the model can reuse.
pub struct FilmSolver {
    bearing: Bearing,
    kind: SolverKind,
}

impl FilmSolver {
    pub fn bearing(&self) -> &Bearing {
        &self.bearing
    }

    /// The film force at `state`; with `want_field` the pressure field too (the closed
    /// forms sample theirs on a 128 x 32 grid).
    pub fn force(&mut self, state: &JournalState, want_field: bool) -> Result<FilmForce> {
        check_state(state)?;
        let lambda = self.bearing.lambda;
        let cav = self.bearing.cavitation;
        match &mut self.kind {
            SolverKind::Short => Ok(short::force(lambda, cav, state, want_field)),
            SolverKind::Long => Ok(long::force(lambda, cav, state, want_field)),
            SolverKind::Finite(s) => s.force(state, want_field),
            SolverKind::Narrow(s) => s.force(state, want_field),
        }
    }

    /// `dF/d(x, y, x', y')` rows `[dF_x; dF_y]` from one factorisation where the model allows
    /// it (finite and narrow-groove models, half-Sommerfeld or full film); `None` otherwise.
    pub fn force_derivatives(
        &mut self,
        state: &JournalState,
    ) -> Result<Option<(FilmForce, [[f64; 4]; 2])>> {
        check_state(state)?;
        match &mut self.kind {
            SolverKind::Finite(s) => s.linearise(state),
            SolverKind::Narrow(s) => s.linearise(state),
            _ => Ok(None),
        }
    }

    /// Along a trajectory: reuse an old factor as the conjugate-gradient preconditioner of
    /// the grooved finite film, to relative residual `tol` (`None`: factor every time). No
    /// effect on the other models.
    pub fn set_factor_reuse(&mut self, tol: Option<f64>) {
        if let SolverKind::Finite(s) = &mut self.kind {
            s.set_factor_reuse(tol);
        }
    }

    /// Just `(F_x, F_y)`.
    pub fn force_xy(&mut self, state: &JournalState) -> Result<[f64; 2]> {
        let f = self.force(state, false)?;
        Ok([f.fx, f.fy])
    }
}

/// The finite-volume grid's own limits (grooves add theirs for the resolved model).
fn check_grid(n_theta: usize, n_zeta: usize) -> Result<()> {
    if n_theta < 8 {
        return Err(Error::param_range(
            "grid.n_theta",
            format!("must be at least 8, got {n_theta}"),
            "integer >= 8",
        ));
    }
    if n_zeta < 2 || !n_zeta.is_multiple_of(2) {
        return Err(Error::param_range(
            "grid.n_zeta",
            format!(
                "must be even and at least 2 (cells must not straddle the mid-plane), got {n_zeta}"
            ),
            "even integer >= 2",
        ));
    }
    Ok(())
}

fn check_state(s: &JournalState) -> Result<()> {
    for (name, v) in [("vx", s.vx), ("vy", s.vy), ("tau", s.tau)] {
        if !v.is_finite() {
            return Err(Error::param(name, format!("must be finite, got {v}")));
        }
    }
    let eps = s.x.hypot(s.y);
    if !eps.is_finite() || eps >= 1.0 {
        return Err(Error::param_range(
            "eccentricity",
            format!("the journal must be inside the clearance circle, got eps = {eps}"),
            "[0, 1)",
        ));
    }
    Ok(())
}
