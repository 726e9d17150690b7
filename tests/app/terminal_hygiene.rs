//! Issue 27: the terminal comes back clean, judged by a real shell
//! (`bash --norc --noediting -i`) in a pseudo-terminal whose far end answers
//! status requests after a delay (tests/common/link.rs), as tmux or a remote
//! terminal does: no answer left in the shell's input after a quit, job
//! control with a full repaint, and every fatal signal restoring the screen.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::link::{Link, Spec};
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
    // The value on an output line: the echo of the typed `printf` line
    // holds `tag=%d|` too, and may be on screen before the output is.
    let value = |l: &str| {
        let i = l.find(&pat)? + pat.len();
        let (v, _) = l[i..].split_once('|')?;
        (!l.contains("printf")).then(|| v.to_string())
    };
    let found = sh.wait_for(20.0, |s| s.lines().any(|l| value(l).is_some()));
    assert!(found.is_some(), "no {tag} on screen: {}", sh.text());
    let text = sh.text();
    text.lines().rev().find_map(value).unwrap()
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

/// The pid of the shell's child running ballpit.
fn app_pid(sh: &Link) -> u32 {
    let shell = sh.child.process_id().unwrap();
    let end = Instant::now() + Duration::from_secs(10);
    loop {
        for e in std::fs::read_dir("/proc").unwrap().flatten() {
            let Ok(stat) = std::fs::read_to_string(e.path().join("stat")) else {
                continue;
            };
            let Some(close) = stat.rfind(')') else {
                continue;
            };
            let name = &stat[stat.find('(').unwrap() + 1..close];
            let ppid: Option<u32> = stat[close + 2..]
                .split_whitespace()
                .nth(1)
                .and_then(|p| p.parse().ok());
            if name == "ballpit" && ppid == Some(shell) {
                return e.file_name().to_str().unwrap().parse().unwrap();
            }
        }
        assert!(Instant::now() < end, "no ballpit under the shell");
        thread::sleep(Duration::from_millis(20));
    }
}

fn kill(sig: &str, pid: u32) {
    let st = std::process::Command::new("kill")
        .args([&format!("-{sig}"), &pid.to_string()])
        .status()
        .unwrap();
    assert!(st.success(), "kill -{sig} {pid}");
}

/// The shell has the terminal: its screen, the cursor shown, and a typed
/// command runs (its text echoed, its output printed).
fn shell_is_usable(sh: &Link, n: u32) {
    let back = sh.wait_for(20.0, |_| sh.modes() == (false, false));
    assert!(
        back.is_some(),
        "the shell's screen did not come back: {}",
        sh.text()
    );
    line(sh, &format!("echo typed$(({n}*2))"));
    let want = format!("typed{}", n * 2);
    let ran = sh.wait_for(20.0, |s| {
        s.contains(&format!("echo typed$(({n}*2))")) && s.lines().any(|l| l.trim() == want)
    });
    assert!(
        ran.is_some(),
        "the typed command did not run: {}",
        sh.text()
    );
}

/// Rows of the screen with something drawn on them.
fn drawn_rows(text: &str) -> usize {
    text.lines().filter(|l| !l.trim().is_empty()).count()
}

/// `fg` resumes the app: the whole screen is drawn again (the model's
/// alternate screen was blanked while the shell had the terminal), and a
/// key acts at once (raw mode: no Enter).
fn fg_repaints(sh: &Link) {
    sh.blank_alternate();
    line(sh, "fg");
    let full = sh.wait_for(20.0, |s| {
        sh.modes() == (true, true) && s.contains("threading") && drawn_rows(s) >= 38
    });
    assert!(full.is_some(), "not repainted after fg: {}", sh.text());
    let tick = |s: &str| crate::common::link::readout(s, "tick").map(str::to_string);
    let before = tick(&sh.text());
    sh.send(b"]");
    let moved = sh.wait_for(20.0, |s| tick(s) != before && drawn_rows(s) >= 38);
    assert!(moved.is_some(), "`]` had no effect after fg: {}", sh.text());
}

#[test]
fn ctrl_z_sigtstp_and_sigstop_give_the_shell_back_and_fg_repaints() {
    let sh = shell();
    line(&sh, &format!("{BIN} --tick 5"));
    wait_app(&sh);
    let pid = app_pid(&sh);

    // Ctrl-Z as a key (the app's terminal is raw).
    sh.send(b"\x1a");
    shell_is_usable(&sh, 21);
    fg_repaints(&sh);

    // SIGTSTP from elsewhere.
    kill("TSTP", pid);
    shell_is_usable(&sh, 22);
    fg_repaints(&sh);

    // SIGSTOP, which the app cannot see: the shell prompts over its screen;
    // the SIGCONT of `fg` puts raw mode and the screen back.
    sh.blank();
    kill("STOP", pid);
    let stopped = sh.wait_for(20.0, |s| s.contains("Stopped"));
    assert!(stopped.is_some(), "{}", sh.text());
    // A stop the app cannot see leaves the answers to its last requests to
    // the shell; they are on the line being typed: kill the line (Ctrl-U).
    thread::sleep(Duration::from_millis(300));
    sh.send(b"\x15");
    fg_repaints(&sh);

    sh.send(b"q");
    let back = sh.wait_for(20.0, |_| sh.modes() == (false, false));
    assert!(back.is_some(), "q did not end the app: {}", sh.text());
    line(&sh, "printf 'rc=%d|\\n' $?");
    assert_eq!(printed(&sh, "rc"), "0");
    assert_eq!(sh.modes(), (false, false));
}

#[test]
fn every_fatal_signal_restores_the_terminal() {
    use signal_hook::consts as c;
    let signals = [
        ("HUP", c::SIGHUP),
        ("INT", c::SIGINT),
        ("QUIT", c::SIGQUIT),
        ("TERM", c::SIGTERM),
        ("USR1", c::SIGUSR1),
        ("USR2", c::SIGUSR2),
        ("ALRM", c::SIGALRM),
        ("VTALRM", c::SIGVTALRM),
        ("PROF", c::SIGPROF),
        ("XCPU", c::SIGXCPU),
        ("XFSZ", c::SIGXFSZ),
        ("PIPE", c::SIGPIPE),
    ];
    let sh = shell();
    // QUIT, XCPU and XFSZ dump core by default: not into the test's tree.
    line(&sh, "ulimit -c 0");
    for (i, (name, sig)) in signals.into_iter().enumerate() {
        sh.blank();
        // A line of its own: bash drops the rest of a list whose command
        // died of SIGINT.
        line(&sh, BIN);
        wait_app(&sh);
        kill(name, app_pid(&sh));
        let back = sh.wait_for(20.0, |_| sh.modes() == (false, false));
        assert!(back.is_some(), "SIG{name}: the screen is still the app's");
        line(&sh, &format!("printf 's%d=%d|\\n' {i} $?"));
        let rc = printed(&sh, &format!("s{i}"));
        assert_eq!(rc, (128 + sig).to_string(), "SIG{name}: exit status");
        assert_eq!(
            sh.modes(),
            (false, false),
            "SIG{name}: alternate screen on or cursor hidden"
        );
        shell_is_usable(&sh, 100 + u32::try_from(i).unwrap());
    }
}
