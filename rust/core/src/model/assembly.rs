//! How a scene's components are put together, chosen once when it is built: a planar
//! disk on the isotropic support gets its effects dispatched statically (the hot path of
//! every scan and simulation of such scenes); anything else is a [`Composed`] list.

use super::component::{Component, Composed, Ctx, Drive};
use super::components::{BallSprings, FusedPlanar, Gravity, Impulse};
use super::{Dynamics, Layout};
use crate::model::Jacobians;

/// The planar disk, isotropic support and free balls ([`FusedPlanar`]) with the effects
/// a scene switches on, each an `Option` set at assembly: the same components as a
/// [`Composed`] list, summed in the same order, without dynamic dispatch.
#[derive(Debug, Clone)]
pub struct PlanarAssembly {
    pub core: FusedPlanar,
    pub drive: Drive,
    pub springs: Option<BallSprings>,
    pub impulse: Option<Impulse>,
    pub gravity: Option<Gravity>,
    layout: Layout,
    m: Vec<f64>,
}

impl PlanarAssembly {
    pub fn new(
        core: FusedPlanar,
        drive: Drive,
        springs: Option<BallSprings>,
        impulse: Option<Impulse>,
        gravity: Option<Gravity>,
    ) -> Self {
        let p = &core.planar;
        let n = p.n_balls();
        PlanarAssembly {
            layout: Layout::planar(n),
            m: (0..n).map(|i| p.m(i)).collect(),
            core,
            drive,
            springs,
            impulse,
            gravity,
        }
    }

    #[inline(always)]
    fn ctx(&self, t: f64) -> Ctx<'_> {
        Ctx {
            t,
            layout: self.layout,
            spin: self.drive.spin(t),
            m: &self.m,
        }
    }
}

impl Dynamics for PlanarAssembly {
    #[inline]
    fn ndof(&self) -> usize {
        self.layout.ndof()
    }

    fn layout(&self) -> Layout {
        self.layout
    }

    #[inline]
    fn residual(&self, t: f64, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]) {
        let cx = self.ctx(t);
        self.core.set_residual(&cx, q, v, a, out);
        if let Some(s) = &self.springs {
            s.add_residual(&cx, q, v, a, out);
        }
        if let Some(f) = &self.impulse {
            f.add_residual(&cx, q, v, a, out);
        }
        if let Some(g) = &self.gravity {
            g.add_residual(&cx, q, v, a, out);
        }
    }

    #[inline]
    fn jacobians(&self, t: f64, q: &[f64], v: &[f64], a: &[f64], jac: Jacobians<'_>) {
        let Jacobians { k, c, m } = jac;
        let cx = self.ctx(t);
        self.core
            .set_jacobians(&cx, q, v, a, Jacobians::new(k, c, m));
        if let Some(s) = &self.springs {
            s.add_jacobians(&cx, q, v, a, Jacobians::new(k, c, m));
        }
        if let Some(g) = &self.gravity {
            g.add_jacobians(&cx, q, v, a, Jacobians::new(k, c, m));
        }
    }

    #[inline]
    fn solve_mass(&self, t: f64, q: &[f64], rhs: &mut [f64]) {
        self.core.planar.solve_mass(t, q, rhs)
    }

    #[inline]
    fn solve_mass_columns(&self, t: f64, q: &[f64], cols: &mut [f64]) {
        self.core.planar.solve_mass_columns(t, q, cols)
    }

    fn time_dependence(&self) -> Option<String> {
        self.drive
            .time_dependence()
            .or(self.gravity.as_ref().and_then(|g| g.time_dependence()))
            .or(self.impulse.as_ref().and_then(|f| f.time_dependence()))
            .map(str::to_string)
    }

    fn base_spin(&self) -> f64 {
        self.drive.base()
    }

    fn angles_modulo_turns(&self) -> bool {
        self.springs.is_none()
    }
}

/// A scene's assembled model.
#[derive(Debug, Clone)]
pub enum Assembly {
    Planar(PlanarAssembly),
    Composed(Composed),
}

impl Assembly {
    pub fn drive(&self) -> &Drive {
        match self {
            Assembly::Planar(p) => &p.drive,
            Assembly::Composed(c) => c.drive(),
        }
    }
}

/// Forwards every [`Dynamics`] method to the assembled variant.
macro_rules! dispatch {
    ($self:ident, $m:ident => $e:expr) => {
        match $self {
            Assembly::Planar($m) => $e,
            Assembly::Composed($m) => $e,
        }
    };
}

impl Dynamics for Assembly {
    #[inline]
    fn ndof(&self) -> usize {
        dispatch!(self, m => m.ndof())
    }
    fn layout(&self) -> Layout {
        dispatch!(self, m => m.layout())
    }
    #[inline]
    fn residual(&self, t: f64, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]) {
        dispatch!(self, m => m.residual(t, q, v, a, out))
    }
    #[inline]
    fn jacobians(&self, t: f64, q: &[f64], v: &[f64], a: &[f64], jac: Jacobians<'_>) {
        let Jacobians { k, c, m: mm } = jac;
        dispatch!(self, m => m.jacobians(t, q, v, a, Jacobians::new(k, c, mm)))
    }
    #[inline]
    fn solve_mass(&self, t: f64, q: &[f64], rhs: &mut [f64]) {
        dispatch!(self, m => m.solve_mass(t, q, rhs))
    }
    #[inline]
    fn solve_mass_columns(&self, t: f64, q: &[f64], cols: &mut [f64]) {
        dispatch!(self, m => m.solve_mass_columns(t, q, cols))
    }
    #[inline]
    fn accel(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        dispatch!(self, m => m.accel(t, q, v, out))
    }
    fn time_dependence(&self) -> Option<String> {
        dispatch!(self, m => m.time_dependence())
    }
    fn base_spin(&self) -> f64 {
        dispatch!(self, m => m.base_spin())
    }
    fn angles_modulo_turns(&self) -> bool {
        dispatch!(self, m => m.angles_modulo_turns())
    }
}
