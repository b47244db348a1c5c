//! The one error type of the core. The core never panics on user input.

use std::fmt;

/// An error the core returns instead of panicking on bad input.
#[derive(Debug, Clone, PartialEq)]
pub enum CoreError {
    /// An argument has the wrong size, range or value; the text names it.
    InvalidInput(String),
}

impl fmt::Display for CoreError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CoreError::InvalidInput(msg) => f.write_str(msg),
        }
    }
}

impl std::error::Error for CoreError {}

/// Shorthand for a core result.
pub type Result<T> = std::result::Result<T, CoreError>;

/// Returns `Err(CoreError::InvalidInput(..))` built from a format string.
#[macro_export]
macro_rules! invalid {
    ($($arg:tt)*) => {
        Err($crate::error::CoreError::InvalidInput(format!($($arg)*)))
    };
}
