//! Where each coordinate lives in `q`: the one statement of the coordinate conventions
//! that solvers and analyses used to assume (coordinate 0 is `x`, the support is
//! coordinates 0 and 1, balls start at 2 or, with a tilting disk, at 4).

use std::ops::Range;

/// The coordinate layout of a model: `q = (x, y, [A, B,] b_1, ..., b_n)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// Index of the rotor's translation `x` (the disk centre, rotating frame).
    pub x: usize,
    /// Index of the rotor's translation `y`.
    pub y: usize,
    /// Indices of the disk's tilts `(A, B)`, when it tilts.
    pub tilt: Option<(usize, usize)>,
    /// Index of the first ball angle; the balls are contiguous from it.
    pub first_ball: usize,
    pub n_balls: usize,
}

impl Layout {
    /// `(x, y, b_1, ..., b_n)`.
    pub const fn planar(n_balls: usize) -> Self {
        Layout {
            x: 0,
            y: 1,
            tilt: None,
            first_ball: 2,
            n_balls,
        }
    }

    /// `(x, y, A, B, b_1, ..., b_n)`.
    pub const fn tilting(n_balls: usize) -> Self {
        Layout {
            x: 0,
            y: 1,
            tilt: Some((2, 3)),
            first_ball: 4,
            n_balls,
        }
    }

    pub const fn ndof(&self) -> usize {
        self.first_ball + self.n_balls
    }

    /// Index of ball `i`'s angle.
    #[inline(always)]
    pub const fn ball(&self, i: usize) -> usize {
        self.first_ball + i
    }

    pub const fn balls(&self) -> Range<usize> {
        self.first_ball..self.first_ball + self.n_balls
    }

    /// The coordinates of the support's motion (what tail ratios and orbit keys measure).
    pub const fn support(&self) -> [usize; 2] {
        [self.x, self.y]
    }

    /// The rotor's coordinates, every one before the first ball.
    pub const fn rotor(&self) -> Range<usize> {
        0..self.first_ball
    }

    /// Coordinate names in order: `x`, `y`, `A`, `B`, `b1`, ..., `bn`.
    pub fn names(&self) -> Vec<String> {
        let mut out = vec![String::new(); self.ndof()];
        out[self.x] = "x".into();
        out[self.y] = "y".into();
        if let Some((a, b)) = self.tilt {
            out[a] = "A".into();
            out[b] = "B".into();
        }
        for i in 0..self.n_balls {
            out[self.ball(i)] = format!("b{}", i + 1);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_follow_the_indices() {
        assert_eq!(Layout::planar(2).names(), ["x", "y", "b1", "b2"]);
        let t = Layout::tilting(3);
        assert_eq!(t.names(), ["x", "y", "A", "B", "b1", "b2", "b3"]);
        assert_eq!((t.ndof(), t.ball(2), t.balls()), (7, 6, 4..7));
    }
}
