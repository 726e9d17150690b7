//! The one gate every write to the terminal passes: once the terminal is
//! restored nothing more is written, while it is held (job control) frames
//! are dropped, and a restore first reads the answers still owed to status
//! requests so they do not reach the shell.
use parking_lot::{Condvar, Mutex};
use std::io::{self, Write};
use std::sync::atomic::{AtomicU8, Ordering};
use std::time::{Duration, Instant};

/// The terminal's state: set up, held (the process is suspended: frames are
/// dropped, the screen is repainted on resume) or restored, and the lock
/// every write to it holds, so that nothing is written once `restore` has
/// run.
pub struct Latch {
    state: AtomicU8,
    /// Held through every change of state, so a second `close` returns only
    /// once the terminal is really back.
    changing: Mutex<()>,
    writing: Mutex<()>,
    /// Status requests written and not yet answered.
    owed: Mutex<u64>,
    answered: Condvar,
}

const OFF: u8 = 0;
const ON: u8 = 1;
const HELD: u8 = 2;

/// How long `restore` waits for a write in progress (a frame going out over
/// a slow link) before it writes anyway.
const RESTORE_WAIT: Duration = Duration::from_millis(500);

/// How long a restore waits for the answers to status requests still in
/// flight: read by the app, they do not land in the shell's input.
pub const DRAIN_WAIT: Duration = Duration::from_millis(200);

impl Latch {
    pub const fn new() -> Latch {
        Latch {
            state: AtomicU8::new(OFF),
            changing: Mutex::new(()),
            writing: Mutex::new(()),
            owed: Mutex::new(0),
            answered: Condvar::new(),
        }
    }

    pub(super) fn open(&self) {
        self.state.store(ON, Ordering::SeqCst);
    }

    /// Closes the latch; `put_back` runs once, after any write in progress
    /// has finished and the answers owed have been read (or `DRAIN_WAIT`
    /// has passed). Later writes through a [`Gated`] writer fail.
    pub fn close(&self, put_back: impl FnOnce()) {
        let _changing = self.changing.lock();
        if self.state.swap(OFF, Ordering::SeqCst) == ON {
            let _lock = self.writing.try_lock_for(RESTORE_WAIT);
            self.drain(DRAIN_WAIT);
            put_back();
        }
    }

    /// Like `close`, but later writes are dropped instead of refused, until
    /// `reopen`. Returns whether the terminal was set up.
    pub fn hold(&self, put_back: impl FnOnce()) -> bool {
        let _changing = self.changing.lock();
        if self
            .state
            .compare_exchange(ON, HELD, Ordering::SeqCst, Ordering::SeqCst)
            .is_err()
        {
            return false;
        }
        let _lock = self.writing.try_lock_for(RESTORE_WAIT);
        self.drain(DRAIN_WAIT);
        put_back();
        true
    }

    /// After a `hold` (or a stop the app did not see): `set_up` runs with
    /// writes locked out, then writes go through again. Nothing happens once
    /// the latch is closed for good.
    pub fn reopen(&self, set_up: impl FnOnce()) -> bool {
        let _changing = self.changing.lock();
        let _lock = self.writing.try_lock_for(RESTORE_WAIT);
        if self.state.load(Ordering::SeqCst) == OFF {
            return false;
        }
        // Answers lost with the old terminal state are not waited for.
        *self.owed.lock() = 0;
        set_up();
        self.state.store(ON, Ordering::SeqCst);
        true
    }

    /// The input thread read an answer to a status request.
    pub fn answer(&self) {
        let mut owed = self.owed.lock();
        *owed = owed.saturating_sub(1);
        if *owed == 0 {
            self.answered.notify_all();
        }
    }

    /// Status requests not answered yet.
    #[cfg(test)]
    pub fn owed(&self) -> u64 {
        *self.owed.lock()
    }

    /// Wait until every status request written has been answered, at most
    /// `limit`. Returns whether all were.
    pub fn drain(&self, limit: Duration) -> bool {
        let end = Instant::now() + limit;
        let mut owed = self.owed.lock();
        while *owed > 0 {
            if self.answered.wait_until(&mut owed, end).timed_out() {
                return *owed == 0;
            }
        }
        true
    }
}

impl Default for Latch {
    fn default() -> Latch {
        Latch::new()
    }
}

/// A writer to the terminal that stops writing once the terminal has been
/// restored (a frame must not land on the shell's screen after a panic).
pub struct Gated<W: Write> {
    inner: W,
    latch: &'static Latch,
}

impl<W: Write> Gated<W> {
    pub fn new(inner: W, latch: &'static Latch) -> Gated<W> {
        Gated { inner, latch }
    }
}

fn restored() -> io::Error {
    io::Error::other("the terminal has been restored")
}

impl<W: Write> Gated<W> {
    /// Write `chunk` whole, which asks `queries` status requests: they are
    /// owed answers only if the chunk really goes out. While the terminal
    /// is held the chunk is dropped.
    pub fn write_chunk(&mut self, chunk: &[u8], queries: u64) -> io::Result<()> {
        let _lock = self.latch.writing.lock();
        match self.latch.state.load(Ordering::SeqCst) {
            ON => {
                // Counted first: a write cut short may still have sent them.
                *self.latch.owed.lock() += queries;
                self.inner.write_all(chunk)?;
                self.inner.flush()
            }
            HELD => Ok(()),
            _ => Err(restored()),
        }
    }
}

impl<W: Write> Write for Gated<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let _lock = self.latch.writing.lock();
        match self.latch.state.load(Ordering::SeqCst) {
            ON => self.inner.write(buf),
            HELD => Ok(buf.len()),
            _ => Err(restored()),
        }
    }
    fn flush(&mut self) -> io::Result<()> {
        let _lock = self.latch.writing.lock();
        match self.latch.state.load(Ordering::SeqCst) {
            ON => self.inner.flush(),
            HELD => Ok(()),
            _ => Err(restored()),
        }
    }
}

/// The real terminal's latch.
pub static TERMINAL: Latch = Latch::new();

/// Stdout, gated by the terminal's latch: the only way frames go out.
pub fn gated_stdout() -> Gated<io::Stdout> {
    Gated::new(io::stdout(), &TERMINAL)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    #[derive(Clone, Default)]
    struct Sink(Arc<parking_lot::Mutex<Vec<u8>>>);
    impl Write for Sink {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            self.0.lock().extend_from_slice(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn nothing_is_written_after_the_terminal_is_restored() {
        let latch: &'static Latch = Box::leak(Box::new(Latch::new()));
        let sink = Sink::default();
        let mut w = io::BufWriter::new(Gated::new(sink.clone(), latch));
        latch.open();
        w.write_all(b"frame 1").unwrap();
        w.flush().unwrap();
        // A frame half built when another thread restores the terminal.
        w.write_all(b"frame 2").unwrap();
        let restore = sink.clone();
        std::thread::spawn(move || {
            latch.close(|| restore.0.lock().extend_from_slice(b"|restored"));
        })
        .join()
        .unwrap();
        assert!(w.flush().is_err());
        assert!(w.get_mut().write(b"x").is_err());
        assert_eq!(&sink.0.lock()[..], b"frame 1|restored");
        // Closing twice puts the terminal back once.
        latch.close(|| sink.0.lock().extend_from_slice(b"again"));
        assert_eq!(&sink.0.lock()[..], b"frame 1|restored");
    }

    #[test]
    fn restore_waits_for_a_write_in_progress() {
        struct Slow(
            Sink,
            crossbeam_channel::Sender<()>,
            crossbeam_channel::Receiver<()>,
        );
        impl Write for Slow {
            fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
                let _ = self.1.send(());
                let _ = self.2.recv();
                self.0.write(buf)
            }
            fn flush(&mut self) -> io::Result<()> {
                Ok(())
            }
        }
        let latch: &'static Latch = Box::leak(Box::new(Latch::new()));
        latch.open();
        let (started_tx, started) = crossbeam_channel::bounded(0);
        let (go_tx, go) = crossbeam_channel::bounded::<()>(0);
        let sink = Sink::default();
        let mut w = Gated::new(Slow(sink.clone(), started_tx, go), latch);
        let writer = std::thread::spawn(move || w.write_all(b"frame"));
        started.recv().unwrap();
        let s2 = sink.clone();
        let closer =
            std::thread::spawn(move || latch.close(|| s2.0.lock().extend_from_slice(b"|restored")));
        go_tx.send(()).unwrap();
        writer.join().unwrap().unwrap();
        closer.join().unwrap();
        assert_eq!(&sink.0.lock()[..], b"frame|restored");
    }

    #[test]
    fn restore_waits_for_the_answers_owed_and_a_hold_drops_frames() {
        let latch: &'static Latch = Box::leak(Box::new(Latch::new()));
        latch.open();
        let sink = Sink::default();
        let mut w = Gated::new(sink.clone(), latch);
        w.write_chunk(b"?frame?", 2).unwrap();
        assert_eq!(latch.owed(), 2);
        // The answers arrive 50 ms later, read by another thread.
        let reader = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(50));
            latch.answer();
            latch.answer();
        });
        let s2 = sink.clone();
        latch.hold(|| s2.0.lock().extend_from_slice(b"|back"));
        assert_eq!(latch.owed(), 0, "put back before the answers were read");
        reader.join().unwrap();
        // Held: frames are dropped, and owe nothing.
        w.write_chunk(b"dropped", 2).unwrap();
        assert_eq!(latch.owed(), 0);
        assert!(latch.reopen(|| sink.0.lock().extend_from_slice(b"|again")));
        w.write_chunk(b"|next", 0).unwrap();
        // An answer that never comes: the restore goes on after the limit.
        w.write_chunk(b"?", 1).unwrap();
        let t0 = Instant::now();
        latch.close(|| sink.0.lock().extend_from_slice(b"|closed"));
        assert!(t0.elapsed() >= DRAIN_WAIT);
        assert!(w.write_chunk(b"late", 0).is_err());
        assert!(!latch.reopen(|| sink.0.lock().extend_from_slice(b"never")));
        assert_eq!(&sink.0.lock()[..], b"?frame?|back|again|next?|closed");
    }
}
