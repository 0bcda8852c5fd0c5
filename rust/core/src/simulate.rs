//! Time simulation of a model from a given state.

use crate::error::{Error, Result};
use crate::model::{first_order_rhs, Dynamics};
use crate::ode::{solve_at, Options, Stats};

/// States `(q, q')` at each output time.
pub struct Trajectory {
    pub t: Vec<f64>,
    pub y: Vec<Vec<f64>>,
    pub stats: Stats,
}

/// Integrates `model` from `y0 = (q, q')` at `t0` and samples it at `t_eval`.
pub fn simulate<D: Dynamics + ?Sized>(
    model: &D,
    y0: &[f64],
    t0: f64,
    t_eval: &[f64],
    opts: &Options,
) -> Result<Trajectory> {
    let n = 2 * model.ndof();
    if y0.len() != n {
        return Err(Error::param(
            "y0",
            format!(
                "needs 2 (n + 2) = {n} values (x, y, b_1..b_n and their rates), got {}",
                y0.len()
            ),
        ));
    }
    if let Some(i) = y0.iter().position(|v| !v.is_finite()) {
        return Err(Error::param(
            "y0",
            format!("entry {i} is not finite ({})", y0[i]),
        ));
    }
    let (y, stats) = solve_at(
        |t, y, dy| first_order_rhs(model, t, y, dy),
        t0,
        y0,
        t_eval,
        opts,
    )?;
    Ok(Trajectory {
        t: t_eval.to_vec(),
        y,
        stats,
    })
}
