//! Narrow-groove theory (Vohr & Chow 1965): the herringbone film smoothed over one groove
//! pitch, an anisotropic Reynolds equation that is exact as the groove count `N_g -> inf`.
//!
//! # Derivation (local averaging over one pitch)
//!
//! Flux per unit width (units as in [`super`]: `12 q` scaled by `mu w R^2 / c^2`) in a film
//! `H` between a surface moving at speed 1 along `e_theta` and a fixed one:
//! `Q = -H^3 grad P + 6 H e_theta`, and continuity is `12 dH/dtau + div Q = 0`.
//!
//! **Sleeve grooves.** Over one pitch the film is `h_g = h + delta_g` on a groove (fraction
//! `gamma` of the pitch) and `h_l = h` on a land, `h` the smooth film there. Take unit vectors
//! `e_s` along the grooves and `e_n` across them. For `N_g -> inf` the pressure is a smooth mean
//! `P` plus a fluctuation periodic over the pitch, and within a pitch the pattern depends on
//! the coordinate along `e_n` only, so
//!
//! * along the grooves the gradient `dP/ds` is continuous across every groove edge (it is a
//!   tangential derivative of a continuous `P`): the same `G_s` on groove and land, and the flux
//!   along `e_s` is the arithmetic mean `Q_s = -<h^3> G_s + 6 <h> u_s`;
//! * across the grooves the flux `Q_n = -h^3 g_n + 6 h u_n` is the same on groove and land
//!   (continuity), so `g_n = (6 h u_n - Q_n) / h^3`, whose mean over the pitch is the mean
//!   gradient `G_n = 6 u_n <h^-2> - Q_n <h^-3>`: `Q_n = -G_n / <h^-3> + 6 u_n <h^-2> / <h^-3>`
//!   (the harmonic mean of `h^3` conducts across the grooves),
//!
//! with `u_s = e_theta . e_s`, `u_n = e_theta . e_n` and `<f> = gamma f(h_g) + (1 - gamma) f(h_l)`.
//! In the `(theta, zeta)` axes the mean flux is `Q = -A grad P + 6 c` with
//!
//! ```text
//! A = a_s e_s e_s^T + a_n e_n e_n^T,    a_s = <h^3>,  a_n = 1 / <h^-3>,
//! c = <h> u_s e_s + h_c u_n e_n = <h> e_theta - D u_n e_n,   h_c = <h^-2> / <h^-3>,  D = <h> - h_c >= 0
//! ```
//!
//! (`D >= 0` by Chebyshev's inequality: `h` and `h^-3` are oppositely ordered). The grooves of
//! the symmetric herringbone are the lines of constant phase `theta + s |zeta| cot(beta)` (see
//! [`super::Grooves`]), so with `g = sign(zeta)`: `e_s = (cos b, -s g sin b)`,
//! `e_n = (s g sin b, cos b)`, `u_n = s g sin b`, and
//!
//! ```text
//! A_tt = a_s cos^2 b + a_n sin^2 b,   A_zz = a_s sin^2 b + a_n cos^2 b,
//! A_tz = -s g (a_s - a_n) sin b cos b,
//! c_t = <h> - D sin^2 b,               c_z = -g D sin b cos b
//! ```
//!
//! `c_z` is the pumping: the cross term `D u_n e_n` of the Couette flux points along the
//! grooves' normal, and its axial part drives fluid towards the mid-plane (`c_z < 0` for
//! `zeta > 0`) whatever the chirality, because `s` enters squared. The mean film `<h> = h +
//! gamma delta_g` moves only with `h`, so the smoothed equation is
//! `div(A grad P) = 6 div c + 12 dh/dtau`.
//!
//! **Journal grooves.** In the frame turning with the journal the grooves stand still and the
//! sleeve moves at `-1`: `Q' = -A grad P - 6 c'` with `c'` the expression above (chirality
//! `s = -1`). Back in the fixed frame the flux gains the transported film,
//! `Q = Q' + 12 <h> e_theta`, and the smoothed coefficients do not depend on the groove phase:
//! the smoothed film is **steady in the fixed frame** (no `tau`). So `c = 2 <h> e_theta - c'`:
//! `c_t = <h> + D sin^2 b`, `c_z = -g D sin b cos b` (with `s = -1`, `u_n e_n` has
//! `zeta` part `-g sin b cos b`): the pumping keeps its sign, only the circumferential flow
//! changes. Both sides: `c_t = <h> - s D sin^2 b`. (Putting the moving grooves only into the
//! Couette term of the fixed frame would pump outwards: bearing.md section 1.)
//!
//! With `delta_g = 0`: `A = h^3 I`, `c = h e_theta`, the plain film. For a concentric journal
//! with grooves over the whole length, `P` depends on `zeta` only and the flux through the
//! mid-plane vanishes by symmetry, so `A_zz P' = 6 c_z`: the apex pressure is
//! `6 lambda D sin b cos b / A_zz`, Muijderman's spiral-groove pressure rise (the tests
//! check it against his formula).
//!
//! # Discretisation
//!
//! The cells, faces and conventions of [`super::finite`]: `A_tt` on the theta faces and
//! `A_zz` on the zeta faces as its face conductances (from the smooth film on the face; the
//! face's grooved fraction for a grooved length below 1), the Couette flux `6 c` as a flux
//! difference over all four faces, the squeeze term integrated exactly. The cross conductance
//! `A_tz` needs the tangential gradient on a face: it enters through the energy
//! `int A_tz dP/dtheta dP/dzeta` taken at every grid vertex with the gradients averaged from
//! the four cells around it (`P = 0` at the ends, half a cell away), integrated over the
//! vertex's dual cell with `g` averaged there (zero on the mid-plane). The matrix stays
//! symmetric and conservative (a 9-point stencil; positive definite since `A` is, though not an
//! M-matrix), and with `delta_g = 0` it is exactly [`super::finite`]'s matrix. Cavitation as
//! there: clip, Swift–Stieber active set, or none.
//!
//! Ctrl-C ([`crate::cancel`]) is polled as in [`super::finite`]: between faer's calls (each
//! one uninterruptible), assemblies and active-set iterations.

use super::finite::{active_set, FiniteSolver};
use super::{Bearing, Cavitation, FilmForce, Grooves, JournalState};
use crate::error::{Error, Result};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{MatMut, Side};
use std::f64::consts::PI;

/// Smoothed conductances and Couette film of a groove/land pair at smooth film `h`:
/// `(a_s, a_n, <h>, D)` (along, across, mean film, pumping film; see the module doc).
pub fn pitch_average(h: f64, depth: f64, width: f64) -> (f64, f64, f64, f64) {
    let hg = h + depth;
    let mean = |f: &dyn Fn(f64) -> f64| width * f(hg) + (1.0 - width) * f(h);
    let m1 = mean(&|v| v);
    let m3 = mean(&|v| v * v * v);
    let r2 = mean(&|v| 1.0 / (v * v));
    let r3 = mean(&|v| 1.0 / (v * v * v));
    (m3, 1.0 / r3, m1, m1 - r2 / r3)
}

/// Smoothed coefficients at smooth film `h`, chirality `s`, axial side `g` (`+-1`):
/// `[A_tt, A_zz, A_tz, c_t, c_z]`.
pub fn coefficients(h: f64, grooves: &Grooves, g: f64) -> [f64; 5] {
    let (a_s, a_n, m1, d) = pitch_average(h, grooves.depth, grooves.width);
    let (sb, cb) = grooves.angle.sin_cos();
    let s = grooves.chirality();
    [
        a_s * cb * cb + a_n * sb * sb,
        a_s * sb * sb + a_n * cb * cb,
        -s * g * (a_s - a_n) * sb * cb,
        m1 - s * d * sb * sb,
        -g * d * sb * cb,
    ]
}

/// The narrow-groove solver of one grooved bearing on `n_theta x n_zeta` cells.
pub struct NarrowSolver {
    /// The plain film on the same grid: force integration and the field.
    plain: FiniteSolver,
    lambda: f64,
    nt: usize,
    nz: usize,
    dth: f64,
    dz: f64,
    grooves: Grooves,
    cavitation: Cavitation,
    sf: Vec<f64>,
    cf: Vec<f64>,
    /// Grooved fraction of the theta faces of cell row `j` and of zeta face `j`.
    wt: Vec<f64>,
    wz: Vec<f64>,
    /// Mean of `sign(zeta)` times the grooved indicator over the dual cell of vertex row `j`.
    sigma: Vec<f64>,
    pattern: SymbolicSparseColMat<usize>,
    /// Stencil slot `(di + 1) * 3 + (dj + 1)` of the column cell for every stored entry.
    slots: Vec<u8>,
    symbolic: SymbolicLlt<usize>,
}

fn slot(di: isize, dj: isize) -> usize {
    ((di + 1) * 3 + (dj + 1)) as usize
}

impl NarrowSolver {
    pub fn new(bearing: &Bearing, nt: usize, nz: usize) -> Result<Self> {
        let grooves = bearing.grooves.ok_or_else(|| {
            Error::param(
                "grooves",
                "narrow-groove theory smooths grooves: none given",
            )
        })?;
        let plain_bearing = Bearing {
            grooves: None,
            ..bearing.clone()
        };
        let plain = FiniteSolver::new(&plain_bearing, nt, nz)?;
        let lambda = bearing.lambda;
        let dth = 2.0 * PI / nt as f64;
        let dz = 2.0 * lambda / nz as f64;
        let u_max = grooves.length_fraction * lambda;
        let overlap = |a: f64, b: f64| (b.min(u_max) - a.max(-u_max)).max(0.0);
        let wt = (0..nz)
            .map(|j| {
                let za = -lambda + j as f64 * dz;
                overlap(za, za + dz) / dz
            })
            .collect();
        let wz = (0..=nz)
            .map(|j| {
                let z = (-lambda + j as f64 * dz).abs();
                if z <= u_max * (1.0 + 1e-12) {
                    1.0
                } else {
                    0.0
                }
            })
            .collect();
        let sigma = (0..=nz)
            .map(|j| {
                let z = -lambda + j as f64 * dz;
                let (a, b) = ((z - 0.5 * dz).max(-lambda), (z + 0.5 * dz).min(lambda));
                (overlap(a.max(0.0), b.max(0.0)) - overlap(a.min(0.0), b.min(0.0))) / (b - a)
            })
            .collect();
        let n = nt * nz;
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(5 * n);
        let mut slots = Vec::with_capacity(5 * n);
        col_ptr.push(0);
        for i in 0..nt {
            for j in 0..nz {
                let c = i * nz + j;
                let mut rows: Vec<(usize, u8)> = Vec::with_capacity(9);
                for di in -1..=1_isize {
                    for dj in -1..=1_isize {
                        let jj = j as isize + dj;
                        if jj < 0 || jj >= nz as isize {
                            continue;
                        }
                        let ii = (i as isize + di).rem_euclid(nt as isize) as usize;
                        let r = ii * nz + jj as usize;
                        if r <= c {
                            rows.push((r, slot(di, dj) as u8));
                        }
                    }
                }
                rows.sort_unstable();
                for (r, k) in rows {
                    row_idx.push(r);
                    slots.push(k);
                }
                col_ptr.push(row_idx.len());
            }
        }
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        // The symbolic factorisation is one uninterruptible faer call (see `cancel`).
        crate::cancel::check()?;
        let symbolic = SymbolicLlt::try_new(pattern.as_ref(), Side::Upper)
            .map_err(|e| Error::param("model", format!("sparse factorisation failed: {e:?}")))?;
        Ok(NarrowSolver {
            plain,
            lambda,
            nt,
            nz,
            dth,
            dz,
            grooves,
            cavitation: bearing.cavitation,
            sf: (0..=nt).map(|i| (i as f64 * dth).sin()).collect(),
            cf: (0..=nt).map(|i| (i as f64 * dth).cos()).collect(),
            wt,
            wz,
            sigma,
            pattern,
            slots,
            symbolic,
        })
    }

    /// The 9-point stencil `[c * 9 + slot]` of `M` and the right-hand side `rhs` of
    /// `M P = -rhs` (as in [`super::finite`]).
    fn assemble(&self, s: &JournalState) -> (Vec<f64>, Vec<f64>) {
        let (nt, nz, dth, dz) = (self.nt, self.nz, self.dth, self.dz);
        let g = &self.grooves;
        let mut st = vec![0.0; nt * nz * 9];
        let mut rhs = vec![0.0; nt * nz];
        // sign(zeta) (0 on the mid-plane) of cell row j (2 j + 1 half-cells from the end) or
        // of face j (2 j half-cells).
        let side = |j2: usize| match j2.cmp(&nz) {
            std::cmp::Ordering::Less => -1.0,
            std::cmp::Ordering::Equal => 0.0,
            std::cmp::Ordering::Greater => 1.0,
        };
        let mix = |w: f64, grooved: f64, plain: f64| w * grooved + (1.0 - w) * plain;
        let couple = |st: &mut Vec<f64>, a: usize, b: usize, di: isize, dj: isize, k: f64| {
            st[a * 9 + slot(0, 0)] += k;
            st[b * 9 + slot(0, 0)] += k;
            st[a * 9 + slot(di, dj)] -= k;
            st[b * 9 + slot(-di, -dj)] -= k;
        };
        // theta faces: face i between cells (i-1, j) and (i, j), smooth film at theta_i.
        let mut ct = vec![0.0; nt * nz];
        for i in 0..nt {
            let h = 1.0 - s.x * self.cf[i] - s.y * self.sf[i];
            let iw = (i + nt - 1) % nt;
            for j in 0..nz {
                let co = coefficients(h, g, side(2 * j + 1));
                let att = mix(self.wt[j], co[0], h * h * h);
                ct[i * nz + j] = mix(self.wt[j], co[3], h);
                couple(&mut st, iw * nz + j, i * nz + j, 1, 0, att * dz / dth);
            }
        }
        for i in 0..nt {
            let ie = (i + 1) % nt;
            let sq = -12.0
                * dz
                * (s.vx * (self.sf[i + 1] - self.sf[i]) - s.vy * (self.cf[i + 1] - self.cf[i]));
            for j in 0..nz {
                rhs[i * nz + j] = 6.0 * dz * (ct[ie * nz + j] - ct[i * nz + j]) + sq;
            }
        }
        // zeta faces: face j of column i, the smooth film averaged over the face.
        for i in 0..nt {
            let h = 1.0 - s.x * (self.sf[i + 1] - self.sf[i]) / dth
                + s.y * (self.cf[i + 1] - self.cf[i]) / dth;
            for j in 0..=nz {
                let co = coefficients(h, g, side(2 * j));
                let azz = mix(self.wz[j], co[1], h * h * h);
                let flux = 6.0 * dth * self.wz[j] * co[4];
                if j > 0 {
                    rhs[i * nz + j - 1] += flux;
                }
                if j < nz {
                    rhs[i * nz + j] -= flux;
                }
                if j == 0 || j == nz {
                    let c = i * nz + if j == 0 { 0 } else { nz - 1 };
                    st[c * 9 + slot(0, 0)] += azz * 2.0 * dth / dz;
                } else {
                    couple(&mut st, i * nz + j - 1, i * nz + j, 0, 1, azz * dth / dz);
                }
            }
        }
        // Vertices (theta_i, zeta_j): the cross energy alpha gbar_theta gbar_zeta.
        for i in 0..nt {
            let h = 1.0 - s.x * self.cf[i] - s.y * self.sf[i];
            let atz = coefficients(h, g, 1.0)[2];
            let iw = (i + nt - 1) % nt;
            for j in 0..=nz {
                if self.sigma[j] == 0.0 {
                    continue;
                }
                // (cell, di, dj relative to the ne cell, u, w) for the cells present.
                let mut cells: [(usize, isize, isize, f64, f64); 4] = [(0, 0, 0, 0.0, 0.0); 4];
                let mut m = 0;
                let (ut, area) = (0.5 / dth, if j == 0 || j == nz { 0.5 } else { 1.0 });
                let wz = if j == 0 || j == nz {
                    1.0 / dz
                } else {
                    0.5 / dz
                };
                if j > 0 {
                    cells[m] = (iw * nz + j - 1, -1, -1, -ut, -wz);
                    cells[m + 1] = (i * nz + j - 1, 0, -1, ut, -wz);
                    m += 2;
                }
                if j < nz {
                    cells[m] = (iw * nz + j, -1, 0, -ut, wz);
                    cells[m + 1] = (i * nz + j, 0, 0, ut, wz);
                    m += 2;
                }
                let alpha = atz * self.sigma[j] * area * dth * dz;
                for &(a, ai, aj, ua, wa) in &cells[..m] {
                    for &(_, bi, bj, ub, wb) in &cells[..m] {
                        st[a * 9 + slot(bi - ai, bj - aj)] += alpha * (ua * wb + wa * ub);
                    }
                }
            }
        }
        (st, rhs)
    }

    /// Matrix values in pattern order; cells in `fixed` get an identity row and column.
    fn values(&self, st: &[f64], fixed: Option<&[bool]>) -> Vec<f64> {
        let is_fixed = |c: usize| fixed.is_some_and(|f| f[c]);
        let cols = self.pattern.col_ptr();
        let rows = self.pattern.row_idx();
        let mut vals = Vec::with_capacity(rows.len());
        for c in 0..self.nt * self.nz {
            for e in cols[c]..cols[c + 1] {
                let r = rows[e];
                vals.push(if r == c && is_fixed(c) {
                    1.0
                } else if is_fixed(r) || is_fixed(c) {
                    0.0
                } else {
                    st[c * 9 + self.slots[e] as usize]
                });
            }
        }
        vals
    }

    fn solve_fixed(&self, st: &[f64], rhs: &[f64], fixed: Option<&[bool]>) -> Result<Vec<f64>> {
        let vals = self.values(st, fixed);
        // Before faer's factorisation, one uninterruptible call (see `cancel`).
        crate::cancel::check()?;
        let mat = SparseColMatRef::new(self.pattern.as_ref(), &vals);
        let llt =
            Llt::try_new_with_symbolic(self.symbolic.clone(), mat, Side::Upper).map_err(|e| {
                Error::Eigen(format!("narrow-groove matrix not positive definite: {e:?}"))
            })?;
        let mut b: Vec<f64> = rhs
            .iter()
            .enumerate()
            .map(|(c, r)| if fixed.is_some_and(|f| f[c]) { 0.0 } else { -r })
            .collect();
        let n = b.len();
        llt.solve_in_place(MatMut::from_column_major_slice_mut(&mut b, n, 1));
        Ok(b)
    }

    /// `(M P)_c` from the stencil.
    fn apply(&self, st: &[f64], p: &[f64]) -> Vec<f64> {
        let (nt, nz) = (self.nt, self.nz);
        let mut out = vec![0.0; nt * nz];
        for i in 0..nt {
            for j in 0..nz {
                let c = i * nz + j;
                let mut v = 0.0;
                for di in -1..=1_isize {
                    let ii = (i as isize + di).rem_euclid(nt as isize) as usize;
                    for dj in -1..=1_isize {
                        let jj = j as isize + dj;
                        if jj >= 0 && jj < nz as isize {
                            v += st[c * 9 + slot(di, dj)] * p[ii * nz + jj as usize];
                        }
                    }
                }
                out[c] = v;
            }
        }
        out
    }

    /// The (cavitated) pressure at `s`.
    pub fn pressure(&self, s: &JournalState) -> Result<Vec<f64>> {
        crate::cancel::check()?;
        let (st, rhs) = self.assemble(s);
        let p = self.solve_fixed(&st, &rhs, None)?;
        Ok(match self.cavitation {
            Cavitation::None => p,
            Cavitation::HalfSommerfeld => p.into_iter().map(|v| v.max(0.0)).collect(),
            Cavitation::Reynolds => active_set(
                &rhs,
                p,
                |fixed| self.solve_fixed(&st, &rhs, Some(fixed)),
                |p| self.apply(&st, p),
            )?,
        })
    }

    pub fn force(&mut self, s: &JournalState, want_field: bool) -> Result<FilmForce> {
        let p = self.pressure(s)?;
        Ok(self.plain.finish(s, p, want_field))
    }

    /// `(lambda, n_theta, n_zeta)`.
    pub fn grid(&self) -> (f64, usize, usize) {
        (self.lambda, self.nt, self.nz)
    }

    /// The force at `s` and its derivatives with respect to position and velocity from
    /// **one** factorisation, as [`FiniteSolver::linearise`]: `M dP/ds = -d rhs/ds - (dM/ds) P`.
    /// The operator's derivatives `dM/ds`, `d rhs/ds` are central differences of the assembly
    /// (step `1e-5`: smooth functions of the film, error about `1e-10`); the right-hand side is
    /// affine in the velocity, so that difference is exact. `None` for the Reynolds condition.
    pub fn linearise(&mut self, s: &JournalState) -> Result<Option<(FilmForce, [[f64; 4]; 2])>> {
        if self.cavitation == Cavitation::Reynolds {
            return Ok(None);
        }
        let n = self.nt * self.nz;
        crate::cancel::check()?;
        let (st, rhs) = self.assemble(s);
        let vals = self.values(&st, None);
        crate::cancel::check()?;
        let mat = SparseColMatRef::new(self.pattern.as_ref(), &vals);
        let llt =
            Llt::try_new_with_symbolic(self.symbolic.clone(), mat, Side::Upper).map_err(|e| {
                Error::Eigen(format!("narrow-groove matrix not positive definite: {e:?}"))
            })?;
        let mut b = faer::Mat::<f64>::zeros(n, 5);
        for c in 0..n {
            b[(c, 0)] = -rhs[c];
        }
        llt.solve_in_place(b.as_mut().subcols_mut(0, 1));
        let p: Vec<f64> = (0..n).map(|c| b[(c, 0)]).collect();
        let h = 1e-5;
        let moved = |dx: f64, dy: f64| JournalState {
            x: s.x + dx,
            y: s.y + dy,
            ..*s
        };
        for (col, (gx, gy)) in [(1.0, 0.0), (0.0, 1.0)].into_iter().enumerate() {
            crate::cancel::check()?;
            let (stp, rp) = self.assemble(&moved(h * gx, h * gy));
            let (stm, rm) = self.assemble(&moved(-h * gx, -h * gy));
            let dst: Vec<f64> = stp
                .iter()
                .zip(&stm)
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect();
            let dmp = self.apply(&dst, &p);
            for c in 0..n {
                b[(c, 1 + col)] = -(rp[c] - rm[c]) / (2.0 * h) - dmp[c];
            }
        }
        let still = JournalState {
            vx: 0.0,
            vy: 0.0,
            ..*s
        };
        let (_, r0) = self.assemble(&still);
        for (col, (vx, vy)) in [(1.0, 0.0), (0.0, 1.0)].into_iter().enumerate() {
            crate::cancel::check()?;
            let (_, r1) = self.assemble(&JournalState { vx, vy, ..still });
            for c in 0..n {
                b[(c, 3 + col)] = -(r1[c] - r0[c]);
            }
        }
        llt.solve_in_place(b.as_mut().subcols_mut(1, 4));
        let clip = self.cavitation == Cavitation::HalfSommerfeld;
        let mut out = [[0.0; 4]; 2];
        for k in 0..4 {
            let dp: Vec<f64> = (0..n)
                .map(|c| {
                    if clip && p[c] < 0.0 {
                        0.0
                    } else {
                        b[(c, 1 + k)]
                    }
                })
                .collect();
            let (dfx, dfy) = self.plain.integrate(&dp);
            out[0][k] = dfx;
            out[1][k] = dfy;
        }
        let p = if clip {
            p.into_iter().map(|v| v.max(0.0)).collect()
        } else {
            p
        };
        Ok(Some((self.plain.finish(s, p, false), out)))
    }
}

#[cfg(test)]
mod tests {
    //! Each against something independent: the plain finite film (another assembly and
    //! solver), Muijderman's closed form, symmetry, and the resolved grooved film.
    use super::super::{linear_coefficients_fd, FilmModel, FilmSolver, GrooveSide};
    use super::*;

    fn herringbone(count: usize, angle_deg: f64, depth: f64, side: GrooveSide) -> Grooves {
        Grooves {
            count,
            angle: angle_deg.to_radians(),
            depth,
            width: 0.5,
            length_fraction: 1.0,
            side,
        }
    }

    fn bearing(lambda: f64, g: Option<Grooves>, cav: Cavitation, model: FilmModel) -> FilmSolver {
        Bearing {
            lambda,
            grooves: g,
            cavitation: cav,
            model,
        }
        .solver()
        .expect("valid bearing")
    }

    fn ngt(nt: usize, nz: usize) -> FilmModel {
        FilmModel::NarrowGroove {
            n_theta: nt,
            n_zeta: nz,
        }
    }

    fn fin(nt: usize, nz: usize) -> FilmModel {
        FilmModel::Finite {
            n_theta: nt,
            n_zeta: nz,
        }
    }

    #[test]
    fn narrow_depth_zero_is_the_plain_film() {
        // The 9-point narrow-groove assembly and its sparse Cholesky against the plain finite
        // film's sine-transform solve (or its 5-point active set for Reynolds).
        let st = JournalState {
            x: 0.45,
            y: -0.3,
            vx: 0.1,
            vy: -0.2,
            tau: 0.3,
        };
        for cav in [
            Cavitation::HalfSommerfeld,
            Cavitation::None,
            Cavitation::Reynolds,
        ] {
            let fp = bearing(0.8, None, cav, fin(64, 16))
                .force(&st, true)
                .unwrap();
            for side in [GrooveSide::Sleeve, GrooveSide::Journal] {
                for length_fraction in [1.0, 0.6] {
                    let g = Grooves {
                        length_fraction,
                        ..herringbone(5, 35.0, 0.0, side)
                    };
                    let fg = bearing(0.8, Some(g), cav, ngt(64, 16))
                        .force(&st, true)
                        .unwrap();
                    let d = (fg.fx - fp.fx).hypot(fg.fy - fp.fy) / fp.fx.hypot(fp.fy);
                    assert!(d < 1e-12, "{cav:?} {side:?}: {d:e}");
                    let (pg, pp) = (fg.pressure.unwrap(), fp.pressure.as_ref().unwrap());
                    let dp = pg
                        .values
                        .iter()
                        .zip(&pp.values)
                        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
                    assert!(dp < 1e-12 * fp.p_max, "{cav:?}: {dp:e}");
                }
            }
        }
    }

    /// Muijderman (1966, *Spiral Groove Bearings*, the pressure-generation function `g_1`):
    /// a grooved surface sliding at `U` over a smooth one builds `dp/dz = 6 mu U g_1 / h_r^2`
    /// across the grooves' direction, `H = h_groove / h_ridge`, `alpha` the groove angle from
    /// the sliding direction, `gamma` the groove fraction.
    fn muijderman_g1(h: f64, gamma: f64, alpha: f64) -> f64 {
        let t = alpha.tan();
        let h3 = h * h * h;
        gamma * (1.0 - gamma) * (h3 - 1.0) * (h - 1.0) * t
            / (h3 * (1.0 + t * t) + gamma * (1.0 - gamma) * (h3 - 1.0).powi(2) * t * t)
    }

    #[test]
    fn narrow_concentric_apex_pressure_is_muijderman() {
        let lambda = 0.7;
        let (nt, nz) = (32, 20);
        for (angle, depth, width) in [(30.0, 1.0, 0.5), (20.0, 2.0, 0.3), (60.0, 0.5, 0.7)] {
            for side in [GrooveSide::Sleeve, GrooveSide::Journal] {
                let g = Grooves {
                    width,
                    ..herringbone(12, angle, depth, side)
                };
                let mut s = bearing(lambda, Some(g), Cavitation::HalfSommerfeld, ngt(nt, nz));
                let f = s.force(&JournalState::at(0.0, 0.0), true).unwrap();
                let p = f.pressure.unwrap();
                // Ridge film = clearance: h_ridge = 1, H = 1 + delta; dP/dzeta = 6 g_1 outward.
                let g1 = muijderman_g1(1.0 + depth, width, f64::to_radians(angle));
                for (k, v) in p.values.iter().enumerate() {
                    let want = 6.0 * g1 * (lambda - p.zeta[k % nz].abs());
                    assert!(
                        (v - want).abs() < 1e-12 * 6.0 * g1 * lambda,
                        "{v} vs {want}"
                    );
                }
                println!(
                    "angle {angle}, depth {depth}, width {width}, {side:?}: apex P = 6 g1 lambda = {:.5}",
                    6.0 * g1 * lambda
                );
                assert!(f.fx.hypot(f.fy) < 1e-13 * f.p_max, "concentric: no load");
            }
        }
    }

    #[test]
    fn narrow_grooves_give_direct_stiffness_at_centre() {
        let plain = linear_coefficients_fd(
            &mut bearing(1.0, None, Cavitation::HalfSommerfeld, ngt(64, 16)),
            0.0,
            0.0,
        )
        .unwrap();
        for side in [GrooveSide::Sleeve, GrooveSide::Journal] {
            let g = herringbone(20, 30.0, 1.0, side);
            let mut s = bearing(1.0, Some(g), Cavitation::HalfSommerfeld, ngt(64, 16));
            let lc = linear_coefficients_fd(&mut s, 0.0, 0.0).unwrap();
            println!("{side:?}: NGT K at centre {:?}, plain {:?}", lc.k, plain.k);
            assert!(plain.k[(0, 0)].abs() < 1e-5 * plain.k[(0, 1)].abs());
            assert!(lc.k[(0, 0)] > 0.1 * lc.k[(0, 1)].abs(), "{side:?}");
            assert!((lc.k[(1, 1)] - lc.k[(0, 0)]).abs() < 1e-6 * lc.k[(0, 0)]);
        }
    }

    /// The resolved herringbone film (finite model, 16 cells per pitch, `n_zeta` growing with
    /// the count) approaches the smoothed one as the grooves multiply.
    #[test]
    fn narrow_is_the_limit_of_many_grooves() {
        let lambda = 0.5;
        let angle = 45.0;
        let eccentric = JournalState::at(0.0, -0.5);
        for side in [GrooveSide::Sleeve, GrooveSide::Journal] {
            let counts: &[usize] = match side {
                GrooveSide::Sleeve => &[8, 16, 32, 64],
                GrooveSide::Journal => &[8, 16, 32],
            };
            let mut apex_d = Vec::new();
            let mut force_d = Vec::new();
            for &n in counts {
                let g = herringbone(n, angle, 1.0, side);
                let nt = 16 * n;
                let nz = (2 * n.div_ceil(2)).max(32);
                let mut f = bearing(lambda, Some(g), Cavitation::HalfSommerfeld, fin(nt, nz));
                let mut s = bearing(lambda, Some(g), Cavitation::HalfSommerfeld, ngt(nt, nz));
                // Apex: the mean over theta of the two cell rows beside the mid-plane.
                let apex = |ff: &FilmForce| {
                    let p = ff.pressure.as_ref().unwrap();
                    let mut sum = 0.0;
                    for i in 0..nt {
                        sum += p.values[i * nz + nz / 2 - 1] + p.values[i * nz + nz / 2];
                    }
                    sum / (2 * nt) as f64
                };
                let c = JournalState::at(0.0, 0.0);
                let (af, an) = (
                    apex(&f.force(&c, true).unwrap()),
                    apex(&s.force(&c, true).unwrap()),
                );
                let ef = f.force(&eccentric, false).unwrap();
                let en = s.force(&eccentric, false).unwrap();
                let d = (ef.fx - en.fx).hypot(ef.fy - en.fy) / en.fx.hypot(en.fy);
                println!(
                    "{side:?} N_g {n:3} ({nt} x {nz}): apex P finite {af:.5} NGT {an:.5} (rel diff {:.2e}); \
                     eps 0.5 force finite ({:.5}, {:.5}) NGT ({:.5}, {:.5}) rel diff {d:.2e}",
                    (af - an).abs() / an,
                    ef.fx,
                    ef.fy,
                    en.fx,
                    en.fy
                );
                apex_d.push((af - an).abs() / an);
                force_d.push(d);
            }
            // The force difference falls like 1/N_g; the apex difference more slowly (the
            // resolved chevron at the apex is a layer about a pitch wide; docs/guide.md).
            for w in force_d.windows(2) {
                assert!(w[1] < 0.62 * w[0], "{side:?}: {force_d:?}");
            }
            for w in apex_d.windows(2) {
                assert!(w[1] < w[0], "{side:?}: {apex_d:?}");
            }
            assert!(apex_d.last().unwrap() < &(0.6 * apex_d[0]), "{apex_d:?}");
        }
        // Finer cells per pitch at N_g = 32: the resolved film's own error (printed only).
        for per in [8, 16, 32] {
            let g = herringbone(32, angle, 1.0, GrooveSide::Sleeve);
            let (nt, nz) = (per * 32, 2 * per);
            let mut f = bearing(lambda, Some(g), Cavitation::HalfSommerfeld, fin(nt, nz));
            let mut s = bearing(lambda, Some(g), Cavitation::HalfSommerfeld, ngt(nt, nz));
            let ef = f.force(&eccentric, false).unwrap();
            let en = s.force(&eccentric, false).unwrap();
            let d = (ef.fx - en.fx).hypot(ef.fy - en.fy) / en.fx.hypot(en.fy);
            println!("N_g 32, {per} cells per pitch ({nt} x {nz}): eps 0.5 force rel diff {d:.3e}");
        }
    }

    #[test]
    fn narrow_factor_reuse_derivatives_match_finite_differences() {
        use super::super::linear_coefficients;
        for (cav, side, x, y) in [
            (Cavitation::HalfSommerfeld, GrooveSide::Sleeve, 0.3, -0.4),
            (Cavitation::None, GrooveSide::Journal, -0.5, 0.2),
        ] {
            let g = herringbone(12, 30.0, 1.2, side);
            let mut s = bearing(0.8, Some(g), cav, ngt(64, 16));
            let a = linear_coefficients(&mut s, x, y).unwrap();
            let f = linear_coefficients_fd(&mut s, x, y).unwrap();
            let scale = a.k.abs().max().max(a.c.abs().max());
            let d = (a.k - f.k).abs().max().max((a.c - f.c).abs().max());
            println!("NGT factor reuse vs central differences: {:.2e}", d / scale);
            assert!(d < 1e-6 * scale, "{a:?} vs {f:?}");
        }
    }

    #[test]
    fn narrow_reynolds_cavitation_settles() {
        let g = herringbone(16, 30.0, 1.0, GrooveSide::Sleeve);
        let st = JournalState::at(0.6, 0.0);
        let fh = bearing(1.0, Some(g), Cavitation::HalfSommerfeld, ngt(64, 16))
            .force(&st, true)
            .unwrap();
        let fr = bearing(1.0, Some(g), Cavitation::Reynolds, ngt(64, 16))
            .force(&st, true)
            .unwrap();
        let (wh, wr) = (fh.fx.hypot(fh.fy), fr.fx.hypot(fr.fy));
        println!(
            "NGT L/D 1, eps 0.6: load Reynolds / half-Sommerfeld = {:.4}",
            wr / wh
        );
        let pr = fr.pressure.unwrap().values;
        assert!(pr.contains(&0.0) && pr.iter().all(|v| *v >= 0.0));
        assert!((0.9..1.3).contains(&(wr / wh)));
    }
}

#[cfg(all(test, feature = "studies"))]
mod studies;
