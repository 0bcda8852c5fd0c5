//! The components scenes are assembled from (see [`super::component`]).
//!
//! * rotor: [`PlanarDisk`] (a rigid disk in its plane, carrying the balls' share of the
//!   translating mass), [`TiltingDisk`] (a disk tilting on a flexible shaft, generated
//!   from its Lagrangian by `scripts/derive_tilt.py`);
//! * support: [`IsotropicSupport`] (the spring–damper `k x + c x'` on the disk centre),
//!   [`AnisotropicSupport`] (a ground-fixed spring–damper, unequal in X and Y),
//!   [`BearingSupport`] (a journal bearing's film, [`JournalSupport`]);
//! * balls: [`FreeBalls`] on a planar disk, [`TiltingBalls`] on a tilting one, and the
//!   coupling [`BallSprings`] (ring or chain);
//! * drive: [`super::component::Drive`] (constant spin or a ramp);
//! * loads: [`Gravity`] (on a planar disk; a tilting disk's gravity is in its generated
//!   terms), [`Impulse`];
//! * [`FusedPlanar`]: planar disk, isotropic support and free balls in one pass, the
//!   planar balancer's own code, which a scene uses when it has all three.

mod balls;
mod bearing_support;
mod fused;
mod loads;
mod rotor;
mod support;

pub use balls::{BallSprings, FreeBalls, SpringLayout, TiltingBalls};
pub use bearing_support::{no_bearing, BearingSupport, JournalSupport, SolverPool, SupportFilm};
pub use fused::{FusedPlanar, FusedTilting};
pub use loads::{Gravity, Impulse};
pub use rotor::{PlanarDisk, TiltingDisk};
pub use support::{AnisotropicSupport, IsotropicSupport};
