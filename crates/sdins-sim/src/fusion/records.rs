//! INS/GNSS fusion on recorded data: an IMU record (`imu_file`) and GNSS fixes
//! (`gnss_file`) through the error-state filter (`sdins_core::aiding::ekf`) and,
//! optionally, the Rauch–Tung–Striebel smoother ([`crate::fusion::smoother`]), with full-rate
//! output (one point per navigation update, forward and smoothed).
//!
//! ## Time
//! Fixes are on the IMU file's clock (see `gnss_file::to_imu_time`). The navigation starts
//! at the first IMU sample boundary at or after the initialising time (the first fix for
//! [`RecordInit::FirstFix`], the record's start otherwise); an IMU stamp marks the end of
//! its sample interval. Output times are on the IMU file's clock.
//!
//! ## Initial state ([`RecordInit`])
//! * `Given`: a full initial state at the record's start and its σ.
//! * `FirstFix`: position from the first fix (antenna minus `C_b^n l`), velocity from it
//!   (or, without a velocity, from the difference to the second fix, σ = √2 σ_p/Δt),
//!   attitude given with its roll/pitch/yaw σ, which is mapped to the attitude-error
//!   covariance by `P_ε = M⁻¹ diag(σ²) M⁻ᵀ` with the Euler-error matrix
//!   [`euler_error_matrix`]; the fix used to initialise is not applied again.
//! * `StaticCoarse`: the vehicle is at rest for the first `window_s`: the two-step coarse
//!   alignment (`sdins_core::align::coarse`) of that window's mean gives the attitude,
//!   the first fix the position, zero velocity. The attitude σ is the first-order
//!   coarse-alignment error of the bias priors (tilt `σ_ba/g`, heading
//!   `σ_bg/(Ω cos L)`), refused beyond the linearised filter's 10° limit.
//!
//! ## Scale factors
//! With [`RecordOptions::scale_factors`] the 21-state filter also estimates the
//! accelerometer and gyro scale factors (random constants from 0 with the given prior σ;
//! `sdins_core::aiding::ekf`).

use crate::cancel::CancelToken;
use crate::fusion::engine::{run_engine, EngineEvent, Event, Row, Start};
use crate::fusion::simulated::{
    engine_config, noise_from_model, FuseError, InitSigma, ScaleFactorPrior,
};
use crate::io::imu_file::ImuData;
use crate::io::navego_params::NavegoImuParams;
use crate::sensors::gnss_fix::GnssFix;
use crate::sensors::imu_error::{ImuErrorModel, DEG};
use sdins_core::aiding::ekf::{NoiseModel, UpdateReport, CHI2_999, DEFAULT_MAX_LATENCY_S};
use sdins_core::aiding::error_model::{
    position_scale, StateMat, I_ATT, I_BA, I_BG, I_POS, I_VEL, N_STATES,
};
use sdins_core::aiding::layout::{BlockKind, Cov, StateLayout, XVec};
use sdins_core::aiding::linalg::MAX_ROWS;
use sdins_core::aiding::meas::{MeasKind, Measurement};
use sdins_core::aiding::sensors::AidingMeas;
use sdins_core::align::coarse::{align as coarse_align, CoarseMethod, StaticMean};
use sdins_core::align::Site;
use sdins_core::coning::Increment;
use sdins_core::earth::EarthModel;
use sdins_core::math::{c_b_n_from_euler, Euler, Mat3, Vec3};
use sdins_core::nav::{AlgorithmSpec, InitialState, NavState};

/// The filter's model of a recorded IMU: noise and bias models, bias priors and the
/// known bias that is subtracted (initial bias estimate).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecordModel {
    /// white noise and bias dynamics
    pub noise: NoiseModel,
    /// prior σ of the residual accelerometer bias \[m/s²\]
    pub accel_bias_sigma_mps2: Vec3,
    /// prior σ of the residual gyro bias \[rad/s\]
    pub gyro_bias_sigma_rps: Vec3,
    /// known accelerometer bias, subtracted \[m/s²\]
    pub accel_bias0_mps2: Vec3,
    /// known gyro bias, subtracted \[rad/s\]
    pub gyro_bias0_rps: Vec3,
}

impl RecordModel {
    /// From an sdins IMU error model (a grade preset or a scenario's `[imu]`), as the
    /// simulated runs use it.
    pub fn from_error_model(m: &ImuErrorModel) -> Self {
        let (noise, s_ba, s_bg, b_a, b_g) = noise_from_model(m);
        Self {
            noise,
            accel_bias_sigma_mps2: s_ba,
            gyro_bias_sigma_rps: s_bg,
            accel_bias0_mps2: b_a,
            gyro_bias0_rps: b_g,
        }
    }

    /// From NaveGo's IMU parameters, the way NaveGo's own example uses them: the static
    /// biases `ab_sta`, `gb_sta` are known and subtracted; the data's actual static bias
    /// differs from them by up to ±10 % (uniform), a residual of σ = 0.1·b_sta/√3; the
    /// dynamic bias is first-order Gauss–Markov with σ = `b_dyn`, T = `b_corr`; white
    /// noise `arw`, `vrw`; bias random walks `arrw`, `vrrw`. One bias state per axis
    /// carries both: prior σ² = (0.1 b_sta/√3)² + b_dyn², dynamics those of the
    /// Gauss–Markov part (the residual constant, once estimated, leaves a state whose
    /// modelled decay is immaterial).
    pub fn from_navego(p: &NavegoImuParams) -> Self {
        let v = Vec3::from;
        let res = |b: [f64; 3], dyn_: [f64; 3]| {
            Vec3::from_fn(|i, _| (0.1 * b[i] / 3f64.sqrt()).hypot(dyn_[i]))
        };
        let tau = |t: [f64; 3], s: [f64; 3]| {
            Vec3::from_fn(|i, _| {
                if s[i] > 0.0 && t[i] > 0.0 {
                    t[i]
                } else {
                    f64::INFINITY
                }
            })
        };
        Self {
            noise: NoiseModel {
                arw_rad_per_sqrt_s: v(p.arw_rad_per_sqrt_s),
                vrw_mps_per_sqrt_s: v(p.vrw_mps_per_sqrt_s),
                accel_bias_gm_mps2: res(p.ab_sta_mps2, p.ab_dyn_mps2),
                accel_bias_tau_s: tau(p.ab_corr_s, p.ab_dyn_mps2),
                gyro_bias_gm_rps: res(p.gb_sta_rps, p.gb_dyn_rps),
                gyro_bias_tau_s: tau(p.gb_corr_s, p.gb_dyn_rps),
                accel_bias_rw: v(p.vrrw_mps2_per_sqrt_s),
                gyro_bias_rw: v(p.arrw_rps_per_sqrt_s),
            },
            accel_bias_sigma_mps2: res(p.ab_sta_mps2, p.ab_dyn_mps2),
            gyro_bias_sigma_rps: res(p.gb_sta_rps, p.gb_dyn_rps),
            accel_bias0_mps2: v(p.ab_sta_mps2),
            gyro_bias0_rps: v(p.gb_sta_rps),
        }
    }
}

/// How the navigation state is initialised.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum RecordInit {
    /// a full state at the record's start, with σ
    Given {
        /// the state (validated by `initial::validate_initial_state` by the caller)
        state: InitialState,
        /// its σ
        sigma: InitSigma,
    },
    /// position and velocity from the first fix, a given attitude
    FirstFix {
        /// roll, pitch, yaw \[rad\]
        rpy_rad: [f64; 3],
        /// their σ \[rad\]
        rpy_sigma_rad: [f64; 3],
    },
    /// at rest for the first `window_s` seconds: coarse alignment, position from the
    /// first fix
    StaticCoarse {
        /// static window \[s\]
        window_s: f64,
    },
}

/// Options of a fused run on recorded data.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordOptions {
    /// mechanization
    pub algo: AlgorithmSpec,
    /// earth model
    pub earth: EarthModel,
    /// covariance propagation rate \[Hz\]
    pub cov_rate_hz: f64,
    /// NIS gate by dof 1…12 (None: no gating)
    pub gate_chi2: Option<[f64; MAX_ROWS]>,
    /// consecutive rejections before the reset policy
    pub max_consecutive_rejections: u32,
    /// GNSS antenna lever arm, body FRD \[m\]
    pub lever_arm_b_m: [f64; 3],
    /// non-holonomic constraint σ \[m/s\] (body = vehicle frame), applied at the
    /// covariance rate
    pub nhc_sigma_mps: Option<f64>,
    /// zero-velocity updates of σ \[m/s\] when the stationarity detector declares rest
    pub zupt_detector: Option<(f64, crate::fusion::detector::DetectorSettings)>,
    /// run the smoother
    pub smooth: bool,
    /// estimate accelerometer and gyro scale factors (the 21-state filter)
    pub scale_factors: Option<ScaleFactorPrior>,
    /// output rows near `t_start + k·every_s` \[s\] (None: every navigation update)
    pub every_s: Option<f64>,
    /// largest latency of a measurement \[s\]
    pub max_latency_s: f64,
    /// the aiding sensors' measurements and the filter's model of them
    pub aiding: AidingRecord,
}

/// Recorded measurements of the aiding sensors (barometer, odometer, magnetometer, dual
/// antenna, body velocity) and the sensor settings that give the filter's states and
/// priors ([`crate::sensors::aiding::add_blocks`]).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct AidingRecord {
    /// the sensors' settings (which blocks, their priors)
    pub config: crate::sensors::aiding::AidingConfig,
    /// the measurements, times of validity on the IMU file's clock, in time order
    pub meas: Vec<AidingMeas>,
}

impl Default for RecordOptions {
    fn default() -> Self {
        Self {
            algo: AlgorithmSpec::new(sdins_core::nav::AlgorithmKind::SongLeeComplete, 2),
            earth: EarthModel::WGS84,
            cov_rate_hz: 10.0,
            gate_chi2: Some(CHI2_999),
            max_consecutive_rejections: 5,
            lever_arm_b_m: [0.0; 3],
            nhc_sigma_mps: None,
            zupt_detector: None,
            smooth: false,
            scale_factors: None,
            every_s: None,
            max_latency_s: DEFAULT_MAX_LATENCY_S,
            aiding: AidingRecord::default(),
        }
    }
}

/// One output point (an output row of the loop: by default every navigation update).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecordPoint {
    /// time on the IMU file's clock \[s\]
    pub t_s: f64,
    /// the navigation state (its `t_s` counts from the navigation start)
    pub state: NavState,
    /// bias estimates (accelerometer \[m/s²\], gyro \[rad/s\])
    pub bias: (Vec3, Vec3),
    /// 1σ of position N, E, D \[m\], velocity N, E, D \[m/s\], attitude error ε N, E, D
    /// \[rad\] (at the latest covariance epoch)
    pub sigma_nav: [f64; 9],
    /// 1σ of the roll, pitch, yaw errors \[rad\]
    pub sigma_euler_rad: [f64; 3],
    /// 1σ of the accelerometer \[m/s²\] and gyro \[rad/s\] bias errors
    pub sigma_bias: [f64; 6],
    /// scale-factor estimates (accelerometer, gyro; dimensionless; zero with 15 states)
    pub scale: (Vec3, Vec3),
    /// 1σ of the accelerometer and gyro scale-factor errors (zero with 15 states)
    pub sigma_scale: [f64; 6],
}

/// What the observer receives.
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub enum RecordEvent<'a> {
    /// a forward navigation update
    Forward(&'a RecordPoint),
    /// a measurement update
    Update(&'a UpdateReport),
    /// a smoothed navigation update (after the forward pass, in time order)
    Smoothed(&'a RecordPoint),
}

/// Summary of a run on recorded data.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct RecordSummary {
    /// fixes applied or rejected (the initialising fix excluded)
    pub fixes_used: u64,
    /// fixes rejected by the gate
    pub rejected: u64,
    /// measurements refused as late
    pub late: u64,
    /// navigation updates
    pub nav_updates: u64,
    /// covariance epochs
    pub cov_epochs: u64,
    /// navigation start on the IMU clock \[s\]
    pub t_start_s: f64,
    /// the initial state used
    pub init: InitialState,
    /// final bias estimates (accelerometer \[m/s²\], gyro \[rad/s\])
    pub final_bias: (Vec3, Vec3),
    /// final scale-factor estimates (zero with 15 states)
    pub final_scale: (Vec3, Vec3),
    /// bytes held by the smoother log (0 without smoothing)
    pub smoother_bytes: usize,
    /// the state layout
    pub layout: StateLayout,
}

/// The matrix `M` of the first-order Euler-angle errors in terms of the attitude error
/// ε (NED, convention G: `Ĉ = (I + [ε×]) C`): `(δφ, δθ, δψ) = M ε` with
/// `M = [[cψ/cθ, sψ/cθ, 0], [−sψ, cψ, 0], [cψ tθ, sψ tθ, 1]]` (Titterton & Weston
/// (11.4) family; the inverse of the map from Euler-angle rates to the navigation-frame
/// rotation rate).
pub fn euler_error_matrix(c_b_n: &Mat3) -> Mat3 {
    let e = sdins_core::math::euler_from_c_b_n(c_b_n);
    let (sy, cy) = e.yaw_rad.sin_cos();
    let (sp, cp) = e.pitch_rad.sin_cos();
    let cp = if cp.abs() < 1e-9 { 1e-9 } else { cp };
    Mat3::new(
        cy / cp,
        sy / cp,
        0.0,
        -sy,
        cy,
        0.0,
        cy * sp / cp,
        sy * sp / cp,
        1.0,
    )
}

/// 1σ of a covariance epoch in output units.
#[derive(Clone, Copy, Debug, Default)]
struct Sig {
    nav: [f64; 9],
    eul: [f64; 3],
    bias: [f64; 6],
    scale: [f64; 6],
}

fn sigmas(p: &Cov, layout: &StateLayout, c_b_n: &Mat3, scale: &Vec3) -> Sig {
    let sd = |i: usize| p[(i, i)].max(0.0).sqrt();
    let mut nav = [0.0; 9];
    for i in 0..3 {
        nav[i] = sd(I_POS + i) * scale[i].abs();
        nav[3 + i] = sd(I_VEL + i);
        nav[6 + i] = sd(I_ATT + i);
    }
    let m = euler_error_matrix(c_b_n);
    let pa = p.fixed_view::<3, 3>(I_ATT, I_ATT).into_owned();
    let pe = m * pa * m.transpose();
    let eul = [
        pe[(0, 0)].max(0.0).sqrt(),
        pe[(1, 1)].max(0.0).sqrt(),
        pe[(2, 2)].max(0.0).sqrt(),
    ];
    let mut b = [0.0; 6];
    for (i, bi) in b.iter_mut().enumerate() {
        *bi = sd(I_BA + i);
    }
    let mut sf = [0.0; 6];
    if let (Some(a), Some(g)) = (
        layout.offset(BlockKind::AccelScale),
        layout.offset(BlockKind::GyroScale),
    ) {
        for i in 0..3 {
            sf[i] = sd(a + i);
            sf[3 + i] = sd(g + i);
        }
    }
    Sig {
        nav,
        eul,
        bias: b,
        scale: sf,
    }
}

fn scale_at(earth: &EarthModel, s: &NavState) -> Vec3 {
    let r = earth.radii(s.lat_rad);
    position_scale(r.r_m_m, r.r_n_m, s.lat_rad.cos(), s.h_m)
}

fn opt_err(name: &'static str, msg: impl Into<String>) -> FuseError {
    FuseError::Option(name, msg.into())
}

/// The event stream of a record: the IMU samples from the navigation start, each fix
/// delivered before the sample during which it arrives (its time is its time of validity
/// and its arrival).
struct RecordStream<'a> {
    incs: &'a [Increment],
    fixes: &'a [GnssFix],
    aid: &'a [AidingMeas],
    t_start_s: f64,
    dt_s: f64,
    i: usize,
    f: usize,
    a: usize,
}

impl Iterator for RecordStream<'_> {
    type Item = Event;
    fn next(&mut self) -> Option<Event> {
        let inc = self.incs.get(self.i)?;
        let t_end = self.t_start_s + self.dt_s * (self.i + 1) as f64;
        if let Some(fix) = self.fixes.get(self.f) {
            if fix.t_s <= t_end + 1e-6 {
                self.f += 1;
                return Some(Event::Gnss {
                    fix: *fix,
                    arrival_s: fix.t_s,
                });
            }
        }
        if let Some(m) = self.aid.get(self.a) {
            let t = m.t_valid_s();
            if t <= t_end + 1e-6 {
                self.a += 1;
                return Some(Event::Meas {
                    meas: *m,
                    arrival_s: t,
                });
            }
        }
        self.i += 1;
        Some(Event::Imu {
            t_s: t_end,
            inc: *inc,
            truth: None,
        })
    }
}

/// False-alarm rate per window of the static-window check: strong evidence of motion
/// only (over a 600 s window of 1 s windows the chance of refusing a record at rest is
/// 6e-4).
pub const STATIC_CHECK_ALPHA: f64 = 1e-6;

/// `--static-s`: refuse a window that moves. The stationarity detector
/// ([`crate::fusion::detector`], 1 s windows or the nearest supported size that fits) with
/// the coarse attitude's earth rate, the known biases removed and the prior bias σ's as
/// the residual ones, at [`STATIC_CHECK_ALPHA`] per window over the disjoint windows of
/// the static interval. Without a noise model (an ideal IMU) or with residual biases
/// that would decide the test, there is nothing to judge by and the window is accepted.
#[allow(clippy::too_many_arguments)]
fn static_window_check(
    imu: &ImuData,
    m_samples: usize,
    model: &RecordModel,
    c_b_n: &Mat3,
    site: &Site,
    earth: &EarthModel,
    lat_rad: f64,
) -> Result<(), FuseError> {
    use crate::fusion::detector::{AnyDetector, DetectorSettings, WINDOWS};
    let dt = imu.dt_s;
    // the largest supported window of at most 1 s that fits the interval
    let Some(w) = WINDOWS
        .iter()
        .copied()
        .filter(|w| (*w as f64) * dt <= 1.0 + 1e-9 && *w <= m_samples)
        .max()
    else {
        return Ok(());
    };
    let settings = DetectorSettings {
        window_s: w as f64 * dt,
        false_alarm: STATIC_CHECK_ALPHA,
    };
    let Ok(mut det) = AnyDetector::from_filter_noise(
        &settings,
        &model.noise,
        dt,
        site.g_mps2,
        &model.accel_bias_sigma_mps2,
        &model.gyro_bias_sigma_rps,
    ) else {
        return Ok(());
    };
    if det
        .set_estimates(
            &model.accel_bias0_mps2,
            &model.gyro_bias0_rps,
            c_b_n,
            &earth.omega_ie_n(lat_rad),
        )
        .is_err()
    {
        return Ok(());
    }
    for (k, inc) in imu.increments[..m_samples].iter().enumerate() {
        // the disjoint windows: the report of every W-th sample
        if let Ok(Some(false)) = det.push(inc) {
            if (k + 1) % w == 0 {
                let t1 = imu.t0_s + dt * k as f64;
                return Err(opt_err(
                    "static_window_s",
                    format!(
                        "the IMU moves in the static window: the {:.2} s ending at t = {t1} s is declared moving by the stationarity detector (false-alarm rate {STATIC_CHECK_ALPHA:e} per window); shorten --static-s or give the attitude (--attitude-deg, --init)",
                        w as f64 * dt
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Run the filter (and the smoother) over recorded data. `fixes` must be on the IMU
/// clock and in time order (the readers guarantee it); fixes outside the record are
/// ignored (clip them first with `gnss_file::clip_to_imu_span` to count them).
pub fn fuse_records(
    imu: &ImuData,
    fixes: &[GnssFix],
    model: &RecordModel,
    init: &RecordInit,
    opts: &RecordOptions,
    cancel: &CancelToken,
    mut observe: impl FnMut(RecordEvent<'_>),
) -> Result<RecordSummary, FuseError> {
    let dt = imu.dt_s;
    let n = opts.algo.samples.clamp(1, 4);
    let earth = opts.earth;
    let lever = Vec3::from(opts.lever_arm_b_m);
    if fixes.is_empty() {
        return Err(opt_err("gnss", "no GNSS fix inside the IMU record"));
    }
    let (start_k, init_state, p0, skip_fixes) = initial(imu, fixes, model, init, &earth, lever)?;
    crate::io::initial::validate_initial_state(&init_state)
        .map_err(|e| opt_err("init", e.to_string()))?;
    if !p0.iter().all(|x| x.is_finite()) {
        return Err(opt_err("init", "initial covariance is not finite"));
    }
    let mut layout = model.noise.layout();
    let mut p0n = Cov::zeros();
    p0n.fixed_view_mut::<N_STATES, N_STATES>(0, 0)
        .copy_from(&p0);
    if let Some(sp) = &opts.scale_factors {
        sp.validate()?;
        layout = layout
            .with_scale_factors()
            .map_err(|e| opt_err("scale_factors", e.to_string()))?;
        let (a, g) = (
            layout.offset(BlockKind::AccelScale),
            layout.offset(BlockKind::GyroScale),
        );
        if let (Some(a), Some(g)) = (a, g) {
            for i in 0..3 {
                p0n[(a + i, a + i)] = (sp.accel_ppm[i] * 1e-6).powi(2);
                p0n[(g + i, g + i)] = (sp.gyro_ppm[i] * 1e-6).powi(2);
            }
        }
    }
    opts.aiding
        .config
        .validate()
        .map_err(|e| opt_err("aiding", e.to_string()))?;
    let layout = crate::sensors::aiding::add_blocks(&opts.aiding.config, layout, &mut p0n)
        .map_err(|e| opt_err("aiding", e.to_string()))?;
    let mut est0 = XVec::zeros();
    for i in 0..3 {
        est0[I_BA + i] = model.accel_bias0_mps2[i];
        est0[I_BG + i] = model.gyro_bias0_rps[i];
    }
    // record start: the first interval begins one sample before the first stamp
    let t_rec0 = imu.t0_s - dt;
    let t_start = t_rec0 + dt * start_k as f64;
    let samples = &imu.increments[start_k.min(imu.increments.len())..];
    let total = (samples.len() / n) as u64;
    let mut cfg = engine_config(
        opts.algo,
        earth,
        dt,
        opts.cov_rate_hz,
        model.noise,
        lever,
        Some(opts.every_s.unwrap_or(dt * n as f64)),
        total,
    )?;
    cfg.gate_chi2 = opts.gate_chi2;
    cfg.max_consecutive_rejections = opts.max_consecutive_rejections;
    cfg.max_latency_s = opts.max_latency_s;
    cfg.nhc_sigma_mps = opts.nhc_sigma_mps;
    cfg.zupt_sigma_mps = opts.zupt_detector.map(|z| z.0);
    cfg.zupt_detector = opts.zupt_detector.map(|z| z.1);
    cfg.smooth = opts.smooth;
    // fixes before the navigation start (and the initialising one) are not used
    let mut first = skip_fixes;
    while first < fixes.len() && fixes[first].t_s - t_start <= 1e-9 {
        first += 1;
    }
    // aiding measurements before the navigation start are not used
    let a0 = opts
        .aiding
        .meas
        .iter()
        .position(|m| m.t_valid_s() - t_start > 1e-9)
        .unwrap_or(opts.aiding.meas.len());
    let mut stream = RecordStream {
        incs: samples,
        fixes: &fixes[first.min(fixes.len())..],
        aid: &opts.aiding.meas[a0..],
        t_start_s: t_start,
        dt_s: dt,
        i: 0,
        f: 0,
        a: 0,
    };
    let start = Start {
        t_start_s: t_start,
        state: init_state,
        layout,
        p0: p0n,
        est0,
        truth: None,
        sensor_truth: None,
    };
    // σ of the forward rows change only at covariance epochs (cached by epoch), of the
    // smoothed rows they come from the backward pass
    let mut cached: Option<(usize, Sig)> = None;
    let mut smoothed: Vec<Sig> = Vec::new();
    let point = |row: &Row<'_>, sig: &Sig| {
        let (a, g) = (
            row.layout.offset(BlockKind::AccelScale),
            row.layout.offset(BlockKind::GyroScale),
        );
        RecordPoint {
            t_s: row.t_s,
            state: *row.state,
            bias: (vec3_at(row.est, Some(I_BA)), vec3_at(row.est, Some(I_BG))),
            sigma_nav: sig.nav,
            sigma_euler_rad: sig.eul,
            sigma_bias: sig.bias,
            scale: (vec3_at(row.est, a), vec3_at(row.est, g)),
            sigma_scale: sig.scale,
        }
    };
    let mut sink = |ev: EngineEvent<'_>| match ev {
        EngineEvent::Forward(row) => {
            let sig = match (cached, row.p) {
                (Some((e, s)), _) if e == row.epoch => s,
                (_, Some(p)) => {
                    let c = row.cov_state;
                    let s = sigmas(p, row.layout, &c.c_b_n, &scale_at(&earth, c));
                    cached = Some((row.epoch, s));
                    s
                }
                _ => Sig::default(),
            };
            observe(RecordEvent::Forward(&point(row, &sig)));
        }
        EngineEvent::Update(u) => observe(RecordEvent::Update(u)),
        EngineEvent::SmoothedCov { epoch, p, state } => {
            if smoothed.len() <= epoch {
                smoothed.resize(epoch + 1, Sig::default());
            }
            smoothed[epoch] = sigmas(p, &layout, &state.c_b_n, &scale_at(&earth, state));
        }
        EngineEvent::Smoothed(row) => {
            let sig = smoothed.get(row.epoch).copied().unwrap_or_default();
            observe(RecordEvent::Smoothed(&point(row, &sig)));
        }
    };
    let s = run_engine(&mut stream, &start, &cfg, cancel, &mut sink)?;
    let c = s.counts[MeasKind::Gnss.index()];
    let (a, g) = (
        s.layout.offset(BlockKind::AccelScale),
        s.layout.offset(BlockKind::GyroScale),
    );
    Ok(RecordSummary {
        fixes_used: c.applied + c.rejected + c.late,
        rejected: c.rejected,
        late: s.counts.iter().map(|c| c.late).sum(),
        nav_updates: s.nav_updates,
        cov_epochs: s.cov_epochs,
        t_start_s: t_start,
        init: init_state,
        final_bias: (vec3_at(&s.est, Some(I_BA)), vec3_at(&s.est, Some(I_BG))),
        final_scale: (vec3_at(&s.est, a), vec3_at(&s.est, g)),
        smoother_bytes: s.smoother_bytes,
        layout: s.layout,
    })
}

fn vec3_at(x: &XVec, o: Option<usize>) -> Vec3 {
    o.map_or(Vec3::zeros(), |o| Vec3::new(x[o], x[o + 1], x[o + 2]))
}

/// The initial state of a record: (first sample index, state, P0 of the 15 states, fixes
/// used to initialise).
fn initial(
    imu: &ImuData,
    fixes: &[GnssFix],
    model: &RecordModel,
    init: &RecordInit,
    earth: &EarthModel,
    lever: Vec3,
) -> Result<(usize, InitialState, StateMat, usize), FuseError> {
    let dt = imu.dt_s;
    let t_rec0 = imu.t0_s - dt;
    let mut p0 = StateMat::zeros();
    let mut skip_fixes = 0usize;
    let earth = *earth;
    let (start_k, init_state) = match *init {
        RecordInit::Given { state, sigma } => {
            let sc = {
                let r = earth.radii(state.lat_rad);
                position_scale(r.r_m_m, r.r_n_m, state.lat_rad.cos(), state.h_m)
            };
            for i in 0..3 {
                p0[(I_POS + i, I_POS + i)] = (sigma.pos_ned_m[i] / sc[i]).powi(2);
                p0[(I_VEL + i, I_VEL + i)] = sigma.vel_ned_mps[i].powi(2);
                p0[(I_ATT + i, I_ATT + i)] = sigma.att_rad[i].powi(2);
            }
            (0usize, state)
        }
        RecordInit::FirstFix {
            rpy_rad,
            rpy_sigma_rad,
        } => {
            let f0 = fixes[0];
            let c = c_b_n_from_euler(&Euler::new(rpy_rad[0], rpy_rad[1], rpy_rad[2]));
            let (st, pp) = from_fix(&earth, fixes, c, lever)?;
            p0 += pp;
            let m = euler_error_matrix(&c);
            let mi = m
                .try_inverse()
                .ok_or_else(|| opt_err("attitude", "pitch at ±90°: Euler angles undefined"))?;
            let d = Mat3::from_diagonal(&Vec3::from(rpy_sigma_rad).map(|x| x * x));
            p0.fixed_view_mut::<3, 3>(I_ATT, I_ATT)
                .copy_from(&(mi * d * mi.transpose()));
            skip_fixes = 1;
            // first sample boundary at or after the fix
            let k = ((f0.t_s - t_rec0) / dt - 1e-6).ceil().max(0.0) as usize;
            (k, st)
        }
        RecordInit::StaticCoarse { window_s } => {
            if !(window_s.is_finite() && window_s >= dt) {
                return Err(opt_err(
                    "static_window_s",
                    format!("must be finite and at least one sample, got {window_s}"),
                ));
            }
            let m_samples = ((window_s / dt).round() as usize).min(imu.increments.len());
            let mut mean = StaticMean::new();
            for inc in &imu.increments[..m_samples] {
                let c = Increment::new(
                    inc.dtheta_b_rad - model.gyro_bias0_rps * dt,
                    inc.dv_b_mps - model.accel_bias0_mps2 * dt,
                );
                mean.add(&c, dt);
            }
            let f0 = fixes[0];
            let site = Site::from_earth(&earth, f0.lat_rad, f0.h_m);
            let c = coarse_align(CoarseMethod::TwoStep, &mean, &site)
                .map_err(|e| opt_err("static_window_s", format!("coarse alignment: {e}")))?;
            static_window_check(imu, m_samples, model, &c, &site, &earth, f0.lat_rad)?;
            let (mut st, pp) = from_fix(&earth, &fixes[..1], c, lever)?;
            st.v_n_mps = Vec3::zeros();
            p0.fixed_view_mut::<3, 3>(I_POS, I_POS)
                .copy_from(&pp.fixed_view::<3, 3>(I_POS, I_POS));
            let g = site.g_mps2;
            let oc = site.omega_ie_rps * f0.lat_rad.cos();
            let s_ba = model.accel_bias_sigma_mps2;
            let s_bg = model.gyro_bias_sigma_rps;
            let tilt = s_ba.x.hypot(s_ba.y) / g;
            let yaw = s_bg.x.hypot(s_bg.y) / oc + tilt * f0.lat_rad.tan().abs();
            if tilt > 10.0 * DEG || yaw > 10.0 * DEG {
                return Err(opt_err(
                    "init",
                    format!(
                        "coarse alignment with these bias priors leaves σ tilt {:.2}°, heading {:.1}°: beyond the linearised filter's 10° (give the attitude with --attitude-deg or use --init)",
                        tilt / DEG,
                        yaw / DEG
                    ),
                ));
            }
            for i in 0..3 {
                p0[(I_VEL + i, I_VEL + i)] = 0.01f64.powi(2);
            }
            p0[(I_ATT, I_ATT)] = tilt * tilt;
            p0[(I_ATT + 1, I_ATT + 1)] = tilt * tilt;
            p0[(I_ATT + 2, I_ATT + 2)] = yaw * yaw;
            (0usize, st)
        }
    };
    for i in 0..3 {
        p0[(I_BA + i, I_BA + i)] = model.accel_bias_sigma_mps2[i].powi(2);
        p0[(I_BG + i, I_BG + i)] = model.gyro_bias_sigma_rps[i].powi(2);
    }
    Ok((start_k, init_state, p0, skip_fixes))
}

/// Errors of output points against a reference trajectory, matched by time: RMSE of
/// roll, pitch, yaw \[rad\], v_N, v_E, v_D \[m/s\], N, E, D \[m\] over every matched point,
/// and the fraction of matched points after `t_check_s` whose error lies within ±3σ,
/// per axis.
#[derive(Clone, Debug, PartialEq)]
pub struct TruthComparison {
    earth: EarthModel,
    truth: Vec<crate::truth::TruthSample>,
    next: usize,
    t_check_s: f64,
    sq: [f64; 9],
    n: u64,
    inside: [u64; 9],
    n_check: u64,
}

/// Axis names of [`TruthComparison`], in order.
pub const COMPARISON_AXES: [&str; 9] = ["roll", "pitch", "yaw", "v_N", "v_E", "v_D", "N", "E", "D"];

impl TruthComparison {
    /// Compare against `truth` (times on the IMU clock, increasing); the ±3σ fractions
    /// count points after `t_check_s`.
    pub fn new(earth: EarthModel, truth: Vec<crate::truth::TruthSample>, t_check_s: f64) -> Self {
        Self {
            earth,
            truth,
            next: 0,
            t_check_s,
            sq: [0.0; 9],
            n: 0,
            inside: [0; 9],
            n_check: 0,
        }
    }
    /// The errors of a point (roll, pitch, yaw, v_N, v_E, v_D, N, E, D) if a reference
    /// sample lies within 1 µs of its time. Points must come in time order.
    pub fn add(&mut self, p: &RecordPoint) -> Option<[f64; 9]> {
        while self.next < self.truth.len() && self.truth[self.next].t_s < p.t_s - 1e-6 {
            self.next += 1;
        }
        let tr = self.truth.get(self.next)?;
        if (tr.t_s - p.t_s).abs() > 1e-6 {
            return None;
        }
        let ne = crate::nav::pipeline::nav_error(&self.earth, &p.state, tr);
        let e = [
            ne.euler_err_rad[0],
            ne.euler_err_rad[1],
            ne.euler_err_rad[2],
            ne.vel_err_ned_mps[0],
            ne.vel_err_ned_mps[1],
            ne.vel_err_ned_mps[2],
            ne.pos_err_ned_m[0],
            ne.pos_err_ned_m[1],
            ne.pos_err_ned_m[2],
        ];
        let s = [
            p.sigma_euler_rad[0],
            p.sigma_euler_rad[1],
            p.sigma_euler_rad[2],
            p.sigma_nav[3],
            p.sigma_nav[4],
            p.sigma_nav[5],
            p.sigma_nav[0],
            p.sigma_nav[1],
            p.sigma_nav[2],
        ];
        for (sq, ei) in self.sq.iter_mut().zip(&e) {
            *sq += ei * ei;
        }
        self.n += 1;
        if p.t_s > self.t_check_s {
            self.n_check += 1;
            for i in 0..9 {
                if e[i].abs() <= 3.0 * s[i] {
                    self.inside[i] += 1;
                }
            }
        }
        Some(e)
    }
    /// RMSE per axis (see [`COMPARISON_AXES`]).
    pub fn rmse(&self) -> [f64; 9] {
        let n = self.n.max(1) as f64;
        self.sq.map(|s| (s / n).sqrt())
    }
    /// Fraction of checked points within ±3σ, per axis.
    pub fn inside_3sigma(&self) -> [f64; 9] {
        let n = self.n_check.max(1) as f64;
        self.inside.map(|c| c as f64 / n)
    }
    /// Points matched.
    pub fn matched(&self) -> u64 {
        self.n
    }
}

/// Initial position and velocity from the first fix(es) with attitude `c` (the antenna at
/// lever arm `l`), and their covariance (position and velocity blocks of P0).
fn from_fix(
    earth: &EarthModel,
    fixes: &[GnssFix],
    c: Mat3,
    l: Vec3,
) -> Result<(InitialState, StateMat), FuseError> {
    let f0 = fixes[0];
    let r = earth.radii(f0.lat_rad);
    let sc = position_scale(r.r_m_m, r.r_n_m, f0.lat_rad.cos(), f0.h_m);
    let cl = c * l;
    let lat = f0.lat_rad - cl.x / sc.x;
    let lon = f0.lon_rad - cl.y / sc.y;
    let h = f0.h_m + cl.z;
    let mut p = StateMat::zeros();
    for i in 0..3 {
        for j in 0..3 {
            p[(I_POS + i, I_POS + j)] = f0.pos_cov_ned_m2[(i, j)] / (sc[i] * sc[j]);
        }
    }
    let (v, pv) = match (f0.vel, fixes.get(1)) {
        (Some((v, cv)), _) => (v, cv),
        (None, Some(f1)) if f1.t_s > f0.t_s => {
            let dt = f1.t_s - f0.t_s;
            let d = Vec3::new(
                (f1.lat_rad - f0.lat_rad) * sc.x,
                (f1.lon_rad - f0.lon_rad) * sc.y,
                -(f1.h_m - f0.h_m),
            );
            (d / dt, (f0.pos_cov_ned_m2 + f1.pos_cov_ned_m2) / (dt * dt))
        }
        _ => {
            return Err(opt_err(
                "init",
                "the first fix has no velocity and there is no second fix to difference",
            ))
        }
    };
    p.fixed_view_mut::<3, 3>(I_VEL, I_VEL).copy_from(&pv);
    Ok((
        InitialState {
            lat_rad: lat,
            lon_rad: lon,
            h_m: h,
            v_n_mps: v,
            c_b_n: c,
        },
        p,
    ))
}

/// A recorded data set simulated from a scenario: the IMU record (the scenario's IMU
/// errors of run `run`, FRD increments stamped at sample ends, `t0_s = δt`) and the GNSS
/// fixes of `gnss` (same clock), without keeping the truth in memory. The input of
/// [`fuse_records`] for benchmarks and for tests on a known truth (regenerate it with
/// `fuse::scenario_truth`).
pub fn record_from_scenario(
    scn: &crate::scenario::Scenario,
    gnss: &crate::sensors::gnss::GnssConfig,
    run: u64,
) -> Result<(ImuData, Vec<GnssFix>), FuseError> {
    record_from_scenario_with_aiding(scn, gnss, run).map(|(i, f, _)| (i, f))
}

/// [`record_from_scenario`] with the scenario's aiding sensors simulated too (their
/// measurements in time order on the same clock).
pub fn record_from_scenario_with_aiding(
    scn: &crate::scenario::Scenario,
    gnss: &crate::sensors::gnss::GnssConfig,
    run: u64,
) -> Result<(ImuData, Vec<GnssFix>, AidingRecord), FuseError> {
    use crate::truth::{TruthGenerator, TruthSample};
    let earth = scn.nav.earth.model();
    let dt = scn.imu.dt_s();
    let cfg = scn.truth_config();
    let generator = TruthGenerator::new(&scn.trajectory, cfg);
    let init = generator.initial_state();
    let n = generator.len_samples() as usize;
    let mut sensor =
        crate::sensors::imu_error::ImuErrorState::new(&scn.imu.model, scn.imu.seed, run)
            .map_err(|e| FuseError::Imu(e.to_string()))?;
    let mut gsim = crate::sensors::gnss::GnssSimulator::new(gnss, earth, run)?;
    let mut prev = TruthSample::new(
        0.0,
        Increment::default(),
        init.lat_rad,
        init.lon_rad,
        init.h_m,
        init.v_n_mps,
        init.c_b_n,
    );
    let mut incs = Vec::with_capacity(n);
    let mut fixes = Vec::new();
    let mut asim = scn
        .aiding
        .any()
        .then(|| crate::sensors::aiding::AidingSimulator::new(&scn.aiding, earth, run));
    let mut aid = Vec::new();
    let mut step_out = Vec::new();
    for ts in generator {
        incs.push(sensor.apply(&ts.inc, dt));
        gsim.step(&scn.trajectory, &prev, &ts, &mut fixes);
        if let Some(a) = asim.as_mut() {
            a.step(&scn.trajectory, &prev, &ts, &mut step_out);
            aid.append(&mut step_out);
        }
        prev = ts;
    }
    // per sample the sensors come in table order: sort by time of validity (stable)
    aid.sort_by(|a: &AidingMeas, b: &AidingMeas| a.t_valid_s().total_cmp(&b.t_valid_s()));
    Ok((
        ImuData {
            format: crate::io::imu_file::ImuFormat::Sdins,
            dt_s: dt,
            t0_s: dt,
            increments: incs,
            psins: None,
            detection: None,
            warnings: Vec::new(),
        },
        fixes,
        AidingRecord {
            config: scn.aiding.clone(),
            meas: aid,
        },
    ))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// M against a numerical Jacobian of the Euler angles of (I + [ε×]) C.
    #[test]
    fn euler_error_matrix_matches_numerical_jacobian() {
        let c = c_b_n_from_euler(&Euler::new(0.3, -0.4, 2.5));
        let m = euler_error_matrix(&c);
        let e0 = sdins_core::math::euler_from_c_b_n(&c);
        let h = 1e-7;
        for j in 0..3 {
            let mut eps = Vec3::zeros();
            eps[j] = h;
            let cp = sdins_core::math::Quat::from_rotvec(&eps).to_dcm() * c;
            let e = sdins_core::math::euler_from_c_b_n(&cp);
            let d = [
                (e.roll_rad - e0.roll_rad) / h,
                (e.pitch_rad - e0.pitch_rad) / h,
                (e.yaw_rad - e0.yaw_rad) / h,
            ];
            for i in 0..3 {
                // O(h) truncation plus rounding ε/h
                assert!(
                    (d[i] - m[(i, j)]).abs() < 1e-6,
                    "({i},{j}) {} vs {}",
                    d[i],
                    m[(i, j)]
                );
            }
        }
    }
}
