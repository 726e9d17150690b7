//! The `input` thread: the one reader of the terminal. It waits on stdin
//! with a level-triggered poll, reads the bytes itself and parses them
//! ([`term_input`](super::term_input)), so a key that arrives together with a
//! resize cannot be lost (resizes come from the `signals` thread). End of
//! input, hang-up and read errors mean the terminal is gone: the thread says
//! so and stops, without spinning.
use super::keys::{self, Action};
use super::quit;
use super::signals;
use super::term_input::{Input, Parser};
use crate::tui::msg::Msg;
use crate::tui::term::latch::TERMINAL;
use crossbeam_channel::Sender;
use rustix::event::{PollFd, PollFlags, Timespec};
use std::io;
use std::os::fd::AsFd;
use std::thread;
use std::time::{Duration, Instant};

/// How long a lone Esc waits for the rest of a sequence. Terminals send a
/// sequence in one write; a person cannot type Esc and `[` this fast.
pub const ESC_TIMEOUT: Duration = Duration::from_millis(30);

pub fn spawn_input(tx: Sender<Msg>) -> io::Result<()> {
    thread::Builder::new().name("input".into()).spawn(move || {
        if let Some(why) = read_loop(&tx) {
            let _ = tx.send(Msg::Fatal(why));
        }
    })?;
    Ok(())
}

/// Runs until the terminal is gone (the reason) or the frame loop has
/// stopped listening (None).
fn read_loop(tx: &Sender<Msg>) -> Option<String> {
    let stdin = io::stdin();
    let fd = stdin.as_fd();
    let mut parser = Parser::new();
    let mut buf = [0u8; 4096];
    let mut events = Vec::new();
    let esc_timeout = Timespec {
        tv_sec: 0,
        tv_nsec: ESC_TIMEOUT.as_nanos() as _,
    };
    loop {
        let timeout = parser.escape_pending().then_some(&esc_timeout);
        let mut fds = [PollFd::new(&fd, PollFlags::IN)];
        match rustix::event::poll(&mut fds, timeout) {
            Ok(0) => parser.flush_escape(&mut events),
            Ok(_) => {
                if fds[0].revents().contains(PollFlags::NVAL) {
                    return Some("the terminal input is closed".into());
                }
                // Readable, hung up or in error: the read says which.
                match rustix::io::read(fd, &mut buf) {
                    Ok(0) => return Some("the terminal went away (end of input)".into()),
                    Ok(n) => parser.feed(&buf[..n], &mut events),
                    Err(rustix::io::Errno::INTR | rustix::io::Errno::AGAIN) => {}
                    Err(rustix::io::Errno::IO) => {
                        return Some("the terminal went away".into());
                    }
                    Err(e) => return Some(format!("reading the terminal failed: {e}")),
                }
            }
            Err(rustix::io::Errno::INTR) => {}
            Err(e) => return Some(format!("waiting for the terminal failed: {e}")),
        }
        let mut quit = false;
        for ev in events.drain(..) {
            let msg = match ev {
                // Keys are read as actions here, once: the frame loop gets
                // only what a key means.
                Input::Key(press) => match keys::lookup(press) {
                    Some(Action::Suspend) => {
                        signals::request_suspend();
                        continue;
                    }
                    Some(action) => {
                        quit |= action == Action::Quit;
                        Msg::Action(action)
                    }
                    None => continue,
                },
                // The pacing's answers: when they were read. A restore
                // waits for the ones still owed.
                Input::StatusOk => {
                    TERMINAL.answer();
                    Msg::Status(Instant::now())
                }
                // Pastes, focus changes and cursor reports are not commands.
                Input::Cursor(..) | Input::Focus(_) | Input::Paste(_) => continue,
            };
            if tx.send(msg).is_err() {
                return None;
            }
        }
        if quit {
            // `q` and Ctrl-C end the app within a second even while a long
            // physics frame holds the frame loop; this thread goes on
            // reading the answers the restore waits for.
            quit::end_after_grace(0);
        }
    }
}
