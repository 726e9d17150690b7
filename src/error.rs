//! Bad input: one clear message, exit code 2 (docs/design.md, Command line).
use std::fmt;
use std::io::Write;
use std::process::ExitCode;

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

/// How a run ends: bad input prints `ballpit: message` and exits 2, other
/// errors exit 1 with their chain. stderr may be gone with the terminal:
/// never panic for it.
pub fn exit_code(result: anyhow::Result<()>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if let Some(bad) = e.downcast_ref::<BadInput>() {
                let _ = writeln!(std::io::stderr(), "ballpit: {bad}");
                ExitCode::from(2)
            } else {
                let _ = writeln!(std::io::stderr(), "ballpit: {e:#}");
                ExitCode::FAILURE
            }
        }
    }
}
