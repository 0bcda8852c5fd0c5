//! The seam between problems and solvers: a square nonlinear system `F(x, p) = 0` in
//! unknowns `x` and one scalar parameter `p`, with its Jacobians `dF/dx` and `dF/dp`.
//! Newton solvers need `residual` and `jac_x`; continuation in `p` (the implicit
//! function theorem `dx/dp = -F_x^-1 F_p`, pseudo-arclength tangents) needs `jac_p` too.
//! The equilibrium problem and the harmonic-balance problem implement it; nothing here
//! knows a concrete model.

use crate::error::{Error, Result};
use crate::model::Dynamics;

/// A model family: copies of a model with one named parameter changed.
pub trait Parametric: Dynamics + Clone {
    /// A copy with the parameter `name` set to `value`, validated.
    fn with_param(&self, name: &str, value: f64) -> Result<Self>;
    /// The current value of the parameter `name` (the names `with_param` takes).
    fn param_value(&self, name: &str) -> Result<f64>;
}

/// A square system `F(x, p) = 0`: `size()` unknowns and as many equations.
pub trait Problem {
    fn size(&self) -> usize;
    /// The parameter value the problem was built at (`NaN` for a problem without a
    /// parameter).
    fn param(&self) -> f64;
    /// `F(x, p)` into `r`.
    fn residual(&mut self, x: &[f64], p: f64, r: &mut [f64]) -> Result<()>;
    /// `F(x, p)` into `r` and the row-major `size() x size()` Jacobian `dF/dx` into
    /// `jac` (together: they share their evaluations).
    fn jac_x(&mut self, x: &[f64], p: f64, r: &mut [f64], jac: &mut [f64]) -> Result<()>;
    /// `dF/dx` alone, for solvers that evaluated the residual already.
    fn jacobian(&mut self, x: &[f64], p: f64, jac: &mut [f64]) -> Result<()> {
        let mut r = vec![0.0; self.size()];
        self.jac_x(x, p, &mut r, jac)
    }
    /// `dF/dp` into `out`. By default a central difference with step
    /// `1e-6 (1 + |p|)`, for problems without an analytic derivative.
    fn jac_p(&mut self, x: &[f64], p: f64, out: &mut [f64]) -> Result<()> {
        if !p.is_finite() {
            return Err(Error::param("p", format!("no derivative at p = {p}")));
        }
        let h = 1e-6 * (1.0 + p.abs());
        let mut rm = vec![0.0; self.size()];
        self.residual(x, p + h, out)?;
        self.residual(x, p - h, &mut rm)?;
        for (o, m) in out.iter_mut().zip(&rm) {
            *o = (*o - m) / (2.0 * h);
        }
        Ok(())
    }
}

/// The model a problem evaluates at a parameter value: the model it was built with at
/// that model's own value, otherwise a copy with the parameter changed (built once per
/// value and kept for repeated evaluations, e.g. a finite difference's two sides).
pub struct ModelAt<'a, D: ?Sized> {
    base: &'a D,
    value: f64,
    vary: Option<Vary<'a>>,
    cached: Option<(u64, Box<dyn Dynamics + 'a>)>,
}

type Vary<'a> = Box<dyn Fn(f64) -> Result<Box<dyn Dynamics + 'a>> + 'a>;

/// The model at one parameter value: the base (statically dispatched, the solvers' fast
/// path) or a varied copy.
pub enum At<'m, D: ?Sized> {
    Base(&'m D),
    Varied(&'m dyn Dynamics),
}

impl<'a, D: Dynamics + ?Sized> ModelAt<'a, D> {
    /// A model without a parameter: only `p = NaN` (or the problem's `param()`) is valid.
    pub fn fixed(base: &'a D) -> Self {
        ModelAt {
            base,
            value: f64::NAN,
            vary: None,
            cached: None,
        }
    }

    /// The family of `base` in the parameter `name`, at the value `base` has.
    pub fn family_of(base: &'a D, name: &'a str) -> Result<Self>
    where
        D: Parametric + 'a,
    {
        Ok(Self::family(base, name, base.param_value(name)?))
    }

    /// The family of `base` in the parameter `name`, whose value in `base` is `value`.
    pub fn family(base: &'a D, name: &'a str, value: f64) -> Self
    where
        D: Parametric + 'a,
    {
        ModelAt {
            base,
            value,
            vary: Some(Box::new(move |p| {
                Ok(Box::new(base.with_param(name, p)?) as Box<dyn Dynamics + 'a>)
            })),
            cached: None,
        }
    }

    pub fn value(&self) -> f64 {
        self.value
    }

    pub fn base(&self) -> &'a D {
        self.base
    }

    /// The model at `p`.
    pub fn at(&mut self, p: f64) -> Result<At<'_, D>> {
        if p.to_bits() == self.value.to_bits() || (p.is_nan() && self.value.is_nan()) {
            return Ok(At::Base(self.base));
        }
        let Some(vary) = &self.vary else {
            return Err(Error::param(
                "p",
                format!("this problem has no parameter to set to {p}"),
            ));
        };
        if self.cached.as_ref().is_none_or(|(b, _)| *b != p.to_bits()) {
            self.cached = Some((p.to_bits(), vary(p)?));
        }
        Ok(At::Varied(self.cached.as_ref().unwrap().1.as_ref()))
    }
}

/// Solves `J y = rhs` for the row-major `n x n` `J` by LU; `None` if singular.
pub fn solve_dense(jac: &[f64], n: usize, rhs: &[f64]) -> Option<Vec<f64>> {
    crate::linalg::lu_solve(jac, n, rhs).map(|s| s.x)
}

/// The implicit-function-theorem tangent `dx/dp = -F_x^-1 F_p` at a solution `x` of
/// `F(x, p) = 0`; `None` where `dF/dx` is singular (a fold, or a family of solutions).
pub fn tangent<P: Problem + ?Sized>(
    problem: &mut P,
    x: &[f64],
    p: f64,
) -> Result<Option<Vec<f64>>> {
    let n = problem.size();
    let (mut r, mut jac, mut fp) = (vec![0.0; n], vec![0.0; n * n], vec![0.0; n]);
    problem.jac_x(x, p, &mut r, &mut jac)?;
    problem.jac_p(x, p, &mut fp)?;
    let neg: Vec<f64> = fp.iter().map(|v| -v).collect();
    Ok(solve_dense(&jac, n, &neg))
}
