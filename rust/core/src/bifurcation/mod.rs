//! Bifurcations of equilibria and periodic solutions, on the generic engine of
//! [`crate::continuation`]: one-parameter branches with their located events
//! ([`equilibria`], [`po_branch`]), the one event vocabulary they share ([`event`]),
//! branch switching at those events ([`switch`], and [`equilibria::switch`] at an
//! equilibrium branch point), and two-parameter curves of the events with their
//! codimension-two points ([`equilibria::curve`], [`po_curves`]).
//!
//! Layers: this module uses [`crate::continuation`], [`crate::numerics`] and the
//! analyses it continues ([`crate::analysis`]); none of those imports from here (the
//! engine knows no bifurcation, see the test in `continuation/mod.rs`).

pub mod equilibria;
pub mod event;
pub mod po_branch;
mod po_colloc;
pub mod po_curves;
pub mod switch;

#[cfg(all(test, feature = "studies"))]
mod studies;

pub use event::Event;
