//! `auto`: runs the cheapest of `discrete`, `swept` and `exact` predicted to
//! keep the tolerance asked, for the scene as it is now (docs/models.md).
//! It chooses again at the next `advance` after the spheres were edited,
//! `dt` changed, or the model it runs broke the tolerance (then only
//! stricter models are let in until the scene changes).
mod choose;

pub use super::kind::{Choice, Tolerance};
pub use choose::{
    Ask, Costs, EXACT_CAP_MARGIN, Rates, Summary, choose, costs, discrete_overlap, rates,
};

use super::exec::Exec;
use super::kind::ModelKind;
use super::model::Model;
use super::world::World;

/// How strict the models let in are: 0 all, 1 `swept` and `exact`, 2 `exact`.
fn level(m: ModelKind) -> u8 {
    match m {
        ModelKind::Discrete => 0,
        ModelKind::Swept => 1,
        ModelKind::Exact | ModelKind::Auto(_) => 2,
    }
}

/// What the choice was made for: the spheres' edit generation, their
/// count, `dt`, the steps per frame and whether overlaps are read.
type Key = (u64, usize, u64, u64, bool);

pub struct Auto {
    tol: Tolerance,
    inner: Box<dyn Model>,
    choice: Option<Choice>,
    key: Option<Key>,
    /// Models below this level broke the tolerance on this scene.
    floor: u8,
    /// Why the floor was raised, for the reason.
    broke: Option<String>,
    /// The choice is to be made again at the next `advance`.
    again: bool,
    /// Whether the caller reads the overlap after each `advance`: assumed
    /// (the engine does) until an `advance` follows one without a readout.
    readouts: bool,
    read_since: bool,
}

impl Auto {
    pub fn new(tol: Tolerance) -> Auto {
        Auto {
            tol,
            inner: ModelKind::Exact.build(),
            choice: None,
            key: None,
            floor: 0,
            broke: None,
            again: true,
            readouts: true,
            read_since: true,
        }
    }

    fn rechoose(&mut self, world: &World, dt: f64, frame: u64) {
        let summary = Summary::of(world);
        let ask = Ask {
            dt,
            frame,
            tol: self.tol,
            parts: super::swept::parts(&world.spheres, world.size, dt),
            floor: self.floor,
            readouts: self.readouts,
        };
        let mut c = choose(&summary, ask);
        if let Some(b) = &self.broke {
            c.reason = format!("{b}: stricter; {}", c.reason);
        }
        if c.model != self.inner.kind() {
            self.inner = c.model.build();
        }
        self.choice = Some(c);
        self.again = false;
    }

    /// The model running broke the tolerance: move up.
    fn broke(&mut self, what: &str) {
        let m = self.inner.kind();
        if level(m) >= 2 || self.choice.as_ref().is_some_and(|c| c.unmet) {
            return;
        }
        self.floor = level(m) + 1;
        self.broke = Some(format!("{m} broke tol ({what})"));
        self.again = true;
    }
}

impl Model for Auto {
    fn kind(&self) -> ModelKind {
        ModelKind::Auto(self.tol)
    }

    fn advance(&mut self, world: &mut World, dt: f64, steps: u64, exec: &dyn Exec) {
        self.readouts = self.read_since;
        self.read_since = false;
        let key = (
            world.generation(),
            world.spheres.len(),
            dt.to_bits(),
            steps,
            self.readouts,
        );
        if self.key != Some(key) {
            self.key = Some(key);
            self.floor = 0;
            self.broke = None;
            self.again = true;
        }
        if self.again {
            self.rechoose(world, dt, steps);
        }
        let capped = world.counters.capped_steps;
        self.inner.advance(world, dt, steps, exec);
        if world.counters.capped_steps > capped {
            self.broke("steps cut short");
        }
    }

    fn invalidate(&mut self) {
        self.inner.invalidate();
        self.key = None;
    }

    fn last_parts(&self) -> u32 {
        self.inner.last_parts()
    }

    /// `discrete` leaves the readout to the caller (the engine's grid pass
    /// on the frame's executor); the others tell it from their own work.
    fn max_overlap_rel(&mut self, world: &World, dt: f64, exec: &dyn Exec) -> Option<f64> {
        self.read_since = true;
        self.inner.max_overlap_rel(world, dt, exec)
    }

    /// The promise is checked against the frame's readout, whoever made it.
    fn overlap_read(&mut self, deepest_rel: f64) {
        self.read_since = true;
        if deepest_rel > self.tol.fraction() + 1e-9 {
            self.broke("overlap");
        }
    }

    fn choice(&self) -> Option<&Choice> {
        self.choice.as_ref()
    }
}

#[cfg(test)]
mod tests {
    use super::Tolerance;

    #[test]
    fn the_ladder_steps_both_ways_stops_at_its_ends_and_takes_in_between_values() {
        let t = |x: f64| Tolerance::new(x).unwrap();
        let mut up = vec![Tolerance::EXACT];
        while up.last() != up.last().map(|x| x.step(true)).as_ref() {
            up.push(up[up.len() - 1].step(true));
        }
        let fractions: Vec<f64> = up.iter().map(|x| x.fraction()).collect();
        assert_eq!(fractions, [0.0, 0.001, 0.01, 0.03, 0.1, 0.3, 1.0]);
        assert_eq!(t(1.0).step(true), t(1.0));
        assert_eq!(t(0.0).step(false), t(0.0));
        assert_eq!(t(0.3).step(false), t(0.1));
        assert_eq!(t(0.05).step(true), t(0.1));
        assert_eq!(t(0.05).step(false), t(0.03));
    }
}
