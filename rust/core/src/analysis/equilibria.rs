//! Equilibria of the balancer (balls at rest relative to the disk) and their stability.
//!
//! At rest `F(q, 0, 0) = 0`. For two equal balls the three families have closed forms
//! (spec section 3; seeds 001 and 003): perfect balance `x = y = 0`,
//! `b_1 = -b_2 = arccos(-1/(2 eta))`; balls together `b_1 = b_2 = b` with
//! `A sin b + Omega cos b = -2 eta Omega`, `A = (1 - Omega^2) / (2 zeta)`; balls opposite
//! `b_2 = b_1 + pi` with `A sin b + Omega cos b = 0`; for the unbalanced ones the disk
//! centre sits on the balls' line at signed distance `r = -mu Omega sin b / (2 zeta)`.
//! Any other ball set is solved numerically from many starts.

use crate::linalg::{eigenvalues, state_matrix};
use crate::model::Jacobians;
use crate::model::{Dynamics, Planar};
use crate::numerics::problem::{At, ModelAt, Problem};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    Stable,
    Unstable,
    /// Largest real part within the tolerance of zero.
    Marginal,
}

impl Verdict {
    pub fn as_str(&self) -> &'static str {
        match self {
            Verdict::Stable => "stable",
            Verdict::Unstable => "unstable",
            Verdict::Marginal => "marginal",
        }
    }
}

/// What an equilibrium is, by the balls' and the disk's configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EquilibriumKind {
    /// The disk centre at rest on the axis, the balls cancelling the unbalance.
    PerfectBalance,
    /// With ball springs: the state that continues the perfect balance.
    Balanced,
    /// Every ball at one angle.
    Together,
    /// Two balls half a turn apart.
    Opposite,
    /// One ball on the far side of the track from the disk's imbalance (`cos b < 0`): it
    /// cancels part of the imbalance, all of it only when `eta = 1` (then the state is
    /// the [`PerfectBalance`](Self::PerfectBalance)).
    PartialBalance,
    /// One ball on the imbalance's side of the track (`cos b >= 0`): it adds to it.
    ImbalanceSide,
    Unbalanced,
}

impl EquilibriumKind {
    /// The name tables and the Python API use.
    pub fn as_str(&self) -> &'static str {
        match self {
            EquilibriumKind::PerfectBalance => "perfect_balance",
            EquilibriumKind::Balanced => "balanced",
            EquilibriumKind::Together => "together",
            EquilibriumKind::Opposite => "opposite",
            EquilibriumKind::PartialBalance => "partial_balance",
            EquilibriumKind::ImbalanceSide => "imbalance_side",
            EquilibriumKind::Unbalanced => "unbalanced",
        }
    }

    /// Order of the equilibrium lists: the balanced states first.
    fn rank(&self) -> u8 {
        match self {
            EquilibriumKind::PerfectBalance | EquilibriumKind::Balanced => 0,
            EquilibriumKind::Together | EquilibriumKind::PartialBalance => 1,
            EquilibriumKind::Opposite => 2,
            EquilibriumKind::Unbalanced | EquilibriumKind::ImbalanceSide => 3,
        }
    }
}

impl std::fmt::Display for EquilibriumKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

#[derive(Debug, Clone)]
pub struct Equilibrium {
    pub kind: EquilibriumKind,
    /// `(x, y, b_1, ..., b_n)`, angles wrapped to `(-pi, pi]`.
    pub q: Vec<f64>,
    /// Max-norm of `F(q, 0, 0)`.
    pub residual: f64,
    /// Eigenvalues of the `2(n+2)` first-order Jacobian, largest real part first.
    pub eigenvalues: Vec<(f64, f64)>,
    /// Relative-stability index of [TwoBallStrength]: the largest real part (of the
    /// non-neutral eigenvalues for a perfect-balance family, n >= 3).
    pub index: f64,
    pub verdict: Verdict,
    /// Eigenvalues excluded as neutral directions of a family of equilibria.
    pub neutral: usize,
    /// Routh–Hurwitz verdict (asymptotically stable?) from the characteristic polynomial.
    pub routh_hurwitz: Option<bool>,
    /// Characteristic polynomial, monic, highest power first (`a_0 = 1, ..., a_2d`).
    pub char_poly: Vec<f64>,
    /// Whether the search that found it tried every start of its lattice (see
    /// [`start_budget`]); `false`: the budget cut the search short and other
    /// equilibria may exist. Always `true` for closed forms and single analyses.
    pub exhaustive: bool,
}

/// Tolerance on the largest real part below which the verdict is `Marginal`.
pub const EIG_TOL: f64 = 1e-9;

pub fn wrap(a: f64) -> f64 {
    let mut r = (a + PI).rem_euclid(2.0 * PI) - PI;
    if r <= -PI {
        r += 2.0 * PI;
    }
    r
}

fn static_residual<D: Dynamics + ?Sized>(p: &D, q: &[f64], out: &mut [f64]) {
    let z = vec![0.0; q.len()];
    p.residual(0.0, q, &z, &z, out);
}

/// The equilibrium problem as a [`Problem`]: `F(0, q, 0, 0) = 0` in `q`, with
/// `dF/dq = K`. For a family of equilibria (three or more free balls) `K` is singular
/// along the family; [`newton_static`] solves it in the least-squares sense, without
/// a gauge equation.
pub struct EquilibriumProblem<'a, D: Dynamics + ?Sized> {
    models: ModelAt<'a, D>,
    z: Vec<f64>,
    c: Vec<f64>,
    m: Vec<f64>,
}

impl<'a, D: Dynamics + ?Sized> EquilibriumProblem<'a, D> {
    pub fn new(models: ModelAt<'a, D>) -> Self {
        let d = models.base().ndof();
        EquilibriumProblem {
            models,
            z: vec![0.0; d],
            c: vec![0.0; d * d],
            m: vec![0.0; d * d],
        }
    }
}

impl<D: Dynamics + ?Sized> Problem for EquilibriumProblem<'_, D> {
    fn size(&self) -> usize {
        self.z.len()
    }
    fn param(&self) -> f64 {
        self.models.value()
    }
    fn residual(&mut self, x: &[f64], p: f64, r: &mut [f64]) -> crate::Result<()> {
        match self.models.at(p)? {
            At::Base(m) => static_residual(m, x, r),
            At::Varied(m) => static_residual(m, x, r),
        }
        Ok(())
    }
    fn jacobian(&mut self, x: &[f64], p: f64, jac: &mut [f64]) -> crate::Result<()> {
        let (z, c, m) = (&self.z, &mut self.c, &mut self.m);
        match self.models.at(p)? {
            At::Base(model) => model.jacobians(0.0, x, z, z, Jacobians::new(jac, c, m)),
            At::Varied(model) => model.jacobians(0.0, x, z, z, Jacobians::new(jac, c, m)),
        }
        Ok(())
    }
    fn jac_x(&mut self, x: &[f64], p: f64, r: &mut [f64], jac: &mut [f64]) -> crate::Result<()> {
        self.residual(x, p, r)?;
        self.jacobian(x, p, jac)
    }
}

/// Analyse a point known (or claimed) to be an equilibrium of the planar balancer.
pub fn analyse(p: &Planar, q: &[f64], kind: EquilibriumKind) -> Equilibrium {
    analyse_model(p, q, kind, true)
}

/// [`analyse`] for any model; `family` says whether a perfect balance of three or more
/// balls is a family of equilibria (true for free balls, not when springs tie them).
pub fn analyse_model<D: Dynamics + ?Sized>(
    p: &D,
    q: &[f64],
    kind: EquilibriumKind,
    family: bool,
) -> Equilibrium {
    let d = p.ndof();
    let mut r = vec![0.0; d];
    static_residual(p, q, &mut r);
    let residual = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let Spectrum {
        k,
        c,
        m,
        a,
        ev,
        index,
        verdict,
        neutral,
    } = spectrum(p, q, kind, family);
    let o = p.first_ball();
    // The cofactor expansion's cost depends on the matrices' zero pattern and explodes
    // past a few balls (0.2 s per equilibrium at 24 balls): beyond it, Hessenberg.
    let poly = if d <= CHAR_POLY_COFACTOR_MAX {
        char_poly(&k, &c, &m, d)
    } else {
        char_poly_hessenberg(&a, 2 * d)
    };
    let rh = if neutral == 0 {
        Some(routh_hurwitz(&poly))
    } else {
        None
    };
    Equilibrium {
        kind,
        q: q.iter()
            .enumerate()
            .map(|(i, &v)| {
                if i >= o && p.angles_modulo_turns() {
                    wrap(v)
                } else {
                    v
                }
            })
            .collect(),
        residual,
        eigenvalues: ev,
        index,
        verdict,
        neutral,
        routh_hurwitz: rh,
        char_poly: poly,
        exhaustive: true,
    }
}

/// The linearisation at an equilibrium and the verdict its eigenvalues give.
struct Spectrum {
    k: Vec<f64>,
    c: Vec<f64>,
    m: Vec<f64>,
    /// The state matrix, row-major `2d x 2d`.
    a: Vec<f64>,
    ev: Vec<(f64, f64)>,
    index: f64,
    verdict: Verdict,
    neutral: usize,
}

/// [`analyse_model`]'s linearisation and verdict, without the characteristic polynomial.
fn spectrum<D: Dynamics + ?Sized>(
    p: &D,
    q: &[f64],
    kind: EquilibriumKind,
    family: bool,
) -> Spectrum {
    let d = p.ndof();
    let z = vec![0.0; d];
    let (mut k, mut c, mut m) = (vec![0.0; d * d], vec![0.0; d * d], vec![0.0; d * d]);
    p.jacobians(0.0, q, &z, &z, Jacobians::new(&mut k, &mut c, &mut m));
    let mut a = vec![0.0; 4 * d * d];
    let mut col = vec![0.0; 2 * d * d];
    state_matrix(p, 0.0, q, &k, &c, &mut col, &mut a);
    let ev = eigenvalues(&a, 2 * d).unwrap_or_default();
    // A perfect balance with n >= 3 balls is an (n-2)-parameter family: those
    // directions have zero eigenvalues and say nothing about attraction.
    let o = p.first_ball();
    let n_balls = d - o;
    let neutral = if family && kind == EquilibriumKind::PerfectBalance && n_balls >= 3 {
        n_balls - 2
    } else {
        0
    };
    let mut by_abs: Vec<&(f64, f64)> = ev.iter().collect();
    by_abs.sort_by(|a, b| a.0.hypot(a.1).total_cmp(&b.0.hypot(b.1)));
    let judged: Vec<&(f64, f64)> = by_abs.into_iter().skip(neutral).collect();
    let index = judged.iter().map(|e| e.0).fold(f64::NEG_INFINITY, f64::max);
    let verdict = if ev.is_empty() || !index.is_finite() {
        Verdict::Marginal
    } else if index < -EIG_TOL {
        Verdict::Stable
    } else if index > EIG_TOL {
        Verdict::Unstable
    } else {
        Verdict::Marginal
    };
    Spectrum {
        k,
        c,
        m,
        a,
        ev,
        index,
        verdict,
        neutral,
    }
}

/// The verdict of the perfect balance [`equilibria`] lists for `p` (`None` where it
/// lists none), without analysing the other equilibria or expanding characteristic
/// polynomials: what a scan reports at every point. Where the equilibria have closed
/// forms, the same perfect balance [`equilibria`] would report first (its order:
/// kind, then `x`), analysed alike.
pub fn perfect_balance_verdict(p: &Planar) -> Option<Verdict> {
    let Some(found) = closed_forms(p) else {
        return perfect_balance(p).map(|e| e.verdict);
    };
    found
        .into_iter()
        .filter(|(_, k)| *k == EquilibriumKind::PerfectBalance)
        // `min_by` keeps the first of equal ones, as `sorted_analysed`'s stable sort
        .min_by(|a, b| a.0[0].total_cmp(&b.0[0]))
        .map(|(q, k)| spectrum(p, &q, k, true).verdict)
}

/// The first perfect balance [`equilibria`] lists for `p`. Where there are no closed
/// forms, from the search alone: the states off the axis that [`equilibria`] adds are
/// never perfect balances, and a scan asks this at every point.
pub fn perfect_balance(p: &Planar) -> Option<Equilibrium> {
    let all = match closed_forms(p) {
        Some(found) => sorted_analysed(p, found, true),
        None => equilibria_of(p, equal_balls(p), true),
    };
    all.into_iter()
        .find(|e| e.kind == EquilibriumKind::PerfectBalance)
}

/// Whether every equilibrium of `p` has a closed form: two equal balls, or one ball on
/// a turning disk.
pub fn has_closed_forms(p: &Planar) -> bool {
    let n = p.n_balls();
    n == 2 && equal_balls(p) || n == 1 && p.omega_s > 0.0
}

/// The closed-form equilibria of `p`, unanalysed, where [`has_closed_forms`].
fn closed_forms(p: &Planar) -> Option<Vec<(Vec<f64>, EquilibriumKind)>> {
    has_closed_forms(p).then(|| {
        if p.n_balls() == 2 {
            closed_form_two_equal(p)
        } else {
            closed_form_one(p)
        }
    })
}

/// Whether all balls have the same mass (states that differ by relabelling are one).
pub fn equal_balls(p: &Planar) -> bool {
    p.eta.windows(2).all(|w| w[0] == w[1])
}

fn classify(q: &[f64], o: usize) -> EquilibriumKind {
    // Newton's points (as opposed to closed forms) carry its tolerance.
    if q[..o].iter().all(|v| v.abs() < 1e-6) {
        return EquilibriumKind::PerfectBalance;
    }
    if q.len() == o + 1 {
        return one_ball_kind(q[o]);
    }
    if q.len() > o + 1 && q[o + 1..].iter().all(|&b| wrap(b - q[o]).abs() < 1e-7) {
        return EquilibriumKind::Together;
    }
    if q.len() == o + 2 {
        let diff = wrap(q[o] - q[o + 1]);
        if (diff.abs() - PI).abs() < 1e-7 {
            return EquilibriumKind::Opposite;
        }
    }
    EquilibriumKind::Unbalanced
}

/// The kind of a one-ball equilibrium off the axis, by the side of the track its ball
/// is on (the disk's imbalance lies at `b = 0`).
pub fn one_ball_kind(b: f64) -> EquilibriumKind {
    if b.cos() < 0.0 {
        EquilibriumKind::PartialBalance
    } else {
        EquilibriumKind::ImbalanceSide
    }
}

/// `|1 + sum eta_i exp(i b_i)|`: the imbalance the disk and balls leave together, in
/// units of the disk's own `m_d e` (0 at a perfect balance).
pub fn residual_imbalance(eta: &[f64], balls: &[f64]) -> f64 {
    let (re, im) = eta.iter().zip(balls).fold((1.0, 0.0), |(re, im), (e, b)| {
        (re + e * b.cos(), im + e * b.sin())
    });
    re.hypot(im)
}

/// The unbalanced equilibria without disk damping (`zeta = 0`) of balls that act on the
/// disk as one mass `eta_sum` (one ball, or two equal balls together). At rest the disk
/// centre is on the balls' line, `x + i y = r exp(i b)`, and `(1 - Omega^2 + 2 i zeta
/// Omega) r = mu Omega^2 (exp(-i b) + eta_sum)` with `r` real; at `zeta = 0` the
/// imaginary part leaves `(1 - Omega^2) sin b = 0`, so `b = 0` or `pi` (the damped
/// forms' limit: their `A = (1 - Omega^2) / (2 zeta)` is infinite there), and `r = mu
/// Omega^2 (cos b + eta_sum) / (1 - Omega^2)`. Returns `(x, b)` with `y = 0`. At the
/// undamped resonance `Omega = 1` the disk equation asks `exp(-i b) + eta_sum = 0`, which
/// only a perfect balance meets: none is returned.
fn undamped_on_axis(p: &Planar, eta_sum: f64) -> Vec<(f64, f64)> {
    let (om, mu) = (p.omega_s, p.mu);
    if om == 0.0 || om == 1.0 {
        return vec![];
    }
    [0.0, PI]
        .into_iter()
        .map(|b: f64| {
            let r = mu * om * om * (b.cos() + eta_sum) / (1.0 - om * om);
            (r * b.cos(), b)
        })
        .collect()
}

/// Closed-form equilibria of one ball (`Omega > 0`; `zeta = 0`: [`undamped_on_axis`]). At rest the disk centre
/// sits on the ball's line, `x + i y = r exp(i b)`, and `(1 - Omega^2 + 2 i zeta Omega)
/// r = mu Omega^2 (exp(-i b) + eta)`: `r = -mu Omega sin b / (2 zeta)` and
/// `A sin b + Omega cos b = -eta Omega`, `A = (1 - Omega^2) / (2 zeta)` (the two-ball
/// together equation with `2 eta` replaced by `eta`). Two roots where `eta Omega <=
/// sqrt(A^2 + Omega^2)`, none otherwise (a heavy ball near the resonance must move). For
/// `eta = 1` one root is `b = pi` exactly with the disk on the axis: a perfect balance.
fn closed_form_one(p: &Planar) -> Vec<(Vec<f64>, EquilibriumKind)> {
    let (eta, om, z, mu) = (p.eta[0], p.omega_s, p.zeta, p.mu);
    if z == 0.0 {
        return undamped_on_axis(p, eta)
            .into_iter()
            .map(|(x, b)| {
                if eta == 1.0 && b == PI {
                    return (vec![0.0, 0.0, PI], EquilibriumKind::PerfectBalance);
                }
                (vec![x, 0.0, b], one_ball_kind(b))
            })
            .collect();
    }
    let a = (1.0 - om * om) / (2.0 * z);
    let amp = a.hypot(om);
    let phi = om.atan2(a);
    let rhs = -eta * om / amp;
    if rhs.abs() > 1.0 {
        return vec![];
    }
    let s = rhs.asin();
    let mut roots = vec![wrap(s - phi), wrap(PI - s - phi)];
    if wrap(roots[0] - roots[1]).abs() < 1e-12 {
        roots.pop();
    }
    roots
        .into_iter()
        .map(|b| {
            if eta == 1.0 && (b.abs() - PI).abs() < 1e-9 {
                return (vec![0.0, 0.0, PI], EquilibriumKind::PerfectBalance);
            }
            let r = -mu * om * b.sin() / (2.0 * z);
            (vec![r * b.cos(), r * b.sin(), b], one_ball_kind(b))
        })
        .collect()
}

/// Closed-form equilibria of two equal balls.
fn closed_form_two_equal(p: &Planar) -> Vec<(Vec<f64>, EquilibriumKind)> {
    let eta = p.eta[0];
    let (om, z, mu) = (p.omega_s, p.zeta, p.mu);
    let mut out = vec![];
    if eta >= 0.5 {
        let b = (-1.0 / (2.0 * eta)).acos();
        out.push((vec![0.0, 0.0, b, -b], EquilibriumKind::PerfectBalance));
    }
    if om == 0.0 {
        return out;
    }
    // Unbalanced: disk centre on the balls' line, r = -mu Omega sin b / (2 zeta).
    let place = |b: f64| -> (f64, f64) {
        let r = if z > 0.0 {
            -mu * om * b.sin() / (2.0 * z)
        } else {
            f64::NAN
        };
        (r * b.cos(), r * b.sin())
    };
    if z == 0.0 {
        for (x, b) in undamped_on_axis(p, 2.0 * eta) {
            out.push((vec![x, 0.0, b, b], EquilibriumKind::Together));
        }
        // Opposite balls cancel each other: the disk alone, `x = mu Omega^2 / (1 -
        // Omega^2)`, balls on its line (b and b + pi are the same configuration).
        if om != 1.0 {
            let x = mu * om * om / (1.0 - om * om);
            out.push((vec![x, 0.0, 0.0, PI], EquilibriumKind::Opposite));
        }
    }
    if z > 0.0 {
        let a = (1.0 - om * om) / (2.0 * z);
        let amp = a.hypot(om);
        let phi = om.atan2(a);
        // together: amp sin(b + phi) = -2 eta Omega
        let rhs = -2.0 * eta * om / amp;
        if rhs.abs() <= 1.0 {
            let s = rhs.asin();
            let mut roots = vec![s - phi, PI - s - phi];
            if (roots[0] - roots[1]).abs() < 1e-12 {
                roots.pop();
            }
            for b in roots {
                let (x, y) = place(b);
                out.push((vec![x, y, b, b], EquilibriumKind::Together));
            }
        }
        // opposite: amp sin(b + phi) = 0; b and b + pi are the same configuration.
        let b = -phi;
        let (x, y) = place(b);
        out.push((vec![x, y, b, b + PI], EquilibriumKind::Opposite));
    }
    out
}

/// Newton (least squares, so that families of equilibria do not stall it) on `F(q,0,0) = 0`.
pub fn newton_static<D: Dynamics + ?Sized>(p: &D, q0: &[f64]) -> Option<Vec<f64>> {
    newton_least_squares(&mut EquilibriumProblem::new(ModelAt::fixed(p)), q0)
}

/// The least-squares Newton of [`newton_static`] on any problem, at its own parameter.
pub fn newton_least_squares<P: Problem + ?Sized>(prob: &mut P, q0: &[f64]) -> Option<Vec<f64>> {
    let d = prob.size();
    let p = prob.param();
    let mut q = q0.to_vec();
    let mut r = vec![0.0; d];
    let mut k = vec![0.0; d * d];
    // Residuals of the last iterations: a Newton that has stopped improving (a nearly
    // neutral direction cut off by the least-squares threshold) goes to the final test
    // now instead of after all 60 iterations (most of a many-ball spring search's time).
    let mut history: Vec<f64> = Vec::with_capacity(60);
    for _ in 0..60 {
        // One start of a 64-ball spring search runs up to 60 SVDs of 66 x 66 (a few
        // tenths of a second on a loaded machine): Ctrl-C is answered between them.
        if crate::cancel::cancelled() {
            return None;
        }
        prob.residual(&q, p, &mut r).ok()?;
        let rn = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if !rn.is_finite() {
            return None;
        }
        history.push(rn);
        let it = history.len();
        if it > 16 && rn < 1e-9 && history[it - 9] <= 2.0 * rn {
            break;
        }
        prob.jacobian(&q, p, &mut k).ok()?;
        // A non-finite Jacobian (a film evaluated at the wall) cannot give a step, and an
        // SVD of it need not stop: this start has failed.
        if !k.iter().all(|v| v.is_finite()) {
            return None;
        }
        let j = DMatrix::from_row_slice(d, d, &k);
        let svd = j.try_svd(
            true,
            true,
            f64::EPSILON,
            crate::numerics::linalg::SVD_MAX_ITER,
        )?;
        let rhs = DVector::from_column_slice(&r);
        let step = svd.solve(&rhs, 1e-10 * svd.singular_values.max()).ok()?;
        let sn = step.amax();
        for i in 0..d {
            q[i] -= step[i];
        }
        if rn < 1e-13 && sn < 1e-11 {
            return Some(q);
        }
    }
    prob.residual(&q, p, &mut r).ok()?;
    let rn = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    (rn < 1e-10).then_some(q)
}

fn same_equilibrium(equal: bool, o: usize, a: &[f64], b: &[f64]) -> bool {
    // Newton's points near a nearly degenerate equilibrium (weak springs) scatter by more
    // than its residual suggests: compare at that accuracy.
    if (0..o).any(|i| (a[i] - b[i]).abs() > 1e-5) {
        return false;
    }
    let n = a.len() - o;
    let direct = (0..n).all(|i| wrap(a[o + i] - b[o + i]).abs() < 1e-4);
    if direct {
        return true;
    }
    if equal {
        // Identical balls: the same physical state up to relabelling.
        let mut sa: Vec<f64> = a[o..].iter().map(|&v| wrap(v)).collect();
        let mut sb: Vec<f64> = b[o..].iter().map(|&v| wrap(v)).collect();
        sa.sort_by(f64::total_cmp);
        sb.sort_by(f64::total_cmp);
        return sa.iter().zip(&sb).all(|(u, v)| wrap(u - v).abs() < 1e-4);
    }
    false
}

/// All equilibria found for the balancer, each analysed. Closed forms for two equal
/// balls; otherwise Newton from a deterministic set of starts.
pub fn equilibria(p: &Planar) -> Vec<Equilibrium> {
    if let Some(found) = closed_forms(p) {
        return sorted_analysed(p, found, true);
    }
    let equal = equal_balls(p);
    let mut out = equilibria_of(p, equal, true);
    // The search's Newton misses most states with the balls on one line (two unequal
    // balls at Omega 1.2, zeta 0.05: none of the four); their closed forms add them.
    let missed: Vec<_> = on_one_line(p)
        .into_iter()
        .filter(|(q, _)| !out.iter().any(|e| same_equilibrium(equal, 2, &e.q, q)))
        .fold(vec![], |mut kept: Vec<(Vec<f64>, EquilibriumKind)>, s| {
            if !kept
                .iter()
                .any(|(k, _)| same_equilibrium(equal, 2, k, &s.0))
            {
                kept.push(s);
            }
            kept
        });
    if !missed.is_empty() {
        let exhaustive = out.first().is_none_or(|e| e.exhaustive);
        out.extend(sorted_analysed(p, missed, true));
        out.iter_mut().for_each(|e| e.exhaustive = exhaustive);
        // `sorted_analysed`'s order (kind, then x), stable for the searched ones.
        out.sort_by(|a, b| {
            a.kind
                .rank()
                .cmp(&b.kind.rank())
                .then(a.q[0].total_cmp(&b.q[0]))
        });
    }
    out
}

/// Most balls whose line states [`on_one_line`] enumerates (`2^(n-1)` sign patterns).
pub const LINE_STATES_MAX_BALLS: usize = 10;

/// Every unbalanced equilibrium of the planar balancer, in closed form. At rest each
/// ball's equation asks the disk centre to lie on the ball's line (`Im(w e^(-i b_i)) =
/// 0`, `w = x + i y`), so with `w != 0` every ball sits at `b` or `b + pi`: a sign
/// pattern `s_i = +-1` (`s_1 = +1`; `(b, s)` and `(b + pi, -s)` are one state) makes the
/// balls act as one mass `eta_s = sum s_i eta_i`, and the disk's equation
/// `(1 - Omega^2 + 2 i zeta Omega) r = mu Omega^2 (exp(-i b) + eta_s)` with `r` real
/// gives `(1 - Omega^2) sin b + 2 zeta Omega cos b = -2 zeta Omega eta_s`: up to two `b`
/// per pattern, `r` from the real part. States with `w = 0` (perfect balances) are the search's.
/// Empty above [`LINE_STATES_MAX_BALLS`] balls and where the disk equation is singular
/// (`Omega = 0`; `zeta = 0` at `Omega = 1`).
fn on_one_line(p: &Planar) -> Vec<(Vec<f64>, EquilibriumKind)> {
    let n = p.n_balls();
    let (om, z, mu) = (p.omega_s, p.zeta, p.mu);
    let (a, c) = (1.0 - om * om, 2.0 * z * om);
    let amp2 = a * a + c * c;
    if n > LINE_STATES_MAX_BALLS || om == 0.0 || amp2 == 0.0 {
        return vec![];
    }
    let (amp, phi) = (amp2.sqrt(), c.atan2(a));
    let mut out = vec![];
    for pattern in 0..1usize << (n - 1) {
        let flipped = |i: usize| i > 0 && pattern >> (i - 1) & 1 == 1;
        let eta_s: f64 = (0..n)
            .map(|i| if flipped(i) { -p.eta[i] } else { p.eta[i] })
            .sum();
        let rhs = -c * eta_s / amp;
        if rhs.abs() > 1.0 {
            continue;
        }
        let s = rhs.asin();
        for b in [s - phi, PI - s - phi] {
            let r = mu * om * om * ((b.cos() + eta_s) * a - b.sin() * c) / amp2;
            if r.abs() < 1e-9 {
                continue;
            }
            let mut q = vec![r * b.cos(), r * b.sin()];
            q.extend((0..n).map(|i| wrap(if flipped(i) { b + PI } else { b })));
            let kind = classify(&q, 2);
            out.push((q, kind));
        }
    }
    out
}

/// All equilibria of any autonomous model, by Newton from a deterministic set of starts
/// (see [`starts`]). `equal`: the balls are identical (states that differ by relabelling
/// are one); `family`: see [`analyse_model`]. With `family`, the perfect balances of three
/// or more balls are one `(n - 2)`-parameter family: every start would land on another
/// point of it, so it is reported once, by the first point found (`neutral > 0`).
pub fn equilibria_of<D: Dynamics + ?Sized>(p: &D, equal: bool, family: bool) -> Vec<Equilibrium> {
    let mut found: Vec<(Vec<f64>, EquilibriumKind)> = vec![];
    let o = p.first_ball();
    let n = p.ndof() - o;
    let one_family = family && n >= 3;
    let (starts, exhaustive) = starts(n, o);
    for q0 in starts {
        if crate::cancel::cancelled() {
            break;
        }
        if let Some(q) = newton_static(p, &q0) {
            let kind = classify(&q, o);
            if one_family && kind == EquilibriumKind::PerfectBalance {
                if found
                    .iter()
                    .any(|(_, k)| *k == EquilibriumKind::PerfectBalance)
                {
                    continue;
                }
            } else if found.iter().any(|(f, _)| same_equilibrium(equal, o, f, &q)) {
                continue;
            }
            found.push((q, kind));
        }
    }
    let mut out = sorted_analysed(p, found, family);
    out.iter_mut().for_each(|e| e.exhaustive = exhaustive);
    out
}

/// Equilibria of a model whose ball angles count turns (a ring of ball springs), found
/// by Newton from starts with the balls in track order, `b_1 <= ... <= b_n <= b_1 + 2 pi`,
/// and kept only if they stay so: balls cannot pass each other, and a ball moved by a
/// whole turn alone is another winding of the springs, not the same state. States that
/// differ by a common turn of every ball are one (reported with `b_1` in `(-pi, pi]`), as
/// are, for identical balls, states that differ by a cyclic relabelling round the ring.
/// `extra`: further starts (e.g. a known equilibrium). Unanalysed, with kinds from their
/// shape; see [`analyse_all`].
pub fn equilibria_in_track_order<D: Dynamics + ?Sized>(
    p: &D,
    equal: bool,
    extra: &[Vec<f64>],
) -> Vec<(Vec<f64>, EquilibriumKind)> {
    let o = p.first_ball();
    let n = p.ndof() - o;
    let mut found: Vec<(Vec<f64>, EquilibriumKind)> = vec![];
    for q0 in extra.iter().cloned().chain(ordered_starts(n, o)) {
        if crate::cancel::cancelled() {
            break;
        }
        let Some(mut q) = newton_static(p, &q0) else {
            continue;
        };
        // Identical balls near their springs' rest spacing form a nearly neutral ring:
        // Newton stops anywhere along it with a small residual. Only points that satisfy
        // the equations to round-off are equilibria.
        let mut r = vec![0.0; q.len()];
        static_residual(p, &q, &mut r);
        if r.iter().any(|v| v.abs() > 1e-12) {
            continue;
        }
        let in_order = (0..n).all(|i| {
            let next = if i + 1 < n {
                q[o + i + 1]
            } else {
                q[o] + 2.0 * PI
            };
            next - q[o + i] >= -1e-9
        });
        if !in_order {
            continue;
        }
        let turn = q[o] - wrap(q[o]);
        q[o..].iter_mut().for_each(|b| *b -= turn);
        if !found.iter().any(|(f, _)| same_in_order(equal, o, f, &q)) {
            let kind = classify(&q, o);
            found.push((q, kind));
        }
    }
    found
}

/// Most starts of the track-order search.
const ORDERED_STARTS_MAX: usize = 600;

/// Starts in track order: the first ball at `per` angles, the others at increasing
/// offsets from it drawn from a lattice of `m` points on `(0, 2 pi)`.
fn ordered_starts(n: usize, o: usize) -> Vec<Vec<f64>> {
    let (per, m) = match n {
        1 => (24, 1),
        2 => (12, 12),
        3 => (6, 10),
        4 => (4, 8),
        _ => (2, n + 3),
    };
    // Offsets: increasing (n - 1)-subsets of the lattice, in lexicographic order, only
    // as many as can be used (all C(n + 3, n - 1) of them were built before the cap:
    // 20 million vectors and 45 s for 24 balls).
    let lattice: Vec<f64> = (0..m)
        .map(|k| 2.0 * PI * (k as f64 + 0.37) / m as f64)
        .collect();
    let k = n - 1;
    let mut subsets: Vec<Vec<usize>> = vec![];
    let mut c: Vec<usize> = (0..k).collect();
    if k <= m {
        loop {
            subsets.push(c.clone());
            if subsets.len() >= ORDERED_STARTS_MAX {
                break;
            }
            // next combination: the rightmost entry that can grow, and the rest after it
            let Some(i) = (0..k).rev().find(|&i| c[i] < m - k + i) else {
                break;
            };
            c[i] += 1;
            for j in i + 1..k {
                c[j] = c[j - 1] + 1;
            }
        }
    }
    let mut out = vec![];
    'outer: for i in 0..per {
        let b1 = -PI + (i as f64 + 0.1) * 2.0 * PI / per as f64;
        for s in &subsets {
            if out.len() >= ORDERED_STARTS_MAX {
                break 'outer;
            }
            let mut q = vec![0.0; o + n];
            q[o] = b1;
            for (j, &k) in s.iter().enumerate() {
                q[o + 1 + j] = b1 + lattice[k];
            }
            out.push(q);
        }
    }
    out
}

/// Whether two track-ordered states are one: equal up to a common whole turn of every
/// ball, and for identical balls up to a cyclic relabelling.
fn same_in_order(equal: bool, o: usize, a: &[f64], b: &[f64]) -> bool {
    if (0..o).any(|i| (a[i] - b[i]).abs() > 1e-5) {
        return false;
    }
    let n = a.len() - o;
    let shifts = if equal { n } else { 1 };
    (0..shifts).any(|r| {
        // b relabelled: ball i is b's ball i + r, a turn further on past the ring's end
        let bb = |i: usize| {
            let j = i + r;
            if j < n {
                b[o + j]
            } else {
                b[o + j - n] + 2.0 * PI
            }
        };
        let d0 = a[o] - bb(0);
        let turn = d0 - wrap(d0);
        (0..n).all(|i| (a[o + i] - bb(i) - turn).abs() < 1e-4)
    })
}

/// Analyses found equilibria and orders them by kind and `x`.
pub fn analyse_all<D: Dynamics + ?Sized>(
    p: &D,
    found: Vec<(Vec<f64>, EquilibriumKind)>,
    family: bool,
) -> Vec<Equilibrium> {
    sorted_analysed(p, found, family)
}

fn sorted_analysed<D: Dynamics + ?Sized>(
    p: &D,
    mut found: Vec<(Vec<f64>, EquilibriumKind)>,
    family: bool,
) -> Vec<Equilibrium> {
    found.sort_by(|a, b| a.1.rank().cmp(&b.1.rank()).then(a.0[0].total_cmp(&b.0[0])));
    found
        .iter()
        .map(|(q, k)| analyse_model(p, q, *k, family))
        .collect()
}

/// Most starts of the lattice search before it is cut to [`start_budget`].
const LATTICE_MAX: u64 = 600;

/// Newton starts of the equilibrium search for `n` balls: from three balls on, every
/// ball together at 24 angles; then the whole lattice of `per^n` ball angles while it has
/// at most [`LATTICE_MAX`] points (n <= 4: 24, 144, 216, 256 starts), or else up to
/// [`start_budget`] starts in all from a low-discrepancy (Kronecker) sequence over the torus of ball angles, so that
/// every ball varies (a prefix of the lattice would move only the first few). Returns the
/// starts and whether they are the whole lattice.
fn starts(n: usize, o: usize) -> (Vec<Vec<f64>>, bool) {
    let per: u64 = match n {
        1 => 24,
        2 => 12,
        3 => 6,
        _ => 4,
    };
    // 4^32 overflowed a u64 to 0 starts: equilibria() was empty from 32 balls on.
    let lattice = u32::try_from(n)
        .ok()
        .and_then(|e| per.checked_pow(e))
        .filter(|&t| t <= LATTICE_MAX);
    // All balls together at 24 angles: the together states, which the lattice of
    // three or four balls misses (its points keep the balls apart).
    let mut out = vec![];
    if n >= 3 {
        for k in 0..24 {
            let mut q = vec![0.0; n + o];
            let b = -PI + (k as f64 + 0.1) * 2.0 * PI / 24.0;
            q[o..].iter_mut().for_each(|v| *v = b);
            out.push(q);
        }
    }
    if let Some(total) = lattice {
        let per = per as usize;
        for idx in 0..total as usize {
            let mut q = vec![0.0; n + o];
            let mut rem = idx;
            for i in 0..n {
                // Offset so that no start sits exactly on a symmetric (singular) point.
                q[o + i] = -PI + (rem % per) as f64 * 2.0 * PI / per as f64 + 0.1 + 0.01 * i as f64;
                rem /= per;
            }
            out.push(q);
        }
        return (out, true);
    }
    let budget = start_budget(n);
    // Roberts' R_n sequence: alpha_i = g^-(i+1), g the root of g^(n+1) = g + 1.
    let mut g = 2.0f64;
    for _ in 0..60 {
        g = (1.0 + g).powf(1.0 / (n as f64 + 1.0));
    }
    let alpha: Vec<f64> = (0..n).map(|i| g.powi(-(i as i32 + 1))).collect();
    for k in 1..=budget.saturating_sub(out.len()) {
        let mut q = vec![0.0; n + o];
        for i in 0..n {
            q[o + i] = -PI + 2.0 * PI * (0.5 + k as f64 * alpha[i]).fract();
        }
        out.push(q);
    }
    (out, false)
}

/// Newton starts the equilibrium search tries for `n` balls when the lattice is too
/// large (n >= 5): `max(600, 25 n)`, so that the search stays within seconds (each start
/// costs one least-squares Newton solve, O(n^3)) while growing with the number of balls.
pub fn start_budget(n: usize) -> usize {
    600usize.max(25 * n)
}

/// Whether [`equilibria`] tries every start of its lattice for `n` balls (n <= 4).
pub fn search_is_exhaustive(n: usize) -> bool {
    starts(n, 0).1
}

// ---------- characteristic polynomial and Routh–Hurwitz ----------

type Poly = Vec<f64>; // ascending powers

fn pmul(a: &Poly, b: &Poly) -> Poly {
    if a.is_empty() || b.is_empty() {
        return vec![];
    }
    let mut r = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            r[i + j] += x * y;
        }
    }
    r
}

fn padd(a: &mut Poly, b: &Poly, sign: f64) {
    if a.len() < b.len() {
        a.resize(b.len(), 0.0);
    }
    for (i, y) in b.iter().enumerate() {
        a[i] += sign * y;
    }
}

fn pdet(m: &[Poly], rows: &[usize], cols: &[usize], d: usize) -> Poly {
    if rows.len() == 1 {
        return m[rows[0] * d + cols[0]].clone();
    }
    let r = rows[0];
    let rest: Vec<usize> = rows[1..].to_vec();
    let mut acc: Poly = vec![0.0];
    for (ci, &c) in cols.iter().enumerate() {
        let e = &m[r * d + c];
        if e.iter().all(|v| *v == 0.0) {
            continue;
        }
        let sub: Vec<usize> = cols.iter().copied().filter(|&x| x != c).collect();
        let minor = pdet(m, &rest, &sub, d);
        let term = pmul(e, &minor);
        padd(&mut acc, &term, if ci % 2 == 0 { 1.0 } else { -1.0 });
    }
    acc
}

/// `det(s^2 M + s C + K)` by cofactor expansion of the polynomial matrix, made monic,
/// returned highest power first. Independent of the eigenvalue route.
pub fn char_poly(k: &[f64], c: &[f64], m: &[f64], d: usize) -> Vec<f64> {
    let entries: Vec<Poly> = (0..d * d).map(|i| vec![k[i], c[i], m[i]]).collect();
    let idx: Vec<usize> = (0..d).collect();
    let mut p = pdet(&entries, &idx, &idx, d);
    p.resize(2 * d + 1, 0.0);
    let lead = p[2 * d];
    p.iter_mut().for_each(|v| *v /= lead);
    p.reverse();
    p
}

/// Largest `d` (coordinates) whose characteristic polynomial is expanded by cofactors.
const CHAR_POLY_COFACTOR_MAX: usize = 8;

/// Characteristic polynomial `det(s I - A)` of the row-major `n x n` matrix `a`, highest
/// power first, in O(n^3): Householder reduction to Hessenberg form `H` (similar to `A`),
/// then the recurrence on its leading minors `p_k(s) = (s - h_kk) p_{k-1}(s) -
/// sum_{i<k} h_ik (h_{i+1,i} ... h_{k,k-1}) p_{i-1}(s)`. Independent of the eigenvalues'
/// QR iteration. For the balancer `det(s^2 M + s C + K) = det M det(s I - A)`.
pub fn char_poly_hessenberg(a: &[f64], n: usize) -> Vec<f64> {
    let h = DMatrix::from_row_slice(n, n, a).hessenberg().h();
    // p[k]: ascending coefficients of the k-th leading minor's polynomial.
    let mut p: Vec<Vec<f64>> = vec![vec![1.0]];
    for k in 0..n {
        let prev = &p[k];
        let mut next = vec![0.0; k + 2];
        for (j, &c) in prev.iter().enumerate() {
            next[j + 1] += c;
            next[j] -= h[(k, k)] * c;
        }
        let mut prod = 1.0;
        for i in (0..k).rev() {
            prod *= h[(i + 1, i)];
            let f = h[(i, k)] * prod;
            if f != 0.0 {
                for (j, &c) in p[i].iter().enumerate() {
                    next[j] -= f * c;
                }
            }
        }
        p.push(next);
    }
    let mut out = p.pop().unwrap_or_default();
    out.reverse();
    out
}

/// Routh–Hurwitz: all roots in the open left half-plane iff every entry of the Routh
/// array's first column is positive (for a monic polynomial). A zero entry means a
/// root on or symmetric about the imaginary axis: not asymptotically stable.
pub fn routh_hurwitz(a: &[f64]) -> bool {
    let deg = a.len() - 1;
    if a.iter().any(|v| !(*v > 0.0)) {
        return false;
    }
    let width = deg / 2 + 1;
    let mut prev: Vec<f64> = (0..width)
        .map(|i| a.get(2 * i).copied().unwrap_or(0.0))
        .collect();
    let mut cur: Vec<f64> = (0..width)
        .map(|i| a.get(2 * i + 1).copied().unwrap_or(0.0))
        .collect();
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for _ in 0..deg.saturating_sub(1) {
        if !(cur[0] > 1e-14 * scale) {
            return false;
        }
        let mut next = vec![0.0; width];
        for i in 0..width - 1 {
            next[i] = (cur[0] * prev[i + 1] - prev[0] * cur[i + 1]) / cur[0];
        }
        prev = cur;
        cur = next;
    }
    cur[0] > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two(om: f64, eta: f64) -> Planar {
        Planar::new(0.2, 0.05, &[0.1], 50.0, om, &[eta, eta]).unwrap()
    }

    #[test]
    fn closed_forms_are_equilibria_and_numeric_path_finds_them() {
        let p = two(1.3, 0.8);
        let eqs = equilibria(&p);
        assert_eq!(eqs[0].kind, EquilibriumKind::PerfectBalance);
        for e in &eqs {
            assert!(e.residual < 1e-13, "{} residual {}", e.kind, e.residual);
        }
        // Numeric multistart on the same balancer (bypassing the closed forms).
        for q0 in starts(p.n_balls(), 2).0 {
            if let Some(q) = newton_static(&p, &q0) {
                assert!(
                    eqs.iter().any(|e| same_equilibrium(true, 2, &e.q, &q)),
                    "numeric equilibrium {q:?} missing from closed forms"
                );
            }
        }
    }

    /// Unequal balls: the states with every ball on the disk's line, which the search
    /// missed (none of four at Omega 1.2, zeta 0.05), are listed; each is an equilibrium;
    /// the list holds no state twice and still holds everything the search finds.
    #[test]
    fn unequal_balls_on_one_line_are_listed() {
        for (etas, zeta, om, unbalanced) in [
            (vec![0.8, 1.0], 0.05, 1.2, 4),
            (vec![0.8, 1.0], 0.05, 0.8, 4),
            (vec![0.8, 1.0], 0.0, 2.0, 4),
            (vec![0.5, 0.6, 0.7], 0.05, 1.2, 8),
        ] {
            let p = Planar::new(0.2, zeta, &[0.05], 50.0, om, &etas).unwrap();
            let eqs = equilibria(&p);
            let off: Vec<_> = eqs
                .iter()
                .filter(|e| e.kind != EquilibriumKind::PerfectBalance)
                .collect();
            assert_eq!(off.len(), unbalanced, "{etas:?} {zeta} {om}");
            for e in &eqs {
                assert!(e.residual < 1e-12, "{} residual {}", e.kind, e.residual);
            }
            for (i, a) in eqs.iter().enumerate() {
                for b in &eqs[i + 1..] {
                    assert!(!same_equilibrium(false, 2, &a.q, &b.q), "{:?} twice", a.q);
                }
            }
            for s in equilibria_of(&p, false, true) {
                assert!(eqs.iter().any(|e| same_equilibrium(false, 2, &e.q, &s.q)));
            }
        }
    }

    /// Without disk damping the equilibria are the damped closed forms' limit: at
    /// `zeta = 0` the list had only the perfect balance (the search's Newton stalls
    /// there), at `zeta = 1e-9` all four. Each undamped one is an equilibrium (its
    /// residual), the same states as at `zeta = 1e-10` (to that `zeta`'s effect), of the
    /// same kinds, for one ball and two equal balls, below and above the resonance.
    #[test]
    fn undamped_equilibria_are_the_damped_ones_limit() {
        for om in [0.6, 1.2, 2.5] {
            for (etas, kinds) in [(vec![0.8, 0.8], 4), (vec![0.54], 2), (vec![1.0], 2)] {
                let at = |z: f64| Planar::new(0.2, z, &[0.05], 50.0, om, &etas).unwrap();
                let (undamped, damped) = (equilibria(&at(0.0)), equilibria(&at(1e-10)));
                assert_eq!(undamped.len(), kinds, "{om} {etas:?}");
                assert_eq!(damped.len(), kinds, "{om} {etas:?}");
                for e in &undamped {
                    assert!(e.residual < 1e-13, "{} residual {}", e.kind, e.residual);
                    // The same disk position and the same set of ball positions on
                    // the track (equal balls: in any order, angles modulo 2 pi).
                    let same = |d: &&Equilibrium| {
                        d.kind == e.kind
                            && (d.q[0] - e.q[0]).abs() < 1e-6
                            && (d.q[1] - e.q[1]).abs() < 1e-6
                            && e.q[2..]
                                .iter()
                                .all(|a| d.q[2..].iter().any(|b| wrap(a - b).abs() < 1e-6))
                    };
                    assert!(
                        damped.iter().any(|d| same(&d)),
                        "{om} {etas:?}: {} {:?} not in {:?}",
                        e.kind,
                        e.q,
                        damped.iter().map(|d| &d.q).collect::<Vec<_>>()
                    );
                }
            }
        }
        // At the undamped resonance only a perfect balance can rest.
        let p = Planar::new(0.2, 0.0, &[0.05], 50.0, 1.0, &[0.8, 0.8]).unwrap();
        let eqs = equilibria(&p);
        assert!(eqs
            .iter()
            .all(|e| e.kind == EquilibriumKind::PerfectBalance));
    }

    #[test]
    fn equilibrium_problem_jacobians_and_the_balance_angles_slope() {
        use crate::numerics::problem::tangent;
        // dF/dq against central differences, at an arbitrary point of three unequal balls.
        let p3 = Planar::new(0.2, 0.05, &[0.1], 50.0, 1.4, &[0.4, 0.6, 0.5]).unwrap();
        let mut prob = EquilibriumProblem::new(ModelAt::family_of(&p3, "Omega").unwrap());
        let q = [0.01, -0.02, 0.3, 2.0, -2.5];
        let n = prob.size();
        let (mut r, mut jac) = (vec![0.0; n], vec![0.0; n * n]);
        prob.jac_x(&q, 1.4, &mut r, &mut jac).unwrap();
        let h = 1e-6;
        let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
        for col in 0..n {
            let mut qp = q.to_vec();
            qp[col] += h;
            prob.residual(&qp, 1.4, &mut rp).unwrap();
            qp[col] -= 2.0 * h;
            prob.residual(&qp, 1.4, &mut rm).unwrap();
            for row in 0..n {
                let fd = (rp[row] - rm[row]) / (2.0 * h);
                assert!((fd - jac[row * n + col]).abs() < 1e-6, "({row},{col})");
            }
        }
        // The perfect balance of two equal balls, b = arccos(-1 / (2 eta)): its slope in
        // eta from the implicit-function theorem (dF/deta by the default difference)
        // against the closed form's derivative.
        let eta = 0.8;
        let p2 = two(1.3, eta);
        let pb = equilibria(&p2)
            .into_iter()
            .find(|e| e.kind == EquilibriumKind::PerfectBalance)
            .unwrap();
        let mut prob = EquilibriumProblem::new(ModelAt::family(&p2, "eta", eta));
        let t = tangent(&mut prob, &pb.q, eta)
            .unwrap()
            .expect("isolated equilibrium");
        let db = -(1.0 / (2.0 * eta * eta)) / (1.0 - 1.0 / (4.0 * eta * eta)).sqrt();
        assert!(t[0].abs() < 1e-7 && t[1].abs() < 1e-7, "{t:?}");
        assert!(
            (t[2] - db).abs() < 1e-6 && (t[3] + db).abs() < 1e-6,
            "{t:?} vs {db}"
        );
        // newton_static goes through the problem: it lands on the closed form.
        let q = newton_static(&p2, &[0.01, 0.0, pb.q[2] + 0.1, pb.q[3] - 0.1]).unwrap();
        assert!(
            q.iter().zip(&pb.q).all(|(a, b)| (a - b).abs() < 1e-10),
            "{q:?}"
        );
    }

    fn one(om: f64, eta: f64) -> Planar {
        Planar::new(0.2, 0.05, &[0.05], 50.0, om, &[eta]).unwrap()
    }

    /// One ball: the closed forms are equilibria, Newton from every start of the lattice
    /// finds no other, each is named by the side of the track its ball is on, and with
    /// `eta = 1` the ball opposite the imbalance balances the disk exactly.
    #[test]
    fn one_ball_closed_forms_kinds_and_perfect_balance() {
        let mut seen: Vec<EquilibriumKind> = vec![];
        for (om, eta) in [
            (0.8, 0.54),
            (1.5, 0.54),
            (1.5, 0.99),
            (1.2, 1.85),
            (1.5, 1.0),
        ] {
            let p = one(om, eta);
            let eqs = equilibria(&p);
            assert!(
                !eqs.is_empty() && eqs.len() <= 2,
                "{om} {eta}: {}",
                eqs.len()
            );
            for e in &eqs {
                assert!(e.residual < 1e-13, "{} residual {}", e.kind, e.residual);
                if !seen.contains(&e.kind) {
                    seen.push(e.kind);
                }
                let b = e.q[2];
                match e.kind {
                    EquilibriumKind::PerfectBalance => {
                        assert_eq!(eta, 1.0);
                        assert!(e.q[0] == 0.0 && e.q[1] == 0.0 && b.cos() == -1.0);
                        assert!(residual_imbalance(&p.eta, &e.q[2..]) < 1e-15);
                    }
                    EquilibriumKind::PartialBalance => assert!(b.cos() < 0.0),
                    EquilibriumKind::ImbalanceSide => assert!(b.cos() >= 0.0),
                    k => panic!("kind {k} for one ball"),
                }
            }
            for q0 in starts(1, 2).0 {
                if let Some(q) = newton_static(&p, &q0) {
                    assert!(
                        eqs.iter().any(|e| same_equilibrium(false, 2, &e.q, &q)),
                        "{om} {eta}: numeric equilibrium {q:?} missing from closed forms"
                    );
                }
            }
        }
        assert_eq!(seen.len(), 3);
        // Near the resonance a ball heavier than the imbalance has nowhere to rest:
        // eta Omega > sqrt(A^2 + Omega^2), and Newton agrees.
        let p = one(1.0, 1.85);
        assert!(equilibria(&p).is_empty());
        assert!(starts(1, 2)
            .0
            .iter()
            .all(|q0| newton_static(&p, q0).is_none()));
    }

    #[test]
    fn residual_imbalance_closed_form() {
        // a ball straight opposite leaves |1 - eta|, on the imbalance 1 + eta
        assert!((residual_imbalance(&[0.54], &[PI]) - 0.46).abs() < 1e-15);
        assert!((residual_imbalance(&[1.85], &[0.0]) - 2.85).abs() < 1e-15);
        // two equal balls at the perfect balance's angles cancel it
        let b = (-1.0 / (2.0 * 0.8f64)).acos();
        assert!(residual_imbalance(&[0.8, 0.8], &[b, -b]) < 1e-15);
        // at right angles: sqrt((1 + 0)^2 + eta^2)
        assert!((residual_imbalance(&[0.75], &[PI / 2.0]) - 1.25).abs() < 1e-15);
    }

    #[test]
    fn perfect_balance_needs_eta_half() {
        assert!(equilibria(&two(1.5, 0.49))
            .iter()
            .all(|e| e.kind != EquilibriumKind::PerfectBalance));
        assert!(equilibria(&two(1.5, 0.51))
            .iter()
            .any(|e| e.kind == EquilibriumKind::PerfectBalance));
    }

    #[test]
    fn routh_hurwitz_simple() {
        assert!(routh_hurwitz(&[1.0, 3.0, 3.0, 1.0])); // (s+1)^3
        assert!(!routh_hurwitz(&[1.0, -1.0, 2.0])); // RHP roots
        assert!(!routh_hurwitz(&[1.0, 0.0, 1.0])); // +-i
        assert!(!routh_hurwitz(&[1.0, 1.0, 1.0, 1.0])); // (s+1)(s^2+1)
    }

    #[test]
    fn routh_hurwitz_agrees_with_eigenvalues_on_grid() {
        let mut checked = 0;
        for i in 0..26 {
            for j in 0..11 {
                let om = 0.5 + 0.1 * i as f64;
                let eta = 0.5 + 0.1 * j as f64;
                let p = two(om, eta);
                for e in equilibria(&p) {
                    if e.index.abs() > 1e-6 {
                        assert_eq!(
                            e.routh_hurwitz.unwrap(),
                            e.verdict == Verdict::Stable,
                            "Omega {om} eta {eta} {}",
                            e.kind
                        );
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 500);
    }

    #[test]
    fn three_balls_perfect_balance_family() {
        let p = Planar::new(0.2, 0.05, &[0.1], 50.0, 1.5, &[0.6, 0.6, 0.6]).unwrap();
        let eqs = equilibria(&p);
        let pb = eqs
            .iter()
            .find(|e| e.kind == EquilibriumKind::PerfectBalance)
            .expect("perfect balance");
        assert!(pb.residual < 1e-10);
        assert_eq!(pb.neutral, 1);
    }

    #[test]
    fn hessenberg_char_poly_matches_cofactors() {
        // Three unequal balls off balance: d = 5, both routes apply.
        let p = Planar::new(0.2, 0.05, &[0.1], 50.0, 1.4, &[0.4, 0.6, 0.5]).unwrap();
        let q = [0.01, -0.02, 0.3, 2.0, -2.5];
        let d = 5;
        let z = vec![0.0; d];
        let (mut k, mut c, mut m) = (vec![0.0; d * d], vec![0.0; d * d], vec![0.0; d * d]);
        p.jacobians(0.0, &q, &z, &z, Jacobians::new(&mut k, &mut c, &mut m));
        let mut a = vec![0.0; 4 * d * d];
        let mut col = vec![0.0; 2 * d * d];
        state_matrix(&p, 0.0, &q, &k, &c, &mut col, &mut a);
        let cof = char_poly(&k, &c, &m, d);
        let hes = char_poly_hessenberg(&a, 2 * d);
        assert_eq!(cof.len(), hes.len());
        for (u, v) in cof.iter().zip(&hes) {
            assert!((u - v).abs() < 1e-8 * (1.0 + u.abs()), "{cof:?} vs {hes:?}");
        }
    }

    /// 4^32 starts overflowed to none: equilibria() was empty from 32 balls on.
    #[test]
    fn many_balls_find_the_perfect_balance() {
        for n in [31usize, 32, 40] {
            let eta = 2.0 / n as f64;
            let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &vec![eta; n]).unwrap();
            let (st, exhaustive) = starts(n, 2);
            assert_eq!(st.len(), start_budget(n));
            assert!(!exhaustive);
            let eqs = equilibria(&p);
            let pb = eqs
                .iter()
                .find(|e| e.kind == EquilibriumKind::PerfectBalance)
                .expect("perfect balance");
            // Closed form of the family: x = y = 0 and the balls' unbalance cancels the
            // disk's, sum eta e^(i b) = -1.
            let (cs, sn) = pb.q[2..].iter().fold((0.0, 0.0), |(a, b), &t| {
                (a + eta * t.cos(), b + eta * t.sin())
            });
            assert!(pb.q[0].abs() < 1e-10 && pb.q[1].abs() < 1e-10);
            assert!((cs + 1.0).abs() < 1e-10 && sn.abs() < 1e-10, "{cs} {sn}");
            assert_eq!(pb.neutral, n - 2);
            assert!(eqs.iter().all(|e| !e.exhaustive));
        }
    }

    #[test]
    fn track_order_starts_and_identity() {
        for n in 1..=6 {
            let st = ordered_starts(n, 2);
            assert!(!st.is_empty() && st.len() <= 600, "n {n}: {}", st.len());
            for q in &st {
                let b = &q[2..];
                assert!(b.windows(2).all(|w| w[1] > w[0]) && b[n - 1] < b[0] + 2.0 * PI);
            }
        }
        // Only the starts used are built (all C(27, 23) subsets took 45 s at 24 balls).
        let t = std::time::Instant::now();
        let st = ordered_starts(24, 2);
        assert_eq!(st.len(), 600);
        assert!(t.elapsed().as_secs_f64() < 1.0);
        let a = [0.1, -0.2, 1.0, 4.0, 5.5];
        // the same state a whole turn on, for any balls
        let turned = [0.1, -0.2, 1.0 + 2.0 * PI, 4.0 + 2.0 * PI, 5.5 + 2.0 * PI];
        assert!(same_in_order(false, 2, &a, &turned));
        // relabelled round the ring: one state only if the balls are identical
        let relabelled = [0.1, -0.2, 4.0, 5.5, 1.0 + 2.0 * PI];
        assert!(same_in_order(true, 2, &a, &relabelled));
        assert!(!same_in_order(false, 2, &a, &relabelled));
        // one ball a turn on is another winding of the springs, not the same state
        let wound = [0.1, -0.2, 1.0, 4.0, 5.5 - 2.0 * PI];
        assert!(!same_in_order(true, 2, &a, &wound));
    }
}
