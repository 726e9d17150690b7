//! The values the command line takes: the domain's enums mirrored for clap,
//! and the parsers of `--dt` and `--fps`.
use crate::engine::Threading;
use crate::physics::ModelKind;
use crate::tui::state::MAX_TICK;
use crate::tui::{ColorChoice, MAX_FPS};
use clap::ValueEnum;
use std::time::Duration;

/// `--model`: [`ModelKind`] as the command line names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModelArg {
    /// Move by dt, then resolve overlaps: cheapest; overlaps grow with dt x speed
    Discrete,
    /// Every contact inside each step, in time order: no tunnelling
    Swept,
    /// Event-driven, every collision in time order; dt only samples
    Exact,
    /// The cheapest of the three that keeps --tolerance, chosen per scene
    Auto,
}

impl From<ModelArg> for ModelKind {
    fn from(m: ModelArg) -> ModelKind {
        match m {
            ModelArg::Discrete => ModelKind::Discrete,
            ModelArg::Swept => ModelKind::Swept,
            ModelArg::Exact => ModelKind::Exact,
            ModelArg::Auto => ModelKind::Auto(crate::physics::auto::Tolerance::EXACT),
        }
    }
}

/// `--threading`: [`Threading`] as the command line names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ThreadingArg {
    /// The main thread, between frames
    Off,
    /// One thread, `physics`, woken for each frame
    Worker,
    /// `physics` plus --threads pool threads sharing each step (data decomposition)
    Pool,
    /// Sphere-sphere and sphere-wall work on two threads (functional decomposition)
    Split,
}

impl From<ThreadingArg> for Threading {
    fn from(t: ThreadingArg) -> Threading {
        match t {
            ThreadingArg::Off => Threading::Off,
            ThreadingArg::Worker => Threading::Worker,
            ThreadingArg::Pool => Threading::Pool,
            ThreadingArg::Split => Threading::Split,
        }
    }
}

/// `--color`: [`ColorChoice`] as the command line names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ColorArg {
    /// 16 colours if the terminal has colour, none under NO_COLOR
    #[allow(clippy::doc_markdown)] // clap prints this as the help
    Auto,
    /// 16 colours: the fewest bytes over SSH
    #[value(name = "16")]
    C16,
    /// 256 colours
    #[value(name = "256")]
    C256,
    /// 24-bit colour
    #[value(name = "true", alias = "truecolor", alias = "24bit")]
    True,
}

impl From<ColorArg> for ColorChoice {
    fn from(c: ColorArg) -> ColorChoice {
        match c {
            ColorArg::Auto => ColorChoice::Auto,
            ColorArg::C16 => ColorChoice::C16,
            ColorArg::C256 => ColorChoice::C256,
            ColorArg::True => ColorChoice::True,
        }
    }
}
/// `--tick`: steps per frame, or `max` (flat out: as many steps as the
/// frame period allows).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tick {
    Steps(u32),
    Max,
}

impl Tick {
    /// The steps a frame runs; `None` for flat out.
    pub fn steps(self) -> Option<u32> {
        match self {
            Tick::Steps(n) => Some(n),
            Tick::Max => None,
        }
    }
}

/// `max`, or a whole number of steps up to the limit the keys share.
pub(super) fn parse_tick(s: &str) -> Result<Tick, String> {
    if s == "max" {
        return Ok(Tick::Max);
    }
    match s.parse::<u32>() {
        Ok(n) if n <= MAX_TICK => Ok(Tick::Steps(n)),
        _ => Err(format!(
            "expected `max` or a whole number of steps from 0 to {MAX_TICK}"
        )),
    }
}

/// A number of seconds, written as a number (0.01) or a fraction (1/60);
/// whether it is allowed is for the validators to say.
pub(super) fn parse_seconds(s: &str) -> Result<f64, String> {
    let num = |t: &str| t.trim().parse::<f64>();
    let v = match s.split_once('/') {
        Some((a, b)) => num(a).and_then(|a| num(b).map(|b| a / b)),
        None => num(s),
    };
    v.map_err(|_| "expected seconds as a number or a fraction, e.g. 0.01 or 1/60".to_string())
}

/// `scaling --seconds`: how long an `off` run should take.
pub(super) fn parse_run_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 600.0 => Ok(v),
        _ => Err("expected wall seconds above 0 and at most 600, e.g. 0.5".into()),
    }
}

pub(super) fn parse_fps(s: &str) -> Result<f64, String> {
    let fps: f64 = s
        .parse()
        .map_err(|_| format!("expected a number above 0 and at most {MAX_FPS}"))?;
    if !(fps > 0.0 && fps <= MAX_FPS) {
        return Err(format!("must be above 0 and at most {MAX_FPS}"));
    }
    // The frame loop waits 1/fps seconds: that must be a Duration.
    if Duration::try_from_secs_f64(1.0 / fps).is_err() {
        return Err("is too small: one frame would take longer than a Duration can hold".into());
    }
    Ok(fps)
}
#[cfg(test)]
mod tests {
    use super::*;

    fn names<T: ValueEnum>() -> Vec<String> {
        T::value_variants()
            .iter()
            .filter_map(ValueEnum::to_possible_value)
            .map(|p| p.get_name().to_string())
            .collect()
    }

    #[test]
    fn the_mirrors_name_every_domain_value_the_same_way() {
        let models: Vec<String> = ModelKind::ALL.iter().map(|m| m.name().into()).collect();
        assert_eq!(names::<ModelArg>(), models);
        for m in ModelArg::value_variants() {
            let name = m.to_possible_value().map(|p| p.get_name().to_string());
            assert_eq!(name.as_deref(), Some(ModelKind::from(*m).name()));
        }
        let modes: Vec<String> = Threading::ALL.iter().map(|t| t.name().into()).collect();
        assert_eq!(names::<ThreadingArg>(), modes);
        for t in ThreadingArg::value_variants() {
            let name = t.to_possible_value().map(|p| p.get_name().to_string());
            assert_eq!(name.as_deref(), Some(Threading::from(*t).name()));
        }
        for c in ColorArg::value_variants() {
            let name = c.to_possible_value().map(|p| p.get_name().to_string());
            let parsed: Result<ColorChoice, _> = name.unwrap_or_default().parse();
            assert_eq!(parsed, Ok(ColorChoice::from(*c)));
        }
    }

    #[test]
    fn fps_takes_what_the_frame_loop_can_time() {
        assert_eq!(parse_fps("30"), Ok(30.0));
        assert_eq!(parse_fps("1000"), Ok(1000.0));
        assert_eq!(parse_fps("0.5"), Ok(0.5));
        for bad in ["0", "-1", "1000.5", "inf", "NaN", "1e-30", "5e-324", "x"] {
            assert!(parse_fps(bad).is_err(), "{bad}");
        }
        assert!(
            parse_fps("0")
                .unwrap_err()
                .contains("above 0 and at most 1000")
        );
        assert!(parse_fps("1e-30").unwrap_err().contains("too small"));
    }

    #[test]
    fn tick_takes_max_or_steps_up_to_the_keys_limit() {
        assert_eq!(parse_tick("max"), Ok(Tick::Max));
        assert_eq!(parse_tick("0"), Ok(Tick::Steps(0)));
        assert_eq!(parse_tick("1000000"), Ok(Tick::Steps(MAX_TICK)));
        for bad in ["1000001", "-1", "MAX", "1.5", "", "maximum"] {
            assert!(parse_tick(bad).is_err(), "{bad}");
        }
        assert_eq!(Tick::Max.steps(), None);
        assert_eq!(Tick::Steps(7).steps(), Some(7));
    }

    #[test]
    fn dt_reads_numbers_and_fractions() {
        assert_eq!(parse_seconds("0.01"), Ok(0.01));
        assert_eq!(parse_seconds("1/60"), Ok(1.0 / 60.0));
        assert_eq!(parse_seconds("-1"), Ok(-1.0));
        for bad in ["", "1/", "/2", "a/b", "1/2/3", "ten"] {
            assert!(parse_seconds(bad).is_err(), "{bad}");
        }
    }
}
