//! Helpers shared by the test crates (`tests/physics`, `tests/engine`,
//! `tests/app`), each declaring this module once.
pub mod bits;
pub mod child;
pub mod cli;
pub mod json;
pub mod large;
pub mod link;
pub mod names;
pub mod pty;
pub mod random_scene;
pub mod screen;
