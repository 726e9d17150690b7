//! Raw mode and the panic hook: the terminal is set up once and put back on
//! every way out (normal return, error, panic in any thread, a signal), and
//! around a stop (job control). Writes go through [`super::latch`]; the quit
//! watchdog is [`crate::tui::input::quit`], the signal thread [`crate::tui::input::signals`].
use super::escapes::{PASTE_OFF, PASTE_ON, RESET_ATTRIBUTES};
use super::latch::TERMINAL;
use crate::tui::msg::Msg;
use crossbeam_channel::Sender;
use crossterm::{cursor, execute, queue, terminal};
use parking_lot::{Condvar, Mutex};
use std::io::{self, Write};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

static PANICKED: AtomicBool = AtomicBool::new(false);
/// Set once the panic hook has restored the terminal and printed the
/// message, so the process does not end before the message is out.
static REPORTED: (Mutex<bool>, Condvar) = (Mutex::new(false), Condvar::new());
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
                {
                    let (done, told) = &REPORTED;
                    *done.lock() = true;
                    told.notify_all();
                }
                if let Some(tx) = WAKE.get() {
                    let _ = tx.send(Msg::Panic);
                }
            }));
        });
        terminal::enable_raw_mode()?;
        TERMINAL.open();
        // Made before the next step, so a failure there is undone too.
        let guard = Guard(());
        set_up_screen()?;
        Ok(guard)
    }
}

impl Drop for Guard {
    fn drop(&mut self) {
        restore();
    }
}

/// Alternate screen, hidden cursor, bracketed paste.
fn set_up_screen() -> io::Result<()> {
    let mut out = io::stdout();
    execute!(out, terminal::EnterAlternateScreen, cursor::Hide)?;
    out.write_all(PASTE_ON)?;
    out.flush()
}

/// The terminal as the shell had it. Errors are ignored: the terminal may
/// already be gone.
fn put_back() {
    let mut out = io::stdout();
    let _ = queue!(out, terminal::EndSynchronizedUpdate);
    let _ = out.write_all(RESET_ATTRIBUTES);
    let _ = out.write_all(PASTE_OFF);
    let _ = execute!(out, cursor::Show, terminal::LeaveAlternateScreen);
    let _ = out.flush();
    let _ = terminal::disable_raw_mode();
}

/// After a panic: wait (at most `limit`) until the hook has printed its
/// message; the frame loop sees the panic as soon as it starts, and would
/// otherwise end the process while the message is still being written.
pub fn wait_for_panic_report(limit: Duration) {
    let (done, told) = &REPORTED;
    let end = Instant::now() + limit;
    let mut done = done.lock();
    while !*done {
        if told.wait_until(&mut done, end).timed_out() {
            return;
        }
    }
}

/// Whether a panic happened anywhere since start.
pub fn panicked() -> bool {
    PANICKED.load(Ordering::SeqCst)
}

/// Put the terminal back for good; safe to call more than once and from
/// any thread. The status requests still in flight are answered and read
/// first (at most [`super::latch::DRAIN_WAIT`]), so their answers do not
/// reach the shell.
pub fn restore() {
    TERMINAL.close(put_back);
}

/// Give the terminal back before the process stops (job control); frames
/// drawn meanwhile are dropped. Returns whether it was set up.
pub fn suspend() -> bool {
    TERMINAL.hold(put_back)
}

/// After a stop: raw mode, the alternate screen and the hidden cursor
/// again, even if the app did not see the stop (SIGSTOP) and the shell
/// reset the terminal meanwhile. Returns whether the screen is the app's.
pub fn resume() -> bool {
    TERMINAL.reopen(|| {
        // crossterm skips enabling raw mode it believes is on: off, then
        // on, sets it whatever the shell did.
        let _ = terminal::disable_raw_mode();
        let _ = terminal::enable_raw_mode();
        let _ = set_up_screen();
    })
}
