//! What comes in: the terminal's bytes read and parsed (`reader`,
//! `term_input`), the one key table (`keys`), the signals (`signals`) and
//! the quit watchdog a quit key starts (`quit`). Each arrives at the frame
//! loop as a [`Msg`](crate::tui::msg::Msg).
pub mod keys;
mod quit;
pub(super) mod reader;
pub(super) mod signals;
mod term_input;
