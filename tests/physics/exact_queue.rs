//! The exact model's event queue, the eight-way tournament, must pop in the
//! order its contract gives (earliest time, `-0` tied with `+0`, ties by
//! lower sphere index), the order that makes runs reproducible. A proptest
//! drives it and a scan of every sphere's time with the same operations
//! and compares every peek. (The binary tournament and the calendar it was
//! once held to alike are deleted: docs/perf-log.md, 2026-12-07.)
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use ballpit::physics::exact::{EightWay, EventQueue};
use proptest::prelude::*;

/// The contract by brute force: every sphere's time, the least found by a
/// scan (times ordered as `f64::total_cmp` orders them, `-0` as `+0`).
#[derive(Default)]
struct Scan(Vec<f64>);

/// `-0` as `+0`, as the contract takes it (every other time kept, bit for bit).
fn tied(t: f64) -> f64 {
    if t == 0.0 { 0.0 } else { t }
}

impl EventQueue for Scan {
    fn reset(&mut self, n: usize) {
        self.0 = vec![f64::INFINITY; n];
    }
    fn set_leaf(&mut self, i: usize, t: f64) {
        self.0[i] = tied(t);
    }
    fn rebuild(&mut self) {}
    fn update(&mut self, i: usize, t: f64) {
        self.0[i] = tied(t);
    }
    fn peek(&mut self) -> (f64, usize) {
        let mut best = (f64::INFINITY, 0);
        for (i, &t) in self.0.iter().enumerate() {
            if t.total_cmp(&best.0).is_lt() {
                best = (t, i);
            }
        }
        best
    }
    fn time_of(&self, i: usize) -> f64 {
        self.0[i]
    }
    fn shift(&mut self, shift: f64) {
        for t in &mut self.0 {
            *t = tied(*t - shift);
        }
    }
    fn heap_bytes(&self) -> usize {
        self.0.capacity() * size_of::<f64>()
    }
}

#[derive(Clone, Debug)]
enum Op {
    Update(usize, f64),
    UpdateTwo(usize, f64, usize, f64),
    /// Process the earliest event as the model does: its sphere's next
    /// event `ahead` later (the window moves on).
    Pop(f64),
    /// Then a partner too, as a contact does.
    PopPair(usize, f64, f64),
    Shift(f64),
    /// Set every time (from a seed list, cycled) and rebuild.
    Rebuild(Vec<f64>),
    Reset,
}

/// Times with many ties: zeros of both signs, a few grid values, infinities,
/// a NaN that sorts first (sign set), far times. (A NaN without the sign
/// sorts after `+inf`, behind the tree's padding leaves: outside the
/// queue's contract, and never made by the model.)
fn time() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => (0u8..6).prop_map(|k| f64::from(k) * 0.25),
        3 => 0.0..4.0f64,
        1 => Just(0.0),
        1 => Just(-0.0),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(-f64::NAN),
        1 => Just(-1.5),
        1 => 1e6..1e12f64,
        1 => Just(1e300),
    ]
}

/// How far ahead a processed sphere's next event is: mostly near, as in a
/// run; sometimes at once, far away, or never.
fn ahead() -> impl Strategy<Value = f64> {
    prop_oneof![
        6 => 0.0..0.01f64,
        2 => 0.01..2.0f64,
        1 => Just(0.0),
        1 => 1e3..1e9f64,
        1 => Just(f64::INFINITY),
    ]
}

fn op(n: usize) -> impl Strategy<Value = Op> {
    prop_oneof![
        6 => (0..n, time()).prop_map(|(i, t)| Op::Update(i, t)),
        2 => (0..n, time(), 0..n, time()).prop_map(|(i, ti, j, tj)| Op::UpdateTwo(i, ti, j, tj)),
        10 => ahead().prop_map(Op::Pop),
        4 => (0..n, ahead(), ahead()).prop_map(|(j, a, b)| Op::PopPair(j, a, b)),
        1 => prop_oneof![Just(0.0), 0.0..3.0f64, Just(1e7)].prop_map(Op::Shift),
        1 => prop::collection::vec(time(), 1..8).prop_map(Op::Rebuild),
        1 => Just(Op::Reset),
    ]
}

/// Equal peeks: the same sphere and the same time, bit for bit (NaNs by bits).
fn same(a: (f64, usize), b: (f64, usize)) -> bool {
    a.1 == b.1 && a.0.to_bits() == b.0.to_bits()
}

fn apply<Q: EventQueue>(q: &mut Q, n: usize, op: &Op) {
    match op {
        Op::Update(i, t) => q.update(*i, *t),
        Op::UpdateTwo(i, ti, j, tj) => q.update_two(*i, *ti, *j, *tj),
        Op::Pop(ahead) => {
            let (t, i) = q.peek();
            if i < n {
                q.update(i, t + ahead);
            }
        }
        Op::PopPair(j, a, b) => {
            let (t, i) = q.peek();
            if i < n {
                q.update_two(i, t + a, *j, t + b);
            }
        }
        Op::Shift(s) => q.shift(*s),
        Op::Rebuild(seed) => {
            for i in 0..n {
                q.set_leaf(i, seed[i % seed.len()] + (i / seed.len()) as f64 * 0.125);
            }
            q.rebuild();
        }
        Op::Reset => q.reset(n),
    }
}

/// The eight-way tree against the scan, op by op, then drained.
fn drive(n: usize, start: &[f64], ops: &[Op]) -> Result<(), TestCaseError> {
    let (mut scan, mut tree) = (Scan::default(), EightWay::default());
    scan.start(n, start);
    tree.start(n, start);
    prop_assert!(same(scan.peek(), tree.peek()), "after the start");
    for (k, op) in ops.iter().enumerate() {
        apply(&mut scan, n, op);
        apply(&mut tree, n, op);
        let (a, b) = (scan.peek(), tree.peek());
        prop_assert!(same(a, b), "op {k} {op:?}: scan {a:?}, eight-way {b:?}");
        let i = k * 7919 % n;
        prop_assert_eq!(scan.time_of(i).to_bits(), tree.time_of(i).to_bits());
    }
    // Drain both: the whole order, not only the first.
    for k in 0..n.min(300) {
        let (a, b) = (scan.peek(), tree.peek());
        prop_assert!(same(a, b), "drain {k}: scan {a:?}, eight-way {b:?}");
        scan.update(a.1, f64::INFINITY);
        tree.update(b.1, f64::INFINITY);
    }
    Ok(())
}

/// Start each from the same times (set, then rebuilt).
trait Queue {
    fn start(&mut self, n: usize, times: &[f64]);
}

impl<Q: EventQueue> Queue for Q {
    fn start(&mut self, n: usize, times: &[f64]) {
        self.reset(n);
        for i in 0..n {
            self.set_leaf(i, times[i % times.len()] * (1.0 + (i / times.len()) as f64));
        }
        self.rebuild();
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn the_tree_pops_as_the_scan_small(
        (n, start, ops) in (1usize..=3).prop_flat_map(|n| (
            Just(n),
            prop::collection::vec(time(), 1..4),
            prop::collection::vec(op(n), 0..200),
        ))
    ) {
        drive(n, &start, &ops)?;
    }

    #[test]
    fn the_tree_pops_as_the_scan_mid(
        (n, start, ops) in (4usize..=70).prop_flat_map(|n| (
            Just(n),
            prop::collection::vec(time(), 1..20),
            prop::collection::vec(op(n), 0..300),
        ))
    ) {
        drive(n, &start, &ops)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]

    #[test]
    fn the_tree_pops_as_the_scan_1000(
        start in prop::collection::vec(0.0..2.0f64, 1..50),
        ops in prop::collection::vec(op(1000), 0..2000),
    ) {
        drive(1000, &start, &ops)?;
    }
}

/// A long run of a model-like schedule at 1000 spheres: each processed
/// sphere's next event a random short time ahead, a few far, ties now and
/// then, and the origin shifted along the way.
#[test]
fn a_long_schedule_pops_alike() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(11);
    let n = 1000;
    let (mut scan, mut tree) = (Scan::default(), EightWay::default());
    let start: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..1.0)).collect();
    scan.start(n, &start);
    tree.start(n, &start);
    for k in 0..200_000 {
        let (a, b) = (scan.peek(), tree.peek());
        assert!(same(a, b), "event {k}: scan {a:?}, eight-way {b:?}");
        // Exponential waits, a few very long, and exact ties now and then.
        let wait = match rng.random_range(0..100) {
            0 => 1e4,
            1 => 0.0,
            _ => -rng.random_range(f64::EPSILON..1.0f64).ln(),
        };
        scan.update(a.1, a.0 + wait);
        tree.update(b.1, b.0 + wait);
        if k % 50_000 == 49_999 {
            scan.shift(a.0);
            tree.shift(a.0);
        }
    }
}
