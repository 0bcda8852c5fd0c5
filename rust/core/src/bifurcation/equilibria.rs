//! Continuation of equilibria: one-parameter branches with their stability and located
//! events (saddle-node fold, Hopf, branch point / pitchfork), branch switching at a
//! branch point, and two-parameter curves of those bifurcations with their
//! codimension-two points.
//!
//! Test functions (all smooth in `(q, p)` near their zeros):
//!
//! * fold: `dp/ds`, the tangent's parameter component (sign change at a fold);
//! * Hopf: `det(2A (.) I)`, the bialternate product of the state matrix
//!   `A = [[0, I], [-M^-1 K, -M^-1 C]]`, whose eigenvalues are the sums `l_i + l_j`
//!   (`i < j`) of `A`'s eigenvalues: it vanishes when a complex pair crosses the
//!   imaginary axis (`l + conj(l) = 2 Re l`), and also at a neutral saddle (two real
//!   eigenvalues `+-l`), which the located point's eigenvalues tell apart;
//! * branch point: the bordered determinant `det [[F_q, F_p], [t^T]]` with the branch's
//!   own tangent `t` (it changes sign at a simple branch point, not at a fold); on the
//!   balls-together branch, the transverse stiffness `K_{b1 b1} - K_{b1 b2}` of the
//!   antisymmetric ball mode (the together subspace `b_1 = ... = b_n` is invariant,
//!   and this is the Jacobian's eigenvalue across it).
//!
//! Two-parameter curves continue `[F; g] = 0` ([`Extended`]) with `g` the test function
//! of the curve's bifurcation, normalised by its gradient at the start so that the
//! corrector's tolerance means a distance. The pitchfork of the together branch and
//! that branch's folds are continued on the together subspace itself (unknowns the
//! rotor coordinates and the common ball angle, equations the rotor's and the sum of
//! the balls'), where the pitchfork is a regular zero of `g` and the fold curve passes
//! the point where it meets the pitchfork.

use crate::analysis::equilibria::{analyse_model, wrap, Equilibrium, EquilibriumKind};
use crate::bifurcation::event::{check_stop_events, Event};
use crate::continuation::arclength::{bordered, point_at, ArcOptions, ArcPoint, ArcStop};
use crate::continuation::curves::{
    both_halves, curve_half, join_halves, CurveHook, Extended, TwoParameter,
};
use crate::continuation::{self, Controls, Declared, Spectrum, Start};
use crate::error::{Error, Result};
use crate::linalg::{eigenvalues, state_matrix};
use crate::model::disk_units::DiskUnits;
use crate::model::Jacobians;
use crate::model::{Dynamics, Planar};
use crate::numerics::problem::{Parametric, Problem};
use nalgebra::DMatrix;
use std::f64::consts::PI;

/// Builds the model at parameter values `ps` (one per continued parameter).
pub type Maker<'a, D> = Box<dyn Fn(&[f64]) -> Result<D> + 'a>;

/// The static equations `F(0, q, 0, 0) = 0` of a model family in one or two
/// parameters, on the full coordinates or on the together subspace.
pub struct EqSystem<'a, D> {
    make: Maker<'a, D>,
    /// The start's parameter value (what [`Problem::param`] reports).
    p0: f64,
    reduced: bool,
    d: usize,
    o: usize,
    cache: Option<(Vec<u64>, D)>,
}

impl<'a, D: Dynamics + Clone> EqSystem<'a, D> {
    /// The family of `base` in the parameters `names` (the names `with_param` takes).
    pub fn family(base: &'a D, names: &[&str]) -> Result<Self>
    where
        D: Parametric + 'a,
    {
        if names.is_empty() || names.len() > 2 {
            return Err(Error::param("parameter", "one or two parameters"));
        }
        let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
        let p0 = base.param_value(&names[0])?;
        for n in &names {
            base.param_value(n)?;
        }
        let make: Maker<'a, D> = Box::new(move |ps: &[f64]| {
            let mut m = base.clone();
            for (n, v) in names.iter().zip(ps) {
                m = m.with_param(n, *v)?;
            }
            Ok(m)
        });
        Ok(Self::new(make, base.ndof(), base.first_ball(), p0))
    }

    /// A family given by its builder (e.g. another nondimensionalisation's parameters,
    /// as [`EqSystem::disk_units`]).
    pub fn new(make: Maker<'a, D>, d: usize, o: usize, p0: f64) -> Self {
        EqSystem {
            make,
            p0,
            reduced: false,
            d,
            o,
            cache: None,
        }
    }

    /// The same family on the together subspace `b_1 = ... = b_n`.
    pub fn on_together(mut self) -> Result<Self> {
        if self.d - self.o < 2 {
            return Err(Error::param(
                "start",
                "the together subspace needs at least two balls",
            ));
        }
        self.reduced = true;
        Ok(self)
    }

    pub fn is_reduced(&self) -> bool {
        self.reduced
    }

    /// The model at `ps`.
    pub fn model(&mut self, ps: &[f64]) -> Result<&D> {
        let key: Vec<u64> = ps.iter().map(|v| v.to_bits()).collect();
        if self.cache.as_ref().is_none_or(|(k, _)| *k != key) {
            let m = (self.make)(ps)?;
            self.cache = Some((key, m));
        }
        Ok(&self.cache.as_ref().unwrap().1)
    }

    /// Unknowns of this system from full coordinates.
    pub fn reduce(&self, q: &[f64]) -> Vec<f64> {
        if self.reduced {
            q[..=self.o].to_vec()
        } else {
            q.to_vec()
        }
    }

    /// Full coordinates from this system's unknowns.
    pub fn full(&self, x: &[f64]) -> Vec<f64> {
        if self.reduced {
            let mut q = x[..self.o].to_vec();
            q.extend(std::iter::repeat_n(x[self.o], self.d - self.o));
            q
        } else {
            x.to_vec()
        }
    }

    fn n(&self) -> usize {
        if self.reduced {
            self.o + 1
        } else {
            self.d
        }
    }

    fn eval(&mut self, x: &[f64], ps: &[f64], r: &mut [f64]) -> Result<()> {
        let q = self.full(x);
        let d = self.d;
        let z = vec![0.0; d];
        let mut rf = vec![0.0; d];
        self.model(ps)?.residual(0.0, &q, &z, &z, &mut rf);
        self.fold_rows(&rf, r);
        Ok(())
    }

    fn fold_rows(&self, rf: &[f64], r: &mut [f64]) {
        if self.reduced {
            r[..self.o].copy_from_slice(&rf[..self.o]);
            r[self.o] = rf[self.o..].iter().sum();
        } else {
            r.copy_from_slice(rf);
        }
    }

    /// Full `K, C, M` at full coordinates `q`.
    pub fn kcm(&mut self, q: &[f64], ps: &[f64]) -> Result<(Vec<f64>, Vec<f64>, Vec<f64>)> {
        let d = self.d;
        let z = vec![0.0; d];
        let (mut k, mut c, mut m) = (vec![0.0; d * d], vec![0.0; d * d], vec![0.0; d * d]);
        self.model(ps)?
            .jacobians(0.0, q, &z, &z, Jacobians::new(&mut k, &mut c, &mut m));
        Ok((k, c, m))
    }

    fn eval_jac(&mut self, x: &[f64], ps: &[f64], r: &mut [f64], jac: &mut [f64]) -> Result<()> {
        self.eval(x, ps, r)?;
        let q = self.full(x);
        let (k, _, _) = self.kcm(&q, ps)?;
        let (d, o) = (self.d, self.o);
        if !self.reduced {
            jac.copy_from_slice(&k);
            return Ok(());
        }
        let n = o + 1;
        jac.fill(0.0);
        for i in 0..d {
            let row = i.min(o);
            for j in 0..d {
                jac[row * n + j.min(o)] += k[i * d + j];
            }
        }
        Ok(())
    }

    /// `det` of this system's Jacobian in its unknowns (the fold's test function).
    pub fn det_jac(&mut self, x: &[f64], ps: &[f64]) -> Result<f64> {
        let n = self.n();
        let (mut r, mut j) = (vec![0.0; n], vec![0.0; n * n]);
        self.eval_jac(x, ps, &mut r, &mut j)?;
        Ok(DMatrix::from_row_slice(n, n, &j).lu().determinant())
    }

    /// The first-order state matrix at full coordinates `q`.
    pub fn state(&mut self, q: &[f64], ps: &[f64]) -> Result<Vec<f64>> {
        let d = self.d;
        let (k, c, _) = self.kcm(q, ps)?;
        let mut a = vec![0.0; 4 * d * d];
        let mut cols = vec![0.0; 2 * d * d];
        state_matrix(self.model(ps)?, 0.0, q, &k, &c, &mut cols, &mut a);
        Ok(a)
    }

    /// The Hopf test function at full coordinates `q` (see the module's notes).
    pub fn hopf_test(&mut self, q: &[f64], ps: &[f64]) -> Result<f64> {
        let n2 = 2 * self.d;
        let a = self.state(q, ps)?;
        Ok(if n2 <= BIALTERNATE_MAX {
            bialternate_det(&a, n2)
        } else {
            pair_sum_product(&eigenvalues(&a, n2).ok_or(Error::Eigen(
                "state matrix eigenvalues did not converge".into(),
            ))?)
        })
    }

    /// The transverse stiffness of the antisymmetric ball mode at full coordinates `q`.
    pub fn transverse(&mut self, q: &[f64], ps: &[f64]) -> Result<f64> {
        let (d, o) = (self.d, self.o);
        let (k, _, _) = self.kcm(q, ps)?;
        Ok(k[o * d + o] - k[o * d + o + 1])
    }

    /// The eigenvalue pair of `A` whose sum is nearest zero: `(kappa, omega)` with
    /// `kappa = Re(l_i l_j)` (`omega^2` for a pair `+-i omega`, negative for a real
    /// pair `+-l`) and `omega = sqrt(kappa)` when positive, else `NaN`.
    pub fn critical_pair(&mut self, q: &[f64], ps: &[f64]) -> Result<(f64, f64)> {
        let n2 = 2 * self.d;
        let a = self.state(q, ps)?;
        let ev = eigenvalues(&a, n2).ok_or(Error::Eigen(
            "state matrix eigenvalues did not converge".into(),
        ))?;
        let mut best = (f64::INFINITY, 0.0);
        for i in 0..ev.len() {
            for j in i + 1..ev.len() {
                let s = (ev[i].0 + ev[j].0).hypot(ev[i].1 + ev[j].1);
                if s < best.0 {
                    best = (s, ev[i].0 * ev[j].0 - ev[i].1 * ev[j].1);
                }
            }
        }
        let kappa = best.1;
        Ok((kappa, if kappa > 0.0 { kappa.sqrt() } else { f64::NAN }))
    }

    /// The bordered determinant `det [[F_x, F_p], [t^T]]` (one parameter).
    fn bordered_det(&mut self, x: &[f64], p: f64, t: &[f64]) -> Result<f64> {
        let y: Vec<f64> = x.iter().copied().chain([p]).collect();
        let (m, _) = bordered(self, &y, t)?;
        Ok(m.lu().determinant())
    }
}

impl EqSystem<'static, Planar> {
    /// The family of the balancer `base` in the disk's units, in its parameters `names` (one
    /// or two of [`crate::model::disk_units::DISK_UNITS_PARAMS`]): the planar model is rebuilt from those values at
    /// every point, so that `m0` moves `mu`, `eta`, `Omega`, `zeta` and `zeta_b` together.
    /// Unknowns and coordinates stay the model's.
    pub fn disk_units(base: DiskUnits, names: &[&str]) -> Result<Self> {
        if names.is_empty() || names.len() > 2 {
            return Err(Error::param("parameter", "one or two parameters"));
        }
        let p0 = base.param_value(names[0])?;
        for n in names {
            base.param_value(n)?;
        }
        let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
        let make: Maker<'static, Planar> = Box::new(move |ps: &[f64]| {
            let mut s = base;
            for (n, v) in names.iter().zip(ps) {
                s = s.with_param(n, *v)?;
            }
            s.planar()
        });
        let p = base.planar()?;
        Ok(Self::new(make, p.ndof(), p.first_ball(), p0))
    }
}

impl<'a, D: Dynamics + Clone> Problem for EqSystem<'a, D> {
    fn size(&self) -> usize {
        self.n()
    }
    fn param(&self) -> f64 {
        self.p0
    }
    fn residual(&mut self, x: &[f64], p: f64, r: &mut [f64]) -> Result<()> {
        self.eval(x, &[p], r)
    }
    fn jac_x(&mut self, x: &[f64], p: f64, r: &mut [f64], jac: &mut [f64]) -> Result<()> {
        self.eval_jac(x, &[p], r, jac)
    }
}

impl<'a, D: Dynamics + Clone> TwoParameter for EqSystem<'a, D> {
    fn size(&self) -> usize {
        self.n()
    }
    fn residual(&mut self, x: &[f64], p: [f64; 2], r: &mut [f64]) -> Result<()> {
        self.eval(x, &p, r)
    }
    fn jac_x(&mut self, x: &[f64], p: [f64; 2], r: &mut [f64], jac: &mut [f64]) -> Result<()> {
        self.eval_jac(x, &p, r, jac)
    }
}

/// Largest state dimension whose Hopf test is the bialternate determinant (a
/// `n(n-1)/2` square matrix); beyond it, the same product from the eigenvalues.
const BIALTERNATE_MAX: usize = 20;

/// `det(2A (.) I)` for the row-major `n x n` `A`: the matrix on pairs `(p, q)`, `p > q`,
/// whose eigenvalues are `l_p + l_q` (Govaerts, *Numerical Methods for Bifurcations
/// of Dynamical Equilibria*, 2000, sec. 4.4).
pub fn bialternate(a: &[f64], n: usize) -> DMatrix<f64> {
    let idx: Vec<(usize, usize)> = (1..n).flat_map(|p| (0..p).map(move |q| (p, q))).collect();
    let m = idx.len();
    let at = |i: usize, j: usize| a[i * n + j];
    DMatrix::from_fn(m, m, |i, j| {
        let (p, q) = idx[i];
        let (r, s) = idx[j];
        if r == q {
            -at(p, s)
        } else if r != p && s == q {
            at(p, r)
        } else if r == p && s == q {
            at(p, p) + at(q, q)
        } else if r == p && s != q {
            at(q, s)
        } else if s == p {
            -at(q, r)
        } else {
            0.0
        }
    })
}

fn bialternate_det(a: &[f64], n: usize) -> f64 {
    bialternate(a, n).lu().determinant()
}

/// The number of singular values of the row-major `d x d` `k` below `1e-5` times the
/// largest (the tolerance of the zero-eigenvalue count at a located point).
fn kernel_dim(k: &[f64], d: usize) -> usize {
    let sv = DMatrix::from_row_slice(d, d, k).singular_values();
    let big = sv.iter().copied().fold(0.0, f64::max);
    sv.iter().filter(|&&v| v <= 1e-5 * big).count()
}

/// `prod_{i<j} (l_i + l_j)` from the eigenvalues (real for a real matrix).
fn pair_sum_product(ev: &[(f64, f64)]) -> f64 {
    let (mut re, mut im) = (1.0f64, 0.0f64);
    for i in 0..ev.len() {
        for j in i + 1..ev.len() {
            let (a, b) = (ev[i].0 + ev[j].0, ev[i].1 + ev[j].1);
            (re, im) = (re * a - im * b, re * b + im * a);
        }
    }
    re
}

/// The kind of an equilibrium by its shape: the balls together, the rotor at rest on
/// the axis (perfect balance), two balls opposite, or else unbalanced; a branch that
/// started as `Balanced` (ball springs) stays so.
pub fn kind_of(q: &[f64], o: usize, start: EquilibriumKind) -> EquilibriumKind {
    if start == EquilibriumKind::Balanced {
        return start;
    }
    let n = q.len() - o;
    if n >= 2 && q[o + 1..].iter().all(|&b| wrap(b - q[o]).abs() < 1e-7) {
        return EquilibriumKind::Together;
    }
    if q[..o].iter().all(|v| v.abs() < 1e-7) {
        return EquilibriumKind::PerfectBalance;
    }
    if n == 2 && (wrap(q[o] - q[o + 1]).abs() - PI).abs() < 1e-7 {
        return EquilibriumKind::Opposite;
    }
    if n == 1 {
        return crate::analysis::equilibria::one_ball_kind(q[o]);
    }
    EquilibriumKind::Unbalanced
}

/// Options of [`branch`] and [`curve`].
#[derive(Debug, Clone)]
pub struct EqOptions {
    pub arc: ArcOptions,
    /// Whether a perfect balance of three or more free balls is a family (see
    /// [`analyse_model`]).
    pub family: bool,
    /// Arclength tolerance of event location.
    pub locate_tol: f64,
    /// User points and stop conditions of a branch (curves ignore them); a stop event
    /// must be one an equilibrium branch locates ([`EQ_STOP_EVENTS`]).
    pub controls: Controls,
}

/// The events an equilibrium branch can be asked to stop at.
pub const EQ_STOP_EVENTS: [Event; 4] = [Event::Fold, Event::BranchPoint, Event::Hopf, Event::User];

impl Default for EqOptions {
    fn default() -> Self {
        EqOptions {
            arc: ArcOptions::default(),
            family: true,
            locate_tol: 1e-11,
            controls: Controls::default(),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventKind {
    Fold,
    Hopf,
    BranchPoint,
    /// A point at a parameter value the user asked for ([`Controls::at`]).
    User,
}

impl EventKind {
    /// The event in the one vocabulary of all branches.
    pub fn event(self) -> Event {
        match self {
            EventKind::Fold => Event::Fold,
            EventKind::Hopf => Event::Hopf,
            EventKind::BranchPoint => Event::BranchPoint,
            EventKind::User => Event::User,
        }
    }

    pub fn as_str(&self) -> &'static str {
        self.event().name()
    }
}

/// One point of a branch.
#[derive(Debug, Clone)]
pub struct EqPoint {
    pub p: f64,
    /// Coordinates as continued (angles not wrapped).
    pub x: Vec<f64>,
    pub tangent: Vec<f64>,
    pub eq: Equilibrium,
    /// Test functions: `dp/ds`, the branch point's, the Hopf one.
    pub fold: f64,
    pub bp: f64,
    pub hopf: f64,
}

/// A located event.
#[derive(Debug, Clone)]
pub struct EqEvent {
    pub kind: EventKind,
    /// The branch row after which... the row of the first point past the event.
    pub row: usize,
    pub p: f64,
    pub x: Vec<f64>,
    pub tangent: Vec<f64>,
    pub eq: Equilibrium,
    /// The event's test function at the located point.
    pub test: f64,
    /// The Hopf frequency (`NaN` for other events).
    pub omega: f64,
}

#[derive(Debug, Clone)]
pub struct EqBranch {
    pub points: Vec<EqPoint>,
    pub events: Vec<EqEvent>,
    /// Why the branch ended (for [`branch_both_ways`]: the half towards increasing `p`).
    pub stop: ArcStop,
    /// For [`branch_both_ways`]: why the half towards decreasing `p` ended.
    pub stop_back: Option<ArcStop>,
}

/// Real parts below this count as on the axis, not unstable: neutral directions of a
/// family sit at round-off from zero and must not look like crossings.
const UNSTABLE_TOL: f64 = 1e-7;

/// What the step control reads of an equilibrium's eigenvalues: those with a positive
/// real part, and the real part of the complex eigenvalue nearest the imaginary axis.
fn spectrum_of(eq: &Equilibrium) -> Spectrum {
    let unstable = eq
        .eigenvalues
        .iter()
        .filter(|(re, _)| *re > UNSTABLE_TOL)
        .count();
    let pair = eq
        .eigenvalues
        .iter()
        .filter(|(_, im)| im.abs() > UNSTABLE_TOL)
        .map(|(re, _)| *re)
        .fold(f64::NAN, |m, re| {
            if re.abs() < m.abs() || m.is_nan() {
                re
            } else {
                m
            }
        });
    Spectrum { unstable, pair }
}

fn analyse_at<D: Dynamics + Clone>(
    sys: &mut EqSystem<'_, D>,
    x: &[f64],
    p: f64,
    start: EquilibriumKind,
    family: bool,
) -> Result<Equilibrium> {
    let q = sys.full(x);
    let o = sys.o;
    let kind = kind_of(&q, o, start);
    Ok(analyse_model(sys.model(&[p])?, &q, kind, family))
}

/// The declared tests of an equilibrium branch, in [`EqTests::NAMES`]' order: `dp/ds`
/// (fold), the branch point's (the bordered determinant, or on the together subspace
/// the transverse stiffness), the bialternate Hopf test.
struct EqTests {
    start: EquilibriumKind,
    family: bool,
}

/// A row of an equilibrium branch as the loop keeps it.
struct EqRow {
    arc: ArcPoint,
    /// Whether the point is balls-together (its branch-point test is the transverse
    /// stiffness).
    together: bool,
    point: EqPoint,
    spectrum: Spectrum,
}

impl EqTests {
    const NAMES: [&'static str; 3] = ["fold", "branch_point", "hopf"];
    const KINDS: [EventKind; 3] = [EventKind::Fold, EventKind::BranchPoint, EventKind::Hopf];

    fn together<D: Dynamics + Clone>(&self, sys: &EqSystem<'_, D>, pt: &ArcPoint) -> bool {
        kind_of(&sys.full(&pt.x), sys.o, self.start) == EquilibriumKind::Together
    }

    fn all<D: Dynamics + Clone>(
        sys: &mut EqSystem<'_, D>,
        pt: &ArcPoint,
        together: bool,
    ) -> Result<[f64; 3]> {
        let q = sys.full(&pt.x);
        let bp = if together {
            sys.transverse(&q, &[pt.p])?
        } else {
            sys.bordered_det(&pt.x, pt.p, &pt.tangent)?
        };
        Ok([pt.dp_ds(), bp, sys.hopf_test(&q, &[pt.p])?])
    }
}

impl<'a, D: Dynamics + Clone> Declared<EqSystem<'a, D>> for EqTests {
    type Point = EqRow;
    type Event = EqEvent;

    fn names(&self) -> &'static [&'static str] {
        &Self::NAMES
    }

    fn point(&mut self, sys: &mut EqSystem<'a, D>, pt: &ArcPoint) -> Result<EqRow> {
        let together = self.together(sys, pt);
        let [fold, bp, hopf] = Self::all(sys, pt, together)?;
        let eq = analyse_at(sys, &pt.x, pt.p, self.start, self.family)?;
        let spectrum = spectrum_of(&eq);
        Ok(EqRow {
            arc: pt.clone(),
            together,
            point: EqPoint {
                p: pt.p,
                x: pt.x.clone(),
                tangent: pt.tangent.clone(),
                eq,
                fold,
                bp,
                hopf,
            },
            spectrum,
        })
    }

    fn arc<'p>(&self, row: &'p EqRow) -> &'p ArcPoint {
        &row.arc
    }

    fn values(&self, row: &EqRow) -> Vec<Option<f64>> {
        let p = &row.point;
        vec![Some(p.fold), Some(p.bp), Some(p.hopf)]
    }

    fn spectrum(&self, row: &EqRow) -> Option<Spectrum> {
        Some(row.spectrum)
    }

    fn value_at(
        &mut self,
        sys: &mut EqSystem<'a, D>,
        a: &EqRow,
        pt: &ArcPoint,
        i: usize,
    ) -> Result<f64> {
        Ok(Self::all(sys, pt, a.together)?[i])
    }

    fn values_at(
        &mut self,
        sys: &mut EqSystem<'a, D>,
        b: &EqRow,
        pt: &ArcPoint,
    ) -> Result<Vec<Option<f64>>> {
        Ok(Self::all(sys, pt, b.together)?.map(Some).to_vec())
    }

    fn comparable(&self, a: &EqRow, b: &EqRow) -> bool {
        a.together == b.together
    }

    fn watched(&self, a: &EqRow, b: &EqRow) -> Vec<usize> {
        let (va, vb) = (
            <Self as Declared<EqSystem<'a, D>>>::values(self, a),
            <Self as Declared<EqSystem<'a, D>>>::values(self, b),
        );
        // The branch-point function changes with the kind on a switched branch.
        (0..3)
            .filter(|&i| i != 1 || a.together == b.together)
            .filter(|&i| matches!((va[i], vb[i]), (Some(x), Some(y)) if x * y < 0.0))
            .collect()
    }

    fn event(
        &mut self,
        s: &mut EqSystem<'a, D>,
        i: usize,
        e: &ArcPoint,
        g: f64,
        row: usize,
    ) -> Result<Option<EqEvent>> {
        let kind = Self::KINDS[i];
        let q = s.full(&e.x);
        let omega = if kind == EventKind::Hopf {
            let (kappa, om) = s.critical_pair(&q, &[e.p])?;
            if kappa <= 0.0 {
                // a neutral saddle: not a bifurcation
                return Ok(None);
            }
            om
        } else {
            f64::NAN
        };
        let eq = analyse_at(s, &e.x, e.p, self.start, self.family)?;
        Ok(Some(EqEvent {
            kind,
            row,
            p: e.p,
            x: e.x.clone(),
            tangent: e.tangent.clone(),
            eq,
            test: g,
            omega,
        }))
    }

    /// A Hopf point moves two eigenvalues across the axis, a fold or branch point one.
    fn moves(&self, e: &EqEvent) -> usize {
        match e.kind {
            EventKind::Hopf => 2,
            EventKind::Fold | EventKind::BranchPoint => 1,
            EventKind::User => 0,
        }
    }

    fn kind(&self, e: &EqEvent) -> &'static str {
        e.kind.as_str()
    }

    /// The user point's test is its parameter's distance from the value asked for: 0.
    fn user(
        &mut self,
        s: &mut EqSystem<'a, D>,
        e: &ArcPoint,
        row: usize,
    ) -> Result<Option<EqEvent>> {
        let eq = analyse_at(s, &e.x, e.p, self.start, self.family)?;
        Ok(Some(EqEvent {
            kind: EventKind::User,
            row,
            p: e.p,
            x: e.x.clone(),
            tangent: e.tangent.clone(),
            eq,
            test: 0.0,
            omega: f64::NAN,
        }))
    }
}

/// Continues the equilibrium `x0` (full coordinates) at `p0` of the one-parameter
/// family `sys`, locating folds, Hopf points and branch points between points
/// ([`crate::continuation::branch`], with its step control against events hidden in a
/// step). `start` is the start's kind (kinds along the branch are judged by shape, see
/// [`kind_of`]); `direction` (in `(x, p)`) orients the first tangent, as at a switch.
pub fn branch<D: Dynamics + Clone>(
    sys: &mut EqSystem<'_, D>,
    x0: &[f64],
    p0: f64,
    start: EquilibriumKind,
    direction: Option<Vec<f64>>,
    opts: &EqOptions,
) -> Result<EqBranch> {
    if sys.reduced {
        return Err(Error::param(
            "start",
            "a branch is continued on full coordinates",
        ));
    }
    if !(opts.locate_tol > 0.0) {
        return Err(Error::param("locate_tol", "must be positive"));
    }
    check_stop_events(&opts.controls, &EQ_STOP_EVENTS)?;
    if !(opts.arc.p_min <= p0 && p0 <= opts.arc.p_max) {
        return Err(Error::param(
            "range",
            format!(
                "must contain the start's value {p0}, got ({}, {})",
                opts.arc.p_min, opts.arc.p_max
            ),
        ));
    }
    let mut tests = EqTests {
        start,
        family: opts.family,
    };
    let from = Start {
        x: x0,
        p: p0,
        direction,
    };
    let run = continuation::branch(
        sys,
        from,
        &opts.arc,
        opts.locate_tol,
        &opts.controls,
        &mut tests,
    )?;
    let stop = run.stop;
    if run.points.is_empty() {
        return Err(Error::param(
            "start",
            match &stop {
                ArcStop::Failed(why) => format!("no branch from the start at {p0}: {why}"),
                other => {
                    format!("the start does not converge to an equilibrium at {p0}: {other:?}")
                }
            },
        ));
    }
    Ok(EqBranch {
        points: run.points.into_iter().map(|r| r.point).collect(),
        events: run.events,
        stop,
        stop_back: None,
    })
}

/// [`branch`] both ways from the start (`opts.arc.forward` ignored): the rows run from
/// the end reached towards decreasing `p` to the end reached towards increasing `p`, the
/// start once, as one branch: the backward half's tangents, and the test functions that
/// depend on their orientation (`dp/ds`, the bordered determinant), are reversed, and
/// the events' `row`s renumbered.
pub fn branch_both_ways<D: Dynamics + Clone>(
    sys: &mut EqSystem<'_, D>,
    x0: &[f64],
    p0: f64,
    start: EquilibriumKind,
    opts: &EqOptions,
) -> Result<EqBranch> {
    let mut o = opts.clone();
    o.arc.forward = false;
    let mut back = branch(sys, x0, p0, start, None, &o)?;
    o.arc.forward = true;
    let fwd = branch(sys, x0, p0, start, None, &o)?;
    let neg = |v: &mut Vec<f64>| v.iter_mut().for_each(|t| *t = -*t);
    for pt in &mut back.points {
        neg(&mut pt.tangent);
        pt.fold = -pt.fold;
        if pt.eq.kind != EquilibriumKind::Together {
            pt.bp = -pt.bp;
        }
    }
    for e in &mut back.events {
        neg(&mut e.tangent);
        let oriented = match e.kind {
            EventKind::Fold => true,
            EventKind::BranchPoint => e.eq.kind != EquilibriumKind::Together,
            EventKind::Hopf | EventKind::User => false,
        };
        if oriented {
            e.test = -e.test;
        }
    }
    let (points, events) = join_halves(
        (back.points, back.events),
        (fwd.points, fwd.events),
        |e: &mut EqEvent| &mut e.row,
    );
    Ok(EqBranch {
        points,
        events,
        stop: fwd.stop,
        stop_back: Some(back.stop),
    })
}

/// The direction of the other branch through the branch point `(x, p)` reached along
/// `tangent`: the null space of `[F_x, F_p]` is two-dimensional there; the unit vector
/// in it orthogonal to the incoming tangent, its largest component made positive.
pub fn switch_direction<D: Dynamics + Clone>(
    sys: &mut EqSystem<'_, D>,
    x: &[f64],
    p: f64,
    tangent: &[f64],
) -> Result<Vec<f64>> {
    let n = Problem::size(sys);
    let (mut r, mut j) = (vec![0.0; n], vec![0.0; n * n]);
    sys.eval_jac(x, &[p], &mut r, &mut j)?;
    let mut fp = vec![0.0; n];
    Problem::jac_p(sys, x, p, &mut fp)?;
    // Padded square so that the SVD returns all n + 1 right singular vectors.
    let m = DMatrix::from_fn(n + 1, n + 1, |i, k| {
        if i < n {
            if k < n {
                j[i * n + k]
            } else {
                fp[i]
            }
        } else {
            0.0
        }
    });
    let svd = m
        .try_svd(
            false,
            true,
            f64::EPSILON,
            crate::numerics::linalg::SVD_MAX_ITER,
        )
        .ok_or(Error::Eigen("SVD did not converge".into()))?;
    let vt = svd.v_t.ok_or(Error::Eigen("SVD failed".into()))?;
    let mut order: Vec<usize> = (0..n + 1).collect();
    order.sort_by(|&a, &b| svd.singular_values[a].total_cmp(&svd.singular_values[b]));
    let v1: Vec<f64> = vt.row(order[0]).iter().copied().collect();
    let v2: Vec<f64> = vt.row(order[1]).iter().copied().collect();
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let (c1, c2) = (dot(tangent, &v1), dot(tangent, &v2));
    let mut phi: Vec<f64> = v1.iter().zip(&v2).map(|(a, b)| c2 * a - c1 * b).collect();
    let norm = dot(&phi, &phi).sqrt();
    if !(norm > 1e-12) {
        return Err(Error::param("event", "no second direction at this point"));
    }
    let big = phi
        .iter()
        .copied()
        .max_by(|a, b| a.abs().total_cmp(&b.abs()))
        .unwrap_or(1.0);
    let s = big.signum() / norm;
    phi.iter_mut().for_each(|v| *v *= s);
    Ok(phi)
}

/// The branch through the branch point `(x, p)` other than the one reached along
/// `tangent`: a first point at arclength `opts.arc.ds` along [`switch_direction`],
/// then [`branch`] from it.
pub fn switch<D: Dynamics + Clone>(
    sys: &mut EqSystem<'_, D>,
    x: &[f64],
    p: f64,
    tangent: &[f64],
    opts: &EqOptions,
) -> Result<EqBranch> {
    let phi = switch_direction(sys, x, p, tangent)?;
    let from = ArcPoint {
        x: x.to_vec(),
        p,
        tangent: phi.clone(),
        ds: 0.0,
        iterations: 0,
        residual: 0.0,
        det_sign: 0.0,
    };
    let mut ds = opts.arc.ds;
    let first = loop {
        if let Some(pt) = point_at(sys, &from, ds, &opts.arc)? {
            break pt;
        }
        ds *= 0.5;
        if ds < opts.arc.ds_min {
            return Err(Error::param(
                "event",
                "the corrector fails on the new branch next to the branch point",
            ));
        }
    };
    let q = sys.full(&first.x);
    let start = kind_of(&q, sys.o, EquilibriumKind::Unbalanced);
    branch(sys, &first.x, first.p, start, Some(first.tangent), opts)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CurveKind {
    /// Saddle-node (fold) of equilibria.
    Fold,
    Hopf,
    /// Pitchfork of the balls-together branch.
    Pitchfork,
}

impl CurveKind {
    pub fn as_str(&self) -> &'static str {
        match self {
            CurveKind::Fold => "saddle_node",
            CurveKind::Hopf => "hopf",
            CurveKind::Pitchfork => "pitchfork",
        }
    }
}

/// One point of a two-parameter curve.
#[derive(Debug, Clone)]
pub struct CurvePoint {
    pub p: [f64; 2],
    /// Full coordinates.
    pub q: Vec<f64>,
    pub eq: Equilibrium,
    /// Hopf frequency on a Hopf curve, else `NaN`.
    pub omega: f64,
    /// The curve's own test function (normalised), zero on it to the tolerance.
    pub g: f64,
}

/// A codimension-two point on a curve.
#[derive(Debug, Clone)]
pub struct Codim2 {
    /// `"BT"` (a double zero eigenvalue with a Jordan block: Bogdanov–Takens), `"ZH"`
    /// (zero-Hopf), `"cusp"`, `"pitchfork"` / `"saddle_node"` (the curve meets that
    /// curve: for two balls at `(Omega, eta) = (1, 1/2)`, where the saddle-node and the
    /// pitchfork share a double zero across the together subspace).
    pub kind: &'static str,
    pub p: [f64; 2],
    pub q: Vec<f64>,
    /// The row of the first curve point past it.
    pub row: usize,
}

#[derive(Debug, Clone)]
pub struct EqCurve {
    pub kind: CurveKind,
    pub points: Vec<CurvePoint>,
    pub special: Vec<Codim2>,
    /// Why each half ended: towards decreasing, then increasing second parameter.
    pub stop: [ArcStop; 2],
}

struct CurveTest {
    kind: CurveKind,
    scale: f64,
}

impl<'a, D: Dynamics + Clone> crate::continuation::curves::TestFunction<EqSystem<'a, D>>
    for CurveTest
{
    fn value(&mut self, s: &mut EqSystem<'a, D>, x: &[f64], p: [f64; 2]) -> Result<f64> {
        raw_curve_test(self.kind, s, x, &p).map(|g| g * self.scale)
    }
}

fn raw_curve_test<D: Dynamics + Clone>(
    kind: CurveKind,
    s: &mut EqSystem<'_, D>,
    x: &[f64],
    p: &[f64],
) -> Result<f64> {
    match kind {
        CurveKind::Fold => s.det_jac(x, p),
        CurveKind::Hopf => {
            let q = s.full(x);
            s.hopf_test(&q, p)
        }
        CurveKind::Pitchfork => {
            let q = s.full(x);
            s.transverse(&q, p)
        }
    }
}

/// The scalar tests watched along a curve for codimension-two points.
fn codim_tests<D: Dynamics + Clone>(
    kind: CurveKind,
    s: &mut EqSystem<'_, D>,
    x: &[f64],
    p: [f64; 2],
) -> Result<Vec<(&'static str, f64)>> {
    let q = s.full(x);
    let mut out = vec![];
    match kind {
        CurveKind::Fold => {
            out.push(("hopf_test", s.hopf_test(&q, &p)?));
            if s.reduced {
                out.push(("pitchfork", s.transverse(&q, &p)?));
            }
        }
        CurveKind::Hopf => {
            out.push(("BT", s.critical_pair(&q, &p)?.0));
            out.push(("ZH", s.det_jac(x, &p)?));
        }
        CurveKind::Pitchfork => {
            // the pitchfork curve meets the saddle-node curve (see `kernel_dim`)
            out.push(("saddle_node", s.det_jac(x, &p)?));
            out.push(("hopf_test", s.hopf_test(&q, &p)?));
        }
    }
    Ok(out)
}

/// Continues the curve of `kind` bifurcations through `(q, p1)` at `p2` of the
/// two-parameter family `sys` (on the together subspace for a pitchfork; for the fold of
/// a together branch, preferably so too), `opts.arc`'s window bounding `p2`, both ways
/// from the start: the rows run from the end reached towards decreasing `p2` to the
/// end reached towards increasing `p2`.
pub fn curve<D: Dynamics + Clone>(
    sys: EqSystem<'_, D>,
    kind: CurveKind,
    q: &[f64],
    p1: f64,
    p2: f64,
    opts: &EqOptions,
) -> Result<EqCurve> {
    if kind == CurveKind::Pitchfork && !sys.reduced {
        return Err(Error::param(
            "event",
            "pitchfork curves are continued on the together subspace",
        ));
    }
    if !(opts.arc.p_min <= p2 && p2 <= opts.arc.p_max) {
        return Err(Error::param(
            "range",
            format!(
                "must contain the second parameter's value {p2}, got ({}, {})",
                opts.arc.p_min, opts.arc.p_max
            ),
        ));
    }
    let x0 = sys.reduce(q);
    let mut ext = Extended::new(sys, CurveTest { kind, scale: 1.0 }, p2);
    // Normalise g by its gradient at the start: then |g| is about the distance from the
    // curve, and the corrector's tolerance applies to it as to F.
    let n = x0.len();
    let mut y0 = x0.clone();
    y0.push(p1);
    let mut grad2 = 0.0;
    for j in 0..n + 2 {
        let h = 1e-6 * (1.0 + if j < n + 1 { y0[j] } else { p2 }.abs());
        let (mut yp, mut ym) = (y0.clone(), y0.clone());
        let (mut pp, mut pm) = (p2, p2);
        if j < n + 1 {
            yp[j] += h;
            ym[j] -= h;
        } else {
            pp += h;
            pm -= h;
        }
        let gp = raw_curve_test(kind, &mut ext.system, &yp[..n], &[yp[n], pp])?;
        let gm = raw_curve_test(kind, &mut ext.system, &ym[..n], &[ym[n], pm])?;
        grad2 += ((gp - gm) / (2.0 * h)).powi(2);
    }
    if !(grad2 > 0.0 && grad2.is_finite()) {
        return Err(Error::param(
            "event",
            "the test function is flat at the start: not a regular bifurcation point",
        ));
    }
    ext.test.scale = 1.0 / grad2.sqrt();
    let mut hook = EqCurveHook {
        kind,
        n,
        family: opts.family,
    };
    let whole = both_halves(
        &opts.arc,
        |arc| curve_half(&mut ext, &y0, p2, arc, opts.locate_tol, &mut hook),
        |c: &mut Codim2| &mut c.row,
    )?;
    Ok(EqCurve {
        kind,
        points: whole.points,
        special: whole.special,
        stop: whole.stop,
    })
}

/// The equilibrium side of the curve loop: codimension-two tests, their located points
/// (a Hopf test's zero told apart into Bogdanov–Takens, zero-Hopf or neither), and each
/// point's equilibrium with its stability.
struct EqCurveHook {
    kind: CurveKind,
    n: usize,
    family: bool,
}

type EqExtended<'a, D> = Extended<EqSystem<'a, D>, CurveTest>;

impl<'a, D: Dynamics + Clone> CurveHook<EqExtended<'a, D>> for EqCurveHook {
    type Point = CurvePoint;
    type Special = Codim2;

    fn n(&self) -> usize {
        self.n
    }

    fn tests(
        &mut self,
        e: &mut EqExtended<'a, D>,
        pt: &ArcPoint,
    ) -> Result<Vec<(&'static str, f64)>> {
        let n = self.n;
        codim_tests(self.kind, &mut e.system, &pt.x[..n], [pt.x[n], pt.p])
    }

    fn cusp(&self) -> Option<&'static str> {
        Some("cusp")
    }

    fn special(
        &mut self,
        e: &mut EqExtended<'a, D>,
        label: &'static str,
        at: &ArcPoint,
        row: usize,
    ) -> Result<Option<Codim2>> {
        let n = self.n;
        let s = &mut e.system;
        let q = s.full(&at.x[..n]);
        let p = [at.x[n], at.p];
        let label = match label {
            "hopf_test" => {
                // the located zero of the Hopf test on a fold / pitchfork curve:
                // a double zero, a zero-Hopf point, or a neutral saddle (none)
                let (kappa, _) = s.critical_pair(&q, &p)?;
                let a = s.state(&q, &p)?;
                let ev = eigenvalues(&a, 2 * s.d).unwrap_or_default();
                let scale = ev.iter().map(|z| z.0.hypot(z.1)).fold(1.0, f64::max);
                let zeros = ev.iter().filter(|z| z.0.hypot(z.1) < 1e-5 * scale).count();
                if zeros >= 2 {
                    // Two zero eigenvalues with a two-dimensional kernel of K are two
                    // simultaneous zero-eigenvalue bifurcations, not a Bogdanov–Takens
                    // point (a Jordan block, a one-dimensional kernel): where the
                    // together branch's fold meets its pitchfork the second zero belongs
                    // to the antisymmetric ball mode, and the curve's other test flags
                    // the point.
                    let (k, _, _) = s.kcm(&q, &p)?;
                    if kernel_dim(&k, s.d) >= 2 {
                        return Ok(None);
                    }
                    "BT"
                } else if kappa > 0.0 {
                    "ZH"
                } else {
                    return Ok(None);
                }
            }
            other => other,
        };
        Ok(Some(Codim2 {
            kind: label,
            p,
            q,
            row,
        }))
    }

    fn point(
        &mut self,
        e: &mut EqExtended<'a, D>,
        pt: &ArcPoint,
        _tests: &[(&'static str, f64)],
    ) -> Result<CurvePoint> {
        let n = self.n;
        let p = [pt.x[n], pt.p];
        let s = &mut e.system;
        let q = s.full(&pt.x[..n]);
        let omega = if self.kind == CurveKind::Hopf {
            s.critical_pair(&q, &p)?.1
        } else {
            f64::NAN
        };
        let start_kind = if s.reduced {
            EquilibriumKind::Together
        } else {
            kind_of(&q, s.o, EquilibriumKind::Unbalanced)
        };
        let k = kind_of(&q, s.o, start_kind);
        let eq = analyse_model(s.model(&p)?, &q, k, self.family);
        let g = raw_curve_test(self.kind, s, &pt.x[..n], &p)? * e.test.scale;
        Ok(CurvePoint { p, q, eq, omega, g })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::equilibria::equilibria;
    use crate::Planar;

    fn planar(om: f64, eta: f64, zeta: f64) -> Planar {
        Planar::new(0.2, zeta, &[0.1], 50.0, om, &[eta, eta]).unwrap()
    }

    fn opts(lo: f64, hi: f64) -> EqOptions {
        EqOptions {
            arc: ArcOptions {
                ds: 0.01,
                ds_max: 0.05,
                max_points: 400,
                p_min: lo,
                p_max: hi,
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// Closed form of the together branch's saddle-node (derived in
    /// scripts/derive_saddle_node.py): (1 - Omega^2)^2 = 4 zeta^2 Omega^2 (4 eta^2 - 1).
    fn eta_fold(om: f64, zeta: f64) -> f64 {
        (0.25 + (1.0 - om * om).powi(2) / (16.0 * zeta * zeta * om * om)).sqrt()
    }

    #[test]
    fn bialternate_eigenvalues_are_pair_sums() {
        let a = [
            0.3, -1.2, 0.5, 0.1, 2.0, -0.4, 0.7, -0.3, -0.5, 0.2, -1.1, 0.9, 0.05, 1.3, -0.6, 0.2,
        ];
        let ev = eigenvalues(&a, 4).unwrap();
        let b = bialternate(&a, 4);
        let evb = eigenvalues(b.transpose().as_slice(), 6).unwrap();
        for i in 0..4 {
            for j in i + 1..4 {
                let s = (ev[i].0 + ev[j].0, ev[i].1 + ev[j].1);
                assert!(
                    evb.iter()
                        .any(|z| (z.0 - s.0).abs() < 1e-10 && (z.1 - s.1).abs() < 1e-10),
                    "{s:?} not in {evb:?}"
                );
            }
        }
        let prod = pair_sum_product(&ev);
        let det = bialternate_det(&a, 4);
        assert!(
            (prod - det).abs() < 1e-10 * det.abs().max(1.0),
            "{prod} {det}"
        );
    }

    #[test]
    fn together_branch_in_eta_has_the_pitchfork_and_the_fold() {
        let (om, zeta) = (1.05, 0.05);
        let p = planar(om, 0.3, zeta);
        let start = equilibria(&p)
            .into_iter()
            .find(|e| e.kind == EquilibriumKind::Together)
            .unwrap();
        let mut sys = EqSystem::family(&p, &["eta"]).unwrap();
        let br = branch(
            &mut sys,
            &start.q,
            0.3,
            EquilibriumKind::Together,
            None,
            &opts(0.2, 1.0),
        )
        .unwrap();
        let bp: Vec<_> = br
            .events
            .iter()
            .filter(|e| e.kind == EventKind::BranchPoint)
            .collect();
        let fold: Vec<_> = br
            .events
            .iter()
            .filter(|e| e.kind == EventKind::Fold)
            .collect();
        assert!(!bp.is_empty() && !fold.is_empty(), "{:?}", br.events);
        assert!((bp[0].p - 0.5).abs() < 1e-9, "{}", bp[0].p);
        assert!(
            (fold[0].p - eta_fold(om, zeta)).abs() < 1e-8,
            "{}",
            fold[0].p
        );
        // Switching at the pitchfork reaches the perfect balance, b = arccos(-1/(2 eta)).
        let ev = bp[0];
        let pb = switch(&mut sys, &ev.x, ev.p, &ev.tangent, &opts(0.2, 1.0)).unwrap();
        let last = pb.points.last().unwrap();
        assert_eq!(last.eq.kind, EquilibriumKind::PerfectBalance);
        let b = (-1.0 / (2.0 * last.p)).acos();
        assert!(
            (last.eq.q[2].abs() - b).abs() < 1e-8 && (last.eq.q[3].abs() - b).abs() < 1e-8,
            "{:?} at {}",
            last.eq.q,
            last.p
        );
    }

    #[test]
    fn saddle_node_curve_matches_the_closed_form() {
        let (om, zeta) = (1.05, 0.05);
        let p = planar(om, 0.3, zeta);
        let start = equilibria(&p)
            .into_iter()
            .find(|e| e.kind == EquilibriumKind::Together)
            .unwrap();
        let mut sys = EqSystem::family(&p, &["eta"]).unwrap();
        let br = branch(
            &mut sys,
            &start.q,
            0.3,
            EquilibriumKind::Together,
            None,
            &opts(0.2, 1.0),
        )
        .unwrap();
        let f = br
            .events
            .iter()
            .find(|e| e.kind == EventKind::Fold)
            .unwrap();
        let sys2 = EqSystem::family(&p, &["eta", "Omega"])
            .unwrap()
            .on_together()
            .unwrap();
        let mut o = opts(0.6, 1.6);
        o.arc.tol = 1e-12;
        let c = curve(sys2, CurveKind::Fold, &f.x, f.p, om, &o).unwrap();
        assert!(c.points.len() > 20, "{:?}", c.stop);
        let mut worst: f64 = 0.0;
        for pt in &c.points {
            worst = worst.max((pt.p[0] - eta_fold(pt.p[1], zeta)).abs());
        }
        assert!(worst < 1e-9, "{worst}");
        // The fold meets the pitchfork at (eta, Omega) = (1/2, 1): flagged once, as that
        // (the Hopf test vanishes there too, by the antisymmetric mode's zero).
        let at: Vec<_> = c
            .special
            .iter()
            .filter(|s| (s.p[0] - 0.5).abs() < 1e-6 && (s.p[1] - 1.0).abs() < 1e-6)
            .map(|s| s.kind)
            .collect();
        assert_eq!(at, ["pitchfork"], "{:?}", c.special);
    }

    #[test]
    fn a_branch_both_ways_is_one_branch_through_its_start() {
        let (om, zeta) = (1.05, 0.05);
        let p = planar(om, 0.6, zeta);
        let start = equilibria(&p)
            .into_iter()
            .find(|e| e.kind == EquilibriumKind::Together)
            .unwrap();
        let mut sys = EqSystem::family(&p, &["eta"]).unwrap();
        let br = branch_both_ways(
            &mut sys,
            &start.q,
            0.6,
            EquilibriumKind::Together,
            &opts(0.2, 1.0),
        )
        .unwrap();
        // both halves: the pitchfork (eta = 1/2) lies below the start, the fold above
        let bp = br
            .events
            .iter()
            .find(|e| e.kind == EventKind::BranchPoint)
            .unwrap();
        let fold = br
            .events
            .iter()
            .find(|e| e.kind == EventKind::Fold)
            .unwrap();
        assert!((bp.p - 0.5).abs() < 1e-9, "{}", bp.p);
        assert!((fold.p - eta_fold(om, zeta)).abs() < 1e-8, "{}", fold.p);
        assert!(br.stop_back.is_some());
        for e in &br.events {
            let (a, b) = (&br.points[e.row - 1], &br.points[e.row]);
            assert!((a.p - e.p) * (b.p - e.p) <= 0.0 || e.kind == EventKind::Fold);
        }
        // consecutive tangents agree in orientation along the rows
        for w in br.points.windows(2) {
            let d: f64 = w[0]
                .tangent
                .iter()
                .zip(&w[1].tangent)
                .map(|(a, b)| a * b)
                .sum();
            assert!(d > 0.0);
        }
        let i0 = br.points.iter().position(|q| q.p == 0.6).unwrap();
        assert_eq!(br.points.iter().filter(|q| q.p == 0.6).count(), 1);
        assert!(br.points[..i0]
            .iter()
            .all(|q| q.p < 0.6 || q.tangent[4] < 0.0));
    }

    #[test]
    fn perfect_balance_hopf_in_omega() {
        // Leading eigenvalues 0.0024 +- 0.09i at Omega 1.1, eta 1.3 (zeta = zeta_b = 0.1):
        // the perfect balance turns stable by a Hopf point as Omega grows.
        let p = Planar::new(0.2, 0.1, &[0.1], 50.0, 1.1, &[1.3, 1.3]).unwrap();
        let pb = equilibria(&p)
            .into_iter()
            .find(|e| e.kind == EquilibriumKind::PerfectBalance)
            .unwrap();
        let mut sys = EqSystem::family(&p, &["Omega"]).unwrap();
        let br = branch(
            &mut sys,
            &pb.q,
            1.1,
            EquilibriumKind::PerfectBalance,
            None,
            &opts(1.0, 1.5),
        )
        .unwrap();
        let h = br
            .events
            .iter()
            .find(|e| e.kind == EventKind::Hopf)
            .expect("hopf");
        let lead = h.eq.eigenvalues[0];
        assert!(lead.0.abs() < 1e-8, "{lead:?}");
        assert!(
            (lead.1.abs() - h.omega).abs() < 1e-8,
            "{lead:?} {}",
            h.omega
        );
        let mut sys2 = EqSystem::family(&p, &["Omega", "eta"]).unwrap();
        let _ = &mut sys2;
        let c = curve(sys2, CurveKind::Hopf, &h.x, h.p, 1.3, &opts(0.5, 1.5)).unwrap();
        assert!(
            c.points.len() > 10,
            "{:?} {:?}",
            c.stop,
            c.points.iter().map(|p| p.p).collect::<Vec<_>>()
        );
        for pt in &c.points {
            assert!(pt.eq.index.abs() < 1e-7, "{} at {:?}", pt.eq.index, pt.p);
        }
    }
}
