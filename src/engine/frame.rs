//! One frame's worth of work, moved whole to whichever thread runs it: the
//! world, the model, the executor, and the back snapshot to fill.
use super::Settings;
use super::probe::Probe;
use super::snapshot::{OverlapScratch, Snapshot};
use crate::physics::auto::Choice;
use crate::physics::exec::Busy;
use crate::physics::overlap::Overlap;
use crate::physics::{Exec, Model, ModelKind, World};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// An executor that can travel with the frame to the physics thread.
pub(crate) type SharedExec = Arc<dyn Exec + Send + Sync>;

pub(crate) struct Frame {
    pub world: World,
    pub model: Box<dyn Model>,
    pub exec: SharedExec,
    pub settings: Settings,
    pub energy_reset: f64,
    pub number: u64,
    pub notice: Option<String>,
    /// The back buffer: filled here, swapped to the front when done.
    pub snap: Snapshot,
    /// Whether the snapshot carries the spheres (a headless run needs none).
    pub views: bool,
    /// Flat out: step until this much time has passed (at least one step)
    /// instead of `tick` steps.
    pub budget: Option<Duration>,
    /// The screen's pause: no step, whatever the tick.
    pub hold: bool,
    /// Steps done so far in the frame under way, for the screen to read
    /// while a long frame runs.
    pub progress: Arc<AtomicU64>,
    scratch: OverlapScratch,
    /// The parallelism of the running scene, for a screen (`None` headless:
    /// `bench` measures its own, apart from the timed run).
    pub probe: Option<Probe>,
    /// This frame's first step ran on the probe, not the pool; and the
    /// pool's widest section of the frame before, which that step hid.
    probed: bool,
    busy: Option<Busy>,
    /// What `auto` ran in the last frame, to tell a switch (`None` for the
    /// other models; kept across a new `auto`, as the tolerance keys make).
    chosen: Option<ModelKind>,
}

impl Frame {
    pub fn new(
        world: World,
        model: Box<dyn Model>,
        exec: SharedExec,
        settings: Settings,
        views: bool,
    ) -> Frame {
        let energy_reset = world.kinetic_energy();
        let snap = Snapshot::new(&world, settings, energy_reset, views);
        Frame {
            world,
            model,
            exec,
            settings,
            energy_reset,
            number: 0,
            notice: None,
            snap,
            views,
            budget: None,
            hold: false,
            progress: Arc::default(),
            scratch: OverlapScratch::default(),
            probe: views.then(Probe::default),
            probed: false,
            busy: None,
            chosen: None,
        }
    }

    /// Step the world `tick` times and fill the back snapshot, on a thread
    /// of the frame's executor.
    pub fn run(&mut self) {
        let exec = self.exec.clone();
        exec.host(&mut || self.run_here());
    }

    /// The timer covers the steps and the overlap readout's detection:
    /// `swept` makes it as the next step's detection and reuses it, the
    /// others search for overlaps; either way it is work the frame costs
    /// (docs/design.md, bench JSON: `wall_seconds` covers any detection for the readouts).
    /// Copying the spheres out for the screen is not timed.
    fn run_here(&mut self) {
        let (steps, overlap, physics_seconds) = self.timed();
        self.number += 1;
        let snap = &mut self.snap;
        snap.fill_world(
            &self.world,
            self.model.last_parts(),
            overlap,
            &*self.exec,
            self.views,
        );
        snap.frame = self.number;
        snap.energy_reset = self.energy_reset;
        snap.physics_seconds = physics_seconds;
        snap.steps = steps;
        snap.settings = self.settings;
        snap.choice = self.model.choice().cloned();
        snap.report_threads();
        snap.switch_notice = switch_notice(self.chosen, snap.choice.as_ref());
        self.chosen = snap.choice.as_ref().map(|c| c.model);
        snap.notice.clone_from(&self.notice);
        snap.parallelism = self.probe.as_ref().and_then(|p| p.value);
        if self.probed {
            snap.pool_busy = match (snap.pool_busy, self.busy) {
                (Some(now), Some(was)) if was.busy > now.busy => Some(was),
                (None, was) => was,
                (now, _) => now,
            };
        }
        self.busy = snap.pool_busy;
    }

    /// The frame's physics, all of it timed: its steps and the overlap
    /// readout (which `auto` checks its promise against). The steps done,
    /// the readout and the wall seconds.
    pub(crate) fn timed(&mut self) -> (u64, Overlap, f64) {
        let t0 = Instant::now();
        let steps = self.step(t0);
        let overlap = self
            .model
            .max_overlap_rel(&self.world, self.settings.dt, &*self.exec)
            .map_or_else(
                || self.scratch.measure(&self.world, &*self.exec),
                Overlap::complete,
            );
        // A readout cut at its budget is a lower bound: the promise is not
        // known kept (and which pairs were seen may differ between modes).
        self.model.overlap_read(if overlap.partial {
            f64::INFINITY
        } else {
            overlap.deepest_rel
        });
        (steps, overlap, t0.elapsed().as_secs_f64())
    }

    /// Run the frame's steps in whole chunks, each sized from the mean step
    /// so far: `tick` steps, or as many as `budget` allows (at least one);
    /// none while held.
    /// Chunks let a long frame report its progress and flat out stop near
    /// its budget; the models give the same bits however the steps are cut.
    fn step(&mut self, t0: Instant) -> u64 {
        let dt = self.settings.dt;
        let tick = if self.hold {
            0
        } else {
            u64::from(self.settings.tick)
        };
        let budget = self.budget.filter(|_| tick > 0);
        // `exact` and `auto` give other bits when their steps are cut
        // differently, so they step one at a time flat out (a state then
        // depends on the step count alone) and run a tick in one piece.
        let cuts_freely = self.settings.model.cuts_freely();
        let (mut done, mut chunk) = (0_u64, if cuts_freely { 1 } else { tick });
        self.progress.store(0, Ordering::Relaxed);
        let ran = self
            .settings
            .model
            .running(self.model.choice().map(|c| c.model));
        let settings = self.settings;
        let mut probe = self
            .probe
            .as_mut()
            .filter(|_| tick > 0)
            .and_then(|p| p.wants(&settings, ran, t0).then_some(p));
        self.probed = probe.is_some();
        loop {
            let want = if budget.is_some() {
                if cuts_freely { chunk } else { 1 }
            } else {
                chunk.min(tick - done)
            };
            if want == 0 {
                return done;
            }
            // The frame's first advance, when the probe is due, is measured
            // on the span executor (the same bits as on the pool).
            if let Some(p) = probe.take() {
                let (model, world) = (&mut self.model, &mut self.world);
                p.measure(self.settings.threads, &mut |exec| {
                    model.advance(world, dt, want, exec);
                });
            } else {
                self.model.advance(&mut self.world, dt, want, &*self.exec);
            }
            done += want;
            self.progress.store(done, Ordering::Relaxed);
            let spent = t0.elapsed();
            let left = match budget.map(|b| b.checked_sub(spent)) {
                Some(None | Some(Duration::ZERO)) => return done,
                Some(Some(left)) => left,
                None => PROGRESS_SLICE,
            };
            // A quarter of what is left: the step time varies, and an
            // overshoot past the budget costs the screen its frame.
            let per_step = spent.as_secs_f64() / done as f64;
            chunk = (left.as_secs_f64() / 4.0 / per_step.max(1e-9)).max(1.0) as u64;
        }
    }
}

/// `auto: swept → exact (reason)` when `auto` runs another model than it
/// ran in the frame before.
fn switch_notice(was: Option<ModelKind>, now: Option<&Choice>) -> Option<String> {
    match (was, now) {
        (Some(was), Some(c)) if was != c.model => {
            Some(format!("auto: {was} → {} ({})", c.model, c.reason))
        }
        _ => None,
    }
}

/// How often a long frame of `tick` steps updates its progress.
const PROGRESS_SLICE: Duration = Duration::from_millis(100);
