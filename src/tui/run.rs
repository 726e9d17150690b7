//! The frame loop and its pacing.
use super::Options;
use super::input::{reader, signals};
use super::msg::Msg;
use super::present::{AfterFirstFrame, Presenter, Scene};
use super::state::AppState;
use super::term::guard::{self, Guard};
use super::view::readouts::Stats;
use super::view::theme::Palette;
use crate::cpu::{CpuReport, Sampler};
use crate::engine::{Command, Engine, Rebuild, Settings, Snapshot};
use crate::physics::World;
use anyhow::{Context, anyhow};
use crossbeam_channel::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

/// Per-thread CPU is sampled once a second: a minute of history is 60 bars.
const SAMPLE_PERIOD: Duration = Duration::from_secs(1);

/// What a caller may add to [`run`].
#[derive(Default)]
pub struct RunExtras {
    /// Reset makes the start again from the scene's description instead of
    /// the engine keeping a copy of the spheres.
    pub rebuild: Option<Rebuild>,
    /// For `examples/panic_probe.rs`; the app passes none.
    pub after_first_frame: Option<AfterFirstFrame>,
}

/// Open the screen on `world` and run until the user quits. `opts` come
/// checked from the command line (`--fps` by clap, the terminal by
/// `Cli::run_screen`), each check in one place.
pub fn run(world: World, settings: Settings, opts: Options) -> anyhow::Result<()> {
    run_with(world, settings, opts, RunExtras::default())
}

/// [`run`], with what `extras` adds.
pub fn run_with(
    world: World,
    settings: Settings,
    opts: Options,
    extras: RunExtras,
) -> anyhow::Result<()> {
    let RunExtras {
        rebuild,
        after_first_frame,
    } = extras;
    let env = |k: &str| std::env::var(k).ok();
    let palette = Palette::resolve(opts.color, &env);
    let detected = Palette::detect(&env);
    let ascii = !super::term::caps::utf8_locale(&env);
    // crossterm drops colours itself under NO_COLOR; the resolved palette
    // already says whether there are any (a --color flag overrides NO_COLOR).
    crossterm::style::Colored::set_ansi_color_disabled(!palette.has_color());
    let mut state = AppState::new(
        &settings,
        world.spheres.len(),
        world.spheres.iter().map(|s| s.radius).fold(0.0, f64::max),
        opts.fps,
    );
    state.flat_out = opts.flat_out;
    let mut engine = match rebuild {
        Some(r) => Engine::with_rebuild(world, settings, r)?,
        None => Engine::new(world, settings)?,
    };
    // The keys send the tick when it changes; flat out from the command
    // line needs one above 0 from the first frame.
    if state.engine_tick() != settings.tick {
        engine.command(Command::SetTick(state.engine_tick()));
    }

    let (tx, rx) = crossbeam_channel::unbounded();
    // A frame slower than the frame period is collected when it is done,
    // not at the next period's start.
    let done = tx.clone();
    engine.set_notify(Box::new(move || {
        let _ = done.send(Msg::PhysicsDone);
    }));
    let guard = Guard::enter(tx.clone()).context("cannot set up the terminal")?;
    let signals = signals::spawn(tx.clone())?;
    reader::spawn_input(tx.clone())?;
    let mut result = Presenter::new(palette, ascii, after_first_frame, tx)
        .and_then(|presenter| FrameLoop::new(engine, state, presenter, detected).run(&rx));
    // A panic restores the terminal, so the frame loop may stop on a refused
    // write first: the panic is the reason to report.
    if result.is_err() && guard::panicked() {
        guard::wait_for_panic_report(Duration::from_secs(2));
        result = Err(anyhow!("a thread panicked (message above)"));
    }
    if let Some(sig) = signals::ending() {
        // The `signals` thread is ending the process by this signal: end
        // it the same way, never first with another status.
        signals::end_by(sig);
    }
    signals.close();
    drop(guard);
    result
}

#[allow(clippy::struct_excessive_bools)] // independent flags of the loop's state
struct FrameLoop {
    engine: Engine,
    state: AppState,
    presenter: Presenter,
    /// A key was handled since the last frame went out.
    update_wanted: bool,
    stats: Stats,
    sampler: Sampler,
    report: CpuReport,
    /// Commands sent that no frame has applied yet.
    pending: bool,
    /// A frame was started and not finished; whether it applied commands.
    in_flight: Option<bool>,
    /// A period began while the physics was still busy: its frame is drawn
    /// as soon as the physics is done.
    late: bool,
    /// Something on screen would change.
    dirty: bool,
    window: Window,
    /// Stopped by job control: no physics, no frames, until resumed.
    held: bool,
    /// The frame in flight spanned a stop: its physics time is not load.
    stopped_mid_frame: bool,
}

/// Counts over the current one-second window for the per-second figures.
#[derive(Default)]
struct Window {
    start: Option<Instant>,
    frames: u32,
    steps: u64,
    collisions_at_start: u64,
    physics_frames: u32,
    physics_seconds: f64,
    render_seconds: f64,
    bytes: u64,
}

impl FrameLoop {
    fn new(engine: Engine, state: AppState, presenter: Presenter, detected: Palette) -> FrameLoop {
        let collisions = collisions(engine.snapshot());
        let mut sampler = Sampler::new();
        let report = sampler.sample().clone();
        FrameLoop {
            engine,
            state,
            presenter,
            update_wanted: false,
            stats: Stats {
                detected: Some(detected),
                ..Stats::default()
            },
            sampler,
            report,
            pending: false,
            in_flight: None,
            late: false,
            dirty: true,
            window: Window {
                start: Some(Instant::now()),
                collisions_at_start: collisions,
                ..Window::default()
            },
            held: false,
            stopped_mid_frame: false,
        }
    }

    fn run(mut self, rx: &Receiver<Msg>) -> anyhow::Result<()> {
        let mut next_frame = Instant::now();
        let mut next_sample = Instant::now() + SAMPLE_PERIOD;
        // The scene at once, before a first frame's physics (a long tick in
        // `off` runs on this thread).
        self.draw(false)?;
        loop {
            let wants_frame = !self.held
                && (self.state.running() || self.pending || self.dirty || self.in_flight.is_some());
            let mut deadline = if wants_frame {
                next_frame.min(next_sample)
            } else {
                next_sample
            };
            if (self.dirty || self.update_wanted)
                && !self.held
                && let Some(t) = self.presenter.pacer.next_change()
            {
                deadline = deadline.min(t);
            }
            let first = match rx.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
                Ok(m) => Some(m),
                Err(RecvTimeoutError::Timeout) => None,
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(anyhow!("the input and signal threads stopped"));
                }
            };
            for msg in first.into_iter().chain(rx.try_iter()) {
                self.update_wanted |= self.handle(msg)?;
            }
            if guard::panicked() {
                return Err(anyhow!("a thread panicked (message above)"));
            }
            if self.state.quit {
                return Ok(());
            }
            let now = Instant::now();
            self.presenter.pacer.tick(now);
            if self.held {
                // Nothing runs while the shell has the terminal; the
                // figures start afresh on resume.
                next_sample = now + SAMPLE_PERIOD;
                next_frame = now;
                continue;
            }
            if now >= next_sample {
                self.sample(now);
                next_sample = later(next_sample, SAMPLE_PERIOD, now);
            }
            if now >= next_frame {
                let period = Duration::from_secs_f64(1.0 / self.state.fps);
                next_frame = later(next_frame, period, now);
                self.frame()?;
                // With the physics on this thread (`off`), the terminal's
                // answer to the last frame arrived while it ran: read it
                // now, or this frame waits for the next one's physics and
                // a step longer than the period halves the frame rate.
                for msg in rx.try_iter() {
                    self.update_wanted |= self.handle(msg)?;
                }
                self.present()?;
            } else if self.late && self.engine.frame_ready() {
                // In place of the frame the physics missed: never more
                // frames than periods.
                self.frame()?;
            } else {
                self.present()?;
            }
        }
    }

    /// Returns whether the screen should answer at once.
    fn handle(&mut self, msg: Msg) -> anyhow::Result<bool> {
        match msg {
            Msg::Action(action) => {
                for cmd in self.state.apply(action, self.engine.snapshot()) {
                    self.engine.command(cmd);
                    self.pending = true;
                }
                self.dirty = true;
                Ok(true)
            }
            Msg::Status(at) => {
                self.presenter.pacer.answered(at);
                Ok(false)
            }
            Msg::Written => {
                self.presenter.pacer.written();
                Ok(false)
            }
            Msg::PhysicsDone => Ok(false),
            Msg::Resize => {
                self.presenter.resize()?;
                self.dirty = true;
                Ok(true)
            }
            Msg::Signal(sig) => Err(anyhow!("stopped by {}", signals::name(sig))),
            Msg::Held => {
                self.held = true;
                self.stopped_mid_frame |= self.in_flight.is_some();
                Ok(false)
            }
            Msg::Resumed => {
                self.resume()?;
                Ok(true)
            }
            Msg::Fatal(why) => Err(anyhow!(why)),
            Msg::Panic => Err(anyhow!("a thread panicked (message above)")),
        }
    }

    /// One frame: collect the physics started last frame, start the next,
    /// and draw while it computes. The physics thus has the whole frame
    /// period, the drawing and the wait for keys included, and the loop
    /// only waits for it when it is slower than the frame rate.
    fn frame(&mut self) -> anyhow::Result<()> {
        if self.in_flight.is_some() && !self.engine.frame_ready() {
            // The physics is slower than the frame rate: keep drawing and
            // answering keys on the last snapshot rather than wait for it.
            self.late = true;
            return self.present();
        }
        self.late = false;
        if let Some(applied) = self.in_flight.take() {
            let snap = self.engine.finish_frame()?;
            self.window.steps += snap.steps;
            if !std::mem::take(&mut self.stopped_mid_frame) {
                self.window.physics_frames += 1;
                self.window.physics_seconds += snap.physics_seconds;
            }
            self.state.sync(snap, applied, self.pending);
            self.dirty = true;
        }
        if self.state.running() || self.pending {
            // Paused, a frame only answers the keys' commands: no step, the
            // tick kept for the resume.
            self.engine.set_hold(self.state.paused);
            if self.pending {
                // The key's answer first: applying it may take long (N).
                self.present()?;
            }
            let budget = self.state.flat_out;
            self.engine
                .set_budget(budget.then(|| self.stats.flat_out_budget(&self.state)));
            self.engine.start_frame()?;
            self.in_flight = Some(self.pending);
            self.pending = false;
        }
        self.present()
    }

    /// Send what the link allows: a frame when the last one is on screen,
    /// and a key's update at once (answer keys rather than wait for the
    /// next frame).
    fn present(&mut self) -> anyhow::Result<()> {
        if self.dirty && self.presenter.pacer.may_send() {
            self.draw(false)
        } else if self.update_wanted && self.presenter.pacer.may_send_update() {
            self.draw(true)
        } else {
            Ok(())
        }
    }

    /// Draw a frame, or with `update` a key's answer that keeps the canvas
    /// of the last frame when the link is slow.
    fn draw(&mut self, update: bool) -> anyhow::Result<()> {
        self.stats.under_way = self.engine.under_way();
        let scene = Scene {
            state: &self.state,
            stats: &self.stats,
            report: &self.report,
        };
        let drawn = self
            .presenter
            .draw(self.engine.snapshot(), &scene, update)?;
        self.window.render_seconds += drawn.seconds;
        self.window.bytes += drawn.bytes;
        self.window.frames += 1;
        if !drawn.kept_canvas {
            self.dirty = false;
        }
        self.update_wanted = false;
        Ok(())
    }

    /// Back from a stop: a new terminal state (ask again whether it
    /// answers), the whole screen repainted at its current size, and
    /// figures that do not count the stop.
    fn resume(&mut self) -> anyhow::Result<()> {
        self.held = false;
        let now = Instant::now();
        self.presenter.resume()?;
        self.dirty = true;
        // A sample now: the next readout spans only the time since, not
        // the stop (the report on screen stays the one before it).
        let _ = self.sampler.sample();
        self.window = Window {
            start: Some(now),
            collisions_at_start: collisions(self.engine.snapshot()),
            ..Window::default()
        };
        Ok(())
    }

    fn sample(&mut self, now: Instant) {
        self.report = self.sampler.sample().clone();
        // Figures are per-second averages: they read better than values
        // that change every frame, and they cost bytes only once a second.
        let w = &self.window;
        let secs = now
            .duration_since(w.start.unwrap_or(now))
            .as_secs_f64()
            .max(1e-9);
        let total = collisions(self.engine.snapshot());
        let st = &mut self.stats;
        st.fps = f64::from(w.frames) / secs;
        st.steps_per_second = w.steps as f64 / secs;
        st.remember(&self.state, &self.engine.snapshot().settings);
        st.collisions_per_second = total.saturating_sub(w.collisions_at_start) as f64 / secs;
        if w.frames > 0 {
            st.render_seconds = w.render_seconds / f64::from(w.frames);
            st.frame_bytes = w.bytes / u64::from(w.frames);
        }
        st.link = Some(self.presenter.pacer.describe());
        st.link_slow = self.presenter.pacer.slow();
        if w.physics_frames > 0 {
            st.physics_seconds = w.physics_seconds / f64::from(w.physics_frames);
        }
        self.window = Window {
            start: Some(now),
            collisions_at_start: total,
            ..Window::default()
        };
        self.dirty = true;
    }
}

/// The next deadline after `prev` by `period`, without piling up missed ones.
fn later(prev: Instant, period: Duration, now: Instant) -> Instant {
    let next = prev + period;
    if next <= now { now + period } else { next }
}

fn collisions(snap: &Snapshot) -> u64 {
    snap.counters.sphere_collisions + snap.counters.wall_collisions
}
