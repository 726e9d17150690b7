//! Key-to-screen latency of the real binary over an emulated slow link
//! (issue 16). Run `cargo build --release` first, then
//! `cargo run --release --example slow_link -- [KEYS] [BIN] [ONLY]`
//! (ONLY: run just the links whose name contains it; `NO_COLOR` is passed on).
//! Prints, per link, the median and worst latency of KEYS presses of `v`
//! at random moments, the frames per second shown by the app, and the
//! bytes per second and per frame the screen received.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap fails the run
#[path = "../tests/common/child.rs"]
mod child;
#[path = "../tests/common/link.rs"]
mod link;

use link::{Link, Spec, readout, style_key_latencies, summary};
use portable_pty::CommandBuilder;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let keys: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(8);
    let bin = args
        .get(2)
        .cloned()
        .unwrap_or_else(|| "target/release/ballpit".into());
    let bin = std::fs::canonicalize(&bin).expect("the ballpit binary (cargo build --release)");
    println!(
        "| link (rate, delay each way) | median | worst of {keys} | fps shown | KB/s to screen | bytes/frame |"
    );
    println!("|---|---:|---:|---:|---:|---:|");
    let links = [
        ("unlimited, 0 ms", None, 0, true),
        ("unlimited, 50 ms", None, 50, true),
        ("64 KB/s, 50 ms", Some(64_000.0), 50, true),
        ("32 KB/s, 50 ms", Some(32_000.0), 50, true),
        ("16 KB/s, 50 ms", Some(16_000.0), 50, true),
        ("unlimited, no answers", None, 0, false),
    ];
    let only = args.get(3).cloned().unwrap_or_default();
    for (name, rate, delay, answers) in links {
        if !name.contains(only.as_str()) {
            continue;
        }
        let mut spec = Spec::new(rate, delay);
        spec.answers = answers;
        let mut cmd = CommandBuilder::new(&bin);
        if std::env::var_os("NO_COLOR").is_some() {
            cmd.env("NO_COLOR", "1");
        }
        let mut link = Link::start(cmd, spec);
        let lat = style_key_latencies(
            &link,
            keys,
            0x16,
            Duration::from_millis(400),
            Duration::from_millis(600),
        );
        let (median, worst) = summary(&lat);
        let each: Vec<u128> = lat.iter().map(std::time::Duration::as_millis).collect();
        eprintln!("{name}: each key, ms: {each:?}");
        // Throughput and frame rate over the next 3 s.
        let b0 = link.delivered.load(Ordering::Relaxed);
        let t0 = Instant::now();
        std::thread::sleep(Duration::from_secs(3));
        let bps = (link.delivered.load(Ordering::Relaxed) - b0) as f64 / t0.elapsed().as_secs_f64();
        let text = link.text();
        let fps: f64 = readout(&text, "fps")
            .and_then(|v| v.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .unwrap_or(f64::NAN);
        let t_quit = link.send(b"q");
        let st = link.wait_exit(5.0);
        let quit = t_quit.elapsed();
        println!(
            "| {name} | {:.0} ms | {:.0} ms | {fps:.1} | {:.1} | {:.0} |   (q: exit {:?} after {:.0} ms)",
            median.as_secs_f64() * 1e3,
            worst.as_secs_f64() * 1e3,
            bps / 1e3,
            bps / fps,
            st.map(|s| s.success()),
            quit.as_secs_f64() * 1e3
        );
    }
}
