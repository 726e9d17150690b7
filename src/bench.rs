//! `ballpit bench`: run a scene headless and print one JSON line.
use crate::engine::{Command, Engine, Settings};
use crate::physics::World;
use serde::Serialize;

#[derive(Debug, Serialize)]
pub struct ThreadCpu {
    pub name: String,
    pub cpu_seconds: f64,
}

/// The fields of docs/design.md's bench JSON, plus `capped_steps`,
/// `temperature` and `collisions_per_second`.
#[derive(Debug, Serialize)]
pub struct BenchReport {
    pub n: usize,
    pub steps: u64,
    pub dt: f64,
    pub model: String,
    pub threading: String,
    pub threads: usize,
    /// The threads the physics really ran on (the driver first).
    pub physics_threads: Vec<String>,
    pub wall_seconds: f64,
    pub steps_per_second: f64,
    pub sphere_steps_per_second: f64,
    pub energy_start: f64,
    pub energy_end: f64,
    pub energy_drift_rel: f64,
    pub max_energy_err_rel: f64,
    pub escaped: usize,
    pub max_overlap_rel: f64,
    pub sphere_collisions: u64,
    pub wall_collisions: u64,
    pub wall_pressure: f64,
    pub collisions_per_second: f64,
    pub temperature: f64,
    pub capped_steps: u64,
    pub thread_cpu: Vec<ThreadCpu>,
    pub peak_rss_bytes: u64,
}

/// Run `steps` steps through the engine in frames of `settings.tick` steps
/// (the last one shorter), in the settings' threading mode; returns the
/// report and the final world (for `--dump`). `wall_seconds` counts only
/// the stepping, not the snapshots between frames.
pub fn run(world: World, settings: &Settings, steps: u64) -> anyhow::Result<(BenchReport, World)> {
    let e0 = world.kinetic_energy();
    let rel = |e: f64| {
        if e0 > 0.0 {
            (e - e0).abs() / e0
        } else {
            (e - e0).abs()
        }
    };
    let t_start = world.time;
    let frame = u64::from(settings.tick.max(1));
    let mut engine = Engine::new(
        world,
        Settings {
            tick: settings.tick.max(1),
            ..*settings
        },
    )?;
    let mut max_err: f64 = 0.0;
    let mut wall = 0.0;
    let mut done = 0;
    while done < steps {
        let now = frame.min(steps - done);
        if now != frame || done == 0 {
            engine.command(Command::SetTick(now as u32));
        }
        engine.start_frame()?;
        let snap = engine.finish_frame()?;
        wall += snap.physics_seconds;
        max_err = max_err.max(rel(snap.energy));
        done += now;
    }
    let world = engine.world().clone();
    let physics_threads = engine.physics_threads();
    // Read while the engine's threads are still alive.
    let thread_cpu = crate::cpu::thread_cpu_seconds()
        .into_iter()
        .map(|(name, cpu_seconds)| ThreadCpu { name, cpu_seconds })
        .collect();
    drop(engine);
    let e1 = world.kinetic_energy();
    let sim = world.time - t_start;
    let n = world.spheres.len();
    let per_sec = |x: f64| if wall > 0.0 { x / wall } else { 0.0 };
    let c = world.counters;
    let area = 6.0 * world.size * world.size;
    let report = BenchReport {
        n,
        steps,
        dt: settings.dt,
        model: settings.model.name().to_string(),
        threading: settings.threading.name().to_string(),
        threads: settings.threads,
        physics_threads,
        wall_seconds: wall,
        steps_per_second: per_sec(steps as f64),
        sphere_steps_per_second: per_sec(steps as f64 * n as f64),
        energy_start: e0,
        energy_end: e1,
        energy_drift_rel: rel(e1),
        max_energy_err_rel: max_err.max(rel(e1)),
        escaped: world.escaped(),
        max_overlap_rel: world.max_overlap_rel(),
        sphere_collisions: c.sphere_collisions,
        wall_collisions: c.wall_collisions,
        wall_pressure: if sim > 0.0 {
            c.wall_momentum / (sim * area)
        } else {
            0.0
        },
        collisions_per_second: if sim > 0.0 {
            c.sphere_collisions as f64 / sim
        } else {
            0.0
        },
        temperature: world.temperature(),
        capped_steps: c.capped_steps,
        thread_cpu,
        peak_rss_bytes: peak_rss_bytes(),
    };
    Ok((report, world))
}

/// `VmHWM` of this process (0 where /proc is not there).
pub fn peak_rss_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<u64>().ok())
        })
        .map_or(0, |kb| kb * 1024)
}
