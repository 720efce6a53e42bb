//! Zero-velocity detection rates of a scenario: the fusion loop's stationarity detector
//! ([`crate::fusion::detector`]) run on the scenario's IMU samples (the run's errors) and
//! compared with the truth, counted per IMU epoch
//! (docs/validation.md §"Zero-velocity detection").
//!
//! An epoch is at rest when the truth's speed is below 1 mm/s. Epochs within ±W samples
//! (the detector window) of a truth transition are excluded: there the window mixes rest
//! and motion by construction. The detector starts from the filter's prior: the known
//! biases removed, the residual-bias σ's the prior σ's (the engine refines both as the
//! filter converges), the earth rate at the true attitude.

use crate::fusion::detector::{AnyDetector, DetectorError, DetectorSettings};
use crate::fusion::simulated::noise_from_model;
use crate::scenario::Scenario;
use crate::sensors::imu_error::ImuErrorState;
use crate::truth::TruthGenerator;

/// Speed below which the truth is at rest \[m/s\].
pub const REST_SPEED_MPS: f64 = 1e-3;

/// What the detector did on one run of a scenario.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DetectionRates {
    /// window \[samples\]
    pub window: usize,
    /// the threshold γ
    pub threshold: f64,
    /// moving epochs counted
    pub moving: u64,
    /// of those, declared at rest
    pub moving_declared_rest: u64,
    /// resting epochs counted
    pub rest: u64,
    /// of those, declared at rest
    pub rest_detected: u64,
    /// the largest truth speed at an epoch declared at rest (all epochs, none excluded)
    /// \[m/s\]
    pub max_speed_declared_rest_mps: f64,
}

impl DetectionRates {
    /// Share of the moving epochs declared at rest.
    pub fn false_rest_rate(&self) -> f64 {
        self.moving_declared_rest as f64 / self.moving.max(1) as f64
    }
    /// Share of the resting epochs detected.
    pub fn detection_rate(&self) -> f64 {
        self.rest_detected as f64 / self.rest.max(1) as f64
    }
}

/// Why the rates cannot be computed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DetectionError {
    /// The detector cannot be built.
    #[error(transparent)]
    Detector(#[from] DetectorError),
    /// The IMU error model is invalid.
    #[error("IMU: {0}")]
    Imu(String),
}

/// The rates of run `run` of `scn` (its IMU errors) with the detector `settings`.
pub fn detection_rates(
    scn: &Scenario,
    settings: &DetectorSettings,
    run: u64,
) -> Result<DetectionRates, DetectionError> {
    let earth = scn.nav.earth.model();
    let dt = scn.imu.dt_s();
    let (noise, s_ba, s_bg, known_ba, known_bg) = noise_from_model(&scn.imu.model);
    let gen = TruthGenerator::new(&scn.trajectory, scn.truth_config());
    let init = gen.initial_state();
    let mut det = AnyDetector::from_filter_noise(
        settings,
        &noise,
        dt,
        earth.gravity(init.lat_rad, init.h_m),
        &s_ba,
        &s_bg,
    )?;
    let omega_ie_n = earth.omega_ie_n(init.lat_rad);
    det.set_estimates(&known_ba, &known_bg, &init.c_b_n, &omega_ie_n)
        .map_err(|e| DetectionError::Detector(DetectorError::Core(format!("{e}"))))?;
    let mut sensor = ImuErrorState::new(&scn.imu.model, scn.imu.seed, run)
        .map_err(|e| DetectionError::Imu(e.to_string()))?;
    let w = det.window();
    // per epoch: truth at rest, declared at rest
    let mut truth_rest = Vec::new();
    let mut declared = Vec::new();
    let mut max_speed = 0.0f64;
    for (k, ts) in gen.enumerate() {
        let inc = sensor.apply(&ts.inc, dt);
        if k % w == 0 {
            let _ = det.set_estimates(&known_ba, &known_bg, &ts.c_b_n, &omega_ie_n);
        }
        let speed = ts.v_n_mps.norm();
        let d = matches!(det.push(&inc), Ok(Some(true)));
        if d {
            max_speed = max_speed.max(speed);
        }
        truth_rest.push(speed < REST_SPEED_MPS);
        declared.push(d);
    }
    // exclude ±W epochs around each truth transition
    let n = truth_rest.len();
    let mut excluded = vec![false; n];
    for k in 1..n {
        if truth_rest[k] != truth_rest[k - 1] {
            for e in excluded
                .iter_mut()
                .take((k + w).min(n))
                .skip(k.saturating_sub(w))
            {
                *e = true;
            }
        }
    }
    let mut r = DetectionRates {
        window: w,
        threshold: det.threshold(),
        moving: 0,
        moving_declared_rest: 0,
        rest: 0,
        rest_detected: 0,
        max_speed_declared_rest_mps: max_speed,
    };
    // the first W − 1 epochs have no full window
    for k in (w - 1)..n {
        if excluded[k] {
            continue;
        }
        if truth_rest[k] {
            r.rest += 1;
            r.rest_detected += u64::from(declared[k]);
        } else {
            r.moving += 1;
            r.moving_declared_rest += u64::from(declared[k]);
        }
    }
    Ok(r)
}
