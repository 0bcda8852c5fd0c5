//! Parallel scans of a two-parameter grid.
//!
//! The grid is cut into lines along the first parameter (one line per value of the
//! second). Each line is solved on one rayon task: continuation from the previous point
//! of the line (the thesis' method), a fresh simulated start where continuation fails,
//! then a backward sweep that continues from later points into earlier gaps. Lines are
//! independent of each other, so the table does not depend on the thread count.

use crate::equilibria::{equilibria, Verdict};
use crate::error::{Error, Result};
use crate::floquet::FloquetOptions;
use crate::hb::{solve, Status};
use crate::periodic::{finish, guess_from_state, initial_states, Periodic, PeriodicOptions};
use crate::Planar;
use rayon::prelude::*;
use std::time::Instant;

#[derive(Debug, Clone)]
pub struct ScanRow {
    /// Grid indices along the first and second parameter.
    pub i: usize,
    pub j: usize,
    pub pattern: usize,
    pub result: Option<Periodic>,
    /// How the point was reached: "continuation", "fresh", "backward" or "none".
    pub origin: &'static str,
    pub seconds: f64,
    pub pb_exists: bool,
    pub pb_stable: bool,
}

pub struct ScanSpec<'a> {
    pub base: &'a Planar,
    pub names: [&'a str; 2],
    pub values: [&'a [f64]; 2],
    /// Rotation pattern per requested solution type.
    pub patterns: &'a [Vec<bool>],
    pub opts: PeriodicOptions,
    pub threads: usize,
}

fn attempt(p: &Planar, guess: Option<&Periodic>, opts: &PeriodicOptions) -> Option<Periodic> {
    let g = guess?;
    let s = solve(p, &g.sol, &opts.hb);
    // Continuation must not jump to a different type of motion.
    if s.status == Status::Converged && s.winding == g.sol.winding {
        Some(finish(p, s, opts))
    } else {
        None
    }
}

fn fresh(p: &Planar, rot: &[bool], opts: &PeriodicOptions) -> Option<Periodic> {
    for y0 in initial_states(p) {
        if let Some(g) = guess_from_state(p, &y0, rot, opts.hb.n_harm, &opts.guess) {
            let s = solve(p, &g, &opts.hb);
            if s.status == Status::Converged {
                return Some(finish(p, s, opts));
            }
        }
    }
    None
}

/// Runs the scan; rows ordered by (j, i, pattern).
pub fn scan(spec: &ScanSpec<'_>) -> Result<Vec<ScanRow>> {
    for (k, vals) in spec.values.iter().enumerate() {
        if vals.is_empty() {
            return Err(Error::param(spec.names[k], "the grid is empty"));
        }
        for &v in vals.iter() {
            // Validates the name and the value before any work starts.
            spec.base.with_param(spec.names[k], v)?;
        }
    }
    if spec.names[0] == spec.names[1] {
        return Err(Error::param(
            spec.names[1],
            "the two scanned parameters must differ",
        ));
    }
    if spec.threads == 0 {
        return Err(Error::param("threads", "must be >= 1"));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(spec.threads)
        .build()
        .map_err(|e| Error::param("threads", e.to_string()))?;
    let (v0, v1) = (spec.values[0], spec.values[1]);
    let lines: Vec<Vec<ScanRow>> = pool.install(|| {
        (0..v1.len())
            .into_par_iter()
            .map(|j| scan_line(spec, j, v0, v1[j]))
            .collect::<Result<Vec<_>>>()
    })?;
    Ok(lines.into_iter().flatten().collect())
}

fn scan_line(spec: &ScanSpec<'_>, j: usize, v0: &[f64], y: f64) -> Result<Vec<ScanRow>> {
    let np = spec.patterns.len();
    let mut rows: Vec<ScanRow> = Vec::with_capacity(v0.len() * np);
    let mut params = Vec::with_capacity(v0.len());
    for (i, &x) in v0.iter().enumerate() {
        let p = spec
            .base
            .with_param(spec.names[1], y)?
            .with_param(spec.names[0], x)?;
        let pb = equilibria(&p)
            .into_iter()
            .find(|e| e.kind == "perfect_balance");
        for k in 0..np {
            rows.push(ScanRow {
                i,
                j,
                pattern: k,
                result: None,
                origin: "none",
                seconds: 0.0,
                pb_exists: pb.is_some(),
                pb_stable: pb.as_ref().is_some_and(|e| e.verdict == Verdict::Stable),
            });
        }
        params.push(p);
    }
    for k in 0..np {
        let rot = &spec.patterns[k];
        // Forward: continuation, else a fresh start.
        for i in 0..v0.len() {
            let t = Instant::now();
            let prev = if i > 0 {
                rows[(i - 1) * np + k].result.clone()
            } else {
                None
            };
            let (res, origin) = match attempt(&params[i], prev.as_ref(), &spec.opts) {
                Some(r) => (Some(r), "continuation"),
                None => match fresh(&params[i], rot, &spec.opts) {
                    Some(r) => (Some(r), "fresh"),
                    None => (None, "none"),
                },
            };
            let row = &mut rows[i * np + k];
            row.result = res;
            row.origin = origin;
            row.seconds = t.elapsed().as_secs_f64();
        }
        // Backward: continue from later solutions into earlier gaps.
        for i in (0..v0.len().saturating_sub(1)).rev() {
            if rows[i * np + k].result.is_some() {
                continue;
            }
            let next = rows[(i + 1) * np + k].result.clone();
            let t = Instant::now();
            if let Some(r) = attempt(&params[i], next.as_ref(), &spec.opts) {
                let row = &mut rows[i * np + k];
                row.result = Some(r);
                row.origin = "backward";
                row.seconds += t.elapsed().as_secs_f64();
            }
        }
    }
    Ok(rows)
}

/// Floquet tolerances suited to many points (see the periodic benchmark).
pub fn scan_floquet_default() -> FloquetOptions {
    FloquetOptions {
        rtol: 1e-6,
        atol: 1e-9,
        margin: 1e-6,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hb::HbOptions;

    #[test]
    fn thread_count_does_not_change_the_table() {
        let base = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let om = [1.15, 1.2, 1.25];
        let eta = [0.9, 1.0];
        let pats = vec![vec![true, true]];
        let mk = |threads| ScanSpec {
            base: &base,
            names: ["Omega", "eta"],
            values: [&om, &eta],
            patterns: &pats,
            opts: PeriodicOptions {
                hb: HbOptions::default(),
                floquet: Some(scan_floquet_default()),
                ..Default::default()
            },
            threads,
        };
        let a = scan(&mk(1)).unwrap();
        let b = scan(&mk(2)).unwrap();
        assert_eq!(a.len(), 6);
        for (x, y) in a.iter().zip(&b) {
            let (rx, ry) = (x.result.as_ref().unwrap(), y.result.as_ref().unwrap());
            assert_eq!(rx.sol.omega.to_bits(), ry.sol.omega.to_bits());
            assert_eq!(x.origin, y.origin);
        }
    }

    #[test]
    fn bad_grid_is_rejected_before_work() {
        let base = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let pats = vec![vec![true, true]];
        let spec = |names: [&'static str; 2], v: &'static [f64]| ScanSpec {
            base: &base,
            names,
            values: [v, &[1.0]],
            patterns: &pats,
            opts: PeriodicOptions::default(),
            threads: 1,
        };
        let e = scan(&spec(["Omega", "eta"], &[])).err().unwrap();
        assert!(e.to_string().starts_with("Omega"), "{e}");
        let e = scan(&spec(["Omega", "eta"], &[f64::NAN])).err().unwrap();
        assert!(e.to_string().starts_with("Omega"), "{e}");
        let e = scan(&spec(["gravity", "eta"], &[1.0])).err().unwrap();
        assert!(e.to_string().starts_with("gravity"), "{e}");
    }
}
