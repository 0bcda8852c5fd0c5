//! Static equilibrium, linearised stiffness and damping, and the whirl threshold of a rigid
//! rotor (fixed frame, no balls) on one bearing.
//!
//! Units: load and forces in `F_S`, displacements in `c`, velocities in `c w`; so `K` is in
//! `F_S / c` and `C` in `F_S / (c w)`. The rigid rotor of mass `M` obeys, with `tau = w t`,
//! `m q'' = f(q, q') + load`, `m = M c w^2 / F_S = M c^3 w / (mu L R^3)` (the classical mass
//! parameter, bearing.md section 4).

use super::{FilmSolver, JournalState};
use crate::error::{Error, Result};
use nalgebra::Matrix2;

/// Static equilibrium of the journal under a load.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Equilibrium {
    pub x: f64,
    pub y: f64,
    pub eccentricity: f64,
    /// Angle from the load direction to the journal's position (radians): the journal
    /// lies at `load angle + attitude`.
    pub attitude: f64,
    pub iterations: usize,
}

/// Linearised film: `f(q0 + dq, dq') ~ f(q0) - K dq - C dq'`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearCoefficients {
    /// `K[(i, j)] = -df_i/dq_j` (x, y fixed frame), units `F_S / c`.
    pub k: Matrix2<f64>,
    /// `C[(i, j)] = -df_i/dq'_j`, units `F_S / (c w)`.
    pub c: Matrix2<f64>,
}

/// Whirl threshold of a rigid rotor on the linearised film.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WhirlStability {
    /// Critical mass parameter `m* = M c w^2 / F_S` at the threshold (infinite: stable at
    /// every speed; 0: unstable at every speed).
    pub critical_mass: f64,
    /// Whirl frequency over spin frequency at the threshold.
    pub whirl_ratio: f64,
    /// Threshold speed in units `sqrt(W / (M c))` for the load `W = |load| F_S`
    /// (`w_th = sqrt(m* / |load|)` in those units).
    pub threshold_speed: f64,
}

/// Journal position where the film carries `load` (units `F_S`, fixed frame), by Newton on
/// `(x, y)` with a central-difference Jacobian and a backtracking line search inside the
/// clearance circle.
pub fn equilibrium(solver: &mut FilmSolver, load: [f64; 2]) -> Result<Equilibrium> {
    let w = load[0].hypot(load[1]);
    if !(w.is_finite() && w > 0.0) {
        return Err(Error::param_range(
            "load",
            format!("must be a finite nonzero vector, got {load:?}"),
            "|load| > 0",
        ));
    }
    let res = |s: &mut FilmSolver, q: [f64; 2]| -> Result<[f64; 2]> {
        let f = s.force_xy(&JournalState::at(q[0], q[1]))?;
        Ok([f[0] + load[0], f[1] + load[1]])
    };
    // Start half way out along the load, where every plain film has a restoring component.
    let mut q = [0.5 * load[0] / w, 0.5 * load[1] / w];
    let mut r = res(solver, q)?;
    let tol = 1e-11 * w.max(1e-3);
    for it in 0..100 {
        let norm = r[0].hypot(r[1]);
        if norm < tol {
            let eps = q[0].hypot(q[1]);
            return Ok(Equilibrium {
                x: q[0],
                y: q[1],
                eccentricity: eps,
                attitude: wrap(q[1].atan2(q[0]) - load[1].atan2(load[0])),
                iterations: it,
            });
        }
        let h = 1e-6;
        let mut jac = Matrix2::zeros();
        for k in 0..2 {
            let (mut qp, mut qm) = (q, q);
            qp[k] += h;
            qm[k] -= h;
            let (rp, rm) = (res(solver, qp)?, res(solver, qm)?);
            jac[(0, k)] = (rp[0] - rm[0]) / (2.0 * h);
            jac[(1, k)] = (rp[1] - rm[1]) / (2.0 * h);
        }
        let step = jac
            .lu()
            .solve(&nalgebra::Vector2::new(-r[0], -r[1]))
            .ok_or_else(|| Error::Integration("equilibrium: singular film Jacobian".into()))?;
        let mut t = 1.0;
        loop {
            let cand = [q[0] + t * step[0], q[1] + t * step[1]];
            if cand[0].hypot(cand[1]) < 0.995 {
                let rc = res(solver, cand)?;
                if rc[0].hypot(rc[1]) < norm || t < 1e-4 {
                    q = cand;
                    r = rc;
                    break;
                }
            }
            t *= 0.5;
            if t < 1e-6 {
                return Err(Error::Integration(
                    "equilibrium: line search failed (load beyond the film's capacity?)".into(),
                ));
            }
        }
    }
    Err(Error::Integration(
        "equilibrium: Newton did not converge in 100 iterations".into(),
    ))
}

fn wrap(a: f64) -> f64 {
    use std::f64::consts::PI;
    (a + PI).rem_euclid(2.0 * PI) - PI
}

/// Linearised stiffness and damping at a static position: for the finite and narrow-groove
/// models (half-Sommerfeld or full film) the derivatives of the discrete force from one
/// factorisation ([`super::FiniteSolver::linearise`], [`super::NarrowSolver::linearise`]),
/// otherwise central differences of the force.
pub fn linear_coefficients(solver: &mut FilmSolver, x: f64, y: f64) -> Result<LinearCoefficients> {
    if let Some((_, d)) = solver.force_derivatives(&JournalState::at(x, y))? {
        let mut k = Matrix2::zeros();
        let mut c = Matrix2::zeros();
        for i in 0..2 {
            for j in 0..2 {
                k[(i, j)] = -d[i][j];
                c[(i, j)] = -d[i][2 + j];
            }
        }
        return Ok(LinearCoefficients { k, c });
    }
    linear_coefficients_fd(solver, x, y)
}

/// Linearised stiffness and damping by central differences of the nonlinear force (step
/// `1e-6` in `c` and `c w`).
pub fn linear_coefficients_fd(
    solver: &mut FilmSolver,
    x: f64,
    y: f64,
) -> Result<LinearCoefficients> {
    let h = 1e-6;
    let mut k = Matrix2::zeros();
    let mut c = Matrix2::zeros();
    for j in 0..4 {
        let mut sp = JournalState::at(x, y);
        let mut sm = sp;
        match j {
            0 => (sp.x, sm.x) = (x + h, x - h),
            1 => (sp.y, sm.y) = (y + h, y - h),
            2 => (sp.vx, sm.vx) = (h, -h),
            _ => (sp.vy, sm.vy) = (h, -h),
        }
        let (fp, fm) = (solver.force_xy(&sp)?, solver.force_xy(&sm)?);
        for i in 0..2 {
            let d = -(fp[i] - fm[i]) / (2.0 * h);
            if j < 2 {
                k[(i, j)] = d;
            } else {
                c[(i, j - 2)] = d;
            }
        }
    }
    Ok(LinearCoefficients { k, c })
}

impl LinearCoefficients {
    /// Eigenvalues `(re, im)` (units `w`) of `m dq'' + C dq' + K dq = 0`, by decreasing real
    /// part (faer's QR; nalgebra's Schur can stall on these matrices).
    pub fn eigenvalues(&self, mass: f64) -> Result<Vec<(f64, f64)>> {
        let mut a = [0.0; 16];
        a[2] = 1.0;
        a[4 + 3] = 1.0;
        for i in 0..2 {
            for j in 0..2 {
                a[(2 + i) * 4 + j] = -self.k[(i, j)] / mass;
                a[(2 + i) * 4 + 2 + j] = -self.c[(i, j)] / mass;
            }
        }
        crate::numerics::linalg::eigenvalues(&a, 4)
            .ok_or_else(|| Error::Eigen("rigid rotor on the film: QR iteration failed".into()))
    }
}

/// Whirl threshold from the linear coefficients (Lund's closed form for a rigid rotor on
/// one film). At the threshold `s = i nu`: `(K - m nu^2 + i nu C) v = 0`. Its real and
/// imaginary parts give the equivalent stiffness
/// `K_eq = (K_xx C_yy + K_yy C_xx - K_xy C_yx - K_yx C_xy) / (C_xx + C_yy)`
/// and the whirl ratio `nu^2 = ((K_xx - K_eq)(K_yy - K_eq) - K_xy K_yx) / (C_xx C_yy - C_xy C_yx)`,
/// and `m* = K_eq / nu^2`. No positive `nu^2` with `K_eq > 0` means no crossing: stable at
/// every speed if stable at low speed; `K_eq <= 0` with a real whirl means unstable at every speed.
pub fn rigid_rotor_stability(lc: &LinearCoefficients, load: f64) -> WhirlStability {
    let (k, c) = (&lc.k, &lc.c);
    let k_eq = (k[(0, 0)] * c[(1, 1)] + k[(1, 1)] * c[(0, 0)]
        - k[(0, 1)] * c[(1, 0)]
        - k[(1, 0)] * c[(0, 1)])
        / (c[(0, 0)] + c[(1, 1)]);
    let nu2 = ((k[(0, 0)] - k_eq) * (k[(1, 1)] - k_eq) - k[(0, 1)] * k[(1, 0)])
        / (c[(0, 0)] * c[(1, 1)] - c[(0, 1)] * c[(1, 0)]);
    let (critical_mass, whirl_ratio) = if nu2 <= 0.0 {
        (f64::INFINITY, f64::NAN)
    } else if k_eq <= 0.0 {
        (0.0, nu2.sqrt())
    } else {
        (k_eq / nu2, nu2.sqrt())
    };
    WhirlStability {
        critical_mass,
        whirl_ratio,
        threshold_speed: (critical_mass / load).sqrt(),
    }
}
