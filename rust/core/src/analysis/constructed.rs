//! Starts built from the pattern instead of simulated: where no simulated start reaches
//! an orbit of the pattern (its basin misses every start at rest, as for Tien's (2011)
//! R-O orbit of table 4-7, reached by about one random start in sixty), Newton is
//! started from the orbit's skeleton: each rotating ball turning uniformly at a trial
//! rate `omega`, each oscillating ball at rest at a trial angle, the support at rest.
//! The harmonic-balance iteration supplies the rest. A small lattice of (rate, angle,
//! phase) trials covers the orbits of one-turn patterns at the cost of a few dozen
//! Newton solves (no simulation).

use std::f64::consts::PI;

use crate::analysis::homotopy::{homotopy_walks, source_of};
use crate::analysis::periodic::{certify, finish, periodic_searched, Periodic, PeriodicOptions};
use crate::hb::{solve, HbSolution, Status};
use crate::numerics::floquet::Stability;
use crate::numerics::problem::Parametric;
use crate::Dynamics;

/// `periodic()` without a guess: the simulated starts ([`periodic_searched`]); if they reach no orbit of the
/// pattern, the `homotopy` starts (`(parameter, value)`, as [`homotopy_walks`] takes
/// them); then, for one-turn patterns, the constructed starts; then the `last_resort`
/// homotopy starts. Returns the result and how it was found (the `guess_source`
/// results report); when nothing converges, the simulated search's own result.
pub fn periodic_discover<D: Parametric>(
    p: &D,
    ball_winding: &[f64],
    homotopy: Option<&[(String, f64)]>,
    last_resort: Option<&[(String, f64)]>,
    opts: &PeriodicOptions,
) -> (Periodic, String) {
    let first = periodic_searched(p, ball_winding, None, opts);
    if first.sol.status == Status::Converged {
        return (first, source_of(false));
    }
    if let Some(found) = homotopy.and_then(|h| homotopy_walks(p, ball_winding, h, opts)) {
        return found;
    }
    if ball_winding.iter().all(|w| w.abs() <= 1.0) {
        let rotating: Vec<bool> = ball_winding.iter().map(|w| *w != 0.0).collect();
        if let Some(found) = constructed_search(p, &rotating, opts) {
            return found;
        }
    }
    if let Some(found) = last_resort.and_then(|h| homotopy_walks(p, ball_winding, h, opts)) {
        return found;
    }
    (first, source_of(false))
}

/// Trial rates of the rotating balls relative to the disk, as fractions of the spin
/// rate: the R-R and R-O orbits of Tien's (2011) maps turn at 0.2 to 0.5 of it.
const RATE_FRACTIONS: [f64; 5] = [0.12, 0.23, 0.35, 0.5, 0.7];
/// Trial angles of the oscillating balls (and phase offsets of rotating ones).
const ANGLES: usize = 8;

/// One trial start: `omega`, then the coefficients of a series whose only non-zero
/// entries are the balls' means.
fn skeleton<D: Dynamics + ?Sized>(
    p: &D,
    rotating: &[bool],
    omega: f64,
    angle: f64,
    n_harm: usize,
) -> HbSolution {
    let d = p.ndof();
    let o = p.first_ball();
    let cols = 2 * n_harm + 1;
    let mut coeffs = vec![0.0; d * cols];
    let mut winding = vec![0.0; d];
    let n = rotating.len();
    let (mut kr, mut ko) = (0usize, 0usize);
    for (i, &r) in rotating.iter().enumerate() {
        // Rotating balls spread evenly behind each other (merged balls are the
        // simulated starts' business); oscillating balls around the trial angle, spread
        // so that two of them do not start on top of each other.
        coeffs[(o + i) * cols] = if r {
            winding[o + i] = -1.0;
            kr += 1;
            2.0 * PI * (kr - 1) as f64 / n as f64
        } else {
            ko += 1;
            angle + 2.0 * PI * (ko - 1) as f64 / n as f64
        };
    }
    HbSolution::start(omega, coeffs, winding, n_harm, Status::NoGuess)
}

/// Whether two converged series are the same orbit (same frequency, same mean ball
/// angles modulo a turn), so that each is judged once.
fn same_orbit(a: &HbSolution, b: &HbSolution, o: usize, d: usize) -> bool {
    let cols = 2 * a.n_harm + 1;
    (a.omega - b.omega).abs() <= 1e-7 * a.omega.abs().max(1.0)
        && (o..d).all(|i| {
            let diff = (a.coeffs[i * cols] - b.coeffs[i * cols]).rem_euclid(2.0 * PI);
            diff.min(2.0 * PI - diff) < 1e-5
        })
}

/// The orbit of the one-turn pattern `rotating` from constructed starts: the first
/// stable orbit found, else the first converged one, else `None`. Each distinct
/// converged orbit gets its certificates and multipliers ([`finish`]); the string says
/// from which trial it came.
pub fn constructed_search<D: Dynamics + ?Sized>(
    p: &D,
    rotating: &[bool],
    opts: &PeriodicOptions,
) -> Option<(Periodic, String)> {
    if !rotating.iter().any(|r| *r) {
        // Without a rotating ball the skeleton is an equilibrium: Newton has no
        // frequency to hold on to (O-O orbits are the Hopf switch's business).
        return None;
    }
    let (o, d) = (p.first_ball(), p.ndof());
    let spin = p.base_spin().abs();
    let n_angles = if rotating.iter().all(|r| *r) {
        2
    } else {
        ANGLES
    };
    let mut seen: Vec<HbSolution> = vec![];
    let mut fallback: Option<(Periodic, String)> = None;
    for frac in RATE_FRACTIONS {
        for k in 0..n_angles {
            if crate::cancel::cancelled() {
                return fallback;
            }
            let angle = -PI + 2.0 * PI * k as f64 / n_angles as f64;
            let start = skeleton(p, rotating, frac * spin, angle, opts.hb.n_harm);
            let mut s = solve(p, &start, &opts.hb);
            if s.status != Status::Converged || s.omega <= 0.0 {
                continue;
            }
            if seen.iter().any(|t| same_orbit(t, &s, o, d)) {
                continue;
            }
            seen.push(s.clone());
            if opts.auto.is_none() {
                certify(p, &mut s, opts);
                if s.status != Status::Converged {
                    continue;
                }
            }
            let r = finish(p, s, opts);
            if r.sol.status != Status::Converged {
                continue;
            }
            let how = format!("constructed (rate {:.3} Omega, angle {:.3})", frac, angle);
            let stable = r.floquet.as_ref().map(|f| f.stability == Stability::Stable);
            match stable {
                // Without multipliers nothing ranks the orbits: the first is as good.
                None | Some(true) => return Some((r, how)),
                Some(false) => {
                    fallback.get_or_insert((r, how));
                }
            }
        }
    }
    fallback
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::periodic::periodic;
    use crate::Planar;

    #[test]
    fn finds_the_r_o_orbit_that_no_simulated_start_reaches() {
        // Tien's (2011) table 4-7 R-O point: every start at rest goes to the perfect
        // balance, yet a stable R-O orbit exists (random starts with a knocked support
        // reach it, with a ball rate of 0.304 measured over 500 time units).
        let p = Planar::new(0.2, 0.02, &[0.1], 50.0, 1.3, &[0.7, 0.7]).unwrap();
        let opts = PeriodicOptions {
            floquet: Some(crate::numerics::floquet::FloquetOptions::default()),
            ..PeriodicOptions::default()
        };
        let simulated = periodic(&p, &[true, false], None, &opts);
        assert_eq!(simulated.sol.status, Status::NoGuess);
        let (r, how) = constructed_search(&p, &[true, false], &opts).unwrap();
        assert_eq!(r.sol.status, Status::Converged);
        assert!((r.sol.omega - 0.304).abs() < 2e-3, "omega {}", r.sol.omega);
        assert_eq!(r.floquet.unwrap().stability, Stability::Stable);
        assert!(how.starts_with("constructed"));
    }

    #[test]
    fn no_orbit_without_a_rotating_ball() {
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        assert!(constructed_search(&p, &[false, false], &PeriodicOptions::default()).is_none());
    }
}
