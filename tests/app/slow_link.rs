//! Issue 16: the real binary over an emulated slow link (tests/common/link.rs):
//! keys reach the screen in a fraction of a second, `q` quits at once, and a
//! terminal that never answers queries is driven as fast as before. The
//! latency table over several links is `examples/slow_link.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::link::{Link, Spec, readout, style_key_latencies, summary};
use portable_pty::CommandBuilder;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// A stand-in app of known behaviour: after a key it writes 8000 bytes, a
/// marker and a status request, then echoes what it reads, visibly (`cat -v`).
fn stand_in() -> CommandBuilder {
    let mut cmd = CommandBuilder::new("sh");
    cmd.args([
        "-c",
        "stty raw -echo; printf 'ready\\r\\n'; dd bs=1 count=1 >/dev/null 2>&1; \
         head -c 8000 /dev/zero | tr '\\0' x; printf '\\r\\nEND\\033[5n'; exec cat -v",
    ]);
    cmd
}

#[test]
#[ignore = "wall-clock bound: .ci/run runs it in its timing step (cargo test --release -- --ignored), retried once"]
fn the_harness_delivers_at_its_rate_and_delay_and_answers_in_order() {
    for answers in [true, false] {
        let mut spec = Spec::new(Some(16_000.0), 50);
        spec.answers = answers;
        let link = Link::start(stand_in(), spec);
        link.wait_for(5.0, |s| s.contains("ready")).expect("ready");
        // Up 50 ms, 8000 bytes at 16 KB/s (500 ms), down 50 ms.
        let t0 = link.send(b"g");
        let t1 = link.wait_for(5.0, |s| s.contains("END")).expect("END");
        let bulk = ms(t1 - t0);
        assert!(
            (560.0..=800.0).contains(&bulk),
            "8000 bytes took {bulk:.0} ms"
        );
        // The answer follows the bytes before the request: up 50, down 50.
        let t2 = link.wait_for(0.6, |s| s.contains("^[[0n"));
        if answers {
            let t2 = t2.expect("the status answer echoed");
            let rt = ms(t2 - t1);
            assert!((95.0..=250.0).contains(&rt), "answer after {rt:.0} ms");
            assert_eq!(link.answered.load(Ordering::Relaxed), 1);
        } else {
            assert!(t2.is_none(), "a terminal told not to answer answered");
            assert_eq!(link.answered.load(Ordering::Relaxed), 0);
        }
        // A key echoed: one round trip.
        let t3 = link.send(b"k");
        let t4 = link
            .wait_for(2.0, |s| s.lines().any(|l| l.contains('k')))
            .expect("echo");
        let echo = ms(t4 - t3);
        assert!((98.0..=250.0).contains(&echo), "echo after {echo:.0} ms");
    }
}

fn ballpit() -> CommandBuilder {
    CommandBuilder::new(env!("CARGO_BIN_EXE_ballpit"))
}

#[test]
#[ignore = "wall-clock bound: .ci/run runs it in its timing step (cargo test --release -- --ignored), retried once"]
fn keys_reach_the_screen_in_a_fraction_of_a_second_over_16_kbs() {
    let mut link = Link::start(ballpit(), Spec::new(Some(16_000.0), 50));
    let lat = style_key_latencies(
        &link,
        8,
        0x5eed,
        Duration::from_millis(300),
        Duration::from_millis(500),
    );
    let (median, worst) = summary(&lat);
    eprintln!("16 KB/s, 50 ms: median {median:?}, worst {worst:?}: {lat:?}");
    // Issue 16's targets (measured: about half of them, see the commit).
    assert!(ms(median) <= 300.0, "median {median:?} of {lat:?}");
    assert!(ms(worst) <= 600.0, "worst {worst:?} of {lat:?}");
    // The link readout says what the app measured.
    let s = link.text();
    let out = readout(&s, "output").unwrap_or_default();
    assert!(out.contains("KB/s"), "{s}");
    // Frames are cheaper (no colours) on a link this slow.
    assert!(out.contains("mono"), "{s}");
    // `q` ends the app promptly, the link notwithstanding.
    let t = link.send(b"q");
    let st = link.wait_exit(2.0).expect("q ends the app");
    assert!(st.success(), "{st:?}");
    assert!(ms(t.elapsed()) <= 550.0, "q took {:?}", t.elapsed());
}

#[test]
#[ignore = "wall-clock bound: .ci/run runs it in its timing step (cargo test --release -- --ignored), retried once"]
fn a_terminal_that_never_answers_runs_as_fast_as_before() {
    let mut spec = Spec::new(None, 0);
    spec.answers = false;
    let mut link = Link::start(ballpit(), spec);
    let t0 = Instant::now();
    link.wait_for(5.0, |s| s.contains("threading"))
        .expect("the first frame");
    // The probe waits at most 200 ms; the first frame follows it.
    assert!(t0.elapsed() < Duration::from_secs(3), "{:?}", t0.elapsed());
    let lat = style_key_latencies(&link, 3, 7, Duration::from_millis(50), Duration::ZERO);
    assert!(lat.iter().all(|l| ms(*l) < 200.0), "{lat:?}");
    // Once a sample of a full second exists: the frame rate is the target.
    let s = link
        .wait_for(4.0, |s| {
            readout(s, "fps")
                .and_then(|v| v.split_whitespace().next())
                .and_then(|v| v.parse::<f64>().ok())
                .is_some_and(|f| f >= 20.0)
        })
        .map(|_| link.text());
    assert!(s.is_some(), "fps stayed low:\n{}", link.text());
    let s = link.text();
    assert!(
        readout(&s, "output")
            .unwrap_or_default()
            .contains("no answers"),
        "{s}"
    );
    link.send(b"q");
    assert!(link.wait_exit(2.0).expect("q ends the app").success());
}
