//! How independent `exact`'s next events are (issue 48): the evidence a
//! parallel event loop that commits in serial order would stand on.
//!
//! Runs `exact` on a melted lattice (N spheres at a packing), records every
//! sphere–sphere contact in the serial order, and cuts that order into
//! rounds of K events. Per round it counts: the prefix of events whose
//! spheres are pairwise disjoint (what a speculation that knew the right K
//! events could commit before the first rollback, so an upper bound on
//! events committed per round at K lanes); the events whose spheres no
//! earlier event of the round touched (the "disjoint" count); and
//! the prefix whose contacts are also more than `4σ` apart (an earlier
//! event there may change a later one's partners: the invalidation range).
//! Then, for 2, 8 and 16 slabs along x, the share of contacts within `σ`
//! of a slab boundary (a spatial domain's boundary events). Wall events
//! are not seen (the observer reports sphere–sphere contacts only).
//!
//! `cargo run --release --example event_independence -- 100000 0.1 200000`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap fails the run
#![allow(clippy::cast_precision_loss)] // counts far below 2^52
use ballpit::physics::exact::Contact;
use ballpit::physics::{Model, Serial};
use ballpit::scene::lattice::melted;
use glam::DVec3;
use std::sync::{Arc, Mutex};

/// One contact: the two spheres and where it happened.
#[derive(Clone, Copy)]
struct Seen {
    i: usize,
    j: usize,
    at: DVec3,
}

/// Mean per round of K: (disjoint prefix, disjoint events, far prefix).
fn rounds(seen: &[Seen], k: usize, far: f64) -> (f64, f64, f64) {
    let (mut prefix, mut disjoint, mut far_prefix, mut n) = (0usize, 0usize, 0usize, 0usize);
    let mut touched: Vec<usize> = Vec::with_capacity(2 * k);
    for round in seen.chunks_exact(k) {
        touched.clear();
        let mut still = true;
        let mut still_far = true;
        for (e, s) in round.iter().enumerate() {
            let free = !touched.contains(&s.i) && !touched.contains(&s.j);
            let apart = round[..e].iter().all(|o| o.at.distance(s.at) > far);
            if free {
                disjoint += 1;
            }
            still &= free;
            still_far &= free && apart;
            prefix += usize::from(still);
            far_prefix += usize::from(still_far);
            touched.extend([s.i, s.j]);
        }
        n += 1;
    }
    let n = n.max(1) as f64;
    (
        prefix as f64 / n,
        disjoint as f64 / n,
        far_prefix as f64 / n,
    )
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().map_or(10_000, |a| a.parse().expect("count"));
    let packing: f64 = args.get(1).map_or(0.1, |a| a.parse().expect("packing"));
    let target: usize = args.get(2).map_or(200_000, |a| a.parse().expect("events"));
    let (mut w, mut m, dt) = melted(n, packing, 20_000.0).expect("scene");
    let sigma = 2.0 * w.spheres[0].radius;
    let log: Arc<Mutex<Vec<Seen>>> = Arc::new(Mutex::new(Vec::with_capacity(target)));
    let sink = log.clone();
    m.set_observer(Some(Box::new(move |c: &Contact| {
        sink.lock().unwrap().push(Seen {
            i: c.i,
            j: c.j,
            at: (c.pos_i + c.pos_j) * 0.5,
        });
    })));
    let e0 = w.kinetic_energy();
    while log.lock().unwrap().len() < target {
        m.advance(&mut w, dt, 1, &Serial);
    }
    let drift = (w.kinetic_energy() - e0).abs() / e0;
    let seen = log.lock().unwrap().clone();
    println!(
        "N={n} packing={packing}: {} contacts; energy drift {drift:.1e}, overlap {:.1e}, escaped {}",
        seen.len(),
        w.max_overlap_rel(),
        w.escaped()
    );
    println!("K,disjoint_prefix,disjoint_events,far_prefix");
    for k in [2, 4, 8, 16, 32, 64, 256, 1024] {
        let (p, d, f) = rounds(&seen, k, 4.0 * sigma);
        println!("{k},{p:.2},{d:.2},{f:.2}");
    }
    let side = w.size;
    for slabs in [2usize, 8, 16] {
        let width = side / slabs as f64;
        let near = seen
            .iter()
            .filter(|s| {
                let x = s.at.x.rem_euclid(width);
                (x < sigma || width - x < sigma) && s.at.x > sigma && s.at.x < side - sigma
            })
            .count();
        println!(
            "slabs {slabs}: {:.1} % of contacts within σ of a boundary",
            100.0 * near as f64 / seen.len() as f64
        );
    }
}
