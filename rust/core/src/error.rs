//! Errors the core reports to callers. Every invalid input names its parameter
//! and the allowed range, so the Python layer can raise a `ValueError` verbatim.

use std::fmt;

#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// A parameter is outside its allowed range. `allowed` states the range or values
    /// as text when there is one (the Python exception carries it as `.allowed`).
    InvalidParameter {
        name: String,
        message: String,
        allowed: Option<String>,
    },
    /// The analysis needs an autonomous scene; `effect` is what makes it time dependent.
    NotAutonomous { effect: String },
    /// The integrator could not proceed (step size underflow, too many steps, non-finite state).
    Integration(String),
    /// The equations are too stiff for the explicit integrator at these parameters.
    Stiff(String),
    /// An eigenvalue computation did not converge.
    Eigen(String),
    /// The caller asked the work to stop (e.g. Ctrl-C); finished parts were handed over.
    Cancelled,
}

impl Error {
    pub fn param(name: impl Into<String>, message: impl Into<String>) -> Self {
        Error::InvalidParameter {
            name: name.into(),
            message: message.into(),
            allowed: None,
        }
    }

    /// An invalid parameter with its allowed range or values stated separately.
    pub fn param_range(
        name: impl Into<String>,
        message: impl Into<String>,
        allowed: impl Into<String>,
    ) -> Self {
        Error::InvalidParameter {
            name: name.into(),
            message: message.into(),
            allowed: Some(allowed.into()),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::InvalidParameter { name, message, .. } => write!(f, "{name}: {message}"),
            Error::NotAutonomous { effect } => write!(
                f,
                "this analysis needs an autonomous scene, but the effect '{effect}' makes it time dependent"
            ),
            Error::Integration(m) => write!(f, "integration failed: {m}"),
            Error::Stiff(m) => write!(f, "too stiff for the explicit integrator: {m}"),
            Error::Eigen(m) => write!(f, "eigenvalue computation failed: {m}"),
            Error::Cancelled => write!(f, "cancelled"),
        }
    }
}

impl std::error::Error for Error {}

pub type Result<T> = std::result::Result<T, Error>;

/// Checks that `v` is finite and inside `[lo, hi]` (open ends when `*_open`).
pub fn check_range(
    name: &str,
    v: f64,
    lo: f64,
    lo_open: bool,
    hi: f64,
    hi_open: bool,
) -> Result<()> {
    let ok_lo = if lo_open { v > lo } else { v >= lo };
    let ok_hi = if hi_open { v < hi } else { v <= hi };
    if !v.is_finite() || !ok_lo || !ok_hi {
        let l = if lo_open { "(" } else { "[" };
        let h = if hi_open { ")" } else { "]" };
        let hs = if hi.is_infinite() {
            "inf".to_string()
        } else {
            format!("{hi}")
        };
        let allowed = format!("{l}{lo}, {hs}{h}");
        return Err(Error::param_range(
            name,
            format!("must be a finite number in {allowed}, got {v}"),
            allowed,
        ));
    }
    Ok(())
}
