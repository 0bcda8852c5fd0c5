//! A scene: the planar balancer plus the physical effects a user switches on, composed
//! so that an effect that is off costs nothing (a scene without effects is never built:
//! callers use [`Planar`] directly).
//!
//! Effects, derived from the Lagrangian in the disk-fixed frame (nondimensional as in
//! `model.md`: lengths over `e`, time over `1/w_n`, forces over `M e w_n^2`). The disk
//! turns by `theta(t)` with `theta' = Omega(t)`; a point at rotating-frame position `p`
//! has absolute acceleration `p'' + 2 Omega J p' + Omega' J p - Omega^2 p` (`J` the
//! quarter turn), so a varying spin adds the `Omega'` terms below to the planar
//! equations, whose `Omega` becomes `Omega(t)`:
//!
//! * x row: `- Omega' y - sum m_i Omega' sin b_i`;
//! * y row: `+ Omega' x + mu Omega' + sum m_i Omega' cos b_i`;
//! * ball row i (divided by `m_i`): `+ Omega' (delta + x cos b_i + y sin b_i)`.
//!
//! Ball springs: neighbouring balls joined by circumferential springs of stiffness `k_d`
//! and rest spacing `2 pi / n`: potential
//! `V = kappa delta^2 / 2 sum_j (b_{j+1} - b_j - 2 pi / n)^2` with `kappa = k_d / k`, and
//! ball row i gains `dV/db_i / m_i`. In a ring (the default) `j` runs over all `n`
//! neighbours, ball n to ball 1 closing it with spacing `b_1 + 2 pi - b_n`; Rezaee et al.'s (2017)
//! chain (its eq. 16) has the `n - 1` springs from ball 1 to ball n only. For two balls
//! the ring's two springs are the chain's one at twice the stiffness.
//!
//! Ground-fixed forces `F = (F_X, F_Y)` act in the rotating frame as
//! `(cos th F_X + sin th F_Y, -sin th F_X + cos th F_Y)`. Gravity (spin axis
//! horizontal, `g` over `e w_n^2`) pulls every mass along `-Y`: the support rows gain
//! `g sin th` and `g cos th`, ball row i gains `g cos(th + b_i)`. An impulsive load on the
//! rotor (Yen's (2005) form) `F(t) = A exp(-s (t - t0)^2)` along the ground direction at
//! angle `psi` enters the support rows only.
//!
//! Tilting disk on a flexible shaft (Rezaee et al. 2017): coordinates `(x, y, A, B, b_1..b_n)`,
//! where `A, B` are the disk's Euler tilts scaled by `delta` (the rim's axial
//! displacement over `e`). The rotor and ball terms, including spin ramp and gravity,
//! come from `scripts/derive_tilt.py`, which derives them from the Lagrangian and
//! writes [`crate::model::tilt_terms`]; the support's spring and damper, springs and the
//! impulsive load are their own components, as for the planar disk. The shaft is massless, simply supported, the disk at distances
//! `a`, `b` (over `r_t`) from the bearings: beam theory gives the translational
//! stiffness `k = 3 E I (1/a^3 + 1/b^3)` (the `k` of `w_n`), the coupling
//! `kappa_c = a b (a - b) / (a^2 - a b + b^2)` and tilt stiffness
//! `kappa_t = a^2 b^2 / (a^2 - a b + b^2)` (over `k r_t` and `k r_t^2`). With `a = b`
//! the coupling vanishes and a disk started flat stays flat: the planar equations.
//!
//! Support: the isotropic spring–damper (the default), or a hydrodynamic journal bearing
//! ([`Scene::with_bearing`], [`BearingSupport`]): the planar disk and free balls as
//! components with the film force on the centre. Its units are the film's, not `w_n`'s
//! (no spring): time over `1 / w_ref` with `w_ref = C_S / M`, `C_S = mu_oil L R^3 / c^3`;
//! the balancer's `zeta` is an external damper in parallel with the film, relative to
//! `w_ref` (see [`crate::model::components::BearingSupport`]).

use crate::error::{Error, Result};
use crate::model::assembly::{Assembly, PlanarAssembly};
use crate::model::component::{Component, Composed, Drive};
use crate::model::components::{
    no_bearing, AnisotropicSupport, BallSprings, BearingSupport, FreeBalls, FusedPlanar,
    FusedTilting, Gravity, IsotropicSupport, JournalSupport, PlanarDisk, SolverPool, SupportFilm,
    TiltingBalls, TiltingDisk,
};
use crate::model::params::{key_list, unknown, ParamId, ParamRef, PLANAR_OWNERS};
use crate::model::tilt_terms::RotorConsts;
use crate::model::Jacobians;
use crate::model::{Dynamics, Layout, Planar};
use std::sync::Arc;

pub use crate::model::components::{Impulse, SpringLayout};

/// A disk that tilts on a flexible shaft, with gyroscopic coupling (Rezaee et al. 2017).
#[derive(Debug, Clone, PartialEq)]
pub struct Tilt {
    /// Distance of the disk from the first bearing, over the track radius.
    pub a: f64,
    /// Distance of the disk from the second bearing, over the track radius.
    pub b: f64,
    /// Transverse moment of inertia of the disk about its mass centre, over `M r_t^2`.
    pub j_t: f64,
    /// Polar moment of inertia of the disk, over `M r_t^2`.
    pub j_z: f64,
    /// Damping ratio of the tilt: `c_r / (2 sqrt(J_t k_phiphi))`, acting on the disk
    /// normal's rate in the ground frame.
    pub zeta_r: f64,
}

impl Tilt {
    fn validate(&self) -> Result<()> {
        ParamId::TiltA.check(self.a)?;
        ParamId::TiltB.check(self.b)?;
        ParamId::TiltJt.check(self.j_t)?;
        // a range that depends on j_t: [0, 2 j_t]
        if !(self.j_z >= 0.0 && self.j_z <= 2.0 * self.j_t) {
            return Err(Error::param(
                "tilt.j_z",
                format!(
                    "must be in [0, 2 j_t] = [0, {}] (a rigid body's polar moment is at most the sum of the other two), got {}",
                    2.0 * self.j_t,
                    self.j_z
                ),
            ));
        }
        ParamId::TiltZetaR.check(self.zeta_r)
    }

    /// Translation–tilt coupling stiffness `kappa_c` of the simply supported shaft.
    pub fn kappa_c(&self) -> f64 {
        let (a, b) = (self.a, self.b);
        a * b * (a - b) / (a * a - a * b + b * b)
    }

    /// Tilt stiffness `kappa_t` of the simply supported shaft.
    pub fn kappa_t(&self) -> f64 {
        let (a, b) = (self.a, self.b);
        a * a * b * b / (a * a - a * b + b * b)
    }
}

/// A change of spin speed from the scene's `Omega` to `to`, linear over `duration`
/// starting at `start` (a run-up, or [TwoBallStrength]'s speed disturbance).
#[derive(Debug, Clone, PartialEq)]
pub struct Ramp {
    pub to: f64,
    pub start: f64,
    pub duration: f64,
}

/// The description of a ground-fixed support unequal in X and Y
/// ([`AnisotropicSupport`]): stiffnesses over the `k` of `w_n`, damping ratios
/// `c / (2 M w_n)`; a damping left `None` is the balancer's `zeta` (so that a scan of
/// `zeta` moves it).
#[derive(Debug, Clone, PartialEq)]
pub struct AnisotropicAxes {
    pub k_x: f64,
    pub k_y: f64,
    pub zeta_x: Option<f64>,
    pub zeta_y: Option<f64>,
}

/// Largest stiffness ratio of an axis to the `k` of `w_n`: beyond it the time unit is
/// the wrong one for the support (its period far below the integrator's natural step).
pub const MAX_AXIS_STIFFNESS: f64 = 1e4;

impl AnisotropicAxes {
    fn validate(&self) -> Result<()> {
        for (name, k) in [("support.k_x", self.k_x), ("support.k_y", self.k_y)] {
            crate::error::check_range(name, k, 0.0, true, MAX_AXIS_STIFFNESS, false)?;
        }
        for (name, z) in [
            ("support.zeta_x", self.zeta_x),
            ("support.zeta_y", self.zeta_y),
        ] {
            if let Some(z) = z {
                ParamId::Zeta.check_named(name, z)?;
            }
        }
        Ok(())
    }

    /// The component, a `None` damping taken as `zeta`.
    pub fn support(&self, zeta: f64) -> AnisotropicSupport {
        AnisotropicSupport {
            k_x: self.k_x,
            k_y: self.k_y,
            zeta_x: self.zeta_x.unwrap_or(zeta),
            zeta_y: self.zeta_y.unwrap_or(zeta),
        }
    }
}

/// A scene: a description (the public fields) and the model assembled from exactly the
/// components it switches on (built once, by [`Scene::new`], [`Scene::set`] and the
/// `with_*` methods; a field changed in place is not seen by the dynamics until
/// [`Scene::reassemble`]).
#[derive(Debug, Clone)]
pub struct Scene {
    pub planar: Planar,
    /// `k_d / k`; 0 for no springs.
    pub springs: f64,
    /// Ring (default) or chain; set with [`Scene::with_spring_layout`].
    pub spring_layout: SpringLayout,
    pub ramp: Option<Ramp>,
    /// `g / (e w_n^2)`; 0 for a vertical spin axis.
    pub gravity: f64,
    pub impulse: Option<Impulse>,
    pub tilt: Option<Tilt>,
    /// The journal-bearing support (`None`: the spring–damper); set with
    /// [`Scene::with_bearing`].
    pub bearing: Option<JournalSupport>,
    /// A ground-fixed support unequal in X and Y in place of the isotropic one
    /// (`None`: the isotropic spring–damper); set with [`Scene::with_anisotropic_support`].
    pub anisotropic: Option<AnisotropicAxes>,
    model: Assembly,
    /// The bearing's film solvers, kept across reassembly while the film is unchanged.
    pool: Option<Arc<SolverPool>>,
}

impl PartialEq for Scene {
    /// Scenes are equal when their descriptions are (the model follows from it).
    fn eq(&self, o: &Self) -> bool {
        self.planar == o.planar
            && self.springs == o.springs
            && self.spring_layout == o.spring_layout
            && self.ramp == o.ramp
            && self.gravity == o.gravity
            && self.impulse == o.impulse
            && self.tilt == o.tilt
            && self.bearing == o.bearing
            && self.anisotropic == o.anisotropic
    }
}

/// The components a scene without a tilting disk may have, as the registry names them.
const SCENE_OWNERS: &[&str] = &[
    "rotor",
    "support",
    "balls",
    "drive",
    "ball_springs",
    "gravity",
];

impl Scene {
    pub fn new(
        planar: Planar,
        springs: f64,
        ramp: Option<Ramp>,
        gravity: f64,
        impulse: Option<Impulse>,
        tilt: Option<Tilt>,
    ) -> Result<Self> {
        ParamId::Springs.check(springs)?;
        if springs > 0.0 && planar.n_balls() < 2 {
            return Err(Error::param(
                "springs",
                "ball springs need at least 2 balls",
            ));
        }
        if let Some(r) = &ramp {
            ParamId::RampTo.check(r.to)?;
            ParamId::RampStart.check(r.start)?;
            ParamId::RampDuration.check(r.duration)?;
        }
        ParamId::Gravity.check(gravity)?;
        if let Some(f) = &impulse {
            ParamId::ImpulseAmplitude.check(f.amplitude)?;
            ParamId::ImpulseT0.check(f.t0)?;
            ParamId::ImpulseAngle.check(f.angle)?;
            ParamId::ImpulseSharpness.check(f.sharpness)?;
        }
        if let Some(tl) = &tilt {
            tl.validate()?;
        }
        let mut s = Scene {
            model: Assembly::Composed(Composed::new(
                Layout::planar(0),
                Drive::Constant(0.0),
                vec![],
                vec![],
            )),
            planar,
            springs,
            spring_layout: SpringLayout::Ring,
            ramp,
            gravity,
            impulse,
            tilt,
            bearing: None,
            anisotropic: None,
            pool: None,
        };
        s.reassemble();
        Ok(s)
    }

    /// The same scene on a journal bearing (`None`: back on the spring–damper). Needs a
    /// planar disk and `Omega > 0` (the film's force scale is the spin).
    pub fn with_bearing(mut self, bearing: Option<JournalSupport>) -> Result<Self> {
        if let Some(b) = &bearing {
            b.validate()?;
            if self.tilt.is_some() {
                return Err(Error::param(
                    "bearing",
                    "a bearing support carries a planar disk; the tilting disk's support is its shaft",
                ));
            }
            Self::check_bearing_spin(&self.planar)?;
        }
        self.bearing = bearing;
        self.reassemble();
        Ok(self)
    }

    /// The same scene on a ground-fixed support unequal in X and Y (`None`: back on the
    /// isotropic spring–damper). Not with a journal bearing (that is the support).
    pub fn with_anisotropic_support(mut self, axes: Option<AnisotropicAxes>) -> Result<Self> {
        if let Some(a) = &axes {
            a.validate()?;
            if self.bearing.is_some() {
                return Err(Error::param(
                    "support",
                    "a scene has one support: a journal bearing or an anisotropic spring–damper",
                ));
            }
        }
        self.anisotropic = axes;
        self.reassemble();
        Ok(self)
    }

    /// The film's force scales with the spin: `Omega > 0` (a ramp's `to` is positive by
    /// its own range).
    fn check_bearing_spin(p: &Planar) -> Result<()> {
        if !(p.omega_s > 0.0) {
            return Err(Error::param_range(
                "Omega",
                format!(
                    "must be > 0 on a bearing (the film's force scales with the spin), got {}",
                    p.omega_s
                ),
                "(0, inf)",
            ));
        }
        Ok(())
    }

    /// Assembles the model from the description: exactly the components switched on,
    /// in the order their terms are summed. A planar disk on the isotropic support runs
    /// the planar balancer's fused code ([`FusedPlanar`]).
    pub fn reassemble(&mut self) {
        let p = &self.planar;
        let n = p.n_balls();
        let m: Vec<f64> = (0..n).map(|i| p.m(i)).collect();
        let drive = match &self.ramp {
            None => Drive::Constant(p.omega_s),
            Some(r) => Drive::Ramp {
                from: p.omega_s,
                to: r.to,
                start: r.start,
                duration: r.duration,
            },
        };
        let springs = (self.springs > 0.0).then_some(BallSprings {
            kd: self.springs * p.delta * p.delta,
            layout: self.spring_layout,
        });
        if let Some(b) = &self.bearing {
            // the planar disk and free balls as components (their inertia is the planar
            // balancer's: its arrow mass solve), then the film
            let mut parts: Vec<Arc<dyn Component>> = vec![
                Arc::new(PlanarDisk { mu: p.mu }),
                Arc::new(FreeBalls {
                    zeta_b: p.zeta_b.clone(),
                    delta: p.delta,
                }),
            ];
            if let Some(s) = springs {
                parts.push(Arc::new(s));
            }
            if self.gravity != 0.0 {
                parts.push(Arc::new(Gravity { g: self.gravity }));
            }
            if let Some(f) = &self.impulse {
                parts.push(Arc::new(f.clone()));
            }
            let support = BearingSupport::new(b.clone(), p.zeta, self.pool.take());
            self.pool = support.pool().cloned();
            parts.push(Arc::new(support));
            self.model = Assembly::Composed(
                Composed::new(Layout::planar(n), drive, m, parts)
                    .with_planar_mass(p)
                    .with_modulo_turns(self.springs == 0.0),
            );
            return;
        }
        let anisotropic = self.anisotropic.as_ref().map(|a| a.support(p.zeta));
        if let (Some(support), None) = (&anisotropic, &self.tilt) {
            let mut parts: Vec<Arc<dyn Component>> = vec![
                Arc::new(PlanarDisk { mu: p.mu }),
                Arc::new(FreeBalls {
                    zeta_b: p.zeta_b.clone(),
                    delta: p.delta,
                }),
                Arc::new(support.clone()),
            ];
            if let Some(s) = springs {
                parts.push(Arc::new(s));
            }
            if let Some(f) = &self.impulse {
                parts.push(Arc::new(f.clone()));
            }
            if self.gravity != 0.0 {
                parts.push(Arc::new(Gravity { g: self.gravity }));
            }
            self.model = Assembly::Composed(
                Composed::new(Layout::planar(n), drive, m, parts)
                    .with_planar_mass(p)
                    .with_modulo_turns(self.springs == 0.0),
            );
            return;
        }
        let Some(consts) = self.rotor_consts() else {
            // the planar balancer's fused code, the effects dispatched statically, summed
            // in the order springs, load, gravity
            self.model = Assembly::Planar(PlanarAssembly::new(
                FusedPlanar { planar: p.clone() },
                drive,
                springs,
                self.impulse.clone(),
                (self.gravity != 0.0).then_some(Gravity { g: self.gravity }),
            ));
            return;
        };
        // a tilting disk's gravity is in its generated terms (it depends on the tilt)
        let mut parts: Vec<Arc<dyn Component>> = vec![
            Arc::new(FusedTilting {
                disk: TiltingDisk { consts },
                balls: TiltingBalls {
                    consts,
                    zeta_b: p.zeta_b.clone(),
                },
            }),
            match anisotropic {
                Some(a) => Arc::new(a),
                None => Arc::new(IsotropicSupport { zeta: p.zeta }),
            },
        ];
        if let Some(s) = springs {
            parts.push(Arc::new(s));
        }
        if let Some(f) = &self.impulse {
            parts.push(Arc::new(f.clone()));
        }
        self.model = Assembly::Composed(
            Composed::new(Layout::tilting(n), drive, m, parts)
                .with_modulo_turns(self.springs == 0.0),
        );
    }

    /// The assembled model.
    pub fn model(&self) -> &Assembly {
        &self.model
    }

    /// The tilting rotor's constants. `None` for a planar disk.
    fn rotor_consts(&self) -> Option<RotorConsts> {
        let tl = self.tilt.as_ref()?;
        let p = &self.planar;
        let balls: f64 = (0..p.n_balls()).map(|i| p.m(i)).sum::<f64>() / p.delta;
        let kt = tl.kappa_t();
        Some(RotorConsts {
            mh: (1.0 - p.mu - balls).max(0.0),
            mu: p.mu,
            dl: p.delta,
            idl: 1.0 / p.delta,
            jt: tl.j_t,
            jz: tl.j_z,
            kc: tl.kappa_c(),
            kt,
            cr: 2.0 * tl.zeta_r * (kt * tl.j_t).sqrt(),
            g: self.gravity,
        })
    }

    /// The same scene with its springs joined as `layout`.
    pub fn with_spring_layout(mut self, layout: SpringLayout) -> Self {
        self.spring_layout = layout;
        self.reassemble();
        self
    }

    /// The names `with_param` takes, as its error lists them.
    fn keys() -> String {
        format!(
            "{}; with a tilting disk {}; on a bearing {}",
            key_list(SCENE_OWNERS),
            key_list(&["tilting_disk"]),
            key_list(&["bearing"])
        )
    }

    /// Returns a copy with one named parameter changed (scans and continuation): a
    /// registry name ([`crate::model::params::REGISTRY`]): the planar balancer's,
    /// `springs`, `gravity`, and the tilt's `a`, `b`, `j_t`, `j_z`, `zeta_r`. The copy is
    /// revalidated and reassembled, so constants derived from the tilt follow the change.
    pub fn with_param(&self, name: &str, value: f64) -> Result<Self> {
        let p = ParamRef::parse(name).ok_or_else(|| unknown(name, "scene", &Self::keys()))?;
        self.with(p, value)
    }

    /// Whether [`Self::with_param`] takes `name`: `Ok`, or its error for that name (a
    /// tilt parameter of a scene without a tilting disk, ...), which comes before any
    /// value is looked at.
    pub fn check_param(&self, name: &str) -> Result<()> {
        let p = ParamRef::parse(name).ok_or_else(|| unknown(name, "scene", &Self::keys()))?;
        self.clone().set_field(p, 0.0)
    }

    /// [`Self::with_param`] by typed id.
    pub fn with(&self, p: ParamRef, value: f64) -> Result<Self> {
        let mut s = self.clone();
        s.set_field(p, value)?;
        let pool = s.pool.take();
        let mut out = Scene::new(s.planar, s.springs, s.ramp, s.gravity, s.impulse, s.tilt)?
            .with_spring_layout(self.spring_layout);
        // a copy whose film is unchanged shares the solvers (results do not depend on them)
        out.pool = pool;
        out.with_bearing(s.bearing)?
            .with_anisotropic_support(s.anisotropic)
    }

    /// Sets one parameter in place and reassembles, without revalidating (continuation's
    /// `dF/dp` perturbs one value); fails for a parameter the scene does not have.
    pub fn set(&mut self, p: ParamRef, value: f64) -> Result<()> {
        self.set_field(p, value)?;
        self.reassemble();
        Ok(())
    }

    /// The value of one parameter (see [`Planar::get`]); `None` when the scene has none.
    pub fn get(&self, p: ParamRef) -> Option<f64> {
        use ParamId as P;
        let (t, r, f) = (
            self.tilt.as_ref(),
            self.ramp.as_ref(),
            self.impulse.as_ref(),
        );
        match p.id {
            P::Springs => Some(self.springs),
            P::Gravity => Some(self.gravity),
            P::TiltA => t.map(|t| t.a),
            P::TiltB => t.map(|t| t.b),
            P::TiltJt => t.map(|t| t.j_t),
            P::TiltJz => t.map(|t| t.j_z),
            P::TiltZetaR => t.map(|t| t.zeta_r),
            P::RampTo => r.map(|r| r.to),
            P::RampStart => r.map(|r| r.start),
            P::RampDuration => r.map(|r| r.duration),
            P::ImpulseAmplitude => f.map(|f| f.amplitude),
            P::ImpulseT0 => f.map(|f| f.t0),
            P::ImpulseSharpness => f.map(|f| f.sharpness),
            P::ImpulseAngle => f.map(|f| f.angle),
            P::Rho => self.bearing.as_ref().map(|b| b.rho),
            P::GrooveDepth => self.grooves().map(|g| g.depth),
            P::GrooveAngle => self.grooves().map(|g| g.angle.to_degrees()),
            _ => self.planar.get(p),
        }
    }

    /// The bearing's grooves, if it has any.
    fn grooves(&self) -> Option<&crate::model::bearing::Grooves> {
        match &self.bearing.as_ref()?.film {
            SupportFilm::Reynolds(b) => b.grooves.as_ref(),
            SupportFilm::Linear { .. } => None,
        }
    }

    fn set_field(&mut self, p: ParamRef, value: f64) -> Result<()> {
        use ParamId as P;
        let missing = |what: &str| {
            Error::param(
                p.name(),
                format!("is a {what} parameter, and the scene has no {what}"),
            )
        };
        let slot: &mut f64 = match p.id {
            P::Springs => &mut self.springs,
            P::Gravity => &mut self.gravity,
            P::TiltA | P::TiltB | P::TiltJt | P::TiltJz | P::TiltZetaR => {
                let Some(t) = self.tilt.as_mut() else {
                    return Err(Error::param(
                        p.name(),
                        "is a tilt parameter, and the scene has no tilting disk",
                    ));
                };
                match p.id {
                    P::TiltA => &mut t.a,
                    P::TiltB => &mut t.b,
                    P::TiltJt => &mut t.j_t,
                    P::TiltJz => &mut t.j_z,
                    _ => &mut t.zeta_r,
                }
            }
            P::RampTo | P::RampStart | P::RampDuration => {
                let r = self.ramp.as_mut().ok_or_else(|| missing("ramp"))?;
                match p.id {
                    P::RampTo => &mut r.to,
                    P::RampStart => &mut r.start,
                    _ => &mut r.duration,
                }
            }
            P::ImpulseAmplitude | P::ImpulseT0 | P::ImpulseSharpness | P::ImpulseAngle => {
                let f = self.impulse.as_mut().ok_or_else(|| missing("impulse"))?;
                match p.id {
                    P::ImpulseAmplitude => &mut f.amplitude,
                    P::ImpulseT0 => &mut f.t0,
                    P::ImpulseSharpness => &mut f.sharpness,
                    _ => &mut f.angle,
                }
            }
            P::Rho => {
                let b = self
                    .bearing
                    .as_mut()
                    .ok_or_else(|| no_bearing(p.name().as_str()))?;
                &mut b.rho
            }
            P::GrooveDepth | P::GrooveAngle => {
                let b = self
                    .bearing
                    .as_mut()
                    .ok_or_else(|| no_bearing(p.name().as_str()))?;
                let g = match &mut b.film {
                    SupportFilm::Reynolds(bb) => bb.grooves.as_mut(),
                    SupportFilm::Linear { .. } => None,
                }
                .ok_or_else(|| {
                    Error::param(
                        p.name(),
                        "is a groove parameter, and the bearing has no grooves",
                    )
                })?;
                if p.id == P::GrooveAngle {
                    // degrees here, radians in the film
                    g.angle = value.to_radians();
                    return Ok(());
                }
                &mut g.depth
            }
            _ => {
                debug_assert!(PLANAR_OWNERS.contains(&p.id.spec().owner));
                return self.planar.set(p, value);
            }
        };
        *slot = value;
        Ok(())
    }

    /// `(Omega(t), Omega'(t), theta(t))`, with `theta(0) = 0`.
    #[inline]
    pub fn spin(&self, t: f64) -> (f64, f64, f64) {
        self.model.drive().spin(t).tuple()
    }
}

impl Dynamics for Scene {
    #[inline]
    fn ndof(&self) -> usize {
        self.model.ndof()
    }

    fn layout(&self) -> Layout {
        self.model.layout()
    }

    fn angles_modulo_turns(&self) -> bool {
        self.model.angles_modulo_turns()
    }

    #[inline]
    fn residual(&self, t: f64, q: &[f64], v: &[f64], a: &[f64], out: &mut [f64]) {
        self.model.residual(t, q, v, a, out)
    }

    #[inline]
    fn jacobians(&self, t: f64, q: &[f64], v: &[f64], a: &[f64], jac: Jacobians<'_>) {
        let Jacobians { k, c, m } = jac;
        self.model.jacobians(t, q, v, a, Jacobians::new(k, c, m))
    }

    #[inline]
    fn solve_mass(&self, t: f64, q: &[f64], rhs: &mut [f64]) {
        self.model.solve_mass(t, q, rhs)
    }

    #[inline]
    fn solve_mass_columns(&self, t: f64, q: &[f64], cols: &mut [f64]) {
        self.model.solve_mass_columns(t, q, cols)
    }

    #[inline]
    fn accel(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        self.model.accel(t, q, v, out)
    }

    fn time_dependence(&self) -> Option<String> {
        self.model.time_dependence()
    }

    fn base_spin(&self) -> f64 {
        self.model.base_spin()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn planar() -> Planar {
        Planar::new(0.2, 0.05, &[0.07, 0.05, 0.06], 50.0, 1.3, &[0.9, 1.1, 0.8]).unwrap()
    }

    fn state() -> ([f64; 5], [f64; 5], [f64; 5]) {
        (
            [0.3, -0.2, 0.7, -1.9, 2.4],
            [0.1, 0.4, -1.2, 0.3, 0.2],
            [0.05, -0.3, 0.2, 0.6, -0.1],
        )
    }

    #[test]
    fn effects_off_equal_the_planar_model() {
        let p = planar();
        let (q, v, a) = state();
        let ramp = Some(Ramp {
            to: 1.3,
            start: 0.0,
            duration: 5.0,
        });
        let imp = Some(Impulse {
            amplitude: 0.0,
            t0: 1.0,
            sharpness: 3.0,
            angle: 0.4,
        });
        let s = Scene::new(p.clone(), 0.0, ramp, 0.0, imp, None).unwrap();
        let (mut r1, mut r2) = ([0.0; 5], [0.0; 5]);
        for t in [0.0, 1.0, 2.5, 7.0] {
            p.residual(t, &q, &v, &a, &mut r1);
            s.residual(t, &q, &v, &a, &mut r2);
            for (x, y) in r1.iter().zip(&r2) {
                assert!((x - y).abs() < 1e-14, "{r1:?} {r2:?}");
            }
        }
    }

    fn all_effects(tilt: Option<Tilt>) -> Scene {
        Scene::new(
            planar(),
            0.3,
            Some(Ramp {
                to: 2.0,
                start: -1.0,
                duration: 4.0,
            }),
            0.7,
            Some(Impulse {
                amplitude: 2.0,
                t0: 0.5,
                sharpness: 2.0,
                angle: 0.3,
            }),
            tilt,
        )
        .unwrap()
    }

    fn tilt() -> Tilt {
        Tilt {
            a: 1.5,
            b: 2.5,
            j_t: 0.3,
            j_z: 0.5,
            zeta_r: 0.05,
        }
    }

    fn check_jacobians(s: &Scene, q: &[f64], v: &[f64], a: &[f64]) {
        let t = 0.8;
        let d = s.ndof();
        let (mut k, mut c, mut m) = (vec![0.0; d * d], vec![0.0; d * d], vec![0.0; d * d]);
        s.jacobians(t, q, v, a, Jacobians::new(&mut k, &mut c, &mut m));
        let h = 1e-5;
        for (which, jac) in [(0, &k), (1, &c), (2, &m)] {
            for j in 0..d {
                let mut plus = [q.to_vec(), v.to_vec(), a.to_vec()];
                let mut minus = plus.clone();
                plus[which][j] += h;
                minus[which][j] -= h;
                let (mut rp, mut rm) = (vec![0.0; d], vec![0.0; d]);
                s.residual(t, &plus[0], &plus[1], &plus[2], &mut rp);
                s.residual(t, &minus[0], &minus[1], &minus[2], &mut rm);
                for i in 0..d {
                    let fd = (rp[i] - rm[i]) / (2.0 * h);
                    assert!(
                        (fd - jac[i * d + j]).abs() < 1e-6 * (1.0 + fd.abs()),
                        "jacobian {which} [{i}][{j}]: fd {fd} analytic {}",
                        jac[i * d + j]
                    );
                }
            }
        }
    }

    #[test]
    fn spring_chain_is_seed_004s_potential_and_half_a_two_ball_ring() {
        // Chain of three balls: ball rows gain dV/db_i / m_i with
        // V = kd/2 [(b2 - b1 - 2pi/3)^2 + (b3 - b2 - 2pi/3)^2], written out here.
        let p = planar();
        let (q, v, a) = state();
        let k = 0.3;
        let chain = Scene::new(p.clone(), k, None, 0.0, None, None)
            .unwrap()
            .with_spring_layout(SpringLayout::Chain);
        let plain = Scene::new(p.clone(), 0.0, None, 0.0, None, None).unwrap();
        let (mut rc, mut r0) = ([0.0; 5], [0.0; 5]);
        chain.residual(0.0, &q, &v, &a, &mut rc);
        plain.residual(0.0, &q, &v, &a, &mut r0);
        let kd = k * p.delta * p.delta;
        let rest = 2.0 * PI / 3.0;
        let (s1, s2) = (q[3] - q[2] - rest, q[4] - q[3] - rest);
        let dv = [-kd * s1, kd * s1 - kd * s2, kd * s2];
        for i in 0..3 {
            let want = r0[2 + i] + dv[i] / p.m(i);
            assert!(
                (rc[2 + i] - want).abs() < 1e-12 * want.abs().max(1.0),
                "{i}: {} {want}",
                rc[2 + i]
            );
        }
        assert_eq!(&rc[..2], &r0[..2]);
        check_jacobians(&chain, &q, &v, &a);
        // Two balls: the ring's two springs are one spring of twice the stiffness.
        let p2 = Planar::new(0.2, 0.05, &[0.07], 50.0, 1.3, &[0.9, 1.1]).unwrap();
        let ring = Scene::new(p2.clone(), k, None, 0.0, None, None).unwrap();
        let chain2 = Scene::new(p2, 2.0 * k, None, 0.0, None, None)
            .unwrap()
            .with_spring_layout(SpringLayout::Chain);
        let (q, v, a) = (
            [0.3, -0.2, 0.7, 2.4],
            [0.1, 0.4, -1.2, 0.3],
            [0.0, 0.1, 0.2, -0.3],
        );
        let (mut x, mut y) = ([0.0; 4], [0.0; 4]);
        ring.residual(0.0, &q, &v, &a, &mut x);
        chain2.residual(0.0, &q, &v, &a, &mut y);
        for i in 0..4 {
            assert!((x[i] - y[i]).abs() < 1e-12 * (1.0 + x[i].abs()));
        }
    }

    #[test]
    fn jacobians_match_finite_differences() {
        let (q, v, a) = state();
        check_jacobians(&all_effects(None), &q, &v, &a);
    }

    #[test]
    fn tilting_jacobians_match_finite_differences() {
        let q = [0.3, -0.2, 0.8, -0.6, 0.7, -1.9, 2.4];
        let v = [0.1, 0.4, -0.3, 0.5, -1.2, 0.3, 0.2];
        let a = [0.05, -0.3, 0.2, -0.1, 0.2, 0.6, -0.1];
        check_jacobians(&all_effects(Some(tilt())), &q, &v, &a);
    }

    fn anisotropic() -> Option<AnisotropicAxes> {
        Some(AnisotropicAxes {
            k_x: 0.7,
            k_y: 2.3,
            zeta_x: Some(0.11),
            zeta_y: None,
        })
    }

    #[test]
    fn anisotropic_jacobians_match_finite_differences() {
        let (q, v, a) = state();
        let s = all_effects(None)
            .with_anisotropic_support(anisotropic())
            .unwrap();
        check_jacobians(&s, &q, &v, &a);
        let q = [0.3, -0.2, 0.8, -0.6, 0.7, -1.9, 2.4];
        let v = [0.1, 0.4, -0.3, 0.5, -1.2, 0.3, 0.2];
        let a = [0.05, -0.3, 0.2, -0.1, 0.2, 0.6, -0.1];
        let s = all_effects(Some(tilt()))
            .with_anisotropic_support(anisotropic())
            .unwrap();
        check_jacobians(&s, &q, &v, &a);
    }

    #[test]
    fn anisotropic_support_is_the_ground_force_turned_into_the_disk() {
        // the support rows less the isotropic scene's (spring 1, damping zeta) are the
        // ground force -(k_x X + 2 z_x X', k_y Y + 2 z_y Y') rotated into the disk frame,
        // less the isotropic one; written here from the ground-frame position and velocity
        let p = planar();
        let (q, v, a) = state();
        let plain = Scene::new(p.clone(), 0.0, None, 0.0, None, None).unwrap();
        let aniso = plain
            .clone()
            .with_anisotropic_support(anisotropic())
            .unwrap();
        assert_eq!(
            aniso.time_dependence().as_deref(),
            Some("anisotropic_support")
        );
        let t = 0.9;
        let (mut r0, mut r1) = ([0.0; 5], [0.0; 5]);
        plain.residual(t, &q, &v, &a, &mut r0);
        aniso.residual(t, &q, &v, &a, &mut r1);
        let (om, th) = (p.omega_s, p.omega_s * t);
        let (sn, cs) = th.sin_cos();
        let (x, y) = (q[0], q[1]);
        let (vx, vy) = (v[0] - om * y, v[1] + om * x);
        let (gx, gy) = (cs * x - sn * y, sn * x + cs * y);
        let (gvx, gvy) = (cs * vx - sn * vy, sn * vx + cs * vy);
        let (fx, fy) = (0.7 * gx + 2.0 * 0.11 * gvx, 2.3 * gy + 2.0 * p.zeta * gvy);
        let (rx, ry) = (cs * fx + sn * fy, -sn * fx + cs * fy);
        let iso = (x + 2.0 * p.zeta * vx, y + 2.0 * p.zeta * vy);
        assert!((r1[0] - r0[0] - (rx - iso.0)).abs() < 1e-12);
        assert!((r1[1] - r0[1] - (ry - iso.1)).abs() < 1e-12);
        for i in 2..5 {
            assert!((r1[i] - r0[i]).abs() < 1e-12 * (1.0 + r0[i].abs()));
        }
        // equal axes: autonomous, and with unit stiffness the isotropic support
        let unit = plain
            .clone()
            .with_anisotropic_support(Some(AnisotropicAxes {
                k_x: 1.0,
                k_y: 1.0,
                zeta_x: None,
                zeta_y: None,
            }))
            .unwrap();
        assert_eq!(unit.time_dependence(), None);
        let mut r2 = [0.0; 5];
        unit.residual(t, &q, &v, &a, &mut r2);
        for i in 0..5 {
            assert!((r2[i] - r0[i]).abs() < 1e-12 * (1.0 + r0[i].abs()));
        }
    }

    #[test]
    fn anisotropic_axes_out_of_range_are_named() {
        let bad = AnisotropicAxes {
            k_x: 0.0,
            k_y: 1.0,
            zeta_x: None,
            zeta_y: None,
        };
        let e = Scene::new(planar(), 0.0, None, 0.0, None, None)
            .unwrap()
            .with_anisotropic_support(Some(bad))
            .unwrap_err();
        assert!(e.to_string().contains("support.k_x"), "{e}");
    }

    #[test]
    fn tilting_mass_matrix_is_the_jacobians_m() {
        let s = all_effects(Some(tilt()));
        let q = [0.3, -0.2, 0.8, -0.6, 0.7, -1.9, 2.4];
        let v = [0.1, 0.4, -0.3, 0.5, -1.2, 0.3, 0.2];
        let (mut k, mut c, mut m) = (vec![0.0; 49], vec![0.0; 49], vec![0.0; 49]);
        s.jacobians(0.8, &q, &v, &v, Jacobians::new(&mut k, &mut c, &mut m));
        let Assembly::Composed(model) = &s.model else {
            panic!("a tilting scene is a composed model")
        };
        let alone = model.mass_matrix(0.8, &q);
        for i in 0..7 {
            for j in 0..7 {
                assert!((alone[(i, j)] - m[i * 7 + j]).abs() < 1e-14, "[{i}][{j}]");
            }
        }
    }

    #[test]
    fn centred_disk_started_flat_is_the_planar_model() {
        // a = b: no translation-tilt coupling, and nothing else tilts a flat disk.
        let centred = Tilt {
            a: 2.0,
            b: 2.0,
            ..tilt()
        };
        let (flat, tilting) = (all_effects(None), all_effects(Some(centred)));
        let (q, v, a) = state();
        let widen = |z: &[f64; 5]| vec![z[0], z[1], 0.0, 0.0, z[2], z[3], z[4]];
        let (mut r1, mut r2) = ([0.0; 5], [0.0; 7]);
        for t in [0.0, 0.4, 2.5] {
            flat.residual(t, &q, &v, &a, &mut r1);
            tilting.residual(t, &widen(&q), &widen(&v), &widen(&a), &mut r2);
            let back = [r2[0], r2[1], r2[4], r2[5], r2[6]];
            for (x, y) in r1.iter().zip(&back) {
                assert!((x - y).abs() < 1e-12 * (1.0 + x.abs()), "{r1:?} {r2:?}");
            }
            assert!(r2[2].abs() < 1e-12 && r2[3].abs() < 1e-12, "{r2:?}");
        }
    }

    #[test]
    fn tilt_stiffness_is_beam_theory() {
        // disk at mid-span of length L: k = 48 EI / L^3, k_phiphi = 12 EI / L
        let t = Tilt {
            a: 2.0,
            b: 2.0,
            ..tilt()
        };
        let l: f64 = 4.0;
        assert!(t.kappa_c().abs() < 1e-15);
        assert!((t.kappa_t() - (12.0 / l) / (48.0 / l.powi(3))).abs() < 1e-12);
        let e = Scene::new(
            planar(),
            0.0,
            None,
            0.0,
            None,
            Some(Tilt { j_z: 0.7, ..tilt() }),
        )
        .unwrap_err();
        assert!(e.to_string().starts_with("tilt.j_z"), "{e}");
    }

    #[test]
    fn spin_profile_is_continuous_and_integrates() {
        let s = Scene::new(
            planar(),
            0.0,
            Some(Ramp {
                to: 2.3,
                start: 1.0,
                duration: 2.0,
            }),
            0.0,
            None,
            None,
        )
        .unwrap();
        // theta' = Omega, checked by central differences across the three pieces
        for t in [0.5, 1.0, 1.7, 3.0, 4.2] {
            let h = 1e-6;
            let (w, _, _) = s.spin(t);
            let d = (s.spin(t + h).2 - s.spin(t - h).2) / (2.0 * h);
            assert!((d - w).abs() < 1e-6, "t {t}: {d} vs {w}");
        }
        assert_eq!(s.spin(10.0).0, 2.3);
        assert_eq!(s.time_dependence().as_deref(), Some("ramp"));
    }

    #[test]
    fn bad_effect_parameters_name_themselves() {
        let e = Scene::new(planar(), -1.0, None, 0.0, None, None).unwrap_err();
        assert!(e.to_string().starts_with("springs"), "{e}");
        let one = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.3, &[1.0]).unwrap();
        let e = Scene::new(one, 0.5, None, 0.0, None, None).unwrap_err();
        assert!(e.to_string().starts_with("springs"), "{e}");
        let r = Some(Ramp {
            to: 1.0,
            start: 0.0,
            duration: 0.0,
        });
        let e = Scene::new(planar(), 0.0, r, 0.0, None, None).unwrap_err();
        assert!(e.to_string().starts_with("ramp.duration"), "{e}");
    }
}
