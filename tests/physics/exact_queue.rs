//! The exact model's event queues: the eight-way tournament (the model's
//! queue) and the calendar must pop in exactly the binary tournament tree's
//! order (earliest time, ties by lower sphere index), so the model gives the
//! same run over any. A proptest drives all three with the same operations
//! and compares every peek; the model over each gives the same contacts and
//! final state, bit for bit, on a few scenes.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::large::with_three_large;
use ballpit::physics::exact::{Calendar, Contact, EightWay, EventDriven, EventQueue, Tournament};
use ballpit::physics::{Model, Serial, World};
use ballpit::scene::lattice::lattice_world;
use ballpit::scene::{SceneSpec, build_world};
use glam::DVec3;
use proptest::prelude::*;
use std::sync::{Arc, Mutex};

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
/// a NaN that sorts first (sign set), times far past any calendar window.
/// (A NaN without the sign sorts after `+inf`, behind the tournament's
/// padding leaves: outside the queues' contract, and never made by the model.)
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

fn drive(n: usize, start: &[f64], ops: &[Op]) -> Result<(), TestCaseError> {
    drive_with::<Calendar>(n, start, ops, "calendar")?;
    drive_with::<EightWay>(n, start, ops, "eight-way")
}

/// Queue `Q` against the binary tree, op by op.
fn drive_with<Q: EventQueue>(
    n: usize,
    start: &[f64],
    ops: &[Op],
    name: &str,
) -> Result<(), TestCaseError> {
    let (mut tree, mut other) = (Tournament::default(), Q::default());
    tree.start(n, start);
    other.start(n, start);
    prop_assert!(same(tree.peek(), other.peek()), "{name}: after the start");
    for (k, op) in ops.iter().enumerate() {
        apply(&mut tree, n, op);
        apply(&mut other, n, op);
        let (a, b) = (tree.peek(), other.peek());
        prop_assert!(same(a, b), "op {k} {op:?}: tournament {a:?}, {name} {b:?}");
        let i = k * 7919 % n;
        prop_assert_eq!(tree.time_of(i).to_bits(), other.time_of(i).to_bits());
    }
    // Drain both: the whole order, not only the first.
    for k in 0..n.min(300) {
        let (a, b) = (tree.peek(), other.peek());
        prop_assert!(same(a, b), "drain {k}: tournament {a:?}, {name} {b:?}");
        if a.1 < n {
            tree.update(a.1, f64::INFINITY);
            other.update(b.1, f64::INFINITY);
        }
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
    fn queues_pop_as_the_tournament_small(
        (n, start, ops) in (1usize..=3).prop_flat_map(|n| (
            Just(n),
            prop::collection::vec(time(), 1..4),
            prop::collection::vec(op(n), 0..200),
        ))
    ) {
        drive(n, &start, &ops)?;
    }

    #[test]
    fn queues_pop_as_the_tournament_mid(
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
    fn queues_pop_as_the_tournament_1000(
        start in prop::collection::vec(0.0..2.0f64, 1..50),
        ops in prop::collection::vec(op(1000), 0..2000),
    ) {
        drive(1000, &start, &ops)?;
    }
}

/// A long run of a model-like schedule at 1000 spheres: each processed
/// sphere's next event a random short time ahead, so the calendar moves
/// through many windows and spills its overflow many times.
#[test]
fn a_long_schedule_pops_alike() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(11);
    let n = 1000;
    let (mut tree, mut cal, mut eight) = (
        Tournament::default(),
        Calendar::default(),
        EightWay::default(),
    );
    let start: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..1.0)).collect();
    tree.start(n, &start);
    cal.start(n, &start);
    eight.start(n, &start);
    for k in 0..200_000 {
        let (a, b, e) = (tree.peek(), cal.peek(), eight.peek());
        assert!(same(a, b), "event {k}: tournament {a:?}, calendar {b:?}");
        assert!(same(a, e), "event {k}: tournament {a:?}, eight-way {e:?}");
        // Exponential waits, a few very long, and exact ties now and then.
        let wait = match rng.random_range(0..100) {
            0 => 1e4,
            1 => 0.0,
            _ => -rng.random_range(f64::EPSILON..1.0f64).ln(),
        };
        tree.update(a.1, a.0 + wait);
        cal.update(b.1, b.0 + wait);
        eight.update(e.1, e.0 + wait);
        if k % 50_000 == 49_999 {
            tree.shift(a.0);
            cal.shift(a.0);
            eight.shift(a.0);
        }
    }
}

/// The contacts, the final world and the events (as text) of a run.
type Run = (Vec<Contact>, World, String);

/// The contacts (spheres, time, centres, impulse, bit for bit), the final
/// world and the events of a run over queue `Q`, with the invariants held.
fn run<Q: EventQueue + Send>(mut w: World, dt: f64, steps: u64) -> Run {
    let seen = Arc::new(Mutex::new(Vec::new()));
    let sink = Arc::clone(&seen);
    let mut m = EventDriven::<Q>::default();
    m.set_observer(Some(Box::new(move |c| {
        sink.lock().expect("observer lock").push(*c);
    })));
    let e0 = w.kinetic_energy();
    m.advance(&mut w, dt, steps, &Serial);
    assert_eq!(w.escaped(), 0);
    assert!((w.kinetic_energy() - e0).abs() <= 1e-10 * e0);
    assert!(w.max_overlap_rel() <= 1e-9);
    assert_eq!(w.counters.capped_steps, 0);
    let stats = format!("{:?}", m.stats);
    let contacts = seen.lock().expect("observer lock").clone();
    (contacts, w, stats)
}

fn bits(c: &Contact) -> [u64; 10] {
    let v = |p: DVec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let [a, b, d] = v(c.pos_i);
    let [e, f, g] = v(c.pos_j);
    [
        c.i as u64,
        c.j as u64,
        c.time.to_bits(),
        c.impulse.to_bits(),
        a,
        b,
        d,
        e,
        f,
        g,
    ]
}

/// The three queues give the same run, bit for bit; the run spans more than
/// the model's time origin span, so the queues shift too.
fn alike(label: &str, w: World, dt: f64, steps: u64) {
    let tree = run::<Tournament>(w.clone(), dt, steps);
    alike_runs(
        &format!("{label}, calendar"),
        &tree,
        &run::<Calendar>(w.clone(), dt, steps),
    );
    alike_runs(
        &format!("{label}, eight-way"),
        &tree,
        &run::<EightWay>(w, dt, steps),
    );
}

/// Two runs, the binary tree's first, the same to the bit.
fn alike_runs(label: &str, (ct, wt, st): &Run, (cc, wc, sc): &Run) {
    assert!(ct.len() > 1000, "{label}: only {} contacts", ct.len());
    assert_eq!(st, sc, "{label}: events");
    assert_eq!(ct.len(), cc.len(), "{label}: contact count");
    for (k, (a, b)) in ct.iter().zip(cc).enumerate() {
        assert_eq!(bits(a), bits(b), "{label}: contact {k}");
    }
    for (k, (a, b)) in wt.spheres.iter().zip(&wc.spheres).enumerate() {
        assert!(
            a.pos.to_array().map(f64::to_bits) == b.pos.to_array().map(f64::to_bits)
                && a.vel.to_array().map(f64::to_bits) == b.vel.to_array().map(f64::to_bits),
            "{label}: sphere {k}"
        );
    }
    assert_eq!(
        wt.counters.wall_momentum.to_bits(),
        wc.counters.wall_momentum.to_bits()
    );
    assert_eq!(wt.counters.wall_collisions, wc.counters.wall_collisions);
}

fn gas(count: usize, radius: f64) -> World {
    build_world(&SceneSpec {
        scene: Some("gas".into()),
        count: Some(count),
        radius: Some(radius),
        seed: Some(5),
        ..Default::default()
    })
    .expect("scene")
}

/// Dilute (packing about 0.005): cell crossings, long free paths.
#[test]
fn dilute_runs_alike() {
    alike("dilute", gas(4000, 0.0067), 1.0 / 30.0, 40);
}

/// Packing about 0.1.
#[test]
fn moderate_runs_alike() {
    alike("0.1", gas(4000, 0.0181), 1.0 / 60.0, 70);
}

/// Packing 0.4: neighbour lists.
#[test]
fn dense_runs_alike() {
    let w = lattice_world(2000, 0.4, 1.0, 5).expect("lattice");
    alike("0.4", w, 1.0 / 200.0, 20);
}

/// Mixed radii: three spheres 15x the bulk (the second level).
#[test]
fn mixed_radii_run_alike() {
    alike("mixed", with_three_large(gas(3000, 0.005)), 1.0 / 30.0, 40);
}
