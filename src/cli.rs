//! The command line of DESIGN.md.
use crate::bad;
use crate::engine::{Settings, Threading};
use crate::error::BadInput;
use crate::physics::ModelKind;
use crate::scene::SceneSpec;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "ballpit",
    version,
    about = "Elastic spheres in a cube, on worker threads, drawn in your terminal",
    after_help = "Without a subcommand, opens the terminal app. Press ? in it for the keys.",
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
    /// Frames per second to draw at most
    #[arg(long, default_value_t = 30.0, value_name = "F")]
    pub fps: f64,
    /// Colours: 16 (default, cheap over SSH), 256 or true; NO_COLOR is honoured
    #[arg(long, value_name = "16|256|true")]
    pub color: Option<String>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scene headless and print one JSON line
    #[command(allow_negative_numbers = true)]
    Bench(BenchArgs),
    /// Measure speed against accuracy for every model over a ladder of dt
    #[command(allow_negative_numbers = true)]
    Tradeoff(TradeoffArgs),
}

#[derive(Debug, Args)]
pub struct BenchArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub run: RunArgs,
    /// Steps to run
    #[arg(long, value_name = "K")]
    pub steps: u64,
    /// Write the final state as a sphere CSV
    #[arg(long, value_name = "FILE.csv")]
    pub dump: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct TradeoffArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Write tradeoff.csv and tradeoff.svg into this directory
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

#[derive(Debug, Args, Clone, Default)]
pub struct SceneArgs {
    /// A preset (gas, billiards, dense, projectiles, cradle, mixed), a .toml scene or a .csv of spheres
    #[arg(long, value_name = "NAME|FILE")]
    pub scene: Option<String>,
    /// Number of spheres
    #[arg(long, value_name = "N")]
    pub count: Option<usize>,
    /// Sphere radius, in box lengths
    #[arg(long, value_name = "R")]
    pub radius: Option<f64>,
    /// Speed (rms), in box lengths per second
    #[arg(long, value_name = "V")]
    pub speed: Option<f64>,
    /// Random seed of the scene
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,
    /// Edge of the cube
    #[arg(long = "box", value_name = "L")]
    pub size: Option<f64>,
}

#[derive(Debug, Args, Clone)]
pub struct RunArgs {
    /// Step length in seconds
    #[arg(long, default_value_t = 1.0 / 60.0, value_name = "DT")]
    pub dt: f64,
    /// Steps per rendered frame (0 freezes); for `bench`, steps per engine
    /// frame (default: a hundredth of --steps)
    #[arg(long, value_name = "N")]
    pub tick: Option<u32>,
    /// Collision model
    #[arg(long, default_value = "swept", value_name = "MODEL")]
    pub model: ModelKind,
    /// Where the physics runs: off, worker, pool, split
    #[arg(long, default_value = "off", value_name = "T")]
    pub threading: Threading,
    /// Pool threads (default: available cores)
    #[arg(long, value_name = "K")]
    pub threads: Option<usize>,
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
            model: self.model,
            dt: self.dt,
            tick: self.tick.unwrap_or(1),
            threading: self.threading,
            threads,
        })
    }
}
