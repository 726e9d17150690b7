//! Bad input: one clear message, exit code 2 (docs/design.md, Command line).
use std::fmt;

/// Something the user gave us is wrong; the message names what and where.
#[derive(Debug, Clone, PartialEq)]
pub struct BadInput(pub String);

impl fmt::Display for BadInput {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for BadInput {}

/// Shorthand for `Err(BadInput(format!(...)))`.
#[macro_export]
macro_rules! bad {
    ($($t:tt)*) => { Err($crate::error::BadInput(format!($($t)*))) };
}

/// Shorthand for `BadInput(format!(...))`, for `map_err`.
#[macro_export]
macro_rules! bad_input {
    ($($t:tt)*) => { $crate::error::BadInput(format!($($t)*)) };
}
