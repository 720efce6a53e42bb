//! The fusion Monte Carlo (`analysis::fuse_mc`) and the consistency criterion
//! (`analysis::consistency`): exactness for any thread count and shard split (default
//! suite), a 10-run consistency smoke test (default suite), and the 100-run consistency
//! of the GNSS-only scenario fusion with 15 and 21 states (release:
//! `cargo test --release -p sdins-sim --test fuse_mc -- --ignored --nocapture`).
#![allow(clippy::unwrap_used)]

use sdins_sim::analysis::consistency::Consistency;
use sdins_sim::analysis::fuse_mc::{run_shard, FuseMcError, FuseMcOptions, FuseMcState};
use sdins_sim::analysis::montecarlo::Shard;
use sdins_sim::fusion::request::{FuseData, FuseRequest, ScenarioData};
use sdins_sim::fusion::simulated::ScaleFactorPrior;
use sdins_sim::scenario::Scenario;
use std::fmt::Write as _;

/// The manoeuvring drive of `tests/fuse.rs` (accelerations, 9 °/s turns both ways,
/// S-turns), 100 Hz, N = 2.
fn maneuver(grade: &str, minutes: u32) -> Scenario {
    let mut segs = String::new();
    for _ in 0..minutes {
        for (kind, extra) in [
            ("accelerate", "accel_mps2 = 1.0"),
            ("turn", "rate_dps = 9.0"),
            ("cruise", ""),
            ("accelerate", "accel_mps2 = -0.5"),
            ("turn", "rate_dps = -9.0"),
            ("sturn", "amplitude_dps = 5.0"),
        ] {
            write!(
                segs,
                "[[segment]]\ntype = \"{kind}\"\nduration_s = 10.0\n{extra}\n"
            )
            .unwrap();
        }
    }
    let toml = format!(
        "name = \"fuse-maneuver\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nh_m = 100.0\nspeed_mps = 10.0\nyaw_deg = 30.0\n[imu]\nrate_hz = 100.0\nseed = 7\ngrade = \"{grade}\"\n[nav]\nsamples = 2\n{segs}"
    );
    Scenario::from_toml(&toml, "maneuver.toml").unwrap()
}

/// Loops in one direction (a 360° and a 180° turn at 9 °/s per minute, speed changes
/// between): the scale-factor scenario of `tests/fuse.rs`.
fn loops(minutes: u32) -> Scenario {
    let mut segs = String::new();
    for _ in 0..minutes {
        for (kind, extra, dur) in [
            ("accelerate", "accel_mps2 = 0.5", 5.0),
            ("turn", "rate_dps = 9.0", 40.0),
            ("accelerate", "accel_mps2 = -0.5", 5.0),
            ("turn", "rate_dps = 9.0", 20.0),
        ] {
            write!(
                segs,
                "[[segment]]\ntype = \"{kind}\"\nduration_s = {dur}\n{extra}\n"
            )
            .unwrap();
        }
    }
    let toml = format!(
        "name = \"fuse-loops\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nh_m = 100.0\nspeed_mps = 15.0\nyaw_deg = 30.0\n[imu]\nrate_hz = 100.0\nseed = 7\ngrade = \"tactical\"\n[nav]\nsamples = 2\n{segs}"
    );
    Scenario::from_toml(&toml, "loops.toml").unwrap()
}

fn request(scn: Scenario) -> FuseRequest {
    let mut r = FuseRequest::new(FuseData::Scenario(ScenarioData {
        scenario: scn,
        run: 0,
        exact_start: false,
        in_motion: false,
        zupt_sigma_mps: None,
    }));
    r.gate = false;
    r
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

#[test]
fn bit_identical_for_threads_and_shards() {
    let req = request(maneuver("tactical", 1).clone());
    let mut req = req;
    req.until_s = Some(20.0);
    let mc = FuseMcOptions {
        runs: 13,
        seed: 5,
        block: 4,
        draw_scale_factors: false,
    };
    let none = || {};
    let go = || false;
    let one = in_pool(1, || run_shard(&req, &mc, Shard::ALL, &none, &go).unwrap());
    let two = in_pool(2, || run_shard(&req, &mc, Shard::ALL, &none, &go).unwrap());
    assert_eq!(one, two);
    let shards: Vec<FuseMcState> = (0..4)
        .map(|i| {
            in_pool(2, || {
                run_shard(&req, &mc, Shard { index: i, count: 4 }, &none, &go).unwrap()
            })
        })
        .collect();
    assert!(!shards[0].missing_blocks().is_empty());
    // merged in a scrambled order, through a JSON round trip
    let json: Vec<FuseMcState> = [2, 0, 3, 1]
        .iter()
        .map(|&i| serde_json::from_str(&serde_json::to_string(&shards[i]).unwrap()).unwrap())
        .collect();
    let merged = FuseMcState::merge(&json).unwrap();
    assert_eq!(merged, one);
    let (a, b) = (one.statistics(), merged.statistics());
    assert_eq!(a.to_csv(), b.to_csv());
    assert!(a.complete && a.runs == 13);
    // 20 s at 10 Hz: 201 rows; NEES of 5 blocks, NIS of 8 kinds
    assert_eq!(a.times_s.len(), 201);
    let names: Vec<&str> = a.columns.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "nees_position",
            "nees_velocity",
            "nees_attitude",
            "nees_accel_bias",
            "nees_gyro_bias",
            "nis_gnss",
            "nis_zupt",
            "nis_nhc",
            "nis_baro",
            "nis_odometer",
            "nis_magnetometer",
            "nis_dual_antenna",
            "nis_body_velocity"
        ]
    );
    // a fix per run at the whole seconds (6 dof), none in between
    let g = &a.columns[5];
    assert_eq!(g.dof, 6);
    assert_eq!((g.n[10], g.n[11]), (13, 0));
    assert!(g.mean[10] > 0.0);
    // overlapping shards, another job, a tampered state are refused
    assert!(matches!(
        FuseMcState::merge(&[shards[1].clone(), shards[1].clone()]),
        Err(FuseMcError::DuplicateBlock(_))
    ));
    let other = run_shard(
        &req,
        &FuseMcOptions { seed: 6, ..mc },
        Shard { index: 0, count: 4 },
        &none,
        &go,
    )
    .unwrap();
    assert!(matches!(
        FuseMcState::merge(&[other, shards[1].clone()]),
        Err(FuseMcError::Mismatch(_))
    ));
    let mut bad = shards[0].clone();
    bad.blocks[0].moments[0].n += 1;
    assert!(bad.validate().is_err());
    // a Monte Carlo needs runs, a scenario, and runs that share their epochs
    assert!(run_shard(
        &req,
        &FuseMcOptions { runs: 0, ..mc },
        Shard::ALL,
        &none,
        &go
    )
    .is_err());
    assert_eq!(
        run_shard(&req, &mc, Shard::ALL, &none, &|| true)
            .unwrap_err()
            .to_string(),
        "interrupted"
    );
}

/// The consistency verdicts of the columns that have values after `after_s`.
fn verdicts(st: &FuseMcState, after_s: f64) -> Vec<Consistency> {
    let s = st.statistics();
    s.columns
        .iter()
        .filter_map(|c| s.consistency(&c.name, after_s, 1))
        .filter(|c| c.epochs > 0)
        .collect()
}

/// 10 runs of a 3-minute manoeuvring drive, gating off: the position, velocity and
/// attitude NEES and the GNSS NIS meet the criterion after 30 s (a smoke version of the
/// release tests below; the bias blocks change too slowly for 10 runs: their epochs are
/// one sample, not 750).
#[test]
fn consistency_smoke_10_runs() {
    let mut req = request(maneuver("tactical", 3));
    req.cov_rate_hz = 5.0;
    let mc = FuseMcOptions {
        runs: 10,
        seed: 1,
        block: 16,
        draw_scale_factors: true,
    };
    let st = run_shard(&req, &mc, Shard::ALL, &|| {}, &|| false).unwrap();
    let v = verdicts(&st, 30.0);
    for c in &v {
        println!("{c}");
    }
    assert_eq!(v.len(), 6);
    for c in v.iter().filter(|c| !c.name.contains("bias")) {
        assert!(c.pass, "{c}");
    }
}

fn criterion(req: &FuseRequest, label: &str) {
    let mc = FuseMcOptions {
        runs: 100,
        seed: 1,
        block: 16,
        draw_scale_factors: true,
    };
    let t = std::time::Instant::now();
    let st = run_shard(req, &mc, Shard::ALL, &|| {}, &|| false).unwrap();
    println!("{label}: 100 runs in {:.1} s", t.elapsed().as_secs_f64());
    let v = verdicts(&st, 30.0);
    for c in &v {
        println!("{label} {c}");
    }
    for c in &v {
        assert!(c.pass, "{label} {c}");
    }
}

/// docs/validation.md §"Filter consistency": the 15-state filter on the 10-minute
/// manoeuvring drive, tactical grade, 1 Hz GNSS, 100 runs, gating off.
#[test]
#[ignore]
fn consistency_criterion_15_states() {
    criterion(&request(maneuver("tactical", 10)), "15 states");
}

/// The 21-state filter on the loops drive (tactical, 10 minutes), each run's true scale
/// factors drawn from the filter's prior (σ 300 ppm every axis), 100 runs, gating off.
#[test]
#[ignore]
fn consistency_criterion_21_states() {
    let mut req = request(loops(10));
    req.scale_factors = Some(ScaleFactorPrior::uniform(300.0, 300.0));
    criterion(&req, "21 states");
}
