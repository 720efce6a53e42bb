//! `--static-s` on recorded data (`RecordInit::StaticCoarse`): the stationarity detector
//! refuses a static window in which the IMU moves, and accepts one at rest
//! (docs/theory/aiding-sensors.md §"Stationarity detection"). The detector sees a smooth
//! constant acceleration only through `‖f‖ − g ≈ a²/2g` (its scatter term is blind to
//! a steady tilt of the specific force): a gentle start (0.2 m/s²: 2 mm/s²) passes at the
//! 1e-6 rate, a drive-off at 1.5 m/s² (0.11 m/s²) does not.
#![allow(clippy::unwrap_used)]

use sdins_sim::cancel::CancelToken;
use sdins_sim::fusion::records::{
    fuse_records, record_from_scenario, RecordInit, RecordModel, RecordOptions,
};
use sdins_sim::scenario::Scenario;
use sdins_sim::sensors::gnss::GnssConfig;

#[test]
fn a_static_window_that_moves_is_refused() {
    // 20 s at rest, then a drive-off at 1.5 m/s², aviation-grade IMU at 100 Hz (gyrocompassing needs it)
    let scn = Scenario::from_toml(
        "name = \"start\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nh_m = 50.0\nyaw_deg = 30.0\n[imu]\nrate_hz = 100.0\nseed = 3\ngrade = \"aviation\"\n[nav]\nsamples = 2\n[[segment]]\ntype = \"static\"\nduration_s = 20.0\n[[segment]]\ntype = \"accelerate\"\naccel_mps2 = 1.5\nduration_s = 5.0\n",
        "start.toml",
    )
    .unwrap();
    let (imu, fixes) = record_from_scenario(&scn, &GnssConfig::default(), 0).unwrap();
    let model = RecordModel::from_error_model(&scn.imu.model);
    let run = |window_s: f64| {
        fuse_records(
            &imu,
            &fixes,
            &model,
            &RecordInit::StaticCoarse { window_s },
            &RecordOptions::default(),
            &CancelToken::new(),
            |_| {},
        )
    };
    // at rest: accepted
    run(15.0).unwrap();
    // 5 s of motion inside the window: refused, naming the window that moved
    let e = run(25.0).unwrap_err().to_string();
    assert!(e.contains("the IMU moves in the static window"), "{e}");
    assert!(e.contains("--static-s"), "{e}");
}
