//! A run replayed on a [`SpanExec`]: the same frames as the engine runs
//! them (the same steps, cut the same way, with the overlap readout `auto`
//! checks its promise against), from the same start, on `P` lanes taken one
//! after another on this thread. `bench` replays a pool run of `K` threads
//! on `K` lanes for its work and span, after the timed run.
use super::Settings;
use super::frame::{Frame, SharedExec};
use super::span::{SpanExec, WorkSpan};
use crate::physics::World;
use std::sync::Arc;

/// Step `world` `steps` steps of `settings`' model, in frames of
/// `settings.tick` steps (the last one shorter), on a [`SpanExec`] of
/// `lanes` lanes: the work and span of the frames' physics (their steps
/// and overlap readouts, what the engine times) and the world they end in.
#[must_use]
pub fn replay(world: World, settings: Settings, steps: u64, lanes: usize) -> (WorkSpan, World) {
    let exec = Arc::new(SpanExec::new(lanes));
    let shared: SharedExec = exec.clone();
    let mut frame = Frame::new(world, settings.model.build(), shared, settings, false);
    let tick = u64::from(settings.tick.max(1));
    let (mut total, mut done) = (WorkSpan::default(), 0);
    while done < steps {
        let now = tick.min(steps - done);
        frame.settings.tick = u32::try_from(now).unwrap_or(u32::MAX);
        total += exec.measure(&mut || {
            frame.timed();
        });
        done += now;
    }
    (total, frame.world)
}
