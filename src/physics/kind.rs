//! What a run asks of the physics: the model (`auto` with the tolerance
//! it must keep) and what `auto` chose. Apart from the models, so that
//! `model.rs` and `auto/` both read it and neither reads the other back.
use std::fmt;
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
    /// `advance` calls: not for `exact` (each call ends by flying every
    /// sphere to the world's time, `write_back`, and a flight cut in two
    /// rounds differently from one), nor for `auto` (it may run `exact`,
    /// and it chooses again when the steps per call change).
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

/// The fraction of the smaller radius by which spheres may sink into each
/// other, held in millionths so that a model kind stays `Eq` and `Hash`
/// (a request finer than 1e-6 rounds to the stricter 0).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Tolerance(u32);

impl Tolerance {
    pub const EXACT: Tolerance = Tolerance(0);
    const PER_UNIT: f64 = 1e6;
    /// The `<` / `>` keys' steps, about ×3 apart from a thousandth up.
    pub const LADDER: [Tolerance; 7] = [
        Tolerance(0),
        Tolerance(1_000),
        Tolerance(10_000),
        Tolerance(30_000),
        Tolerance(100_000),
        Tolerance(300_000),
        Tolerance(1_000_000),
    ];

    /// `t` in [0, 1]; anything else (negative, NaN, above 1) is refused.
    pub fn new(t: f64) -> Option<Tolerance> {
        (0.0..=1.0)
            .contains(&t)
            // In [0, 1e6] after the check, so the cast is exact.
            .then(|| Tolerance((t * Self::PER_UNIT).floor() as u32))
    }

    pub fn fraction(self) -> f64 {
        f64::from(self.0) / Self::PER_UNIT
    }

    /// The next step of the ladder up (looser) or down (tighter); a value
    /// between steps (from `--tolerance`) goes to the neighbouring one, and
    /// the ends stay where they are.
    #[must_use]
    pub fn step(self, looser: bool) -> Tolerance {
        let l = &Self::LADDER;
        if looser {
            l.iter()
                .copied()
                .find(|&x| x > self)
                .unwrap_or(l[l.len() - 1])
        } else {
            l.iter().rev().copied().find(|&x| x < self).unwrap_or(l[0])
        }
    }
}

impl fmt::Display for Tolerance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.fraction())
    }
}

/// The model chosen and why, in the screen's words.
#[derive(Clone, Debug, PartialEq)]
pub struct Choice {
    pub model: ModelKind,
    pub reason: String,
    /// The tolerance cannot be kept by any model within its budget.
    pub unmet: bool,
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
