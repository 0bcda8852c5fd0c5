//! A block's table rows: one per point, solution type and solution found (or one row
//! saying none was found), ordered by point, type and frequency.

use super::grid::Local;
use super::Found;
use crate::continuation::{Lattice, Tally};
use crate::periodic::Periodic;

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
