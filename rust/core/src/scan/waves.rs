//! Continuation inside a block: the harmonic-balance solve as the continuation's
//! corrector, and the scan's rules for what a new solution is (same rotation pattern,
//! resolved, certified; not an orbit already known there).

use super::{count, profile, work, Family, Found, Origin, ScanSpec};
use crate::continuation::lattice::Known;
use crate::continuation::{Corrector, Waves};
use crate::hb::{solve, HbSolution, Status};
use crate::periodic::{finish_certified, is_repeated};
use std::time::{Duration, Instant};

/// Most solutions of one type kept at one point: a guard against a duplicate test
/// that a pathological orbit family might slip through.
pub(super) const MAX_PER_TYPE: usize = 4;

/// A block's models and options, as the continuation sees them.
pub(super) struct BlockWaves<'s, 'a, D: Family> {
    pub spec: &'s ScanSpec<'a, D>,
    /// The model at every point of the block.
    pub params: &'s [D],
}

/// An accepted series and the closure of its orbit-closure certificate, when the
/// certificate was computed (without N = "auto"), which `finish` then need not
/// integrate again.
pub(super) struct Certified {
    sol: HbSolution,
    closure: Option<f64>,
}

impl<D: Family> Corrector for BlockWaves<'_, '_, D> {
    type At = usize;
    type Point = HbSolution;
    fn correct(&self, at: &usize, guess: &HbSolution, from: &HbSolution) -> Option<HbSolution> {
        self.attempt(*at, guess, from, None).map(|c| c.sol)
    }
}

impl<D: Family> Waves for BlockWaves<'_, '_, D> {
    type Found = Found;
    type Key = Vec<f64>;
    type Corrected = Certified;
    fn point(f: &Found) -> &HbSolution {
        &f.res.sol
    }
    fn corrected(c: &Certified) -> &HbSolution {
        &c.sol
    }
    fn class(f: &Found) -> usize {
        f.pattern
    }
    fn parent(f: &Found) -> Option<(usize, usize)> {
        f.parent
    }
    fn key(&self, p: &HbSolution) -> Vec<f64> {
        // every point of a block has the base model's layout
        orbit_key(p, self.spec.base.layout().support())
    }
    fn found_key(f: &Found) -> &Vec<f64> {
        &f.key
    }
    fn admit(&self, have: &[Found], class: usize, key: &Vec<f64>) -> bool {
        admit(have, class, key)
    }
    fn attempt(
        &self,
        at: usize,
        guess: &HbSolution,
        from: &HbSolution,
        last: Option<Known<'_, Found>>,
    ) -> Option<Certified> {
        let model = &self.params[at];
        count(work::WAVE_SOLVE);
        let mut r = solve(model, guess, &self.spec.hb_for(&guess.winding));
        if !resolved(model, &r, from, self.spec) {
            return None;
        }
        // Most last attempts reach an orbit already found at their point: its
        // certificate would only decide whether a later guess is tried, and there is
        // none.
        if let Some(k) = last {
            let key = self.key(&r);
            if !admit(k.have, k.class, &key) || !admit(k.new, k.class, &key) {
                count(work::SPARED);
                return None;
            }
        }
        // In place: a refused series is dropped.
        let closure = certified(model, &mut r, self.spec)?;
        Some(Certified { sol: r, closure })
    }
    fn complete(
        &self,
        at: usize,
        point: Certified,
        class: usize,
        key: Vec<f64>,
        parent: (usize, usize),
        started: Instant,
    ) -> Option<Found> {
        count(work::FINISH);
        let model = &self.params[at];
        let res = finish_certified(model, point.sol, &self.spec.opts, point.closure);
        // Refined with N = "auto" and certified: a series that fails is neither
        // reported nor continued, like a failed solve.
        if res.sol.status != Status::Converged {
            return None;
        }
        Some(Found {
            pattern: class,
            res,
            origin: Origin::Continuation,
            parent: Some(parent),
            key,
            seconds: started.elapsed().as_secs_f64(),
        })
    }
    fn left_the_branch(
        &self,
        predicted: &HbSolution,
        corrected: &HbSolution,
        from: &HbSolution,
    ) -> bool {
        // Off by more than half the frequency change the secant predicts (and more
        // than Newton's tolerance): nearer another branch than the predicted one.
        let step = (predicted.omega - from.omega).abs();
        (corrected.omega - predicted.omega).abs() > 0.5 * step + 1e-9 * from.omega.abs()
    }
    fn wave_times(&self, parallel: Duration, tasks: &[profile::Task], serial: Duration) {
        profile::step(profile::WAVES, parallel, tasks);
        profile::serial(profile::GLUE, serial);
    }
}

/// A converged, resolved solution of the same rotation pattern as its guess, whose
/// series passes the orbit-closure certificate (checked here already, before the
/// duplicate test and the Floquet analysis, so that a refused series can fall back to
/// the next guess; with N = "auto" only after refinement, in `finish`).
pub(super) fn accept<D: Family>(
    model: &D,
    s: &HbSolution,
    guess: &HbSolution,
    spec: &ScanSpec<'_, D>,
) -> bool {
    resolved(model, s, guess, spec) && certified(model, &mut s.clone(), spec).is_some()
}

/// [`accept`]'s first part: converged, of the guess's pattern, resolved, and not an
/// orbit of a shorter period written several times (a period-doubled branch continued
/// to its period doubling becomes the single orbit twice over, which is its own type's).
fn resolved<D: Family>(
    model: &D,
    s: &HbSolution,
    guess: &HbSolution,
    spec: &ScanSpec<'_, D>,
) -> bool {
    s.status == Status::Converged
        && s.winding == guess.winding
        && s.tail_ratio_on(model.layout().support()) <= spec.max_tail
        && !is_repeated(s)
}

/// [`accept`]'s second part: the orbit-closure certificate (with N = "auto" only after
/// refinement, in `finish`). `None` when refused, else the closure when computed.
/// The certificate may mark `s` refused.
fn certified<D: Family>(
    model: &D,
    s: &mut HbSolution,
    spec: &ScanSpec<'_, D>,
) -> Option<Option<f64>> {
    if spec.opts.auto.is_some() {
        return Some(None);
    }
    count(work::CERTIFY);
    let closure = crate::periodic::certify(model, s, &spec.opts);
    (s.status == Status::Converged).then_some(closure)
}

/// Whether an orbit of type `pattern` with `key` is new among `have`, and its type
/// still has room there.
pub(super) fn admit(have: &[Found], pattern: usize, key: &[f64]) -> bool {
    let mut n = 0;
    for h in have.iter().filter(|h| h.pattern == pattern) {
        if same_orbit(&h.key, key) {
            return false;
        }
        n += 1;
    }
    n < MAX_PER_TYPE
}

/// Phase-free description of an orbit: omega, the sorted windings, and the amplitude
/// of every harmonic of the support motion (a time shift changes only phases, and
/// swapping identical balls does not change x, y).
pub(super) fn orbit_key(s: &HbSolution, support: [usize; 2]) -> Vec<f64> {
    let mut key = vec![s.omega];
    let mut w: Vec<f64> = s.winding.clone();
    w.sort_by(f64::total_cmp);
    key.extend(w);
    let (cx, cy) = (s.coord(support[0]), s.coord(support[1]));
    key.push(cx[0].hypot(cy[0]));
    for m in 1..=s.n_harm {
        let (i, j) = (2 * m - 1, 2 * m);
        key.push((cx[i].powi(2) + cx[j].powi(2) + cy[i].powi(2) + cy[j].powi(2)).sqrt());
    }
    key
}

pub(super) fn same_orbit(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-5 * (1.0 + x.abs().max(y.abs())))
}
