use crate::model::component::{Component, Ctx};
use crate::model::{Layout, ParamId, Planar};

/// [`super::PlanarDisk`] + [`super::IsotropicSupport`] + [`super::FreeBalls`] in one
/// pass: the planar balancer's fused code (one `sin_cos` per ball for all three), plus
/// the `Omega'` terms of a varying spin. A scene with a planar disk on the isotropic
/// support uses it; the test `fused_planar_is_its_three_components` holds it to the
/// three separate components.
#[derive(Debug, Clone, PartialEq)]
pub struct FusedPlanar {
    pub planar: Planar,
}

impl Component for FusedPlanar {
    fn name(&self) -> &'static str {
        "rotor"
    }
    fn params(&self) -> &'static [ParamId] {
        &[
            ParamId::Mu,
            ParamId::Zeta,
            ParamId::ZetaB,
            ParamId::Delta,
            ParamId::Eta,
        ]
    }
    fn coords(&self, l: &Layout) -> Vec<usize> {
        (0..l.ndof()).collect()
    }
    #[inline]
    fn add_residual(&self, cx: &Ctx, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]) {
        self.planar.add_forces_at(cx.spin.om, q, v, out);
        self.inertia_and_ramp(cx, q, a, out);
    }
    #[inline]
    fn set_residual(&self, cx: &Ctx, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]) {
        self.planar.forces_at(cx.spin.om, q, v, out);
        self.inertia_and_ramp(cx, q, a, out);
    }
    #[inline]
    fn add_jacobians(
        &self,
        cx: &Ctx,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        k: &mut [f64],
        c: &mut [f64],
        m: &mut [f64],
    ) {
        self.planar.add_jacobians_at(cx.spin.om, q, v, a, k, c, m);
        self.ramp_jacobian(cx, q, k);
    }
    #[inline]
    fn set_jacobians(
        &self,
        cx: &Ctx,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        k: &mut [f64],
        c: &mut [f64],
        m: &mut [f64],
    ) {
        self.planar.jacobians_at(cx.spin.om, q, v, a, k, c, m);
        self.ramp_jacobian(cx, q, k);
    }
}

impl FusedPlanar {
    /// The inertia terms, and the `Omega'` terms of a varying spin.
    #[inline(always)]
    fn inertia_and_ramp(&self, cx: &Ctx, q: &[f64], a: &[f64], out: &mut [f64]) {
        let p = &self.planar;
        p.add_inertia(q, a, out);
        let dom = cx.spin.dom;
        if dom != 0.0 {
            let (x, y) = (q[0], q[1]);
            out[0] -= dom * y;
            out[1] += dom * (x + p.mu);
            for i in 0..p.n_balls() {
                let (s, c) = q[2 + i].sin_cos();
                let mi = p.m(i);
                out[0] -= mi * dom * s;
                out[1] += mi * dom * c;
                out[2 + i] += dom * (p.delta + x * c + y * s);
            }
        }
    }

    #[inline(always)]
    fn ramp_jacobian(&self, cx: &Ctx, q: &[f64], k: &mut [f64]) {
        let p = &self.planar;
        let dom = cx.spin.dom;
        if dom != 0.0 {
            let d = p.n_balls() + 2;
            k[1] -= dom;
            k[d] += dom;
            for i in 0..p.n_balls() {
                let j = 2 + i;
                let (s, cs) = q[j].sin_cos();
                let mi = p.m(i);
                k[j] -= mi * dom * cs;
                k[d + j] -= mi * dom * s;
                k[j * d] += dom * cs;
                k[j * d + 1] += dom * s;
                k[j * d + j] += dom * (-q[0] * s + q[1] * cs);
            }
        }
    }
}
