//! `sdins fuse` as one library call: a typed request ([`FuseRequest`]: a scenario or
//! recorded files, and the filter options), [`fuse`] running it through the one fusion
//! loop, its rows streamed to an observer ([`FuseOutput`]) and a typed result
//! ([`FuseOutcome`]: fixes, rejections, RMS, bias and scale-factor estimates). The CLI
//! (`sdins fuse SCENARIO`, `sdins fuse --imu --gnss`) and Python (`sdins.fuse`,
//! `sdins.fuse_files`) call it.
//!
//! `grade` is defined here once: on a scenario it replaces the scenario's IMU error model,
//! i.e. both the simulated IMU errors and the filter's model; on recorded data it is the
//! filter's model only.
//!
//! Option errors name the option in both spellings (`cov_rate_hz` / `--cov-rate-hz`).

use super::health::{HealthMonitor, HealthVerdict, DEFAULT_MAX_SIGMA_H_M};
use crate::cancel::CancelToken;
use crate::fusion::detector::DetectorSettings;
use crate::fusion::files::{fuse_files, FilesError, FilesInput, FilesResult};
use crate::fusion::files::{InitSource, InputColumns, SensorModelSource};
use crate::fusion::records::{RecordEvent, RecordOptions, RecordPoint, TruthComparison};
use crate::fusion::sensor_model::SensorModel;
use crate::fusion::simulated::{
    fuse_scenario, FuseEpoch, FuseError, FuseEvent, FuseOptions, FuseSummary, InMotionInit,
    InitSigma, ScaleFactorPrior,
};
use crate::io::gnss_file::{GnssFormat, GnssReadOptions, ImuClock};
use crate::io::imu_file::ImuFormat;
use crate::nav::options::apply_grade;
use crate::scenario::Scenario;
use sdins_core::aiding::ekf::{UpdateReport, CHI2_999, DEFAULT_MAX_LATENCY_S};
use sdins_core::aiding::layout::StateLayout;
use sdins_core::aiding::meas::MeasKind;
use sdins_core::math::Vec3;
use sdins_core::nav::AlgorithmSpec;
use std::path::PathBuf;

/// Where the data come from.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
#[allow(clippy::large_enum_variant)]
pub enum FuseData {
    /// a scenario (its `[gnss]` table sets the receiver)
    Scenario(ScenarioData),
    /// recorded files
    Files(FilesData),
}

/// A scenario and the options that only a simulation has.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioData {
    /// the scenario
    pub scenario: Scenario,
    /// run number (the IMU, GNSS and initial-error streams)
    pub run: u64,
    /// start at the truth (no drawn initial errors)
    pub exact_start: bool,
    /// in-motion alignment from an unknown heading
    pub in_motion: bool,
    /// ZUPT σ \[m/s\] while the truth is at rest (speed < 1 mm/s)
    pub zupt_sigma_mps: Option<f64>,
}

/// Recorded files and the options that only recorded data have.
#[derive(Clone, Debug, PartialEq)]
pub struct FilesData {
    /// IMU file and format
    pub imu: (PathBuf, ImuFormat),
    /// GNSS file and format
    pub gnss: (PathBuf, GnssFormat),
    /// `t_imu − t_gnss` \[s\]
    pub gnss_offset_s: f64,
    /// NaveGo IMU parameters (the filter's model; excludes `grade`)
    pub navego_params: Option<PathBuf>,
    /// a sensor-model file, sdins TOML or KF-GINS YAML by its extension `.yaml`/`.yml`
    /// (the filter's model, and optionally the lever arm, scale-factor σ and initial
    /// attitude and σ; excludes `grade` and `navego_params`;
    /// [`crate::fusion::sensor_model`])
    pub sensor_model: Option<PathBuf>,
    /// initial state: the `--init` text
    pub init: Option<String>,
    /// initial attitude roll, pitch, yaw \[deg\] (position and velocity from the first fix)
    pub attitude_deg: Option<[f64; 3]>,
    /// its σ \[deg\]
    pub attitude_sigma_deg: Option<[f64; 3]>,
    /// at rest for the first seconds: coarse alignment
    pub static_s: Option<f64>,
    /// antenna lever arm, body FRD \[m\]
    pub lever_arm_m: Option<[f64; 3]>,
    /// reference trajectory
    pub truth: Option<PathBuf>,
    /// column maps of the IMU and GNSS files (docs/own-data.md; each `None`: the file's
    /// format)
    pub columns: InputColumns,
    /// the aiding sensors' TOML file (docs/own-data.md §"Aiding sensors")
    pub aiding: Option<PathBuf>,
}

/// A fusion request.
#[derive(Clone, Debug, PartialEq)]
pub struct FuseRequest {
    /// the data
    pub data: FuseData,
    /// IMU grade preset (see the module documentation)
    pub grade: Option<String>,
    /// algorithm name (savage, songlee, songlee-complete, dualquat)
    pub algo: String,
    /// samples per navigation update (default: the scenario's; 2 for files)
    pub samples: Option<usize>,
    /// covariance rate \[Hz\]
    pub cov_rate_hz: f64,
    /// χ² 99.9 % gate on GNSS fixes
    pub gate: bool,
    /// NHC σ \[m/s\]
    pub nhc_sigma_mps: Option<f64>,
    /// run the smoother
    pub smooth: bool,
    /// estimate scale factors with this prior
    pub scale_factors: Option<ScaleFactorPrior>,
    /// output rows every … s (default: scenarios the covariance interval, files every
    /// update)
    pub every_s: Option<f64>,
    /// stop after this time \[s\] (scenarios)
    pub until_s: Option<f64>,
    /// largest latency of a measurement \[s\]
    pub max_latency_s: Option<f64>,
    /// the health verdict's largest horizontal σ \[m\] (default
    /// [`health::DEFAULT_MAX_SIGMA_H_M`](super::health::DEFAULT_MAX_SIGMA_H_M))
    pub health_max_sigma_m: Option<f64>,
    /// zero-velocity updates of σ \[m/s\] whenever the IMU's stationarity detector
    /// declares rest ([`crate::fusion::detector`]; scenarios and files; on scenarios in
    /// place of the truth trigger `ScenarioData::zupt_sigma_mps`)
    pub zupt_detector: Option<(f64, DetectorSettings)>,
}

impl FuseRequest {
    /// A request with the library defaults (`songlee-complete`, 10 Hz covariance, gate
    /// on, no smoother).
    pub fn new(data: FuseData) -> Self {
        Self {
            data,
            grade: None,
            algo: "songlee-complete".into(),
            samples: None,
            cov_rate_hz: 10.0,
            gate: true,
            nhc_sigma_mps: None,
            smooth: false,
            scale_factors: None,
            every_s: None,
            until_s: None,
            max_latency_s: None,
            health_max_sigma_m: None,
            zupt_detector: None,
        }
    }
}

impl FuseRequest {
    /// Check the options shared by both modes and, on files, the file options (the
    /// sensor model is read; the data files are read when it runs).
    pub fn check(&self) -> Result<(), FuseRunError> {
        match &self.data {
            FuseData::Scenario(d) => common(self, d.scenario.nav.samples).map(|_| ()),
            FuseData::Files(d) => files_input(self, d).map(|_| ()),
        }
    }
}

/// Why a request failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FuseRunError {
    /// An option is out of range or the options contradict each other.
    #[error("{0}")]
    Option(String),
    /// The scenario run failed.
    #[error(transparent)]
    Fuse(#[from] FuseError),
    /// The run on files failed.
    #[error(transparent)]
    Files(#[from] FilesError),
}

impl FuseRunError {
    /// Whether the run was cancelled.
    pub fn is_cancelled(&self) -> bool {
        matches!(
            self,
            FuseRunError::Fuse(FuseError::Cancelled(_))
                | FuseRunError::Files(FilesError::Fuse(FuseError::Cancelled(_)))
        )
    }
}

/// A row of either source.
#[derive(Clone, Copy, Debug)]
pub enum FuseRow<'a> {
    /// a scenario row: errors against the exact truth, covariance
    Scenario(&'a FuseEpoch),
    /// a recorded-data row and, with a reference trajectory matching its time, its errors
    /// (roll, pitch, yaw \[rad\], v N, E, D \[m/s\], N, E, D \[m\])
    Files(&'a RecordPoint, Option<&'a [f64; 9]>),
}

/// What the observer of [`fuse`] receives.
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub enum FuseOutput<'a> {
    /// a forward row
    Forward(FuseRow<'a>),
    /// a smoothed row (after the forward pass, in time order)
    Smoothed(FuseRow<'a>),
    /// a measurement update (times on the data's clock)
    Update(&'a UpdateReport),
}

/// The mode-specific part of a result.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
#[allow(clippy::large_enum_variant)]
pub enum FuseDetails {
    /// a scenario run
    Scenario {
        /// scenario name
        name: String,
        /// run number
        run: u64,
        /// the filter run
        summary: FuseSummary,
        /// GNSS fix rate \[Hz\]
        gnss_rate_hz: f64,
    },
    /// a run on files
    Files(FilesResult),
}

/// What a request did.
#[derive(Clone, Debug, PartialEq)]
pub struct FuseOutcome {
    /// the mechanization used
    pub algo: AlgorithmSpec,
    /// GNSS fixes processed (applied, rejected, late)
    pub fixes: u64,
    /// GNSS fixes rejected by the gate
    pub rejected: u64,
    /// measurements refused as late
    pub late: u64,
    /// navigation updates
    pub nav_updates: u64,
    /// final bias estimates (accelerometer \[m/s²\], gyro \[rad/s\])
    pub bias_est: (Vec3, Vec3),
    /// final scale-factor estimates (zero without those states)
    pub scale_est: (Vec3, Vec3),
    /// the state layout
    pub layout: StateLayout,
    /// scenarios: RMS over the forward rows of the position \[m\], velocity \[m/s\] and
    /// attitude ε \[rad\] errors N, E, D; files with a reference: of roll, pitch, yaw
    /// \[rad\], v N, E, D \[m/s\], N, E, D \[m\] (the reference's matched rows)
    pub rms_forward: Option<[f64; 9]>,
    /// the same over the smoothed rows
    pub rms_smoothed: Option<[f64; 9]>,
    /// the mode-specific part
    pub details: FuseDetails,
    /// can the solution be trusted? ([`super::health`])
    pub health: HealthVerdict,
    /// every measurement kind that occurred (GNSS, ZUPT, NHC, the aiding sensors), in
    /// [`MeasKind::ALL`] order
    pub measurements: Vec<KindTally>,
}

/// What happened to the measurements of one kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KindTally {
    /// the kind
    pub kind: MeasKind,
    /// applied (including forced after the reset policy)
    pub applied: u64,
    /// rejected by the gate
    pub rejected: u64,
    /// refused as late
    pub late: u64,
}

fn bad(name: &str, flag: &str, msg: impl std::fmt::Display) -> FuseRunError {
    FuseRunError::Option(format!("{name} ({flag}): {msg}"))
}

fn positive(name: &str, flag: &str, v: Option<f64>) -> Result<(), FuseRunError> {
    match v {
        Some(x) if !(x.is_finite() && x > 0.0) => {
            Err(bad(name, flag, format!("must be finite and > 0, got {x}")))
        }
        _ => Ok(()),
    }
}

/// The checks shared by both modes; the mechanization.
fn common(req: &FuseRequest, default_samples: usize) -> Result<AlgorithmSpec, FuseRunError> {
    let samples = req.samples.unwrap_or(default_samples);
    if !(1..=4).contains(&samples) {
        return Err(bad(
            "samples",
            "--samples",
            format!("must be 1..4, got {samples}"),
        ));
    }
    positive("cov_rate_hz", "--cov-rate-hz", Some(req.cov_rate_hz))?;
    positive("nhc_sigma_mps", "--nhc-sigma-mps", req.nhc_sigma_mps)?;
    if let Some((sigma, ds)) = &req.zupt_detector {
        positive("zupt_sigma_mps", "--zupt-sigma-mps", Some(*sigma))?;
        positive("zupt_window_s", "--zupt-window-s", Some(ds.window_s))?;
        if !(1e-9..=0.5).contains(&ds.false_alarm) {
            return Err(bad(
                "zupt_false_alarm",
                "--zupt-false-alarm",
                format!("must be in [1e-9, 0.5], got {}", ds.false_alarm),
            ));
        }
    }
    positive("every_s", "--every-s", req.every_s)?;
    positive("until_s", "--until-s", req.until_s)?;
    if let Some(l) = req.max_latency_s {
        if !(l.is_finite() && (0.0..=10.0).contains(&l)) {
            return Err(bad(
                "max_latency_s",
                "--max-latency-s",
                format!("must be in [0, 10] s, got {l}"),
            ));
        }
    }
    if let Some(sp) = &req.scale_factors {
        sp.validate().map_err(|_| {
            bad(
                "scale_factors",
                "--scale-factors-ppm",
                "prior σ must be finite and in (0, 100000] ppm",
            )
        })?;
    }
    AlgorithmSpec::from_name(&req.algo, samples).ok_or_else(|| {
        bad(
            "algo",
            "--algo",
            format!("unknown algorithm `{}`", req.algo),
        )
    })
}

/// Run a request; `observe` sees every row and update.
pub fn fuse(
    req: &FuseRequest,
    cancel: &CancelToken,
    observe: &mut dyn FnMut(FuseOutput<'_>),
) -> Result<FuseOutcome, FuseRunError> {
    positive(
        "health_max_sigma_m",
        "--health-max-sigma",
        req.health_max_sigma_m,
    )?;
    let mut monitor = HealthMonitor::new(req.health_max_sigma_m.unwrap_or(DEFAULT_MAX_SIGMA_H_M));
    let mut tally: Vec<KindTally> = MeasKind::ALL
        .iter()
        .map(|&kind| KindTally {
            kind,
            applied: 0,
            rejected: 0,
            late: 0,
        })
        .collect();
    let mut watch = |ev: FuseOutput<'_>| {
        monitor.observe(&ev);
        if let FuseOutput::Update(u) = &ev {
            if let Some(t) = tally.get_mut(u.kind.index()) {
                if u.late {
                    t.late += 1;
                } else if u.accepted {
                    t.applied += 1;
                } else {
                    t.rejected += 1;
                }
            }
        }
        observe(ev);
    };
    let mut o = match &req.data {
        FuseData::Scenario(d) => fuse_scenario_request(req, d, cancel, &mut watch),
        FuseData::Files(d) => fuse_files_request(req, d, cancel, &mut watch),
    }?;
    o.health = monitor.verdict();
    o.measurements = tally
        .into_iter()
        .filter(|t| t.applied + t.rejected + t.late > 0)
        .collect();
    Ok(o)
}

/// Sums of squares of 9 channels, in row order.
#[derive(Clone, Copy, Debug, Default)]
struct Rms {
    sq: [f64; 9],
    n: u64,
}

impl Rms {
    fn add(&mut self, v: &[f64; 9]) {
        for (s, x) in self.sq.iter_mut().zip(v) {
            *s += x * x;
        }
        self.n += 1;
    }
    fn get(&self) -> [f64; 9] {
        let n = self.n.max(1) as f64;
        self.sq.map(|s| (s / n).sqrt())
    }
}

fn errors9(e: &FuseEpoch) -> [f64; 9] {
    let mut v = [0.0; 9];
    v[..3].copy_from_slice(&e.nav.pos_err_ned_m);
    v[3..6].copy_from_slice(&e.nav.vel_err_ned_mps);
    v[6..].copy_from_slice(&e.nav.att_err_rad);
    v
}

/// The scenario of a request with `grade` applied (the simulated IMU errors and the
/// filter's model).
pub fn request_scenario(req: &FuseRequest, d: &ScenarioData) -> Result<Scenario, FuseRunError> {
    let mut scn = d.scenario.clone();
    if let Some(g) = &req.grade {
        apply_grade(&mut scn, g).map_err(|e| FuseRunError::Option(e.to_string()))?;
    }
    Ok(scn)
}

/// The filter options of a scenario request.
pub fn scenario_options(
    req: &FuseRequest,
    d: &ScenarioData,
    scn: &Scenario,
) -> Result<FuseOptions, FuseRunError> {
    let algo = common(req, scn.nav.samples)?;
    positive("zupt_sigma_mps", "--zupt-sigma-mps", d.zupt_sigma_mps)?;
    let zupt = match (d.zupt_sigma_mps, &req.zupt_detector) {
        (Some(_), Some(_)) => {
            return Err(bad(
                "zupt_detector",
                "--zupt-detector",
                "a scenario's ZUPT comes from the truth (zupt_sigma_mps) or from the detector, not both",
            ))
        }
        (Some(s), None) => Some((s, 1e-3)),
        (None, Some((s, _))) => Some((*s, 1e-3)),
        (None, None) => None,
    };
    Ok(FuseOptions {
        algo,
        cov_rate_hz: req.cov_rate_hz,
        draw_initial_errors: !d.exact_start,
        gate_chi2: req.gate.then_some(CHI2_999),
        zupt,
        zupt_detector: req.zupt_detector.map(|z| z.1),
        nhc_sigma_mps: req.nhc_sigma_mps,
        until_s: req.until_s,
        smooth: req.smooth,
        in_motion: d.in_motion.then(InMotionInit::default),
        scale_factors: req.scale_factors,
        every_s: req.every_s,
        max_latency_s: req.max_latency_s.unwrap_or(DEFAULT_MAX_LATENCY_S),
        ..FuseOptions::default()
    })
}

fn fuse_scenario_request(
    req: &FuseRequest,
    d: &ScenarioData,
    cancel: &CancelToken,
    observe: &mut dyn FnMut(FuseOutput<'_>),
) -> Result<FuseOutcome, FuseRunError> {
    let scn = request_scenario(req, d)?;
    let opts = scenario_options(req, d, &scn)?;
    let gnss = scn.gnss.clone().unwrap_or_default();
    let (mut fwd, mut smo) = (Rms::default(), Rms::default());
    let s = fuse_scenario(&scn, &gnss, &opts, d.run, cancel, |ev| match ev {
        FuseEvent::Epoch(e) => {
            fwd.add(&errors9(e));
            observe(FuseOutput::Forward(FuseRow::Scenario(e)));
        }
        FuseEvent::Smoothed(e) => {
            smo.add(&errors9(e));
            observe(FuseOutput::Smoothed(FuseRow::Scenario(e)));
        }
        FuseEvent::Update(u) => observe(FuseOutput::Update(u)),
    })?;
    Ok(FuseOutcome {
        algo: opts.algo,
        fixes: s.fixes,
        rejected: s.rejected,
        late: s.late,
        nav_updates: s.nav_updates,
        bias_est: s.est_bias,
        scale_est: s.est_scale,
        layout: s.layout,
        rms_forward: Some(fwd.get()),
        rms_smoothed: req.smooth.then(|| smo.get()),
        details: FuseDetails::Scenario {
            name: scn.name.clone(),
            run: d.run,
            summary: s,
            gnss_rate_hz: gnss.rate_hz,
        },
        health: HealthVerdict::default(),
        measurements: Vec::new(),
    })
}

fn triple_ok(name: &str, flag: &str, v: Option<[f64; 3]>) -> Result<(), FuseRunError> {
    if v.is_some_and(|a| a.iter().any(|x| !x.is_finite())) {
        return Err(bad(name, flag, "must be three finite numbers"));
    }
    Ok(())
}

/// The reader inputs and filter options of a files request.
pub fn files_input(
    req: &FuseRequest,
    d: &FilesData,
) -> Result<(FilesInput, RecordOptions), FuseRunError> {
    let algo = common(req, 2)?;
    if req.until_s.is_some() {
        return Err(bad("until_s", "--until-s", "applies to scenarios"));
    }
    triple_ok("lever_arm_m", "--lever-arm-m", d.lever_arm_m)?;
    triple_ok("attitude_deg", "--attitude-deg", d.attitude_deg)?;
    if d.columns.imu.is_some() && d.imu.1 != ImuFormat::Auto {
        return Err(bad(
            "imu_format",
            "--imu-format",
            "the IMU file is read through a column map (imu_columns / --imu-columns or a profile): give one",
        ));
    }
    if d.columns.gnss.is_some() && d.gnss.1 != GnssFormat::Auto {
        return Err(bad(
            "gnss_format",
            "--gnss-format",
            "the GNSS file is read through a column map (gnss_columns / --gnss-columns or a profile): give one",
        ));
    }
    if !d.gnss_offset_s.is_finite() {
        return Err(bad("gnss_offset_s", "--gnss-offset-s", "must be finite"));
    }
    let sensor = SensorModelSource::from_options(
        req.grade.as_deref(),
        d.navego_params.as_deref(),
        d.sensor_model.as_deref(),
    )
    .map_err(FuseRunError::Option)?;
    let file_model = sensor.file();
    let init = init_source(d, file_model)?;
    let lever_arm_b_m = match (d.lever_arm_m, file_model.and_then(|m| m.lever_arm_b_m)) {
        (Some(_), Some(_)) => {
            return Err(bad(
                "lever_arm_m",
                "--lever-arm-m",
                "the sensor model (--sensor-model) gives the lever arm too: give one",
            ))
        }
        (a, b) => a.or(b).unwrap_or([0.0; 3]),
    };
    let scale_factors = match (req.scale_factors, file_model.and_then(|m| m.scale_sigma)) {
        (Some(_), Some(_)) => {
            return Err(bad(
                "scale_factors",
                "--scale-factors-ppm",
                "the sensor model (--sensor-model) gives the scale-factor σ too: give one",
            ))
        }
        (a, b) => a.or(b),
    };
    let input = FilesInput {
        imu: d.imu.clone(),
        gnss: d.gnss.clone(),
        gnss_options: GnssReadOptions::default(),
        clock: if d.gnss_offset_s == 0.0 {
            ImuClock::SameAsGnss
        } else {
            ImuClock::Offset {
                t_imu_minus_t_gnss_s: d.gnss_offset_s,
            }
        },
        sensor,
        init,
        truth: d.truth.clone(),
        check_after_s: 30.0,
        columns: d.columns.clone(),
        aiding: d.aiding.clone(),
    };
    let opts = RecordOptions {
        algo,
        cov_rate_hz: req.cov_rate_hz,
        gate_chi2: req.gate.then_some(CHI2_999),
        lever_arm_b_m,
        nhc_sigma_mps: req.nhc_sigma_mps,
        zupt_detector: req.zupt_detector,
        smooth: req.smooth,
        scale_factors,
        every_s: req.every_s,
        max_latency_s: req.max_latency_s.unwrap_or(DEFAULT_MAX_LATENCY_S),
        ..RecordOptions::default()
    };
    Ok((input, opts))
}

/// The initial state of a files request: the options, completed by a sensor-model file
/// (its attitude σ for `--attitude-deg` without `--attitude-sigma-deg`, its initial σ for
/// `--init`, its attitude when none of `--init`, `--attitude-deg`, `--static-s` is given).
fn init_source(d: &FilesData, file: Option<&SensorModel>) -> Result<InitSource, FuseRunError> {
    let Some(m) = file else {
        return InitSource::from_options(
            d.init.as_deref(),
            d.attitude_deg,
            d.attitude_sigma_deg,
            d.static_s,
            d.navego_params.is_some(),
        )
        .map_err(FuseRunError::Option);
    };
    let s = m.initial_sigma;
    if let Some(a) = s.att_rpy_rad {
        if a.iter().any(|x| x.to_degrees() > 10.0) {
            return Err(FuseRunError::Option(format!(
                "--sensor-model {}: the initial attitude σ must be <= 10 deg (the linearised filter's limit)",
                m.file.display()
            )));
        }
    }
    let none = d.init.is_none() && d.attitude_deg.is_none() && d.static_s.is_none();
    if none {
        if let Some(att) = m.attitude_rpy_rad {
            let sig =
                s.att_rpy_rad
                    .unwrap_or([1f64.to_radians(), 1f64.to_radians(), 2f64.to_radians()]);
            return Ok(InitSource::FirstFix(att, sig));
        }
    }
    let att_sigma_deg = d
        .attitude_sigma_deg
        .or(s.att_rpy_rad.map(|a| a.map(f64::to_degrees)));
    let init = InitSource::from_options(
        d.init.as_deref(),
        d.attitude_deg,
        att_sigma_deg,
        d.static_s,
        false,
    )
    .map_err(FuseRunError::Option)?;
    Ok(match init {
        InitSource::Given(st, def) => InitSource::Given(
            st,
            InitSigma {
                pos_ned_m: s.pos_ned_m.unwrap_or(def.pos_ned_m),
                vel_ned_mps: s.vel_ned_mps.unwrap_or(def.vel_ned_mps),
                att_rad: s.att_rpy_rad.unwrap_or(def.att_rad),
            },
        ),
        other => other,
    })
}

fn fuse_files_request(
    req: &FuseRequest,
    d: &FilesData,
    cancel: &CancelToken,
    observe: &mut dyn FnMut(FuseOutput<'_>),
) -> Result<FuseOutcome, FuseRunError> {
    let (input, opts) = files_input(req, d)?;
    let r = fuse_files(&input, &opts, cancel, |ev, err| match ev {
        RecordEvent::Forward(p) => observe(FuseOutput::Forward(FuseRow::Files(p, err))),
        RecordEvent::Smoothed(p) => observe(FuseOutput::Smoothed(FuseRow::Files(p, err))),
        RecordEvent::Update(u) => observe(FuseOutput::Update(u)),
    })?;
    let s = &r.summary;
    let rms = |c: &Option<TruthComparison>| c.as_ref().map(TruthComparison::rmse);
    Ok(FuseOutcome {
        algo: opts.algo,
        fixes: s.fixes_used,
        rejected: s.rejected,
        late: s.late,
        nav_updates: s.nav_updates,
        bias_est: s.final_bias,
        scale_est: s.final_scale,
        layout: s.layout,
        rms_forward: rms(&r.forward),
        rms_smoothed: rms(&r.smoothed),
        details: FuseDetails::Files(r),
        health: HealthVerdict::default(),
        measurements: Vec::new(),
    })
}
