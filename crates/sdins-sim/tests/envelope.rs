//! The kinematic envelope over whole scenarios: the hostile-input examples are refused with
//! the file, line and segment; random scenarios (property test) are either refused with a
//! located error or produce finite truth and navigation inside the documented envelope.
#![allow(clippy::unwrap_used)]
use proptest::prelude::*;
use sdins_core::nav::{AlgorithmKind, AlgorithmSpec};
use sdins_sim::nav::pipeline::{run, RunOptions};
use sdins_sim::scenario::{Scenario, ScenarioError};
use sdins_sim::truth::envelope::Envelope;
use sdins_sim::truth::{TruthConfig, TruthGenerator};

fn scenario(start: &str, segments: &str) -> Result<Scenario, ScenarioError> {
    let text = format!("[start]\n{start}\n[imu]\nrate_hz = 100.0\n{segments}");
    Scenario::from_toml(&text, "hostile.toml")
}

fn refused(start: &str, segments: &str, want: &str, line: usize) {
    match scenario(start, segments) {
        Err(ScenarioError::Invalid {
            line: l, message, ..
        }) => {
            assert!(
                message.contains(want),
                "{segments}: `{message}` lacks `{want}`"
            );
            assert_eq!(l, line, "{segments}: {message}");
        }
        other => panic!("{segments}: accepted or wrong error: {other:?}"),
    }
}

#[test]
fn hostile_trajectories_are_refused_at_their_segment() {
    let s0 = "lat_deg = 37.5\nlon_deg = 127.0\nh_m = 100.0\nspeed_mps = 100.0";
    // lines: 1 [start] 2-5 start keys 6 [imu] 7 rate 8 [[segment]] 9 type ...
    refused(
        s0,
        "[[segment]]\ntype = \"turn\"\nrate_dps = 1e300\nduration_s = 1.0\n",
        "angular rate",
        8,
    );
    // climb that ends at −7.5 km: 100 m/s down after 150 s averages 50 m/s
    refused(
        s0,
        "[[segment]]\ntype = \"cruise\"\nduration_s = 1.0\n[[segment]]\ntype = \"climb\"\nto_climb_rate_mps = -100.0\nduration_s = 152.0\n",
        "height",
        11,
    );
    // climb to 114 km
    refused(
        s0,
        "[[segment]]\ntype = \"climb\"\nto_climb_rate_mps = 500.0\nduration_s = 456.0\n",
        "height",
        8,
    );
    // acceleration that passes 3 km/s
    refused(
        s0,
        "[[segment]]\ntype = \"accelerate\"\naccel_mps2 = 50.0\nduration_s = 100.0\n",
        "speed",
        8,
    );
    // a cruise north from 89.9° reaches the pole in 11 km
    refused(
        "lat_deg = 89.9\nlon_deg = 0.0\nspeed_mps = 100.0",
        "[[segment]]\ntype = \"cruise\"\nduration_s = 600.0\n",
        "latitude",
        7,
    );
    // a segment with no IMU sample
    refused(
        s0,
        "[[segment]]\ntype = \"cruise\"\nduration_s = 1e-12\n",
        "shorter than one IMU sample",
        10,
    );
}

#[test]
fn a_return_to_rest_is_not_rejected_by_rounding() {
    // 0.1 × 3 − 0.3 × 1 = 5.55e-17 in floating point
    let scn = scenario(
        "lat_deg = 37.5\nlon_deg = 127.0",
        "[[segment]]\ntype = \"accelerate\"\naccel_mps2 = 0.1\nduration_s = 3.0\n[[segment]]\ntype = \"accelerate\"\naccel_mps2 = -0.3\nduration_s = 1.0\n[[segment]]\ntype = \"static\"\nduration_s = 2.0\n",
    )
    .unwrap();
    let k = scn.trajectory.kinematics(5.0, 5.0);
    assert_eq!(k.v_n_mps.norm(), 0.0);
}

#[test]
fn every_builtin_is_inside_the_envelope() {
    for b in sdins_sim::scenario::BUILTINS {
        Scenario::from_toml(b.toml, b.name).unwrap();
    }
}

static ACCEPTED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

fn segment_text(kind: u8, x: f64, dur: f64) -> String {
    let body = match kind {
        0 => "type = \"cruise\"".to_string(),
        1 => format!("type = \"accelerate\"\naccel_mps2 = {x:?}"),
        2 => format!("type = \"turn\"\nrate_dps = {x:?}"),
        3 => format!("type = \"turn\"\nprofile = \"smooth\"\nangle_deg = {x:?}"),
        4 => format!("type = \"sturn\"\namplitude_dps = {x:?}"),
        _ => format!("type = \"climb\"\nto_climb_rate_mps = {x:?}"),
    };
    format!("[[segment]]\n{body}\nduration_s = {dur:?}\n")
}

fn magnitude() -> impl Strategy<Value = f64> {
    prop_oneof![
        -50.0..50.0_f64,
        -5000.0..5000.0_f64,
        Just(1e300),
        Just(-1e300),
        Just(0.0),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, rng_seed: proptest::test_runner::RngSeed::Fixed(16), ..ProptestConfig::default() })]

    /// Random scenarios with extreme values: refused with a located error, or every truth
    /// and navigation output finite and the truth inside the envelope (height, latitude,
    /// speed) at every sample.
    #[test]
    fn random_scenarios_are_refused_or_finite_and_inside(
        lat in prop_oneof![-89.999..89.999_f64, Just(89.99), Just(-89.99)],
        h in prop_oneof![-900.0..90_000.0_f64, Just(-1000.0), Just(100_000.0)],
        speed in prop_oneof![0.0..400.0_f64, Just(2999.0)],
        yaw in -180.0..180.0_f64,
        segs in proptest::collection::vec((0u8..6, magnitude(), 1u32..20), 1..4),
        overlay in proptest::option::of((0u8..3, 0.01..20.0_f64, 0.1..30.0_f64)),
    ) {
        let start = format!("lat_deg = {lat}\nlon_deg = 10.0\nh_m = {h}\nspeed_mps = {speed}\nyaw_deg = {yaw}");
        let mut body = String::new();
        for (k, x, d) in &segs {
            body += &segment_text(*k, *x, *d as f64);
        }
        if let Some((k, a, f)) = overlay {
            body += &match k {
                0 => format!("[[overlay]]\ntype = \"coning\"\nhalf_angle_deg = {}\nfreq_hz = {f}\n", a.min(80.0)),
                1 => format!("[[overlay]]\ntype = \"vibration\"\naccel_amp_mps2 = {}\nfreq_hz = {f}\n", a * 10.0),
                _ => format!("[[overlay]]\ntype = \"sculling\"\nangle_amp_deg = {a}\naccel_amp_mps2 = {a}\nfreq_hz = {f}\n"),
            };
        }
        match scenario(&start, &body) {
            Err(ScenarioError::Invalid { file, line, message, .. }) => {
                if std::env::var_os("SDINS_PRINT").is_some() { eprintln!("refused: {message}"); }
                prop_assert_eq!(file, "hostile.toml");
                prop_assert!(line >= 1);
            }
            Err(e) => prop_assert!(false, "unlocated error {e:?}"),
            Ok(scn) => {
                ACCEPTED.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let env = Envelope::DEFAULT;
                let cfg = TruthConfig {
                    earth: scn.nav.earth.model(),
                    dt_s: scn.imu.dt_s(),
                    lat0_rad: scn.start.lat_rad,
                    lon0_rad: scn.start.lon_rad,
                    h0_m: scn.start.h_m,
                    substeps: scn.nav.substeps,
                };
                for s in TruthGenerator::new(&scn.trajectory, cfg) {
                    let ok = s.lat_rad.is_finite() && s.h_m.is_finite()
                        && s.v_n_mps.iter().all(|v| v.is_finite())
                        && s.inc.dtheta_b_rad.iter().chain(&s.inc.dv_b_mps).all(|v| v.is_finite());
                    prop_assert!(ok, "non-finite truth at t = {}", s.t_s);
                    // the check samples at ≥ 16 points per period: allow its 1.9 % and the
                    // trapezoidal position integration a metre
                    prop_assert!(s.lat_rad.abs() <= env.max_abs_lat_rad + 1e-6, "lat {}", s.lat_rad);
                    prop_assert!(s.h_m >= env.min_h_m - 1.0 && s.h_m <= env.max_h_m + 1.0, "h {}", s.h_m);
                    prop_assert!(s.v_n_mps.norm() <= env.max_speed_mps * 1.02, "speed");
                }
                if std::env::var_os("SDINS_PRINT").is_some() { eprintln!("accepted {}", ACCEPTED.load(std::sync::atomic::Ordering::Relaxed)); }
                let opts = RunOptions {
                    algos: vec![AlgorithmSpec::new(AlgorithmKind::SongLeeComplete, 2)],
                    vertical_hold: false,
                    every_s: None,
                    until_s: None,
                    sensor_run: None,
                };
                let mut finite = true;
                run(&scn, &opts, |_, st, _, e| {
                    finite &= st.lat_rad.is_finite() && st.h_m.is_finite()
                        && e.pos_err_ned_m.iter().chain(&e.att_err_rad).all(|v| v.is_finite());
                }, |_, _| {}).unwrap();
                prop_assert!(finite, "non-finite navigation");
            }
        }
    }
}
