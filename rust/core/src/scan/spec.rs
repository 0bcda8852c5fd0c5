//! What a scan is asked for: the grid, the solution types, the numerical options; its
//! validation and its cut into chunks and blocks.

use super::Family;
use crate::error::{Error, Result};
use crate::periodic::{initial_states, require_autonomous, PeriodicOptions};
use std::ops::Range;

/// Most turns per period a scan type's windings may share ([`crate::periodic::repetitions`]).
pub const MAX_SCAN_TURNS: usize = 2;

#[derive(Debug, Clone)]
pub struct ScanSpec<'a, D: Family> {
    pub base: &'a D,
    pub names: Vec<String>,
    pub values: Vec<Vec<f64>>,
    /// The balls' windings per requested solution type
    /// ([`crate::periodic::parse_solution_type`]): `-1` per rotating and 0 per
    /// oscillating ball for a plain pattern, more turns for an orbit that winds more
    /// than once per period (`[-2, -2]`: the period-doubled R-R orbit).
    pub patterns: Vec<Vec<f64>>,
    pub opts: PeriodicOptions,
    /// Seed points per parameter over the whole grid (their spacing in grid steps is
    /// `ceil(len / seeds)`); every chunk gets at least one seed line.
    pub seeds: usize,
    /// Simulated initial states per seed point.
    pub starts: usize,
    /// Values of the last parameter per continuation block (seeding and continuation
    /// stay inside a block, so this is a numerical option; see [`default_chunk`]).
    pub block: usize,
    /// Values of the last parameter per chunk, rounded up to whole blocks: the unit of
    /// progress and resumption only; the rows do not depend on it.
    pub chunk: usize,
    pub threads: usize,
    /// Largest accepted [`crate::hb::HbSolution::tail_ratio`]; a solution above it is not resolved
    /// by `N` harmonics and is neither reported nor continued.
    pub max_tail: f64,
}

impl<D: Family> ScanSpec<'_, D> {
    /// Checks every value and option before any work starts.
    pub fn validate(&self) -> Result<()> {
        require_autonomous(self.base)?;
        if self.names.is_empty() || self.names.len() != self.values.len() {
            return Err(Error::param(
                "grid",
                "give at least one parameter with its values",
            ));
        }
        for (k, vals) in self.values.iter().enumerate() {
            let name = &self.names[k];
            if self.names[..k].contains(name) {
                return Err(Error::param(name.as_str(), "is scanned twice"));
            }
            if vals.is_empty() {
                return Err(Error::param(name.as_str(), "the grid is empty"));
            }
            for &v in vals {
                // a value can switch an effect on (grooves cut into a bearing's sleeve)
                require_autonomous(&self.base.with_param(name, v)?)?;
            }
        }
        // Every combination must be valid, not just every value (e.g. ball masses).
        for k in 0..self.values.len() {
            let mut p = self.base.clone();
            for (j, vals) in self.values.iter().enumerate() {
                if j != k {
                    p = p.with_param(&self.names[j], vals[0])?;
                }
            }
            for &v in &self.values[k] {
                p.with_param(&self.names[k], v)?;
            }
        }
        if self.patterns.is_empty() {
            return Err(Error::param("patterns", "give at least one solution type"));
        }
        // Seeds watch six turns, enough to tell orbits of one and two turns per period
        // apart; three would need a longer watch for every seed, which would change
        // the guesses, and so the rows, of the other types.
        if let Some(w) = self
            .patterns
            .iter()
            .find(|w| crate::periodic::repetitions(w) > MAX_SCAN_TURNS)
        {
            return Err(Error::param_range(
                "patterns",
                format!(
                    "a scan type may repeat at most {MAX_SCAN_TURNS} turns per period, got windings [{}] (periodic() takes any)",
                    w.iter().map(|x| (*x as i64).to_string()).collect::<Vec<_>>().join(",")
                ),
                format!("windings whose common divisor is at most {MAX_SCAN_TURNS}"),
            ));
        }
        for (name, v, lo) in [
            ("threads", self.threads, 1),
            ("seeds", self.seeds, 1),
            ("starts", self.starts, 1),
            ("chunk", self.chunk, 1),
            ("block", self.block, 1),
        ] {
            if v < lo {
                return Err(Error::param(name, format!("must be >= {lo}, got {v}")));
            }
        }
        if !(self.max_tail > 0.0) {
            return Err(Error::param(
                "max_tail",
                format!("must be a number > 0, got {}", self.max_tail),
            ));
        }
        let available = initial_states(self.base).len();
        if self.starts > available {
            return Err(Error::param(
                "starts",
                format!("must be in [1, {available}], got {}", self.starts),
            ));
        }
        Ok(())
    }

    /// The harmonic balance's settings for a type with the balls' windings `winding`:
    /// `opts.hb`'s harmonics (and samples, where set) per turn of an orbit that winds
    /// several times per period ([`crate::periodic::repetitions`]), so that a
    /// period-doubled orbit is as resolved as the single one.
    pub fn hb_for(&self, winding: &[f64]) -> crate::hb::HbOptions {
        let m = crate::periodic::repetitions(winding);
        crate::hb::HbOptions {
            n_harm: self.opts.hb.n_harm * m,
            samples: self.opts.hb.samples.map(|s| s * m),
            ..self.opts.hb.clone()
        }
    }

    /// Chunk length actually used: `chunk` rounded up to whole blocks, so that no block
    /// is ever split between chunks (a split block would continue less).
    pub fn chunk_len(&self) -> usize {
        let b = self.block.max(1);
        self.chunk.max(1).div_ceil(b) * b
    }

    /// Chunk bounds along the last parameter.
    pub fn chunks(&self) -> Vec<Range<usize>> {
        let n = self.values.last().map_or(0, |v| v.len());
        let len = self.chunk_len();
        (0..n).step_by(len).map(|a| a..(a + len).min(n)).collect()
    }

    /// Block bounds inside a chunk (chunks start on block edges).
    pub(super) fn blocks(&self, chunk: &Range<usize>) -> Vec<Range<usize>> {
        let b = self.block.max(1);
        chunk
            .clone()
            .step_by(b)
            .map(|a| a..(a + b).min(chunk.end))
            .collect()
    }
}

/// Default block (and chunk) length: about 1024 grid points, so that a block is long
/// enough for continuation and seeds to pay off and short enough to report progress and
/// lose little on interruption. It depends on the grid's shape only.
pub fn default_chunk(lens: &[usize]) -> usize {
    let inner: usize = lens[..lens.len().saturating_sub(1)].iter().product();
    let outer = lens.last().copied().unwrap_or(1);
    1024usize.div_ceil(inner.max(1)).clamp(1, outer.max(1))
}
