//! The detection half of a step, shared by the per-step models: which pairs
//! the grid finds (sphere–sphere work) and which spheres a predicate picks
//! for wall handling (sphere–wall work). On a functional executor (`split`)
//! the two run side by side; otherwise each is cut into blocks over the
//! lanes (`pool`). Either way the results are the same bits.
use super::broad::{Grid, Pair};
use super::exec::{Exec, PerBlock, Serial, for_each_block_of, work_ns};
use super::sphere::Sphere;
use glam::DVec3;
use parking_lot::Mutex;

/// Spheres per parallel block; fixed so results never depend on the number
/// of threads.
pub(crate) const SPHERE_BLOCK: usize = 2048;
/// Predicted nanoseconds of a sphere's test against the walls
/// (docs/threading.md).
const NS_PER_WALL_TEST: usize = 1;

/// Where detection leaves its answers, kept between steps to reuse memory.
#[derive(Default)]
pub(crate) struct Detection {
    pub grid: Grid,
    /// Pairs the grid found and `keep` accepted, in a fixed order.
    pub pairs: Vec<Pair>,
    /// Per block of spheres, in order, the ones `wall` picked.
    pub walls: PerBlock<Vec<u32>>,
    /// Stop finding pairs once there are more than this (a step's work
    /// budget, see `swept`); `None` finds them all.
    pub pair_limit: Option<usize>,
    /// Set by `run` when the pairs numbered more than `pair_limit`: then
    /// `pairs` holds only some of them.
    pub overran: bool,
}

impl Detection {
    pub fn run<B, K, W>(
        &mut self,
        exec: &dyn Exec,
        spheres: &[Sphere],
        size: f64,
        ball: B,
        keep: &K,
        wall: &W,
    ) where
        B: Fn(&Sphere) -> (DVec3, f64) + Sync,
        K: Fn(u32, u32) -> bool + Sync,
        W: Fn(&Sphere) -> bool + Sync,
    {
        let n = spheres.len();
        let blocks = n.div_ceil(SPHERE_BLOCK);
        self.walls.ensure(blocks);
        self.walls.truncate(blocks);
        let slots = &self.walls;
        let limit = self.pair_limit;
        let find_walls = |exec: &dyn Exec| {
            for_each_block_of(exec, blocks, work_ns(n, NS_PER_WALL_TEST), &|b| {
                let mut v = slots[b].lock();
                v.clear();
                let (start, end) = (b * SPHERE_BLOCK, ((b + 1) * SPHERE_BLOCK).min(n));
                let near_walls = (start..end).filter(|&i| wall(&spheres[i]));
                v.extend(near_walls.map(|i| i as u32));
            });
        };
        if exec.functional() {
            let pair_job = Mutex::new((&mut self.grid, &mut self.pairs, true));
            exec.join(
                &|| {
                    let mut job = pair_job.lock();
                    let (grid, pairs, all) = &mut *job;
                    grid.build(spheres, size, &ball, &Serial);
                    *all = grid.pairs_within(&Serial, keep, pairs, limit);
                },
                &|| find_walls(&Serial),
            );
            self.overran = !pair_job.into_inner().2;
        } else {
            self.grid.build(spheres, size, &ball, exec);
            self.overran = !self.grid.pairs_within(exec, keep, &mut self.pairs, limit);
            find_walls(exec);
        }
    }

    /// The spheres `wall` picked, in sphere order, into `out`.
    pub fn wall_hits(&self, out: &mut Vec<u32>) {
        out.clear();
        for w in self.walls.iter() {
            out.extend_from_slice(&w.lock());
        }
    }
}
