//! The `output` thread: the one writer of frames. The frame loop hands it
//! each frame's bytes and goes on handling keys, so a slow terminal never
//! blocks the thread that answers them. It writes through the terminal's
//! latch ([`latch::gated_stdout`]), so nothing lands after a restore.
use super::latch;
use crate::tui::msg::Msg;
use crossbeam_channel::Sender;
use std::io;
use std::thread;

/// Where frames go: a channel to the `output` thread.
pub struct Output {
    tx: Sender<(Vec<u8>, u64)>,
}

impl Output {
    /// Start the thread; it reports each chunk written (or the error that
    /// ended it) on `events`.
    pub fn spawn(events: Sender<Msg>) -> io::Result<Output> {
        let (tx, rx) = crossbeam_channel::unbounded::<(Vec<u8>, u64)>();
        thread::Builder::new()
            .name("output".into())
            .spawn(move || {
                let mut out = latch::gated_stdout();
                for (chunk, queries) in rx {
                    let msg = match out.write_chunk(&chunk, queries) {
                        Ok(()) => Msg::Written,
                        Err(e) => Msg::Fatal(format!("writing to the terminal failed: {e}")),
                    };
                    let fatal = matches!(msg, Msg::Fatal(_));
                    if events.send(msg).is_err() || fatal {
                        return;
                    }
                }
            })?;
        Ok(Output { tx })
    }

    /// Queue `bytes`, which ask `queries` status requests (the terminal owes
    /// that many answers once they are written); false if the thread has
    /// stopped.
    pub fn send(&self, bytes: Vec<u8>, queries: u64) -> bool {
        self.tx.send((bytes, queries)).is_ok()
    }
}
