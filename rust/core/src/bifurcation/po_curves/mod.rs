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
use crate::continuation::curves::{both_halves, curve_half, CurveHook};
use crate::continuation::{ArcOptions, ArcPoint, ArcStop};
use crate::error::{Error, Result};
use crate::hb::HbSolution;
use crate::numerics::problem::Parametric;
use crate::periodic::{finish_on_branch, Periodic, PeriodicOptions};
use nalgebra::DVector;
use std::f64::consts::PI;

mod augmented;
mod certificate;
mod system;

pub use augmented::Augmented;
use augmented::{Border, CBorder};
pub use certificate::{
    certify_codim2, combine, condition_status, Codim2Certificate, Codim2Status, CODIM2_RESOLUTION,
    CODIM2_SAFETY,
};
use system::start_angle;
pub use system::PoSystem;

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
            Error::param(
                label,
                format!(
                    "{name:?} is not a parameter of this model{}",
                    crate::model::params::ball_hint(name)
                ),
            )
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
    let n = sys.n();
    let mut y0 = x0[..n].to_vec();
    y0.push(p0[0]);
    y0.extend_from_slice(&x0[n..]);
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
        border: border.clone(),
        cborder: cborder.clone(),
        scale: 1.0,
        p2: p0[1],
        grad: None,
    };
    let mut hook = PoCurveHook {
        kind,
        n,
        ns,
        p1_range: opts.p1_range,
        popts,
    };
    let half = |arc: &ArcOptions| {
        // Each half starts from the start's borders (the other half rebased them).
        ext.border = border.clone();
        ext.cborder = cborder.clone();
        ext.scale = 1.0;
        ext.grad = None;
        let norm = ext.gradient_norm(&y0, p0[1])?;
        if !(norm > 0.0 && norm.is_finite()) {
            return Err(Error::param(
                "event",
                "the test function is flat at the start: not a regular bifurcation point",
            ));
        }
        ext.scale = 1.0 / norm;
        ext.grad = None;
        curve_half(&mut ext, &y0, p0[1], arc, opts.locate_tol, &mut hook)
    };
    let whole = both_halves(&opts.arc, half, |c: &mut PoCodim2| &mut c.row)?;
    Ok(PoCurve {
        kind,
        points: whole.points,
        special: whole.special,
        together,
        stop: whole.stop.map(|s| ArcStop::text(Some(&s))),
    })
}

/// The start's borders: real, or complex for `NS`.
#[derive(Debug, Clone)]
enum Borders {
    Real(Border<f64>),
    Complex(CBorder),
}

/// On an `NS` curve closer than this to 0 or pi, the pair meets the real axis (strong
/// resonance 1:1 or 1:2) and the curve ends.
const THETA_END: f64 = 1e-3;

/// The periodic side of the curve loop: the ends the arclength window does not know
/// (the first parameter's window, omega vanishing, a Neimark–Sacker angle at a strong
/// resonance), the other kinds' determinants as codimension-two tests with each located
/// point's multiplier certificate, and each point's series certified and judged.
struct PoCurveHook {
    kind: PoCurveKind,
    n: usize,
    /// A Neimark–Sacker curve: `theta` is the unknown after `p1`.
    ns: bool,
    p1_range: (f64, f64),
    popts: PeriodicOptions,
}

impl PoCurveHook {
    fn theta(&self, pt: &ArcPoint) -> Option<f64> {
        self.ns.then(|| pt.x[self.n + 1])
    }

    fn omega<D: Parametric>(&self, e: &Augmented<'_, D>, pt: &ArcPoint) -> f64 {
        e.sys
            .full(&pt.x[..self.n])
            .last()
            .copied()
            .unwrap_or(f64::NAN)
    }
}

impl<'a, D: Parametric> CurveHook<Augmented<'a, D>> for PoCurveHook {
    type Point = PoCurvePoint;
    type Special = PoCodim2;

    fn n(&self) -> usize {
        self.n
    }

    fn end(&mut self, e: &mut Augmented<'a, D>, pt: &ArcPoint) -> Result<Option<&'static str>> {
        let (lo, hi) = self.p1_range;
        if !(lo..=hi).contains(&pt.x[self.n]) {
            return Ok(Some("boundary"));
        }
        if !(self.omega(e, pt) > 1e-3) {
            return Ok(Some("omega_vanishes"));
        }
        Ok(match self.theta(pt) {
            Some(t) if t < THETA_END => Some("resonance_1:1"),
            Some(t) if t > PI - THETA_END => Some("resonance_1:2"),
            _ => None,
        })
    }

    fn tests(
        &mut self,
        e: &mut Augmented<'a, D>,
        pt: &ArcPoint,
    ) -> Result<Vec<(&'static str, f64)>> {
        let p = [pt.x[self.n], pt.p];
        e.sys
            .secondary(self.kind, &pt.x[..self.n], p, self.theta(pt))
    }

    fn cusp(&self) -> Option<&'static str> {
        (self.kind == PoCurveKind::Fold).then_some("CP")
    }

    fn special(
        &mut self,
        e: &mut Augmented<'a, D>,
        label: &'static str,
        at: &ArcPoint,
        row: usize,
    ) -> Result<Option<PoCodim2>> {
        let omega = self.omega(e, at);
        let certificate = certify_at(e, self.kind, label, at, self.n, self.ns)?;
        Ok(Some(PoCodim2 {
            kind: label,
            p: [at.x[self.n], at.p],
            omega,
            row,
            certificate,
        }))
    }

    fn point(
        &mut self,
        e: &mut Augmented<'a, D>,
        pt: &ArcPoint,
        tests: &[(&'static str, f64)],
    ) -> Result<PoCurvePoint> {
        let n = self.n;
        let p = [pt.x[n], pt.p];
        let sol = e.sys.series(&pt.x[..n], pt.residual);
        let model = e.sys.model(p)?.clone();
        let result = finish_on_branch(&model, sol, &self.popts);
        let g = e.g(&pt.x, pt.p)?;
        let g = if self.ns { g[0].hypot(g[1]) } else { g[0] };
        // New borders for the next step (the curve is the same set: g = 0 iff H is
        // singular, whatever the borders).
        e.rebase(&pt.x, pt.p)?;
        Ok(PoCurvePoint {
            p,
            result,
            g,
            theta: self.theta(pt),
            tests: tests.to_vec(),
        })
    }
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
pub(super) mod tests {
    use super::certificate::{added_need, complement, smin, Need};
    use super::system::C64;
    use super::*;
    use crate::bifurcation::po_branch::{periodic_branch, PoBranchOptions, PoEventKind};
    use crate::floquet::FloquetOptions;
    use crate::hb::HbOptions;
    use crate::hb::Status;
    use crate::periodic::periodic;
    use crate::Planar;
    use nalgebra::DMatrix;

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

    pub(in crate::bifurcation) fn curve_opts(
        n: usize,
        p1: (f64, f64),
        p2: (f64, f64),
        points: usize,
    ) -> PoCurveOptions {
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
    pub(in crate::bifurcation) fn whirl_branch(
        n: usize,
        lo: f64,
    ) -> (crate::Scene, crate::bifurcation::po_branch::PoBranch) {
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
    pub(in crate::bifurcation) fn curve_at_event<D: Parametric>(
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
