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

/// What a column of a result table holds: a real, a count, a yes/no, a label, or the
/// multipliers (the `mult_re` and `mult_im` cells as one list of complex numbers).
/// Every value may be missing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnType {
    Float,
    Count,
    Flag,
    Label,
    Multipliers,
}

impl ColumnType {
    /// The name the binding serves (`_native.scan_schema()`).
    pub fn as_str(self) -> &'static str {
        match self {
            ColumnType::Float => "float",
            ColumnType::Count => "count",
            ColumnType::Flag => "flag",
            ColumnType::Label => "label",
            ColumnType::Multipliers => "multipliers",
        }
    }

    /// The type of a cell's values (a part of the multipliers for `V`).
    pub fn of(cell: &Cell) -> ColumnType {
        match cell {
            Cell::F(_) => ColumnType::Float,
            Cell::U(_) => ColumnType::Count,
            Cell::B(_) => ColumnType::Flag,
            Cell::S(_) | Cell::Text(_) => ColumnType::Label,
            Cell::V(_) => ColumnType::Multipliers,
        }
    }
}

/// The types of [`SOLUTION_FIELDS`], in their order: what [`solution_cells`] makes
/// of a solution (its `None`s are missing values of these types).
pub const SOLUTION_TYPES: [ColumnType; 22] = {
    use ColumnType::*;
    [
        Label,
        Float,
        Float,
        Label,
        Float,
        Float,
        Label,
        Float,
        Multipliers,
        Multipliers,
        Float,
        Float,
        Float,
        Float,
        Float,
        Count,
        Count,
        Label,
        Count,
        Flag,
        Label,
        Flag,
    ]
};

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::floquet::FloquetOptions;
    use crate::periodic::{periodic, PeriodicOptions};
    use crate::Planar;

    /// Every cell a solution gives (with Floquet and Hill, so that every cell is made)
    /// is of its declared type.
    #[test]
    fn cells_are_of_the_declared_types() {
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let opts = PeriodicOptions {
            floquet: Some(FloquetOptions::default()),
            hill: true,
            ..Default::default()
        };
        let r = periodic(&p, &[true, true], None, &opts);
        assert!(r.floquet.is_some() && r.hill.is_some());
        // A missing solution's cells are missing values (F(None) stands for any type)
        // but for its status and harmonics.
        for ((name, cell), t) in SOLUTION_FIELDS
            .iter()
            .zip(&missing_cells(3))
            .zip(SOLUTION_TYPES)
        {
            let missing = matches!(cell, Cell::F(None));
            assert!(ColumnType::of(cell) == t || missing, "{name}: {cell:?}");
        }
        for ((name, cell), t) in SOLUTION_FIELDS
            .iter()
            .zip(solution_cells(&r))
            .zip(SOLUTION_TYPES)
        {
            assert_eq!(ColumnType::of(&cell), t, "{name}");
        }
    }
}
