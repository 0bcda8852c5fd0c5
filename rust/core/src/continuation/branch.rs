//! The one event-driven branch loop: pseudo-arclength continuation ([`Arclength`]) of a
//! problem whose branch declares its test functions ([`Declared`]); every sign change of
//! a test function between two points is located in arclength ([`locate`]) and offered
//! to the branch as an event.
//!
//! Step control against events hidden inside one step (a step is taken again in halves,
//! at most [`MAX_SPLITS`] times in a row, through [`Arclength::subdivide`]):
//!
//! * `explained`: when the branch counts unstable eigenvalues (or multipliers) and the
//!   count changes over a step by more than the located events move, something crossed
//!   twice inside it (a Hopf point and its return, two pairs at once);
//! * `crossed_twice`: when the complex pair nearest the stability boundary is within
//!   reach of it at both ends (see [`pair_may_return`]), the test functions are
//!   evaluated at the step's midpoint: a test that changes sign there though not between
//!   the ends has two zeros inside the step.

use super::arclength::{
    locate, point_at, ArcOptions, ArcPoint, ArcStop, Arclength, Bracket, Within,
};
use crate::error::{Error, Result};
use crate::numerics::problem::Problem;

/// At most this many halvings of one step by the checks for events hidden inside it
/// (the step then stands: a check that keeps failing, e.g. on an eigenvalue that sits on
/// the axis, must not stall the branch).
pub const MAX_SPLITS: usize = 6;

/// What the step control reads of a point's spectrum (eigenvalues of an equilibrium,
/// multipliers of a periodic orbit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spectrum {
    /// Eigenvalues (multipliers) on the unstable side.
    pub unstable: usize,
    /// Signed distance of the complex pair nearest the stability boundary from it (its
    /// real part; a multiplier's modulus minus one), NaN without a pair.
    pub pair: f64,
}

impl Spectrum {
    fn pair_distance(&self) -> f64 {
        if self.pair.is_nan() {
            f64::INFINITY
        } else {
            self.pair.abs()
        }
    }
}

/// Whether the complex pair nearest the boundary could cross it and come back inside a
/// step of arclength `ds` from `a` to `b`. Near its largest value inside the step the
/// distance is `m - k (s - s*)^2`: an end a distance `d <= ds` from `s*` that is still
/// off the boundary has `|m| <= k d^2` and slope `2 k d`, so `|m| <= slope ds / 2`.
/// `rate` is that slope at `a` from the step before it (the secant); twice `rate ds`,
/// four times the parabola's bound, allows for the secant's error. Without a step
/// before `a`, the slope is taken as one (unknowns and parameters are O(1)).
pub fn pair_may_return(a: &Spectrum, b: &Spectrum, rate: Option<f64>, ds: f64) -> bool {
    let reach = rate.map_or(ds.abs(), |r| 2.0 * r * ds.abs());
    a.pair_distance().max(b.pair_distance()) < reach
}

/// The rate at which the pair nearest the boundary moves over a step of arclength `ds`.
fn pair_rate(a: &Spectrum, b: &Spectrum, ds: f64) -> Option<f64> {
    let r = (b.pair - a.pair).abs() / ds.abs();
    // a pair appearing or vanishing (NaN) or a zero step: no rate, the O(1) default
    r.is_finite().then_some(r)
}

/// Whether events that move `moved` eigenvalues (multipliers) across the boundary
/// account for the change in the unstable count from `a` to `b`.
fn explained(a: &Spectrum, b: &Spectrum, moved: usize) -> bool {
    a.unstable.abs_diff(b.unstable) <= moved
}

/// A branch's declared test functions and what it keeps: the bifurcation side of
/// [`branch`]. Test `i` is the `i`-th of [`Declared::names`]; its value at a point may be
/// missing (`None`, e.g. multipliers where a certificate failed), and then no event of
/// it is looked for next to that point.
pub trait Declared<P: Problem + ?Sized> {
    /// The row kept per point.
    type Point;
    /// A located event.
    type Event;
    /// The test functions' names.
    fn names(&self) -> &'static [&'static str];
    /// The row at a corrected point.
    fn point(&mut self, problem: &mut P, pt: &ArcPoint) -> Result<Self::Point>;
    /// The arclength point a row was made at.
    fn arc<'p>(&self, point: &'p Self::Point) -> &'p ArcPoint;
    /// The test functions' values at a row.
    fn values(&self, point: &Self::Point) -> Vec<Option<f64>>;
    /// The spectrum the step control reads, if the branch counts unstable eigenvalues
    /// (or multipliers) at this row.
    fn spectrum(&self, _point: &Self::Point) -> Option<Spectrum> {
        None
    }
    /// Test `i` at a trial point `pt` of a location between `a` and the next row.
    fn value_at(
        &mut self,
        problem: &mut P,
        a: &Self::Point,
        pt: &ArcPoint,
        i: usize,
    ) -> Result<f64>;
    /// Every test at the trial point `pt` (the middle of the step to `b`), for the check
    /// that a test changed sign twice inside a step.
    fn values_at(
        &mut self,
        problem: &mut P,
        b: &Self::Point,
        pt: &ArcPoint,
    ) -> Result<Vec<Option<f64>>>;
    /// Whether the tests of `a` and `b` are the same functions (a switched branch may
    /// change one with the solution's kind): events hidden in the step are looked for
    /// only then.
    fn comparable(&self, _a: &Self::Point, _b: &Self::Point) -> bool {
        true
    }
    /// The tests whose sign change from `a` to `b` is located, in that order (by
    /// default every test that changes sign; a branch may leave one out, e.g. when
    /// another explains it).
    fn watched(&self, a: &Self::Point, b: &Self::Point) -> Vec<usize> {
        let (va, vb) = (self.values(a), self.values(b));
        (0..va.len())
            .filter(|&i| matches!((va[i], vb[i]), (Some(x), Some(y)) if x * y < 0.0))
            .collect()
    }
    /// The event at the located zero `e` of test `i` (`g` its value there; `row` the
    /// index of the first row past it), or `None` when the zero is not one (a neutral
    /// saddle on a Hopf test, say).
    fn event(
        &mut self,
        problem: &mut P,
        i: usize,
        e: &ArcPoint,
        g: f64,
        row: usize,
    ) -> Result<Option<Self::Event>>;
    /// How many eigenvalues (multipliers) an event moves across the boundary.
    fn moves(&self, event: &Self::Event) -> usize;
    /// Why the branch ends at row `b` (it is not kept), and the event that ends it, if
    /// it does; `points` are the rows kept so far.
    fn end(
        &mut self,
        _points: &[Self::Point],
        _b: &Self::Point,
    ) -> Option<(&'static str, Option<Self::Event>)> {
        None
    }
    /// The events found between `a` and `b`, before `b` is kept (e.g. to order them, or
    /// to note them on `b`).
    fn settle(&mut self, _a: &Self::Point, _b: &mut Self::Point, _events: &mut Vec<Self::Event>) {}
}

/// A branch: its rows, its events in order, and why it ended.
#[derive(Debug, Clone)]
pub struct Branch<Pt, Ev> {
    pub points: Vec<Pt>,
    pub events: Vec<Ev>,
    pub stop: ArcStop,
}

/// Whether a test changes sign at the step's midpoint though not between its ends.
fn crossed_twice<P, T>(
    problem: &mut P,
    tests: &mut T,
    a: &T::Point,
    b: &T::Point,
    opts: &ArcOptions,
) -> Result<bool>
where
    P: Problem + ?Sized,
    T: Declared<P>,
{
    let (pa, pb) = (tests.arc(a), tests.arc(b));
    let Some(m) = point_at(problem, pa, 0.5 * pb.ds, opts)? else {
        return Ok(false);
    };
    let vm = tests.values_at(problem, b, &m)?;
    let (va, vb) = (tests.values(a), tests.values(b));
    Ok((0..va.len()).any(|i| match (va[i], vm[i], vb[i]) {
        (Some(ga), Some(gm), Some(gb)) => ga * gb > 0.0 && ga * gm < 0.0,
        _ => false,
    }))
}

/// Where a branch starts: the solution `x` at the parameter `p`, and the direction (in
/// `(x, p)`) that orients the first tangent, as at a switch (`None`: along `opts.forward`).
#[derive(Debug, Clone)]
pub struct Start<'a> {
    pub x: &'a [f64],
    pub p: f64,
    pub direction: Option<Vec<f64>>,
}

/// The one branch loop: continues `problem` from `start` by pseudo-arclength, keeps the
/// row [`Declared::point`] makes at each corrected point, and locates the sign changes
/// of the declared tests between rows to arclength `locate_tol`, subdividing a step
/// that may hide events (see the module's notes). The rows are empty when not even the
/// start converges (the caller says what it would have started from).
pub fn branch<P, T>(
    problem: &mut P,
    start: Start<'_>,
    opts: &ArcOptions,
    locate_tol: f64,
    tests: &mut T,
) -> Result<Branch<T::Point, T::Event>>
where
    P: Problem + ?Sized,
    T: Declared<P>,
{
    let within = Within {
        s: locate_tol,
        g: 0.0,
    };
    let mut arc = Arclength::new(problem, start.x, start.p, start.direction, opts.clone())?;
    let mut points: Vec<T::Point> = vec![];
    let mut events: Vec<T::Event> = vec![];
    // The rate the pair nearest the boundary moved at over the last step kept.
    let mut rate: Option<f64> = None;
    let mut splits = 0;
    while let Some(pt) = arc.next() {
        let mut b = tests.point(arc.problem(), &pt)?;
        if let Some((why, event)) = tests.end(&points, &b) {
            events.extend(event);
            arc.finish(why);
            break;
        }
        let row = points.len();
        let mut found = vec![];
        let mut rate_b = None;
        if let Some(a) = points.last() {
            let (sa, sb) = (tests.spectrum(a), tests.spectrum(&b));
            let same = tests.comparable(a, &b);
            let may_hide = splits < MAX_SPLITS && same;
            if let (Some(sa), Some(sb)) = (sa, sb) {
                rate_b = pair_rate(&sa, &sb, pt.ds);
                if may_hide
                    && pair_may_return(&sa, &sb, rate, pt.ds)
                    && crossed_twice(arc.problem(), tests, a, &b, opts)?
                    && arc.subdivide()
                {
                    splits += 1;
                    continue;
                }
            }
            let (va, vb) = (tests.values(a), tests.values(&b));
            for i in tests.watched(a, &b) {
                let (Some(ga), Some(gb)) = (va[i], vb[i]) else {
                    continue;
                };
                let bracket = Bracket {
                    a: tests.arc(a),
                    b: &pt,
                    ga,
                    gb,
                };
                let g = |pr: &mut P, t: &ArcPoint| tests.value_at(pr, a, t, i);
                let Some((e, ge)) = locate(arc.problem(), bracket, g, within, opts)? else {
                    continue;
                };
                found.extend(tests.event(arc.problem(), i, &e, ge, row)?);
            }
            // Unstable eigenvalues that appear or vanish with no located event to
            // account for them crossed inside the step: it is taken again in halves.
            if let (Some(sa), Some(sb)) = (sa, sb) {
                let moved: usize = found.iter().map(|e| tests.moves(e)).sum();
                if may_hide && !explained(&sa, &sb, moved) && arc.subdivide() {
                    splits += 1;
                    continue;
                }
            }
            tests.settle(a, &mut b, &mut found);
        }
        splits = 0;
        rate = rate_b;
        events.extend(found);
        points.push(b);
    }
    let stop = arc.stop().cloned().unwrap_or(ArcStop::MaxPoints);
    if crate::cancel::cancelled() {
        return Err(Error::Cancelled);
    }
    Ok(Branch {
        points,
        events,
        stop,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `x - p = 0`: the branch `x = p`, tangent `(1, 1) / sqrt 2`.
    struct Diagonal;
    impl Problem for Diagonal {
        fn size(&self) -> usize {
            1
        }
        fn param(&self) -> f64 {
            0.0
        }
        fn residual(&mut self, x: &[f64], p: f64, r: &mut [f64]) -> Result<()> {
            r[0] = x[0] - p;
            Ok(())
        }
        fn jac_x(&mut self, x: &[f64], p: f64, r: &mut [f64], j: &mut [f64]) -> Result<()> {
            self.residual(x, p, r)?;
            j[0] = 1.0;
            Ok(())
        }
        fn jac_p(&mut self, _x: &[f64], _p: f64, out: &mut [f64]) -> Result<()> {
            out[0] = -1.0;
            Ok(())
        }
    }

    /// A complex pair with real part `h^2 - (p - c)^2`: unstable for `p` in
    /// `(c - h, c + h)`, a Hopf point and its return. The test function is that real
    /// part; `counted` says whether the branch reports its spectrum.
    struct Pair {
        c: f64,
        h: f64,
        counted: bool,
    }

    impl Pair {
        fn re(&self, p: f64) -> f64 {
            self.h * self.h - (p - self.c) * (p - self.c)
        }
    }

    impl Declared<Diagonal> for Pair {
        type Point = ArcPoint;
        type Event = f64;
        fn names(&self) -> &'static [&'static str] {
            &["hopf"]
        }
        fn point(&mut self, _: &mut Diagonal, pt: &ArcPoint) -> Result<ArcPoint> {
            Ok(pt.clone())
        }
        fn arc<'p>(&self, point: &'p ArcPoint) -> &'p ArcPoint {
            point
        }
        fn values(&self, point: &ArcPoint) -> Vec<Option<f64>> {
            vec![Some(self.re(point.p))]
        }
        fn spectrum(&self, point: &ArcPoint) -> Option<Spectrum> {
            let pair = self.re(point.p);
            self.counted.then_some(Spectrum {
                unstable: if pair > 0.0 { 2 } else { 0 },
                pair,
            })
        }
        fn value_at(
            &mut self,
            _: &mut Diagonal,
            _: &ArcPoint,
            pt: &ArcPoint,
            _: usize,
        ) -> Result<f64> {
            Ok(self.re(pt.p))
        }
        fn values_at(
            &mut self,
            _: &mut Diagonal,
            _: &ArcPoint,
            pt: &ArcPoint,
        ) -> Result<Vec<Option<f64>>> {
            Ok(vec![Some(self.re(pt.p))])
        }
        fn event(
            &mut self,
            _: &mut Diagonal,
            _: usize,
            e: &ArcPoint,
            _: f64,
            _: usize,
        ) -> Result<Option<f64>> {
            Ok(Some(e.p))
        }
        fn moves(&self, _: &f64) -> usize {
            2
        }
    }

    fn run(pair: &mut Pair) -> Branch<ArcPoint, f64> {
        let opts = ArcOptions {
            p_max: 1.0,
            ..ArcOptions::default()
        };
        let start = Start {
            x: &[0.0],
            p: 0.0,
            direction: None,
        };
        branch(&mut Diagonal, start, &opts, 1e-12, pair).unwrap()
    }

    #[test]
    fn two_zeros_inside_one_default_step_are_both_located() {
        // The pair sits inside the longest step the default options take on this
        // branch, its two zeros half that step apart.
        let far = run(&mut Pair {
            c: 10.0,
            h: 0.0,
            counted: false,
        });
        let (lo, hi) = far
            .points
            .windows(2)
            .map(|w| (w[0].p, w[1].p))
            .max_by(|a, b| (a.1 - a.0).total_cmp(&(b.1 - b.0)))
            .unwrap();
        let (c, h) = (0.5 * (lo + hi), 0.25 * (hi - lo));
        // Without the spectrum the loop has no step control and passes over the pair:
        // the test has the same sign at both ends of that step.
        let blind = run(&mut Pair {
            c,
            h,
            counted: false,
        });
        assert!(blind.events.is_empty(), "{:?}", blind.events);
        let b = run(&mut Pair {
            c,
            h,
            counted: true,
        });
        assert_eq!(b.events.len(), 2, "{:?}", b.events);
        for (e, exact) in b.events.iter().zip([c - h, c + h]) {
            assert!((e - exact).abs() < 1e-9, "event at {e}, expected {exact}");
        }
        assert_eq!(b.stop, ArcStop::Boundary);
    }
}
