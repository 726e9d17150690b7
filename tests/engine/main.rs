//! The engine and the command line without a screen: threading modes,
//! frames and budgets, `bench`, `tradeoff`, `scaling`, scene input, the
//! README's commands. One test binary for all of them (a binary a file took
//! longer to link than to run).
#[allow(dead_code)] // each crate uses part of the shared helpers
#[path = "../common/mod.rs"]
mod common;

mod budget;
mod cli;
mod cli_messages;
mod engine;
mod exact_tradeoff;
mod flat_out;
mod grow;
mod headless;
mod hostile_scenes;
mod memory_limit;
mod pool_idle;
mod readme;
mod scaling;
mod scene_files;
mod scenes;
mod synopsis;
mod timer;
