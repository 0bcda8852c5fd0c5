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
//!    directions (from the solution itself, and from the secant prediction where that
//!    fails or jumps to another branch), wave after wave, until no new solution appears. This reaches unstable
//!    solutions that no simulation finds, and coexisting ones from different seeds.
//!
//! Each wave reads only what earlier waves produced and runs its points in parallel,
//! so the table does not depend on the thread count. Solutions that are the same orbit
//! (shifted phase, swapped identical balls) are merged by a phase-free key.
//!
//! Files: [`spec`] (what is asked, chunks and blocks), `grid` (a block's points and
//! neighbours), `seeding`, `waves` (the harmonic balance as the corrector of
//! [`crate::continuation`]'s neighbour waves) and [`rows`]. The scan sees models only
//! through [`Family`].

mod doubling;
mod grid;
pub mod profile;
pub mod rows;
mod seeding;
pub mod spec;
mod waves;

pub use crate::analysis::family::Family;
pub use rows::{Origin, ScanRow};
pub use spec::{default_chunk, ScanSpec};

use crate::continuation::{self, Lattice, Tally};
use crate::equilibria::Verdict;
use crate::error::{Error, Result};
use crate::floquet::FloquetOptions;
use crate::periodic::Periodic;
use grid::Local;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

/// Seconds spent per stage of the scans this process ran, summed over blocks (on one
/// thread: the stages' cost; on more, block stages that overlap are counted each):
/// `[perfect-balance checks, seed simulations and their solves, continuation waves,
/// row building]`. A benchmark's measure; nothing reads it back.
pub fn stage_seconds() -> [f64; 4] {
    std::array::from_fn(|i| STAGE_NS[i].load(Ordering::Relaxed) as f64 * 1e-9)
}

static STAGE_NS: [std::sync::atomic::AtomicU64; 4] =
    [const { std::sync::atomic::AtomicU64::new(0) }; 4];

fn add_stage(i: usize, since: std::time::Instant) {
    STAGE_NS[i].fetch_add(since.elapsed().as_nanos() as u64, Ordering::Relaxed);
}

/// Work done by the scans this process ran, summed over blocks: `[harmonic-balance
/// solves from seed simulations, harmonic-balance solves of continuation attempts,
/// orbit-closure certificates of solved attempts, solutions finished (refinement and
/// Floquet analysis), certificates spared (an attempt's last guess that converged to
/// an orbit already known at its point)]`. A benchmark's measure (one relaxed atomic
/// add per solve); nothing reads it back.
pub fn work_counts() -> [u64; 5] {
    std::array::from_fn(|i| WORK[i].load(Ordering::Relaxed))
}

static WORK: [std::sync::atomic::AtomicU64; 5] =
    [const { std::sync::atomic::AtomicU64::new(0) }; 5];

/// Indices into [`work_counts`].
pub(crate) mod work {
    pub const SEED_SOLVE: usize = 0;
    pub const WAVE_SOLVE: usize = 1;
    pub const CERTIFY: usize = 2;
    pub const FINISH: usize = 3;
    pub const SPARED: usize = 4;
}

pub(crate) fn count(i: usize) {
    WORK[i].fetch_add(1, Ordering::Relaxed);
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

/// A solution found at one point of a block.
#[derive(Clone)]
pub(crate) struct Found {
    pattern: usize,
    res: Periodic,
    origin: Origin,
    /// (point, solution) it was continued from.
    parent: Option<(usize, usize)>,
    key: Vec<f64>,
    seconds: f64,
}

impl Found {
    /// Stable by its Floquet verdict (undetermined is not stable).
    fn is_stable(&self) -> bool {
        self.res
            .floquet
            .as_ref()
            .is_some_and(|f| f.stability == crate::floquet::Stability::Stable)
    }
}

fn scan_chunk<D: Family>(
    spec: &ScanSpec<'_, D>,
    range: Range<usize>,
    cancel: &AtomicBool,
) -> Result<Vec<ScanRow>> {
    let glue = std::time::Instant::now();
    let geo = Local::new(spec, &range);
    let npts = geo.size();
    // The reported types; period-doubled ones are seeded from the orbits they double,
    // which are solved as unreported types where not asked for, so that a type's rows
    // do not depend on which other types were asked for.
    let np = spec.patterns.len();
    let parents = doubling::parents_needed(&spec.patterns);
    let extended;
    let spec = if parents.is_empty() {
        spec
    } else {
        extended = ScanSpec {
            patterns: spec.patterns.iter().cloned().chain(parents).collect(),
            ..spec.clone()
        };
        &extended
    };
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
    profile::serial(profile::GLUE, glue.elapsed());
    let t = std::time::Instant::now();
    let (pb, tasks): (Vec<(bool, bool)>, Vec<profile::Task>) = params
        .par_iter()
        .map(|p| {
            profile::timed(|| {
                let v = p.balance_verdict();
                (v.is_some(), v == Some(Verdict::Stable))
            })
        })
        .unzip();
    profile::step(profile::BALANCE, t.elapsed(), &tasks);
    let check = || {
        if cancel.load(Ordering::Relaxed) {
            Err(Error::Cancelled)
        } else {
            Ok(())
        }
    };
    add_stage(0, t);
    check()?;

    let t = std::time::Instant::now();
    let (tasks, starts, lattice) = seeding::seed_tasks(spec, &geo, &range, &pb);
    let whirls = seeding::whirl_tasks(spec, &lattice);
    profile::serial(profile::GLUE, t.elapsed());
    // Its parallel steps record themselves.
    let (mut sols, frontier) =
        seeding::run_seeds(spec, &params, &tasks, &starts, &whirls, &pb, cancel);
    add_stage(1, t);
    check()?;

    let mut tally = Tally::new(npts, spec.patterns.len());
    let block = waves::BlockWaves {
        spec,
        params: &params,
    };
    let t = std::time::Instant::now();
    continuation::waves(&block, &geo, &mut sols, frontier, &mut tally, cancel)?;
    check()?;
    // Gap seeds where nothing stable of a type is listed yet, continued in turn.
    let mut seeded: Vec<usize> = tasks.iter().map(|t| t.0).collect();
    seeded.dedup();
    let gaps = seeding::gap_tasks(spec, &geo, np, &sols, &pb, &lattice);
    let gap_starts = seeding::gap_starts(spec, &params, &geo, &gaps, &seeded);
    let mut frontier = vec![];
    for (p, f) in seeding::run_gap_seeds(spec, &params, &gap_starts, starts[0], cancel) {
        if waves::admit(&sols[p], f.pattern, &f.key) {
            sols[p].push(f);
            frontier.push((p, sols[p].len() - 1));
        }
    }
    check()?;
    continuation::waves(&block, &geo, &mut sols, frontier, &mut tally, cancel)?;
    // Period-doubled orbits from the orbits they double, continued in turn.
    let mut frontier = vec![];
    for (p, f) in doubling::doubling_seeds(spec, &params, &sols, cancel) {
        sols[p].push(f);
        frontier.push((p, sols[p].len() - 1));
    }
    check()?;
    continuation::waves(&block, &geo, &mut sols, frontier, &mut tally, cancel)?;
    add_stage(2, t);
    let t = std::time::Instant::now();
    // A gap seed at rest counts as one run for every type it was asked for, a gap
    // whirl start as one of its own type.
    let whirls: Vec<(usize, usize, usize)> = whirls
        .into_iter()
        .filter(|w| w.1 < np)
        .chain(gap_starts.iter().flat_map(|g| {
            g.types
                .iter()
                .map(move |&k| (g.point, k, g.whirl.unwrap_or(0)))
        }))
        .collect();
    let rows = rows::rows(&geo, np, &sols, &tally, &tasks, &whirls, &pb);
    profile::serial(profile::ROWS, t.elapsed());
    add_stage(3, t);
    Ok(rows)
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
pub(crate) mod tests {
    use super::waves::{orbit_key, same_orbit};
    use super::*;
    use crate::hb::HbOptions;
    use crate::numerics::problem::Parametric;
    use crate::periodic::{GuessOptions, PeriodicOptions};
    use crate::{Planar, Scene};

    /// A two-parameter (Omega, eta) R-R scan with the scan's defaults, small blocks.
    pub(crate) fn spec<'a, D: Family>(
        base: &'a D,
        om: &[f64],
        eta: &[f64],
        threads: usize,
    ) -> ScanSpec<'a, D> {
        ScanSpec {
            base,
            names: vec!["Omega".into(), "eta".into()],
            values: vec![om.to_vec(), eta.to_vec()],
            patterns: vec![vec![-1.0, -1.0]],
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
        let s2 = Parametric::with_param(&sc, "springs", 2e-5).unwrap();
        assert_eq!(s2.springs, 2e-5);
        let e = Parametric::with_param(&sc, "j_t", 0.1).err().unwrap();
        assert!(e.to_string().starts_with("j_t: is a tilt parameter"), "{e}");
        let e = Parametric::with_param(&sc, "spring", 0.1).err().unwrap();
        assert!(e.to_string().contains("parameter of the scene"), "{e}");
        let e = Parametric::with_param(&sc, "springs", -1.0).err().unwrap();
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
        assert!(same_orbit(&orbit_key(&s, [0, 1]), &orbit_key(&t, [0, 1])));
        let mut u = s.clone();
        u.omega *= 1.001;
        assert!(!same_orbit(&orbit_key(&s, [0, 1]), &orbit_key(&u, [0, 1])));
    }
}
