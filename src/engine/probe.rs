//! The threads panel's parallelism: every few seconds of a pool run, one
//! step of the running scene is taken on a [`SpanExec`] of at least
//! [`MIN_LANES`] lanes in place of the pool (every executor gives the same
//! bits, so the world is the one the pool would have made), and its work
//! over its span on unlimited lanes (Cilk's T₁/T∞) is what the snapshot
//! carries. That step runs on one thread: its time is in the frame's
//! physics time, so steps/s stays what the app really does.
use super::span::SpanExec;
use super::{Settings, Threading};
use crate::physics::{Exec, ModelKind};
use std::time::{Duration, Instant};

/// How often the parallelism is measured again: often enough to follow a
/// scene the user edits, rarely enough that a step on one thread in place
/// of the pool costs little.
pub(crate) const EVERY: Duration = Duration::from_secs(5);

/// A probe waits at least this many times its own duration before the
/// next, so it costs at most a fiftieth of the time on a slow scene.
const SPACING: u32 = 50;

/// Lanes the step is cut for, or the pool's threads when more: the
/// parallelism of a many-core machine's cut, measured on this one.
pub(crate) const MIN_LANES: usize = 64;

/// What the measurement was made for: another mode, pool size or model
/// starts again.
type Key = (Threading, usize, ModelKind);

#[derive(Default)]
pub(crate) struct Probe {
    exec: Option<SpanExec>,
    key: Option<Key>,
    due: Option<Instant>,
    /// The last measurement, for the settings in `key`.
    pub value: Option<f64>,
}

impl Probe {
    /// The spheres changed from outside the model: measure them afresh.
    pub fn forget(&mut self) {
        self.key = None;
    }

    /// Whether the frame's first step is to be measured: a pool runs a
    /// model that spreads, and the time has come. A change of settings
    /// drops the old figure and waits one frame (the first frame of a new
    /// model loads it, which no later step repeats).
    pub fn wants(&mut self, settings: &Settings, ran: ModelKind, now: Instant) -> bool {
        let key = (settings.threading, settings.threads, settings.model);
        if self.key != Some(key) {
            self.key = Some(key);
            self.value = None;
            self.due = Some(now);
            return false;
        }
        settings.threading == Threading::Pool
            && !ran.runs_on_one_lane()
            && self.due.is_some_and(|d| now >= d)
    }

    /// Run `job` (one advance of the frame) on the span executor and keep
    /// its parallelism.
    pub fn measure(&mut self, threads: usize, job: &mut dyn FnMut(&dyn Exec)) {
        let lanes = threads.max(MIN_LANES);
        let exec = match self.exec.take() {
            Some(e) if e.lanes() == lanes => e,
            _ => SpanExec::new(lanes),
        };
        let t0 = Instant::now();
        let ws = exec.measure(&mut || job(&exec));
        let took = t0.elapsed();
        self.value = Some(ws.parallelism());
        self.due = Some(Instant::now() + EVERY.max(took * SPACING));
        self.exec = Some(exec);
    }
}
