//! Flat out (`--tick max`, key x) in the real binary in a real pty: where
//! the physics CPU goes in each mode, read per thread from /proc, and the
//! steps/s readout. The default tests assert only shares among the
//! process's own threads, which a loaded runner cannot break; the steps/s
//! rate is a wall-clock figure, in an ignored test of the timing step.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::pty::{App, start};
use std::collections::HashMap;
use std::thread;
use std::time::Duration;

/// CPU ticks (user + system) of each of the app's threads, by name; the
/// pool threads' names are kept whole (`pool-0`, `pool-1`).
fn thread_ticks(app: &App) -> HashMap<String, u64> {
    let pid = app.child.process_id().expect("pid");
    let mut out = HashMap::new();
    for e in std::fs::read_dir(format!("/proc/{pid}/task"))
        .unwrap()
        .flatten()
    {
        let Ok(stat) = std::fs::read_to_string(e.path().join("stat")) else {
            continue;
        };
        let (Some(a), Some(b)) = (stat.find('('), stat.rfind(')')) else {
            continue;
        };
        let name = stat[a + 1..b].to_string();
        let f: Vec<&str> = stat[b + 2..].split_whitespace().collect();
        let ticks = f[11].parse::<u64>().unwrap() + f[12].parse::<u64>().unwrap();
        *out.entry(name).or_insert(0) += ticks;
    }
    out
}

/// Each thread's share of the process's CPU over `secs`.
fn shares(app: &App, secs: f64) -> HashMap<String, f64> {
    let a = thread_ticks(app);
    thread::sleep(Duration::from_secs_f64(secs));
    let b = thread_ticks(app);
    let d: HashMap<String, u64> = b
        .iter()
        .map(|(k, v)| (k.clone(), v - a.get(k).copied().unwrap_or(0)))
        .collect();
    let total = d.values().sum::<u64>().max(1) as f64;
    d.into_iter().map(|(k, v)| (k, v as f64 / total)).collect()
}

fn share_of(s: &HashMap<String, f64>, pred: impl Fn(&str) -> bool) -> f64 {
    s.iter().filter(|(k, _)| pred(k)).map(|(_, v)| v).sum()
}

/// The steps/s figure on screen (full form: the first word after the label).
fn steps_per_second(screen: &str) -> Option<f64> {
    screen.lines().find_map(|l| {
        let i = l.find("steps/s ")? + "steps/s ".len();
        l[i..].split_whitespace().next()?.parse().ok()
    })
}

/// The steps/s readout follows the work: flat out runs many steps a frame.
/// A rate over wall time, so it needs the CPU the app asks for.
#[test]
#[ignore = "wall-clock bound: .ci/run runs it in its timing step (cargo test --release -- --ignored), retried once"]
fn flat_out_runs_many_more_steps_a_second_than_tick_1() {
    let mut app = start(&["--count", "1000"], None);
    app.wait_for("the readouts", 20.0, |s| s.contains("steps/s"));
    // Tick 1: about fps steps a second.
    thread::sleep(Duration::from_millis(2500));
    let ticked = steps_per_second(&app.text()).expect("steps/s on screen");
    app.send("x");
    app.wait_for("flat out", 5.0, |s| s.contains("flat out"));
    thread::sleep(Duration::from_millis(2500));
    let flat = steps_per_second(&app.text()).expect("steps/s on screen");
    assert!(
        flat > 5.0 * ticked,
        "flat out {flat} steps/s, tick 1 {ticked}"
    );
    app.quit();
}

#[test]
fn flat_out_moves_the_physics_cpu_to_the_mode_that_runs_it() {
    let mut app = start(&["--count", "1000"], None);
    app.wait_for("the readouts", 20.0, |s| s.contains("steps/s"));
    app.send("x");
    app.wait_for("flat out", 5.0, |s| s.contains("flat out"));
    thread::sleep(Duration::from_millis(2500));
    let off = shares(&app, 2.0);
    assert!(
        share_of(&off, |n| n == "ballpit") > 0.8,
        "off: main should hold the CPU: {off:?}"
    );
    app.send("t");
    app.wait_for("worker", 5.0, |s| s.contains("worker  "));
    thread::sleep(Duration::from_millis(1500));
    let worker = shares(&app, 2.0);
    let physics = share_of(&worker, |n| n == "physics");
    let main = share_of(&worker, |n| n == "ballpit");
    assert!(
        physics > 0.5 && physics > 2.0 * main,
        "worker: physics should hold most of the CPU: {worker:?}"
    );
    app.send("d");
    app.wait_for("pool", 5.0, |s| s.contains("pool  "));
    thread::sleep(Duration::from_millis(1500));
    let pool = shares(&app, 2.0);
    let pooled = share_of(&pool, |n| n.starts_with("pool-"));
    assert!(
        pooled > 0.5 && pooled > share_of(&pool, |n| n == "physics"),
        "pool: the pool threads should hold most of the CPU: {pool:?}"
    );
    // The comparison with off stays on screen.
    let screen = app.text();
    assert!(
        screen.contains("worker ") && screen.contains("x off"),
        "{screen}"
    );
    app.quit();
}

#[test]
fn a_huge_tick_shows_a_frame_at_once_and_quits() {
    let mut app = start(&["--tick", "1000000"], None);
    // The first frame is drawn before the first frame's physics.
    app.wait_for("a first frame", 10.0, |s| s.contains("steps/s"));
    app.send("q");
    // `q` is read once the frame on this thread is done (seconds).
    let st = app.wait_exit(120.0).expect("q ends the app");
    assert!(st.success(), "{st:?}");
}

#[test]
fn a_long_threaded_frame_says_it_is_under_way() {
    let app = start(&["--tick", "1000000", "--threading", "worker"], None);
    let screen = app.wait_for("a long frame", 20.0, |s| s.contains("under way"));
    assert!(screen.contains("steps,"), "{screen}");
    app.quit();
}
