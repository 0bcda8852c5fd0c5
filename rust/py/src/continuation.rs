//! Continuation options: `ballbal._branch.Continuation` into the core's `ArcOptions`
//! (the values are checked by `ArcOptions::validate`, once, in the core).

use crate::errors::CoreResult;
use ballbal_core::bifurcation::event::Event;
use ballbal_core::continuation::{ArcOptions, Controls};
use ballbal_core::Result;
use pyo3::prelude::*;

/// `ballbal._branch.Continuation`'s fields.
#[derive(FromPyObject)]
pub struct ContinuationArgs {
    ds: f64,
    ds_min: f64,
    ds_max: f64,
    max_points: usize,
    tol: f64,
    max_newton: usize,
    grow: f64,
    min_cos: f64,
    forward: bool,
}

impl ContinuationArgs {
    /// The core options over the parameter window `p_range` (weights: all one).
    pub fn options(&self, p_range: (f64, f64)) -> ArcOptions {
        ArcOptions {
            ds: self.ds,
            ds_min: self.ds_min,
            ds_max: self.ds_max,
            max_points: self.max_points,
            p_min: p_range.0,
            p_max: p_range.1,
            tol: self.tol,
            max_newton: self.max_newton,
            grow: self.grow,
            min_cos: self.min_cos,
            forward: self.forward,
            weights: None,
        }
    }
}

/// A branch's user points and the events it stops at (`at=`, `stop=`: names or aliases
/// `Event::parse` reads), as the core takes them (it checks them against the branch).
pub fn controls(at: Option<Vec<f64>>, stop: Option<Vec<String>>) -> PyResult<Controls> {
    let stop_events = stop
        .unwrap_or_default()
        .iter()
        .map(|k| Event::parse(k, "stop").map(|e| e.name()))
        .collect::<Result<Vec<_>>>()
        .py()?;
    Ok(Controls {
        at: at.unwrap_or_default(),
        stop_events,
        stop_level: None,
    })
}
