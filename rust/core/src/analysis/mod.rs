//! Analyses a user asks for, built on the numerics: time simulation, equilibria and
//! their stability, periodic solutions with their certificates.

pub mod attractors;
pub mod balanced;
pub mod basins;
pub mod colloc_periodic;
pub mod constructed;
pub mod equilibria;
pub mod family;
pub mod homotopy;
pub mod journal;
pub mod periodic;
pub mod record;
pub mod simulate;
