//! Branch switching: the first solution of the branch that crosses a known one at a
//! bifurcation, from the critical eigenvector instead of a simulation.
//!
//! Each switch builds a point `y0 = (x0, p0)` on (or near) the known branch, written in
//! the unknowns of the new one, and the direction `v` in which the new branch leaves it:
//!
//! * period doubling: `x0` the orbit written over two periods (harmonic `k` becomes `2k`,
//!   `omega / 2`, windings doubled), `v` the series of `Phi(t) e` over `2 T`, `e` the
//!   monodromy's eigenvector of the multiplier nearest -1 (anti-periodic over `T`);
//! * branch point (a real multiplier through +1 other than the trivial one; for merged
//!   balls the antisymmetric separation mode): `x0` the orbit, `v` the series of
//!   `Phi(t) e` over `T`;
//! * Hopf point of an equilibrium: `x0` the equilibrium as a constant series at the
//!   critical frequency, `v` the first harmonic of the critical eigenvector (rotated so
//!   that the phase condition, no `sin tau` in `x`, holds).
//!
//! The new branch's point is then the pseudo-arclength corrector's solution at distance
//! `amplitude` along `v` ([`point_at`]), the parameter free: on a pitchfork, period
//! doubling or Hopf branch `p - p*` grows like the amplitude squared, which the corrector
//! finds by itself.

use crate::analysis::periodic::{finish_on_branch, Periodic, PeriodicOptions};
use crate::bifurcation::event::Event;
use crate::continuation::{point_at, ArcOptions, ArcPoint};
use crate::error::{Error, Result};
use crate::floquet::{merged_pair, monodromy, FloquetOptions};
use crate::hb::{default_samples, fit_coefficients, HbProblem, HbSolution, Status};
use crate::linalg::{eigenvalues, lu_solve};
use crate::model::Jacobians;
use crate::model::{first_order_rhs, Dynamics};
use crate::numerics::problem::{ModelAt, Parametric};
use crate::ode::{solve_at, Options};

/// Which bifurcation of a periodic orbit to switch at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Switch {
    PeriodDoubling,
    BranchPoint,
}

impl Switch {
    /// The switch at the event named `kind` (any spelling [`Event::parse`] reads).
    pub fn parse(kind: &str) -> Result<Self> {
        match Event::parse(kind, "kind")? {
            Event::PeriodDoubling => Ok(Switch::PeriodDoubling),
            Event::BranchPoint => Ok(Switch::BranchPoint),
            other => Err(Error::param_range(
                "kind",
                format!(
                    "a periodic solution is switched at a period_doubling or branch_point, \
                     not a {}",
                    other.name()
                ),
                "period_doubling, branch_point",
            )),
        }
    }
}

/// The new branch's first point: the solution (with its certificates and multipliers at
/// the new parameter value) and that value.
#[derive(Debug, Clone)]
pub struct Switched {
    pub periodic: Periodic,
    pub p: f64,
    /// The critical multiplier (or eigenvalue, at a Hopf point) switched along.
    pub critical: (f64, f64),
}

/// A real eigenvector of the row-major `n x n` matrix `a` for its real eigenvalue near
/// `lambda`, by inverse iteration; unit Euclidean norm.
fn real_eigenvector(a: &[f64], n: usize, lambda: f64) -> Option<Vec<f64>> {
    let shift = lambda + 1e-9 * (1.0 + lambda.abs());
    let mut m = a.to_vec();
    for i in 0..n {
        m[i * n + i] -= shift;
    }
    let mut v: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * i as f64).collect();
    for _ in 0..3 {
        let s = lu_solve(&m, n, &v)?;
        let norm = s.x.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return None;
        }
        v = s.x.iter().map(|x| x / norm).collect();
    }
    Some(v)
}

/// A complex eigenvector `(re, im)` of the real `n x n` `a` for the eigenvalue
/// `(lr, li)`, by inverse iteration on the real `2n` form of `a - lambda I`.
fn complex_eigenvector(a: &[f64], n: usize, (lr, li): (f64, f64)) -> Option<(Vec<f64>, Vec<f64>)> {
    let n2 = 2 * n;
    let eps = 1e-9 * (1.0 + lr.hypot(li));
    let (sr, si) = (lr + eps, li);
    // [[A - sr, si], [-si, A - sr]] (u, w) = (f, g)  <=>  (A - s)(u + i w) = f + i g.
    let mut m = vec![0.0; n2 * n2];
    for i in 0..n {
        for j in 0..n {
            m[i * n2 + j] = a[i * n + j];
            m[(n + i) * n2 + n + j] = a[i * n + j];
        }
        m[i * n2 + i] -= sr;
        m[(n + i) * n2 + n + i] -= sr;
        m[i * n2 + n + i] = si;
        m[(n + i) * n2 + i] = -si;
    }
    let mut v: Vec<f64> = (0..n2).map(|i| 1.0 + 0.1 * i as f64).collect();
    for _ in 0..3 {
        let s = lu_solve(&m, n2, &v)?;
        let norm = s.x.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return None;
        }
        v = s.x.iter().map(|x| x / norm).collect();
    }
    Some((v[..n].to_vec(), v[n..].to_vec()))
}

/// `Phi(t) e` along the orbit, its position part sampled at `samples` phases over
/// `periods` periods and fitted with `n_harm` harmonics (no winding): the perturbation
/// series.
fn variational_series<D: Dynamics + ?Sized>(
    model: &D,
    sol: &HbSolution,
    e: &[f64],
    periods: usize,
    n_harm: usize,
    fo: &FloquetOptions,
) -> Result<Vec<f64>> {
    let d = model.ndof();
    let om = sol.omega;
    let (mut q, mut v, mut a) = (vec![0.0; d], vec![0.0; d], vec![0.0; d]);
    let (mut k, mut c, mut m) = (vec![0.0; d * d], vec![0.0; d * d], vec![0.0; d * d]);
    let rhs = |t: f64, y: &[f64], dy: &mut [f64]| {
        sol.eval_rates(om * t, &mut q, &mut v, &mut a);
        model.jacobians(t, &q, &v, &a, Jacobians::new(&mut k, &mut c, &mut m));
        // xi'' = -M^-1 (K xi + C xi')
        let mut f: Vec<f64> = (0..d)
            .map(|i| {
                -(0..d)
                    .map(|j| k[i * d + j] * y[j] + c[i * d + j] * y[d + j])
                    .sum::<f64>()
            })
            .collect();
        model.solve_mass(t, &q, &mut f);
        dy[..d].copy_from_slice(&y[d..]);
        dy[d..].copy_from_slice(&f);
    };
    let s = 2 * default_samples(n_harm);
    let span = periods as f64 * sol.period();
    let times: Vec<f64> = (0..s).map(|i| span * i as f64 / s as f64).collect();
    let opts = Options {
        max_steps: fo.max_steps,
        ..Options::new(fo.rtol, fo.atol)
    };
    let (ys, _) = solve_at(rhs, 0.0, e, &times, &opts)?;
    let mut samples = vec![0.0; s * d];
    for (i, y) in ys.iter().enumerate() {
        samples[i * d..(i + 1) * d].copy_from_slice(&y[..d]);
    }
    Ok(fit_coefficients(&samples, d, &vec![0.0; d], n_harm))
}

/// The orbit written over `m` of its periods: harmonic `k` becomes `m k`.
pub fn repeated(sol: &HbSolution, m: usize) -> HbSolution {
    let (l, lm) = (2 * sol.n_harm + 1, 2 * m * sol.n_harm + 1);
    let d = sol.ndof();
    let mut coeffs = vec![0.0; d * lm];
    for j in 0..d {
        coeffs[j * lm] = sol.coeffs[j * l];
        for k in 1..=sol.n_harm {
            coeffs[j * lm + 2 * m * k - 1] = sol.coeffs[j * l + 2 * k - 1];
            coeffs[j * lm + 2 * m * k] = sol.coeffs[j * l + 2 * k];
        }
    }
    HbSolution {
        omega: sol.omega / m as f64,
        coeffs,
        winding: sol.winding.iter().map(|w| w * m as f64).collect(),
        n_harm: m * sol.n_harm,
        ..sol.clone()
    }
}

/// The monodromy's critical eigenvector for `kind`: `(multiplier, e)`.
fn critical_mode<D: Dynamics + ?Sized>(
    model: &D,
    sol: &HbSolution,
    kind: Switch,
    fo: &FloquetOptions,
) -> Result<(f64, Vec<f64>)> {
    let d = model.ndof();
    let n2 = 2 * d;
    let (phi, _, _) = monodromy(model, sol, fo)?;
    let ev = eigenvalues(&phi, n2)
        .ok_or_else(|| Error::Eigen("eigenvalues of the monodromy matrix".into()))?;
    let real: Vec<f64> = ev
        .iter()
        .filter(|z| z.1.abs() <= 1e-6 * (1.0 + z.0.abs()))
        .map(|z| z.0)
        .collect();
    let no_mode = |what: &str| {
        Error::param(
            "kind",
            format!("the solution has no real multiplier near {what}"),
        )
    };
    match kind {
        Switch::PeriodDoubling => {
            let lam = real
                .iter()
                .copied()
                .filter(|l| *l < 0.0)
                .min_by(|a, b| (a + 1.0).abs().total_cmp(&(b + 1.0).abs()))
                .ok_or_else(|| no_mode("-1"))?;
            let e = real_eigenvector(&phi, n2, lam).ok_or_else(|| no_mode("-1"))?;
            Ok((lam, e))
        }
        Switch::BranchPoint => {
            if let Some((i, j)) = merged_pair(sol, model.first_ball()) {
                // The separation mode's 2 x 2 block, as in `floquet::separation_error`.
                let r = std::f64::consts::FRAC_1_SQRT_2;
                let basis = |c: usize| {
                    let mut e = vec![0.0; n2];
                    let off = if c == 0 { 0 } else { d };
                    e[off + i] = r;
                    e[off + j] = -r;
                    e
                };
                let mut b = [0.0; 4];
                for c in 0..2 {
                    let ec = basis(c);
                    for rr in 0..2 {
                        let er = basis(rr);
                        b[rr * 2 + c] = (0..n2)
                            .map(|row| {
                                er[row] * (0..n2).map(|k| phi[row * n2 + k] * ec[k]).sum::<f64>()
                            })
                            .sum();
                    }
                }
                let (tr, det) = (b[0] + b[3], b[0] * b[3] - b[1] * b[2]);
                let disc = tr * tr - 4.0 * det;
                if disc < 0.0 {
                    return Err(no_mode("+1 in the balls' separation mode"));
                }
                let roots = [(tr + disc.sqrt()) / 2.0, (tr - disc.sqrt()) / 2.0];
                let lam = if (roots[0] - 1.0).abs() <= (roots[1] - 1.0).abs() {
                    roots[0]
                } else {
                    roots[1]
                };
                let u = real_eigenvector(&b, 2, lam)
                    .ok_or_else(|| no_mode("+1 in the balls' separation mode"))?;
                let (e0, e1) = (basis(0), basis(1));
                let e: Vec<f64> = (0..n2).map(|k| u[0] * e0[k] + u[1] * e1[k]).collect();
                return Ok((lam, e));
            }
            // Otherwise the real multiplier nearest 1 whose mode is not the time shift
            // (the flow direction).
            let y0 = sol.state(0.0);
            let mut f = vec![0.0; n2];
            first_order_rhs(model, 0.0, &y0, &mut f);
            let fnorm = f.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-300);
            let mut near: Vec<f64> = real.clone();
            near.sort_by(|a, b| (a - 1.0).abs().total_cmp(&(b - 1.0).abs()));
            let mut best: Option<(f64, f64, Vec<f64>)> = None;
            for &lam in near.iter().take(2) {
                if let Some(e) = real_eigenvector(&phi, n2, lam) {
                    let cos = (e.iter().zip(&f).map(|(a, b)| a * b).sum::<f64>() / fnorm).abs();
                    if best.as_ref().is_none_or(|b| cos < b.0) {
                        best = Some((cos, lam, e));
                    }
                }
            }
            let (_, lam, e) = best.ok_or_else(|| no_mode("+1"))?;
            Ok((lam, e))
        }
    }
}

/// Where a new branch leaves the known one: the known solution `base` written in the
/// new branch's unknowns, the direction `dir` it leaves in, how far to step
/// (`amplitude`), and the critical multiplier (or eigenvalue) that marks the point.
struct Departure<'a> {
    base: &'a HbSolution,
    dir: Vec<f64>,
    amplitude: f64,
    critical: (f64, f64),
}

/// Corrects along `dir` at distance `amplitude` (halved up to 4 times when the
/// corrector fails) and finishes the solution at the parameter found; `accept` refuses
/// a solution that is the known branch again.
fn step_off<D: Parametric>(
    model: &D,
    name: &str,
    leave: Departure<'_>,
    opts: &PeriodicOptions,
    accept: impl Fn(&HbSolution) -> bool,
) -> Result<Switched> {
    let Departure {
        base,
        dir,
        amplitude,
        critical,
    } = leave;
    crate::error::check_range("amplitude", amplitude, 0.0, true, 10.0, false)?;
    let p0 = model.param_value(name)?;
    let samples = default_samples(base.n_harm);
    let mut prob = HbProblem::new(
        ModelAt::family(model, name, p0),
        &base.winding,
        base.n_harm,
        samples,
    );
    let x0 = base.unknowns();
    let mut tangent = dir;
    tangent.push(0.0); // omega
    tangent.push(0.0); // the parameter
    let norm = tangent.iter().map(|t| t * t).sum::<f64>().sqrt();
    if !(norm > 0.0 && norm.is_finite()) {
        return Err(Error::param(
            "solution",
            "no critical direction to switch along",
        ));
    }
    tangent.iter_mut().for_each(|t| *t /= norm);
    let from = ArcPoint {
        x: x0,
        p: p0,
        tangent,
        ds: 0.0,
        iterations: 0,
        residual: f64::NAN,
        det_sign: 0.0,
    };
    let arc = ArcOptions {
        tol: opts.hb.tol,
        max_newton: 30,
        ..Default::default()
    };
    let mut ds = amplitude;
    for _ in 0..5 {
        if let Some(pt) = point_at(&mut prob, &from, ds, &arc)? {
            let n = pt.x.len();
            let sol = HbSolution {
                omega: pt.x[n - 1],
                coeffs: pt.x[..n - 1].to_vec(),
                status: Status::Converged,
                residual: pt.residual,
                iterations: pt.iterations,
                samples,
                ..base.clone()
            };
            if sol.omega > 0.0 && accept(&sol) {
                let at = model.with_param(name, pt.p)?;
                // Polish at the new value with the user's harmonic-balance options.
                let polished = crate::hb::solve(
                    &at,
                    &sol,
                    &crate::hb::HbOptions {
                        n_harm: sol.n_harm,
                        ..opts.hb.clone()
                    },
                );
                let periodic = finish_on_branch(&at, polished, opts);
                return Ok(Switched {
                    periodic,
                    p: pt.p,
                    critical,
                });
            }
        }
        ds *= 0.5;
    }
    Err(Error::param(
        "amplitude",
        format!("no solution of the new branch within amplitude {amplitude} of the switch point"),
    ))
}

/// The first solution on the branch that leaves the periodic solution `sol` of `model`
/// at a period doubling or a branch point, in the parameter `name`.
pub fn switch_periodic<D: Parametric>(
    model: &D,
    name: &str,
    sol: &HbSolution,
    kind: Switch,
    amplitude: f64,
    opts: &PeriodicOptions,
) -> Result<Switched> {
    let fo = opts.floquet.clone().unwrap_or_default();
    let (lam, base, dir) = leaving_direction(model, sol, kind, &fo)?;
    let o = model.first_ball();
    match kind {
        Switch::PeriodDoubling => {
            let leave = Departure {
                base: &base,
                dir,
                amplitude,
                critical: (lam, 0.0),
            };
            step_off(model, name, leave, opts, |s| {
                !crate::analysis::periodic::repeats(s, 2)
            })
        }
        Switch::BranchPoint => {
            let merged = merged_pair(sol, o).is_some();
            let leave = Departure {
                base: &base,
                dir,
                amplitude,
                critical: (lam, 0.0),
            };
            step_off(model, name, leave, opts, move |s| {
                !merged || merged_pair(s, o).is_none()
            })
        }
    }
}

/// Where a branch switched at `kind` leaves `sol`: the critical multiplier, the orbit in
/// the new branch's unknowns (written over two periods at a period doubling) and the
/// direction, the series of `Phi(t) e` over as many periods.
fn leaving_direction<D: Dynamics + ?Sized>(
    model: &D,
    sol: &HbSolution,
    kind: Switch,
    fo: &FloquetOptions,
) -> Result<(f64, HbSolution, Vec<f64>)> {
    let (lam, e) = critical_mode(model, sol, kind, fo)?;
    let m = match kind {
        Switch::PeriodDoubling => 2,
        Switch::BranchPoint => 1,
    };
    let base = repeated(sol, m);
    let dir = variational_series(model, sol, &e, m, base.n_harm, fo)?;
    Ok((lam, base, dir))
}

/// Starts for an orbit born in a period doubling of `sol`, at `sol`'s own parameters
/// (no continuation in a parameter, as a scan needs at a grid point): the orbit written
/// over two periods ([`repeated`]) displaced along the critical mode (the series of
/// `Phi(t) e` over two periods, `e` the monodromy's eigenvector of its real multiplier
/// nearest -1, scaled to unit norm) by each of `amplitudes`. Past a supercritical period
/// doubling (that multiplier below -1) the doubled orbit lies at a distance that grows
/// like the square root of the distance from the bifurcation, so several amplitudes are
/// tried. `None` when the orbit has no real negative multiplier or the mode's series
/// cannot be integrated.
pub fn period_doubling_starts<D: Dynamics + ?Sized>(
    model: &D,
    sol: &HbSolution,
    fo: &FloquetOptions,
    amplitudes: &[f64],
) -> Option<Vec<HbSolution>> {
    let (_, base, dir) = leaving_direction(model, sol, Switch::PeriodDoubling, fo).ok()?;
    let norm = dir.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(norm > 0.0 && norm.is_finite()) {
        return None;
    }
    Some(
        amplitudes
            .iter()
            .map(|a| HbSolution {
                coeffs: base
                    .coeffs
                    .iter()
                    .zip(&dir)
                    .map(|(c, v)| c + a * v / norm)
                    .collect(),
                status: Status::NoGuess,
                ..base.clone()
            })
            .collect(),
    )
}

/// The Jacobian (row-major `2d x 2d`) of the first-order equations at the equilibrium
/// `q` (at rest relative to the disk), by central differences.
pub fn equilibrium_jacobian<D: Dynamics + ?Sized>(model: &D, q: &[f64]) -> Vec<f64> {
    let d = model.ndof();
    let n2 = 2 * d;
    let mut y: Vec<f64> = q.to_vec();
    y.extend(std::iter::repeat_n(0.0, d));
    let mut jac = vec![0.0; n2 * n2];
    let (mut fp, mut fm) = (vec![0.0; n2], vec![0.0; n2]);
    for j in 0..n2 {
        let h = 1e-6 * (1.0 + y[j].abs());
        let mut yp = y.clone();
        yp[j] += h;
        first_order_rhs(model, 0.0, &yp, &mut fp);
        yp[j] -= 2.0 * h;
        first_order_rhs(model, 0.0, &yp, &mut fm);
        for i in 0..n2 {
            jac[i * n2 + j] = (fp[i] - fm[i]) / (2.0 * h);
        }
    }
    jac
}

/// The first oscillating (all balls `O`) orbit born at the Hopf point of the equilibrium
/// `q` of `model`, in the parameter `name`, with `n_harm` harmonics. The critical pair
/// is the complex pair of eigenvalues nearest the imaginary axis.
pub fn switch_hopf<D: Parametric>(
    model: &D,
    name: &str,
    q: &[f64],
    amplitude: f64,
    opts: &PeriodicOptions,
) -> Result<Switched> {
    let d = model.ndof();
    if q.len() != d {
        return Err(Error::param(
            "solution",
            format!("the equilibrium needs {d} coordinates, got {}", q.len()),
        ));
    }
    let n2 = 2 * d;
    let jac = equilibrium_jacobian(model, q);
    let ev = eigenvalues(&jac, n2)
        .ok_or_else(|| Error::Eigen("eigenvalues of the equilibrium's Jacobian".into()))?;
    let lam = ev
        .iter()
        .copied()
        .filter(|z| z.1 > 1e-8)
        .min_by(|a, b| a.0.abs().total_cmp(&b.0.abs()))
        .ok_or_else(|| Error::param("solution", "the equilibrium has no complex eigenvalues"))?;
    let (re, im) = complex_eigenvector(&jac, n2, lam)
        .ok_or_else(|| Error::Eigen("the critical eigenvector did not converge".into()))?;
    // Rotate so that x's component is real: q = Re(v e^{i tau}) has no sin tau in x.
    let x = model.layout().x;
    let phase = im[x].atan2(re[x]);
    let (c, s) = (phase.cos(), phase.sin());
    // v e^{-i phase}
    let vr: Vec<f64> = (0..d).map(|j| re[j] * c + im[j] * s).collect();
    let vi: Vec<f64> = (0..d).map(|j| im[j] * c - re[j] * s).collect();
    let n_harm = opts.hb.n_harm;
    let l = 2 * n_harm + 1;
    let mut coeffs = vec![0.0; d * l];
    let mut dir = vec![0.0; d * l];
    for j in 0..d {
        coeffs[j * l] = q[j];
        dir[j * l + 1] = vr[j];
        dir[j * l + 2] = -vi[j];
    }
    let base = HbSolution::start(lam.1, coeffs, vec![0.0; d], n_harm, Status::NoGuess);
    let leave = Departure {
        base: &base,
        dir,
        amplitude,
        critical: lam,
    };
    step_off(model, name, leave, opts, |s| {
        // Not the equilibrium again: a first harmonic in some coordinate.
        (0..d).any(|j| s.coord(j)[1].hypot(s.coord(j)[2]) > 1e-9)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Planar;

    #[test]
    fn repeated_series_is_the_same_motion() {
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let r = crate::periodic::periodic(&p, &[true, true], None, &PeriodicOptions::default());
        let s2 = repeated(&r.sol, 2);
        let (a, b) = (r.sol.state(1.3), s2.state(1.3));
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-12);
        }
        assert!(crate::periodic::repeats(&s2, 2));
        assert!(!crate::periodic::repeats(&r.sol, 2));
    }
}
