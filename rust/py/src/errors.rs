//! The one place where core errors become Python exceptions: the classes of
//! `ballbal.exceptions`, with their fields (`.parameter`, `.allowed`, `.effect`).

use ballbal_core::Error;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A core error on its way to Python. The orphan rule forbids `From<Error> for PyErr`
/// (both are foreign types): this wrapper carries it, so that `?` converts a core
/// `Result` inside an entry point through [`CoreResult::py`] or `PyErr::from`.
pub struct CoreError(pub Error);

impl From<Error> for CoreError {
    fn from(e: Error) -> Self {
        CoreError(e)
    }
}

impl From<CoreError> for PyErr {
    fn from(CoreError(e): CoreError) -> PyErr {
        to_py(e)
    }
}

/// `result.py()?` in an entry point: a core result with its error mapped by [`to_py`].
pub trait CoreResult<T> {
    fn py(self) -> PyResult<T>;
}

impl<T> CoreResult<T> for Result<T, Error> {
    fn py(self) -> PyResult<T> {
        self.map_err(|e| CoreError(e).into())
    }
}

/// The mapping itself; [`CoreError`]'s conversion and [`CoreResult::py`] use it.
pub fn to_py(e: Error) -> PyErr {
    Python::attach(|py| {
        let text = e.to_string();
        let made = (|| -> PyResult<PyErr> {
            let m = py.import("ballbal.exceptions")?;
            let obj = match e {
                Error::InvalidParameter {
                    name,
                    message,
                    allowed,
                } => {
                    let kw = PyDict::new(py);
                    kw.set_item("allowed", allowed)?;
                    m.getattr("ParameterError")?
                        .call((name, message), Some(&kw))?
                }
                Error::NotAutonomous { effect } => {
                    m.getattr("NotAutonomousError")?.call1((effect,))?
                }
                Error::Integration(_) => m.getattr("IntegrationError")?.call1((text.clone(),))?,
                Error::Stiff(_) => m.getattr("StiffError")?.call1((text.clone(),))?,
                Error::Eigen(_) => m.getattr("EigenSolverError")?.call1((text.clone(),))?,
                Error::Cancelled => return Ok(PyKeyboardInterrupt::new_err("cancelled")),
            };
            Ok(PyErr::from_value(obj))
        })();
        // Only if the exceptions module itself cannot be imported (a broken install).
        made.unwrap_or_else(|_| PyRuntimeError::new_err(text))
    })
}

/// `NotAutonomousError` with the analysis named in its message.
pub fn not_autonomous(e: Error, what: &str) -> PyErr {
    match e {
        Error::NotAutonomous { effect } => Python::attach(|py| {
            let msg = format!(
                "{what}: {}",
                Error::NotAutonomous {
                    effect: effect.clone()
                }
            );
            py.import("ballbal.exceptions")
                .and_then(|m| m.getattr("NotAutonomousError"))
                .and_then(|c| c.call1((effect, msg.clone())))
                .map(PyErr::from_value)
                .unwrap_or_else(|_| pyo3::exceptions::PyValueError::new_err(msg))
        }),
        e => to_py(e),
    }
}

/// The text a panic carried.
pub fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<String>()
        .cloned()
        .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_else(|| "unknown".into())
}

/// A panic in the core as `InternalError`: it must never unwind into Python.
pub fn panic_error(p: Box<dyn std::any::Any + Send>) -> PyErr {
    let text = format!(
        "internal error in ballbal core (please report): {}",
        panic_text(&*p)
    );
    Python::attach(|py| {
        py.import("ballbal.exceptions")
            .and_then(|m| m.getattr("InternalError"))
            .and_then(|c| c.call1((text.clone(),)))
            .map(PyErr::from_value)
            .unwrap_or_else(|_| PyRuntimeError::new_err(text))
    })
}
