//! Seeds of a block: the points simulated from a few initial states, each attractor's
//! rotation pattern read off the simulation and the harmonic balance solved from it.

use super::grid::Local;
use super::waves::{accept, admit, orbit_key, same_orbit, MAX_PER_TYPE};
use super::{count, profile, work, Family, Found, Origin, ScanSpec};
use crate::analysis::attractors::{seed_guess, Capture};
use crate::analysis::periodic::{is_plain, pattern_whirl_starts, repetitions};
use crate::continuation::Lattice;
use crate::hb::{solve, HbOptions, HbSolution, Status};
use crate::periodic::is_repeated;
use crate::periodic::{finish, initial_states};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Seed points: the lattice, every chunk's middle line if the lattice misses the
/// chunk, and the points on either side of the perfect balance's stability boundary,
/// where O motions are born in a Hopf bifurcation and where the rotating motions that
/// coexist with an unstable balance are reached; these get half the starts, since there
/// are many of them. The tasks do not depend on which patterns were asked for, so that
/// neither do a pattern's rows (asking for "O-O" beside "R-R" once added 54 stable R-R
/// rows to a 91-point scan: its boundary starts settled on them). Returns the (point,
/// start) tasks, sorted, the starts' indices into [`initial_states`] and the lattice's
/// points (where [`whirl_tasks`] start mixed patterns as well).
pub(super) fn seed_tasks<D: Family>(
    spec: &ScanSpec<'_, D>,
    geo: &Local,
    range: &Range<usize>,
    pb: &[(bool, bool)],
) -> (Vec<(usize, usize)>, Vec<usize>, Vec<usize>) {
    let npts = geo.size();
    let dims = spec.names.len();
    let mut per_dim: Vec<Vec<usize>> = spec
        .values
        .iter()
        .map(|v| seed_positions(v.len(), spec.seeds))
        .collect();
    let last = per_dim.last_mut().unwrap();
    last.retain(|j| range.contains(j));
    if last.is_empty() {
        last.push(range.start + range.len() / 2);
    }
    let seeds: Vec<usize> = (0..npts)
        .filter(|&p| {
            let idx = geo.index(p);
            (0..dims).all(|k| per_dim[k].contains(&idx[k]))
        })
        .collect();
    let boundary: Vec<usize> = (0..npts)
        .filter(|&p| !seeds.contains(&p) && geo.neighbours(p).iter().any(|&(q, _)| pb[q] != pb[p]))
        .collect();
    let starts = spread(initial_states(spec.base).len(), spec.starts);
    let half = starts.len().div_ceil(2);
    let mut tasks: Vec<(usize, usize)> = seeds
        .iter()
        .flat_map(|&p| (0..starts.len()).map(move |s| (p, s)))
        .chain(
            boundary
                .iter()
                .flat_map(|&p| (0..half).map(move |s| (p, s))),
        )
        .collect();
    tasks.sort_unstable();
    (tasks, starts, seeds)
}

/// Whirl starts at the lattice points: for every requested pattern, each start of
/// [`pattern_whirl_starts`] (none but for patterns in which some balls rotate and others
/// rest, R-O, O-R) at each point, as (point, pattern, start). Simulated like the starts
/// at rest; a start counts only if it settles on its own pattern, so that asking for R-O
/// adds no row of another pattern.
pub(super) fn whirl_tasks<D: Family>(
    spec: &ScanSpec<'_, D>,
    lattice: &[usize],
) -> Vec<(usize, usize, usize)> {
    let per: Vec<(usize, usize)> = (0..spec.patterns.len())
        .map(|k| (k, whirl_starts_of(spec.base, &spec.patterns[k]).len()))
        .collect();
    lattice
        .iter()
        .flat_map(|&p| {
            per.iter()
                .flat_map(move |&(k, n)| (0..n).map(move |j| (p, k, j)))
        })
        .collect()
}

/// The whirl starts of a solution type: [`pattern_whirl_starts`] of its pattern for the
/// usual windings, none for an orbit winding more than once per period.
fn whirl_starts_of<D: Family>(model: &D, winding: &[f64]) -> Vec<Vec<f64>> {
    if !is_plain(winding) {
        return vec![];
    }
    let rotating: Vec<bool> = winding.iter().map(|w| *w != 0.0).collect();
    pattern_whirl_starts(model, &rotating)
}

/// Whether a seed's series with the balls' windings `w` is of the requested type with
/// windings `want`: the same windings for a type that winds more than once per period;
/// the same pattern, winding once, for a plain type (a ball that turns forwards is
/// still an R ball).
fn of_type(w: &[f64], want: &[f64]) -> bool {
    if !is_plain(want) {
        return w == want;
    }
    repetitions(w) == 1 && w.iter().zip(want).all(|(a, b)| (*a != 0.0) == (*b != 0.0))
}

/// The candidate a simulated start `y0` gives at the point of `model`: the attractor it
/// settles on (or stops at on reaching one of `captures`), if periodic and of a
/// requested type (one of `only`, where given), solved from its fitted series and
/// accepted ([`accept`]): its type's index, the series and its orbit key.
fn simulated_candidate<D: Family>(
    spec: &ScanSpec<'_, D>,
    model: &D,
    y0: &[f64],
    captures: &[Capture],
    only: Option<&[usize]>,
) -> Option<(usize, HbSolution, Vec<f64>)> {
    // Observed over as many turns as the most wound type asks for.
    let max_turns = spec
        .patterns
        .iter()
        .map(|w| repetitions(w))
        .max()
        .unwrap_or(1);
    let g = seed_guess(
        model,
        y0,
        spec.opts.hb.n_harm,
        &spec.opts.guess,
        captures,
        max_turns,
    )?;
    let w = &g.winding[model.layout().balls()];
    let k = match only {
        Some(ks) => *ks.iter().find(|&&k| of_type(w, &spec.patterns[k]))?,
        None => spec.patterns.iter().position(|want| of_type(w, want))?,
    };
    count(work::SEED_SOLVE);
    let hb = spec.hb_for(&g.winding);
    let mut sol = solve(model, &g, &hb);
    if !accept(model, &sol, &g, spec) {
        sol = with_more_harmonics(model, &sol, &g, spec, &hb)?;
    }
    let key = orbit_key(&sol, model.layout().support());
    Some((k, sol, key))
}

/// Times a seed's harmonics may be doubled when its series is not resolved or does
/// not close at the scan's `N` ([`with_more_harmonics`]).
const SEED_DOUBLINGS: usize = 2;

/// A seed's series that Newton converged on but that the scan's `N` does not resolve
/// (tail above `max_tail`) or that fails the closure certificate, solved again with
/// twice and four times the harmonics; the first that is accepted. A slow orbit near a
/// rotating branch's infinite-period end (the census' random point 22: omega 0.00178,
/// a period of 3 500) spends its period in a slow phase and a fast turn, which three
/// harmonics cannot write: simulation reaches it from every start, and the scan listed
/// nothing there. Not with `N = "auto"`, whose refinement does this in `finish`.
fn with_more_harmonics<D: Family>(
    model: &D,
    sol: &HbSolution,
    guess: &HbSolution,
    spec: &ScanSpec<'_, D>,
    hb: &HbOptions,
) -> Option<HbSolution> {
    if spec.opts.auto.is_some()
        || sol.status != Status::Converged
        || sol.winding != guess.winding
        || is_repeated(sol)
    {
        return None;
    }
    let mut n = hb.n_harm;
    let mut from = sol.clone();
    for _ in 0..SEED_DOUBLINGS {
        n *= 2;
        let opts = HbOptions {
            n_harm: n,
            samples: hb.samples.map(|s| s * n / hb.n_harm),
            ..hb.clone()
        };
        count(work::SEED_SOLVE);
        let s = solve(model, &from, &opts);
        if accept(model, &s, guess, spec) {
            return Some(s);
        }
        if s.status != Status::Converged {
            return None;
        }
        from = s;
    }
    None
}

/// A seed's solved series before its Floquet analysis: (point, type, series, key,
/// seconds so far).
type Candidate = (usize, usize, HbSolution, Vec<f64>, f64);

/// Runs the seed tasks in parallel: each simulated start that settles on a periodic
/// motion of a requested type, solved, resolved and certified, is a found solution.
/// Returns the solutions kept per point (in task order, duplicates of an orbit already
/// kept there dropped) and their `(point, solution)` indices.
///
/// Several starts often settle on the same orbit; only the first of them in task order
/// needs `finish` (its Floquet analysis), which therefore runs after the duplicate test
/// rather than for every start. A first that fails there leaves its place to the next
/// duplicate, exactly as when every start was finished before the test.
pub(super) fn run_seeds<D: Family>(
    spec: &ScanSpec<'_, D>,
    params: &[D],
    tasks: &[(usize, usize)],
    starts: &[usize],
    whirls: &[(usize, usize, usize)],
    pb: &[(bool, bool)],
    cancel: &AtomicBool,
) -> (Vec<Vec<Found>>, Vec<(usize, usize)>) {
    // Starts where the perfect balance is not stable first: they are the long ones
    // (simulations that never settle run the whole window), and a long task started
    // last leaves the other threads idle. Only the schedule changes: the candidates
    // are put back in task order below.
    let mut order: Vec<usize> = (0..tasks.len()).collect();
    order.sort_by_key(|&i| (pb[tasks[i].0].1, i));
    let t = Instant::now();
    // Per seed point, the equilibria a start may stop at once it gets close.
    let mut points: Vec<usize> = tasks.iter().map(|t| t.0).collect();
    points.dedup();
    let captures: Vec<Vec<Capture>> = points
        .par_iter()
        .map(|&p| captures_at(&params[p]))
        .collect();
    let captures_of = |p: usize| &captures[points.binary_search(&p).unwrap()];
    let (cands, times): (Vec<Option<(usize, Candidate)>>, Vec<profile::Task>) = order
        .par_iter()
        .with_max_len(1)
        .map(|&i| (i, tasks[i]))
        .map(|(i, (p, s))| {
            profile::timed(|| {
                if cancel.load(Ordering::Relaxed) {
                    return None;
                }
                let t = Instant::now();
                let model = &params[p];
                // This point's own states: "at rest in the ground frame" depends on its spin.
                let y0 = &initial_states(model)[starts[s]];
                let (k, sol, key) = simulated_candidate(spec, model, y0, captures_of(p), None)?;
                Some((i, (p, k, sol, key, t.elapsed().as_secs_f64())))
            })
        })
        .unzip();
    profile::step(profile::SEEDS, t.elapsed(), &times);
    let t = Instant::now();
    let (whirl_cands, whirl_times): (Vec<Option<(usize, Candidate)>>, Vec<profile::Task>) = whirls
        .par_iter()
        .with_max_len(1)
        .enumerate()
        .map(|(j, &(p, k, start))| {
            profile::timed(|| {
                if cancel.load(Ordering::Relaxed) {
                    return None;
                }
                let t = Instant::now();
                let model = &params[p];
                let y0 = &whirl_starts_of(model, &spec.patterns[k])[start];
                let (k, sol, key) =
                    simulated_candidate(spec, model, y0, captures_of(p), Some(&[k]))?;
                let secs = t.elapsed().as_secs_f64();
                Some((tasks.len() + j, (p, k, sol, key, secs)))
            })
        })
        .unzip();
    profile::step(profile::SEEDS, t.elapsed(), &whirl_times);
    let mut cands: Vec<(usize, Candidate)> =
        cands.into_iter().chain(whirl_cands).flatten().collect();
    cands.sort_unstable_by_key(|c| c.0);
    let cands: Vec<Candidate> = cands.into_iter().map(|c| c.1).collect();
    // finished[i]: None = not analysed yet, Some(None) = refused by `finish`.
    let mut finished: Vec<Option<Option<Found>>> = (0..cands.len()).map(|_| None).collect();
    loop {
        // Admission in task order, counting the orbits not analysed yet as kept.
        let mut kept: Vec<Vec<(usize, &[f64])>> = vec![vec![]; params.len()];
        let mut todo = vec![];
        for (i, (p, k, _, key, _)) in cands.iter().enumerate() {
            if !new_orbit(&kept[*p], *k, key) {
                continue;
            }
            match &finished[i] {
                Some(None) => {}
                Some(Some(_)) => kept[*p].push((*k, key)),
                None => {
                    todo.push(i);
                    kept[*p].push((*k, key));
                }
            }
        }
        if todo.is_empty() {
            break;
        }
        let t = Instant::now();
        let (done, times): (Vec<Option<Found>>, Vec<profile::Task>) = todo
            .par_iter()
            .map(|&i| {
                profile::timed(|| {
                    let (p, k, sol, key, secs) = &cands[i];
                    if cancel.load(Ordering::Relaxed) {
                        return None;
                    }
                    let t = Instant::now();
                    count(work::FINISH);
                    let res = finish(&params[*p], sol.clone(), &spec.opts);
                    (res.sol.status == Status::Converged).then(|| Found {
                        pattern: *k,
                        res,
                        origin: Origin::Seed,
                        parent: None,
                        key: key.clone(),
                        seconds: secs + t.elapsed().as_secs_f64(),
                    })
                })
            })
            .unzip();
        profile::step(profile::SEEDS, t.elapsed(), &times);
        for (i, f) in todo.into_iter().zip(done) {
            finished[i] = Some(f);
        }
    }
    let mut sols: Vec<Vec<Found>> = vec![vec![]; params.len()];
    let mut frontier = vec![];
    for (i, (p, k, _, key, _)) in cands.iter().enumerate() {
        if admit(&sols[*p], *k, key) {
            if let Some(Some(f)) = finished[i].take() {
                sols[*p].push(f);
                frontier.push((*p, sols[*p].len() - 1));
            }
        }
    }
    (sols, frontier)
}

/// The equilibria a start at the point of `model` may stop at once it gets close.
fn captures_at<D: Family>(model: &D) -> Vec<Capture> {
    model
        .attracting_rests()
        .iter()
        .filter_map(|(q, rate)| Capture::new(model, q, *rate))
        .collect()
}

/// Gap seeds: the points of a block where the perfect balance is not stable and a
/// requested single-turn type has no stable solution after the seeds and their
/// continuation, with the types missing there. Something attracts the motion at such a
/// point, and a stable orbit of the type may be that attractor although no seed lattice
/// point or stability-boundary point lies in its band: a 1-D speed scan at step 0.01
/// listed no stable R-R (zeta_b 0.16, eta 0.66) where step 0.02 listed eight, because
/// the band (Omega 1.0-1.15) held a seed point only on the coarser grid. Points already
/// simulated from every start and whirl start (the seed `lattice`) are left out; the
/// stability boundary's points are not, since their starts are fewer and include no
/// whirl start (in blocks of 3 eta values the boundary held whole lines on which a
/// stable R-O band went missing). On grids of two or more axes the gap points are
/// those of even index along every axis, and those next to where a type's rows end
/// (below): most gaps are regions where another type attracts, and a simulation at
/// every one of their points would take the 10^6-point scan past its time budget (+12 %
/// at 4 10^4 points), while a band two grid steps wide still holds a gap point. A type is missing at a point by its own rows and the perfect
/// balance only, so that the gaps of a type do not depend on which other types were
/// asked for; the lattice is the grid's, so that they do not depend on the blocks.
pub(super) fn gap_tasks<D: Family>(
    spec: &ScanSpec<'_, D>,
    geo: &Local,
    reported: usize,
    sols: &[Vec<Found>],
    pb: &[(bool, bool)],
    lattice: &[usize],
) -> Vec<(usize, Vec<usize>)> {
    let plain: Vec<usize> = (0..reported)
        .filter(|&k| is_plain(&spec.patterns[k]))
        .collect();
    let stride = if spec.names.len() == 1 { 1 } else { 2 };
    let has = |p: usize, k: usize| sols[p].iter().any(|f| f.pattern == k);
    (0..sols.len())
        .filter(|&p| !pb[p].1 && lattice.binary_search(&p).is_err())
        .filter_map(|p| {
            let missing: Vec<usize> = plain
                .iter()
                .copied()
                .filter(|&k| !sols[p].iter().any(|f| f.pattern == k && f.is_stable()))
                .collect();
            // Every point next to the end of a type's continued rows is a gap point as
            // well: continuation stops where the orbit turns slow near its infinite-
            // period end (its series needs more harmonics than the scan's), which may
            // leave a band one grid step wide at an odd index (mu 0.2, zeta 0.02,
            // zeta_b 0.05, delta 50: stable R-R at Omega 0.95, eta 1.5 and 1.6, omega
            // 0.031 and 0.037, listed only by a 1-point scan).
            let lattice_point = geo.index(p).iter().all(|i| i % stride == 0);
            let edge = |k: usize| !has(p, k) && geo.neighbours(p).iter().any(|&(q, _)| has(q, k));
            (!missing.is_empty() && (lattice_point || missing.iter().any(|&k| edge(k))))
                .then_some((p, missing))
        })
        .collect()
}

/// One simulated start of the gap seeds: at `point`, accepted only as one of `types`;
/// from rest (`whirl` None) or from that whirl start of its one type.
pub(super) struct GapStart {
    pub point: usize,
    pub types: Vec<usize>,
    pub whirl: Option<usize>,
}

/// The simulated starts of the gap seeds ([`gap_tasks`]): the start at rest for all the
/// point's missing types, except at the stability boundary's points, which started from
/// rest already; and at the points of even index along every axis (every point on a
/// 1-D grid) the first whirl start of each missing type that has them
/// ([`whirl_starts_of`]), for that type alone.
/// Without the whirl starts a stable R-O band away from the seed lattice was found only
/// where continuation from a lattice point's whirl start reached it: a scan in blocks
/// of 3 eta values listed 13 fewer stable R-O rows than the same grid in one block (mu
/// 0.2, zeta 0.02, zeta_b 0.05, delta 50), since continuation does not cross block
/// edges. One whirl start at every second point finds them all there; four at every
/// point cost the nine Tien (2011) maps 25 % more time for no further row.
pub(super) fn gap_starts<D: Family>(
    spec: &ScanSpec<'_, D>,
    params: &[D],
    geo: &Local,
    gaps: &[(usize, Vec<usize>)],
    seeded: &[usize],
) -> Vec<GapStart> {
    let stride = if spec.names.len() == 1 { 1 } else { 2 };
    gaps.iter()
        .flat_map(|(p, missing)| {
            let whirling = geo.index(*p).iter().all(|i| i % stride == 0);
            let whirls = missing
                .iter()
                .filter(move |&&k| {
                    whirling && !whirl_starts_of(&params[*p], &spec.patterns[k]).is_empty()
                })
                .map(move |&k| GapStart {
                    point: *p,
                    types: vec![k],
                    whirl: Some(0),
                });
            let at_rest = seeded.binary_search(p).is_err().then(|| GapStart {
                point: *p,
                types: missing.clone(),
                whirl: None,
            });
            at_rest.into_iter().chain(whirls)
        })
        .collect()
}

/// Runs the gap seeds ([`gap_starts`]): the first start at rest at each point, its
/// balls set slightly apart, accepted only as one of the types missing there, and the
/// missing types' whirl starts, each accepted only as its own type; solved, resolved
/// and analysed. Returns the solutions found, in task order.
pub(super) fn run_gap_seeds<D: Family>(
    spec: &ScanSpec<'_, D>,
    params: &[D],
    starts: &[GapStart],
    start: usize,
    cancel: &AtomicBool,
) -> Vec<(usize, Found)> {
    let t = Instant::now();
    let (found, times): (Vec<Option<(usize, Found)>>, Vec<profile::Task>) = starts
        .par_iter()
        .with_max_len(1)
        .map(|g| {
            let p = g.point;
            profile::timed(|| {
                if cancel.load(Ordering::Relaxed) {
                    return None;
                }
                let t = Instant::now();
                let model = &params[p];
                let captures = captures_at(model);
                let y0 = match g.whirl {
                    None => {
                        // Identical balls started together stay together for ever
                        // (merged balls are an invariant set): such a start settles on
                        // a merged orbit even where it is unstable to the balls'
                        // separation, and misses the separated orbit that attracts
                        // there (fine_rr at Omega 1.1, eta 0.46). The balls are set
                        // apart by a milliradian or so, as a tap on a rig would.
                        let mut y0 = initial_states(model)[start].clone();
                        let balls = model.layout().balls();
                        let mid = (balls.len() as f64 - 1.0) / 2.0;
                        for (k, i) in balls.enumerate() {
                            y0[i] += 1e-3 * (k as f64 - mid);
                        }
                        y0
                    }
                    Some(j) => whirl_starts_of(model, &spec.patterns[g.types[0]])[j].clone(),
                };
                let (k, sol, key) =
                    simulated_candidate(spec, model, &y0, &captures, Some(&g.types))?;
                count(work::FINISH);
                let res = finish(model, sol, &spec.opts);
                (res.sol.status == Status::Converged).then(|| {
                    let f = Found {
                        pattern: k,
                        res,
                        origin: Origin::GapSeed,
                        parent: None,
                        key,
                        seconds: t.elapsed().as_secs_f64(),
                    };
                    (p, f)
                })
            })
        })
        .unzip();
    profile::step(profile::SEEDS, t.elapsed(), &times);
    found.into_iter().flatten().collect()
}

/// [`admit`] on (type, key) pairs.
pub(super) fn new_orbit(have: &[(usize, &[f64])], pattern: usize, key: &[f64]) -> bool {
    let mut n = 0;
    for (_, h) in have.iter().filter(|(k, _)| *k == pattern) {
        if same_orbit(h, key) {
            return false;
        }
        n += 1;
    }
    n < MAX_PER_TYPE
}

/// Seed positions along one parameter of length `len`: spacing `ceil(len / seeds)`,
/// offset to the middle of the first interval.
fn seed_positions(len: usize, seeds: usize) -> Vec<usize> {
    let s = len.div_ceil(seeds.max(1)).max(1);
    (s / 2..len).step_by(s).collect()
}

/// Indices of `k` of the `n` initial states, spread over the list (which alternates
/// configurations and starts at rest in the ground frame, then relative to the disk).
fn spread(n: usize, k: usize) -> Vec<usize> {
    let k = k.min(n);
    (0..k).map(|i| (i * n / k + i / 2) % n).collect()
}
