//! Natural-parameter continuation on a grid: every solution found is continued to its
//! grid neighbours in all directions (from the solution itself; where it came from the
//! neighbour on the opposite side and that step fails or lands off the branch, from the
//! secant prediction as well), wave after wave, until no new solution appears. Each
//! wave reads only what earlier waves produced and runs its points in parallel, so the
//! result does not depend on the thread count.

use super::{Corrector, Secant};
use crate::error::{Error, Result};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// A grid of parameter points numbered `0..size()`.
pub trait Lattice: Sync {
    fn size(&self) -> usize;
    /// Neighbours of `p` as (neighbour, the point on the far side of `p` from it),
    /// in increasing order. Symmetric: `q` is a neighbour of `p` when `p` is one of `q`.
    fn neighbours(&self, p: usize) -> Vec<(usize, Option<usize>)>;
}

/// What a step at a point knows there, for the last guess (see [`Waves::attempt`]).
pub struct Known<'a, F> {
    /// The class of the solution continued.
    pub class: usize,
    /// Solutions stored at the point.
    pub have: &'a [F],
    /// Solutions this wave found there so far.
    pub new: &'a [F],
}

/// What the waves need beyond the corrector: stored solutions and how to tell a new
/// one from those known.
pub trait Waves: Corrector<At = usize> {
    /// A solution stored at a grid point (the corrected point and what else was
    /// computed for it).
    type Found: Send + Sync;
    /// A description by which the same solution is recognised.
    type Key: Send + Sync;
    /// A corrected point with what its correction learned about it (e.g. a certificate
    /// that [`Self::complete`] then need not compute again).
    type Corrected: Send;
    fn point(f: &Self::Found) -> &Self::Point;
    /// The point of a correction.
    fn corrected(c: &Self::Corrected) -> &Self::Point;
    /// Solutions are counted per class (e.g. a rotation pattern).
    fn class(f: &Self::Found) -> usize;
    /// The (grid point, solution) it was continued from.
    fn parent(f: &Self::Found) -> Option<(usize, usize)>;
    fn key(&self, p: &Self::Point) -> Self::Key;
    /// The key a stored solution was admitted with.
    fn found_key(f: &Self::Found) -> &Self::Key;
    /// Whether a solution of `class` with `key` is new among `have` (and its class
    /// still has room there).
    fn admit(&self, have: &[Self::Found], class: usize, key: &Self::Key) -> bool;
    /// [`Corrector::correct`] with what it learned. For the last guess of a step,
    /// `last` tells what is known at `at`: the correction may then refuse a point that
    /// [`Self::admit`] refuses there without the checks that only decide whether a
    /// later guess is tried (none comes after the last, and a point not admitted gives
    /// nothing either way).
    fn attempt(
        &self,
        at: usize,
        guess: &Self::Point,
        from: &Self::Point,
        last: Option<Known<'_, Self::Found>>,
    ) -> Option<Self::Corrected>;
    /// Completes a corrected, admitted point into a stored solution (e.g. with its
    /// stability), or refuses it; `started`: when this step began.
    fn complete(
        &self,
        at: usize,
        point: Self::Corrected,
        class: usize,
        key: Self::Key,
        parent: (usize, usize),
        started: Instant,
    ) -> Option<Self::Found>;
    /// Whether `corrected`, reached from `from`'s own solution as the guess, left the
    /// branch that the secant prediction `predicted` follows (it converged nearer to
    /// another solution). The waves then also try the prediction itself. By default
    /// never.
    fn left_the_branch(
        &self,
        _predicted: &Self::Point,
        _corrected: &Self::Point,
        _from: &Self::Point,
    ) -> bool {
        false
    }
    /// Told after every wave: how long its parallel part took, the duration of every
    /// target point's task and the pool thread it ran on, and how long the serial work
    /// around it took (its targets, the merge of its results). For a caller that
    /// measures parallel efficiency; nothing by default.
    fn wave_times(
        &self,
        _parallel: Duration,
        _tasks: &[(Option<usize>, Duration)],
        _serial: Duration,
    ) {
    }
}

/// Corrector calls and the time of failed steps, per grid point and class.
#[derive(Debug, Clone)]
pub struct Tally {
    pub attempts: Vec<Vec<usize>>,
    pub fail_secs: Vec<Vec<f64>>,
}

impl Tally {
    pub fn new(points: usize, classes: usize) -> Self {
        Tally {
            attempts: vec![vec![0; classes]; points],
            fail_secs: vec![vec![0.0; classes]; points],
        }
    }
}

/// One target point's share of a wave: its new solutions, the attempts and time of
/// failures per class, and the task's duration and pool thread.
type PointWave<F> = (Vec<F>, Vec<usize>, Vec<f64>, (Option<usize>, Duration));

static LONGEST_FIRST: AtomicBool = AtomicBool::new(true);

/// Whether [`waves`] starts a wave's target points with the most sources first (the
/// default) rather than in point order. The result is the same; a wave whose biggest
/// task starts last ends with one thread working alone. A benchmark's switch.
pub fn set_longest_first(on: bool) {
    LONGEST_FIRST.store(on, Ordering::Relaxed);
}

/// Runs continuation waves from `frontier` (indices `(point, solution)` into `sols`)
/// until no new solution appears; new solutions are appended to `sols`. Stops with
/// `Error::Cancelled` after the wave during which `cancel` was set.
pub fn waves<W: Waves, L: Lattice>(
    w: &W,
    lattice: &L,
    sols: &mut [Vec<W::Found>],
    mut frontier: Vec<(usize, usize)>,
    tally: &mut Tally,
    cancel: &AtomicBool,
) -> Result<()> {
    let npts = lattice.size();
    let classes = tally.attempts.first().map_or(0, |a| a.len());
    let mut fresh_at: Vec<Vec<usize>> = vec![vec![]; npts];
    while !frontier.is_empty() {
        let glue = Instant::now();
        for &(p, s) in &frontier {
            fresh_at[p].push(s);
        }
        // The points with a fresh neighbour: the neighbours of fresh points (the
        // relation is symmetric), in point order.
        let mut targets: Vec<usize> = frontier
            .iter()
            .flat_map(|&(p, _)| lattice.neighbours(p).into_iter().map(|(q, _)| q))
            .collect();
        targets.sort_unstable();
        targets.dedup();
        // Started with the most sources first, so that a wave's biggest tasks do not
        // run alone at its end; the results are merged in point order all the same.
        let sources = |q: usize| -> usize {
            lattice
                .neighbours(q)
                .iter()
                .map(|(p, _)| fresh_at[*p].len())
                .sum()
        };
        let mut order: Vec<(usize, usize)> = targets.iter().map(|&q| (sources(q), q)).collect();
        if LONGEST_FIRST.load(Ordering::Relaxed) {
            order.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
        }
        let mut serial = glue.elapsed();
        let known: &[Vec<W::Found>] = sols;
        let fresh: &[Vec<usize>] = &fresh_at;
        let parallel = Instant::now();
        let mut done: Vec<(usize, PointWave<W::Found>)> = order
            .par_iter()
            .with_max_len(1)
            .map(|&(_, q)| {
                let t0 = Instant::now();
                let (new, tries, secs) = wave_at(w, lattice, known, fresh, q, classes, cancel);
                let task = (rayon::current_thread_index(), t0.elapsed());
                (q, (new, tries, secs, task))
            })
            .collect();
        let parallel = parallel.elapsed();
        if cancel.load(Ordering::Relaxed) {
            return Err(Error::Cancelled);
        }
        let glue = Instant::now();
        done.sort_unstable_by_key(|d| d.0);
        let mut tasks = Vec::with_capacity(done.len());
        for &(p, _) in &frontier {
            fresh_at[p].clear();
        }
        frontier.clear();
        for (q, (new, tries, secs, task)) in done {
            tasks.push(task);
            for k in 0..classes {
                tally.attempts[q][k] += tries[k];
                tally.fail_secs[q][k] += secs[k];
            }
            for f in new {
                if w.admit(&sols[q], W::class(&f), W::found_key(&f)) {
                    sols[q].push(f);
                    frontier.push((q, sols[q].len() - 1));
                }
            }
        }
        serial += glue.elapsed();
        w.wave_times(parallel, &tasks, serial);
    }
    Ok(())
}

/// The steps of a wave into point `q`: from every fresh solution at its neighbours.
fn wave_at<W: Waves, L: Lattice>(
    w: &W,
    lattice: &L,
    known: &[Vec<W::Found>],
    fresh_at: &[Vec<usize>],
    q: usize,
    classes: usize,
    cancel: &AtomicBool,
) -> (Vec<W::Found>, Vec<usize>, Vec<f64>) {
    let mut new: Vec<W::Found> = vec![];
    let mut tries = vec![0usize; classes];
    let mut secs = vec![0.0f64; classes];
    for (p, _) in lattice.neighbours(q) {
        // The point beyond `p` on the line from `q` through it: a solution at `p`
        // continued from there has a secant prediction at `q`.
        let behind = lattice
            .neighbours(p)
            .into_iter()
            .find(|&(n, _)| n == q)
            .and_then(|(_, f)| f);
        for &s in &fresh_at[p] {
            if cancel.load(Ordering::Relaxed) {
                return (new, tries, secs);
            }
            let src = &known[p][s];
            // Continuing back to where a solution came from, or again from a
            // solution already continued here, gives nothing new.
            if W::parent(src).is_some_and(|(pp, _)| pp == q)
                || known[q].iter().any(|f| W::parent(f) == Some((p, s)))
            {
                continue;
            }
            let k = W::class(src);
            let t = Instant::now();
            let previous = match (behind, W::parent(src)) {
                (Some(f), Some((pp, ps))) if pp == f => Some(W::point(&known[pp][ps])),
                _ => None,
            };
            // The source itself as the guess, told what is known here. Where it fails,
            // or converges off the branch the secant through the source's parent
            // predicts (a step that jumps to a neighbouring branch: what it reaches is
            // kept), the secant prediction is tried as well, so that the branch is
            // followed too.
            let current = W::point(src);
            tries[k] += 1;
            let last = Known {
                class: k,
                have: &known[q],
                new: &new,
            };
            let mut points: Vec<W::Corrected> = w
                .attempt(q, current, current, Some(last))
                .into_iter()
                .collect();
            if let Some(b) = previous {
                let predicted = current.secant(b);
                let off = points
                    .first()
                    .is_none_or(|c| w.left_the_branch(&predicted, W::corrected(c), current));
                if off {
                    tries[k] += 1;
                    points.extend(w.attempt(q, &predicted, current, None));
                }
            }
            if points.is_empty() {
                secs[k] += t.elapsed().as_secs_f64();
                continue;
            }
            for sol in points {
                let key = w.key(W::corrected(&sol));
                // Before completing (e.g. a Floquet analysis), which a known solution
                // does not need.
                if !w.admit(&known[q], k, &key) || !w.admit(&new, k, &key) {
                    secs[k] += t.elapsed().as_secs_f64();
                    continue;
                }
                match w.complete(q, sol, k, key, (p, s), t) {
                    Some(f) => new.push(f),
                    None => secs[k] += t.elapsed().as_secs_f64(),
                }
            }
        }
    }
    (new, tries, secs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::continuation::Secant;

    /// Points `0..n` on a line at parameters `p_i = 2 + 0.1 i`; the branch solves
    /// x^3 + x = p (closed form checked below), by three Newton steps from the guess so
    /// that a poor guess fails.
    struct Line(usize);
    impl Lattice for Line {
        fn size(&self) -> usize {
            self.0
        }
        fn neighbours(&self, p: usize) -> Vec<(usize, Option<usize>)> {
            let mut out = vec![];
            if p > 0 {
                out.push((p - 1, (p + 1 < self.0).then_some(p + 1)));
            }
            if p + 1 < self.0 {
                out.push((p + 1, p.checked_sub(1)));
            }
            out
        }
    }
    #[derive(Clone, Debug)]
    struct X(f64);
    impl Secant for X {
        fn secant(&self, previous: &Self) -> Self {
            X(2.0 * self.0 - previous.0)
        }
    }
    struct Cubic;
    impl Corrector for Cubic {
        type At = usize;
        type Point = X;
        fn correct(&self, at: &usize, guess: &X, _from: &X) -> Option<X> {
            let p = 2.0 + 0.1 * *at as f64;
            let mut x = guess.0;
            for _ in 0..3 {
                x -= (x * x * x + x - p) / (3.0 * x * x + 1.0);
            }
            ((x * x * x + x - p).abs() < 1e-12).then_some(X(x))
        }
    }
    struct F {
        x: X,
        parent: Option<(usize, usize)>,
    }
    impl Waves for Cubic {
        type Found = F;
        type Key = f64;
        type Corrected = X;
        fn point(f: &F) -> &X {
            &f.x
        }
        fn corrected(c: &X) -> &X {
            c
        }
        fn attempt(&self, at: usize, guess: &X, from: &X, _: Option<Known<'_, F>>) -> Option<X> {
            self.correct(&at, guess, from)
        }
        fn class(_: &F) -> usize {
            0
        }
        fn parent(f: &F) -> Option<(usize, usize)> {
            f.parent
        }
        fn key(&self, p: &X) -> f64 {
            p.0
        }
        fn found_key(f: &F) -> &f64 {
            &f.x.0
        }
        fn admit(&self, have: &[F], _: usize, key: &f64) -> bool {
            have.iter().all(|h| (h.x.0 - key).abs() > 1e-9)
        }
        fn complete(
            &self,
            _: usize,
            x: X,
            _: usize,
            _: f64,
            parent: (usize, usize),
            _: Instant,
        ) -> Option<F> {
            Some(F {
                x,
                parent: Some(parent),
            })
        }
    }

    #[test]
    fn waves_reach_every_point_of_the_branch_once() {
        let n = 12;
        let mut sols: Vec<Vec<F>> = (0..n).map(|_| vec![]).collect();
        // One seed in the middle: x^3 + x = 2.5.
        let x5 = Cubic.correct(&5, &X(1.115), &X(1.115)).unwrap();
        sols[5].push(F {
            x: x5,
            parent: None,
        });
        let mut tally = Tally::new(n, 1);
        waves(
            &Cubic,
            &Line(n),
            &mut sols,
            vec![(5, 0)],
            &mut tally,
            &AtomicBool::new(false),
        )
        .unwrap();
        for (i, s) in sols.iter().enumerate() {
            assert_eq!(s.len(), 1, "point {i}");
            let (x, p) = (s[0].x.0, 2.0 + 0.1 * i as f64);
            assert!((x * x * x + x - p).abs() < 1e-12);
        }
        // Each point solved once, from its one neighbour nearer the seed, with the
        // first guess (the secant where the source has a parent) converging.
        assert!(tally.attempts.iter().all(|a| a[0] <= 1));
        assert_eq!(tally.attempts.iter().map(|a| a[0]).sum::<usize>(), n - 1);
        assert!(waves(
            &Cubic,
            &Line(n),
            &mut sols,
            vec![(5, 0)],
            &mut tally,
            &AtomicBool::new(true)
        )
        .is_err());
    }
}
