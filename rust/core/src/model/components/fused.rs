use crate::model::component::{Component, Ctx};
use crate::model::Jacobians;
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
    fn add_jacobians(&self, cx: &Ctx, q: &[f64], v: &[f64], a: &[f64], jac: Jacobians<'_>) {
        let Jacobians { k, c, m } = jac;
        self.planar
            .add_jacobians_at(cx.spin.om, q, v, a, Jacobians::new(k, c, m));
        self.ramp_jacobian(cx, q, k);
    }
    #[inline]
    fn set_jacobians(&self, cx: &Ctx, q: &[f64], v: &[f64], a: &[f64], jac: Jacobians<'_>) {
        let Jacobians { k, c, m } = jac;
        self.planar
            .jacobians_at(cx.spin.om, q, v, a, Jacobians::new(k, c, m));
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

/// [`super::TiltingDisk`] + [`super::TiltingBalls`] in one component, so that the
/// generated rotor and ball terms are compiled together (their trigonometry of the
/// tilts is shared): what a scene with a tilting disk uses.
#[derive(Debug, Clone, PartialEq)]
pub struct FusedTilting {
    pub disk: super::TiltingDisk,
    pub balls: super::TiltingBalls,
}

impl Component for FusedTilting {
    fn name(&self) -> &'static str {
        "tilting_disk"
    }
    fn params(&self) -> &'static [ParamId] {
        &[
            ParamId::Mu,
            ParamId::TiltA,
            ParamId::TiltB,
            ParamId::TiltJt,
            ParamId::TiltJz,
            ParamId::TiltZetaR,
            ParamId::ZetaB,
            ParamId::Delta,
            ParamId::Eta,
        ]
    }
    fn time_dependence(&self) -> Option<&'static str> {
        self.disk.time_dependence()
    }
    fn coords(&self, l: &Layout) -> Vec<usize> {
        (0..l.ndof()).collect()
    }
    #[inline]
    fn add_residual(&self, cx: &Ctx, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]) {
        self.disk.add_residual(cx, q, v, a, out);
        self.balls.add_residual(cx, q, v, a, out);
    }
    #[inline]
    fn add_jacobians(&self, cx: &Ctx, q: &[f64], v: &[f64], a: &[f64], jac: Jacobians<'_>) {
        let Jacobians { k, c, m } = jac;
        self.disk
            .add_jacobians(cx, q, v, a, Jacobians::new(k, c, m));
        self.balls
            .add_jacobians(cx, q, v, a, Jacobians::new(k, c, m));
    }
    /// The rotor's and the balls' generated mass terms in one body, so that the
    /// trigonometry of the tilts is computed once for all of them.
    #[inline]
    fn add_mass(&self, cx: &Ctx, q: &[f64], m: &mut [f64]) {
        use crate::model::tilt_terms::{ball_mass, rotor_mass};
        let (c, l) = (&self.disk.consts, &cx.layout);
        let mut rm = [0.0; 16];
        rotor_mass(c, q, &mut rm);
        super::rotor::add_rotor_block(cx.ndof(), &rm, m);
        let mut bm = [0.0; 25];
        for (i, &mi) in cx.m.iter().enumerate() {
            ball_mass(c, &super::TiltingBalls::view(l, q, i), &mut bm);
            super::TiltingBalls::add_block(l, i, mi, &bm, m);
        }
    }
}
