//! The `physics` thread: created once with the engine, asleep on its start
//! channel until handed a frame, and handing it back on the done channel
//! (the article's start and done events, carrying the frame with them).
use super::frame::Frame;
use crate::cpu::ThreadRole;
use crossbeam_channel::{Receiver, Sender, bounded};
use parking_lot::Mutex;
use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::thread::JoinHandle;

pub(crate) type Outcome = Result<Box<Frame>, String>;

/// Called on the `physics` thread each time a frame is back.
pub type Notify = Box<dyn Fn() + Send>;

pub(crate) struct Worker {
    start: Option<Sender<Box<Frame>>>,
    done: Receiver<Outcome>,
    handle: Option<JoinHandle<()>>,
    tid: Option<i32>,
    notify: Arc<Mutex<Option<Notify>>>,
}

impl Worker {
    pub fn spawn() -> anyhow::Result<Worker> {
        let (start_tx, start_rx) = bounded::<Box<Frame>>(1);
        let (done_tx, done_rx) = bounded::<Outcome>(1);
        let (tid_tx, tid_rx) = bounded(1);
        let notify: Arc<Mutex<Option<Notify>>> = Arc::default();
        let hook = notify.clone();
        let handle = std::thread::Builder::new()
            .name(ThreadRole::Physics.name().into_owned())
            .spawn(move || {
                let _ = tid_tx.send(crate::cpu::current_tid());
                while let Ok(frame) = start_rx.recv() {
                    if done_tx.send(run_caught(frame)).is_err() {
                        break;
                    }
                    if let Some(f) = &*hook.lock() {
                        f();
                    }
                }
            })?;
        let tid = tid_rx.recv().ok().flatten();
        Ok(Worker {
            start: Some(start_tx),
            done: done_rx,
            handle: Some(handle),
            tid,
            notify,
        })
    }

    /// Call `f` on the `physics` thread whenever a frame is back.
    pub fn set_notify(&self, f: Notify) {
        *self.notify.lock() = Some(f);
    }

    /// The thread's kernel id (Linux), to read its CPU time.
    pub fn tid(&self) -> Option<i32> {
        self.tid
    }

    pub fn start(&self, frame: Box<Frame>) -> anyhow::Result<()> {
        self.start
            .as_ref()
            .and_then(|s| s.send(frame).ok())
            .ok_or_else(|| anyhow::anyhow!("the physics thread has stopped"))
    }

    /// Whether the frame handed over last is back (or failed): `wait`
    /// would not block.
    pub fn ready(&self) -> bool {
        !self.done.is_empty()
    }

    pub fn wait(&self) -> Outcome {
        self.done
            .recv()
            .unwrap_or_else(|_| Err("the physics thread has stopped".into()))
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        // Closing the start channel ends the thread's loop.
        self.start = None;
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

/// Run the frame; a panic (here or on a pool thread it waited for) becomes
/// the message the caller gets instead of the frame.
pub(crate) fn run_caught(mut frame: Box<Frame>) -> Outcome {
    match catch_unwind(AssertUnwindSafe(|| frame.run())) {
        Ok(()) => Ok(frame),
        Err(p) => Err(format!("physics panicked: {}", panic_text(p.as_ref()))),
    }
}

fn panic_text(p: &(dyn Any + Send)) -> &str {
    p.downcast_ref::<&str>()
        .copied()
        .or_else(|| p.downcast_ref::<String>().map(String::as_str))
        .unwrap_or("(no message)")
}
