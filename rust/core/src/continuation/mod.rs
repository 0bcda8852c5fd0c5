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
//! [`curves`] presents a two-parameter curve of a test function's zeros as such a
//! problem.
//!
//! This is the generic engine: it knows no model, no analysis and no bifurcation. It
//! imports nothing from the crate's analysis, bifurcation, scan or model modules (the
//! test `engine_imports_no_higher_layer` below holds it to that); the bifurcation layer
//! and the scans build on it, never the other way.

pub mod arclength;
pub mod branch;
pub mod curves;
pub mod lattice;
pub mod natural;

pub use arclength::{
    component, locate, point_at, point_on_level, ArcOptions, ArcPoint, ArcStop, Arclength, Bracket,
    Within,
};
pub use branch::{branch, Branch, Controls, Declared, Level, Spectrum, Start, MAX_USER_POINTS};
pub use curves::{
    both_halves, curve_half, CurveHalf, CurveHook, Extended, TestFunction, TwoParameter,
};
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

#[cfg(test)]
mod tests {
    /// The engine's sources, read at compile time so that the layer rule is checked on
    /// what is built.
    const SOURCES: [(&str, &str); 6] = [
        ("mod.rs", include_str!("mod.rs")),
        ("arclength.rs", include_str!("arclength.rs")),
        ("curves.rs", include_str!("curves.rs")),
        ("lattice.rs", include_str!("lattice.rs")),
        ("natural.rs", include_str!("natural.rs")),
        ("branch.rs", include_str!("branch.rs")),
    ];

    #[test]
    fn engine_imports_no_higher_layer() {
        let higher = ["analysis", "bifurcation", "scan", "model"];
        for (file, text) in SOURCES {
            // Whatever follows a path from the crate's root on a line (`a::b`, a
            // `{a, b}` group) is what that line reaches into.
            for (row, line) in text.lines().enumerate() {
                for (at, _) in line.match_indices("crate::") {
                    let path: String = line[at + 7..]
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || "_:{}, ".contains(*c))
                        .collect();
                    let reached = path
                        .split(|c: char| !(c.is_alphanumeric() || c == '_'))
                        .filter(|w| !w.is_empty());
                    for word in reached {
                        assert!(
                            !higher.contains(&word),
                            "continuation/{file}:{} reaches into `{word}`: the engine must not \
                             know a higher layer",
                            row + 1
                        );
                    }
                }
            }
        }
    }
}
