//! A partial-pivoting LU that can be cancelled between column panels.
//!
//! faer's own factorisation is one uninterruptible call: at N = 256 with 6 balls (a
//! 4100-row harmonic-balance Jacobian) it takes over a second, with 10 balls several,
//! and Ctrl-C waited for it. This right-looking blocked form does the same arithmetic
//! through faer's kernels (a panel's LU, a unit-lower triangular solve and one matrix
//! product per panel) and polls [`crate::cancel`] before each panel, so a cancelled
//! call returns within one panel's work. Only large systems take this path (see
//! [`BLOCKED_MIN_ROWS`]); below it faer's call is short and its rounding stays as it was.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::factor::{lu_in_place, lu_in_place_scratch};
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{
    solve_unit_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::prelude::{Reborrow, ReborrowMut};
use faer::{Accum, Mat, Par};

/// Systems with at least this many rows are factorised panel by panel: faer's one-call LU
/// of a smaller one is short enough for Ctrl-C to wait for it (docs/measurements.md).
pub const BLOCKED_MIN_ROWS: usize = 1024;

/// Columns per panel: wide enough that the trailing update is a real matrix product,
/// narrow enough that one panel of the largest systems takes a small part of a second.
const PANEL: usize = 128;

/// Columns of the trailing update between two polls.
const UPDATE_COLS: usize = 512;

/// `P A = L U` of a square matrix, factors stored in place (unit lower `L` below the
/// diagonal); `perm[i]` is the row of `A` that ends in row `i`.
pub struct BlockedLu {
    lu: Mat<f64>,
    perm: Vec<usize>,
}

/// The column-major copy of the row-major `n x n` matrix `a`, filled [`PANEL`] columns
/// at a time with a cancellation poll before each, or `None` once cancellation was asked
/// for: in one `Mat::from_fn` the copy of a large harmonic-balance Jacobian takes seconds,
/// most of it the first touch of fresh pages, and Ctrl-C waited for all of it
/// (docs/measurements.md). The same values in a matrix of the same shape (so the same
/// layout) as `Mat::from_fn` makes.
pub fn column_major_copy(a: &[f64], n: usize) -> Option<Mat<f64>> {
    let mut m = Mat::<f64>::with_capacity(n, n);
    for j in (0..n).step_by(PANEL) {
        if crate::cancel::cancelled() {
            return None;
        }
        m.resize_with(n, (j + PANEL).min(n), |i, k| a[i * n + k]);
    }
    Some(m)
}

impl BlockedLu {
    /// Factorises `a` (consumed), or `None` once cancellation was asked for.
    pub fn factor(mut a: Mat<f64>) -> Option<Self> {
        let n = a.nrows();
        assert_eq!(n, a.ncols(), "blocked LU of a non-square matrix");
        let mut perm: Vec<usize> = (0..n).collect();
        let mut buf = MemBuffer::new(lu_in_place_scratch::<usize, f64>(
            n,
            PANEL,
            Par::Seq,
            Default::default(),
        ));
        let mut p = vec![0usize; n];
        let mut p_inv = vec![0usize; n];
        let mut tmp = vec![0.0; n];
        let mut moved: Vec<usize> = Vec::with_capacity(n);
        for k in (0..n).step_by(PANEL) {
            if crate::cancel::cancelled() {
                return None;
            }
            let b = PANEL.min(n - k);
            let m = n - k;
            lu_in_place(
                a.as_mut().submatrix_mut(k, k, m, b),
                &mut p[..m],
                &mut p_inv[..m],
                Par::Seq,
                MemStack::new(&mut buf),
                Default::default(),
            );
            // The panel swapped its own rows; the same rows of the other columns and of
            // the permutation follow.
            // At most 2b rows moved (b transpositions): only those are copied.
            moved.clear();
            moved.extend((0..m).filter(|&i| p[i] != i));
            for j in (0..k).chain(k + b..n) {
                let mut col = a.as_mut().col_mut(j);
                for (t, &i) in moved.iter().enumerate() {
                    tmp[t] = col[k + p[i]];
                }
                for (t, &i) in moved.iter().enumerate() {
                    col[k + i] = tmp[t];
                }
            }
            let old: Vec<usize> = perm[k..].to_vec();
            for i in 0..m {
                perm[k + i] = old[p[i]];
            }
            if k + b < n {
                let (left, right) = a.as_mut().split_at_col_mut(k + b);
                let (top, bottom) = right.split_at_row_mut(k + b);
                let mut u12 = top.subrows_mut(k, b);
                let panel = left.rb().submatrix(k, k, m, b);
                solve_unit_lower_triangular_in_place(panel.subrows(0, b), u12.rb_mut(), Par::Seq);
                // The trailing update is most of a panel's work (a large fraction of a
                // second on big systems, docs/measurements.md): in column slices, each
                // preceded by a poll.
                let mut bottom = bottom;
                let cols = bottom.ncols();
                for j in (0..cols).step_by(UPDATE_COLS) {
                    if crate::cancel::cancelled() {
                        return None;
                    }
                    let w = UPDATE_COLS.min(cols - j);
                    matmul(
                        bottom.rb_mut().subcols_mut(j, w),
                        Accum::Add,
                        panel.subrows(b, m - b),
                        u12.rb().subcols(j, w),
                        -1.0,
                        Par::Seq,
                    );
                }
            }
        }
        Some(BlockedLu { lu: a, perm })
    }

    /// `|u_ii|` for every `i`.
    pub fn pivots(&self) -> impl Iterator<Item = f64> + '_ {
        (0..self.lu.nrows()).map(|i| self.lu[(i, i)].abs())
    }

    /// Solves `A x = b`.
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = self.lu.nrows();
        let mut x = Mat::<f64>::from_fn(n, 1, |i, _| b[self.perm[i]]);
        solve_unit_lower_triangular_in_place(self.lu.as_ref(), x.as_mut(), Par::Seq);
        solve_upper_triangular_in_place(self.lu.as_ref(), x.as_mut(), Par::Seq);
        (0..n).map(|i| x[(i, 0)]).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reproducible, well-mixed test matrix that needs pivoting: small diagonal.
    pub(super) fn matrix(n: usize) -> Mat<f64> {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        Mat::from_fn(n, n, |i, j| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let r = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            if i == j {
                1e-3 * r
            } else {
                r
            }
        })
    }

    #[test]
    fn blocked_lu_solves_like_a_dense_residual_says() {
        // Sizes below, at and across panel boundaries.
        for n in [5, 128, 129, 300, 517] {
            let a = matrix(n);
            let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() + 0.1).collect();
            let b: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| a[(i, j)] * x_true[j]).sum())
                .collect();
            let lu = BlockedLu::factor(a.clone()).unwrap();
            // P A = L U, entry by entry, against the factors' own product.
            let mut worst = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let s: f64 = (0..=i.min(j))
                        .map(|k| {
                            let l = if k == i { 1.0 } else { lu.lu[(i, k)] };
                            l * lu.lu[(k, j)]
                        })
                        .sum();
                    worst = worst.max((s - a[(lu.perm[i], j)]).abs());
                }
            }
            assert!(worst < 1e-12 * n as f64, "n {n}: |PA - LU| {worst:e}");
            let x = lu.solve(&b);
            let err = x
                .iter()
                .zip(&x_true)
                .map(|(u, v)| (u - v).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-8, "n {n}: solution error {err:e}");
            // Partial pivoting: every multiplier at most 1 in magnitude.
            for j in 0..n {
                for i in j + 1..n {
                    assert!(lu.lu[(i, j)].abs() <= 1.0 + 1e-15);
                }
            }
        }
    }

    #[test]
    fn the_polled_copy_equals_from_fn_and_factors_alike() {
        // Sizes below, at and across copy panels; the factors of both copies too.
        for n in [0, 1, 5, 128, 129, 300] {
            let m = matrix(n);
            let a: Vec<f64> = (0..n * n).map(|k| m[(k / n, k % n)]).collect();
            let want = Mat::<f64>::from_fn(n, n, |i, j| a[i * n + j]);
            let got = column_major_copy(&a, n).unwrap();
            assert_eq!((got.nrows(), got.ncols()), (n, n));
            assert_eq!(got.col_stride(), want.col_stride(), "n {n}: layout");
            assert!(got == want, "n {n}");
            if n > 0 {
                let (x, y) = (
                    BlockedLu::factor(got).unwrap(),
                    BlockedLu::factor(want).unwrap(),
                );
                assert_eq!(x.perm, y.perm);
                assert!(x.lu == y.lu, "n {n}: factors");
            }
        }
        // Cancelled before the first panel: no copy.
        let tok = crate::cancel::Token::new();
        tok.cancel();
        let a = vec![1.0; 300 * 300];
        assert!(crate::cancel::with(Some(tok), || column_major_copy(&a, 300)).is_none());
    }

    #[test]
    fn a_cancelled_factorisation_stops() {
        let tok = crate::cancel::Token::new();
        tok.cancel();
        let out = crate::cancel::with(Some(tok), || BlockedLu::factor(matrix(300)));
        assert!(out.is_none());
    }
}

#[cfg(all(test, feature = "studies"))]
mod studies;
