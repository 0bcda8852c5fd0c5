//! The minimally augmented system `[F; g] = 0` of a curve: the borders that keep the
//! bordered test matrix regular, and the system as a [`Problem`] in `(x, p1)` (with
//! `theta` for Neimark–Sacker) over the second parameter.

use super::system::{PoSystem, C64};
use super::PoCurveKind;
use crate::error::{Error, Result};
use crate::numerics::problem::{Parametric, Problem};
use nalgebra::{ComplexField, DMatrix, DVector};

/// Borders of a minimally augmented system: `b` (a column), `c` (a row, kept as its
/// adjoint): real, or complex for the Neimark–Sacker test matrix.
#[derive(Debug, Clone)]
pub(super) struct Border<T: ComplexField> {
    pub(super) b: DVector<T>,
    pub(super) c: DVector<T>,
}

pub(super) type CBorder = Border<C64>;

impl<T: ComplexField<RealField = f64>> Border<T> {
    /// The smallest singular value's left and right vectors.
    pub(super) fn from_svd(h: &DMatrix<T>) -> Result<Self> {
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
    pub(super) fn matrix(&self, h: &DMatrix<T>) -> DMatrix<T> {
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
    pub(super) fn solve(
        &self,
        h: &DMatrix<T>,
        adjoint: bool,
    ) -> Option<(T, Option<(Vec<T>, Vec<T>)>)> {
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
    pub(super) fn update(&mut self, v: &[T], w: &[T]) {
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
    pub(super) kind: PoCurveKind,
    pub(super) border: Border<f64>,
    /// The complex borders of an `NS` curve (`border` is then unused).
    pub(super) cborder: Option<CBorder>,
    /// `g` is divided by its gradient's norm at the start: `|g|` is then about the
    /// distance from the curve, and the corrector's tolerance means the same for it.
    pub(super) scale: f64,
    pub(super) p2: f64,
    /// The last gradient of `g` (over `x`, `p1`, `p2`) and where it was taken:
    /// `jac_x` and `jac_p` of one point share it.
    pub(super) grad: Option<GradCache>,
}

pub(super) fn singular_at(p: [f64; 2]) -> Error {
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
    pub(super) fn g(&mut self, y: &[f64], p2: f64) -> Result<Vec<f64>> {
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
    pub(super) fn g_grad(
        &mut self,
        x: &[f64],
        p: [f64; 2],
    ) -> Result<(f64, Vec<f64>, Vec<f64>, Vec<f64>)> {
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
    pub(super) fn g_grad_ns(&mut self, y: &[f64], p2: f64) -> Result<GradCache> {
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
    pub(super) fn at(&mut self, y: &[f64], p2: f64) -> Result<&GradCache> {
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
    pub(super) fn gradient_norm(&mut self, y: &[f64], p2: f64) -> Result<f64> {
        let c = self.at(y, p2)?;
        Ok(c.grad.iter().flatten().map(|g| g * g).sum::<f64>().sqrt())
    }

    /// Borders from the null and adjoint vectors at a curve point.
    pub(super) fn rebase(&mut self, y: &[f64], p2: f64) -> Result<()> {
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
    pub(super) fn extra(&self) -> usize {
        usize::from(self.cborder.is_some())
    }
}

pub(super) enum Null {
    Real(Vec<f64>, Vec<f64>),
    Complex(Vec<C64>, Vec<C64>),
}

pub(super) struct GradCache {
    pub(super) key: Vec<u64>,
    /// One test function, or `Re g, Im g`.
    pub(super) g: Vec<f64>,
    /// Their gradients over `(x, p1, p2[, theta])`.
    pub(super) grad: Vec<Vec<f64>>,
    pub(super) null: Null,
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
    pub(super) fn f_p(&mut self, x: &[f64], p: [f64; 2], k: usize) -> Result<Vec<f64>> {
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
