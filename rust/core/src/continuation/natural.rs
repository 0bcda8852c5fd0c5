//! Natural-parameter continuation: the parameter takes given values one after another,
//! and each solve starts from the secant prediction through the last two solutions, then
//! (if that fails) from the last solution itself.

use super::{BranchPoint, Corrector, Secant};

/// The outcome of one continuation step.
#[derive(Debug, Clone)]
pub struct Step<P> {
    pub point: Option<P>,
    /// Corrector calls made (one per guess tried).
    pub attempts: usize,
}

/// Continues `current` to `at`: first from the secant prediction when `previous` (the
/// solution one step before `current`, on the far side from `at`) is known, then from
/// `current` itself.
pub fn natural_step<C: Corrector>(
    c: &C,
    at: &C::At,
    current: &C::Point,
    previous: Option<&C::Point>,
) -> Step<C::Point> {
    let secant = previous.map(|b| current.secant(b));
    let mut attempts = 0;
    for guess in secant.iter().chain(std::iter::once(current)) {
        attempts += 1;
        if let Some(p) = c.correct(at, guess, current) {
            return Step {
                point: Some(p),
                attempts,
            };
        }
    }
    Step {
        point: None,
        attempts,
    }
}

/// Natural-parameter continuation along a sequence of parameter points from a solution
/// at the point before the first: yields each corrected point, and ends after the first
/// step that fails (yielded with `point: None` so that its attempts are counted) or at
/// the end of the sequence.
pub struct Natural<'c, C: Corrector, I> {
    corrector: &'c C,
    ats: I,
    current: Option<C::Point>,
    previous: Option<C::Point>,
}

impl<'c, C: Corrector, I> Natural<'c, C, I> {
    pub fn new(corrector: &'c C, start: C::Point, ats: I) -> Self {
        Natural {
            corrector,
            ats,
            current: Some(start),
            previous: None,
        }
    }
}

impl<C, I> Iterator for Natural<'_, C, I>
where
    C: Corrector,
    C::At: Sized + Clone,
    I: Iterator<Item = C::At>,
{
    type Item = BranchPoint<C::At, Option<C::Point>>;

    fn next(&mut self) -> Option<Self::Item> {
        let current = self.current.take()?;
        let at = self.ats.next()?;
        let step = natural_step(self.corrector, &at, &current, self.previous.as_ref());
        if let Some(p) = &step.point {
            self.previous = Some(current);
            self.current = Some(p.clone());
        }
        Some(BranchPoint {
            at,
            point: step.point,
            attempts: step.attempts,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The root of x^3 + x - p near a guess, by Newton from the guess: a branch with
    /// the closed-form inverse p = x^3 + x.
    struct Cubic;
    impl Secant for f64 {
        fn secant(&self, previous: &Self) -> Self {
            2.0 * self - previous
        }
    }
    impl Corrector for Cubic {
        type At = f64;
        type Point = f64;
        fn correct(&self, p: &f64, guess: &f64, _from: &f64) -> Option<f64> {
            let mut x = *guess;
            // Few iterations, so that only a good guess converges.
            for _ in 0..3 {
                x -= (x * x * x + x - p) / (3.0 * x * x + 1.0);
            }
            ((x * x * x + x - p).abs() < 1e-12).then_some(x)
        }
    }

    #[test]
    fn follows_the_branch_and_the_secant_saves_attempts() {
        let ps: Vec<f64> = (1..=20).map(|i| 2.0 + 0.05 * i as f64).collect();
        let pts: Vec<_> = Natural::new(&Cubic, 1.0, ps.iter().copied()).collect();
        assert_eq!(pts.len(), 20);
        for b in &pts {
            let x = b.point.expect("converged");
            assert!((x * x * x + x - b.at).abs() < 1e-12);
        }
        // The first step has no secant; later ones converge from it at the first try.
        assert_eq!(pts[0].attempts, 1);
        assert!(pts[2..].iter().all(|b| b.attempts == 1));
    }

    #[test]
    fn ends_after_the_first_failed_step() {
        // A jump far along the branch: neither guess converges in three iterations.
        let ps = [2.05, 2.1, 500.0, 2.2];
        let pts: Vec<_> = Natural::new(&Cubic, 1.0, ps.iter().copied()).collect();
        assert_eq!(pts.len(), 3);
        assert!(pts[2].point.is_none());
        assert_eq!(pts[2].attempts, 2);
    }
}
