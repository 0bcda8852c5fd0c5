//! Thin wrappers over faer (LU, general eigenvalues) and nalgebra (small dense
//! solves) working on row-major slices, the layout the model fills.

use crate::model::Dynamics;
use faer::prelude::*;
use faer::Mat;

/// Iterations of an SVD before it is taken as failed: an ordinary matrix needs a few per
/// singular value. nalgebra's own `svd` has no limit, and the equilibrium search of a
/// finite-film bearing scene at `Omega = 10` (or `rho = 1e5`) spun in it for over a minute
/// without an answer; every SVD of the core goes through `try_svd` with this limit.
pub const SVD_MAX_ITER: usize = 10_000;

/// Eigenvalues `(re, im)` of the row-major `n x n` matrix `a`, sorted by decreasing
/// real part then imaginary part, or `None` if the QR iteration failed.
pub fn eigenvalues(a: &[f64], n: usize) -> Option<Vec<(f64, f64)>> {
    let m = Mat::<f64>::from_fn(n, n, |i, j| a[i * n + j]);
    let ev = m.eigenvalues().ok()?;
    let mut out: Vec<(f64, f64)> = ev.iter().map(|z| (z.re, z.im)).collect();
    if out.iter().any(|(r, i)| !r.is_finite() || !i.is_finite()) {
        return None;
    }
    out.sort_by(|a, b| b.0.total_cmp(&a.0).then(b.1.total_cmp(&a.1)));
    Some(out)
}

/// Result of a dense LU solve with a cheap conditioning indicator.
pub struct LuSolve {
    pub x: Vec<f64>,
    /// max |u_ii| / min |u_ii| of the LU factor: a lower bound on the condition number.
    pub pivot_ratio: f64,
}

/// faer's one-call factorisation, or the panel-by-panel one for systems long enough
/// that Ctrl-C must not wait for them.
enum Factors {
    Faer(faer::linalg::solvers::PartialPivLu<f64>),
    Blocked(crate::numerics::blocked_lu::BlockedLu),
}

/// A partial-pivoting LU factorisation of a row-major matrix (faer's, or the blocked one
/// for large systems), kept for solves with several right-hand sides.
pub struct LuFactor {
    lu: Factors,
    n: usize,
    /// max |u_ii| / min |u_ii| of the LU factor: a lower bound on the condition number.
    pub pivot_ratio: f64,
}

/// Factors the row-major `n x n` matrix `a`, or `None` when it is numerically singular.
pub fn lu_factor(a: &[f64], n: usize) -> Option<LuFactor> {
    if n >= crate::numerics::blocked_lu::BLOCKED_MIN_ROWS {
        // `None` also when cancelled: the caller's result is discarded then.
        let m = crate::numerics::blocked_lu::column_major_copy(&a[..n * n], n)?;
        let lu = crate::numerics::blocked_lu::BlockedLu::factor(m)?;
        let pivot_ratio = pivot_ratio(lu.pivots())?;
        return Some(LuFactor {
            lu: Factors::Blocked(lu),
            n,
            pivot_ratio,
        });
    }
    // faer copies its argument into the matrix it factors; handing it the row-major
    // view skips a second, element-by-element copy (the same values in the same
    // column-major matrix, so the same factors to the bit).
    let lu = faer::MatRef::from_row_major_slice(&a[..n * n], n, n).partial_piv_lu();
    let u = lu.U();
    let pivot_ratio = pivot_ratio((0..n).map(|i| u[(i, i)].abs()))?;
    Some(LuFactor {
        lu: Factors::Faer(lu),
        n,
        pivot_ratio,
    })
}

/// `max |u_ii| / min |u_ii|` of the pivots' moduli, or `None` when the matrix is
/// numerically singular (a pivot below 1e-15 of the largest, or one not finite).
fn pivot_ratio(pivots: impl Iterator<Item = f64>) -> Option<f64> {
    let (umax, umin) = pivots.fold((0.0f64, f64::INFINITY), |(hi, lo), v| {
        (hi.max(v), lo.min(v))
    });
    if !(umin > umax * 1e-15) || !umax.is_finite() {
        return None;
    }
    Some(umax / umin)
}

impl LuFactor {
    /// The solution of `a x = b`, or `None` if it is not finite.
    pub fn solve(&self, b: &[f64]) -> Option<Vec<f64>> {
        let n = self.n;
        let x: Vec<f64> = match &self.lu {
            Factors::Faer(lu) => {
                let rhs = Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
                let sol = lu.solve(&rhs);
                (0..n).map(|i| sol[(i, 0)]).collect()
            }
            Factors::Blocked(lu) => lu.solve(b),
        };
        if x.iter().any(|v| !v.is_finite()) {
            return None;
        }
        Some(x)
    }
}

/// Solves the row-major `n x n` system `a x = b` by partial-pivoting LU (faer).
/// Returns `None` when the matrix is numerically singular or the result is not finite.
pub fn lu_solve(a: &[f64], n: usize, b: &[f64]) -> Option<LuSolve> {
    let f = lu_factor(a, n)?;
    let x = f.solve(b)?;
    Some(LuSolve {
        x,
        pivot_ratio: f.pivot_ratio,
    })
}

/// Storage for repeated LU solves of systems of one size (Newton's iterations): the
/// factorisation of [`lu_solve`] without its per-call allocations.
///
/// faer's `PartialPivLu` copies the matrix, factors it in place and then copies the
/// factors apart into `L` and `U` (zeroing the other triangles) before a solve reads
/// them; here the same `lu_in_place` factors the same column-major copy (a matrix of the
/// same shape, so the same layout) and the triangular solves read the factors where they
/// are: the unit-lower solve reads only the strict lower triangle and the upper one only
/// the upper triangle and diagonal, so the values, and every rounding, are those of
/// [`lu_solve`]. Systems of [`BLOCKED_MIN_ROWS`](crate::numerics::blocked_lu::BLOCKED_MIN_ROWS)
/// rows or more go to [`lu_solve`] (its cancellable factorisation).
pub struct LuWork {
    n: usize,
    lu: Mat<f64>,
    fwd: Vec<usize>,
    bwd: Vec<usize>,
    scratch: faer::dyn_stack::MemBuffer,
}

impl LuWork {
    pub fn new(n: usize) -> Self {
        use faer::linalg::lu::partial_pivoting::factor::lu_in_place_scratch;
        let small = n < crate::numerics::blocked_lu::BLOCKED_MIN_ROWS;
        let m = if small { n } else { 0 };
        LuWork {
            n,
            lu: Mat::zeros(m, m),
            fwd: vec![0; m],
            bwd: vec![0; m],
            scratch: faer::dyn_stack::MemBuffer::new(lu_in_place_scratch::<usize, f64>(
                m,
                m,
                faer::Par::Seq,
                Default::default(),
            )),
        }
    }

    /// [`lu_solve`]`(a, n, b)`: the same solution and pivot ratio, or `None` in the same
    /// cases.
    pub fn solve(&mut self, a: &[f64], b: &[f64]) -> Option<LuSolve> {
        use faer::linalg::lu::partial_pivoting::factor::lu_in_place;
        use faer::linalg::triangular_solve::{
            solve_unit_lower_triangular_in_place, solve_upper_triangular_in_place,
        };
        let n = self.n;
        if n >= crate::numerics::blocked_lu::BLOCKED_MIN_ROWS {
            return lu_solve(a, n, b);
        }
        self.lu
            .copy_from(faer::MatRef::from_row_major_slice(&a[..n * n], n, n));
        lu_in_place(
            self.lu.as_mut(),
            &mut self.fwd,
            &mut self.bwd,
            faer::Par::Seq,
            faer::dyn_stack::MemStack::new(&mut self.scratch),
            Default::default(),
        );
        let pivot_ratio = pivot_ratio((0..n).map(|i| self.lu[(i, i)].abs()))?;
        // Row i of P b is row fwd[i] of b, as faer's permutation of the right-hand side.
        let mut rhs = Mat::<f64>::from_fn(n, 1, |i, _| b[self.fwd[i]]);
        solve_unit_lower_triangular_in_place(self.lu.as_ref(), rhs.as_mut(), faer::Par::Seq);
        solve_upper_triangular_in_place(self.lu.as_ref(), rhs.as_mut(), faer::Par::Seq);
        let x: Vec<f64> = (0..n).map(|i| rhs[(i, 0)]).collect();
        if x.iter().any(|v| !v.is_finite()) {
            return None;
        }
        Some(LuSolve { x, pivot_ratio })
    }
}

/// A sequential partial-pivoting LU (faer's) of a column-major `n x n` matrix, nalgebra's
/// `DMatrix` layout: for the bordered systems of pseudo-arclength continuation, where
/// nalgebra's unblocked LU took a third of a harmonic-balance branch's time at N = 24
/// (197 unknowns).
pub struct ColumnLu {
    lu: Mat<f64>,
    fwd: Vec<usize>,
    transpositions: usize,
}

impl ColumnLu {
    pub fn new(a: &[f64], n: usize) -> Self {
        use faer::linalg::lu::partial_pivoting::factor::{lu_in_place, lu_in_place_scratch};
        let mut lu = faer::MatRef::from_column_major_slice(&a[..n * n], n, n).to_owned();
        let (mut fwd, mut bwd) = (vec![0; n], vec![0; n]);
        let mut scratch = faer::dyn_stack::MemBuffer::new(lu_in_place_scratch::<usize, f64>(
            n,
            n,
            faer::Par::Seq,
            Default::default(),
        ));
        let transpositions = lu_in_place(
            lu.as_mut(),
            &mut fwd,
            &mut bwd,
            faer::Par::Seq,
            faer::dyn_stack::MemStack::new(&mut scratch),
            Default::default(),
        )
        .0
        .transposition_count;
        ColumnLu {
            lu,
            fwd,
            transpositions,
        }
    }

    /// The determinant: U's diagonal, signed by the row exchanges.
    pub fn determinant(&self) -> f64 {
        let d = (0..self.fwd.len()).fold(1.0, |d, i| d * self.lu[(i, i)]);
        if self.transpositions.is_multiple_of(2) {
            d
        } else {
            -d
        }
    }

    /// The solution of `a x = b`, or `None` when it is not finite (a singular matrix).
    pub fn solve(&self, b: &[f64]) -> Option<Vec<f64>> {
        use faer::linalg::triangular_solve::{
            solve_unit_lower_triangular_in_place, solve_upper_triangular_in_place,
        };
        let n = self.fwd.len();
        let mut rhs = Mat::<f64>::from_fn(n, 1, |i, _| b[self.fwd[i]]);
        solve_unit_lower_triangular_in_place(self.lu.as_ref(), rhs.as_mut(), faer::Par::Seq);
        solve_upper_triangular_in_place(self.lu.as_ref(), rhs.as_mut(), faer::Par::Seq);
        let x: Vec<f64> = (0..n).map(|i| rhs[(i, 0)]).collect();
        x.iter().all(|v| v.is_finite()).then_some(x)
    }
}

/// First-order state matrix `A = [[0, I], [-M^-1 K, -M^-1 C]]` (row-major, `2d x 2d`),
/// using the model's own mass solve; `cols` is scratch of length `2 d^2`.
pub fn state_matrix<D: Dynamics + ?Sized>(
    model: &D,
    t: f64,
    q: &[f64],
    k: &[f64],
    c: &[f64],
    cols: &mut [f64],
    out: &mut [f64],
) {
    let d = model.ndof();
    let n2 = 2 * d;
    for i in 0..d {
        out[i * n2..(i + 1) * n2].fill(0.0);
        out[i * n2 + d + i] = 1.0;
    }
    // Columns of -K then -C, solved against M together.
    for (src, off) in [(k, 0), (c, d)] {
        for j in 0..d {
            for i in 0..d {
                cols[(off + j) * d + i] = -src[i * d + j];
            }
        }
    }
    model.solve_mass_columns(t, q, cols);
    for j in 0..n2 {
        for i in 0..d {
            out[(d + i) * n2 + j] = cols[j * d + i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigenvalues_of_companion() {
        // x^2 + 2x + 5 -> -1 +- 2i
        let a = [0.0, 1.0, -5.0, -2.0];
        let ev = eigenvalues(&a, 2).unwrap();
        assert!((ev[0].0 + 1.0).abs() < 1e-12 && (ev[0].1 - 2.0).abs() < 1e-12);
    }

    #[test]
    fn column_lu_solves_and_gives_the_determinant() {
        // rows [1, 3, 1], [2, 1, 0], [0, 1, 4] (pivoting swaps the first two), stored by
        // columns; the determinant by cofactors of the first row
        let a = [1.0, 2.0, 0.0, 3.0, 1.0, 1.0, 1.0, 0.0, 4.0];
        let det = 1.0 * (1.0 * 4.0 - 0.0 * 1.0) - 3.0 * (2.0 * 4.0 - 0.0 * 0.0)
            + 1.0 * (2.0 * 1.0 - 1.0 * 0.0);
        let lu = ColumnLu::new(&a, 3);
        assert!(
            (lu.determinant() - det).abs() < 1e-13,
            "{}",
            lu.determinant()
        );
        let b = [1.0, -2.0, 0.5];
        let x = lu.solve(&b).unwrap();
        for i in 0..3 {
            let ax: f64 = (0..3).map(|j| a[j * 3 + i] * x[j]).sum();
            assert!((ax - b[i]).abs() < 1e-13);
        }
        assert!(ColumnLu::new(&[1.0, 2.0, 2.0, 4.0], 2)
            .solve(&[1.0, 1.0])
            .is_none());
    }

    #[test]
    fn lu_solves_and_flags_singular() {
        let a = [2.0, 1.0, 1.0, 3.0];
        let s = lu_solve(&a, 2, &[3.0, 5.0]).unwrap();
        assert!((s.x[0] - 0.8).abs() < 1e-14 && (s.x[1] - 1.4).abs() < 1e-14);
        assert!(lu_solve(&[1.0, 2.0, 2.0, 4.0], 2, &[1.0, 1.0]).is_none());
    }

    #[test]
    fn factoring_the_row_major_view_gives_the_copied_matrix_factors_to_the_bit() {
        // What `lu_solve` computed before it handed faer the row-major view: a
        // column-major copy built element by element, then factored. Sizes around
        // faer's block sizes, and a harmonic-balance-sized one.
        for n in [2, 7, 29, 33, 69, 101] {
            let a: Vec<f64> = (0..n * n)
                .map(|k| {
                    ((k * 7919 % 1009) as f64 / 1009.0 - 0.5)
                        + if k % (n + 1) == 0 { 2.0 } else { 0.0 }
                })
                .collect();
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
            let m = Mat::<f64>::from_fn(n, n, |i, j| a[i * n + j]);
            let lu = m.partial_piv_lu();
            let rhs = Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
            let sol = lu.solve(&rhs);
            let got = lu_solve(&a, n, &b).unwrap();
            for i in 0..n {
                assert_eq!(got.x[i].to_bits(), sol[(i, 0)].to_bits(), "n {n} x[{i}]");
            }
        }
    }

    #[test]
    fn reused_lu_work_solves_as_faer_to_the_bit() {
        // faer's own `PartialPivLu` solve (separate L and U) against the in-place
        // factors, three matrices per workspace (its reuse), small diagonals so that
        // rows are swapped; sizes around faer's block sizes and the HB sizes 29, 69.
        for n in [1, 2, 5, 17, 29, 33, 69, 101] {
            let mut work = LuWork::new(n);
            for round in 0..3usize {
                let a: Vec<f64> = (0..n * n)
                    .map(|k| {
                        let r = ((k * 7919 + round * 131) % 1009) as f64 / 1009.0 - 0.5;
                        if k % (n + 1) == 0 {
                            1e-3 * r
                        } else {
                            r
                        }
                    })
                    .collect();
                let b: Vec<f64> = (0..n)
                    .map(|i| (i as f64 * 0.37 + round as f64).sin())
                    .collect();
                let lu = faer::MatRef::from_row_major_slice(&a, n, n).partial_piv_lu();
                let sol = lu.solve(&Mat::<f64>::from_fn(n, 1, |i, _| b[i]));
                let got = work.solve(&a, &b).unwrap();
                let want = lu_solve(&a, n, &b).unwrap();
                assert_eq!(
                    got.pivot_ratio.to_bits(),
                    want.pivot_ratio.to_bits(),
                    "n {n}"
                );
                for i in 0..n {
                    assert_eq!(got.x[i].to_bits(), sol[(i, 0)].to_bits(), "n {n} x[{i}]");
                }
            }
        }
        let mut work = LuWork::new(2);
        assert!(work.solve(&[1.0, 2.0, 2.0, 4.0], &[1.0, 1.0]).is_none());
        let s = work.solve(&[2.0, 1.0, 1.0, 3.0], &[3.0, 5.0]).unwrap();
        assert!((s.x[0] - 0.8).abs() < 1e-14 && (s.x[1] - 1.4).abs() < 1e-14);
    }
}
