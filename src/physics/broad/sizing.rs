//! How wide a level's cells are. A cell is twice the reach of the balls it
//! is sized for; the wider ones go up a level. Which share of the balls a
//! level is sized for is chosen by the work it predicts: a cell's pair
//! tests grow with its volume, so a few wide balls are cheaper a level up
//! than in every cell, but each of them then looks through the finer
//! level's cells. A function of a sample of the reaches only, so the grid,
//! and the order pairs come out in, never depend on history.

/// The shares of the balls a level may be sized for, widest first (the
/// first wins a tie).
const SHARES: [usize; 4] = [98, 90, 75, 50];
/// Cells a same-level pair search looks through a ball: its own and the
/// forward half of its 26 neighbours.
const WINDOW: f64 = 13.5;
/// A sample whose 98th percentile reach is within this factor of its
/// median is sized for the 98th without weighing the others: their cells
/// would be nearly as wide.
const NARROW: f64 = 1.25;
/// The most reaches the shares are weighed on: enough for the 98th
/// percentile to stand apart, few enough to cost a step nothing.
const WEIGHED: usize = 256;
/// The cap the levels put on their cells: about 4 a ball.
const CELLS_PER_BALL: f64 = 4.0;

/// The cell for the reaches `reaches` (every `stride`-th is sampled) of
/// `n` balls in a box of `size`; `max` the widest reach known.
pub(super) fn cell_for(
    reaches: impl Iterator<Item = f64>,
    max: f64,
    stride: usize,
    n: usize,
    size: f64,
    scratch: &mut Vec<f64>,
) -> f64 {
    scratch.clear();
    scratch.extend(reaches.step_by(stride));
    cell_of_sample(scratch, max, n, size)
}

/// [`cell_for`] of reaches already sampled into `scratch` (reordered);
/// `max` is the widest reach known (for the first level, the sample's: a
/// ball wider than the cell then goes up a level, as any would).
pub(super) fn cell_of_sample(scratch: &mut [f64], max: f64, n: usize, size: f64) -> f64 {
    if scratch.is_empty() {
        return 2.0 * max;
    }
    let k = rank(scratch.len(), SHARES[0]);
    let q = *scratch.select_nth_unstable_by(k, f64::total_cmp).1;
    let mid = rank(scratch.len(), 50).min(k);
    let half = *scratch[..=k].select_nth_unstable_by(mid, f64::total_cmp).1;
    // Reaches within a quarter of each other: no share is much narrower,
    // and one level (or two, for the few past `q`) is the least work.
    if q <= NARROW * half {
        return 2.0 * widest(q, max);
    }
    // Weighed on at most `WEIGHED` of the sample, in place.
    let stride = scratch.len().div_ceil(WEIGHED);
    let len = scratch.len().div_ceil(stride);
    for i in 1..len {
        scratch[i] = scratch[i * stride];
    }
    let s = &mut scratch[..len];
    s.sort_unstable_by(f64::total_cmp);
    let s = &*s;
    let (mut best, mut least) = (max, f64::INFINITY);
    for share in SHARES {
        let q = s[rank(s.len(), share)];
        let q = if share == SHARES[0] {
            widest(q, max)
        } else {
            q
        };
        let work = work(s, q, n as f64, size);
        if work < least {
            (best, least) = (q, work);
        }
    }
    2.0 * best
}

/// The pair tests and cell visits predicted for a level sized for reach
/// `q` (the sample `s` sorted) and one more level for the balls wider.
fn work(s: &[f64], q: f64, n: f64, size: f64) -> f64 {
    let v = size.powi(3);
    let split = s.partition_point(|&r| r <= q);
    let m = s.len() as f64;
    let (n1, n2) = (n * split as f64 / m, n * (s.len() - split) as f64 / m);
    // A level's cells: as wide as asked, at most about 4 a ball, and at
    // most the box.
    let cell_volume =
        |c: f64, balls: f64| c.powi(3).max(v / (CELLS_PER_BALL * balls).max(1.0)).min(v);
    let same = |balls: f64, c: f64| {
        (balls * balls * WINDOW * cell_volume(c, balls) / v).min(0.5 * balls * balls)
    };
    let c1 = 2.0 * q;
    let fine = same(n1, c1);
    let wider = &s[split..];
    if wider.is_empty() {
        return fine;
    }
    let c2 = 2.0 * wider[rank(wider.len(), SHARES[0])];
    let coarse = same(n2, c2);
    // Each wider ball looks through the finer level's cells over its reach
    // and the finer level's widest: the cells visited, and the balls in them.
    let cell1 = cell_volume(c1, n1).cbrt();
    let (mut cells, mut tests) = (0.0, 0.0);
    for &r in wider {
        let side = 2.0 * (r + q) + cell1;
        cells += (side / cell1).min(size / cell1).powi(3);
        tests += side.powi(3).min(v) * n1 / v;
    }
    let per = n2 / wider.len() as f64;
    fine + coarse + per * (cells + tests)
}

/// Where the `share` percentile of `len` sorted values is.
fn rank(len: usize, share: usize) -> usize {
    (len * share / 100).min(len - 1)
}

/// The reach a level sized for the 98th percentile `q` takes: the widest
/// when it is close to the bulk, so one level holds everyone.
fn widest(q: f64, max: f64) -> f64 {
    if max <= 1.25 * q { max } else { q }
}
