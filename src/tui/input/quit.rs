//! The quit watchdog: a quit key gives the frame loop a grace period to end
//! by itself, then the process is ended for it, the terminal put back.
use crate::tui::term::guard::restore;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;
use std::time::Duration;

/// How long the frame loop gets to exit by itself after a quit key before
/// the process is ended for it (the loop may be waiting on a long physics
/// frame, which cannot be interrupted).
pub const QUIT_GRACE: Duration = Duration::from_millis(700);

/// Give the frame loop `QUIT_GRACE` to finish, then restore the terminal
/// and end the process with `code`. On a thread of its own, so the input
/// thread goes on reading the answers the restore waits for.
pub fn end_after_grace(code: i32) {
    static STARTED: AtomicBool = AtomicBool::new(false);
    if STARTED.swap(true, Ordering::SeqCst) {
        return;
    }
    let spawned = thread::Builder::new()
        .name("quit-timer".into())
        .spawn(move || {
            thread::sleep(QUIT_GRACE);
            restore();
            std::process::exit(code);
        });
    if spawned.is_err() {
        // No thread for the timer: the frame loop's own exit must do.
        STARTED.store(false, Ordering::SeqCst);
    }
}
