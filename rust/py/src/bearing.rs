//! `ballbal.bearing`'s description of a journal bearing (`Bearing`, `Grooves`), read by
//! attribute into the core's [`ballbal_core::model::bearing::Bearing`]. Ranges are the
//! core's (`Bearing::validate`), checked once there.

use crate::errors::CoreResult;
use ballbal_core::model::bearing::{Bearing, Cavitation, FilmModel, GrooveSide, Grooves};
use ballbal_core::Error;
use pyo3::prelude::*;

/// `ballbal.bearing.Grooves`'s fields (angle in degrees from the circumferential direction).
#[derive(FromPyObject)]
pub struct GroovesArgs {
    count: usize,
    angle: f64,
    depth_ratio: f64,
    width_ratio: f64,
    grooved_length: f64,
    side: String,
}

/// `ballbal.bearing.Bearing`'s fields.
#[derive(FromPyObject)]
pub struct BearingArgs {
    length_ratio: f64,
    grooves: Option<GroovesArgs>,
    cavitation: String,
    model: String,
    grid: (usize, usize),
}

impl GroovesArgs {
    fn to_core(&self) -> Result<Grooves, Error> {
        let side = match self.side.as_str() {
            "sleeve" => GrooveSide::Sleeve,
            "journal" => GrooveSide::Journal,
            other => {
                return Err(Error::param_range(
                    "side",
                    format!("unknown groove side {other:?}"),
                    "sleeve, journal",
                ))
            }
        };
        Ok(Grooves {
            count: self.count,
            angle: self.angle.to_radians(),
            depth: self.depth_ratio,
            width: self.width_ratio,
            length_fraction: self.grooved_length,
            side,
        })
    }
}

impl BearingArgs {
    /// The core bearing, validated.
    pub fn to_core(&self) -> Result<Bearing, Error> {
        let cavitation = match self.cavitation.as_str() {
            "half_sommerfeld" => Cavitation::HalfSommerfeld,
            "reynolds" => Cavitation::Reynolds,
            "none" => Cavitation::None,
            other => {
                return Err(Error::param_range(
                    "cavitation",
                    format!("unknown cavitation model {other:?}"),
                    "half_sommerfeld, reynolds, none",
                ))
            }
        };
        let (n_theta, n_zeta) = self.grid;
        let model = match self.model.as_str() {
            "short" => FilmModel::Short,
            "long" => FilmModel::Long,
            "finite" => FilmModel::Finite { n_theta, n_zeta },
            "narrow_groove" => FilmModel::NarrowGroove,
            other => {
                return Err(Error::param_range(
                    "model",
                    format!("unknown film model {other:?}"),
                    "short, long, finite, narrow_groove",
                ))
            }
        };
        let bearing = Bearing {
            lambda: self.length_ratio,
            grooves: self.grooves.as_ref().map(|g| g.to_core()).transpose()?,
            cavitation,
            model,
        };
        bearing.validate()?;
        Ok(bearing)
    }
}

/// Checks a `ballbal.bearing.Bearing` the way the core does, and nothing more.
#[pyfunction]
pub fn validate_bearing(bearing: BearingArgs) -> PyResult<()> {
    bearing.to_core().py().map(|_| ())
}
