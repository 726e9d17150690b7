//! The `signals` thread: resizes, job control and the signals that end the
//! process. Every one of them that can be caught puts the terminal back
//! first (docs/terminal-io.md, Signals).
use crate::tui::msg::Msg;
use crate::tui::term::guard;
use crossbeam_channel::Sender;
use signal_hook::consts::{
    SIGALRM, SIGCONT, SIGHUP, SIGINT, SIGPIPE, SIGPROF, SIGQUIT, SIGTERM, SIGTSTP, SIGUSR1,
    SIGUSR2, SIGVTALRM, SIGWINCH, SIGXCPU, SIGXFSZ,
};
use std::io::{self, Write};
use std::sync::atomic::{AtomicI32, Ordering};
use std::thread;

/// The signals whose default action ends the process and that can be
/// caught. SIGPIPE applies too: stdout is the terminal, so only `kill`
/// sends it.
pub const FATAL: [i32; 12] = [
    SIGHUP, SIGINT, SIGQUIT, SIGTERM, SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF, SIGXCPU,
    SIGXFSZ, SIGPIPE,
];

/// The fatal signal the process is ending by (0: none).
static ENDING: AtomicI32 = AtomicI32::new(0);

/// The fatal signal that is ending the process, if any: the frame loop's
/// own way out must not end it first with another status.
pub fn ending() -> Option<i32> {
    match ENDING.load(Ordering::SeqCst) {
        0 => None,
        sig => Some(sig),
    }
}

/// Put the terminal back, say why, and end the process by `sig` with its
/// default action (the shell sees the signal, `$?` is 128 + its number).
pub fn end_by(sig: i32) -> ! {
    let first = ENDING.swap(sig, Ordering::SeqCst) == 0;
    guard::restore();
    if first {
        let _ = writeln!(io::stderr(), "ballpit: stopped by {}", name(sig));
    }
    let _ = signal_hook::low_level::emulate_default_handler(sig);
    // Only if the default action could not be had.
    std::process::exit(128 + sig);
}

/// A named thread turning signals into messages and actions. Returns a
/// handle whose `close` stops it.
pub fn spawn(tx: Sender<Msg>) -> io::Result<signal_hook::iterator::Handle> {
    let mut wanted = vec![SIGWINCH, SIGTSTP, SIGCONT];
    wanted.extend(FATAL);
    let mut signals = signal_hook::iterator::Signals::new(wanted)?;
    let handle = signals.handle();
    thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            for sig in signals.forever() {
                let msg = match sig {
                    SIGWINCH => Msg::Resize,
                    SIGTSTP => {
                        if !job_control() {
                            // Nobody could resume the process: stay.
                            continue;
                        }
                        guard::suspend();
                        let _ = tx.send(Msg::Held);
                        // Stops here until SIGCONT, which comes next.
                        let _ = signal_hook::low_level::emulate_default_handler(SIGTSTP);
                        continue;
                    }
                    SIGCONT => {
                        // In the background the terminal is the shell's.
                        if !foreground() || !guard::resume() {
                            continue;
                        }
                        Msg::Resumed
                    }
                    _ => {
                        let _ = tx.send(Msg::Signal(sig));
                        end_by(sig);
                    }
                };
                if tx.send(msg).is_err() {
                    return;
                }
            }
        })?;
    Ok(handle)
}

/// Ask for a stop as Ctrl-Z does in a shell (the terminal is raw, so the
/// key arrives as a byte).
pub fn request_suspend() {
    let _ = signal_hook::low_level::raise(SIGTSTP);
}

/// Whether a shell could resume the process: not when it leads its own
/// session (started straight in a terminal, as in a test's pty).
fn job_control() -> bool {
    let me = rustix::process::getpid();
    rustix::process::getsid(None).is_ok_and(|sid| sid != me)
}

/// Whether the process group owns the terminal.
fn foreground() -> bool {
    let stdin = io::stdin();
    rustix::termios::tcgetpgrp(&stdin).is_ok_and(|g| g == rustix::process::getpgrp())
}

pub fn name(sig: i32) -> String {
    let known = [
        (SIGHUP, "SIGHUP (the terminal hung up)"),
        (SIGINT, "SIGINT"),
        (SIGQUIT, "SIGQUIT"),
        (SIGTERM, "SIGTERM"),
        (SIGUSR1, "SIGUSR1"),
        (SIGUSR2, "SIGUSR2"),
        (SIGALRM, "SIGALRM"),
        (SIGVTALRM, "SIGVTALRM"),
        (SIGPROF, "SIGPROF"),
        (SIGXCPU, "SIGXCPU (CPU time limit)"),
        (SIGXFSZ, "SIGXFSZ (file size limit)"),
        (SIGPIPE, "SIGPIPE"),
    ];
    known
        .iter()
        .find(|(n, _)| *n == sig)
        .map_or_else(|| format!("signal {sig}"), |(_, s)| (*s).to_string())
}
