//! The models a scan or a continuation varies, as the [`Family`] trait they see: the
//! planar balancer and scenes, with the equilibrium reported beside every point. The
//! scan knows only the trait.

use crate::equilibria::{equilibria, Equilibrium, EquilibriumKind};
use crate::error::Result;
use crate::model::ParamRef;
use crate::numerics::problem::Parametric;
use crate::{Planar, Scene};

/// A model whose parameters a scan varies.
pub trait Family: Parametric {
    /// The equilibrium reported beside every point (`pb_exists`, `pb_stable`): the
    /// perfect balance, or with ball springs the balanced state that continues it.
    fn balance(&self) -> Option<Equilibrium>;
}

impl Parametric for Planar {
    fn with_param(&self, name: &str, value: f64) -> Result<Self> {
        Planar::with_param(self, name, value)
    }
    fn param_value(&self, name: &str) -> Result<f64> {
        registry_value(name, ParamRef::parse(name).and_then(|p| self.get(p)))
    }
}

impl Family for Planar {
    fn balance(&self) -> Option<Equilibrium> {
        equilibria(self)
            .into_iter()
            .find(|e| e.kind == EquilibriumKind::PerfectBalance)
    }
}

impl Parametric for Scene {
    fn with_param(&self, name: &str, value: f64) -> Result<Self> {
        Scene::with_param(self, name, value)
    }
    fn param_value(&self, name: &str) -> Result<f64> {
        registry_value(name, ParamRef::parse(name).and_then(|p| self.get(p)))
    }
}

impl Family for Scene {
    fn balance(&self) -> Option<Equilibrium> {
        crate::analysis::balanced::balanced_state(self)
    }
}

/// A parameter's value looked up in the registry, or an error naming it.
fn registry_value(name: &str, v: Option<f64>) -> Result<f64> {
    v.ok_or_else(|| crate::Error::param(name, "is not a parameter of this model"))
}
