//! What is drawn: one screen's layout (`layout`) and its parts, the canvas
//! (`canvas`, through `projection`), the readouts, the thread panel, the CPU
//! chart and the key bar and overlay (`help`), all coloured by `theme`.
//! They draw into a ratatui buffer and never write to the terminal.
pub mod canvas;
mod chart;
pub mod help;
pub mod layout;
mod parallelism;
pub mod projection;
pub mod readouts;
pub mod theme;
pub mod threads;
mod wrap;
