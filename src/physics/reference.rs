//! The reference `tradeoff` measures every model against, `exact` included:
//! hard spheres run from event to event by brute force, written apart from
//! the models so it shares none of their code (no cells, no lists, no
//! queue, no step; its own time of impact and its own response). After each
//! event every sphere is moved to the event's time, the spheres in it look
//! again at every other sphere and every wall, and every other sphere checks
//! them: O(N) per event, slow but plain.
use super::world::World;
use glam::DVec3;

/// What a sphere meets next.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Meets {
    Nothing,
    /// A wall across axis `k`.
    Wall(usize),
    Sphere(usize),
}

/// When (from the start of the run) and what a sphere meets next.
#[derive(Clone, Copy, Debug)]
struct Next {
    at: f64,
    meets: Meets,
}

/// Run `world` for `duration` simulated seconds, taking every contact in
/// time order; returns the number of events.
pub fn run(world: &mut World, duration: f64) -> u64 {
    let n = world.spheres.len();
    let mut next: Vec<Next> = (0..n).map(|i| predict(world, i, 0.0)).collect();
    let mut now = 0.0;
    let mut events = 0;
    loop {
        let first = (0..n)
            .filter(|&i| next[i].meets != Meets::Nothing)
            .min_by(|&a, &b| next[a].at.total_cmp(&next[b].at));
        let Some(i) = first.filter(|&i| next[i].at <= duration) else {
            fly(world, duration - now);
            break;
        };
        let at = next[i].at;
        fly(world, at - now);
        now = at;
        events += 1;
        let moved = match next[i].meets {
            Meets::Wall(k) => {
                let s = &mut world.spheres[i];
                world.counters.wall_momentum += 2.0 * s.mass * s.vel[k].abs();
                world.counters.wall_collisions += 1;
                s.vel[k] = -s.vel[k];
                [Some(i), None]
            }
            Meets::Sphere(j) => {
                bounce(world, i, j);
                world.counters.sphere_collisions += 1;
                [Some(i), Some(j)]
            }
            Meets::Nothing => [None, None],
        };
        let moved: Vec<usize> = moved.into_iter().flatten().collect();
        for (k, nk) in next.iter_mut().enumerate() {
            let involved =
                moved.contains(&k) || matches!(nk.meets, Meets::Sphere(p) if moved.contains(&p));
            if involved {
                *nk = predict(world, k, now);
                continue;
            }
            // The changed paths may now meet this sphere sooner.
            for &m in &moved {
                if let Some(t) = meet_time(world, k, m)
                    && now + t < nk.at
                {
                    *nk = Next {
                        at: now + t,
                        meets: Meets::Sphere(m),
                    };
                }
            }
        }
    }
    world.time += duration;
    events
}

/// Sphere `i`'s first wall or sphere, looking at all of them.
fn predict(world: &World, i: usize, now: f64) -> Next {
    let mut best = Next {
        at: f64::INFINITY,
        meets: Meets::Nothing,
    };
    let s = &world.spheres[i];
    for k in 0..3 {
        let (x, v) = (s.pos[k], s.vel[k]);
        let t = if v > 0.0 {
            (world.size - s.radius - x) / v
        } else if v < 0.0 {
            (s.radius - x) / v
        } else {
            continue;
        };
        if now + t.max(0.0) < best.at {
            best = Next {
                at: now + t.max(0.0),
                meets: Meets::Wall(k),
            };
        }
    }
    for j in 0..world.spheres.len() {
        if j != i
            && let Some(t) = meet_time(world, i, j)
            && now + t < best.at
        {
            best = Next {
                at: now + t,
                meets: Meets::Sphere(j),
            };
        }
    }
    best
}

/// Time until spheres `i` and `j` touch on straight paths, if they approach:
/// the smaller root of `|dp + dv t|^2 = (r_i + r_j)^2`, 0 if they already
/// overlap.
fn meet_time(world: &World, i: usize, j: usize) -> Option<f64> {
    let (a, b) = (&world.spheres[i], &world.spheres[j]);
    let dp = b.pos - a.pos;
    let dv = b.vel - a.vel;
    let approach = dp.dot(dv);
    if approach >= 0.0 {
        return None;
    }
    let sigma = a.radius + b.radius;
    let gap = dp.dot(dp) - sigma * sigma;
    if gap <= 0.0 {
        return Some(0.0);
    }
    let speed2 = dv.dot(dv);
    let disc = approach * approach - speed2 * gap;
    (disc >= 0.0).then(|| ((-approach - disc.sqrt()) / speed2).max(0.0))
}

/// Elastic response along the line of centres.
fn bounce(world: &mut World, i: usize, j: usize) {
    let (a, b) = (world.spheres[i], world.spheres[j]);
    let normal: DVec3 = (b.pos - a.pos).normalize();
    let closing = (a.vel - b.vel).dot(normal);
    let impulse = 2.0 * closing / (a.mass + b.mass);
    world.spheres[i].vel -= impulse * b.mass * normal;
    world.spheres[j].vel += impulse * a.mass * normal;
}

fn fly(world: &mut World, t: f64) {
    for s in &mut world.spheres {
        s.pos += s.vel * t;
    }
}
