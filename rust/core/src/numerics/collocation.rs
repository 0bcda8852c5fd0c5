//! Periodic orbits by orthogonal collocation on an adaptive mesh (AUTO-07p's and
//! COLSYS's discretisation), next to harmonic balance ([`crate::hb`]).
//!
//! Harmonic balance is the right tool while an orbit is smooth. Near the infinite-period
//! end of a rotating branch the orbit spends its time in a narrow slow phase and crosses
//! the rest in a fast jump, and a Fourier series needs ever more harmonics; piecewise
//! polynomials on a mesh that crowds into the jump do not.
//!
//! The first-order state `y = (q, q')` of the model is followed in scaled time
//! `s = t / T` in `[0, 1]`. Each of the `NTST` mesh intervals carries a polynomial of
//! degree `NCOL`, given by its values at `NCOL + 1` equally spaced points (the ends are
//! mesh points shared with the neighbours, so continuity holds by construction). The
//! unknowns are those values, `n (NTST NCOL + 1)` for `n = 2 d` states, and the period
//! `T`. The equations:
//! - collocation `y'(s) = T f(y(s))` at the `NCOL` Gauss–Legendre points of every
//!   interval (multiplied by the interval's length, so rows are of the size of `y`);
//! - periodicity `y(1) = y(0) + jump`: rotating balls gain `2 pi w` per period
//!   (`w` their winding, as harmonic balance's secular term), everything else returns;
//! - AUTO's integral phase condition `int_0^1 <y(s) - y_ref(s), y_ref'(s)> ds = 0`
//!   against a reference orbit (the start, or the previous solution).
//!
//! Newton solves the linearisation by AUTO's condensation: each interval's interior
//! values are eliminated with partial pivoting (leaving `n` equations between the two
//! mesh values), then the mesh values one after another (a pivoted sweep), leaving a
//! `(2n + 1)`-row system in `y(0), y(1), T`: linear work in `NTST`, no dense Jacobian.
//! The sweep's last block is the discretised variational equation's map
//! `dy(0) -> dy(1)`: its eigenvalues are the Floquet multipliers (AUTO's way); they get
//! an error bound from the monodromy integrated along the collocation orbit at tight
//! tolerance ([`multipliers_checked`]).
//!
//! The mesh is adapted as in AUTO and COLSYS: the `NCOL`-th derivative is constant on
//! each interval; its jumps between intervals estimate the `(NCOL + 1)`-th; the new
//! mesh equidistributes that derivative's `1/(NCOL + 1)`-th power, and the solution is
//! re-interpolated onto it.

use crate::error::{Error, Result};
use crate::hb::HbSolution;
use crate::linalg::{eigenvalues, lu_solve, state_matrix};
use crate::model::Dynamics;
use crate::model::Jacobians;
use crate::numerics::floquet::judge;
use crate::numerics::ode::{Dopri5, Options};
use crate::numerics::problem::{At, ModelAt, Parametric, Problem};
use std::f64::consts::PI;

/// Collocation points per interval unless asked otherwise (AUTO's default too).
pub const NCOL_DEFAULT: usize = 4;
/// Most collocation points per interval (Gauss points of degree 7 reach order 14).
pub const NCOL_MAX: usize = 7;
/// Most mesh intervals: `NTST NCOL n` unknowns stay a few hundred thousand for the
/// largest scenes and memory linear in `NTST`.
pub const NTST_MAX: usize = 10_000;

/// Gauss–Legendre nodes and weights on `[0, 1]`, nodes increasing.
pub fn gauss_legendre(m: usize) -> (Vec<f64>, Vec<f64>) {
    let (mut z, mut w) = (vec![0.0; m], vec![0.0; m]);
    for i in 0..m {
        // Newton on P_m from the asymptotic guess for its (i+1)-th largest root.
        let mut x = (PI * (i as f64 + 0.75) / (m as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=m {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            let pm = if m == 0 { 1.0 } else { p1 };
            let pm1 = if m == 1 { 1.0 } else { p0 };
            dp = m as f64 * (x * pm - pm1) / (x * x - 1.0);
            let dx = pm / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        // x runs from the largest root down: s = (1 - x) / 2 increases.
        z[i] = 0.5 * (1.0 - x);
        w[i] = 1.0 / ((1.0 - x * x) * dp * dp);
    }
    (z, w)
}

/// Lagrange basis on the `ncol + 1` equally spaced points `k / ncol` of `[0, 1]`:
/// values and first derivatives at `s`.
fn lagrange(ncol: usize, s: f64, l: &mut [f64], dl: &mut [f64]) {
    let nodes: Vec<f64> = (0..=ncol).map(|k| k as f64 / ncol as f64).collect();
    for k in 0..=ncol {
        let mut den = 1.0;
        let mut val = 1.0;
        let mut der = 0.0;
        for m in 0..=ncol {
            if m == k {
                continue;
            }
            den *= nodes[k] - nodes[m];
            // Product rule, accumulated: d(val * (s - x_m)) = der (s - x_m) + val.
            der = der * (s - nodes[m]) + val;
            val *= s - nodes[m];
        }
        l[k] = val / den;
        dl[k] = der / den;
    }
}

/// Weights `c_k` with `p^(ncol) = sum_k c_k p(k / ncol)` for a polynomial of degree
/// `ncol` on `[0, 1]` (its leading coefficient times `ncol!`).
fn top_derivative_weights(ncol: usize) -> Vec<f64> {
    let fact: f64 = (1..=ncol).map(|k| k as f64).product();
    (0..=ncol)
        .map(|k| {
            let den: f64 = (0..=ncol)
                .filter(|&m| m != k)
                .map(|m| (k as f64 - m as f64) / ncol as f64)
                .product();
            fact / den
        })
        .collect()
}

/// A periodic orbit on a collocation mesh.
#[derive(Debug, Clone)]
pub struct CollocOrbit {
    /// Mesh points `0 = s_0 < ... < s_NTST = 1` in scaled time.
    pub mesh: Vec<f64>,
    pub ncol: usize,
    /// States per point, `2 d`.
    pub n: usize,
    /// States at the points `s_j + (s_{j+1} - s_j) k / NCOL`, interval by interval
    /// (`NTST NCOL + 1` points of `n` values; rotating angles unwrapped).
    pub u: Vec<f64>,
    pub period: f64,
    /// `y(1) - y(0)`: `2 pi w` on a ball angle with winding `w`, otherwise 0.
    pub jump: Vec<f64>,
}

impl CollocOrbit {
    pub fn ntst(&self) -> usize {
        self.mesh.len() - 1
    }

    /// The state at point `k` of interval `j` (`k = NCOL` is the next mesh point).
    pub fn at(&self, j: usize, k: usize) -> &[f64] {
        let p = j * self.ncol + k;
        &self.u[p * self.n..(p + 1) * self.n]
    }

    /// The state and its derivative in scaled time at `s` (any real: the orbit
    /// continues periodically with its jump).
    pub fn eval(&self, s: f64, y: &mut [f64], dy: &mut [f64]) {
        let turns = s.floor();
        let s0 = s - turns;
        let j = self
            .mesh
            .partition_point(|&m| m <= s0)
            .clamp(1, self.ntst())
            - 1;
        let h = self.mesh[j + 1] - self.mesh[j];
        let sigma = (s0 - self.mesh[j]) / h;
        let mut l = vec![0.0; self.ncol + 1];
        let mut dl = vec![0.0; self.ncol + 1];
        lagrange(self.ncol, sigma, &mut l, &mut dl);
        y.fill(0.0);
        dy.fill(0.0);
        for k in 0..=self.ncol {
            let p = self.at(j, k);
            for i in 0..self.n {
                y[i] += l[k] * p[i];
                dy[i] += dl[k] * p[i] / h;
            }
        }
        for (yi, ji) in y.iter_mut().zip(&self.jump) {
            *yi += turns * ji;
        }
    }

    /// The first-order state at time `t` (in units of `1/w_n`, from the orbit's start).
    pub fn state(&self, t: f64) -> Vec<f64> {
        let (mut y, mut dy) = (vec![0.0; self.n], vec![0.0; self.n]);
        self.eval(t / self.period, &mut y, &mut dy);
        y
    }

    /// Unknowns of the collocation system: the point values, then `T`.
    pub fn unknowns(&self) -> Vec<f64> {
        let mut x = self.u.clone();
        x.push(self.period);
        x
    }

    /// The same orbit on `mesh` (same `NCOL`), values interpolated from this one.
    pub fn remeshed(&self, mesh: &[f64]) -> CollocOrbit {
        let ntst = mesh.len() - 1;
        let mut u = Vec::with_capacity((ntst * self.ncol + 1) * self.n);
        let (mut y, mut dy) = (vec![0.0; self.n], vec![0.0; self.n]);
        for j in 0..ntst {
            for k in 0..self.ncol {
                let s = mesh[j] + (mesh[j + 1] - mesh[j]) * k as f64 / self.ncol as f64;
                self.eval(s, &mut y, &mut dy);
                u.extend_from_slice(&y);
            }
        }
        // The last point is the first plus the jump exactly, not an extrapolation.
        let last: Vec<f64> = (0..self.n).map(|i| u[i] + self.jump[i]).collect();
        u.extend_from_slice(&last);
        CollocOrbit {
            mesh: mesh.to_vec(),
            ncol: self.ncol,
            n: self.n,
            u,
            period: self.period,
            jump: self.jump.clone(),
        }
    }

    /// The orbit of the state function `state(t)` (time in units of `1/w_n`) of period
    /// `period` on a uniform mesh.
    pub fn sampled(
        state: impl Fn(f64) -> Vec<f64>,
        period: f64,
        jump: Vec<f64>,
        ntst: usize,
        ncol: usize,
    ) -> CollocOrbit {
        let n = jump.len();
        let mesh: Vec<f64> = (0..=ntst).map(|j| j as f64 / ntst as f64).collect();
        let mut u = Vec::with_capacity((ntst * ncol + 1) * n);
        for p in 0..ntst * ncol {
            u.extend(state(period * p as f64 / (ntst * ncol) as f64));
        }
        let last: Vec<f64> = (0..n).map(|i| u[i] + jump[i]).collect();
        u.extend_from_slice(&last);
        CollocOrbit {
            mesh,
            ncol,
            n,
            u,
            period,
            jump,
        }
    }

    /// A harmonic-balance series as a collocation orbit on a uniform mesh (its secular
    /// terms become the balls' angle jumps).
    pub fn from_hb(sol: &HbSolution, ntst: usize, ncol: usize) -> CollocOrbit {
        CollocOrbit::sampled(
            |t| sol.state(t),
            sol.period(),
            jump_of(&sol.winding),
            ntst,
            ncol,
        )
    }

    /// A simulated stretch of motion as a collocation orbit: the model integrated from
    /// `y0` over `period` at tight tolerance (`y0` on, or near, an orbit of that period
    /// with the balls' windings `winding`, one per coordinate as in harmonic balance).
    pub fn from_simulation<D: Dynamics + ?Sized>(
        model: &D,
        y0: &[f64],
        period: f64,
        winding: &[f64],
        ntst: usize,
        ncol: usize,
    ) -> Result<CollocOrbit> {
        let m = ntst * ncol;
        let times: Vec<f64> = (0..m).map(|p| period * p as f64 / m as f64).collect();
        let f = |t: f64, y: &[f64], dy: &mut [f64]| crate::model::first_order_rhs(model, t, y, dy);
        let (states, _) = crate::ode::solve_at(f, 0.0, y0, &times, &Options::new(1e-11, 1e-12))?;
        let n = y0.len();
        let mut u: Vec<f64> = states.concat();
        let last: Vec<f64> = (0..n).map(|i| u[i] + jump_of(winding)[i]).collect();
        u.extend_from_slice(&last);
        Ok(CollocOrbit {
            mesh: (0..=ntst).map(|j| j as f64 / ntst as f64).collect(),
            ncol,
            n,
            u,
            period,
            jump: jump_of(winding),
        })
    }
}

/// The first-order state's jump over one period for coordinates with `winding` turns:
/// `2 pi w` on the positions, 0 on the rates.
pub fn jump_of(winding: &[f64]) -> Vec<f64> {
    let mut j: Vec<f64> = winding.iter().map(|w| 2.0 * PI * w).collect();
    j.extend(winding.iter().map(|_| 0.0));
    j
}

/// Newton and mesh-adaptation settings.
#[derive(Debug, Clone)]
pub struct CollocOptions {
    pub ntst: usize,
    pub ncol: usize,
    /// Max-norm of the residual required for convergence.
    pub tol: f64,
    /// Max-norm of the last Newton step (relative to `1 + |x|`) required.
    pub step_tol: f64,
    pub max_iter: usize,
    /// Mesh adaptations after the first convergence (each followed by Newton again).
    pub adapt: usize,
}

impl Default for CollocOptions {
    fn default() -> Self {
        CollocOptions {
            ntst: 20,
            ncol: NCOL_DEFAULT,
            tol: 1e-10,
            step_tol: 1e-10,
            max_iter: 30,
            adapt: 3,
        }
    }
}

impl CollocOptions {
    /// Checks every option; errors name it and its range.
    pub fn validate(&self) -> Result<()> {
        if !(2..=NTST_MAX).contains(&self.ntst) {
            return Err(Error::param_range(
                "ntst",
                format!("must be in [2, {NTST_MAX}], got {}", self.ntst),
                format!("[2, {NTST_MAX}]"),
            ));
        }
        if !(1..=NCOL_MAX).contains(&self.ncol) {
            return Err(Error::param_range(
                "ncol",
                format!("must be in [1, {NCOL_MAX}], got {}", self.ncol),
                format!("[1, {NCOL_MAX}]"),
            ));
        }
        for (name, v) in [("tol", self.tol), ("step_tol", self.step_tol)] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(Error::param(
                    name,
                    format!("must be a finite number > 0, got {v}"),
                ));
            }
        }
        if !(1..=1000).contains(&self.max_iter) {
            return Err(Error::param_range(
                "max_iter",
                format!("must be in [1, 1000], got {}", self.max_iter),
                "[1, 1000]",
            ));
        }
        if self.adapt > 100 {
            return Err(Error::param_range(
                "adapt",
                format!("must be in [0, 100], got {}", self.adapt),
                "[0, 100]",
            ));
        }
        Ok(())
    }
}

/// Tables shared by every interval: the Lagrange basis and its derivative at the Gauss
/// points, and the Gauss weights.
#[derive(Debug, Clone)]
struct Tables {
    ncol: usize,
    w: Vec<f64>,
    /// `l[i * (ncol + 1) + k] = L_k(z_i)`, likewise `dl` for `L_k'`.
    l: Vec<f64>,
    dl: Vec<f64>,
}

impl Tables {
    fn new(ncol: usize) -> Self {
        let (z, w) = gauss_legendre(ncol);
        let m = ncol + 1;
        let (mut l, mut dl) = (vec![0.0; ncol * m], vec![0.0; ncol * m]);
        for i in 0..ncol {
            lagrange(
                ncol,
                z[i],
                &mut l[i * m..(i + 1) * m],
                &mut dl[i * m..(i + 1) * m],
            );
        }
        Tables { ncol, w, l, dl }
    }
}

/// The collocation equations of one orbit shape (mesh, `NCOL`, jump, phase reference),
/// evaluated for a model.
pub struct CollocSystem {
    tab: Tables,
    mesh: Vec<f64>,
    n: usize,
    jump: Vec<f64>,
    /// `h_j w_i y_ref'(z_ji)` per interval and Gauss point (`n` each): the phase row's
    /// weights before the Lagrange basis spreads them onto the point values.
    phase_w: Vec<f64>,
    /// `int <y_ref, y_ref'>`: the phase condition's constant.
    phase_c: f64,
}

/// A condensed Newton step's by-products: the map `dy(0) -> dy(1)` of the discretised
/// variational equation (row-major `n x n`).
pub struct Condensed {
    pub step: Vec<f64>,
    pub residual: f64,
    pub monodromy: Vec<f64>,
}

/// Gaussian elimination with partial pivoting of the first `ne` columns of the
/// row-major `rows x width` matrix `a`, pivots chosen among its first `piv` rows; the
/// other rows are reduced too. After it rows `0..ne` are upper triangular in those
/// columns and every later row has zeros there. `None` on a zero pivot.
fn eliminate(a: &mut [f64], width: usize, piv: usize, ne: usize) -> Option<()> {
    let rows = a.len() / width;
    for c in 0..ne {
        let (mut best, mut bv) = (c, 0.0f64);
        for r in c..piv {
            let v = a[r * width + c].abs();
            if v > bv {
                bv = v;
                best = r;
            }
        }
        if !(bv > 0.0) || !bv.is_finite() {
            return None;
        }
        if best != c {
            for k in 0..width {
                a.swap(c * width + k, best * width + k);
            }
        }
        let p = a[c * width + c];
        for r in c + 1..rows {
            let f = a[r * width + c] / p;
            if f != 0.0 {
                for k in c..width {
                    a[r * width + k] -= f * a[c * width + k];
                }
            }
        }
    }
    Some(())
}

/// Solves the upper-triangular pivot rows `0..ne` of an [`eliminate`]d matrix for
/// their `ne` unknowns, given the values `rest` of the columns `ne..width - 1` (the
/// last column is the right-hand side).
fn back_substitute(a: &[f64], width: usize, ne: usize, rest: &[f64]) -> Vec<f64> {
    let mut x = vec![0.0; ne];
    for c in (0..ne).rev() {
        let row = &a[c * width..(c + 1) * width];
        let mut s = row[width - 1];
        for k in c + 1..ne {
            s -= row[k] * x[k];
        }
        for (k, v) in rest.iter().enumerate() {
            s -= row[ne + k] * v;
        }
        x[c] = s / row[c];
    }
    x
}

/// `f(y)` and, with `jac`, `df/dy` (row-major `n x n`) of the first-order system.
struct Rhs {
    d: usize,
    k: Vec<f64>,
    c: Vec<f64>,
    m: Vec<f64>,
    a: Vec<f64>,
    cols: Vec<f64>,
}

impl Rhs {
    fn new(d: usize) -> Self {
        Rhs {
            d,
            k: vec![0.0; d * d],
            c: vec![0.0; d * d],
            m: vec![0.0; d * d],
            a: vec![0.0; d],
            cols: vec![0.0; 2 * d * d],
        }
    }

    fn eval<D: Dynamics + ?Sized>(
        &mut self,
        model: &D,
        y: &[f64],
        f: &mut [f64],
        jac: Option<&mut [f64]>,
    ) {
        let d = self.d;
        let (q, v) = y.split_at(d);
        model.accel(0.0, q, v, &mut self.a);
        f[..d].copy_from_slice(v);
        f[d..].copy_from_slice(&self.a);
        if let Some(jac) = jac {
            model.jacobians(
                0.0,
                q,
                v,
                &self.a,
                Jacobians::new(&mut self.k, &mut self.c, &mut self.m),
            );
            state_matrix(model, 0.0, q, &self.k, &self.c, &mut self.cols, jac);
        }
    }
}

impl CollocSystem {
    /// The system of orbits shaped like `reference` (its mesh, `NCOL`, jump), with the
    /// phase condition against it.
    pub fn new(reference: &CollocOrbit) -> Self {
        let tab = Tables::new(reference.ncol);
        let mut sys = CollocSystem {
            tab,
            mesh: reference.mesh.clone(),
            n: reference.n,
            jump: reference.jump.clone(),
            phase_w: vec![],
            phase_c: 0.0,
        };
        sys.set_reference(reference);
        sys
    }

    /// Takes `reference` (on this system's mesh) as the phase condition's reference.
    pub fn set_reference(&mut self, reference: &CollocOrbit) {
        let (n, ncol) = (self.n, self.tab.ncol);
        let m = ncol + 1;
        let ntst = self.mesh.len() - 1;
        self.phase_w = vec![0.0; ntst * ncol * n];
        self.phase_c = 0.0;
        for j in 0..ntst {
            for i in 0..ncol {
                let pw = &mut self.phase_w[(j * ncol + i) * n..(j * ncol + i + 1) * n];
                let mut yr = vec![0.0; n];
                for k in 0..m {
                    let p = reference.at(j, k);
                    for c in 0..n {
                        // h w_i y_ref'(z) = w_i sum_k L_k'(z) y_k (the 1/h cancels).
                        pw[c] += self.tab.w[i] * self.tab.dl[i * m + k] * p[c];
                        yr[c] += self.tab.l[i * m + k] * p[c];
                    }
                }
                self.phase_c += (0..n).map(|c| pw[c] * yr[c]).sum::<f64>();
            }
        }
    }

    pub fn size(&self) -> usize {
        self.n * ((self.mesh.len() - 1) * self.tab.ncol + 1) + 1
    }

    fn ntst(&self) -> usize {
        self.mesh.len() - 1
    }

    /// Residual rows of interval `j` (`NCOL n`) into `r` and, with `jac`, their
    /// derivatives: row-major `NCOL n x ((NCOL + 1) n + 1)`, columns the interval's
    /// points in order, then `T`.
    fn interval<D: Dynamics + ?Sized>(
        &self,
        model: &D,
        rhs: &mut Rhs,
        x: &[f64],
        j: usize,
        r: &mut [f64],
        mut jac: Option<&mut [f64]>,
    ) {
        let (n, ncol) = (self.n, self.tab.ncol);
        let m = ncol + 1;
        let width = m * n + 1;
        let period = x[x.len() - 1];
        let h = self.mesh[j + 1] - self.mesh[j];
        let pts = &x[j * ncol * n..(j * ncol + m) * n];
        let (mut y, mut f) = (vec![0.0; n], vec![0.0; n]);
        let mut df = vec![0.0; n * n];
        for i in 0..ncol {
            y.fill(0.0);
            let rr = &mut r[i * n..(i + 1) * n];
            rr.fill(0.0);
            for k in 0..m {
                let (l, dl) = (self.tab.l[i * m + k], self.tab.dl[i * m + k]);
                for c in 0..n {
                    y[c] += l * pts[k * n + c];
                    rr[c] += dl * pts[k * n + c];
                }
            }
            rhs.eval(model, &y, &mut f, jac.as_ref().map(|_| &mut df[..]));
            for c in 0..n {
                rr[c] -= h * period * f[c];
            }
            if let Some(jac) = jac.as_deref_mut() {
                for c in 0..n {
                    let row = &mut jac[(i * n + c) * width..(i * n + c + 1) * width];
                    for k in 0..m {
                        let (l, dl) = (self.tab.l[i * m + k], self.tab.dl[i * m + k]);
                        for e in 0..n {
                            row[k * n + e] = -h * period * l * df[c * n + e];
                        }
                        row[k * n + c] += dl;
                    }
                    row[m * n] = -h * f[c];
                }
            }
        }
    }

    /// The full residual (collocation, periodicity, phase) at `x`.
    pub fn residual<D: Dynamics + ?Sized>(&self, model: &D, x: &[f64], r: &mut [f64]) {
        let (n, ncol) = (self.n, self.tab.ncol);
        let mut rhs = Rhs::new(n / 2);
        let ntst = self.ntst();
        for j in 0..ntst {
            let (a, b) = (j * ncol * n, (j + 1) * ncol * n);
            self.interval(model, &mut rhs, x, j, &mut r[a..b], None);
        }
        let base = ntst * ncol * n;
        for c in 0..n {
            r[base + c] = x[base + c] - x[c] - self.jump[c];
        }
        r[base + n] = self.phase(x);
    }

    fn phase(&self, x: &[f64]) -> f64 {
        let (n, ncol) = (self.n, self.tab.ncol);
        let m = ncol + 1;
        let mut s = -self.phase_c;
        for j in 0..self.ntst() {
            for i in 0..ncol {
                let pw = &self.phase_w[(j * ncol + i) * n..(j * ncol + i + 1) * n];
                for k in 0..m {
                    let l = self.tab.l[i * m + k];
                    let p = &x[(j * ncol + k) * n..(j * ncol + k + 1) * n];
                    s += l * (0..n).map(|c| pw[c] * p[c]).sum::<f64>();
                }
            }
        }
        s
    }

    /// The full row-major Jacobian (dense: for [`Problem`] users and checks; the
    /// solver itself never forms it).
    pub fn jacobian_dense<D: Dynamics + ?Sized>(
        &self,
        model: &D,
        x: &[f64],
        r: &mut [f64],
        jac: &mut [f64],
    ) {
        let (n, ncol) = (self.n, self.tab.ncol);
        let m = ncol + 1;
        let size = self.size();
        let lw = m * n + 1;
        jac.fill(0.0);
        let mut rhs = Rhs::new(n / 2);
        let mut local = vec![0.0; ncol * n * lw];
        let ntst = self.ntst();
        for j in 0..ntst {
            let (a, b) = (j * ncol * n, (j + 1) * ncol * n);
            self.interval(model, &mut rhs, x, j, &mut r[a..b], Some(&mut local));
            for row in 0..ncol * n {
                let g = (a + row) * size;
                for col in 0..m * n {
                    jac[g + j * ncol * n + col] = local[row * lw + col];
                }
                jac[g + size - 1] = local[row * lw + m * n];
            }
        }
        let base = ntst * ncol * n;
        for c in 0..n {
            r[base + c] = x[base + c] - x[c] - self.jump[c];
            jac[(base + c) * size + base + c] = 1.0;
            jac[(base + c) * size + c] -= 1.0;
        }
        r[base + n] = self.phase(x);
        let prow = (base + n) * size;
        for j in 0..ntst {
            for i in 0..ncol {
                let pw = &self.phase_w[(j * ncol + i) * n..(j * ncol + i + 1) * n];
                for k in 0..m {
                    let l = self.tab.l[i * m + k];
                    for c in 0..n {
                        jac[prow + (j * ncol + k) * n + c] += l * pw[c];
                    }
                }
            }
        }
    }

    /// One Newton step `J dx = -F(x)` by condensation, with the residual's max-norm and
    /// the discretised monodromy. `None` where a pivot vanished (a singular system).
    pub fn newton_step<D: Dynamics + ?Sized>(&self, model: &D, x: &[f64]) -> Option<Condensed> {
        let (n, ncol) = (self.n, self.tab.ncol);
        let m = ncol + 1;
        let ntst = self.ntst();
        let ni = (ncol - 1) * n; // interior unknowns per interval
        let lw = m * n + 1; // interval Jacobian width
                            // Condensation matrix of an interval: columns [interior | y_j | y_j+1 | T | rhs],
                            // rows the NCOL n collocation rows, then the phase row's share.
        let cw = ni + 2 * n + 2;
        let crow = ncol * n + 1;
        let mut rhs = Rhs::new(n / 2);
        let mut r = vec![0.0; ncol * n];
        let mut local = vec![0.0; ncol * n * lw];
        let mut cond: Vec<Vec<f64>> = Vec::with_capacity(ntst);
        let mut res = 0.0f64;
        // The reduced phase row over [y_0 .. y_NTST | T | rhs].
        let mut phase = vec![0.0; (ntst + 1) * n + 2];
        // Condensed interval equations: E_j y_j + G_j y_j+1 + e_j T = s_j (n rows of
        // width 2n + 2).
        let mut red: Vec<Vec<f64>> = Vec::with_capacity(ntst);
        let col_of = |k: usize| -> usize {
            if k == 0 {
                ni
            } else if k == ncol {
                ni + n
            } else {
                (k - 1) * n
            }
        };
        for j in 0..ntst {
            if crate::cancel::cancelled() {
                return None;
            }
            self.interval(model, &mut rhs, x, j, &mut r, Some(&mut local));
            res = r.iter().fold(res, |a, v| a.max(v.abs()));
            let mut a = vec![0.0; crow * cw];
            for row in 0..ncol * n {
                for k in 0..m {
                    let c0 = col_of(k);
                    for e in 0..n {
                        a[row * cw + c0 + e] = local[row * lw + k * n + e];
                    }
                }
                a[row * cw + ni + 2 * n] = local[row * lw + m * n];
                a[row * cw + cw - 1] = -r[row];
            }
            let prow = ncol * n * cw;
            for i in 0..ncol {
                let pw = &self.phase_w[(j * ncol + i) * n..(j * ncol + i + 1) * n];
                for k in 0..m {
                    let l = self.tab.l[i * m + k];
                    let c0 = col_of(k);
                    for c in 0..n {
                        a[prow + c0 + c] += l * pw[c];
                    }
                }
            }
            eliminate(&mut a, cw, ncol * n, ni)?;
            // Rows ni..ncol n: the interval's condensed equations.
            let mut e = vec![0.0; n * (2 * n + 2)];
            for row in 0..n {
                e[row * (2 * n + 2)..(row + 1) * (2 * n + 2)]
                    .copy_from_slice(&a[(ni + row) * cw + ni..(ni + row + 1) * cw]);
            }
            red.push(e);
            for c in 0..n {
                phase[j * n + c] += a[prow + ni + c];
                phase[(j + 1) * n + c] += a[prow + ni + n + c];
            }
            phase[(ntst + 1) * n] += a[prow + ni + 2 * n];
            phase[(ntst + 1) * n + 1] += a[prow + cw - 1];
            a.truncate(ni * cw);
            cond.push(a);
        }
        let base = ntst * ncol * n;
        let per: Vec<f64> = (0..n).map(|c| x[base + c] - x[c] - self.jump[c]).collect();
        let ph = self.phase(x);
        res = per.iter().fold(res, |a, v| a.max(v.abs())).max(ph.abs());
        phase[(ntst + 1) * n + 1] -= ph;

        // The sweep: acc = [A y_0 + B y_k + t T = s], combined with interval k's rows to
        // eliminate y_k. Columns of the combined matrix: [y_k | y_0 | y_k+1 | T | rhs].
        let sw = 3 * n + 2;
        let mut acc = red[0].clone(); // columns [y_0 | y_1 | T | rhs]
        let mut sweeps: Vec<Vec<f64>> = Vec::with_capacity(ntst.saturating_sub(1));
        let tcol = (ntst + 1) * n;
        for k in 1..ntst {
            let mut b = vec![0.0; (2 * n + 1) * sw];
            for row in 0..n {
                let s = &acc[row * (2 * n + 2)..(row + 1) * (2 * n + 2)];
                let d = &mut b[row * sw..(row + 1) * sw];
                d[..n].copy_from_slice(&s[n..2 * n]); // y_k
                d[n..2 * n].copy_from_slice(&s[..n]); // y_0
                d[3 * n] = s[2 * n];
                d[3 * n + 1] = s[2 * n + 1];
                let s = &red[k][row * (2 * n + 2)..(row + 1) * (2 * n + 2)];
                let d = &mut b[(n + row) * sw..(n + row + 1) * sw];
                d[..n].copy_from_slice(&s[..n]); // y_k
                d[2 * n..3 * n].copy_from_slice(&s[n..2 * n]); // y_k+1
                d[3 * n] = s[2 * n];
                d[3 * n + 1] = s[2 * n + 1];
            }
            let pr = 2 * n * sw;
            for c in 0..n {
                b[pr + c] = phase[k * n + c];
                b[pr + n + c] = phase[c];
                b[pr + 2 * n + c] = phase[(k + 1) * n + c];
            }
            b[pr + 3 * n] = phase[tcol];
            b[pr + 3 * n + 1] = phase[tcol + 1];
            eliminate(&mut b, sw, 2 * n, n)?;
            for c in 0..n {
                phase[k * n + c] = 0.0;
                phase[c] = b[pr + n + c];
                phase[(k + 1) * n + c] = b[pr + 2 * n + c];
            }
            phase[tcol] = b[pr + 3 * n];
            phase[tcol + 1] = b[pr + 3 * n + 1];
            for row in 0..n {
                let s = &b[(n + row) * sw..(n + row + 1) * sw];
                acc[row * (2 * n + 2)..(row + 1) * (2 * n + 2)].copy_from_slice(&s[n..]);
            }
            b.truncate(n * sw);
            sweeps.push(b);
        }

        // The final system in [y_0 | y_N | T]: acc, periodicity, phase.
        let fs = 2 * n + 1;
        let mut fm = vec![0.0; fs * fs];
        let mut fr = vec![0.0; fs];
        for row in 0..n {
            let s = &acc[row * (2 * n + 2)..(row + 1) * (2 * n + 2)];
            fm[row * fs..(row + 1) * fs].copy_from_slice(&s[..fs]);
            fr[row] = s[fs];
            fm[(n + row) * fs + row] = -1.0;
            fm[(n + row) * fs + n + row] = 1.0;
            fr[n + row] = -per[row];
        }
        for c in 0..n {
            fm[2 * n * fs + c] = phase[c];
            fm[2 * n * fs + n + c] = phase[ntst * n + c];
        }
        fm[2 * n * fs + 2 * n] = phase[tcol];
        fr[2 * n] = phase[tcol + 1];
        let sol = lu_solve(&fm, fs, &fr)?.x;
        // Monodromy of the discretised variational equation: A dy_0 + B dy_N = 0.
        let mut bm = vec![0.0; n * n];
        for row in 0..n {
            bm[row * n..(row + 1) * n]
                .copy_from_slice(&acc[row * (2 * n + 2) + n..row * (2 * n + 2) + 2 * n]);
        }
        let lu = crate::linalg::lu_factor(&bm, n)?;
        let mut mono = vec![0.0; n * n];
        for c in 0..n {
            let col: Vec<f64> = (0..n).map(|row| -acc[row * (2 * n + 2) + c]).collect();
            let z = lu.solve(&col)?;
            for row in 0..n {
                mono[row * n + c] = z[row];
            }
        }

        // Back-substitution: mesh values, then the interiors.
        let mut ym = vec![0.0; (ntst + 1) * n];
        ym[..n].copy_from_slice(&sol[..n]);
        ym[ntst * n..].copy_from_slice(&sol[n..2 * n]);
        let dt = sol[2 * n];
        for k in (1..ntst).rev() {
            let mut rest = Vec::with_capacity(2 * n + 1);
            rest.extend_from_slice(&ym[..n]);
            rest.extend_from_slice(&ym[(k + 1) * n..(k + 2) * n]);
            rest.push(dt);
            let yk = back_substitute(&sweeps[k - 1], sw, n, &rest);
            ym[k * n..(k + 1) * n].copy_from_slice(&yk);
        }
        let mut step = vec![0.0; x.len()];
        for j in 0..ntst {
            let mut rest = Vec::with_capacity(2 * n + 1);
            rest.extend_from_slice(&ym[j * n..(j + 1) * n]);
            rest.extend_from_slice(&ym[(j + 1) * n..(j + 2) * n]);
            rest.push(dt);
            let inner = back_substitute(&cond[j], cw, ni, &rest);
            let p0 = j * ncol * n;
            step[p0..p0 + n].copy_from_slice(&ym[j * n..(j + 1) * n]);
            step[p0 + n..p0 + ncol * n].copy_from_slice(&inner);
        }
        step[base..base + n].copy_from_slice(&ym[ntst * n..]);
        step[base + n] = dt;
        Some(Condensed {
            step,
            residual: res,
            monodromy: mono,
        })
    }

    /// Per-interval `(NCOL + 1)`-th derivative estimates (norm over the states) from
    /// the jumps of the `NCOL`-th derivative between neighbouring intervals (periodic
    /// wrap-around).
    fn top_derivative_jumps(&self, orbit: &CollocOrbit) -> Vec<f64> {
        let (n, ncol) = (self.n, self.tab.ncol);
        let ntst = self.ntst();
        let wts = top_derivative_weights(ncol);
        let h: Vec<f64> = (0..ntst).map(|j| self.mesh[j + 1] - self.mesh[j]).collect();
        let dn: Vec<Vec<f64>> = (0..ntst)
            .map(|j| {
                let hp = h[j].powi(ncol as i32);
                (0..n)
                    .map(|c| (0..=ncol).map(|k| wts[k] * orbit.at(j, k)[c]).sum::<f64>() / hp)
                    .collect()
            })
            .collect();
        let jump = |a: usize, b: usize| -> f64 {
            let s: f64 = (0..n).map(|c| (dn[b][c] - dn[a][c]).powi(2)).sum();
            s.sqrt() / (0.5 * (h[a] + h[b]))
        };
        (0..ntst)
            .map(|j| {
                let prev = (j + ntst - 1) % ntst;
                let next = (j + 1) % ntst;
                0.5 * (jump(prev, j) + jump(j, next))
            })
            .collect()
    }

    /// A mesh of `ntst` intervals equidistributing `|y^(NCOL+1)|^(1/(NCOL+1))` of
    /// `orbit` (on this system's mesh), and the largest per-interval error indicator
    /// `h^(NCOL+1) |y^(NCOL+1)|` of the current mesh.
    pub fn adapted_mesh(&self, orbit: &CollocOrbit, ntst: usize) -> (Vec<f64>, f64) {
        let ncol = self.tab.ncol;
        let old = self.ntst();
        let e = self.top_derivative_jumps(orbit);
        let h: Vec<f64> = (0..old).map(|j| self.mesh[j + 1] - self.mesh[j]).collect();
        let indicator = (0..old)
            .map(|j| h[j].powi(ncol as i32 + 1) * e[j])
            .fold(0.0, f64::max);
        let p = 1.0 / (ncol as f64 + 1.0);
        let mut rho: Vec<f64> = e.iter().map(|v| v.powf(p)).collect();
        // A floor keeps intervals where the estimate happens to vanish from growing
        // without bound: a twentieth of the mean density.
        let mean: f64 = rho.iter().zip(&h).map(|(r, h)| r * h).sum::<f64>();
        let floor = 0.05 * mean.max(1e-300);
        rho.iter_mut().for_each(|r| *r = r.max(floor));
        let mut cum = vec![0.0; old + 1];
        for j in 0..old {
            cum[j + 1] = cum[j] + rho[j] * h[j];
        }
        let total = cum[old];
        let mut mesh = vec![0.0; ntst + 1];
        let mut j = 0;
        for (k, m) in mesh.iter_mut().enumerate().take(ntst).skip(1) {
            let target = total * k as f64 / ntst as f64;
            while cum[j + 1] < target {
                j += 1;
            }
            *m = self.mesh[j] + (target - cum[j]) / rho[j];
        }
        mesh[ntst] = 1.0;
        (mesh, indicator)
    }
}

/// How a collocation solve ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CollocStatus {
    Converged,
    /// The residual could not be reduced or a pivot vanished.
    Diverged,
    MaxIterations,
    Cancelled,
}

/// A collocation solve's result.
#[derive(Debug, Clone)]
pub struct CollocSolution {
    pub orbit: CollocOrbit,
    pub status: CollocStatus,
    /// Residual max-norm at the last iterate.
    pub residual: f64,
    pub iterations: usize,
    /// The discretised monodromy at the solution (row-major `n x n`), AUTO's multipliers'
    /// matrix.
    pub monodromy: Vec<f64>,
    /// The largest `h^(NCOL+1) |y^(NCOL+1)|` of the final mesh (an error indicator).
    pub mesh_error: f64,
}

/// Newton on the orbit's own mesh, the phase condition against `reference`.
fn newton<D: Dynamics + ?Sized>(
    model: &D,
    guess: &CollocOrbit,
    reference: &CollocOrbit,
    opts: &CollocOptions,
) -> CollocSolution {
    let sys = CollocSystem::new(reference);
    let mut x = guess.unknowns();
    let mut out = CollocSolution {
        orbit: guess.clone(),
        status: CollocStatus::MaxIterations,
        residual: f64::NAN,
        iterations: 0,
        monodromy: vec![],
        mesh_error: f64::NAN,
    };
    for it in 0..opts.max_iter {
        if crate::cancel::cancelled() {
            out.status = CollocStatus::Cancelled;
            break;
        }
        let Some(c) = sys.newton_step(model, &x) else {
            out.status = CollocStatus::Diverged;
            break;
        };
        out.residual = c.residual;
        out.iterations = it;
        out.monodromy = c.monodromy;
        // The states' step relative to their size, the period's to the period.
        let last = x.len() - 1;
        let xmax = x[..last].iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let smax = c.step[..last].iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let small = smax <= opts.step_tol * (1.0 + xmax)
            && c.step[last].abs() <= opts.step_tol * x[last].abs();
        if !smax.is_finite() || !c.residual.is_finite() {
            out.status = CollocStatus::Diverged;
            break;
        }
        if c.residual <= opts.tol && small {
            out.status = CollocStatus::Converged;
            break;
        }
        // A damped step: halve while the period would not stay positive.
        let mut lam = 1.0;
        let t = x[x.len() - 1];
        while t + lam * c.step[x.len() - 1] <= 0.0 && lam > 1e-3 {
            lam *= 0.5;
        }
        for (xi, si) in x.iter_mut().zip(&c.step) {
            *xi += lam * si;
        }
    }
    let np = out.orbit.u.len();
    out.orbit.u.copy_from_slice(&x[..np]);
    out.orbit.period = x[np];
    out
}

/// Solves for the periodic orbit near `guess` (which fixes `NCOL` and the jump; its mesh
/// is replaced by one of `opts.ntst` intervals), adapting the mesh `opts.adapt` times.
pub fn solve<D: Dynamics + ?Sized>(
    model: &D,
    guess: &CollocOrbit,
    opts: &CollocOptions,
) -> Result<CollocSolution> {
    opts.validate()?;
    if guess.ncol != opts.ncol {
        return Err(Error::param(
            "ncol",
            format!(
                "the guess has {} points per interval, the options {}",
                guess.ncol, opts.ncol
            ),
        ));
    }
    // A periodic orbit needs autonomous equations (the model says; numerics names no
    // analysis).
    if let Some(effect) = model.time_dependence() {
        return Err(Error::NotAutonomous { effect });
    }
    // Another NTST: a mesh of that many intervals adapted to the guess (a uniform one
    // would lose the fast jump of a long-period orbit).
    let mut start = if guess.ntst() == opts.ntst {
        guess.clone()
    } else {
        let mesh = CollocSystem::new(guess).adapted_mesh(guess, opts.ntst).0;
        guess.remeshed(&mesh)
    };
    let mut sol = newton(model, &start, &start, opts);
    for _ in 0..opts.adapt {
        if sol.status != CollocStatus::Converged {
            break;
        }
        let sys = CollocSystem::new(&sol.orbit);
        let (mesh, _) = sys.adapted_mesh(&sol.orbit, opts.ntst);
        // A mesh that would move no point by a hundredth of an average interval is the
        // one we have: another Newton run would only re-interpolate.
        let moved = mesh
            .iter()
            .zip(&sol.orbit.mesh)
            .fold(0.0f64, |a, (u, v)| a.max((u - v).abs()));
        if mesh.len() == sol.orbit.mesh.len() && moved < 0.01 / opts.ntst as f64 {
            break;
        }
        start = sol.orbit.remeshed(&mesh);
        sol = newton(model, &start, &start, opts);
    }
    if sol.status == CollocStatus::Converged {
        let sys = CollocSystem::new(&sol.orbit);
        sol.mesh_error = sys.adapted_mesh(&sol.orbit, opts.ntst).1;
    }
    if sol.status == CollocStatus::Cancelled {
        return Err(Error::Cancelled);
    }
    Ok(sol)
}

/// Multipliers with an error bound on the leading non-trivial one.
#[derive(Debug, Clone)]
pub struct CheckedMultipliers {
    /// Eigenvalues of the discretised monodromy (AUTO's), largest modulus first.
    pub multipliers: Vec<(f64, f64)>,
    /// The same from the monodromy integrated along the collocation orbit (Dormand–
    /// Prince at `rtol`), largest modulus first.
    pub integrated: Vec<(f64, f64)>,
    /// Leading non-trivial modulus of each.
    pub max_modulus: f64,
    pub max_modulus_integrated: f64,
    /// Twice the two leading moduli's difference: the bound a verdict is judged
    /// against.
    pub modulus_error: f64,
    /// `|lambda_trivial - 1|` of the discretised multipliers.
    pub trivial_error: f64,
}

/// The multipliers of a converged solution, AUTO's way (eigenvalues of its discretised
/// monodromy), and the same from the variational equation integrated along the orbit
/// at tolerance `rtol` (every `dt` sampled from the collocation polynomial): their
/// difference bounds the discretised ones' error.
pub fn multipliers_checked<D: Dynamics + ?Sized>(
    model: &D,
    sol: &CollocSolution,
    rtol: f64,
) -> Result<CheckedMultipliers> {
    let n = sol.orbit.n;
    let eig = |m: &[f64]| -> Result<Vec<(f64, f64)>> {
        let mut ev = eigenvalues(m, n)
            .ok_or_else(|| Error::Eigen("eigenvalues of the collocation monodromy".into()))?;
        ev.sort_by(|a, b| b.0.hypot(b.1).total_cmp(&a.0.hypot(a.1)));
        Ok(ev)
    };
    let ev = eig(&sol.monodromy)?;
    let phi = integrated_monodromy(model, &sol.orbit, rtol)?;
    let ei = eig(&phi)?;
    let (a, b) = (judge(&ev, 0.0, 1.0), judge(&ei, 0.0, 1.0));
    Ok(CheckedMultipliers {
        max_modulus: a.max_modulus,
        max_modulus_integrated: b.max_modulus,
        modulus_error: 2.0 * (a.max_modulus - b.max_modulus).abs(),
        trivial_error: a.trivial_error,
        multipliers: ev,
        integrated: ei,
    })
}

/// The monodromy (row-major `n x n`) of the variational equation along the collocation
/// orbit, integrated by Dormand–Prince at `rtol` (absolute tolerance `rtol` too).
pub fn integrated_monodromy<D: Dynamics + ?Sized>(
    model: &D,
    orbit: &CollocOrbit,
    rtol: f64,
) -> Result<Vec<f64>> {
    let n = orbit.n;
    let period = orbit.period;
    let mut y0 = vec![0.0; n * n];
    for i in 0..n {
        y0[i * n + i] = 1.0;
    }
    let mut rhs = Rhs::new(n / 2);
    let (mut y, mut dy, mut f, mut a) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n * n]);
    let deriv = |t: f64, p: &[f64], dp: &mut [f64]| {
        orbit.eval(t / period, &mut y, &mut dy);
        rhs.eval(model, &y, &mut f, Some(&mut a));
        for i in 0..n {
            let out = &mut dp[i * n..(i + 1) * n];
            out.fill(0.0);
            for k in 0..n {
                let aik = a[i * n + k];
                if aik != 0.0 {
                    for (o, v) in out.iter_mut().zip(&p[k * n..(k + 1) * n]) {
                        *o += aik * v;
                    }
                }
            }
        }
    };
    let mut solver = Dopri5::new(n * n);
    let (_, phi, _) = solver.integrate(
        deriv,
        0.0,
        &y0,
        period,
        &Options::new(rtol, rtol),
        |_, _, _| !crate::cancel::cancelled(),
    )?;
    Ok(phi)
}

/// The slowest speed `min_t |f(y(t))|` (Euclidean norm of the first-order vector field)
/// along the orbit, and the scaled time where it is reached. Near a saddle-node on an
/// invariant circle the orbit passes the bottleneck at a speed proportional to the
/// parameter's distance from the saddle-node (normal form `x' = a (p - p*) + b x^2`), so
/// it falls to zero linearly at the infinite-period end, where the period (`~ 1 /
/// sqrt|p - p*|`) diverges: a test function read off the orbit itself. Each interval is
/// sampled at `4 NCOL + 1` points, then the best sample's neighbourhood is searched by
/// golden section (the slow phase is smooth, the minimum a parabola there).
pub fn slowest_speed<D: Dynamics + ?Sized>(model: &D, orbit: &CollocOrbit) -> (f64, f64) {
    let n = orbit.n;
    let mut rhs = Rhs::new(n / 2);
    let (mut y, mut dy, mut f) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut speed = |s: f64| {
        orbit.eval(s, &mut y, &mut dy);
        rhs.eval(model, &y, &mut f, None);
        f.iter().map(|v| v * v).sum::<f64>().sqrt()
    };
    let per = 4 * orbit.ncol;
    let (mut best, mut at, mut width) = (f64::INFINITY, 0.0, 0.0);
    for j in 0..orbit.ntst() {
        let (a, b) = (orbit.mesh[j], orbit.mesh[j + 1]);
        for k in 0..per {
            let s = a + (b - a) * k as f64 / per as f64;
            let v = speed(s);
            if v < best {
                (best, at, width) = (v, s, (b - a) / per as f64);
            }
        }
    }
    // Golden section on [at - width, at + width].
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut lo, mut hi) = (at - width, at + width);
    let (mut c, mut d) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut fc, mut fd) = (speed(c), speed(d));
    for _ in 0..80 {
        if fc < fd {
            hi = d;
            (d, fd) = (c, fc);
            c = hi - g * (hi - lo);
            fc = speed(c);
        } else {
            lo = c;
            (c, fc) = (d, fd);
            d = lo + g * (hi - lo);
            fd = speed(d);
        }
        if hi - lo < 1e-15 {
            break;
        }
    }
    let (s, v) = if fc < fd { (c, fc) } else { (d, fd) };
    if v < best {
        (v, s.rem_euclid(1.0))
    } else {
        (best, at)
    }
}

/// The collocation system as a [`Problem`] (dense Jacobian; for the package's generic
/// continuation and checks on small meshes): unknowns the point values and `T`, the
/// parameter one of the model's.
pub struct CollocProblem<'a, D: Dynamics + ?Sized> {
    sys: CollocSystem,
    models: ModelAt<'a, D>,
}

impl<'a, D: Dynamics + ?Sized> CollocProblem<'a, D> {
    pub fn new(models: ModelAt<'a, D>, reference: &CollocOrbit) -> Self {
        CollocProblem {
            sys: CollocSystem::new(reference),
            models,
        }
    }
}

impl<D: Dynamics + ?Sized> Problem for CollocProblem<'_, D> {
    fn size(&self) -> usize {
        self.sys.size()
    }
    fn param(&self) -> f64 {
        self.models.value()
    }
    fn residual(&mut self, x: &[f64], p: f64, r: &mut [f64]) -> Result<()> {
        match self.models.at(p)? {
            At::Base(m) => self.sys.residual(m, x, r),
            At::Varied(m) => self.sys.residual(m, x, r),
        }
        Ok(())
    }
    fn jac_x(&mut self, x: &[f64], p: f64, r: &mut [f64], jac: &mut [f64]) -> Result<()> {
        match self.models.at(p)? {
            At::Base(m) => self.sys.jacobian_dense(m, x, r, jac),
            At::Varied(m) => self.sys.jacobian_dense(m, x, r, jac),
        }
        Ok(())
    }
}

/// One point of a branch followed by [`follow`].
#[derive(Debug, Clone)]
pub struct BranchPoint {
    pub param: f64,
    pub solution: CollocSolution,
}

/// Natural continuation of a collocation orbit in the model parameter `name` from the
/// solved `start` (at the model's value) towards `target`: steps of `step` at first,
/// halved after a failed solve and grown by half after an easy one, until `target` is
/// reached or the step falls below `min_step` (then the branch ends there, e.g. at an
/// infinite-period end). The predictor keeps the last orbit's shape and extrapolates
/// its period linearly.
pub fn follow<D: Parametric>(
    model: &D,
    name: &str,
    start: &CollocSolution,
    target: f64,
    step: f64,
    min_step: f64,
    opts: &CollocOptions,
) -> Result<Vec<BranchPoint>> {
    opts.validate()?;
    if !(step > 0.0 && step.is_finite() && min_step > 0.0 && min_step <= step) {
        return Err(Error::param(
            "step",
            format!("needs 0 < min_step <= step, got step {step}, min_step {min_step}"),
        ));
    }
    let p0 = model.param_value(name)?;
    let dir = (target - p0).signum();
    let mut pts = vec![BranchPoint {
        param: p0,
        solution: start.clone(),
    }];
    let mut h = step;
    let mut slope = 0.0; // dT/dp of the last step
    while h >= min_step {
        if crate::cancel::cancelled() {
            return Err(Error::Cancelled);
        }
        let last = pts.last().unwrap();
        let left = (target - last.param) * dir;
        if left <= 0.0 {
            break;
        }
        let dp = dir * h.min(left);
        let p = last.param + dp;
        let m = model.with_param(name, p)?;
        let mut guess = last.solution.orbit.clone();
        let predicted = guess.period + slope * dp;
        if predicted > 0.0 {
            guess.period = predicted;
        }
        let sol = solve(&m, &guess, opts)?;
        // A converged orbit far from the predicted period jumped elsewhere.
        let jumped = (sol.orbit.period / last.solution.orbit.period).ln().abs() > 0.5;
        if sol.status == CollocStatus::Converged && !jumped {
            slope = (sol.orbit.period - last.solution.orbit.period) / dp;
            if sol.iterations <= 3 {
                h *= 1.5;
            }
            pts.push(BranchPoint {
                param: p,
                solution: sol,
            });
        } else {
            h *= 0.5;
        }
    }
    Ok(pts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::floquet::FloquetOptions;
    use crate::hb::{HbOptions, Status};
    use crate::model::Planar;
    use crate::periodic::{periodic, Periodic, PeriodicOptions};

    /// The standard case: merged R-R at mu 0.2, zeta 0.05, zeta_b 0.1, delta 50,
    /// eta (1, 1).
    fn balancer(omega: f64) -> Planar {
        Planar::new(0.2, 0.05, &[0.1], 50.0, omega, &[1.0, 1.0]).unwrap()
    }

    fn hb(p: &Planar, n_harm: usize, guess: Option<&HbSolution>) -> Periodic {
        let opts = PeriodicOptions {
            hb: HbOptions {
                n_harm,
                tol: 1e-12,
                ..Default::default()
            },
            floquet: Some(FloquetOptions {
                rtol: 1e-12,
                atol: 1e-13,
                ..Default::default()
            }),
            ..Default::default()
        };
        let r = periodic(p, &[true, true], guess, &opts);
        assert_eq!(r.sol.status, Status::Converged);
        r
    }

    fn opts(ntst: usize) -> CollocOptions {
        CollocOptions {
            ntst,
            ..Default::default()
        }
    }

    #[test]
    fn colloc_gauss_legendre_integrates_degree_2m_minus_1() {
        for m in 1..=NCOL_MAX {
            let (z, w) = gauss_legendre(m);
            for deg in 0..2 * m {
                let q: f64 = z.iter().zip(&w).map(|(z, w)| w * z.powi(deg as i32)).sum();
                let exact = 1.0 / (deg as f64 + 1.0);
                assert!((q - exact).abs() < 1e-14, "m {m} deg {deg}: {q} vs {exact}");
            }
        }
    }

    #[test]
    fn colloc_condensed_step_equals_the_dense_solve() {
        // The condensation is exact linear algebra: its step must be the dense LU's.
        let p = balancer(1.2);
        let r = hb(&p, 8, None);
        let mut orbit = CollocOrbit::from_hb(&r.sol, 5, 4);
        // A perturbed point, so that the step is not near zero.
        for (i, v) in orbit.u.iter_mut().enumerate() {
            *v += 1e-3 * ((i as f64) * 0.7).sin();
        }
        orbit.period *= 1.001;
        let reference = CollocOrbit::from_hb(&r.sol, 5, 4);
        let sys = CollocSystem::new(&reference);
        let x = orbit.unknowns();
        let n = sys.size();
        let (mut res, mut jac) = (vec![0.0; n], vec![0.0; n * n]);
        sys.jacobian_dense(&p, &x, &mut res, &mut jac);
        let neg: Vec<f64> = res.iter().map(|v| -v).collect();
        let dense = lu_solve(&jac, n, &neg).unwrap().x;
        let c = sys.newton_step(&p, &x).unwrap();
        let scale = dense.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let diff = dense
            .iter()
            .zip(&c.step)
            .fold(0.0f64, |a, (u, v)| a.max((u - v).abs()));
        assert!(
            scale > 1e-4 && diff < 1e-9 * scale,
            "diff {diff:e} scale {scale:e}"
        );
        // And the dense Jacobian is the residual's derivative (central differences).
        let mut worst = 0.0f64;
        for col in [0, 7, 13, n / 2, n - 2, n - 1] {
            let h = 1e-6;
            let (mut xp, mut xm) = (x.clone(), x.clone());
            xp[col] += h;
            xm[col] -= h;
            let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
            sys.residual(&p, &xp, &mut rp);
            sys.residual(&p, &xm, &mut rm);
            for row in 0..n {
                let fd = (rp[row] - rm[row]) / (2.0 * h);
                worst = worst.max((fd - jac[row * n + col]).abs());
            }
        }
        assert!(worst < 1e-6, "Jacobian vs differences: {worst:e}");
    }

    /// Times at which the ball angle `b` (state index `ib`, decreasing one turn per
    /// period) passes `b(0) - 2 pi m`, m = 1..=turns, integrating from `y0` at `rtol`:
    /// the Poincaré section's return times, found on the integrator's dense output by
    /// bisection.
    fn section_times(
        p: &Planar,
        y0: &[f64],
        ib: usize,
        turns: usize,
        t_end: f64,
        rtol: f64,
    ) -> Vec<f64> {
        let f = |t: f64, y: &[f64], dy: &mut [f64]| crate::model::first_order_rhs(p, t, y, dy);
        let start = y0[ib];
        let mut times = Vec::new();
        let mut buf = vec![0.0; y0.len()];
        let mut solver = Dopri5::new(y0.len());
        let mut prev = start;
        let _ = solver.integrate(
            f,
            0.0,
            y0,
            t_end,
            &Options::new(rtol, rtol * 1e-2),
            |ta, tb, dense| {
                let now = dense.end()[ib];
                let level = start - 2.0 * PI * (times.len() + 1) as f64;
                if prev > level && now <= level {
                    let (mut lo, mut hi) = (ta, tb);
                    for _ in 0..80 {
                        let mid = 0.5 * (lo + hi);
                        dense.eval(mid, &mut buf);
                        if buf[ib] > level {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    times.push(0.5 * (lo + hi));
                }
                prev = now;
                times.len() < turns
            },
        );
        times
    }

    /// Leading non-trivial modulus (the multiplier closest to 1 is the trivial one).
    fn leading(ev: &[(f64, f64)]) -> f64 {
        judge(ev, 0.0, 1.0).max_modulus
    }

    /// (a) Omega 1.2: the collocation orbit, started from a simulated orbit (not from
    /// harmonic balance), against harmonic balance at N = 24 (an independent method,
    /// resolved there): period and multipliers to ~1e-8; and the period against the
    /// simulation's own section return time.
    #[test]
    fn colloc_smooth_orbit_agrees_with_harmonic_balance_and_simulation() {
        let p = balancer(1.2);
        let r24 = hb(&p, 24, None);
        let f24 = r24.floquet.as_ref().unwrap();
        // A rough start (N = 3), then 30 turns of simulation onto the attractor: the
        // section crossing after them is the orbit's start, the last return time its
        // period.
        let r3 = hb(&p, 3, None);
        let times = section_times(
            &p,
            &r3.sol.state(0.0),
            2,
            30,
            40.0 * r24.sol.period(),
            1e-12,
        );
        assert_eq!(times.len(), 30);
        let t_return = times[29] - times[28];
        let f = |t: f64, y: &[f64], dy: &mut [f64]| crate::model::first_order_rhs(&p, t, y, dy);
        let (ys, _) = crate::ode::solve_at(
            f,
            0.0,
            &r3.sol.state(0.0),
            &[times[28]],
            &Options::new(1e-12, 1e-14),
        )
        .unwrap();
        assert!((t_return / r24.sol.period() - 1.0).abs() < 1e-8);
        for ntst in [20, 50] {
            let guess =
                CollocOrbit::from_simulation(&p, &ys[0], t_return, &r24.sol.winding, ntst, 4)
                    .unwrap();
            let s = solve(&p, &guess, &opts(ntst)).unwrap();
            assert_eq!(s.status, CollocStatus::Converged);
            let rel = (s.orbit.period / r24.sol.period() - 1.0).abs();
            assert!(rel < 1e-8, "NTST {ntst}: period off HB by {rel:e}");
            let m = multipliers_checked(&p, &s, 1e-12).unwrap();
            let (lc, lh) = (leading(&m.multipliers), f24.max_modulus);
            assert!((lc - lh).abs() < 1e-8, "NTST {ntst}: {lc} vs HB {lh}");
            assert!(
                m.modulus_error < 1e-8,
                "NTST {ntst}: bound {:e}",
                m.modulus_error
            );
            // The bound covers the actual error against harmonic balance.
            assert!((lc - lh).abs() <= m.modulus_error.max(1e-10));
            assert!(m.trivial_error < 1e-8);
            // Every integrated multiplier matches one of harmonic balance's.
            let d = crate::floquet::multiplier_distance(&f24.multipliers, &m.integrated);
            assert!(
                d < 1e-7,
                "NTST {ntst}: integrated multipliers off HB by {d:e}"
            );
            // The orbit itself: the series at the time where its first ball has the
            // collocation start's angle (modulo turns; Newton on b1(t)), every state
            // against the collocation start's (angles modulo turns).
            let yc = s.orbit.state(0.0);
            let wrap = |a: f64| a - 2.0 * PI * (a / (2.0 * PI)).round();
            let mut t = (0..400)
                .map(|k| r24.sol.period() * k as f64 / 400.0)
                .min_by(|a, b| {
                    let da = wrap(r24.sol.state(*a)[2] - yc[2]).abs();
                    let db = wrap(r24.sol.state(*b)[2] - yc[2]).abs();
                    da.total_cmp(&db)
                })
                .unwrap();
            for _ in 0..20 {
                let y = r24.sol.state(t);
                t -= wrap(y[2] - yc[2]) / y[6];
            }
            let yh = r24.sol.state(t);
            let off = (0..8)
                .map(|c| {
                    if c == 2 || c == 3 {
                        wrap(yh[c] - yc[c])
                    } else {
                        yh[c] - yc[c]
                    }
                })
                .fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(off < 1e-8, "NTST {ntst}: state off the series by {off:e}");
        }
    }

    /// (b) Omega 0.93, slow orbit (period ~370): the branch followed down from 1.2 by
    /// collocation, its period against the return time of a long integration at tight
    /// tolerance (the last of 8 turns: the start's error has decayed by the leading
    /// multiplier, ~1e-8, per turn, so only the integration's own error remains).
    #[test]
    fn colloc_slow_orbit_period_agrees_with_a_long_integration() {
        let p = balancer(1.2);
        let r = hb(&p, 24, None);
        let q = balancer(0.93);
        for ntst in [20, 50] {
            let o = opts(ntst);
            let s = solve(&p, &CollocOrbit::from_hb(&r.sol, ntst, 4), &o).unwrap();
            let br = follow(&p, "Omega", &s, 0.93, 0.05, 1e-6, &o).unwrap();
            let last = br.last().unwrap();
            assert!((last.param - 0.93).abs() < 1e-15);
            let times = section_times(
                &q,
                &last.solution.orbit.state(0.0),
                2,
                8,
                10.0 * last.solution.orbit.period,
                1e-12,
            );
            assert_eq!(times.len(), 8);
            let t_int = times[7] - times[6];
            assert!(t_int > 300.0);
            let rel = (last.solution.orbit.period / t_int - 1.0).abs();
            assert!(
                rel < 1e-7,
                "NTST {ntst}: period {} vs {t_int}: {rel:e}",
                last.solution.orbit.period
            );
            // The multipliers: the orbit is strongly attracting (integrated along the
            // collocation orbit, the leading non-trivial modulus is ~1e-8). The
            // discretised monodromy's (AUTO's way) is off, as AUTO's are near this end:
            // 0.40 at NTST 20, 0.009 at NTST 50. The bound (twice the difference) always
            // covers that; at NTST 50 it is small enough for a verdict, at NTST 20 not.
            let m = multipliers_checked(&q, &last.solution, 1e-11).unwrap();
            assert!(m.max_modulus_integrated < 1e-6, "NTST {ntst}: {m:?}");
            assert!((m.integrated[0].0 - 1.0).abs() < 1e-6, "NTST {ntst}: {m:?}");
            if ntst == 50 {
                assert!(m.max_modulus + m.modulus_error < 0.1, "{m:?}");
            }
        }
    }

    /// (c) Towards the infinite-period end (the saddle-node on the invariant circle at
    /// Omega* = 0.917140455, AUTO-07p's value): at NTST 50 the branch gets within 1e-7
    /// of it, and the last points follow T ~ |Omega - Omega*|^(-1/2): `T^-2` is linear
    /// in Omega, and its zero (from the orbits alone) is AUTO's Omega* to 1e-8.
    #[test]
    fn colloc_branch_reaches_the_infinite_period_end() {
        let p = balancer(0.93);
        let ntst = 50;
        let o = opts(ntst);
        let r = hb(&balancer(1.2), 24, None);
        let s = solve(&balancer(1.2), &CollocOrbit::from_hb(&r.sol, ntst, 4), &o).unwrap();
        let down = follow(&balancer(1.2), "Omega", &s, 0.93, 0.05, 1e-6, &o).unwrap();
        let br = follow(
            &p,
            "Omega",
            &down.last().unwrap().solution,
            0.9,
            0.005,
            1e-13,
            &o,
        )
        .unwrap();
        let omega_star = 0.917140455;
        let last = br.last().unwrap();
        assert!(last.param - omega_star < 1e-7, "stopped at {}", last.param);
        assert!(last.solution.orbit.period > 1e5);
        // T = C (Omega - Omega*)^(-1/2) + T0 through three points with 1e4 < T < 1.5e5
        // (long, and resolved: mesh indicator below 0.15): the Omega* that puts the
        // middle one on the line through the outer two, by bisection.
        let long: Vec<(f64, f64)> = br
            .iter()
            .filter(|b| (1e4..1.5e5).contains(&b.solution.orbit.period))
            .map(|b| (b.param, b.solution.orbit.period))
            .collect();
        assert!(long.len() >= 3, "{long:?}");
        let three = [long[0], long[long.len() / 2], long[long.len() - 1]];
        let miss = |star: f64| {
            let z = |w: f64| (w - star).powf(-0.5);
            let (a, b, c) = (three[0], three[1], three[2]);
            let slope = (c.1 - a.1) / (z(c.0) - z(a.0));
            a.1 + slope * (z(b.0) - z(a.0)) - b.1
        };
        let (mut lo, mut hi) = (three[2].0 - 1e-4, three[2].0 - 1e-12);
        assert!(miss(lo).signum() != miss(hi).signum(), "{long:?}");
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if miss(mid).signum() == miss(lo).signum() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let fitted = 0.5 * (lo + hi);
        assert!((fitted - omega_star).abs() < 5e-9, "fitted end {fitted}");
    }

    /// The slowest speed along an orbit near the infinite-period end against a brute-force
    /// minimum: the model's vector field at 200 000 evenly spaced times (its own
    /// `accel`, not the collocation's `Rhs`). The golden-section search must find a
    /// minimum at least as low, and not lower by more than the grid's resolution allows.
    #[test]
    fn colloc_slowest_speed_matches_a_dense_search() {
        let p = balancer(0.93);
        let r = hb(&balancer(1.2), 24, None);
        let o = opts(50);
        let s = solve(&balancer(1.2), &CollocOrbit::from_hb(&r.sol, 50, 4), &o).unwrap();
        let down = follow(&balancer(1.2), "Omega", &s, 0.93, 0.05, 1e-6, &o).unwrap();
        let orbit = &down.last().unwrap().solution.orbit;
        let (v, at) = slowest_speed(&p, orbit);
        let d = orbit.n / 2;
        let (mut y, mut dy, mut a) = (vec![0.0; orbit.n], vec![0.0; orbit.n], vec![0.0; d]);
        let mut brute = (f64::INFINITY, 0.0);
        let k = 200_000;
        for i in 0..k {
            let sc = i as f64 / k as f64;
            orbit.eval(sc, &mut y, &mut dy);
            p.accel(0.0, &y[..d], &y[d..], &mut a);
            let speed = (y[d..].iter().chain(&a).map(|x| x * x).sum::<f64>()).sqrt();
            if speed < brute.0 {
                brute = (speed, sc);
            }
        }
        assert!(v <= brute.0 * (1.0 + 1e-12), "{v} vs {brute:?}");
        assert!(v > 0.99 * brute.0, "{v} vs {brute:?}");
        assert!((at - brute.1).abs() < 1e-3, "{at} vs {brute:?}");
    }

    /// The collocation system through the generic [`Problem`] interface: its
    /// implicit-function tangent's `dT/dOmega` against the difference of two solves.
    #[test]
    fn colloc_problem_tangent_matches_solves() {
        let p = balancer(1.2);
        let r = hb(&p, 24, None);
        let o = CollocOptions {
            ntst: 10,
            ..Default::default()
        };
        let s = solve(&p, &CollocOrbit::from_hb(&r.sol, 10, 4), &o).unwrap();
        let mut prob = CollocProblem::new(ModelAt::family_of(&p, "Omega").unwrap(), &s.orbit);
        let x = s.orbit.unknowns();
        let mut res = vec![0.0; prob.size()];
        prob.residual(&x, 1.2, &mut res).unwrap();
        assert!(res.iter().all(|v| v.abs() < 1e-8));
        let tan = crate::numerics::problem::tangent(&mut prob, &x, 1.2)
            .unwrap()
            .unwrap();
        let dt_tangent = tan[tan.len() - 1];
        // Fixed mesh (no adaptation), so that both solves discretise alike.
        let fixed = CollocOptions { adapt: 0, ..o };
        let h = 1e-4;
        let period = |w: f64| solve(&balancer(w), &s.orbit, &fixed).unwrap().orbit.period;
        let fd = (period(1.2 + h) - period(1.2 - h)) / (2.0 * h);
        assert!(
            (dt_tangent - fd).abs() < 1e-5 * fd.abs(),
            "{dt_tangent} vs {fd}"
        );
    }

    /// Bad options are refused by name.
    #[test]
    fn colloc_options_out_of_range_are_refused() {
        let name = |o: CollocOptions| match o.validate() {
            Err(Error::InvalidParameter { name, .. }) => name,
            other => panic!("{other:?}"),
        };
        assert_eq!(
            name(CollocOptions {
                ntst: 1,
                ..Default::default()
            }),
            "ntst"
        );
        assert_eq!(
            name(CollocOptions {
                ntst: NTST_MAX + 1,
                ..Default::default()
            }),
            "ntst"
        );
        assert_eq!(
            name(CollocOptions {
                ncol: 0,
                ..Default::default()
            }),
            "ncol"
        );
        assert_eq!(
            name(CollocOptions {
                ncol: 8,
                ..Default::default()
            }),
            "ncol"
        );
        assert_eq!(
            name(CollocOptions {
                tol: f64::NAN,
                ..Default::default()
            }),
            "tol"
        );
        assert_eq!(
            name(CollocOptions {
                max_iter: 0,
                ..Default::default()
            }),
            "max_iter"
        );
    }

    /// Timings and reach (a measurement, not a test): `cargo test --release -j1 -p
    /// ballbal-core --features studies colloc_measure -- --ignored --nocapture`.
    #[cfg(feature = "studies")]
    #[test]
    #[ignore]
    fn colloc_measure() {
        let time = |f: &mut dyn FnMut()| {
            let mut v: Vec<f64> = (0..5)
                .map(|_| {
                    let t = std::time::Instant::now();
                    f();
                    t.elapsed().as_secs_f64()
                })
                .collect();
            v.sort_by(f64::total_cmp);
            v[2]
        };
        let p12 = balancer(1.2);
        let r24 = hb(&p12, 24, None);
        let s50 = solve(&p12, &CollocOrbit::from_hb(&r24.sol, 50, 4), &opts(50)).unwrap();
        let br = follow(&p12, "Omega", &s50, 0.93, 0.05, 1e-6, &opts(50)).unwrap();
        let at093 = br.last().unwrap().solution.orbit.clone();
        for (w, orbit) in [(1.2, None), (0.93, Some(&at093))] {
            let p = balancer(w);
            // Starts: the neighbouring solution at Omega + 1e-3 (a continuation step).
            let q = balancer(w + 1e-3);
            let base = match orbit {
                None => CollocOrbit::from_hb(&r24.sol, 50, 4),
                Some(o) => o.clone(),
            };
            let near = solve(&q, &base, &opts(50)).unwrap().orbit;
            for ntst in [20, 50] {
                let s = solve(&p, &near, &opts(ntst)).unwrap();
                let s1 = solve(
                    &p,
                    &near,
                    &CollocOptions {
                        adapt: 0,
                        ..opts(ntst)
                    },
                )
                .unwrap();
                println!(
                    "  Newton iterations: last run {} (adapted), {} (fixed mesh)",
                    s.iterations, s1.iterations
                );
                let t = time(&mut || {
                    let _ = solve(&p, &near, &opts(ntst)).unwrap();
                });
                let t1 = time(&mut || {
                    let _ = solve(
                        &p,
                        &near,
                        &CollocOptions {
                            adapt: 0,
                            ..opts(ntst)
                        },
                    )
                    .unwrap();
                });
                let tm = time(&mut || {
                    let _ = multipliers_checked(&p, &s, 1e-10).unwrap();
                });
                println!(
                    "Omega {w} colloc NTST {ntst}: solve {:.2} ms (3 adaptations), {:.2} ms \
                     (fixed mesh), multipliers checked {:.2} ms; T {:.12}",
                    t * 1e3,
                    t1 * 1e3,
                    tm * 1e3,
                    s.orbit.period
                );
            }
            // Harmonic balance from the same neighbour (its series fitted to the orbit).
            let d = 4;
            let winding = vec![0.0, 0.0, -1.0, -1.0];
            for n_harm in [8, 24] {
                let samples = 4 * n_harm + 8;
                let mut flat = Vec::with_capacity(samples * d);
                for i in 0..samples {
                    let y = near.state(near.period * i as f64 / samples as f64);
                    flat.extend_from_slice(&y[..d]);
                }
                let coeffs = crate::hb::fit_coefficients(&flat, d, &winding, n_harm);
                let g = HbSolution::start(
                    2.0 * PI / near.period,
                    coeffs,
                    winding.clone(),
                    n_harm,
                    Status::Converged,
                );
                let ho = HbOptions {
                    n_harm,
                    ..Default::default()
                };
                let sol = crate::hb::solve(&p, &g, &ho);
                let t = time(&mut || {
                    let _ = crate::hb::solve(&p, &g, &ho);
                });
                println!(
                    "Omega {w} HB N {n_harm}: solve {:.2} ms, {:?}, T {:.12}",
                    t * 1e3,
                    sol.status,
                    sol.period()
                );
            }
        }
        // One condensed Newton step against NTST: linear work expected.
        for ntst in [20, 50, 100, 200] {
            let o = CollocOrbit::from_hb(&r24.sol, ntst, 4);
            let sys = CollocSystem::new(&o);
            let x = o.unknowns();
            let t = time(&mut || {
                let _ = sys.newton_step(&p12, &x).unwrap();
            });
            println!("one Newton step at NTST {ntst}: {:.3} ms", t * 1e3);
        }
        // Reach towards Omega* = 0.917140455 (AUTO: NTST 20 3.1e-6, 50 8.8e-8, 100 6e-11).
        for ntst in [20, 50, 100] {
            let o = opts(ntst);
            let s = solve(&balancer(0.93), &at093, &o).unwrap();
            let t = std::time::Instant::now();
            let br = follow(&balancer(0.93), "Omega", &s, 0.9, 0.005, 1e-13, &o).unwrap();
            let last = br.last().unwrap();
            // The period there on finer meshes (from this orbit, at the same Omega).
            let here = balancer(last.param);
            for finer in [2 * ntst, 4 * ntst] {
                let f = solve(&here, &last.solution.orbit, &opts(finer)).unwrap();
                println!(
                    "  same Omega at NTST {finer}: {:?}, T {:.6e} (relative difference {:.1e})",
                    f.status,
                    f.orbit.period,
                    f.orbit.period / last.solution.orbit.period - 1.0
                );
            }
            // And a point with T ~ 3e4 (AUTO NTST 20's reach).
            if let Some(b) = br.iter().find(|b| b.solution.orbit.period > 2.5e4) {
                let f = solve(&balancer(b.param), &b.solution.orbit, &opts(4 * ntst)).unwrap();
                println!(
                    "  Omega* + {:.2e}: T {:.6e}, at NTST {}: {:.6e} (relative {:.1e})",
                    b.param - 0.917140455,
                    b.solution.orbit.period,
                    4 * ntst,
                    f.orbit.period,
                    b.solution.orbit.period / f.orbit.period - 1.0
                );
            }
            println!(
                "NTST {ntst}: 0.93 -> Omega* + {:.2e} (T {:.3e}, mesh indicator {:.1e}), {} points, {:.2} s",
                last.param - 0.917140455,
                last.solution.orbit.period,
                last.solution.mesh_error,
                br.len(),
                t.elapsed().as_secs_f64()
            );
        }
    }
}
