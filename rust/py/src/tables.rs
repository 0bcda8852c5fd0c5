//! Results as Python values: an equilibrium's dict, a periodic solution's dict and a
//! scan chunk's columns. A periodic solution's schema is the core's
//! (`ballbal_core::analysis::record`): `periodic()`'s dict and the scan's columns both
//! use it; here its cells only become Python values.

use ballbal_core::analysis::record::{missing_cells, solution_cells, Cell, SOLUTION_FIELDS};
use ballbal_core::equilibria::Equilibrium;
use ballbal_core::periodic::{pattern_string, Periodic};
use ballbal_core::scan::ScanRow;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// As a Python value; a vector as a NumPy array if `arrays`, else as a list (a
/// scan column of lists becomes a polars list column).
pub fn cell_to_py(cell: Cell, py: Python<'_>, arrays: bool) -> PyResult<Bound<'_, PyAny>> {
    Ok(match cell {
        Cell::F(v) => v.into_pyobject(py)?.into_any(),
        Cell::U(v) => v.into_pyobject(py)?.into_any(),
        Cell::B(v) => v.into_pyobject(py)?.to_owned().into_any(),
        Cell::S(v) => v.into_pyobject(py)?.into_any(),
        Cell::Text(v) => v.into_pyobject(py)?.into_any(),
        Cell::V(Some(v)) if arrays => PyArray1::from_vec(py, v).into_any(),
        Cell::V(v) => v.into_pyobject(py)?.into_any(),
    })
}

pub fn equilibrium_dict(py: Python<'_>, e: Equilibrium) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("kind", e.kind.as_str())?;
    d.set_item("q", PyArray1::from_vec(py, e.q))?;
    d.set_item("residual", e.residual)?;
    d.set_item(
        "eig_re",
        PyArray1::from_vec(py, e.eigenvalues.iter().map(|z| z.0).collect()),
    )?;
    d.set_item(
        "eig_im",
        PyArray1::from_vec(py, e.eigenvalues.iter().map(|z| z.1).collect()),
    )?;
    d.set_item("index", e.index)?;
    d.set_item("stability", e.verdict.as_str())?;
    d.set_item("neutral", e.neutral)?;
    d.set_item("routh_hurwitz", e.routh_hurwitz)?;
    d.set_item("char_poly", PyArray1::from_vec(py, e.char_poly))?;
    d.set_item("exhaustive", e.exhaustive)?;
    Ok(d)
}

/// `periodic()`'s result: the schema's fields, plus the series itself (`coeffs`,
/// `winding`, `samples`, `step`, `last_omega`: the omega Newton ended at, also when it
/// failed) and Hill's multipliers.
pub fn solution_dict(py: Python<'_>, r: Periodic, n_balls: usize) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    for (name, cell) in SOLUTION_FIELDS.iter().zip(solution_cells(&r)) {
        d.set_item(name, cell_to_py(cell, py, true)?)?;
    }
    if let Some((m, _)) = &r.hill {
        d.set_item(
            "hill_re",
            PyArray1::from_vec(py, m.iter().map(|z| z.0).collect()),
        )?;
        d.set_item(
            "hill_im",
            PyArray1::from_vec(py, m.iter().map(|z| z.1).collect()),
        )?;
    }
    let s = r.sol;
    d.set_item("type", pattern_string(&s.winding, n_balls))?;
    d.set_item("last_omega", s.omega)?;
    let l = 2 * s.n_harm + 1;
    let ndof = s.winding.len();
    d.set_item(
        "coeffs",
        PyArray1::from_vec(py, s.coeffs).reshape([ndof, l])?,
    )?;
    d.set_item("winding", PyArray1::from_vec(py, s.winding))?;
    d.set_item("samples", s.samples)?;
    d.set_item("step", s.step)?;
    Ok(d)
}

/// What a chunk's table needs besides its rows.
pub struct Columns<'a> {
    pub names: &'a [String],
    pub values: &'a [Vec<f64>],
    pub patterns: &'a [String],
    pub n_harm: usize,
}

/// One chunk's rows as a dict of equally long lists (None where a value does not
/// apply): the grid's axes, `type`, `solution`, the solution schema, and how each row
/// was reached.
pub fn scan_columns<'py>(
    py: Python<'py>,
    cols: &Columns<'_>,
    rows: &[ScanRow],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, name) in cols.names.iter().enumerate() {
        d.set_item(
            name,
            rows.iter()
                .map(|r| cols.values[k][r.index[k]])
                .collect::<Vec<_>>(),
        )?;
    }
    d.set_item(
        "type",
        rows.iter()
            .map(|r| cols.patterns[r.pattern].as_str())
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "solution",
        rows.iter().map(|r| r.solution).collect::<Vec<_>>(),
    )?;
    let mut lists: Vec<Vec<Bound<'py, PyAny>>> = (0..SOLUTION_FIELDS.len())
        .map(|_| Vec::with_capacity(rows.len()))
        .collect();
    for r in rows {
        let cells = match &r.result {
            Some(x) => solution_cells(x),
            None => missing_cells(cols.n_harm),
        };
        for (list, cell) in lists.iter_mut().zip(cells) {
            list.push(cell_to_py(cell, py, false)?);
        }
    }
    for (name, list) in SOLUTION_FIELDS.iter().zip(lists) {
        d.set_item(name, PyList::new(py, list)?)?;
    }
    d.set_item(
        "attempts",
        rows.iter().map(|r| r.attempts).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "seconds",
        rows.iter().map(|r| r.seconds).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "origin",
        rows.iter().map(|r| r.origin.as_str()).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "pb_exists",
        rows.iter().map(|r| r.pb_exists).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "pb_stable",
        rows.iter().map(|r| r.pb_stable).collect::<Vec<_>>(),
    )?;
    Ok(d)
}

/// A scan table's columns after its axes, with their types
/// (`ballbal_core::scan::rows::SCAN_COLUMNS`): `(name, type)` with the type one of
/// `"float"`, `"count"`, `"flag"`, `"label"`, `"multipliers"`.
#[pyfunction]
pub fn scan_schema() -> Vec<(&'static str, &'static str)> {
    ballbal_core::scan::rows::SCAN_COLUMNS
        .iter()
        .map(|(n, t)| (*n, t.as_str()))
        .collect()
}
