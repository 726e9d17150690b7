//! Getting out cleanly: the terminal is put back on every way out (normal
//! return, error, panic in any thread, SIGTERM/SIGHUP/SIGINT), and a terminal
//! that goes away ends the process instead of leaving it spinning.
use crossbeam_channel::Sender;
use crossterm::event::KeyEvent;
use crossterm::{cursor, execute, queue, terminal};
use parking_lot::Mutex;
use std::io::{self, Write};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;
use std::time::Duration;

/// What wakes the frame loop besides its own clock.
#[derive(Clone, Debug, PartialEq)]
pub enum Msg {
    Key(KeyEvent),
    /// The terminal answered a status request (read at that instant).
    Status(std::time::Instant),
    /// The `output` thread finished writing a chunk.
    Written,
    /// The physics finished a frame.
    PhysicsDone,
    Resize,
    /// A termination signal (its number).
    Signal(i32),
    /// The terminal is gone or unreadable.
    Fatal(String),
    /// Some thread panicked (the hook has restored the terminal already).
    Panic,
}

/// The terminal's state: set up or restored, and the lock every write to it
/// holds, so that nothing is written once `restore` has run.
pub struct Latch {
    active: AtomicBool,
    writing: Mutex<()>,
}

/// How long `restore` waits for a write in progress (a frame going out over
/// a slow link) before it writes anyway.
const RESTORE_WAIT: Duration = Duration::from_millis(500);

impl Latch {
    pub const fn new() -> Latch {
        Latch {
            active: AtomicBool::new(false),
            writing: Mutex::new(()),
        }
    }

    fn open(&self) {
        self.active.store(true, Ordering::SeqCst);
    }

    /// Closes the latch; `put_back` runs once, after any write in progress
    /// has finished. Later writes through a [`Gated`] writer fail.
    pub fn close(&self, put_back: impl FnOnce()) {
        if self.active.swap(false, Ordering::SeqCst) {
            let _lock = self.writing.try_lock_for(RESTORE_WAIT);
            put_back();
        }
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

impl<W: Write> Write for Gated<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let _lock = self.latch.writing.lock();
        if !self.latch.active.load(Ordering::SeqCst) {
            return Err(restored());
        }
        self.inner.write(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        let _lock = self.latch.writing.lock();
        if !self.latch.active.load(Ordering::SeqCst) {
            return Err(restored());
        }
        self.inner.flush()
    }
}

/// The real terminal's latch.
pub static TERMINAL: Latch = Latch::new();

/// Stdout, gated by the terminal's latch: the only way frames go out.
pub fn gated_stdout() -> Gated<io::Stdout> {
    Gated::new(io::stdout(), &TERMINAL)
}

/// Pasted text arrives bracketed, so it is not taken for key presses.
const PASTE_ON: &[u8] = b"\x1b[?2004h";
const PASTE_OFF: &[u8] = b"\x1b[?2004l";

static PANICKED: AtomicBool = AtomicBool::new(false);
static WAKE: OnceLock<Sender<Msg>> = OnceLock::new();
static HOOK: OnceLock<()> = OnceLock::new();

/// Raw mode, alternate screen, hidden cursor; undone on drop.
pub struct Guard(());

impl Guard {
    pub fn enter(wake: Sender<Msg>) -> io::Result<Guard> {
        let _ = WAKE.set(wake);
        HOOK.get_or_init(|| {
            let previous = std::panic::take_hook();
            std::panic::set_hook(Box::new(move |info| {
                PANICKED.store(true, Ordering::SeqCst);
                // Restore first, so the message lands on the normal screen.
                restore();
                previous(info);
                if let Some(tx) = WAKE.get() {
                    let _ = tx.send(Msg::Panic);
                }
            }));
        });
        terminal::enable_raw_mode()?;
        TERMINAL.open();
        // Made before the next step, so a failure there is undone too.
        let guard = Guard(());
        let mut out = io::stdout();
        execute!(out, terminal::EnterAlternateScreen, cursor::Hide)?;
        out.write_all(PASTE_ON)?;
        out.flush()?;
        Ok(guard)
    }
}

impl Drop for Guard {
    fn drop(&mut self) {
        restore();
    }
}

/// Whether a panic happened anywhere since start.
pub fn panicked() -> bool {
    PANICKED.load(Ordering::SeqCst)
}

/// Put the terminal back; safe to call more than once and from any thread.
/// Errors are ignored: the terminal may already be gone.
pub fn restore() {
    TERMINAL.close(|| {
        let mut out = io::stdout();
        let _ = queue!(out, terminal::EndSynchronizedUpdate);
        let _ = out.write_all(b"\x1b[0m");
        let _ = out.write_all(PASTE_OFF);
        let _ = execute!(out, cursor::Show, terminal::LeaveAlternateScreen);
        let _ = out.flush();
        let _ = terminal::disable_raw_mode();
    });
}

/// How long the frame loop gets to exit by itself after a termination
/// signal or a quit key before the process is ended for it (the loop may be
/// waiting on a long physics frame, which cannot be interrupted).
pub const QUIT_GRACE: Duration = Duration::from_millis(700);

/// Give the frame loop `QUIT_GRACE` to finish, then restore the terminal
/// and end the process with `code`. Called on the thread that saw the
/// request, which has nothing else left to do.
pub fn end_after_grace(code: i32) -> ! {
    thread::sleep(QUIT_GRACE);
    restore();
    std::process::exit(code);
}

/// A named thread turning signals into messages. Returns a handle whose
/// `close` stops it.
pub fn spawn_signals(tx: Sender<Msg>) -> io::Result<signal_hook::iterator::Handle> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGQUIT, SIGTERM, SIGWINCH};
    let mut signals =
        signal_hook::iterator::Signals::new([SIGTERM, SIGHUP, SIGINT, SIGQUIT, SIGWINCH])?;
    let handle = signals.handle();
    thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            for sig in signals.forever() {
                if sig == SIGWINCH {
                    if tx.send(Msg::Resize).is_err() {
                        return;
                    }
                    continue;
                }
                let _ = tx.send(Msg::Signal(sig));
                end_after_grace(128 + sig);
            }
        })?;
    Ok(handle)
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
}
