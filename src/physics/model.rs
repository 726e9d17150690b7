use super::exec::Exec;
use super::world::World;
use strum::{Display, EnumCount, EnumString, IntoStaticStr};

/// The collision models of docs/design.md; the names are the command line's.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, Display, EnumCount, EnumString, IntoStaticStr,
)]
#[strum(serialize_all = "lowercase")]
pub enum ModelKind {
    Discrete,
    Swept,
    Exact,
}

impl ModelKind {
    /// Every model, in the `m` key's cycle (a new variant does not compile
    /// until it is listed here).
    pub const ALL: [ModelKind; Self::COUNT] =
        [ModelKind::Discrete, ModelKind::Swept, ModelKind::Exact];

    pub fn name(self) -> &'static str {
        self.into()
    }

    /// Whether a step runs as one sequence on one lane, whatever the
    /// executor offers: `exact` runs one event loop.
    pub fn runs_on_one_lane(self) -> bool {
        matches!(self, ModelKind::Exact)
    }

    /// The next model in the `m` key's cycle.
    #[must_use]
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back_and_the_cycle_visits_every_model() {
        let names: Vec<_> = ModelKind::ALL.map(ModelKind::name).into();
        assert_eq!(names, ["discrete", "swept", "exact"]);
        for m in ModelKind::ALL {
            assert_eq!(m.to_string(), m.name());
            assert_eq!(m.name().parse(), Ok(m));
        }
        assert!("Exact".parse::<ModelKind>().is_err());
        let mut m = ModelKind::Discrete;
        let mut seen = Vec::new();
        for _ in 0..ModelKind::COUNT {
            m = m.next();
            seen.push(m);
        }
        assert_eq!(
            seen,
            [ModelKind::Swept, ModelKind::Exact, ModelKind::Discrete]
        );
    }
}
