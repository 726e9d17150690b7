//! The command line of docs/design.md. clap stays here: the enums below
//! mirror the domain's (models, threading modes, colours) so physics/ and
//! engine/ never see clap.
use crate::bad;
use crate::engine::{Settings, Threading};
use crate::error::BadInput;
use crate::physics::ModelKind;
use crate::scene::SceneSpec;
use crate::scene::presets::PRESETS;
use crate::tui::ColorChoice;
use clap::parser::ValueSource;
use clap::{ArgMatches, Args, CommandFactory, FromArgMatches, Parser, Subcommand, ValueEnum};
use std::ffi::OsString;
use std::path::PathBuf;
use std::time::Duration;

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
        long_about = "Measure speed against accuracy for every model over a ladder of dt.\n\n\
                      Runs discrete, swept and exact on one thread for dt = 1/15 s down to \
                      1/1920 s (halving), each for 2 simulated seconds, and measures each run \
                      against a reference run of the same scene: cost (wall seconds per \
                      simulated second), worst energy error, deepest overlap, escapes, \
                      collisions missed, and the position error at a short horizon. Prints a \
                      markdown table; the table names its reference.",
        after_help = "With --out DIR it also writes DIR/tradeoff.csv (columns: model, dt, steps, \
                      wall_s_per_sim_s, sphere_steps_per_second, energy_err_rel, max_overlap_rel, \
                      escaped, sphere_collisions, missed_rel, horizon_s, pos_err_rms, capped_steps) \
                      and DIR/tradeoff.svg (position error against cost, one line per model)."
    )]
    Tradeoff(TradeoffArgs),
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
    /// Steps per rendered frame (0 freezes) [default: 1]; for bench, steps
    /// per engine frame [default: a hundredth of --steps]
    #[arg(long, value_name = "N")]
    pub tick: Option<u32>,
    /// Collision model
    #[arg(long, value_enum, default_value_t = ModelArg::Swept, value_name = "MODEL")]
    pub model: ModelArg,
    /// Where the physics runs
    #[arg(long, value_enum, default_value_t = ThreadingArg::Off, value_name = "MODE")]
    pub threading: ThreadingArg,
    /// Pool threads (1 to 256) [default: available cores]
    #[arg(long, value_name = "K")]
    pub threads: Option<usize>,
}

/// `--model`: [`ModelKind`] as the command line names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModelArg {
    /// Move by dt, then resolve overlaps: cheapest; overlaps grow with dt x speed
    Discrete,
    /// Every contact inside each step, in time order: no tunnelling
    Swept,
    /// Event-driven, every collision in time order; dt only samples
    Exact,
}

impl From<ModelArg> for ModelKind {
    fn from(m: ModelArg) -> ModelKind {
        match m {
            ModelArg::Discrete => ModelKind::Discrete,
            ModelArg::Swept => ModelKind::Swept,
            ModelArg::Exact => ModelKind::Exact,
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

/// The fields of `bench`'s JSON line, in the order it prints them, with what
/// each holds; `bench --help` shows them and a test holds them to the output.
pub const BENCH_FIELDS: &[(&str, &str)] = &[
    ("n", "spheres"),
    ("steps", "steps run"),
    ("dt", "step length, s"),
    ("model", "collision model"),
    ("threading", "threading mode"),
    ("threads", "pool threads (--threads)"),
    (
        "physics_threads",
        "the threads the physics ran on, driver first",
    ),
    ("wall_seconds", "wall time of the stepping only"),
    ("steps_per_second", "steps / wall_seconds"),
    ("sphere_steps_per_second", "n x steps / wall_seconds"),
    ("energy_start", "kinetic energy at the start"),
    ("energy_end", "kinetic energy at the end"),
    (
        "energy_drift_rel",
        "|energy_end - energy_start| / energy_start",
    ),
    (
        "max_energy_err_rel",
        "worst relative energy error over the frames",
    ),
    (
        "escaped",
        "centres outside [r, L-r] by more than 1e-9 L, at the end",
    ),
    (
        "max_overlap_rel",
        "deepest pair overlap / smaller radius, at the end",
    ),
    ("sphere_collisions", "sphere-sphere collisions"),
    ("wall_collisions", "sphere-wall collisions"),
    (
        "wall_pressure",
        "momentum given to the walls / (simulated time x wall area)",
    ),
    (
        "collisions_per_second",
        "sphere_collisions per simulated second",
    ),
    ("temperature", "mean kinetic energy per sphere, 2/3 x E/n"),
    (
        "capped_steps",
        "steps that hit the model's event cap and were finished coarsely",
    ),
    (
        "thread_cpu",
        "[{name, cpu_seconds}] for every thread of the process",
    ),
    ("peak_rss_bytes", "peak resident memory of the process"),
];

fn bench_after_help() -> String {
    let mut s = String::from("Prints one JSON line with these fields:\n");
    let w = BENCH_FIELDS.iter().map(|f| f.0.len()).max().unwrap_or(0);
    for (name, what) in BENCH_FIELDS {
        s.push_str(&format!("  {name:<w$}  {what}\n"));
    }
    s.push_str("\nExample: ballpit bench --scene dense --model exact --threading pool --steps 600");
    s
}

fn scene_long_help() -> String {
    let mut s = String::from(
        "A preset, a .toml scene or a .csv of spheres (header x,y,z,vx,vy,vz,radius,mass) \
         [default: gas]. --count, --radius, --speed, --seed and --box override a preset.\n\
         Presets:",
    );
    let w = PRESETS.iter().map(|p| p.name.len()).max().unwrap_or(0);
    for p in &PRESETS {
        s.push_str(&format!("\n  {:<w$}  {}", p.name, p.about));
    }
    s
}

/// A number of seconds, written as a number (0.01) or a fraction (1/60);
/// whether it is allowed is for the validators to say.
fn parse_seconds(s: &str) -> Result<f64, String> {
    let num = |t: &str| t.trim().parse::<f64>();
    let v = match s.split_once('/') {
        Some((a, b)) => num(a).and_then(|a| num(b).map(|b| a / b)),
        None => num(s),
    };
    v.map_err(|_| "expected seconds as a number or a fraction, e.g. 0.01 or 1/60".to_string())
}

/// Largest frame rate `--fps` accepts.
pub const MAX_FPS: f64 = 1000.0;

fn parse_fps(s: &str) -> Result<f64, String> {
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
            if let Some(first) = early.first() {
                let msg = format!(
                    "{} must come after `{sub}` (ballpit {sub} {first} ...): flags before a subcommand are the terminal app's",
                    early.join(", ")
                );
                return Err(cmd.error(clap::error::ErrorKind::ArgumentConflict, msg));
            }
        }
        Cli::from_arg_matches(&matches).map_err(|e| e.format(&mut cmd))
    }

    /// The validated screen options.
    pub fn options(&self) -> crate::tui::Options {
        crate::tui::Options {
            fps: self.fps,
            color: self.color.into(),
        }
    }
}

/// The long names of the top-level flags the user typed.
fn flags_given(cmd: &clap::Command, m: &ArgMatches) -> Vec<String> {
    cmd.get_arguments()
        .filter(|a| m.value_source(a.get_id().as_str()) == Some(ValueSource::CommandLine))
        .filter_map(|a| a.get_long().map(|l| format!("--{l}")))
        .collect()
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
    pub fn settings(&self) -> Result<Settings, BadInput> {
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return bad!("--dt must be a finite number > 0, got {}", self.dt);
        }
        let threads = match self.threads {
            Some(0) => return bad!("--threads must be at least 1"),
            Some(k) if k > 256 => return bad!("--threads {k} is more than the 256 ballpit allows"),
            Some(k) => k,
            None => std::thread::available_parallelism().map_or(1, |n| n.get()),
        };
        Ok(Settings {
            model: self.model.into(),
            dt: self.dt,
            tick: self.tick.unwrap_or(1),
            threading: self.threading.into(),
            threads,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names<T: ValueEnum>() -> Vec<String> {
        T::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value())
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
    fn dt_reads_numbers_and_fractions() {
        assert_eq!(parse_seconds("0.01"), Ok(0.01));
        assert_eq!(parse_seconds("1/60"), Ok(1.0 / 60.0));
        assert_eq!(parse_seconds("-1"), Ok(-1.0));
        for bad in ["", "1/", "/2", "a/b", "1/2/3", "ten"] {
            assert!(parse_seconds(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn the_command_is_well_formed() {
        Cli::command().debug_assert();
    }
}
