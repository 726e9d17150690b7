//! Issue 27, item 6: a locale that is not UTF-8 gets an ASCII screen, a
//! terminal without colours gets no colour escape, and the size message
//! fits at any size (the real binary in a real pty).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::child::wait_exit;
use crate::common::pty;
use portable_pty::CommandBuilder;
use std::io::{Read, Write};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant};

/// Run the app at `rows` x `cols` with `env` until `ready` holds for the
/// screen (or 20 s, generous for a loaded runner), press `q`; the screen
/// then and every byte the app wrote.
fn run(
    env: &[(&str, &str)],
    (rows, cols): (u16, u16),
    ready: fn(&str) -> bool,
) -> (String, Vec<u8>) {
    let pty = pty::open((rows, cols));
    let mut cmd = CommandBuilder::new(env!("CARGO_BIN_EXE_ballpit"));
    cmd.env_remove("NO_COLOR");
    cmd.env_remove("LC_ALL");
    cmd.env_remove("LC_CTYPE");
    cmd.env("TERM", "xterm-256color");
    cmd.env("LANG", "C.UTF-8");
    for (k, v) in env {
        cmd.env(k, v);
    }
    let mut child = pty.slave.spawn_command(cmd).unwrap();
    drop(pty.slave);
    let mut reader = pty.master.try_clone_reader().unwrap();
    let mut writer = pty.master.take_writer().unwrap();
    let raw = Arc::new(Mutex::new(Vec::new()));
    let r = raw.clone();
    thread::spawn(move || {
        let mut buf = vec![0u8; 65536];
        while let Ok(n) = reader.read(&mut buf) {
            if n == 0 {
                return;
            }
            r.lock().unwrap().extend_from_slice(&buf[..n]);
        }
    });
    let screen = |raw: &[u8]| {
        let mut p = vt100::Parser::new(pty::nz(rows), pty::nz(cols), 0);
        p.process(raw);
        p.screen().contents()
    };
    let end = Instant::now() + Duration::from_secs(20);
    let text = loop {
        let t = screen(&raw.lock().unwrap());
        if ready(&t) {
            break t;
        }
        assert!(Instant::now() < end, "timed out; screen:\n{t}");
        thread::sleep(Duration::from_millis(50));
    };
    // A second more of frames, then quit.
    thread::sleep(Duration::from_secs(1));
    let text = if ready(&screen(&raw.lock().unwrap())) {
        screen(&raw.lock().unwrap())
    } else {
        text
    };
    writer.write_all(b"q").unwrap();
    writer.flush().unwrap();
    wait_exit(&mut *child, 20.0, Duration::from_millis(20)).expect("q did not end the app");
    thread::sleep(Duration::from_millis(100));
    let bytes = raw.lock().unwrap().clone();
    (text, bytes)
}

fn app_up(s: &str) -> bool {
    s.contains("threading") && s.contains("fps")
}

#[test]
fn a_locale_that_is_not_utf8_gets_an_ascii_screen() {
    for (k, v) in [
        ("LANG", "C"),
        ("LC_ALL", "POSIX"),
        ("LC_CTYPE", "en_US.ISO-8859-1"),
    ] {
        let (text, _) = run(&[(k, v)], (40, 120), app_up);
        let odd: Vec<char> = text.chars().filter(|c| !c.is_ascii()).collect();
        assert!(odd.is_empty(), "{k}={v}: {odd:?} on screen:\n{text}");
        // Borders are drawn, in ASCII.
        assert!(
            text.contains("+-") && text.contains('|'),
            "{k}={v}:\n{text}"
        );
    }
    // The same app in a UTF-8 locale draws box lines (the check can fail).
    let (text, _) = run(&[], (40, 120), app_up);
    assert!(text.contains('│'), "{text}");
}

/// SGR parameters of every `ESC [ ... m` in `bytes`.
fn sgr_params(bytes: &[u8]) -> Vec<String> {
    let mut out = Vec::new();
    let mut i = 0;
    while i + 1 < bytes.len() {
        if bytes[i] == 0x1b && bytes[i + 1] == b'[' {
            let mut j = i + 2;
            while j < bytes.len() && (bytes[j].is_ascii_digit() || bytes[j] == b';') {
                j += 1;
            }
            if j < bytes.len() && bytes[j] == b'm' {
                out.push(String::from_utf8_lossy(&bytes[i + 2..j]).into_owned());
            }
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

fn colour_codes(bytes: &[u8]) -> Vec<String> {
    sgr_params(bytes)
        .into_iter()
        .filter(|p| {
            p.split(';').any(|n| {
                n.parse::<u32>()
                    .is_ok_and(|n| matches!(n, 30..=49 | 90..=97 | 100..=107))
            })
        })
        .collect()
}

#[test]
fn terminals_without_colours_get_no_colour_escape() {
    for term in ["xterm-mono", "vt100", "dumb"] {
        let (text, bytes) = run(&[("TERM", term)], (40, 120), app_up);
        let colours = colour_codes(&bytes);
        assert!(
            colours.is_empty(),
            "TERM={term}: {:?}\n{text}",
            &colours[..colours.len().min(5)]
        );
    }
    // The same app on a colour terminal writes colours (the check can fail).
    let (_, bytes) = run(&[("TERM", "xterm")], (40, 120), app_up);
    assert!(!colour_codes(&bytes).is_empty());
}

#[test]
fn the_size_message_fits_down_to_1x1() {
    for (rows, cols, want) in [
        (5, 20, "this is 20x5."),
        (1, 1, "!"),
        (3, 12, "need"),
        (10, 40, "this terminal is 40x10."),
    ] {
        let (text, _) = run(&[], (rows, cols), |s| !s.trim().is_empty());
        assert!(text.contains(want), "{cols}x{rows}: {text:?}");
    }
}
