//! ballpit: elastic spheres in a cube, on worker threads, drawn in a terminal.
pub mod bench;
pub mod cli;
pub mod cpu;
pub mod engine;
pub mod error;
pub mod memory;
pub mod physics;
pub(crate) mod procfs;
mod progress;
pub mod scaling;
pub mod scene;
pub mod tradeoff;
pub mod tui;
