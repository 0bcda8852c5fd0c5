//! The disk centre carried by a hydrodynamic journal bearing instead of the spring–damper
//! (bearing.md section 4).
//!
//! Units. There is no spring, so the reference frequency is the film's:
//! `w_ref = C_S / M` with `C_S = mu_oil L R^3 / c^3` (time over `1 / w_ref`, forces over
//! `M e w_ref^2`, lengths over `e`), and the spin ratio `Omega = w / w_ref` is the
//! classical mass parameter `M c^3 w / (mu_oil L R^3)`. With `rho = e / c` the journal sits
//! at `X = rho R(theta) q` (units `c`) and moves at `V = rho R(theta) (q' + Omega J q) /
//! Omega` (units `c w`); the film force `F` (units `F_S = mu_oil w L R^3 / c^2 = C_S c w`)
//! becomes, over `M e w_ref^2`, `f = (Omega / rho) R(-theta) F(X, V)`
//! (`scripts/derive_bearing_support.py` checks this). The residual gains `-f` in the
//! x, y rows; the balls' rows are unchanged.
//!
//! Frames. A plain film, a grooved journal (grooves turning with the disk) and
//! narrow-groove theory are unchanged by a rotation of the whole bearing, so
//! `R(-theta) F(R(theta) X, R(theta) V; tau = theta) = F(X, V; tau = 0)`: the support is
//! evaluated in the disk's frame, which keeps the scene autonomous exactly (also for a
//! finite-volume grid, which turns with the disk). A grooved sleeve with the finite model
//! (resolved grooves) is not: it is evaluated in the fixed frame at `theta(t)` and the
//! support declares the time dependence `"grooved_sleeve"`.
//!
//! The balancer's `zeta` stays as an external viscous damper on the centre's ground
//! velocity, `2 zeta (q' + Omega J q)` (relative to `w_ref`: its value is not the
//! spring–damper scene's), in parallel with the film; 0 leaves the film alone.
//!
//! State. [`FilmSolver`] keeps factorisations (`&mut`), components take `&self`: the
//! support keeps a pool of solvers behind a mutex (one taken per evaluation, put back
//! after), so threads never share one. Factor reuse is never switched on, so a solver's
//! result does not depend on what it solved before: results do not depend on the thread
//! count. A journal at or past the wall (`eps >= 1`, where the film fails) gives a
//! non-finite residual, which the integrator rejects (the step shrinks until it fails).

use crate::error::{check_range, Error, Result};
use crate::model::bearing::{Bearing, FilmModel, FilmSolver, GrooveSide, JournalState};
use crate::model::component::{Component, Ctx};
use crate::model::Jacobians;
use crate::model::{Layout, ParamId};
use std::fmt;
use std::sync::{Arc, Mutex};

/// What produces the support force.
#[derive(Debug, Clone, PartialEq)]
pub enum SupportFilm {
    /// A journal bearing's Reynolds film.
    Reynolds(Bearing),
    /// An isotropic linear film `F = -k X - c V` in the bearing's units (force over
    /// `F_S`, position over `c`, velocity over `c w`): a check of the transform and the
    /// scaling, which with `k = 1 / Omega`, `c = 2 zeta` is the spring–damper support.
    Linear { stiffness: f64, damping: f64 },
}

/// The journal-bearing support of a scene: the film and `rho = e / c`.
#[derive(Debug, Clone, PartialEq)]
pub struct JournalSupport {
    pub film: SupportFilm,
    pub rho: f64,
}

impl JournalSupport {
    pub fn validate(&self) -> Result<()> {
        ParamId::Rho.check(self.rho)?;
        match &self.film {
            SupportFilm::Reynolds(b) => b.validate(),
            SupportFilm::Linear { stiffness, damping } => {
                check_range("stiffness", *stiffness, 0.0, false, f64::INFINITY, true)?;
                check_range("damping", *damping, 0.0, false, f64::INFINITY, true)
            }
        }
    }

    /// `Some("grooved_sleeve")` when the film is time-periodic in the disk's frame:
    /// resolved grooves (finite model) of nonzero depth on the stationary sleeve.
    pub fn time_dependence(&self) -> Option<&'static str> {
        let SupportFilm::Reynolds(b) = &self.film else {
            return None;
        };
        let resolved = matches!(b.model, FilmModel::Finite { .. });
        b.grooves
            .filter(|g| resolved && g.side == GrooveSide::Sleeve && g.depth > 0.0)
            .map(|_| "grooved_sleeve")
    }
}

/// Solvers of one bearing, taken and put back per evaluation (see the module docs).
pub struct SolverPool {
    bearing: Bearing,
    solvers: Mutex<Vec<FilmSolver>>,
}

impl SolverPool {
    pub fn new(bearing: Bearing) -> Self {
        SolverPool {
            bearing,
            solvers: Mutex::new(Vec::new()),
        }
    }

    pub fn bearing(&self) -> &Bearing {
        &self.bearing
    }

    fn with<T>(&self, f: impl FnOnce(&mut FilmSolver) -> T) -> Option<T> {
        let taken = self.solvers.lock().ok().and_then(|mut v| v.pop());
        let mut s = match taken {
            Some(s) => s,
            // validated with the scene: this cannot fail
            None => self.bearing.solver().ok()?,
        };
        let out = f(&mut s);
        if let Ok(mut v) = self.solvers.lock() {
            v.push(s);
        }
        Some(out)
    }
}

impl fmt::Debug for SolverPool {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SolverPool")
            .field("bearing", &self.bearing)
            .finish_non_exhaustive()
    }
}

/// The support component (see the module docs).
#[derive(Debug, Clone)]
pub struct BearingSupport {
    pub spec: JournalSupport,
    /// External viscous damping on the centre's ground velocity (the balancer's `zeta`).
    pub zeta: f64,
    /// Solvers of a Reynolds film (`None` for the linear film).
    pool: Option<Arc<SolverPool>>,
    fixed_frame: bool,
}

/// `dF/dX`, `dF/dV` (2 x 2 each, row-major by force component).
type FilmJacobian = ([[f64; 2]; 2], [[f64; 2]; 2]);

impl BearingSupport {
    /// `pool`: solvers of this bearing to share (a scene reassembled with the same film
    /// keeps its factorisations); a new one when `None` or of another bearing.
    pub fn new(spec: JournalSupport, zeta: f64, pool: Option<Arc<SolverPool>>) -> Self {
        let pool = match &spec.film {
            SupportFilm::Reynolds(b) => Some(match pool {
                Some(p) if p.bearing == *b => p,
                _ => Arc::new(SolverPool::new(b.clone())),
            }),
            SupportFilm::Linear { .. } => None,
        };
        BearingSupport {
            fixed_frame: spec.time_dependence().is_some(),
            spec,
            zeta,
            pool,
        }
    }

    pub fn pool(&self) -> Option<&Arc<SolverPool>> {
        self.pool.as_ref()
    }

    /// The film force `(F_x, F_y)` at `st` (bearing units); `None` past the wall.
    #[inline]
    fn film(&self, st: &JournalState) -> Option<[f64; 2]> {
        match (&self.spec.film, &self.pool) {
            (SupportFilm::Linear { stiffness, damping }, _) => Some([
                -stiffness * st.x - damping * st.vx,
                -stiffness * st.y - damping * st.vy,
            ]),
            (SupportFilm::Reynolds(_), Some(pool)) => pool.with(|s| s.force_xy(st).ok()).flatten(),
            (SupportFilm::Reynolds(_), None) => None,
        }
    }

    /// `dF/dX`, `dF/dV` at `st`: from one factorisation where the solver offers it
    /// (a grooved finite film), else central differences of the force (`8` evaluations).
    fn film_jacobian(&self, st: &JournalState) -> Option<FilmJacobian> {
        if let SupportFilm::Linear { stiffness, damping } = self.spec.film {
            let (k, c) = (-stiffness, -damping);
            return Some(([[k, 0.0], [0.0, k]], [[c, 0.0], [0.0, c]]));
        }
        if let SupportFilm::Reynolds(b) = &self.spec.film {
            // The plain finite film's force takes a sine-transform fast path that the
            // factorisation does not: differences of it are cheaper and consistent.
            if b.grooves.is_some_and(|g| g.depth > 0.0) {
                if let Some(Some((_, d))) = self
                    .pool
                    .as_ref()
                    .and_then(|p| p.with(|s| s.force_derivatives(st).ok().flatten()))
                {
                    return Some((
                        [[d[0][0], d[0][1]], [d[1][0], d[1][1]]],
                        [[d[0][2], d[0][3]], [d[1][2], d[1][3]]],
                    ));
                }
            }
        }
        let (mut dx, mut dv) = ([[0.0; 2]; 2], [[0.0; 2]; 2]);
        let base = [st.x, st.y, st.vx, st.vy];
        for j in 0..4 {
            // positions stay well inside the clearance circle: absolute steps
            let h = if j < 2 {
                1e-6
            } else {
                1e-6 * base[j].abs().max(1.0)
            };
            let mut up = base;
            let mut down = base;
            up[j] += h;
            down[j] -= h;
            let at = |z: [f64; 4]| JournalState {
                x: z[0],
                y: z[1],
                vx: z[2],
                vy: z[3],
                tau: st.tau,
            };
            let fp = self.film(&at(up))?;
            let fm = self.film(&at(down))?;
            let span = up[j] - down[j];
            for i in 0..2 {
                let d = (fp[i] - fm[i]) / span;
                if j < 2 {
                    dx[i][j] = d;
                } else {
                    dv[i][j - 2] = d;
                }
            }
        }
        Some((dx, dv))
    }

    /// The journal state (fixed frame, or the disk's when autonomous), the rotation
    /// `(cos, sin)` back to the disk's frame and the force factor `Omega / rho`.
    #[inline(always)]
    fn state(&self, cx: &Ctx, q: &[f64], v: &[f64]) -> (JournalState, f64, f64, f64) {
        let (ix, iy) = (cx.layout.x, cx.layout.y);
        let om = cx.spin.om;
        let rho = self.spec.rho;
        // ground velocity of the centre in the disk's components
        let (gx, gy) = (v[ix] - om * q[iy], v[iy] + om * q[ix]);
        let (s, c) = if self.fixed_frame {
            cx.spin.th.sin_cos()
        } else {
            (0.0, 1.0)
        };
        let k = rho / om;
        let st = JournalState {
            x: rho * (c * q[ix] - s * q[iy]),
            y: rho * (s * q[ix] + c * q[iy]),
            vx: k * (c * gx - s * gy),
            vy: k * (s * gx + c * gy),
            // grooves on the journal: evaluated in the journal's frame, where they rest
            tau: 0.0,
        };
        (st, c, s, om / rho)
    }
}

impl Component for BearingSupport {
    fn name(&self) -> &'static str {
        "bearing"
    }
    fn params(&self) -> &'static [ParamId] {
        &[
            ParamId::Zeta,
            ParamId::Rho,
            ParamId::GrooveDepth,
            ParamId::GrooveAngle,
        ]
    }
    fn time_dependence(&self) -> Option<&'static str> {
        self.spec.time_dependence()
    }
    fn coords(&self, l: &Layout) -> Vec<usize> {
        l.support().to_vec()
    }
    fn has_inertia(&self) -> bool {
        false
    }
    #[inline]
    fn add_residual(&self, cx: &Ctx, q: &[f64], v: &[f64], _a: &[f64], out: &mut [f64]) {
        let (ix, iy) = (cx.layout.x, cx.layout.y);
        let (st, c, s, scale) = self.state(cx, q, v);
        let [fx, fy] = self.film(&st).unwrap_or([f64::NAN; 2]);
        let (fx, fy) = (scale * (c * fx + s * fy), scale * (-s * fx + c * fy));
        let (z, om) = (self.zeta, cx.spin.om);
        out[ix] += 2.0 * z * (v[ix] - om * q[iy]) - fx;
        out[iy] += 2.0 * z * (v[iy] + om * q[ix]) - fy;
    }
    fn add_jacobians(&self, cx: &Ctx, q: &[f64], v: &[f64], _a: &[f64], jac: Jacobians<'_>) {
        let Jacobians { k, c: cm, m: _m } = jac;
        let (ix, iy, d) = (cx.layout.x, cx.layout.y, cx.ndof());
        let (st, c, s, _) = self.state(cx, q, v);
        let om = cx.spin.om;
        let nan = [[f64::NAN; 2]; 2];
        let (dx, dv) = self.film_jacobian(&st).unwrap_or((nan, nan));
        // f = (Om/rho) R^T F(rho R q, rho R (v + Om J q) / Om):
        // df/dq = Om R^T (D_X + D_V J) R, df/dv = R^T D_V R (R commutes with J).
        let rot = [[c, -s], [s, c]];
        let j = [[0.0, -1.0], [1.0, 0.0]];
        let mul = |a: [[f64; 2]; 2], b: [[f64; 2]; 2]| {
            let mut r = [[0.0; 2]; 2];
            for (i, row) in r.iter_mut().enumerate() {
                for (jj, x) in row.iter_mut().enumerate() {
                    *x = a[i][0] * b[0][jj] + a[i][1] * b[1][jj];
                }
            }
            r
        };
        let rt = [[c, s], [-s, c]];
        let dvj = mul(dv, j);
        let kq = mul(
            rt,
            mul(
                [
                    [dx[0][0] + dvj[0][0], dx[0][1] + dvj[0][1]],
                    [dx[1][0] + dvj[1][0], dx[1][1] + dvj[1][1]],
                ],
                rot,
            ),
        );
        let cv = mul(rt, mul(dv, rot));
        let rows = [ix, iy];
        for (a, &r) in rows.iter().enumerate() {
            for (b, &col) in rows.iter().enumerate() {
                k[r * d + col] -= om * kq[a][b];
                cm[r * d + col] -= cv[a][b];
            }
        }
        let z = self.zeta;
        k[ix * d + iy] -= 2.0 * z * om;
        k[iy * d + ix] += 2.0 * z * om;
        cm[ix * d + ix] += 2.0 * z;
        cm[iy * d + iy] += 2.0 * z;
    }
}

/// The error for a bearing parameter asked of a scene without one.
pub fn no_bearing(name: &str) -> Error {
    Error::param(
        name,
        "is a bearing parameter, and the scene's support is the spring–damper",
    )
}
