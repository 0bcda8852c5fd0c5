//! Python objects into core values: the model (`ballbal.Balancer` / `ballbal.Scene`)
//! and the option dataclasses of `ballbal.options`, read by attribute, and NumPy arrays.
//! Values are not checked here: the core's constructors and `validate` do that, once.

use crate::bearing::BearingArgs;
use crate::errors::CoreResult;
use ballbal_core::floquet::{FloquetMethod, FloquetOptions, HillTarget};
use ballbal_core::hb::HbOptions;
use ballbal_core::model::components::{JournalSupport, SupportFilm};
use ballbal_core::model::scene::{AnisotropicAxes, Impulse, Ramp, Tilt};
use ballbal_core::periodic::{AutoHarmonics, GuessOptions, PeriodicOptions};
use ballbal_core::{Dynamics, Error, Planar, Scene, SpringLayout};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;

/// One number shared by all balls, or one per ball (`Balancer.zeta_b`).
#[derive(FromPyObject)]
enum Reals {
    One(f64),
    Many(Vec<f64>),
}

/// `ballbal.Balancer`'s fields.
#[derive(FromPyObject)]
pub struct BalancerArgs {
    mu: f64,
    zeta: f64,
    zeta_b: Reals,
    delta: f64,
    #[pyo3(attribute("Omega"))]
    omega: f64,
    eta: Vec<f64>,
}

#[derive(FromPyObject)]
struct RampArgs {
    to: f64,
    start: f64,
    duration: f64,
}

#[derive(FromPyObject)]
struct ImpulseArgs {
    amplitude: f64,
    t0: f64,
    sharpness: f64,
    angle: f64,
}

#[derive(FromPyObject)]
struct TiltArgs {
    a: f64,
    b: f64,
    j_t: f64,
    j_z: f64,
    zeta_r: f64,
}

/// `ballbal.BearingSupport`'s fields: the film and `rho = e / c`.
#[derive(FromPyObject)]
struct SupportArgs {
    bearing: BearingArgs,
    rho: f64,
}

/// `ballbal.AnisotropicSupport`'s fields (a `None` damping is the balancer's `zeta`).
#[derive(FromPyObject)]
struct AnisotropicArgs {
    k_x: f64,
    k_y: f64,
    zeta_x: Option<f64>,
    zeta_y: Option<f64>,
}

/// The scene's `support`: a journal bearing or an anisotropic spring–damper (tried in
/// that order: only the bearing has `bearing`).
#[derive(FromPyObject)]
enum SupportKind {
    Bearing(SupportArgs),
    Anisotropic(AnisotropicArgs),
}

/// `ballbal.Scene`'s fields.
#[derive(FromPyObject)]
pub struct SceneArgs {
    balancer: BalancerArgs,
    springs: f64,
    ramp: Option<RampArgs>,
    gravity: f64,
    impulse: Option<ImpulseArgs>,
    tilt: Option<TiltArgs>,
    spring_layout: String,
    support: Option<SupportKind>,
}

/// What every analysis takes first. A scene is tried first: a balancer has no
/// `balancer` attribute.
// Read once per call (pyo3 cannot extract into a box): the size difference costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(FromPyObject)]
pub enum ModelArgs {
    Scene(SceneArgs),
    Balancer(BalancerArgs),
}

/// A built, validated core model: the planar code when no effect is on.
// Built once per call and matched by reference: the size difference costs nothing.
#[allow(clippy::large_enum_variant)]
pub enum Model {
    Planar(Planar),
    Scene(Scene),
}

/// `dispatch!(model, m => expr)`: `expr` with `m` the planar balancer or the scene, the
/// one place an entry point chooses between the two (each arm is its own
/// monomorphisation, so the planar code runs at full speed).
macro_rules! dispatch {
    ($model:expr, $m:ident => $e:expr) => {
        match $model {
            $crate::convert::Model::Planar($m) => $e,
            $crate::convert::Model::Scene($m) => $e,
        }
    };
}
pub(crate) use dispatch;

impl BalancerArgs {
    pub fn planar(&self) -> Result<Planar, Error> {
        let zb = match &self.zeta_b {
            Reals::One(v) => vec![*v],
            Reals::Many(v) => v.clone(),
        };
        Planar::new(self.mu, self.zeta, &zb, self.delta, self.omega, &self.eta)
    }
}

impl SceneArgs {
    fn effects_on(&self) -> bool {
        self.springs != 0.0
            || self.ramp.is_some()
            || self.gravity != 0.0
            || self.impulse.is_some()
            || self.tilt.is_some()
            || self.support.is_some()
    }

    fn scene(&self, p: Planar) -> Result<Scene, Error> {
        let layout = match self.spring_layout.as_str() {
            "ring" => SpringLayout::Ring,
            "chain" => SpringLayout::Chain,
            other => {
                return Err(Error::param_range(
                    "spring_layout",
                    format!("must be 'ring' or 'chain', got {other:?}"),
                    "ring, chain",
                ))
            }
        };
        Scene::new(
            p,
            self.springs,
            self.ramp.as_ref().map(|r| Ramp {
                to: r.to,
                start: r.start,
                duration: r.duration,
            }),
            self.gravity,
            self.impulse.as_ref().map(|i| Impulse {
                amplitude: i.amplitude,
                t0: i.t0,
                sharpness: i.sharpness,
                angle: i.angle,
            }),
            self.tilt.as_ref().map(|t| Tilt {
                a: t.a,
                b: t.b,
                j_t: t.j_t,
                j_z: t.j_z,
                zeta_r: t.zeta_r,
            }),
        )
        .map(|s| s.with_spring_layout(layout))?
        .with_bearing(match &self.support {
            Some(SupportKind::Bearing(b)) => Some(JournalSupport {
                film: SupportFilm::Reynolds(b.bearing.to_core()?),
                rho: b.rho,
            }),
            _ => None,
        })?
        .with_anisotropic_support(match &self.support {
            Some(SupportKind::Anisotropic(a)) => Some(AnisotropicAxes {
                k_x: a.k_x,
                k_y: a.k_y,
                zeta_x: a.zeta_x,
                zeta_y: a.zeta_y,
            }),
            _ => None,
        })
    }
}

impl ModelArgs {
    /// The core model, validated by its constructors. A scene with every effect off is
    /// the planar balancer unless `always_scene` (a scan that varies a scene parameter,
    /// the balanced state, which is defined on scenes).
    pub fn build(&self, always_scene: bool) -> Result<Model, Error> {
        match self {
            ModelArgs::Balancer(b) => {
                let p = b.planar()?;
                if always_scene {
                    Ok(Model::Scene(Scene::new(p, 0.0, None, 0.0, None, None)?))
                } else {
                    Ok(Model::Planar(p))
                }
            }
            ModelArgs::Scene(s) => {
                let p = s.balancer.planar()?;
                if always_scene || s.effects_on() {
                    Ok(Model::Scene(s.scene(p)?))
                } else {
                    Ok(Model::Planar(p))
                }
            }
        }
    }
}

impl Model {
    pub fn n_balls(&self) -> usize {
        match self {
            Model::Planar(p) => p.n_balls(),
            Model::Scene(s) => s.planar.n_balls(),
        }
    }
}

/// `ballbal.options.HarmonicBalance`, with `N = "auto"` read through its properties.
#[derive(FromPyObject)]
pub struct HarmonicBalanceArgs {
    #[pyo3(attribute("_start"))]
    start: usize,
    #[pyo3(attribute("_auto_target"))]
    auto_target: Option<f64>,
    #[pyo3(attribute("N_max"))]
    n_max: usize,
    samples: Option<usize>,
    tol: f64,
    step_tol: f64,
    max_iter: usize,
}

/// `ballbal.options.Floquet`.
#[derive(FromPyObject)]
pub struct FloquetArgs {
    method: String,
    rtol: f64,
    atol: f64,
    margin: f64,
    max_steps: usize,
    max_trivial: f64,
    monodromy: bool,
    hill: bool,
    hill_target: String,
    hill_band: Option<f64>,
    refine: bool,
}

/// `ballbal.options.GuessSearch`.
#[derive(FromPyObject)]
pub struct GuessArgs {
    settle: f64,
    window: f64,
    rtol: f64,
    atol: f64,
    pub seeds: usize,
    pub starts: usize,
}

/// `ballbal.options.PeriodicOptions`, and the mathematical part of `ScanOptions`
/// (which adds `block`, read by the scan's entry point).
#[derive(FromPyObject)]
pub struct PeriodicArgs {
    harmonic_balance: HarmonicBalanceArgs,
    floquet: FloquetArgs,
    pub guess: GuessArgs,
    max_closure: f64,
    max_tail: f64,
}

impl PeriodicArgs {
    /// The core's options, validated before any work starts; errors name the option.
    /// [`Self::to_core`], checked against the model's size (the harmonic-balance system
    /// it would build).
    pub fn to_core_for(&self, m: &Model) -> PyResult<PeriodicOptions> {
        let opts = self.to_core()?;
        let ndof = dispatch!(m, x => x.ndof());
        opts.validate_for(ndof).py()?;
        Ok(opts)
    }

    pub fn to_core(&self) -> PyResult<PeriodicOptions> {
        let mut opts = PeriodicOptions {
            max_closure: self.max_closure,
            max_tail: self.max_tail,
            ..Default::default()
        };
        self.harmonic_balance.apply(&mut opts);
        self.floquet.apply(&mut opts)?;
        self.guess.apply(&mut opts);
        opts.validate().py()?;
        Ok(opts)
    }
}

impl HarmonicBalanceArgs {
    /// Sets the harmonic-balance part of `opts` (`hb`, `auto`).
    fn apply(&self, opts: &mut PeriodicOptions) {
        opts.auto = self.auto_target.map(|target| AutoHarmonics {
            target,
            n_max: self.n_max,
        });
        opts.hb = HbOptions {
            n_harm: self.start,
            samples: self.samples,
            tol: self.tol,
            step_tol: self.step_tol,
            max_iter: self.max_iter,
        };
    }
}

impl FloquetArgs {
    /// Sets the stability part of `opts` (the monodromy's options and Hill's); the
    /// monodromy's options are checked even with it off: a bad value is a mistake
    /// either way.
    fn apply(&self, opts: &mut PeriodicOptions) -> PyResult<()> {
        let fo = FloquetOptions {
            method: FloquetMethod::parse(&self.method).py()?,
            rtol: self.rtol,
            atol: self.atol,
            margin: self.margin,
            max_steps: self.max_steps,
            max_trivial: self.max_trivial,
        };
        fo.validate().py()?;
        opts.hill = self.hill;
        opts.hill_judging = Some((self.margin, self.max_trivial));
        opts.hill_target = HillTarget::parse(&self.hill_target).py()?;
        opts.hill_band = self.hill_band;
        opts.refine_verdicts = self.refine;
        opts.floquet = self.monodromy.then_some(fo);
        Ok(())
    }
}

impl GuessArgs {
    /// Sets the start search's part of `opts`.
    fn apply(&self, opts: &mut PeriodicOptions) {
        opts.guess = GuessOptions {
            settle: self.settle,
            window: self.window,
            rtol: self.rtol,
            atol: self.atol,
        };
    }
}

/// One option dataclass checked on its own when it is made: its part set into the
/// core's default options (valid by construction), so that every error is this part's
/// and the checks stay the core's ([`PeriodicOptions::validate`]).
pub fn validate_part(set: impl FnOnce(&mut PeriodicOptions) -> PyResult<()>) -> PyResult<()> {
    let mut opts = PeriodicOptions::default();
    set(&mut opts)?;
    opts.validate().py()
}

/// [`validate_part`] of `ballbal.options.HarmonicBalance`.
pub fn validate_harmonic_balance(h: &HarmonicBalanceArgs) -> PyResult<()> {
    validate_part(|o| {
        h.apply(o);
        Ok(())
    })
}

/// [`validate_part`] of `ballbal.options.Floquet`.
pub fn validate_floquet(f: &FloquetArgs) -> PyResult<()> {
    validate_part(|o| f.apply(o))
}

/// [`validate_part`] of `ballbal.options.GuessSearch`.
pub fn validate_guess(g: &GuessArgs) -> PyResult<()> {
    validate_part(|o| {
        g.apply(o);
        Ok(())
    })
}

/// A contiguous float64 array's values.
pub fn slice<'a>(a: &'a PyReadonlyArray1<'_, f64>, name: &str) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|_| Error::param(name, "must be a contiguous float64 array"))
        .py()
}
