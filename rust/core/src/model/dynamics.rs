//! The balancer's equations of motion in the disk-fixed rotating frame.
//!
//! Every analysis (time simulation, equilibria, harmonic balance, Floquet) works on
//! the implicit residual `F(t, q, v, a) = M(q) a + g(q, v)`, with `v = q'`, `a = q''`,
//! and its three Jacobians `K = dF/dq`, `C = dF/dv`, `M = dF/da`. Harmonic balance
//! never needs `M^-1`; simulation solves `F(t, q, v, a) = 0` for `a`. A model that adds
//! physical effects only has to supply this residual and its Jacobians.
//!
//! Coordinates: `q = (x, y, b_1, ..., b_n)` (see `shared/spec/model.md` section 2),
//! or another [`Layout`] a model declares; solvers ask the layout, never assume it.
//! Ball rows are divided by `m_i = mu eta_i` so that light balls do not make the
//! harmonic-balance Jacobian badly scaled.

use super::component::fd_add_jacobians;
use super::Layout;

/// Where a model writes (or adds) the three Jacobians of its residual `F(t, q, v, a)`,
/// each row-major `d x d`: `k = dF/dq`, `c = dF/dv`, `m = dF/da`. One argument rather
/// than three, so that the outputs travel together through components and assemblies.
pub struct Jacobians<'a> {
    pub k: &'a mut [f64],
    pub c: &'a mut [f64],
    pub m: &'a mut [f64],
}

impl<'a> Jacobians<'a> {
    #[inline(always)]
    pub fn new(k: &'a mut [f64], c: &'a mut [f64], m: &'a mut [f64]) -> Self {
        Jacobians { k, c, m }
    }
}

/// The dynamics interface shared by every analysis.
pub trait Dynamics: Send + Sync {
    /// Number of generalised coordinates `d`.
    fn ndof(&self) -> usize;
    /// Residual `F(t, q, v, a)` into `out` (length `d`).
    fn residual(&self, t: f64, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]);
    /// Row-major `d x d` Jacobians `K = dF/dq`, `C = dF/dv`, `M = dF/da` at `(t, q, v, a)`.
    /// Default: central differences of [`Self::residual`] (steps scaled to each
    /// variable), for a model without analytic derivatives; `6 d` residuals per call.
    fn jacobians(&self, t: f64, q: &[f64], v: &[f64], a: &[f64], jac: Jacobians<'_>) {
        let Jacobians { k, c, m } = jac;
        k.fill(0.0);
        c.fill(0.0);
        m.fill(0.0);
        let mut full = vec![0.0; q.len()];
        fd_add_jacobians(
            |q, v, a, out| {
                self.residual(t, q, v, a, &mut full);
                out.iter_mut().zip(&full).for_each(|(o, f)| *o += f);
            },
            q,
            v,
            a,
            k,
            c,
            m,
        );
    }
    /// Solves `M(q) z = rhs` in place (`M = dF/da`).
    fn solve_mass(&self, t: f64, q: &[f64], rhs: &mut [f64]);
    /// Solves `M(q) Z = B` in place for `B` stored as consecutive columns of length `d`.
    /// Models override it to factor `M` once for all columns.
    fn solve_mass_columns(&self, t: f64, q: &[f64], cols: &mut [f64]) {
        let d = self.ndof();
        for c in cols.chunks_mut(d) {
            self.solve_mass(t, q, c);
        }
    }
    /// Accelerations solving `F(t, q, v, a) = 0`: `a = -M^-1 F(t, q, v, 0)` (`F` is
    /// affine in `a`). Models with a cheaper route override it.
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
    /// `None` when the equations do not depend on `t`; otherwise the effect responsible.
    fn time_dependence(&self) -> Option<String> {
        None
    }
    /// The disk's spin `Omega` at rest of any spin profile: simulated starts begin at
    /// rest in the ground frame, i.e. with ball rates `-Omega`.
    fn base_spin(&self) -> f64 {
        0.0
    }
    /// Where each coordinate lives in `q`. Default: the planar `(x, y, b_1, ..., b_n)`.
    fn layout(&self) -> Layout {
        Layout::planar(self.ndof().saturating_sub(2))
    }
    /// Index of the first ball angle in `q` (the coordinates before it are the rotor's).
    fn first_ball(&self) -> usize {
        self.layout().first_ball
    }
    /// Whether ball angles that differ by whole turns are the same state (not so when
    /// springs count the turns).
    fn angles_modulo_turns(&self) -> bool {
        true
    }
}

/// First-order right-hand side `y' = f(t, y)` with `y = (q, v)`.
pub fn first_order_rhs<D: Dynamics + ?Sized>(model: &D, t: f64, y: &[f64], dy: &mut [f64]) {
    let d = model.ndof();
    let (q, v) = y.split_at(d);
    dy[..d].copy_from_slice(v);
    model.accel(t, q, v, &mut dy[d..]);
}
