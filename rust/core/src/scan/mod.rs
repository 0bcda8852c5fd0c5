//! Parallel scans of a parameter grid (one or more dimensions).
//!
//! The grid is cut into *blocks* along its last parameter (`block` values each, fixed by
//! the grid's shape unless chosen): a block is the unit of the science, since seeding
//! and continuation stay inside it, so its rows depend only on the grid, the options
//! and its bounds. Blocks are grouped into *chunks* of whole blocks, the unit of
//! progress reports, interruption, resumption and distribution: a chunk's rows never
//! depend on the chunk length, on which other chunks run, where, or on how many
//! threads. Inside a block:
//!
//! 1. *Seeds*: a sparse lattice of points, plus the points where the perfect balance
//!    changes stability (O-type motions are born there), is simulated from a few
//!    initial states; each attractor's rotation pattern is read off the simulation and
//!    the harmonic balance is solved from it for every requested type at once.
//! 2. *Continuation*: every solution found is continued to its grid neighbours in all
//!    directions (secant predictor where the solution itself came from the opposite
//!    neighbour), wave after wave, until no new solution appears. This reaches unstable
//!    solutions that no simulation finds, and coexisting ones from different seeds.
//!
//! Each wave reads only what earlier waves produced and runs its points in parallel,
//! so the table does not depend on the thread count. Solutions that are the same orbit
//! (shifted phase, swapped identical balls) are merged by a phase-free key.

use crate::equilibria::{equilibria, Equilibrium, Verdict};
use crate::error::{Error, Result};
use crate::floquet::FloquetOptions;
use crate::hb::{solve, HbSolution, Status};
use crate::periodic::{
    finish, guess_from_state, initial_states, require_autonomous, Periodic, PeriodicOptions,
};
use crate::{Dynamics, Planar, Scene};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Most solutions of one type kept at one point: a guard against a duplicate test
/// that a pathological orbit family might slip through.
const MAX_PER_TYPE: usize = 4;

/// A model whose parameters a scan varies: the planar balancer, or a scene.
pub trait Family: Dynamics + Clone {
    /// A copy with one named parameter changed, validated.
    fn with_param(&self, name: &str, value: f64) -> Result<Self>;
    /// The equilibrium reported beside every point (`pb_exists`, `pb_stable`): the
    /// perfect balance, or with ball springs the balanced state that continues it.
    fn balance(&self) -> Option<Equilibrium>;
}

impl Family for Planar {
    fn with_param(&self, name: &str, value: f64) -> Result<Self> {
        Planar::with_param(self, name, value)
    }
    fn balance(&self) -> Option<Equilibrium> {
        equilibria(self)
            .into_iter()
            .find(|e| e.kind == "perfect_balance")
    }
}

impl Family for Scene {
    fn with_param(&self, name: &str, value: f64) -> Result<Self> {
        Scene::with_param(self, name, value)
    }
    fn balance(&self) -> Option<Equilibrium> {
        crate::analysis::balanced::balanced_state(self)
    }
}

#[derive(Debug, Clone)]
pub struct ScanRow {
    /// Grid index along each parameter.
    pub index: Vec<usize>,
    pub pattern: usize,
    /// Number of this solution among those of its type at this point (0, 1, ...);
    /// `None` when none was found.
    pub solution: Option<usize>,
    pub result: Option<Periodic>,
    /// How the solution was reached: "seed" (simulated start), "continuation"; "none".
    pub origin: &'static str,
    /// Harmonic-balance attempts made at this point for this type.
    pub attempts: usize,
    /// Time of the successful solve and its Floquet analysis, or of all failed attempts.
    pub seconds: f64,
    pub pb_exists: bool,
    pub pb_stable: bool,
}

#[derive(Debug, Clone)]
pub struct ScanSpec<'a, D: Family> {
    pub base: &'a D,
    pub names: Vec<String>,
    pub values: Vec<Vec<f64>>,
    /// Rotation pattern per requested solution type.
    pub patterns: Vec<Vec<bool>>,
    pub opts: PeriodicOptions,
    /// Seed points per parameter over the whole grid (their spacing in grid steps is
    /// `ceil(len / seeds)`); every chunk gets at least one seed line.
    pub seeds: usize,
    /// Simulated initial states per seed point.
    pub starts: usize,
    /// Values of the last parameter per continuation block (seeding and continuation
    /// stay inside a block, so this is a numerical option; see [`default_chunk`]).
    pub block: usize,
    /// Values of the last parameter per chunk, rounded up to whole blocks: the unit of
    /// progress and resumption only; the rows do not depend on it.
    pub chunk: usize,
    pub threads: usize,
    /// Largest accepted [`HbSolution::tail_ratio`]; a solution above it is not resolved
    /// by `N` harmonics and is neither reported nor continued.
    pub max_tail: f64,
}

impl<D: Family> ScanSpec<'_, D> {
    /// Checks every value and option before any work starts.
    pub fn validate(&self) -> Result<()> {
        require_autonomous(self.base)?;
        if self.names.is_empty() || self.names.len() != self.values.len() {
            return Err(Error::param(
                "grid",
                "give at least one parameter with its values",
            ));
        }
        for (k, vals) in self.values.iter().enumerate() {
            let name = &self.names[k];
            if self.names[..k].contains(name) {
                return Err(Error::param(name.as_str(), "is scanned twice"));
            }
            if vals.is_empty() {
                return Err(Error::param(name.as_str(), "the grid is empty"));
            }
            for &v in vals {
                self.base.with_param(name, v)?;
            }
        }
        // Every combination must be valid, not just every value (e.g. ball masses).
        for k in 0..self.values.len() {
            let mut p = self.base.clone();
            for (j, vals) in self.values.iter().enumerate() {
                if j != k {
                    p = p.with_param(&self.names[j], vals[0])?;
                }
            }
            for &v in &self.values[k] {
                p.with_param(&self.names[k], v)?;
            }
        }
        if self.patterns.is_empty() {
            return Err(Error::param("patterns", "give at least one solution type"));
        }
        for (name, v, lo) in [
            ("threads", self.threads, 1),
            ("seeds", self.seeds, 1),
            ("starts", self.starts, 1),
            ("chunk", self.chunk, 1),
            ("block", self.block, 1),
        ] {
            if v < lo {
                return Err(Error::param(name, format!("must be >= {lo}, got {v}")));
            }
        }
        if !(self.max_tail > 0.0) {
            return Err(Error::param(
                "max_tail",
                format!("must be a number > 0, got {}", self.max_tail),
            ));
        }
        let available = initial_states(self.base).len();
        if self.starts > available {
            return Err(Error::param(
                "starts",
                format!("must be in [1, {available}], got {}", self.starts),
            ));
        }
        Ok(())
    }

    /// Chunk length actually used: `chunk` rounded up to whole blocks, so that no block
    /// is ever split between chunks (a split block would continue less).
    pub fn chunk_len(&self) -> usize {
        let b = self.block.max(1);
        self.chunk.max(1).div_ceil(b) * b
    }

    /// Chunk bounds along the last parameter.
    pub fn chunks(&self) -> Vec<Range<usize>> {
        let n = self.values.last().map_or(0, |v| v.len());
        let len = self.chunk_len();
        (0..n).step_by(len).map(|a| a..(a + len).min(n)).collect()
    }

    /// Block bounds inside a chunk (chunks start on block edges).
    fn blocks(&self, chunk: &Range<usize>) -> Vec<Range<usize>> {
        let b = self.block.max(1);
        chunk
            .clone()
            .step_by(b)
            .map(|a| a..(a + b).min(chunk.end))
            .collect()
    }
}

/// Default block (and chunk) length: about 1024 grid points, so that a block is long
/// enough for continuation and seeds to pay off and short enough to report progress and
/// lose little on interruption. It depends on the grid's shape only.
pub fn default_chunk(lens: &[usize]) -> usize {
    let inner: usize = lens[..lens.len().saturating_sub(1)].iter().product();
    let outer = lens.last().copied().unwrap_or(1);
    1024usize.div_ceil(inner.max(1)).clamp(1, outer.max(1))
}

/// Runs the chunks `which` (indices into `spec.chunks()`) and hands each finished
/// chunk's rows to `on_chunk` (from a worker thread, in completion order). Stops early,
/// with `Error::Cancelled`, once `cancel` is set; chunks already handed over are kept.
pub fn scan_chunks<D: Family>(
    spec: &ScanSpec<'_, D>,
    which: &[usize],
    cancel: &AtomicBool,
    on_chunk: &(dyn Fn(usize, Vec<ScanRow>) + Sync),
) -> Result<()> {
    spec.validate()?;
    let chunks = spec.chunks();
    if let Some(&c) = which.iter().find(|&&c| c >= chunks.len()) {
        return Err(Error::param(
            "chunks",
            format!("chunk {c} is out of range 0..{}", chunks.len()),
        ));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(spec.threads)
        .build()
        .map_err(|e| Error::param("threads", e.to_string()))?;
    pool.install(|| {
        which.par_iter().try_for_each(|&c| {
            let parts = spec
                .blocks(&chunks[c])
                .into_par_iter()
                .map(|b| scan_chunk(spec, b, cancel))
                .collect::<Result<Vec<_>>>()?;
            on_chunk(c, parts.into_iter().flatten().collect());
            Ok(())
        })
    })
}

/// The whole grid in one call; rows ordered by point (first parameter fastest), type
/// and solution number.
pub fn scan<D: Family>(spec: &ScanSpec<'_, D>) -> Result<Vec<ScanRow>> {
    let n = spec.chunks().len();
    let out = std::sync::Mutex::new(vec![None; n]);
    let all: Vec<usize> = (0..n).collect();
    scan_chunks(spec, &all, &AtomicBool::new(false), &|c, rows| {
        out.lock().unwrap()[c] = Some(rows);
    })?;
    Ok(out
        .into_inner()
        .unwrap()
        .into_iter()
        .flat_map(|r| r.unwrap_or_default())
        .collect())
}

/// A solution found at one point of a chunk.
#[derive(Clone)]
struct Found {
    pattern: usize,
    res: Periodic,
    origin: &'static str,
    /// (point, solution) it was continued from.
    parent: Option<(usize, usize)>,
    key: Vec<f64>,
    seconds: f64,
}

/// Phase-free description of an orbit: omega, the sorted windings, and the amplitude
/// of every harmonic of the support motion (a time shift changes only phases, and
/// swapping identical balls does not change x, y).
fn orbit_key(s: &HbSolution) -> Vec<f64> {
    let mut key = vec![s.omega];
    let mut w: Vec<f64> = s.winding.clone();
    w.sort_by(f64::total_cmp);
    key.extend(w);
    let (cx, cy) = (s.coord(0), s.coord(1));
    key.push(cx[0].hypot(cy[0]));
    for m in 1..=s.n_harm {
        let (i, j) = (2 * m - 1, 2 * m);
        key.push((cx[i].powi(2) + cx[j].powi(2) + cy[i].powi(2) + cy[j].powi(2)).sqrt());
    }
    key
}

fn same_orbit(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-5 * (1.0 + x.abs().max(y.abs())))
}

/// Chunk-local grid geometry: sizes, strides, neighbours.
struct Local {
    lens: Vec<usize>,
    strides: Vec<usize>,
    outer0: usize,
}

impl Local {
    fn new<D: Family>(spec: &ScanSpec<'_, D>, range: &Range<usize>) -> Self {
        let mut lens: Vec<usize> = spec.values.iter().map(|v| v.len()).collect();
        *lens.last_mut().unwrap() = range.len();
        let mut strides = vec![1; lens.len()];
        for k in 1..lens.len() {
            strides[k] = strides[k - 1] * lens[k - 1];
        }
        Local {
            lens,
            strides,
            outer0: range.start,
        }
    }
    fn size(&self) -> usize {
        self.lens.iter().product()
    }
    fn index(&self, p: usize) -> Vec<usize> {
        let mut idx: Vec<usize> = (0..self.lens.len())
            .map(|k| (p / self.strides[k]) % self.lens[k])
            .collect();
        *idx.last_mut().unwrap() += self.outer0;
        idx
    }
    /// Neighbours of `p` as (neighbour, the point on the far side of `p` from it).
    fn neighbours(&self, p: usize) -> Vec<(usize, Option<usize>)> {
        let mut out = vec![];
        for k in 0..self.lens.len() {
            let i = (p / self.strides[k]) % self.lens[k];
            let s = self.strides[k];
            if i > 0 {
                out.push((p - s, (i + 1 < self.lens[k]).then(|| p + s)));
            }
            if i + 1 < self.lens[k] {
                out.push((p + s, (i > 0).then(|| p - s)));
            }
        }
        out.sort_unstable();
        out
    }
}

/// Seed positions along one parameter of length `len`: spacing `ceil(len / seeds)`,
/// offset to the middle of the first interval.
fn seed_positions(len: usize, seeds: usize) -> Vec<usize> {
    let s = len.div_ceil(seeds.max(1)).max(1);
    (s / 2..len).step_by(s).collect()
}

fn scan_chunk<D: Family>(
    spec: &ScanSpec<'_, D>,
    range: Range<usize>,
    cancel: &AtomicBool,
) -> Result<Vec<ScanRow>> {
    let geo = Local::new(spec, &range);
    let npts = geo.size();
    let dims = spec.names.len();
    let np = spec.patterns.len();
    let params: Vec<D> = (0..npts)
        .map(|p| {
            let idx = geo.index(p);
            let mut q = spec.base.clone();
            for (k, &i) in idx.iter().enumerate() {
                q = q.with_param(&spec.names[k], spec.values[k][i])?;
            }
            Ok(q)
        })
        .collect::<Result<_>>()?;
    let pb: Vec<(bool, bool)> = params
        .par_iter()
        .map(|p| {
            let e = p.balance();
            (e.is_some(), e.is_some_and(|e| e.verdict == Verdict::Stable))
        })
        .collect();
    let check = || {
        if cancel.load(Ordering::Relaxed) {
            Err(Error::Cancelled)
        } else {
            Ok(())
        }
    };
    check()?;

    // Seed points: the lattice, every chunk's middle line if the lattice misses the
    // chunk, and (when an oscillating type is wanted) the points on either side of the
    // perfect balance's stability boundary, where O motions are born in a Hopf
    // bifurcation; these get half the starts, since there are many of them.
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
    let mut boundary: Vec<usize> = vec![];
    if spec.patterns.iter().any(|r| r.iter().any(|&b| !b)) {
        boundary = (0..npts)
            .filter(|&p| {
                !seeds.contains(&p) && geo.neighbours(p).iter().any(|&(q, _)| pb[q] != pb[p])
            })
            .collect();
    }

    let mut sols: Vec<Vec<Found>> = vec![vec![]; npts];
    let mut attempts = vec![vec![0usize; np]; npts];
    let mut fail_secs = vec![vec![0.0f64; np]; npts];
    let n_harm = spec.opts.hb.n_harm;
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
    let seeded: Vec<Option<(usize, Found)>> = tasks
        .par_iter()
        .map(|&(p, s)| {
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            let t = Instant::now();
            let model = &params[p];
            // This point's own states: "at rest in the ground frame" depends on its spin.
            let y0 = &initial_states(model)[starts[s]];
            let g = guess_from_state(model, y0, None, n_harm, &spec.opts.guess)?;
            let rot: Vec<bool> = g.winding[model.first_ball()..]
                .iter()
                .map(|w| *w != 0.0)
                .collect();
            let k = spec.patterns.iter().position(|r| *r == rot)?;
            let sol = solve(model, &g, &spec.opts.hb);
            if !accept(model, &sol, &g, spec) {
                return None;
            }
            let key = orbit_key(&sol);
            let res = finish(model, sol, &spec.opts);
            if res.sol.status != Status::Converged {
                return None;
            }
            Some((
                p,
                Found {
                    pattern: k,
                    res,
                    origin: "seed",
                    parent: None,
                    key,
                    seconds: t.elapsed().as_secs_f64(),
                },
            ))
        })
        .collect();
    check()?;
    let mut frontier: Vec<(usize, usize)> = vec![];
    for (p, f) in seeded.into_iter().flatten() {
        if admit(&sols[p], f.pattern, &f.key) {
            sols[p].push(f);
            frontier.push((p, sols[p].len() - 1));
        }
    }

    // Continuation waves.
    while !frontier.is_empty() {
        let mut fresh_at: Vec<Vec<usize>> = vec![vec![]; npts];
        for &(p, s) in &frontier {
            fresh_at[p].push(s);
        }
        let targets: Vec<usize> = (0..npts)
            .filter(|&q| {
                geo.neighbours(q)
                    .iter()
                    .any(|(p, _)| !fresh_at[*p].is_empty())
            })
            .collect();
        let results: Vec<(Vec<Found>, Vec<usize>, Vec<f64>)> = targets
            .par_iter()
            .map(|&q| {
                let mut new: Vec<Found> = vec![];
                let mut tries = vec![0usize; np];
                let mut secs = vec![0.0f64; np];
                for (p, far) in geo.neighbours(q) {
                    for &s in &fresh_at[p] {
                        if cancel.load(Ordering::Relaxed) {
                            return (new, tries, secs);
                        }
                        let src = &sols[p][s];
                        // Continuing back to where a solution came from, or again from a
                        // solution already continued here, gives nothing new.
                        if src.parent.is_some_and(|(pp, _)| pp == q)
                            || sols[q].iter().any(|f| f.parent == Some((p, s)))
                        {
                            continue;
                        }
                        let k = src.pattern;
                        let t = Instant::now();
                        let secant = match (far, src.parent) {
                            (Some(f), Some((pp, ps))) if pp == f => {
                                Some(extrapolate(&src.res.sol, &sols[pp][ps].res.sol))
                            }
                            _ => None,
                        };
                        let mut sol = None;
                        for g in secant.iter().chain(std::iter::once(&src.res.sol)) {
                            tries[k] += 1;
                            let r = solve(&params[q], g, &spec.opts.hb);
                            if accept(&params[q], &r, &src.res.sol, spec) {
                                sol = Some(r);
                                break;
                            }
                        }
                        let Some(sol) = sol else {
                            secs[k] += t.elapsed().as_secs_f64();
                            continue;
                        };
                        let key = orbit_key(&sol);
                        // Before the Floquet analysis, which a known orbit does not need.
                        if !admit(&sols[q], k, &key) || !admit(&new, k, &key) {
                            secs[k] += t.elapsed().as_secs_f64();
                            continue;
                        }
                        let res = finish(&params[q], sol, &spec.opts);
                        // Refined with N = "auto" and certified: a series that fails
                        // is neither reported nor continued, like a failed solve.
                        if res.sol.status != Status::Converged {
                            secs[k] += t.elapsed().as_secs_f64();
                            continue;
                        }
                        new.push(Found {
                            pattern: k,
                            res,
                            origin: "continuation",
                            parent: Some((p, s)),
                            key,
                            seconds: t.elapsed().as_secs_f64(),
                        });
                    }
                }
                (new, tries, secs)
            })
            .collect();
        check()?;
        frontier.clear();
        for (&q, (new, tries, secs)) in targets.iter().zip(results) {
            for k in 0..np {
                attempts[q][k] += tries[k];
                fail_secs[q][k] += secs[k];
            }
            for f in new {
                if admit(&sols[q], f.pattern, &f.key) {
                    sols[q].push(f);
                    frontier.push((q, sols[q].len() - 1));
                }
            }
        }
    }

    let mut seed_runs = vec![0usize; npts];
    for &(p, _) in &tasks {
        seed_runs[p] += 1;
    }
    let mut rows = vec![];
    for p in 0..npts {
        let index = geo.index(p);
        for k in 0..np {
            let mut mine: Vec<&Found> = sols[p].iter().filter(|f| f.pattern == k).collect();
            mine.sort_by(|a, b| a.res.sol.omega.total_cmp(&b.res.sol.omega));
            let base = ScanRow {
                index: index.clone(),
                pattern: k,
                solution: None,
                result: None,
                origin: "none",
                attempts: attempts[p][k] + seed_runs[p],
                seconds: fail_secs[p][k],
                pb_exists: pb[p].0,
                pb_stable: pb[p].1,
            };
            if mine.is_empty() {
                rows.push(base.clone());
            }
            for (m, f) in mine.into_iter().enumerate() {
                rows.push(ScanRow {
                    solution: Some(m),
                    result: Some(f.res.clone()),
                    origin: f.origin,
                    seconds: f.seconds,
                    ..base.clone()
                });
            }
        }
    }
    Ok(rows)
}

/// A converged, resolved solution of the same rotation pattern as its guess, whose
/// series passes the orbit-closure certificate (checked here already, before the
/// duplicate test and the Floquet analysis, so that a refused series can fall back to
/// the next guess; with N = "auto" only after refinement, in `finish`).
fn accept<D: Family>(
    model: &D,
    s: &HbSolution,
    guess: &HbSolution,
    spec: &ScanSpec<'_, D>,
) -> bool {
    if !(s.status == Status::Converged
        && s.winding == guess.winding
        && s.tail_ratio() <= spec.max_tail)
    {
        return false;
    }
    spec.opts.auto.is_some() || {
        let mut c = s.clone();
        crate::periodic::certify(model, &mut c, &spec.opts);
        c.status == Status::Converged
    }
}

/// Whether an orbit of type `pattern` with `key` is new among `have`, and its type
/// still has room there.
fn admit(have: &[Found], pattern: usize, key: &[f64]) -> bool {
    let mut n = 0;
    for h in have.iter().filter(|h| h.pattern == pattern) {
        if same_orbit(&h.key, key) {
            return false;
        }
        n += 1;
    }
    n < MAX_PER_TYPE
}

/// Secant predictor `2 a - b` in coefficients and frequency.
fn extrapolate(a: &HbSolution, b: &HbSolution) -> HbSolution {
    let mut g = a.clone();
    for (x, y) in g.coeffs.iter_mut().zip(&b.coeffs) {
        *x = 2.0 * *x - y;
    }
    g.omega = 2.0 * a.omega - b.omega;
    if !(g.omega > 0.0) {
        g.omega = a.omega;
    }
    g
}

/// Indices of `k` of the `n` initial states, spread over the list (which alternates
/// configurations and starts at rest in the ground frame, then relative to the disk).
fn spread(n: usize, k: usize) -> Vec<usize> {
    let k = k.min(n);
    (0..k).map(|i| (i * n / k + i / 2) % n).collect()
}

/// Floquet tolerances suited to many points (see the periodic benchmark).
pub fn scan_floquet_default() -> FloquetOptions {
    FloquetOptions {
        rtol: 1e-6,
        atol: 1e-9,
        margin: 1e-6,
        max_steps: 20_000,
        ..FloquetOptions::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hb::HbOptions;
    use crate::periodic::GuessOptions;

    fn spec<'a, D: Family>(
        base: &'a D,
        om: &[f64],
        eta: &[f64],
        threads: usize,
    ) -> ScanSpec<'a, D> {
        ScanSpec {
            base,
            names: vec!["Omega".into(), "eta".into()],
            values: vec![om.to_vec(), eta.to_vec()],
            patterns: vec![vec![true, true]],
            opts: PeriodicOptions {
                hb: HbOptions::default(),
                floquet: Some(scan_floquet_default()),
                guess: GuessOptions {
                    rtol: 1e-6,
                    atol: 1e-8,
                    ..Default::default()
                },
                ..Default::default()
            },
            seeds: 2,
            starts: 2,
            block: 2,
            chunk: 2,
            threads,
            max_tail: 0.25,
        }
    }

    #[test]
    fn thread_count_does_not_change_the_table() {
        let base = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let om = [1.1, 1.15, 1.2, 1.25];
        let eta = [0.9, 1.0, 1.1];
        let a = scan(&spec(&base, &om, &eta, 1)).unwrap();
        let b = scan(&spec(&base, &om, &eta, 2)).unwrap();
        assert_eq!(a.len(), b.len());
        assert!(a.iter().filter(|r| r.result.is_some()).count() >= 10);
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.index, y.index);
            assert_eq!(x.origin, y.origin);
            let (wx, wy) = (
                x.result.as_ref().map(|r| r.sol.omega.to_bits()),
                y.result.as_ref().map(|r| r.sol.omega.to_bits()),
            );
            assert_eq!(wx, wy);
        }
    }

    #[test]
    fn chunk_results_do_not_depend_on_which_chunks_run() {
        let base = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let om = [1.15, 1.2, 1.25];
        let eta = [0.9, 1.0, 1.1, 1.2];
        let s = spec(&base, &om, &eta, 2);
        let all = scan(&s).unwrap();
        let got = std::sync::Mutex::new(vec![]);
        scan_chunks(&s, &[1], &AtomicBool::new(false), &|_, rows| {
            got.lock().unwrap().extend(rows)
        })
        .unwrap();
        let part = got.into_inner().unwrap();
        let tail: Vec<&ScanRow> = all.iter().filter(|r| r.index[1] >= 2).collect();
        assert_eq!(part.len(), tail.len());
        for (x, y) in part.iter().zip(tail) {
            assert_eq!(
                x.result.as_ref().map(|r| r.sol.omega.to_bits()),
                y.result.as_ref().map(|r| r.sol.omega.to_bits())
            );
        }
    }

    #[test]
    fn chunk_length_does_not_change_the_table() {
        // Chunks of 1, 2 (one block), 3 and 5 values: every chunk is made of whole
        // blocks, so the rows are those of the one-block-per-chunk scan, bit for bit.
        let base = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let om = [1.15, 1.2, 1.25];
        let eta = [0.8, 0.9, 1.0, 1.1, 1.2];
        let reference = scan(&spec(&base, &om, &eta, 2)).unwrap();
        assert!(reference.iter().filter(|r| r.result.is_some()).count() >= 10);
        for chunk in [1, 3, 5] {
            let s = ScanSpec {
                chunk,
                ..spec(&base, &om, &eta, 1)
            };
            assert!(s.chunks().iter().all(|c| c.start % 2 == 0));
            let rows = scan(&s).unwrap();
            assert_eq!(rows.len(), reference.len(), "chunk {chunk}");
            for (x, y) in rows.iter().zip(&reference) {
                assert_eq!(
                    (&x.index, x.pattern, x.solution),
                    (&y.index, y.pattern, y.solution)
                );
                assert_eq!(
                    x.result.as_ref().map(|r| r.sol.omega.to_bits()),
                    y.result.as_ref().map(|r| r.sol.omega.to_bits())
                );
            }
        }
    }

    #[test]
    fn cancelled_scan_stops_with_cancelled() {
        let base = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let s = spec(&base, &[1.2, 1.3], &[1.0], 1);
        let r = scan_chunks(&s, &[0], &AtomicBool::new(true), &|_, _| {
            panic!("no chunk may finish")
        });
        assert_eq!(r, Err(Error::Cancelled));
    }

    #[test]
    fn bad_grid_is_rejected_before_work() {
        let base = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let mk = |name: &str, v: Vec<f64>| ScanSpec {
            names: vec![name.into(), "eta".into()],
            values: vec![v, vec![1.0]],
            ..spec(&base, &[1.0], &[1.0], 1)
        };
        let e = scan(&mk("Omega", vec![])).err().unwrap();
        assert!(e.to_string().starts_with("Omega"), "{e}");
        let e = scan(&mk("Omega", vec![f64::NAN])).err().unwrap();
        assert!(e.to_string().starts_with("Omega"), "{e}");
        let e = scan(&mk("gravity", vec![1.0])).err().unwrap();
        assert!(e.to_string().starts_with("gravity"), "{e}");
        let e = scan(&mk("eta", vec![1.0])).err().unwrap();
        assert!(e.to_string().starts_with("eta"), "{e}");
    }

    #[test]
    fn mid_span_tilting_scene_scans_like_the_planar_balancer() {
        // a = b: no coupling, a flat disk stays flat; every planar orbit is an orbit of
        // the scene with A = B = 0, and the scan must find it with the same omega.
        let base = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let tilt = crate::model::scene::Tilt {
            a: 2.0,
            b: 2.0,
            j_t: 0.15,
            j_z: 0.25,
            zeta_r: 0.05,
        };
        let sc = Scene::new(base.clone(), 0.0, None, 0.0, None, Some(tilt)).unwrap();
        let om = [1.15, 1.2, 1.25];
        let eta = [0.9, 1.0];
        let flat = scan(&spec(&base, &om, &eta, 2)).unwrap();
        let tilted = scan(&spec(&sc, &om, &eta, 2)).unwrap();
        let mut matched = 0;
        for r in flat.iter().filter(|r| r.result.is_some()) {
            let w = r.result.as_ref().unwrap().sol.omega;
            let twin = tilted.iter().find(|t| {
                t.index == r.index
                    && t.result
                        .as_ref()
                        .is_some_and(|x| (x.sol.omega - w).abs() < 1e-9)
            });
            assert!(
                twin.is_some(),
                "planar orbit omega {w} at {:?} missing",
                r.index
            );
            assert_eq!(twin.unwrap().pb_stable, r.pb_stable);
            matched += 1;
        }
        assert!(matched >= 6);
    }

    #[test]
    fn scene_parameters_are_scanned_by_name_and_time_dependent_scenes_refused() {
        let base = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let sc = Scene::new(base.clone(), 1e-5, None, 0.0, None, None).unwrap();
        let s2 = Family::with_param(&sc, "springs", 2e-5).unwrap();
        assert_eq!(s2.springs, 2e-5);
        let e = Family::with_param(&sc, "j_t", 0.1).err().unwrap();
        assert!(e.to_string().starts_with("j_t: is a tilt parameter"), "{e}");
        let e = Family::with_param(&sc, "spring", 0.1).err().unwrap();
        assert!(e.to_string().contains("parameter of the scene"), "{e}");
        let e = Family::with_param(&sc, "springs", -1.0).err().unwrap();
        assert!(e.to_string().starts_with("springs"), "{e}");
        let ramp = crate::model::scene::Ramp {
            to: 2.0,
            start: 0.0,
            duration: 10.0,
        };
        let sr = Scene::new(base, 0.0, Some(ramp), 0.0, None, None).unwrap();
        let e = scan(&spec(&sr, &[1.2], &[1.0], 1)).err().unwrap();
        assert!(e.to_string().contains("'ramp'"), "{e}");
    }

    #[test]
    fn orbit_key_ignores_time_shift() {
        let base = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let r = crate::periodic::periodic(&base, &[true, true], None, &PeriodicOptions::default());
        let s = r.sol;
        // The same orbit started a quarter period later: rotate every harmonic.
        let mut t = s.clone();
        let l = 2 * s.n_harm + 1;
        for j in 0..2 {
            for m in 1..=s.n_harm {
                let th = m as f64 * std::f64::consts::FRAC_PI_2;
                let (a, b) = (s.coeffs[j * l + 2 * m - 1], s.coeffs[j * l + 2 * m]);
                t.coeffs[j * l + 2 * m - 1] = a * th.cos() + b * th.sin();
                t.coeffs[j * l + 2 * m] = -a * th.sin() + b * th.cos();
            }
        }
        assert!(same_orbit(&orbit_key(&s), &orbit_key(&t)));
        let mut u = s.clone();
        u.omega *= 1.001;
        assert!(!same_orbit(&orbit_key(&s), &orbit_key(&u)));
    }
}
