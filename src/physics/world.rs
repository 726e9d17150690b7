use super::sphere::{Sphere, overlap_rel};
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

    /// Deepest pair overlap divided by the smaller radius (0 if none).
    pub fn max_overlap_rel(&self) -> f64 {
        let mut worst: f64 = 0.0;
        super::broad::for_each_near_pair(&self.spheres, self.size, |i, j| {
            let (a, b) = (&self.spheres[i], &self.spheres[j]);
            worst = worst.max(overlap_rel(a.pos, a.radius, b.pos, b.radius));
        });
        worst
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
