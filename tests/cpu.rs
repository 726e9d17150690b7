//! The CPU sampler reads threads by name and agrees with the kernel.
//! A test binary of its own, not a module of a grouped crate: the sampler
//! reads this process's threads, and tests run beside it as threads of the
//! same process would take the CPU its quarter-busy thread is measured on.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use ballpit::cpu::{Sampler, current_tid, thread_cpu_seconds, thread_cpu_seconds_of};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// A thread that spins for `busy` at the start of every `period`, and
/// sleeps until the next one: late wake-ups on a busy machine are absorbed
/// by the fixed schedule, so the duty stays `busy / period`.
fn duty_thread(name: &str, busy: Duration, period: Duration) -> (i32, Arc<AtomicBool>) {
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = std::sync::mpsc::channel();
    let flag = stop.clone();
    std::thread::Builder::new()
        .name(name.into())
        .spawn(move || {
            tx.send(current_tid().unwrap()).unwrap();
            let mut next = Instant::now();
            while !flag.load(Ordering::Relaxed) {
                let t0 = Instant::now();
                while t0.elapsed() < busy {
                    std::hint::spin_loop();
                }
                next += period;
                let now = Instant::now();
                if next > now {
                    std::thread::sleep(next - now);
                } else {
                    next = now;
                }
            }
        })
        .unwrap();
    (rx.recv().unwrap(), stop)
}

/// CPU seconds of `tid` from `/proc/self/task/TID/stat` (clock ticks).
fn stat_seconds(tid: i32) -> f64 {
    let stat = std::fs::read_to_string(format!("/proc/self/task/{tid}/stat")).unwrap();
    let rest = &stat[stat.rfind(')').unwrap() + 1..];
    let f: Vec<u64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .map(|x| x.parse().unwrap())
        .collect();
    (f[0] + f[1]) as f64 / 100.0
}

#[test]
fn sampler_reads_a_quarter_busy_thread() {
    // A quarter, not a half: a thread that sleeps three quarters of the time
    // still gets its share when the test machine is busy with other work.
    let (tid, stop) = duty_thread(
        "duty25",
        Duration::from_millis(5),
        Duration::from_millis(15),
    );
    let mut sampler = Sampler::new();
    let t0 = Instant::now();
    let (s0, w0) = (stat_seconds(tid), Instant::now());
    let mut readings = Vec::new();
    while t0.elapsed() < Duration::from_secs(5) {
        let report = sampler.sample();
        let me = report.threads.iter().find(|t| t.tid == tid).unwrap();
        assert_eq!(me.name, "duty25");
        if t0.elapsed() > Duration::from_millis(1500) {
            readings.push(me.percent);
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let truth = (stat_seconds(tid) - s0) / w0.elapsed().as_secs_f64() * 100.0;
    let report = sampler.sample().clone();
    stop.store(true, Ordering::Relaxed);
    let me = report.threads.iter().find(|t| t.tid == tid).unwrap();
    let mean = readings.iter().sum::<f64>() / readings.len() as f64;
    // The window reading tracks the duty cycle, and the kernel's own ticks.
    assert!((mean - 25.0).abs() < 10.0, "sampler read {mean:.1} %");
    assert!(
        (mean - truth).abs() < 5.0,
        "sampler {mean:.1} % vs stat {truth:.1} %"
    );
    assert!(
        readings.iter().all(|p| (p - 25.0).abs() < 15.0),
        "{readings:?}"
    );
    // One history point per second over five seconds; a quarter of five
    // seconds on the CPU.
    assert!((5..=6).contains(&me.history.len()), "{}", me.history.len());
    assert!(
        me.cpu_seconds > 0.8 && me.cpu_seconds < 1.8,
        "{}",
        me.cpu_seconds
    );
    assert!(report.cores >= 1);
    // Other processes: a reading between none and every CPU of the machine.
    let others = report.others_percent.expect("two readings of /proc/stat");
    let cpus = std::fs::read_to_string("/proc/stat")
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("cpu") && !l.starts_with("cpu "))
        .count();
    assert!(
        others >= 0.0 && others <= cpus as f64 * 100.0 + 1e-9,
        "{others}"
    );
    assert!(report.total_percent >= me.percent);
}

#[test]
fn every_thread_is_listed_by_name() {
    let (tid, stop) = duty_thread("listed", Duration::from_millis(2), Duration::from_millis(4));
    std::thread::sleep(Duration::from_millis(200));
    let all = thread_cpu_seconds();
    let mine = thread_cpu_seconds_of(tid).unwrap();
    stop.store(true, Ordering::Relaxed);
    let listed = all.iter().find(|(n, _)| n == "listed").unwrap();
    assert!(
        listed.1 > 0.01 && listed.1 <= mine,
        "{} vs {mine}",
        listed.1
    );
    // The test harness thread is there too.
    assert!(all.len() >= 2);
    let own = current_tid().unwrap();
    assert!(thread_cpu_seconds_of(own).unwrap() > 0.0);
}
