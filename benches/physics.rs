//! Step throughput, one thread, `swept` (and `discrete` for comparison):
//! N = 1k, 10k, 100k at packing fractions 0.005 and 0.1. Throughput is in
//! sphere-steps per second (criterion's "elem/s").
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap fails the run
use ballpit::physics::sphere::volume;
use ballpit::physics::{ModelKind, Serial};
use ballpit::scene::{SceneSpec, build_world};
use criterion::measurement::WallTime;
use criterion::{
    BenchmarkGroup, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main,
};
use std::time::Duration;

/// Ten samples of about three seconds: the 100k steps take tens of ms.
fn short_group<'a>(c: &'a mut Criterion, name: &str) -> BenchmarkGroup<'a, WallTime> {
    let mut group = c.benchmark_group(name);
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    group
}

fn step_throughput(c: &mut Criterion) {
    let mut group = short_group(c, "step");
    for model in [ModelKind::Swept, ModelKind::Discrete] {
        for phi in [0.005, 0.1] {
            for n in [1_000usize, 10_000, 100_000] {
                let radius = (phi / (n as f64 * volume(1.0))).cbrt();
                let mut world = build_world(&SceneSpec {
                    count: Some(n),
                    radius: Some(radius),
                    seed: Some(7),
                    ..Default::default()
                })
                .expect("scene");
                let mut m = model.build();
                group.throughput(Throughput::Elements(n as u64));
                group.bench_function(BenchmarkId::new(format!("{model}/phi{phi}"), n), |b| {
                    b.iter(|| m.advance(&mut world, 1.0 / 60.0, 1, &Serial));
                });
            }
        }
    }
    group.finish();
}

/// The same spheres in a bigger box: N = 10k and 100k at packing 0.005,
/// both with the radius and the speed (in absolute units) of the 10k scene,
/// the box grown to keep the packing. Each sphere then has the same
/// neighbours, collisions and path per step at both counts, so the ratio of
/// the step times is what the code adds as N grows. (In the unit box of
/// `step`, the spheres shrink as N grows and each collides N^(1/3) times as
/// often; that ratio includes the extra physics.)
fn same_spheres(c: &mut Criterion) {
    let mut group = short_group(c, "same_spheres");
    let (n0, phi) = (10_000usize, 0.005);
    let radius = (phi / (n0 as f64 * volume(1.0))).cbrt();
    for n in [n0, 10 * n0] {
        let size = (n as f64 / n0 as f64).cbrt();
        let mut world = build_world(&SceneSpec {
            count: Some(n),
            radius: Some(radius),
            speed: Some(0.5),
            size: Some(size),
            seed: Some(7),
            ..Default::default()
        })
        .expect("scene");
        let mut m = ModelKind::Swept.build();
        group.throughput(Throughput::Elements(n as u64));
        group.bench_function(BenchmarkId::new("swept/phi0.005", n), |b| {
            b.iter(|| m.advance(&mut world, 1.0 / 60.0, 1, &Serial));
        });
    }
    group.finish();
}

criterion_group!(benches, step_throughput, same_spheres);
criterion_main!(benches);
