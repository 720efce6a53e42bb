//! End-to-end benchmark (criterion): the whole 90-minute Mach-1 case (`mach1-east`,
//! 500 Hz, N = 3: 2.7 M IMU samples, 900 k updates) per algorithm, from an in-memory
//! increment buffer, *including the error computation* (`pipeline::nav_error` against
//! the truth after every update). Throughput is in IMU samples (samples/s).
//!
//! `cargo bench -p sdins-sim --bench end_to_end` (docs/performance.md has the numbers).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{full_run, record, scenario};
use criterion::{black_box, criterion_group, criterion_main, Criterion, SamplingMode, Throughput};
use sdins_core::nav::{AlgorithmKind, AlgorithmSpec};
use std::time::{Duration, Instant};

fn mach1(c: &mut Criterion) {
    let scn = scenario("mach1-east");
    let n = scn.nav.samples;
    let rec = record(&scn, n, None);
    let mut g = c.benchmark_group("mach1-east_90min");
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(8))
        .throughput(Throughput::Elements(rec.incs.len() as u64));
    for kind in AlgorithmKind::ALL {
        let spec = AlgorithmSpec::new(kind, n);
        g.bench_function(format!("{}/N={n}", kind.name()), |b| {
            b.iter_custom(|iters| {
                let t0 = Instant::now();
                for _ in 0..iters {
                    black_box(full_run(black_box(&rec), &spec));
                }
                t0.elapsed()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, mach1);
criterion_main!(benches);
