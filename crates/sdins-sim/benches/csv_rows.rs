//! CSV writing (criterion): 100 000 rows of an IMU increment table (seven f64 columns),
//! formatted by hand with `{:e}` (how sdins wrote them before) and serialized through the
//! `csv` crate (how `sdins truth`, `nav`, `run` and `fuse` write them now), both into
//! memory, so that the choice "csv crate everywhere, no hand-formatted hot path" rests on a
//! measurement.
//!
//! `cargo bench -p sdins-sim --bench csv_rows` (docs/performance.md has the numbers).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use std::io::Write;

fn rows() -> Vec<[f64; 7]> {
    (0..100_000)
        .map(|k| {
            let t = k as f64 * 0.005;
            [
                t,
                1e-6 * (t * 1.3).sin(),
                -2.2e-7 * (t * 0.7).cos(),
                3.3e-5 * t.sin(),
                1e-3 * (t * 2.1).cos(),
                -8.8e-5 * t.cos(),
                -0.049 + 1e-6 * t.sin(),
            ]
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let data = rows();
    let mut g = c.benchmark_group("csv_100k_imu_rows");
    g.sample_size(20);
    g.bench_function("hand_format_e", |b| {
        b.iter(|| {
            let mut out = Vec::with_capacity(16 << 20);
            for r in &data {
                writeln!(
                    out,
                    "{},{:e},{:e},{:e},{:e},{:e},{:e}",
                    r[0], r[1], r[2], r[3], r[4], r[5], r[6]
                )
                .unwrap();
            }
            black_box(out.len())
        })
    });
    g.bench_function("csv_crate_serialize", |b| {
        b.iter(|| {
            let mut w = csv::WriterBuilder::new()
                .has_headers(false)
                .from_writer(Vec::with_capacity(16 << 20));
            for r in &data {
                w.serialize(r).unwrap();
            }
            black_box(w.into_inner().unwrap().len())
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
