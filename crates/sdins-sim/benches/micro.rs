//! Micro-benchmarks (criterion): one navigation update of every algorithm for N = 1..4,
//! the truth generator per sample (closed form, Gauss, RK4 reference), and the IMU error model per
//! sample. Throughput is in IMU samples, so criterion prints samples/s.
//!
//! `cargo bench -p sdins-sim --bench micro` (docs/performance.md has the numbers).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{record, scenario, truth_config, Recorded};
use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use sdins_core::nav::{AlgorithmKind, AlgorithmSpec, AnyMechanization, Mechanization};
use sdins_sim::sensors::imu_error::{ImuErrorModel, ImuErrorState};
use sdins_sim::truth::TruthGenerator;
use std::time::{Duration, Instant};

/// Time `iters` updates, cycling through the recorded increments; the mechanization is
/// restarted from its initial state whenever the buffer wraps (rare: ≥ 7500 updates).
fn time_updates(rec: &Recorded, m0: &AnyMechanization, n: usize, iters: u64) -> Duration {
    let updates = rec.incs.len() / n;
    let mut m = m0.clone();
    let mut k = 0;
    let t0 = Instant::now();
    for _ in 0..iters {
        if k == updates {
            m = m0.clone();
            k = 0;
        }
        m.update(black_box(&rec.incs[k * n..(k + 1) * n]));
        k += 1;
    }
    black_box(m.state());
    t0.elapsed()
}

fn nav_update(c: &mut Criterion) {
    // 60 s of Mach-1 cruise (500 Hz) and the whole dq-paper case (100 Hz, 450 s, coning)
    for (name, max) in [("mach1-east", Some(30_000)), ("dq-paper", None)] {
        let scn = scenario(name);
        let rec = record(&scn, 12, max);
        let mut g = c.benchmark_group(format!("nav_update/{name}"));
        g.sample_size(20)
            .warm_up_time(Duration::from_millis(300))
            .measurement_time(Duration::from_secs(1));
        for kind in AlgorithmKind::ALL {
            for n in 1..=4 {
                let spec = AlgorithmSpec::new(kind, n);
                let m0 = AnyMechanization::new(&spec, rec.earth, rec.dt_s, &rec.init);
                g.throughput(Throughput::Elements(n as u64));
                g.bench_function(format!("{}/N={n}", kind.name()), |b| {
                    b.iter_custom(|iters| time_updates(&rec, &m0, n, iters))
                });
            }
        }
        g.finish();
    }
}

fn truth(c: &mut Criterion) {
    let mut g = c.benchmark_group("truth_per_sample");
    g.sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .throughput(Throughput::Elements(1));
    // 0: closed form, 1: the general (Gauss) path, 2: the RK4 reference
    for (label, name, path) in [
        ("closed_form/mach1-east", "mach1-east", 0),
        ("gauss/mach1-east", "mach1-east", 1),
        ("gauss/dq-paper", "dq-paper", 1),
        ("gauss/turn-90dps", "turn-90dps", 1),
        ("rk4_reference/dq-paper", "dq-paper", 2),
    ] {
        let scn = scenario(name);
        let cfg = truth_config(&scn);
        let make = || {
            let t = TruthGenerator::new(&scn.trajectory, cfg);
            match path {
                0 => t,
                1 => t.without_closed_form(),
                _ => t.reference_rk4(),
            }
        };
        g.bench_function(label, |b| {
            let mut gen = make();
            b.iter(|| match gen.next() {
                Some(s) => s,
                None => {
                    gen = make();
                    gen.next().expect("non-empty scenario")
                }
            })
        });
    }
    g.finish();
}

fn imu_error(c: &mut Criterion) {
    let scn = scenario("mach1-east");
    let rec = record(&scn, 1, Some(30_000));
    let model = ImuErrorModel::preset("aviation").expect("preset");
    let mut g = c.benchmark_group("imu_error_per_sample");
    g.sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .throughput(Throughput::Elements(1));
    g.bench_function("aviation", |b| {
        let mut st = ImuErrorState::new(&model, 1, 0).expect("valid preset");
        let mut k = 0;
        b.iter(|| {
            k = if k + 1 == rec.incs.len() { 0 } else { k + 1 };
            st.apply(black_box(&rec.incs[k]), rec.dt_s)
        })
    });
    g.finish();
}

criterion_group!(benches, nav_update, truth, imu_error);
criterion_main!(benches);
