//! `sdins truth` and Python `sdins.truth` as one library call: the exact truth of a
//! scenario as rows, reported to a [`TruthObserver`] (the CLI writes `truth.csv` and
//! `imu.csv`, Python fills arrays).
//!
//! * IMU rows: every sample, `(t, Δθ, Δv)` with `t` the sample's end; sensed at the IMU's
//!   lever arm and mounting when the scenario has a `[mounting]` IMU.
//! * Truth rows: the initial state at `t = 0`, then every `every`-th sample, at the vehicle
//!   reference point.
//! * Times carry `t_offset_s` (the first reference time of a recorded trajectory).

use crate::cancel::{CancelToken, Cancelled};
use crate::nav::options::OptionError;
use crate::scenario::Scenario;
use crate::truth::{TruthGenerator, TruthSample};
use sdins_core::coning::Increment;
use sdins_core::math::{Mat3, Vec3};

/// What a front end asks of the truth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TruthRequest {
    /// a truth row every `every` samples (≥ 1)
    pub every: u64,
    /// stop after this time \[s\] (None: the whole scenario)
    pub until_s: Option<f64>,
    /// added to every time \[s\]
    pub t_offset_s: f64,
    /// whether IMU rows are wanted
    pub imu: bool,
}

impl Default for TruthRequest {
    fn default() -> Self {
        Self {
            every: 1,
            until_s: None,
            t_offset_s: 0.0,
            imu: true,
        }
    }
}

/// A validated truth request: what it will produce.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TruthPlan {
    /// the request
    pub request: TruthRequest,
    /// IMU samples to generate
    pub samples: u64,
    /// truth rows (the initial state included)
    pub rows: u64,
    /// whether the IMU rows are sensed at a mounted IMU (`[mounting]`)
    pub imu_mounted: bool,
}

/// A truth row: position, NED velocity and attitude of the vehicle reference point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TruthRow {
    /// time \[s\]
    pub t_s: f64,
    /// latitude \[rad\]
    pub lat_rad: f64,
    /// longitude \[rad\]
    pub lon_rad: f64,
    /// height \[m\]
    pub h_m: f64,
    /// NED velocity \[m/s\]
    pub v_n_mps: Vec3,
    /// attitude
    pub c_b_n: Mat3,
}

/// Receives the rows of a truth run.
pub trait TruthObserver {
    /// an IMU sample ending at `t_s`
    fn imu(&mut self, t_s: f64, inc: &Increment);
    /// a truth row
    fn row(&mut self, row: &TruthRow);
    /// progress: `done` of `total` samples, every 65 536 samples
    fn progress(&mut self, _done: u64, _total: u64) {}
}

/// Validate a request (messages name `--every` and `--until-s`).
pub fn plan(scn: &Scenario, req: TruthRequest) -> Result<TruthPlan, OptionError> {
    if req.every == 0 {
        return Err(OptionError::Bad("--every: must be at least 1".into()));
    }
    if let Some(u) = req.until_s {
        if !(u.is_finite() && u > 0.0) {
            return Err(OptionError::Bad(format!(
                "--until-s {u}: expected a positive number of seconds"
            )));
        }
    }
    let cfg = scn.truth_config();
    let mut samples = TruthGenerator::new(&scn.trajectory, cfg).len_samples();
    if let Some(u) = req.until_s {
        samples = samples.min((u / cfg.dt_s).round() as u64);
    }
    Ok(TruthPlan {
        request: req,
        samples,
        rows: 1 + samples / req.every,
        imu_mounted: scn.mounting.imu.is_some(),
    })
}

fn row_of(s: &TruthSample, t_offset_s: f64) -> TruthRow {
    TruthRow {
        t_s: s.t_s + t_offset_s,
        lat_rad: s.lat_rad,
        lon_rad: s.lon_rad,
        h_m: s.h_m,
        v_n_mps: s.v_n_mps,
        c_b_n: s.c_b_n,
    }
}

/// Generate the truth of `scn` by `plan`, reporting rows to `obs`; polls `cancel` every
/// 65 536 samples.
pub fn run(
    scn: &Scenario,
    plan: &TruthPlan,
    cancel: &CancelToken,
    obs: &mut impl TruthObserver,
) -> Result<(), Cancelled> {
    let req = plan.request;
    let mut gen = TruthGenerator::new(&scn.trajectory, scn.truth_config());
    // the initial row stays at the vehicle reference point, as every truth row
    let init = gen.initial_state();
    if let Some(m) = scn.mounting.imu {
        gen = gen.with_mount(m);
    }
    obs.row(&TruthRow {
        t_s: req.t_offset_s,
        lat_rad: init.lat_rad,
        lon_rad: init.lon_rad,
        h_m: init.h_m,
        v_n_mps: init.v_n_mps,
        c_b_n: init.c_b_n,
    });
    for (k, s) in gen.take(plan.samples as usize).enumerate() {
        if req.imu {
            obs.imu(s.t_s + req.t_offset_s, &s.inc);
        }
        if (k as u64 + 1).is_multiple_of(req.every) {
            obs.row(&row_of(&s, req.t_offset_s));
        }
        if k % 65_536 == 0 {
            obs.progress(k as u64, plan.samples);
            cancel.check()?;
        }
    }
    Ok(())
}
