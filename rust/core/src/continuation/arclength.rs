//! Pseudo-arclength continuation of `F(x, p) = 0` over the [`Problem`] trait: the branch
//! is followed in `y = (x, p)` rather than in `p`, so that it passes folds, where `p`
//! turns back. Each step predicts along the unit tangent `t` and corrects by Newton on
//! the bordered system
//!
//! ```text
//!   F(x, p)                 = 0
//!   t . W (y - y_pred)      = 0      (y_pred = y0 + ds t, W the weights)
//! ```
//!
//! with Jacobian `[[F_x, F_p], [W t]]`. The step length adapts to the corrector's
//! iteration count and to the angle between successive tangents (a sharp turn means
//! the step jumped, or nearly jumped, to another branch).
//!
//! Events are located by the caller, who knows what a test function is: [`point_at`]
//! corrects a point at any arclength from a branch point, and [`locate`] finds a zero
//! of a scalar test function between two consecutive points (secant on arclength,
//! Illinois-safeguarded). The bordered determinant's sign and the tangent's `p`
//! component, which every point carries, are the generic test functions of a branch
//! point and of a fold.

use crate::error::{Error, Result};
use crate::numerics::linalg::ColumnLu;
use crate::numerics::problem::Problem;
use nalgebra::DMatrix;

/// Settings of [`Arclength`].
#[derive(Debug, Clone)]
pub struct ArcOptions {
    /// First step length (in the weighted norm).
    pub ds: f64,
    pub ds_min: f64,
    pub ds_max: f64,
    /// Points to yield after the start (the start itself included as the first).
    pub max_points: usize,
    /// The parameter window: continuation stops on its edge, with a point on it.
    pub p_min: f64,
    pub p_max: f64,
    /// Newton converges when `max |F| <= tol` and the last update's largest component
    /// is below `tol.sqrt()` times the unknowns' scale.
    pub tol: f64,
    pub max_newton: usize,
    /// Step growth after a corrector that converged in at most 3 iterations.
    pub grow: f64,
    /// Smallest cosine allowed between successive tangents (weighted); a sharper turn
    /// halves the step and retries.
    pub min_cos: f64,
    /// Start towards increasing `p` (the tangent's orientation at the start).
    pub forward: bool,
    /// Weights of `(x, p)` in the arclength norm (length `size + 1`); `None` = all 1.
    pub weights: Option<Vec<f64>>,
}

impl Default for ArcOptions {
    fn default() -> Self {
        ArcOptions {
            ds: 0.01,
            ds_min: 1e-8,
            ds_max: 0.1,
            max_points: 200,
            p_min: f64::NEG_INFINITY,
            p_max: f64::INFINITY,
            tol: 1e-10,
            max_newton: 8,
            grow: 1.5,
            min_cos: 0.9,
            forward: true,
            weights: None,
        }
    }
}

impl ArcOptions {
    pub fn validate(&self) -> Result<()> {
        let pos = |name: &str, v: f64| -> Result<()> {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(Error::param(
                    name,
                    format!("must be positive and finite, got {v}"),
                ))
            }
        };
        pos("ds", self.ds)?;
        pos("ds_min", self.ds_min)?;
        pos("ds_max", self.ds_max)?;
        pos("tol", self.tol)?;
        if self.ds_min > self.ds || self.ds > self.ds_max {
            return Err(Error::param(
                "ds",
                format!(
                    "needs ds_min <= ds <= ds_max, got {} <= {} <= {}",
                    self.ds_min, self.ds, self.ds_max
                ),
            ));
        }
        if !(self.p_min < self.p_max) || self.p_min.is_nan() || self.p_max.is_nan() {
            return Err(Error::param(
                "p_range",
                format!("needs p_min < p_max, got {} .. {}", self.p_min, self.p_max),
            ));
        }
        if !(self.grow >= 1.0 && self.grow.is_finite()) {
            return Err(Error::param(
                "grow",
                format!("must be >= 1, got {}", self.grow),
            ));
        }
        if !(-1.0..1.0).contains(&self.min_cos) {
            return Err(Error::param(
                "min_cos",
                format!("must be in [-1, 1), got {}", self.min_cos),
            ));
        }
        if self.max_newton == 0 {
            return Err(Error::param("max_newton", "must be at least 1"));
        }
        Ok(())
    }
}

/// One corrected point of a branch.
#[derive(Debug, Clone)]
pub struct ArcPoint {
    pub x: Vec<f64>,
    pub p: f64,
    /// Unit tangent in `(x, p)` (weighted norm), oriented along the direction of travel.
    pub tangent: Vec<f64>,
    /// The step that reached this point (0 for the start).
    pub ds: f64,
    pub iterations: usize,
    /// `max |F|` at the point.
    pub residual: f64,
    /// Sign of `det [[F_x, F_p], [t^T]]`: it changes at a branch point (not at a fold).
    pub det_sign: f64,
}

impl ArcPoint {
    /// `dp/ds`, the tangent's parameter component: it changes sign at a fold.
    pub fn dp_ds(&self) -> f64 {
        *self.tangent.last().unwrap()
    }
}

/// Why a continuation ended.
#[derive(Debug, Clone, PartialEq)]
pub enum ArcStop {
    /// `max_points` reached.
    MaxPoints,
    /// The last point lies on the parameter window's edge.
    Boundary,
    /// The corrector failed with the step at `ds_min`.
    StepTooSmall,
    /// The caller ended it (see [`Arclength::finish`]).
    Finished(String),
    /// The problem failed to evaluate.
    Failed(String),
}

impl ArcStop {
    /// How tables report the end of a run (`None`: still running, reported as
    /// `max_points`): `"max_points"`, `"boundary"`, `"step_too_small"`, the caller's
    /// reason, or `"failed: ..."`.
    pub fn text(s: Option<&ArcStop>) -> String {
        match s {
            None | Some(ArcStop::MaxPoints) => "max_points".into(),
            Some(ArcStop::Boundary) => "boundary".into(),
            Some(ArcStop::StepTooSmall) => "step_too_small".into(),
            Some(ArcStop::Finished(w)) => w.clone(),
            Some(ArcStop::Failed(w)) => format!("failed: {w}"),
        }
    }
}

fn weights(opts: &ArcOptions, n1: usize) -> Vec<f64> {
    match &opts.weights {
        Some(w) if w.len() == n1 => w.clone(),
        _ => vec![1.0; n1],
    }
}

fn wdot(w: &[f64], a: &[f64], b: &[f64]) -> f64 {
    w.iter().zip(a).zip(b).map(|((w, a), b)| w * a * b).sum()
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(
        0.0f64,
        |m, x| if x.is_nan() { f64::NAN } else { m.max(x.abs()) },
    )
}

/// The bordered matrix `[[F_x, F_p], [row^T]]` and `F` at `y = (x, p)`; branch-point
/// tests take its determinant.
pub(crate) fn bordered<P: Problem + ?Sized>(
    problem: &mut P,
    y: &[f64],
    row: &[f64],
) -> Result<(DMatrix<f64>, Vec<f64>)> {
    let n = problem.size();
    let (x, p) = (&y[..n], y[n]);
    let mut r = vec![0.0; n];
    let mut jac = vec![0.0; n * n];
    let mut fp = vec![0.0; n];
    problem.jac_x(x, p, &mut r, &mut jac)?;
    problem.jac_p(x, p, &mut fp)?;
    let m = DMatrix::from_fn(n + 1, n + 1, |i, j| {
        if i < n {
            if j < n {
                jac[i * n + j]
            } else {
                fp[i]
            }
        } else {
            row[j]
        }
    });
    Ok((m, r))
}

/// The unit tangent at `y`: the solution of `[[F_x, F_p], [r^T]] t = e_{n+1}`,
/// normalised in the weighted norm and oriented so that `W t . orient > 0`, where `r`
/// is `W orient` (the previous tangent), or the unit `p` direction at a start. Also the
/// sign of the bordered determinant with the new tangent as its last row.
fn tangent_at<P: Problem + ?Sized>(
    problem: &mut P,
    y: &[f64],
    orient: &[f64],
    w: &[f64],
) -> Result<Option<(Vec<f64>, f64)>> {
    let n1 = y.len();
    let row: Vec<f64> = orient.iter().zip(w).map(|(o, w)| o * w).collect();
    let (m, _) = bordered(problem, y, &row)?;
    let mut rhs = vec![0.0; n1];
    rhs[n1 - 1] = 1.0;
    let Some(t) = ColumnLu::new(m.as_slice(), n1).solve(&rhs) else {
        return Ok(None);
    };
    let norm = wdot(w, &t, &t).sqrt();
    if !(norm > 0.0 && norm.is_finite()) {
        return Ok(None);
    }
    let mut t: Vec<f64> = t.iter().map(|v| v / norm).collect();
    if wdot(w, &t, orient) < 0.0 {
        t.iter_mut().for_each(|v| *v = -*v);
    }
    let mut mt = m;
    for j in 0..n1 {
        mt[(n1 - 1, j)] = w[j] * t[j];
    }
    let det = ColumnLu::new(mt.as_slice(), n1).determinant();
    Ok(Some((t, det.signum())))
}

/// Newton on the bordered system from `y_pred`, the constraint row being `W t`.
/// `None` when it does not converge within `max_newton` iterations or diverges.
fn correct<P: Problem + ?Sized>(
    problem: &mut P,
    y_pred: &[f64],
    t: &[f64],
    w: &[f64],
    opts: &ArcOptions,
) -> Result<Option<(Vec<f64>, usize, f64)>> {
    let n1 = y_pred.len();
    let n = n1 - 1;
    let row: Vec<f64> = t.iter().zip(w).map(|(t, w)| t * w).collect();
    let mut y = y_pred.to_vec();
    let scale = max_abs(y_pred).max(1.0);
    for it in 1..=opts.max_newton {
        let (m, r) = match bordered(problem, &y, &row) {
            Ok(v) => v,
            // A parameter value the model refuses ends this attempt, not the branch.
            Err(Error::InvalidParameter { .. }) => return Ok(None),
            Err(e) => return Err(e),
        };
        let mut rhs = vec![0.0; n1];
        for i in 0..n {
            rhs[i] = -r[i];
        }
        rhs[n] = -wdot(
            w,
            t,
            &y.iter().zip(y_pred).map(|(a, b)| a - b).collect::<Vec<_>>(),
        );
        let Some(dy) = ColumnLu::new(m.as_slice(), n1).solve(&rhs) else {
            // Singular exactly on a branch point: a point that already solves F stands.
            let ok = max_abs(&r) <= opts.tol && rhs[n].abs() <= opts.tol;
            return Ok(ok.then(|| (y.clone(), it - 1, max_abs(&r))));
        };
        if dy.iter().any(|v| !v.is_finite()) {
            return Ok(None);
        }
        for (yi, d) in y.iter_mut().zip(dy.iter()) {
            *yi += d;
        }
        let step = max_abs(&dy);
        let mut rr = vec![0.0; n];
        match problem.residual(&y[..n], y[n], &mut rr) {
            Ok(()) => {}
            Err(Error::InvalidParameter { .. }) => return Ok(None),
            Err(e) => return Err(e),
        }
        let res = max_abs(&rr);
        if !res.is_finite() {
            return Ok(None);
        }
        if res <= opts.tol && step <= opts.tol.sqrt() * scale {
            return Ok(Some((y, it, res)));
        }
    }
    Ok(None)
}

/// Whether `F_x` at `(x, p)` is singular to working precision (its LU's smallest pivot
/// below `1e-10` of the largest).
fn singular_at<P: Problem + ?Sized>(problem: &mut P, x: &[f64], p: f64) -> Result<bool> {
    let n = x.len();
    let (mut r, mut jac) = (vec![0.0; n], vec![0.0; n * n]);
    problem.jac_x(x, p, &mut r, &mut jac)?;
    let probe = vec![1.0; n];
    Ok(crate::linalg::lu_solve(&jac, n, &probe).is_none_or(|s| s.pivot_ratio < 1e-10))
}

/// Newton on `F(x, p_fixed) = 0` from `x0` (natural-parameter correction), for the point
/// on the parameter window's edge.
fn correct_at_p<P: Problem + ?Sized>(
    problem: &mut P,
    x0: &[f64],
    p: f64,
    opts: &ArcOptions,
) -> Result<Option<(Vec<f64>, usize, f64)>> {
    let n = x0.len();
    let mut x = x0.to_vec();
    let (mut r, mut jac) = (vec![0.0; n], vec![0.0; n * n]);
    let scale = max_abs(x0).max(1.0);
    for it in 1..=opts.max_newton {
        problem.jac_x(&x, p, &mut r, &mut jac)?;
        let neg: Vec<f64> = r.iter().map(|v| -v).collect();
        let Some(s) = crate::linalg::lu_solve(&jac, n, &neg) else {
            return Ok(None);
        };
        for (xi, d) in x.iter_mut().zip(&s.x) {
            *xi += d;
        }
        problem.residual(&x, p, &mut r)?;
        let res = max_abs(&r);
        if !res.is_finite() {
            return Ok(None);
        }
        if res <= opts.tol && max_abs(&s.x) <= opts.tol.sqrt() * scale {
            return Ok(Some((x, it, res)));
        }
    }
    Ok(None)
}

/// The point at arclength `ds` from `from` along its tangent (predictor plus bordered
/// corrector), with its own tangent; `None` if the corrector fails.
pub fn point_at<P: Problem + ?Sized>(
    problem: &mut P,
    from: &ArcPoint,
    ds: f64,
    opts: &ArcOptions,
) -> Result<Option<ArcPoint>> {
    let n1 = from.tangent.len();
    let w = weights(opts, n1);
    let y0: Vec<f64> = from.x.iter().copied().chain([from.p]).collect();
    let pred: Vec<f64> = y0
        .iter()
        .zip(&from.tangent)
        .map(|(y, t)| y + ds * t)
        .collect();
    let Some((y, iterations, residual)) = correct(problem, &pred, &from.tangent, &w, opts)? else {
        return Ok(None);
    };
    // Exactly at a branch point the bordered matrix is singular: the point is still a
    // solution, with the incoming tangent and a zero determinant.
    let (tangent, det_sign) =
        tangent_at(problem, &y, &from.tangent, &w)?.unwrap_or_else(|| (from.tangent.clone(), 0.0));
    Ok(Some(ArcPoint {
        x: y[..n1 - 1].to_vec(),
        p: y[n1 - 1],
        tangent,
        ds,
        iterations,
        residual,
        det_sign,
    }))
}

/// Component `k` of a point's `y = (x, p)` (`k = x.len()`: the parameter).
pub fn component(pt: &ArcPoint, k: usize) -> f64 {
    if k == pt.x.len() {
        pt.p
    } else {
        pt.x[k]
    }
}

/// The solution whose component `k` of `y = (x, p)` is `value`, by Newton from `near`
/// on `F = 0` bordered by `y_k = value` (for `k` the parameter's index: the corrector
/// with the parameter fixed), with its tangent oriented as `near`'s; `None` if Newton
/// fails. The constraint is linear, so it holds after the first update up to the
/// solve's round-off: `y_k` is then set to `value` itself, so that a table reads the
/// value asked for. The point keeps `near`'s `ds`.
pub fn point_on_level<P: Problem + ?Sized>(
    problem: &mut P,
    near: &ArcPoint,
    k: usize,
    value: f64,
    opts: &ArcOptions,
) -> Result<Option<ArcPoint>> {
    let n1 = near.tangent.len();
    let mut y0: Vec<f64> = near.x.iter().copied().chain([near.p]).collect();
    y0[k] = value;
    let mut row = vec![0.0; n1];
    row[k] = 1.0;
    let Some((mut y, iterations, residual)) = correct(problem, &y0, &row, &vec![1.0; n1], opts)?
    else {
        return Ok(None);
    };
    y[k] = value;
    let w = weights(opts, n1);
    let (tangent, det_sign) =
        tangent_at(problem, &y, &near.tangent, &w)?.unwrap_or_else(|| (near.tangent.clone(), 0.0));
    Ok(Some(ArcPoint {
        x: y[..n1 - 1].to_vec(),
        p: y[n1 - 1],
        tangent,
        ds: near.ds,
        iterations,
        residual,
        det_sign,
    }))
}

/// Two consecutive points `a`, `b` of a branch and a test function's values `ga`, `gb`
/// there, of opposite signs: where [`locate`] looks for its zero.
#[derive(Debug, Clone, Copy)]
pub struct Bracket<'a> {
    pub a: &'a ArcPoint,
    pub b: &'a ArcPoint,
    pub ga: f64,
    pub gb: f64,
}

/// How close [`locate`] gets: to an arclength interval of `s` or a test value of `g`.
#[derive(Debug, Clone, Copy)]
pub struct Within {
    pub s: f64,
    pub g: f64,
}

/// Locates a zero of the test function `g` inside `bracket` by the Illinois variant of
/// regula falsi on the arclength from `a`, to `|Δs| <= within.s` or `|g| <= within.g`.
/// Returns the point and its `g`, or `None` if a corrector fails.
pub fn locate<P, G>(
    problem: &mut P,
    bracket: Bracket<'_>,
    mut g: G,
    within: Within,
    opts: &ArcOptions,
) -> Result<Option<(ArcPoint, f64)>>
where
    P: Problem + ?Sized,
    G: FnMut(&mut P, &ArcPoint) -> Result<f64>,
{
    let Bracket { a, b, ga, gb } = bracket;
    let Within { s: s_tol, g: g_tol } = within;
    let (mut s0, mut g0) = (0.0, ga);
    let (mut s1, mut g1) = (b.ds, gb);
    let mut best: Option<(ArcPoint, f64)> = None;
    let mut side = 0i8;
    for _ in 0..60 {
        let s = if (g1 - g0).abs() > 0.0 {
            s1 - g1 * (s1 - s0) / (g1 - g0)
        } else {
            0.5 * (s0 + s1)
        };
        let s = if s.is_finite() && (s - s0) * (s - s1) < 0.0 {
            s
        } else {
            0.5 * (s0 + s1)
        };
        let Some(pt) = point_at(problem, a, s, opts)? else {
            return Ok(best);
        };
        let gs = g(problem, &pt)?;
        let done = gs.abs() <= g_tol || (s1 - s0).abs() <= s_tol;
        best = Some((pt, gs));
        if done || gs == 0.0 {
            break;
        }
        if gs.signum() == g1.signum() {
            (s1, g1) = (s, gs);
            if side == 1 {
                g0 *= 0.5;
            }
            side = 1;
        } else {
            (s0, g0) = (s, gs);
            if side == -1 {
                g1 *= 0.5;
            }
            side = -1;
        }
        if (s1 - s0).abs() <= s_tol {
            let pt = point_at(problem, a, 0.5 * (s0 + s1), opts)?;
            if let Some(pt) = pt {
                let gs = g(problem, &pt)?;
                best = Some((pt, gs));
            }
            break;
        }
    }
    Ok(best)
}

/// Pseudo-arclength continuation as an iterator of corrected points, starting with the
/// (corrected) start itself. After it ends, [`Arclength::stop`] says why.
pub struct Arclength<'a, P: Problem + ?Sized> {
    problem: &'a mut P,
    opts: ArcOptions,
    w: Vec<f64>,
    start: Option<(Vec<f64>, f64, Option<Vec<f64>>)>,
    last: Option<ArcPoint>,
    /// The point before `last`: where [`Arclength::subdivide`] steps again from.
    before: Option<ArcPoint>,
    ds: f64,
    stop: Option<ArcStop>,
    yielded: usize,
}

impl<'a, P: Problem + ?Sized> Arclength<'a, P> {
    /// From a solution (or a close guess) `x0` at `p0`; the initial tangent is the
    /// implicit-function direction `(dx/dp, 1)` oriented by `opts.forward`, or
    /// `direction` when given (e.g. the null vector at a branch point, to switch).
    pub fn new(
        problem: &'a mut P,
        x0: &[f64],
        p0: f64,
        direction: Option<Vec<f64>>,
        opts: ArcOptions,
    ) -> Result<Self> {
        opts.validate()?;
        let n1 = problem.size() + 1;
        if x0.len() + 1 != n1 {
            return Err(Error::param(
                "x0",
                format!("needs {} unknowns, got {}", n1 - 1, x0.len()),
            ));
        }
        if let Some(d) = &direction {
            if d.len() != n1 {
                return Err(Error::param(
                    "direction",
                    format!("needs {} components (x, p), got {}", n1, d.len()),
                ));
            }
        }
        let w = weights(&opts, n1);
        let ds = opts.ds;
        Ok(Arclength {
            problem,
            opts,
            w,
            start: Some((x0.to_vec(), p0, direction)),
            last: None,
            before: None,
            ds,
            stop: None,
            yielded: 0,
        })
    }

    pub fn stop(&self) -> Option<&ArcStop> {
        self.stop.as_ref()
    }

    pub fn problem(&mut self) -> &mut P {
        self.problem
    }

    pub fn options(&self) -> &ArcOptions {
        &self.opts
    }

    /// The caller ends the branch (e.g. at an infinite-period end), with a reason.
    pub fn finish(&mut self, why: impl Into<String>) {
        self.stop = Some(ArcStop::Finished(why.into()));
    }

    /// The caller refuses the point just yielded because its step may hide what the
    /// caller must see (e.g. a pair of events, whose test function changes sign twice):
    /// the next point is taken from the point before it with half that step. Returns
    /// `false`, changing nothing, when the step is already `ds_min` or the refused
    /// point is the start.
    pub fn subdivide(&mut self) -> bool {
        let (Some(last), Some(_)) = (&self.last, &self.before) else {
            return false;
        };
        if last.ds.abs() <= self.opts.ds_min {
            return false;
        }
        self.ds = (0.5 * last.ds.abs()).max(self.opts.ds_min);
        self.last = self.before.take();
        self.yielded -= 1;
        if self.stop == Some(ArcStop::Boundary) {
            self.stop = None;
        }
        true
    }

    fn first(
        &mut self,
        x0: Vec<f64>,
        p0: f64,
        direction: Option<Vec<f64>>,
    ) -> Result<Option<ArcPoint>> {
        let Some((x, iterations, residual)) = correct_at_p(self.problem, &x0, p0, &self.opts)?
        else {
            if singular_at(self.problem, &x0, p0)? {
                // Newton cannot converge there; say why, not only that it failed.
                self.stop = Some(ArcStop::Failed(format!(
                    "the Jacobian is singular at the start (p = {p0}): a zero eigenvalue (a \
                     fold, a branch point, or a family of equilibria); start beside it"
                )));
            }
            return Ok(None);
        };
        let n1 = x.len() + 1;
        let mut y: Vec<f64> = x.clone();
        y.push(p0);
        let orient = match direction {
            Some(d) => d,
            None => {
                let mut e = vec![0.0; n1];
                e[n1 - 1] = if self.opts.forward { 1.0 } else { -1.0 };
                e
            }
        };
        let Some((tangent, det_sign)) = tangent_at(self.problem, &y, &orient, &self.w)? else {
            return Ok(None);
        };
        Ok(Some(ArcPoint {
            x,
            p: p0,
            tangent,
            ds: 0.0,
            iterations,
            residual,
            det_sign,
        }))
    }

    fn advance(&mut self) -> Result<Option<ArcPoint>> {
        let last = self.last.clone().expect("advance after the start");
        loop {
            let ds = self.ds;
            let candidate = point_at(self.problem, &last, ds, &self.opts)?;
            let ok = candidate
                .as_ref()
                .filter(|pt| wdot(&self.w, &pt.tangent, &last.tangent) >= self.opts.min_cos);
            if let Some(pt) = ok {
                let mut pt = pt.clone();
                if pt.p > self.opts.p_max || pt.p < self.opts.p_min {
                    let edge = if pt.p > self.opts.p_max {
                        self.opts.p_max
                    } else {
                        self.opts.p_min
                    };
                    // Interpolate linearly to the edge, then correct at it.
                    let f = (edge - last.p) / (pt.p - last.p);
                    let xg: Vec<f64> = last
                        .x
                        .iter()
                        .zip(&pt.x)
                        .map(|(a, b)| a + f * (b - a))
                        .collect();
                    if let Some((x, iterations, residual)) =
                        correct_at_p(self.problem, &xg, edge, &self.opts)?
                    {
                        let mut y = x.clone();
                        y.push(edge);
                        if let Some((tangent, det_sign)) =
                            tangent_at(self.problem, &y, &last.tangent, &self.w)?
                        {
                            pt = ArcPoint {
                                x,
                                p: edge,
                                tangent,
                                ds: ds * f,
                                iterations,
                                residual,
                                det_sign,
                            };
                        }
                    }
                    self.stop = Some(ArcStop::Boundary);
                    return Ok(Some(pt));
                }
                if pt.iterations <= 3 {
                    self.ds = (self.ds * self.opts.grow).min(self.opts.ds_max);
                }
                return Ok(Some(pt));
            }
            if self.ds <= self.opts.ds_min {
                self.stop = Some(ArcStop::StepTooSmall);
                return Ok(None);
            }
            self.ds = (self.ds * 0.5).max(self.opts.ds_min);
        }
    }
}

impl<P: Problem + ?Sized> Iterator for Arclength<'_, P> {
    type Item = ArcPoint;

    fn next(&mut self) -> Option<ArcPoint> {
        if self.stop.is_some() {
            return None;
        }
        if self.yielded >= self.opts.max_points {
            self.stop = Some(ArcStop::MaxPoints);
            return None;
        }
        if crate::cancel::cancelled() {
            self.stop = Some(ArcStop::Failed("cancelled".into()));
            return None;
        }
        let out = if let Some((x0, p0, dir)) = self.start.take() {
            self.first(x0, p0, dir).inspect(|o| {
                if o.is_none() && self.stop.is_none() {
                    self.stop = Some(ArcStop::Failed("the start does not converge".into()));
                }
            })
        } else {
            self.advance()
        };
        match out {
            Ok(Some(pt)) => {
                self.before = self.last.replace(pt.clone());
                self.yielded += 1;
                Some(pt)
            }
            Ok(None) => None,
            Err(e) => {
                self.stop = Some(ArcStop::Failed(e.to_string()));
                None
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `x^2 + p^2 - 1 = 0`: a circle, two folds at p = +-1.
    struct Circle;
    impl Problem for Circle {
        fn size(&self) -> usize {
            1
        }
        fn param(&self) -> f64 {
            0.0
        }
        fn residual(&mut self, x: &[f64], p: f64, r: &mut [f64]) -> Result<()> {
            r[0] = x[0] * x[0] + p * p - 1.0;
            Ok(())
        }
        fn jac_x(&mut self, x: &[f64], p: f64, r: &mut [f64], j: &mut [f64]) -> Result<()> {
            self.residual(x, p, r)?;
            j[0] = 2.0 * x[0];
            Ok(())
        }
        fn jac_p(&mut self, _x: &[f64], p: f64, out: &mut [f64]) -> Result<()> {
            out[0] = 2.0 * p;
            Ok(())
        }
    }

    /// Pitchfork `x (p - x^2) = 0`: the trivial branch x = 0 and x = ±sqrt(p) cross at 0.
    struct Pitchfork;
    impl Problem for Pitchfork {
        fn size(&self) -> usize {
            1
        }
        fn param(&self) -> f64 {
            0.0
        }
        fn residual(&mut self, x: &[f64], p: f64, r: &mut [f64]) -> Result<()> {
            r[0] = x[0] * (p - x[0] * x[0]);
            Ok(())
        }
        fn jac_x(&mut self, x: &[f64], p: f64, r: &mut [f64], j: &mut [f64]) -> Result<()> {
            self.residual(x, p, r)?;
            j[0] = p - 3.0 * x[0] * x[0];
            Ok(())
        }
    }

    #[test]
    fn passes_the_fold_of_a_circle_and_locates_it() {
        let opts = ArcOptions {
            ds: 0.05,
            ds_max: 0.1,
            max_points: 40,
            ..Default::default()
        };
        let mut prob = Circle;
        let pts: Vec<ArcPoint> = Arclength::new(&mut prob, &[1.0], 0.0, None, opts.clone())
            .unwrap()
            .collect();
        for pt in &pts {
            assert!((pt.x[0].powi(2) + pt.p.powi(2) - 1.0).abs() < 1e-10);
        }
        // Up to p = 1 with x > 0, then back with x < 0.
        let k = pts
            .windows(2)
            .position(|w| w[0].dp_ds() * w[1].dp_ds() < 0.0)
            .unwrap();
        assert!(pts.last().unwrap().x[0] < 0.0);
        let (a, b) = (&pts[k], &pts[k + 1]);
        let mut prob = Circle;
        let bracket = Bracket {
            a,
            b,
            ga: a.dp_ds(),
            gb: b.dp_ds(),
        };
        let within = Within { s: 1e-12, g: 1e-12 };
        let (fold, g) = locate(&mut prob, bracket, |_, pt| Ok(pt.dp_ds()), within, &opts)
            .unwrap()
            .unwrap();
        assert!(g.abs() < 1e-9);
        assert!((fold.p - 1.0).abs() < 1e-12 && fold.x[0].abs() < 1e-6);
    }

    #[test]
    fn a_refused_step_is_taken_again_in_halves() {
        // On the unit circle a step ds from a point lands where the angle's sine is ds
        // (the corrector stays on the hyperplane ds along the tangent).
        let opts = ArcOptions {
            ds: 0.2,
            ds_max: 0.2,
            grow: 1.0,
            p_min: -0.5,
            p_max: 0.5,
            ..Default::default()
        };
        let mut prob = Circle;
        let mut arc = Arclength::new(&mut prob, &[1.0], 0.0, None, opts).unwrap();
        let start = arc.next().unwrap();
        assert!(!arc.subdivide(), "the start has no step to halve");
        let far = arc.next().unwrap();
        assert!(arc.subdivide());
        let near = arc.next().unwrap();
        let angle = |pt: &ArcPoint| pt.p.atan2(pt.x[0]) - start.p.atan2(start.x[0]);
        assert!(
            (angle(&far) - 0.2f64.asin()).abs() < 1e-8,
            "{}",
            angle(&far)
        );
        assert!(
            (angle(&near) - 0.1f64.asin()).abs() < 1e-8,
            "{}",
            angle(&near)
        );
        // refused at the edge: the boundary stop is lifted, the edge reached again
        let rest: Vec<ArcPoint> = arc.by_ref().collect();
        assert_eq!(rest.last().unwrap().p, 0.5);
        assert!(arc.subdivide());
        assert!(arc.stop().is_none());
        let again: Vec<ArcPoint> = arc.by_ref().collect();
        assert_eq!(again.last().unwrap().p, 0.5);
        assert_eq!(arc.stop(), Some(&ArcStop::Boundary));
    }

    #[test]
    fn stops_on_the_window_edge() {
        let opts = ArcOptions {
            ds: 0.05,
            p_min: -0.5,
            p_max: 0.5,
            ..Default::default()
        };
        let mut prob = Circle;
        let mut arc = Arclength::new(&mut prob, &[1.0], 0.0, None, opts).unwrap();
        let pts: Vec<ArcPoint> = arc.by_ref().collect();
        assert_eq!(arc.stop(), Some(&ArcStop::Boundary));
        let last = pts.last().unwrap();
        assert_eq!(last.p, 0.5);
        assert!((last.x[0] - 0.75f64.sqrt()).abs() < 1e-10);
    }

    #[test]
    fn branch_point_flips_the_bordered_determinant() {
        // Along x = 0 from p = -1: the determinant changes sign at the pitchfork p = 0.
        let opts = ArcOptions {
            ds: 0.07,
            ds_max: 0.07,
            max_points: 30,
            p_max: 1.0,
            ..Default::default()
        };
        let mut prob = Pitchfork;
        let pts: Vec<ArcPoint> = Arclength::new(&mut prob, &[0.0], -1.0, None, opts.clone())
            .unwrap()
            .collect();
        assert!(pts.iter().all(|pt| pt.x[0].abs() < 1e-12));
        let k = pts
            .windows(2)
            .position(|w| w[0].det_sign != w[1].det_sign)
            .unwrap();
        let (a, b) = (&pts[k], &pts[k + 1]);
        let mut prob = Pitchfork;
        // The test function: F_x on the branch (here p - 3 x^2).
        let bracket = Bracket {
            a,
            b,
            ga: a.p,
            gb: b.p,
        };
        let within = Within { s: 1e-13, g: 1e-13 };
        let g = |_: &mut Pitchfork, pt: &ArcPoint| Ok(pt.p - 3.0 * pt.x[0] * pt.x[0]);
        let (bp, _) = locate(&mut prob, bracket, g, within, &opts)
            .unwrap()
            .unwrap();
        assert!(bp.p.abs() < 1e-12);
        // Switching with the null direction (x) follows the parabola x^2 = p.
        let mut prob = Pitchfork;
        let pts: Vec<ArcPoint> = Arclength::new(
            &mut prob,
            &[0.05],
            0.0025,
            Some(vec![1.0, 0.0]),
            ArcOptions {
                ds: 0.02,
                max_points: 20,
                ..Default::default()
            },
        )
        .unwrap()
        .collect();
        assert!(pts.len() == 20);
        assert!(pts
            .iter()
            .all(|pt| (pt.x[0] * pt.x[0] - pt.p).abs() < 1e-9 && pt.x[0] > 0.0));
    }

    #[test]
    fn bad_options_name_the_parameter() {
        let mut prob = Circle;
        let e = Arclength::new(
            &mut prob,
            &[1.0],
            0.0,
            None,
            ArcOptions {
                ds: -1.0,
                ..Default::default()
            },
        )
        .err()
        .unwrap();
        assert!(
            matches!(e, Error::InvalidParameter { ref name, .. } if name == "ds"),
            "{e:?}"
        );
    }
}
