//! `ballpit bench`: run a scene headless and print one JSON line.
use crate::engine::{Command, Engine, Settings, Threading};
use crate::physics::World;
use serde::Serialize;

#[derive(Debug, Serialize)]
pub struct ThreadCpu {
    pub name: String,
    pub cpu_seconds: f64,
}

/// The fields of docs/design.md's bench JSON, plus `physics_threads`,
/// `load_average`, `collisions_per_sim_second`, `temperature` and
/// `capped_steps` (and `budget_steps`, those of them a work budget
/// stopped).
#[derive(Debug, Serialize)]
pub struct BenchReport {
    pub n: usize,
    pub steps: u64,
    pub dt: f64,
    pub model: String,
    /// What `auto` chose to run at the end and why (null for the others).
    pub model_chosen: Option<String>,
    pub model_reason: Option<String>,
    /// Not in the JSON: `auto` could not meet its tolerance (in `warnings`).
    #[serde(skip)]
    pub tolerance_unmet: bool,
    pub threading: String,
    pub threads: usize,
    /// The threads the physics really ran on (the driver first).
    pub physics_threads: Vec<String>,
    /// Wall time of the physics: every frame's steps and the detection
    /// behind its overlap readout (not the copy of the spheres for it).
    pub wall_seconds: f64,
    /// CPU seconds the `physics_threads` ran while stepping (all of their
    /// time then, the snapshots' copies included; pool threads' spinning
    /// between sections too). Read from schedstat: exact for threads that
    /// sleep between frames, up to the last scheduler tick for the caller
    /// in `off`.
    pub physics_cpu_seconds: f64,
    /// The first frame alone, which also loads the spheres into the model
    /// and builds its structures: a run's steady rate leaves it out,
    /// `(sphere_collisions - first_frame.sphere_collisions) /
    /// (physics_cpu_seconds - first_frame.physics_cpu_seconds)`.
    pub first_frame: FirstFrame,
    /// In `pool`: the part of `wall_seconds` spent inside sections that ran
    /// on more than one lane; the rest is the step's serial part (null in
    /// the other modes).
    pub parallel_seconds: Option<f64>,
    /// In `pool` of `K` threads: the CPU seconds of the same steps from the
    /// same start replayed after the timed run on a [`SpanExec`] of `K`
    /// lanes (`engine::replay`), its span on those `K` lanes and its
    /// parallelism, work over the span on unlimited lanes (so at least
    /// `work_seconds / span_seconds`). A measurement apart from the timed
    /// run, not in `wall_seconds` or `steps_per_second`; null in the other
    /// modes.
    ///
    /// [`SpanExec`]: crate::engine::SpanExec
    pub work_seconds: Option<f64>,
    pub span_seconds: Option<f64>,
    pub parallelism: Option<f64>,
    /// The 1-minute load average of the host (`/proc/loadavg`) before and
    /// after stepping, so a reader can judge the timings; empty elsewhere.
    pub load_average: Vec<f64>,
    pub steps_per_second: f64,
    pub sphere_steps_per_second: f64,
    pub energy_start: f64,
    pub energy_end: f64,
    pub energy_drift_rel: f64,
    pub max_energy_err_rel: f64,
    pub escaped: usize,
    pub max_overlap_rel: f64,
    /// Not in the JSON: the overlap readout stopped at its pair budget, so
    /// `max_overlap_rel` is a lower bound (said in `warnings`).
    #[serde(skip)]
    pub overlap_partial: bool,
    pub sphere_collisions: u64,
    pub wall_collisions: u64,
    pub wall_pressure: f64,
    /// Sphere–sphere collisions per simulated second.
    pub collisions_per_sim_second: f64,
    pub temperature: f64,
    pub capped_steps: u64,
    pub budget_steps: u64,
    pub thread_cpu: Vec<ThreadCpu>,
    pub peak_rss_bytes: u64,
    /// Where the run could not keep a model's promise, and why (empty when
    /// it kept them all).
    pub warnings: Vec<String>,
}

/// The first frame's share of a run (see [`BenchReport::first_frame`]).
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq)]
pub struct FirstFrame {
    pub physics_cpu_seconds: f64,
    pub sphere_collisions: u64,
}

/// What a reader of `report` must know before trusting its figures: the
/// promises the run could not keep, and why.
pub fn warnings(report: &BenchReport) -> Vec<String> {
    let mut w = Vec::new();
    let events = report.capped_steps - report.budget_steps.min(report.capped_steps);
    if events > 0 {
        w.push(format!(
            "{} steps hit the event cap and were finished in free flight, skipping contacts: overlaps up to {:.2e} r remain at the end (a smaller --dt or --speed avoids the cap)",
            events, report.max_overlap_rel
        ));
    }
    if report.budget_steps > 0 {
        w.push(format!(
            "{} steps ran out of their work budget (too many contacts to follow in one step) and were finished in free flight, skipping contacts: overlaps up to {:.2e} r remain at the end (a smaller --dt or --speed avoids it)",
            report.budget_steps, report.max_overlap_rel
        ));
    }
    if report.overlap_partial {
        w.push(format!(
            "more overlapping pairs than a step may answer: the overlap readout looked at the first {} of them, so max_overlap_rel is the deepest among those, a lower bound",
            crate::physics::discrete::pair_budget(report.n)
        ));
    }
    if report.tolerance_unmet {
        w.push(format!(
            "auto could not meet its tolerance and ran the strictest model: {}",
            report.model_reason.as_deref().unwrap_or("")
        ));
    }
    if report.escaped > 0 {
        w.push(format!("{} spheres ended outside the cube", report.escaped));
    }
    if report.n > 0 && report.energy_start == 0.0 {
        // Zero energy is a world at rest or masses too small for f64 (5e-324
        // at 0.1 box/s): the figure, not the motion, is what is known.
        w.push("the kinetic energy is 0 (spheres at rest, or masses too small to give an energy in f64): the energy figures say nothing".into());
    }
    w
}

/// Run `steps` steps through the engine in frames of `settings.tick` steps
/// (the last one shorter), in the settings' threading mode; returns the
/// report and the final world (for `--dump`). `wall_seconds` counts only
/// the stepping, not the snapshots between frames. The engine is headless
/// and the final world is moved out of it, so the spheres are held once.
pub fn run(world: World, settings: &Settings, steps: u64) -> anyhow::Result<(BenchReport, World)> {
    let e0 = world.kinetic_energy();
    let t_start = world.time;
    let frame = u64::from(settings.tick.max(1));
    let mut engine = Engine::headless(
        world,
        Settings {
            tick: settings.tick.max(1),
            ..*settings
        },
    )?;
    let load_start = load_average();
    // CPU already run by the threads that exist before stepping; threads
    // born while stepping (pools) start from 0.
    let cpu_before: Vec<(i32, f64)> = [crate::cpu::current_tid(), engine.physics_tid()]
        .into_iter()
        .flatten()
        .map(|tid| (tid, crate::cpu::thread_cpu_seconds_of(tid).unwrap_or(0.0)))
        .collect();
    let parallel_before = engine.parallel_seconds().unwrap_or(0.0);
    let mut first_frame = FirstFrame::default();
    let mut after_first = |e: &Engine| {
        first_frame = FirstFrame {
            physics_cpu_seconds: physics_cpu(e, &e.physics_threads(), &cpu_before),
            sphere_collisions: e.snapshot().counters.sphere_collisions,
        };
    };
    let rel = |e| energy_change(e, e0);
    let (wall, max_err) = step_frames(&mut engine, steps, frame, &rel, &mut after_first)?;
    let physics_threads = engine.physics_threads();
    let measured = Measured {
        wall,
        max_err,
        parallel_seconds: (settings.threading == Threading::Pool)
            .then(|| engine.parallel_seconds().unwrap_or(0.0) - parallel_before),
        physics_cpu_seconds: physics_cpu(&engine, &physics_threads, &cpu_before),
        first_frame,
        physics_threads,
        load_average: load_start.into_iter().chain(load_average()).collect(),
        // Read while the engine's threads are still alive.
        thread_cpu: crate::cpu::thread_cpu_seconds()
            .into_iter()
            .map(|(name, cpu_seconds)| ThreadCpu { name, cpu_seconds })
            .collect(),
    };
    // The last snapshot's figures are the final world's.
    let last = engine.snapshot().clone();
    let world = engine
        .into_world()
        .ok_or_else(|| anyhow::anyhow!("the engine lost its world"))?;
    let report = report_of(
        &world,
        settings,
        steps,
        e0,
        world.time - t_start,
        measured,
        &last,
    );
    Ok((report, world))
}

/// `ballpit bench`: [`run`], and for a pool of `K` threads the same steps
/// from the same start replayed on `K` lanes one after another on this
/// thread, for `work_seconds`, `span_seconds` and `parallelism`. The start
/// is copied for the replay (the copy is in `peak_rss_bytes`).
///
/// # Errors
/// As [`run`]; and when the replay ends in other bits than the timed run.
pub fn run_spanned(
    world: World,
    settings: &Settings,
    steps: u64,
) -> anyhow::Result<(BenchReport, World)> {
    if settings.threading != Threading::Pool {
        return run(world, settings, steps);
    }
    let start = world.clone();
    let (report, end) = run(world, settings, steps)?;
    let lanes = report.threads.clamp(1, crate::engine::MAX_THREADS);
    let replayed = Settings {
        tick: settings.tick.max(1),
        ..*settings
    };
    let (ws, again) = crate::engine::replay(start, replayed, steps, lanes);
    if again.spheres != end.spheres || again.counters != end.counters {
        anyhow::bail!(
            "the replay of the run on {lanes} lanes (for work_seconds and span_seconds) ended in other bits than the timed run: a bug, please report it"
        );
    }
    let report = BenchReport {
        work_seconds: Some(ws.work),
        span_seconds: Some(ws.span),
        parallelism: Some(ws.parallelism()),
        ..report
    };
    Ok((report, end))
}

/// The energy's change from `e0`, relative where `e0` is not 0.
fn energy_change(e: f64, e0: f64) -> f64 {
    if e0 > 0.0 {
        (e - e0).abs() / e0
    } else {
        (e - e0).abs()
    }
}

/// What [`run`] measured while the engine stepped.
struct Measured {
    wall: f64,
    max_err: f64,
    parallel_seconds: Option<f64>,
    physics_cpu_seconds: f64,
    first_frame: FirstFrame,
    physics_threads: Vec<String>,
    load_average: Vec<f64>,
    thread_cpu: Vec<ThreadCpu>,
}

/// The report of a run of `steps` that took the world from energy `e0`
/// over `sim` simulated seconds to `world`, `last` its last snapshot.
fn report_of(
    world: &World,
    settings: &Settings,
    steps: u64,
    e0: f64,
    sim: f64,
    m: Measured,
    last: &crate::engine::Snapshot,
) -> BenchReport {
    let n = world.spheres.len();
    let per_sec = |x: f64| if m.wall > 0.0 { x / m.wall } else { 0.0 };
    let per_sim = |x: f64| if sim > 0.0 { x / sim } else { 0.0 };
    let c = world.counters;
    let area = 6.0 * world.size * world.size;
    let choice = last.choice.as_ref();
    let report = BenchReport {
        n,
        steps,
        dt: settings.dt,
        model: settings.model.name().to_string(),
        model_chosen: choice.map(|c| c.model.name().to_string()),
        tolerance_unmet: choice.is_some_and(|c| c.unmet),
        model_reason: choice.map(|c| c.reason.clone()),
        threading: settings.threading.name().to_string(),
        threads: settings.threads,
        physics_threads: m.physics_threads,
        wall_seconds: m.wall,
        physics_cpu_seconds: m.physics_cpu_seconds,
        first_frame: m.first_frame,
        parallel_seconds: m.parallel_seconds,
        work_seconds: None,
        span_seconds: None,
        parallelism: None,
        load_average: m.load_average,
        steps_per_second: per_sec(steps as f64),
        sphere_steps_per_second: per_sec(steps as f64 * n as f64),
        energy_start: e0,
        energy_end: last.energy,
        energy_drift_rel: energy_change(last.energy, e0),
        max_energy_err_rel: m.max_err.max(energy_change(last.energy, e0)),
        escaped: last.escaped,
        max_overlap_rel: last.max_overlap_rel,
        overlap_partial: last.overlap_partial,
        sphere_collisions: c.sphere_collisions,
        wall_collisions: c.wall_collisions,
        wall_pressure: per_sim(c.wall_momentum / area),
        collisions_per_sim_second: per_sim(c.sphere_collisions as f64),
        temperature: world.temperature(),
        capped_steps: c.capped_steps,
        budget_steps: c.budget_steps,
        thread_cpu: m.thread_cpu,
        peak_rss_bytes: peak_rss_bytes(),
        warnings: Vec::new(),
    };
    BenchReport {
        warnings: warnings(&report),
        ..report
    }
}

/// Run `steps` steps in frames of `frame` steps (the last one shorter):
/// the physics seconds they took and the worst energy error `rel` gave;
/// `after_first` reads the engine once the first frame is done.
fn step_frames(
    engine: &mut Engine,
    steps: u64,
    frame: u64,
    rel: &dyn Fn(f64) -> f64,
    after_first: &mut dyn FnMut(&Engine),
) -> anyhow::Result<(f64, f64)> {
    let (mut wall, mut max_err, mut done) = (0.0, 0.0f64, 0);
    while done < steps {
        let now = frame.min(steps - done);
        if now != frame || done == 0 {
            engine.command(Command::SetTick(now as u32));
        }
        engine.start_frame()?;
        let snap = engine.finish_frame()?;
        wall += snap.physics_seconds;
        max_err = max_err.max(rel(snap.energy));
        if done == 0 {
            after_first(engine);
        }
        done += now;
    }
    Ok((wall, max_err))
}

/// CPU seconds the threads named in `names` ran since `before` (by
/// thread id; a thread not in it started later, from 0).
fn physics_cpu(engine: &Engine, names: &[String], before: &[(i32, f64)]) -> f64 {
    let caller = std::thread::current().name().unwrap_or("main").to_string();
    let threads = engine
        .thread_ids()
        .into_iter()
        .chain(crate::cpu::current_tid().map(|t| (caller, t)));
    threads
        .filter(|(name, _)| names.contains(name))
        .map(|(_, tid)| {
            let start = before.iter().find(|b| b.0 == tid).map_or(0.0, |b| b.1);
            crate::cpu::thread_cpu_seconds_of(tid).map_or(0.0, |now| now - start)
        })
        .sum()
}

/// The 1-minute load average (Linux), `None` elsewhere.
pub fn load_average() -> Option<f64> {
    crate::procfs::loadavg_1min()
}

/// `VmHWM` of this process (0 where /proc is not there).
pub fn peak_rss_bytes() -> u64 {
    crate::procfs::status_kib("VmHWM").map_or(0, |kib| kib.saturating_mul(1024))
}
