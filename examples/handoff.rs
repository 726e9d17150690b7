//! What one parallel section costs the pool when it has nothing to do: an
//! empty `for_each_lane` on two threads, called from outside the pool (as
//! the physics thread did) and from inside it (as a frame now runs), with
//! a little serial work between sections as a step has.
//!
//! `cargo run --release --example handoff`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap fails the run
use ballpit::engine::PoolExec;
use ballpit::physics::Exec;
use std::hint::black_box;
use std::time::Instant;

fn serial_work(n: u64) -> u64 {
    (0..n).fold(1u64, |a, x| {
        black_box(a.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(x))
    })
}

fn main() {
    let pool = PoolExec::new(2).expect("pool");
    let sections = 20_000;
    for gap in [0u64, 2_000, 20_000] {
        let run = |exec: &dyn Exec| {
            let t0 = Instant::now();
            for _ in 0..sections {
                exec.for_each_lane(&|lane| {
                    black_box(lane);
                });
                black_box(serial_work(gap));
            }
            t0.elapsed().as_secs_f64()
        };
        let alone = {
            let t0 = Instant::now();
            for _ in 0..sections {
                black_box(serial_work(gap));
            }
            t0.elapsed().as_secs_f64()
        };
        let outside = run(&pool);
        let mut inside = 0.0;
        pool.host(&mut || inside = run(&pool));
        let per = |t: f64| (t - alone) / sections as f64 * 1e6;
        println!(
            "serial work between sections {:>6.1} us: a section costs {:.1} us from outside the pool, {:.1} us from inside",
            alone / sections as f64 * 1e6,
            per(outside),
            per(inside)
        );
    }
}
