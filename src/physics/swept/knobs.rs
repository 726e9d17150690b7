//! The knobs tests, benchmarks and examples turn (feature `experiments`,
//! which the crate's dev-dependency on itself enables; the shipped binary
//! has none): a fixed number of parts a step, another work budget, and the
//! plain serial event loop the clusters must match.
use super::{Swept, parts};

/// What the knobs are set to; the defaults are the shipped model's.
#[derive(Default)]
pub(super) struct Knobs {
    /// Parts per step when not the scene's choice.
    pub fixed_parts: Option<u32>,
    /// The work budget per step, when not the default one: (base, per sphere).
    pub budget: Option<(u64, u64)>,
}

impl Swept {
    /// Cut every step into `k` parts instead of the number the scene
    /// calls for (see `parts.rs`); `None` goes back to that.
    #[must_use]
    pub fn fixed_parts(mut self, k: Option<u32>) -> Self {
        self.knobs.fixed_parts = k.map(|k| k.clamp(1, parts::MAX_PARTS));
        self
    }

    /// Run every step's events as one serial loop, not in clusters (the
    /// reference the clusters must match).
    #[must_use]
    pub fn serial_events(mut self, on: bool) -> Self {
        self.rounds.serial_only = on;
        self
    }

    /// Give every step a work budget of `base + per_sphere × n` pair
    /// checks instead of the default (`u64::MAX` for none).
    #[must_use]
    pub fn with_work_budget(mut self, base: u64, per_sphere: u64) -> Self {
        self.knobs.budget = Some((base, per_sphere));
        self
    }
}
