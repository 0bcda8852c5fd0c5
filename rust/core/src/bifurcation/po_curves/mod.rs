//! Two-parameter curves of bifurcations of periodic solutions: folds (`LP`), branch
//! points of merged balls (`BP`), period doublings (`PD`) and Neimark–Sacker points
//! (`NS`), continued in any two model
//! parameters `(p1, p2)` by pseudo-arclength on a minimally augmented system
//!
//! ```text
//!   F(x, p1, p2) = 0      (harmonic balance: coefficients and omega, phase condition)
//!   g(x, p1, p2) = 0      (g from  [[H, b], [c^T, 0]] [v; g] = [0; 1])
//! ```
//!
//! where `H` is a square matrix computed from the harmonic-balance data that is singular
//! exactly on the curve, and `b`, `c` are borders (the left and right singular vectors at
//! the start, then the previous point's adjoint and null vectors, so that the bordered
//! matrix stays well conditioned). `g` is smooth, and its gradient is
//! `g_y = -w^T H_y v` (`w` the adjoint solution): no differences over every unknown.
//!
//! * `LP`: `H = F_x`, the harmonic-balance Jacobian (with omega and the phase condition,
//!   which removes the trivial multiplier's null vector). `F_xx` is symmetric, so
//!   `w^T F_xx[v, .] = w^T (F_x(x + h v) - F_x(x - h v)) / 2h`: two Jacobians.
//! * `BP` of merged balls: the separating mode `b_1 = -b_2 = e` leaves the rotor's
//!   equations and the together subspace alone; its Galerkin block
//!   `H = J_{b1 b1} - J_{b1 b2}` is singular when the separation multiplier is +1. The
//!   curve is continued on the together subspace (unknowns: rotor and common ball
//!   series, omega; equations: rotor rows, the balls' rows summed, phase), where the
//!   branch point is a regular zero of `g` (on the full coordinates the separating null
//!   vector would make the augmented system singular too).
//! * `PD`: `H` is the Galerkin matrix of the linearisation on half harmonics
//!   `cos (k + 1/2) tau, sin (k + 1/2) tau` (`k < N`): it is singular when the
//!   linearisation has a solution of period 2T that changes sign over T, i.e. a
//!   multiplier -1, to the harmonic balance's own truncation. Its derivative uses the
//!   same symmetry, on the state perturbed along the half-harmonic null vector.
//!
//! * `NS`: `H` is Hill's matrix of the linearisation on `e^{i (k + theta/2pi) tau}`
//!   (`|k| <= N`), complex, singular when `e^{i theta}` is a multiplier. The bordered
//!   system is complex; `Re g = Im g = 0` with `theta` an extra unknown next to
//!   `(x, p1)`. `w^H H v` is a sampled sum over one period of the Floquet solution and
//!   the adjoint (`PoSystem::ns_gradient`): its gradient needs four sweeps of the
//!   model's Jacobians along `+-Re U`, `+-Im U`. The curve ends where `theta` reaches 0
//!   or pi (strong resonances 1:1, 1:2); `R4`, `R3`, `LPNS`, `PDNS`, `BPNS` are flagged.
//!
//! Merged starts (all balls on one series) are continued on the together subspace for
//! every kind, so that the balls stay merged. Codimension-two points flagged on the way
//! (sign changes of the other kinds' determinants, located in arclength): on an `LP`
//! curve `CP` (cusp: the curve reverses in the parameter plane), `BP` (it meets the
//! branch-point curve) and `LPPD` (fold–flip); on a `BP` curve `LP` and `PD`; on a `PD`
//! curve `LPPD` and `BP`.

use crate::bifurcation::event::Event;
use crate::bifurcation::po_branch::{branch_options, check_start};
use crate::continuation::curves::join_halves;
use crate::continuation::{locate, ArcOptions, ArcPoint, ArcStop, Arclength};
use crate::error::{Error, Result};
use crate::hb::{eval_series_sc, HbSolution, HbSystem, Status};
use crate::numerics::problem::{Parametric, Problem};
use crate::periodic::{finish_on_branch, Periodic, PeriodicOptions};
use nalgebra::{Complex, ComplexField, DMatrix, DVector};
use std::f64::consts::PI;

/// The bifurcation a curve continues.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PoCurveKind {
    Fold,
    BranchPoint,
    PeriodDoubling,
    NeimarkSacker,
}

impl PoCurveKind {
    /// The event whose curve this is, in the one vocabulary of all branches.
    pub fn event(self) -> Event {
        match self {
            PoCurveKind::Fold => Event::Fold,
            PoCurveKind::BranchPoint => Event::BranchPoint,
            PoCurveKind::PeriodDoubling => Event::PeriodDoubling,
            PoCurveKind::NeimarkSacker => Event::NeimarkSacker,
        }
    }

    pub fn as_str(&self) -> &'static str {
        self.event().name()
    }

    /// The curve of the event named `name` (any spelling [`Event::parse`] reads).
    pub fn parse(name: &str) -> Result<Self> {
        match Event::parse(name, "kind")? {
            Event::Fold => Ok(PoCurveKind::Fold),
            Event::BranchPoint => Ok(PoCurveKind::BranchPoint),
            Event::PeriodDoubling => Ok(PoCurveKind::PeriodDoubling),
            Event::NeimarkSacker => Ok(PoCurveKind::NeimarkSacker),
            other => Err(Error::param_range(
                "kind",
                format!("no curve of {} events of periodic orbits", other.name()),
                "fold, branch_point, period_doubling, neimark_sacker",
            )),
        }
    }
}

/// The harmonic-balance equations of a model family in two parameters, on the full
/// coordinates or on the together subspace of merged balls.
pub struct PoSystem<'a, D: Parametric> {
    base: &'a D,
    names: [String; 2],
    hb: HbSystem<'a, D>,
    reduced: bool,
    d: usize,
    o: usize,
    l: usize,
    n_harm: usize,
    samples: usize,
    winding: Vec<f64>,
    cache: Option<([u64; 2], D)>,
}

/// Step of the directional differences along a unit null vector.
const DIR_STEP: f64 = 1e-5;

impl<'a, D: Parametric> PoSystem<'a, D> {
    pub fn new(
        base: &'a D,
        names: [&str; 2],
        winding: &[f64],
        n_harm: usize,
        samples: usize,
        reduced: bool,
    ) -> Self {
        let d = base.ndof();
        PoSystem {
            base,
            names: [names[0].to_string(), names[1].to_string()],
            hb: HbSystem::new(base, winding, n_harm, samples),
            reduced,
            d,
            o: base.first_ball(),
            l: 2 * n_harm + 1,
            n_harm,
            samples,
            winding: winding.to_vec(),
            cache: None,
        }
    }

    pub fn is_reduced(&self) -> bool {
        self.reduced
    }

    /// The model at `p`.
    pub fn model(&mut self, p: [f64; 2]) -> Result<&D> {
        let key = [p[0].to_bits(), p[1].to_bits()];
        if self.cache.as_ref().is_none_or(|(k, _)| *k != key) {
            let m = self
                .base
                .with_param(&self.names[0], p[0])?
                .with_param(&self.names[1], p[1])?;
            self.cache = Some((key, m));
        }
        Ok(&self.cache.as_ref().unwrap().1)
    }

    /// Unknowns of this system.
    pub fn n(&self) -> usize {
        if self.reduced {
            (self.o + 1) * self.l + 1
        } else {
            self.nf()
        }
    }

    fn nf(&self) -> usize {
        self.d * self.l + 1
    }

    /// Full unknowns (coefficients of every coordinate, omega) from this system's.
    pub fn full(&self, x: &[f64]) -> Vec<f64> {
        if !self.reduced {
            return x.to_vec();
        }
        let (o, l) = (self.o, self.l);
        let mut f = Vec::with_capacity(self.nf());
        f.extend_from_slice(&x[..(o + 1) * l]);
        for _ in o + 1..self.d {
            f.extend_from_slice(&x[o * l..(o + 1) * l]);
        }
        f.push(x[(o + 1) * l]);
        f
    }

    /// This system's unknowns from full ones.
    pub fn reduce(&self, xf: &[f64]) -> Vec<f64> {
        if !self.reduced {
            return xf.to_vec();
        }
        let mut x = xf[..(self.o + 1) * self.l].to_vec();
        x.push(xf[self.d * self.l]);
        x
    }

    /// The reduced index of full index `i` (rows: the balls' rows are summed; columns:
    /// the common ball's coefficient moves every ball's).
    fn map(&self, i: usize) -> usize {
        if !self.reduced {
            return i;
        }
        let (o, l) = (self.o, self.l);
        if i == self.d * l {
            (o + 1) * l
        } else {
            (i / l).min(o) * l + i % l
        }
    }

    fn full_eval(
        &mut self,
        xf: &[f64],
        p: [f64; 2],
        r: &mut [f64],
        jac: Option<&mut [f64]>,
    ) -> Result<()> {
        self.model(p)?;
        let m = &self.cache.as_ref().unwrap().1;
        self.hb.assemble_with(m, xf, r, jac);
        if crate::cancel::cancelled() {
            return Err(Error::Cancelled);
        }
        Ok(())
    }

    /// `F` and, when asked, `F_x` (row-major) in this system's unknowns.
    pub fn eval(
        &mut self,
        x: &[f64],
        p: [f64; 2],
        r: &mut [f64],
        jac: Option<&mut [f64]>,
    ) -> Result<()> {
        if !self.reduced {
            return self.full_eval(x, p, r, jac);
        }
        let xf = self.full(x);
        let (nf, n) = (self.nf(), self.n());
        let mut rf = vec![0.0; nf];
        let mut jf = jac.as_ref().map(|_| vec![0.0; nf * nf]);
        self.full_eval(&xf, p, &mut rf, jf.as_deref_mut())?;
        r.fill(0.0);
        for (i, v) in rf.iter().enumerate() {
            r[self.map(i)] += v;
        }
        if let (Some(jac), Some(jf)) = (jac, jf) {
            jac.fill(0.0);
            for i in 0..nf {
                let row = self.map(i) * n;
                for k in 0..nf {
                    jac[row + self.map(k)] += jf[i * nf + k];
                }
            }
        }
        Ok(())
    }

    /// The separating mode's Galerkin block `J_{b1 b1} - J_{b1 b2}` of a full Jacobian.
    fn separating(&self, jf: &[f64]) -> DMatrix<f64> {
        let (nf, l, o) = (self.nf(), self.l, self.o);
        DMatrix::from_fn(l, l, |i, k| {
            let row = (o * l + i) * nf;
            jf[row + o * l + k] - jf[row + (o + 1) * l + k]
        })
    }

    fn full_jac(&mut self, xf: &[f64], p: [f64; 2]) -> Result<Vec<f64>> {
        let nf = self.nf();
        let (mut r, mut jf) = (vec![0.0; nf], vec![0.0; nf * nf]);
        self.full_eval(xf, p, &mut r, Some(&mut jf))?;
        Ok(jf)
    }

    fn sys_jac(&mut self, x: &[f64], p: [f64; 2]) -> Result<DMatrix<f64>> {
        let n = self.n();
        let (mut r, mut j) = (vec![0.0; n], vec![0.0; n * n]);
        self.eval(x, p, &mut r, Some(&mut j))?;
        Ok(DMatrix::from_row_slice(n, n, &j))
    }

    /// The matrix that is singular on a curve of `kind`, at this system's `x`.
    pub fn test_matrix(
        &mut self,
        kind: PoCurveKind,
        x: &[f64],
        p: [f64; 2],
    ) -> Result<DMatrix<f64>> {
        match kind {
            PoCurveKind::Fold => self.sys_jac(x, p),
            PoCurveKind::BranchPoint => {
                let xf = self.full(x);
                let jf = self.full_jac(&xf, p)?;
                Ok(self.separating(&jf))
            }
            PoCurveKind::PeriodDoubling => {
                let xf = self.full(x);
                let half = Table::new(Basis::Half, self.n_harm, self.samples, 1);
                self.galerkin(&xf, None, p, &half, &half, false, 1)
            }
            PoCurveKind::NeimarkSacker => Err(complex_kind()),
        }
    }

    /// The Galerkin matrix of the linearisation about the series `xf` (plus `pert`, a
    /// half-harmonic series, when given): rows the basis `rows` per coordinate, columns
    /// `cols` per coordinate and, with `omega_col`, the derivative in omega; sampled
    /// `periods` times over `[0, 2 pi)`.
    #[allow(clippy::too_many_arguments)]
    fn galerkin(
        &mut self,
        xf: &[f64],
        pert: Option<&[f64]>,
        p: [f64; 2],
        rows: &Table,
        cols: &Table,
        omega_col: bool,
        periods: usize,
    ) -> Result<DMatrix<f64>> {
        let (d, l, nh) = (self.d, self.l, self.n_harm);
        let s = self.samples * periods;
        let om = xf[d * l];
        let (nr, nc) = (rows.width, cols.width);
        let mut h = DMatrix::zeros(d * nr, d * nc + usize::from(omega_col));
        let half = Table::new(Basis::Half, nh, self.samples, periods);
        self.model(p)?;
        let m = &self.cache.as_ref().unwrap().1;
        let (mut q, mut qt, mut qtt) = (vec![0.0; d], vec![0.0; d], vec![0.0; d]);
        let (mut v, mut a) = (vec![0.0; d], vec![0.0; d]);
        let (mut kk, mut cc, mut mm) = (vec![0.0; d * d], vec![0.0; d * d], vec![0.0; d * d]);
        let mut g = vec![0.0; nc];
        for i in 0..s {
            let tau = 2.0 * PI * periods as f64 * i as f64 / s as f64;
            let sc = tau.sin_cos();
            for j in 0..d {
                let (x0, x1, x2) =
                    eval_series_sc(&xf[j * l..(j + 1) * l], self.winding[j], tau, sc);
                (q[j], qt[j], qtt[j]) = (x0, x1, x2);
                if let Some(e) = pert {
                    let w = 2 * nh;
                    for r in 0..w {
                        let (f0, f1, f2) = half.at(i, r);
                        q[j] += e[j * w + r] * f0;
                        qt[j] += e[j * w + r] * f1;
                        qtt[j] += e[j * w + r] * f2;
                    }
                }
                v[j] = om * qt[j];
                a[j] = om * om * qtt[j];
            }
            m.jacobians(tau / om, &q, &v, &a, &mut kk, &mut cc, &mut mm);
            for j in 0..d {
                for k in 0..d {
                    let o = j * d + k;
                    let (kv, cv, mv) = (kk[o], om * cc[o], om * om * mm[o]);
                    if kv == 0.0 && cv == 0.0 && mv == 0.0 {
                        continue;
                    }
                    for (c, gc) in g.iter_mut().enumerate() {
                        let (f0, f1, f2) = cols.at(i, c);
                        *gc = kv * f0 + cv * f1 + mv * f2;
                    }
                    for r in 0..nr {
                        let wr = rows.weight(i, r);
                        if wr == 0.0 {
                            continue;
                        }
                        for (c, gc) in g.iter().enumerate() {
                            h[(j * nr + r, k * nc + c)] += wr * gc;
                        }
                    }
                }
                if omega_col {
                    let mut dfo = 0.0;
                    for k in 0..d {
                        let o = j * d + k;
                        dfo += cc[o] * qt[k] + 2.0 * om * mm[o] * qtt[k];
                    }
                    for r in 0..nr {
                        h[(j * nr + r, d * nc)] += rows.weight(i, r) * dfo;
                    }
                }
            }
        }
        Ok(h)
    }

    /// `d/dy (u^T H(y) v)` over this system's unknowns, `p1` and `p2` (`u`, `v` fixed), for
    /// the test matrix of `kind`: the second-derivative symmetry along `v` for the
    /// unknowns, central differences for the parameters.
    fn contracted_gradient(
        &mut self,
        kind: PoCurveKind,
        x: &[f64],
        p: [f64; 2],
        u: &[f64],
        v: &[f64],
    ) -> Result<Vec<f64>> {
        let n = self.n();
        let mut grad = vec![0.0; n + 2];
        let h = DIR_STEP;
        match kind {
            PoCurveKind::Fold => {
                let xp: Vec<f64> = x.iter().zip(v).map(|(a, b)| a + h * b).collect();
                let xm: Vec<f64> = x.iter().zip(v).map(|(a, b)| a - h * b).collect();
                let jp = self.sys_jac(&xp, p)?;
                let jm = self.sys_jac(&xm, p)?;
                let uv = DVector::from_column_slice(u);
                let row = (jp - jm).tr_mul(&uv) / (2.0 * h);
                grad[..n].copy_from_slice(row.as_slice());
                for k in 0..2 {
                    grad[n + k] = self.mixed_p(
                        &xp,
                        &xm,
                        p,
                        k,
                        |r| r.iter().zip(u).map(|(a, b)| a * b).sum(),
                        false,
                    )? / (2.0 * h);
                }
            }
            PoCurveKind::BranchPoint => {
                let (nf, l, o) = (self.nf(), self.l, self.o);
                let xf = self.full(x);
                // The full direction of the separating mode: +v on ball 1, -v on ball 2.
                let mut ev = vec![0.0; nf];
                for i in 0..l {
                    ev[o * l + i] = v[i];
                    ev[(o + 1) * l + i] = -v[i];
                }
                let xp: Vec<f64> = xf.iter().zip(&ev).map(|(a, b)| a + h * b).collect();
                let xm: Vec<f64> = xf.iter().zip(&ev).map(|(a, b)| a - h * b).collect();
                let jp = self.full_jac(&xp, p)?;
                let jm = self.full_jac(&xm, p)?;
                for k in 0..nf {
                    let s: f64 = u
                        .iter()
                        .enumerate()
                        .map(|(i, ui)| {
                            let row = (o * l + i) * nf;
                            ui * (jp[row + k] - jm[row + k])
                        })
                        .sum();
                    grad[self.map(k)] += s / (2.0 * h);
                }
                for k in 0..2 {
                    grad[n + k] = self.mixed_p(
                        &xp,
                        &xm,
                        p,
                        k,
                        |r| (0..l).map(|i| u[i] * r[o * l + i]).sum(),
                        true,
                    )? / (2.0 * h);
                }
            }
            PoCurveKind::PeriodDoubling => {
                let xf = self.full(x);
                let (nh, s) = (self.n_harm, self.samples);
                let half = Table::new(Basis::Half, nh, s, 2);
                let whole = Table::new(Basis::Whole, nh, s, 2);
                let ep: Vec<f64> = v.iter().map(|b| h * b).collect();
                let em: Vec<f64> = v.iter().map(|b| -h * b).collect();
                let gp = self.galerkin(&xf, Some(&ep), p, &half, &whole, true, 2)?;
                let gm = self.galerkin(&xf, Some(&em), p, &half, &whole, true, 2)?;
                let uv = DVector::from_column_slice(u);
                let row = (gp - gm).tr_mul(&uv) / (2.0 * h);
                for (k, g) in row.iter().enumerate() {
                    grad[self.map(k)] += g;
                }
                let vv = DVector::from_column_slice(v);
                let one = Table::new(Basis::Half, nh, s, 1);
                for k in 0..2 {
                    let hp = 1e-6 * (1.0 + p[k].abs());
                    let (mut pp, mut pm) = (p, p);
                    pp[k] += hp;
                    pm[k] -= hp;
                    let a = self.galerkin(&xf, None, pp, &one, &one, false, 1)?;
                    let b = self.galerkin(&xf, None, pm, &one, &one, false, 1)?;
                    grad[n + k] = uv.dot(&((a - b) * &vv)) / (2.0 * hp);
                }
            }
            PoCurveKind::NeimarkSacker => return Err(complex_kind()),
        }
        Ok(grad)
    }

    /// `(phi(F(x+, p+) - F(x+, p-)) - phi(F(x-, p+) - F(x-, p-))) / (2 h_p)` for
    /// parameter `k` (`full`: `x+-` are full unknowns and `F` the full residual).
    fn mixed_p(
        &mut self,
        xp: &[f64],
        xm: &[f64],
        p: [f64; 2],
        k: usize,
        phi: impl Fn(&[f64]) -> f64,
        full: bool,
    ) -> Result<f64> {
        let hp = 1e-4 * (1.0 + p[k].abs());
        let (mut pp, mut pm) = (p, p);
        pp[k] += hp;
        pm[k] -= hp;
        let n = if full { self.nf() } else { self.n() };
        let mut r = vec![0.0; n];
        let mut total = 0.0;
        for (x, sx) in [(xp, 1.0), (xm, -1.0)] {
            for (pv, sp) in [(pp, 1.0), (pm, -1.0)] {
                if full {
                    self.full_eval(x, pv, &mut r, None)?;
                } else {
                    self.eval(x, pv, &mut r, None)?;
                }
                total += sx * sp * phi(&r);
            }
        }
        Ok(total / (2.0 * hp))
    }

    /// Signs of the other kinds' determinants (rows scaled to unit max-norm: the sign is
    /// kept and the value stays in range), for codimension-two points; on an `NS` curve
    /// (`theta` its angle) also `theta - pi/2` and `theta - 2 pi/3`, the strong
    /// resonances 1:4 and 1:3.
    fn secondary(
        &mut self,
        kind: PoCurveKind,
        x: &[f64],
        p: [f64; 2],
        theta: Option<f64>,
    ) -> Result<Vec<(&'static str, f64)>> {
        let mut out = vec![];
        let kinds: &[(PoCurveKind, &'static str)] = match kind {
            PoCurveKind::Fold => &[
                (PoCurveKind::BranchPoint, "BP"),
                (PoCurveKind::PeriodDoubling, "LPPD"),
            ],
            PoCurveKind::BranchPoint => &[
                (PoCurveKind::Fold, "LP"),
                (PoCurveKind::PeriodDoubling, "PD"),
            ],
            PoCurveKind::PeriodDoubling => &[
                (PoCurveKind::Fold, "LPPD"),
                (PoCurveKind::BranchPoint, "BP"),
            ],
            PoCurveKind::NeimarkSacker => &[
                (PoCurveKind::Fold, "LPNS"),
                (PoCurveKind::PeriodDoubling, "PDNS"),
                (PoCurveKind::BranchPoint, "BPNS"),
            ],
        };
        for &(k, label) in kinds {
            if k == PoCurveKind::BranchPoint && !self.reduced {
                continue;
            }
            let m = self.test_matrix(k, x, p)?;
            out.push((label, scaled_det(m)));
        }
        if let Some(t) = theta {
            out.push(("R4", t - PI / 2.0));
            out.push(("R3", t - 2.0 * PI / 3.0));
        }
        Ok(out)
    }

    /// The full series at this system's `x`.
    pub fn series(&self, x: &[f64], residual: f64) -> HbSolution {
        let xf = self.full(x);
        let nf = self.nf();
        HbSolution {
            omega: xf[nf - 1],
            coeffs: xf[..nf - 1].to_vec(),
            winding: self.winding.clone(),
            n_harm: self.n_harm,
            samples: self.samples,
            residual,
            step: 0.0,
            iterations: 0,
            status: if xf[nf - 1] > 0.0 && xf[nf - 1].is_finite() {
                Status::Converged
            } else {
                Status::Diverged
            },
            pivot_ratio: f64::NAN,
        }
    }
}

fn complex_kind() -> Error {
    Error::param(
        "kind",
        "the Neimark–Sacker test matrix is complex: it has no real test matrix",
    )
}

fn scaled_det(mut m: DMatrix<f64>) -> f64 {
    for i in 0..m.nrows() {
        let s = m.row(i).iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if s > 0.0 {
            m.row_mut(i).iter_mut().for_each(|v| *v /= s);
        }
    }
    m.lu().determinant()
}

#[derive(Clone, Copy, PartialEq)]
enum Basis {
    /// `1, cos k tau, sin k tau` (`k <= N`): the harmonic balance's own.
    Whole,
    /// `cos (k + 1/2) tau, sin (k + 1/2) tau` (`k < N`).
    Half,
}

/// A basis's values and tau-derivatives at the samples, with the Galerkin weights.
struct Table {
    width: usize,
    vals: Vec<(f64, f64, f64)>,
    wgt: Vec<f64>,
}

impl Table {
    fn new(basis: Basis, nh: usize, samples: usize, periods: usize) -> Self {
        let s = samples * periods;
        let width = match basis {
            Basis::Whole => 2 * nh + 1,
            Basis::Half => 2 * nh,
        };
        let mut vals = Vec::with_capacity(s * width);
        let mut wgt = Vec::with_capacity(s * width);
        for i in 0..s {
            let tau = 2.0 * PI * periods as f64 * i as f64 / s as f64;
            if basis == Basis::Whole {
                vals.push((1.0, 0.0, 0.0));
                wgt.push(1.0 / s as f64);
            }
            let (k0, k1) = match basis {
                Basis::Whole => (1, nh + 1),
                Basis::Half => (0, nh),
            };
            for k in k0..k1 {
                let mu = match basis {
                    Basis::Whole => k as f64,
                    Basis::Half => k as f64 + 0.5,
                };
                let (sn, cs) = (mu * tau).sin_cos();
                vals.push((cs, -mu * sn, -mu * mu * cs));
                vals.push((sn, mu * cs, -mu * mu * sn));
                wgt.push(2.0 * cs / s as f64);
                wgt.push(2.0 * sn / s as f64);
            }
        }
        Table { width, vals, wgt }
    }

    fn at(&self, i: usize, r: usize) -> (f64, f64, f64) {
        self.vals[i * self.width + r]
    }

    fn weight(&self, i: usize, r: usize) -> f64 {
        self.wgt[i * self.width + r]
    }
}

/// Complex numbers of the Neimark–Sacker test matrix.
type C64 = Complex<f64>;

/// The orbit's linearisation sampled over one period, `L u = K u + omega C u' +
/// omega^2 M u''` (tau-derivatives): per sample `K`, `omega C` and `omega^2 M`
/// (row-major `d x d`), with the state `(q, q', q'')` it was taken at.
struct Sampled {
    s: usize,
    d: usize,
    om: f64,
    k: Vec<f64>,
    c: Vec<f64>,
    m: Vec<f64>,
    /// The unscaled `C` and `M` and the state's tau-derivatives, for the omega column.
    cc: Vec<f64>,
    mm: Vec<f64>,
    qt: Vec<f64>,
    qtt: Vec<f64>,
}

impl<'a, D: Parametric> PoSystem<'a, D> {
    /// The linearisation about the full series `xf` (plus `pert`, per sample) at `p`.
    fn sampled(&mut self, xf: &[f64], pert: Option<&[[f64; 3]]>, p: [f64; 2]) -> Result<Sampled> {
        let (d, l, s) = (self.d, self.l, self.samples);
        let om = xf[d * l];
        self.model(p)?;
        let m = &self.cache.as_ref().unwrap().1;
        let mut out = Sampled {
            s,
            d,
            om,
            k: vec![0.0; s * d * d],
            c: vec![0.0; s * d * d],
            m: vec![0.0; s * d * d],
            cc: vec![0.0; s * d * d],
            mm: vec![0.0; s * d * d],
            qt: vec![0.0; s * d],
            qtt: vec![0.0; s * d],
        };
        let (mut q, mut qt, mut qtt) = (vec![0.0; d], vec![0.0; d], vec![0.0; d]);
        let (mut v, mut a) = (vec![0.0; d], vec![0.0; d]);
        for i in 0..s {
            let tau = 2.0 * PI * i as f64 / s as f64;
            let sc = tau.sin_cos();
            for j in 0..d {
                let (x0, x1, x2) =
                    eval_series_sc(&xf[j * l..(j + 1) * l], self.winding[j], tau, sc);
                (q[j], qt[j], qtt[j]) = (x0, x1, x2);
                if let Some(e) = pert {
                    let [u0, u1, u2] = e[i * d + j];
                    q[j] += u0;
                    qt[j] += u1;
                    qtt[j] += u2;
                }
                v[j] = om * qt[j];
                a[j] = om * om * qtt[j];
            }
            let o = i * d * d;
            m.jacobians(
                tau / om,
                &q,
                &v,
                &a,
                &mut out.k[o..o + d * d],
                &mut out.cc[o..o + d * d],
                &mut out.mm[o..o + d * d],
            );
            for r in o..o + d * d {
                out.c[r] = om * out.cc[r];
                out.m[r] = om * om * out.mm[r];
            }
            out.qt[i * d..(i + 1) * d].copy_from_slice(&qt);
            out.qtt[i * d..(i + 1) * d].copy_from_slice(&qtt);
        }
        if crate::cancel::cancelled() {
            return Err(Error::Cancelled);
        }
        Ok(out)
    }

    /// Hill's matrix of the linearisation at the multiplier `e^{i theta}`: the Galerkin
    /// matrix on `e^{i (c + nu) tau}` (`|c| <= N`, `nu = theta / 2 pi`), rows
    /// `e^{-i (r + nu) tau}`, index `j (2N + 1) + c + N` per coordinate `j`. It is
    /// singular when the linearisation has a solution `e^{i nu tau} P(tau)` with `P`
    /// periodic, i.e. a multiplier `e^{i theta}`, to the harmonic balance's truncation.
    fn hill_ns(&mut self, xf: &[f64], p: [f64; 2], theta: f64) -> Result<DMatrix<C64>> {
        let lin = self.sampled(xf, None, p)?;
        Ok(hill_from(&lin, self.n_harm, theta))
    }

    /// The phase-free Floquet solution's sample values: per sample and coordinate
    /// `(U, U', U'')` of `U = e^{i nu tau} P(tau)`, `P` the series `v` on `e^{i c tau}`,
    /// and `conj(W)/S` of the adjoint series `w` likewise.
    fn ns_samples(&self, theta: f64, v: &[C64], w: &[C64]) -> (Vec<[C64; 3]>, Vec<C64>) {
        let (d, s, nh) = (self.d, self.samples, self.n_harm as i64);
        let l = self.l;
        let nu = theta / (2.0 * PI);
        let iu = C64::new(0.0, 1.0);
        let mut u = vec![[C64::new(0.0, 0.0); 3]; s * d];
        let mut wc = vec![C64::new(0.0, 0.0); s * d];
        for i in 0..s {
            let tau = 2.0 * PI * i as f64 / s as f64;
            let rot = C64::from_polar(1.0, nu * tau);
            for j in 0..d {
                let (mut p0, mut p1, mut p2) = (C64::default(), C64::default(), C64::default());
                let mut ww = C64::default();
                for c in -nh..=nh {
                    let e = C64::from_polar(1.0, c as f64 * tau);
                    let idx = j * l + (c + nh) as usize;
                    let cf = c as f64;
                    let t = v[idx] * e;
                    p0 += t;
                    p1 += t * iu * cf;
                    p2 -= t * cf * cf;
                    ww += w[idx] * e;
                }
                u[i * d + j] = [
                    rot * p0,
                    rot * (p1 + iu * nu * p0),
                    rot * (p2 + 2.0 * iu * nu * p1 - nu * nu * p0),
                ];
                wc[i * d + j] = (rot * ww).conj() / s as f64;
            }
        }
        (u, wc)
    }

    /// `d/dy (w^H H(y) v)` for the Neimark–Sacker matrix [`Self::hill_ns`], over this
    /// system's unknowns, `p1`, `p2` and `theta` (in that order). `w^H H v` is the
    /// sampled sum `sum_i conj(W(tau_i)) (L U)(tau_i) / S` of the Floquet solution `U`
    /// and the adjoint `W` (the factors `e^{+- i nu tau}` cancel), and `L U` is the
    /// residual's derivative along `U`: by the symmetry of second derivatives, its
    /// gradient over the orbit is the harmonic-balance Jacobian's pointwise rows
    /// differenced along `Re U` and `Im U`.
    fn ns_gradient(
        &mut self,
        x: &[f64],
        p: [f64; 2],
        theta: f64,
        v: &[C64],
        w: &[C64],
    ) -> Result<Vec<C64>> {
        let n = self.n();
        let (d, l, s, nh) = (self.d, self.l, self.samples, self.n_harm);
        let xf = self.full(x);
        let (u, wc) = self.ns_samples(theta, v, w);
        let mut grad = vec![C64::default(); n + 3];
        let h = DIR_STEP;
        let whole = Table::new(Basis::Whole, nh, s, 1);
        let mut gf = vec![C64::default(); self.nf()];
        for (part, unit) in [(0usize, C64::new(1.0, 0.0)), (1, C64::new(0.0, 1.0))] {
            for sign in [1.0, -1.0] {
                let e: Vec<[f64; 3]> = u
                    .iter()
                    .map(|z| {
                        let pick = |c: C64| sign * h * if part == 0 { c.re } else { c.im };
                        [pick(z[0]), pick(z[1]), pick(z[2])]
                    })
                    .collect();
                let lin = self.sampled(&xf, Some(&e), p)?;
                let f = unit * (sign / (2.0 * h));
                for i in 0..s {
                    for j in 0..d {
                        let a = wc[i * d + j] * f;
                        let mut dfo = 0.0;
                        for k in 0..d {
                            let o = i * d * d + j * d + k;
                            let (kv, cv, mv) = (lin.k[o], lin.c[o], lin.m[o]);
                            dfo += lin.cc[o] * lin.qt[i * d + k]
                                + 2.0 * lin.om * lin.mm[o] * lin.qtt[i * d + k];
                            if kv == 0.0 && cv == 0.0 && mv == 0.0 {
                                continue;
                            }
                            for c in 0..l {
                                let (f0, f1, f2) = whole.at(i, c);
                                gf[k * l + c] += a * (kv * f0 + cv * f1 + mv * f2);
                            }
                        }
                        gf[d * l] += a * dfo;
                    }
                }
            }
        }
        for (k, g) in gf.iter().enumerate() {
            grad[self.map(k)] += g;
        }
        let phi = |lin: &Sampled| -> C64 {
            let mut t = C64::default();
            for i in 0..s {
                for j in 0..d {
                    let mut r = C64::default();
                    for k in 0..d {
                        let o = i * d * d + j * d + k;
                        let z = u[i * d + k];
                        r += z[0] * lin.k[o] + z[1] * lin.c[o] + z[2] * lin.m[o];
                    }
                    t += wc[i * d + j] * r;
                }
            }
            t
        };
        for k in 0..2 {
            let hp = 1e-6 * (1.0 + p[k].abs());
            let (mut pp, mut pm) = (p, p);
            pp[k] += hp;
            pm[k] -= hp;
            let a = self.sampled(&xf, None, pp)?;
            let b = self.sampled(&xf, None, pm)?;
            grad[n + k] = (phi(&a) - phi(&b)) / (2.0 * hp);
        }
        // d/dnu of e^{-i nu tau} L e^{i nu tau} is i (omega C + 2 omega^2 M d/dtau).
        let lin = self.sampled(&xf, None, p)?;
        let iu = C64::new(0.0, 1.0);
        let mut t = C64::default();
        for i in 0..s {
            for j in 0..d {
                let mut r = C64::default();
                for k in 0..d {
                    let o = i * d * d + j * d + k;
                    let z = u[i * d + k];
                    r += z[0] * lin.c[o] + z[1] * (2.0 * lin.m[o]);
                }
                t += wc[i * d + j] * iu * r;
            }
        }
        grad[n + 2] = t / (2.0 * PI);
        Ok(grad)
    }
}

/// [`PoSystem::hill_ns`] from the sampled linearisation: with the samples' discrete
/// Fourier coefficients `K_m = sum_i K(tau_i) e^{-i m tau_i} / S` (likewise `omega C`,
/// `omega^2 M`), entry `(r, c)` of block `(j, k)` is
/// `K_{r-c} + i (c + nu) C_{r-c} - (c + nu)^2 M_{r-c}`, the sampled Galerkin sum exactly.
fn hill_from(lin: &Sampled, n_harm: usize, theta: f64) -> DMatrix<C64> {
    let (d, s) = (lin.d, lin.s);
    let nh = n_harm as i64;
    let l = 2 * n_harm + 1;
    let nu = theta / (2.0 * PI);
    let nf = 4 * n_harm + 1;
    // hat[(m + 2N) * d * d + jk] for K, C, M.
    let mut hat = [
        vec![C64::default(); nf * d * d],
        vec![C64::default(); nf * d * d],
        vec![C64::default(); nf * d * d],
    ];
    for i in 0..s {
        let tau = 2.0 * PI * i as f64 / s as f64;
        let o = i * d * d;
        for (mi, m) in (-2 * nh..=2 * nh).enumerate() {
            let e = C64::from_polar(1.0 / s as f64, -(m as f64) * tau);
            for (src, dst) in [&lin.k, &lin.c, &lin.m].into_iter().zip(hat.iter_mut()) {
                for jk in 0..d * d {
                    let v = src[o + jk];
                    if v != 0.0 {
                        dst[mi * d * d + jk] += e * v;
                    }
                }
            }
        }
    }
    let iu = C64::new(0.0, 1.0);
    DMatrix::from_fn(d * l, d * l, |row, col| {
        let (j, r) = (row / l, row % l);
        let (k, c) = (col / l, col % l);
        let mi = (r as i64 - c as i64 + 2 * nh) as usize;
        let jk = mi * d * d + j * d + k;
        let f = c as f64 - nh as f64 + nu;
        hat[0][jk] + iu * f * hat[1][jk] - f * f * hat[2][jk]
    })
}

/// The angle in `(0, pi)` where Hill's matrix of [`PoSystem::hill_ns`] is closest to
/// singular (smallest least singular value): the start's critical pair.
fn start_angle<D: Parametric>(sys: &mut PoSystem<'_, D>, xf: &[f64], p: [f64; 2]) -> Result<f64> {
    let lin = sys.sampled(xf, None, p)?;
    let nh = sys.n_harm;
    let smin = |t: f64| {
        hill_from(&lin, nh, t)
            .singular_values()
            .iter()
            .fold(f64::INFINITY, |a, &b| a.min(b))
    };
    // Away from the trivial multiplier at 0 and the conjugate's copy at pi.
    let (lo, hi, n) = (0.02, PI - 0.02, 120);
    let grid: Vec<(f64, f64)> = (0..=n)
        .map(|i| {
            let t = lo + (hi - lo) * i as f64 / n as f64;
            (t, smin(t))
        })
        .collect();
    let mut best = (f64::NAN, f64::INFINITY);
    for i in 0..=n {
        let left = if i > 0 { grid[i - 1].1 } else { f64::INFINITY };
        let right = if i < n { grid[i + 1].1 } else { f64::INFINITY };
        if grid[i].1 > left || grid[i].1 > right {
            continue;
        }
        // Golden section on the bracket around the grid's local minimum.
        let step = (hi - lo) / n as f64;
        let (mut a, mut b) = ((grid[i].0 - step).max(lo), (grid[i].0 + step).min(hi));
        let r = 0.5 * (5f64.sqrt() - 1.0);
        let (mut c, mut e) = (b - r * (b - a), a + r * (b - a));
        let (mut fc, mut fe) = (smin(c), smin(e));
        for _ in 0..60 {
            if fc < fe {
                b = e;
                (e, fe) = (c, fc);
                c = b - r * (b - a);
                fc = smin(c);
            } else {
                a = c;
                (c, fc) = (e, fe);
                e = a + r * (b - a);
                fe = smin(e);
            }
            if b - a < 1e-12 {
                break;
            }
        }
        let t = 0.5 * (a + b);
        let f = smin(t);
        if f < best.1 {
            best = (t, f);
        }
    }
    if best.0.is_nan() {
        return Err(Error::param(
            "event",
            "no complex pair of multipliers on the unit circle at the start",
        ));
    }
    Ok(best.0)
}

/// Borders of a minimally augmented system: `b` (a column), `c` (a row, kept as its
/// adjoint): real, or complex for the Neimark–Sacker test matrix.
#[derive(Debug, Clone)]
struct Border<T: ComplexField> {
    b: DVector<T>,
    c: DVector<T>,
}

type CBorder = Border<C64>;

impl<T: ComplexField<RealField = f64>> Border<T> {
    /// The smallest singular value's left and right vectors.
    fn from_svd(h: &DMatrix<T>) -> Result<Self> {
        let svd = h
            .clone()
            .try_svd(
                true,
                true,
                f64::EPSILON,
                crate::numerics::linalg::SVD_MAX_ITER,
            )
            .ok_or(Error::Eigen(
                "SVD of the test matrix did not converge".into(),
            ))?;
        let (u, vt) = match (svd.u, svd.v_t) {
            (Some(u), Some(vt)) => (u, vt),
            _ => return Err(Error::Eigen("SVD of the test matrix failed".into())),
        };
        let k = svd
            .singular_values
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .map(|(i, _)| i)
            .unwrap_or(0);
        Ok(Border {
            b: u.column(k).into_owned(),
            c: vt.row(k).adjoint(),
        })
    }

    /// `[[H, b], [c^H, 0]]`.
    fn matrix(&self, h: &DMatrix<T>) -> DMatrix<T> {
        let m = h.nrows();
        DMatrix::from_fn(m + 1, m + 1, |i, j| match (i < m, j < m) {
            (true, true) => h[(i, j)].clone(),
            (true, false) => self.b[i].clone(),
            (false, true) => self.c[j].clone().conjugate(),
            (false, false) => T::zero(),
        })
    }

    /// `g` of `[[H, b], [c^H, 0]] [v; g] = e`; with `adjoint`, also `v` and the adjoint
    /// `w` of `[[H, b], [c^H, 0]]^H [w; h] = e` (then `dg = -w^H dH v`).
    #[allow(clippy::type_complexity)]
    fn solve(&self, h: &DMatrix<T>, adjoint: bool) -> Option<(T, Option<(Vec<T>, Vec<T>)>)> {
        let m = h.nrows();
        let bm = self.matrix(h);
        let mut e = DVector::zeros(m + 1);
        e[m] = T::one();
        let s = bm.clone().lu().solve(&e)?;
        let g = s[m].clone();
        if !g.is_finite() {
            return None;
        }
        if !adjoint {
            return Some((g, None));
        }
        let t = bm.adjoint().lu().solve(&e)?;
        Some((
            g,
            Some((
                s.rows(0, m).iter().cloned().collect(),
                t.rows(0, m).iter().cloned().collect(),
            )),
        ))
    }

    /// New borders from a point's null and adjoint vectors (unit length).
    fn update(&mut self, v: &[T], w: &[T]) {
        let norm = |x: &[T]| {
            x.iter()
                .map(|a| a.clone().modulus_squared())
                .sum::<f64>()
                .sqrt()
        };
        let (nv, nw) = (norm(v), norm(w));
        if nv > 0.0 && nw > 0.0 && nv.is_finite() && nw.is_finite() {
            self.c = DVector::from_iterator(v.len(), v.iter().map(|x| x.clone().unscale(nv)));
            self.b = DVector::from_iterator(w.len(), w.iter().map(|x| x.clone().unscale(nw)));
        }
    }
}

/// `[F; g] = 0` as a [`Problem`] in `(x, p1)` with parameter `p2`; for `NS` the test
/// function is complex, `[F; Re g; Im g] = 0` in `(x, p1, theta)`.
pub struct Augmented<'a, D: Parametric> {
    pub sys: PoSystem<'a, D>,
    kind: PoCurveKind,
    border: Border<f64>,
    /// The complex borders of an `NS` curve (`border` is then unused).
    cborder: Option<CBorder>,
    /// `g` is divided by its gradient's norm at the start: `|g|` is then about the
    /// distance from the curve, and the corrector's tolerance means the same for it.
    scale: f64,
    p2: f64,
    /// The last gradient of `g` (over `x`, `p1`, `p2`) and where it was taken:
    /// `jac_x` and `jac_p` of one point share it.
    grad: Option<GradCache>,
}

fn singular_at(p: [f64; 2]) -> Error {
    Error::param(
        "test_function",
        format!(
            "the bordered test matrix is singular at ({}, {})",
            p[0], p[1]
        ),
    )
}

impl<'a, D: Parametric> Augmented<'a, D> {
    /// Test functions at `y = (x, p1[, theta])` (one, or `Re g, Im g` for `NS`).
    fn g(&mut self, y: &[f64], p2: f64) -> Result<Vec<f64>> {
        let n = self.sys.n();
        let p = [y[n], p2];
        if let Some(cb) = &self.cborder {
            let cb = cb.clone();
            let xf = self.sys.full(&y[..n]);
            let h = self.sys.hill_ns(&xf, p, y[n + 1])?;
            return match cb.solve(&h, false) {
                Some((g, _)) => Ok(vec![g.re * self.scale, g.im * self.scale]),
                None => Err(singular_at(p)),
            };
        }
        let h = self.sys.test_matrix(self.kind, &y[..n], p)?;
        match self.border.solve(&h, false) {
            Some((g, _)) => Ok(vec![g * self.scale]),
            None => Err(singular_at(p)),
        }
    }

    /// `g` and its gradient over `(x, p1, p2)`, and the null / adjoint vectors.
    #[allow(clippy::type_complexity)]
    fn g_grad(&mut self, x: &[f64], p: [f64; 2]) -> Result<(f64, Vec<f64>, Vec<f64>, Vec<f64>)> {
        let h = self.sys.test_matrix(self.kind, x, p)?;
        let Some((g, Some((v, w)))) = self.border.solve(&h, true) else {
            return Err(singular_at(p));
        };
        let grad = self.sys.contracted_gradient(self.kind, x, p, &w, &v)?;
        let grad = grad.iter().map(|d| -d * self.scale).collect();
        Ok((g * self.scale, grad, v, w))
    }

    /// The complex `g`, its gradient over `(x, p1, p2, theta)` (rows `Re`, `Im`) and the
    /// null / adjoint vectors, for `NS`.
    fn g_grad_ns(&mut self, y: &[f64], p2: f64) -> Result<GradCache> {
        let n = self.sys.n();
        let (p, theta) = ([y[n], p2], y[n + 1]);
        let cb = self
            .cborder
            .clone()
            .expect("complex borders of an NS curve");
        let xf = self.sys.full(&y[..n]);
        let h = self.sys.hill_ns(&xf, p, theta)?;
        let Some((g, Some((v, w)))) = cb.solve(&h, true) else {
            return Err(singular_at(p));
        };
        let grad = self.sys.ns_gradient(&y[..n], p, theta, &v, &w)?;
        let s = self.scale;
        Ok(GradCache {
            key: vec![],
            g: vec![g.re * s, g.im * s],
            grad: vec![
                grad.iter().map(|d| -d.re * s).collect(),
                grad.iter().map(|d| -d.im * s).collect(),
            ],
            null: Null::Complex(v, w),
        })
    }

    /// `g`, its gradient and the null / adjoint vectors at `(y, p2)`, kept for the
    /// next call at the same point (`jac_x`, `jac_p` and the border update share them).
    fn at(&mut self, y: &[f64], p2: f64) -> Result<&GradCache> {
        let mut key: Vec<u64> = y.iter().map(|v| v.to_bits()).collect();
        key.push(p2.to_bits());
        if self.grad.as_ref().is_none_or(|c| c.key != key) {
            let n = self.sys.n();
            let mut c = if self.cborder.is_some() {
                self.g_grad_ns(y, p2)?
            } else {
                let (g, grad, v, w) = self.g_grad(&y[..n], [y[n], p2])?;
                GradCache {
                    key: vec![],
                    g: vec![g],
                    grad: vec![grad],
                    null: Null::Real(v, w),
                }
            };
            c.key = key;
            self.grad = Some(c);
        }
        Ok(self.grad.as_ref().unwrap())
    }

    /// The norm of the test functions' gradient over every unknown and `p2`.
    fn gradient_norm(&mut self, y: &[f64], p2: f64) -> Result<f64> {
        let c = self.at(y, p2)?;
        Ok(c.grad.iter().flatten().map(|g| g * g).sum::<f64>().sqrt())
    }

    /// Borders from the null and adjoint vectors at a curve point.
    fn rebase(&mut self, y: &[f64], p2: f64) -> Result<()> {
        self.at(y, p2)?;
        let c = self.grad.take().unwrap();
        match &c.null {
            Null::Real(v, w) => self.border.update(v, w),
            Null::Complex(v, w) => {
                if let Some(cb) = self.cborder.as_mut() {
                    cb.update(v, w);
                }
            }
        }
        Ok(())
    }

    /// Extra unknowns beyond `(x, p1)`: `theta` for `NS`.
    fn extra(&self) -> usize {
        usize::from(self.cborder.is_some())
    }
}

enum Null {
    Real(Vec<f64>, Vec<f64>),
    Complex(Vec<C64>, Vec<C64>),
}

struct GradCache {
    key: Vec<u64>,
    /// One test function, or `Re g, Im g`.
    g: Vec<f64>,
    /// Their gradients over `(x, p1, p2[, theta])`.
    grad: Vec<Vec<f64>>,
    null: Null,
}

impl<D: Parametric> Problem for Augmented<'_, D> {
    fn size(&self) -> usize {
        self.sys.n() + 1 + self.extra()
    }
    fn param(&self) -> f64 {
        self.p2
    }
    fn residual(&mut self, y: &[f64], p2: f64, r: &mut [f64]) -> Result<()> {
        let n = self.sys.n();
        let p = [y[n], p2];
        self.sys.eval(&y[..n], p, &mut r[..n], None)?;
        let g = self.g(y, p2)?;
        r[n..n + g.len()].copy_from_slice(&g);
        Ok(())
    }
    fn jac_x(&mut self, y: &[f64], p2: f64, r: &mut [f64], jac: &mut [f64]) -> Result<()> {
        let n = self.sys.n();
        let e = self.extra();
        let n1 = n + 1 + e;
        let p = [y[n], p2];
        let mut jx = vec![0.0; n * n];
        self.sys.eval(&y[..n], p, &mut r[..n], Some(&mut jx))?;
        let fp = self.f_p(&y[..n], p, 0)?;
        for i in 0..n {
            jac[i * n1..i * n1 + n].copy_from_slice(&jx[i * n..(i + 1) * n]);
            jac[i * n1 + n] = fp[i];
            if e == 1 {
                jac[i * n1 + n + 1] = 0.0;
            }
        }
        let c = self.at(y, p2)?;
        for (k, (g, grad)) in c.g.iter().zip(&c.grad).enumerate() {
            let row = (n + k) * n1;
            r[n + k] = *g;
            jac[row..row + n + 1].copy_from_slice(&grad[..n + 1]);
            if e == 1 {
                jac[row + n + 1] = grad[n + 2];
            }
        }
        Ok(())
    }
    fn jac_p(&mut self, y: &[f64], p2: f64, out: &mut [f64]) -> Result<()> {
        let n = self.sys.n();
        let fp = self.f_p(&y[..n], [y[n], p2], 1)?;
        out[..n].copy_from_slice(&fp);
        let c = self.at(y, p2)?;
        for (k, grad) in c.grad.iter().enumerate() {
            out[n + k] = grad[n + 1];
        }
        Ok(())
    }
}

impl<D: Parametric> Augmented<'_, D> {
    fn f_p(&mut self, x: &[f64], p: [f64; 2], k: usize) -> Result<Vec<f64>> {
        let n = self.sys.n();
        let h = 1e-6 * (1.0 + p[k].abs());
        let (mut pp, mut pm) = (p, p);
        pp[k] += h;
        pm[k] -= h;
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        self.sys.eval(x, pp, &mut a, None)?;
        self.sys.eval(x, pm, &mut b, None)?;
        Ok(a.iter().zip(&b).map(|(a, b)| (a - b) / (2.0 * h)).collect())
    }
}

/// Settings of [`periodic_curve`].
#[derive(Debug, Clone)]
pub struct PoCurveOptions {
    /// Step control; `p_min`, `p_max` bound the second parameter.
    pub arc: ArcOptions,
    /// The first parameter's window: the curve stops where it leaves it.
    pub p1_range: (f64, f64),
    /// Harmonics (`hb.n_harm`, `hb.samples`) and the certificates and multipliers
    /// reported per point (`auto` is ignored).
    pub periodic: PeriodicOptions,
    /// Arclength tolerance of codimension-two points.
    pub locate_tol: f64,
}

impl Default for PoCurveOptions {
    fn default() -> Self {
        PoCurveOptions {
            arc: ArcOptions::default(),
            p1_range: (f64::NEG_INFINITY, f64::INFINITY),
            periodic: PeriodicOptions::default(),
            locate_tol: 1e-8,
        }
    }
}

/// One point of a curve.
#[derive(Debug, Clone)]
pub struct PoCurvePoint {
    pub p: [f64; 2],
    /// The series, certified and judged as `periodic()` does, its verdict bounded at the
    /// curve's harmonics ([`finish_on_branch`]).
    pub result: Periodic,
    /// The curve's own test function (normalised; for `NS` the modulus of the complex
    /// one), zero to the corrector's tolerance.
    pub g: f64,
    /// `NS`: the critical pair's angle, multipliers `e^{+- i theta}` (`0 < theta < pi`).
    pub theta: Option<f64>,
    /// The other kinds' determinants (their sign changes are codimension-two points).
    pub tests: Vec<(&'static str, f64)>,
}

/// A codimension-two point.
#[derive(Debug, Clone)]
pub struct PoCodim2 {
    pub kind: &'static str,
    pub p: [f64; 2],
    pub omega: f64,
    /// The row of the first curve point past it.
    pub row: usize,
    /// Its multipliers' verdict on the label: only a confirmed point is a bifurcation
    /// point; the others stay listed (the test function did change sign there).
    pub certificate: Codim2Certificate,
}

/// What the multipliers of a located codimension-two point say about its label.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Codim2Status {
    /// Every multiplier the label needs is there, to the monodromy's error, and the
    /// monodromy resolves multipliers that far from it.
    Confirmed,
    /// A multiplier the label needs is not there: no perturbation of the monodromy within
    /// its error puts one at the required value.
    Rejected,
    /// The monodromy cannot decide (its error is too large, or its multipliers there are
    /// so ill conditioned that it cannot tell the required value from one 0.1 away).
    Undetermined,
}

impl Codim2Status {
    pub fn as_str(&self) -> &'static str {
        match self {
            Codim2Status::Confirmed => "confirmed",
            Codim2Status::Rejected => "rejected",
            Codim2Status::Undetermined => "undetermined",
        }
    }
}

/// The multiplier certificate of a codimension-two point: the monodromy matrix `Phi` of
/// the located series (RK45 at rtol 1e-10; at the default 1e-8 alone when that one fails
/// the trivial-multiplier certificate, which makes the point undetermined), and for each multiplier the point needs (the
/// curve's own and the one its label adds) the backward error
/// `sigma_min(A - z I)` of the value `z` on the block `A` of `Phi` it lives on: the
/// smallest perturbation of `A` that makes `z` a multiplier.
#[derive(Debug, Clone, Copy)]
pub struct Codim2Certificate {
    pub status: Codim2Status,
    /// Distance of the nearest multiplier (of the block) to the value the label adds (for
    /// `CP`, `R3`, `R4`, which add none, to the curve's own).
    pub gap: f64,
    /// `sigma_min(A - z I)` for that value.
    pub residual: f64,
    /// The same for the curve's own critical multiplier.
    pub own_residual: f64,
    /// The monodromy's estimated error (2-norm of a matrix perturbation): the larger of
    /// the integration's (tight against default tolerances) and the orbit's, measured on
    /// the exactly known trivial eigenvector, `|Phi v - v| / |v|` with `v` the orbit's
    /// velocity.
    pub error: f64,
}

/// The decision's safety factor on the monodromy's error estimate: the estimate measures
/// the error in a few directions (the trivial eigenvector, the integration's change), not
/// its worst.
pub const CODIM2_SAFETY: f64 = 10.0;

/// Radius at which the monodromy must resolve the required value from its neighbours for
/// a confirmation.
pub const CODIM2_RESOLUTION: f64 = 0.1;

/// A multiplier a codimension-two point needs, and the block of `Phi` it lives on.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Need {
    /// `-1`, anywhere.
    MinusOne,
    /// A second `+1` next to the trivial one (a Jordan block at a fold): `+1` of `Phi`
    /// with the trivial eigenvector deflated, on the together subspace of merged balls
    /// (the separation pair is the branch point's, not a fold's). Deflation turns the
    /// Jordan block's `sqrt(error)` splitting into a simple eigenvalue's `error`.
    SecondPlusOne,
    /// `+1` of merged balls' separation pair (the 2 x 2 block of the separating mode).
    Separation,
    /// `e^{i theta}` (a Neimark–Sacker pair).
    Pair(f64),
}

fn own_need(kind: PoCurveKind, theta: Option<f64>) -> Need {
    match kind {
        PoCurveKind::Fold => Need::SecondPlusOne,
        PoCurveKind::BranchPoint => Need::Separation,
        PoCurveKind::PeriodDoubling => Need::MinusOne,
        PoCurveKind::NeimarkSacker => Need::Pair(theta.unwrap_or(f64::NAN)),
    }
}

/// The multiplier a label adds to the curve's own (`None`: a geometric point).
fn added_need(kind: PoCurveKind, label: &str) -> Option<Need> {
    match (kind, label) {
        (PoCurveKind::Fold, "LPPD") | (_, "PD") | (_, "PDNS") => Some(Need::MinusOne),
        (PoCurveKind::PeriodDoubling, "LPPD") | (_, "LP") | (_, "LPNS") => {
            Some(Need::SecondPlusOne)
        }
        (_, "BP") | (_, "BPNS") => Some(Need::Separation),
        _ => None,
    }
}

/// The verdict on one needed multiplier: `residual` the backward error at the value,
/// `resolution` the larger of those at the value moved by [`CODIM2_RESOLUTION`] either
/// way (another genuine multiplier may sit on one side), `error` the monodromy's, `trusted` whether the monodromy passes the crate's own
/// certificate (trivial multiplier within `MAX_TRIVIAL` of 1) at all.
pub fn condition_status(residual: f64, resolution: f64, error: f64, trusted: bool) -> Codim2Status {
    let tol = CODIM2_SAFETY * error;
    if !trusted || !residual.is_finite() || !(tol.is_finite()) {
        Codim2Status::Undetermined
    } else if residual > tol {
        Codim2Status::Rejected
    } else if !(resolution > tol) {
        Codim2Status::Undetermined
    } else {
        Codim2Status::Confirmed
    }
}

/// Both conditions together: rejected if either is, confirmed only if both are.
pub fn combine(a: Codim2Status, b: Codim2Status) -> Codim2Status {
    use Codim2Status::*;
    match (a, b) {
        (Rejected, _) | (_, Rejected) => Rejected,
        (Confirmed, Confirmed) => Confirmed,
        _ => Undetermined,
    }
}

type CMat = DMatrix<C64>;

fn smin(a: &CMat, z: C64) -> f64 {
    let n = a.nrows();
    let m = a - CMat::identity(n, n) * z;
    m.singular_values()
        .iter()
        .fold(f64::INFINITY, |x, &y| x.min(y))
}

/// An orthonormal basis (columns) of the complement of `v` (Householder).
fn complement(v: &DVector<f64>) -> DMatrix<f64> {
    let n = v.len();
    let u0 = v / v.norm();
    let s = if u0[0] >= 0.0 { 1.0 } else { -1.0 };
    let mut u = u0.clone();
    u[0] += s;
    let h = DMatrix::identity(n, n) - (&u * u.transpose()) * (2.0 / u.norm_squared());
    h.columns(1, n - 1).into_owned()
}

/// The multiplier certificate of the series `sol` of `model` at a codimension-two point
/// labelled `label` on a curve of `kind` (`theta`: an `NS` curve's angle); `merged`: the
/// curve runs on merged balls.
pub fn certify_codim2<D: crate::Dynamics + ?Sized>(
    model: &D,
    sol: &HbSolution,
    kind: PoCurveKind,
    label: &str,
    theta: Option<f64>,
    merged: bool,
) -> Codim2Certificate {
    let undetermined = Codim2Certificate {
        status: Codim2Status::Undetermined,
        gap: f64::NAN,
        residual: f64::NAN,
        own_residual: f64::NAN,
        error: f64::NAN,
    };
    let tight = crate::floquet::FloquetOptions {
        rtol: 1e-10,
        atol: 1e-12,
        max_steps: 1_000_000,
        ..Default::default()
    };
    let loose = crate::floquet::FloquetOptions {
        max_steps: 1_000_000,
        ..Default::default()
    };
    let d = model.ndof();
    let n2 = 2 * d;
    let trivial_of = |phi: &DMatrix<f64>| {
        // (column-major data read row-major: the transpose, the same spectrum)
        crate::linalg::eigenvalues(phi.as_slice(), n2).map(|ev| {
            ev.iter()
                .map(|z| (z.0 - 1.0).hypot(z.1))
                .fold(f64::INFINITY, f64::min)
        })
    };
    let Ok((phi2, _, _)) = crate::floquet::monodromy(model, sol, &loose) else {
        return undetermined;
    };
    let phi2 = DMatrix::from_row_slice(n2, n2, &phi2);
    let Some(trivial) = trivial_of(&phi2) else {
        return undetermined;
    };
    // A monodromy that fails the crate's certificate at the default tolerances decides
    // nothing (near-homoclinic series at N = 8: nothing within 0.8 of +1): the tight one
    // would not change that, and its long integration is spared.
    let trusted = trivial <= crate::floquet::MAX_TRIVIAL;
    let phi = if trusted {
        match crate::floquet::monodromy(model, sol, &tight) {
            Ok((phi, _, _)) => DMatrix::from_row_slice(n2, n2, &phi),
            Err(_) => return undetermined,
        }
    } else {
        phi2.clone()
    };
    // The orbit's velocity: the exact monodromy's eigenvector of the trivial multiplier.
    let (mut q, mut qv, mut qa) = (vec![0.0; d], vec![0.0; d], vec![0.0; d]);
    sol.eval_rates(0.0, &mut q, &mut qv, &mut qa);
    let v = DVector::from_iterator(n2, qv.iter().chain(&qa).copied());
    if !(v.norm() > 0.0) || !phi.iter().all(|x| x.is_finite()) {
        return undetermined;
    }
    let e_orbit = (&phi * &v - &v).norm() / v.norm();
    let e_int = (&phi - &phi2).norm();
    let error = e_orbit.max(e_int).max(1e-14 * phi.norm());
    let trusted = trusted && trivial_of(&phi).is_some_and(|t| t <= crate::floquet::MAX_TRIVIAL);
    // Together / separation blocks of merged balls (both invariant: swapping the two
    // balls is a symmetry of the model on their common motion).
    let pair = if merged {
        crate::floquet::merged_pair(sol, model.first_ball())
    } else {
        None
    };
    let (together, sep) = match pair {
        Some((i, j)) => {
            let r = std::f64::consts::FRAC_1_SQRT_2;
            let mut cols_t = vec![];
            for k in 0..n2 {
                if k % d != i && k % d != j {
                    let mut e = DVector::zeros(n2);
                    e[k] = 1.0;
                    cols_t.push(e);
                }
            }
            let mut cols_s = vec![];
            for off in [0, d] {
                let (mut t, mut s) = (DVector::zeros(n2), DVector::zeros(n2));
                (t[off + i], t[off + j]) = (r, r);
                (s[off + i], s[off + j]) = (r, -r);
                cols_t.push(t);
                cols_s.push(s);
            }
            (
                DMatrix::from_columns(&cols_t),
                Some(DMatrix::from_columns(&cols_s)),
            )
        }
        None => (DMatrix::identity(n2, n2), None),
    };
    let block = |need: Need| -> Option<(CMat, C64)> {
        let (a, z) = match need {
            Need::MinusOne => (phi.clone(), C64::new(-1.0, 0.0)),
            Need::Separation => {
                let s = sep.as_ref()?;
                (s.transpose() * &phi * s, C64::new(1.0, 0.0))
            }
            Need::SecondPlusOne => {
                let vt = together.transpose() * &v;
                let q = &together * complement(&vt);
                (q.transpose() * &phi * &q, C64::new(1.0, 0.0))
            }
            Need::Pair(t) => (phi.clone(), C64::from_polar(1.0, t)),
        };
        if !z.re.is_finite() || !z.im.is_finite() {
            return None;
        }
        Some((a.map(|x| C64::new(x, 0.0)), z))
    };
    let judge_need = |need: Need| -> (Codim2Status, f64, f64) {
        let Some((a, z)) = block(need) else {
            return (Codim2Status::Undetermined, f64::NAN, f64::NAN);
        };
        let residual = smin(&a, z);
        let resolution =
            smin(&a, z * (1.0 + CODIM2_RESOLUTION)).max(smin(&a, z * (1.0 - CODIM2_RESOLUTION)));
        let n = a.nrows();
        let re: Vec<f64> = a.iter().map(|c| c.re).collect();
        // column-major data read row-major: the transpose, the same eigenvalues
        let gap = crate::linalg::eigenvalues(&re, n)
            .map(|ev| {
                ev.iter()
                    .map(|w| (w.0 - z.re).hypot(w.1 - z.im))
                    .fold(f64::INFINITY, f64::min)
            })
            .unwrap_or(f64::NAN);
        (
            condition_status(residual, resolution, error, trusted),
            residual,
            gap,
        )
    };
    let (s_own, r_own, g_own) = judge_need(own_need(kind, theta));
    let (status, residual, gap) = match added_need(kind, label) {
        Some(need) => {
            let (s, r, g) = judge_need(need);
            (combine(s_own, s), r, g)
        }
        None => (s_own, r_own, g_own),
    };
    Codim2Certificate {
        status,
        gap,
        residual,
        own_residual: r_own,
        error,
    }
}

#[derive(Debug, Clone)]
pub struct PoCurve {
    pub kind: PoCurveKind,
    pub points: Vec<PoCurvePoint>,
    pub special: Vec<PoCodim2>,
    /// Whether the curve was continued on the together subspace (merged balls).
    pub together: bool,
    /// Why each half ended: towards decreasing, then increasing second parameter.
    pub stop: [String; 2],
}

/// Whether every ball of `sol` runs the same series (the together subspace).
fn all_merged(sol: &HbSolution, o: usize) -> bool {
    let d = sol.ndof();
    if d < o + 2 {
        return false;
    }
    let scale = sol.coeffs.iter().fold(1.0f64, |m, c| m.max(c.abs()));
    (o + 1..d).all(|j| {
        sol.winding[j] == sol.winding[o]
            && sol
                .coord(j)
                .iter()
                .zip(sol.coord(o))
                .all(|(a, b)| (a - b).abs() <= 1e-7 * scale)
    })
}

/// Continues the curve of `kind` through the bifurcation point `start` (a periodic
/// solution of `base` at a located event, e.g. a row of a periodic branch's events) in
/// the parameters `names = [p1, p2]` of `base` (which has the event's values), both ways
/// in `p2` from the start: the rows run from the end reached towards decreasing `p2` to
/// the end reached towards increasing `p2`.
pub fn periodic_curve<D: Parametric>(
    base: &D,
    names: [&str; 2],
    kind: PoCurveKind,
    start: &HbSolution,
    opts: &PoCurveOptions,
) -> Result<PoCurve> {
    opts.arc.validate()?;
    opts.periodic.validate()?;
    crate::error::check_range("locate_tol", opts.locate_tol, 0.0, true, 1.0, true)?;
    if names[0] == names[1] {
        return Err(Error::param(
            "parameter2",
            "must differ from the first parameter",
        ));
    }
    let mut p0 = [0.0; 2];
    for (k, (name, label)) in names.iter().zip(["parameter", "parameter2"]).enumerate() {
        p0[k] = base.param_value(name).map_err(|_| {
            Error::param(label, format!("{name:?} is not a parameter of this model"))
        })?;
    }
    let (lo, hi) = opts.p1_range;
    if !(lo < hi) || !(lo..=hi).contains(&p0[0]) {
        return Err(Error::param_range(
            "range1",
            format!(
                "must contain the start's {} = {}, got ({lo}, {hi})",
                names[0], p0[0]
            ),
            format!("lo <= {} <= hi", p0[0]),
        ));
    }
    if !(opts.arc.p_min..=opts.arc.p_max).contains(&p0[1]) {
        return Err(Error::param_range(
            "range",
            format!(
                "must contain the start's {} = {}, got ({}, {})",
                names[1], p0[1], opts.arc.p_min, opts.arc.p_max
            ),
            format!("lo <= {} <= hi", p0[1]),
        ));
    }
    check_start(base, start)?;
    let (popts, n_harm, samples) = branch_options(&opts.periodic);
    // No Newton at fixed parameters here: at a fold its Jacobian is singular. The
    // augmented system's first correction (in x and p1) converges the start.
    let first = if start.n_harm == n_harm {
        start.clone()
    } else {
        start.resized(n_harm)
    };
    let together = all_merged(&first, base.first_ball());
    if kind == PoCurveKind::BranchPoint && !together {
        return Err(Error::param(
            "event",
            "branch-point curves are continued for merged balls (the separation multiplier \
             through +1); this solution's balls are not merged",
        ));
    }
    let mut sys = PoSystem::new(base, names, &first.winding, n_harm, samples, together);
    let mut x0 = sys.reduce(&first.unknowns());
    let border = if kind == PoCurveKind::NeimarkSacker {
        let xf = sys.full(&x0);
        let theta = start_angle(&mut sys, &xf, p0)?;
        let h0 = sys.hill_ns(&xf, p0, theta)?;
        // theta rides after x and p1 in the augmented unknowns: `half` splits it off.
        x0.push(theta);
        Borders::Complex(CBorder::from_svd(&h0)?)
    } else {
        let h0 = sys.test_matrix(kind, &x0, p0)?;
        Borders::Real(Border::from_svd(&h0)?)
    };
    let mut o = opts.clone();
    o.arc.forward = false;
    let (back, sys) = half(sys, kind, &x0, p0, border.clone(), &o, &popts)?;
    o.arc.forward = true;
    let (fwd, _) = half(sys, kind, &x0, p0, border, &o, &popts)?;
    let stop = [back.stop[1].clone(), fwd.stop[1].clone()];
    let (points, special) = join_halves(
        (back.points, back.special),
        (fwd.points, fwd.special),
        |c: &mut PoCodim2| &mut c.row,
    );
    Ok(PoCurve {
        kind,
        points,
        special,
        together,
        stop,
    })
}

type Half<'a, D> = (PoCurve, PoSystem<'a, D>);

/// The start's borders: real, or complex for `NS`.
#[derive(Debug, Clone)]
enum Borders {
    Real(Border<f64>),
    Complex(CBorder),
}

/// On an `NS` curve closer than this to 0 or pi, the pair meets the real axis (strong
/// resonance 1:1 or 1:2) and the curve ends.
const THETA_END: f64 = 1e-3;

fn half<'a, D: Parametric>(
    sys: PoSystem<'a, D>,
    kind: PoCurveKind,
    x0: &[f64],
    p0: [f64; 2],
    border: Borders,
    opts: &PoCurveOptions,
    popts: &PeriodicOptions,
) -> Result<Half<'a, D>> {
    let n = sys.n();
    let (border, cborder) = match border {
        Borders::Real(b) => (b, None),
        Borders::Complex(c) => (
            Border {
                b: DVector::zeros(0),
                c: DVector::zeros(0),
            },
            Some(c),
        ),
    };
    let ns = cborder.is_some();
    let mut ext = Augmented {
        sys,
        kind,
        border,
        cborder,
        scale: 1.0,
        p2: p0[1],
        grad: None,
    };
    let mut y0 = x0[..n].to_vec();
    y0.push(p0[0]);
    y0.extend_from_slice(&x0[n..]);
    let norm = ext.gradient_norm(&y0, p0[1])?;
    if !(norm > 0.0 && norm.is_finite()) {
        return Err(Error::param(
            "event",
            "the test function is flat at the start: not a regular bifurcation point",
        ));
    }
    ext.scale = 1.0 / norm;
    ext.grad = None;
    let arc_opts = opts.arc.clone();
    let (lo, hi) = opts.p1_range;
    let mut arc = Arclength::new(&mut ext, &y0, p0[1], None, arc_opts.clone())?;
    let mut points: Vec<PoCurvePoint> = vec![];
    let mut special: Vec<PoCodim2> = vec![];
    let mut prev: Option<(ArcPoint, Vec<(&'static str, f64)>)> = None;
    while let Some(pt) = arc.next() {
        let p = [pt.x[n], pt.p];
        if !(lo..=hi).contains(&p[0]) {
            arc.finish("boundary");
            break;
        }
        let omega = arc
            .problem()
            .sys
            .full(&pt.x[..n])
            .last()
            .copied()
            .unwrap_or(f64::NAN);
        if !(omega > 1e-3) {
            arc.finish("omega_vanishes");
            break;
        }
        let theta = ns.then(|| pt.x[n + 1]);
        if let Some(t) = theta {
            if t < THETA_END {
                arc.finish("resonance_1:1");
                break;
            }
            if t > PI - THETA_END {
                arc.finish("resonance_1:2");
                break;
            }
        }
        let tt = arc.problem().sys.secondary(kind, &pt.x[..n], p, theta)?;
        let row = points.len();
        if let Some((a, ta)) = &prev {
            for (i, ((label, ga), (_, gb))) in ta.iter().zip(&tt).enumerate() {
                if ga * gb >= 0.0 {
                    continue;
                }
                let g = |e: &mut Augmented<'_, D>, pt: &ArcPoint| {
                    e.sys
                        .secondary(kind, &pt.x[..n], [pt.x[n], pt.p], ns.then(|| pt.x[n + 1]))
                        .map(|v| v[i].1)
                };
                if let Some((e, _)) = locate(
                    arc.problem(),
                    a,
                    &pt,
                    *ga,
                    *gb,
                    g,
                    opts.locate_tol,
                    0.0,
                    &arc_opts,
                )? {
                    let om = arc
                        .problem()
                        .sys
                        .full(&e.x[..n])
                        .last()
                        .copied()
                        .unwrap_or(f64::NAN);
                    let certificate = certify_at(arc.problem(), kind, label, &e, n, ns)?;
                    special.push(PoCodim2 {
                        kind: label,
                        p: [e.x[n], e.p],
                        omega: om,
                        row,
                        certificate,
                    });
                }
            }
            if kind == PoCurveKind::Fold {
                // A cusp: the curve's direction in the parameter plane reverses.
                let ua = [a.tangent[n], a.tangent[n + 1]];
                let ub = [pt.tangent[n], pt.tangent[n + 1]];
                let gb = ub[0] * ua[0] + ub[1] * ua[1];
                if gb < 0.0 {
                    let ga = ua[0] * ua[0] + ua[1] * ua[1];
                    let g = |_: &mut Augmented<'_, D>, pt: &ArcPoint| {
                        Ok(pt.tangent[n] * ua[0] + pt.tangent[n + 1] * ua[1])
                    };
                    if let Some((e, _)) = locate(
                        arc.problem(),
                        a,
                        &pt,
                        ga,
                        gb,
                        g,
                        opts.locate_tol,
                        0.0,
                        &arc_opts,
                    )? {
                        let om = arc
                            .problem()
                            .sys
                            .full(&e.x[..n])
                            .last()
                            .copied()
                            .unwrap_or(f64::NAN);
                        let certificate = certify_at(arc.problem(), kind, "CP", &e, n, ns)?;
                        special.push(PoCodim2 {
                            kind: "CP",
                            p: [e.x[n], e.p],
                            omega: om,
                            row,
                            certificate,
                        });
                    }
                }
            }
        }
        let prob = arc.problem();
        let sol = prob.sys.series(&pt.x[..n], pt.residual);
        let model = prob.sys.model(p)?.clone();
        let result = finish_on_branch(&model, sol, popts);
        let g = prob.g(&pt.x, pt.p)?;
        let g = if ns { g[0].hypot(g[1]) } else { g[0] };
        // New borders for the next step (the curve is the same set: g = 0 iff H is
        // singular, whatever the borders).
        prob.rebase(&pt.x, pt.p)?;
        points.push(PoCurvePoint {
            p,
            result,
            g,
            theta,
            tests: tt.clone(),
        });
        prev = Some((pt, tt));
    }
    let stop = ArcStop::text(arc.stop());
    if crate::cancel::cancelled() {
        return Err(Error::Cancelled);
    }
    if points.is_empty() {
        return Err(Error::param(
            "event",
            format!("the curve's start does not converge: {stop}"),
        ));
    }
    drop(arc);
    Ok((
        PoCurve {
            kind,
            points,
            special,
            together: ext.sys.reduced,
            stop: [stop.clone(), stop],
        },
        ext.sys,
    ))
}

/// [`certify_codim2`] at a located arclength point `e` of the augmented system.
fn certify_at<D: Parametric>(
    prob: &mut Augmented<'_, D>,
    kind: PoCurveKind,
    label: &str,
    e: &ArcPoint,
    n: usize,
    ns: bool,
) -> Result<Codim2Certificate> {
    let p = [e.x[n], e.p];
    let sol = prob.sys.series(&e.x[..n], e.residual);
    let merged = prob.sys.reduced;
    let model = prob.sys.model(p)?.clone();
    let cert = certify_codim2(&model, &sol, kind, label, ns.then(|| e.x[n + 1]), merged);
    if crate::cancel::cancelled() {
        return Err(Error::Cancelled);
    }
    Ok(cert)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bifurcation::po_branch::{periodic_branch, PoBranchOptions, PoEventKind};
    use crate::floquet::FloquetOptions;
    use crate::hb::HbOptions;
    use crate::periodic::periodic;
    use crate::Planar;

    fn popts(n: usize) -> PeriodicOptions {
        PeriodicOptions {
            hb: HbOptions {
                n_harm: n,
                ..Default::default()
            },
            floquet: Some(FloquetOptions::default()),
            ..Default::default()
        }
    }

    fn branch_opts(n: usize, lo: f64, hi: f64) -> PoBranchOptions {
        PoBranchOptions {
            arc: ArcOptions {
                ds: 0.02,
                ds_max: 0.05,
                ds_min: 1e-6,
                max_points: 200,
                p_min: lo,
                p_max: hi,
                ..Default::default()
            },
            periodic: popts(n),
            ..Default::default()
        }
    }

    fn curve_opts(n: usize, p1: (f64, f64), p2: (f64, f64), points: usize) -> PoCurveOptions {
        PoCurveOptions {
            arc: ArcOptions {
                ds: 0.01,
                ds_max: 0.05,
                ds_min: 1e-6,
                max_points: points,
                p_min: p2.0,
                p_max: p2.1,
                ..Default::default()
            },
            p1_range: p1,
            periodic: popts(n),
            ..Default::default()
        }
    }

    /// The standard merged R-R band's upper end at N = 6: its LP and BP events.
    fn standard_events(eta: f64) -> (Planar, Vec<(PoEventKind, f64, HbSolution)>) {
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[eta, eta]).unwrap();
        let o = branch_opts(6, 1.2, 1.9);
        let start = periodic(&p, &[true, true], None, &o.periodic);
        assert_eq!(start.sol.status, Status::Converged);
        let b = periodic_branch(&p, "Omega", &start.sol, &o).unwrap();
        let ev = b
            .events
            .iter()
            .map(|e| (e.kind, e.p, e.point.result.sol.clone()))
            .collect();
        (p, ev)
    }

    /// Along the LP and BP curves in (Omega, eta), each point is a fold / branch point
    /// of the branch continued in Omega at that point's eta: the second method is
    /// po_branch's event location (bisection on dp/ds and on the bordered determinant).
    #[test]
    fn fold_and_branch_point_curves_agree_with_branch_events() {
        let (p, ev) = standard_events(1.0);
        for kind in [PoCurveKind::Fold, PoCurveKind::BranchPoint] {
            let want = match kind {
                PoCurveKind::Fold => PoEventKind::Fold,
                _ => PoEventKind::BranchPoint,
            };
            let (_, om, sol) = ev.iter().find(|e| e.0 == want).expect("event").clone();
            let base = p.with_param("Omega", om).unwrap();
            let c = periodic_curve(
                &base,
                ["Omega", "eta"],
                kind,
                &sol,
                &curve_opts(6, (1.0, 3.0), (0.9, 1.1), 8),
            )
            .unwrap();
            assert!(c.together);
            assert!(c.points.len() >= 10, "{:?} {:?}", c.stop, c.points.len());
            for pt in [c.points.first().unwrap(), c.points.last().unwrap()] {
                let eta = pt.p[1];
                let (_, ev2) = standard_events(eta);
                let e = ev2.iter().find(|e| e.0 == want).expect("event at eta");
                assert!(
                    (e.1 - pt.p[0]).abs() < 1e-6,
                    "{kind:?} at eta {eta}: curve {} branch {}",
                    pt.p[0],
                    e.1
                );
            }
        }
    }

    /// Along the PD curve in (eta, Omega), the monodromy of every point's series (the
    /// variational equations integrated by RK45, not the half-harmonic Galerkin matrix
    /// the curve is defined by) has a multiplier at -1.
    #[test]
    fn period_doubling_curve_points_have_a_monodromy_multiplier_at_minus_one() {
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[0.9, 0.9]).unwrap();
        let mut o = branch_opts(6, 0.8, 0.9);
        o.arc.forward = false;
        o.arc.ds_max = 0.02;
        let start = periodic(&p, &[true, true], None, &o.periodic);
        let b = periodic_branch(&p, "eta", &start.sol, &o).unwrap();
        let mut co = curve_opts(6, (0.3, 1.5), (1.15, 1.25), 6);
        (co.arc.ds, co.arc.ds_max) = (0.05, 0.2);
        let c = curve_at_event(
            &p,
            &b,
            PoEventKind::PeriodDoubling,
            ["eta", "Omega"],
            PoCurveKind::PeriodDoubling,
            &co,
        );
        assert!(c.points.len() >= 8, "{:?}", c.stop);
        let (lo, hi) = c
            .points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), pt| {
                (a.min(pt.p[1]), b.max(pt.p[1]))
            });
        assert!(hi - lo > 0.02, "{lo} {hi}");
        for pt in &c.points {
            let m = &pt.result.floquet.as_ref().expect("multipliers").multipliers;
            let d = m
                .iter()
                .map(|z| (z.0 + 1.0).hypot(z.1))
                .fold(f64::INFINITY, f64::min);
            assert!(d < 1e-6, "{d} at {:?}", pt.p);
        }
    }

    /// A balancer on Ocvirk's short bearing (L/D 1/2, rho = e/c) with an external damper
    /// `zeta`, at Omega 2: the oil-whirl orbit (balls rocking, O-O) has a complex pair
    /// that leaves the unit circle between zeta 0.100 and 0.136 at rho 0.5.
    fn whirl_scene(zeta: f64, rho: f64) -> crate::Scene {
        use crate::model::bearing::{Bearing, Cavitation, FilmModel};
        use crate::model::components::{JournalSupport, SupportFilm};
        let p = Planar::new(0.2, zeta, &[0.1], 50.0, 2.0, &[1.0, 1.0]).unwrap();
        let film = SupportFilm::Reynolds(Bearing {
            lambda: 0.5,
            grooves: None,
            cavitation: Cavitation::HalfSommerfeld,
            model: FilmModel::Short,
        });
        crate::Scene::new(p, 0.0, None, 0.0, None, None)
            .unwrap()
            .with_bearing(Some(JournalSupport { film, rho }))
            .unwrap()
    }

    /// The whirl branch in zeta from 0.3 down to `lo` at rho 0.5 (N harmonics).
    fn whirl_branch(n: usize, lo: f64) -> (crate::Scene, crate::bifurcation::po_branch::PoBranch) {
        let sc = whirl_scene(0.3, 0.5);
        let mut o = branch_opts(n, lo, 0.3);
        o.arc.forward = false;
        // zeta 0.3: the whirl attracts strongly (pair 0.95), a short simulation finds it
        o.periodic.guess.settle = 200.0;
        o.periodic.guess.window = 100.0;
        let start = periodic(&sc, &[false, false], None, &o.periodic);
        assert_eq!(start.sol.status, Status::Converged);
        let b = periodic_branch(&sc, "zeta", &start.sol, &o).unwrap();
        (sc, b)
    }

    /// The curve of `kind` in `names` through the first `event` of `b`, a branch of `p`
    /// in `names[0]`.
    fn curve_at_event<D: Parametric>(
        p: &D,
        b: &crate::bifurcation::po_branch::PoBranch,
        event: PoEventKind,
        names: [&str; 2],
        kind: PoCurveKind,
        co: &PoCurveOptions,
    ) -> PoCurve {
        let e = b
            .events
            .iter()
            .find(|e| e.kind == event)
            .unwrap_or_else(|| panic!("a {event:?} event"));
        let base = p.with_param(names[0], e.p).unwrap();
        periodic_curve(&base, names, kind, &e.point.result.sol, co).unwrap()
    }

    /// Along the NS curve in (zeta, rho), the monodromy of every point's series (the
    /// variational equations integrated by RK45, not the Hill matrix the curve is defined
    /// by) has a complex pair on the unit circle at the curve's angle.
    #[test]
    fn neimark_sacker_curve_points_have_a_monodromy_pair_on_the_unit_circle() {
        let (sc, b) = whirl_branch(5, 0.12);
        let mut co = curve_opts(5, (0.05, 0.3), (0.48, 0.52), 3);
        (co.arc.ds, co.arc.ds_max) = (0.01, 0.02);
        let c = curve_at_event(
            &sc,
            &b,
            PoEventKind::NeimarkSacker,
            ["zeta", "rho"],
            PoCurveKind::NeimarkSacker,
            &co,
        );
        assert!(c.points.len() >= 4, "{:?}", c.stop);
        for pt in &c.points {
            let theta = pt.theta.expect("an NS curve's angle");
            let m = &pt.result.floquet.as_ref().expect("multipliers").multipliers;
            let z = m
                .iter()
                .filter(|z| z.1 > 1e-9)
                .min_by(|a, b| {
                    let d = |z: &&(f64, f64)| (z.0.hypot(z.1) - 1.0).abs();
                    d(a).total_cmp(&d(b))
                })
                .expect("a complex pair");
            assert!((z.0.hypot(z.1) - 1.0).abs() < 1e-6, "{z:?} at {:?}", pt.p);
            assert!((z.1.atan2(z.0) - theta).abs() < 1e-5, "{z:?} {theta}");
        }
    }

    /// Measurement: `cargo test --release -p ballbal-core explore_ns -- --ignored
    /// --nocapture`.
    #[test]
    #[ignore]
    fn explore_ns() {
        let n: usize = std::env::var("N")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(6);
        let t = std::time::Instant::now();
        let (sc, b) = whirl_branch(n, 0.05);
        println!(
            "{} points {:?} stop {}",
            b.points.len(),
            t.elapsed(),
            b.stop
        );
        for e in &b.events {
            println!(
                "EVENT {} p={:.9} w={}",
                e.kind.as_str(),
                e.p,
                e.point.omega()
            );
        }
        let mut co = curve_opts(n, (0.0, 1.0), (0.3, 1.0), 40);
        (co.arc.ds, co.arc.ds_max) = (0.01, 0.05);
        let c = curve_at_event(
            &sc,
            &b,
            PoEventKind::NeimarkSacker,
            ["zeta", "rho"],
            PoCurveKind::NeimarkSacker,
            &co,
        );
        println!("curve {:?} {:?}", c.stop, t.elapsed());
        for pt in &c.points {
            let m = &pt.result.floquet.as_ref().expect("multipliers").multipliers;
            let ns = m
                .iter()
                .filter(|z| z.1 > 1e-9)
                .map(|z| format!("{:.6}@{:.4}", z.0.hypot(z.1), z.1.atan2(z.0)))
                .collect::<Vec<_>>()
                .join(" ");
            println!(
                "zeta={:.6} rho={:.6} theta={:.5} g={:.1e} w={:.5} {:?} | {}",
                pt.p[0],
                pt.p[1],
                pt.theta.unwrap(),
                pt.g,
                pt.result.sol.omega,
                pt.tests,
                ns
            );
        }
        for s in &c.special {
            println!("SPECIAL {} {:?} row {}", s.kind, s.p, s.row);
        }
    }

    /// The decision on one needed multiplier and on a point's two: a multiplier is
    /// confirmed only within the safety factor times the error and when the monodromy
    /// resolves it from values 0.1 away; an untrusted monodromy decides nothing; a point
    /// is confirmed only if both its multipliers are.
    #[test]
    fn codim2_status_logic() {
        use Codim2Status::*;
        let e = 1e-6;
        assert_eq!(condition_status(5e-6, 0.05, e, true), Confirmed);
        assert_eq!(condition_status(2e-5, 0.05, e, true), Rejected);
        // ill conditioned: values 0.1 away are as consistent as the required one
        assert_eq!(condition_status(5e-6, 5e-6, e, true), Undetermined);
        // far off even so: no perturbation within the error reaches it
        assert_eq!(condition_status(1e-3, 5e-6, e, true), Rejected);
        assert_eq!(condition_status(5e-6, 0.05, e, false), Undetermined);
        assert_eq!(condition_status(1.0, 0.05, e, false), Undetermined);
        assert_eq!(condition_status(f64::NAN, 0.05, e, true), Undetermined);
        assert_eq!(condition_status(5e-6, 0.05, f64::NAN, true), Undetermined);
        for a in [Confirmed, Rejected, Undetermined] {
            assert_eq!(combine(a, Rejected), Rejected);
            assert_eq!(combine(Rejected, a), Rejected);
        }
        assert_eq!(combine(Confirmed, Confirmed), Confirmed);
        assert_eq!(combine(Confirmed, Undetermined), Undetermined);
        assert_eq!(combine(Undetermined, Confirmed), Undetermined);
        // what each label adds to its curve's own
        assert_eq!(added_need(PoCurveKind::Fold, "LPPD"), Some(Need::MinusOne));
        assert_eq!(
            added_need(PoCurveKind::PeriodDoubling, "LPPD"),
            Some(Need::SecondPlusOne)
        );
        assert_eq!(added_need(PoCurveKind::Fold, "BP"), Some(Need::Separation));
        assert_eq!(
            added_need(PoCurveKind::BranchPoint, "LP"),
            Some(Need::SecondPlusOne)
        );
        assert_eq!(
            added_need(PoCurveKind::BranchPoint, "PD"),
            Some(Need::MinusOne)
        );
        assert_eq!(
            added_need(PoCurveKind::NeimarkSacker, "BPNS"),
            Some(Need::Separation)
        );
        assert_eq!(added_need(PoCurveKind::Fold, "CP"), None);
        assert_eq!(added_need(PoCurveKind::NeimarkSacker, "R4"), None);
    }

    /// The backward error of a value against a known spectrum: `diag(2, -1 + h)` has
    /// `sigma_min(A + I) = h`; a Jordan block `[[1, 1], [0, 1]]` deflated along its
    /// eigenvector `e1` leaves `[1]`, a simple `+1`.
    #[test]
    fn backward_error_and_deflation() {
        let h = 1e-7;
        let a = DMatrix::from_row_slice(2, 2, &[2.0, 0.0, 0.0, -1.0 + h]).map(|x| C64::new(x, 0.0));
        assert!((smin(&a, C64::new(-1.0, 0.0)) - h).abs() < 1e-15);
        let j = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 0.0, 1.0 + 4.0 * h]);
        let v = DVector::from_column_slice(&[1.0, 0.0]);
        let q = complement(&v);
        let d = (q.transpose() * &j * &q).map(|x| C64::new(x, 0.0));
        // linear in the perturbation, where the eigenvalues of j split by ~sqrt
        assert!((smin(&d, C64::new(1.0, 0.0)) - 4.0 * h).abs() < 1e-12);
    }

    #[test]
    fn bad_inputs_name_the_parameter() {
        let (p, ev) = standard_events(1.0);
        let (_, om, sol) = ev
            .iter()
            .find(|e| e.0 == PoEventKind::BranchPoint)
            .unwrap()
            .clone();
        let base = p.with_param("Omega", om).unwrap();
        let o = curve_opts(6, (1.0, 3.0), (0.9, 1.1), 4);
        let name = |names: [&str; 2], sol: &HbSolution, o: &PoCurveOptions| match periodic_curve(
            &base,
            names,
            PoCurveKind::BranchPoint,
            sol,
            o,
        ) {
            Err(Error::InvalidParameter { name, .. }) => name,
            other => panic!("{:?}", other.map(|c| c.stop)),
        };
        assert_eq!(name(["nope", "eta"], &sol, &o), "parameter");
        assert_eq!(name(["Omega", "nope"], &sol, &o), "parameter2");
        assert_eq!(name(["Omega", "Omega"], &sol, &o), "parameter2");
        let mut bad = sol.clone();
        bad.omega = f64::NAN;
        assert_eq!(name(["Omega", "eta"], &bad, &o), "start");
        let mut o1 = o.clone();
        o1.p1_range = (2.0, 3.0);
        assert_eq!(name(["Omega", "eta"], &sol, &o1), "range1");
        let mut o2 = o.clone();
        (o2.arc.p_min, o2.arc.p_max) = (1.2, 1.3);
        assert_eq!(name(["Omega", "eta"], &sol, &o2), "range");
        let mut o3 = o.clone();
        o3.locate_tol = -1.0;
        assert_eq!(name(["Omega", "eta"], &sol, &o3), "locate_tol");
        assert!(PoCurveKind::parse("XX").is_err());
        assert_eq!(
            PoCurveKind::parse("NS").ok(),
            Some(PoCurveKind::NeimarkSacker)
        );
    }
}
