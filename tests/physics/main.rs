//! The physics through the library: contact maths, broad phases, the step
//! models and `exact`, `auto`'s choice, lanes and decompositions, numerics
//! at the extremes, property tests. One test binary for all of them (a
//! binary a file took longer to link than to run).
#[allow(dead_code)] // each crate uses part of the shared helpers
#[path = "../common/mod.rs"]
mod common;

mod analytic;
mod auto;
mod auto_choice;
mod broad_large;
mod broad_phase;
mod clusters;
mod decomposition;
mod exact;
mod exact_overlap;
mod exact_pin;
mod exact_queue;
mod exact_theory;
mod extremes;
mod fluid_start;
mod fuzz_exact;
mod lanes;
mod properties;
mod tuned;
