//! Components: the pieces a model is assembled from. Each contributes its own terms to
//! the residual `F(t, q, v, a)` and to its Jacobians `K, C, M` (adding into them), and
//! declares its parameters, its time dependence and the coordinates it owns.
//!
//! A new physical part (a fluid-film journal bearing, say) is one struct implementing
//! [`Component`]: [`Component::add_residual`] is all it must write; without analytic
//! derivatives it gets central finite differences of its own terms
//! ([`fd_add_jacobians`]), and without inertia terms it says so with
//! [`Component::has_inertia`] so that the assembly keeps a cheap mass solve.
//! [`Composed`] sums the components a model switches on; its [`Dynamics`] is what every
//! solver sees.

use super::{Dynamics, Layout, ParamId, Planar};
use crate::model::Jacobians;
use nalgebra::DMatrix;
use std::fmt::Debug;
use std::sync::Arc;

/// The spin state at one time: `Omega(t)`, `Omega'(t)` and the disk's angle `theta(t)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spin {
    pub om: f64,
    pub dom: f64,
    pub th: f64,
}

impl Spin {
    /// The tuple the generated tilt terms take.
    #[inline(always)]
    pub fn tuple(&self) -> (f64, f64, f64) {
        (self.om, self.dom, self.th)
    }
}

/// What every component sees at one evaluation besides the state: the time, the
/// coordinate layout, the spin given by the drive, and the ball masses `m_i = mu eta_i`
/// that scale the ball rows (a ball row is its equation divided by `m_i`).
#[derive(Debug, Clone, Copy)]
pub struct Ctx<'a> {
    pub t: f64,
    pub layout: Layout,
    pub spin: Spin,
    pub m: &'a [f64],
}

impl Ctx<'_> {
    /// Number of coordinates `d` (the Jacobians are row-major `d x d`).
    #[inline(always)]
    pub fn ndof(&self) -> usize {
        self.layout.ndof()
    }
}

/// One part of a model. See the module documentation.
pub trait Component: Send + Sync + Debug {
    /// The component's name, as the parameter registry's `owner` names it.
    fn name(&self) -> &'static str;
    /// The registry ids of its parameters.
    fn params(&self) -> &'static [ParamId] {
        &[]
    }
    /// `Some(effect)` when its terms depend on time explicitly.
    fn time_dependence(&self) -> Option<&'static str> {
        None
    }
    /// The coordinates it introduces (its own rows); it may add to any row.
    fn coords(&self, _layout: &Layout) -> Vec<usize> {
        vec![]
    }
    /// Whether its terms depend on `a` (adds to `M = dF/da`). Conservative default.
    fn has_inertia(&self) -> bool {
        true
    }
    /// Adds its terms of `F(t, q, v, a)` to `out`.
    fn add_residual(&self, cx: &Ctx, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]);
    /// Writes its terms into `out` (the first component of an assembly writes, the
    /// others add). Override when writing costs less than zeroing and adding.
    #[inline]
    fn set_residual(&self, cx: &Ctx, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        self.add_residual(cx, q, v, a, out);
    }
    /// Adds its terms of `K, C, M` (row-major `d x d`). Default: central differences of
    /// [`Self::add_residual`].
    fn add_jacobians(&self, cx: &Ctx, q: &[f64], v: &[f64], a: &[f64], jac: Jacobians<'_>) {
        let Jacobians { k, c, m } = jac;
        fd_add_jacobians(
            |q, v, a, out| self.add_residual(cx, q, v, a, out),
            q,
            v,
            a,
            k,
            c,
            m,
        );
    }
    /// Writes its terms of `K, C, M` (see [`Self::set_residual`]).
    #[inline]
    fn set_jacobians(&self, cx: &Ctx, q: &[f64], v: &[f64], a: &[f64], jac: Jacobians<'_>) {
        let Jacobians { k, c, m } = jac;
        k.fill(0.0);
        c.fill(0.0);
        m.fill(0.0);
        self.add_jacobians(cx, q, v, a, Jacobians::new(k, c, m));
    }
    /// Adds its terms of `M` alone (it must depend on `q` only). Default: from
    /// [`Self::add_jacobians`] at `v = a = 0`.
    fn add_mass(&self, cx: &Ctx, q: &[f64], m: &mut [f64]) {
        if !self.has_inertia() {
            return;
        }
        let d = q.len();
        let z = vec![0.0; d];
        let (mut k, mut c) = (vec![0.0; d * d], vec![0.0; d * d]);
        self.add_jacobians(cx, q, &z, &z, Jacobians::new(&mut k, &mut c, m));
    }
}

/// Central-difference step for a variable of size `x`: `eps^(1/3)` balances truncation
/// (`h^2`) against round-off (`eps / h`).
#[inline]
fn fd_step(x: f64) -> f64 {
    6.0e-6 * x.abs().max(1.0)
}

/// Adds the central-difference Jacobians of `f` (which adds a residual into its last
/// argument) with respect to `q`, `v` and `a` to `k`, `c`, `m`: `6 d` evaluations.
pub fn fd_add_jacobians<F>(
    mut f: F,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    k: &mut [f64],
    c: &mut [f64],
    m: &mut [f64],
) where
    F: FnMut(&[f64], &[f64], &[f64], &mut [f64]),
{
    let d = q.len();
    let mut args = [q.to_vec(), v.to_vec(), a.to_vec()];
    let (mut rp, mut rm) = (vec![0.0; d], vec![0.0; d]);
    for (which, jac) in [&mut *k, &mut *c, &mut *m].into_iter().enumerate() {
        for j in 0..d {
            let x0 = args[which][j];
            let h = fd_step(x0);
            // the step actually taken, after rounding x0 + h
            args[which][j] = x0 + h;
            let up = args[which][j];
            rp.fill(0.0);
            f(&args[0], &args[1], &args[2], &mut rp);
            args[which][j] = x0 - h;
            let down = args[which][j];
            rm.fill(0.0);
            f(&args[0], &args[1], &args[2], &mut rm);
            args[which][j] = x0;
            let span = up - down;
            for i in 0..d {
                jac[i * d + j] += (rp[i] - rm[i]) / span;
            }
        }
    }
}

/// The spin profile: constant `Omega`, or a linear change to `to` over `duration` from
/// `start` (a run-up, or [TwoBallStrength]'s speed disturbance). It hands `Omega(t)`,
/// `Omega'(t)` and `theta(t)` (with `theta(0) = 0`) to the other components.
#[derive(Debug, Clone, PartialEq)]
pub enum Drive {
    Constant(f64),
    Ramp {
        from: f64,
        to: f64,
        start: f64,
        duration: f64,
    },
}

impl Drive {
    /// `Omega` at rest of the profile (before any ramp).
    pub fn base(&self) -> f64 {
        match *self {
            Drive::Constant(w) | Drive::Ramp { from: w, .. } => w,
        }
    }

    #[inline]
    pub fn spin(&self, t: f64) -> Spin {
        let (om, dom, th) = match *self {
            Drive::Constant(w0) => (w0, 0.0, w0 * t),
            Drive::Ramp {
                from: w0,
                to,
                start,
                duration,
            } => {
                let rate = (to - w0) / duration;
                let end = start + duration;
                if t < start {
                    (w0, 0.0, w0 * t)
                } else if t < end {
                    let u = t - start;
                    (w0 + rate * u, rate, w0 * t + 0.5 * rate * u * u)
                } else {
                    let th_end = w0 * end + 0.5 * rate * duration * duration;
                    (to, 0.0, th_end + to * (t - end))
                }
            }
        };
        Spin { om, dom, th }
    }
}

impl Component for Drive {
    fn name(&self) -> &'static str {
        "drive"
    }
    fn params(&self) -> &'static [ParamId] {
        match self {
            Drive::Constant(_) => &[ParamId::Omega],
            Drive::Ramp { .. } => &[
                ParamId::Omega,
                ParamId::RampTo,
                ParamId::RampStart,
                ParamId::RampDuration,
            ],
        }
    }
    fn time_dependence(&self) -> Option<&'static str> {
        match self {
            Drive::Constant(_) => None,
            Drive::Ramp { .. } => Some("ramp"),
        }
    }
    fn has_inertia(&self) -> bool {
        false
    }
    /// The drive has no terms of its own: the spin it sets enters the others' terms.
    fn add_residual(&self, _: &Ctx, _: &[f64], _: &[f64], _: &[f64], _: &mut [f64]) {}
    fn add_jacobians(&self, _: &Ctx, _: &[f64], _: &[f64], _: &[f64], _: Jacobians<'_>) {}
}

/// Largest `d` whose mass matrix is factored on the stack.
const SMALL: usize = 16;

/// Solves `M Z = B` in place by Gaussian elimination with partial pivoting: `m` the
/// row-major `d x d` matrix (overwritten), `cols` the columns of `B`, each of length `d`.
fn gauss_solve(m: &mut [f64], d: usize, cols: &mut [f64]) {
    for k in 0..d {
        let p = (k..d)
            .max_by(|&i, &j| m[i * d + k].abs().total_cmp(&m[j * d + k].abs()))
            .unwrap_or(k);
        if p != k {
            for j in 0..d {
                m.swap(k * d + j, p * d + j);
            }
            for c in cols.chunks_mut(d) {
                c.swap(k, p);
            }
        }
        let piv = m[k * d + k];
        for i in k + 1..d {
            let f = m[i * d + k] / piv;
            if f == 0.0 {
                continue;
            }
            for j in k + 1..d {
                m[i * d + j] -= f * m[k * d + j];
            }
            for c in cols.chunks_mut(d) {
                c[i] -= f * c[k];
            }
        }
    }
    for c in cols.chunks_mut(d) {
        for k in (0..d).rev() {
            let s: f64 = (k + 1..d).map(|j| m[k * d + j] * c[j]).sum();
            c[k] = (c[k] - s) / m[k * d + k];
        }
    }
}

/// How a composed model solves `M z = rhs`: chosen once, at assembly.
#[derive(Debug, Clone)]
enum MassSolve {
    /// The planar disk with free balls: `M` is an arrow, eliminated in `O(n)`.
    Arrow(Planar),
    /// Anything else: a dense LU of the assembled `M`.
    Dense,
}

/// A model assembled from components: the residual and Jacobians are the sums of theirs.
#[derive(Debug, Clone)]
pub struct Composed {
    layout: Layout,
    drive: Drive,
    m: Vec<f64>,
    parts: Vec<Arc<dyn Component>>,
    mass: MassSolve,
    modulo_turns: bool,
}

impl Composed {
    /// `m`: the ball masses `m_i = mu eta_i` (one per ball of `layout`).
    pub fn new(layout: Layout, drive: Drive, m: Vec<f64>, parts: Vec<Arc<dyn Component>>) -> Self {
        assert_eq!(m.len(), layout.n_balls, "one ball mass per ball");
        Composed {
            layout,
            drive,
            m,
            parts,
            mass: MassSolve::Dense,
            modulo_turns: true,
        }
    }

    /// Declares that the inertia terms are exactly those of `planar` (a planar disk with
    /// free balls; every other component without inertia), so that the mass solve uses
    /// its `O(n)` elimination. Checked in debug builds.
    pub fn with_planar_mass(mut self, planar: &Planar) -> Self {
        debug_assert!(self.layout == Layout::planar(planar.n_balls()));
        self.mass = MassSolve::Arrow(planar.clone());
        self
    }

    /// Whether ball angles that differ by whole turns are the same state (not so when
    /// a component counts the turns, as ball springs do).
    pub fn with_modulo_turns(mut self, modulo: bool) -> Self {
        self.modulo_turns = modulo;
        self
    }

    pub fn drive(&self) -> &Drive {
        &self.drive
    }

    pub fn components(&self) -> impl Iterator<Item = &dyn Component> {
        std::iter::once(&self.drive as &dyn Component).chain(self.parts.iter().map(|p| &**p))
    }

    #[inline(always)]
    fn ctx(&self, t: f64) -> Ctx<'_> {
        Ctx {
            t,
            layout: self.layout,
            spin: self.drive.spin(t),
            m: &self.m,
        }
    }

    /// The assembled mass matrix `M(q)`.
    pub fn mass_matrix(&self, t: f64, q: &[f64]) -> DMatrix<f64> {
        let d = self.layout.ndof();
        let cx = self.ctx(t);
        let mut m = vec![0.0; d * d];
        for p in &self.parts {
            p.add_mass(&cx, q, &mut m);
        }
        DMatrix::from_row_slice(d, d, &m)
    }
}

impl Dynamics for Composed {
    fn ndof(&self) -> usize {
        self.layout.ndof()
    }

    fn layout(&self) -> Layout {
        self.layout
    }

    #[inline]
    fn residual(&self, t: f64, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]) {
        let cx = self.ctx(t);
        let Some((first, rest)) = self.parts.split_first() else {
            return out.fill(0.0);
        };
        first.set_residual(&cx, q, v, a, out);
        for p in rest {
            p.add_residual(&cx, q, v, a, out);
        }
    }

    fn jacobians(&self, t: f64, q: &[f64], v: &[f64], a: &[f64], jac: Jacobians<'_>) {
        let Jacobians { k, c, m } = jac;
        let cx = self.ctx(t);
        let Some((first, rest)) = self.parts.split_first() else {
            k.fill(0.0);
            c.fill(0.0);
            return m.fill(0.0);
        };
        first.set_jacobians(&cx, q, v, a, Jacobians::new(k, c, m));
        for p in rest {
            p.add_jacobians(&cx, q, v, a, Jacobians::new(k, c, m));
        }
    }

    fn solve_mass(&self, t: f64, q: &[f64], rhs: &mut [f64]) {
        match &self.mass {
            MassSolve::Arrow(p) => p.solve_mass(t, q, rhs),
            MassSolve::Dense => self.solve_mass_columns(t, q, rhs),
        }
    }

    fn solve_mass_columns(&self, t: f64, q: &[f64], cols: &mut [f64]) {
        match &self.mass {
            MassSolve::Arrow(p) => p.solve_mass_columns(t, q, cols),
            MassSolve::Dense => {
                let d = self.ndof();
                // M is the kinetic-energy Hessian with rows scaled: never singular.
                if d <= SMALL {
                    // on the stack: a right-hand side evaluation allocates nothing
                    let mut buf = [0.0; SMALL * SMALL];
                    let m = &mut buf[..d * d];
                    let cx = self.ctx(t);
                    for p in &self.parts {
                        p.add_mass(&cx, q, m);
                    }
                    return gauss_solve(m, d, cols);
                }
                let lu = self.mass_matrix(t, q).lu();
                let mut b = DMatrix::from_column_slice(d, cols.len() / d, cols);
                lu.solve_mut(&mut b);
                cols.copy_from_slice(b.as_slice());
            }
        }
    }

    fn time_dependence(&self) -> Option<String> {
        self.components()
            .find_map(|c| c.time_dependence())
            .map(str::to_string)
    }

    fn base_spin(&self) -> f64 {
        self.drive.base()
    }

    fn angles_modulo_turns(&self) -> bool {
        self.modulo_turns
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::components::{FreeBalls, FusedPlanar, IsotropicSupport, PlanarDisk};
    use crate::model::scene::{Impulse, Ramp, Tilt};
    use crate::model::Scene;

    /// A model that only has a residual: its Jacobians are [`Dynamics`]'s default.
    struct ResidualOnly<'a, D: Dynamics>(&'a D);

    impl<D: Dynamics> Dynamics for ResidualOnly<'_, D> {
        fn ndof(&self) -> usize {
            self.0.ndof()
        }
        fn residual(&self, t: f64, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]) {
            self.0.residual(t, q, v, a, out)
        }
        fn solve_mass(&self, t: f64, q: &[f64], rhs: &mut [f64]) {
            self.0.solve_mass(t, q, rhs)
        }
        fn accel(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
            self.0.accel(t, q, v, out)
        }
    }

    fn jacs<D: Dynamics + ?Sized>(
        model: &D,
        t: f64,
        q: &[f64],
        v: &[f64],
        a: &[f64],
    ) -> [Vec<f64>; 3] {
        let d = model.ndof();
        let (mut k, mut c, mut m) = (vec![0.0; d * d], vec![0.0; d * d], vec![0.0; d * d]);
        // stale values must not leak into the result
        k.fill(7.0);
        c.fill(7.0);
        m.fill(7.0);
        model.jacobians(t, q, v, a, Jacobians::new(&mut k, &mut c, &mut m));
        [k, c, m]
    }

    /// Largest error of `b` against `a`, relative to the largest entry of `a`.
    fn rel_err(a: &[f64], b: &[f64]) -> f64 {
        let scale = a.iter().fold(0.0f64, |s, x| s.max(x.abs())).max(1e-300);
        a.iter()
            .zip(b)
            .fold(0.0f64, |e, (x, y)| e.max((x - y).abs()))
            / scale
    }

    fn planar() -> Planar {
        Planar::new(0.2, 0.05, &[0.07, 0.05, 0.06], 50.0, 1.3, &[0.9, 1.1, 0.8]).unwrap()
    }

    fn tilting_scene() -> Scene {
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
            Some(Tilt {
                a: 1.5,
                b: 2.5,
                j_t: 0.3,
                j_z: 0.5,
                zeta_r: 0.05,
            }),
        )
        .unwrap()
    }

    #[test]
    fn finite_difference_default_matches_analytic_jacobians() {
        let p = planar();
        let (q, v, a) = (
            [0.3, -0.2, 0.7, -1.9, 2.4],
            [0.1, 0.4, -1.2, 0.3, 0.2],
            [0.05, -0.3, 0.2, 0.6, -0.1],
        );
        let (exact, fd) = (
            jacs(&p, 0.0, &q, &v, &a),
            jacs(&ResidualOnly(&p), 0.0, &q, &v, &a),
        );
        for (e, f) in exact.iter().zip(&fd) {
            assert!(rel_err(e, f) < 1e-8, "planar: {}", rel_err(e, f));
        }
        let s = tilting_scene();
        let q = [0.3, -0.2, 0.8, -0.6, 0.7, -1.9, 2.4];
        let v = [0.1, 0.4, -0.3, 0.5, -1.2, 0.3, 0.2];
        let a = [0.05, -0.3, 0.2, -0.1, 0.2, 0.6, -0.1];
        let (exact, fd) = (
            jacs(&s, 0.8, &q, &v, &a),
            jacs(&ResidualOnly(&s), 0.8, &q, &v, &a),
        );
        for (e, f) in exact.iter().zip(&fd) {
            assert!(rel_err(e, f) < 1e-6, "tilting scene: {}", rel_err(e, f));
        }
    }

    /// The planar disk, the isotropic support and free balls as three components.
    fn three_components(p: &Planar, drive: Drive) -> Composed {
        let n = p.n_balls();
        let parts: Vec<Arc<dyn Component>> = vec![
            Arc::new(PlanarDisk { mu: p.mu }),
            Arc::new(IsotropicSupport { zeta: p.zeta }),
            Arc::new(FreeBalls {
                zeta_b: p.zeta_b.clone(),
                delta: p.delta,
            }),
        ];
        Composed::new(
            Layout::planar(n),
            drive,
            (0..n).map(|i| p.m(i)).collect(),
            parts,
        )
    }

    #[test]
    fn composed_planar_scene_is_the_planar_balancer() {
        let p = planar();
        let composed = three_components(&p, Drive::Constant(p.omega_s));
        let (q, v, a) = (
            [0.3, -0.2, 0.7, -1.9, 2.4],
            [0.1, 0.4, -1.2, 0.3, 0.2],
            [0.05, -0.3, 0.2, 0.6, -0.1],
        );
        let (mut r1, mut r2) = ([0.0; 5], [0.0; 5]);
        p.residual(0.3, &q, &v, &a, &mut r1);
        composed.residual(0.3, &q, &v, &a, &mut r2);
        assert!(rel_err(&r1, &r2) < 1e-13, "{r1:?} {r2:?}");
        for (e, f) in jacs(&p, 0.3, &q, &v, &a)
            .iter()
            .zip(&jacs(&composed, 0.3, &q, &v, &a))
        {
            assert!(rel_err(e, f) < 1e-13, "{e:?} {f:?}");
        }
        // the dense mass solve of the components is the planar arrow elimination
        let (mut z1, mut z2) = ([0.4, -1.0, 2.0, 0.25, 0.5], [0.4, -1.0, 2.0, 0.25, 0.5]);
        p.solve_mass(0.0, &q, &mut z1);
        composed.solve_mass(0.0, &q, &mut z2);
        assert!(rel_err(&z1, &z2) < 1e-13, "{z1:?} {z2:?}");
        assert_eq!(composed.time_dependence(), None);
        assert_eq!(composed.base_spin(), p.omega_s);
    }

    #[test]
    fn fused_planar_is_its_three_components() {
        // with a spin ramp, so that the Omega' terms of both are compared too
        let p = planar();
        let drive = Drive::Ramp {
            from: p.omega_s,
            to: 2.0,
            start: -1.0,
            duration: 4.0,
        };
        let n = p.n_balls();
        let fused = Composed::new(
            Layout::planar(n),
            drive.clone(),
            (0..n).map(|i| p.m(i)).collect(),
            vec![Arc::new(FusedPlanar { planar: p.clone() })],
        );
        let split = three_components(&p, drive);
        let (q, v, a) = (
            [0.3, -0.2, 0.7, -1.9, 2.4],
            [0.1, 0.4, -1.2, 0.3, 0.2],
            [0.05, -0.3, 0.2, 0.6, -0.1],
        );
        let t = 0.8;
        assert!(fused.drive().spin(t).dom != 0.0);
        let (mut r1, mut r2) = ([0.0; 5], [0.0; 5]);
        fused.residual(t, &q, &v, &a, &mut r1);
        split.residual(t, &q, &v, &a, &mut r2);
        assert!(rel_err(&r1, &r2) < 1e-13, "{r1:?} {r2:?}");
        for (e, f) in jacs(&fused, t, &q, &v, &a)
            .iter()
            .zip(&jacs(&split, t, &q, &v, &a))
        {
            assert!(rel_err(e, f) < 1e-13, "{e:?} {f:?}");
        }
        // and the split components' analytic Jacobians are their residual's derivatives
        for (e, f) in
            jacs(&split, t, &q, &v, &a)
                .iter()
                .zip(&jacs(&ResidualOnly(&split), t, &q, &v, &a))
        {
            assert!(rel_err(e, f) < 1e-8, "{}", rel_err(e, f));
        }
        assert_eq!(split.time_dependence().as_deref(), Some("ramp"));
    }

    #[test]
    fn component_without_jacobians_gets_finite_differences() {
        // a cubic support spring written as a residual only
        #[derive(Debug)]
        struct Cubic;
        impl Component for Cubic {
            fn name(&self) -> &'static str {
                "support"
            }
            fn has_inertia(&self) -> bool {
                false
            }
            fn add_residual(&self, cx: &Ctx, q: &[f64], v: &[f64], _: &[f64], out: &mut [f64]) {
                let (x, y) = (q[cx.layout.x], q[cx.layout.y]);
                out[cx.layout.x] += x * x * x + 0.1 * v[cx.layout.x];
                out[cx.layout.y] += y * y * y;
            }
        }
        let l = Layout::planar(0);
        let cx = Ctx {
            t: 0.0,
            layout: l,
            spin: Spin {
                om: 1.0,
                dom: 0.0,
                th: 0.0,
            },
            m: &[],
        };
        let (mut k, mut c, mut m) = ([0.0; 4], [0.0; 4], [0.0; 4]);
        Cubic.add_jacobians(
            &cx,
            &[0.5, -2.0],
            &[0.0; 2],
            &[0.0; 2],
            Jacobians::new(&mut k, &mut c, &mut m),
        );
        let want_k = [3.0 * 0.25, 0.0, 0.0, 3.0 * 4.0];
        assert!(rel_err(&want_k, &k) < 1e-9, "{k:?}");
        assert!(rel_err(&[0.1, 0.0, 0.0, 0.0], &c) < 1e-9, "{c:?}");
        assert_eq!(m, [0.0; 4]);
    }
}
