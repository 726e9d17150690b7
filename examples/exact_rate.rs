//! The exact model on the benchmark's scene (N = 4000, lattice start,
//! melted), run for a fixed span: a deterministic target for instruction
//! counts (`valgrind --tool=callgrind --toggle-collect='*run_until*'`
//! counts only the event loop; divide by the collisions printed).
//!
//! `cargo run --release --example exact_rate -- 0.25 400000`
use ballpit::physics::{Model, Serial};
use ballpit::scene::lattice::melted;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let packing: f64 = args.first().map_or(0.25, |a| a.parse().expect("packing"));
    let target: u64 = args
        .get(1)
        .map_or(400_000, |a| a.parse().expect("collisions"));
    // Steps of about 40 000 collisions, as in `benches/exact.rs` (a long
    // step could hit the event cap).
    let (mut w, mut m, dt) = melted(4000, packing, 40_000.0).expect("scene");
    let steps = target.div_ceil(40_000);
    let (c0, s0) = (w.counters.sphere_collisions, m.stats);
    let start = Instant::now();
    m.advance(&mut w, dt, steps, &Serial);
    let secs = start.elapsed().as_secs_f64();
    let c = w.counters.sphere_collisions - c0;
    let s = m.stats;
    println!(
        "packing={packing}: {c} collisions in {secs:.3} s ({:.3} M/s); per collision: {:.3} stale, \
         {:.3} walls, {:.3} crossings, {:.3} relists; overlap {:.2e}, escaped {}, capped {}",
        c as f64 / secs / 1e6,
        (s.stale - s0.stale) as f64 / c as f64,
        (s.walls - s0.walls) as f64 / c as f64,
        (s.crossings - s0.crossings) as f64 / c as f64,
        (s.relists - s0.relists) as f64 / c as f64,
        w.max_overlap_rel(),
        w.escaped(),
        w.counters.capped_steps,
    );
}
