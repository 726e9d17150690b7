use super::exec::Exec;
use super::world::World;
use std::fmt;
use std::str::FromStr;

/// The collision models of docs/design.md.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ModelKind {
    Discrete,
    Swept,
    Exact,
}

impl ModelKind {
    pub const ALL: [ModelKind; 3] = [ModelKind::Discrete, ModelKind::Swept, ModelKind::Exact];

    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Discrete => "discrete",
            ModelKind::Swept => "swept",
            ModelKind::Exact => "exact",
        }
    }

    /// Whether a step runs as one sequence on one lane, whatever the
    /// executor offers: `exact` runs one event loop.
    pub fn runs_on_one_lane(self) -> bool {
        matches!(self, ModelKind::Exact)
    }

    /// The next model in the `m` key's cycle.
    pub fn next(self) -> ModelKind {
        let i = Self::ALL.iter().position(|&m| m == self).unwrap_or(0);
        Self::ALL[(i + 1) % Self::ALL.len()]
    }

    pub fn build(self) -> Box<dyn Model> {
        match self {
            ModelKind::Discrete => Box::new(super::discrete::Discrete::default()),
            ModelKind::Swept => Box::new(super::swept::Swept::default()),
            ModelKind::Exact => Box::new(super::exact::Exact::default()),
        }
    }
}

impl fmt::Display for ModelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ModelKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .iter()
            .copied()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Self::ALL.iter().map(|m| m.name()).collect();
                format!(
                    "unknown model '{s}' (expected one of: {})",
                    names.join(", ")
                )
            })
    }
}

/// A collision model. It may keep state between calls (schedules, grids); it
/// must drop what depends on the spheres when `invalidate` is called.
pub trait Model: Send {
    fn kind(&self) -> ModelKind;
    /// Advance `world` by `steps` steps of `dt`. On return every sphere's
    /// position and velocity in `world` are those at `world.time`.
    fn advance(&mut self, world: &mut World, dt: f64, steps: u64, exec: &dyn Exec);
    /// The spheres were changed from outside (added, removed, resized).
    fn invalidate(&mut self) {}
    /// Into how many parts the model cut its last step (1: whole).
    fn last_parts(&self) -> u32 {
        1
    }
    /// The deepest overlap in `world` (as `World::max_overlap_rel`), if the
    /// model can tell it from work it does anyway for a next step of `dt`;
    /// `None` leaves it to the caller.
    fn max_overlap_rel(&mut self, _world: &World, _dt: f64, _exec: &dyn Exec) -> Option<f64> {
        None
    }
}
