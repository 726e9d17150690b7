//! The app: its state, its screen drawn at fixed states (insta snapshots),
//! and the real binary in a pseudo-terminal, over a slow link and under a
//! shell. One test binary for all of them (a binary a file took longer to
//! link than to run).
#[allow(dead_code)] // each crate uses part of the shared helpers
#[path = "../common/mod.rs"]
mod common;

mod flat_out_pty;
mod help_overlay;
mod locale_colour;
mod notices;
mod readme_keys;
mod readouts_panel;
mod slow_link;
mod terminal_hygiene;
mod threads_panel;
mod threads_refused;
mod tui_large;
mod tui_layout_pty;
mod tui_notty;
mod tui_pty;
mod tui_snapshots;
mod tui_state;
