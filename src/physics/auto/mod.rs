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
use super::world::{Stamp, World};

/// How strict the models let in are: 0 all, 1 `swept` and `exact`, 2 `exact`.
fn level(m: ModelKind) -> u8 {
    match m {
        ModelKind::Discrete => 0,
        ModelKind::Swept => 1,
        ModelKind::Exact | ModelKind::Auto(_) => 2,
    }
}

/// What the choice was made for: the scene (as edited, however far it
/// ran), `dt`, the steps per frame and whether overlaps are read.
type Key = (Stamp, u64, u64, bool);

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
    /// The drift check: the rms speed and `swept`'s parts the choice was
    /// made for, the `advance`s since, and the count at which to look again.
    drift: Drift,
}

/// Collisions change a scene the user did not edit: spheres started at one
/// speed share their energy by mass (light ones end several times faster),
/// a lattice melts. So the state is looked at again 1, 2, 4, … and then
/// every 64 `advance`s after a choice (one pass over the spheres), and a
/// change past `DRIFT` in the rms speed or in `swept`'s parts chooses again.
#[derive(Clone, Copy, Default)]
struct Drift {
    v_rms: f64,
    parts: u32,
    since: u64,
    next: u64,
}

/// How far the rms speed or the parts may move before the choice is made
/// again: a quarter either way (the cost margins are 1.2×).
const DRIFT: f64 = 1.25;
/// The longest gap between two looks at the state, in `advance`s.
const DRIFT_EVERY: u64 = 64;

impl Drift {
    fn at(s: &Summary, parts: u32) -> Drift {
        Drift {
            v_rms: s.v_rms,
            parts,
            since: 0,
            next: 1,
        }
    }

    /// One more `advance`: whether the state is to be looked at now.
    fn due(&mut self) -> bool {
        self.since += 1;
        self.since >= self.next
    }

    /// Looked at and not moved: the next look twice as far, at most
    /// `DRIFT_EVERY` on.
    fn settle(&mut self) {
        self.next = (self.next * 2).min(self.since + DRIFT_EVERY);
    }

    /// Whether `now` (rms speed, parts) is past `DRIFT` from the choice's.
    fn moved(&self, v_rms: f64, parts: u32) -> bool {
        let off = |a: f64, b: f64| {
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            hi > DRIFT * lo
        };
        off(self.v_rms, v_rms) || off(f64::from(self.parts.max(1)), f64::from(parts.max(1)))
    }
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
            drift: Drift::default(),
        }
    }

    fn rechoose(&mut self, world: &World, dt: f64, frame: u64) {
        let summary = Summary::of(world);
        let parts = super::swept::parts(&world.spheres, world.size, dt);
        self.choose_for(&summary, parts, dt, frame, None);
    }

    /// `drifted`: the rms speed the choice before was made for, when the
    /// state drifted from it.
    fn choose_for(
        &mut self,
        summary: &Summary,
        parts: u32,
        dt: f64,
        frame: u64,
        drifted: Option<f64>,
    ) {
        let ask = Ask {
            dt,
            frame,
            tol: self.tol,
            parts,
            floor: self.floor,
            readouts: self.readouts,
        };
        let mut c = choose(summary, ask);
        if let Some(b) = &self.broke {
            c.reason = format!("{b}: stricter; {}", c.reason);
        }
        if let Some(v) = drifted {
            c.reason = format!(
                "speeds drifted (rms {} → {}): {}",
                speed_text(v),
                speed_text(summary.v_rms),
                c.reason
            );
        }
        self.drift = Drift::at(summary, parts);
        if c.model != self.inner.kind() {
            self.inner = c.model.build();
        }
        self.choice = Some(c);
        self.again = false;
    }

    /// On the drift check's schedule, the state looked at again, and the
    /// choice made again when it moved.
    fn check_drift(&mut self, world: &World, dt: f64, frame: u64) {
        if !self.drift.due() {
            return;
        }
        let summary = Summary::of(world);
        let parts = super::swept::parts(&world.spheres, world.size, dt);
        if self.drift.moved(summary.v_rms, parts) {
            let before = self.drift.v_rms;
            self.choose_for(&summary, parts, dt, frame, Some(before));
        } else {
            self.drift.settle();
        }
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
        let key = (world.stamp().scene(), dt.to_bits(), steps, self.readouts);
        if self.key != Some(key) {
            self.key = Some(key);
            self.floor = 0;
            self.broke = None;
            self.again = true;
        }
        if self.again {
            self.rechoose(world, dt, steps);
        } else {
            self.check_drift(world, dt, steps);
        }
        let capped = world.counters.capped_steps;
        self.inner.advance(world, dt, steps, exec);
        if world.counters.capped_steps > capped {
            self.broke("steps cut short");
        }
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

/// A speed in box lengths a second, to two significant figures.
fn speed_text(v: f64) -> String {
    if v >= 10.0 {
        format!("{v:.0}")
    } else if v >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

#[cfg(test)]
mod tests {
    use super::{DRIFT_EVERY, Drift, Tolerance};

    #[test]
    fn the_drift_check_looks_at_1_2_4_then_every_64_and_past_a_quarter() {
        let mut d = Drift {
            v_rms: 2.0,
            parts: 4,
            since: 0,
            next: 1,
        };
        let mut looks = Vec::new();
        for _ in 0..400 {
            if d.due() {
                looks.push(d.since);
                d.settle();
            }
        }
        assert_eq!(looks, [1, 2, 4, 8, 16, 32, 64, 128, 192, 256, 320, 384]);
        assert!(looks.windows(2).all(|w| w[1] - w[0] <= DRIFT_EVERY));
        assert!(!d.moved(2.0, 4));
        assert!(!d.moved(2.49, 5));
        assert!(!d.moved(1.61, 4));
        assert!(d.moved(2.6, 4));
        assert!(d.moved(1.5, 4));
        assert!(d.moved(2.0, 6));
        assert!(d.moved(2.0, 3));
    }

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
