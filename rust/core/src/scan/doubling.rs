//! Seeds of period-doubled types from the orbits they double: where a solution of a
//! single-turn type has a real multiplier below -1, the orbit born in that period
//! doubling is looked for at the same point, from the critical mode.
//!
//! Simulation from rest reaches a stable period-doubled orbit only from a sliver of
//! starts (the census' random point 32: 1 start of 16, none of the scan's), but the
//! orbit it doubles is on the map already: the doubled orbit exists wherever a
//! supercritical period doubling has left that orbit with a multiplier below -1.

use super::seeding::new_orbit;
use super::waves::{accept, admit, orbit_key};
use super::{count, work, Family, Found, Origin, ScanSpec};
use crate::analysis::periodic::{is_plain, repetitions};
use crate::bifurcation::switch::period_doubling_starts;
use crate::hb::{solve, Status};
use crate::periodic::finish;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Displacements along the critical mode tried per orbit (the mode's series has unit
/// norm; the orbits' coefficients are of order 1).
const AMPLITUDES: [f64; 3] = [0.03, 0.1, 0.3];

/// For every requested type that is a single-turn type's windings doubled, the index of
/// that single-turn type: `(doubled, single)`. The single-turn types must be among
/// `patterns` (a scan adds them, unreported, where they were not asked for).
pub(super) fn doubled_types(patterns: &[Vec<f64>]) -> Vec<(usize, usize)> {
    patterns
        .iter()
        .enumerate()
        .filter_map(|(k, w)| {
            let single = single_of(w)?;
            Some((k, patterns.iter().position(|p| *p == single)?))
        })
        .collect()
}

/// The single-turn type whose period doubling has the windings `w`, if `w` are a
/// single-turn type's windings doubled.
fn single_of(w: &[f64]) -> Option<Vec<f64>> {
    let single: Vec<f64> = w.iter().map(|x| x / 2.0).collect();
    (repetitions(w) == 2 && is_plain(&single)).then_some(single)
}

/// The single-turn types a scan of `patterns` needs besides them: those doubled by a
/// requested type but not requested themselves.
pub fn parents_needed(patterns: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let mut out: Vec<Vec<f64>> = vec![];
    for single in patterns.iter().filter_map(|w| single_of(w)) {
        if !patterns.contains(&single) && !out.contains(&single) {
            out.push(single);
        }
    }
    out
}

/// Whether the solution has a real multiplier below -1 (past a period doubling).
fn doubles(f: &Found) -> bool {
    f.res.floquet.as_ref().is_some_and(|fl| {
        fl.multipliers
            .iter()
            .any(|(re, im)| *re < -1.0 && im.abs() <= 1e-6 * (1.0 + re.abs()))
    })
}

/// The period-doubled solutions found from the block's solutions `sols`, as (point,
/// solution), new at their point (not an orbit already there) and finished; in point
/// order, each point's in the order of its single-turn solutions and amplitudes.
pub(super) fn doubling_seeds<D: Family>(
    spec: &ScanSpec<'_, D>,
    params: &[D],
    sols: &[Vec<Found>],
    cancel: &AtomicBool,
) -> Vec<(usize, Found)> {
    let pairs = doubled_types(&spec.patterns);
    if pairs.is_empty() {
        return vec![];
    }
    let Some(fo) = spec.opts.floquet.clone() else {
        return vec![];
    };
    let tasks: Vec<(usize, usize, usize)> = sols
        .iter()
        .enumerate()
        .flat_map(|(p, have)| {
            let pairs = &pairs;
            have.iter().enumerate().flat_map(move |(i, f)| {
                pairs
                    .iter()
                    .filter(move |(_, j)| f.pattern == *j && doubles(f))
                    .map(move |(k, _)| (p, i, *k))
            })
        })
        .collect();
    let cands: Vec<Vec<(usize, usize, Found)>> = tasks
        .par_iter()
        .with_max_len(1)
        .map(|&(p, i, k)| {
            if cancel.load(Ordering::Relaxed) {
                return vec![];
            }
            let t = Instant::now();
            let model = &params[p];
            let parent = &sols[p][i].res.sol;
            let Some(starts) = period_doubling_starts(model, parent, &fo, &AMPLITUDES) else {
                return vec![];
            };
            let mut out: Vec<(usize, usize, Found)> = vec![];
            for g in starts {
                count(work::SEED_SOLVE);
                let sol = solve(model, &g, &spec.hb_for(&g.winding));
                if !accept(model, &sol, &g, spec) {
                    continue;
                }
                let key = orbit_key(&sol, model.layout().support());
                let known: Vec<(usize, &[f64])> =
                    out.iter().map(|c| (c.1, c.2.key.as_slice())).collect();
                if !admit(&sols[p], k, &key) || !new_orbit(&known, k, &key) {
                    continue;
                }
                count(work::FINISH);
                let res = finish(model, sol, &spec.opts);
                if res.sol.status != Status::Converged {
                    continue;
                }
                out.push((
                    p,
                    k,
                    Found {
                        pattern: k,
                        res,
                        origin: Origin::PeriodDoubling,
                        parent: None,
                        key,
                        seconds: t.elapsed().as_secs_f64(),
                    },
                ));
            }
            out
        })
        .collect();
    // Kept in task order, an orbit already kept at its point (from another orbit it
    // doubles) dropped; each task checked its own against `sols` already.
    let mut kept: Vec<(usize, Found)> = vec![];
    for (p, k, f) in cands.into_iter().flatten() {
        let here: Vec<(usize, &[f64])> = kept
            .iter()
            .filter(|(q, _)| *q == p)
            .map(|(_, g)| (g.pattern, g.key.as_slice()))
            .collect();
        if new_orbit(&here, k, &f.key) {
            kept.push((p, f));
        }
    }
    kept
}
