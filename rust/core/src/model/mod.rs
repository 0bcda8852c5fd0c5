//! The model layer: what the equations of motion are, never how they are solved.
//!
//! [`Dynamics`] is the one interface the solvers see, with the coordinate [`Layout`]
//! it declares. Models are assembled from [`component`]s ([`components`] holds the
//! rotor, support, balls, drive and loads); [`params`] is the one registry of their
//! parameters. [`Planar`] is the planar balancer fused for speed (every analysis of a
//! scene without effects runs it); [`Scene`] assembles the components a user switches on.

pub mod assembly;
pub mod bearing;
pub mod component;
pub mod components;
pub mod disk_units;
mod dynamics;
pub mod layout;
pub mod params;
pub mod planar;
pub mod scene;
#[rustfmt::skip]
pub mod tilt_terms;

pub use component::{Component, Composed, Ctx, Drive, Spin};
pub use disk_units::DiskUnits;
pub use dynamics::{first_order_rhs, Dynamics, Jacobians};
pub use layout::Layout;
pub use params::{ParamId, ParamRef};
pub use planar::Planar;
pub use scene::{Scene, SpringLayout};
