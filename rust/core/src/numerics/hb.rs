//! Periodic solutions by modified incremental harmonic balance (MIHB).
//!
//! Each coordinate is a truncated Fourier series in `tau = omega t` plus a secular term
//! `w_j tau` (`w_j = -1` for a ball that lags the disk by one turn per period, 0 for one
//! that oscillates). The Galerkin projection of the residual on `1, cos m tau, sin m tau`
//! is evaluated by alternating frequency–time sampling, and Newton iterates on the
//! coefficients and `omega` with an analytic Jacobian (chain rule through the model's
//! `K, C, M`), a faer LU and a backtracking line search. One extra equation fixes the
//! free time shift: `b_r(0) = 0` for the first rotating ball `r`, otherwise the
//! `sin tau` coefficient of `x` is zero (spec section 4).

use crate::continuation::Secant;
use crate::linalg::LuWork;
use crate::model::Dynamics;
use crate::model::Jacobians;
use crate::numerics::problem::{At, ModelAt, Problem};
use std::f64::consts::PI;
use std::sync::Arc;

/// Relative size of the harmonics below which a series without winding is an
/// equilibrium ([`Status::Equilibrium`]). On the nine Tien (2011) maps at N = 3 the series
/// Newton converged on in O-O scans had harmonics either between 0.1 and 10 (orbits) or of
/// 1e-16 to 1e-15 (equilibria, with pivot ratios of 1e8 to 3e10 because `omega` is
/// free); 1e-9 sits between with six decades to spare on either side.
pub const STILL: f64 = 1e-9;

/// Coefficient layout per coordinate: `[a_0, a_1, b_1, ..., a_N, b_N]`.
#[derive(Debug, Clone)]
pub struct Basis {
    pub n_harm: usize,
    pub samples: usize,
    /// Row-major `S x L` tables of the basis and its first two tau-derivatives.
    phi: Vec<f64>,
    dphi: Vec<f64>,
    ddphi: Vec<f64>,
    /// Galerkin weights `S x L`: basis times 1/S (mean) or 2/S (harmonics).
    wgt: Vec<f64>,
    tau: Vec<f64>,
    /// `phi, dphi, ddphi` transposed (`L x S`): sampling runs along the samples.
    phi_t: Vec<f64>,
    dphi_t: Vec<f64>,
    ddphi_t: Vec<f64>,
}

impl Basis {
    pub fn new(n_harm: usize, samples: usize) -> Self {
        let l = 2 * n_harm + 1;
        let s = samples;
        let mut phi = vec![0.0; s * l];
        let mut dphi = vec![0.0; s * l];
        let mut ddphi = vec![0.0; s * l];
        let mut wgt = vec![0.0; s * l];
        let mut tau = vec![0.0; s];
        for i in 0..s {
            let t = 2.0 * PI * i as f64 / s as f64;
            tau[i] = t;
            phi[i * l] = 1.0;
            wgt[i * l] = 1.0 / s as f64;
            for m in 1..=n_harm {
                let mf = m as f64;
                let (sn, cs) = (mf * t).sin_cos();
                let (c, sidx) = (i * l + 2 * m - 1, i * l + 2 * m);
                phi[c] = cs;
                phi[sidx] = sn;
                dphi[c] = -mf * sn;
                dphi[sidx] = mf * cs;
                ddphi[c] = -mf * mf * cs;
                ddphi[sidx] = -mf * mf * sn;
                wgt[c] = 2.0 * cs / s as f64;
                wgt[sidx] = 2.0 * sn / s as f64;
            }
        }
        let transpose = |a: &[f64]| -> Vec<f64> {
            let mut t = vec![0.0; s * l];
            for i in 0..s {
                for p in 0..l {
                    t[p * s + i] = a[i * l + p];
                }
            }
            t
        };
        Basis {
            n_harm,
            samples,
            phi_t: transpose(&phi),
            dphi_t: transpose(&dphi),
            ddphi_t: transpose(&ddphi),
            phi,
            dphi,
            ddphi,
            wgt,
            tau,
        }
    }

    /// Coefficients per coordinate, `2N + 1`.
    pub fn width(&self) -> usize {
        2 * self.n_harm + 1
    }
}

/// Default number of time samples per period for `N` harmonics: `8 (N + 1)` up to
/// N = 3 (at least 16), then `4 (N + 5)` (N = 8: 52, N = 12: 68).
///
/// The products and trigonometric functions in the equations reach beyond harmonic `N`,
/// and what lies beyond `S - N` aliases onto the retained harmonics. Four samples per
/// harmonic project products of three series exactly (`S > 4N`); the twenty more cover
/// the tails of the trigonometric terms: against a count where aliasing is at round-off,
/// the maps' solutions keep their verdicts, and omega and the multipliers move far less
/// than their truncation errors (docs/measurements.md, "Default samples per period").
/// Up to N = 3 the count is unchanged (scans at N = 3 keep every result); above it the
/// samples, and with them the residual, the Jacobian's sampling and the certificate,
/// grow half as fast with N.
pub fn default_samples(n_harm: usize) -> usize {
    (8 * (n_harm + 1)).min(4 * (n_harm + 5)).max(16)
}

/// Evaluates one coordinate's series and its tau-derivatives at `tau`.
pub fn eval_series(c: &[f64], w: f64, tau: f64) -> (f64, f64, f64) {
    eval_series_sc(c, w, tau, tau.sin_cos())
}

/// As [`eval_series`] with `sin tau, cos tau` supplied, so that several coordinates at
/// one phase share a single trigonometric call.
pub fn eval_series_sc(c: &[f64], w: f64, tau: f64, sc: (f64, f64)) -> (f64, f64, f64) {
    let (mut q, mut qt, mut qtt) = ([0.0], [0.0], [0.0]);
    eval_series_rows(c, &[w], tau, sc, &mut q, &mut qt, &mut qtt);
    (q[0], qt[0], qtt[0])
}

/// [`eval_series_sc`] for every coordinate of `coeffs` (one row of `2N + 1` per entry of
/// `winding`) into `q, qt, qtt`, with the harmonics outermost so that the rotation
/// recurrence (the same for every coordinate) runs once: the same operations on each
/// coordinate's sums in the same order as one coordinate alone, so the same values.
fn eval_series_rows(
    coeffs: &[f64],
    winding: &[f64],
    tau: f64,
    (s1, c1): (f64, f64),
    q: &mut [f64],
    qt: &mut [f64],
    qtt: &mut [f64],
) {
    let d = winding.len();
    let l = coeffs.len() / d;
    let n = (l - 1) / 2;
    let (q, qt, qtt) = (&mut q[..d], &mut qt[..d], &mut qtt[..d]);
    for j in 0..d {
        let w = winding[j];
        q[j] = coeffs[j * l] + w * tau;
        qt[j] = w;
        qtt[j] = 0.0;
    }
    let (mut sm, mut cm) = (0.0f64, 1.0f64);
    for m in 1..=n {
        // cos/sin of m tau by rotation recurrence: no trig call per harmonic.
        let (ns, nc) = (sm * c1 + cm * s1, cm * c1 - sm * s1);
        sm = ns;
        cm = nc;
        let mf = m as f64;
        for j in 0..d {
            let (a, b) = (coeffs[j * l + 2 * m - 1], coeffs[j * l + 2 * m]);
            q[j] += a * cm + b * sm;
            qt[j] += mf * (-a * sm + b * cm);
            qtt[j] -= mf * mf * (a * cm + b * sm);
        }
    }
}

/// Convergence status of a Newton–IHB solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    Converged,
    /// The residual could not be reduced, grew without bound, or omega left (0, inf).
    Diverged,
    /// The Jacobian was numerically singular.
    Singular,
    MaxIterations,
    /// No starting guess could be built (e.g. the simulation found no motion of this type).
    NoGuess,
    /// Newton converged, but the series is not an orbit: its ODE defect between the
    /// collocation times integrates to more than the allowed closure error
    /// ([`defect_closure`]).
    NotClosed,
    /// Newton converged, but the highest harmonic is too large relative to the motion
    /// ([`HbSolution::tail_ratio`]): `N` does not resolve the orbit.
    Truncated,
    /// Newton converged on a series that does not move: every coordinate's harmonics
    /// are at round-off ([`HbSolution::oscillation`]) and no ball winds, so the series
    /// is an equilibrium, which solves the equations at any `omega` — no periodic orbit
    /// and no frequency.
    Equilibrium,
    /// Newton converged on an orbit of a shorter period written several times over the
    /// period asked for (only its harmonics that are multiples of the balls' common
    /// winding are non-zero): the orbit the windings asked for, e.g. a period-doubled
    /// one, is not this ([`crate::periodic::is_repeated`]).
    Repeated,
}

impl Status {
    pub fn as_str(&self) -> &'static str {
        match self {
            Status::Converged => "converged",
            Status::Diverged => "diverged",
            Status::Singular => "singular",
            Status::MaxIterations => "max_iterations",
            Status::NoGuess => "no_guess",
            Status::NotClosed => "not_closed",
            Status::Truncated => "truncated",
            Status::Equilibrium => "equilibrium",
            Status::Repeated => "repeated",
        }
    }
}

#[derive(Debug, Clone)]
pub struct HbOptions {
    pub n_harm: usize,
    /// Time samples per period; `None` uses [`default_samples`].
    pub samples: Option<usize>,
    /// Max-norm of the harmonic-balance residual required for convergence.
    pub tol: f64,
    /// Max-norm of the last Newton step required for convergence.
    pub step_tol: f64,
    pub max_iter: usize,
}

impl Default for HbOptions {
    fn default() -> Self {
        HbOptions {
            n_harm: 3,
            samples: None,
            tol: 1e-10,
            step_tol: 1e-8,
            max_iter: 50,
        }
    }
}

impl HbOptions {
    pub fn validate(&self) -> crate::Result<()> {
        use crate::Error;
        if self.n_harm < 1 || self.n_harm > 256 {
            return Err(Error::param(
                "N",
                format!("must be in [1, 256], got {}", self.n_harm),
            ));
        }
        if let Some(s) = self.samples {
            let min = 2 * self.n_harm + 2;
            if s < min || s > 1 << 16 {
                return Err(Error::param(
                    "samples",
                    format!("must be in [{min}, 65536] (more than 2N + 1 to resolve N harmonics), got {s}"),
                ));
            }
        }
        if !(self.tol > 0.0 && self.tol.is_finite()) {
            return Err(Error::param(
                "tol",
                format!("must be a finite number > 0, got {}", self.tol),
            ));
        }
        if !(self.step_tol > 0.0 && self.step_tol.is_finite()) {
            return Err(Error::param(
                "step_tol",
                format!("must be a finite number > 0, got {}", self.step_tol),
            ));
        }
        if self.max_iter == 0 || self.max_iter > 10_000 {
            return Err(Error::param(
                "max_iter",
                format!("must be in [1, 10000], got {}", self.max_iter),
            ));
        }
        Ok(())
    }
}

/// A harmonic-balance solution (or the last iterate of a failed solve).
#[derive(Debug, Clone)]
pub struct HbSolution {
    pub omega: f64,
    /// Row-major `d x (2N+1)` coefficients.
    pub coeffs: Vec<f64>,
    /// Secular slope per coordinate (`-1` for a rotating ball).
    pub winding: Vec<f64>,
    pub n_harm: usize,
    pub samples: usize,
    pub residual: f64,
    pub step: f64,
    pub iterations: usize,
    pub status: Status,
    /// max |u_ii| / min |u_ii| of the last LU: lower bound of the condition number.
    pub pivot_ratio: f64,
}

impl HbSolution {
    /// An unsolved starting point (a guess, or an attempt that never started).
    pub fn start(
        omega: f64,
        coeffs: Vec<f64>,
        winding: Vec<f64>,
        n_harm: usize,
        status: Status,
    ) -> Self {
        HbSolution {
            omega,
            coeffs,
            winding,
            n_harm,
            samples: 0,
            residual: f64::NAN,
            step: f64::NAN,
            iterations: 0,
            status,
            pivot_ratio: f64::NAN,
        }
    }

    pub fn ndof(&self) -> usize {
        self.winding.len()
    }

    pub fn coord(&self, j: usize) -> &[f64] {
        let l = 2 * self.n_harm + 1;
        &self.coeffs[j * l..(j + 1) * l]
    }

    /// `q` and its rates in time, `dq/dt = omega dq/dtau`, `d2q/dt2 = omega^2 d2q/dtau2`,
    /// at phase `tau`: what the model's residual and Jacobians take along the orbit.
    pub fn eval_rates(&self, tau: f64, q: &mut [f64], v: &mut [f64], a: &mut [f64]) {
        self.eval(tau, q, v, a);
        let om = self.omega;
        v.iter_mut().for_each(|x| *x *= om);
        a.iter_mut().for_each(|x| *x *= om * om);
    }

    /// `q, dq/dtau, d2q/dtau2` at phase `tau`.
    pub fn eval(&self, tau: f64, q: &mut [f64], qt: &mut [f64], qtt: &mut [f64]) {
        eval_series_rows(&self.coeffs, &self.winding, tau, tau.sin_cos(), q, qt, qtt);
    }

    /// First-order state `(q, q')` at time `t` (in units of 1/w_n).
    pub fn state(&self, t: f64) -> Vec<f64> {
        let d = self.ndof();
        let (mut q, mut qt, mut qtt) = (vec![0.0; d], vec![0.0; d], vec![0.0; d]);
        self.eval(self.omega * t, &mut q, &mut qt, &mut qtt);
        q.extend(qt.iter().map(|v| v * self.omega));
        q
    }

    pub fn period(&self) -> f64 {
        2.0 * PI / self.omega
    }

    /// Magnitude of the highest retained harmonic over all coordinates: a truncation indicator.
    pub fn tail(&self) -> f64 {
        let n = self.n_harm;
        (0..self.ndof())
            .map(|j| {
                let c = self.coord(j);
                c[2 * n - 1].hypot(c[2 * n])
            })
            .fold(0.0, f64::max)
    }

    /// [`Self::tail`] relative to the support's first-harmonic amplitude (at least 1): a
    /// series whose last harmonic is as large as its motion has not resolved the orbit
    /// (such "solutions" appear where a rotating branch creeps towards omega = 0).
    /// The support is coordinates 0 and 1, as in every layout the core builds; with a
    /// model at hand, [`Self::tail_ratio_on`] its `layout().support()`.
    pub fn tail_ratio(&self) -> f64 {
        self.tail_ratio_on(crate::model::Layout::planar(0).support())
    }

    /// [`Self::tail_ratio`] relative to the motion of the coordinates `support`.
    pub fn tail_ratio_on(&self, support: [usize; 2]) -> f64 {
        let amp = support
            .into_iter()
            .map(|j| {
                let c = self.coord(j);
                c[1].hypot(c[2])
            })
            .fold(1.0, f64::max);
        self.tail() / amp
    }

    /// Largest harmonic coefficient (`a_m, b_m`, `m >= 1`) over the coordinates: how far
    /// the series moves apart from any winding.
    pub fn oscillation(&self) -> f64 {
        (0..self.ndof())
            .flat_map(|j| self.coord(j)[1..].iter())
            .fold(0.0, |m, v| m.max(v.abs()))
    }

    /// Whether the series is an equilibrium rather than an orbit: no coordinate winds
    /// and the harmonics are below [`STILL`] of the coordinates' size (at least 1).
    pub fn is_still(&self) -> bool {
        let size = (0..self.ndof())
            .map(|j| self.coord(j)[0].abs())
            .fold(1.0, f64::max);
        self.winding.iter().all(|w| *w == 0.0) && self.oscillation() <= STILL * size
    }

    /// The same solution with `n_harm` harmonics (truncated or zero-padded): a predictor.
    pub fn resized(&self, n_harm: usize) -> HbSolution {
        let (lo, ln) = (2 * self.n_harm + 1, 2 * n_harm + 1);
        let mut coeffs = vec![0.0; self.ndof() * ln];
        for j in 0..self.ndof() {
            for p in 0..lo.min(ln) {
                coeffs[j * ln + p] = self.coeffs[j * lo + p];
            }
        }
        HbSolution {
            coeffs,
            n_harm,
            ..self.clone()
        }
    }
}

/// Harmonic counts up to which the Galerkin Jacobian is projected sample by sample
/// ([`HbSystem`]'s direct path, the arithmetic every N = 3 scan was saved with); above
/// it, from the Fourier coefficients of the Jacobian entries (product-to-sum).
///
/// At N = 3 the two take about the same arithmetic (`S (2N+1)^2 = 1568` multiply-adds
/// per coordinate pair against `3 S (4N+2) = 1344` for the coefficients plus the
/// `(2N+1)^2` sums), so the direct path costs little there and keeps the scans' Newton
/// paths to the bit: the two differ at round-off, and a scan's discovery (which
/// coexisting O-O orbit a Newton run from a simulated seed reaches on the zeta 0.02
/// maps) changed on such round-off in an earlier attempt. This is a deliberate switch on
/// N, not a hidden one: N <= 3 gives the results saved before it, N >= 4 moves at
/// round-off (omega 2e-16, multipliers 4e-13 relative on Tien (2011) N = 8 scans).
/// From N = 4 on the product-to-sum path is the cheaper one: at N = 8 the projection
/// and its omega column fell from about 8 M to 1.2 M instructions per warm solve.
pub const DIRECT_PROJECTION_MAX_HARM: usize = 3;

/// Stages of a harmonic-balance solve whose time [`stage_seconds`] reports, when
/// [`stage_profile`] has switched the timers on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Sampling the series, the model's residual at the samples and its projection
    /// (the alternating frequency–time residual).
    Residual = 0,
    /// The model's `K, C, M` at the samples.
    ModelJacobians = 1,
    /// The Galerkin projection of `K, C, M` into the Jacobian (and its omega column).
    Projection = 2,
    /// The LU factorisation and solve of the Newton step.
    Lu = 3,
}

const STAGES: usize = 4;
static PROFILE_ON: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
static STAGE_NANOS: [std::sync::atomic::AtomicU64; STAGES] =
    [const { std::sync::atomic::AtomicU64::new(0) }; STAGES];
/// Solves, Newton iterations (LU factorisations) and residual evaluations.
static COUNTS: [std::sync::atomic::AtomicU64; 3] =
    [const { std::sync::atomic::AtomicU64::new(0) }; 3];

/// Switches the per-stage timers of [`stage_seconds`] on or off (off by default: a
/// benchmark's measure; the timers cost two clock reads per stage and change nothing
/// else) and resets them.
pub fn stage_profile(on: bool) {
    use std::sync::atomic::Ordering::Relaxed;
    PROFILE_ON.store(on, Relaxed);
    STAGE_NANOS
        .iter()
        .chain(&COUNTS)
        .for_each(|a| a.store(0, Relaxed));
}

/// Seconds per [`Stage`] (in its order) since [`stage_profile`] switched the timers on,
/// then the number of solves, Newton iterations (LU factorisations) and residual
/// evaluations.
pub fn stage_seconds() -> [f64; STAGES + 3] {
    use std::sync::atomic::Ordering::Relaxed;
    let mut out = [0.0; STAGES + 3];
    for (o, a) in out.iter_mut().zip(&STAGE_NANOS) {
        *o = a.load(Relaxed) as f64 * 1e-9;
    }
    for (o, a) in out[STAGES..].iter_mut().zip(&COUNTS) {
        *o = a.load(Relaxed) as f64;
    }
    out
}

#[inline(always)]
fn profiling() -> bool {
    PROFILE_ON.load(std::sync::atomic::Ordering::Relaxed)
}

/// Runs `f`, adding its time to `stage` when the timers are on.
#[inline(always)]
fn timed<T>(stage: Stage, f: impl FnOnce() -> T) -> T {
    if !profiling() {
        return f();
    }
    let t = std::time::Instant::now();
    let out = f();
    STAGE_NANOS[stage as usize].fetch_add(
        t.elapsed().as_nanos() as u64,
        std::sync::atomic::Ordering::Relaxed,
    );
    out
}

fn count(what: usize) {
    if profiling() {
        COUNTS[what].fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }
}

/// `cos k tau_i` and `sin k tau_i` for `k = 0..=2N` (row-major `S x 2(2N+1)`, the
/// cosines first): the discrete Fourier transform that gives the Jacobian entries'
/// coefficients. The angle is reduced to `2 pi (k i mod S) / S` before the
/// trigonometric call, so every entry is as accurate as the basis tables.
fn dft_table(n_harm: usize, samples: usize) -> Vec<f64> {
    let w = 2 * n_harm + 1;
    // S points on the unit circle serve every product k i.
    let circle: Vec<(f64, f64)> = (0..samples)
        .map(|j| (2.0 * PI * j as f64 / samples as f64).sin_cos())
        .collect();
    let mut t = vec![0.0; samples * 2 * w];
    for i in 0..samples {
        for k in 0..w {
            let (sn, cs) = circle[(k * i) % samples];
            t[i * 2 * w + k] = cs;
            t[i * 2 * w + w + k] = sn;
        }
    }
    t
}

/// Largest `samples x (2N + 1)` kept in [`shared_tables`]' per-thread cache (four tables
/// of it, 0.5 MiB): every warm solve of a scan builds a system of the same size.
const SHARED_TABLES_MAX: usize = 16_384;

/// `(N, samples)`, the basis and the DFT table built for them.
type SharedTables = (usize, usize, Arc<Basis>, Arc<Vec<f64>>);

thread_local! {
    /// The basis and DFT tables of the last few `(N, samples)` this thread solved at.
    static TABLES: std::cell::RefCell<Vec<SharedTables>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// [`Basis::new`] and [`dft_table`] (empty at `N <= DIRECT_PROJECTION_MAX_HARM`, whose
/// path does not use it) for `(n_harm, samples)`, built once per thread for the sizes
/// a thread keeps solving at: the same values as building them for each system (the
/// same computation), without its sine and cosine calls, a fifth of a warm N = 8 solve's
/// instructions outside the model.
fn shared_tables(n_harm: usize, samples: usize) -> (Arc<Basis>, Arc<Vec<f64>>) {
    let build = || {
        let dft = if n_harm > DIRECT_PROJECTION_MAX_HARM {
            dft_table(n_harm, samples)
        } else {
            vec![]
        };
        (Arc::new(Basis::new(n_harm, samples)), Arc::new(dft))
    };
    if samples * (2 * n_harm + 1) > SHARED_TABLES_MAX {
        return build();
    }
    TABLES.with(|t| {
        let mut t = t.borrow_mut();
        if let Some(e) = t.iter().find(|e| e.0 == n_harm && e.1 == samples) {
            return (e.2.clone(), e.3.clone());
        }
        let (b, d) = build();
        if t.len() == 4 {
            t.remove(0);
        }
        t.push((n_harm, samples, b.clone(), d.clone()));
        (b, d)
    })
}

/// Zeroes the `(j, k)` block of coefficient rows and columns (`L x L`) of `jac`.
fn zero_block_of(jac: &mut [f64], n: usize, l: usize, j: usize, k: usize) {
    for rr in 0..l {
        jac[(j * l + rr) * n + k * l..(j * l + rr) * n + (k + 1) * l].fill(0.0);
    }
}

/// Workspace and fixed data of one harmonic-balance problem.
pub struct HbSystem<'a, D: Dynamics + ?Sized> {
    model: &'a D,
    d: usize,
    basis: Arc<Basis>,
    winding: Vec<f64>,
    /// Coordinate used by the phase condition and whether it is a rotating ball.
    phase_coord: usize,
    phase_rotating: bool,
    // sample workspaces
    q: Vec<f64>,
    qt: Vec<f64>,
    qtt: Vec<f64>,
    f: Vec<f64>,
    /// Row-major `S x 3d^2`: per sample `K`, then `C`, then `M` (each row-major `d x d`).
    kcm: Vec<f64>,
    /// The direct path's `S x L` product (rows padded to groups of 8), sized on first use.
    g: Vec<f64>,
    /// One coordinate's `q, q', q''` at every sample (`3 x S`), as [`Self::sample`]
    /// builds them.
    col: Vec<f64>,
    /// Product-to-sum path (`n_harm > DIRECT_PROJECTION_MAX_HARM`): the DFT table and
    /// the `3d^2 x 2(2N+1)` Fourier coefficients of the entries of `K, C, M`.
    dft: Arc<Vec<f64>>,
    coef: Vec<f64>,
    /// The entries that vary along the orbit (`S x nv`) and their coefficients.
    packed: Vec<f64>,
    packed_coef: Vec<f64>,
}

impl<'a, D: Dynamics + ?Sized> HbSystem<'a, D> {
    pub fn new(model: &'a D, winding: &[f64], n_harm: usize, samples: usize) -> Self {
        let d = model.ndof();
        assert_eq!(winding.len(), d);
        let (basis, dft) = shared_tables(n_harm, samples);
        let rot = winding.iter().position(|w| *w != 0.0);
        let s = samples;
        HbSystem {
            model,
            d,
            basis,
            winding: winding.to_vec(),
            phase_coord: rot.unwrap_or(model.layout().x),
            phase_rotating: rot.is_some(),
            q: vec![0.0; s * d],
            qt: vec![0.0; s * d],
            qtt: vec![0.0; s * d],
            f: vec![0.0; s * d],
            kcm: vec![0.0; s * 3 * d * d],
            g: vec![],
            col: vec![0.0; 3 * s],
            dft,
            // Sized on first use: the direct path never needs them.
            coef: vec![],
            packed: vec![],
            packed_coef: vec![],
        }
    }

    /// Number of unknowns (coefficients and omega) and equations.
    pub fn size(&self) -> usize {
        self.d * self.basis.width() + 1
    }

    /// Samples the coordinates at every collocation time: `q = Phi c + w tau`. Each
    /// value sums `w tau` (or `w`, `0`) and then the terms `c_p phi_p` in the order of
    /// `p`, all samples of a coordinate at once (the loop over the samples vectorises;
    /// the sums are the same, term by term, as a sample-by-sample loop's).
    #[inline(always)]
    fn sample(&mut self, x: &[f64]) {
        let (d, l, s) = (self.d, self.basis.width(), self.basis.samples);
        let b = &*self.basis;
        let (qa, rest) = self.col.split_at_mut(s);
        let (qb, qc) = rest.split_at_mut(s);
        let qc = &mut qc[..s];
        for j in 0..d {
            let w = self.winding[j];
            for ((a, bb), (cc, tau)) in qa
                .iter_mut()
                .zip(qb.iter_mut())
                .zip(qc.iter_mut().zip(&b.tau))
            {
                *a = w * tau;
                *bb = w;
                *cc = 0.0;
            }
            for (p, &c) in x[j * l..(j + 1) * l].iter().enumerate() {
                let (ph, dph, ddph) = (
                    &b.phi_t[p * s..(p + 1) * s],
                    &b.dphi_t[p * s..(p + 1) * s],
                    &b.ddphi_t[p * s..(p + 1) * s],
                );
                for ((a, bb), (cc, (f, (f1, f2)))) in qa
                    .iter_mut()
                    .zip(qb.iter_mut())
                    .zip(qc.iter_mut().zip(ph.iter().zip(dph.iter().zip(ddph))))
                {
                    *a += c * f;
                    *bb += c * f1;
                    *cc += c * f2;
                }
            }
            for i in 0..s {
                self.q[i * d + j] = qa[i];
                self.qt[i * d + j] = qb[i];
                self.qtt[i * d + j] = qc[i];
            }
        }
    }

    /// Residual `r` (length `size()`), and the Jacobian (row-major) when `jac` is given.
    pub fn assemble(&mut self, x: &[f64], r: &mut [f64], jac: Option<&mut [f64]>) {
        let model = self.model;
        self.assemble_with(model, x, r, jac);
    }

    /// [`Self::assemble`] for another model of the same coordinates (the same model at
    /// another parameter value). Kept out of line: inlined into a caller that has both
    /// the base model's and a varied model's instance, it compiled 14 % slower.
    #[inline(never)]
    pub fn assemble_with<M: Dynamics + ?Sized>(
        &mut self,
        model: &M,
        x: &[f64],
        r: &mut [f64],
        jac: Option<&mut [f64]>,
    ) {
        timed(Stage::Residual, || self.residual_with(model, x, r));
        if let Some(jac) = jac {
            self.jacobian_at_samples(model, x, jac);
        }
    }

    /// The residual alone: samples `x`, evaluates the model there and projects.
    #[inline(never)]
    fn residual_with<M: Dynamics + ?Sized>(&mut self, model: &M, x: &[f64], r: &mut [f64]) {
        count(2);
        let (d, l, s) = (self.d, self.basis.width(), self.basis.samples);
        let om = x[d * l];
        self.sample(x);
        let mut v = vec![0.0; d];
        let mut a = vec![0.0; d];
        for i in 0..s {
            for j in 0..d {
                v[j] = om * self.qt[i * d + j];
                a[j] = om * om * self.qtt[i * d + j];
            }
            let t = self.basis.tau[i] / om;
            let q = &self.q[i * d..(i + 1) * d];
            model.residual(t, q, &v, &a, &mut self.f[i * d..(i + 1) * d]);
        }
        // Galerkin projection.
        r.fill(0.0);
        for (w, f) in self.basis.wgt.chunks_exact(l).zip(self.f.chunks_exact(d)) {
            for (row, fj) in r[..d * l].chunks_exact_mut(l).zip(f) {
                for (rp, wp) in row.iter_mut().zip(w) {
                    *rp += wp * fj;
                }
            }
        }
        // Phase condition.
        let pc = self.phase_coord;
        r[d * l] = if self.phase_rotating {
            x[pc * l]
                + (1..=self.basis.n_harm)
                    .map(|m| x[pc * l + 2 * m - 1])
                    .sum::<f64>()
        } else {
            x[pc * l + 2]
        };
    }

    /// The Jacobian at `x`, the point the last residual evaluation sampled (its
    /// `q, q', q''` are reused): what Newton needs after a line search accepted the
    /// point whose residual it has just evaluated.
    pub fn jacobian_after_residual(&mut self, x: &[f64], jac: &mut [f64]) {
        let model = self.model;
        self.jacobian_at_samples(model, x, jac);
    }

    /// `K, C, M` at the sampled points and their Galerkin projection.
    fn jacobian_at_samples<M: Dynamics + ?Sized>(&mut self, model: &M, x: &[f64], jac: &mut [f64]) {
        let (d, l, s) = (self.d, self.basis.width(), self.basis.samples);
        let om = x[d * l];
        let dd = d * d;
        timed(Stage::ModelJacobians, || {
            let mut v = vec![0.0; d];
            let mut a = vec![0.0; d];
            for i in 0..s {
                for j in 0..d {
                    v[j] = om * self.qt[i * d + j];
                    a[j] = om * om * self.qtt[i * d + j];
                }
                let t = self.basis.tau[i] / om;
                let q = &self.q[i * d..(i + 1) * d];
                let (kk, rest) = self.kcm[i * 3 * dd..(i + 1) * 3 * dd].split_at_mut(dd);
                let (cc, mm) = rest.split_at_mut(dd);
                model.jacobians(t, q, &v, &a, Jacobians::new(kk, cc, mm));
            }
        });
        timed(Stage::Projection, || {
            // Every entry of a coupled block, the omega column and the phase row are
            // written below; the blocks of coordinates that do not interact are zeroed
            // where they are skipped.
            let done = if self.basis.n_harm <= DIRECT_PROJECTION_MAX_HARM {
                self.project_direct(om, jac)
            } else {
                self.project_product_to_sum(om, jac)
            };
            if done {
                self.omega_column(om, jac);
            }
        });
    }

    /// Whether no sample couples coordinate `j` to `k` (a zero block).
    fn zero_block(&self, j: usize, k: usize) -> bool {
        let dd = self.d * self.d;
        let idx = j * self.d + k;
        !(0..self.basis.samples).any(|i| {
            let o = i * 3 * dd + idx;
            self.kcm[o] != 0.0 || self.kcm[o + dd] != 0.0 || self.kcm[o + 2 * dd] != 0.0
        })
    }

    /// The Galerkin projection sample by sample, `J_jk = W^T (K Phi + omega C Phi' +
    /// omega^2 M Phi'')`. Every entry sums its samples in order from zero, exactly as
    /// the scans at N <= [`DIRECT_PROJECTION_MAX_HARM`] were computed (weights that are
    /// exactly zero, `sin m tau_0`, are skipped as they always were). Returns `false`
    /// if cancelled.
    #[inline(never)]
    fn project_direct(&mut self, om: f64, jac: &mut [f64]) -> bool {
        let (d, l, s) = (self.d, self.basis.width(), self.basis.samples);
        let n = self.size();
        let dd = d * d;
        let om2 = om * om;
        // G's rows padded to whole groups of 8 columns (the padding stays zero).
        let lp = l.div_ceil(8) * 8;
        if self.g.is_empty() {
            self.g = vec![0.0; s * lp];
        }
        for j in 0..d {
            for k in 0..d {
                // A block takes a fraction of a second at hundreds of harmonics; a
                // cancelled solve stops at the next Newton iteration (see `cancel`).
                if crate::cancel::cancelled() {
                    return false;
                }
                if self.zero_block(j, k) {
                    zero_block_of(jac, n, l, j, k);
                    continue;
                }
                let idx = j * d + k;
                let g = &mut self.g;
                // G = K Phi + omega C Phi' + omega^2 M Phi''  (S x L)
                for i in 0..s {
                    let o = i * 3 * dd + idx;
                    let (kv, cv, mv) = (
                        self.kcm[o],
                        om * self.kcm[o + dd],
                        om2 * self.kcm[o + 2 * dd],
                    );
                    let b = i * l;
                    for p in 0..l {
                        g[i * lp + p] = kv * self.basis.phi[b + p]
                            + cv * self.basis.dphi[b + p]
                            + mv * self.basis.ddphi[b + p];
                    }
                }
                // J block = W^T G, eight columns at a time in registers; each entry
                // sums its samples in order from zero as before.
                for rr in 0..l {
                    let row = &mut jac[(j * l + rr) * n + k * l..(j * l + rr) * n + (k + 1) * l];
                    for p0 in (0..l).step_by(8) {
                        let mut acc = [0.0f64; 8];
                        for i in 0..s {
                            let wr = self.basis.wgt[i * l + rr];
                            if wr == 0.0 {
                                continue;
                            }
                            let gi = &g[i * lp + p0..i * lp + p0 + 8];
                            for t in 0..8 {
                                acc[t] += wr * gi[t];
                            }
                        }
                        let m = (l - p0).min(8);
                        row[p0..p0 + m].copy_from_slice(&acc[..m]);
                    }
                }
            }
        }
        true
    }

    /// The Galerkin projection from the Fourier coefficients of each entry of `K, C, M`
    /// (`X_c[k] = sum_i X_i cos k tau_i`, `X_s[k]` likewise, `k <= 2N`, one matrix
    /// product for all entries): the products of two basis functions in the projection
    /// are sums of harmonics `|m - n|` and `m + n` (product-to-sum), so each block is a
    /// Toeplitz-plus-Hankel combination of these coefficients. Equal to
    /// [`Self::project_direct`] in exact arithmetic at any sample count (the identities
    /// hold sample by sample), `O(S N d^2 + N^2 d^2)` instead of `O(S N^2 d^2)`.
    /// Returns `false` if cancelled.
    #[inline(never)]
    fn project_product_to_sum(&mut self, om: f64, jac: &mut [f64]) -> bool {
        use faer::{linalg::matmul::matmul, Accum, MatMut, MatRef, Par};
        let (d, l, s) = (self.d, self.basis.width(), self.basis.samples);
        let nh = self.basis.n_harm;
        let n = self.size();
        let dd = d * d;
        let w = 2 * nh + 1;
        if self.dft.is_empty() {
            // The direct path's system (a test calls both paths).
            self.dft = Arc::new(dft_table(nh, s));
        }
        self.coef.resize(3 * dd * 2 * w, 0.0);
        // coef (3d^2 x 2w) = KCM^T (3d^2 x S) * table (S x 2w), for the entries that
        // vary along the orbit; an entry that is the same at every sample (the planar
        // model's mass and damping constants, or zero) has the coefficients `S x` of
        // its constant at k = 0 and none above (sum_i cos k tau_i = 0 for 0 < k < S).
        let e3 = 3 * dd;
        let (mut varying, mut constant) = (Vec::with_capacity(e3), Vec::with_capacity(e3));
        // Entries that are zero at every sample: a block whose `K, C, M` entries all are
        // is [`Self::zero_block`] (read here instead of scanning the samples again).
        let mut zero = vec![false; e3];
        for (e, is_zero) in zero.iter_mut().enumerate() {
            let first = self.kcm[e];
            if (1..s).all(|i| self.kcm[i * e3 + e] == first) {
                constant.push((e, first));
                *is_zero = first == 0.0;
            } else {
                varying.push(e);
            }
        }
        let nv = varying.len();
        self.packed.resize(s * nv, 0.0);
        for i in 0..s {
            for (t, &e) in varying.iter().enumerate() {
                self.packed[i * nv + t] = self.kcm[i * e3 + e];
            }
        }
        self.packed_coef.resize(nv * 2 * w, 0.0);
        matmul(
            MatMut::from_row_major_slice_mut(&mut self.packed_coef, nv, 2 * w),
            Accum::Replace,
            MatRef::from_row_major_slice(&self.packed, s, nv).transpose(),
            MatRef::from_row_major_slice(&self.dft, s, 2 * w),
            1.0,
            Par::Seq,
        );
        for (t, &e) in varying.iter().enumerate() {
            self.coef[e * 2 * w..(e + 1) * 2 * w]
                .copy_from_slice(&self.packed_coef[t * 2 * w..(t + 1) * 2 * w]);
        }
        for (e, c) in constant {
            let row = &mut self.coef[e * 2 * w..(e + 1) * 2 * w];
            row.fill(0.0);
            row[0] = s as f64 * c;
        }
        let inv = 1.0 / s as f64;
        // Per block, the coefficients on the signed harmonics h = -2N..2N (index
        // h + 2N): cosines even in h, sines odd (sin(-h tau) = -sin(h tau)).
        let e = 4 * nh + 1;
        let z = 2 * nh;
        let mut work = vec![0.0; 8 * e];
        let (ext, rest) = work.split_at_mut(6 * e);
        let (ac, as_) = rest.split_at_mut(e);
        let mut entries = vec![0.0; 4 * nh];
        for j in 0..d {
            for k in 0..d {
                if crate::cancel::cancelled() {
                    return false;
                }
                let idx = j * d + k;
                if zero[idx] && zero[dd + idx] && zero[2 * dd + idx] {
                    zero_block_of(jac, n, l, j, k);
                    continue;
                }
                for x in 0..3 {
                    let c = &self.coef[(x * dd + idx) * 2 * w..(x * dd + idx + 1) * 2 * w];
                    let (cos, sin) = c.split_at(w);
                    let (ce, se) = ext[2 * x * e..(2 * x + 2) * e].split_at_mut(e);
                    // h >= 0 at z + h, then h <= 0 at z - h (the sines negated), h = 0
                    // written last by the second, as entry by entry before.
                    ce[z..].copy_from_slice(cos);
                    se[z..].copy_from_slice(sin);
                    for (v, c) in ce[..=z].iter_mut().rev().zip(cos) {
                        *v = *c;
                    }
                    for (v, c) in se[..=z].iter_mut().rev().zip(sin) {
                        *v = -c;
                    }
                }
                let (kc, ks) = (&ext[0..e], &ext[e..2 * e]);
                let (cc, cs) = (&ext[2 * e..3 * e], &ext[3 * e..4 * e]);
                let (mc, ms) = (&ext[4 * e..5 * e], &ext[5 * e..6 * e]);
                let base = j * l * n + k * l;
                // Column n of a block: K phi + omega C phi' + omega^2 M phi'' with
                // phi = cos n tau gives (K - omega^2 n^2 M) cos n tau - omega n C sin n tau,
                // with phi = sin n tau, (K - omega^2 n^2 M) sin n tau + omega n C cos n tau.
                // Rows: weight 1/S (mean), 2/S cos m tau, 2/S sin m tau.
                jac[base] = inv * kc[z];
                for m in 1..=nh {
                    jac[base + (2 * m - 1) * n] = 2.0 * inv * kc[z + m];
                    jac[base + 2 * m * n] = 2.0 * inv * ks[z + m];
                }
                for nn in 1..=nh {
                    let nf = nn as f64;
                    let (a2, cn) = (om * om * nf * nf, om * nf);
                    // A = K - omega^2 n^2 M, coefficient by coefficient, on the harmonics
                    // m -+ n (m = 1..N) and n that this column reads.
                    let hs = z + 1 - nn..z + nh + nn + 1;
                    for ((a, b), ((k1, k2), (m1, m2))) in
                        ac[hs.clone()].iter_mut().zip(&mut as_[hs.clone()]).zip(
                            kc[hs.clone()]
                                .iter()
                                .zip(&ks[hs.clone()])
                                .zip(mc[hs.clone()].iter().zip(&ms[hs])),
                        )
                    {
                        *a = k1 - a2 * m1;
                        *b = k2 - a2 * m2;
                    }
                    let (pc, ps) = (base + 2 * nn - 1, base + 2 * nn);
                    jac[pc] = inv * (ac[z + nn] - cn * cs[z + nn]);
                    jac[ps] = inv * (as_[z + nn] + cn * cc[z + nn]);
                    // Rows m = 1..N read the harmonics m - n (`lo`) and m + n (`hi`): both
                    // runs are contiguous, so the four entries are computed for all m
                    // from slices (no per-entry index arithmetic or bounds checks; the
                    // same expression per entry, so the same values) and then stored
                    // down the block's two columns.
                    // cos m cos n = (cos(m-n) + cos(m+n))/2, cos m sin n =
                    // (sin(m+n) - sin(m-n))/2, sin m cos n = (sin(m+n) + sin(m-n))/2,
                    // sin m sin n = (cos(m-n) - cos(m+n))/2.
                    let (lo, hi) = (z + 1 - nn..z + nh + 1 - nn, z + 1 + nn..z + nh + 1 + nn);
                    let (acd, acs) = (&ac[lo.clone()], &ac[hi.clone()]);
                    let (asd, ass) = (&as_[lo.clone()], &as_[hi.clone()]);
                    let (ccd, ccs) = (&cc[lo.clone()], &cc[hi.clone()]);
                    let (csd, css) = (&cs[lo], &cs[hi]);
                    let (t_cc, rest) = entries.split_at_mut(nh);
                    let (t_cs, rest) = rest.split_at_mut(nh);
                    let (t_sc, t_ss) = rest.split_at_mut(nh);
                    for i in 0..nh {
                        t_cc[i] = inv * (acd[i] + acs[i] - cn * (css[i] - csd[i]));
                        t_cs[i] = inv * (ass[i] - asd[i] + cn * (ccd[i] + ccs[i]));
                        t_sc[i] = inv * (ass[i] + asd[i] - cn * (ccd[i] - ccs[i]));
                        t_ss[i] = inv * (acd[i] - acs[i] + cn * (css[i] + csd[i]));
                    }
                    for (i, rows) in jac[pc + n..].chunks_mut(2 * n).take(nh).enumerate() {
                        rows[0] = t_cc[i];
                        rows[1] = t_cs[i];
                        rows[n] = t_sc[i];
                        rows[n + 1] = t_ss[i];
                    }
                }
            }
        }
        true
    }

    /// The omega column, `d/d omega = W^T (C q_tau + 2 omega M q_tautau)`, and the
    /// phase condition's row.
    fn omega_column(&self, om: f64, jac: &mut [f64]) {
        let (d, l, s) = (self.d, self.basis.width(), self.basis.samples);
        let n = self.size();
        let dd = d * d;
        // Summed in a contiguous column (sample by sample from zero, as the strided
        // column of `jac` was: the same sums).
        let mut col = vec![0.0; d * l];
        // `2 omega M` is `(2 omega) M`: the product taken once gives the same values.
        let om2 = 2.0 * om;
        for i in 0..s {
            let w = &self.basis.wgt[i * l..(i + 1) * l];
            let kcm = &self.kcm[i * 3 * dd..(i + 1) * 3 * dd];
            let (cm, mm) = (&kcm[dd..2 * dd], &kcm[2 * dd..3 * dd]);
            let (qt, qtt) = (&self.qt[i * d..(i + 1) * d], &self.qtt[i * d..(i + 1) * d]);
            for ((crow, mrow), cj) in cm
                .chunks_exact(d)
                .zip(mm.chunks_exact(d))
                .zip(col.chunks_exact_mut(l))
            {
                let mut dfo = 0.0;
                for ((cv, mv), (qk, qkk)) in crow.iter().zip(mrow).zip(qt.iter().zip(qtt)) {
                    dfo += cv * qk + om2 * mv * qkk;
                }
                for (c, wr) in cj.iter_mut().zip(w) {
                    *c += wr * dfo;
                }
            }
        }
        for (row, c) in col.iter().enumerate() {
            jac[row * n + d * l] = *c;
        }
        let pc = self.phase_coord;
        let prow = d * l * n;
        jac[prow..prow + n].fill(0.0);
        if self.phase_rotating {
            jac[prow + pc * l] = 1.0;
            for m in 1..=self.basis.n_harm {
                jac[prow + pc * l + 2 * m - 1] = 1.0;
            }
        } else {
            jac[prow + pc * l + 2] = 1.0;
        }
    }
}

/// The harmonic-balance problem as a [`Problem`]: unknowns the coefficients and
/// `omega` (`x = (c, omega)`), equations the Galerkin residual and the phase condition;
/// the parameter is one of the model's (see [`ModelAt`]).
pub struct HbProblem<'a, D: Dynamics + ?Sized> {
    sys: HbSystem<'a, D>,
    models: ModelAt<'a, D>,
}

impl<'a, D: Dynamics + ?Sized> HbProblem<'a, D> {
    pub fn new(models: ModelAt<'a, D>, winding: &[f64], n_harm: usize, samples: usize) -> Self {
        HbProblem {
            sys: HbSystem::new(models.base(), winding, n_harm, samples),
            models,
        }
    }

    fn assemble(
        &mut self,
        x: &[f64],
        p: f64,
        r: &mut [f64],
        jac: Option<&mut [f64]>,
    ) -> crate::Result<()> {
        match self.models.at(p)? {
            At::Base(m) => self.sys.assemble_with(m, x, r, jac),
            At::Varied(m) => self.sys.assemble_with(m, x, r, jac),
        }
        Ok(())
    }
}

impl HbSolution {
    /// The solution as the [`HbProblem`]'s unknowns: its coefficients, then omega.
    pub fn unknowns(&self) -> Vec<f64> {
        let mut x = self.coeffs.clone();
        x.push(self.omega);
        x
    }
}

impl<D: Dynamics + ?Sized> Problem for HbProblem<'_, D> {
    fn size(&self) -> usize {
        self.sys.size()
    }
    fn param(&self) -> f64 {
        self.models.value()
    }
    fn residual(&mut self, x: &[f64], p: f64, r: &mut [f64]) -> crate::Result<()> {
        self.assemble(x, p, r, None)
    }
    fn jac_x(&mut self, x: &[f64], p: f64, r: &mut [f64], jac: &mut [f64]) -> crate::Result<()> {
        self.assemble(x, p, r, Some(jac))
    }
}

/// The secant predictor `2 a - b` in coefficients and frequency (a frequency that
/// would not be positive keeps `a`'s).
impl Secant for HbSolution {
    fn secant(&self, previous: &Self) -> Self {
        let mut g = self.clone();
        for (x, y) in g.coeffs.iter_mut().zip(&previous.coeffs) {
            *x = 2.0 * *x - y;
        }
        g.omega = 2.0 * self.omega - previous.omega;
        if !(g.omega > 0.0) {
            g.omega = self.omega;
        }
        g
    }
}

fn l2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(
        0.0f64,
        |m, x| if x.is_nan() { f64::NAN } else { m.max(x.abs()) },
    )
}

/// Newton–IHB from the starting guess `guess` (its `coeffs`, `omega`, `winding`; resized
/// to `opts.n_harm` if needed).
pub fn solve<D: Dynamics + ?Sized>(model: &D, guess: &HbSolution, opts: &HbOptions) -> HbSolution {
    let g = if guess.n_harm == opts.n_harm {
        guess.clone()
    } else {
        guess.resized(opts.n_harm)
    };
    let samples = opts.samples.unwrap_or_else(|| default_samples(opts.n_harm));
    count(0);
    let mut sys = HbSystem::new(model, &g.winding, opts.n_harm, samples);
    let n = sys.size();
    let mut x = g.unknowns();
    let mut r = vec![0.0; n];
    let mut rt = vec![0.0; n];
    let mut jac = vec![0.0; n * n];
    let mut lu = LuWork::new(n);
    let mut out = HbSolution {
        omega: g.omega,
        coeffs: g.coeffs.clone(),
        winding: g.winding.clone(),
        n_harm: opts.n_harm,
        samples,
        residual: f64::INFINITY,
        step: f64::INFINITY,
        iterations: 0,
        status: Status::MaxIterations,
        pivot_ratio: f64::NAN,
    };
    let finish =
        |x: &[f64], out: &mut HbSolution, status: Status, res: f64, step: f64, it: usize| {
            out.coeffs.copy_from_slice(&x[..n - 1]);
            out.omega = x[n - 1];
            out.status = status;
            out.residual = res;
            out.step = step;
            out.iterations = it;
        };
    if !(g.omega > 0.0) || x.iter().any(|v| !v.is_finite()) {
        finish(
            &x,
            &mut out,
            Status::Diverged,
            f64::INFINITY,
            f64::INFINITY,
            0,
        );
        return out;
    }
    sys.assemble(&x, &mut r, Some(&mut jac));
    let mut rn = max_abs(&r);
    let scale0 = max_abs(&x).max(1.0);
    for it in 1..=opts.max_iter {
        // A cancelled solve's result is discarded by whoever cancelled it (see `cancel`).
        if crate::cancel::cancelled() {
            finish(
                &x,
                &mut out,
                Status::MaxIterations,
                rn,
                f64::INFINITY,
                it - 1,
            );
            return out;
        }
        if !rn.is_finite() {
            finish(&x, &mut out, Status::Diverged, rn, f64::INFINITY, it - 1);
            return out;
        }
        let neg: Vec<f64> = r.iter().map(|v| -v).collect();
        count(1);
        let Some(sol) = timed(Stage::Lu, || lu.solve(&jac, &neg)) else {
            finish(&x, &mut out, Status::Singular, rn, f64::INFINITY, it - 1);
            return out;
        };
        out.pivot_ratio = sol.pivot_ratio;
        let dx = sol.x;
        // Backtracking on ||R||_2, for which the Newton direction is a descent direction
        // (the max-norm need not fall even when the step is good).
        let merit = l2(&r);
        let mut lam = 1.0;
        let mut accepted = false;
        let mut xt = x.clone();
        let mut rtn = f64::INFINITY;
        for _ in 0..16 {
            for i in 0..n {
                xt[i] = x[i] + lam * dx[i];
            }
            if xt[n - 1] > 0.0 {
                sys.assemble(&xt, &mut rt, None);
                rtn = max_abs(&rt);
                let mt = l2(&rt);
                if mt.is_finite() && mt < (1.0 - 1e-4 * lam) * merit.max(1e-300) {
                    accepted = true;
                    break;
                }
                // Already at round-off: the residual cannot fall further, take the step.
                if rn <= opts.tol && rtn <= opts.tol {
                    accepted = true;
                    break;
                }
            }
            lam *= 0.5;
        }
        if !accepted {
            finish(&x, &mut out, Status::Diverged, rn, max_abs(&dx), it);
            return out;
        }
        let step = lam * max_abs(&dx);
        x.copy_from_slice(&xt);
        rn = rtn;
        if max_abs(&x) > 1e8 * scale0 {
            finish(&x, &mut out, Status::Diverged, rn, step, it);
            return out;
        }
        if rn <= opts.tol && step <= opts.step_tol * max_abs(&x).max(1.0) {
            finish(&x, &mut out, Status::Converged, rn, step, it);
            return out;
        }
        // The accepted point is the last one the line search evaluated: its residual
        // is `rt` and its samples are still in `sys`, so only the Jacobian is new.
        r.copy_from_slice(&rt);
        sys.jacobian_after_residual(&x, &mut jac);
        rn = max_abs(&r);
        if it == opts.max_iter {
            finish(&x, &mut out, Status::MaxIterations, rn, step, it);
        }
    }
    out
}

/// Nanoseconds spent in certificate checks by this process (all threads): what
/// `benchmarks/bench_certificates.py` sets against a scan's time.
static CERTIFICATE_NANOS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Runs a certificate check, adding its time to [`certificate_seconds`].
pub(crate) fn timed_certificate<T>(f: impl FnOnce() -> T) -> T {
    let t = std::time::Instant::now();
    let out = f();
    CERTIFICATE_NANOS.fetch_add(
        t.elapsed().as_nanos() as u64,
        std::sync::atomic::Ordering::Relaxed,
    );
    out
}

/// Total time this process has spent in certificate checks, in seconds.
pub fn certificate_seconds() -> f64 {
    CERTIFICATE_NANOS.load(std::sync::atomic::Ordering::Relaxed) as f64 * 1e-9
}

/// Orbit-closure certificate of a series without integrating the flow: the ODE defect
/// `M^-1 F(t, q, q', q'')` of the series (an acceleration error) at `points` phases
/// placed between the collocation times, integrated over one period,
/// `T / points * sum_k max_j |defect_j(t_k)|`.
///
/// Harmonic balance zeroes only the first `N` harmonics of the residual at the sampled
/// times; what the series leaves in the higher harmonics and between the samples is the
/// defect. Integrated, it bounds the velocity error a simulation from the series'
/// state accumulates over a period *before* the linearised flow amplifies it, so the
/// certificate does not grow with the multipliers of an unstable orbit the way a
/// simulated closure does (which would refuse genuine unstable orbits at small `N`),
/// while a series that is no orbit at all (aliased solutions near a branch's
/// infinite-period end) has an O(1) defect over a long period.
pub fn defect_closure<D: Dynamics + ?Sized>(model: &D, sol: &HbSolution, points: usize) -> f64 {
    let d = sol.ndof();
    let om = sol.omega;
    if !(om > 0.0 && om.is_finite()) || points == 0 {
        return f64::INFINITY;
    }
    let (mut q, mut v, mut a, mut f) = (vec![0.0; d], vec![0.0; d], vec![0.0; d], vec![0.0; d]);
    let mut sum = 0.0;
    for k in 0..points {
        // Half a step off a uniform grid of `points`: with `points` a multiple of the
        // collocation samples, none of these phases is a collocation time.
        let tau = 2.0 * PI * (k as f64 + 0.5) / points as f64;
        sol.eval_rates(tau, &mut q, &mut v, &mut a);
        let t = tau / om;
        model.residual(t, &q, &v, &a, &mut f);
        model.solve_mass(t, &q, &mut f);
        sum += max_abs(&f);
    }
    let c = sum * sol.period() / points as f64;
    if c.is_nan() {
        f64::INFINITY
    } else {
        c
    }
}

/// Fourier coefficients of `d` sampled coordinates over one period: `samples[i*d + j]`
/// at `tau_i = 2 pi i / S`, secular part `w_j tau` removed first.
pub fn fit_coefficients(samples: &[f64], d: usize, winding: &[f64], n_harm: usize) -> Vec<f64> {
    let s = samples.len() / d;
    let l = 2 * n_harm + 1;
    let basis = Basis::new(n_harm, s);
    let mut c = vec![0.0; d * l];
    for i in 0..s {
        let tau = basis.tau[i];
        for j in 0..d {
            let v = samples[i * d + j] - winding[j] * tau;
            for p in 0..l {
                c[j * l + p] += basis.wgt[i * l + p] * v;
            }
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Duffing-like single coordinate as a `Dynamics` to check the machinery.
    /// x'' + 0.1 x' + x + x^3 = 0 has no periodic orbit; use a Van der Pol limit cycle:
    /// x'' - eps (1 - x^2) x' + x = 0, which for eps -> 0 has amplitude 2 and omega 1.
    struct Vdp(f64);
    impl Dynamics for Vdp {
        fn ndof(&self) -> usize {
            1
        }
        fn residual(&self, _t: f64, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]) {
            out[0] = a[0] - self.0 * (1.0 - q[0] * q[0]) * v[0] + q[0];
        }
        fn jacobians(&self, _t: f64, q: &[f64], v: &[f64], _a: &[f64], jac: Jacobians<'_>) {
            let Jacobians { k, c, m } = jac;
            k[0] = 2.0 * self.0 * q[0] * v[0] + 1.0;
            c[0] = -self.0 * (1.0 - q[0] * q[0]);
            m[0] = 1.0;
        }
        fn solve_mass(&self, _t: f64, _q: &[f64], rhs: &mut [f64]) {
            let _ = rhs;
        }
        fn accel(&self, _t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
            out[0] = self.0 * (1.0 - q[0] * q[0]) * v[0] - q[0];
        }
    }

    #[test]
    fn van_der_pol_limit_cycle() {
        // Classic result: omega = 1 - eps^2/16 + O(eps^4), amplitude 2 + O(eps^2).
        let eps = 0.1;
        let model = Vdp(eps);
        let mut coeffs = vec![0.0; 2 * 8 + 1];
        coeffs[1] = 1.8;
        let guess = HbSolution {
            omega: 0.95,
            coeffs,
            winding: vec![0.0],
            n_harm: 8,
            samples: 0,
            residual: 0.0,
            step: 0.0,
            iterations: 0,
            status: Status::Converged,
            pivot_ratio: 0.0,
        };
        let opts = HbOptions {
            n_harm: 8,
            ..Default::default()
        };
        let sol = solve(&model, &guess, &opts);
        assert_eq!(sol.status, Status::Converged, "{sol:?}");
        let expect = 1.0 - eps * eps / 16.0 + 17.0 * eps.powi(4) / 3072.0;
        assert!(
            (sol.omega - expect).abs() < 1e-6,
            "omega {} vs {}",
            sol.omega,
            expect
        );
        let amp = sol.coord(0)[1].hypot(sol.coord(0)[2]);
        assert!((amp - 2.0).abs() < 1e-3, "amplitude {amp}");
        assert!(sol.iterations < 15);
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        use crate::model::Planar;
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 0.8]).unwrap();
        let n_harm = 3;
        let mut sys = HbSystem::new(&p, &[0.0, 0.0, -1.0, 0.0], n_harm, 32);
        let n = sys.size();
        let x: Vec<f64> = (0..n)
            .map(|i| 0.1 * ((i * 7 % 11) as f64 - 5.0) / 5.0)
            .collect();
        let mut x = x;
        x[n - 1] = 0.3;
        let mut r = vec![0.0; n];
        let mut jac = vec![0.0; n * n];
        sys.assemble(&x, &mut r, Some(&mut jac));
        let h = 1e-6;
        for col in 0..n {
            let mut xp = x.clone();
            xp[col] += h;
            let mut rp = vec![0.0; n];
            sys.assemble(&xp, &mut rp, None);
            xp[col] -= 2.0 * h;
            let mut rm = vec![0.0; n];
            sys.assemble(&xp, &mut rm, None);
            for row in 0..n {
                let fd = (rp[row] - rm[row]) / (2.0 * h);
                assert!(
                    (fd - jac[row * n + col]).abs() < 1e-6,
                    "({row},{col}) fd {fd} an {}",
                    jac[row * n + col]
                );
            }
        }
    }

    fn fd_check(prob: &mut impl Problem, x: &[f64], p: f64, tol: f64) {
        let n = prob.size();
        let (mut r, mut jac) = (vec![0.0; n], vec![0.0; n * n]);
        prob.jac_x(x, p, &mut r, &mut jac).unwrap();
        let h = 1e-6;
        let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
        for col in 0..n {
            let mut xp = x.to_vec();
            xp[col] += h;
            prob.residual(&xp, p, &mut rp).unwrap();
            xp[col] -= 2.0 * h;
            prob.residual(&xp, p, &mut rm).unwrap();
            for row in 0..n {
                let fd = (rp[row] - rm[row]) / (2.0 * h);
                assert!(
                    (fd - jac[row * n + col]).abs() < tol,
                    "({row},{col}) fd {fd} an {}",
                    jac[row * n + col]
                );
            }
        }
    }

    #[test]
    fn hb_problem_jacobians_match_finite_differences() {
        use crate::model::Planar;
        let base = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 0.8]).unwrap();
        let mut prob = HbProblem::new(
            ModelAt::family(&base, "Omega", 1.2),
            &[0.0, 0.0, -1.0, 0.0],
            3,
            32,
        );
        let n = prob.size();
        let mut x: Vec<f64> = (0..n)
            .map(|i| 0.1 * ((i * 7 % 11) as f64 - 5.0) / 5.0)
            .collect();
        x[n - 1] = 0.3;
        // At the model's own Omega and at another one (a rebuilt model).
        fd_check(&mut prob, &x, 1.2, 1e-6);
        fd_check(&mut prob, &x, 1.35, 1e-6);
        // dF/dp against a difference of residuals of separately built models, with
        // another step.
        let mut fp = vec![0.0; n];
        prob.jac_p(&x, 1.2, &mut fp).unwrap();
        let h = 1e-4;
        let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
        let (mp, mm) = (
            base.with_param("Omega", 1.2 + h).unwrap(),
            base.with_param("Omega", 1.2 - h).unwrap(),
        );
        HbSystem::new(&mp, &[0.0, 0.0, -1.0, 0.0], 3, 32).assemble(&x, &mut rp, None);
        HbSystem::new(&mm, &[0.0, 0.0, -1.0, 0.0], 3, 32).assemble(&x, &mut rm, None);
        let mut moved = 0;
        for i in 0..n {
            let fd = (rp[i] - rm[i]) / (2.0 * h);
            assert!(
                (fd - fp[i]).abs() < 1e-6 * (1.0 + fd.abs()),
                "{i}: {fd} vs {}",
                fp[i]
            );
            moved += usize::from(fd.abs() > 1e-3);
        }
        assert!(moved > 5, "Omega must move the residual");
        // A problem without a parameter refuses another value instead of ignoring it.
        let mut fixed = HbProblem::new(ModelAt::fixed(&base), &[0.0, 0.0, -1.0, 0.0], 3, 32);
        assert!(fixed.residual(&x, 1.3, &mut rp).is_err());
        let nan = fixed.param();
        assert!(fixed.jac_p(&x, nan, &mut fp).is_err());
    }

    #[test]
    fn omega_slope_from_the_implicit_function_theorem_matches_neighbouring_solutions() {
        // dx/dp = -F_x^-1 F_p at a converged R-R orbit of the standard case, against the
        // central difference of two orbits solved at Omega -+ h (a second method: two
        // Newton solves, no Jacobian in p).
        use crate::model::Planar;
        use crate::numerics::problem::tangent;
        use crate::periodic::{periodic, PeriodicOptions};
        let om = 1.2;
        let base = Planar::new(0.2, 0.05, &[0.05], 50.0, om, &[1.0, 1.0]).unwrap();
        let hb = HbOptions {
            n_harm: 8,
            ..Default::default()
        };
        let opts = PeriodicOptions {
            hb: hb.clone(),
            ..Default::default()
        };
        let sol = periodic(&base, &[true, true], None, &opts).sol;
        assert_eq!(sol.status, Status::Converged);
        let mut prob = HbProblem::new(
            ModelAt::family(&base, "Omega", om),
            &sol.winding,
            sol.n_harm,
            sol.samples,
        );
        let x = sol.unknowns();
        let t = tangent(&mut prob, &x, om).unwrap().expect("regular point");
        let at = |w: f64| solve(&base.with_param("Omega", w).unwrap(), &sol, &hb);
        let ift = t[t.len() - 1];
        // The central difference's error falls as h^2 towards the tangent (measured:
        // 6.2e-6 at h = 1e-3, 6.2e-8 at h = 1e-4 against a slope of 1.03).
        let mut gaps = vec![];
        for h in [1e-3, 1e-4] {
            let (up, down) = (at(om + h), at(om - h));
            assert!(up.status == Status::Converged && down.status == Status::Converged);
            let slope = (up.omega - down.omega) / (2.0 * h);
            assert!(slope.abs() > 0.05, "a slope worth comparing: {slope}");
            assert!(
                (ift - slope).abs() < 1e-5 * slope.abs(),
                "h {h}: IFT {ift} vs {slope}"
            );
            gaps.push((ift - slope).abs());
            for (i, ti) in t[..t.len() - 1].iter().enumerate() {
                let s = (up.coeffs[i] - down.coeffs[i]) / (2.0 * h);
                assert!(
                    (ti - s).abs() < 1e-3 * (1.0 + s.abs()),
                    "h {h} coefficient {i}: {ti} vs {s}"
                );
            }
        }
        assert!(gaps[1] < gaps[0] / 30.0, "not converging as h^2: {gaps:?}");
    }

    /// The Galerkin Jacobian written out sample by sample, independently of
    /// `HbSystem`: `J[(j, r), (k, p)] = sum_i w_r(tau_i) (K phi_p + omega C phi_p' +
    /// omega^2 M phi_p'')_jk` with the basis from `cos`/`sin` of `m tau_i`, and the omega
    /// column `sum_i w_r (C q_tau + 2 omega M q_tautau)_j`.
    fn direct_jacobian<D: Dynamics>(model: &D, sol: &HbSolution, s: usize) -> Vec<f64> {
        let (d, nh) = (sol.ndof(), sol.n_harm);
        let l = 2 * nh + 1;
        let n = d * l + 1;
        let om = sol.omega;
        let mut jac = vec![0.0; n * n];
        // basis p at tau: (phi, phi', phi'')
        let basis = |p: usize, t: f64| -> (f64, f64, f64) {
            if p == 0 {
                return (1.0, 0.0, 0.0);
            }
            let m = p.div_ceil(2) as f64;
            let (sn, cs) = ((m * t).sin(), (m * t).cos());
            if p % 2 == 1 {
                (cs, -m * sn, -m * m * cs)
            } else {
                (sn, m * cs, -m * m * sn)
            }
        };
        let (mut q, mut v, mut a) = (vec![0.0; d], vec![0.0; d], vec![0.0; d]);
        let (mut k, mut c, mut m) = (vec![0.0; d * d], vec![0.0; d * d], vec![0.0; d * d]);
        for i in 0..s {
            let t = 2.0 * PI * i as f64 / s as f64;
            sol.eval_rates(t, &mut q, &mut v, &mut a);
            model.jacobians(t / om, &q, &v, &a, Jacobians::new(&mut k, &mut c, &mut m));
            let (mut qt, mut qtt) = (vec![0.0; d], vec![0.0; d]);
            sol.eval(t, &mut q, &mut qt, &mut qtt);
            for r in 0..l {
                let wr = basis(r, t).0 * if r == 0 { 1.0 } else { 2.0 } / s as f64;
                for j in 0..d {
                    for kk in 0..d {
                        let o = j * d + kk;
                        for p in 0..l {
                            let (f, f1, f2) = basis(p, t);
                            jac[(j * l + r) * n + kk * l + p] +=
                                wr * (k[o] * f + om * c[o] * f1 + om * om * m[o] * f2);
                        }
                        jac[(j * l + r) * n + d * l] +=
                            wr * (c[o] * qt[kk] + 2.0 * om * m[o] * qtt[kk]);
                    }
                }
            }
        }
        jac
    }

    #[test]
    fn product_to_sum_jacobian_equals_the_direct_projection() {
        use crate::model::Planar;
        use crate::periodic::{periodic, PeriodicOptions};
        let opts = |n_harm| PeriodicOptions {
            hb: HbOptions {
                n_harm,
                ..Default::default()
            },
            ..Default::default()
        };
        // Two merged balls on a converged R-R orbit (standard case), and motions of two
        // and three balls with one rotating and one oscillating ball: a series with
        // slowly decaying harmonics in every coordinate.
        let two = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let three = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.3, &[1.0, 0.8, 0.6]).unwrap();
        let rr = periodic(&two, &[true, true], None, &opts(3)).sol;
        assert_eq!(rr.status, Status::Converged);
        let synthetic = |winding: Vec<f64>, nh: usize| {
            let l = 2 * nh + 1;
            let coeffs = (0..winding.len() * l)
                .map(|i| {
                    let h = (i % l).div_ceil(2) as f64;
                    0.3 * ((i * 37 % 17) as f64 / 8.0 - 1.0) / (1.0 + h * h)
                })
                .collect();
            HbSolution::start(0.83, coeffs, winding, nh, Status::Converged)
        };
        let mut worst = 0.0f64;
        for nh in [3, 8, 12] {
            let rr_n = periodic(&two, &[true, true], Some(&rr), &opts(nh)).sol;
            assert_eq!(rr_n.status, Status::Converged);
            let cases: [(&Planar, HbSolution); 3] = [
                (&two, rr_n),
                (&two, synthetic(vec![0.0, 0.0, -1.0, 0.0], nh)),
                (&three, synthetic(vec![0.0, 0.0, 0.0, -1.0, -1.0], nh)),
            ];
            for (model, sol) in &cases {
                let s = default_samples(nh);
                let expect = direct_jacobian(*model, sol, s);
                let scale = expect.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                let mut sys = HbSystem::new(*model, &sol.winding, nh, s);
                let n = sys.size();
                let x = sol.unknowns();
                let (mut r, mut jac) = (vec![0.0; n], vec![0.0; n * n]);
                sys.assemble(&x, &mut r, Some(&mut jac));
                // Both paths, whichever `assemble` takes at this N.
                let (mut direct, mut pts) = (vec![0.0; n * n], vec![0.0; n * n]);
                assert!(sys.project_direct(sol.omega, &mut direct));
                sys.omega_column(sol.omega, &mut direct);
                assert!(sys.project_product_to_sum(sol.omega, &mut pts));
                sys.omega_column(sol.omega, &mut pts);
                for row in 0..n - 1 {
                    for col in 0..n {
                        let e = expect[row * n + col];
                        for (name, got) in [("assembled", &jac), ("direct", &direct), ("pts", &pts)]
                        {
                            let gap = (got[row * n + col] - e).abs();
                            worst = worst.max(gap / scale);
                            assert!(
                                gap <= 1e-13 * scale,
                                "N {nh} d {} {name} ({row},{col}): {} vs {e}",
                                sol.ndof(),
                                got[row * n + col]
                            );
                        }
                    }
                }
                // The rotating and oscillating balls' blocks are not empty.
                let nonzero = pts.iter().filter(|v| v.abs() > 1e-8 * scale).count();
                assert!(nonzero > n * n / 4, "N {nh}: {nonzero} of {}", n * n);
            }
        }
        println!("largest gap relative to the largest entry: {worst:.1e}");
    }

    #[test]
    fn solution_evaluation_is_the_series_coordinate_by_coordinate() {
        // `HbSolution::eval` shares one rotation recurrence between the coordinates; each
        // coordinate must still be `eval_series` to the bit, and `eval_series` the
        // closed form `w tau + a_0 + sum a_m cos m tau + b_m sin m tau` to round-off.
        let (n_harm, d) = (8, 3);
        let l = 2 * n_harm + 1;
        let coeffs: Vec<f64> = (0..d * l)
            .map(|k| ((k * 37 % 23) as f64 - 11.0) / 7.0)
            .collect();
        let sol = HbSolution::start(1.3, coeffs, vec![-1.0, 0.0, 2.0], n_harm, Status::Converged);
        let (mut q, mut qt, mut qtt) = (vec![0.0; d], vec![0.0; d], vec![0.0; d]);
        for k in 0..50 {
            let tau = 0.37 * k as f64 - 3.0;
            sol.eval(tau, &mut q, &mut qt, &mut qtt);
            for j in 0..d {
                let c = sol.coord(j);
                let (a, b, e) = eval_series(c, sol.winding[j], tau);
                assert_eq!(
                    [q[j], qt[j], qtt[j]].map(f64::to_bits),
                    [a, b, e].map(f64::to_bits)
                );
                let exact: f64 = sol.winding[j] * tau
                    + c[0]
                    + (1..=n_harm)
                        .map(|m| {
                            let mt = m as f64 * tau;
                            c[2 * m - 1] * mt.cos() + c[2 * m] * mt.sin()
                        })
                        .sum::<f64>();
                assert!((a - exact).abs() < 1e-12, "tau {tau}: {a} against {exact}");
            }
        }
    }

    /// The default sample count keeps aliasing below round-off of the results: solved
    /// again with three times the samples (the projections of the equations' products
    /// then exact far beyond the retained harmonics), Tien's (2011) standard orbit and
    /// its period-106 hard case at N = 6, 8 and 12 move by less than 1e-13 in omega and
    /// 1e-12 in any coefficient (measured: at most 6e-17 and 8e-15, round-off; their
    /// truncation errors are 1e-14 and 7e-8 in omega at N = 8; 36 samples at N = 8
    /// would move the hard case's coefficients by 1e-10).
    #[test]
    fn default_samples_alias_below_the_results_accuracy() {
        use crate::periodic::{periodic, PeriodicOptions};
        for (om, eta) in [(1.2, 1.0), (1.0, 0.7)] {
            let p = crate::Planar::new(0.2, 0.05, &[0.05], 50.0, om, &[eta, eta]).unwrap();
            let seed = periodic(&p, &[true, true], None, &PeriodicOptions::default()).sol;
            assert_eq!(seed.status, Status::Converged, "Omega {om}");
            for n_harm in [6, 8, 12] {
                let at = |samples| HbOptions {
                    n_harm,
                    samples: Some(samples),
                    ..Default::default()
                };
                let s = default_samples(n_harm);
                let a = solve(&p, &seed, &at(s));
                let b = solve(&p, &a, &at(3 * s));
                assert_eq!(a.status, Status::Converged);
                assert_eq!(b.status, Status::Converged);
                let dw = (a.omega - b.omega).abs();
                let dc = a
                    .coeffs
                    .iter()
                    .zip(&b.coeffs)
                    .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
                assert!(
                    dw < 1e-13 && dc < 1e-12,
                    "Omega {om} N {n_harm}: {dw:e} {dc:e}"
                );
            }
        }
    }

    #[test]
    fn series_evaluation_and_fit_round_trip() {
        let c = [0.3, 1.0, -0.5, 0.2, 0.1];
        let s = 16;
        let samples: Vec<f64> = (0..s)
            .map(|i| eval_series(&c, -1.0, 2.0 * PI * i as f64 / s as f64).0)
            .collect();
        let fit = fit_coefficients(&samples, 1, &[-1.0], 2);
        for (a, b) in fit.iter().zip(&c) {
            assert!((a - b).abs() < 1e-13);
        }
    }
}

#[cfg(all(test, feature = "studies"))]
mod studies;
