//! Issue 27: the terminal comes back clean, judged by a real shell
//! (`bash --norc --noediting -i`) in a pseudo-terminal whose far end answers
//! status requests after a delay (tests/common/link.rs), as tmux or a remote
//! terminal does: no answer left in the shell's input after a quit, job
//! control with a full repaint, and every fatal signal restoring the screen.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
mod common;

use common::link::{Link, Spec};
use portable_pty::CommandBuilder;
use std::thread;
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_ballpit");

/// bash at 120x40 behind a link that answers 10 ms late each way, so the
/// answers to a 120 fps app's requests are always in flight.
fn shell() -> Link {
    let mut cmd = CommandBuilder::new("bash");
    cmd.args(["--norc", "--noprofile", "--noediting", "-i"]);
    cmd.env("PS1", "$ ");
    cmd.env("LANG", "C.UTF-8");
    cmd.env_remove("PROMPT_COMMAND");
    let sh = Link::start(cmd, Spec::new(None, 10));
    assert!(
        sh.wait_for(10.0, |s| s.contains("$ ")).is_some(),
        "no prompt: {}",
        sh.text()
    );
    sh
}

/// Type a line into the shell.
fn line(sh: &Link, text: &str) {
    sh.send(format!("{text}\r").as_bytes());
}

/// Wait (generously: a loaded 2-core runner) until the app's screen is up.
fn wait_app(sh: &Link) {
    let up = sh.wait_for(20.0, |s| s.contains("threading") && s.contains("fps"));
    assert!(up.is_some(), "the app did not start: {}", sh.text());
    assert!(sh.modes().0, "the app is not on the alternate screen");
}

/// The value printed after `tag=` up to `|`, once it is on screen.
fn printed(sh: &Link, tag: &str) -> String {
    let pat = format!("{tag}=");
    let found = sh.wait_for(20.0, |s| {
        s.lines()
            .any(|l| l.find(&pat).is_some_and(|i| l[i..].contains('|')))
    });
    assert!(found.is_some(), "no {tag} on screen: {}", sh.text());
    let text = sh.text();
    let l = text.lines().rev().find(|l| l.contains(&pat)).unwrap();
    let i = l.find(&pat).unwrap() + pat.len();
    l[i..].split('|').next().unwrap().to_string()
}

/// 12 quits in one shell: each about a second after the start, by `q`,
/// Esc or Ctrl-C in turn, at 30 and 120 fps. Afterwards the shell reads its
/// input for 0.3 s: nothing may be there.
fn quits(first: usize) {
    let keys: [(&str, &[u8]); 3] = [("q", b"q"), ("Esc", b"\x1b"), ("Ctrl-C", b"\x03")];
    let mut sh = shell();
    for i in first..first + 12 {
        let fps = if i % 2 == 0 { 30 } else { 120 };
        let (name, key) = keys[i % 3];
        sh.blank();
        line(
            &sh,
            &format!(
                "{BIN} --fps {fps}; rc=$?; read -t 0.3 -r -n 200 left; \
                 printf 'q%d=%d %q|\\n' {i} $rc \"$left\""
            ),
        );
        let t0 = Instant::now();
        wait_app(&sh);
        thread::sleep(Duration::from_secs(1).saturating_sub(t0.elapsed()));
        sh.send(key);
        let got = printed(&sh, &format!("q{i}"));
        assert_eq!(
            got, "0 ''",
            "quit {i} by {name} at {fps} fps: exit status and what was left \
             in the shell's input"
        );
        assert_eq!(
            sh.modes(),
            (false, false),
            "quit {i} by {name} at {fps} fps: alternate screen on or cursor hidden"
        );
    }
    line(&sh, "exit");
    assert!(sh.wait_exit(10.0).is_some());
}

#[test]
fn quits_leave_nothing_in_the_shells_input() {
    // Two shells at once: 24 quits in about half the time.
    let other = thread::spawn(|| quits(12));
    quits(0);
    other.join().unwrap();
}
