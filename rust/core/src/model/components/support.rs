use crate::model::component::{Component, Ctx};
use crate::model::Jacobians;
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
    fn add_jacobians(&self, cx: &Ctx, _q: &[f64], _v: &[f64], _a: &[f64], jac: Jacobians<'_>) {
        let Jacobians { k, c, m: _m } = jac;
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

/// A support fixed to the ground whose stiffness and damping differ between the ground
/// axes `X` and `Y` (a rig's plate or frame, stiffer one way than the other): ground force
/// `-(k_x X + 2 zeta_x X', k_y Y + 2 zeta_y Y')` on the disk centre, stiffness over the
/// `k` of `w_n` and damping ratios `c / (2 M w_n)` as in `model.md`. In the rotating frame
/// the axes turn at `-Omega`, so unless both axes are equal the terms depend on time (on
/// the spin angle) and the scene is time-periodic: simulation only. Free vibration
/// without spin has the two frequencies `sqrt(k_x)`, `sqrt(k_y)`; with `k_x = k_y = 1`
/// and both dampings `zeta` it is [`IsotropicSupport`].
#[derive(Debug, Clone, PartialEq)]
pub struct AnisotropicSupport {
    pub k_x: f64,
    pub k_y: f64,
    pub zeta_x: f64,
    pub zeta_y: f64,
}

impl AnisotropicSupport {
    /// Equal axes: the terms do not depend on the spin angle.
    pub fn is_isotropic(&self) -> bool {
        self.k_x == self.k_y && self.zeta_x == self.zeta_y
    }

    /// The rotating-frame matrices `R^T diag(a_x, a_y) R` of the ground-axis diagonal
    /// `(a_x, a_y)`, `R` the rotation by the spin angle `th` (ground = `R` rotating).
    #[inline]
    fn turned(ax: f64, ay: f64, th: f64) -> [f64; 3] {
        let (s, c) = th.sin_cos();
        // [[xx, xy], [xy, yy]]
        [
            ax * c * c + ay * s * s,
            (ay - ax) * s * c,
            ax * s * s + ay * c * c,
        ]
    }
}

impl Component for AnisotropicSupport {
    fn name(&self) -> &'static str {
        "support"
    }
    fn params(&self) -> &'static [ParamId] {
        &[ParamId::Zeta]
    }
    fn time_dependence(&self) -> Option<&'static str> {
        (!self.is_isotropic()).then_some("anisotropic_support")
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
        let (om, th) = (cx.spin.om, cx.spin.th);
        let k = Self::turned(self.k_x, self.k_y, th);
        let c = Self::turned(2.0 * self.zeta_x, 2.0 * self.zeta_y, th);
        // the centre's ground velocity in rotating components
        let (gx, gy) = (v[x] - om * q[y], v[y] + om * q[x]);
        out[x] += k[0] * q[x] + k[1] * q[y] + c[0] * gx + c[1] * gy;
        out[y] += k[1] * q[x] + k[2] * q[y] + c[1] * gx + c[2] * gy;
    }
    #[inline]
    fn add_jacobians(&self, cx: &Ctx, _q: &[f64], _v: &[f64], _a: &[f64], jac: Jacobians<'_>) {
        let Jacobians {
            k: kk,
            c: cc,
            m: _m,
        } = jac;
        let (x, y, d) = (cx.layout.x, cx.layout.y, cx.ndof());
        let (om, th) = (cx.spin.om, cx.spin.th);
        let k = Self::turned(self.k_x, self.k_y, th);
        let c = Self::turned(2.0 * self.zeta_x, 2.0 * self.zeta_y, th);
        // d/dq of c (v + om J q) with J q = (-y, x): c J om
        kk[x * d + x] += k[0] + om * c[1];
        kk[x * d + y] += k[1] - om * c[0];
        kk[y * d + x] += k[1] + om * c[2];
        kk[y * d + y] += k[2] - om * c[1];
        cc[x * d + x] += c[0];
        cc[x * d + y] += c[1];
        cc[y * d + x] += c[1];
        cc[y * d + y] += c[2];
    }
}
