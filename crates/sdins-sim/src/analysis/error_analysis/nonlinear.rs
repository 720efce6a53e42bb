//! Nonlinear free-inertial reference runs for the error analysis: a stationary vehicle
//! navigated by a full strapdown mechanization with injected sensor biases (docs/validation.md
//! §"error propagation" T9).
//!
//! The exact truth increments of a stationary scenario at latitude L are corrupted by an
//! [`ImuErrorModel`] with fixed body-frame biases (`gyro_bias_dph`, `accel_bias_ug`,
//! measured − true, docs/theory/imu-errors.md §"IMU error model") and navigated by one algorithm
//! (default `songlee-complete`) with the vertical channel **held** to the truth (height and v_D
//! replaced after every update, as in the stationary closed form). An initial attitude error φ0
//! (convention G) starts the navigation from `Ĉ_b^n = exp([φ0×]) C_b^n`.
//!
//! Earth: by default a **spherical** earth of radius R0 with constant gravity g and
//! Earth rate Ω, i.e. exactly the constants of the closed form ([`SchulerParams`]), so
//! that a difference between the two is the closed form's approximation and not a
//! different planet; [`NonlinearRun::earth`] can be set to WGS-84 instead (radii R_M,
//! R_N ≠ R0 shift the Schuler periods by ≈ 0.1 % per channel).
//!
//! The errors are those of [`crate::nav::pipeline::nav_error`] (position in metres NED with the
//! model's radii, attitude ε with `C_alg C_trueᵀ = I + [ε×]`).

use super::periods::SchulerParams;
use crate::nav::pipeline::{nav_error, NavError};
use crate::scenario::{Scenario, ScenarioError};
use crate::sensors::imu_error::{ImuErrorModel, ImuErrorState};
use crate::truth::{TruthConfig, TruthGenerator};
use sdins_core::coning::Increment;
use sdins_core::earth::{EarthModel, Gravity};
use sdins_core::math::dcm_from_rotvec;
use sdins_core::nav::{AlgorithmSpec, AnyMechanization, Mechanization};
use sdins_core::Vec3;

/// Spherical earth with the closed form's constants: a = R0, f = 0, constant g, Ω.
pub fn spherical_earth(p: &SchulerParams) -> EarthModel {
    EarthModel {
        a_m: p.r0_m,
        f: 0.0,
        e2: 0.0,
        omega_ie_rps: p.omega_ie_rps,
        gravity: Gravity::Constant { g_mps2: p.g_mps2 },
        transport: true,
    }
}

/// A stationary nonlinear free-inertial run.
#[derive(Clone, Debug, PartialEq)]
pub struct NonlinearRun {
    /// latitude \[rad\]
    pub lat_rad: f64,
    /// true attitude roll, pitch, yaw \[deg\] (body = NED: zeros)
    pub rpy_deg: [f64; 3],
    /// body gyro bias \[°/h\]
    pub gyro_bias_dph: [f64; 3],
    /// body accelerometer bias \[μg\]
    pub accel_bias_ug: [f64; 3],
    /// initial attitude error φ0 (convention G) \[rad\]
    pub phi0: Vec3,
    /// earth model of truth and navigation
    pub earth: EarthModel,
    /// IMU rate \[Hz\]
    pub rate_hz: f64,
    /// the algorithm (its `samples` is N)
    pub algo: AlgorithmSpec,
    /// duration \[s\]
    pub duration_s: f64,
    /// output spacing \[s\] (rounded to whole updates)
    pub every_s: f64,
}

impl NonlinearRun {
    /// Body = NED at `lat_rad`, spherical earth of `params`, 20 Hz, `songlee-complete`
    /// with N = 2 (10 Hz updates), output every 60 s.
    pub fn stationary(lat_rad: f64, params: &SchulerParams, duration_s: f64) -> Self {
        NonlinearRun {
            lat_rad,
            rpy_deg: [0.0; 3],
            gyro_bias_dph: [0.0; 3],
            accel_bias_ug: [0.0; 3],
            phi0: Vec3::zeros(),
            earth: spherical_earth(params),
            rate_hz: 20.0,
            algo: AlgorithmSpec::new(sdins_core::nav::AlgorithmKind::SongLeeComplete, 2),
            duration_s,
            every_s: 60.0,
        }
    }

    /// Run; one [`NavError`] per output epoch, the first at t = 0.
    pub fn run(&self) -> Result<Vec<NavError>, ScenarioError> {
        Ok(self
            .run_cancellable(&crate::cancel::CancelToken::new())?
            .unwrap_or_default())
    }

    /// [`Self::run`], polling `token` every [`crate::cancel::POLL_EVERY_SAMPLES`] updates;
    /// `Ok(None)` when it was set.
    pub fn run_cancellable(
        &self,
        token: &crate::cancel::CancelToken,
    ) -> Result<Option<Vec<NavError>>, ScenarioError> {
        let text = format!(
            "name = \"nonlinear-stationary\"\n[start]\nlat_deg = {}\nlon_deg = 127.0\nroll_deg = {}\npitch_deg = {}\nyaw_deg = {}\n[imu]\nrate_hz = {}\n[[segment]]\ntype = \"static\"\nduration_s = {}\n",
            self.lat_rad.to_degrees(),
            self.rpy_deg[0],
            self.rpy_deg[1],
            self.rpy_deg[2],
            self.rate_hz,
            self.duration_s
        );
        let scn = Scenario::from_toml(&text, "<nonlinear stationary>")?;
        let dt = scn.imu.dt_s();
        let cfg = TruthConfig {
            earth: self.earth,
            dt_s: dt,
            lat0_rad: scn.start.lat_rad,
            lon0_rad: scn.start.lon_rad,
            h0_m: scn.start.h_m,
            substeps: scn.nav.substeps,
        };
        let mut truth = TruthGenerator::new(&scn.trajectory, cfg);
        let mut init = truth.initial_state();
        let c_true0 = init.c_b_n;
        init.c_b_n = dcm_from_rotvec(&self.phi0) * init.c_b_n;
        let n = self.algo.samples.max(1);
        let mut mech = AnyMechanization::new(&self.algo, self.earth, dt, &init);
        let model = ImuErrorModel {
            gyro_bias_dph: self.gyro_bias_dph,
            accel_bias_ug: self.accel_bias_ug,
            ..ImuErrorModel::default()
        };
        let mut sensor = ImuErrorState::new(&model, 0, 0).map_err(|e| ScenarioError::Invalid {
            file: "<nonlinear stationary>".into(),
            line: 0,
            key: "imu.errors".into(),
            message: e.to_string(),
        })?;
        let every = ((self.every_s / (dt * n as f64)).round() as u64).max(1);
        let mut out = Vec::new();
        let t0 = crate::truth::TruthSample::new(
            0.0,
            Increment::default(),
            init.lat_rad,
            init.lon_rad,
            init.h_m,
            init.v_n_mps,
            c_true0,
        );
        out.push(nav_error(&self.earth, &mech.state(), &t0));
        let mut buf = Vec::with_capacity(n);
        let mut k: u64 = 0;
        loop {
            buf.clear();
            let mut end = None;
            for _ in 0..n {
                if let Some(s) = truth.next() {
                    buf.push(sensor.apply(&s.inc, dt));
                    end = Some(s);
                }
            }
            let Some(end) = end else { break };
            if buf.len() < n {
                break;
            }
            mech.update(&buf);
            mech.hold_vertical(end.h_m, end.v_n_mps.z);
            k += 1;
            if k.is_multiple_of(crate::cancel::POLL_EVERY_SAMPLES) && token.is_cancelled() {
                return Ok(None);
            }
            if k.is_multiple_of(every) {
                out.push(nav_error(&self.earth, &mech.state(), &end));
            }
        }
        Ok(Some(out))
    }
}
