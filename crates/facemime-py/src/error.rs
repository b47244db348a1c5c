//! The one mapping of core errors to Python: `facemime.errors.InvalidInputError`.

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
        let msg = e.0.to_string();
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
}
