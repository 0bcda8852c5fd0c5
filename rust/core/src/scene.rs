//! A scene: the planar balancer plus the physical effects a user switches on, composed
//! so that an effect that is off costs nothing (a scene without effects is never built:
//! callers use [`Planar`] directly).
//!
//! Effects, derived from the Lagrangian in the disk-fixed frame (nondimensional as in
//! `model.md`: lengths over `e`, time over `1/w_n`, forces over `M e w_n^2`). The disk
//! turns by `theta(t)` with `theta' = Omega(t)`; a point at rotating-frame position `p`
//! has absolute acceleration `p'' + 2 Omega J p' + Omega' J p - Omega^2 p` (`J` the
//! quarter turn), so a varying spin adds the `Omega'` terms below to the planar
//! equations, whose `Omega` becomes `Omega(t)`:
//!
//! * x row: `- Omega' y - sum m_i Omega' sin b_i`;
//! * y row: `+ Omega' x + mu Omega' + sum m_i Omega' cos b_i`;
//! * ball row i (divided by `m_i`): `+ Omega' (delta + x cos b_i + y sin b_i)`.
//!
//! Ball springs: neighbouring balls (a ring, ball n to ball 1) joined by circumferential
//! springs of stiffness `k_d` and rest spacing `2 pi / n`: potential
//! `V = kappa delta^2 / 2 sum_j (b_{j+1} - b_j - 2 pi / n)^2` with `kappa = k_d / k`, and
//! ball row i gains `dV/db_i / m_i`.
//!
//! Ground-fixed forces `F = (F_X, F_Y)` act in the rotating frame as
//! `(cos th F_X + sin th F_Y, -sin th F_X + cos th F_Y)`. Gravity (spin axis
//! horizontal, `g` over `e w_n^2`) pulls every mass along `-Y`: the support rows gain
//! `g sin th` and `g cos th`, ball row i gains `g cos(th + b_i)`. An impulsive load on the
//! rotor (seed 002's form) `F(t) = A exp(-s (t - t0)^2)` along the ground direction at
//! angle `psi` enters the support rows only.

use crate::error::{check_range, Error, Result};
use crate::model::{Dynamics, Planar};
use std::f64::consts::PI;

/// A change of spin speed from the scene's `Omega` to `to`, linear over `duration`
/// starting at `start` (a run-up, or seed 001's speed disturbance).
#[derive(Debug, Clone, PartialEq)]
pub struct Ramp {
    pub to: f64,
    pub start: f64,
    pub duration: f64,
}

/// `F(t) = amplitude exp(-sharpness (t - t0)^2)` along the ground direction `angle`.
#[derive(Debug, Clone, PartialEq)]
pub struct Impulse {
    pub amplitude: f64,
    pub t0: f64,
    pub sharpness: f64,
    pub angle: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    pub planar: Planar,
    /// `k_d / k`; 0 for no springs.
    pub springs: f64,
    pub ramp: Option<Ramp>,
    /// `g / (e w_n^2)`; 0 for a vertical spin axis.
    pub gravity: f64,
    pub impulse: Option<Impulse>,
}

impl Scene {
    pub fn new(
        planar: Planar,
        springs: f64,
        ramp: Option<Ramp>,
        gravity: f64,
        impulse: Option<Impulse>,
    ) -> Result<Self> {
        check_range("springs", springs, 0.0, false, f64::INFINITY, true)?;
        if springs > 0.0 && planar.n_balls() < 2 {
            return Err(Error::param(
                "springs",
                "ball springs need at least 2 balls",
            ));
        }
        if let Some(r) = &ramp {
            check_range("ramp.to", r.to, 0.0, true, f64::INFINITY, true)?;
            check_range(
                "ramp.start",
                r.start,
                f64::NEG_INFINITY,
                true,
                f64::INFINITY,
                true,
            )?;
            check_range("ramp.duration", r.duration, 0.0, true, f64::INFINITY, true)?;
        }
        check_range("gravity", gravity, 0.0, false, f64::INFINITY, true)?;
        if let Some(f) = &impulse {
            for (name, v) in [
                ("impulse.amplitude", f.amplitude),
                ("impulse.t0", f.t0),
                ("impulse.angle", f.angle),
            ] {
                check_range(name, v, f64::NEG_INFINITY, true, f64::INFINITY, true)?;
            }
            check_range(
                "impulse.sharpness",
                f.sharpness,
                0.0,
                true,
                f64::INFINITY,
                true,
            )?;
        }
        Ok(Scene {
            planar,
            springs,
            ramp,
            gravity,
            impulse,
        })
    }

    /// `(Omega(t), Omega'(t), theta(t))`, with `theta(0) = 0`.
    #[inline]
    pub fn spin(&self, t: f64) -> (f64, f64, f64) {
        let w0 = self.planar.omega_s;
        match &self.ramp {
            None => (w0, 0.0, w0 * t),
            Some(r) => {
                let rate = (r.to - w0) / r.duration;
                let end = r.start + r.duration;
                if t < r.start {
                    (w0, 0.0, w0 * t)
                } else if t < end {
                    let u = t - r.start;
                    (w0 + rate * u, rate, w0 * t + 0.5 * rate * u * u)
                } else {
                    let th_end = w0 * end + 0.5 * rate * r.duration * r.duration;
                    (r.to, 0.0, th_end + r.to * (t - end))
                }
            }
        }
    }

    /// The ground-frame force on the rotor other than gravity.
    #[inline]
    fn load(&self, t: f64) -> (f64, f64) {
        match &self.impulse {
            None => (0.0, 0.0),
            Some(f) => {
                let a = f.amplitude * (-f.sharpness * (t - f.t0).powi(2)).exp();
                (a * f.angle.cos(), a * f.angle.sin())
            }
        }
    }

    /// Spring spacing of spring `j` (ball j to ball j + 1, the last one closing the ring).
    #[inline]
    fn spacing(&self, q: &[f64], j: usize) -> f64 {
        let n = self.planar.n_balls();
        let rest = 2.0 * PI / n as f64;
        if j + 1 < n {
            q[3 + j] - q[2 + j] - rest
        } else {
            q[2] + 2.0 * PI - q[2 + j] - rest
        }
    }

    fn add_effects(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let p = &self.planar;
        let n = p.n_balls();
        let (_, dom, th) = self.spin(t);
        if dom != 0.0 {
            let (x, y) = (q[0], q[1]);
            out[0] -= dom * y;
            out[1] += dom * (x + p.mu);
            for i in 0..n {
                let (s, c) = q[2 + i].sin_cos();
                let mi = p.m(i);
                out[0] -= mi * dom * s;
                out[1] += mi * dom * c;
                out[2 + i] += dom * (p.delta + x * c + y * s);
            }
        }
        if self.springs > 0.0 {
            let kd = self.springs * p.delta * p.delta;
            for j in 0..n {
                let f = kd * self.spacing(q, j);
                let b = (j + 1) % n;
                // dV/db_j = -k s_j, dV/db_{j+1} = +k s_j
                out[2 + j] -= f / p.m(j);
                out[2 + b] += f / p.m(b);
            }
        }
        let (lx, ly) = self.load(t);
        if self.gravity != 0.0 || lx != 0.0 || ly != 0.0 {
            let (sn, cs) = th.sin_cos();
            let (fx, fy) = (lx, ly - self.gravity);
            out[0] -= cs * fx + sn * fy;
            out[1] -= -sn * fx + cs * fy;
            if self.gravity != 0.0 {
                for i in 0..n {
                    out[2 + i] += self.gravity * (th + q[2 + i]).cos();
                }
            }
        }
    }
}

impl Dynamics for Scene {
    fn ndof(&self) -> usize {
        self.planar.ndof()
    }

    fn residual(&self, t: f64, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]) {
        let (om, _, _) = self.spin(t);
        self.planar.forces_at(om, q, v, out);
        self.planar.add_inertia(q, a, out);
        self.add_effects(t, q, out);
    }

    fn jacobians(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        k: &mut [f64],
        c: &mut [f64],
        m: &mut [f64],
    ) {
        let p = &self.planar;
        let (om, dom, th) = self.spin(t);
        p.jacobians_at(om, q, v, a, k, c, m);
        let n = p.n_balls();
        let d = n + 2;
        if dom != 0.0 {
            k[1] -= dom;
            k[d] += dom;
            for i in 0..n {
                let j = 2 + i;
                let (s, cs) = q[j].sin_cos();
                let mi = p.m(i);
                k[j] -= mi * dom * cs;
                k[d + j] -= mi * dom * s;
                k[j * d] += dom * cs;
                k[j * d + 1] += dom * s;
                k[j * d + j] += dom * (-q[0] * s + q[1] * cs);
            }
        }
        if self.springs > 0.0 {
            let kd = self.springs * p.delta * p.delta;
            for jj in 0..n {
                let b = (jj + 1) % n;
                let (ra, rb) = (2 + jj, 2 + b);
                // Hessian of kd/2 (b_b - b_a - rest)^2, rows divided by the ball's m.
                let (ma, mb) = (p.m(jj), p.m(b));
                k[ra * d + ra] += kd / ma;
                k[ra * d + rb] -= kd / ma;
                k[rb * d + rb] += kd / mb;
                k[rb * d + ra] -= kd / mb;
            }
        }
        if self.gravity != 0.0 {
            for i in 0..n {
                let j = 2 + i;
                k[j * d + j] -= self.gravity * (th + q[j]).sin();
            }
        }
    }

    fn solve_mass(&self, t: f64, q: &[f64], rhs: &mut [f64]) {
        self.planar.solve_mass(t, q, rhs);
    }

    fn solve_mass_columns(&self, t: f64, q: &[f64], cols: &mut [f64]) {
        self.planar.solve_mass_columns(t, q, cols);
    }

    fn accel(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        let d = self.ndof();
        let zero = [0.0; 16];
        let heap: Vec<f64>;
        let a: &[f64] = if d <= 16 {
            &zero[..d]
        } else {
            heap = vec![0.0; d];
            &heap
        };
        self.residual(t, q, v, a, out);
        for o in out.iter_mut() {
            *o = -*o;
        }
        self.planar.solve_mass(t, q, out);
    }

    fn time_dependence(&self) -> Option<String> {
        if self.ramp.is_some() {
            Some("ramp".into())
        } else if self.gravity != 0.0 {
            Some("gravity".into())
        } else if self.impulse.is_some() {
            Some("impulse".into())
        } else {
            None
        }
    }

    fn base_spin(&self) -> f64 {
        self.planar.omega_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn planar() -> Planar {
        Planar::new(0.2, 0.05, &[0.07, 0.05, 0.06], 50.0, 1.3, &[0.9, 1.1, 0.8]).unwrap()
    }

    fn state() -> ([f64; 5], [f64; 5], [f64; 5]) {
        (
            [0.3, -0.2, 0.7, -1.9, 2.4],
            [0.1, 0.4, -1.2, 0.3, 0.2],
            [0.05, -0.3, 0.2, 0.6, -0.1],
        )
    }

    #[test]
    fn effects_off_equal_the_planar_model() {
        let p = planar();
        let (q, v, a) = state();
        let ramp = Some(Ramp {
            to: 1.3,
            start: 0.0,
            duration: 5.0,
        });
        let imp = Some(Impulse {
            amplitude: 0.0,
            t0: 1.0,
            sharpness: 3.0,
            angle: 0.4,
        });
        let s = Scene::new(p.clone(), 0.0, ramp, 0.0, imp).unwrap();
        let (mut r1, mut r2) = ([0.0; 5], [0.0; 5]);
        for t in [0.0, 1.0, 2.5, 7.0] {
            p.residual(t, &q, &v, &a, &mut r1);
            s.residual(t, &q, &v, &a, &mut r2);
            for (x, y) in r1.iter().zip(&r2) {
                assert!((x - y).abs() < 1e-14, "{r1:?} {r2:?}");
            }
        }
    }

    #[test]
    fn jacobians_match_finite_differences() {
        let s = Scene::new(
            planar(),
            0.3,
            Some(Ramp {
                to: 2.0,
                start: -1.0,
                duration: 4.0,
            }),
            0.7,
            Some(Impulse {
                amplitude: 2.0,
                t0: 0.5,
                sharpness: 2.0,
                angle: 0.3,
            }),
        )
        .unwrap();
        let (q, v, a) = state();
        let t = 0.8;
        let d = 5;
        let (mut k, mut c, mut m) = (vec![0.0; 25], vec![0.0; 25], vec![0.0; 25]);
        s.jacobians(t, &q, &v, &a, &mut k, &mut c, &mut m);
        let h = 1e-6;
        for (which, jac) in [(0, &k), (1, &c), (2, &m)] {
            for j in 0..d {
                let (mut qp, mut vp, mut ap) = (q, v, a);
                let (mut qm, mut vm, mut am) = (q, v, a);
                match which {
                    0 => {
                        qp[j] += h;
                        qm[j] -= h;
                    }
                    1 => {
                        vp[j] += h;
                        vm[j] -= h;
                    }
                    _ => {
                        ap[j] += h;
                        am[j] -= h;
                    }
                }
                let (mut rp, mut rm) = ([0.0; 5], [0.0; 5]);
                s.residual(t, &qp, &vp, &ap, &mut rp);
                s.residual(t, &qm, &vm, &am, &mut rm);
                for i in 0..d {
                    let fd = (rp[i] - rm[i]) / (2.0 * h);
                    assert!(
                        (fd - jac[i * d + j]).abs() < 1e-6 * (1.0 + fd.abs()),
                        "jacobian {which} [{i}][{j}]: fd {fd} analytic {}",
                        jac[i * d + j]
                    );
                }
            }
        }
    }

    #[test]
    fn spin_profile_is_continuous_and_integrates() {
        let s = Scene::new(
            planar(),
            0.0,
            Some(Ramp {
                to: 2.3,
                start: 1.0,
                duration: 2.0,
            }),
            0.0,
            None,
        )
        .unwrap();
        // theta' = Omega, checked by central differences across the three pieces
        for t in [0.5, 1.0, 1.7, 3.0, 4.2] {
            let h = 1e-6;
            let (w, _, _) = s.spin(t);
            let d = (s.spin(t + h).2 - s.spin(t - h).2) / (2.0 * h);
            assert!((d - w).abs() < 1e-6, "t {t}: {d} vs {w}");
        }
        assert_eq!(s.spin(10.0).0, 2.3);
        assert_eq!(s.time_dependence().as_deref(), Some("ramp"));
    }

    #[test]
    fn bad_effect_parameters_name_themselves() {
        let e = Scene::new(planar(), -1.0, None, 0.0, None).unwrap_err();
        assert!(e.to_string().starts_with("springs"), "{e}");
        let one = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.3, &[1.0]).unwrap();
        let e = Scene::new(one, 0.5, None, 0.0, None).unwrap_err();
        assert!(e.to_string().starts_with("springs"), "{e}");
        let r = Some(Ramp {
            to: 1.0,
            start: 0.0,
            duration: 0.0,
        });
        let e = Scene::new(planar(), 0.0, r, 0.0, None).unwrap_err();
        assert!(e.to_string().starts_with("ramp.duration"), "{e}");
    }
}
