//! The one vocabulary of the events located on branches: every branch (equilibria,
//! periodic solutions), curve and branch switch names an event by [`Event::name`], and
//! reads a name the user gives with [`Event::parse`], which also takes AUTO's
//! abbreviations (`LP`, `BP`, `HB`, `PD`, `NS` / `TR`), in any case. The binding serves
//! [`VOCABULARY`] to Python, so that no list of names is kept twice.

use crate::continuation::Controls;
use crate::{Error, Result};

/// A codimension-one bifurcation (or the end of a branch of periodic orbits, or a point
/// the user asked for) located between two points of a branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Event {
    /// The branch turns back in its parameter (a limit point): a real eigenvalue (a
    /// multiplier, for a periodic orbit, other than the trivial one) passes 0 (+1), and
    /// two solutions meet.
    Fold,
    /// Another branch crosses this one (a pitchfork or transcritical point): the
    /// bordered Jacobian is singular while the branch goes on.
    BranchPoint,
    /// A complex pair of eigenvalues of an equilibrium crosses the imaginary axis: an
    /// orbit of that frequency is born.
    Hopf,
    /// A real multiplier of a periodic orbit passes -1: an orbit of twice the period
    /// is born (flip).
    PeriodDoubling,
    /// A complex pair of multipliers of a periodic orbit crosses the unit circle: a
    /// torus is born (AUTO's torus bifurcation, `TR`).
    NeimarkSacker,
    /// The orbit's period grows without bound at the branch's end: the orbit meets an
    /// equilibrium (a saddle-node on the invariant circle or a homoclinic orbit).
    InfinitePeriod,
    /// Not a bifurcation: the point at a parameter value the user asked for (a branch's
    /// `at=`, AUTO's `UZ`), solved there exactly.
    User,
}

/// One entry of the vocabulary: the canonical name, the other spellings read as it,
/// and what it means.
#[derive(Debug, Clone, Copy)]
pub struct EventName {
    pub event: Event,
    pub name: &'static str,
    pub aliases: &'static [&'static str],
    pub meaning: &'static str,
}

/// Every event, in the order the docs list them.
pub const VOCABULARY: [EventName; 7] = [
    EventName {
        event: Event::Fold,
        name: "fold",
        aliases: &["LP", "SN", "saddle_node", "limit_point"],
        meaning: "the branch turns back in its parameter (an eigenvalue passes 0, a \
                  multiplier +1)",
    },
    EventName {
        event: Event::BranchPoint,
        name: "branch_point",
        aliases: &["BP", "pitchfork"],
        meaning: "another branch crosses this one (the bordered Jacobian is singular)",
    },
    EventName {
        event: Event::Hopf,
        name: "hopf",
        aliases: &["HB", "H"],
        meaning: "a complex pair of eigenvalues of an equilibrium crosses the imaginary \
                  axis",
    },
    EventName {
        event: Event::PeriodDoubling,
        name: "period_doubling",
        aliases: &["PD", "flip"],
        meaning: "a multiplier of a periodic orbit passes -1",
    },
    EventName {
        event: Event::NeimarkSacker,
        name: "neimark_sacker",
        aliases: &["NS", "TR", "torus"],
        meaning: "a complex pair of multipliers of a periodic orbit crosses the unit \
                  circle",
    },
    EventName {
        event: Event::InfinitePeriod,
        name: "infinite_period",
        aliases: &["IP"],
        meaning: "the period of a periodic orbit grows without bound (the orbit meets \
                  an equilibrium)",
    },
    EventName {
        event: Event::User,
        name: "user",
        aliases: &["UZ", "user_point"],
        meaning: "the point at a parameter value asked for with at= (not a bifurcation), \
                  solved there with the parameter fixed",
    },
];

impl Event {
    fn entry(self) -> &'static EventName {
        VOCABULARY
            .iter()
            .find(|e| e.event == self)
            .expect("every event is in the vocabulary")
    }

    /// The canonical (lower-case) name, as every table writes it.
    pub fn name(self) -> &'static str {
        self.entry().name
    }

    /// The event named `text`: a canonical name or an alias, in any case, `-` or a
    /// space read as `_`. An unknown name is an error about `parameter`, listing the
    /// names.
    pub fn parse(text: &str, parameter: &str) -> Result<Event> {
        let key: String = text
            .trim()
            .chars()
            .map(|c| match c {
                '-' | ' ' => '_',
                c => c.to_ascii_lowercase(),
            })
            .collect();
        VOCABULARY
            .iter()
            .find(|e| e.name == key || e.aliases.iter().any(|a| a.to_ascii_lowercase() == key))
            .map(|e| e.event)
            .ok_or_else(|| {
                Error::param_range(
                    parameter,
                    format!("unknown event {:?}", truncate(text)),
                    names(),
                )
            })
    }
}

/// `Err` naming `stop` unless every event `controls` stops at is one of `allowed` (the
/// events a branch of that kind locates).
pub fn check_stop_events(controls: &Controls, allowed: &[Event]) -> Result<()> {
    match controls
        .stop_events
        .iter()
        .find(|k| !allowed.iter().any(|e| e.name() == **k))
    {
        None => Ok(()),
        Some(k) => Err(Error::param_range(
            "stop",
            format!("this branch locates no {k} event"),
            allowed
                .iter()
                .map(|e| e.name())
                .collect::<Vec<_>>()
                .join(", "),
        )),
    }
}

/// The canonical names, comma-separated (for error messages).
pub fn names() -> String {
    VOCABULARY
        .iter()
        .map(|e| e.name)
        .collect::<Vec<_>>()
        .join(", ")
}

fn truncate(text: &str) -> String {
    text.chars().take(40).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_and_alias_reads_back_as_its_event() {
        for e in VOCABULARY {
            assert_eq!(Event::parse(e.name, "event").unwrap(), e.event);
            assert_eq!(e.event.name(), e.name);
            for a in e.aliases {
                assert_eq!(Event::parse(a, "event").unwrap(), e.event);
                assert_eq!(Event::parse(&a.to_lowercase(), "event").unwrap(), e.event);
            }
        }
        assert_eq!(
            Event::parse("Neimark-Sacker", "kind").unwrap(),
            Event::NeimarkSacker
        );
        assert_eq!(Event::parse("HOPF", "kind").unwrap(), Event::Hopf);
    }

    #[test]
    fn an_unknown_name_is_refused_naming_the_parameter() {
        let e = Event::parse("cusp", "kind").unwrap_err();
        assert!(
            matches!(e, Error::InvalidParameter { ref name, ref allowed, .. }
                if name == "kind" && allowed.as_deref() == Some(names().as_str())),
            "{e:?}"
        );
    }

    #[test]
    fn names_and_aliases_do_not_collide() {
        let mut seen = std::collections::HashSet::new();
        for e in VOCABULARY {
            for s in std::iter::once(e.name).chain(e.aliases.iter().copied()) {
                assert!(seen.insert(s.to_ascii_lowercase()), "{s} twice");
            }
        }
    }
}
