//! A child process a test started in a pseudo-terminal: waiting, up to a
//! deadline, for it to exit. Shared by `pty.rs` and `link.rs` (and so by
//! `examples/slow_link.rs`, which compiles `link.rs` and this file by path).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use portable_pty::{Child, ExitStatus};
use std::time::{Duration, Instant};

/// How `child` exited, looked for every `poll`; None if it still runs
/// after `secs`.
pub fn wait_exit(child: &mut dyn Child, secs: f64, poll: Duration) -> Option<ExitStatus> {
    let end = Instant::now() + Duration::from_secs_f64(secs);
    while Instant::now() < end {
        if let Some(st) = child.try_wait().unwrap() {
            return Some(st);
        }
        std::thread::sleep(poll);
    }
    None
}
