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

/// Integrates `model` from `y0 = (q, q')` at `t0` and samples it at `t_eval`, in at
/// most `opts.max_steps` steps (accepted and rejected): a budget spent is an
/// `Error::Integration` that says how far the integration got.
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
    if opts.max_steps == 0 {
        return Err(Error::param_range(
            "max_steps",
            "must be >= 1",
            format!("[1, {}]", usize::MAX),
        ));
    }
    let (y, stats) = solve_at(
        |t, y, dy| first_order_rhs(model, t, y, dy),
        t0,
        y0,
        t_eval,
        opts,
    )
    .map_err(|e| match e {
        // The budget is the caller's to raise: say which keyword does it.
        Error::Integration(m) if m.starts_with("more than max_steps") => Error::Integration(
            format!("{m}: raise simulate's max_steps or shorten the time span"),
        ),
        e => e,
    })?;
    Ok(Trajectory {
        t: t_eval.to_vec(),
        y,
        stats,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Planar;

    #[test]
    fn step_budget_is_the_callers() {
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let mut y0 = vec![0.0; 8];
        y0[2] = 0.3;
        y0[3] = 1.8;
        let mut opts = Options::new(1e-8, 1e-10);
        opts.max_steps = 50;
        // Far more than 50 steps of the fastest motion (period ~ 5) fit in 1e4.
        match simulate(&p, &y0, 0.0, &[1e4], &opts) {
            Err(Error::Integration(m)) => assert!(m.contains("max_steps = 50"), "{m}"),
            other => panic!(
                "expected the budget to run out, got {:?}",
                other.map(|t| t.stats)
            ),
        }
        opts.max_steps = 0;
        assert!(matches!(
            simulate(&p, &y0, 0.0, &[1.0], &opts),
            Err(Error::InvalidParameter { name, .. }) if name == "max_steps"
        ));
        opts.max_steps = 10_000_000;
        assert!(simulate(&p, &y0, 0.0, &[1.0], &opts).is_ok());
    }
}
