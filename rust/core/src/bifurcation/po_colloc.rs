//! The collocation part of a periodic branch ([`super::po_branch`]): natural
//! continuation in the parameter of the collocation orbit
//! ([`crate::numerics::collocation`], mesh adapted at every point), each row certified as
//! `periodic(method="collocation")` certifies its orbit ([`certify_orbit`]: closure,
//! the discretised monodromy's multipliers with their error bound), into the
//! infinite-period end.
//!
//! Harmonic balance follows a branch through folds and branch points; near the
//! infinite-period end of a rotating branch its series needs ever more harmonics.
//! There the branch is continued by collocation: the end is approached by steps that
//! halve the distance to the end estimated from the orbits themselves, the period
//! predicted by the saddle-node law `T ~ 1 / sqrt|p - p*|`.
//!
//! The infinite-period event is located from the orbit: the slowest speed along it
//! ([`slowest_speed`], the bottleneck of the slow phase) is proportional to `|p - p*|`
//! near a saddle-node on the invariant circle; its secant zero through the last two rows
//! is `p*`, and the branch ends when the last row is within `event_tol` of it.
//! Multiplier events (period doubling, Neimark–Sacker, a real multiplier through +1) are
//! located between rows by bisection in the parameter on the discretised multipliers.
//! Natural continuation cannot pass a fold: a branch forced to collocation that meets
//! one ends with `"step_too_small"` there (harmonic balance's arclength passes it).

use super::po_branch::{multiplier_tests, PoBranchOptions, PoEvent, PoEventKind, PoPoint, PoTests};
use crate::analysis::colloc_periodic::certify_orbit;
use crate::continuation::ArcPoint;
use crate::error::{Error, Result};
use crate::hb::Status;
use crate::linalg::eigenvalues;
use crate::numerics::collocation::{slowest_speed, solve, CollocOrbit, CollocStatus};
use crate::numerics::problem::Parametric;
use crate::periodic::PeriodicOptions;

/// Which discretisation a row of a periodic branch was solved with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowMethod {
    Hb,
    Collocation,
}

impl RowMethod {
    pub fn as_str(self) -> &'static str {
        match self {
            RowMethod::Hb => "hb",
            RowMethod::Collocation => "collocation",
        }
    }
}

/// Where the collocation part starts: the orbit `orbit` (a guess, at `from_p`, or
/// solved there when `keep_start`), first solved at `first_p`.
pub(super) struct TailStart {
    pub from_p: f64,
    pub orbit: CollocOrbit,
    pub first_p: f64,
    /// The row before the first (the last harmonic-balance row), for the events between.
    pub before: Option<PoPoint>,
    /// Rows already on the branch (the events' indices count from there).
    pub offset: usize,
    /// The first step after `first_p` (later ones grow from the steps taken).
    pub h0: f64,
}

/// The collocation part's rows, events, and why it ended.
pub(super) struct Tail {
    pub points: Vec<PoPoint>,
    pub events: Vec<PoEvent>,
    pub stop: String,
}

/// Steps that fail are halved; below this fraction of `event_tol` near the end (or of
/// `ds_min` elsewhere) the branch ends.
const FLOOR_OF_EVENT_TOL: f64 = 1e-3;

/// A converged collocation orbit more than this factor (in log) from the predicted period
/// jumped to another branch.
const MAX_PERIOD_JUMP: f64 = 0.5;

/// A row's slowest speed this far (relative) from the line through the two rows before
/// it is no longer resolved. Far from the end the speed is not yet linear in the
/// parameter: on the merged R-R branch three rows 0.11 to 0.06 from the end miss the
/// line by 20 %; a speed at the discretisation's floor misses it by 100 %.
const UNRESOLVED_SPEED: f64 = 0.5;

struct Solved {
    point: PoPoint,
    orbit: CollocOrbit,
}

/// The row at `p` from `guess`: `None` unless Newton converges and the orbit passes its
/// closure certificate.
fn solve_row<D: Parametric>(
    base: &D,
    name: &str,
    p: f64,
    guess: &CollocOrbit,
    popts: &PeriodicOptions,
    copts: &crate::numerics::collocation::CollocOptions,
) -> Result<Option<Solved>> {
    let m = base.with_param(name, p)?;
    let sol = solve(&m, guess, copts)?;
    if sol.status != CollocStatus::Converged {
        return Ok(None);
    }
    let (speed, _) = slowest_speed(&m, &sol.orbit);
    let orbit = sol.orbit.clone();
    let (residual, iterations) = (sol.residual, sol.iterations);
    let result = certify_orbit(&m, sol, popts).periodic;
    if result.sol.status != Status::Converged {
        return Ok(None);
    }
    let mut tests = PoTests {
        lp: f64::NAN,
        bp: f64::NAN,
        ip: Some(speed),
        ..Default::default()
    };
    if let Some(f) = &result.floquet {
        let t = multiplier_tests(&f.multipliers);
        tests.bp_multipliers = Some(t.0);
        tests.pd = Some(t.1);
        tests.ns = Some(t.2);
        tests.complex_pairs = t.3;
    }
    let arc = ArcPoint {
        x: vec![],
        p,
        // No arclength tangent in natural continuation: dp/ds and the determinant's
        // sign are not defined on these rows.
        tangent: vec![f64::NAN],
        ds: 0.0,
        iterations,
        residual,
        det_sign: f64::NAN,
    };
    Ok(Some(Solved {
        point: PoPoint {
            p,
            result,
            arc,
            tests,
            events: vec![],
            method: RowMethod::Collocation,
        },
        orbit,
    }))
}

/// The discretised multipliers' test functions of the orbit at `p` from `guess` (a
/// trial point of an event's location: no certificates).
fn trial_tests<D: Parametric>(
    base: &D,
    name: &str,
    p: f64,
    guess: &CollocOrbit,
    copts: &crate::numerics::collocation::CollocOptions,
) -> Result<Option<(f64, f64, f64, usize)>> {
    let m = base.with_param(name, p)?;
    let sol = solve(&m, guess, copts)?;
    if sol.status != CollocStatus::Converged {
        return Ok(None);
    }
    Ok(eigenvalues(&sol.monodromy, sol.orbit.n).map(|ev| multiplier_tests(&ev)))
}

/// `p*` where the slowest speed, linear in `p` near the saddle-node, extrapolates to 0
/// from the last two rows: only while it falls in the direction of travel.
fn end_estimate(a: &PoPoint, b: &PoPoint) -> Option<f64> {
    let (va, vb) = (a.tests.ip?, b.tests.ip?);
    if !(vb < va && vb >= 0.0) || a.p == b.p {
        return None;
    }
    let ps = b.p - vb * (b.p - a.p) / (vb - va);
    ps.is_finite().then_some(ps)
}

const WATCHED: [(usize, PoEventKind); 3] = [
    (1, PoEventKind::PeriodDoubling),
    (2, PoEventKind::NeimarkSacker),
    (0, PoEventKind::BranchPoint),
];

fn pick(t: &PoTests, i: usize) -> Option<f64> {
    match i {
        0 => t.bp_multipliers,
        1 => t.pd,
        _ => t.ns,
    }
}

/// Continues by collocation from `start` in the direction `dir` (+1 towards increasing
/// `p`), within `opts.arc`'s window and point budget, with `opts.controls`' user points
/// and stop events and `opts.stop_period`.
pub(super) fn collocation_tail<D: Parametric>(
    base: &D,
    name: &str,
    popts: &PeriodicOptions,
    opts: &PoBranchOptions,
    dir: f64,
    start: TailStart,
) -> Result<Tail> {
    let copts = &opts.collocation;
    let edge = if dir > 0.0 {
        opts.arc.p_max
    } else {
        opts.arc.p_min
    };
    let mut points: Vec<PoPoint> = vec![];
    let mut events: Vec<PoEvent> = vec![];
    let prev: Option<PoPoint> = start.before;
    let mut cur_p = start.from_p;
    let mut cur_orbit = start.orbit;
    let mut h = start.h0;
    let mut slope = 0.0; // dT/dp over the last step
    let mut first = true;
    let budget = opts.arc.max_points.saturating_sub(start.offset).max(1);
    let stop;
    loop {
        if crate::cancel::cancelled() {
            return Err(Error::Cancelled);
        }
        if points.len() >= budget {
            stop = "max_points".to_string();
            break;
        }
        let last = points.last().or(prev.as_ref());
        let two = match (points.len(), &prev) {
            (0, _) => None,
            (1, Some(b)) => Some((b, &points[0])),
            (1, None) => None,
            (k, _) => Some((&points[k - 2], &points[k - 1])),
        };
        let p_star = two
            .and_then(|(a, b)| end_estimate(a, b))
            .filter(|ps| (ps - cur_p) * dir > 0.0);
        // The last row's speed off the line through the two before it: the orbit no
        // longer resolves the bottleneck's speed (its discretisation error, ~1e-8 at
        // NTST 50 on the merged R-R branch, is what is left of it). The end is where the
        // two before put it.
        let k = points.len();
        let three = match (k, &prev) {
            (0 | 1, _) => None,
            (2, Some(a)) => Some((a, &points[0], &points[1])),
            (2, None) => None,
            (k, _) => Some((&points[k - 3], &points[k - 2], &points[k - 1])),
        };
        if let Some((a, b, c)) = three {
            if let (Some(va), Some(vb), Some(vc), Some(ps)) =
                (a.tests.ip, b.tests.ip, c.tests.ip, end_estimate(a, b))
            {
                let pred = vb + (c.p - b.p) * (vb - va) / (b.p - a.p);
                if pred > 0.0 && (vc - pred).abs() > UNRESOLVED_SPEED * pred {
                    events.push(PoEvent {
                        kind: PoEventKind::InfinitePeriod,
                        p: ps,
                        point: c.clone(),
                        test: vc,
                        index: start.offset + k,
                    });
                    stop = "infinite_period".to_string();
                    break;
                }
            }
        }
        if let (Some(ps), Some(l)) = (p_star, points.last()) {
            if (ps - cur_p).abs() <= opts.event_tol {
                events.push(end_event(ps, l, start.offset + points.len()));
                stop = "infinite_period".to_string();
                break;
            }
        }
        let mut step = h.min(opts.arc.ds_max);
        if let Some(ps) = p_star {
            step = step.min(0.5 * (ps - cur_p).abs());
        }
        let mut target = if first {
            start.first_p
        } else {
            cur_p + dir * step
        };
        if (target - edge) * dir >= 0.0 {
            target = edge;
        }
        let user = opts
            .controls
            .at
            .iter()
            .copied()
            .filter(|&v| (v - cur_p) * dir > 0.0 && (target - v) * dir >= 0.0)
            .min_by(|a, b| ((a - cur_p) * dir).total_cmp(&((b - cur_p) * dir)));
        if let Some(v) = user {
            target = v;
        }
        let mut guess = cur_orbit.clone();
        let predicted = match p_star {
            Some(ps) => guess.period * ((ps - cur_p) / (ps - target)).abs().sqrt(),
            None => guess.period + slope * (target - cur_p),
        };
        if predicted > 0.0 && predicted.is_finite() {
            guess.period = predicted;
        }
        let row = solve_row(base, name, target, &guess, popts, copts)?
            .filter(|r| (r.orbit.period / guess.period).ln().abs() <= MAX_PERIOD_JUMP);
        let Some(mut row) = row else {
            h = 0.5 * (target - cur_p).abs();
            first = false;
            let floor = if p_star.is_some() {
                FLOOR_OF_EVENT_TOL * opts.event_tol
            } else {
                opts.arc.ds_min
            };
            if h < floor {
                if let (Some(ps), Some(l)) = (p_star, points.last()) {
                    // The orbit can no longer be resolved this close to the end: the
                    // end is where the last rows put it.
                    events.push(end_event(ps, l, start.offset + points.len()));
                    stop = "infinite_period".to_string();
                } else {
                    stop = "step_too_small".to_string();
                }
                break;
            }
            continue;
        };
        let index = start.offset + points.len();
        let mut found: Vec<PoEvent> = vec![];
        let mut cut: Option<Solved> = None;
        if let Some(a) = last {
            let (ta, tb) = (&a.tests, &row.point.tests);
            for (i, kind) in WATCHED {
                let (Some(ga), Some(gb)) = (pick(ta, i), pick(tb, i)) else {
                    continue;
                };
                if ga * gb >= 0.0 || (i == 2 && ta.complex_pairs != tb.complex_pairs) {
                    continue;
                }
                let (mut lo, mut hi, mut glo) = (a.p, target, ga);
                let mut ok = true;
                while (hi - lo).abs() > opts.event_tol {
                    let mid = 0.5 * (lo + hi);
                    let Some(t) = trial_tests(base, name, mid, &cur_orbit, copts)? else {
                        ok = false;
                        break;
                    };
                    let g = [t.0, t.1, t.2][i];
                    if g * glo > 0.0 {
                        (lo, glo) = (mid, g);
                    } else {
                        hi = mid;
                    }
                }
                if !ok {
                    continue;
                }
                let pe = 0.5 * (lo + hi);
                if let Some(s) = solve_row(base, name, pe, &cur_orbit, popts, copts)? {
                    found.push(PoEvent {
                        kind,
                        p: pe,
                        point: s.point,
                        test: glo,
                        index,
                    });
                }
            }
            // stop_period: the row where the period reaches it, by secant in p.
            if let Some(tstop) = opts.stop_period {
                let (t0, t1) = (a.result.sol.period(), row.point.result.sol.period());
                if (t0 - tstop) * (t1 - tstop) <= 0.0 && t1 != t0 {
                    let (mut pa, mut ta_, mut pb, mut tb_) = (a.p, t0, target, t1);
                    let mut best: Option<Solved> = None;
                    for _ in 0..30 {
                        let pm = pa + (tstop - ta_) * (pb - pa) / (tb_ - ta_);
                        let Some(s) = solve_row(base, name, pm, &cur_orbit, popts, copts)? else {
                            break;
                        };
                        let tm = s.point.result.sol.period();
                        let done = (tm / tstop - 1.0).abs() < 1e-12;
                        if (tm - tstop) * (ta_ - tstop) > 0.0 {
                            (pa, ta_) = (pm, tm);
                        } else {
                            (pb, tb_) = (pm, tm);
                        }
                        best = Some(s);
                        if done {
                            break;
                        }
                    }
                    if let Some(s) = best {
                        found.retain(|e| (e.p - a.p) * dir <= (s.point.p - a.p) * dir);
                        cut = Some(s);
                    }
                }
            }
        }
        if let Some(v) = user {
            found.push(PoEvent {
                kind: PoEventKind::User,
                p: v,
                point: row.point.clone(),
                test: 0.0,
                index,
            });
        }
        found.sort_by(|x, y| ((x.p - cur_p) * dir).total_cmp(&((y.p - cur_p) * dir)));
        // The first stop event met ends the branch, its point the last row.
        let stop_at = found
            .iter()
            .position(|e| opts.controls.stop_events.contains(&e.kind.event().name()));
        let mut why: Option<String> = None;
        if let Some(k) = stop_at {
            found.truncate(k + 1);
            let e = &found[k];
            if e.kind != PoEventKind::User {
                row.point = e.point.clone();
            }
            why = Some(e.kind.as_str().to_string());
        } else if let Some(s) = cut {
            row = s;
            why = Some("period".to_string());
        }
        row.point.events = found.iter().map(|e| e.kind).collect();
        events.extend(found);
        if let Some(a) = last {
            let dp = row.point.p - a.p;
            if dp != 0.0 {
                slope = (row.orbit.period - a.result.sol.period()) / dp;
            }
        }
        if !first {
            h = (row.point.p - cur_p).abs() * opts.arc.grow;
        }
        first = false;
        cur_p = row.point.p;
        cur_orbit = row.orbit;
        points.push(row.point);
        crate::cancel::advance();
        if let Some(w) = why {
            stop = w;
            break;
        }
        if cur_p == edge {
            stop = "boundary".to_string();
            break;
        }
    }
    Ok(Tail {
        points,
        events,
        stop,
    })
}

/// The infinite-period event at `p_star`, where the last rows' slowest speeds put the end,
/// carried by the last row `last` (`index` the index of the row past it).
fn end_event(p_star: f64, last: &PoPoint, index: usize) -> PoEvent {
    PoEvent {
        kind: PoEventKind::InfinitePeriod,
        p: p_star,
        point: last.clone(),
        test: last.tests.ip.unwrap_or(f64::NAN),
        index,
    }
}
