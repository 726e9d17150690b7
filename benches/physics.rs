//! Step throughput, one thread, `swept` (and `discrete` for comparison):
//! N = 1k, 10k, 100k at packing fractions 0.005 and 0.1. Throughput is in
//! sphere-steps per second (criterion's "elem/s").
use ballpit::physics::sphere::volume;
use ballpit::physics::{ModelKind, Serial};
use ballpit::scene::{SceneSpec, build_world};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::time::Duration;

fn step_throughput(c: &mut Criterion) {
    let mut group = c.benchmark_group("step");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
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
                    b.iter(|| m.advance(&mut world, 1.0 / 60.0, 1, &Serial))
                });
            }
        }
    }
    group.finish();
}

criterion_group!(benches, step_throughput);
criterion_main!(benches);
