//! The terminal app. It only reads engine snapshots and sends commands.
//!
//! One thread (the caller's) runs the frame loop: start the engine's next
//! frame, draw the previous snapshot while it computes, finish the frame.
//! Keys, resizes and signals arrive over a channel from the named threads
//! `input` and `signals`, so the loop sleeps until a frame is due or
//! something happens, and never busy-waits.
pub mod app;
pub mod canvas;
mod caps;
mod chart;
mod escapes;
mod guard;
pub mod help;
pub mod keys;
mod latch;
mod msg;
pub mod output;
mod pacing;
pub mod parallelism;
mod present;
pub mod projection;
mod quit;
mod reader;
pub mod readouts;
mod run;
mod signals;
pub mod state;
mod term_input;
pub mod theme;
pub mod threads;
mod wrap;
mod writer;

pub use present::AfterFirstFrame;
pub use run::{RunExtras, run, run_with};
pub use theme::ColorChoice;

/// Largest frame rate the frame loop takes (`--fps`).
pub const MAX_FPS: f64 = 1000.0;

/// What the command line sets for the screen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Frames per second to aim at (default 30).
    pub fps: f64,
    pub color: ColorChoice,
    /// `--tick max`: start flat out (key x).
    pub flat_out: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            fps: 30.0,
            color: ColorChoice::Auto,
            flat_out: false,
        }
    }
}
