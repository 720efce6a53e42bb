//! The `align` procedure as one library call (docs/theory/alignment.md §"Coarse alignment";
//! docs/theory/alignment.md §"Fine alignment"; docs/theory/alignment.md §"Multi-heading alignment",
//! docs/alignment_i0.md): load the input (a scenario's exact truth corrupted with one run
//! of its error model, or an IMU file), pick the window, run the chosen method (coarse
//! 1-step / 2-step, inertial-frame i0, 12-state Kalman fine alignment started from i0 or
//! from the 2-step coarse solution, multi-heading Algorithm A or B) and assemble the result
//! with the per-update filter history. The CLI (`sdins align`) and Python (`sdins.align`)
//! only parse, call [`align`] and format.
//!
//! Attitude errors use convention G (`Ĉ = (I + [φ×]) C`, NED, docs/conventions.md); biases
//! are body (FRD) axes.
//!
//! Methods that assume a stationary base (coarse, Kalman fine, multi-heading) refuse a
//! scenario whose truth speed exceeds [`STATIONARY_SPEED_MPS`] anywhere in the alignment
//! window; on IMU files (no truth) they only warn, once, when the i0 fit's velocity
//! residual RMS over the window exceeds that speed. The i0 method is built for a disturbed
//! base and never refuses.

use crate::align::experiment::{
    algorithm_a, algorithm_b, coarse_window, corrupt, fine_from_i0, i0_window, run_fine,
    truth_record, AlignStop,
};
use crate::cancel::{CancelToken, Cancelled};
use crate::io::imu_file::{ImuData, ImuFormat};
use crate::scenario::Scenario;
use crate::sensors::imu_error::{ImuErrorState, DPSH, UG};
use crate::truth::trajectory::Motion;
use sdins_core::align::coarse::CoarseMethod;
use sdins_core::align::fine::{reference_config, FineAlign, FineConfig};
use sdins_core::align::i0::InertialAlign;
use sdins_core::align::{AlignError, Site};
use sdins_core::coning::Increment;
use sdins_core::earth::EarthModel;
use sdins_core::math::{attitude_error, euler_from_c_b_n, Euler, Mat3, Vec3};

/// Truth speed above which a stationary-only method refuses a scenario \[m/s\].
pub const STATIONARY_SPEED_MPS: f64 = 0.5;

/// Alignment method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum AlignMethod {
    /// 1-step analytic (TRIAD-type), polar-orthonormalised (docs/theory/alignment.md
    /// §"Coarse alignment")
    Coarse1,
    /// 2-step: levelling + gyrocompassing (docs/theory/alignment.md §"Coarse alignment")
    Coarse2,
    /// inertial-frame coarse alignment (docs/alignment_i0.md), attitude at window end
    I0,
    /// 12-state zero-velocity Kalman fine alignment (docs/theory/alignment.md §"Fine alignment")
    Fine,
    /// multi-heading (docs/theory/alignment.md §"Multi-heading alignment": Algorithm A or B)
    Multiheading,
}

impl AlignMethod {
    /// Whether the method assumes a stationary base (all but i0).
    pub fn is_stationary_only(self) -> bool {
        !matches!(self, AlignMethod::I0)
    }
    /// Lower-case name as on the command line (`coarse1`, ..., `multiheading`).
    pub fn name(self) -> &'static str {
        match self {
            AlignMethod::Coarse1 => "coarse1",
            AlignMethod::Coarse2 => "coarse2",
            AlignMethod::I0 => "i0",
            AlignMethod::Fine => "fine",
            AlignMethod::Multiheading => "multiheading",
        }
    }
}

/// Multi-heading algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum MultiheadingAlg {
    /// Algorithm A (docs/theory/alignment.md §"Multi-heading alignment"): one closed-loop filter,
    /// body-frame bias states
    #[default]
    A,
    /// Algorithm B (docs/theory/alignment.md §"Multi-heading alignment"): pseudo-error least
    /// squares over the static phases (scenarios only)
    B,
}

/// Start of the fine filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum FineStart {
    /// i0 over the window, σ_z from the disturbance, start refined once
    /// ([`fine_from_i0`])
    #[default]
    I0,
    /// 2-step coarse alignment over the window, σ_z as given
    Coarse2,
}

/// Options of [`align`]; `Default` is the CLI's default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlignOptions {
    /// method
    pub method: AlignMethod,
    /// multi-heading algorithm
    pub alg: MultiheadingAlg,
    /// start of the fine filter
    pub start: FineStart,
    /// coarse / i0 averaging window \[s\] (also the start window of the filters)
    pub window_s: f64,
    /// use only the first `duration_s` seconds of the record
    pub duration_s: Option<f64>,
    /// zero-velocity measurement σ \[m/s\] (a floor with [`FineStart::I0`])
    pub sigma_z_mps: f64,
    /// filter VRW \[μg/√Hz\] (`None`: the input's, see [`AlignInput::vrw_mps_per_sqrt_s`])
    pub vrw_ug_per_sqrt_hz: Option<f64>,
    /// filter ARW \[°/√h\] (`None`: the input's)
    pub arw_deg_per_sqrt_h: Option<f64>,
}

impl Default for AlignOptions {
    fn default() -> Self {
        Self {
            method: AlignMethod::Fine,
            alg: MultiheadingAlg::A,
            start: FineStart::I0,
            window_s: 60.0,
            duration_s: None,
            sigma_z_mps: 1e-3,
            vrw_ug_per_sqrt_hz: None,
            arw_deg_per_sqrt_h: None,
        }
    }
}

/// Why [`align`] or an input constructor failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AlignRunError {
    /// an option out of range; `option` is the [`AlignOptions`] field (or input argument)
    /// name, `message` the whole located message
    #[error("{message}")]
    BadOption {
        /// field name (`window_s`, `sigma_z_mps`, `vrw_ug_per_sqrt_hz`, ...)
        option: &'static str,
        /// `<option> <value>: expected ...`
        message: String,
    },
    /// the input cannot be aligned (too short for the window, no latitude, bad error
    /// model, method not applicable); the message names the input
    #[error("{0}")]
    BadInput(String),
    /// a stationary-only method on a scenario that moves in the alignment window
    #[error(
        "{name}: method {method} assumes a stationary base, but the truth speed is {speed_mps:.3} m/s at t = {t_s:.3} s (limit {limit} m/s within the alignment window); use --method i0 for a moving or disturbed base",
        limit = STATIONARY_SPEED_MPS
    )]
    Moving {
        /// input name
        name: String,
        /// method name
        method: &'static str,
        /// first time the speed exceeds the limit \[s\]
        t_s: f64,
        /// the speed there \[m/s\]
        speed_mps: f64,
    },
    /// the alignment mathematics failed
    #[error("{name}: {source}")]
    Align {
        /// input name
        name: String,
        /// cause
        source: AlignStop,
    },
    /// stopped through the [`CancelToken`]
    #[error("cancelled")]
    Cancelled,
}

impl From<Cancelled> for AlignRunError {
    fn from(_: Cancelled) -> Self {
        AlignRunError::Cancelled
    }
}

/// One loaded alignment input.
#[derive(Clone, Debug)]
pub struct AlignInput {
    /// scenario name or file path
    pub name: String,
    /// sample period \[s\]
    pub dt_s: f64,
    /// the (corrupted) increments, FRD
    pub increments: Vec<Increment>,
    /// site: latitude, gravity, earth rate
    pub site: Site,
    /// true `C_b^n` at the end of each sample (scenarios)
    pub truth_c_b_n: Option<Vec<Mat3>>,
    /// true speed at the end of each sample \[m/s\] (scenarios)
    pub truth_speed_mps: Option<Vec<f64>>,
    /// true constant body biases (scenarios): accelerometer \[m/s²\], gyro \[rad/s\]
    pub true_bias: Option<(Vec3, Vec3)>,
    /// static phases `(t_start_s, duration_s)` (scenarios)
    pub phases: Vec<(f64, f64)>,
    /// the input's VRW \[m/s/√s\] (scenario's model, else aviation grade 20 μg/√Hz)
    pub vrw_mps_per_sqrt_s: f64,
    /// the input's ARW \[rad/√s\] (scenario's model, else aviation grade 0.002 °/√h)
    pub arw_rad_per_sqrt_s: f64,
    /// error-model seed (scenarios)
    pub seed: Option<u64>,
    /// the format actually read (IMU files)
    pub format: Option<ImuFormat>,
    /// latitude used \[deg\]
    pub lat_deg: f64,
    /// height used \[m\]
    pub h_m: f64,
}

impl AlignInput {
    /// A scenario's exact truth, corrupted with run `run` of its IMU error model;
    /// `lat_deg` overrides the scenario's start latitude.
    pub fn from_scenario(
        scn: &Scenario,
        run: u64,
        lat_deg: Option<f64>,
    ) -> Result<Self, AlignRunError> {
        check_site(lat_deg, None)?;
        let name = &scn.name;
        let earth = scn.nav.earth.model();
        let lat = lat_deg.map_or(scn.start.lat_rad, f64::to_radians);
        let tr = truth_record(
            &scn.trajectory,
            earth,
            scn.imu.dt_s(),
            lat,
            scn.start.lon_rad,
            scn.start.h_m,
        );
        let model = &scn.imu.model;
        let bad = |e: crate::sensors::imu_error::ImuErrorModelError| {
            AlignRunError::BadInput(format!("{name}: imu.errors: {e}"))
        };
        let incs = corrupt(&tr.increments, tr.dt_s, model, scn.imu.seed, run).map_err(bad)?;
        let st = ImuErrorState::new(model, scn.imu.seed, run).map_err(bad)?;
        let (bg, ba) = st.constant_bias();
        let phases = scn
            .trajectory
            .segments()
            .iter()
            .filter(|s| matches!(s.motion, Motion::Static))
            .map(|s| (s.t0_s, s.duration_s))
            .collect();
        Ok(Self {
            name: scn.name.clone(),
            dt_s: tr.dt_s,
            increments: incs,
            site: tr.site,
            truth_c_b_n: Some(tr.c_b_n),
            truth_speed_mps: Some(tr.speed_mps),
            true_bias: Some((ba, bg)),
            phases,
            vrw_mps_per_sqrt_s: model.accel_vrw_ugpsqrthz[0].max(1e-3) * UG,
            arw_rad_per_sqrt_s: model.gyro_arw_dpsh[0].max(1e-6) * DPSH,
            seed: Some(scn.imu.seed),
            format: None,
            lat_deg: lat.to_degrees(),
            h_m: scn.start.h_m,
        })
    }

    /// An IMU file already read (`name` is its path as given): latitude from `lat_deg`,
    /// else the PSINS header; height from `h_m`, else the header, else 0. PSINS files use
    /// the PSINS earth constants, others WGS-84.
    pub fn from_imu_data(
        name: &str,
        data: ImuData,
        lat_deg: Option<f64>,
        h_m: Option<f64>,
    ) -> Result<Self, AlignRunError> {
        check_site(lat_deg, h_m)?;
        let (earth, lat_hdr, h_hdr) = match &data.psins {
            Some(p) => (EarthModel::PSINS, Some(p.lat_deg), p.h_m),
            None => (EarthModel::WGS84, None, 0.0),
        };
        let lat = lat_deg.or(lat_hdr).ok_or_else(|| {
            AlignRunError::BadInput(format!("{name}: no latitude in the file: give --lat DEG"))
        })?;
        if !(lat.is_finite() && lat.abs() <= 80.0) {
            return Err(AlignRunError::BadOption {
                option: "lat_deg",
                message: format!(
                    "--lat {lat}: expected a latitude within ±80° (docs/theory/alignment.md)"
                ),
            });
        }
        let h = h_m.unwrap_or(h_hdr);
        Ok(Self {
            name: name.to_string(),
            dt_s: data.dt_s,
            increments: data.increments,
            site: Site::from_earth(&earth, lat.to_radians(), h),
            truth_c_b_n: None,
            truth_speed_mps: None,
            true_bias: None,
            phases: Vec::new(),
            vrw_mps_per_sqrt_s: 20.0 * UG,
            arw_rad_per_sqrt_s: 0.002 * DPSH,
            seed: None,
            format: Some(data.format),
            lat_deg: lat,
            h_m: h,
        })
    }
}

/// One Kalman update of a filter (fine, multi-heading A), SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlignHistoryRow {
    /// time at the end of the update \[s\]
    pub t_s: f64,
    /// attitude estimate
    pub euler: Euler,
    /// 1σ attitude error φ N/E/D \[rad\]
    pub attitude_sigma: Vec3,
    /// accelerometer bias estimate, body \[m/s²\]
    pub accel_bias_b: Vec3,
    /// its 1σ \[m/s²\]
    pub accel_bias_sigma_b: Vec3,
    /// gyro bias estimate, body \[rad/s\]
    pub gyro_bias_b: Vec3,
    /// its 1σ \[rad/s\]
    pub gyro_bias_sigma_b: Vec3,
    /// attitude error against the truth, convention G \[rad\] (scenarios)
    pub phi_true: Option<Vec3>,
}

/// Result of [`align`].
#[derive(Clone, Debug, PartialEq)]
pub struct AlignOutcome {
    /// method name as printed: `coarse1`, `coarse2`, `i0`, `fine`, `multiheading-a`/`-b`
    pub method: String,
    /// final attitude estimate
    pub c_b_n: Mat3,
    /// its Euler angles
    pub euler: Euler,
    /// accelerometer bias estimate and 1σ, body \[m/s²\] (filters)
    pub accel_bias: Option<(Vec3, Vec3)>,
    /// gyro bias estimate and 1σ, body \[rad/s\] (filters)
    pub gyro_bias: Option<(Vec3, Vec3)>,
    /// attitude 1σ N/E/D \[rad\] (fine alignment)
    pub attitude_sigma: Option<Vec3>,
    /// attitude error φ against the truth at the epoch of the estimate \[rad\] (scenarios)
    pub phi_true: Option<Vec3>,
    /// the zero-velocity σ used by a fine filter started from i0 \[m/s\]
    pub sigma_z_used_mps: Option<f64>,
    /// whether the method is a filter with a per-update history (fine, multi-heading A)
    pub has_history: bool,
    /// per-update history (empty unless `has_history`)
    pub history: Vec<AlignHistoryRow>,
    /// samples used (after `duration_s`)
    pub samples: usize,
    /// the filter configuration (site, noise, σ_z as given)
    pub config: FineConfig,
    /// notes that did not stop the alignment (at most one: a file that seems to move)
    pub warnings: Vec<String>,
}

/// Check a site override: latitude within ±89.99°, height in [−1 km, 100 km].
pub fn check_site(lat_deg: Option<f64>, h_m: Option<f64>) -> Result<(), AlignRunError> {
    for (option, flag, v, lo, hi) in [
        ("lat_deg", "--lat", lat_deg, -89.99, 89.99),
        ("h_m", "--h", h_m, -1000.0, 100_000.0),
    ] {
        range(option, flag, v, lo, false, hi)?;
    }
    Ok(())
}

fn range(
    option: &'static str,
    flag: &str,
    v: Option<f64>,
    lo: f64,
    lo_open: bool,
    hi: f64,
) -> Result<(), AlignRunError> {
    if let Some(x) = v {
        let low_ok = if lo_open { x > lo } else { x >= lo };
        if !(x.is_finite() && low_ok && x <= hi) {
            return Err(AlignRunError::BadOption {
                option,
                message: format!(
                    "{flag} {x}: expected a finite value in {}{lo}, {hi}]",
                    if lo_open { "(" } else { "[" }
                ),
            });
        }
    }
    Ok(())
}

/// Check the options of [`align`] (finite, in range); the messages name the CLI flag.
pub fn check_options(o: &AlignOptions) -> Result<(), AlignRunError> {
    if !(o.window_s.is_finite() && o.window_s > 0.0) {
        return Err(AlignRunError::BadOption {
            option: "window_s",
            message: format!(
                "--window-s {}: expected a positive number of seconds",
                o.window_s
            ),
        });
    }
    if !(o.sigma_z_mps.is_finite() && o.sigma_z_mps > 0.0) {
        return Err(AlignRunError::BadOption {
            option: "sigma_z_mps",
            message: format!(
                "--sigma-z {}: expected a positive velocity σ in m/s",
                o.sigma_z_mps
            ),
        });
    }
    range(
        "vrw_ug_per_sqrt_hz",
        "--vrw",
        o.vrw_ug_per_sqrt_hz,
        0.0,
        false,
        1e6,
    )?;
    range(
        "arw_deg_per_sqrt_h",
        "--arw",
        o.arw_deg_per_sqrt_h,
        0.0,
        false,
        1e3,
    )?;
    range("duration_s", "--duration-s", o.duration_s, 0.0, true, 1e7)?;
    Ok(())
}

/// The filter configuration [`align`] uses: the reference configuration (docs/theory/alignment.md
/// §"Fine alignment") at the input's site with the options' (else the input's) VRW/ARW and σ_z.
pub fn filter_config(inp: &AlignInput, o: &AlignOptions) -> FineConfig {
    let mut cfg = reference_config(
        inp.site,
        o.vrw_ug_per_sqrt_hz
            .map_or(inp.vrw_mps_per_sqrt_s, |v| v * UG),
        o.arw_deg_per_sqrt_h
            .map_or(inp.arw_rad_per_sqrt_s, |v| v * DPSH),
    );
    cfg.sigma_z_mps = o.sigma_z_mps;
    cfg
}

/// Run one alignment of `inp` (docs/theory/alignment.md §"Coarse alignment";
/// docs/theory/alignment.md §"Fine alignment"; docs/theory/alignment.md §"Multi-heading alignment",
/// docs/alignment_i0.md). The window is `n_w = round(window_s / dt)` samples from the start; coarse
/// methods use `[0, n_w)` (attitude at t = 0 for coarse, at sample `n_w − 1` for i0), the filters
/// the whole record (first `duration_s` seconds). Stationary-only methods refuse a scenario whose
/// truth speed exceeds [`STATIONARY_SPEED_MPS`] in the samples they use.
pub fn align(
    inp: &AlignInput,
    o: &AlignOptions,
    token: &CancelToken,
) -> Result<AlignOutcome, AlignRunError> {
    check_options(o)?;
    token.check()?;
    let dt = inp.dt_s;
    let n_all = match o.duration_s {
        Some(d) => ((d / dt).round().max(0.0) as usize).min(inp.increments.len()),
        None => inp.increments.len(),
    };
    let incs = &inp.increments[..n_all];
    let nw = (o.window_s / dt).round() as usize;
    if nw == 0 || nw > incs.len() {
        return Err(AlignRunError::BadInput(format!(
            "{}: --window-s {} needs {nw} samples, the record has {}",
            inp.name,
            o.window_s,
            incs.len()
        )));
    }
    let coarse = matches!(o.method, AlignMethod::Coarse1 | AlignMethod::Coarse2);
    let used = if coarse || o.method == AlignMethod::I0 {
        nw
    } else {
        incs.len()
    };
    let mut warnings = Vec::new();
    if o.method.is_stationary_only() {
        stationary_check(inp, o.method, used, &mut warnings)?;
    }
    let cfg = filter_config(inp, o);
    let truth = inp.truth_c_b_n.as_ref();
    let mut history = Vec::new();
    let mut record = |j: usize, fa: &FineAlign| {
        history.push(AlignHistoryRow {
            t_s: (j + 1) as f64 * dt,
            euler: euler_from_c_b_n(&fa.c_b_n()),
            attitude_sigma: fa.attitude_sigma(),
            accel_bias_b: fa.accel_bias_b(),
            accel_bias_sigma_b: fa.accel_bias_sigma_b(),
            gyro_bias_b: fa.gyro_bias_b(),
            gyro_bias_sigma_b: fa.gyro_bias_sigma_b(),
            phi_true: truth
                .and_then(|t| t.get(j))
                .map(|c| attitude_error(&fa.c_b_n(), c)),
        });
    };
    let name = &inp.name;
    let stop = |source: AlignStop| match source {
        AlignStop::Cancelled(_) => AlignRunError::Cancelled,
        source => AlignRunError::Align {
            name: name.clone(),
            source,
        },
    };
    let core = |e: AlignError| stop(AlignStop::Align(e));
    let mut sigma_z_used = None;
    let mut has_history = false;
    let (method, c_b_n, accel_bias, gyro_bias, attitude_sigma) = match o.method {
        AlignMethod::Coarse1 | AlignMethod::Coarse2 => {
            let (m, label) = if o.method == AlignMethod::Coarse1 {
                (CoarseMethod::OneStep, "coarse1")
            } else {
                (CoarseMethod::TwoStep, "coarse2")
            };
            let c = coarse_window(incs, dt, 0, nw, &inp.site, m).map_err(core)?;
            (label.to_string(), c, None, None, None)
        }
        AlignMethod::I0 => {
            let c = i0_window(incs, dt, 0, nw, &inp.site).map_err(core)?;
            ("i0".to_string(), c, None, None, None)
        }
        AlignMethod::Fine => {
            has_history = true;
            let fa = match o.start {
                FineStart::Coarse2 => {
                    let c0 = coarse_window(incs, dt, 0, nw, &inp.site, CoarseMethod::TwoStep)
                        .map_err(core)?;
                    run_fine(incs, dt, cfg, &c0, &mut record, token)?
                }
                FineStart::I0 => {
                    let (fa, _, sz) =
                        fine_from_i0(incs, dt, cfg, nw, &mut record, token).map_err(stop)?;
                    sigma_z_used = Some(sz);
                    fa
                }
            };
            (
                "fine".to_string(),
                fa.c_b_n(),
                Some((fa.accel_bias_b(), fa.accel_bias_sigma_b())),
                Some((fa.gyro_bias_b(), fa.gyro_bias_sigma_b())),
                Some(fa.attitude_sigma()),
            )
        }
        AlignMethod::Multiheading => {
            let r = match o.alg {
                MultiheadingAlg::A => {
                    has_history = true;
                    algorithm_a(incs, dt, cfg, o.window_s, &mut record, token).map_err(stop)?
                }
                MultiheadingAlg::B => {
                    if inp.phases.len() < 2 {
                        return Err(AlignRunError::BadInput(format!(
                            "{}: Algorithm B needs a scenario with at least two static segments at different headings",
                            inp.name
                        )));
                    }
                    algorithm_b(incs, dt, cfg, o.window_s, &inp.phases, token).map_err(stop)?
                }
            };
            let alg = if o.alg == MultiheadingAlg::A {
                "a"
            } else {
                "b"
            };
            (
                format!("multiheading-{alg}"),
                r.c_b_n,
                Some((r.accel_bias_b, r.accel_bias_sigma_b)),
                Some((r.gyro_bias_b, r.gyro_bias_sigma_b)),
                None,
            )
        }
    };
    let j_true = match o.method {
        AlignMethod::Coarse1 | AlignMethod::Coarse2 => 0,
        AlignMethod::I0 => nw - 1,
        _ => incs.len().saturating_sub(1),
    };
    let phi_true = truth
        .and_then(|t| t.get(j_true))
        .map(|c| attitude_error(&c_b_n, c));
    Ok(AlignOutcome {
        method,
        euler: euler_from_c_b_n(&c_b_n),
        c_b_n,
        accel_bias,
        gyro_bias,
        attitude_sigma,
        phi_true,
        sigma_z_used_mps: sigma_z_used,
        has_history,
        history,
        samples: incs.len(),
        config: cfg,
        warnings,
    })
}

/// Refuse a moving scenario (first sample of the first `used` whose truth speed exceeds
/// [`STATIONARY_SPEED_MPS`]); on a file, warn when the i0 fit's velocity residual RMS over
/// the window (docs/alignment_i0.md: the base's own velocity about the fitted inertial
/// solution) exceeds that speed.
fn stationary_check(
    inp: &AlignInput,
    method: AlignMethod,
    used: usize,
    warnings: &mut Vec<String>,
) -> Result<(), AlignRunError> {
    if let Some(speed) = &inp.truth_speed_mps {
        if let Some((j, v)) = speed
            .iter()
            .take(used)
            .enumerate()
            .find(|(_, v)| **v > STATIONARY_SPEED_MPS)
        {
            return Err(AlignRunError::Moving {
                name: inp.name.clone(),
                method: method.name(),
                t_s: (j + 1) as f64 * inp.dt_s,
                speed_mps: *v,
            });
        }
        return Ok(());
    }
    let mut a = InertialAlign::new(inp.site);
    for inc in inp.increments.iter().take(used) {
        a.add(inc, inp.dt_s);
    }
    if let Ok(rms) = a.residual_rms_mps() {
        if rms > STATIONARY_SPEED_MPS {
            warnings.push(format!(
                "{}: method {} assumes a stationary base, but the velocity residual of an inertial-frame fit over the window is {rms:.3} m/s RMS (> {STATIONARY_SPEED_MPS} m/s): the base may be moving; use --method i0 for a moving or disturbed base",
                inp.name,
                method.name()
            ));
        }
    }
    Ok(())
}
