//! Periodic solutions the simulated starts miss: where every simulated start settles
//! elsewhere (the perfect balance, another pattern) although a stable orbit of the
//! pattern exists, it is found at a nearby parameter point where simulation does reach
//! it and followed to the point asked for by natural-parameter continuation (secant
//! predictor, Newton–IHB corrector, certified at every step, the step halved on
//! failure).

use crate::analysis::periodic::{certify, finish, periodic_searched, Periodic, PeriodicOptions};
use crate::hb::{solve, HbSolution, Status};
use crate::numerics::problem::Parametric;

/// How the solution was found: the `guess_source` the results report.
pub fn source_of(guess: bool) -> String {
    if guess { "guess" } else { "simulation" }.to_string()
}

/// Follows `start` (a solution of `p` with `name = from`) to `p`'s own value of `name`;
/// `None` if a step fails below 1/256 of the way.
fn walk<D: Parametric>(
    p: &D,
    name: &str,
    from: f64,
    start: HbSolution,
    opts: &PeriodicOptions,
) -> Option<HbSolution> {
    let target = p.param_value(name).ok()?;
    let span = target - from;
    let min_h = span.abs() / 256.0;
    let mut h = span / 8.0;
    let (mut v, mut cur, mut prev): (f64, HbSolution, Option<HbSolution>) = (from, start, None);
    for _ in 0..400 {
        if crate::cancel::cancelled() {
            return None;
        }
        let done = (target - v).abs() <= h.abs();
        let next = if done { target } else { v + h };
        let model = if done {
            p.clone()
        } else {
            p.with_param(name, next).ok()?
        };
        let guess = match &prev {
            Some(pr) => {
                use crate::continuation::Secant;
                cur.secant(pr)
            }
            None => cur.clone(),
        };
        let mut s = solve(&model, &guess, &opts.hb);
        certify(&model, &mut s, opts);
        if s.status == Status::Converged {
            if done {
                return Some(s);
            }
            prev = Some(cur);
            cur = s;
            v = next;
        } else {
            h *= 0.5;
            prev = None;
            if h.abs() < min_h {
                return None;
            }
        }
    }
    None
}

/// From each of `starts` (`(parameter, value)`) in turn: the orbit found by simulation
/// there, followed to `p`. The first that arrives, with how it was found (`"homotopy
/// from NAME=VALUE"`); `None` if none does.
pub fn homotopy_walks<D: Parametric>(
    p: &D,
    ball_winding: &[f64],
    starts: &[(String, f64)],
    opts: &PeriodicOptions,
) -> Option<(Periodic, String)> {
    // The start needs no multipliers: only its series is followed.
    let quiet = PeriodicOptions {
        floquet: None,
        hill: false,
        auto: None,
        ..opts.clone()
    };
    for (name, from) in starts {
        let Ok(target) = p.param_value(name) else {
            continue;
        };
        if *from == target || !from.is_finite() {
            continue;
        }
        let Ok(m0) = p.with_param(name, *from) else {
            continue;
        };
        let r0 = periodic_searched(&m0, ball_winding, None, &quiet);
        if r0.sol.status != Status::Converged {
            continue;
        }
        if let Some(sol) = walk(p, name, *from, r0.sol, &quiet) {
            let r = finish(p, sol, opts);
            if r.sol.status == Status::Converged {
                return Some((r, format!("homotopy from {name}={from}")));
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::periodic::periodic_wound;
    use crate::Planar;

    #[test]
    fn walk_reaches_the_target_value_exactly() {
        // From the standard case at Omega 1.2 to 1.25: the result solves the model at
        // 1.25 itself (its residual there, not at a nearby value, is below tolerance).
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.25, &[1.0, 1.0]).unwrap();
        let opts = PeriodicOptions::default();
        let m0 = p.with_param("Omega", 1.2).unwrap();
        let r0 = periodic_wound(&m0, &[-1.0, -1.0], None, &opts);
        assert_eq!(r0.sol.status, Status::Converged);
        let s = walk(&p, "Omega", 1.2, r0.sol.clone(), &opts).unwrap();
        let direct = solve(&p, &s, &opts.hb);
        assert_eq!(direct.status, Status::Converged);
        assert!((direct.omega - s.omega).abs() < 1e-9);
        assert!((s.omega - r0.sol.omega).abs() > 1e-3);
    }
}
