use super::auto::{Choice, Tolerance};
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
    /// Runs the cheapest of the three predicted to keep the tolerance
    /// (`src/physics/auto/`); the tolerance is part of the model asked.
    Auto(Tolerance),
}

impl ModelKind {
    /// Every model, in the `m` key's cycle (a new variant does not compile
    /// until it is listed here).
    pub const ALL: [ModelKind; Self::COUNT] = [
        ModelKind::Discrete,
        ModelKind::Swept,
        ModelKind::Exact,
        ModelKind::Auto(Tolerance::EXACT),
    ];
    /// The models that `auto` chooses among (and `tradeoff` measures).
    pub const FIXED: [ModelKind; 3] = [ModelKind::Discrete, ModelKind::Swept, ModelKind::Exact];

    pub fn name(self) -> &'static str {
        self.into()
    }

    /// Whether a step runs as one sequence on one lane, whatever the
    /// executor offers: `exact` runs one event loop. `auto` cannot say
    /// alone: ask it of [`ModelKind::running`].
    pub fn runs_on_one_lane(self) -> bool {
        matches!(self, ModelKind::Exact)
    }

    /// The model that really runs: for `auto`, the one it chose (the
    /// snapshot's `choice`) once it has chosen.
    #[must_use]
    pub fn running(self, chosen: Option<ModelKind>) -> ModelKind {
        match (self, chosen) {
            (ModelKind::Auto(_), Some(c)) => c,
            (m, _) => m,
        }
    }

    /// Whether a run of steps gives the same bits however it is cut into
    /// `advance` calls: not for `exact` (its schedule is rebuilt at each
    /// call's end), nor for `auto` (it may run `exact`, and it chooses
    /// again when the steps per call change).
    pub fn cuts_freely(self) -> bool {
        matches!(self, ModelKind::Discrete | ModelKind::Swept)
    }

    /// The next model in the `m` key's cycle.
    #[must_use]
    pub fn next(self) -> ModelKind {
        match self {
            ModelKind::Discrete => ModelKind::Swept,
            ModelKind::Swept => ModelKind::Exact,
            ModelKind::Exact => ModelKind::Auto(Tolerance::EXACT),
            ModelKind::Auto(_) => ModelKind::Discrete,
        }
    }

    /// The tolerance asked, for `auto`.
    pub fn tolerance(self) -> Option<Tolerance> {
        match self {
            ModelKind::Auto(t) => Some(t),
            _ => None,
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
    /// The deepest overlap the caller read after an `advance` (the model's
    /// own answer or the caller's search; infinite when the search stopped
    /// at its budget): `auto` checks its promise against it.
    fn overlap_read(&mut self, _deepest_rel: f64) {}
    /// What `auto` chose to run and why (`None` for the other models).
    fn choice(&self) -> Option<&Choice> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back_and_the_cycle_visits_every_model() {
        let names: Vec<_> = ModelKind::ALL.map(ModelKind::name).into();
        assert_eq!(names, ["discrete", "swept", "exact", "auto"]);
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
            [
                ModelKind::Swept,
                ModelKind::Exact,
                ModelKind::Auto(Tolerance::EXACT),
                ModelKind::Discrete
            ]
        );
        let loose = ModelKind::Auto(Tolerance::new(0.1).unwrap());
        assert_eq!(loose.name(), "auto");
        assert_eq!(loose.next(), ModelKind::Discrete);
        assert_eq!(loose.tolerance().map(Tolerance::fraction), Some(0.1));
    }

    #[test]
    fn auto_runs_on_the_lanes_of_its_choice() {
        let auto = ModelKind::Auto(Tolerance::EXACT);
        assert!(!auto.runs_on_one_lane());
        assert!(auto.running(Some(ModelKind::Exact)).runs_on_one_lane());
        assert!(!auto.running(Some(ModelKind::Swept)).runs_on_one_lane());
        assert_eq!(auto.running(None), auto);
        // Another model's stale choice is not what runs.
        assert_eq!(
            ModelKind::Swept.running(Some(ModelKind::Exact)),
            ModelKind::Swept
        );
    }
}
