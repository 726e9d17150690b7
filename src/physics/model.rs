use super::exec::Exec;
pub use super::kind::{Choice, ModelKind};
use super::world::World;

/// A collision model. It may keep state between calls (schedules, grids); it
/// must drop what depends on the spheres when the world's generation moved
/// (`World::touch`, the one signal of an edit from outside).
pub trait Model: Send {
    fn kind(&self) -> ModelKind;
    /// Advance `world` by `steps` steps of `dt`. On return every sphere's
    /// position and velocity in `world` are those at `world.time`.
    fn advance(&mut self, world: &mut World, dt: f64, steps: u64, exec: &dyn Exec);
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
