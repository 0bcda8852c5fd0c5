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
//!
//! What a user asks of a branch besides its window ([`Controls`], AUTO's `UZ` and stop
//! conditions) is done here too, once for every kind of branch: a point solved exactly
//! at each requested parameter value a step crosses (an event, the rows unchanged), and
//! an end at the first event of a requested kind or where an unknown reaches a value
//! (the last row solved there).

use super::arclength::{
    component, locate, point_at, point_on_level, ArcOptions, ArcPoint, ArcStop, Arclength, Bracket,
    Within,
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

/// Most parameter values one branch may be asked for ([`Controls::at`]): each costs a
/// solve and an event wherever the branch crosses it.
pub const MAX_USER_POINTS: usize = 1000;

/// A value of one component of `y = (x, p)` (`index` = the unknowns' count: the
/// parameter) at which a branch ends; `why` is the stop reason it records.
#[derive(Debug, Clone, PartialEq)]
pub struct Level {
    pub index: usize,
    pub value: f64,
    pub why: &'static str,
}

/// What a user asks of a branch besides its parameter window (which already ends it at
/// a value, with a point on the edge): AUTO's user points (`UZ`) and stop conditions.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Controls {
    /// Parameter values where the branch gets a point solved with the parameter fixed
    /// at the value, each time a step crosses it or ends on it (not at the start),
    /// offered to the branch as an event ([`Declared::user`]); the rows are those of the
    /// branch without them. (Where Newton with the parameter fixed fails, exactly on a
    /// fold, there is no point.)
    pub at: Vec<f64>,
    /// The branch ends at the first event whose [`Declared::kind`] is one of these, its
    /// last row the event's point, the stop reason the kind.
    pub stop_events: Vec<&'static str>,
    /// The branch ends where this component reaches its value, its last row solved
    /// with the component fixed there.
    pub stop_level: Option<Level>,
}

impl Controls {
    /// `Err` naming `at` unless it holds at most [`MAX_USER_POINTS`] values, each inside
    /// the parameter window `[p_min, p_max]` (so finite).
    pub fn validate(&self, p_min: f64, p_max: f64) -> Result<()> {
        if self.at.len() > MAX_USER_POINTS {
            return Err(Error::param_range(
                "at",
                format!("holds {} values", self.at.len()),
                format!("at most {MAX_USER_POINTS} values"),
            ));
        }
        if let Some(v) = self.at.iter().find(|v| !(p_min..=p_max).contains(*v)) {
            return Err(Error::param_range(
                "at",
                format!("value {v} is outside the branch's range"),
                format!("values in [{p_min}, {p_max}]"),
            ));
        }
        if let Some(l) = &self.stop_level {
            if !l.value.is_finite() {
                return Err(Error::param(
                    l.why,
                    format!("must be finite, got {}", l.value),
                ));
            }
        }
        Ok(())
    }
}

/// Whether a step from `ya` to `yb` crosses `v` or ends on it.
fn crosses(ya: f64, yb: f64, v: f64) -> bool {
    yb == v || (ya - v) * (yb - v) < 0.0
}

/// The point of a step from `a` to `b` that [`crosses`] `value` in component `k` where
/// that component is `value`: located along the step (to a hundred-millionth of the
/// value's scale, a close guess) and then solved on the level ([`point_on_level`]).
fn level_point<P: Problem + ?Sized>(
    problem: &mut P,
    a: &ArcPoint,
    b: &ArcPoint,
    k: usize,
    value: f64,
    opts: &ArcOptions,
) -> Result<Option<ArcPoint>> {
    let gap = |pt: &ArcPoint| component(pt, k) - value;
    let near = if gap(b) == 0.0 {
        b.clone()
    } else {
        let bracket = Bracket {
            a,
            b,
            ga: gap(a),
            gb: gap(b),
        };
        let within = Within {
            s: 0.0,
            g: 1e-8 * value.abs().max(1.0),
        };
        match locate(problem, bracket, |_, pt| Ok(gap(pt)), within, opts)? {
            Some((pt, _)) => pt,
            None => return Ok(None),
        }
    };
    point_on_level(problem, &near, k, value, opts)
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
    /// The event's name, as [`Controls::stop_events`] lists it.
    fn kind(&self, event: &Self::Event) -> &'static str;
    /// The event of a user point `pt` (solved at a value of [`Controls::at`]; `row` the
    /// index of the first row past it), or `None` when the branch reports none.
    fn user(
        &mut self,
        _problem: &mut P,
        _pt: &ArcPoint,
        _row: usize,
    ) -> Result<Option<Self::Event>> {
        Ok(None)
    }
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
/// that may hide events (see the module's notes), with the user points and stop
/// conditions of `controls`. The rows are empty when not even the start converges (the
/// caller says what it would have started from).
pub fn branch<P, T>(
    problem: &mut P,
    start: Start<'_>,
    opts: &ArcOptions,
    locate_tol: f64,
    controls: &Controls,
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
    controls.validate(opts.p_min, opts.p_max)?;
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
        // Each event with the point it was located at (for the stop conditions).
        let mut found: Vec<(ArcPoint, T::Event)> = vec![];
        let mut stopping = None;
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
                if let Some(event) = tests.event(arc.problem(), i, &e, ge, row)? {
                    found.push((e, event));
                }
            }
            // Unstable eigenvalues that appear or vanish with no located event to
            // account for them crossed inside the step: it is taken again in halves.
            if let (Some(sa), Some(sb)) = (sa, sb) {
                let moved: usize = found.iter().map(|(_, e)| tests.moves(e)).sum();
                if may_hide && !explained(&sa, &sb, moved) && arc.subdivide() {
                    splits += 1;
                    continue;
                }
            }
            let pa = tests.arc(a).clone();
            let n = pa.x.len();
            for &v in &controls.at {
                if crosses(pa.p, pt.p, v) {
                    if let Some(u) = level_point(arc.problem(), &pa, &pt, n, v, opts)? {
                        if let Some(event) = tests.user(arc.problem(), &u, row)? {
                            found.push((u, event));
                        }
                    }
                }
            }
            // The first stop the step meets ends the branch: its point is the last row,
            // and what lies past it on the step is dropped.
            let mut end: Option<(ArcPoint, &'static str)> = None;
            let earlier = |e: &ArcPoint, end: &Option<(ArcPoint, &str)>| {
                end.as_ref().is_none_or(|s| e.ds.abs() < s.0.ds.abs())
            };
            for (e, event) in &found {
                let kind = tests.kind(event);
                if controls.stop_events.contains(&kind) && earlier(e, &end) {
                    end = Some((e.clone(), kind));
                }
            }
            if let Some(l) = &controls.stop_level {
                if crosses(component(&pa, l.index), component(&pt, l.index), l.value) {
                    let e = level_point(arc.problem(), &pa, &pt, l.index, l.value, opts)?;
                    if let Some(e) = e.filter(|e| earlier(e, &end)) {
                        end = Some((e, l.why));
                    }
                }
            }
            if let Some((e, why)) = end {
                found.retain(|(f, _)| f.ds.abs() <= e.ds.abs());
                b = tests.point(arc.problem(), &e)?;
                stopping = Some(why);
            }
            let mut settled: Vec<T::Event> = found.into_iter().map(|(_, e)| e).collect();
            tests.settle(a, &mut b, &mut settled);
            events.extend(settled);
        }
        splits = 0;
        rate = rate_b;
        points.push(b);
        crate::cancel::advance();
        if let Some(why) = stopping {
            arc.finish(why);
            break;
        }
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
        fn kind(&self, _: &f64) -> &'static str {
            "hopf"
        }
    }

    /// A branch of `x = p` that reports a zero of `p - c` as a "hopf" event and user
    /// points as "user" events, each event its kind and point.
    struct Marks {
        c: f64,
    }

    impl Declared<Diagonal> for Marks {
        type Point = ArcPoint;
        type Event = (&'static str, ArcPoint);
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
            vec![Some(point.p - self.c)]
        }
        fn value_at(
            &mut self,
            _: &mut Diagonal,
            _: &ArcPoint,
            pt: &ArcPoint,
            _: usize,
        ) -> Result<f64> {
            Ok(pt.p - self.c)
        }
        fn values_at(
            &mut self,
            _: &mut Diagonal,
            _: &ArcPoint,
            pt: &ArcPoint,
        ) -> Result<Vec<Option<f64>>> {
            Ok(vec![Some(pt.p - self.c)])
        }
        fn event(
            &mut self,
            _: &mut Diagonal,
            _: usize,
            e: &ArcPoint,
            _: f64,
            _: usize,
        ) -> Result<Option<Self::Event>> {
            Ok(Some(("hopf", e.clone())))
        }
        fn moves(&self, _: &Self::Event) -> usize {
            0
        }
        fn kind(&self, e: &Self::Event) -> &'static str {
            e.0
        }
        fn user(
            &mut self,
            _: &mut Diagonal,
            pt: &ArcPoint,
            _: usize,
        ) -> Result<Option<Self::Event>> {
            Ok(Some(("user", pt.clone())))
        }
    }

    fn marked(controls: &Controls, p_max: f64) -> Branch<ArcPoint, (&'static str, ArcPoint)> {
        let opts = ArcOptions {
            p_max,
            ..ArcOptions::default()
        };
        let start = Start {
            x: &[0.0],
            p: 0.0,
            direction: None,
        };
        branch(
            &mut Diagonal,
            start,
            &opts,
            1e-12,
            controls,
            &mut Marks { c: 0.5 },
        )
        .unwrap()
    }

    #[test]
    fn user_points_are_solved_at_their_values_and_leave_the_rows_alone() {
        let plain = marked(&Controls::default(), 1.0);
        let at = [0.123456789, 0.5, 0.77, 1.0];
        let c = Controls {
            at: at.to_vec(),
            ..Default::default()
        };
        let b = marked(&c, 1.0);
        assert_eq!(b.points.len(), plain.points.len());
        for (u, v) in b.points.iter().zip(&plain.points) {
            assert!((u.p - v.p).abs() < 1e-14 && (u.x[0] - v.x[0]).abs() < 1e-14);
        }
        let users: Vec<&ArcPoint> = b
            .events
            .iter()
            .filter(|e| e.0 == "user")
            .map(|e| &e.1)
            .collect();
        assert_eq!(users.len(), at.len(), "{:?}", b.events);
        for (u, v) in users.iter().zip(at) {
            // on the value asked for, and a solution there (x = p)
            assert_eq!(u.p, v);
            assert!((u.x[0] - v).abs() < 1e-12, "{} at {v}", u.x[0]);
        }
        assert_eq!(b.stop, ArcStop::Boundary);
    }

    #[test]
    fn a_branch_stops_at_its_first_stop_event_or_level() {
        let c = Controls {
            at: vec![0.3, 0.9],
            stop_events: vec!["hopf"],
            ..Default::default()
        };
        let b = marked(&c, 1.0);
        assert_eq!(b.stop, ArcStop::Finished("hopf".into()));
        let last = b.points.last().unwrap();
        assert!((last.p - 0.5).abs() < 1e-9, "{}", last.p);
        // the user point before the stop is kept, the one past it never reached
        let kinds: Vec<&str> = b.events.iter().map(|e| e.0).collect();
        assert_eq!(kinds, ["user", "hopf"]);
        // stopping at the first user point: the last row is on its value
        let c = Controls {
            at: vec![0.3, 0.9],
            stop_events: vec!["user"],
            ..Default::default()
        };
        let b = marked(&c, 1.0);
        assert_eq!(b.points.last().unwrap().p, 0.3);
        assert_eq!(b.stop, ArcStop::Finished("user".into()));
        // a level of the unknown x: the last row has x = 0.7 exactly, p = x
        let c = Controls {
            stop_level: Some(Level {
                index: 0,
                value: 0.7,
                why: "level",
            }),
            ..Default::default()
        };
        let b = marked(&c, 1.0);
        let last = b.points.last().unwrap();
        assert_eq!(last.x[0], 0.7);
        assert!((last.p - 0.7).abs() < 1e-12);
        assert_eq!(b.stop, ArcStop::Finished("level".into()));
        assert_eq!(b.events.len(), 1);
    }

    #[test]
    fn bad_user_points_name_at() {
        for at in [vec![f64::NAN], vec![2.0], vec![0.5; MAX_USER_POINTS + 1]] {
            let c = Controls {
                at,
                ..Default::default()
            };
            let start = Start {
                x: &[0.0],
                p: 0.0,
                direction: None,
            };
            let opts = ArcOptions {
                p_max: 1.0,
                ..ArcOptions::default()
            };
            let e = branch(
                &mut Diagonal,
                start,
                &opts,
                1e-12,
                &c,
                &mut Marks { c: 0.5 },
            )
            .err()
            .unwrap();
            assert!(
                matches!(e, Error::InvalidParameter { ref name, .. } if name == "at"),
                "{e:?}"
            );
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
        branch(
            &mut Diagonal,
            start,
            &opts,
            1e-12,
            &Controls::default(),
            pair,
        )
        .unwrap()
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
