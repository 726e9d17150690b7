//! The spheres with events take their runs' ends of the step, and the
//! counters their totals, in sphere order, so the sums are the serial
//! loop's to the bit. The results are cut into blocks (one below
//! `wide.rs`'s lanes), each a run of sphere ids, that write their spheres and count
//! in parallel; the integer counts add exactly in any order, and the one
//! sum that rounds, the momentum given to the walls, is then taken over
//! the few spheres that hit one, in sphere order.
use super::cluster::Coarse;
use super::rounds::Rounds;
use crate::physics::exec::{Exec, PerBlock, for_each_block_of, work_ns};
use crate::physics::sphere::Sphere;
use crate::physics::wide::wide_pass;
use crate::physics::world::Counters;
use parking_lot::Mutex;

/// Results per block when taken in parallel.
const RESULT_BLOCK: usize = 4096;
/// Predicted nanoseconds of taking one result (docs/threading.md).
const NS_PER_RESULT: usize = 30;

/// What one block of results adds up to.
#[derive(Default)]
pub(super) struct Totals {
    pair_hits: u64,
    wall_hits: u64,
    capped: Option<Coarse>,
    /// The momenta given to the walls that are not zero, in sphere order.
    momenta: Vec<f64>,
}

/// Every sphere with events takes its run's end; the counters take their
/// totals. Returns the most severe cap among the runs.
pub(super) fn take_results(
    exec: &dyn Exec,
    rounds: &Rounds,
    spheres: &mut [Sphere],
    c: &mut Counters,
    totals: &mut PerBlock<Totals>,
) -> Option<Coarse> {
    let m = rounds.involved();
    // One block on few lanes: the same loop, on the calling thread.
    let per = if wide_pass(exec, m, RESULT_BLOCK) {
        RESULT_BLOCK
    } else {
        m.max(1)
    };
    let blocks = m.div_ceil(per);
    // The results are in sphere order: block `b`'s spheres are the ids from
    // its first result's up to the next block's first.
    let mut pieces = Vec::with_capacity(blocks);
    let (mut rest, mut base) = (spheres, 0usize);
    for b in 0..blocks {
        let end = if b + 1 == blocks {
            base + rest.len()
        } else {
            rounds.result((b + 1) * per).0.id as usize
        };
        let (mine, after) = rest.split_at_mut(end - base);
        pieces.push(Mutex::new((base, mine)));
        (rest, base) = (after, end);
    }
    totals.ensure(blocks);
    let sums = &*totals;
    for_each_block_of(exec, blocks, work_ns(m, NS_PER_RESULT), &|b| {
        let mut piece = pieces[b].lock();
        let (first, mine) = &mut *piece;
        let mut t = sums[b].lock();
        (t.pair_hits, t.wall_hits, t.capped) = (0, 0, None);
        t.momenta.clear();
        for k in b * per..((b + 1) * per).min(m) {
            let (r, cap) = rounds.result(k);
            let s = &mut mine[r.id as usize - *first];
            (s.pos, s.vel) = (r.pos, r.vel);
            // Adding zero leaves a sum of non-negative momenta as it was.
            if r.wall_momentum != 0.0 {
                t.momenta.push(r.wall_momentum);
            }
            t.pair_hits += u64::from(r.pair_hits);
            t.wall_hits += u64::from(r.wall_hits);
            t.capped = t.capped.max(cap);
        }
    });
    let mut capped = None;
    for t in &mut totals[..blocks] {
        let t = t.get_mut();
        for &p in &t.momenta {
            c.wall_momentum += p;
        }
        c.sphere_collisions += t.pair_hits;
        c.wall_collisions += t.wall_hits;
        capped = capped.max(t.capped);
    }
    capped
}
