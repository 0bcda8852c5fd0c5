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
    /// One value per ball (`eta1`, `zeta_b2`: balls are named from 1, as the
    /// coordinates `b1`, `b2` are).
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

    /// Checks per-ball values, named `name1`, `name2`, ... (or `name` when one value is
    /// shared).
    pub fn check_balls(self, values: &[f64], shared: bool) -> Result<()> {
        let base = self.spec().name;
        for (i, &v) in values.iter().enumerate() {
            if shared {
                self.check_named(base, v)?;
            } else {
                self.check_named(&ball_name(base, i), v)?;
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
    /// Looks a `with_param` name up: `"mu"`, `"a"`, `"eta"` (every ball), `"eta3"` (the
    /// third ball: balls are named from 1, as the coordinates `b1`, `b2` are).
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

    /// The `with_param` name (`"eta3"` for the third ball), or the registered name when
    /// it has none.
    pub fn name(&self) -> String {
        let s = self.id.spec();
        let base = s.key.unwrap_or(s.name);
        match self.ball {
            Some(i) => ball_name(base, i),
            None => base.to_string(),
        }
    }
}

/// A per-ball parameter's name for the ball at index `i` (from 0): `eta1` for `i = 0`.
/// Names count balls from 1, as the coordinates `b1`, `b2` and the rates `rate1` do, so
/// that `eta1` is the ball whose angle is `b1`.
pub fn ball_name(base: &str, i: usize) -> String {
    format!("{base}{}", i + 1)
}

/// The `with_param` names of the parameters owned by `owners`, as an error lists them:
/// `mu, zeta, zeta_b, ..., eta<k>, zeta_b<k>` (per-ball forms last; `k` from 1).
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
            .map(|s| format!("{}<k>", s.key.unwrap())),
    );
    names.join(", ")
}

/// The error for a name that is not in the registry (or not of this model). A ball
/// written with an index in brackets (`eta[0]`, Python's indexing of `Balancer.eta`) is
/// told the name it meant.
pub fn unknown(name: &str, model: &str, owners: &str) -> Error {
    Error::param(
        name,
        format!(
            "is not a parameter of the {model} ({owners}){}",
            ball_hint(name)
        ),
    )
}

/// For a ball written with an index in brackets (`eta[0]`), the sentence that tells the
/// name it meant; empty for any other name.
pub fn ball_hint(name: &str) -> String {
    bracketed(name)
        .map(|(base, i)| {
            format!(
                "; balls are named from 1 without brackets: {} is the ball at index {i}",
                ball_name(base, i)
            )
        })
        .unwrap_or_default()
}

/// The ball index of `name` = `base` followed by its number from 1 (`eta1` -> 0); `None`
/// for `eta0`, a leading zero (`eta01`) or anything else.
fn indexed(name: &str, base: &str) -> Option<usize> {
    let rest = name.strip_prefix(base)?;
    if rest.starts_with('0') || !rest.bytes().all(|c| c.is_ascii_digit()) {
        return None;
    }
    rest.parse::<usize>().ok()?.checked_sub(1)
}

/// `eta[2]` -> (`eta`, 2) for a per-ball key: the bracketed form that names balls from 0.
fn bracketed(name: &str) -> Option<(&'static str, usize)> {
    let (base, rest) = name.split_once('[')?;
    let i = rest.strip_suffix(']')?.parse().ok()?;
    REGISTRY
        .iter()
        .filter(|s| s.per_ball)
        .find_map(|s| s.key.filter(|k| *k == base))
        .map(|k| (k, i))
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
            ParamRef::parse("zeta_b4"),
            Some(ParamRef {
                id: ParamId::ZetaB,
                ball: Some(3)
            })
        );
        assert_eq!(ParamRef::parse("zeta_b4").unwrap().name(), "zeta_b4");
        for refused in [
            "zeta_b[3]",
            "eta0",
            "eta01",
            "eta1.5",
            "eta-1",
            "mu1",
            "mu[1]",
        ] {
            assert_eq!(ParamRef::parse(refused), None, "{refused}");
        }
        let hint = unknown("eta[0]", "planar balancer", "").to_string();
        assert!(hint.contains("eta1 is the ball at index 0"), "{hint}");
        assert_eq!(ParamRef::parse("ramp.to"), None);
        assert_eq!(
            key_list(PLANAR_OWNERS),
            "mu, zeta, zeta_b, delta, Omega, eta, zeta_b<k>, eta<k>"
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
