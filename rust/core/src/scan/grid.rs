//! A block's grid of parameter points: indices, strides and neighbours.

use super::Family;
use super::ScanSpec;
use crate::continuation::Lattice;
use std::ops::Range;

/// Chunk-local grid geometry: sizes, strides, neighbours.
pub(super) struct Local {
    lens: Vec<usize>,
    strides: Vec<usize>,
    outer0: usize,
}

impl Local {
    pub(super) fn new<D: Family>(spec: &ScanSpec<'_, D>, range: &Range<usize>) -> Self {
        let mut lens: Vec<usize> = spec.values.iter().map(|v| v.len()).collect();
        *lens.last_mut().unwrap() = range.len();
        let mut strides = vec![1; lens.len()];
        for k in 1..lens.len() {
            strides[k] = strides[k - 1] * lens[k - 1];
        }
        Local {
            lens,
            strides,
            outer0: range.start,
        }
    }
    pub(super) fn index(&self, p: usize) -> Vec<usize> {
        let mut idx: Vec<usize> = (0..self.lens.len())
            .map(|k| (p / self.strides[k]) % self.lens[k])
            .collect();
        *idx.last_mut().unwrap() += self.outer0;
        idx
    }
}

impl Lattice for Local {
    fn size(&self) -> usize {
        self.lens.iter().product()
    }
    /// Neighbours of `p` as (neighbour, the point on the far side of `p` from it).
    fn neighbours(&self, p: usize) -> Vec<(usize, Option<usize>)> {
        let mut out = vec![];
        for k in 0..self.lens.len() {
            let i = (p / self.strides[k]) % self.lens[k];
            let s = self.strides[k];
            if i > 0 {
                out.push((p - s, (i + 1 < self.lens[k]).then(|| p + s)));
            }
            if i + 1 < self.lens[k] {
                out.push((p + s, (i > 0).then(|| p - s)));
            }
        }
        out.sort_unstable();
        out
    }
}
