//! Finite-volume Reynolds solver on `n_theta x n_zeta` cells.
//!
//! Cell `(i, j)` spans `theta in [i dth, (i+1) dth]` (periodic) and
//! `zeta in [-lambda + j dz, -lambda + (j+1) dz]`; unknown `P_ij` at the cell centre, index
//! `i * n_zeta + j`. Integrating the Reynolds equation over a cell gives a conservative
//! 5-point scheme:
//!
//! * face conductances `K = H_f^3 (face length / centre distance)` with `H_f` the film averaged
//!   **over the face** (exact for the plain film; for grooves the groove fraction of the face is
//!   computed exactly from the groove phase, which is linear along every face); the end faces
//!   `zeta = +-lambda` (ambient `P = 0`) are half a cell from the centre;
//! * the Couette term as a flux difference `6 dz (Q_e - Q_w)` with `Q` the face film, so it
//!   is exactly conservative across groove edges; grooves moving at speed `v_g` (the journal's,
//!   in the fixed frame) enter as `Q = s H_f - 2 v_g delta_g G_f`, which is bearing.md's
//!   `-6 delta_g dG/dtheta` (`6 s dH/dtheta + 12 dH/dtau` with `dG/dtau = -v_g dG/dtheta`),
//!   `s` the mean surface speed (1 in the fixed frame, -1 in the journal frame);
//! * the smooth squeeze term `12 int dH/dtau` integrated exactly over the cell.
//!
//! The matrix `M` (`M P = -rhs`) is symmetric, an M-matrix, positive definite. A plain film
//! depends on `theta` only, so `M = A (x) I + C (x) T` with `T` the cell-centred Dirichlet
//! Laplacian in `zeta`, whose eigenvectors are the DST-II vectors `sin(k pi (j + 1/2) / n_zeta)`:
//! one periodic tridiagonal system per (odd) sine mode, the fast path. Everything else is a
//! sparse Cholesky (faer) whose symbolic factorisation is built once per solver, by its
//! first sparse solve.
//!
//! Ctrl-C ([`crate::cancel`]) is polled between faer's calls (each one uninterruptible: the
//! symbolic factorisation, a numeric factorisation, a solve), per active-set and
//! conjugate-gradient iteration; a cancelled solve returns `Error::Cancelled`. The longest
//! wait is then one faer call or the plain film's sine sweep, which the grid's size bounds
//! (`film_cancel_latency` below measures it).
//!
//! The film is mirror-symmetric about the mid-plane for every model here (aligned journal,
//! `H` and the groove phase depend on `|zeta|`, ambient pressure at both ends, the squeeze
//! term independent of `zeta`), and so is the discrete system (the cells, faces and groove
//! fractions mirror exactly; `n_zeta` is even). Its unique solution, and the
//! complementarity problem's, is then symmetric too, and the sparse path solves only the
//! half `zeta < 0` (`n_zeta / 2` cells per column) with a zero-flux mid-plane face: the
//! restriction of the full system, so the same pressure to round-off at half the unknowns
//! and a quarter of the fill per column.

use super::{Bearing, Cavitation, FilmForce, Grooves, JournalState, PressureField};
use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};
use std::f64::consts::PI;

/// What couples the two cells of an upper-triangle matrix entry (half-domain indices).
#[derive(Debug, Clone, Copy)]
enum Entry {
    Diag(usize),
    /// theta face index `i * nh + j` (between cells `(i-1, j)` and `(i, j)`).
    Theta(usize),
    /// interior zeta face `i * (nh + 1) + j` (between cells `(i, j-1)` and `(i, j)`).
    Zeta(usize),
}

/// The frame-independent description of one Reynolds problem on the grid.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Problem {
    pub x: f64,
    pub y: f64,
    pub vx: f64,
    pub vy: f64,
    /// Mean surface speed `s` in the Couette term.
    pub couette: f64,
    /// Speed of the groove pattern along `theta` (0: grooves fixed on the grid).
    pub groove_speed: f64,
    /// The groove pattern is `G(theta - groove_offset, zeta)`.
    pub groove_offset: f64,
}

/// Face films and conductances for one evaluation, on the half domain `zeta < 0`
/// (`nh = n_zeta / 2` cells per column; zeta face `nh` is the mid-plane, conductance 0).
struct Film {
    /// theta-face conductance, `[i * nh + j]`, face `i` at `theta = i dth`.
    kt: Vec<f64>,
    /// zeta-face conductance, `[i * (nh + 1) + j]`, face `j` at `zeta = -lambda + j dz`.
    kz: Vec<f64>,
    /// Couette face flux film `Q`, `[i * nh + j]`.
    q: Vec<f64>,
    /// Face films behind `kt` and `kz`.
    ht: Vec<f64>,
    hz: Vec<f64>,
}

/// Conductance factor of zeta face `j` of the half domain: the end face is half a cell
/// from the centre, the mid-plane face carries no flux (symmetry).
fn zeta_face_factor(j: usize, nh: usize) -> f64 {
    if j == 0 {
        2.0
    } else if j == nh {
        0.0
    } else {
        1.0
    }
}

/// The sparse Cholesky of the half-domain matrix: the symbolic factor (built once) and
/// one scratch buffer for numeric factorisations and solves (no allocation per solve).
struct Cholesky {
    symbolic: SymbolicCholesky<usize>,
    mem: MemBuffer,
}

impl Cholesky {
    /// At most this many right-hand sides per solve ([`FiniteSolver::linearise`] uses 4).
    const MAX_RHS: usize = 4;

    fn new(pattern: &SymbolicSparseColMat<usize>) -> Result<Self> {
        // AMD with faer's automatic (here simplicial) choice: the cheapest of the orderings
        // and factorisations tried on the half strip (callgrind and wall clock agree; the
        // supernodes of a 16-wide strip are too small for the blocked kernels to pay;
        // counts in docs/measurements.md).
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| Error::param("model", format!("sparse factorisation failed: {e:?}")))?;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(Self::MAX_RHS, Par::Seq),
        ]);
        let mem = MemBuffer::try_new(req)
            .map_err(|_| Error::param("model", "sparse factorisation: out of memory"))?;
        Ok(Cholesky { symbolic, mem })
    }

    /// Numeric factor of `vals` (in the pattern's order) into `out`.
    fn factor(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        vals: &[f64],
        out: &mut Vec<f64>,
    ) -> Result<()> {
        out.clear();
        out.resize(self.symbolic.len_val(), 0.0);
        let mat = SparseColMatRef::new(pattern.as_ref(), vals);
        self.symbolic
            .factorize_numeric_llt(
                out,
                mat,
                Side::Upper,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut self.mem),
                Default::default(),
            )
            .map_err(|e| Error::Eigen(format!("Reynolds matrix not positive definite: {e:?}")))?;
        Ok(())
    }

    /// Solves in place for `ncols` right-hand sides stored column after column in `b`.
    fn solve(&mut self, factor: &[f64], b: &mut [f64], ncols: usize) {
        debug_assert!(ncols <= Self::MAX_RHS);
        let n = self.symbolic.nrows();
        LltRef::new(&self.symbolic, factor).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(b, n, ncols),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
}

/// The finite-volume solver of one bearing (tables and the symbolic factorisation).
pub struct FiniteSolver {
    lambda: f64,
    nt: usize,
    nz: usize,
    /// Cells per column of the half domain, `nz / 2`.
    nh: usize,
    dth: f64,
    dz: f64,
    grooves: Option<Grooves>,
    cavitation: Cavitation,
    /// `sin`, `cos` at the theta faces `i dth`, `i = 0..=nt`.
    sf: Vec<f64>,
    cf: Vec<f64>,
    /// Sine modes `(mu_k, beta_k, v_k[0..nz/2])` with nonzero projection of the constant.
    modes: Vec<(f64, f64, Vec<f64>)>,
    pattern: SymbolicSparseColMat<usize>,
    entries: Vec<Entry>,
    /// Built by the first sparse solve ([`Self::ensure_cholesky`]).
    chol: Option<Cholesky>,
    /// Groove fractions on the theta and zeta faces for the last pattern offset.
    groove_cache: Option<(f64, Vec<f64>, Vec<f64>)>,
    /// Along a trajectory: precondition conjugate gradients with an old factor instead of
    /// refactoring (see [`Self::set_factor_reuse`]).
    reuse: Option<f64>,
    old_factor: Option<Vec<f64>>,
    /// Numeric factor of the current matrix (direct solves).
    factor_values: Vec<f64>,
    /// Conjugate-gradient iterations and refactorisations since construction.
    pub cg_iterations: usize,
    pub factorisations: usize,
}

impl FiniteSolver {
    pub fn new(bearing: &Bearing, nt: usize, nz: usize) -> Result<Self> {
        let lambda = bearing.lambda;
        let dth = 2.0 * PI / nt as f64;
        let dz = 2.0 * lambda / nz as f64;
        let nh = nz / 2;
        let sf = (0..=nt).map(|i| (i as f64 * dth).sin()).collect();
        let cf = (0..=nt).map(|i| (i as f64 * dth).cos()).collect();
        let mut modes = Vec::new();
        for k in 1..=nz {
            // O(nz^2) sines: a fraction of a second at thousands of cells across.
            crate::cancel::check()?;
            let v: Vec<f64> = (0..nz)
                .map(|j| (k as f64 * PI * (j as f64 + 0.5) / nz as f64).sin())
                .collect();
            let sum: f64 = v.iter().sum();
            let norm: f64 = v.iter().map(|a| a * a).sum();
            let beta = sum / norm;
            if beta.abs() > 1e-13 {
                let mu = 4.0 * (k as f64 * PI / (2.0 * nz as f64)).sin().powi(2);
                modes.push((mu, beta, v[..nh].to_vec()));
            }
        }
        // Upper-triangle pattern of the half domain, rows sorted within each column.
        let n = nt * nh;
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(3 * n);
        let mut entries = Vec::with_capacity(3 * n);
        col_ptr.push(0);
        for i in 0..nt {
            for j in 0..nh {
                let c = i * nh + j;
                if i == nt - 1 {
                    row_idx.push(j);
                    entries.push(Entry::Theta(j)); // face 0 couples cell nt-1 with cell 0
                }
                if i > 0 {
                    row_idx.push(c - nh);
                    entries.push(Entry::Theta(i * nh + j));
                }
                if j > 0 {
                    row_idx.push(c - 1);
                    entries.push(Entry::Zeta(i * (nh + 1) + j));
                }
                row_idx.push(c);
                entries.push(Entry::Diag(c));
                col_ptr.push(row_idx.len());
            }
        }
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        Ok(FiniteSolver {
            lambda,
            nt,
            nz,
            nh,
            dth,
            dz,
            grooves: bearing.grooves,
            cavitation: bearing.cavitation,
            sf,
            cf,
            modes,
            pattern,
            entries,
            chol: None,
            groove_cache: None,
            reuse: None,
            old_factor: None,
            factor_values: Vec::new(),
            cg_iterations: 0,
            factorisations: 0,
        })
    }

    fn problem(&self, s: &JournalState) -> Problem {
        let (groove_speed, groove_offset) = match self.grooves {
            Some(g) if g.side == super::GrooveSide::Journal => (1.0, s.tau),
            _ => (0.0, 0.0),
        };
        Problem {
            x: s.x,
            y: s.y,
            vx: s.vx,
            vy: s.vy,
            couette: 1.0,
            groove_speed,
            groove_offset,
        }
    }

    /// Builds the sparse Cholesky's symbolic factor if no solve has yet: a plain film's
    /// force never needs it (the sine-transform path), and its AMD ordering is one
    /// uninterruptible faer call, the longest step of setting up a large grid.
    fn ensure_cholesky(&mut self) -> Result<()> {
        if self.chol.is_none() {
            crate::cancel::check()?;
            self.chol = Some(Cholesky::new(&self.pattern)?);
        }
        Ok(())
    }

    /// Film force at a journal state in the fixed frame.
    pub fn force(&mut self, s: &JournalState, want_field: bool) -> Result<FilmForce> {
        let pb = self.problem(s);
        let p = self.solve(&pb, false)?;
        Ok(self.finish(s, p, want_field))
    }

    /// Pressure on the whole grid for a problem; `force_sparse` bypasses the
    /// sine-transform fast path.
    pub(crate) fn solve(&mut self, pb: &Problem, force_sparse: bool) -> Result<Vec<f64>> {
        crate::cancel::check()?;
        if self.grooves.is_none() && self.cavitation != Cavitation::Reynolds && !force_sparse {
            let mut p = self.solve_plain(pb);
            if self.cavitation == Cavitation::HalfSommerfeld {
                p.iter_mut().for_each(|v| *v = v.max(0.0));
            }
            return Ok(p);
        }
        let film = self.film(pb);
        let rhs = self.rhs(pb, &film);
        let mut p = match self.reuse {
            Some(tol) if self.cavitation != Cavitation::Reynolds => {
                self.solve_reusing(&film, &rhs, tol)?
            }
            _ => self.solve_sparse(&film, &rhs, None)?,
        };
        match self.cavitation {
            Cavitation::None => {}
            Cavitation::HalfSommerfeld => p.iter_mut().for_each(|v| *v = v.max(0.0)),
            Cavitation::Reynolds => p = self.active_set(&film, &rhs, p)?,
        }
        Ok(self.mirror(&p))
    }

    /// The whole grid's pressure from the half domain's.
    fn mirror(&self, ph: &[f64]) -> Vec<f64> {
        let (nz, nh) = (self.nz, self.nh);
        let mut p = vec![0.0; self.nt * nz];
        for (row, half) in p.chunks_exact_mut(nz).zip(ph.chunks_exact(nh)) {
            row[..nh].copy_from_slice(half);
            for (a, b) in row[nh..].iter_mut().zip(half.iter().rev()) {
                *a = *b;
            }
        }
        p
    }

    /// Force, peak pressure and the field from a (clipped) pressure.
    pub(crate) fn finish(&self, s: &JournalState, p: Vec<f64>, want_field: bool) -> FilmForce {
        let (fx, fy) = self.integrate(&p);
        let p_max = p.iter().cloned().fold(0.0_f64, f64::max);
        let mut f = FilmForce::from_xy(s, fx, fy, p_max);
        if want_field {
            f.pressure = Some(PressureField {
                n_theta: self.nt,
                n_zeta: self.nz,
                theta: (0..self.nt).map(|i| (i as f64 + 0.5) * self.dth).collect(),
                zeta: (0..self.nz)
                    .map(|j| -self.lambda + (j as f64 + 0.5) * self.dz)
                    .collect(),
                values: p,
            });
        }
        f
    }

    /// `F = -(1/2 lambda) sum P_ij dz int_cell n dtheta` (units `F_S`).
    pub(crate) fn integrate(&self, p: &[f64]) -> (f64, f64) {
        self.integrate_columns(p, self.nz, 1.0)
    }

    /// [`Self::integrate`] over a field stored `width` cells per column, each counted
    /// `weight` times (the half domain: `nh`, 2).
    fn integrate_columns(&self, p: &[f64], width: usize, weight: f64) -> (f64, f64) {
        let (mut fx, mut fy) = (0.0, 0.0);
        for i in 0..self.nt {
            let sum: f64 = p[i * width..(i + 1) * width].iter().sum();
            fx -= sum * (self.sf[i + 1] - self.sf[i]);
            fy += sum * (self.cf[i + 1] - self.cf[i]);
        }
        let k = weight * self.dz / (2.0 * self.lambda);
        (fx * k, fy * k)
    }

    /// The force at `s` and its exact derivatives (of the discrete, clipped model) with
    /// respect to position and velocity, from **one** factorisation:
    /// `M dP/ds = -d rhs/ds - (dM/ds) P` for the positions (`dM/ds` from `3 H^2 dH/ds` on
    /// every face), `M dP/dv = -d rhs/dv` for the velocities (the matrix does not depend on
    /// them); with the half-Sommerfeld clip the cavitated cells have `dP = 0`. Returns `None`
    /// for the Reynolds condition (its active set is not differentiable this way). Position
    /// and velocity perturbations keep the film symmetric about the mid-plane, so the
    /// half domain serves here too.
    pub fn linearise(&mut self, s: &JournalState) -> Result<Option<(FilmForce, [[f64; 4]; 2])>> {
        if self.cavitation == Cavitation::Reynolds {
            return Ok(None);
        }
        let pb = self.problem(s);
        let (nt, nh) = (self.nt, self.nh);
        let film = self.film(&pb);
        let rhs = self.rhs(&pb, &film);
        let vals = self.values(&film, None);
        self.ensure_cholesky()?;
        // Between faer's calls (each one uninterruptible): see `cancel`.
        crate::cancel::check()?;
        let chol = self.chol.as_mut().expect("built above");
        let mut factor = std::mem::take(&mut self.factor_values);
        chol.factor(&self.pattern, &vals, &mut factor)?;
        let n = nt * nh;
        let mut p: Vec<f64> = rhs.iter().map(|r| -r).collect();
        chol.solve(&factor, &mut p, 1);
        let mut b = vec![0.0; 4 * n];
        let (ct, cz) = (self.dz / self.dth, self.dth / self.dz);
        for (col, (gx, gy)) in [(1.0, 0.0), (0.0, 1.0)].into_iter().enumerate() {
            // Derivative of the film with respect to x (gx = 1) or y (gy = 1).
            let mut d = Film {
                kt: vec![0.0; n],
                kz: vec![0.0; nt * (nh + 1)],
                q: vec![0.0; n],
                ht: Vec::new(),
                hz: Vec::new(),
            };
            for i in 0..nt {
                let dh = -gx * self.cf[i] - gy * self.sf[i];
                for j in 0..nh {
                    let h = film.ht[i * nh + j];
                    d.kt[i * nh + j] = 3.0 * h * h * dh * ct;
                    d.q[i * nh + j] = pb.couette * dh;
                }
                let dhc = (-gx * (self.sf[i + 1] - self.sf[i])
                    + gy * (self.cf[i + 1] - self.cf[i]))
                    / self.dth;
                for j in 0..=nh {
                    let h = film.hz[i * (nh + 1) + j];
                    d.kz[i * (nh + 1) + j] = 3.0 * h * h * dhc * cz * zeta_face_factor(j, nh);
                }
            }
            let still = Problem {
                vx: 0.0,
                vy: 0.0,
                ..pb
            };
            let drhs = self.rhs(&still, &d);
            let dmp = self.apply(&d, &p);
            for c in 0..n {
                b[col * n + c] = -drhs[c] - dmp[c];
            }
        }
        for i in 0..nt {
            let dsx = -12.0 * self.dz * (self.sf[i + 1] - self.sf[i]);
            let dsy = 12.0 * self.dz * (self.cf[i + 1] - self.cf[i]);
            for j in 0..nh {
                b[2 * n + i * nh + j] = -dsx;
                b[3 * n + i * nh + j] = -dsy;
            }
        }
        let chol = self.chol.as_mut().expect("built above");
        chol.solve(&factor, &mut b, 4);
        self.factor_values = factor;
        let clip = self.cavitation == Cavitation::HalfSommerfeld;
        let mut out = [[0.0; 4]; 2];
        for k in 0..4 {
            let dp: Vec<f64> = (0..n)
                .map(|c| {
                    if clip && p[c] < 0.0 {
                        0.0
                    } else {
                        b[k * n + c]
                    }
                })
                .collect();
            let (dfx, dfy) = self.integrate_columns(&dp, nh, 2.0);
            out[0][k] = dfx;
            out[1][k] = dfy;
        }
        if clip {
            p.iter_mut().for_each(|v| *v = v.max(0.0));
        }
        let p = self.mirror(&p);
        Ok(Some((self.finish(s, p, false), out)))
    }

    fn film(&mut self, pb: &Problem) -> Film {
        let (nt, nh) = (self.nt, self.nh);
        let (gt, gz, depth) = match self.grooves {
            Some(g) => {
                let stale =
                    !matches!(&self.groove_cache, Some((off, _, _)) if *off == pb.groove_offset);
                if stale {
                    let (a, b) = self.groove_fractions(&g, pb.groove_offset);
                    self.groove_cache = Some((pb.groove_offset, a, b));
                }
                let (_, a, b) = self.groove_cache.as_ref().expect("filled above");
                (Some(a), Some(b), g.depth)
            }
            None => (None, None, 0.0),
        };
        let mut kt = vec![0.0; nt * nh];
        let mut q = vec![0.0; nt * nh];
        let mut kz = vec![0.0; nt * (nh + 1)];
        let mut ht = vec![0.0; nt * nh];
        let mut hz = vec![0.0; nt * (nh + 1)];
        let ct = self.dz / self.dth;
        let cz = self.dth / self.dz;
        for i in 0..nt {
            let hs = 1.0 - pb.x * self.cf[i] - pb.y * self.sf[i];
            for j in 0..nh {
                let g = gt.map_or(0.0, |a| a[i * nh + j]);
                let h = hs + depth * g;
                kt[i * nh + j] = h * h * h * ct;
                ht[i * nh + j] = h;
                q[i * nh + j] = pb.couette * h - 2.0 * pb.groove_speed * depth * g;
            }
            let hc = 1.0 - pb.x * (self.sf[i + 1] - self.sf[i]) / self.dth
                + pb.y * (self.cf[i + 1] - self.cf[i]) / self.dth;
            for j in 0..=nh {
                let g = gz.map_or(0.0, |a| a[i * (nh + 1) + j]);
                let h = hc + depth * g;
                kz[i * (nh + 1) + j] = h * h * h * cz * zeta_face_factor(j, nh);
                hz[i * (nh + 1) + j] = h;
            }
        }
        Film { kt, kz, q, ht, hz }
    }

    /// Cell right-hand sides `rhs_ij` of `sum K (P_nb - P) = rhs` (half domain).
    fn rhs(&self, pb: &Problem, film: &Film) -> Vec<f64> {
        let (nt, nh) = (self.nt, self.nh);
        let mut r = vec![0.0; nt * nh];
        for i in 0..nt {
            let ie = (i + 1) % nt;
            let sq = -12.0
                * self.dz
                * (pb.vx * (self.sf[i + 1] - self.sf[i]) - pb.vy * (self.cf[i + 1] - self.cf[i]));
            for j in 0..nh {
                r[i * nh + j] = 6.0 * self.dz * (film.q[ie * nh + j] - film.q[i * nh + j]) + sq;
            }
        }
        r
    }

    /// Groove fractions of the half domain's theta faces `[i * nh + j]` and zeta faces
    /// `[i * (nh+1) + j]` (the groove phase depends on `|zeta|`, so these are the other
    /// half's too).
    fn groove_fractions(&self, g: &Grooves, offset: f64) -> (Vec<f64>, Vec<f64>) {
        let (nt, nh) = (self.nt, self.nh);
        let cot = g.chirality() / g.angle.tan();
        let u_max = g.length_fraction * self.lambda;
        let nf = g.count as f64 / (2.0 * PI);
        let cum = |s: f64| {
            let f = s.floor();
            f * g.width + (s - f).min(g.width)
        };
        let frac = |psi_a: f64, psi_b: f64| {
            let (sa, sb) = (nf * psi_a, nf * psi_b);
            if (sb - sa).abs() < 1e-12 {
                if sa - sa.floor() < g.width {
                    1.0
                } else {
                    0.0
                }
            } else {
                (cum(sb) - cum(sa)) / (sb - sa)
            }
        };
        let mut gt = vec![0.0; nt * nh];
        let mut gz = vec![0.0; nt * (nh + 1)];
        for i in 0..nt {
            let th = i as f64 * self.dth - offset;
            for j in 0..nh {
                let za = -self.lambda + j as f64 * self.dz;
                let zb = za + self.dz;
                let (ua, ub) = if za >= 0.0 {
                    (za, zb)
                } else {
                    (zb.abs(), za.abs())
                };
                if ua < u_max {
                    let uc = ub.min(u_max);
                    gt[i * nh + j] = (uc - ua) / (ub - ua) * frac(th + cot * ua, th + cot * uc);
                }
            }
            for j in 0..=nh {
                let u = (-self.lambda + j as f64 * self.dz).abs();
                if u <= u_max * (1.0 + 1e-12) {
                    gz[i * (nh + 1) + j] = frac(th + cot * u, th + self.dth + cot * u);
                }
            }
        }
        (gt, gz)
    }

    /// Fast path for a plain film: one periodic tridiagonal solve per odd sine mode. The
    /// same face films, conductances and right-hand side as [`Self::film`] and [`Self::rhs`],
    /// once per theta column since nothing depends on `zeta`. Not polled for cancellation:
    /// `O(n_theta n_zeta^2)` work, short even on the largest grids, and a poll per mode
    /// made this path several per cent slower (docs/measurements.md).
    fn solve_plain(&self, pb: &Problem) -> Vec<f64> {
        let (nt, nz) = (self.nt, self.nz);
        let (ctf, czf) = (self.dz / self.dth, self.dth / self.dz);
        let mut kt = vec![0.0; nt];
        let mut q = vec![0.0; nt];
        let mut cz = vec![0.0; nt];
        for i in 0..nt {
            let h = 1.0 - pb.x * self.cf[i] - pb.y * self.sf[i];
            kt[i] = h * h * h * ctf;
            q[i] = pb.couette * h;
            let hc = 1.0 - pb.x * (self.sf[i + 1] - self.sf[i]) / self.dth
                + pb.y * (self.cf[i + 1] - self.cf[i]) / self.dth;
            cz[i] = hc * hc * hc * czf;
        }
        let mut r = vec![0.0; nt];
        for (i, ri) in r.iter_mut().enumerate() {
            let sq = -12.0
                * self.dz
                * (pb.vx * (self.sf[i + 1] - self.sf[i]) - pb.vy * (self.cf[i + 1] - self.cf[i]));
            *ri = -(6.0 * self.dz * (q[(i + 1) % nt] - q[i]) + sq);
        }
        let half = nz / 2;
        let mut p = vec![0.0; nt * nz];
        let mut diag = vec![0.0; nt];
        let mut sol = vec![0.0; nt];
        let mut b = vec![0.0; nt];
        let mut work = CyclicWork::new(nt);
        for (mu, beta, v) in &self.modes {
            for i in 0..nt {
                diag[i] = kt[i] + kt[(i + 1) % nt] + mu * cz[i];
                b[i] = r[i] * beta;
            }
            work.solve(&kt, &diag, &b, &mut sol);
            for i in 0..nt {
                let row = &mut p[i * nz..i * nz + half];
                for (pj, vj) in row.iter_mut().zip(v) {
                    *pj += sol[i] * vj;
                }
            }
        }
        // The film is symmetric about the mid-plane.
        for i in 0..nt {
            for j in 0..half {
                p[i * nz + nz - 1 - j] = p[i * nz + j];
            }
        }
        p
    }

    /// Matrix values in pattern order; cells in `fixed` get an identity row and column.
    fn values(&self, film: &Film, fixed: Option<&[bool]>) -> Vec<f64> {
        let nh = self.nh;
        let is_fixed = |c: usize| fixed.is_some_and(|f| f[c]);
        let cols = self.pattern.col_ptr();
        let rows = self.pattern.row_idx();
        let mut vals = Vec::with_capacity(self.entries.len());
        for c in 0..self.nt * nh {
            for (k, &r) in rows.iter().enumerate().take(cols[c + 1]).skip(cols[c]) {
                let v = match self.entries[k] {
                    Entry::Diag(cell) => {
                        if is_fixed(cell) {
                            1.0
                        } else {
                            let (i, j) = (cell / nh, cell % nh);
                            film.kt[i * nh + j]
                                + film.kt[((i + 1) % self.nt) * nh + j]
                                + film.kz[i * (nh + 1) + j]
                                + film.kz[i * (nh + 1) + j + 1]
                        }
                    }
                    Entry::Theta(f) => -film.kt[f],
                    Entry::Zeta(f) => -film.kz[f],
                };
                let coupled = matches!(self.entries[k], Entry::Diag(_));
                vals.push(if !coupled && (is_fixed(r) || is_fixed(c)) {
                    0.0
                } else {
                    v
                });
            }
        }
        vals
    }

    /// Direct solve on the half domain (a fresh numeric factor).
    fn solve_sparse(
        &mut self,
        film: &Film,
        rhs: &[f64],
        fixed: Option<&[bool]>,
    ) -> Result<Vec<f64>> {
        let vals = self.values(film, fixed);
        self.ensure_cholesky()?;
        crate::cancel::check()?;
        let chol = self.chol.as_mut().expect("built above");
        let mut factor = std::mem::take(&mut self.factor_values);
        let res = chol.factor(&self.pattern, &vals, &mut factor);
        let mut b: Vec<f64> = rhs
            .iter()
            .enumerate()
            .map(|(c, r)| if fixed.is_some_and(|f| f[c]) { 0.0 } else { -r })
            .collect();
        if res.is_ok() {
            chol.solve(&factor, &mut b, 1);
        }
        self.factor_values = factor;
        res.map(|()| b)
    }

    /// With `Some(tol)`, grooved (sparse) solves run preconditioned conjugate gradients with
    /// the last numeric factor to a relative residual `tol`, refactoring for the next solves
    /// once a solve takes more than [`REFACTOR_AFTER`] iterations, and at once when one does
    /// not converge in 25 (a film that changed a lot); the force then agrees with the
    /// direct solve to about `tol` times the matrix's condition number. `None` (the default)
    /// factors every time (round-off accuracy).
    pub fn set_factor_reuse(&mut self, tol: Option<f64>) {
        self.reuse = tol;
    }

    fn factor(&mut self, film: &Film) -> Result<()> {
        let vals = self.values(film, None);
        self.ensure_cholesky()?;
        crate::cancel::check()?;
        let chol = self.chol.as_mut().expect("built above");
        let mut factor = self.old_factor.take().unwrap_or_default();
        chol.factor(&self.pattern, &vals, &mut factor)?;
        self.old_factor = Some(factor);
        self.factorisations += 1;
        Ok(())
    }

    fn solve_reusing(&mut self, film: &Film, rhs: &[f64], tol: f64) -> Result<Vec<f64>> {
        if self.old_factor.is_none() {
            self.factor(film)?;
        }
        let n = rhs.len();
        let b: Vec<f64> = rhs.iter().map(|r| -r).collect();
        let bnorm = b.iter().map(|v| v * v).sum::<f64>().sqrt();
        if bnorm == 0.0 {
            return Ok(vec![0.0; n]);
        }
        let mut z = vec![0.0; n];
        let mut ad = vec![0.0; n];
        for attempt in 0..2 {
            let factor = self.old_factor.take().expect("factored above");
            let chol = self.chol.as_mut().expect("built with the factor");
            let mut x = vec![0.0; n];
            let mut r = b.clone();
            z.copy_from_slice(&r);
            chol.solve(&factor, &mut z, 1);
            let mut d = z.clone();
            let mut rz: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
            let mut converged = false;
            let mut iterations = 0;
            for _ in 0..25 {
                if crate::cancel::cancelled() {
                    self.old_factor = Some(factor);
                    return Err(Error::Cancelled);
                }
                iterations += 1;
                apply_half(self.nt, self.nh, film, &d, &mut ad);
                let alpha = rz / d.iter().zip(&ad).map(|(a, b)| a * b).sum::<f64>();
                for k in 0..n {
                    x[k] += alpha * d[k];
                    r[k] -= alpha * ad[k];
                }
                self.cg_iterations += 1;
                if r.iter().map(|v| v * v).sum::<f64>().sqrt() < tol * bnorm {
                    converged = true;
                    break;
                }
                z.copy_from_slice(&r);
                chol.solve(&factor, &mut z, 1);
                let rz_new: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
                let beta = rz_new / rz;
                rz = rz_new;
                for k in 0..n {
                    d[k] = z[k] + beta * d[k];
                }
            }
            self.old_factor = Some(factor);
            if converged {
                if iterations > REFACTOR_AFTER {
                    // The film has drifted: a factorisation costs about as much as seven
                    // iterations, and the following solves would take more.
                    self.factor(film)?;
                }
                return Ok(x);
            }
            if attempt == 0 {
                self.factor(film)?;
            }
        }
        Err(Error::Integration(
            "grooved film: conjugate gradients with a fresh factor did not converge".into(),
        ))
    }

    /// `(M P)_c` with the full stencil (half domain).
    fn apply(&self, film: &Film, p: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; p.len()];
        self.apply_into(film, p, &mut out);
        out
    }

    fn apply_into(&self, film: &Film, p: &[f64], out: &mut [f64]) {
        apply_half(self.nt, self.nh, film, p, out);
    }
    /// Swift–Stieber cavitation: see [`active_set`].
    fn active_set(&mut self, film: &Film, rhs: &[f64], p0: Vec<f64>) -> Result<Vec<f64>> {
        let (nt, nh) = (self.nt, self.nh);
        active_set(
            rhs,
            p0,
            |fixed| self.solve_sparse(film, rhs, Some(fixed)),
            |p| {
                let mut out = vec![0.0; p.len()];
                apply_half(nt, nh, film, p, &mut out);
                out
            },
        )
    }
}

/// Swift–Stieber: `P >= 0`, `w = M P + rhs >= 0`, `P w = 0`, by a primal–dual active set
/// started from the linear solution `p0` (finite for an M-matrix). `solve` solves `M P = -rhs`
/// with the cells marked fixed held at 0, `apply` is `P -> M P`. Stops with
/// `Error::Cancelled` between iterations once cancelled ([`crate::cancel`]).
pub(crate) fn active_set(
    rhs: &[f64],
    p0: Vec<f64>,
    mut solve: impl FnMut(&[bool]) -> Result<Vec<f64>>,
    apply: impl Fn(&[f64]) -> Vec<f64>,
) -> Result<Vec<f64>> {
    let mut fixed: Vec<bool> = p0.iter().map(|v| *v < 0.0).collect();
    for _ in 0..100 {
        // Each iteration is a factorisation: seconds in all on a large grid.
        crate::cancel::check()?;
        let p = solve(&fixed)?;
        let mp = apply(&p);
        let mut changed = false;
        for c in 0..p.len() {
            let w = mp[c] + rhs[c];
            let next = if fixed[c] { w > 0.0 } else { p[c] < 0.0 };
            if next != fixed[c] {
                fixed[c] = next;
                changed = true;
            }
        }
        if !changed {
            return Ok(p.into_iter().map(|v| v.max(0.0)).collect());
        }
    }
    Err(Error::Integration(
        "Reynolds cavitation: the active set did not settle in 100 iterations".into(),
    ))
}

/// `(M P)_c` with the full stencil on the half domain of `nt x nh` cells.
fn apply_half(nt: usize, nh: usize, film: &Film, p: &[f64], out: &mut [f64]) {
    for i in 0..nt {
        let (iw, ie) = ((i + nt - 1) % nt, (i + 1) % nt);
        for j in 0..nh {
            let c = i * nh + j;
            let (kw, ke) = (film.kt[i * nh + j], film.kt[ie * nh + j]);
            let (ks, kn) = (film.kz[i * (nh + 1) + j], film.kz[i * (nh + 1) + j + 1]);
            let mut v = (kw + ke + ks + kn) * p[c] - kw * p[iw * nh + j] - ke * p[ie * nh + j];
            if j > 0 {
                v -= ks * p[c - 1];
            }
            if j + 1 < nh {
                v -= kn * p[c + 1];
            }
            out[c] = v;
        }
    }
}

/// Conjugate-gradient iterations after which [`FiniteSolver::solve_reusing`] refactors for
/// the next solves. Callgrind along a whirl orbit (256 x 32 herringbone, 0.01 rad per step,
/// tolerance 1e-10), instructions per evaluation: 2 -> 22.2 M (a factor every step), 6 ->
/// 15.0 M, 8 -> 15.1 M, 10 -> 16.8 M, 12 -> 18.2 M, never -> 24.9 M; a cold factorisation
/// is 14.5 M. 10 keeps a tight tolerance (1e-12) from refactoring at every step.
const REFACTOR_AFTER: usize = 10;

/// Workspace for a symmetric periodic tridiagonal solve (Sherman–Morrison on Thomas).
struct CyclicWork {
    c: Vec<f64>,
    d: Vec<f64>,
    u: Vec<f64>,
}

impl CyclicWork {
    fn new(n: usize) -> Self {
        CyclicWork {
            c: vec![0.0; n],
            d: vec![0.0; n],
            u: vec![0.0; n],
        }
    }

    /// Solves `diag_i x_i - k_i x_{i-1} - k_{i+1} x_{i+1} = b_i` (indices mod n).
    fn solve(&mut self, k: &[f64], diag: &[f64], b: &[f64], x: &mut [f64]) {
        let n = diag.len();
        // A = B + u v^T with u = (g, 0.., -k0), v = (1, 0.., -k0 / g): B is tridiagonal.
        let k0 = k[0];
        let g = -diag[0];
        let alpha = -k0; // A[n-1][0]
        let beta = -k0; // A[0][n-1]
        self.d.copy_from_slice(diag);
        self.d[0] = diag[0] - g;
        self.d[n - 1] = diag[n - 1] - alpha * beta / g;
        // Forward elimination, shared by both right-hand sides.
        self.u.iter_mut().for_each(|v| *v = 0.0);
        self.u[0] = g;
        self.u[n - 1] = alpha;
        x.copy_from_slice(b);
        let mut inv = 1.0 / self.d[0];
        x[0] *= inv;
        self.u[0] *= inv;
        for i in 1..n {
            // B[i-1][i] = B[i][i-1] = -k_i.
            self.c[i - 1] = -k[i] * inv;
            inv = 1.0 / (self.d[i] + k[i] * self.c[i - 1]);
            x[i] = (x[i] + k[i] * x[i - 1]) * inv;
            self.u[i] = (self.u[i] + k[i] * self.u[i - 1]) * inv;
        }
        for i in (0..n - 1).rev() {
            x[i] -= self.c[i] * x[i + 1];
            self.u[i] -= self.c[i] * self.u[i + 1];
        }
        let fact = (x[0] + beta * x[n - 1] / g) / (1.0 + self.u[0] + beta * self.u[n - 1] / g);
        for (xi, ui) in x.iter_mut().zip(&self.u) {
            *xi -= fact * ui;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::*;
    use crate::cancel::{with, Token};

    pub(super) fn herringbone() -> Grooves {
        Grooves {
            count: 8,
            angle: 30f64.to_radians(),
            depth: 1.0,
            width: 0.5,
            length_fraction: 1.0,
            side: GrooveSide::Sleeve,
        }
    }

    /// An eccentric, moving journal: the state the cancellation tests and the latency
    /// report solve the film at.
    pub(super) fn moving_state() -> JournalState {
        JournalState {
            x: 0.4,
            y: -0.3,
            vx: 0.01,
            vy: 0.02,
            tau: 0.0,
        }
    }

    #[test]
    fn a_cancelled_film_call_stops_with_cancelled_and_the_solver_stays_usable() {
        let st = moving_state();
        let cancelled = || {
            let t = Token::new();
            t.cancel();
            Some(t)
        };
        let (finite, narrow) = (
            FilmModel::Finite {
                n_theta: 128,
                n_zeta: 16,
            },
            FilmModel::NarrowGroove {
                n_theta: 64,
                n_zeta: 16,
            },
        );
        for (grooves, model) in [
            (None, finite),
            (Some(herringbone()), finite),
            (Some(herringbone()), narrow),
        ] {
            for cavitation in [Cavitation::HalfSommerfeld, Cavitation::Reynolds] {
                for reuse in [None, Some(1e-10)] {
                    let b = Bearing {
                        lambda: 1.0,
                        grooves,
                        cavitation,
                        model,
                    };
                    let what = format!("{model:?} {grooves:?} {cavitation:?} reuse {reuse:?}");
                    assert_eq!(
                        with(cancelled(), || b.solver().map(|_| ())),
                        Err(Error::Cancelled),
                        "{what}: new"
                    );
                    let mut s = b.solver().unwrap();
                    s.set_factor_reuse(reuse);
                    let got = with(cancelled(), || s.force(&st, false).map(|f| f.fx));
                    assert_eq!(got, Err(Error::Cancelled), "{what}: force");
                    // The Reynolds condition has no derivatives from a factorisation: no work.
                    let got = with(cancelled(), || {
                        s.force_derivatives(&st).map(|d| d.is_some())
                    });
                    let want = match cavitation {
                        Cavitation::Reynolds => Ok(false),
                        _ => Err(Error::Cancelled),
                    };
                    assert_eq!(got, want, "{what}: derivatives");
                    // Not cancelled: the same force as a solver that never was.
                    let fx = s.force(&st, false).unwrap().fx;
                    let fresh = b.solver().unwrap().force(&st, false).unwrap().fx;
                    assert!(
                        (fx - fresh).abs() <= 1e-9 * fresh.abs(),
                        "{what}: {fx} {fresh}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_active_set_stops_at_the_iteration_after_a_cancellation() {
        // One cell whose solves alternate in sign, so that it enters and leaves the
        // cavitated set at every iteration: without the poll the active set runs its 100
        // iterations and reports that it did not settle.
        let tok = Token::new();
        let mut solves = 0;
        let out = with(Some(tok.clone()), || {
            super::active_set(
                &[0.0],
                vec![1.0],
                |_| {
                    solves += 1;
                    if solves == 3 {
                        tok.cancel();
                    }
                    Ok(vec![if solves % 2 == 1 { -1.0 } else { 1.0 }])
                },
                |p| p.iter().map(|v| -v).collect(),
            )
        });
        assert_eq!(out, Err(Error::Cancelled));
        assert_eq!(solves, 3);
    }
}

#[cfg(all(test, feature = "studies"))]
mod studies;
