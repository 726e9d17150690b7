//! The phase breakdown `cargo bench --bench engine` prints first: what a
//! `swept` step spends where, and the share of it that can run in parallel.
use super::{DT, cpu_now, settings};
use ballpit::engine::{Engine, Threading};
use ballpit::physics::broad::Grid;
use ballpit::physics::contact::pair_toi;
use ballpit::physics::{Exec, ModelKind, Serial, Sphere, World};
use glam::DVec3;
use parking_lot::Mutex;

/// Runs every lane on the calling thread, one after another, and adds up
/// the CPU time of those sections: what a pool would share out.
struct SerialLanes {
    spent: Mutex<f64>,
}

impl Exec for SerialLanes {
    fn lanes(&self) -> usize {
        2
    }
    fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
        let t0 = cpu_now();
        f(0);
        f(1);
        *self.spent.lock() += cpu_now() - t0;
    }
    fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
        let t0 = cpu_now();
        a();
        b();
        *self.spent.lock() += cpu_now() - t0;
    }
}

/// Functional decomposition on the calling thread, timing each job: how
/// well `split`'s two threads could be balanced.
#[derive(Default)]
struct SerialJoin {
    spent: Mutex<(f64, f64)>,
}

impl Exec for SerialJoin {
    fn lanes(&self) -> usize {
        1
    }
    fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
        f(0);
    }
    fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
        let t0 = cpu_now();
        a();
        let t1 = cpu_now();
        b();
        let t2 = cpu_now();
        let mut s = self.spent.lock();
        s.0 += t1 - t0;
        s.1 += t2 - t1;
    }
    fn functional(&self) -> bool {
        true
    }
}

/// The ball a sphere's path stays in during a step (as `swept` uses it).
fn path_ball(s: &Sphere) -> (DVec3, f64) {
    (
        s.pos + s.vel * (0.5 * DT),
        (s.radius + s.vel.length() * 0.5 * DT) * (1.0 + 1e-9),
    )
}

/// The pairs a `swept` step foresees meeting and the clusters they link
/// spheres into: the contact events of one cluster never touch another's.
fn clusters(w: &World) -> (usize, usize, usize, usize) {
    let mut grid = Grid::default();
    grid.build(&w.spheres, w.size, path_ball, &Serial);
    let mut pairs = Vec::new();
    let sp = &w.spheres;
    let meets = |i: u32, j: u32| {
        let (a, b) = (&sp[i as usize], &sp[j as usize]);
        pair_toi(a.pos - b.pos, a.vel - b.vel, a.radius + b.radius).is_some_and(|t| t <= DT)
    };
    grid.pairs(&Serial, &meets, &mut pairs);
    let mut parent: Vec<usize> = (0..w.spheres.len()).collect();
    #[allow(clippy::items_after_statements)] // next to its one use
    fn root(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    let mut involved = vec![false; w.spheres.len()];
    for &(i, j) in &pairs {
        let (a, b) = (root(&mut parent, i as usize), root(&mut parent, j as usize));
        parent[a.max(b)] = a.min(b);
        involved[i as usize] = true;
        involved[j as usize] = true;
    }
    let mut size = vec![0usize; w.spheres.len()];
    for (i, _) in involved.iter().enumerate().filter(|&(_, &x)| x) {
        let r = root(&mut parent, i);
        size[r] += 1;
    }
    let count = size.iter().filter(|&&s| s > 0).count();
    let largest = size.iter().copied().max().unwrap_or(0);
    let inv = involved.iter().filter(|&&x| x).count();
    (pairs.len(), inv, count, largest)
}

/// Where a `swept` step's CPU time goes: the sections the model hands its
/// executor (what a pool can share) and the serial rest.
pub(super) fn phases(label: &str, world: &World) {
    let steps = 10;
    let mut w = world.clone();
    let mut model = ModelKind::Swept.build();
    model.advance(&mut w, DT, 2, &Serial);
    let lanes = SerialLanes {
        spent: Mutex::new(0.0),
    };
    // One thread runs the plain serial loop; lanes run the events in
    // clusters, which costs a little more in all.
    let mut off = w.clone();
    let t0 = cpu_now();
    model.advance(&mut off, DT, steps, &Serial);
    let alone = (cpu_now() - t0) / steps as f64;
    let t0 = cpu_now();
    model.advance(&mut w, DT, steps, &lanes);
    let total = (cpu_now() - t0) / steps as f64;
    let par = *lanes.spent.lock() / steps as f64;
    // The grid build alone, on the same spheres: its serial share.
    let mut grid = Grid::default();
    let build_lanes = SerialLanes {
        spent: Mutex::new(0.0),
    };
    let t0 = cpu_now();
    for _ in 0..steps {
        grid.build(&w.spheres, w.size, path_ball, &build_lanes);
    }
    let build = (cpu_now() - t0 - *build_lanes.spent.lock()) / steps as f64;
    let (pairs, involved, count, largest) = clusters(&w);
    let join = SerialJoin::default();
    model.advance(&mut w.clone(), DT, steps, &join);
    let (pair_job, wall_job) = *join.spent.lock();
    // What the engine adds per frame: the snapshot (views, energy, overlap;
    // `swept` takes the overlap from the next step's detection, which that
    // step then reuses), measured as a frame of one step less the step.
    let mut e = Engine::new(w.clone(), settings(Threading::Off, 1, 1)).unwrap();
    let t0 = cpu_now();
    for _ in 0..steps {
        e.start_frame().unwrap();
        e.finish_frame().unwrap();
    }
    let framed = cpu_now() - t0;
    let mut bare = ModelKind::Swept.build();
    let t0 = cpu_now();
    bare.advance(&mut w.clone(), DT, steps, &Serial);
    let snapshot = (framed - (cpu_now() - t0)) / steps as f64;
    eprintln!(
        "phases {label}: CPU per step on one thread {:.1} ms; with lanes {:.1} ms = shareable \
         sections (grid binning, pair search, wall search, contact events in clusters, flight) \
         {:.1} ms + serial {:.1} ms (of which grid build {:.1} ms) => Amdahl bound for 2 \
         threads {:.2}x; {pairs} pairs meeting, {involved} of {} spheres in {count} clusters, \
         largest {largest}; the engine's snapshot {:.1} ms per frame; split's jobs per step: \
         sphere-sphere {:.2} ms beside sphere-wall {:.2} ms",
        alone * 1e3,
        total * 1e3,
        par * 1e3,
        (total - par) * 1e3,
        build * 1e3,
        alone / (total - par + par / 2.0),
        w.spheres.len(),
        snapshot * 1e3,
        pair_job / steps as f64 * 1e3,
        wall_job / steps as f64 * 1e3,
    );
}
