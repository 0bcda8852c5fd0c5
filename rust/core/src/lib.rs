//! ballbal-core: nonlinear dynamics of automatic ball balancers.
//!
//! The pure-Rust engine behind the `ballbal` Python package. Layers depend one way:
//!
//! * [`model`]: the equations of motion ([`Dynamics`]), the planar balancer and scenes;
//! * [`numerics`]: integrator, linear algebra, harmonic balance, Floquet multipliers;
//! * [`analysis`]: simulation, attractors, equilibria, periodic solutions and their
//!   certificates;
//! * [`continuation`]: the generic engine that follows solutions through parameter
//!   space, over a corrector (the problems of [`numerics::problem`]); it knows no model;
//! * [`bifurcation`]: branches of equilibria and periodic solutions with their events,
//!   branch switching and two-parameter curves, on that engine;
//! * [`scan`]: parallel parameter scans;
//! * [`error`] and [`cancel`]: what every layer shares.

// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod analysis;
pub mod bifurcation;
pub mod cancel;
pub mod continuation;
pub mod error;
pub mod model;
pub mod numerics;
pub mod scan;

// Short paths for the modules every layer uses.
pub use analysis::{equilibria, periodic, simulate};
pub use numerics::{floquet, hb, linalg, ode};

pub use error::{Error, Result};
pub use model::{Dynamics, Planar, Scene, SpringLayout};
