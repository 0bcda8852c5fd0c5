//! Numerical methods, generic over [`crate::model::Dynamics`]: the integrator, small
//! dense linear algebra, harmonic balance and Floquet multipliers. Nothing here knows
//! a concrete model.

pub mod blocked_lu;
pub mod collocation;
pub mod floquet;
pub mod hb;
pub mod linalg;
pub mod magnus;
pub mod ode;
pub mod problem;
pub mod rosenbrock;
