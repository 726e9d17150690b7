use super::sphere::Sphere;
use std::sync::atomic::{AtomicU64, Ordering};

/// Hands out generations: a number is never given twice in a process, so a
/// world replaced by another (a reset, a new scene) never looks unchanged.
static NEXT_GENERATION: AtomicU64 = AtomicU64::new(1);

fn next_generation() -> u64 {
    NEXT_GENERATION.fetch_add(1, Ordering::Relaxed)
}

/// Running totals a model keeps while it steps; they feed the bench JSON and
/// the screen.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Counters {
    pub sphere_collisions: u64,
    pub wall_collisions: u64,
    /// Momentum given to the walls (sum of `2 m |v_n|`), for the pressure.
    pub wall_momentum: f64,
    /// Steps (or frames, for `exact`) that hit the event cap and were
    /// finished without resolving every contact.
    pub capped_steps: u64,
    /// Of those, the steps stopped by a work budget (`swept`, `discrete`; the rest hit
    /// an event cap).
    pub budget_steps: u64,
}

/// The cube `[0, size]^3` and the spheres in it.
#[derive(Clone, Debug)]
pub struct World {
    pub size: f64,
    pub spheres: Vec<Sphere>,
    /// Simulated time since the scene started.
    pub time: f64,
    pub counters: Counters,
    /// Changes with every edit from outside a model (see `touch`).
    generation: u64,
}

/// Two worlds are equal when what they hold is: the generation only tells
/// a model whether the world it saw was edited since.
impl PartialEq for World {
    fn eq(&self, other: &World) -> bool {
        self.size == other.size
            && self.spheres == other.spheres
            && self.time == other.time
            && self.counters == other.counters
    }
}

/// Whether a world is the one a model last saw, without a pass over the
/// spheres: its edit generation (every edit from outside a model calls
/// [`World::touch`]), its time (a step by any model moves it), its box and
/// its count. The one way every model asks "has the world changed?".
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stamp {
    generation: u64,
    time: u64,
    size: u64,
    count: usize,
}

impl Stamp {
    /// The stamp of the scene however far it ran: equal for two worlds
    /// that differ only by steps taken since the last edit.
    #[must_use]
    pub fn scene(self) -> Stamp {
        Stamp { time: 0, ..self }
    }
}

impl World {
    pub fn new(size: f64, spheres: Vec<Sphere>) -> Self {
        World {
            size,
            spheres,
            time: 0.0,
            counters: Counters::default(),
            generation: next_generation(),
        }
    }

    /// Announce an edit of the spheres from outside a model (added,
    /// removed, resized, moved, given new velocities): every caller that
    /// changes `spheres` other than a model's `advance` must call it, and
    /// work a model kept for this world (`swept`'s detection made ahead for
    /// the overlap readout) is then dropped.
    pub fn touch(&mut self) {
        self.generation = next_generation();
    }

    /// A number that changes with every `touch` and differs between worlds
    /// made apart (clones share it until one of them is touched).
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// What says whether this is the world a model last saw.
    #[must_use]
    pub fn stamp(&self) -> Stamp {
        Stamp {
            generation: self.generation,
            time: self.time.to_bits(),
            size: self.size.to_bits(),
            count: self.spheres.len(),
        }
    }

    pub fn kinetic_energy(&self) -> f64 {
        // Fixed order: energy figures are part of what must be reproducible.
        // From +0, not `sum`'s -0, so an empty box reads 0.
        self.spheres.iter().fold(0.0, |e, s| e + s.kinetic_energy())
    }

    pub fn momentum(&self) -> glam::DVec3 {
        self.spheres.iter().map(|s| s.mass * s.vel).sum()
    }

    /// `kT` from the mean kinetic energy per sphere (`2/3 <E_kin>`).
    pub fn temperature(&self) -> f64 {
        if self.spheres.is_empty() {
            return 0.0;
        }
        2.0 / 3.0 * self.kinetic_energy() / self.spheres.len() as f64
    }

    /// Spheres whose centre lies outside `[r, L - r]` by more than `1e-9 L`.
    pub fn escaped(&self) -> usize {
        let tol = 1e-9 * self.size;
        self.spheres
            .iter()
            .filter(|s| escapes(s, self.size, tol))
            .count()
    }

    /// Deepest pair overlap divided by the smaller radius (0 if none):
    /// [`overlap::deepest`](super::overlap::deepest) on one thread.
    pub fn max_overlap_rel(&self) -> f64 {
        let mut grid = super::broad::Grid::default();
        super::overlap::deepest(&mut grid, self, &super::exec::Serial, None).deepest_rel
    }

    pub fn has_non_finite(&self) -> bool {
        self.spheres
            .iter()
            .any(|s| !(s.pos.is_finite() && s.vel.is_finite()))
    }
}

/// Whether `s`'s centre lies outside `[r, size - r]` by more than `tol`.
#[inline]
pub fn escapes(s: &Sphere, size: f64, tol: f64) -> bool {
    (0..3).any(|k| s.pos[k] < s.radius - tol || s.pos[k] > size - s.radius + tol)
}

#[cfg(test)]
mod tests {
    use super::World;
    use crate::physics::sphere::Sphere;
    use glam::DVec3;

    fn world() -> World {
        let s = Sphere::new(DVec3::splat(0.5), DVec3::X, 0.1);
        World::new(1.0, vec![s])
    }

    #[test]
    fn the_stamp_changes_with_an_edit_a_step_and_the_count() {
        let w = world();
        let before = w.stamp();
        assert_eq!(w.clone().stamp(), before, "a clone is the same world");
        let mut edited = w.clone();
        edited.touch();
        assert_ne!(edited.stamp(), before);
        let mut ran = w.clone();
        ran.time += 1.0 / 60.0;
        assert_ne!(ran.stamp(), before);
        assert_eq!(ran.stamp().scene(), before.scene(), "the same scene, later");
        assert_ne!(edited.stamp().scene(), before.scene());
        let mut more = w.clone();
        more.spheres.push(more.spheres[0]);
        assert_ne!(more.stamp().scene(), before.scene());
        assert_ne!(world().stamp(), before, "worlds made apart differ");
    }
}
