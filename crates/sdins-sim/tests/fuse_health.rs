//! The health verdict (`fusion::health`) on consistent runs: its false-alarm rate measured
//! by Monte Carlo. The module documents the rates of each check; their sum bounds the
//! share of consistent runs that fail (≈ 1.1 %: NIS windows 1 %, bias 0.04 %, the rest
//! below 1e-6). The diverged case (NaveGo's ADIS16488 with the tactical preset) is an
//! end-to-end CLI test: `sdins-cli --test cli fuse_health_verdict_exit_3_on_a_diverged_filter`.
#![allow(clippy::unwrap_used)]

use sdins_sim::cancel::CancelToken;
use sdins_sim::fusion::health::HealthVerdict;
use sdins_sim::fusion::request::{fuse, FuseData, FuseRequest, ScenarioData};
use sdins_sim::scenario::Scenario;
use std::fmt::Write as _;

/// A manoeuvring drive (accelerations, 9 °/s turns both ways, S-turns), 100 Hz, N = 2,
/// 1 Hz GNSS, the grade's errors simulated and modelled alike.
fn drive(minutes: u32) -> Scenario {
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
        "name = \"health-drive\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nh_m = 100.0\nspeed_mps = 10.0\nyaw_deg = 30.0\n[imu]\nrate_hz = 100.0\nseed = 11\ngrade = \"tactical\"\n[nav]\nsamples = 2\n{segs}"
    );
    Scenario::from_toml(&toml, "health-drive.toml").unwrap()
}

/// The verdicts of runs `runs` of the drive (gate on, the default).
fn verdicts(minutes: u32, runs: std::ops::Range<u64>) -> Vec<HealthVerdict> {
    let scn = drive(minutes);
    runs.map(|run| {
        let req = FuseRequest::new(FuseData::Scenario(ScenarioData {
            scenario: scn.clone(),
            run,
            exact_start: false,
            in_motion: false,
            zupt_sigma_mps: None,
        }));
        fuse(&req, &CancelToken::new(), &mut |_| {}).unwrap().health
    })
    .collect()
}

fn failed(v: &[HealthVerdict]) -> Vec<String> {
    v.iter()
        .enumerate()
        .filter(|(_, h)| !h.ok())
        .map(|(i, h)| format!("run {i}: {}", h.failures().join("; ")))
        .collect()
}

/// 10 consistent runs of a 5-minute drive (300 fixes: 5 NIS windows each): at a per-run
/// false-alarm rate of ≈ 1.1 %, two or more failures have probability 0.5 %; the seeds
/// are fixed, so this is a measurement that a broken check (a wrong band, a prior taken
/// from the wrong row) would fail.
#[test]
fn health_false_alarms_on_consistent_runs() {
    let v = verdicts(5, 0..10);
    for h in &v {
        assert_eq!(h.checks.len(), 5);
        let nis = &h.checks[0];
        assert!(nis.detail.contains("5 windows"), "{}", nis.detail);
    }
    let f = failed(&v);
    assert!(f.len() <= 1, "{f:?}");
}

/// The criterion: across 200 consistent runs (10-minute drives, 10 NIS windows
/// each) at most 2 verdicts fail (expected 2.2 at 1.1 %). Release, ignored.
#[test]
#[ignore]
fn health_false_alarms_200_runs() {
    let v = verdicts(10, 0..200);
    let f = failed(&v);
    println!("{} of 200 consistent runs failed: {f:?}", f.len());
    assert!(f.len() <= 2, "{f:?}");
}
