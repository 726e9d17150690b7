//! The real binary in a real pseudo-terminal, its screen parsed with vt100.
use portable_pty::{CommandBuilder, MasterPty, PtySize, native_pty_system};
use std::io::{Read, Write};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant};

fn nz(n: u16) -> std::num::NonZeroU16 {
    std::num::NonZeroU16::new(n).unwrap()
}

struct App {
    master: Option<Box<dyn MasterPty + Send>>,
    writer: Option<Box<dyn Write + Send>>,
    child: Box<dyn portable_pty::Child + Send + Sync>,
    screen: Arc<Mutex<vt100::Parser>>,
    /// Set by the reader thread when it stops reading.
    reader: Option<thread::JoinHandle<()>>,
}

/// Start `ballpit args` at 120×40. With `read_until`, the reader thread stops
/// (and closes its end) once that text is on screen.
fn start(args: &[&str], read_until: Option<&'static str>) -> App {
    let pty = native_pty_system()
        .openpty(PtySize {
            rows: 40,
            cols: 120,
            pixel_width: 0,
            pixel_height: 0,
        })
        .expect("openpty");
    let mut cmd = CommandBuilder::new(env!("CARGO_BIN_EXE_ballpit"));
    cmd.args(args);
    cmd.env("TERM", "xterm-256color");
    cmd.env_remove("NO_COLOR");
    let child = pty.slave.spawn_command(cmd).expect("spawn ballpit");
    drop(pty.slave);
    let mut reader = pty.master.try_clone_reader().expect("reader");
    let writer = pty.master.take_writer().expect("writer");
    let screen = Arc::new(Mutex::new(vt100::Parser::new(nz(40), nz(120), 0)));
    let s = screen.clone();
    let reader = thread::spawn(move || {
        let mut buf = [0u8; 65536];
        loop {
            match reader.read(&mut buf) {
                Ok(0) | Err(_) => return,
                Ok(n) => {
                    let mut p = s.lock().unwrap();
                    p.process(&buf[..n]);
                    if read_until.is_some_and(|t| p.screen().contents().contains(t)) {
                        return;
                    }
                }
            }
        }
    });
    App {
        master: Some(pty.master),
        writer: Some(writer),
        child,
        screen,
        reader: Some(reader),
    }
}

impl App {
    fn text(&self) -> String {
        self.screen.lock().unwrap().screen().contents()
    }

    fn send(&mut self, keys: &str) {
        let w = self.writer.as_mut().unwrap();
        w.write_all(keys.as_bytes()).unwrap();
        w.flush().unwrap();
    }

    /// Resize the terminal and the screen model that parses it.
    fn resize(&self, rows: u16, cols: u16) {
        self.master
            .as_ref()
            .unwrap()
            .resize(PtySize {
                rows,
                cols,
                pixel_width: 0,
                pixel_height: 0,
            })
            .unwrap();
        self.screen
            .lock()
            .unwrap()
            .screen_mut()
            .set_size(nz(rows), nz(cols));
    }

    /// Wait until `pred` holds for the screen text; the text when it does.
    fn wait_for(&self, what: &str, secs: f64, pred: impl Fn(&str) -> bool) -> String {
        let end = Instant::now() + Duration::from_secs_f64(secs);
        loop {
            let t = self.text();
            if pred(&t) {
                return t;
            }
            if Instant::now() > end {
                panic!("timed out waiting for {what}; screen:\n{t}");
            }
            thread::sleep(Duration::from_millis(50));
        }
    }

    fn wait_exit(&mut self, secs: f64) -> Option<portable_pty::ExitStatus> {
        let end = Instant::now() + Duration::from_secs_f64(secs);
        while Instant::now() < end {
            if let Some(st) = self.child.try_wait().unwrap() {
                return Some(st);
            }
            thread::sleep(Duration::from_millis(20));
        }
        None
    }
}

impl Drop for App {
    fn drop(&mut self) {
        let _ = self.child.kill();
    }
}

/// The value after `label` on the readouts line starting with it.
fn readout<'a>(screen: &'a str, label: &str) -> Option<&'a str> {
    screen.lines().find_map(|l| {
        let i = l.find(&format!("│{label} "))?;
        l[i + label.len() + "│".len()..]
            .split('│')
            .next()
            .map(str::trim)
    })
}

/// CPU % per thread name from the thread panel.
fn thread_loads(screen: &str) -> Vec<(String, f64)> {
    let mut out = Vec::new();
    let mut in_panel = false;
    for l in screen.lines() {
        if l.contains("threads: CPU %") {
            in_panel = true;
            continue;
        }
        // The panel's row is what lies between its two borders.
        let parts: Vec<&str> = l.split('│').collect();
        if !in_panel || parts.len() < 3 {
            continue;
        }
        let row = parts[parts.len() - 2];
        let cells: Vec<&str> = row.split_whitespace().collect();
        if cells.len() >= 2
            && cells[0] != "thread"
            && cells[0] != "total"
            && let Ok(p) = cells[1].parse::<f64>()
        {
            out.push((cells[0].to_string(), p));
        }
    }
    out
}

#[test]
fn readouts_threading_tick_and_quit_in_a_real_terminal() {
    // A tick high enough that the physics, not the drawing, is the load.
    let mut app = start(&["--tick", "120"], None);
    let s = app.wait_for("the readouts", 10.0, |s| {
        s.contains("threading") && s.contains("fps") && s.contains("physics")
    });
    assert!(app.screen.lock().unwrap().screen().alternate_screen());
    assert_eq!(
        readout(&s, "threading").map(|v| v.starts_with("off")),
        Some(true),
        "{s}"
    );
    assert_eq!(
        readout(&s, "tick").map(|v| v.starts_with("120 ")),
        Some(true),
        "{s}"
    );
    assert_eq!(readout(&s, "count"), Some("1000"), "{s}");
    // `t` switches threading on: the worker.
    app.send("t");
    app.wait_for("threading worker", 3.0, |s| {
        readout(s, "threading").is_some_and(|v| v.starts_with("worker"))
    });
    // The load moves to the `physics` thread (once per-thread figures exist).
    if !app.text().contains("no per-thread figures") {
        let s = app.wait_for("physics to carry most of the load", 6.0, |s| {
            let loads = thread_loads(s);
            let physics = loads.iter().find(|(n, _)| n == "physics").map(|l| l.1);
            physics.is_some_and(|p| loads.iter().all(|(n, q)| n == "physics" || *q < p))
        });
        assert!(
            thread_loads(&s)
                .iter()
                .any(|(n, p)| n == "physics" && *p > 10.0),
            "{s}"
        );
    }
    // Frames are paced at --fps (30 by default): never faster.
    let s = app.wait_for("an fps figure", 4.0, |s| {
        readout(s, "fps").is_some_and(|v| !v.starts_with("0.0 "))
    });
    let fps: f64 = readout(&s, "fps")
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .expect("fps readout");
    assert!((10.0..=31.5).contains(&fps), "fps {fps}\n{s}");
    // `]` raises the tick on screen.
    app.send("]");
    app.wait_for("tick 121", 3.0, |s| {
        readout(s, "tick").is_some_and(|v| v.starts_with("121 "))
    });
    app.send("q");
    let st = app.wait_exit(3.0).expect("q ends the app");
    assert!(st.success(), "exit {st:?}");
    // Everything written has been read once the child is gone.
    thread::sleep(Duration::from_millis(200));
    assert!(
        !app.screen.lock().unwrap().screen().alternate_screen(),
        "left the alternate screen"
    );
}

#[test]
fn closing_the_terminal_ends_the_app_within_two_seconds() {
    let mut app = start(&[], Some("threading"));
    app.reader.take().unwrap().join().unwrap();
    // The connection drops: every handle on the master side goes.
    app.writer.take();
    app.master.take();
    let t0 = Instant::now();
    let st = app.wait_exit(2.0);
    assert!(
        st.is_some(),
        "still running {:?} after the pty closed",
        t0.elapsed()
    );
    assert!(!st.unwrap().success());
}

#[test]
fn sigterm_restores_the_terminal_and_exits_non_zero() {
    let mut app = start(&[], None);
    app.wait_for("the readouts", 10.0, |s| s.contains("threading"));
    let pid = app.child.process_id().expect("pid");
    let killed = std::process::Command::new("kill")
        .args(["-TERM", &pid.to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let st = app.wait_exit(2.0).expect("SIGTERM ends the app");
    assert!(!st.success());
    thread::sleep(Duration::from_millis(200));
    let p = app.screen.lock().unwrap();
    assert!(!p.screen().alternate_screen(), "left the alternate screen");
    assert!(!p.screen().hide_cursor(), "cursor shown again");
}

#[test]
fn a_small_terminal_gets_told_how_big_it_must_be_and_resizing_recovers() {
    let mut app = start(&[], None);
    app.wait_for("the readouts", 10.0, |s| s.contains("threading"));
    app.resize(15, 50);
    let s = app.wait_for("the size message", 3.0, |s| s.contains("at least"));
    assert!(s.contains("72x22") && s.contains("50x15"), "{s}");
    app.resize(40, 120);
    app.wait_for("the readouts again", 3.0, |s| {
        s.contains("threading") && !s.contains("at least")
    });
    app.send("q");
    assert!(app.wait_exit(3.0).expect("q ends the app").success());
}

#[test]
fn a_panic_in_another_thread_restores_the_terminal_then_prints_and_fails() {
    let pty = native_pty_system()
        .openpty(PtySize {
            rows: 40,
            cols: 120,
            pixel_width: 0,
            pixel_height: 0,
        })
        .unwrap();
    let mut cmd = CommandBuilder::new(env!("CARGO_BIN_EXE_ballpit"));
    cmd.env("TERM", "xterm-256color");
    cmd.env("BALLPIT_TEST_PANIC_THREAD", "1");
    cmd.env("RUST_BACKTRACE", "0");
    let mut child = pty.slave.spawn_command(cmd).unwrap();
    drop(pty.slave);
    let mut reader = pty.master.try_clone_reader().unwrap();
    let raw = Arc::new(Mutex::new(Vec::new()));
    let r = raw.clone();
    let drain = thread::spawn(move || {
        let mut buf = [0u8; 65536];
        while let Ok(n) = reader.read(&mut buf) {
            if n == 0 {
                break;
            }
            r.lock().unwrap().extend_from_slice(&buf[..n]);
        }
    });
    let end = Instant::now() + Duration::from_secs(5);
    let status = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        assert!(Instant::now() < end, "the panic did not end the app");
        thread::sleep(Duration::from_millis(20));
    };
    assert!(!status.success());
    // Everything the app wrote before it ended, however loaded the machine:
    // the reader stops at the end of the terminal's output.
    let end = Instant::now() + Duration::from_secs(5);
    while !drain.is_finished() && Instant::now() < end {
        thread::sleep(Duration::from_millis(20));
    }
    let out = String::from_utf8_lossy(&raw.lock().unwrap()).to_string();
    let left = out.rfind("\x1b[?1049l").expect("left the alternate screen");
    let msg = out
        .find("test panic in a worker thread")
        .expect("the panic message");
    assert!(left < msg, "message printed after the restore");
    let mut p = vt100::Parser::new(nz(40), nz(120), 0);
    p.process(out.as_bytes());
    assert!(!p.screen().alternate_screen());
    assert!(
        p.screen()
            .contents()
            .contains("test panic in a worker thread")
    );
}

#[test]
fn ctrl_c_and_esc_quit_cleanly() {
    for key in ["\x03", "\x1b"] {
        let mut app = start(&[], None);
        app.wait_for("the readouts", 10.0, |s| s.contains("threading"));
        app.send(key);
        let st = app.wait_exit(3.0).expect("the key ends the app");
        assert!(st.success(), "{key:?}: {st:?}");
        thread::sleep(Duration::from_millis(200));
        assert!(!app.screen.lock().unwrap().screen().alternate_screen());
    }
}
