//! The one mapping of the binding's errors to Python: `facemime.errors.InvalidInputError`, for
//! the core's errors and for every argument the binding refuses.

use facemime_core::CoreError;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// Wraps a core error so that `?` turns it into the project's Python exception.
pub struct CoreErr(pub CoreError);

impl From<CoreError> for CoreErr {
    fn from(e: CoreError) -> Self {
        CoreErr(e)
    }
}

impl From<CoreErr> for PyErr {
    fn from(e: CoreErr) -> PyErr {
        invalid(e.0.to_string())
    }
}

/// The error of an input the binding refuses, core or binding alike:
/// `facemime.errors.InvalidInputError` with `msg` (a plain `ValueError` only where that module
/// cannot be imported).
pub fn invalid(msg: impl Into<String>) -> PyErr {
    let msg = msg.into();
    Python::attach(|py| {
        match py
            .import("facemime.errors")
            .and_then(|m| m.getattr("InvalidInputError"))
        {
            Ok(cls) => PyErr::from_type(cls.cast_into().expect("an exception class"), msg),
            Err(_) => PyValueError::new_err(msg),
        }
    })
}
