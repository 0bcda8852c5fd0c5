use crate::model::component::{Component, Ctx};
use crate::model::{Layout, ParamId};

/// The isotropic spring–damper support of the disk centre: force `-(x + 2 zeta C')` with
/// `C'` the centre's ground velocity, in rotating components `(x' - Omega y, y' + Omega x)`
/// (stiffness 1 and damping ratio `zeta` in the units of `model.md`).
#[derive(Debug, Clone, PartialEq)]
pub struct IsotropicSupport {
    pub zeta: f64,
}

impl Component for IsotropicSupport {
    fn name(&self) -> &'static str {
        "support"
    }
    fn params(&self) -> &'static [ParamId] {
        &[ParamId::Zeta]
    }
    fn coords(&self, l: &Layout) -> Vec<usize> {
        l.support().to_vec()
    }
    fn has_inertia(&self) -> bool {
        false
    }
    #[inline]
    fn add_residual(&self, cx: &Ctx, q: &[f64], v: &[f64], _a: &[f64], out: &mut [f64]) {
        let (x, y) = (cx.layout.x, cx.layout.y);
        let (z, om) = (self.zeta, cx.spin.om);
        out[x] += q[x] + 2.0 * z * (v[x] - om * q[y]);
        out[y] += q[y] + 2.0 * z * (v[y] + om * q[x]);
    }
    #[inline]
    fn add_jacobians(
        &self,
        cx: &Ctx,
        _q: &[f64],
        _v: &[f64],
        _a: &[f64],
        k: &mut [f64],
        c: &mut [f64],
        _m: &mut [f64],
    ) {
        let (x, y, d) = (cx.layout.x, cx.layout.y, cx.ndof());
        let (z, om) = (self.zeta, cx.spin.om);
        k[x * d + x] += 1.0;
        k[x * d + y] -= 2.0 * z * om;
        k[y * d + x] += 2.0 * z * om;
        k[y * d + y] += 1.0;
        c[x * d + x] += 2.0 * z;
        c[y * d + y] += 2.0 * z;
    }
}
