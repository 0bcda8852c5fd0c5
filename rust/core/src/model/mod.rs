//! The model layer: what the equations of motion are, never how they are solved.
//!
//! [`Dynamics`] is the one interface the solvers see. [`Planar`] is the planar
//! balancer fused for speed; [`Scene`] adds the physical effects a user switches on.

pub mod bearing;
mod dynamics;
pub mod planar;
pub mod scene;
#[rustfmt::skip]
pub mod tilt_terms;

pub use dynamics::{first_order_rhs, Dynamics};
pub use planar::Planar;
pub use scene::{Scene, SpringLayout};
