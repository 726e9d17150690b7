//! Getting out cleanly: the terminal is put back on every way out (normal
//! return, error, panic in any thread, SIGTERM/SIGHUP/SIGINT), and a terminal
//! that goes away ends the process instead of leaving it spinning.
use super::output::END_SYNC;
use crossbeam_channel::Sender;
use crossterm::event::{Event, KeyEvent};
use crossterm::{cursor, execute, terminal};
use std::io::{self, Write};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;
use std::time::Duration;

/// What wakes the frame loop besides its own clock.
#[derive(Clone, Debug, PartialEq)]
pub enum Msg {
    Key(KeyEvent),
    Resize,
    /// A termination signal (its number).
    Signal(i32),
    /// The terminal is gone or unreadable.
    Fatal(String),
    /// Some thread panicked (the hook has restored the terminal already).
    Panic,
}

static ACTIVE: AtomicBool = AtomicBool::new(false);
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
        ACTIVE.store(true, Ordering::SeqCst);
        // Made before the next step, so a failure there is undone too.
        let guard = Guard(());
        execute!(io::stdout(), terminal::EnterAlternateScreen, cursor::Hide)?;
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
    if ACTIVE.swap(false, Ordering::SeqCst) {
        let mut out = io::stdout();
        let _ = out.write_all(END_SYNC);
        let _ = out.write_all(b"\x1b[0m");
        let _ = execute!(out, cursor::Show, terminal::LeaveAlternateScreen);
        let _ = out.flush();
        let _ = terminal::disable_raw_mode();
    }
}

/// How long the frame loop gets to exit by itself after a termination
/// signal before the signal thread ends the process (the loop may be waiting
/// on a long physics frame).
const SIGNAL_GRACE: Duration = Duration::from_millis(700);

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
                thread::sleep(SIGNAL_GRACE);
                restore();
                std::process::exit(128 + sig);
            }
        })?;
    Ok(handle)
}

/// A named thread reading keys. It waits on the terminal itself and treats
/// hang-up, errors and end of input as fatal: crossterm's own poll spins at
/// full CPU on a terminal that has gone away (crossterm issue 793).
pub fn spawn_input(tx: Sender<Msg>) -> io::Result<()> {
    thread::Builder::new().name("input".into()).spawn(move || {
        let fatal = |tx: &Sender<Msg>, why: String| {
            let _ = tx.send(Msg::Fatal(why));
        };
        let stdin = io::stdin();
        // Wake-ups that brought no event in a row: end of input.
        let mut empty = 0u32;
        loop {
            use rustix::event::{PollFd, PollFlags};
            let mut fds = [PollFd::new(&stdin, PollFlags::IN)];
            match rustix::event::poll(&mut fds, None) {
                Ok(_) => {}
                Err(rustix::io::Errno::INTR) => continue,
                Err(e) => return fatal(&tx, format!("terminal input failed: {e}")),
            }
            let re = fds[0].revents();
            if re.intersects(PollFlags::HUP | PollFlags::ERR | PollFlags::NVAL) {
                return fatal(&tx, "the terminal went away".into());
            }
            let mut got = false;
            loop {
                match crossterm::event::poll(Duration::from_millis(1)) {
                    Ok(true) => {}
                    Ok(false) => break,
                    Err(e) => return fatal(&tx, format!("terminal input failed: {e}")),
                }
                let msg = match crossterm::event::read() {
                    Ok(Event::Key(k)) => Msg::Key(k),
                    Ok(Event::Resize(..)) => Msg::Resize,
                    Ok(_) => continue,
                    Err(e) => return fatal(&tx, format!("terminal input failed: {e}")),
                };
                got = true;
                if tx.send(msg).is_err() {
                    return;
                }
            }
            if got {
                empty = 0;
            } else {
                empty += 1;
                if empty >= 50 {
                    return fatal(&tx, "terminal input ended".into());
                }
                // Readable yet nothing to read: don't turn into a spin.
                thread::sleep(Duration::from_millis(5));
            }
        }
    })?;
    Ok(())
}
