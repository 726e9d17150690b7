//! Frames per second of the real app in a pseudo-terminal: counts the
//! synchronized-output frames (DEC 2026) the binary writes over a window
//! and reads the fps and physics figures its status line shows at the end,
//! and the app's peak resident memory.
//! Run `cargo build --release` first, then
//!
//!     cargo run --release --example tui_fps -- SECS COLSxROWS [BALLPIT ARGS...]
//!
//! e.g. `-- 10 120x40 --count 100000 --radius 0.002285 --threading pool`.
use portable_pty::{CommandBuilder, PtySize, native_pty_system};
use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

const BEGIN_SYNC: &[u8] = b"\x1b[?2026h";

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let secs: f64 = args.first().map_or(Ok(10.0), |a| a.parse())?;
    let (cols, rows) = args
        .get(1)
        .and_then(|s| s.split_once('x'))
        .map_or(Ok((120, 40)), |(c, r)| anyhow::Ok((c.parse()?, r.parse()?)))?;
    let bin = std::env::var("BALLPIT").unwrap_or_else(|_| "target/release/ballpit".into());
    let pty = native_pty_system().openpty(PtySize {
        rows,
        cols,
        pixel_width: 0,
        pixel_height: 0,
    })?;
    let mut cmd = CommandBuilder::new(std::fs::canonicalize(&bin)?);
    cmd.args(args.iter().skip(2));
    cmd.env("TERM", "xterm-256color");
    let mut child = pty.slave.spawn_command(cmd)?;
    drop(pty.slave);
    let mut reader = pty.master.try_clone_reader()?;
    let mut writer = pty.master.take_writer()?;
    let frames = Arc::new(AtomicU64::new(0));
    let bytes = Arc::new(AtomicU64::new(0));
    let nz = |n: u16| std::num::NonZeroU16::new(n).ok_or_else(|| anyhow::anyhow!("a size of 0"));
    let screen = Arc::new(Mutex::new(vt100::Parser::new(nz(rows)?, nz(cols)?, 0)));
    let done = Arc::new(AtomicBool::new(false));
    let (f, b, s, d) = (frames.clone(), bytes.clone(), screen.clone(), done.clone());
    let read = std::thread::spawn(move || {
        let mut buf = vec![0u8; 1 << 16];
        // A marker split over two reads still counts once.
        let mut tail: Vec<u8> = Vec::new();
        while let Ok(n) = reader.read(&mut buf) {
            if n == 0 || d.load(Ordering::Relaxed) {
                break;
            }
            tail.extend_from_slice(&buf[..n]);
            let hits = tail
                .windows(BEGIN_SYNC.len())
                .filter(|w| *w == BEGIN_SYNC)
                .count();
            f.fetch_add(hits as u64, Ordering::Relaxed);
            b.fetch_add(n as u64, Ordering::Relaxed);
            tail.drain(..tail.len().saturating_sub(BEGIN_SYNC.len() - 1));
            if let Ok(mut p) = s.lock() {
                p.process(&buf[..n]);
            }
        }
    });
    // The window opens at the first frame and after a second to settle.
    let t0 = Instant::now();
    while frames.load(Ordering::Relaxed) == 0 && t0.elapsed() < Duration::from_mins(1) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let start_up = t0.elapsed();
    std::thread::sleep(Duration::from_secs(1));
    let (f0, b0, t1) = (
        frames.load(Ordering::Relaxed),
        bytes.load(Ordering::Relaxed),
        Instant::now(),
    );
    std::thread::sleep(Duration::from_secs_f64(secs));
    let (f1, b1, dt) = (
        frames.load(Ordering::Relaxed),
        bytes.load(Ordering::Relaxed),
        t1.elapsed().as_secs_f64(),
    );
    let text = screen
        .lock()
        .map(|p| p.screen().contents())
        .unwrap_or_default();
    println!(
        "{:.1} frames/s counted over {dt:.1} s ({} frames, {:.0} KB/s), first frame after {:.2} s",
        (f1 - f0) as f64 / dt,
        f1 - f0,
        (b1 - b0) as f64 / dt / 1e3,
        start_up.as_secs_f64()
    );
    print_readouts(&text, child.process_id());
    done.store(true, Ordering::Relaxed);
    writer.write_all(b"q")?;
    writer.flush()?;
    let t2 = Instant::now();
    while child.try_wait()?.is_none() {
        if t2.elapsed() > Duration::from_secs(10) {
            child.kill()?;
            break;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    drop(writer);
    drop(pty.master);
    let _ = read.join();
    Ok(())
}

/// The status lines about speed, and the app's peak resident memory so far
/// (Linux).
fn print_readouts(text: &str, pid: Option<u32>) {
    let wanted = ["fps", "physics", "render", "steps/s"];
    for l in text
        .lines()
        .filter(|l| wanted.iter().any(|w| l.contains(w)))
    {
        println!("  {}", l.trim_end());
    }
    let hwm = pid
        .and_then(|pid| std::fs::read_to_string(format!("/proc/{pid}/status")).ok())
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .map(str::to_string)
        });
    if let Some(l) = hwm {
        println!("  {l}");
    }
}
