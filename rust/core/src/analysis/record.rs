//! The one schema of a periodic solution, owned by the core: the names and values that
//! `periodic()`'s result and a scan table's columns both carry (the multipliers as real
//! and imaginary parts). The binding only turns [`Cell`]s into Python values.

use crate::hb::Status;
use crate::periodic::Periodic;

/// One value of a solution's schema; `None` where it does not apply (no Floquet
/// analysis, no Hill estimate, no solution).
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    F(Option<f64>),
    U(Option<usize>),
    B(Option<bool>),
    S(Option<&'static str>),
    Text(Option<String>),
    /// One part of the multipliers (`mult_re`, `mult_im`).
    V(Option<Vec<f64>>),
}

/// The schema's names, in the order of [`solution_cells`]. `pivot_ratio` is the last
/// Newton matrix's largest over smallest LU pivot, a lower bound of its condition
/// number (`PeriodicSolution.condition` before; stored scan tables use this name).
pub const SOLUTION_FIELDS: [&str; 22] = [
    "status",
    "omega",
    "omega_error",
    "stability",
    "max_modulus",
    "modulus_error",
    "modulus_error_source",
    "trivial_error",
    "mult_re",
    "mult_im",
    "residual",
    "tail",
    "closure",
    "separation_error",
    "pivot_ratio",
    "iterations",
    "floquet_steps",
    "floquet_error",
    "N",
    "target_met",
    "hill_stability",
    "verdicts_disagree",
];

/// A solution's values in the order of [`SOLUTION_FIELDS`]. A series that converged
/// but failed a certificate (`not_closed`, `truncated`) keeps its `omega` for
/// inspection; its status says why it is not a result. An `equilibrium` has no `omega`
/// (any value solves its equations).
pub fn solution_cells(r: &Periodic) -> [Cell; 22] {
    let s = &r.sol;
    let fl = r.floquet.as_ref();
    let ok = matches!(
        s.status,
        Status::Converged | Status::NotClosed | Status::Truncated
    );
    let part = |k: fn(&(f64, f64)) -> f64| fl.map(|f| f.multipliers.iter().map(k).collect());
    [
        Cell::S(Some(s.status.as_str())),
        Cell::F(ok.then_some(s.omega)),
        Cell::F(r.omega_error),
        Cell::S(Some(fl.map_or("undetermined", |f| f.stability.as_str()))),
        Cell::F(fl.map(|f| f.max_modulus)),
        Cell::F(fl.and_then(|f| f.modulus_error)),
        Cell::Text(fl.and_then(|f| {
            f.modulus_error_against
                .map(|m| format!("N {} vs {m}", s.n_harm))
        })),
        Cell::F(fl.map(|f| f.trivial_error)),
        Cell::V(part(|z| z.0)),
        Cell::V(part(|z| z.1)),
        Cell::F(Some(s.residual)),
        Cell::F(Some(r.tail)),
        Cell::F(r.closure),
        Cell::F(fl.and_then(|f| f.separation_error)),
        Cell::F(Some(s.pivot_ratio)),
        Cell::U(Some(s.iterations)),
        Cell::U(fl.map(|f| f.steps)),
        Cell::Text(r.floquet_error.clone()),
        Cell::U(Some(s.n_harm)),
        Cell::B(r.target_met),
        Cell::S(r.hill.as_ref().map(|h| h.1.as_str())),
        Cell::B(r.verdicts_disagree()),
    ]
}

/// The schema's values where no solution was found (a scan row `not_found`, with the
/// harmonics it was asked for).
pub fn missing_cells(n_harm: usize) -> [Cell; 22] {
    let mut c: [Cell; 22] = std::array::from_fn(|_| Cell::F(None));
    c[0] = Cell::S(Some("not_found"));
    c[N_FIELD] = Cell::U(Some(n_harm));
    c
}

/// The position of `N` in [`SOLUTION_FIELDS`].
const N_FIELD: usize = 18;
const _: () = assert!(matches!(SOLUTION_FIELDS[N_FIELD].as_bytes(), b"N"));
