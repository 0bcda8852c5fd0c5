//! Continuation inside a block: the harmonic-balance solve as the continuation's
//! corrector, and the scan's rules for what a new solution is (same rotation pattern,
//! resolved, certified; not an orbit already known there).

use super::{count, work, Family, Found, Origin, ScanSpec};
use crate::continuation::{Corrector, Waves};
use crate::hb::{solve, HbSolution, Status};
use crate::periodic::finish_certified;
use std::time::Instant;

/// Most solutions of one type kept at one point: a guard against a duplicate test
/// that a pathological orbit family might slip through.
pub(super) const MAX_PER_TYPE: usize = 4;

/// A block's models and options, as the continuation sees them.
pub(super) struct BlockWaves<'s, 'a, D: Family> {
    pub spec: &'s ScanSpec<'a, D>,
    /// The model at every point of the block.
    pub params: &'s [D],
}

impl<D: Family> Corrector for BlockWaves<'_, '_, D> {
    type At = usize;
    type Point = HbSolution;
    fn correct(&self, at: &usize, guess: &HbSolution, from: &HbSolution) -> Option<HbSolution> {
        let model = &self.params[*at];
        count(work::WAVE_SOLVE);
        CERTIFIED.set(None);
        let r = solve(model, guess, &self.spec.opts.hb);
        accept(model, &r, from, self.spec).then_some(r)
    }
}

impl<D: Family> Waves for BlockWaves<'_, '_, D> {
    type Found = Found;
    type Key = Vec<f64>;
    fn point(f: &Found) -> &HbSolution {
        &f.res.sol
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
    fn correct_last(
        &self,
        at: &usize,
        guess: &HbSolution,
        from: &HbSolution,
        class: usize,
        have: &[Found],
        new: &[Found],
    ) -> Option<HbSolution> {
        // Most attempts reach an orbit already found at their point: its certificate
        // would only decide whether a later guess is tried, and there is none.
        let model = &self.params[*at];
        count(work::WAVE_SOLVE);
        CERTIFIED.set(None);
        let r = solve(model, guess, &self.spec.opts.hb);
        if !resolved(model, &r, from, self.spec) {
            return None;
        }
        let key = self.key(&r);
        if !admit(have, class, &key) || !admit(new, class, &key) {
            count(work::SPARED);
            return None;
        }
        certified(model, &r, self.spec).then_some(r)
    }
    fn complete(
        &self,
        at: usize,
        point: HbSolution,
        class: usize,
        key: Vec<f64>,
        parent: (usize, usize),
        started: Instant,
    ) -> Option<Found> {
        count(work::FINISH);
        let model = &self.params[at];
        let passed = CERTIFIED
            .take()
            .filter(|(m, c, _)| *m == model as *const D as usize && same_series(c, &point))
            .map(|(_, _, closure)| closure);
        let res = finish_certified(model, point, &self.spec.opts, passed);
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
    resolved(model, s, guess, spec) && certified(model, s, spec)
}

/// [`accept`]'s first part: converged, of the guess's pattern, resolved.
fn resolved<D: Family>(
    model: &D,
    s: &HbSolution,
    guess: &HbSolution,
    spec: &ScanSpec<'_, D>,
) -> bool {
    s.status == Status::Converged
        && s.winding == guess.winding
        && s.tail_ratio_on(model.layout().support()) <= spec.max_tail
}

/// [`accept`]'s second part: the orbit-closure certificate (with N = "auto" only after
/// refinement, in `finish`).
fn certified<D: Family>(model: &D, s: &HbSolution, spec: &ScanSpec<'_, D>) -> bool {
    spec.opts.auto.is_some() || {
        count(work::CERTIFY);
        let mut c = s.clone();
        let closure = crate::periodic::certify(model, &mut c, &spec.opts);
        let ok = c.status == Status::Converged;
        if let (true, Some(closure)) = (ok, closure) {
            CERTIFIED.set(Some((model as *const D as usize, c, closure)));
        }
        ok
    }
}

thread_local! {
    /// The last series this thread's continuation certified (its model's address, the
    /// series, its closure): the step's `complete` follows on the same thread with that
    /// very series, whose certificate `finish` then need not integrate again. Cleared
    /// before every solve, and used only for a bit-identical series of the same model.
    static CERTIFIED: std::cell::Cell<Option<(usize, HbSolution, f64)>> =
        const { std::cell::Cell::new(None) };
}

/// Whether two series are the same bits in everything [`crate::periodic::certify`]
/// reads.
fn same_series(a: &HbSolution, b: &HbSolution) -> bool {
    let bits = |x: &[f64], y: &[f64]| {
        x.len() == y.len() && x.iter().zip(y).all(|(u, v)| u.to_bits() == v.to_bits())
    };
    a.omega.to_bits() == b.omega.to_bits()
        && a.n_harm == b.n_harm
        && a.samples == b.samples
        && a.status == b.status
        && bits(&a.coeffs, &b.coeffs)
        && bits(&a.winding, &b.winding)
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
