//! `ballbal.bearing.groove_study`'s native half: the core's parallel groove scan
//! ([`ballbal_core::model::bearing::study`]) off the GIL, returned as columns.

use crate::bearing::BearingArgs;
use crate::errors::CoreResult;
use crate::run::guarded_progress;
use ballbal_core::model::bearing::study::{groove_study as core_study, GrooveAxes};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Columns of the groove study (one entry per point, `angle` slowest), see
/// `ballbal._groove_study.groove_study`.
#[allow(
    clippy::too_many_arguments,
    reason = "a #[pyfunction]'s arguments are the Python call's keywords"
)]
#[pyfunction]
#[pyo3(signature = (bearing, angle, depth_ratio, width_ratio, length_ratio, count, eccentricity, threads=None, progress=None))]
pub fn groove_study<'py>(
    py: Python<'py>,
    bearing: BearingArgs,
    angle: Vec<f64>,
    depth_ratio: Vec<f64>,
    width_ratio: Vec<f64>,
    length_ratio: Vec<f64>,
    count: Vec<usize>,
    eccentricity: f64,
    threads: Option<usize>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let base = bearing.to_core().py()?;
    let axes = GrooveAxes {
        angle,
        depth: depth_ratio,
        width: width_ratio,
        length_ratio,
        count,
    };
    let rows = guarded_progress(py, progress.as_ref(), || {
        core_study(&base, &axes, eccentricity, threads)
    })?;
    let out = PyDict::new(py);
    let col = |f: &dyn Fn(&ballbal_core::model::bearing::study::GroovePoint) -> f64| {
        rows.iter().map(f).collect::<Vec<f64>>()
    };
    out.set_item("angle", col(&|r| r.angle))?;
    out.set_item("depth_ratio", col(&|r| r.depth))?;
    out.set_item("width_ratio", col(&|r| r.width))?;
    out.set_item("length_ratio", col(&|r| r.length_ratio))?;
    out.set_item("count", rows.iter().map(|r| r.count).collect::<Vec<_>>())?;
    out.set_item(
        "status",
        rows.iter()
            .map(|r| match &r.status {
                Ok(()) => "ok".to_string(),
                Err(e) => e.clone(),
            })
            .collect::<Vec<_>>(),
    )?;
    out.set_item("load", col(&|r| r.load))?;
    out.set_item("sommerfeld", col(&|r| r.sommerfeld))?;
    out.set_item("attitude", col(&|r| r.attitude))?;
    for (i, a) in ["x", "y"].iter().enumerate() {
        for (j, b) in ["x", "y"].iter().enumerate() {
            out.set_item(format!("k{a}{b}"), col(&|r| r.k[i][j]))?;
            out.set_item(format!("c{a}{b}"), col(&|r| r.c[i][j]))?;
        }
    }
    out.set_item("critical_mass", col(&|r| r.critical_mass))?;
    out.set_item("whirl_ratio", col(&|r| r.whirl_ratio))?;
    out.set_item("threshold_speed", col(&|r| r.threshold_speed))?;
    out.set_item("k_centre", col(&|r| r.k_centre))?;
    out.set_item("k_centre_cross", col(&|r| r.k_centre_cross))?;
    Ok(out)
}
