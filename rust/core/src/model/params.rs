//! The parameter registry: every scalar a model takes, with its name, the component
//! that owns it and its allowed range, in one table. Validation (`Planar::new`,
//! `Scene::new`), `with_param` by name and typed access ([`ParamRef`], for scans and,
//! next, continuation's `dF/dp`) all read it, so a parameter is declared once.

use crate::error::{check_range, Error, Result};

/// A typed parameter id. Per-ball parameters (`eta`, `zeta_b`) take a ball index in
/// [`ParamRef`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ParamId {
    Mu,
    Zeta,
    ZetaB,
    Delta,
    Omega,
    Eta,
    Springs,
    Gravity,
    TiltA,
    TiltB,
    TiltJt,
    TiltJz,
    TiltZetaR,
    RampTo,
    RampStart,
    RampDuration,
    ImpulseAmplitude,
    ImpulseT0,
    ImpulseSharpness,
    ImpulseAngle,
    Rho,
    GrooveDepth,
    GrooveAngle,
}

/// An interval with open or closed ends; infinite ends are always open.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    pub lo: f64,
    pub lo_open: bool,
    pub hi: f64,
    pub hi_open: bool,
}

const fn iv(lo: f64, lo_open: bool, hi: f64, hi_open: bool) -> Interval {
    Interval {
        lo,
        lo_open,
        hi,
        hi_open,
    }
}

const INF: f64 = f64::INFINITY;
/// `(0, inf)`
const POSITIVE: Interval = iv(0.0, true, INF, true);
/// `[0, inf)`
const NON_NEGATIVE: Interval = iv(0.0, false, INF, true);
/// any finite number
const FINITE: Interval = iv(-INF, true, INF, true);

/// Largest `rho = e / c` of a bearing support. The journal sits at `rho |q|` clearances
/// from the centre, so at `rho = 1e3` it reaches the wall with the disk centre `1e-3 e`
/// off the axis: only the balanced state is left inside the clearance. Larger values mean
/// nothing physically, and searches from `|q| ~ 1` put the journal far outside the
/// clearance (`equilibria` at `rho = 1e5` spun without an answer).
pub const MAX_RHO: f64 = 1e3;
/// Largest groove depth over the clearance. The film's load stops changing long before
/// (a finite film with 8 grooves at `eps = 0.5`: 0.003643 `F_S` at `1e3`, 0.003642 at
/// `1e10`: a groove that deep is a reservoir), and near `1e102` the conductance `H^3`
/// overflows and the Reynolds solve fails as if the matrix were not positive definite.
pub const MAX_DEPTH_RATIO: f64 = 1e3;

/// One registry row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSpec {
    pub id: ParamId,
    /// The name errors carry (`.parameter` in Python): `"mu"`, `"tilt.a"`, `"ramp.to"`.
    pub name: &'static str,
    /// The name `with_param` and scans take, when the parameter can be varied that way.
    pub key: Option<&'static str>,
    /// The component that owns it (see [`crate::model::component`]).
    pub owner: &'static str,
    pub range: Interval,
    /// One value per ball (`eta[i]`, `zeta_b[i]`).
    pub per_ball: bool,
}

const fn spec(
    id: ParamId,
    name: &'static str,
    key: Option<&'static str>,
    owner: &'static str,
    range: Interval,
    per_ball: bool,
) -> ParamSpec {
    ParamSpec {
        id,
        name,
        key,
        owner,
        range,
        per_ball,
    }
}

use ParamId as P;

/// The registry, in the order `with_param`'s error lists the names.
pub const REGISTRY: &[ParamSpec] = &[
    spec(
        P::Mu,
        "mu",
        Some("mu"),
        "rotor",
        iv(0.0, true, 1.0, true),
        false,
    ),
    spec(
        P::Zeta,
        "zeta",
        Some("zeta"),
        "support",
        NON_NEGATIVE,
        false,
    ),
    spec(
        P::ZetaB,
        "zeta_b",
        Some("zeta_b"),
        "balls",
        NON_NEGATIVE,
        true,
    ),
    spec(P::Delta, "delta", Some("delta"), "balls", POSITIVE, false),
    spec(
        P::Omega,
        "Omega",
        Some("Omega"),
        "drive",
        NON_NEGATIVE,
        false,
    ),
    spec(P::Eta, "eta", Some("eta"), "balls", POSITIVE, true),
    spec(
        P::Springs,
        "springs",
        Some("springs"),
        "ball_springs",
        NON_NEGATIVE,
        false,
    ),
    spec(
        P::Gravity,
        "gravity",
        Some("gravity"),
        "gravity",
        NON_NEGATIVE,
        false,
    ),
    spec(
        P::TiltA,
        "tilt.a",
        Some("a"),
        "tilting_disk",
        POSITIVE,
        false,
    ),
    spec(
        P::TiltB,
        "tilt.b",
        Some("b"),
        "tilting_disk",
        POSITIVE,
        false,
    ),
    spec(
        P::TiltJt,
        "tilt.j_t",
        Some("j_t"),
        "tilting_disk",
        POSITIVE,
        false,
    ),
    // also at most 2 j_t: checked with the tilt (a range that depends on another value)
    spec(
        P::TiltJz,
        "tilt.j_z",
        Some("j_z"),
        "tilting_disk",
        NON_NEGATIVE,
        false,
    ),
    spec(
        P::TiltZetaR,
        "tilt.zeta_r",
        Some("zeta_r"),
        "tilting_disk",
        NON_NEGATIVE,
        false,
    ),
    spec(P::RampTo, "ramp.to", None, "drive", POSITIVE, false),
    spec(P::RampStart, "ramp.start", None, "drive", FINITE, false),
    spec(
        P::RampDuration,
        "ramp.duration",
        None,
        "drive",
        POSITIVE,
        false,
    ),
    spec(
        P::ImpulseAmplitude,
        "impulse.amplitude",
        None,
        "impulse",
        FINITE,
        false,
    ),
    spec(P::ImpulseT0, "impulse.t0", None, "impulse", FINITE, false),
    spec(
        P::ImpulseSharpness,
        "impulse.sharpness",
        None,
        "impulse",
        POSITIVE,
        false,
    ),
    spec(
        P::ImpulseAngle,
        "impulse.angle",
        None,
        "impulse",
        FINITE,
        false,
    ),
    // the journal-bearing support: e / c, and its grooves (angle in degrees from the
    // circumferential direction, as ballbal.bearing.Grooves gives it)
    spec(
        P::Rho,
        "rho",
        Some("rho"),
        "bearing",
        iv(0.0, true, MAX_RHO, false),
        false,
    ),
    spec(
        P::GrooveDepth,
        "grooves.depth_ratio",
        Some("depth_ratio"),
        "bearing",
        iv(0.0, false, MAX_DEPTH_RATIO, false),
        false,
    ),
    spec(
        P::GrooveAngle,
        "grooves.angle",
        Some("groove_angle"),
        "bearing",
        iv(0.0, true, 90.0, false),
        false,
    ),
];

impl ParamId {
    /// This id's registry row.
    pub fn spec(self) -> &'static ParamSpec {
        REGISTRY
            .iter()
            .find(|s| s.id == self)
            .expect("every ParamId has a registry row")
    }

    /// Checks `v` against the registered range, reporting it under `name`.
    pub fn check_named(self, name: &str, v: f64) -> Result<()> {
        let r = self.spec().range;
        check_range(name, v, r.lo, r.lo_open, r.hi, r.hi_open)
    }

    /// Checks `v` against the registered range under the registered name.
    pub fn check(self, v: f64) -> Result<()> {
        self.check_named(self.spec().name, v)
    }

    /// Checks per-ball values, named `name[i]` (or `name` when one value is shared).
    pub fn check_balls(self, values: &[f64], shared: bool) -> Result<()> {
        let base = self.spec().name;
        for (i, &v) in values.iter().enumerate() {
            if shared {
                self.check_named(base, v)?;
            } else {
                self.check_named(&format!("{base}[{i}]"), v)?;
            }
        }
        Ok(())
    }
}

/// A parameter as a model is asked for it: the id, and for a per-ball parameter either
/// one ball or (`None`) all of them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ParamRef {
    pub id: ParamId,
    pub ball: Option<usize>,
}

impl From<ParamId> for ParamRef {
    fn from(id: ParamId) -> Self {
        ParamRef { id, ball: None }
    }
}

impl ParamRef {
    /// Looks a `with_param` name up: `"mu"`, `"a"`, `"eta"` (every ball), `"eta[2]"` (the third ball: balls count from 0, as everywhere in ballbal).
    pub fn parse(name: &str) -> Option<ParamRef> {
        for s in REGISTRY {
            let Some(key) = s.key else { continue };
            if name == key {
                return Some(s.id.into());
            }
            if s.per_ball {
                if let Some(i) = indexed(name, key) {
                    return Some(ParamRef {
                        id: s.id,
                        ball: Some(i),
                    });
                }
            }
        }
        None
    }

    /// The `with_param` name (`"eta[2]"`), or the registered name when it has none.
    pub fn name(&self) -> String {
        let s = self.id.spec();
        let base = s.key.unwrap_or(s.name);
        match self.ball {
            Some(i) => format!("{base}[{i}]"),
            None => base.to_string(),
        }
    }
}

/// The `with_param` names of the parameters owned by `owners`, as an error lists them:
/// `mu, zeta, zeta_b, ..., eta[i], zeta_b[i]` (per-ball forms last).
pub fn key_list(owners: &[&str]) -> String {
    let rows = || {
        REGISTRY
            .iter()
            .filter(|s| s.key.is_some() && owners.contains(&s.owner))
    };
    let mut names: Vec<String> = rows().map(|s| s.key.unwrap().to_string()).collect();
    names.extend(
        rows()
            .filter(|s| s.per_ball)
            .map(|s| format!("{}[i]", s.key.unwrap())),
    );
    names.join(", ")
}

/// The error for a name that is not in the registry (or not of this model).
pub fn unknown(name: &str, model: &str, owners: &str) -> Error {
    Error::param(
        name,
        format!("is not a parameter of the {model} ({owners})"),
    )
}

fn indexed(name: &str, base: &str) -> Option<usize> {
    let rest = name
        .strip_prefix(base)?
        .strip_prefix('[')?
        .strip_suffix(']')?;
    rest.parse().ok()
}

/// The components of the planar balancer, as the registry names them.
pub const PLANAR_OWNERS: &[&str] = &["rotor", "support", "balls", "drive"];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_id_has_one_row_and_names_parse_back() {
        for s in REGISTRY {
            assert_eq!(REGISTRY.iter().filter(|t| t.id == s.id).count(), 1);
            if let Some(k) = s.key {
                assert_eq!(ParamRef::parse(k), Some(s.id.into()));
            }
        }
        assert_eq!(
            ParamRef::parse("zeta_b[3]"),
            Some(ParamRef {
                id: ParamId::ZetaB,
                ball: Some(3)
            })
        );
        assert_eq!(ParamRef::parse("mu[1]"), None);
        assert_eq!(ParamRef::parse("ramp.to"), None);
        assert_eq!(
            key_list(PLANAR_OWNERS),
            "mu, zeta, zeta_b, delta, Omega, eta, zeta_b[i], eta[i]"
        );
    }

    #[test]
    fn ranges_reject_their_ends_and_nan() {
        assert!(ParamId::Mu.check(1.0).is_err());
        assert!(ParamId::Mu.check(0.0).is_err());
        assert!(ParamId::Zeta.check(0.0).is_ok());
        assert!(ParamId::Omega.check(f64::NAN).is_err());
        match ParamId::TiltA.check(-1.0) {
            Err(Error::InvalidParameter { name, allowed, .. }) => {
                assert_eq!(name, "tilt.a");
                assert_eq!(allowed.as_deref(), Some("(0, inf)"));
            }
            other => panic!("{other:?}"),
        }
    }
}
