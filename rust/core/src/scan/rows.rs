//! A block's table rows: one per point, solution type and solution found (or one row
//! saying none was found), ordered by point, type and frequency.

use super::grid::Local;
use super::Found;
use crate::analysis::record::ColumnType;
use crate::continuation::{Lattice, Tally};
use crate::periodic::Periodic;

/// A scan table's columns after the grid's axes (and their index columns), in the
/// order the tables and their stored files have always had: the solution type, the
/// solution's number, the solution's schema ([`crate::analysis::record::SOLUTION_FIELDS`],
/// the multipliers as one column) with how the row was reached (a [`ScanRow`]'s own
/// fields) after `N`. The binding serves it, so the Python tables restate nothing.
pub const SCAN_COLUMNS: [(&str, ColumnType); 28] = {
    use ColumnType::*;
    [
        ("type", Label),
        ("solution", Count),
        ("status", Label),
        ("omega", Float),
        ("omega_error", Float),
        ("stability", Label),
        ("max_modulus", Float),
        ("modulus_error", Float),
        ("modulus_error_source", Label),
        ("trivial_error", Float),
        ("multipliers", Multipliers),
        ("residual", Float),
        ("tail", Float),
        ("closure", Float),
        ("separation_error", Float),
        ("pivot_ratio", Float),
        ("iterations", Count),
        ("floquet_steps", Count),
        ("floquet_error", Label),
        ("N", Count),
        ("attempts", Count),
        ("seconds", Float),
        ("origin", Label),
        ("pb_exists", Flag),
        ("pb_stable", Flag),
        ("target_met", Flag),
        ("hill_stability", Label),
        ("verdicts_disagree", Flag),
    ]
};

/// How a scan reached a solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin {
    /// From a simulated start at this point.
    Seed,
    /// From a simulated start at a point where the perfect balance is not stable and no
    /// stable solution of this type had been found by the seeds and their continuation.
    GapSeed,
    /// Continued from a neighbouring point.
    Continuation,
    /// Started at this point from an orbit of the single-turn type it doubles, displaced
    /// along that orbit's period-doubling mode.
    PeriodDoubling,
    /// No solution of this type was found here.
    None,
}

impl Origin {
    /// The name scan tables store.
    pub fn as_str(&self) -> &'static str {
        match self {
            Origin::Seed => "seed",
            Origin::GapSeed => "gap_seed",
            Origin::Continuation => "continuation",
            Origin::PeriodDoubling => "period_doubling",
            Origin::None => "none",
        }
    }
}

#[derive(Debug, Clone)]
pub struct ScanRow {
    /// Grid index along each parameter.
    pub index: Vec<usize>,
    pub pattern: usize,
    /// Number of this solution among those of its type at this point (0, 1, ...);
    /// `None` when none was found.
    pub solution: Option<usize>,
    pub result: Option<Periodic>,
    pub origin: Origin,
    /// Harmonic-balance attempts made at this point for this type.
    pub attempts: usize,
    /// Time of the successful solve and its Floquet analysis, or of all failed attempts.
    pub seconds: f64,
    pub pb_exists: bool,
    pub pb_stable: bool,
}

/// The rows of a block: `sols` per point, `tally` of the continuation, one seed run
/// counted per start at rest (`tasks`), and per whirl start (`whirls`) of the row's
/// type.
pub(super) fn rows(
    geo: &Local,
    classes: usize,
    sols: &[Vec<Found>],
    tally: &Tally,
    tasks: &[(usize, usize)],
    whirls: &[(usize, usize, usize)],
    pb: &[(bool, bool)],
) -> Vec<ScanRow> {
    let npts = geo.size();
    let mut seed_runs = vec![0usize; npts];
    for &(p, _) in tasks {
        seed_runs[p] += 1;
    }
    // Per (point, type), flat: `p * classes + k`.
    let mut whirl_runs = vec![0usize; npts * classes];
    for &(p, k, _) in whirls {
        whirl_runs[p * classes + k] += 1;
    }
    let mut rows = vec![];
    for p in 0..npts {
        let index = geo.index(p);
        for k in 0..classes {
            let mut mine: Vec<&Found> = sols[p].iter().filter(|f| f.pattern == k).collect();
            mine.sort_by(|a, b| a.res.sol.omega.total_cmp(&b.res.sol.omega));
            let base = ScanRow {
                index: index.clone(),
                pattern: k,
                solution: None,
                result: None,
                origin: Origin::None,
                attempts: tally.attempts[p][k] + seed_runs[p] + whirl_runs[p * classes + k],
                seconds: tally.fail_secs[p][k],
                pb_exists: pb[p].0,
                pb_stable: pb[p].1,
            };
            if mine.is_empty() {
                rows.push(base.clone());
            }
            for (m, f) in mine.into_iter().enumerate() {
                rows.push(ScanRow {
                    solution: Some(m),
                    result: Some(f.res.clone()),
                    origin: f.origin,
                    seconds: f.seconds,
                    ..base.clone()
                });
            }
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::record::{SOLUTION_FIELDS, SOLUTION_TYPES};

    /// The scan's columns are the solution's schema (the multipliers' two parts as one
    /// column), each with its type, plus the row's own columns, each once.
    #[test]
    fn scan_columns_hold_the_solution_schema() {
        let own = [
            ("type", ColumnType::Label),
            ("solution", ColumnType::Count),
            ("attempts", ColumnType::Count),
            ("seconds", ColumnType::Float),
            ("origin", ColumnType::Label),
            ("pb_exists", ColumnType::Flag),
            ("pb_stable", ColumnType::Flag),
        ];
        let mut expected: Vec<(&str, ColumnType)> = SOLUTION_FIELDS
            .iter()
            .zip(SOLUTION_TYPES)
            .filter(|(n, _)| **n != "mult_im")
            .map(|(n, t)| (if *n == "mult_re" { "multipliers" } else { *n }, t))
            .chain(own)
            .collect();
        let mut got = SCAN_COLUMNS.to_vec();
        expected.sort_by_key(|c| c.0);
        got.sort_by_key(|c| c.0);
        assert_eq!(got, expected);
    }
}
