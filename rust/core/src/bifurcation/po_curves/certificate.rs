//! The certificate of a codimension-two point: whether the monodromy's multipliers at the
//! located point carry the values its label needs, to the monodromy's error.

use super::system::C64;
use super::PoCurveKind;
use crate::hb::HbSolution;
use nalgebra::{DMatrix, DVector};

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
pub(super) enum Need {
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

pub(super) fn own_need(kind: PoCurveKind, theta: Option<f64>) -> Need {
    match kind {
        PoCurveKind::Fold => Need::SecondPlusOne,
        PoCurveKind::BranchPoint => Need::Separation,
        PoCurveKind::PeriodDoubling => Need::MinusOne,
        PoCurveKind::NeimarkSacker => Need::Pair(theta.unwrap_or(f64::NAN)),
    }
}

/// The multiplier a label adds to the curve's own (`None`: a geometric point).
pub(super) fn added_need(kind: PoCurveKind, label: &str) -> Option<Need> {
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

pub(super) type CMat = DMatrix<C64>;

pub(super) fn smin(a: &CMat, z: C64) -> f64 {
    let n = a.nrows();
    let m = a - CMat::identity(n, n) * z;
    m.singular_values()
        .iter()
        .fold(f64::INFINITY, |x, &y| x.min(y))
}

/// An orthonormal basis (columns) of the complement of `v` (Householder).
pub(super) fn complement(v: &DVector<f64>) -> DMatrix<f64> {
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
