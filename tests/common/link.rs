//! A slow link between an app in a pseudo-terminal and an emulated terminal
//! (issue 16): the far end reads the app's output at a limited rate, adds a
//! one-way delay each way, feeds it to a vt100 screen, and answers the
//! device status query (`ESC[5n` → `ESC[0n`), cursor position (`ESC[6n`)
//! and device attributes (`ESC[c`) only once it has consumed the bytes before
//! them, as a real terminal does. Shared by `tests/app/slow_link.rs` and
//! `examples/slow_link.rs` (which compiles `child.rs` beside it by path).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
#![allow(dead_code)] // examples/slow_link.rs compiles this file too, and each uses part of it
use crossbeam_channel::{Receiver, Sender, unbounded};
use portable_pty::{CommandBuilder, MasterPty, PtySize, native_pty_system};
use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant};

#[derive(Clone, Copy, Debug)]
pub struct Spec {
    /// Bytes per second from the app to the screen; None: unlimited.
    pub rate: Option<f64>,
    /// One-way delay, each way.
    pub delay: Duration,
    /// Whether the terminal answers queries.
    pub answers: bool,
    pub rows: u16,
    pub cols: u16,
}

impl Spec {
    pub fn new(rate: Option<f64>, delay_ms: u64) -> Spec {
        Spec {
            rate,
            delay: Duration::from_millis(delay_ms),
            answers: true,
            rows: 40,
            cols: 120,
        }
    }
}

pub struct Link {
    pub child: Box<dyn portable_pty::Child + Send + Sync>,
    _master: Box<dyn MasterPty + Send>,
    screen: Arc<Mutex<vt100::Parser>>,
    up: Sender<(Instant, Vec<u8>)>,
    spec: Spec,
    /// Bytes the screen has consumed.
    pub delivered: Arc<AtomicU64>,
    /// Queries answered.
    pub answered: Arc<AtomicU64>,
    stop: Arc<AtomicBool>,
}

fn sleep_until(t: Instant) {
    let now = Instant::now();
    if t > now {
        thread::sleep(t - now);
    }
}

const QUERIES: [&[u8]; 3] = [b"\x1b[5n", b"\x1b[6n", b"\x1b[c"];

impl Link {
    // Each end of the link is a thread; the far one scans every chunk for
    // the terminal queries it answers.
    #[allow(clippy::too_many_lines)] // the link's three threads, set up in one place
    #[allow(clippy::excessive_nesting)] // the far end's loop: read, scan, answer, forward
    pub fn start(mut cmd: CommandBuilder, spec: Spec) -> Link {
        let pty = native_pty_system()
            .openpty(PtySize {
                rows: spec.rows,
                cols: spec.cols,
                pixel_width: 0,
                pixel_height: 0,
            })
            .expect("openpty");
        cmd.env("TERM", "xterm-256color");
        if cmd.get_env("NO_COLOR").is_none() {
            cmd.env_remove("NO_COLOR");
        }
        let child = pty.slave.spawn_command(cmd).expect("spawn");
        drop(pty.slave);
        let mut reader = pty.master.try_clone_reader().expect("reader");
        let mut writer = pty.master.take_writer().expect("writer");
        let screen = Arc::new(Mutex::new(vt100::Parser::new(
            std::num::NonZeroU16::new(spec.rows).unwrap(),
            std::num::NonZeroU16::new(spec.cols).unwrap(),
            0,
        )));
        let delivered = Arc::new(AtomicU64::new(0));
        let answered = Arc::new(AtomicU64::new(0));
        let stop = Arc::new(AtomicBool::new(false));
        let (up, up_rx): (Sender<(Instant, Vec<u8>)>, Receiver<_>) = unbounded();
        let (down, down_rx): (Sender<(Instant, Vec<u8>)>, Receiver<_>) = unbounded();

        // Upstream: keys and answers, each after the delay, in order.
        let st = stop.clone();
        thread::spawn(move || {
            for (due, bytes) in up_rx {
                sleep_until(due);
                if st.load(Ordering::Relaxed) || writer.write_all(&bytes).is_err() {
                    return;
                }
                let _ = writer.flush();
            }
        });
        // The link's sending end: reads the pty no faster than the rate, so
        // the app's writes back up as they would on a slow link.
        let delay = spec.delay;
        thread::spawn(move || {
            let chunk = match spec.rate {
                // About 10 ms of the link per read.
                Some(r) => ((r / 100.0) as usize).clamp(64, 65536),
                None => 65536,
            };
            let mut buf = vec![0u8; chunk];
            let mut free = Instant::now();
            loop {
                let n = match reader.read(&mut buf) {
                    Ok(0) | Err(_) => return,
                    Ok(n) => n,
                };
                let now = Instant::now();
                let sent = match spec.rate {
                    Some(r) => {
                        free = free.max(now) + Duration::from_secs_f64(n as f64 / r);
                        free
                    }
                    None => now,
                };
                if down.send((sent + delay, buf[..n].to_vec())).is_err() {
                    return;
                }
                // The link is busy until this chunk is sent.
                sleep_until(sent);
            }
        });
        // The far end: the screen, and the answers to queries in order.
        let (scr, del, ans, up2, st) = (
            screen.clone(),
            delivered.clone(),
            answered.clone(),
            up.clone(),
            stop.clone(),
        );
        thread::spawn(move || {
            let mut tail: Vec<u8> = Vec::new();
            for (due, bytes) in down_rx {
                sleep_until(due);
                if st.load(Ordering::Relaxed) {
                    return;
                }
                let mut p = scr.lock().unwrap();
                // Queries may straddle chunks: look at the last bytes too.
                let mut all = std::mem::take(&mut tail);
                let old = all.len();
                all.extend_from_slice(&bytes);
                let mut done = old;
                let mut i = 0;
                while i < all.len() {
                    let hit = QUERIES.iter().find(|q| all[i..].starts_with(q));
                    match hit {
                        Some(q) if i + q.len() > old => {
                            let end = i + q.len();
                            p.process(&all[done..end]);
                            done = end;
                            if spec.answers {
                                let answer = answer_to(q, p.screen());
                                ans.fetch_add(1, Ordering::Relaxed);
                                let _ = up2.send((Instant::now() + delay, answer));
                            }
                            i = end;
                        }
                        _ => i += 1,
                    }
                }
                p.process(&all[done..]);
                del.fetch_add(bytes.len() as u64, Ordering::Relaxed);
                let keep = all.len().min(3);
                tail = all[all.len() - keep..].to_vec();
            }
        });
        Link {
            child,
            _master: pty.master,
            screen,
            up,
            spec,
            delivered,
            answered,
            stop,
        }
    }

    /// A key pressed at the far end now: it reaches the app after the delay.
    pub fn send(&self, bytes: &[u8]) -> Instant {
        let now = Instant::now();
        let _ = self.up.send((now + self.spec.delay, bytes.to_vec()));
        now
    }

    pub fn text(&self) -> String {
        self.screen.lock().unwrap().screen().contents()
    }

    /// Whether the alternate screen is on, and whether the cursor is hidden.
    pub fn modes(&self) -> (bool, bool) {
        let p = self.screen.lock().unwrap();
        (p.screen().alternate_screen(), p.screen().hide_cursor())
    }

    /// Blank the screen model (what comes next must draw it again).
    pub fn blank(&self) {
        self.screen.lock().unwrap().process(b"\x1b[2J");
    }

    /// Blank the model's alternate screen too, leaving the normal one on:
    /// what the app shows there next it must have drawn again.
    pub fn blank_alternate(&self) {
        self.screen
            .lock()
            .unwrap()
            .process(b"\x1b[?1049h\x1b[2J\x1b[?1049l");
    }

    /// When `pred` first held for the screen (polled every millisecond),
    /// or None at the deadline.
    pub fn wait_for(&self, secs: f64, pred: impl Fn(&str) -> bool) -> Option<Instant> {
        let end = Instant::now() + Duration::from_secs_f64(secs);
        loop {
            let now = Instant::now();
            if pred(&self.text()) {
                return Some(now);
            }
            if now > end {
                return None;
            }
            thread::sleep(Duration::from_millis(1));
        }
    }

    pub fn wait_exit(&mut self, secs: f64) -> Option<portable_pty::ExitStatus> {
        super::child::wait_exit(&mut *self.child, secs, Duration::from_millis(5))
    }
}

impl Drop for Link {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        let _ = self.child.kill();
    }
}

/// The value after `label` on the readouts line that has it.
pub fn readout<'a>(screen: &'a str, label: &str) -> Option<&'a str> {
    screen.lines().find_map(|l| {
        let i = [format!("│{label} "), format!(" {label} ")]
            .iter()
            .find_map(|pat| l.find(pat.as_str()).map(|i| i + pat.len() - 1))?;
        l[i..].split('│').next().map(str::trim)
    })
}

pub const STYLES: [&str; 3] = ["braille, speed", "braille, depth", "shaded blocks"];

/// Key-to-screen latencies of `keys` presses of `v` (the style row), at
/// random moments (`gap` plus up to `jitter`, from a seeded generator).
pub fn style_key_latencies(
    link: &Link,
    keys: usize,
    seed: u64,
    gap: Duration,
    jitter: Duration,
) -> Vec<Duration> {
    let mut rng = seed | 1;
    let mut next = || {
        rng ^= rng >> 12;
        rng ^= rng << 25;
        rng ^= rng >> 27;
        rng.wrapping_mul(0x2545_f491_4f6c_dd1d)
    };
    let style = |s: &str| STYLES.iter().position(|n| readout(s, "style") == Some(n));
    link.wait_for(20.0, |s| style(s).is_some())
        .expect("the style row");
    let mut at = style(&link.text()).unwrap();
    let mut out = Vec::new();
    for _ in 0..keys {
        let wait = gap + jitter.mul_f64((next() % 1000) as f64 / 1000.0);
        thread::sleep(wait);
        at = (at + 1) % STYLES.len();
        let t0 = link.send(b"v");
        let seen = link
            .wait_for(10.0, |s| style(s) == Some(at))
            .unwrap_or_else(|| panic!("style {} never shown:\n{}", STYLES[at], link.text()));
        out.push(seen - t0);
    }
    out
}

/// Median and worst.
pub fn summary(lat: &[Duration]) -> (Duration, Duration) {
    let mut v = lat.to_vec();
    v.sort();
    let median = if v.len().is_multiple_of(2) {
        (v[v.len() / 2 - 1] + v[v.len() / 2]) / 2
    } else {
        v[v.len() / 2]
    };
    (median, *v.last().unwrap())
}

/// What a terminal answers to query `q` (status, cursor position, device
/// attributes).
fn answer_to(q: &[u8], screen: &vt100::Screen) -> Vec<u8> {
    match q[q.len() - 1] {
        b'n' if q[2] == b'5' => b"\x1b[0n".to_vec(),
        b'n' => {
            let (r, c) = screen.cursor_position();
            format!("\x1b[{};{}R", r + 1, c + 1).into_bytes()
        }
        _ => b"\x1b[?62;22c".to_vec(),
    }
}
