//! `ballbal.bearing`'s description of a journal bearing (`Bearing`, `Grooves`), read by
//! attribute into the core's [`ballbal_core::model::bearing::Bearing`], and the film-force
//! entry points of `ballbal.bearing` (force, equilibrium, coefficients, whirl threshold), run
//! off the GIL. Ranges are the core's (`Bearing::validate`), checked once there.

use crate::errors::CoreResult;
use crate::run::guarded;
use ballbal_core::model::bearing::{
    equilibrium, linear_coefficients, rigid_rotor_stability, Bearing, Cavitation, FilmForce,
    FilmModel, GrooveSide, Grooves, JournalState,
};
use ballbal_core::Error;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

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
            "narrow_groove" => FilmModel::NarrowGroove { n_theta, n_zeta },
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

/// `FilmForce` as a dict; with the field, `pressure` (n_theta x n_zeta), `theta`, `zeta`.
fn force_dict<'py>(py: Python<'py>, f: FilmForce) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("fx", f.fx)?;
    d.set_item("fy", f.fy)?;
    d.set_item("radial", f.f_radial)?;
    d.set_item("tangential", f.f_tangential)?;
    d.set_item("eccentricity", f.eccentricity)?;
    d.set_item("position_angle", f.position_angle)?;
    d.set_item("attitude", f.attitude)?;
    d.set_item("sommerfeld", f.sommerfeld)?;
    d.set_item("peak_pressure", f.p_max)?;
    d.set_item("min_film", f.h_min)?;
    if let Some(p) = f.pressure {
        let arr = PyArray1::from_vec(py, p.values).reshape([p.n_theta, p.n_zeta])?;
        d.set_item("pressure", arr)?;
        d.set_item("theta", PyArray1::from_vec(py, p.theta))?;
        d.set_item("zeta", PyArray1::from_vec(py, p.zeta))?;
    }
    Ok(d)
}

/// A 2 x 2 NumPy array from a core coefficient matrix (row-major).
macro_rules! matrix {
    ($py:expr, $m:expr) => {
        PyArray1::from_vec($py, vec![$m[(0, 0)], $m[(0, 1)], $m[(1, 0)], $m[(1, 1)]])
            .reshape([2, 2])?
            .into_any()
    };
}

/// Film force at journal position `(x, y)` (units `c`) and velocity `(x', y')` (units
/// `c w`), journal angle `tau` (journal grooves only); forces in `F_S`.
#[pyfunction]
#[pyo3(signature = (bearing, position, velocity, tau, field))]
pub fn bearing_force<'py>(
    py: Python<'py>,
    bearing: BearingArgs,
    position: (f64, f64),
    velocity: (f64, f64),
    tau: f64,
    field: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let b = bearing.to_core().py()?;
    let st = JournalState {
        x: position.0,
        y: position.1,
        vx: velocity.0,
        vy: velocity.1,
        tau,
    };
    let f = guarded(py, || {
        check_position(position)?;
        b.solver()?.force(&st, field)
    })?;
    force_dict(py, f)
}

/// Static equilibrium under `load` (units `F_S`, fixed frame): `x, y, eccentricity,
/// attitude, iterations`.
#[pyfunction]
pub fn bearing_equilibrium<'py>(
    py: Python<'py>,
    bearing: BearingArgs,
    load: (f64, f64),
) -> PyResult<Bound<'py, PyDict>> {
    let b = bearing.to_core().py()?;
    let e = guarded(py, || equilibrium(&mut b.solver()?, [load.0, load.1]))?;
    let d = PyDict::new(py);
    d.set_item("x", e.x)?;
    d.set_item("y", e.y)?;
    d.set_item("eccentricity", e.eccentricity)?;
    d.set_item("attitude", e.attitude)?;
    d.set_item("iterations", e.iterations)?;
    Ok(d)
}

/// Linearised `(K, C)` at a static position (units `F_S / c`, `F_S / (c w)`).
#[pyfunction]
pub fn bearing_coefficients<'py>(
    py: Python<'py>,
    bearing: BearingArgs,
    position: (f64, f64),
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let b = bearing.to_core().py()?;
    let lc = guarded(py, || {
        check_position(position)?;
        linear_coefficients(&mut b.solver()?, position.0, position.1)
    })?;
    Ok((matrix!(py, lc.k), matrix!(py, lc.c)))
}

fn check_position(p: (f64, f64)) -> Result<(), Error> {
    let eps = p.0.hypot(p.1);
    if !eps.is_finite() || eps >= 1.0 {
        return Err(Error::param_range(
            "position",
            format!("the journal must be inside the clearance circle, got eccentricity {eps}"),
            "eccentricity in [0, 1)",
        ));
    }
    Ok(())
}

/// Rigid rotor (fixed frame, no balls) on the bearing under `load` (units `F_S`): the
/// equilibrium, the coefficients there and the whirl threshold.
#[pyfunction]
pub fn bearing_stability<'py>(
    py: Python<'py>,
    bearing: BearingArgs,
    load: (f64, f64),
) -> PyResult<Bound<'py, PyDict>> {
    let b = bearing.to_core().py()?;
    let (e, lc, w) = guarded(py, || {
        let mut s = b.solver()?;
        let e = equilibrium(&mut s, [load.0, load.1])?;
        let lc = linear_coefficients(&mut s, e.x, e.y)?;
        let w = rigid_rotor_stability(&lc, load.0.hypot(load.1));
        Ok((e, lc, w))
    })?;
    let d = PyDict::new(py);
    d.set_item("x", e.x)?;
    d.set_item("y", e.y)?;
    d.set_item("eccentricity", e.eccentricity)?;
    d.set_item("attitude", e.attitude)?;
    d.set_item("k", matrix!(py, lc.k))?;
    d.set_item("c", matrix!(py, lc.c))?;
    d.set_item("critical_mass", w.critical_mass)?;
    d.set_item("whirl_ratio", w.whirl_ratio)?;
    d.set_item("threshold_speed", w.threshold_speed)?;
    Ok(d)
}
