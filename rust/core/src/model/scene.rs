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
//! Ball springs: neighbouring balls joined by circumferential springs of stiffness `k_d`
//! and rest spacing `2 pi / n`: potential
//! `V = kappa delta^2 / 2 sum_j (b_{j+1} - b_j - 2 pi / n)^2` with `kappa = k_d / k`, and
//! ball row i gains `dV/db_i / m_i`. In a ring (the default) `j` runs over all `n`
//! neighbours, ball n to ball 1 closing it with spacing `b_1 + 2 pi - b_n`; seed 004's
//! chain (its eq. 16) has the `n - 1` springs from ball 1 to ball n only. For two balls
//! the ring's two springs are the chain's one at twice the stiffness.
//!
//! Ground-fixed forces `F = (F_X, F_Y)` act in the rotating frame as
//! `(cos th F_X + sin th F_Y, -sin th F_X + cos th F_Y)`. Gravity (spin axis
//! horizontal, `g` over `e w_n^2`) pulls every mass along `-Y`: the support rows gain
//! `g sin th` and `g cos th`, ball row i gains `g cos(th + b_i)`. An impulsive load on the
//! rotor (seed 002's form) `F(t) = A exp(-s (t - t0)^2)` along the ground direction at
//! angle `psi` enters the support rows only.
//!
//! Tilting disk on a flexible shaft (seed 004): coordinates `(x, y, A, B, b_1..b_n)`,
//! where `A, B` are the disk's Euler tilts scaled by `delta` (the rim's axial
//! displacement over `e`). The rotor and ball terms, including spin ramp and gravity,
//! come from `scripts/derive_tilt.py`, which derives them from the Lagrangian and
//! writes [`crate::model::tilt_terms`]; springs and the impulsive load are added here as for
//! the planar disk. The shaft is massless, simply supported, the disk at distances
//! `a`, `b` (over `r_t`) from the bearings: beam theory gives the translational
//! stiffness `k = 3 E I (1/a^3 + 1/b^3)` (the `k` of `w_n`), the coupling
//! `kappa_c = a b (a - b) / (a^2 - a b + b^2)` and tilt stiffness
//! `kappa_t = a^2 b^2 / (a^2 - a b + b^2)` (over `k r_t` and `k r_t^2`). With `a = b`
//! the coupling vanishes and a disk started flat stays flat: the planar equations.

use crate::error::{check_range, Error, Result};
use crate::model::tilt_terms::{
    ball_jacobians, ball_mass, ball_residual, rotor_jacobians, rotor_mass, rotor_residual,
    RotorConsts,
};
use crate::model::{Dynamics, Planar};
use nalgebra::DMatrix;
use std::f64::consts::PI;

/// A disk that tilts on a flexible shaft, with gyroscopic coupling (seed 004).
#[derive(Debug, Clone, PartialEq)]
pub struct Tilt {
    /// Distance of the disk from the first bearing, over the track radius.
    pub a: f64,
    /// Distance of the disk from the second bearing, over the track radius.
    pub b: f64,
    /// Transverse moment of inertia of the disk about its mass centre, over `M r_t^2`.
    pub j_t: f64,
    /// Polar moment of inertia of the disk, over `M r_t^2`.
    pub j_z: f64,
    /// Damping ratio of the tilt: `c_r / (2 sqrt(J_t k_phiphi))`, acting on the disk
    /// normal's rate in the ground frame.
    pub zeta_r: f64,
}

impl Tilt {
    fn validate(&self) -> Result<()> {
        check_range("tilt.a", self.a, 0.0, true, f64::INFINITY, true)?;
        check_range("tilt.b", self.b, 0.0, true, f64::INFINITY, true)?;
        check_range("tilt.j_t", self.j_t, 0.0, true, f64::INFINITY, true)?;
        check_range("tilt.j_z", self.j_z, 0.0, false, 2.0 * self.j_t, false)
            .map_err(|_| {
                Error::param(
                    "tilt.j_z",
                    format!(
                        "must be in [0, 2 j_t] = [0, {}] (a rigid body's polar moment is at most the sum of the other two), got {}",
                        2.0 * self.j_t,
                        self.j_z
                    ),
                )
            })?;
        check_range("tilt.zeta_r", self.zeta_r, 0.0, false, f64::INFINITY, true)
    }

    /// Translation–tilt coupling stiffness `kappa_c` of the simply supported shaft.
    pub fn kappa_c(&self) -> f64 {
        let (a, b) = (self.a, self.b);
        a * b * (a - b) / (a * a - a * b + b * b)
    }

    /// Tilt stiffness `kappa_t` of the simply supported shaft.
    pub fn kappa_t(&self) -> f64 {
        let (a, b) = (self.a, self.b);
        a * a * b * b / (a * a - a * b + b * b)
    }
}

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

/// How the ball springs join the balls.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SpringLayout {
    /// `n` springs round the track, the last from ball n to ball 1.
    #[default]
    Ring,
    /// `n - 1` springs, ball 1 to 2, ..., n - 1 to n (seed 004).
    Chain,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    pub planar: Planar,
    /// `k_d / k`; 0 for no springs.
    pub springs: f64,
    /// Ring (default) or chain; set with [`Scene::with_spring_layout`].
    pub spring_layout: SpringLayout,
    pub ramp: Option<Ramp>,
    /// `g / (e w_n^2)`; 0 for a vertical spin axis.
    pub gravity: f64,
    pub impulse: Option<Impulse>,
    pub tilt: Option<Tilt>,
}

impl Scene {
    pub fn new(
        planar: Planar,
        springs: f64,
        ramp: Option<Ramp>,
        gravity: f64,
        impulse: Option<Impulse>,
        tilt: Option<Tilt>,
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
        if let Some(tl) = &tilt {
            tl.validate()?;
        }
        Ok(Scene {
            planar,
            springs,
            spring_layout: SpringLayout::Ring,
            ramp,
            gravity,
            impulse,
            tilt,
        })
    }

    /// The tilting rotor's constants, derived from the public fields on every call (a
    /// few flops beside the generated terms), so a scene changed in place never carries
    /// stale ones. `None` for a planar disk.
    #[inline]
    fn rotor_consts(&self) -> Option<RotorConsts> {
        let tl = self.tilt.as_ref()?;
        let p = &self.planar;
        let balls: f64 = (0..p.n_balls()).map(|i| p.m(i)).sum::<f64>() / p.delta;
        let kt = tl.kappa_t();
        Some(RotorConsts {
            mh: (1.0 - p.mu - balls).max(0.0),
            mu: p.mu,
            dl: p.delta,
            idl: 1.0 / p.delta,
            jt: tl.j_t,
            jz: tl.j_z,
            kc: tl.kappa_c(),
            kt,
            cr: 2.0 * tl.zeta_r * (kt * tl.j_t).sqrt(),
            zeta: p.zeta,
            g: self.gravity,
        })
    }

    /// The same scene with its springs joined as `layout`.
    pub fn with_spring_layout(mut self, layout: SpringLayout) -> Self {
        self.spring_layout = layout;
        self
    }

    /// Number of ball springs (when `springs > 0`).
    #[inline]
    fn n_springs(&self) -> usize {
        let n = self.planar.n_balls();
        match self.spring_layout {
            SpringLayout::Ring => n,
            SpringLayout::Chain => n - 1,
        }
    }

    /// Returns a copy with one named parameter changed (scans and continuation): the
    /// planar balancer's names, `springs`, `gravity`, and the tilt's `a`, `b`, `j_t`,
    /// `j_z`, `zeta_r`. The copy is rebuilt and revalidated, so the rotor constants
    /// derived from the tilt follow the change.
    pub fn with_param(&self, name: &str, value: f64) -> Result<Self> {
        let mut planar = self.planar.clone();
        let mut springs = self.springs;
        let mut gravity = self.gravity;
        let mut tilt = self.tilt.clone();
        match name {
            "springs" => springs = value,
            "gravity" => gravity = value,
            "a" | "b" | "j_t" | "j_z" | "zeta_r" => {
                let Some(t) = tilt.as_mut() else {
                    return Err(Error::param(
                        name,
                        "is a tilt parameter, and the scene has no tilting disk",
                    ));
                };
                match name {
                    "a" => t.a = value,
                    "b" => t.b = value,
                    "j_t" => t.j_t = value,
                    "j_z" => t.j_z = value,
                    _ => t.zeta_r = value,
                }
            }
            _ => {
                planar = self.planar.with_param(name, value).map_err(|e| match e {
                    Error::InvalidParameter {
                        name: n, message, ..
                    } if message.starts_with("is not a") => Error::param(
                        n,
                        "is not a parameter of the scene (mu, zeta, zeta_b, delta, Omega, \
                             eta, eta[i], zeta_b[i], springs, gravity; with a tilting disk \
                             a, b, j_t, j_z, zeta_r)",
                    ),
                    e => e,
                })?
            }
        }
        Scene::new(
            planar,
            springs,
            self.ramp.clone(),
            gravity,
            self.impulse.clone(),
            tilt,
        )
        .map(|s| s.with_spring_layout(self.spring_layout))
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

    /// Index of the first ball angle in `q`.
    #[inline]
    fn off(&self) -> usize {
        if self.tilt.is_some() {
            4
        } else {
            2
        }
    }

    /// Spring spacing of spring `j` (ball j to ball j + 1, the last one closing the ring).
    #[inline]
    fn spacing(&self, q: &[f64], j: usize) -> f64 {
        let n = self.planar.n_balls();
        let o = self.off();
        let rest = 2.0 * PI / n as f64;
        if j + 1 < n {
            q[o + 1 + j] - q[o + j] - rest
        } else {
            q[o] + 2.0 * PI - q[o + j] - rest
        }
    }

    fn add_springs(&self, q: &[f64], out: &mut [f64]) {
        let p = &self.planar;
        let (n, o) = (p.n_balls(), self.off());
        let kd = self.springs * p.delta * p.delta;
        for j in 0..self.n_springs() {
            let f = kd * self.spacing(q, j);
            let b = (j + 1) % n;
            // dV/db_j = -k s_j, dV/db_{j+1} = +k s_j
            out[o + j] -= f / p.m(j);
            out[o + b] += f / p.m(b);
        }
    }

    fn add_spring_jacobian(&self, k: &mut [f64]) {
        let p = &self.planar;
        let (n, o, d) = (p.n_balls(), self.off(), self.ndof());
        let kd = self.springs * p.delta * p.delta;
        for jj in 0..self.n_springs() {
            let b = (jj + 1) % n;
            let (ra, rb) = (o + jj, o + b);
            // Hessian of kd/2 (b_b - b_a - rest)^2, rows divided by the ball's m.
            let (ma, mb) = (p.m(jj), p.m(b));
            k[ra * d + ra] += kd / ma;
            k[ra * d + rb] -= kd / ma;
            k[rb * d + rb] += kd / mb;
            k[rb * d + ra] -= kd / mb;
        }
    }

    /// The seed-002 load on the disk centre, turned into the rotating frame.
    fn add_load(&self, t: f64, th: f64, out: &mut [f64]) {
        let (lx, ly) = self.load(t);
        if lx != 0.0 || ly != 0.0 {
            let (sn, cs) = th.sin_cos();
            out[0] -= cs * lx + sn * ly;
            out[1] -= -sn * lx + cs * ly;
        }
    }

    /// One ball's `(x, y, A, B, b_i)` slice of a tilting state.
    #[inline]
    fn ball_view(x: &[f64], i: usize) -> [f64; 5] {
        [x[0], x[1], x[2], x[3], x[4 + i]]
    }

    fn tilt_residual(
        &self,
        c: &RotorConsts,
        t: f64,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        out: &mut [f64],
    ) {
        let p = &self.planar;
        let spin = self.spin(t);
        rotor_residual(c, spin, q, v, a, out);
        let mut r = [0.0; 5];
        for i in 0..p.n_balls() {
            let (qb, vb, ab) = (
                Self::ball_view(q, i),
                Self::ball_view(v, i),
                Self::ball_view(a, i),
            );
            ball_residual(c, p.zeta_b[i], spin, &qb, &vb, &ab, &mut r);
            let mi = p.m(i);
            for (o, ri) in out[..4].iter_mut().zip(&r[..4]) {
                *o += mi * ri;
            }
            out[4 + i] = r[4];
        }
        if self.springs > 0.0 {
            self.add_springs(q, out);
        }
        self.add_load(t, spin.2, out);
    }

    #[allow(clippy::too_many_arguments)]
    fn tilt_jacobians(
        &self,
        cn: &RotorConsts,
        t: f64,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        k: &mut [f64],
        c: &mut [f64],
        m: &mut [f64],
    ) {
        let p = &self.planar;
        let d = self.ndof();
        let spin = self.spin(t);
        k.fill(0.0);
        c.fill(0.0);
        m.fill(0.0);
        let (mut rk, mut rc, mut rm) = ([0.0; 16], [0.0; 16], [0.0; 16]);
        rotor_jacobians(cn, spin, q, v, a, &mut rk, &mut rc, &mut rm);
        for (big, block) in [(&mut *k, &rk), (&mut *c, &rc), (&mut *m, &rm)] {
            Self::set_rotor_block(d, block, big);
        }
        let (mut bk, mut bc, mut bm) = ([0.0; 25], [0.0; 25], [0.0; 25]);
        for i in 0..p.n_balls() {
            let (qb, vb, ab) = (
                Self::ball_view(q, i),
                Self::ball_view(v, i),
                Self::ball_view(a, i),
            );
            ball_jacobians(
                cn,
                p.zeta_b[i],
                spin,
                &qb,
                &vb,
                &ab,
                &mut bk,
                &mut bc,
                &mut bm,
            );
            for (big, block) in [(&mut *k, &bk), (&mut *c, &bc), (&mut *m, &bm)] {
                self.add_ball_block(i, block, big);
            }
        }
        if self.springs > 0.0 {
            self.add_spring_jacobian(k);
        }
    }

    /// Copies the rotor's 4 x 4 block into the top left of a `d x d` matrix.
    fn set_rotor_block(d: usize, block: &[f64; 16], big: &mut [f64]) {
        for i in 0..4 {
            big[i * d..i * d + 4].copy_from_slice(&block[i * 4..i * 4 + 4]);
        }
    }

    /// Adds ball `i`'s 5 x 5 block (rows and columns x, y, A, B, b_i) to a `d x d`
    /// matrix, its rotor rows scaled by the ball's mass (its own row is already over it).
    fn add_ball_block(&self, i: usize, block: &[f64; 25], big: &mut [f64]) {
        let d = self.ndof();
        let mi = self.planar.m(i);
        let idx = [0, 1, 2, 3, 4 + i];
        for (r, &row) in idx.iter().enumerate() {
            let scale = if r < 4 { mi } else { 1.0 };
            for (s, &col) in idx.iter().enumerate() {
                big[row * d + col] += scale * block[r * 5 + s];
            }
        }
    }

    /// The tilting model's mass matrix `dF/da` (it depends on `q` only).
    fn tilt_mass(&self, q: &[f64]) -> DMatrix<f64> {
        let d = self.ndof();
        let cn = &self.rotor_consts().expect("tilting scene");
        let mut m = vec![0.0; d * d];
        let mut rm = [0.0; 16];
        rotor_mass(cn, q, &mut rm);
        Self::set_rotor_block(d, &rm, &mut m);
        let mut bm = [0.0; 25];
        for i in 0..self.planar.n_balls() {
            ball_mass(cn, &Self::ball_view(q, i), &mut bm);
            self.add_ball_block(i, &bm, &mut m);
        }
        DMatrix::from_row_slice(d, d, &m)
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
            self.add_springs(q, out);
        }
        self.add_load(t, th, out);
        if self.gravity != 0.0 {
            let (sn, cs) = th.sin_cos();
            out[0] += sn * self.gravity;
            out[1] += cs * self.gravity;
            for i in 0..n {
                out[2 + i] += self.gravity * (th + q[2 + i]).cos();
            }
        }
    }
}

impl Dynamics for Scene {
    fn ndof(&self) -> usize {
        self.planar.ndof() + if self.tilt.is_some() { 2 } else { 0 }
    }

    fn first_ball(&self) -> usize {
        self.off()
    }

    fn angles_modulo_turns(&self) -> bool {
        self.springs == 0.0
    }

    fn residual(&self, t: f64, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]) {
        if let Some(c) = &self.rotor_consts() {
            return self.tilt_residual(c, t, q, v, a, out);
        }
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
        if let Some(cn) = &self.rotor_consts() {
            return self.tilt_jacobians(cn, t, q, v, a, k, c, m);
        }
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
            self.add_spring_jacobian(k);
        }
        if self.gravity != 0.0 {
            for i in 0..n {
                let j = 2 + i;
                k[j * d + j] -= self.gravity * (th + q[j]).sin();
            }
        }
    }

    fn solve_mass(&self, t: f64, q: &[f64], rhs: &mut [f64]) {
        if self.tilt.is_none() {
            return self.planar.solve_mass(t, q, rhs);
        }
        self.solve_mass_columns(t, q, rhs);
    }

    fn solve_mass_columns(&self, t: f64, q: &[f64], cols: &mut [f64]) {
        if self.tilt.is_none() {
            return self.planar.solve_mass_columns(t, q, cols);
        }
        let d = self.ndof();
        // M is the kinetic-energy Hessian with rows scaled: never singular.
        let lu = self.tilt_mass(q).lu();
        let mut b = DMatrix::from_column_slice(d, cols.len() / d, cols);
        lu.solve_mut(&mut b);
        cols.copy_from_slice(b.as_slice());
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
        self.solve_mass(t, q, out);
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
        let s = Scene::new(p.clone(), 0.0, ramp, 0.0, imp, None).unwrap();
        let (mut r1, mut r2) = ([0.0; 5], [0.0; 5]);
        for t in [0.0, 1.0, 2.5, 7.0] {
            p.residual(t, &q, &v, &a, &mut r1);
            s.residual(t, &q, &v, &a, &mut r2);
            for (x, y) in r1.iter().zip(&r2) {
                assert!((x - y).abs() < 1e-14, "{r1:?} {r2:?}");
            }
        }
    }

    fn all_effects(tilt: Option<Tilt>) -> Scene {
        Scene::new(
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
            tilt,
        )
        .unwrap()
    }

    fn tilt() -> Tilt {
        Tilt {
            a: 1.5,
            b: 2.5,
            j_t: 0.3,
            j_z: 0.5,
            zeta_r: 0.05,
        }
    }

    fn check_jacobians(s: &Scene, q: &[f64], v: &[f64], a: &[f64]) {
        let t = 0.8;
        let d = s.ndof();
        let (mut k, mut c, mut m) = (vec![0.0; d * d], vec![0.0; d * d], vec![0.0; d * d]);
        s.jacobians(t, q, v, a, &mut k, &mut c, &mut m);
        let h = 1e-5;
        for (which, jac) in [(0, &k), (1, &c), (2, &m)] {
            for j in 0..d {
                let mut plus = [q.to_vec(), v.to_vec(), a.to_vec()];
                let mut minus = plus.clone();
                plus[which][j] += h;
                minus[which][j] -= h;
                let (mut rp, mut rm) = (vec![0.0; d], vec![0.0; d]);
                s.residual(t, &plus[0], &plus[1], &plus[2], &mut rp);
                s.residual(t, &minus[0], &minus[1], &minus[2], &mut rm);
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
    fn spring_chain_is_seed_004s_potential_and_half_a_two_ball_ring() {
        // Chain of three balls: ball rows gain dV/db_i / m_i with
        // V = kd/2 [(b2 - b1 - 2pi/3)^2 + (b3 - b2 - 2pi/3)^2], written out here.
        let p = planar();
        let (q, v, a) = state();
        let k = 0.3;
        let chain = Scene::new(p.clone(), k, None, 0.0, None, None)
            .unwrap()
            .with_spring_layout(SpringLayout::Chain);
        let plain = Scene::new(p.clone(), 0.0, None, 0.0, None, None).unwrap();
        let (mut rc, mut r0) = ([0.0; 5], [0.0; 5]);
        chain.residual(0.0, &q, &v, &a, &mut rc);
        plain.residual(0.0, &q, &v, &a, &mut r0);
        let kd = k * p.delta * p.delta;
        let rest = 2.0 * PI / 3.0;
        let (s1, s2) = (q[3] - q[2] - rest, q[4] - q[3] - rest);
        let dv = [-kd * s1, kd * s1 - kd * s2, kd * s2];
        for i in 0..3 {
            let want = r0[2 + i] + dv[i] / p.m(i);
            assert!(
                (rc[2 + i] - want).abs() < 1e-12 * want.abs().max(1.0),
                "{i}: {} {want}",
                rc[2 + i]
            );
        }
        assert_eq!(&rc[..2], &r0[..2]);
        check_jacobians(&chain, &q, &v, &a);
        // Two balls: the ring's two springs are one spring of twice the stiffness.
        let p2 = Planar::new(0.2, 0.05, &[0.07], 50.0, 1.3, &[0.9, 1.1]).unwrap();
        let ring = Scene::new(p2.clone(), k, None, 0.0, None, None).unwrap();
        let chain2 = Scene::new(p2, 2.0 * k, None, 0.0, None, None)
            .unwrap()
            .with_spring_layout(SpringLayout::Chain);
        let (q, v, a) = (
            [0.3, -0.2, 0.7, 2.4],
            [0.1, 0.4, -1.2, 0.3],
            [0.0, 0.1, 0.2, -0.3],
        );
        let (mut x, mut y) = ([0.0; 4], [0.0; 4]);
        ring.residual(0.0, &q, &v, &a, &mut x);
        chain2.residual(0.0, &q, &v, &a, &mut y);
        for i in 0..4 {
            assert!((x[i] - y[i]).abs() < 1e-12 * (1.0 + x[i].abs()));
        }
    }

    #[test]
    fn jacobians_match_finite_differences() {
        let (q, v, a) = state();
        check_jacobians(&all_effects(None), &q, &v, &a);
    }

    #[test]
    fn tilting_jacobians_match_finite_differences() {
        let q = [0.3, -0.2, 0.8, -0.6, 0.7, -1.9, 2.4];
        let v = [0.1, 0.4, -0.3, 0.5, -1.2, 0.3, 0.2];
        let a = [0.05, -0.3, 0.2, -0.1, 0.2, 0.6, -0.1];
        check_jacobians(&all_effects(Some(tilt())), &q, &v, &a);
    }

    #[test]
    fn tilting_mass_matrix_is_the_jacobians_m() {
        let s = all_effects(Some(tilt()));
        let q = [0.3, -0.2, 0.8, -0.6, 0.7, -1.9, 2.4];
        let v = [0.1, 0.4, -0.3, 0.5, -1.2, 0.3, 0.2];
        let (mut k, mut c, mut m) = (vec![0.0; 49], vec![0.0; 49], vec![0.0; 49]);
        s.jacobians(0.8, &q, &v, &v, &mut k, &mut c, &mut m);
        let alone = s.tilt_mass(&q);
        for i in 0..7 {
            for j in 0..7 {
                assert!((alone[(i, j)] - m[i * 7 + j]).abs() < 1e-14, "[{i}][{j}]");
            }
        }
    }

    #[test]
    fn centred_disk_started_flat_is_the_planar_model() {
        // a = b: no translation-tilt coupling, and nothing else tilts a flat disk.
        let centred = Tilt {
            a: 2.0,
            b: 2.0,
            ..tilt()
        };
        let (flat, tilting) = (all_effects(None), all_effects(Some(centred)));
        let (q, v, a) = state();
        let widen = |z: &[f64; 5]| vec![z[0], z[1], 0.0, 0.0, z[2], z[3], z[4]];
        let (mut r1, mut r2) = ([0.0; 5], [0.0; 7]);
        for t in [0.0, 0.4, 2.5] {
            flat.residual(t, &q, &v, &a, &mut r1);
            tilting.residual(t, &widen(&q), &widen(&v), &widen(&a), &mut r2);
            let back = [r2[0], r2[1], r2[4], r2[5], r2[6]];
            for (x, y) in r1.iter().zip(&back) {
                assert!((x - y).abs() < 1e-12 * (1.0 + x.abs()), "{r1:?} {r2:?}");
            }
            assert!(r2[2].abs() < 1e-12 && r2[3].abs() < 1e-12, "{r2:?}");
        }
    }

    #[test]
    fn tilt_stiffness_is_beam_theory() {
        // disk at mid-span of length L: k = 48 EI / L^3, k_phiphi = 12 EI / L
        let t = Tilt {
            a: 2.0,
            b: 2.0,
            ..tilt()
        };
        let l: f64 = 4.0;
        assert!(t.kappa_c().abs() < 1e-15);
        assert!((t.kappa_t() - (12.0 / l) / (48.0 / l.powi(3))).abs() < 1e-12);
        let e = Scene::new(
            planar(),
            0.0,
            None,
            0.0,
            None,
            Some(Tilt { j_z: 0.7, ..tilt() }),
        )
        .unwrap_err();
        assert!(e.to_string().starts_with("tilt.j_z"), "{e}");
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
        let e = Scene::new(planar(), -1.0, None, 0.0, None, None).unwrap_err();
        assert!(e.to_string().starts_with("springs"), "{e}");
        let one = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.3, &[1.0]).unwrap();
        let e = Scene::new(one, 0.5, None, 0.0, None, None).unwrap_err();
        assert!(e.to_string().starts_with("springs"), "{e}");
        let r = Some(Ramp {
            to: 1.0,
            start: 0.0,
            duration: 0.0,
        });
        let e = Scene::new(planar(), 0.0, r, 0.0, None, None).unwrap_err();
        assert!(e.to_string().starts_with("ramp.duration"), "{e}");
    }
}
