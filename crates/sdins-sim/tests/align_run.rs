//! `align_run::align`: stationary-only methods refuse a moving scenario (naming the time
//! and speed) and only warn on an input without truth; i0 accepts the disturbed-base
//! built-ins.
#![allow(clippy::unwrap_used)]
use sdins_sim::align::run::{align, AlignInput, AlignMethod, AlignOptions, AlignRunError};
use sdins_sim::cancel::CancelToken;
use sdins_sim::scenario::Scenario;

/// 100 s static, then 1 m/s² along track: the speed passes 0.5 m/s at t = 100.5 s.
const MOVING: &str = r#"
name = "starts-moving"
[start]
lat_deg = 37.5
lon_deg = 127.0
[imu]
rate_hz = 20.0
grade = "aviation"
[[segment]]
type = "static"
duration_s = 100.0
[[segment]]
type = "accelerate"
accel_mps2 = 1.0
duration_s = 20.0
"#;

fn moving() -> AlignInput {
    let scn = Scenario::from_toml(MOVING, "<test>").unwrap();
    AlignInput::from_scenario(&scn, 0, None).unwrap()
}

#[test]
fn stationary_methods_refuse_a_moving_scenario() {
    let inp = moving();
    for method in [
        AlignMethod::Fine,
        AlignMethod::Multiheading,
        AlignMethod::Coarse2,
    ] {
        let o = AlignOptions {
            method,
            // coarse uses only its window: make it reach into the motion
            window_s: 110.0,
            ..AlignOptions::default()
        };
        match align(&inp, &o, &CancelToken::new()) {
            Err(e @ AlignRunError::Moving { t_s, speed_mps, .. }) => {
                // first sample above 0.5 m/s: t = 100 + 0.5 s (1 m/s², 20 Hz grid)
                assert!((t_s - 100.55).abs() < 0.051, "{t_s}");
                assert!(speed_mps > 0.5 && speed_mps < 0.6, "{speed_mps}");
                let m = e.to_string();
                assert!(m.contains("--method i0") && m.contains("t = 100."), "{m}");
            }
            other => panic!("{method:?}: {other:?}"),
        }
    }
    // the same record cut before the motion is accepted
    let o = AlignOptions {
        method: AlignMethod::Coarse2,
        window_s: 60.0,
        ..AlignOptions::default()
    };
    let r = align(&inp, &o, &CancelToken::new()).unwrap();
    assert!(r.warnings.is_empty());
    // i0 is built for a disturbed base: it never refuses
    let o = AlignOptions {
        method: AlignMethod::I0,
        window_s: 110.0,
        ..AlignOptions::default()
    };
    assert!(align(&inp, &o, &CancelToken::new()).is_ok());
}

/// Without truth (as from a file) the same moving record only warns, once.
#[test]
fn input_without_truth_only_warns() {
    let mut inp = moving();
    inp.truth_speed_mps = None;
    inp.truth_c_b_n = None;
    let o = AlignOptions {
        method: AlignMethod::Coarse2,
        window_s: 120.0,
        ..AlignOptions::default()
    };
    let r = align(&inp, &o, &CancelToken::new()).unwrap();
    assert_eq!(r.warnings.len(), 1, "{:?}", r.warnings);
    assert!(r.warnings[0].contains("--method i0"));
    // a stationary record does not warn
    let scn = Scenario::load("alignment").unwrap();
    let mut inp = AlignInput::from_scenario(&scn, 0, None).unwrap();
    inp.truth_speed_mps = None;
    let r = align(
        &inp,
        &AlignOptions {
            method: AlignMethod::Coarse2,
            ..AlignOptions::default()
        },
        &CancelToken::new(),
    )
    .unwrap();
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

/// The disturbed-base built-ins still align with i0 (docs/alignment_i0.md: heading within
/// a few mrad after 300 s / 100 s).
#[test]
fn disturbed_base_builtins_align_with_i0() {
    for (name, window_s) in [("moored-ship", 300.0), ("rocking-car", 100.0)] {
        let scn = Scenario::load(name).unwrap();
        let inp = AlignInput::from_scenario(&scn, 0, None).unwrap();
        let o = AlignOptions {
            method: AlignMethod::I0,
            window_s,
            ..AlignOptions::default()
        };
        let r = align(&inp, &o, &CancelToken::new()).unwrap();
        let phi = r.phi_true.unwrap();
        assert!(phi.amax() < 1e-2, "{name}: {phi:?}");
    }
}

#[test]
fn cancelled_token_stops() {
    let inp = moving();
    let t = CancelToken::new();
    t.cancel();
    let o = AlignOptions {
        method: AlignMethod::I0,
        ..AlignOptions::default()
    };
    assert_eq!(align(&inp, &o, &t), Err(AlignRunError::Cancelled));
}
