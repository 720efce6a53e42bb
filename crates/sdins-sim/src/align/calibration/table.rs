//! The 24 parameters of a calibration as named rows with units, estimate, 1σ and (for
//! simulations) the truth: the one layout of the CLI's table, CSV and JSON.

use super::estimate::TriadEstimate;
use super::run::{CalibrationRun, TriadTruth};
use crate::sensors::imu_error::{DPH, MRAD, PPM, UG};
use serde::Serialize;

/// One parameter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParamRow {
    /// name: `bg_x` (gyro bias), `sg_x` (gyro scale factor), `mg_xy` (gyro
    /// misalignment: output x per true y), `ba_*`, `sa_*`, `ma_*` for the accelerometers
    pub name: String,
    /// unit of the numbers (`deg/h`, `ug`, `ppm`, `mrad`)
    pub unit: &'static str,
    /// estimate
    pub estimate: f64,
    /// 1σ of the estimate
    pub sigma: f64,
    /// true value (simulations)
    pub truth: Option<f64>,
}

impl ParamRow {
    /// `(estimate − truth)/σ`, if the truth is known.
    pub fn normalised_error(&self) -> Option<f64> {
        self.truth.map(|t| (self.estimate - t) / self.sigma)
    }
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// Rows of one triad: bias, scale factors, misalignments (row-major, off-diagonal).
pub fn triad_rows(
    est: &TriadEstimate,
    truth: Option<&TriadTruth>,
    letter: char,
    bias_unit: (f64, &'static str),
) -> Vec<ParamRow> {
    let sb = est.bias_sigma();
    let sk = est.k_sigma();
    let mut out = Vec::with_capacity(12);
    for i in 0..3 {
        out.push(ParamRow {
            name: format!("b{letter}_{}", AXES[i]),
            unit: bias_unit.1,
            estimate: est.bias[i] / bias_unit.0,
            sigma: sb[i] / bias_unit.0,
            truth: truth.map(|t| t.bias[i] / bias_unit.0),
        });
    }
    for i in 0..3 {
        out.push(ParamRow {
            name: format!("s{letter}_{}", AXES[i]),
            unit: "ppm",
            estimate: est.k[(i, i)] / PPM,
            sigma: sk[(i, i)] / PPM,
            truth: truth.map(|t| t.k[(i, i)] / PPM),
        });
    }
    for i in 0..3 {
        for j in (0..3).filter(|&j| j != i) {
            out.push(ParamRow {
                name: format!("m{letter}_{}{}", AXES[i], AXES[j]),
                unit: "mrad",
                estimate: est.k[(i, j)] / MRAD,
                sigma: sk[(i, j)] / MRAD,
                truth: truth.map(|t| t.k[(i, j)] / MRAD),
            });
        }
    }
    out
}

/// All 24 rows of a simulated run: gyro (°/h) then accelerometer (μg).
pub fn rows(run: &CalibrationRun) -> Vec<ParamRow> {
    let mut r = triad_rows(&run.gyro, Some(&run.gyro_truth), 'g', (DPH, "deg/h"));
    r.extend(triad_rows(
        &run.accel,
        Some(&run.accel_truth),
        'a',
        (UG, "ug"),
    ));
    r
}
