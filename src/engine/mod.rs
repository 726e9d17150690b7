//! The engine: owns the world, runs frames of `tick` steps in one of the
//! threading modes, and hands out snapshots. It knows nothing of drawing.
//!
//! API contract (the TUI and `bench` depend on it; extend, don't break):
//! `Engine::new`, `command`, `start_frame`, `finish_frame`, `snapshot`,
//! `settings`, `world`.
use crate::physics::{Counters, Model, ModelKind, Serial, World};
use std::fmt;
use std::str::FromStr;
use std::time::Instant;

/// Where the physics runs (DESIGN.md, Threading).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Threading {
    Off,
    Worker,
    Pool,
    Split,
}

impl Threading {
    pub const ALL: [Threading; 4] = [
        Threading::Off,
        Threading::Worker,
        Threading::Pool,
        Threading::Split,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Threading::Off => "off",
            Threading::Worker => "worker",
            Threading::Pool => "pool",
            Threading::Split => "split",
        }
    }

    /// The `d` key: worker → pool → split → worker (off stays off).
    pub fn next_threaded(self) -> Threading {
        match self {
            Threading::Off => Threading::Off,
            Threading::Worker => Threading::Pool,
            Threading::Pool => Threading::Split,
            Threading::Split => Threading::Worker,
        }
    }
}

impl fmt::Display for Threading {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Threading {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .iter()
            .copied()
            .find(|t| t.name() == s)
            .ok_or_else(|| {
                format!("unknown threading '{s}' (expected one of: off, worker, pool, split)")
            })
    }
}

/// What the engine runs with; changed only through [`Command`]s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    pub model: ModelKind,
    pub dt: f64,
    /// Steps per frame; 0 freezes the physics.
    pub tick: u32,
    pub threading: Threading,
    /// Pool size for `pool`.
    pub threads: usize,
}

/// Changes the user asks for; applied at the next frame boundary, in order.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    SetThreading(Threading),
    SetThreads(usize),
    SetTick(u32),
    SetModel(ModelKind),
    /// New spheres go into free space; removal drops the last ones.
    SetCount(usize),
    /// Growth stops where spheres would touch; the snapshot's notice says so.
    SetRadius(f64),
    /// Back to the scene as it started.
    Reset,
}

/// What the screen needs of one sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereView {
    pub pos: [f64; 3],
    pub radius: f64,
    pub speed: f64,
}

/// One finished frame, read by the renderer while the next one computes.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub frame: u64,
    pub time: f64,
    pub size: f64,
    pub spheres: Vec<SphereView>,
    pub energy: f64,
    /// Energy right after the last reset (or scene start), for the drift.
    pub energy_reset: f64,
    pub max_overlap_rel: f64,
    pub escaped: usize,
    pub counters: Counters,
    /// Wall-clock seconds the physics of this frame took.
    pub physics_seconds: f64,
    /// Steps run in this frame.
    pub steps: u64,
    /// The settings this frame ran with (what really ran).
    pub settings: Settings,
    /// A limit the last command hit, e.g. "radius limit: spheres touch".
    pub notice: Option<String>,
}

impl Snapshot {
    fn capture(world: &World, settings: Settings, energy_reset: f64) -> Snapshot {
        Snapshot {
            frame: 0,
            time: world.time,
            size: world.size,
            spheres: world
                .spheres
                .iter()
                .map(|s| SphereView {
                    pos: s.pos.to_array(),
                    radius: s.radius,
                    speed: s.vel.length(),
                })
                .collect(),
            energy: world.kinetic_energy(),
            energy_reset,
            max_overlap_rel: world.max_overlap_rel(),
            escaped: world.escaped(),
            counters: world.counters,
            physics_seconds: 0.0,
            steps: 0,
            settings,
            notice: None,
        }
    }

    /// `|E - E_reset| / E_reset` (0 for a world at rest).
    pub fn energy_drift(&self) -> f64 {
        if self.energy_reset > 0.0 {
            (self.energy - self.energy_reset).abs() / self.energy_reset
        } else {
            0.0
        }
    }
}

/// Single-threaded placeholder of the engine: runs every mode on the calling
/// thread. The threading issue replaces the inside, keeping this API.
pub struct Engine {
    world: World,
    initial: World,
    model: Box<dyn Model>,
    settings: Settings,
    pending: Vec<Command>,
    snapshot: Snapshot,
    energy_reset: f64,
    frame: u64,
}

impl Engine {
    pub fn new(world: World, settings: Settings) -> anyhow::Result<Engine> {
        let energy_reset = world.kinetic_energy();
        Ok(Engine {
            snapshot: Snapshot::capture(&world, settings, energy_reset),
            initial: world.clone(),
            model: settings.model.build(),
            world,
            settings,
            pending: Vec::new(),
            energy_reset,
            frame: 0,
        })
    }

    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Queue a change for the next frame boundary.
    pub fn command(&mut self, cmd: Command) {
        self.pending.push(cmd);
    }

    /// Begin computing the next frame (threaded modes return at once).
    pub fn start_frame(&mut self) -> anyhow::Result<()> {
        for cmd in std::mem::take(&mut self.pending) {
            match cmd {
                Command::SetThreading(t) => self.settings.threading = t,
                Command::SetThreads(k) => self.settings.threads = k.max(1),
                Command::SetTick(t) => self.settings.tick = t,
                Command::SetModel(m) => {
                    self.settings.model = m;
                    self.model = m.build();
                }
                Command::SetCount(_) | Command::SetRadius(_) => {}
                Command::Reset => {
                    self.world = self.initial.clone();
                    self.model = self.settings.model.build();
                    self.energy_reset = self.world.kinetic_energy();
                }
            }
        }
        let t0 = Instant::now();
        let steps = u64::from(self.settings.tick);
        self.model
            .advance(&mut self.world, self.settings.dt, steps, &Serial);
        let physics_seconds = t0.elapsed().as_secs_f64();
        self.frame += 1;
        self.snapshot = Snapshot::capture(&self.world, self.settings, self.energy_reset);
        self.snapshot.frame = self.frame;
        self.snapshot.physics_seconds = physics_seconds;
        self.snapshot.steps = steps;
        Ok(())
    }

    /// Wait for the frame started last and make it the current snapshot.
    pub fn finish_frame(&mut self) -> anyhow::Result<&Snapshot> {
        Ok(&self.snapshot)
    }

    /// The latest finished frame.
    pub fn snapshot(&self) -> &Snapshot {
        &self.snapshot
    }

    /// The world between frames (after `finish_frame`).
    pub fn world(&self) -> &World {
        &self.world
    }
}
