//! Two-parameter curves of bifurcation points as continuation of an extended system.
//!
//! A codimension-one bifurcation of `F(x, p1, p2) = 0` is a zero of a scalar test
//! function `g(x, p1, p2)` on the solution manifold (a determinant for a fold, a
//! bialternate-product determinant for a Hopf point, a characteristic multiplier's
//! distance from -1 for period doubling, ...). The curve is the solution set of
//!
//! ```text
//!   F(x, p1, p2) = 0
//!   g(x, p1, p2) = 0
//! ```
//!
//! which [`Extended`] presents as an ordinary [`Problem`] with unknowns `(x, p1)` and
//! parameter `p2`, so that [`super::Arclength`] follows it through folds of the curve.
//! The test function need only be smooth and regular near the curve; its derivatives are
//! taken by central differences (minimally augmented systems supply `g` by one bordered
//! solve, which is what makes this cheap).

use crate::continuation::arclength::{
    locate, ArcOptions, ArcPoint, ArcStop, Arclength, Bracket, Within,
};
use crate::error::{Error, Result};
use crate::numerics::problem::Problem;

/// A square system in `x` with two scalar parameters.
pub trait TwoParameter {
    fn size(&self) -> usize;
    fn residual(&mut self, x: &[f64], p: [f64; 2], r: &mut [f64]) -> Result<()>;
    /// `F` into `r` and the row-major `dF/dx` into `jac`.
    fn jac_x(&mut self, x: &[f64], p: [f64; 2], r: &mut [f64], jac: &mut [f64]) -> Result<()>;
    /// `dF/dp_k` (k = 0, 1) into `out`; by default a central difference.
    fn jac_p(&mut self, x: &[f64], p: [f64; 2], k: usize, out: &mut [f64]) -> Result<()> {
        let h = 1e-6 * (1.0 + p[k].abs());
        let (mut pp, mut pm) = (p, p);
        pp[k] += h;
        pm[k] -= h;
        let mut rm = vec![0.0; self.size()];
        self.residual(x, pp, out)?;
        self.residual(x, pm, &mut rm)?;
        for (o, m) in out.iter_mut().zip(&rm) {
            *o = (*o - m) / (2.0 * h);
        }
        Ok(())
    }
}

/// A scalar test function on a [`TwoParameter`] system.
pub trait TestFunction<T: TwoParameter + ?Sized> {
    fn value(&mut self, system: &mut T, x: &[f64], p: [f64; 2]) -> Result<f64>;
}

impl<T: TwoParameter + ?Sized, G: FnMut(&mut T, &[f64], [f64; 2]) -> Result<f64>> TestFunction<T>
    for G
{
    fn value(&mut self, system: &mut T, x: &[f64], p: [f64; 2]) -> Result<f64> {
        self(system, x, p)
    }
}

/// One curve from its two halves, continued from the same start backwards and forwards:
/// the backward points reversed, then the forward ones (the start, first of both, once);
/// the special points in that order, their `row` (index into the half's points,
/// reached through `row`) renumbered into the whole curve.
pub fn join_halves<P, C>(
    back: (Vec<P>, Vec<C>),
    fwd: (Vec<P>, Vec<C>),
    row: impl Fn(&mut C) -> &mut usize,
) -> (Vec<P>, Vec<C>) {
    let nb = back.0.len();
    let mut points: Vec<P> = back.0.into_iter().rev().collect();
    points.extend(fwd.0.into_iter().skip(1));
    let mut special: Vec<C> = back
        .1
        .into_iter()
        .rev()
        .map(|mut c| {
            *row(&mut c) = nb - *row(&mut c);
            c
        })
        .collect();
    special.extend(fwd.1.into_iter().map(|mut c| {
        *row(&mut c) += nb - 1;
        c
    }));
    (points, special)
}

/// What the bifurcation side supplies to [`curve_half`] along a curve continued as a
/// [`Problem`] `P` whose unknowns are `(x, p1, ...)` (`x` of [`CurveHook::n`] entries)
/// with `p2` its parameter: the codimension-two test functions, what a located zero of
/// one is, and the row kept per point.
pub trait CurveHook<P: Problem + ?Sized> {
    /// The row kept per curve point.
    type Point;
    /// A located codimension-two point.
    type Special;
    /// The size of `x`: `p1` is the unknown after it.
    fn n(&self) -> usize;
    /// Why the curve ends at the corrected point `pt` (it is not kept), if it does:
    /// a window the arclength corrector does not know, a degenerate solution.
    fn end(&mut self, _problem: &mut P, _pt: &ArcPoint) -> Result<Option<&'static str>> {
        Ok(None)
    }
    /// The labelled scalar tests whose sign changes between two points are
    /// codimension-two points (the same labels, in the same order, at every point).
    fn tests(&mut self, problem: &mut P, pt: &ArcPoint) -> Result<Vec<(&'static str, f64)>>;
    /// The label of a cusp (the curve's direction in the parameter plane reverses), or
    /// `None` when cusps are not watched.
    fn cusp(&self) -> Option<&'static str>;
    /// The codimension-two point at the located zero `e` of test `label` (or a cusp),
    /// `row` the index of the first point past it; `None` when the zero is not one (a
    /// neutral saddle on a Hopf test, say).
    fn special(
        &mut self,
        problem: &mut P,
        label: &'static str,
        e: &ArcPoint,
        row: usize,
    ) -> Result<Option<Self::Special>>;
    /// The row kept at the corrected point `pt`, with its tests; the last call at a
    /// point (it may rebase the problem's borders for the next step).
    fn point(
        &mut self,
        problem: &mut P,
        pt: &ArcPoint,
        tests: &[(&'static str, f64)],
    ) -> Result<Self::Point>;
}

/// One half of a curve (or a whole curve, its halves joined).
#[derive(Debug, Clone)]
pub struct CurveHalf<Pt, Sp> {
    pub points: Vec<Pt>,
    pub special: Vec<Sp>,
    /// Why each half ended: towards decreasing, then increasing second parameter (a
    /// single half reports its own end twice).
    pub stop: [ArcStop; 2],
}

/// The one two-parameter curve loop: continues `problem` by pseudo-arclength from `y0`
/// at `p2` in the direction `opts.forward`, keeps a row per corrected point, and locates
/// (to arclength `locate_tol`) every codimension-two test's sign change and every cusp
/// between two points. Errors when not even the start converges.
pub fn curve_half<P, H>(
    problem: &mut P,
    y0: &[f64],
    p2: f64,
    opts: &ArcOptions,
    locate_tol: f64,
    hook: &mut H,
) -> Result<CurveHalf<H::Point, H::Special>>
where
    P: Problem + ?Sized,
    H: CurveHook<P>,
{
    let n = hook.n();
    let within = Within {
        s: locate_tol,
        g: 0.0,
    };
    let mut arc = Arclength::new(problem, y0, p2, None, opts.clone())?;
    let mut points = vec![];
    let mut special = vec![];
    let mut prev: Option<(ArcPoint, Vec<(&'static str, f64)>)> = None;
    while let Some(pt) = arc.next() {
        if let Some(why) = hook.end(arc.problem(), &pt)? {
            arc.finish(why);
            break;
        }
        let tt = hook.tests(arc.problem(), &pt)?;
        let row = points.len();
        if let Some((a, ta)) = &prev {
            for (i, ((label, ga), (_, gb))) in ta.iter().zip(&tt).enumerate() {
                if ga * gb >= 0.0 {
                    continue;
                }
                let g = |e: &mut P, pt: &ArcPoint| hook.tests(e, pt).map(|v| v[i].1);
                let bracket = Bracket {
                    a,
                    b: &pt,
                    ga: *ga,
                    gb: *gb,
                };
                let located = locate(arc.problem(), bracket, g, within, opts)?;
                if let Some((e, _)) = located {
                    special.extend(hook.special(arc.problem(), label, &e, row)?);
                }
            }
            if let Some(label) = hook.cusp() {
                // The curve's direction in the parameter plane reverses.
                let ua = [a.tangent[n], a.tangent[n + 1]];
                let ub = [pt.tangent[n], pt.tangent[n + 1]];
                let gb = ub[0] * ua[0] + ub[1] * ua[1];
                if gb < 0.0 {
                    let ga = ua[0] * ua[0] + ua[1] * ua[1];
                    let g = |_: &mut P, pt: &ArcPoint| {
                        Ok(pt.tangent[n] * ua[0] + pt.tangent[n + 1] * ua[1])
                    };
                    let bracket = Bracket { a, b: &pt, ga, gb };
                    let located = locate(arc.problem(), bracket, g, within, opts)?;
                    if let Some((e, _)) = located {
                        special.extend(hook.special(arc.problem(), label, &e, row)?);
                    }
                }
            }
        }
        points.push(hook.point(arc.problem(), &pt, &tt)?);
        crate::cancel::advance();
        prev = Some((pt, tt));
    }
    let stop = arc.stop().cloned().unwrap_or(ArcStop::MaxPoints);
    if crate::cancel::cancelled() {
        return Err(Error::Cancelled);
    }
    if points.is_empty() {
        return Err(Error::param(
            "event",
            format!(
                "the curve's start does not converge: {}",
                ArcStop::text(Some(&stop))
            ),
        ));
    }
    Ok(CurveHalf {
        points,
        special,
        stop: [stop.clone(), stop],
    })
}

/// A whole curve: `half` run towards decreasing, then increasing `p2` (with
/// `opts.forward` set accordingly), the halves joined by [`join_halves`].
pub fn both_halves<Pt, Sp>(
    opts: &ArcOptions,
    mut half: impl FnMut(&ArcOptions) -> Result<CurveHalf<Pt, Sp>>,
    row: impl Fn(&mut Sp) -> &mut usize,
) -> Result<CurveHalf<Pt, Sp>> {
    let mut o = opts.clone();
    o.forward = false;
    let back = half(&o)?;
    o.forward = true;
    let fwd = half(&o)?;
    let stop = [back.stop[1].clone(), fwd.stop[1].clone()];
    let (points, special) =
        join_halves((back.points, back.special), (fwd.points, fwd.special), row);
    Ok(CurveHalf {
        points,
        special,
        stop,
    })
}

/// `[F; g] = 0` as a [`Problem`] in `(x, p1)` with parameter `p2`.
pub struct Extended<T, G> {
    pub system: T,
    pub test: G,
    /// The `p2` value `param()` reports (the curve's start).
    pub p2: f64,
    /// Relative step of the test function's central differences.
    pub fd_step: f64,
}

impl<T: TwoParameter, G: TestFunction<T>> Extended<T, G> {
    pub fn new(system: T, test: G, p2: f64) -> Self {
        Extended {
            system,
            test,
            p2,
            fd_step: 1e-6,
        }
    }

    fn g(&mut self, x: &[f64], p: [f64; 2]) -> Result<f64> {
        let v = self.test.value(&mut self.system, x, p)?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(Error::param(
                "test_function",
                format!("not finite at p = ({}, {})", p[0], p[1]),
            ))
        }
    }

    /// Central difference of `g` in unknown `j` of `(x, p1)` (`j == n` is `p1`) or, with
    /// `j == n + 1`, in `p2`.
    fn g_diff(&mut self, x: &[f64], p: [f64; 2], j: usize) -> Result<f64> {
        let n = x.len();
        let mut xp = x.to_vec();
        let mut xm = x.to_vec();
        let (mut pp, mut pm) = (p, p);
        let v = match j {
            j if j < n => x[j],
            j if j == n => p[0],
            _ => p[1],
        };
        let h = self.fd_step * (1.0 + v.abs());
        match j {
            j if j < n => {
                xp[j] += h;
                xm[j] -= h;
            }
            j if j == n => {
                pp[0] += h;
                pm[0] -= h;
            }
            _ => {
                pp[1] += h;
                pm[1] -= h;
            }
        }
        Ok((self.g(&xp, pp)? - self.g(&xm, pm)?) / (2.0 * h))
    }
}

impl<T: TwoParameter, G: TestFunction<T>> Problem for Extended<T, G> {
    fn size(&self) -> usize {
        self.system.size() + 1
    }
    fn param(&self) -> f64 {
        self.p2
    }
    fn residual(&mut self, y: &[f64], p2: f64, r: &mut [f64]) -> Result<()> {
        let n = self.system.size();
        let p = [y[n], p2];
        self.system.residual(&y[..n], p, &mut r[..n])?;
        r[n] = self.g(&y[..n], p)?;
        Ok(())
    }
    fn jac_x(&mut self, y: &[f64], p2: f64, r: &mut [f64], jac: &mut [f64]) -> Result<()> {
        let n = self.system.size();
        let n1 = n + 1;
        let p = [y[n], p2];
        let mut jx = vec![0.0; n * n];
        let mut fp = vec![0.0; n];
        self.system.jac_x(&y[..n], p, &mut r[..n], &mut jx)?;
        self.system.jac_p(&y[..n], p, 0, &mut fp)?;
        for i in 0..n {
            jac[i * n1..i * n1 + n].copy_from_slice(&jx[i * n..(i + 1) * n]);
            jac[i * n1 + n] = fp[i];
        }
        r[n] = self.g(&y[..n], p)?;
        for j in 0..n1 {
            jac[n * n1 + j] = self.g_diff(&y[..n], p, j)?;
        }
        Ok(())
    }
    fn jac_p(&mut self, y: &[f64], p2: f64, out: &mut [f64]) -> Result<()> {
        let n = self.system.size();
        let p = [y[n], p2];
        self.system.jac_p(&y[..n], p, 1, &mut out[..n])?;
        out[n] = self.g_diff(&y[..n], p, n + 1)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::continuation::{ArcOptions, Arclength};

    /// `x^3 - a x + b = 0` (the cusp): folds where `3 x^2 = a`, i.e. on the curve
    /// `27 b^2 = 4 a^3`.
    struct Cusp;
    impl TwoParameter for Cusp {
        fn size(&self) -> usize {
            1
        }
        fn residual(&mut self, x: &[f64], p: [f64; 2], r: &mut [f64]) -> Result<()> {
            r[0] = x[0].powi(3) - p[0] * x[0] + p[1];
            Ok(())
        }
        fn jac_x(&mut self, x: &[f64], p: [f64; 2], r: &mut [f64], j: &mut [f64]) -> Result<()> {
            self.residual(x, p, r)?;
            j[0] = 3.0 * x[0] * x[0] - p[0];
            Ok(())
        }
    }

    #[test]
    fn fold_curve_of_the_cusp() {
        // Fold test function det F_x; start on the curve at a = 3, x = 1, b = 2.
        let ext = Extended::new(
            Cusp,
            |s: &mut Cusp, x: &[f64], p: [f64; 2]| {
                let (mut r, mut j) = ([0.0], [0.0]);
                s.jac_x(x, p, &mut r, &mut j)?;
                Ok(j[0])
            },
            2.0,
        );
        let mut ext = ext;
        let opts = ArcOptions {
            ds: 0.05,
            ds_max: 0.2,
            max_points: 30,
            p_max: 6.0,
            forward: false,
            ..Default::default()
        };
        let pts: Vec<_> = Arclength::new(&mut ext, &[1.0, 3.0], 2.0, None, opts)
            .unwrap()
            .collect();
        assert!(pts.len() > 10);
        for pt in &pts {
            let (x, a, b) = (pt.x[0], pt.x[1], pt.p);
            assert!((27.0 * b * b - 4.0 * a.powi(3)).abs() < 1e-8 * (1.0 + a.powi(3).abs()));
            assert!((3.0 * x * x - a).abs() < 1e-8);
        }
        // It passes the cusp point (a, b) = (0, 0) onto the other fold (x changes sign).
        assert!(pts.first().unwrap().x[0] > 0.0 && pts.last().unwrap().x[0] < 0.0);
    }
}
