//! Throughput of the exact model: sphere–sphere collisions per second on one
//! core at N = 4000, packing 0.05, 0.25 and 0.45 (lattice start, melted
//! before timing). `cargo bench --bench exact`; the accuracy figures (energy
//! drift over 10 million collisions, deepest overlap, escapes) print first.
use ballpit::physics::exact::Exact;
use ballpit::physics::{Model, Serial, World};
use ballpit::scene::lattice;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::time::{Duration, Instant};

const N: usize = 4000;

/// A melted start and a step that holds about 40 000 collisions.
fn melted(packing: f64) -> (World, Exact, f64) {
    lattice::melted(N, packing, 40_000.0).unwrap()
}

fn accuracy_report() {
    let (mut w, mut m, dt) = melted(0.25);
    let stats0 = m.stats;
    let e0 = w.kinetic_energy();
    let start = Instant::now();
    let mut max_err: f64 = 0.0;
    while w.counters.sphere_collisions < 10_000_000 {
        m.advance(&mut w, dt, 10, &Serial);
        max_err = max_err.max((w.kinetic_energy() - e0).abs() / e0);
    }
    let secs = start.elapsed().as_secs_f64();
    println!(
        "exact N={N} packing=0.25: {} collisions in {secs:.2} s ({:.3} M/s incl. sampling); \
         energy drift {:.3e} (max {:.3e}); deepest overlap {:.3e} radius; escaped {}; capped {}; \
         events: {} stale, {} walls, {} relists, {} crossings",
        w.counters.sphere_collisions,
        w.counters.sphere_collisions as f64 / secs / 1e6,
        (w.kinetic_energy() - e0).abs() / e0,
        max_err,
        w.max_overlap_rel(),
        w.escaped(),
        w.counters.capped_steps,
        m.stats.stale - stats0.stale,
        m.stats.walls - stats0.walls,
        m.stats.relists - stats0.relists,
        m.stats.crossings - stats0.crossings,
    );
}

fn throughput(c: &mut Criterion) {
    accuracy_report();
    let mut g = c.benchmark_group("exact_collisions");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    for packing in [0.05, 0.25, 0.45] {
        // Collisions per timed run, the same every time (deterministic).
        let probe = {
            let (mut w, mut m, dt) = melted(packing);
            m.advance(&mut w, dt, 5, &Serial);
            w.counters.sphere_collisions
        };
        g.throughput(Throughput::Elements(probe));
        g.bench_function(format!("n{N}_packing{packing}"), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    let (mut w, mut m, dt) = melted(packing);
                    let t = Instant::now();
                    m.advance(&mut w, dt, 5, &Serial);
                    total += t.elapsed();
                    assert_eq!(w.counters.sphere_collisions, probe);
                }
                total
            })
        });
    }
    g.finish();
}

criterion_group!(benches, throughput);
criterion_main!(benches);
