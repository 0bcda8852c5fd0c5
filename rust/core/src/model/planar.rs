//! The planar n-ball balancer on an isotropic spring–damper support, fused into one
//! residual for speed: every scene without effects runs this code.

use super::params::{ball_name, key_list, unknown, ParamId, ParamRef, PLANAR_OWNERS};
use super::Dynamics;
use crate::error::{Error, Result};

/// Planar n-ball automatic balancer on an isotropic spring–damper support.
#[derive(Debug, Clone, PartialEq)]
pub struct Planar {
    /// Disk mass over total mass.
    pub mu: f64,
    /// Support damping ratio.
    pub zeta: f64,
    /// Track damping ratio, one per ball.
    pub zeta_b: Vec<f64>,
    /// Track radius over eccentricity.
    pub delta: f64,
    /// Spin speed ratio.
    pub omega_s: f64,
    /// Balancing capacity, one per ball.
    pub eta: Vec<f64>,
}

impl Planar {
    /// Validates and builds a planar balancer. `zeta_b` may have length 1 (shared by all balls).
    pub fn new(
        mu: f64,
        zeta: f64,
        zeta_b: &[f64],
        delta: f64,
        omega_s: f64,
        eta: &[f64],
    ) -> Result<Self> {
        ParamId::Mu.check(mu)?;
        ParamId::Zeta.check(zeta)?;
        ParamId::Delta.check(delta)?;
        ParamId::Omega.check(omega_s)?;
        if eta.is_empty() {
            return Err(Error::param(
                "eta",
                "needs one value per ball and at least one ball (n >= 1), got n = 0",
            ));
        }
        ParamId::Eta.check_balls(eta, false)?;
        let zb: Vec<f64> = match zeta_b.len() {
            1 => vec![zeta_b[0]; eta.len()],
            n if n == eta.len() => zeta_b.to_vec(),
            n => {
                return Err(Error::param(
                    "zeta_b",
                    format!("needs 1 value or one per ball ({}), got {n}", eta.len()),
                ))
            }
        };
        ParamId::ZetaB.check_balls(&zb, zeta_b.len() == 1)?;
        // Disk and balls are part of the total mass M: m_d + sum m_b <= M.
        let share = mu * (1.0 + eta.iter().sum::<f64>() / delta);
        if share > 1.0 {
            return Err(Error::param(
                "eta",
                format!(
                    "disk and balls exceed the total mass: mu * (1 + sum(eta) / delta) must be <= 1, got {share:.4}"
                ),
            ));
        }
        Ok(Planar {
            mu,
            zeta,
            zeta_b: zb,
            delta,
            omega_s,
            eta: eta.to_vec(),
        })
    }

    pub fn n_balls(&self) -> usize {
        self.eta.len()
    }

    /// Ball mass parameter `m_i = mu eta_i`.
    #[inline(always)]
    pub fn m(&self, i: usize) -> f64 {
        self.mu * self.eta[i]
    }

    /// `g(q, v) = F(q, v, 0)`: everything but the inertia terms.
    #[inline(always)]
    pub fn forces(&self, q: &[f64], v: &[f64], out: &mut [f64]) {
        self.forces_at(self.omega_s, q, v, out);
    }

    /// [`Self::forces`] at spin `om` (a scene's spin may vary in time).
    #[inline(always)]
    pub fn forces_at(&self, om: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        self.forces_impl::<false>(om, q, v, out);
    }

    /// Adds [`Self::forces_at`] to `out` (the fused planar component of a scene).
    #[inline(always)]
    pub fn add_forces_at(&self, om: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        self.forces_impl::<true>(om, q, v, out);
    }

    #[inline(always)]
    fn forces_impl<const ADD: bool>(&self, om: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        self.forces_trig::<ADD>(om, q, v, |i| q[2 + i].sin_cos(), out);
    }

    /// [`Self::forces_impl`] with each ball's `(sin, cos)` from `trig`.
    #[inline(always)]
    fn forces_trig<const ADD: bool>(
        &self,
        om: f64,
        q: &[f64],
        v: &[f64],
        trig: impl Fn(usize) -> (f64, f64),
        out: &mut [f64],
    ) {
        let (z, dl) = (self.zeta, self.delta);
        let (x, y, vx, vy) = (q[0], q[1], v[0], v[1]);
        let k = 1.0 - om * om;
        let mut fx = 2.0 * z * vx - 2.0 * om * vy + k * x - 2.0 * z * om * y - self.mu * om * om;
        let mut fy = 2.0 * z * vy + 2.0 * om * vx + k * y + 2.0 * z * om * x;
        for i in 0..self.n_balls() {
            let (s, c) = trig(i);
            let mi = self.m(i);
            let w = om + v[2 + i];
            fx -= mi * w * w * c;
            fy -= mi * w * w * s;
            put::<ADD>(
                &mut out[2 + i],
                2.0 * om * (c * vx + s * vy)
                    + 2.0 * self.zeta_b[i] * dl * v[2 + i]
                    + om * om * (x * s - y * c),
            );
        }
        put::<ADD>(&mut out[0], fx);
        put::<ADD>(&mut out[1], fy);
    }

    /// Returns a copy with one named parameter changed (used by scans and continuation):
    /// a registry name (`"mu"`, `"eta"` for every ball, `"eta2"`, the second ball), revalidated.
    pub fn with_param(&self, name: &str, value: f64) -> Result<Self> {
        self.with(Self::param_ref(name)?, value)
    }

    /// Whether [`Self::with_param`] takes `name`: `Ok`, or its error for that name, which
    /// comes before any value is looked at (a scan's axes are checked so before work).
    pub fn check_param(&self, name: &str) -> Result<()> {
        self.clone().set(Self::param_ref(name)?, 0.0)
    }

    fn param_ref(name: &str) -> Result<ParamRef> {
        ParamRef::parse(name)
            .filter(|p| PLANAR_OWNERS.contains(&p.id.spec().owner))
            .ok_or_else(|| unknown(name, "planar balancer", &key_list(PLANAR_OWNERS)))
    }

    /// [`Self::with_param`] by typed id.
    pub fn with(&self, p: ParamRef, value: f64) -> Result<Self> {
        let mut c = self.clone();
        c.set(p, value)?;
        Planar::new(c.mu, c.zeta, &c.zeta_b, c.delta, c.omega_s, &c.eta)
    }

    /// Sets one parameter in place, without revalidating the whole (continuation's
    /// `dF/dp` perturbs one value); fails for a parameter the planar balancer does not
    /// have or a ball it does not have.
    pub fn set(&mut self, p: ParamRef, value: f64) -> Result<()> {
        let n = self.n_balls();
        let one = match p.id {
            ParamId::Mu => &mut self.mu,
            ParamId::Zeta => &mut self.zeta,
            ParamId::Delta => &mut self.delta,
            ParamId::Omega => &mut self.omega_s,
            _ => return self.set_balls(p, value, n),
        };
        *one = value;
        Ok(())
    }

    fn set_balls(&mut self, p: ParamRef, value: f64, n: usize) -> Result<()> {
        let balls = match p.id {
            ParamId::Eta => &mut self.eta,
            ParamId::ZetaB => &mut self.zeta_b,
            _ => {
                return Err(unknown(
                    &p.name(),
                    "planar balancer",
                    &key_list(PLANAR_OWNERS),
                ))
            }
        };
        match p.ball {
            None => balls.iter_mut().for_each(|x| *x = value),
            Some(i) => match balls.get_mut(i) {
                Some(x) => *x = value,
                None => {
                    return Err(Error::param_range(
                        p.name(),
                        format!("names ball {} of a balancer with {n}", i + 1),
                        format!(
                            "{} to {}",
                            ball_name(p.id.spec().name, 0),
                            ball_name(p.id.spec().name, n - 1)
                        ),
                    ))
                }
            },
        }
        Ok(())
    }

    /// The value of one parameter; for a per-ball parameter without a ball index, its
    /// value when every ball shares it. `None` when the planar balancer has no such value.
    pub fn get(&self, p: ParamRef) -> Option<f64> {
        let balls = match p.id {
            ParamId::Mu => return Some(self.mu),
            ParamId::Zeta => return Some(self.zeta),
            ParamId::Delta => return Some(self.delta),
            ParamId::Omega => return Some(self.omega_s),
            ParamId::Eta => &self.eta,
            ParamId::ZetaB => &self.zeta_b,
            _ => return None,
        };
        match p.ball {
            Some(i) => balls.get(i).copied(),
            None => balls.windows(2).all(|w| w[0] == w[1]).then(|| balls[0]),
        }
    }

    /// Adds the inertia terms `M(q) a` to `out`.
    #[inline(always)]
    pub fn add_inertia(&self, q: &[f64], a: &[f64], out: &mut [f64]) {
        self.add_inertia_trig(a, |i| q[2 + i].sin_cos(), out);
    }

    /// [`Self::add_inertia`] with each ball's `(sin, cos)` from `trig`.
    #[inline(always)]
    fn add_inertia_trig(&self, a: &[f64], trig: impl Fn(usize) -> (f64, f64), out: &mut [f64]) {
        let (ax, ay) = (a[0], a[1]);
        for i in 0..self.n_balls() {
            let (s, c) = trig(i);
            let mi = self.m(i);
            let ab = a[2 + i];
            out[0] -= mi * s * ab;
            out[1] += mi * c * ab;
            out[2 + i] += self.delta * ab - s * ax + c * ay;
        }
        out[0] += ax;
        out[1] += ay;
    }

    /// [`Dynamics::jacobians`] at spin `om`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub fn jacobians_at(
        &self,
        om: f64,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        k: &mut [f64],
        c: &mut [f64],
        m: &mut [f64],
    ) {
        self.jacobians_impl::<false>(om, q, v, a, k, c, m);
    }

    /// Adds [`Self::jacobians_at`] to `k`, `c`, `m`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub fn add_jacobians_at(
        &self,
        om: f64,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        k: &mut [f64],
        c: &mut [f64],
        m: &mut [f64],
    ) {
        self.jacobians_impl::<true>(om, q, v, a, k, c, m);
    }

    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn jacobians_impl<const ADD: bool>(
        &self,
        om: f64,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        k: &mut [f64],
        c: &mut [f64],
        m: &mut [f64],
    ) {
        let d = self.ndof();
        if !ADD {
            k.fill(0.0);
            c.fill(0.0);
            m.fill(0.0);
        }
        let (z, dl) = (self.zeta, self.delta);
        let stiff = 1.0 - om * om;
        put::<ADD>(&mut k[0], stiff);
        put::<ADD>(&mut k[1], -2.0 * z * om);
        put::<ADD>(&mut k[d], 2.0 * z * om);
        put::<ADD>(&mut k[d + 1], stiff);
        put::<ADD>(&mut c[0], 2.0 * z);
        put::<ADD>(&mut c[1], -2.0 * om);
        put::<ADD>(&mut c[d], 2.0 * om);
        put::<ADD>(&mut c[d + 1], 2.0 * z);
        put::<ADD>(&mut m[0], 1.0);
        put::<ADD>(&mut m[d + 1], 1.0);
        for i in 0..self.n_balls() {
            let j = 2 + i;
            let (s, cs) = q[j].sin_cos();
            let mi = self.m(i);
            let w = om + v[j];
            let ab = a[j];
            // x row
            put::<ADD>(&mut m[j], -mi * s);
            put::<ADD>(&mut c[j], -2.0 * mi * w * cs);
            put::<ADD>(&mut k[j], -mi * cs * ab + mi * w * w * s);
            // y row
            put::<ADD>(&mut m[d + j], mi * cs);
            put::<ADD>(&mut c[d + j], -2.0 * mi * w * s);
            put::<ADD>(&mut k[d + j], -mi * s * ab - mi * w * w * cs);
            // ball row
            let r = j * d;
            put::<ADD>(&mut m[r], -s);
            put::<ADD>(&mut m[r + 1], cs);
            put::<ADD>(&mut m[r + j], dl);
            put::<ADD>(&mut c[r], 2.0 * om * cs);
            put::<ADD>(&mut c[r + 1], 2.0 * om * s);
            put::<ADD>(&mut c[r + j], 2.0 * self.zeta_b[i] * dl);
            put::<ADD>(&mut k[r], om * om * s);
            put::<ADD>(&mut k[r + 1], -om * om * cs);
            put::<ADD>(
                &mut k[r + j],
                -cs * a[0] - s * a[1]
                    + 2.0 * om * (-s * v[0] + cs * v[1])
                    + om * om * (q[0] * cs + q[1] * s),
            );
        }
    }
}

impl Planar {
    /// Every ball's `(sin, cos)` of its angle, on the stack up to 16 balls, for `f`:
    /// the right-hand side and the residual need them in two places each, and the
    /// trigonometry was a fifth of a scan's instructions when each place computed its own.
    #[inline(always)]
    fn with_trig<R>(&self, q: &[f64], f: impl FnOnce(&[(f64, f64)]) -> R) -> R {
        let n = self.n_balls();
        let mut buf = [(0.0f64, 0.0f64); 16];
        let mut heap: Vec<(f64, f64)>;
        let sc: &mut [(f64, f64)] = if n <= 16 {
            &mut buf[..n]
        } else {
            heap = vec![(0.0, 0.0); n];
            &mut heap
        };
        for (i, x) in sc.iter_mut().enumerate() {
            *x = q[2 + i].sin_cos();
        }
        f(sc)
    }

    /// [`Dynamics::solve_mass`] with each ball's `(sin, cos)` given.
    #[inline(always)]
    fn solve_mass_trig(&self, trig: &[(f64, f64)], rhs: &mut [f64]) {
        // The mass matrix is an arrow: eliminate the ball rows (Schur complement)
        // and solve the remaining 2 x 2 system, O(n) instead of a dense LU.
        let dl = self.delta;
        let schur = self.mass_schur(trig);
        let (mut r1, mut r2) = (rhs[0], rhs[1]);
        for (i, &(s, c)) in trig.iter().enumerate() {
            let mi = self.m(i);
            let rb = rhs[2 + i];
            r1 += mi * s * rb / dl;
            r2 -= mi * c * rb / dl;
        }
        Self::mass_back(trig, dl, schur, r1, r2, rhs);
    }

    /// The 2 x 2 Schur complement of the mass matrix's ball rows, `[a11, a12, a22, det]`.
    #[inline(always)]
    fn mass_schur(&self, trig: &[(f64, f64)]) -> [f64; 4] {
        let dl = self.delta;
        let (mut a11, mut a12, mut a22) = (1.0, 0.0, 1.0);
        for (i, &(s, c)) in trig.iter().enumerate() {
            let mi = self.m(i);
            a11 -= mi * s * s / dl;
            a12 += mi * s * c / dl;
            a22 -= mi * c * c / dl;
        }
        [a11, a12, a22, a11 * a22 - a12 * a12]
    }

    /// The rotor's accelerations from the reduced right-hand side `(r1, r2)`, then the
    /// balls' by back substitution, into `v` (whose ball entries hold the right-hand side).
    #[inline(always)]
    fn mass_back(trig: &[(f64, f64)], dl: f64, schur: [f64; 4], r1: f64, r2: f64, v: &mut [f64]) {
        let [a11, a12, a22, det] = schur;
        let ax = (r1 * a22 - a12 * r2) / det;
        let ay = (a11 * r2 - a12 * r1) / det;
        v[0] = ax;
        v[1] = ay;
        for (i, &(s, c)) in trig.iter().enumerate() {
            v[2 + i] = (v[2 + i] + s * ax - c * ay) / dl;
        }
    }
}

/// `*x = v`, or `*x += v` when adding into a sum of components.
#[inline(always)]
fn put<const ADD: bool>(x: &mut f64, v: f64) {
    if ADD {
        *x += v;
    } else {
        *x = v;
    }
}

impl Dynamics for Planar {
    fn ndof(&self) -> usize {
        self.eta.len() + 2
    }

    fn residual(&self, _t: f64, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]) {
        self.with_trig(q, |sc| {
            self.forces_trig::<false>(self.omega_s, q, v, |i| sc[i], out);
            self.add_inertia_trig(a, |i| sc[i], out);
        });
    }

    fn jacobians(
        &self,
        _t: f64,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        k: &mut [f64],
        c: &mut [f64],
        m: &mut [f64],
    ) {
        self.jacobians_at(self.omega_s, q, v, a, k, c, m);
    }

    fn base_spin(&self) -> f64 {
        self.omega_s
    }

    fn solve_mass(&self, _t: f64, q: &[f64], rhs: &mut [f64]) {
        self.with_trig(q, |trig| self.solve_mass_trig(trig, rhs));
    }

    fn solve_mass_columns(&self, _t: f64, q: &[f64], cols: &mut [f64]) {
        // Same elimination as solve_mass, with the trigonometry and the 2 x 2 factor
        // computed once: the Floquet right-hand side solves 2d columns per evaluation.
        let n = self.n_balls();
        let d = n + 2;
        let dl = self.delta;
        self.with_trig(q, |sc| {
            let schur = self.mass_schur(sc);
            for col in cols.chunks_mut(d) {
                let (mut r1, mut r2) = (col[0], col[1]);
                for (i, &(s, c)) in sc.iter().enumerate() {
                    let w = self.m(i) * col[2 + i] / dl;
                    r1 += s * w;
                    r2 -= c * w;
                }
                Self::mass_back(sc, dl, schur, r1, r2, col);
            }
        });
    }

    fn accel(&self, _t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        self.with_trig(q, |sc| {
            self.forces_trig::<false>(self.omega_s, q, v, |i| sc[i], out);
            out.iter_mut().for_each(|g| *g = -*g);
            self.solve_mass_trig(sc, out);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Planar {
        Planar::new(0.2, 0.05, &[0.07], 50.0, 1.3, &[0.9, 1.1]).unwrap()
    }

    #[test]
    fn accel_solves_residual() {
        let p = sample();
        let q = [0.3, -0.2, 0.7, -1.9];
        let v = [0.1, 0.4, -1.2, 0.3];
        let mut a = [0.0; 4];
        p.accel(0.0, &q, &v, &mut a);
        let mut r = [0.0; 4];
        p.residual(0.0, &q, &v, &a, &mut r);
        for x in r {
            assert!(x.abs() < 1e-13, "{r:?}");
        }
    }

    #[test]
    fn solve_mass_inverts_mass_matrix() {
        let p = sample();
        let q = [0.3, -0.2, 0.7, -1.9];
        let (mut k, mut c, mut m) = (vec![0.0; 16], vec![0.0; 16], vec![0.0; 16]);
        p.jacobians(0.0, &q, &[0.0; 4], &[0.0; 4], &mut k, &mut c, &mut m);
        let z = [0.4, -1.0, 2.0, 0.25];
        let mut r = [0.0; 4];
        for i in 0..4 {
            r[i] = (0..4).map(|j| m[i * 4 + j] * z[j]).sum();
        }
        let mut two = [r, r].concat();
        p.solve_mass(0.0, &q, &mut r);
        for i in 0..4 {
            assert!((r[i] - z[i]).abs() < 1e-13);
        }
        p.solve_mass_columns(0.0, &q, &mut two);
        for i in 0..8 {
            assert!((two[i] - z[i % 4]).abs() < 1e-13);
        }
    }

    #[test]
    fn jacobians_match_finite_differences() {
        let p = sample();
        let q = [0.3, -0.2, 0.7, -1.9];
        let v = [0.1, 0.4, -1.2, 0.3];
        let a = [0.5, -0.3, 0.2, 0.9];
        let d = 4;
        let (mut k, mut c, mut m) = (vec![0.0; 16], vec![0.0; 16], vec![0.0; 16]);
        p.jacobians(0.0, &q, &v, &a, &mut k, &mut c, &mut m);
        let h = 1e-6;
        for (which, jac) in [(0, &k), (1, &c), (2, &m)] {
            for col in 0..d {
                let mut args = [q, v, a];
                args[which][col] += h;
                let mut rp = [0.0; 4];
                p.residual(0.0, &args[0], &args[1], &args[2], &mut rp);
                args[which][col] -= 2.0 * h;
                let mut rm = [0.0; 4];
                p.residual(0.0, &args[0], &args[1], &args[2], &mut rm);
                for row in 0..d {
                    let fd = (rp[row] - rm[row]) / (2.0 * h);
                    let an = jac[row * d + col];
                    assert!(
                        (fd - an).abs() < 1e-7,
                        "jac {which} ({row},{col}): fd {fd} vs {an}"
                    );
                }
            }
        }
    }

    #[test]
    fn validation_names_parameters() {
        let e = Planar::new(0.2, -0.1, &[0.05], 50.0, 1.0, &[1.0]).unwrap_err();
        assert!(e.to_string().starts_with("zeta:"), "{e}");
        let e = Planar::new(0.2, 0.1, &[0.05], 50.0, 1.0, &[]).unwrap_err();
        assert!(e.to_string().contains("n = 0"), "{e}");
        let e = Planar::new(0.2, 0.1, &[0.05], 50.0, f64::NAN, &[1.0]).unwrap_err();
        assert!(e.to_string().starts_with("Omega:"), "{e}");
        let e = Planar::new(0.2, 0.1, &[0.05], 50.0, 1.0, &[1.0, 0.0]).unwrap_err();
        assert!(e.to_string().starts_with("eta2:"), "{e}");
    }
}
