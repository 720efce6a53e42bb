//! INS/GNSS benchmark (criterion): one hour of 200 Hz IMU increments with 1 Hz GNSS held
//! in memory (`bench/scenarios/drive-1h-200hz.toml`, tactical grade), forward filter and
//! RTS smoother with full-rate smoothed output, covariance at 1 Hz and at 10 Hz (and the
//! 21-state filter with scale factors at 1 Hz); one
//! GNSS position + velocity update; and, separately, parsing the hour's IMU text file.
//!
//! `cargo bench -p sdins-sim --bench fuse` (docs/performance.md has the numbers).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{black_box, criterion_group, criterion_main, Criterion, SamplingMode};
use sdins_sim::cancel::CancelToken;
use sdins_sim::fusion::records::{
    fuse_records, record_from_scenario, record_from_scenario_with_aiding, RecordEvent, RecordInit,
    RecordModel, RecordOptions,
};
use sdins_sim::fusion::simulated::InitSigma;
use sdins_sim::scenario::Scenario;
use sdins_sim::sensors::gnss::GnssConfig;
use std::io::Write;
use std::time::Duration;

fn hour() -> Scenario {
    Scenario::from_toml(
        include_str!("../../../bench/scenarios/drive-1h-200hz.toml"),
        "drive-1h-200hz.toml",
    )
    .unwrap()
}

fn fuse(c: &mut Criterion) {
    let scn = hour();
    let (imu, fixes) = record_from_scenario(&scn, &GnssConfig::default(), 0).unwrap();
    let model = RecordModel::from_error_model(&scn.imu.model);
    let state =
        sdins_sim::truth::TruthGenerator::new(&scn.trajectory, scn.truth_config()).initial_state();
    let init = RecordInit::Given {
        state,
        sigma: InitSigma::default(),
    };
    let mut g = c.benchmark_group("fuse_1h_200hz");
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(10));
    let sf = sdins_sim::fusion::simulated::ScaleFactorPrior {
        accel_ppm: [300.0; 3],
        gyro_ppm: [300.0; 3],
    };
    for (smooth, cov, states) in [
        (false, 1.0, 15),
        (true, 1.0, 15),
        (false, 10.0, 15),
        (true, 10.0, 15),
        (true, 1.0, 21),
    ] {
        let opts = RecordOptions {
            smooth,
            cov_rate_hz: cov,
            scale_factors: (states == 21).then_some(sf),
            ..Default::default()
        };
        let name = format!(
            "{}/cov_{cov}hz{}",
            if smooth {
                "forward+smoother"
            } else {
                "forward"
            },
            if states == 21 { "/21_states" } else { "" }
        );
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut n = 0u64;
                fuse_records(
                    &imu,
                    &fixes,
                    &model,
                    &init,
                    &opts,
                    &CancelToken::new(),
                    |ev| {
                        if let RecordEvent::Smoothed(p) = ev {
                            n += black_box(p.t_s) as u64 & 1;
                        }
                    },
                )
                .unwrap();
                n
            })
        });
    }
    // the same hour with a 10 Hz odometer (speed and NHC rows) and a 1 Hz barometer
    let scn_aid = Scenario::from_toml(
        &format!(
            "{}\n[odometer]\nrate_hz = 10.0\nnhc_sigma_mps = 0.1\n[baro]\nrate_hz = 1.0\n",
            include_str!("../../../bench/scenarios/drive-1h-200hz.toml")
        ),
        "drive-1h-200hz-aided.toml",
    )
    .unwrap();
    let (imu_a, fixes_a, aiding) =
        record_from_scenario_with_aiding(&scn_aid, &GnssConfig::default(), 0).unwrap();
    let opts = RecordOptions {
        smooth: true,
        cov_rate_hz: 1.0,
        aiding,
        ..Default::default()
    };
    g.bench_function("forward+smoother/cov_1hz/odometer_10hz_baro_1hz", |b| {
        b.iter(|| {
            let mut n = 0u64;
            fuse_records(
                &imu_a,
                &fixes_a,
                &model,
                &init,
                &opts,
                &CancelToken::new(),
                |ev| {
                    if let RecordEvent::Smoothed(p) = ev {
                        n += black_box(p.t_s) as u64 & 1;
                    }
                },
            )
            .unwrap();
            n
        })
    });
    g.finish();

    // text parsing of the same hour (sdins increment CSV, 720 000 rows)
    let path = std::env::temp_dir().join(format!("sdins-bench-fuse-{}.csv", std::process::id()));
    {
        let mut f = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
        writeln!(
            f,
            "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps"
        )
        .unwrap();
        for (k, i) in imu.increments.iter().enumerate() {
            let t = imu.t0_s + imu.dt_s * k as f64;
            writeln!(
                f,
                "{t},{:e},{:e},{:e},{:e},{:e},{:e}",
                i.dtheta_b_rad.x,
                i.dtheta_b_rad.y,
                i.dtheta_b_rad.z,
                i.dv_b_mps.x,
                i.dv_b_mps.y,
                i.dv_b_mps.z
            )
            .unwrap();
        }
    }
    let mut g = c.benchmark_group("parse_1h_200hz");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    g.bench_function("sdins_imu_csv_720k_rows", |b| {
        b.iter(|| {
            sdins_sim::io::imu_file::read_imu_file(&path, sdins_sim::io::imu_file::ImuFormat::Sdins)
                .unwrap()
                .increments
                .len()
        })
    });
    g.finish();
    std::fs::remove_file(&path).ok();
}

criterion_group!(benches, fuse);
criterion_main!(benches);
