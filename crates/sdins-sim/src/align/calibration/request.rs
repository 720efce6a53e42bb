//! `sdins calibrate` and Python `sdins.calibrate` as one library call: a scenario's schedule
//! calibrated on its simulated IMU (one run or a Monte Carlo) or on a recorded IMU file,
//! with the parameter rows and the `--json` summary both front ends print.

use super::run::{
    calibrate_recorded, calibrate_scenario, monte_carlo, CalibrationError, CalibrationRun,
    DrawSpec, GroupMax, MonteCarloSummary,
};
use super::table::{rows, triad_rows, ParamRow};
use super::N_PARAMS;
use crate::cancel::CancelToken;
use crate::io::imu_file::{read_imu_file, ImuFileError, ImuFormat};
use crate::scenario::Scenario;
use crate::sensors::imu_error::{DPH, DPSH, UG, UG_PER_SQRT_HZ};
use std::path::PathBuf;

/// Largest accepted number of Monte Carlo runs.
pub const MAX_RUNS: usize = 100_000;

/// A calibration as a front end gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct CalibrateRequest {
    /// a recorded IMU file of the schedule (None: simulate the scenario's IMU)
    pub imu: Option<PathBuf>,
    /// its format
    pub imu_format: ImuFormat,
    /// error-model run index of a single run
    pub run: u64,
    /// Monte Carlo runs (1: the single run `run`)
    pub runs: usize,
    /// drawn scale factors and misalignments (None: the scenario's own)
    pub draw: Option<DrawSpec>,
}

impl Default for CalibrateRequest {
    fn default() -> Self {
        Self {
            imu: None,
            imu_format: ImuFormat::Auto,
            run: 0,
            runs: 1,
            draw: Some(DrawSpec::DEFAULT),
        }
    }
}

/// What a calibration estimated.
#[derive(Clone, Debug)]
pub struct CalibrateResult {
    /// the 24 parameters with 1σ (and truth for simulations)
    pub rows: Vec<ParamRow>,
    /// samples used
    pub samples: u64,
    /// the (first) simulated run
    pub first: Option<CalibrationRun>,
    /// every run of a Monte Carlo (empty otherwise)
    pub all: Vec<CalibrationRun>,
    /// the Monte Carlo summary
    pub mc: Option<MonteCarloSummary>,
    /// one line on the estimate's quality (NEES, or the residual noise densities)
    pub note: String,
    /// warnings (reader warnings, unmodelled terms)
    pub warnings: Vec<String>,
}

/// Run a calibration of `scn` (messages name `--runs`, `--imu`, the draw options).
pub fn calibrate(
    scn: &Scenario,
    req: &CalibrateRequest,
    cancel: &CancelToken,
) -> Result<CalibrateResult, CalibrationError> {
    if req.runs == 0 || req.runs > MAX_RUNS {
        return Err(CalibrationError::Option(format!(
            "--runs: {} must be in 1..={MAX_RUNS}",
            req.runs
        )));
    }
    if let Some(d) = &req.draw {
        d.validate()?;
    }
    if let Some(path) = &req.imu {
        if req.runs != 1 {
            return Err(CalibrationError::Option(
                "--runs: a recorded IMU file is one calibration (Monte Carlo needs a simulated IMU)"
                    .into(),
            ));
        }
        let data = read_imu_file(path, req.imu_format).map_err(|e| match e {
            ImuFileError::Io { .. } => CalibrationError::ImuIo(e.to_string()),
            other => CalibrationError::ImuFile(other.to_string()),
        })?;
        let (g, a) = calibrate_recorded(scn, &data.increments, data.dt_s, cancel)?;
        let mut rows = triad_rows(&g, None, 'g', (DPH, "deg/h"));
        rows.extend(triad_rows(&a, None, 'a', (UG, "ug")));
        let resid = |v: sdins_core::math::Vec3, unit: f64| {
            format!("{:.4}, {:.4}, {:.4}", v.x / unit, v.y / unit, v.z / unit)
        };
        let note = format!(
            "{}: residual noise densities: gyro {} °/√h, accelerometer {} μg/√Hz (the 1σ uses {})",
            path.display(),
            resid(g.density_residual, DPSH),
            resid(a.density_residual, UG_PER_SQRT_HZ),
            if g.density == g.density_residual {
                "these"
            } else {
                "the scenario's grade"
            }
        );
        return Ok(CalibrateResult {
            rows,
            samples: g.samples,
            first: None,
            all: Vec::new(),
            mc: None,
            note,
            warnings: data.warnings,
        });
    }
    let (first, all, mc) = if req.runs == 1 {
        (
            calibrate_scenario(scn, req.draw.as_ref(), req.run, cancel)?,
            Vec::new(),
            None,
        )
    } else {
        let (all, s) = monte_carlo(scn, req.draw.as_ref(), req.runs, cancel)?;
        (all[0].clone(), all, Some(s))
    };
    let mut warnings = Vec::new();
    if !first.unmodelled.is_empty() {
        warnings.push(format!(
            "the IMU model has terms the estimator does not model ({}): its 1σ is optimistic",
            first.unmodelled.join(", ")
        ));
    }
    let note = format!(
        "run {}: NEES {:.2} (χ²(24): mean 24, 95 % below 36.4)",
        first.run, first.nees
    );
    Ok(CalibrateResult {
        rows: rows(&first),
        samples: first.gyro.samples,
        first: Some(first),
        all,
        mc,
        note,
        warnings,
    })
}

fn group_json(g: &GroupMax, bias_unit: &str) -> serde_json::Value {
    serde_json::json!({
        format!("bias_{bias_unit}"): g.bias,
        "scale_ppm": g.scale_ppm,
        "misalignment_mrad": g.misalignment_mrad,
    })
}

impl CalibrateResult {
    /// The summary of `sdins calibrate --json` (and of Python `sdins.calibrate`).
    pub fn summary_json(&self, scn: &Scenario) -> serde_json::Value {
        let params: Vec<serde_json::Value> = self
            .rows
            .iter()
            .map(|r| {
                serde_json::json!({
                    "name": r.name, "unit": r.unit, "estimate": r.estimate,
                    "sigma": r.sigma, "truth": r.truth,
                })
            })
            .collect();
        let first = self.first.as_ref();
        let mut v = serde_json::json!({
            "scenario": scn.name,
            "samples": self.samples,
            "dt_s": scn.imu.dt_s(),
            "run": first.map(|f| f.run),
            "nees": first.map(|f| f.nees),
            "nees_dof": N_PARAMS,
            "unmodelled_terms": first.map_or(Vec::new(), |f| f.unmodelled.clone()),
            "parameters": params,
        });
        if let Some(m) = &self.mc {
            v["monte_carlo"] = serde_json::json!({
                "runs": m.runs,
                "mean_nees": m.mean_nees,
                "nees_band_95": [m.nees_band.0, m.nees_band.1],
                "gyro_max_abs_error": group_json(&m.gyro_max, "dph"),
                "accel_max_abs_error": group_json(&m.accel_max, "ug"),
            });
        }
        v
    }
}
