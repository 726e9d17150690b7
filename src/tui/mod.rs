//! The terminal app. It only reads engine snapshots and sends commands.
//!
//! One thread (the caller's) runs the frame loop: start the engine's next
//! frame, draw the previous snapshot while it computes, finish the frame.
//! Keys, resizes and signals arrive over a channel from the named threads
//! `input` and `signals`, so the loop sleeps until a frame is due or
//! something happens, and never busy-waits.
//!
//! The files go by idea: `input/` (what comes in: keys, signals), `term/`
//! (the terminal: set-up, the one gate for writes, the `output` thread,
//! bytes and pacing), `view/` (what is drawn, into a buffer), and here the
//! loop itself: `run` (engine, state, deadlines), `present` (a view of the
//! state to one chunk on the wire), `state` (what the keys asked) and `msg`
//! (what wakes the loop), with `look` (the style, camera and light the
//! state owns and the view draws by). The modules the tests and benches use are
//! re-exported here, one path each.
mod input;
pub mod look;
mod msg;
mod present;
mod run;
pub mod state;
mod term;
mod view;

pub use input::keys;
pub use term::backend;
pub use view::{canvas, help, layout, projection, readouts, theme, threads};

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
