//! The harmonic-balance equations a periodic curve continues, in two parameters, on the
//! full coordinates or on the together subspace of merged balls, with the test matrices
//! `H` of each kind (the Galerkin matrices of fold, branch point and period doubling,
//! Hill's matrix of Neimark–Sacker) and the contracted gradients `w^T H_y v`.

use super::PoCurveKind;
use crate::error::{Error, Result};
use crate::hb::{eval_series_sc, HbSolution, HbSystem, Status};
use crate::model::Jacobians;
use crate::numerics::problem::Parametric;
use nalgebra::{Complex, DMatrix, DVector};
use std::f64::consts::PI;

/// The harmonic-balance equations of a model family in two parameters, on the full
/// coordinates or on the together subspace of merged balls.
pub struct PoSystem<'a, D: Parametric> {
    pub(super) base: &'a D,
    pub(super) names: [String; 2],
    pub(super) hb: HbSystem<'a, D>,
    pub(super) reduced: bool,
    pub(super) d: usize,
    pub(super) o: usize,
    pub(super) l: usize,
    pub(super) n_harm: usize,
    pub(super) samples: usize,
    pub(super) winding: Vec<f64>,
    pub(super) cache: Option<([u64; 2], D)>,
}

/// What a Galerkin matrix is projected on: rows the basis `rows` per coordinate,
/// columns `cols` per coordinate and, with `omega_col`, the derivative in omega; sampled
/// `periods` times over `[0, 2 pi)` (twice for a half-harmonic basis, whose period is
/// two of the orbit's).
#[derive(Clone, Copy)]
pub(super) struct Projection<'t> {
    rows: &'t Table,
    cols: &'t Table,
    omega_col: bool,
    periods: usize,
}

impl<'t> Projection<'t> {
    fn new(rows: &'t Table, cols: &'t Table, omega_col: bool, periods: usize) -> Self {
        Projection {
            rows,
            cols,
            omega_col,
            periods,
        }
    }
}

/// Step of the directional differences along a unit null vector.
pub(super) const DIR_STEP: f64 = 1e-5;

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

    pub(super) fn nf(&self) -> usize {
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
    pub(super) fn map(&self, i: usize) -> usize {
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

    pub(super) fn full_eval(
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
    pub(super) fn separating(&self, jf: &[f64]) -> DMatrix<f64> {
        let (nf, l, o) = (self.nf(), self.l, self.o);
        DMatrix::from_fn(l, l, |i, k| {
            let row = (o * l + i) * nf;
            jf[row + o * l + k] - jf[row + (o + 1) * l + k]
        })
    }

    pub(super) fn full_jac(&mut self, xf: &[f64], p: [f64; 2]) -> Result<Vec<f64>> {
        let nf = self.nf();
        let (mut r, mut jf) = (vec![0.0; nf], vec![0.0; nf * nf]);
        self.full_eval(xf, p, &mut r, Some(&mut jf))?;
        Ok(jf)
    }

    pub(super) fn sys_jac(&mut self, x: &[f64], p: [f64; 2]) -> Result<DMatrix<f64>> {
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
                self.galerkin(&xf, None, p, Projection::new(&half, &half, false, 1))
            }
            PoCurveKind::NeimarkSacker => Err(complex_kind()),
        }
    }

    /// The Galerkin matrix of the linearisation about the series `xf` (plus `pert`, a
    /// half-harmonic series, when given) on the projection `on`.
    pub(super) fn galerkin(
        &mut self,
        xf: &[f64],
        pert: Option<&[f64]>,
        p: [f64; 2],
        on: Projection<'_>,
    ) -> Result<DMatrix<f64>> {
        let Projection {
            rows,
            cols,
            omega_col,
            periods,
        } = on;
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
            m.jacobians(
                tau / om,
                &q,
                &v,
                &a,
                Jacobians::new(&mut kk, &mut cc, &mut mm),
            );
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
    pub(super) fn contracted_gradient(
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
                let gp =
                    self.galerkin(&xf, Some(&ep), p, Projection::new(&half, &whole, true, 2))?;
                let gm =
                    self.galerkin(&xf, Some(&em), p, Projection::new(&half, &whole, true, 2))?;
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
                    let a = self.galerkin(&xf, None, pp, Projection::new(&one, &one, false, 1))?;
                    let b = self.galerkin(&xf, None, pm, Projection::new(&one, &one, false, 1))?;
                    grad[n + k] = uv.dot(&((a - b) * &vv)) / (2.0 * hp);
                }
            }
            PoCurveKind::NeimarkSacker => return Err(complex_kind()),
        }
        Ok(grad)
    }

    /// `(phi(F(x+, p+) - F(x+, p-)) - phi(F(x-, p+) - F(x-, p-))) / (2 h_p)` for
    /// parameter `k` (`full`: `x+-` are full unknowns and `F` the full residual).
    pub(super) fn mixed_p(
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
    pub(super) fn secondary(
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

pub(super) fn complex_kind() -> Error {
    Error::param(
        "kind",
        "the Neimark–Sacker test matrix is complex: it has no real test matrix",
    )
}

pub(super) fn scaled_det(mut m: DMatrix<f64>) -> f64 {
    for i in 0..m.nrows() {
        let s = m.row(i).iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if s > 0.0 {
            m.row_mut(i).iter_mut().for_each(|v| *v /= s);
        }
    }
    m.lu().determinant()
}

#[derive(Clone, Copy, PartialEq)]
pub(super) enum Basis {
    /// `1, cos k tau, sin k tau` (`k <= N`): the harmonic balance's own.
    Whole,
    /// `cos (k + 1/2) tau, sin (k + 1/2) tau` (`k < N`).
    Half,
}

/// A basis's values and tau-derivatives at the samples, with the Galerkin weights.
pub(super) struct Table {
    pub(super) width: usize,
    pub(super) vals: Vec<(f64, f64, f64)>,
    pub(super) wgt: Vec<f64>,
}

impl Table {
    pub(super) fn new(basis: Basis, nh: usize, samples: usize, periods: usize) -> Self {
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

    pub(super) fn at(&self, i: usize, r: usize) -> (f64, f64, f64) {
        self.vals[i * self.width + r]
    }

    pub(super) fn weight(&self, i: usize, r: usize) -> f64 {
        self.wgt[i * self.width + r]
    }
}

/// Complex numbers of the Neimark–Sacker test matrix.
pub(super) type C64 = Complex<f64>;

/// The orbit's linearisation sampled over one period, `L u = K u + omega C u' +
/// omega^2 M u''` (tau-derivatives): per sample `K`, `omega C` and `omega^2 M`
/// (row-major `d x d`), with the state `(q, q', q'')` it was taken at.
pub(super) struct Sampled {
    pub(super) s: usize,
    pub(super) d: usize,
    pub(super) om: f64,
    pub(super) k: Vec<f64>,
    pub(super) c: Vec<f64>,
    pub(super) m: Vec<f64>,
    /// The unscaled `C` and `M` and the state's tau-derivatives, for the omega column.
    pub(super) cc: Vec<f64>,
    pub(super) mm: Vec<f64>,
    pub(super) qt: Vec<f64>,
    pub(super) qtt: Vec<f64>,
}

impl<'a, D: Parametric> PoSystem<'a, D> {
    /// The linearisation about the full series `xf` (plus `pert`, per sample) at `p`.
    pub(super) fn sampled(
        &mut self,
        xf: &[f64],
        pert: Option<&[[f64; 3]]>,
        p: [f64; 2],
    ) -> Result<Sampled> {
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
                Jacobians::new(
                    &mut out.k[o..o + d * d],
                    &mut out.cc[o..o + d * d],
                    &mut out.mm[o..o + d * d],
                ),
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
    pub(super) fn hill_ns(&mut self, xf: &[f64], p: [f64; 2], theta: f64) -> Result<DMatrix<C64>> {
        let lin = self.sampled(xf, None, p)?;
        Ok(hill_from(&lin, self.n_harm, theta))
    }

    /// The phase-free Floquet solution's sample values: per sample and coordinate
    /// `(U, U', U'')` of `U = e^{i nu tau} P(tau)`, `P` the series `v` on `e^{i c tau}`,
    /// and `conj(W)/S` of the adjoint series `w` likewise.
    pub(super) fn ns_samples(&self, theta: f64, v: &[C64], w: &[C64]) -> (Vec<[C64; 3]>, Vec<C64>) {
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
    pub(super) fn ns_gradient(
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
pub(super) fn hill_from(lin: &Sampled, n_harm: usize, theta: f64) -> DMatrix<C64> {
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
pub(super) fn start_angle<D: Parametric>(
    sys: &mut PoSystem<'_, D>,
    xf: &[f64],
    p: [f64; 2],
) -> Result<f64> {
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
