//! The real binary in a real pseudo-terminal, its screen parsed with vt100:
//! start it, type, resize, and wait (with a deadline) for what the screen
//! shows. Shared by the pty tests.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use portable_pty::{CommandBuilder, MasterPty, PtyPair, PtySize, native_pty_system};
use std::io::{Read, Write};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant};

pub fn nz(n: u16) -> std::num::NonZeroU16 {
    std::num::NonZeroU16::new(n).unwrap()
}

/// A pseudo-terminal of `rows` x `cols`.
pub fn open((rows, cols): (u16, u16)) -> PtyPair {
    native_pty_system()
        .openpty(PtySize {
            rows,
            cols,
            pixel_width: 0,
            pixel_height: 0,
        })
        .expect("openpty")
}

pub struct App {
    pub master: Option<Box<dyn MasterPty + Send>>,
    pub writer: Option<Box<dyn Write + Send>>,
    pub child: Box<dyn portable_pty::Child + Send + Sync>,
    pub screen: Arc<Mutex<vt100::Parser>>,
    /// Set by the reader thread when it stops reading.
    pub reader: Option<thread::JoinHandle<()>>,
}

/// Start `ballpit args` at 120×40. With `read_until`, the reader thread stops
/// (and closes its end) once that text is on screen.
pub fn start(args: &[&str], read_until: Option<&'static str>) -> App {
    start_with(args, read_until, (40, 120), "xterm-256color")
}

pub fn start_with(
    args: &[&str],
    read_until: Option<&'static str>,
    (rows, cols): (u16, u16),
    term: &str,
) -> App {
    let mut cmd = CommandBuilder::new(env!("CARGO_BIN_EXE_ballpit"));
    cmd.args(args);
    start_command(cmd, read_until, (rows, cols), term)
}

/// Start `cmd` (e.g. a shell that sets a limit and execs the binary).
pub fn start_command(
    mut cmd: CommandBuilder,
    read_until: Option<&'static str>,
    (rows, cols): (u16, u16),
    term: &str,
) -> App {
    let pty = open((rows, cols));
    cmd.env("TERM", term);
    cmd.env_remove("NO_COLOR");
    let child = pty.slave.spawn_command(cmd).expect("spawn ballpit");
    drop(pty.slave);
    let mut reader = pty.master.try_clone_reader().expect("reader");
    let writer = pty.master.take_writer().expect("writer");
    let screen = Arc::new(Mutex::new(vt100::Parser::new(nz(rows), nz(cols), 0)));
    let s = screen.clone();
    let reader = thread::spawn(move || {
        let mut buf = vec![0u8; 65536];
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
    pub fn text(&self) -> String {
        self.screen.lock().unwrap().screen().contents()
    }

    pub fn send(&mut self, keys: &str) {
        let w = self.writer.as_mut().unwrap();
        w.write_all(keys.as_bytes()).unwrap();
        w.flush().unwrap();
    }

    /// Resize the screen model that parses the terminal, then the terminal
    /// (in that order, so the app's redraw for the new size is parsed at
    /// that size). A size of 0 leaves the model as it was: vt100 has no
    /// empty screen.
    pub fn resize(&self, rows: u16, cols: u16) {
        if rows > 0 && cols > 0 {
            self.screen
                .lock()
                .unwrap()
                .screen_mut()
                .set_size(nz(rows), nz(cols));
        }
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
    }

    /// Blank the screen model, resize, and wait until the app has drawn
    /// `what` again: proof it has taken the resize in (a resize makes it
    /// redraw everything). The blank comes first: made after the resize it
    /// could wipe a redraw that had already arrived.
    pub fn resize_and_wait(&self, rows: u16, cols: u16, what: &str) {
        self.screen.lock().unwrap().process(b"\x1b[2J");
        self.resize(rows, cols);
        self.wait_for(what, 5.0, |s| s.contains(what));
    }

    pub fn alive(&mut self) -> bool {
        self.child.try_wait().unwrap().is_none()
    }

    /// CPU seconds (user + system) the app has used so far.
    pub fn cpu_seconds(&self) -> f64 {
        let pid = self.child.process_id().expect("pid");
        let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).expect("stat");
        // Fields after the command name, which is in parentheses.
        let rest = &stat[stat.rfind(')').unwrap() + 2..];
        let f: Vec<&str> = rest.split_whitespace().collect();
        let ticks: f64 = f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap();
        ticks / 100.0
    }

    /// Wait until `pred` holds for the screen text; the text when it does.
    pub fn wait_for(&self, what: &str, secs: f64, pred: impl Fn(&str) -> bool) -> String {
        let end = Instant::now() + Duration::from_secs_f64(secs);
        loop {
            let t = self.text();
            if pred(&t) {
                return t;
            }
            assert!(
                Instant::now() <= end,
                "timed out waiting for {what}; screen:\n{t}"
            );
            thread::sleep(Duration::from_millis(50));
        }
    }

    pub fn wait_exit(&mut self, secs: f64) -> Option<portable_pty::ExitStatus> {
        super::child::wait_exit(&mut *self.child, secs, Duration::from_millis(20))
    }

    /// Press `q` and check the app exits 0 within 5 s.
    pub fn quit(mut self) {
        self.send("q");
        let st = self.wait_exit(5.0).expect("q ends the app");
        assert!(st.success(), "{st:?}");
    }
}

impl Drop for App {
    fn drop(&mut self) {
        let _ = self.child.kill();
    }
}
