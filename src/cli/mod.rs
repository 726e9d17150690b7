//! The command line of docs/design.md. clap stays in this module: the enums
//! of `values.rs` mirror the domain's (models, threading modes, colours) so
//! physics/ and engine/ never see clap.
mod help;
mod screen;
mod values;

pub use crate::tui::MAX_FPS;
pub use help::{BENCH_FIELDS, keys_section};
pub use values::{ColorArg, ModelArg, ThreadingArg};

use crate::bad;
use crate::engine::{MAX_THREADS, Settings, default_threads};
use crate::error::BadInput;
use crate::physics::ModelKind;
use crate::physics::auto::Tolerance;
use crate::scene::SceneSpec;
use clap::builder::RangedU64ValueParser;
use clap::parser::ValueSource;
use clap::{ArgMatches, Args, CommandFactory, FromArgMatches, Parser, Subcommand};
use help::{
    bench_after_help, scaling_after_help, scene_long_help, threads_help, tradeoff_after_help,
    tradeoff_long_about,
};
use std::ffi::OsString;
use std::path::PathBuf;
use values::{parse_fps, parse_seconds};

#[derive(Debug, Parser)]
#[command(
    name = "ballpit",
    version,
    about = "Elastic spheres in a cube, on worker threads, drawn in your terminal",
    after_help = "Without a subcommand, opens the terminal app (press ? in it for the keys).\n\
                  Scene and run flags go after a subcommand: ballpit bench --model exact --steps 600.\n\
                  Units are box lengths and seconds. Bad input exits with code 2.",
    // `--dt -1` must reach the validators and their message, not read as a flag.
    allow_negative_numbers = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub run: RunArgs,
    /// Frames per second to draw at most (0 < F <= 1000; keys f/F change it)
    #[arg(long, default_value_t = 30.0, value_name = "F", value_parser = parse_fps)]
    pub fps: f64,
    /// Colours (NO_COLOR is honoured unless this is given)
    #[allow(clippy::doc_markdown)] // clap prints this as the help
    #[arg(long, value_enum, default_value_t = ColorArg::Auto, value_name = "COLORS")]
    pub color: ColorArg,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scene headless and print one JSON line
    #[command(allow_negative_numbers = true, after_help = bench_after_help())]
    Bench(BenchArgs),
    /// Measure speed against accuracy for every model over a ladder of dt
    #[command(
        allow_negative_numbers = true,
        long_about = tradeoff_long_about(),
        after_help = tradeoff_after_help()
    )]
    Tradeoff(TradeoffArgs),
    /// Measure what threading buys here: every mode, pools of 1, 2, 4, … threads
    #[command(
        allow_negative_numbers = true,
        long_about = "Measure what threading buys on this machine, for one scene.\n\n\
                      Runs off, worker, split, and pool at 1, 2, 4, ... threads up to the core \
                      count and once at twice it (oversubscribed), every configuration once a \
                      round, the rounds in alternation, each run the same number of steps. \
                      Prints a markdown table: steps/s, speed-up over off, efficiency, physics \
                      CPU seconds, and the pool's serial fraction, measured from its own clock \
                      and as the Karp-Flatt fraction of its speed-up; then one Amdahl fit of \
                      the pool's speed-ups and the speed-up it predicts at 16, 64 and 128 cores, \
                      labelled as a prediction.",
        after_help = scaling_after_help()
    )]
    Scaling(ScalingArgs),
    /// Print a shell completion script, e.g. ballpit completions bash
    Completions {
        /// The shell to complete for
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff), e.g. ballpit man | man -l -
    Man,
}

#[derive(Debug, Args)]
pub struct BenchArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub run: RunArgs,
    /// Steps to run (0 only builds the scene, e.g. to --dump it)
    #[arg(long, value_name = "K")]
    pub steps: u64,
    /// Write the final state as a sphere CSV (reads back with --scene FILE.csv)
    #[arg(long, value_name = "FILE.csv", value_hint = clap::ValueHint::FilePath)]
    pub dump: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct TradeoffArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Write tradeoff.csv and tradeoff.svg into this directory
    #[arg(long, value_name = "DIR", value_hint = clap::ValueHint::DirPath)]
    pub out: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct ScalingArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Step length in seconds (> 0), a number or a fraction such as 1/120
    #[arg(long, default_value = "1/60", value_name = "DT", value_parser = parse_seconds)]
    pub dt: f64,
    /// Collision model
    #[arg(long, value_enum, default_value_t = ModelArg::Swept, value_name = "MODEL")]
    pub model: ModelArg,
    /// The largest pool before the oversubscribed one (which is twice it, at most 256)
    /// [default: available cores]
    #[arg(long, value_name = "K",
          value_parser = RangedU64ValueParser::<usize>::new().range(1..=MAX_THREADS as u64))]
    pub threads: Option<usize>,
    /// Rounds: every configuration runs once a round (1 to 100)
    #[arg(long, default_value_t = 3, value_name = "R",
          value_parser = RangedU64ValueParser::<usize>::new().range(1..=100))]
    pub rounds: usize,
    /// Wall seconds an `off` run should take; every run then steps as many steps
    /// (0 < S <= 600)
    #[arg(long, default_value = "1", value_name = "S", value_parser = values::parse_run_seconds)]
    pub seconds: f64,
    /// Write scaling.csv and scaling.svg into this directory
    #[arg(long, value_name = "DIR", value_hint = clap::ValueHint::DirPath)]
    pub out: Option<PathBuf>,
}

/// `scaling` without `--scene`, `--count` or `--radius`: enough spheres
/// that a pool has work to share (the screen's default has too few).
pub const SCALING_COUNT: usize = 100_000;
/// Packing of `scaling`'s default scene (and of `--count N` without
/// `--radius` or `--scene`).
pub const SCALING_PACKING: f64 = 0.05;

impl ScalingArgs {
    /// The scene: the flags as given, but without `--scene` the gas at
    /// [`SCALING_COUNT`] spheres (or `--count`) and packing [`SCALING_PACKING`]
    /// (unless `--radius`).
    pub fn spec(&self) -> SceneSpec {
        let mut spec = self.scene.spec();
        if spec.scene.is_none() {
            let n = *spec.count.get_or_insert(SCALING_COUNT);
            if spec.radius.is_none() && n > 0 {
                let size = spec.size.unwrap_or(1.0);
                let each = SCALING_PACKING * size.powi(3) / n as f64;
                spec.radius = Some((each / crate::physics::sphere::volume(1.0)).cbrt());
            }
        }
        spec
    }

    pub fn plan(&self) -> crate::scaling::Plan {
        let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
        crate::scaling::Plan {
            model: self.model.into(),
            dt: self.dt,
            top: self.threads.unwrap_or_else(default_threads),
            rounds: self.rounds,
            seconds: self.seconds,
            cores,
        }
    }
}

#[derive(Debug, Args, Clone, Default)]
pub struct SceneArgs {
    /// A preset, a .toml scene or a .csv of spheres [default: gas]
    #[arg(long, value_name = "NAME|FILE", long_help = scene_long_help(),
          value_hint = clap::ValueHint::FilePath)]
    pub scene: Option<String>,
    /// Number of spheres (0 to 10000000) [default: the preset's]
    #[arg(long, value_name = "N")]
    pub count: Option<usize>,
    /// Sphere radius in box lengths (> 0, under half the box) [default: the preset's]
    #[arg(long, value_name = "R")]
    pub radius: Option<f64>,
    /// Speed (rms) in box lengths per second (>= 0) [default: the preset's]
    #[arg(long, value_name = "V")]
    pub speed: Option<f64>,
    /// Random seed of the scene [default: 1]
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,
    /// Edge of the cube (> 0) [default: 1]
    #[arg(long = "box", value_name = "L")]
    pub size: Option<f64>,
}

#[derive(Debug, Args, Clone)]
pub struct RunArgs {
    /// Step length in seconds (> 0), a number or a fraction such as 1/120
    #[arg(long, default_value = "1/60", value_name = "DT", value_parser = parse_seconds)]
    pub dt: f64,
    /// Steps per rendered frame (0 freezes; at most 1000000), or `max`:
    /// flat out, as many steps as the frame rate allows (key x) [default: 1];
    /// for bench, steps per engine frame [default: a hundredth of --steps]
    #[arg(long, value_name = "N|max", value_parser = values::parse_tick)]
    pub tick: Option<values::Tick>,
    /// Collision model
    #[arg(long, value_enum, default_value_t = ModelArg::Swept, value_name = "MODEL")]
    pub model: ModelArg,
    /// For --model auto: the fraction of the smaller radius by which spheres
    /// may sink into each other, 0 to 1 [default: 0, contacts exact]
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
    /// Where the physics runs
    #[arg(long, value_enum, default_value_t = ThreadingArg::Off, value_name = "MODE")]
    pub threading: ThreadingArg,
    /// Pool threads [default: available cores]
    #[arg(long, value_name = "K", help = threads_help(),
          value_parser = RangedU64ValueParser::<usize>::new().range(1..=MAX_THREADS as u64))]
    pub threads: Option<usize>,
}
impl Cli {
    /// Parse `args` (the program name first), as `main` does. Flags given
    /// before a subcommand belong to the terminal app, and clap would drop
    /// them silently, so they are refused (a usage error, exit code 2).
    pub fn try_parse_checked<I, T>(args: I) -> Result<Cli, clap::Error>
    where
        I: IntoIterator<Item = T>,
        T: Into<OsString> + Clone,
    {
        let mut cmd = Cli::command();
        let matches = cmd.try_get_matches_from_mut(args)?;
        if let Some((sub, _)) = matches.subcommand() {
            let early = flags_given(&cmd, &matches);
            if !early.is_empty() {
                let msg = early_flags_message(&cmd, sub, &early);
                return Err(cmd.error(clap::error::ErrorKind::ArgumentConflict, msg));
            }
        }
        let cli = Cli::from_arg_matches(&matches).map_err(|e| e.format(&mut cmd))?;
        for w in cli.warnings() {
            eprintln!("ballpit: warning: {w}");
        }
        Ok(cli)
    }

    /// Input that is legal but does nothing in the mode chosen.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        if let Some(Command::Bench(b)) = &self.command
            && let Some(k) = b.run.threads
            && b.run.threading != ThreadingArg::Pool
        {
            // The app keeps it for `d`; a bench never switches modes.
            w.push(format!(
                "--threads {k} does nothing with --threading {}: it sets the pool, used with --threading pool",
                crate::engine::Threading::from(b.run.threading).name()
            ));
        }
        w
    }

    /// The man page (roff) of the whole command line, with its keys.
    pub fn man_page() -> std::io::Result<Vec<u8>> {
        help::man_page(&Cli::command())
    }

    /// The validated screen options.
    pub fn options(&self) -> crate::tui::Options {
        crate::tui::Options {
            fps: self.fps,
            color: self.color.into(),
            flat_out: self.run.tick == Some(values::Tick::Max),
        }
    }
}

/// What to do with flags typed before `sub`: move those `sub` takes after
/// it, drop those only the terminal app has (`--fps`, `--color`).
fn early_flags_message(cmd: &clap::Command, sub: &str, early: &[String]) -> String {
    let takes = |flag: &str| {
        cmd.find_subcommand(sub).is_some_and(|c| {
            c.get_arguments()
                .any(|a| a.get_long().is_some_and(|l| flag == format!("--{l}")))
        })
    };
    let (movable, app_only): (Vec<&String>, Vec<&String>) = early.iter().partition(|f| takes(f));
    let join = |v: &[&String]| v.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(", ");
    let mut parts = Vec::new();
    if let Some(first) = movable.first() {
        parts.push(format!(
            "{} must come after `{sub}` (ballpit {sub} {first} ...)",
            join(&movable)
        ));
    }
    if !app_only.is_empty() {
        let (verb, pron) = if app_only.len() == 1 {
            ("is", "it")
        } else {
            ("are", "them")
        };
        parts.push(format!(
            "{} {verb} the terminal app's and {} nothing for `{sub}`: drop {pron}",
            join(&app_only),
            if app_only.len() == 1 { "does" } else { "do" }
        ));
    }
    parts.join("; ")
}

/// The long names of the top-level flags the user typed.
fn flags_given(cmd: &clap::Command, m: &ArgMatches) -> Vec<String> {
    cmd.get_arguments()
        .filter(|a| m.value_source(a.get_id().as_str()) == Some(ValueSource::CommandLine))
        .filter_map(|a| a.get_long().map(|l| format!("--{l}")))
        .collect()
}

/// `--dt` as every command takes it: a finite step above 0 (the parser
/// reads numbers and fractions; this is the one check of their range).
pub fn check_dt(dt: f64) -> Result<f64, BadInput> {
    if dt.is_finite() && dt > 0.0 {
        Ok(dt)
    } else {
        bad!("--dt must be a finite number > 0, got {dt}")
    }
}

impl SceneArgs {
    pub fn spec(&self) -> SceneSpec {
        SceneSpec {
            scene: self.scene.clone(),
            count: self.count,
            radius: self.radius,
            speed: self.speed,
            seed: self.seed,
            size: self.size,
        }
    }
}

impl RunArgs {
    /// Steps per engine frame for `bench`: `--tick`, else a hundredth of
    /// the run. Flat out is the screen's: a bench runs a set number of steps.
    pub fn bench_tick(&self, steps: u64) -> Result<u32, BadInput> {
        match self.tick {
            Some(values::Tick::Max) => {
                bad!("--tick max is for the screen; bench runs --steps steps in frames of --tick N")
            }
            Some(values::Tick::Steps(n)) => Ok(n),
            None => Ok(steps.div_ceil(100).clamp(1, u64::from(u32::MAX)) as u32),
        }
    }

    pub fn settings(&self) -> Result<Settings, BadInput> {
        check_dt(self.dt)?;
        let threads = self.threads.unwrap_or_else(default_threads);
        let mut model: ModelKind = self.model.into();
        if let Some(t) = self.tolerance {
            let Some(tol) = Tolerance::new(t) else {
                return bad!(
                    "--tolerance must be a fraction of the smaller radius from 0 to 1, got {t}"
                );
            };
            if model.tolerance().is_some() {
                model = ModelKind::Auto(tol);
            } else {
                eprintln!(
                    "ballpit: warning: --tolerance only steers --model auto; {model} ignores it"
                );
            }
        }
        Ok(Settings {
            model,
            dt: self.dt,
            // Flat out keeps tick 1 to go back to (key x).
            tick: self.tick.and_then(values::Tick::steps).unwrap_or(1),
            threading: self.threading.into(),
            threads,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_command_is_well_formed() {
        Cli::command().debug_assert();
    }

    #[test]
    fn tradeoff_help_names_every_model_it_runs() {
        let mut cmd = Cli::command();
        let help = cmd
            .find_subcommand_mut("tradeoff")
            .expect("a tradeoff subcommand")
            .render_long_help()
            .to_string();
        assert!(
            help.contains("Runs discrete, swept, exact and auto (auto at tolerance 0"),
            "{help}"
        );
        for m in ModelKind::ALL {
            assert!(help.contains(m.name()), "{m} missing from: {help}");
        }
    }
}
