//! Zero-velocity detection on a car with stops
//! (docs/validation.md §"Zero-velocity detection"): the fusion loop's stationarity detector, per IMU epoch against the truth,
//! at tactical and consumer grade, with road vibration (0.32 m/s² RMS per axis, 2–45 Hz)
//! only while the car moves; and the fusion loop with `--zupt-detector` never applies a
//! ZUPT while the truth moves faster than 0.5 m/s.
#![allow(clippy::unwrap_used)]

use sdins_core::aiding::meas::MeasKind;
use sdins_core::aiding::stationarity::MotionModel;
use sdins_sim::analysis::detection::detection_rates;
use sdins_sim::fusion::detector::{AnyDetector, DetectorSettings};
use sdins_sim::fusion::request::{fuse, FuseData, FuseOutput, FuseRequest, ScenarioData};
use sdins_sim::fusion::simulated::{noise_from_model, scenario_truth};
use sdins_sim::scenario::Scenario;
use std::fmt::Write as _;

/// Flat specific-force PSD giving 0.32 m/s² RMS per axis over 2–45 Hz.
const PSD: f64 = 0.32 * 0.32 / 43.0;

/// `cycles` cycles of: 12 s stop, 10 s at 1 m/s² to 10 m/s, `cruise_s` of straight
/// cruise, a 90° turn, 10 s braking; then a last stop. Random vibration during each
/// moving stretch.
fn car(grade: &str, cycles: u32, cruise_s: f64) -> Scenario {
    let mut segs = String::new();
    let mut over = String::new();
    let cycle_s = 42.0 + cruise_s;
    for c in 0..cycles {
        let t0 = cycle_s * f64::from(c);
        write!(segs, "[[segment]]\ntype = \"static\"\nduration_s = 12.0\n[[segment]]\ntype = \"accelerate\"\naccel_mps2 = 1.0\nduration_s = 10.0\n[[segment]]\ntype = \"cruise\"\nduration_s = {cruise_s}\n[[segment]]\ntype = \"turn\"\nrate_dps = 9.0\nduration_s = 10.0\n[[segment]]\ntype = \"accelerate\"\naccel_mps2 = -1.0\nduration_s = 10.0\n").unwrap();
        write!(
            over,
            "[[overlay]]\ntype = \"random_vibration\"\naccel_psd_breakpoints = [[2.0, {PSD}], [45.0, {PSD}]]\nstart_s = {}\nend_s = {}\nseed = {}\n",
            t0 + 12.0,
            t0 + cycle_s,
            c + 3
        )
        .unwrap();
    }
    segs.push_str("[[segment]]\ntype = \"static\"\nduration_s = 12.0\n");
    let toml = format!(
        "name = \"car-stops\"\nvehicle = \"car\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nh_m = 50.0\n[imu]\nrate_hz = 100.0\nseed = 5\ngrade = \"{grade}\"\n[nav]\nsamples = 2\n{segs}{over}"
    );
    Scenario::from_toml(&toml, "car-stops.toml").unwrap()
}

/// Two cycles with 60 s of straight cruise, tactical and consumer grade (release:
/// `cargo test --release -p sdins-sim --test zupt_detection -- --ignored --nocapture`).
#[test]
#[ignore]
fn detector_rates_on_a_car_with_stops() {
    rates(&["tactical", "consumer"], 2, 60.0);
}

/// The smoke version: one cycle with 5 s of cruise, tactical.
#[test]
fn detector_rates_smoke() {
    rates(&["tactical"], 1, 5.0);
}

fn rates(grades: &[&str], cycles: u32, cruise_s: f64) {
    let settings = DetectorSettings::default();
    for grade in grades {
        let scn = car(grade, cycles, cruise_s);
        // the prediction from the threshold and the vibration level
        let (noise, s_ba, s_bg, ..) = noise_from_model(&scn.imu.model);
        let det =
            AnyDetector::from_filter_noise(&settings, &noise, scn.imu.dt_s(), 9.8, &s_ba, &s_bg)
                .unwrap();
        let alpha = det
            .probability_declared_moving(&MotionModel::default())
            .unwrap();
        let p_moving_vib = det
            .probability_declared_moving(&MotionModel {
                vibration_accel_mps2: 0.32,
                ..MotionModel::default()
            })
            .unwrap();
        let r = detection_rates(&scn, &settings, 0).unwrap();
        println!(
            "{grade}: W = {} samples, γ = {:.3}; rest {} epochs, detected {:.3} % (predicted {:.3} %); moving {} epochs, declared at rest {:.4} % (predicted {:.2e} %); fastest epoch declared at rest {:.4} m/s",
            r.window,
            r.threshold,
            r.rest,
            100.0 * r.detection_rate(),
            100.0 * (1.0 - alpha),
            r.moving,
            100.0 * r.false_rest_rate(),
            100.0 * (1.0 - p_moving_vib),
            r.max_speed_declared_rest_mps
        );
        // rest: the stops less the window either side; moving: the rest less the same
        let stops = f64::from(cycles + 1);
        assert!(r.rest as f64 > stops * (1200.0 - 2.0 * 50.0) - 1.0, "{r:?}");
        // (each moving stretch's last sample ends the braking at speed 0: at rest)
        assert!(
            r.moving as f64 >= f64::from(cycles) * ((30.0 + cruise_s) * 100.0 - 2.0 * 50.0 - 1.0),
            "{r:?}"
        );
        assert!(r.detection_rate() >= 0.95, "{grade}: {r:?}");
        assert!(r.false_rest_rate() <= 1e-3, "{grade}: {r:?}");
        assert!(r.max_speed_declared_rest_mps <= 0.5, "{grade}: {r:?}");
    }
}

/// The fusion loop with the detector trigger: ZUPTs happen (at the stops) and none while
/// the truth moves faster than 0.5 m/s.
#[test]
fn fusion_zupts_only_at_the_stops() {
    let scn = car("tactical", 1, 5.0);
    let truth = scenario_truth(&scn);
    let dt = scn.imu.dt_s();
    let mut req = FuseRequest::new(FuseData::Scenario(ScenarioData {
        scenario: scn,
        run: 0,
        exact_start: false,
        in_motion: false,
        zupt_sigma_mps: None,
    }));
    req.zupt_detector = Some((0.01, DetectorSettings::default()));
    let mut zupts = 0u64;
    let mut fastest = 0.0f64;
    let out = fuse(&req, &sdins_sim::cancel::CancelToken::new(), &mut |o| {
        if let FuseOutput::Update(u) = o {
            if u.kind == MeasKind::Zupt {
                zupts += 1;
                let k = ((u.t_valid_s / dt).round() as usize).min(truth.len() - 1);
                fastest = fastest.max(truth[k].v_n_mps.norm());
            }
        }
    })
    .unwrap();
    println!("{zupts} ZUPTs, fastest truth speed at one {fastest:.4} m/s");
    // 2 stops of 12 s at 10 Hz, less a window each
    assert!(zupts > 2 * 115, "{zupts}");
    assert!(fastest <= 0.5, "{fastest}");
    assert!(out.health.ok(), "{:?}", out.health);
}
