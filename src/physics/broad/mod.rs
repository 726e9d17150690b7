//! Broad phase: which pairs can touch within a step. A hierarchy of uniform
//! grids: the first level's cell is sized for the bulk of the spheres (the
//! share of their reaches that predicts the least work, `sizing.rs`); the
//! ones that do not fit go up to a coarser level sized the same way among
//! themselves, and so on, and the last
//! handful are tested against everything. A sphere of a coarse level meets
//! the finer levels by querying their cells over its own reach, so radii or
//! speeds spread over orders of magnitude stay about linear in cost. Tiny
//! scenes use all pairs.
mod entry;
mod level;
mod pairs;
mod place;
mod sizing;

use super::exec::{Exec, PerBlock, for_each_block, for_each_chunk};
use super::sphere::Sphere;
use entry::{Ball, Entry, Source};
use glam::DVec3;
use level::{Level, WIDE};
use sizing::{cell_for, cell_of_sample};

/// At most this many spheres are tested against everything.
const ALL_PAIRS_MAX: usize = 24;
/// Fewer spheres than this are sorted into the first level on one lane.
const LANES_MIN_SPHERES: usize = 4096;
/// Spheres per parallel block while binning.
const BUILD_BLOCK: usize = 4096;
/// Planes of cells per parallel block when finding the balls on faces.
const FACE_PLANES: usize = 8;
/// The first level's cell comes from every this-many-th reach.
const SAMPLE_STRIDE: usize = 32;
/// From this many spheres on, the first level is staged as cell keys alone
/// and each record is made again where it is placed: 4 bytes a sphere held
/// instead of a 40-byte record, for a second `ball` per sphere (at 100 000
/// dilute spheres that cost about a tenth more time; at a million, none).
const KEYED_MIN: usize = 1 << 18;

/// A pair that may touch: sphere indices, `i < j` not implied.
pub type Pair = (u32, u32);
#[derive(Default)]
pub struct Grid {
    levels: Vec<Level>,
    /// The last few, tested against everything.
    top: Vec<(Ball, u32)>,
    staged: Vec<Entry>,
    /// From [`KEYED_MIN`] spheres on, in place of `staged`: the cell keys.
    keys: Vec<u32>,
    /// Per block of spheres, the widest ball among the keyed ones.
    widest: PerBlock<f64>,
    /// The box's side, as of the last build.
    size: f64,
    /// Spheres not yet placed in a level: (ball, id).
    rest: Vec<(Ball, u32)>,
    scratch: Vec<f64>,
    /// Per block of spheres, the balls too wide for the first level (found
    /// in parallel, joined in block order).
    wide: PerBlock<Vec<(Ball, u32)>>,
    slots: PerBlock<Vec<Pair>>,
    /// Per block of planes of cells, the spheres `near_faces_lanes` found.
    faces: PerBlock<Vec<u32>>,
}

/// The first level's records as cell keys and the spheres they come from.
struct Keyed<'a, T, B> {
    keys: &'a [u32],
    spheres: &'a [T],
    ball: &'a B,
}

impl<T: Sync, B: Fn(&T) -> (DVec3, f64) + Sync> Source for Keyed<'_, T, B> {
    #[inline(always)]
    fn keys(&self) -> impl DoubleEndedIterator<Item = (u32, f64)> + ExactSizeIterator {
        self.keys.iter().map(|&k| (k, 0.0))
    }
    #[inline(always)]
    fn entry(&self, i: usize) -> Entry {
        let (pos, reach) = (self.ball)(&self.spheres[i]);
        Entry {
            ball: Ball { pos, reach },
            id: i as u32,
            key: self.keys[i],
        }
    }
    fn records(&self) -> Option<&[Entry]> {
        None
    }
}

impl Grid {
    /// Bin the spheres (or any items with a ball). `ball(s)` is a centre and
    /// a reach: during the step
    /// the sphere stays inside that ball, so a pair matters only when the
    /// distance of the centres is at most the sum of the reaches. The
    /// per-sphere arithmetic of the first level runs on `exec`.
    pub fn build<T: Sync>(
        &mut self,
        spheres: &[T],
        size: f64,
        ball: impl Fn(&T) -> (DVec3, f64) + Sync,
        exec: &dyn Exec,
    ) {
        let n = spheres.len();
        self.size = size;
        self.top.clear();
        let mut depth = 0;
        if n > ALL_PAIRS_MAX {
            self.build_first_level(spheres, &ball, exec);
            depth = self.build_coarse_levels(size);
            self.top.extend_from_slice(&self.rest);
        } else {
            self.top.extend(spheres.iter().zip(0..).map(|(s, i)| {
                let (pos, reach) = ball(s);
                (Ball { pos, reach }, i)
            }));
        }
        self.levels.truncate(depth);
    }

    /// The first level, sized for the bulk; the balls too wide for it are
    /// left in `rest`.
    fn build_first_level<T: Sync>(
        &mut self,
        spheres: &[T],
        ball: &(impl Fn(&T) -> (DVec3, f64) + Sync),
        exec: &dyn Exec,
    ) {
        let n = spheres.len();
        if self.levels.is_empty() {
            self.levels.push(Level::default());
        }
        // The first level's cell comes from a sample of the reaches (a
        // function of the state only, so the grid, and the order pairs
        // come out in, never depend on history); then each sphere's
        // ball and key are made in one pass over the spheres.
        self.scratch.clear();
        self.scratch
            .extend(spheres.iter().step_by(SAMPLE_STRIDE).map(|s| ball(s).1));
        let max = self.scratch.iter().fold(0.0f64, |m, &r| m.max(r));
        let want = cell_of_sample(&mut self.scratch, max, n, self.size);
        self.levels[0].shape(self.size, want, n, true);
        self.rest.clear();
        if n >= KEYED_MIN {
            self.staged = Vec::new();
            self.build_keyed(spheres, ball, exec);
        } else if n < LANES_MIN_SPHERES || exec.lanes() <= 1 {
            self.build_staged_one_lane(spheres, ball, exec);
        } else {
            self.build_staged(spheres, ball, exec);
        }
    }

    /// The first level from staged records on one lane. Under
    /// [`LANES_MIN_SPHERES`], waking other threads costs more than the
    /// sort; the layout is the same for any number of lanes.
    fn build_staged_one_lane<T: Sync>(
        &mut self,
        spheres: &[T],
        ball: &(impl Fn(&T) -> (DVec3, f64) + Sync),
        exec: &dyn Exec,
    ) {
        self.keys = Vec::new();
        self.staged.resize(spheres.len(), Entry::default());
        let level = &mut self.levels[0];
        // One lane: the cells are counted while staging, so the table's
        // increments overlap the arithmetic of the balls and the staged
        // records are read once less.
        level.cell_start.fill(0);
        let (mut count, mut reach_max) = (0, 0.0f64);
        for ((slot, s), id) in self.staged.iter_mut().zip(spheres).zip(0..) {
            *slot = level.stage(ball(s), id, &mut self.rest);
            if slot.key != WIDE {
                level.cell_start[slot.key as usize] += 1;
                count += 1;
                // Not `f64::max`: see `fill_lanes`.
                if slot.ball.reach > reach_max {
                    reach_max = slot.ball.reach;
                }
            }
        }
        level.fill_lanes(&self.staged[..], exec, Some((count, reach_max)));
    }

    /// The first level from records staged in parallel blocks, the wide
    /// balls of each block joined in block order.
    fn build_staged<T: Sync>(
        &mut self,
        spheres: &[T],
        ball: &(impl Fn(&T) -> (DVec3, f64) + Sync),
        exec: &dyn Exec,
    ) {
        let n = spheres.len();
        self.keys = Vec::new();
        self.staged.resize(n, Entry::default());
        let blocks = n.div_ceil(BUILD_BLOCK);
        self.wide.ensure(blocks);
        let level = &self.levels[0];
        let wide = &self.wide;
        for_each_chunk(exec, &mut self.staged, BUILD_BLOCK, &|b, chunk| {
            let mut wide = wide[b].lock();
            wide.clear();
            let first = (b * BUILD_BLOCK) as u32;
            let mine = chunk.iter_mut().zip(&spheres[b * BUILD_BLOCK..]);
            for ((slot, s), id) in mine.zip(first..) {
                *slot = level.stage(ball(s), id, &mut wide);
            }
        });
        self.levels[0].fill_lanes(&self.staged[..], exec, None);
        for w in &self.wide[..blocks] {
            self.rest.extend_from_slice(&w.lock());
        }
    }

    /// Coarser levels for what did not fit the first, serially: they are
    /// few. Returns the levels in all; `rest` keeps the balls wider than
    /// any level, for the top.
    fn build_coarse_levels(&mut self, size: f64) -> usize {
        let mut depth = 1;
        while self.rest.len() > ALL_PAIRS_MAX {
            if self.levels.len() == depth {
                self.levels.push(Level::default());
            }
            let max = self.rest.iter().fold(0.0f64, |m, b| m.max(b.0.reach));
            let want = cell_for(
                self.rest.iter().map(|b| b.0.reach),
                max,
                1,
                self.rest.len(),
                size,
                &mut self.scratch,
            );
            let level = &mut self.levels[depth];
            level.shape(size, want, self.rest.len(), false);
            let placed: Vec<Entry> = self
                .rest
                .iter()
                .filter(|b| level.fits(b.0.reach))
                .map(|&(ball, id)| Entry {
                    ball,
                    id,
                    key: level.key_of(ball.pos),
                })
                .collect();
            if placed.is_empty() {
                // Balls wider than a one-cell level (the whole box) fit
                // no coarser level either: they join the top, tested
                // against everything. Without this the loop never ends.
                break;
            }
            level.fill(&placed);
            let cell = level.cell;
            self.rest.retain(|b| 2.0 * b.0.reach > cell);
            depth += 1;
        }
        depth
    }

    /// The first level of [`Grid::build`] from [`KEYED_MIN`] spheres on:
    /// each sphere's cell key is staged (and the widest ball kept) in
    /// parallel blocks, then the level sorts the spheres by key and makes
    /// each record again where it goes. The same level as from records.
    fn build_keyed<T: Sync>(
        &mut self,
        spheres: &[T],
        ball: &(impl Fn(&T) -> (DVec3, f64) + Sync),
        exec: &dyn Exec,
    ) {
        let n = spheres.len();
        let blocks = n.div_ceil(BUILD_BLOCK);
        self.keys.resize(n, 0);
        self.wide.ensure(blocks);
        self.widest.ensure(blocks);
        let level = &self.levels[0];
        let (wide, widest) = (&self.wide, &self.widest);
        for_each_chunk(exec, &mut self.keys, BUILD_BLOCK, &|b, chunk| {
            let mut wide = wide[b].lock();
            wide.clear();
            let mut reach_max = 0.0f64;
            let first = (b * BUILD_BLOCK) as u32;
            let mine = chunk.iter_mut().zip(&spheres[b * BUILD_BLOCK..]);
            for ((slot, s), id) in mine.zip(first..) {
                let e = level.stage(ball(s), id, &mut wide);
                // Not `f64::max`: see `fill_lanes`.
                if e.key != WIDE && e.ball.reach > reach_max {
                    reach_max = e.ball.reach;
                }
                *slot = e.key;
            }
            *widest[b].lock() = reach_max;
        });
        let keyed = Keyed {
            keys: &self.keys,
            spheres,
            ball,
        };
        let level = &mut self.levels[0];
        level.fill_lanes(&keyed, exec, None);
        for w in &self.widest[..blocks] {
            level.reach_max = level.reach_max.max(*w.lock());
        }
        for w in &self.wide[..blocks] {
            self.rest.extend_from_slice(&w.lock());
        }
    }

    /// Every sphere whose ball may meet a ball of radius `reach` around `p`,
    /// as `f(id, centre, reach as binned)`, the caller applying its own test.
    /// `grow`: found too are balls that have since grown up to `grow` times
    /// their level's widest (see [`Grid::widest_in_level`]); 1 for balls as
    /// binned. Swept's runs grow balls as paths turn and pick the factor.
    pub fn near(&self, p: DVec3, reach: f64, grow: f64, f: &mut impl FnMut(u32, DVec3, f64)) {
        for level in &self.levels {
            level.near(p, reach + grow * level.reach_max, &mut |j| {
                let e = &level.entries[j];
                f(e.id, e.ball.pos, e.ball.reach);
            });
        }
        for (b, id) in &self.top {
            f(*id, b.pos, b.reach);
        }
    }

    /// Every sphere whose ball reaches a face of the box the grid was built
    /// for, as `f(id)`, in no particular order. Only the cells on the faces
    /// and the last few are looked at: a ball is at most half a cell wide,
    /// so from any other cell it stays over half a cell inside.
    pub fn near_faces(&self, f: &mut impl FnMut(u32)) {
        let size = self.size;
        let out = |b: &Ball| {
            (b.pos.min_element() - b.reach <= 0.0) | (b.pos.max_element() + b.reach >= size)
        };
        for level in &self.levels {
            level.on_faces(&mut |j| {
                // The balls lie in cell order, so this test reads memory in
                // order; the caller's test, for the few that pass, does not.
                let e = &level.entries[j];
                if out(&e.ball) {
                    f(e.id);
                }
            });
        }
        for (b, id) in &self.top {
            if out(b) {
                f(*id);
            }
        }
    }

    /// [`Grid::near_faces`] on `exec`'s lanes, the spheres `keep` takes
    /// into `out` in the order `near_faces` gives them: each level's planes
    /// of cells in blocks, each block's finds joined in block order.
    pub fn near_faces_lanes(
        &mut self,
        exec: &dyn Exec,
        keep: &(dyn Fn(u32) -> bool + Sync),
        out: &mut Vec<u32>,
    ) {
        out.clear();
        let size = self.size;
        let reaches = move |b: &Ball| {
            (b.pos.min_element() - b.reach <= 0.0) | (b.pos.max_element() + b.reach >= size)
        };
        for level in &self.levels {
            let blocks = level.per_side.div_ceil(FACE_PLANES);
            self.faces.ensure(blocks);
            let faces = &self.faces;
            let take = |j: usize, found: &mut Vec<u32>| {
                let e = &level.entries[j];
                if reaches(&e.ball) && keep(e.id) {
                    found.push(e.id);
                }
            };
            for_each_block(exec, blocks, &|b| {
                let mut found = faces[b].lock();
                found.clear();
                let zs = b * FACE_PLANES..((b + 1) * FACE_PLANES).min(level.per_side);
                level.on_faces_of(zs, &mut |j| take(j, &mut found));
            });
            for f in &self.faces[..blocks] {
                out.extend_from_slice(&f.lock());
            }
        }
        for (b, id) in &self.top {
            if reaches(b) && keep(*id) {
                out.push(*id);
            }
        }
    }

    /// The widest ball of the level a ball of `reach` is binned in (infinite
    /// for the last few, which every search visits whatever their reach).
    #[must_use]
    pub fn widest_in_level(&self, reach: f64) -> f64 {
        self.levels
            .iter()
            .find(|l| l.fits(reach))
            .map_or(f64::INFINITY, |l| l.reach_max)
    }

    /// Cells per side of each level, and how many spheres each holds (the
    /// last number: tested against everything). For diagnostics.
    #[must_use]
    pub fn shape(&self) -> (Vec<(usize, usize)>, usize) {
        (
            self.levels
                .iter()
                .map(|l| (l.per_side, l.entries.len().saturating_sub(1)))
                .collect(),
            self.top.len(),
        )
    }
}

/// Calls `f(i, j)` once for every pair whose spheres touch or overlap
/// (centres within the sum of radii). Serial; for checks and placement.
pub fn for_each_near_pair(spheres: &[Sphere], size: f64, mut f: impl FnMut(usize, usize)) {
    let mut grid = Grid::default();
    grid.build(spheres, size, |s| (s.pos, s.radius), &super::exec::Serial);
    let mut out = Vec::new();
    grid.pairs(&super::exec::Serial, &|_: u32, _: u32| true, &mut out);
    for (i, j) in out {
        f(i as usize, j as usize);
    }
}
