//! The engine: owns the world, runs frames of `tick` steps in one of the
//! threading modes, and hands out snapshots. It knows nothing of drawing.
//!
//! API contract (the TUI and `bench` depend on it; extend, don't break):
//! `Engine::new`, `command`, `start_frame`, `finish_frame`, `snapshot`,
//! `settings`, `world`.
//!
//! Threads: `physics` (created with the engine, asleep on a channel until a
//! frame is handed to it) takes every threaded frame; in `pool` it hands the
//! frame on to `pool-0..K-1`, which run it and its data-parallel sections
//! while `physics` sleeps; `split` lends it `split-pair` and `split-wall`
//! for the two functional jobs. The physics
//! cuts its work into fixed blocks combined in block order, so every mode
//! gives the same bits. The frame (world, model, executor, back snapshot)
//! moves whole to the thread that runs it and back, so no lock guards the
//! world and a mode switch between frames cannot lose or repeat anything.
mod frame;
mod pool;
mod probe;
mod replay;
mod snapshot;
mod span;
mod start;
mod worker;

pub use pool::{KEPT_WORKER, PoolExec, Refused, SPLIT_ROLES, SplitExec, kept_pool, pool_name};
pub use replay::replay;
pub use snapshot::{Snapshot, SphereView};
pub use span::{SpanExec, WorkSpan, makespan};
pub use start::Rebuild;

use crate::cpu::ThreadRole;
use crate::physics::{Model, ModelKind, Serial, World, edit};
use frame::{Frame, SharedExec};
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use start::Start;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};
use strum::{Display, EnumCount, EnumString, IntoStaticStr};
pub use worker::Notify;
use worker::Worker;

/// Where the physics runs (docs/design.md, Threading); the names are the
/// command line's.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, Display, EnumCount, EnumString, IntoStaticStr,
)]
#[strum(serialize_all = "lowercase")]
pub enum Threading {
    Off,
    Worker,
    Pool,
    Split,
}

impl Threading {
    /// Every mode (a new variant does not compile until it is listed here).
    pub const ALL: [Threading; Self::COUNT] = [
        Threading::Off,
        Threading::Worker,
        Threading::Pool,
        Threading::Split,
    ];

    pub fn name(self) -> &'static str {
        self.into()
    }

    /// The `d` key: worker → pool → split → worker (off stays off).
    #[must_use]
    pub fn next_threaded(self) -> Threading {
        match self {
            Threading::Off => Threading::Off,
            Threading::Worker => Threading::Pool,
            Threading::Pool => Threading::Split,
            Threading::Split => Threading::Worker,
        }
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
    /// New spheres (median radius, rms speed, random directions) go into
    /// free space; removal drops the last ones.
    SetCount(usize),
    /// Scale every radius so the largest becomes this; growing pushes the
    /// spheres apart (masses, velocities and energy unchanged). When the box
    /// is full, the snapshot's notice says so.
    SetRadius(f64),
    /// Back to the scene as it started.
    Reset,
}

/// The default pool size: the cores the system gives us.
pub fn default_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get().min(MAX_THREADS))
}

/// Most pool threads `SetThreads` allows (the command line and the keys too).
pub const MAX_THREADS: usize = 256;

/// The threads a mode puts physics work on, driver first; `off` runs on the
/// calling thread. In `pool` the frame itself runs on a pool thread (rayon
/// picks which) while `physics` sleeps until it is done, so only the pool
/// threads are named. A model that runs on one lane (`exact`) ignores the
/// executor's lanes, so in `split` it runs on `physics` alone.
pub fn physics_threads(threading: Threading, threads: usize, model: ModelKind) -> Vec<String> {
    match threading {
        Threading::Off => vec![
            std::thread::current()
                .name()
                .map_or_else(|| ThreadRole::Main.name().into_owned(), String::from),
        ],
        Threading::Pool => (0..threads).map(pool_name).collect(),
        Threading::Split if !model.runs_on_one_lane() => std::iter::once(ThreadRole::Physics)
            .chain(SPLIT_ROLES)
            .map(|r| r.name().into_owned())
            .collect(),
        Threading::Worker | Threading::Split => vec![ThreadRole::Physics.name().into_owned()],
    }
}
/// Seeds the placement of spheres added by `SetCount`, so runs repeat.
#[allow(clippy::unreadable_literal)] // "ballpit!" in ASCII
const EDIT_SEED: u64 = 0x62616c6c70697421;

/// Owns the world and runs frames in the chosen threading mode.
///
/// Frame loop: `start_frame` (applies queued commands, then starts the
/// physics of the next frame: on the `physics` thread in threaded modes,
/// returning at once; on the caller when threading is off); draw
/// `snapshot()` meanwhile; `finish_frame` waits for the frame and makes its
/// snapshot current. Modes change only between frames, when the world is
/// back home, so nothing is lost or repeated.
pub struct Engine {
    /// The frame, while no thread is computing it.
    home: Option<Box<Frame>>,
    in_flight: bool,
    front: Snapshot,
    /// The scene as it started, for Reset.
    start: Start,
    /// The start's median radius and rms speed, for spheres added to an
    /// emptied box.
    start_radius: Option<f64>,
    start_speed: f64,
    settings: Settings,
    pending: Vec<Command>,
    worker: Worker,
    serial: SharedExec,
    pool: Option<Arc<PoolExec>>,
    split: Option<Arc<SplitExec>>,
    failed: Option<String>,
    rng: Xoshiro256PlusPlus,
    /// Flat out: each frame steps for this long (see [`Engine::set_budget`]).
    budget: Option<Duration>,
    /// Frames run no step (see [`Engine::set_hold`]).
    hold: bool,
    /// The frame's step counter, and when the frame in flight started.
    progress: Arc<AtomicU64>,
    started: Instant,
    /// A frame has started: threads refused from now on are a notice, not
    /// the end of the run.
    running: bool,
}

impl Engine {
    pub fn new(world: World, settings: Settings) -> anyhow::Result<Engine> {
        let model = settings.model.build();
        Engine::with_model(world, settings, model)
    }

    /// An engine running a model of the caller's (tests, instrumented runs).
    pub fn with_model(
        world: World,
        settings: Settings,
        model: Box<dyn Model>,
    ) -> anyhow::Result<Engine> {
        let start = Start::Kept(world.clone());
        Engine::build(world, settings, model, start, true)
    }

    /// An engine that rebuilds the start on Reset instead of keeping a copy
    /// (a preset scene: `rebuild` must give the same world each time; Reset
    /// checks, and leaves a notice if not).
    ///
    /// # Errors
    /// When the `physics` thread cannot be started.
    pub fn with_rebuild(
        world: World,
        settings: Settings,
        rebuild: Rebuild,
    ) -> anyhow::Result<Engine> {
        let model = settings.model.build();
        let start = Start::rebuilt(&world, rebuild);
        Engine::build(world, settings, model, start, true)
    }

    /// An engine for runs without a screen (`bench`): its snapshots carry
    /// the figures but not the spheres, and it keeps no copy of the start,
    /// so Reset only leaves a notice. The world is then held once.
    ///
    /// # Errors
    /// When the `physics` thread cannot be started.
    pub fn headless(world: World, settings: Settings) -> anyhow::Result<Engine> {
        let model = settings.model.build();
        Engine::build(world, settings, model, Start::Dropped, false)
    }

    fn build(
        world: World,
        mut settings: Settings,
        model: Box<dyn Model>,
        start: Start,
        views: bool,
    ) -> anyhow::Result<Engine> {
        settings.threads = settings.threads.clamp(1, MAX_THREADS);
        let serial: SharedExec = Arc::new(Serial);
        let (start_radius, start_speed) = (edit::typical_radius(&world), edit::rms_speed(&world));
        let frame = Frame::new(world, model, serial.clone(), settings, views);
        let progress = frame.progress.clone();
        Ok(Engine {
            front: frame.snap.clone(),
            home: Some(Box::new(frame)),
            in_flight: false,
            start,
            start_radius,
            start_speed,
            settings,
            pending: Vec::new(),
            worker: Worker::spawn()?,
            serial,
            pool: None,
            split: None,
            failed: None,
            rng: Xoshiro256PlusPlus::seed_from_u64(EDIT_SEED),
            budget: None,
            hold: false,
            progress,
            started: Instant::now(),
            running: false,
        })
    }

    /// The settings the next frame runs with (commands queued since the
    /// last `start_frame` are not in yet).
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Flat out: from the next frame on, each frame runs whole steps until
    /// `budget` has passed (at least one, none while the tick is 0) in
    /// place of `tick` steps; `None` goes back to `tick`. The frame loop
    /// sets it from the frame period, so the screen keeps its rate.
    pub fn set_budget(&mut self, budget: Option<Duration>) {
        self.budget = budget;
    }

    /// The screen's pause: from the next frame on, while `hold`, a frame
    /// applies the queued commands and fills its snapshot but runs no step
    /// (its `steps` are 0), so a command is answered with a fresh snapshot
    /// whose settings keep the tick for the resume.
    pub fn set_hold(&mut self, hold: bool) {
        self.hold = hold;
    }

    /// Queue a change for the next frame boundary.
    pub fn command(&mut self, cmd: Command) {
        self.pending.push(cmd);
    }

    /// Begin computing the next frame: threaded modes return at once, `off`
    /// computes it here. A frame still running is finished first.
    // The frame is home once check() passed and none is in flight.
    #[allow(clippy::expect_used, clippy::missing_panics_doc)]
    pub fn start_frame(&mut self) -> anyhow::Result<()> {
        if self.in_flight {
            self.finish_frame()?;
        }
        self.check()?;
        let mut frame = self
            .home
            .take()
            .expect("a healthy engine has its frame at home");
        if let Err(e) = self.apply_commands(&mut frame) {
            self.home = Some(frame);
            return Err(e);
        }
        frame.budget = self.budget;
        frame.hold = self.hold;
        self.running = true;
        if self.settings.threading == Threading::Off {
            let frame = worker::run_caught(frame).map_err(|e| self.fail(e))?;
            self.land(frame);
        } else {
            self.worker
                .start(frame)
                .map_err(|e| self.fail(e.to_string()))?;
            self.in_flight = true;
            self.started = Instant::now();
        }
        Ok(())
    }

    /// Wait for the frame started last and make it the current snapshot.
    pub fn finish_frame(&mut self) -> anyhow::Result<&Snapshot> {
        if self.in_flight {
            self.in_flight = false;
            let frame = self.worker.wait().map_err(|e| self.fail(e))?;
            self.land(frame);
        }
        self.check()?;
        Ok(&self.front)
    }

    /// The latest finished frame.
    pub fn snapshot(&self) -> &Snapshot {
        &self.front
    }

    /// The world between frames (after `finish_frame`).
    ///
    /// # Panics
    /// While a frame is in flight or after the physics failed; see
    /// [`Engine::try_world`].
    #[allow(clippy::expect_used)] // the documented panic; try_world is the checked form
    pub fn world(&self) -> &World {
        self.try_world()
            .expect("Engine::world needs a finished frame: call finish_frame first")
    }

    /// The world, unless a frame is in flight or the physics failed.
    pub fn try_world(&self) -> Option<&World> {
        self.home.as_ref().map(|f| &f.world)
    }

    /// The world, moved out without a copy (as `try_world`: `None` while a
    /// frame is in flight or after the physics failed).
    #[must_use]
    pub fn into_world(mut self) -> Option<World> {
        self.home.take().map(|f| f.world)
    }

    /// Whether `finish_frame` would return without waiting: no frame is in
    /// flight, or the one in flight is done.
    pub fn frame_ready(&self) -> bool {
        !self.in_flight || self.worker.ready()
    }

    /// Call `f` (on the `physics` thread) whenever a threaded frame is done,
    /// so a caller waiting on something else can collect it at once.
    pub fn set_notify(&self, f: Notify) {
        self.worker.set_notify(f);
    }

    /// A threaded frame still computing: the steps it has done so far and
    /// how long it has run (the screen says a long frame is under way).
    pub fn under_way(&self) -> Option<(u64, Duration)> {
        (self.in_flight && !self.worker.ready()).then(|| {
            (
                self.progress.load(Ordering::Relaxed),
                self.started.elapsed(),
            )
        })
    }

    /// Whether a threaded frame is being computed.
    pub fn in_flight(&self) -> bool {
        self.in_flight
    }

    /// Kernel thread id of the `physics` thread (Linux), for CPU checks.
    pub fn physics_tid(&self) -> Option<i32> {
        self.worker.tid()
    }

    /// `(name, kernel thread id)` of every thread the engine has started so
    /// far (Linux): `physics`, then the pool and split threads that exist.
    pub fn thread_ids(&self) -> Vec<(String, i32)> {
        let pool = self.pool.iter().flat_map(|p| p.thread_ids());
        let split = self.split.iter().flat_map(|s| s.thread_ids());
        self.worker
            .tid()
            .map(|t| (ThreadRole::Physics.name().into_owned(), t))
            .into_iter()
            .chain(pool)
            .chain(split)
            .collect()
    }

    /// Seconds the pool has spent so far inside sections of more than one
    /// lane (`None` before a pool was first used): the rest of a pool
    /// frame's physics time is its serial part.
    pub fn parallel_seconds(&self) -> Option<f64> {
        self.pool.as_ref().map(|p| p.parallel_seconds())
    }

    /// The threads the latest finished frame's physics ran on, driver first
    /// (its snapshot's `physics_threads`); for `auto`, those of the model
    /// it ran.
    pub fn physics_threads(&self) -> Vec<String> {
        self.front.physics_threads.clone()
    }

    fn check(&self) -> anyhow::Result<()> {
        match &self.failed {
            Some(e) => Err(anyhow::anyhow!("{e}")),
            None => Ok(()),
        }
    }

    /// The physics died with the frame: the engine stays failed and says why.
    fn fail(&mut self, msg: String) -> anyhow::Error {
        self.failed = Some(msg.clone());
        anyhow::anyhow!(msg)
    }

    /// A finished frame comes home; its snapshot becomes the front one.
    fn land(&mut self, mut frame: Box<Frame>) {
        std::mem::swap(&mut self.front, &mut frame.snap);
        self.home = Some(frame);
    }

    fn apply_commands(&mut self, frame: &mut Frame) -> anyhow::Result<()> {
        for cmd in std::mem::take(&mut self.pending) {
            match cmd {
                Command::SetThreading(t) => self.settings.threading = t,
                Command::SetThreads(k) => self.settings.threads = k.clamp(1, MAX_THREADS),
                Command::SetTick(t) => self.settings.tick = t,
                Command::SetModel(m) => {
                    self.settings.model = m;
                    frame.model = m.build();
                }
                Command::SetCount(n) => {
                    // Any model may run next: plan for the hungriest. Only
                    // growth needs the check (and its read of /proc).
                    if n > frame.world.spheres.len()
                        && let Some(why) =
                            crate::memory::count_notice(n, crate::memory::available())
                    {
                        frame.notice = Some(why);
                        continue;
                    }
                    let w = &mut frame.world;
                    // An emptied box takes new spheres like the start's.
                    let (radius, speed) = if w.spheres.is_empty() {
                        (self.start_radius, self.start_speed)
                    } else {
                        (edit::typical_radius(w), edit::rms_speed(w))
                    };
                    let radius = radius.unwrap_or(0.02 * w.size);
                    frame.notice = edit::set_count(w, n, radius, speed, &mut self.rng);
                    self.edited(frame);
                }
                Command::SetRadius(r) => {
                    frame.notice = edit::set_radius(&mut frame.world, r);
                    self.edited(frame);
                }
                Command::Reset => {
                    match self.start.world() {
                        Ok(w) => frame.world = w,
                        Err(why) => {
                            frame.notice = Some(why);
                            continue;
                        }
                    }
                    self.edited(frame);
                    frame.model = self.settings.model.build();
                    frame.notice = None;
                    frame.energy_reset = frame.world.kinetic_energy();
                }
            }
        }
        frame.exec = match self.exec() {
            Ok(exec) => exec,
            Err(refused) if self.running => {
                let kept = self.keep_going();
                frame.notice = Some(refused.notice(&kept));
                self.exec()
                    .map_err(|e| crate::error::BadInput(e.to_string()))?
            }
            Err(refused) => return Err(crate::error::BadInput(refused.to_string()).into()),
        };
        frame.settings = self.settings;
        Ok(())
    }

    /// Threads were refused while running: go back to what exists (the pool
    /// there is, else `worker`) and say which.
    fn keep_going(&mut self) -> String {
        if let (Some(p), Threading::Pool) = (&self.pool, self.settings.threading) {
            self.settings.threads = p.threads();
            pool::kept_pool(p.threads())
        } else {
            self.settings.threading = Threading::Worker;
            pool::KEPT_WORKER.into()
        }
    }

    /// The spheres changed from outside the model.
    #[allow(clippy::unused_self)] // one of the engine's steps, called as one
    fn edited(&self, frame: &mut Frame) {
        frame.world.touch();
        if let Some(p) = frame.probe.as_mut() {
            p.forget();
        }
        frame.energy_reset = frame.world.kinetic_energy();
    }

    /// The executor for the current mode; pools are made when first needed
    /// and kept (asleep) while other modes run.
    #[allow(clippy::single_match_else)] // the same shape as the pool arm
    fn exec(&mut self) -> Result<SharedExec, Refused> {
        Ok(match self.settings.threading {
            Threading::Off | Threading::Worker => self.serial.clone(),
            Threading::Pool => {
                let k = self.settings.threads;
                match &self.pool {
                    Some(p) if p.threads() == k => p.clone(),
                    _ => {
                        let p = Arc::new(PoolExec::new(k)?);
                        self.pool = Some(p.clone());
                        p
                    }
                }
            }
            Threading::Split => match &self.split {
                Some(s) => s.clone(),
                None => {
                    let s = Arc::new(SplitExec::new()?);
                    self.split = Some(s.clone());
                    s
                }
            },
        })
    }
}
