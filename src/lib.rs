//! ballpit: elastic spheres in a cube, on worker threads, drawn in a terminal.
#![forbid(unsafe_code)]

pub mod cpu;
pub mod engine;
pub mod error;
pub mod physics;
pub mod tui;
