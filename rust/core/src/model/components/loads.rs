use crate::model::component::{Component, Ctx};
use crate::model::Jacobians;
use crate::model::ParamId;

/// Gravity across a horizontal spin axis on a planar disk (`g` over `e w_n^2`, along
/// ground `-Y`): the support rows gain `g sin th`, `g cos th`, ball row i `g cos(th + b_i)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Gravity {
    pub g: f64,
}

impl Component for Gravity {
    fn name(&self) -> &'static str {
        "gravity"
    }
    fn params(&self) -> &'static [ParamId] {
        &[ParamId::Gravity]
    }
    fn time_dependence(&self) -> Option<&'static str> {
        Some("gravity")
    }
    fn has_inertia(&self) -> bool {
        false
    }
    #[inline]
    fn add_residual(&self, cx: &Ctx, q: &[f64], _v: &[f64], _a: &[f64], out: &mut [f64]) {
        let th = cx.spin.th;
        let (sn, cs) = th.sin_cos();
        out[cx.layout.x] += sn * self.g;
        out[cx.layout.y] += cs * self.g;
        for j in cx.layout.balls() {
            out[j] += self.g * (th + q[j]).cos();
        }
    }
    #[inline]
    fn add_jacobians(&self, cx: &Ctx, q: &[f64], _v: &[f64], _a: &[f64], jac: Jacobians<'_>) {
        let Jacobians { k, c: _c, m: _m } = jac;
        let d = cx.ndof();
        for j in cx.layout.balls() {
            k[j * d + j] -= self.g * (cx.spin.th + q[j]).sin();
        }
    }
}

/// Yen's (2005) impulsive load on the rotor, `F(t) = amplitude exp(-sharpness (t - t0)^2)`
/// along the ground direction `angle`, turned into the rotating frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Impulse {
    pub amplitude: f64,
    pub t0: f64,
    pub sharpness: f64,
    pub angle: f64,
}

impl Impulse {
    /// The ground-frame force at `t`.
    #[inline]
    pub fn load(&self, t: f64) -> (f64, f64) {
        let a = self.amplitude * (-self.sharpness * (t - self.t0).powi(2)).exp();
        (a * self.angle.cos(), a * self.angle.sin())
    }
}

impl Component for Impulse {
    fn name(&self) -> &'static str {
        "impulse"
    }
    fn params(&self) -> &'static [ParamId] {
        &[
            ParamId::ImpulseAmplitude,
            ParamId::ImpulseT0,
            ParamId::ImpulseSharpness,
            ParamId::ImpulseAngle,
        ]
    }
    fn time_dependence(&self) -> Option<&'static str> {
        Some("impulse")
    }
    fn has_inertia(&self) -> bool {
        false
    }
    #[inline]
    fn add_residual(&self, cx: &Ctx, _q: &[f64], _v: &[f64], _a: &[f64], out: &mut [f64]) {
        let (lx, ly) = self.load(cx.t);
        if lx != 0.0 || ly != 0.0 {
            let (sn, cs) = cx.spin.th.sin_cos();
            out[cx.layout.x] -= cs * lx + sn * ly;
            out[cx.layout.y] -= -sn * lx + cs * ly;
        }
    }
    /// The load does not depend on the state.
    fn add_jacobians(&self, _: &Ctx, _: &[f64], _: &[f64], _: &[f64], _: Jacobians<'_>) {}
}
