//! The models a scan or a continuation varies, as the [`Family`] trait they see: the
//! planar balancer and scenes, with the equilibrium reported beside every point. The
//! scan knows only the trait.

use crate::equilibria::{
    equilibria, has_closed_forms, perfect_balance, perfect_balance_verdict, Equilibrium, Verdict,
};
use crate::error::Result;
use crate::model::ParamRef;
use crate::numerics::problem::Parametric;
use crate::{Planar, Scene};

/// A model whose parameters a scan varies.
pub trait Family: Parametric {
    /// The equilibrium reported beside every point (`pb_exists`, `pb_stable`): the
    /// perfect balance, or with ball springs the balanced state that continues it.
    fn balance(&self) -> Option<Equilibrium>;
    /// The verdict of [`Self::balance`], which a model may find more cheaply (a scan
    /// asks it at every point).
    fn balance_verdict(&self) -> Option<Verdict> {
        self.balance().map(|e| e.verdict)
    }
    /// Equilibria that attract their neighbourhood, as `(positions, rate)` with `rate`
    /// minus the largest real part of their eigenvalues (none neutral), where the model
    /// has them cheaply (closed forms); a scan's seeds stop on reaching one (see
    /// [`crate::analysis::attractors::Capture`]). Empty: the seeds wait for rest.
    fn attracting_rests(&self) -> Vec<(Vec<f64>, f64)> {
        vec![]
    }
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
        perfect_balance(self)
    }
    fn balance_verdict(&self) -> Option<Verdict> {
        perfect_balance_verdict(self)
    }
    fn attracting_rests(&self) -> Vec<(Vec<f64>, f64)> {
        let n = self.n_balls();
        if !(has_closed_forms(self) && self.zeta > 0.0) {
            return vec![];
        }
        let mut out = vec![];
        for e in equilibria(self) {
            if e.verdict != Verdict::Stable || e.neutral > 0 {
                continue;
            }
            let rate = -e.index;
            if n == 2 {
                // identical balls: the relabelled state is the same equilibrium
                let mut s = e.q.clone();
                s.swap(2, 3);
                out.push((s, rate));
            }
            out.push((e.q, rate));
        }
        out
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
    v.ok_or_else(|| {
        crate::Error::param(
            name,
            format!(
                "is not a parameter of this model{}",
                crate::model::params::ball_hint(name)
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scan's per-point verdict against the full list of analysed equilibria:
    /// closed forms (one ball, two equal balls), Newton's search (unequal balls, three
    /// balls, no damping), perfect balances that exist or not, stable or not.
    #[test]
    fn balance_verdict_is_the_listed_perfect_balance_verdict() {
        let mut seen = [0usize; 3];
        let etas: [&[f64]; 5] = [&[1.0], &[0.7], &[1.0, 1.0], &[0.4, 0.4], &[0.9, 0.6]];
        for eta in etas {
            for zeta in [0.0, 0.05] {
                for om in [0.4, 0.9, 1.1, 1.6, 3.0] {
                    let zb = vec![0.05; eta.len()];
                    let p = Planar::new(0.2, zeta, &zb, 50.0, om, eta).unwrap();
                    let want = p.balance().map(|e| e.verdict);
                    assert_eq!(
                        p.balance_verdict(),
                        want,
                        "eta {eta:?} zeta {zeta} Omega {om}"
                    );
                    seen[match want {
                        None => 0,
                        Some(Verdict::Stable) => 1,
                        Some(_) => 2,
                    }] += 1;
                }
            }
        }
        let three = Planar::new(0.2, 0.05, &[0.05; 3], 50.0, 1.6, &[0.5; 3]).unwrap();
        assert_eq!(three.balance_verdict(), three.balance().map(|e| e.verdict));
        assert!(seen.iter().all(|&n| n > 0), "{seen:?}");
    }
}
