//! The screen's layout in the real binary, in a real pseudo-terminal at
//! 80x24 (the size most terminals open at), its screen parsed with vt100:
//! every thread is on screen in every threading mode, and `c` shows the
//! chart. Waits poll the screen with a deadline; nothing sleeps blind.
use portable_pty::{CommandBuilder, PtySize, native_pty_system};
use std::io::{Read, Write};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant};

struct App {
    _master: Box<dyn portable_pty::MasterPty + Send>,
    writer: Box<dyn Write + Send>,
    child: Box<dyn portable_pty::Child + Send + Sync>,
    screen: Arc<Mutex<vt100::Parser>>,
}

fn start(args: &[&str], cols: u16, rows: u16) -> App {
    let pty = native_pty_system()
        .openpty(PtySize {
            rows,
            cols,
            pixel_width: 0,
            pixel_height: 0,
        })
        .expect("openpty");
    let mut cmd = CommandBuilder::new(env!("CARGO_BIN_EXE_ballpit"));
    cmd.args(args);
    cmd.env("TERM", "xterm-256color");
    let child = pty.slave.spawn_command(cmd).expect("spawn ballpit");
    drop(pty.slave);
    let mut reader = pty.master.try_clone_reader().expect("reader");
    let writer = pty.master.take_writer().expect("writer");
    let nz = |n| std::num::NonZeroU16::new(n).unwrap();
    let screen = Arc::new(Mutex::new(vt100::Parser::new(nz(rows), nz(cols), 0)));
    let s = screen.clone();
    thread::spawn(move || {
        let mut buf = [0u8; 65536];
        while let Ok(n @ 1..) = reader.read(&mut buf) {
            s.lock().unwrap().process(&buf[..n]);
        }
    });
    App {
        _master: pty.master,
        writer,
        child,
        screen,
    }
}

impl App {
    fn text(&self) -> String {
        self.screen.lock().unwrap().screen().contents()
    }

    fn send(&mut self, keys: &str) {
        self.writer.write_all(keys.as_bytes()).unwrap();
        self.writer.flush().unwrap();
    }

    fn wait_for(&self, what: &str, secs: f64, pred: impl Fn(&str) -> bool) -> String {
        let end = Instant::now() + Duration::from_secs_f64(secs);
        loop {
            let t = self.text();
            if pred(&t) {
                return t;
            }
            assert!(
                Instant::now() < end,
                "timed out waiting for {what}; screen:\n{t}"
            );
            thread::sleep(Duration::from_millis(50));
        }
    }

    fn quit(mut self) {
        self.send("q");
        let end = Instant::now() + Duration::from_secs(5);
        while Instant::now() < end {
            if let Some(st) = self.child.try_wait().unwrap() {
                assert!(st.success(), "{st:?}");
                return;
            }
            thread::sleep(Duration::from_millis(20));
        }
        panic!("q did not end the app");
    }
}

impl Drop for App {
    fn drop(&mut self) {
        let _ = self.child.kill();
    }
}

/// Grid cells of the thread panel (idle dot or a bar).
fn cells(screen: &str) -> usize {
    let mut n = 0;
    let mut in_grid = false;
    for l in screen.lines() {
        if l.contains("pool x") {
            in_grid = true;
            continue;
        }
        if in_grid {
            if l.contains("total") {
                break;
            }
            // The panel's part of the line: after the canvas.
            let panel = l.rsplit_once('│').map_or(l, |p| p.0);
            let panel = panel.rsplit('│').next().unwrap_or(panel);
            n += panel.chars().filter(|c| "·▁▂▃▄▅▆▇█".contains(*c)).count();
        }
    }
    n
}

#[test]
fn every_thread_and_the_total_at_80x24_in_pool_split_and_64_threads() {
    let names = |s: &str, want: &[&str]| want.iter().all(|n| s.contains(n));
    let base = ["main", "physics", "total", "other procs"];

    let app = start(&["--threading", "pool", "--threads", "2"], 80, 24);
    app.wait_for("pool-0 and pool-1", 10.0, |s| {
        names(s, &base) && names(s, &["pool-0", "pool-1"])
    });
    app.quit();

    let app = start(&["--threading", "split"], 80, 24);
    app.wait_for("split-pair and split-wall", 10.0, |s| {
        names(s, &base) && names(s, &["split-pair", "split-wall"])
    });
    app.quit();

    let app = start(&["--threading", "pool", "--threads", "64"], 80, 24);
    app.wait_for("a cell for each of 64 pool threads", 10.0, |s| {
        names(s, &base) && s.contains("pool x64:") && cells(s) == 64
    });
    // The help overlay fits too: its first and last keys and its border.
    let mut app = app;
    app.send("?");
    app.wait_for("the help overlay", 3.0, |s| {
        s.contains("this help") && s.contains("frame rate") && s.contains("closes this help")
    });
    app.quit();
}

#[test]
fn c_swaps_the_canvas_for_the_chart_and_back() {
    let mut app = start(&["--threading", "worker"], 80, 24);
    app.wait_for("the readouts", 10.0, |s| s.contains("threading"));
    app.send("c");
    app.wait_for("the chart with its legend", 3.0, |s| {
        s.contains("CPU per thread, last 60 s") && s.contains("━ main") && s.contains("━ physics")
    });
    app.send("c");
    app.wait_for("the canvas again", 3.0, |s| !s.contains("CPU per thread"));
    app.quit();
}
