//! Simulated calibration runs: exact truth of a schedule, IMU errors with drawn scale
//! factors and misalignments, the least-squares estimate and its normalised error
//! (docs/theory/calibration.md §4).

use super::estimate::{EstimateError, TriadAccumulator, TriadEstimate};
use crate::cancel::{CancelToken, Cancelled};
use crate::scenario::Scenario;
use crate::sensors::imu_error::{ImuErrorModel, ImuErrorModelError, ImuErrorState, MRAD, PPM};
use crate::truth::TruthGenerator;
use nalgebra::Matrix3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha20Rng;
use rayon::prelude::*;
use sdins_core::coning::Increment;
use sdins_core::math::Vec3;
use serde::Serialize;

/// Number of estimated parameters: per triad bias (3), scale factors (3) and
/// misalignments (6).
pub const N_PARAMS: usize = 24;

/// Per-run draw of scale factors and misalignments: magnitudes uniform in the ranges,
/// sign ±1 with equal probability, independently for every entry.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DrawSpec {
    /// scale-factor magnitude range \[ppm\]
    pub scale_ppm: (f64, f64),
    /// misalignment magnitude range \[mrad\]
    pub misalignment_mrad: (f64, f64),
}

impl DrawSpec {
    /// The ranges of docs/theory/calibration.md §4: 100–1000 ppm, 0.1–1 mrad.
    pub const DEFAULT: DrawSpec = DrawSpec {
        scale_ppm: (100.0, 1000.0),
        misalignment_mrad: (0.1, 1.0),
    };

    /// Largest drawn scale factor \[ppm\]: the estimator's small-error model.
    pub const MAX_SCALE_PPM: f64 = 1e5;
    /// Largest drawn misalignment \[mrad\]: the estimator's small-angle model.
    pub const MAX_MISALIGNMENT_MRAD: f64 = 100.0;

    /// Check both ranges: finite, `0 ≤ lo ≤ hi`, within the estimator's small-error model
    /// ([`Self::MAX_SCALE_PPM`], [`Self::MAX_MISALIGNMENT_MRAD`]).
    pub fn validate(&self) -> Result<(), CalibrationError> {
        for (key, (lo, hi), max, what) in [
            (
                "scale_ppm",
                self.scale_ppm,
                Self::MAX_SCALE_PPM,
                "small-error",
            ),
            (
                "misalignment_mrad",
                self.misalignment_mrad,
                Self::MAX_MISALIGNMENT_MRAD,
                "small-angle",
            ),
        ] {
            if !(lo.is_finite() && hi.is_finite() && 0.0 <= lo && lo <= hi) {
                return Err(CalibrationError::Draw {
                    key,
                    what: format!("range [{lo}, {hi}] must be finite with 0 ≤ lo ≤ hi"),
                });
            }
            if hi > max {
                return Err(CalibrationError::Draw {
                    key,
                    what: format!("{hi} is beyond the {what} model (at most {max})"),
                });
            }
        }
        Ok(())
    }

    /// The model with the drawn terms of run `run` replacing its scale factors and
    /// misalignments (ChaCha20 stream `1 000 003 + run` of `seed`, disjoint from the
    /// sensor-noise streams `6·run + c`).
    pub fn apply(&self, model: &ImuErrorModel, seed: u64, run: u64) -> ImuErrorModel {
        let mut rng = ChaCha20Rng::seed_from_u64(seed);
        rng.set_stream(1_000_003 + run);
        let mut draw = |(lo, hi): (f64, f64)| -> f64 {
            let m = lo + (hi - lo) * rng.gen::<f64>();
            if rng.gen::<bool>() {
                m
            } else {
                -m
            }
        };
        let mut m = model.clone();
        for sensor in 0..2 {
            let sf: [f64; 3] = core::array::from_fn(|_| draw(self.scale_ppm));
            let mut mis = [[0.0; 3]; 3];
            for (i, row) in mis.iter_mut().enumerate() {
                for (j, v) in row.iter_mut().enumerate() {
                    if i != j {
                        *v = draw(self.misalignment_mrad);
                    }
                }
            }
            if sensor == 0 {
                m.gyro_scale_ppm = sf;
                m.gyro_misalignment_mrad = mis;
            } else {
                m.accel_scale_ppm = sf;
                m.accel_misalignment_mrad = mis;
            }
        }
        m
    }
}

/// A calibration error.
#[derive(Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CalibrationError {
    /// The IMU error model is invalid.
    #[error("IMU error model: {0}")]
    Model(#[from] ImuErrorModelError),
    /// The estimate cannot be formed.
    #[error(transparent)]
    Estimate(#[from] EstimateError),
    /// A draw range is invalid.
    #[error("draw.{key}: {what}")]
    Draw {
        /// the key
        key: &'static str,
        /// what is wrong
        what: String,
    },
    /// `runs` is zero.
    #[error("runs must be at least 1")]
    NoRuns,
    /// A recorded IMU file does not fit the schedule.
    #[error("the IMU record does not fit the schedule: {0}")]
    Mismatch(String),
    /// An option is not usable (the message names it).
    #[error("{0}")]
    Option(String),
    /// The IMU file cannot be read as an IMU record (the reader's located message).
    #[error("{0}")]
    ImuFile(String),
    /// The IMU file cannot be read at all (an I/O failure).
    #[error("{0}")]
    ImuIo(String),
    /// Stopped through the cancel token.
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
}

/// The true parameters of one triad.
#[derive(Clone, Debug, PartialEq)]
pub struct TriadTruth {
    /// bias (constant part: fixed + turn-on) \[rad/s or m/s²\]
    pub bias: Vec3,
    /// `K = diag(scale) + misalignment` (dimensionless)
    pub k: Matrix3<f64>,
}

/// One simulated calibration.
#[derive(Clone, Debug, PartialEq)]
pub struct CalibrationRun {
    /// run index
    pub run: u64,
    /// gyro estimate (rad/s, rates)
    pub gyro: TriadEstimate,
    /// accelerometer estimate (m/s²)
    pub accel: TriadEstimate,
    /// true gyro parameters
    pub gyro_truth: TriadTruth,
    /// true accelerometer parameters
    pub accel_truth: TriadTruth,
    /// NEES of the 24-vector (χ²(24) for a consistent estimator)
    pub nees: f64,
    /// terms of the model the estimator does not model (its covariance ignores them)
    pub unmodelled: Vec<&'static str>,
}

/// Terms of `m` outside the estimator's model (bias, scale factor, misalignment, white
/// noise): they make the least-squares covariance optimistic.
pub fn unmodelled_terms(m: &ImuErrorModel) -> Vec<&'static str> {
    let nz = |v: &[f64]| v.iter().any(|x| *x != 0.0);
    let mut out = Vec::new();
    for (name, v) in [
        ("gyro_bias_gm_dph", &m.gyro_bias_gm_dph[..]),
        (
            "gyro_bias_instability_dph",
            &m.gyro_bias_instability_dph[..],
        ),
        ("gyro_rrw_dphpsh", &m.gyro_rrw_dphpsh[..]),
        ("gyro_scale_asym_ppm", &m.gyro_scale_asym_ppm[..]),
        (
            "gyro_g_sensitivity_dphpg",
            m.gyro_g_sensitivity_dphpg.as_flattened(),
        ),
        ("gyro_quantum_arcsec", &m.gyro_quantum_arcsec[..]),
        ("accel_bias_gm_ug", &m.accel_bias_gm_ug[..]),
        (
            "accel_bias_instability_ug",
            &m.accel_bias_instability_ug[..],
        ),
        ("accel_rrw_ugpsh", &m.accel_rrw_ugpsh[..]),
        ("accel_scale_asym_ppm", &m.accel_scale_asym_ppm[..]),
        ("accel_quantum_mps", &m.accel_quantum_mps[..]),
    ] {
        if nz(v) {
            out.push(name);
        }
    }
    if m.gyro_range_dps.is_some() {
        out.push("gyro_range_dps");
    }
    if m.accel_range_g.is_some() {
        out.push("accel_range_g");
    }
    out
}

/// White-noise densities of a model: gyro ARW \[rad/√s\], accelerometer VRW \[m/s/√s\].
pub fn noise_densities(m: &ImuErrorModel) -> (Vec3, Vec3) {
    use crate::sensors::imu_error::{DPSH, MPS_PER_SQRT_H, UG_PER_SQRT_HZ};
    (
        Vec3::from_fn(|i, _| m.gyro_arw_dpsh[i] * DPSH),
        Vec3::from_fn(|i, _| {
            (m.accel_vrw_ugpsqrthz[i] * UG_PER_SQRT_HZ).hypot(m.accel_vrw_mpsph[i] * MPS_PER_SQRT_H)
        }),
    )
}

/// The exact increments of a scenario's whole trajectory (polls `cancel` every 2048
/// samples).
pub fn truth_increments(scn: &Scenario, cancel: &CancelToken) -> Result<Vec<Increment>, Cancelled> {
    let gen = TruthGenerator::new(&scn.trajectory, scn.truth_config());
    let mut out = Vec::with_capacity(gen.len_samples() as usize);
    for (k, s) in gen.enumerate() {
        if k % 2048 == 0 {
            cancel.check()?;
        }
        out.push(s.inc);
    }
    Ok(out)
}

/// Densities for the covariance: the model's where it has white noise on every axis,
/// else `None` (the residual estimate is used).
fn densities_or_none(d: Vec3) -> Option<Vec3> {
    (d.min() > 0.0).then_some(d)
}

/// Calibrate from measured and exact increments (same length, period `dt_s`): the
/// least-squares estimate of both triads. `densities` = (gyro ARW \[rad/√s\], VRW
/// \[m/s/√s\]) for the covariance, `None` per triad to use the residual estimate.
pub fn estimate(
    exact: &[Increment],
    measured: &[Increment],
    dt_s: f64,
    densities: (Option<Vec3>, Option<Vec3>),
    cancel: &CancelToken,
) -> Result<(TriadEstimate, TriadEstimate), CalibrationError> {
    let mut g = TriadAccumulator::default();
    let mut a = TriadAccumulator::default();
    for (k, (x, y)) in exact.iter().zip(measured).enumerate() {
        if k % 4096 == 0 {
            cancel.check()?;
        }
        g.add(&(x.dtheta_b_rad / dt_s), &(y.dtheta_b_rad / dt_s));
        a.add(&(x.dv_b_mps / dt_s), &(y.dv_b_mps / dt_s));
    }
    Ok((
        g.solve("gyro", densities.0, dt_s)?,
        a.solve("accelerometer", densities.1, dt_s)?,
    ))
}

/// One simulated run on precomputed exact increments: corrupt them with `model` (with
/// the draw of `draw` for this run, if any) for (`seed`, `run`), estimate, and compare.
pub fn run_on_truth(
    exact: &[Increment],
    dt_s: f64,
    model: &ImuErrorModel,
    draw: Option<&DrawSpec>,
    seed: u64,
    run: u64,
    cancel: &CancelToken,
) -> Result<CalibrationRun, CalibrationError> {
    let model = match draw {
        Some(d) => {
            d.validate()?;
            d.apply(model, seed, run)
        }
        None => model.clone(),
    };
    let mut state = ImuErrorState::new(&model, seed, run)?;
    let (bg, ba) = state.constant_bias();
    let (dg, da) = noise_densities(&model);
    let mut g = TriadAccumulator::default();
    let mut a = TriadAccumulator::default();
    for (k, x) in exact.iter().enumerate() {
        if k % 4096 == 0 {
            cancel.check()?;
        }
        let y = state.apply(x, dt_s);
        g.add(&(x.dtheta_b_rad / dt_s), &(y.dtheta_b_rad / dt_s));
        a.add(&(x.dv_b_mps / dt_s), &(y.dv_b_mps / dt_s));
    }
    let gyro = g.solve("gyro", densities_or_none(dg), dt_s)?;
    let accel = a.solve("accelerometer", densities_or_none(da), dt_s)?;
    let k_of = |sf: &[f64; 3], mis: &[[f64; 3]; 3]| {
        Matrix3::from_fn(|i, j| mis[i][j] * MRAD + if i == j { sf[i] * PPM } else { 0.0 })
    };
    let gyro_truth = TriadTruth {
        bias: bg,
        k: k_of(&model.gyro_scale_ppm, &model.gyro_misalignment_mrad),
    };
    let accel_truth = TriadTruth {
        bias: ba,
        k: k_of(&model.accel_scale_ppm, &model.accel_misalignment_mrad),
    };
    let nees =
        gyro.nees(&gyro_truth.bias, &gyro_truth.k) + accel.nees(&accel_truth.bias, &accel_truth.k);
    Ok(CalibrationRun {
        run,
        gyro,
        accel,
        gyro_truth,
        accel_truth,
        nees,
        unmodelled: unmodelled_terms(&model),
    })
}

/// One simulated calibration of a scenario (its IMU model, seed and run index `run`).
pub fn calibrate_scenario(
    scn: &Scenario,
    draw: Option<&DrawSpec>,
    run: u64,
    cancel: &CancelToken,
) -> Result<CalibrationRun, CalibrationError> {
    let exact = truth_increments(scn, cancel)?;
    run_on_truth(
        &exact,
        scn.imu.dt_s(),
        &scn.imu.model,
        draw,
        scn.imu.seed,
        run,
        cancel,
    )
}

/// Calibrate a recorded IMU stream against the exact truth of a schedule scenario (its
/// site, start attitude and rotations): `measured` must have the scenario's sample period
/// (to 1e-6 relative) and one sample per truth sample, starting with the first dwell. The
/// covariance uses the scenario's white-noise densities where its model has them (a
/// `grade` or `[imu.errors]`), else the residual estimate.
pub fn calibrate_recorded(
    scn: &Scenario,
    measured: &[Increment],
    dt_s: f64,
    cancel: &CancelToken,
) -> Result<(TriadEstimate, TriadEstimate), CalibrationError> {
    let want_dt = scn.imu.dt_s();
    if !(dt_s.is_finite() && (dt_s - want_dt).abs() <= 1e-6 * want_dt) {
        return Err(CalibrationError::Mismatch(format!(
            "sample period {dt_s} s, the schedule's is {want_dt} s (imu.rate_hz = {})",
            scn.imu.rate_hz
        )));
    }
    let exact = truth_increments(scn, cancel)?;
    if measured.len() != exact.len() {
        return Err(CalibrationError::Mismatch(format!(
            "{} samples, the schedule has {} ({} s at {} Hz)",
            measured.len(),
            exact.len(),
            scn.duration_s(),
            scn.imu.rate_hz
        )));
    }
    let (dg, da) = noise_densities(&scn.imu.model);
    estimate(
        &exact,
        measured,
        want_dt,
        (densities_or_none(dg), densities_or_none(da)),
        cancel,
    )
}

/// Largest absolute errors of one parameter group over runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct GroupMax {
    /// bias \[°/h for gyros, μg for accelerometers\]
    pub bias: f64,
    /// scale factor \[ppm\]
    pub scale_ppm: f64,
    /// misalignment \[mrad\]
    pub misalignment_mrad: f64,
}

/// Monte Carlo summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MonteCarloSummary {
    /// number of runs
    pub runs: usize,
    /// mean NEES of the 24-vector
    pub mean_nees: f64,
    /// the two-sided 95 % band of the mean NEES, χ²(24·runs)/runs
    pub nees_band: (f64, f64),
    /// max |error| over runs and axes, gyro (bias in °/h)
    pub gyro_max: GroupMax,
    /// max |error| over runs and axes, accelerometer (bias in μg)
    pub accel_max: GroupMax,
}

/// Max |error| per group of one triad's estimate (bias in `bias_unit` per SI unit).
pub fn group_errors(est: &TriadEstimate, truth: &TriadTruth, bias_unit: f64) -> GroupMax {
    let mut g = GroupMax {
        bias: (est.bias - truth.bias).amax() / bias_unit,
        ..GroupMax::default()
    };
    for i in 0..3 {
        for j in 0..3 {
            let e = (est.k[(i, j)] - truth.k[(i, j)]).abs();
            if i == j {
                g.scale_ppm = g.scale_ppm.max(e / PPM);
            } else {
                g.misalignment_mrad = g.misalignment_mrad.max(e / MRAD);
            }
        }
    }
    g
}

fn max_of(a: GroupMax, b: GroupMax) -> GroupMax {
    GroupMax {
        bias: a.bias.max(b.bias),
        scale_ppm: a.scale_ppm.max(b.scale_ppm),
        misalignment_mrad: a.misalignment_mrad.max(b.misalignment_mrad),
    }
}

/// Two-sided `p`-quantile band of `χ²(dof)/runs` by the Wilson–Hilferty approximation
/// (`χ²_p(k) ≈ k(1 − 2/(9k) + z_p √(2/(9k)))³`, accurate to < 0.1 % for k ≥ 100), with
/// `z` the standard-normal quantile of the band's upper end.
pub fn chi2_mean_band(dof: f64, runs: f64, z: f64) -> (f64, f64) {
    let c = 2.0 / (9.0 * dof);
    let q = |z: f64| dof * (1.0 - c + z * c.sqrt()).powi(3) / runs;
    (q(-z), q(z))
}

/// Monte Carlo of `runs` simulated calibrations of a scenario (the truth once, the runs
/// in parallel; each run a pure function of (seed, run), so the result is the same for any
/// thread count).
pub fn monte_carlo(
    scn: &Scenario,
    draw: Option<&DrawSpec>,
    runs: usize,
    cancel: &CancelToken,
) -> Result<(Vec<CalibrationRun>, MonteCarloSummary), CalibrationError> {
    if runs == 0 {
        return Err(CalibrationError::NoRuns);
    }
    let exact = truth_increments(scn, cancel)?;
    let dt = scn.imu.dt_s();
    let out: Result<Vec<CalibrationRun>, CalibrationError> = (0..runs as u64)
        .into_par_iter()
        .map(|r| run_on_truth(&exact, dt, &scn.imu.model, draw, scn.imu.seed, r, cancel))
        .collect();
    let out = out?;
    let mean_nees = out.iter().map(|r| r.nees).sum::<f64>() / runs as f64;
    let (mut gm, mut am) = (GroupMax::default(), GroupMax::default());
    for r in &out {
        gm = max_of(
            gm,
            group_errors(&r.gyro, &r.gyro_truth, crate::sensors::imu_error::DPH),
        );
        am = max_of(
            am,
            group_errors(&r.accel, &r.accel_truth, crate::sensors::imu_error::UG),
        );
    }
    let summary = MonteCarloSummary {
        runs,
        mean_nees,
        nees_band: chi2_mean_band((N_PARAMS * runs) as f64, runs as f64, 1.96),
        gyro_max: gm,
        accel_max: am,
    };
    Ok((out, summary))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi2_band_matches_the_issue_numbers() {
        // χ²(2400)/100, two-sided 95 % (z = 1.96): the issue's [22.7, 25.4]; the normal
        // approximation 24 ± 1.96·√(2·2400)/100 = [22.64, 25.36] differs by the skew
        let (lo, hi) = chi2_mean_band(2400.0, 100.0, 1.96);
        assert!(
            (lo - 22.7).abs() < 0.05 && (hi - 25.4).abs() < 0.05,
            "{lo} {hi}"
        );
    }
}
