use ballpit::physics::exact::Exact;
use ballpit::physics::exact::lattice::lattice_world;
use ballpit::physics::{Model, Serial};
use std::time::Instant;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let packing: f64 = a[1].parse().unwrap();
    let target: u64 = a[2].parse().unwrap();
    let mut w = lattice_world(4000, packing, 1.0, 42).unwrap();
    let mut m = Exact::default();
    let dt: f64 = std::env::var("DT").map(|v| v.parse().unwrap()).unwrap_or(0.01);
    while w.counters.sphere_collisions < 40_000 { m.advance(&mut w, dt, 1, &Serial); }
    let c0 = w.counters.sphere_collisions; let s0 = m.stats;
    let t = Instant::now();
    while w.counters.sphere_collisions - c0 < target { m.advance(&mut w, dt, 1, &Serial); }
    let secs = t.elapsed().as_secs_f64();
    let c = w.counters.sphere_collisions - c0;
    println!("packing {packing}: {c} coll in {secs:.3}s = {:.3} M/s; stats {:?} (start {:?}) steps {}", c as f64/secs/1e6, m.stats, s0, (w.time/dt) as u64);
}
