//! The grid at many spheres, where its first level is staged as cell keys
//! alone and the records are made again where they go: the pairs are those
//! a sweep along x finds, each once, and the grid is the same serial and on
//! a pool (the same pairs in the same order).
use ballpit::engine::PoolExec;
use ballpit::physics::broad::Grid;
use ballpit::physics::{Exec, Serial, Sphere};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::collections::BTreeSet;

/// 270 000 balls (past the keyed threshold, 2^18): most small, a few a
/// hundred times wider (they go up to coarser levels and the last few).
fn balls(seed: u64) -> Vec<Sphere> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..270_000)
        .map(|k| {
            let p = DVec3::new(rng.random(), rng.random(), rng.random());
            let r = if k % 4999 == 0 {
                rng.random_range(0.02..0.1)
            } else {
                rng.random_range(0.0005..0.004)
            };
            Sphere::new(p, DVec3::ZERO, r)
        })
        .collect()
}

/// Every pair whose balls meet, by sorting the balls along x and sweeping.
fn swept_pairs(s: &[Sphere]) -> BTreeSet<(u32, u32)> {
    let mut by_x: Vec<usize> = (0..s.len()).collect();
    by_x.sort_by(|&a, &b| (s[a].pos.x - s[a].radius).total_cmp(&(s[b].pos.x - s[b].radius)));
    let mut out = BTreeSet::new();
    for (k, &i) in by_x.iter().enumerate() {
        let right = s[i].pos.x + s[i].radius;
        for &j in &by_x[k + 1..] {
            if s[j].pos.x - s[j].radius > right {
                break;
            }
            let r = s[i].radius + s[j].radius;
            if s[i].pos.distance_squared(s[j].pos) <= r * r {
                out.insert((i.min(j) as u32, i.max(j) as u32));
            }
        }
    }
    out
}

fn grid_pairs(s: &[Sphere], exec: &dyn Exec) -> Vec<(u32, u32)> {
    let mut grid = Grid::default();
    grid.build(s, 1.0, |b| (b.pos, b.radius), exec);
    let (levels, top) = grid.shape();
    assert!(
        levels.len() >= 2,
        "the wide balls make a second level: {levels:?}"
    );
    assert_eq!(
        levels.iter().map(|l| l.1).sum::<usize>() + top,
        s.len(),
        "every ball is binned once"
    );
    let mut out = Vec::new();
    grid.pairs(exec, &|_: u32, _: u32| true, &mut out);
    out
}

#[test]
fn keyed_grid_finds_every_pair_once_serial_and_pooled() {
    let s = balls(11);
    let serial = grid_pairs(&s, &Serial);
    let found: BTreeSet<(u32, u32)> = serial.iter().map(|&(i, j)| (i.min(j), i.max(j))).collect();
    assert_eq!(found.len(), serial.len(), "a pair was reported twice");
    let want = swept_pairs(&s);
    assert!(want.len() > 10_000, "the scene has pairs: {}", want.len());
    assert_eq!(found, want);
    let pool = PoolExec::new(2).unwrap();
    assert_eq!(grid_pairs(&s, &pool), serial, "pool and serial differ");
}
