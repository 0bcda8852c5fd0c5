//! Continuation of solution branches through parameter space, generic over what is
//! continued: the solvers plug in through [`Corrector`] (solve at a parameter point from
//! a guess) and [`Secant`] (extrapolate a branch from its last two points).
//!
//! A strategy is an iterator of [`BranchPoint`]s. [`natural`] steps the parameter along
//! a given sequence of values (secant predictor, the last solution as fallback);
//! [`lattice`] runs the same step to the neighbours of every solution on a grid, wave
//! after wave, as the scans do. [`arclength`] (pseudo-arclength continuation) steps
//! along the branch and lets the parameter follow, through folds; it works over the
//! [`crate::numerics::problem::Problem`] trait (`jac_x`, `jac_p` give its tangent).

pub mod arclength;
pub mod curves;
pub mod equilibria;
pub mod event;
pub mod lattice;
pub mod natural;

pub use arclength::{locate, point_at, ArcOptions, ArcPoint, ArcStop, Arclength};
pub use curves::{Extended, TestFunction, TwoParameter};
pub use event::Event;
pub use lattice::{waves, Lattice, Tally, Waves};
pub use natural::{natural_step, Natural, Step};

/// A solution that a predictor can extrapolate from its branch's last two points.
pub trait Secant: Clone {
    /// The secant prediction one step beyond `self`, `previous` being one step before.
    fn secant(&self, previous: &Self) -> Self;
}

/// Solves the problem at a parameter point from a guess.
pub trait Corrector: Sync {
    /// Where a solution lives: a parameter value, or a grid point's index.
    type At: ?Sized;
    type Point: Secant + Send + Sync;
    /// The corrected solution at `at` from `guess`, or `None` when the solve fails or
    /// its result is refused; `from` is the solution the guess was predicted from
    /// (e.g. to check that the solution is of the same kind).
    fn correct(
        &self,
        at: &Self::At,
        guess: &Self::Point,
        from: &Self::Point,
    ) -> Option<Self::Point>;
}

/// One point of a branch, as a continuation strategy yields it.
#[derive(Debug, Clone)]
pub struct BranchPoint<A, P> {
    pub at: A,
    pub point: P,
    /// Corrector calls spent on this point (failed predictions included).
    pub attempts: usize,
}
