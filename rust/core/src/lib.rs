//! ballbal-core: nonlinear dynamics of automatic ball balancers.
//!
//! The pure-Rust engine behind the `ballbal` Python package: the planar n-ball
//! balancer model, an adaptive Dormand–Prince integrator, equilibria with
//! eigenvalue and Routh–Hurwitz stability, periodic solutions by modified
//! incremental harmonic balance, Floquet multipliers and parallel scans.

// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod cancel;
pub mod equilibria;
pub mod error;
pub mod floquet;
pub mod hb;
pub mod linalg;
pub mod model;
pub mod ode;
pub mod periodic;
pub mod scan;
pub mod scene;
pub mod simulate;
#[rustfmt::skip]
pub mod tilt_terms;

pub use error::{Error, Result};
pub use model::{Dynamics, Planar};
pub use scene::{Scene, SpringLayout};
