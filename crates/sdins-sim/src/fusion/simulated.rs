//! INS/GNSS fusion on a scenario: truth → IMU errors → GNSS → error-state filter
//! (`sdins_core::aiding::ekf`) → errors against the truth, with the filter's covariance.
//!
//! * Filter noise from the scenario's IMU error model: ARW, VRW, turn-on bias σ (prior
//!   of random-constant bias states), Gauss–Markov bias (σ, T; `q = 2σ²/T`), rate random
//!   walk; the fixed bias is known (initial estimate). With
//!   [`FuseOptions::scale_factors`] the filter has 21 states and estimates the
//!   accelerometer and gyro scale factors (random constants, prior σ from the option,
//!   initial estimate 0); the scenario's `accel_scale_ppm` / `gyro_scale_ppm` plus the
//!   diagonal of the misalignment matrices are then the true values. Not modelled (and
//!   therefore not to be simulated in consistency runs): scale factor (15-state filter),
//!   scale asymmetry, off-diagonal misalignment, g-sensitivity, flicker, quantization,
//!   saturation.
//! * Initial errors: position/velocity/attitude σ of [`FuseOptions::init_sigma`], drawn
//!   per run from P0 (`draw_initial_errors`, stream channel 10–12 of the GNSS seed) or
//!   zero; the attitude error is applied as `Ĉ = exp([ε×]) C` (convention G). The
//!   linearised filter is limited to initial attitude σ ≤ 10° per axis (larger is
//!   rejected: in-motion alignment from an unknown heading is not part of this filter).
//! * ZUPT is triggered by the scenario truth (speed below a threshold), NHC is applied
//!   whenever the truth is not at rest; both at the covariance rate.
//! * The observer sees every covariance epoch (true error in the filter's state
//!   coordinates and P, after that epoch's measurements) and every measurement report.
//! * With [`FuseOptions::smooth`], the covariance epochs are logged
//!   ([`crate::fusion::smoother::SmootherLog`]) and, after the forward pass, the
//!   Rauch–Tung–Striebel smoother's epochs arrive as [`FuseEvent::Smoothed`] in time
//!   order (true error of the smoothed state and the smoothed covariance).

use crate::cancel::{CancelToken, Cancelled};
use crate::fusion::smoother::{SmootherError, SmootherLog};
use crate::nav::pipeline::nav_error;
use crate::scenario::Scenario;
use crate::sensors::gnss::{GnssConfig, GnssConfigError, GnssSimulator};
use crate::sensors::gnss_fix::GnssFix;
use crate::sensors::imu_error::{
    ImuErrorModel, ImuErrorState, DEG, DPH, DPHPSH, DPSH, MPS_PER_SQRT_H,
};
use crate::sensors::imu_error::{UG, UG_PER_SQRT_H, UG_PER_SQRT_HZ};
use crate::truth::{lon_diff, TruthGenerator, TruthSample};
use nalgebra::{SMatrix, SVector};
use rand::SeedableRng;
use rand_chacha::ChaCha20Rng;
use rand_distr::{Distribution, StandardNormal};
use sdins_core::aiding::ekf::{
    correct_nav_state, Ekf, EkfConfig, FilterError, GnssMeasurement, NoiseModel, UpdateReport,
    CHI2_999,
};
use sdins_core::aiding::error_model::{
    StateMat, StateMatN, StateVec, I_ATT, I_BA, I_BG, I_POS, I_SA, I_SG, I_VEL, N_STATES,
    N_STATES_SF,
};
use sdins_core::coning::Increment;
use sdins_core::math::{Mat3, Quat, Vec3};
use sdins_core::nav::{AlgorithmSpec, AnyMechanization, InitialState, NavState};

/// Initial 1σ errors of position \[m NED\], velocity \[m/s NED\], attitude \[rad NED\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitSigma {
    /// position σ N, E, D \[m\]
    pub pos_ned_m: [f64; 3],
    /// velocity σ N, E, D \[m/s\]
    pub vel_ned_mps: [f64; 3],
    /// attitude σ N, E, D \[rad\]
    pub att_rad: [f64; 3],
}

impl Default for InitSigma {
    fn default() -> Self {
        Self {
            pos_ned_m: [3.0; 3],
            vel_ned_mps: [0.1; 3],
            att_rad: [1e-3, 1e-3, 5e-3],
        }
    }
}

/// Options of a fused run.
#[derive(Clone, Debug, PartialEq)]
pub struct FuseOptions {
    /// mechanization (any of the four, N = 1..4)
    pub algo: AlgorithmSpec,
    /// covariance propagation rate \[Hz\] (≤ the navigation update rate)
    pub cov_rate_hz: f64,
    /// initial errors (σ)
    pub init_sigma: InitSigma,
    /// draw the initial errors from P0 (else start at the truth)
    pub draw_initial_errors: bool,
    /// NIS gate thresholds by dof 1…6 (None: no gating)
    pub gate_chi2: Option<[f64; 6]>,
    /// consecutive rejections before the reset policy
    pub max_consecutive_rejections: u32,
    /// ZUPT σ \[m/s\] and the truth speed below which the vehicle is at rest \[m/s\]
    pub zupt: Option<(f64, f64)>,
    /// NHC σ \[m/s\]
    pub nhc_sigma_mps: Option<f64>,
    /// tell the filter the GNSS lever arm (false: the filter assumes zero)
    pub model_lever_arm: bool,
    /// stop after this time \[s\]
    pub until_s: Option<f64>,
    /// run the Rauch–Tung–Striebel smoother after the forward pass
    pub smooth: bool,
    /// in-motion alignment from the GNSS track instead of a known initial attitude
    pub in_motion: Option<InMotionInit>,
    /// estimate accelerometer and gyro scale factors (the 21-state filter) with this prior
    pub scale_factors: Option<ScaleFactorPrior>,
}

/// Prior 1σ of the scale-factor states of the 21-state filter, per body axis \[ppm\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScaleFactorPrior {
    /// accelerometer scale-factor σ \[ppm\]
    pub accel_ppm: [f64; 3],
    /// gyro scale-factor σ \[ppm\]
    pub gyro_ppm: [f64; 3],
}

impl ScaleFactorPrior {
    /// The same σ on every axis: `accel_ppm` for the accelerometers, `gyro_ppm` for the gyros.
    pub fn uniform(accel_ppm: f64, gyro_ppm: f64) -> Self {
        Self {
            accel_ppm: [accel_ppm; 3],
            gyro_ppm: [gyro_ppm; 3],
        }
    }
    /// Every σ finite and in \[0, 100 000\] ppm.
    pub fn validate(&self) -> Result<(), FuseError> {
        if self
            .accel_ppm
            .iter()
            .chain(self.gyro_ppm.iter())
            .any(|x| !x.is_finite() || *x < 0.0 || *x > 1e5)
        {
            return Err(FuseError::Option(
                "scale_factors",
                "prior σ must be finite and in [0, 100000] ppm".into(),
            ));
        }
        Ok(())
    }
}

/// In-motion alignment for a ground vehicle from an unknown heading: the filter starts at
/// the first GNSS fix whose horizontal speed is at least `min_speed_mps`. Heading from the
/// GNSS track, `ψ = atan2(v_E, v_N)` (the velocity of a car points along its body x axis
/// up to sideslip: the non-holonomic constraint), advanced to the start sample with the
/// measured z rate; pitch `θ = atan2(−v_D, |v_h|)`, roll 0 (level road); position and
/// velocity from the fix (lever arm removed). σ: heading
/// `√(σ_track² + (σ_vN² sin²ψ + σ_vE² cos²ψ)/|v_h|²)`, roll and pitch `tilt_sigma_rad`,
/// mapped to the attitude-error covariance with the Euler-error matrix
/// (`fuse_records::euler_error_matrix`). This "coarse heading from the track, then the
/// linear filter" formulation is valid for any initial heading because the coarse step
/// leaves errors of a fraction of a degree, inside the linearised filter's range; it needs
/// motion without large sideslip (not a hovering or crabbing vehicle).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InMotionInit {
    /// smallest horizontal speed of the starting fix \[m/s\]
    pub min_speed_mps: f64,
    /// roll and pitch σ of the level assumption \[rad\]
    pub tilt_sigma_rad: f64,
    /// heading σ of the track-to-heading assumption (sideslip, mounting) \[rad\]
    pub track_sigma_rad: f64,
}

impl Default for InMotionInit {
    fn default() -> Self {
        Self {
            min_speed_mps: 5.0,
            tilt_sigma_rad: 1.0 * DEG,
            track_sigma_rad: 0.2 * DEG,
        }
    }
}

impl Default for FuseOptions {
    fn default() -> Self {
        Self {
            algo: AlgorithmSpec::new(sdins_core::nav::AlgorithmKind::SongLeeComplete, 2),
            cov_rate_hz: 10.0,
            init_sigma: InitSigma::default(),
            draw_initial_errors: true,
            gate_chi2: Some(CHI2_999),
            max_consecutive_rejections: 5,
            zupt: None,
            nhc_sigma_mps: None,
            model_lever_arm: true,
            until_s: None,
            smooth: false,
            in_motion: None,
            scale_factors: None,
        }
    }
}

/// Why a fused run stopped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FuseError {
    /// Bad GNSS settings.
    #[error(transparent)]
    Gnss(#[from] GnssConfigError),
    /// Bad IMU error model.
    #[error("IMU error model: {0}")]
    Imu(String),
    /// Bad option.
    #[error("fuse option `{0}`: {1}")]
    Option(&'static str, String),
    /// The filter failed (names the epoch).
    #[error(transparent)]
    Filter(#[from] FilterError),
    /// The smoother failed (names the epoch).
    #[error(transparent)]
    Smoother(#[from] SmootherError),
    /// Cancelled.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
}

/// One covariance epoch: the true error in the filter's state coordinates
/// (δL, δλ, δh; δv; ε; accel residual bias `b − b̂`; gyro residual bias) and P.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuseEpoch {
    /// time \[s\]
    pub t_s: f64,
    /// true error
    pub err: StateVec,
    /// filter covariance
    pub p: StateMat,
    /// scale from (δL, δλ, δh) to metres NED
    pub pos_scale: Vec3,
    /// the navigation errors in user units
    pub nav: crate::nav::pipeline::NavError,
    /// the true attitude at the epoch
    pub c_b_n_true: sdins_core::math::Mat3,
    /// 21-state filter: the scale-factor states (accel 0–2, gyro 3–5)
    pub scale_factors: Option<ScaleFactorEpoch>,
}

/// The scale-factor states of an epoch of the 21-state filter: true error `s − ŝ`
/// (dimensionless; accelerometer x, y, z then gyro x, y, z) and its covariance block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScaleFactorEpoch {
    /// true error `s − ŝ`
    pub err: SVector<f64, 6>,
    /// the filter's covariance of those states
    pub p: SMatrix<f64, 6, 6>,
}

impl ScaleFactorEpoch {
    /// NEES of the accelerometer (`i0 = 0`) or gyro (`i0 = 3`) scale factors (3 dof).
    pub fn nees_block(&self, i0: usize) -> f64 {
        let x = self.err.fixed_rows::<3>(i0).into_owned();
        let p = self.p.fixed_view::<3, 3>(i0, i0).into_owned();
        p.cholesky().map_or(f64::INFINITY, |c| x.dot(&c.solve(&x)))
    }
}

impl FuseEpoch {
    /// NEES of the 3-state block starting at `i0` (`I_POS`, `I_VEL`, `I_ATT`, …).
    pub fn nees_block(&self, i0: usize) -> f64 {
        let x = self.err.fixed_rows::<3>(i0).into_owned();
        let p = self.p.fixed_view::<3, 3>(i0, i0).into_owned();
        p.cholesky().map_or(f64::INFINITY, |c| x.dot(&c.solve(&x)))
    }
    /// Horizontal (N, E) position NEES (2 dof).
    pub fn nees_horizontal(&self) -> f64 {
        let x = self.err.fixed_rows::<2>(I_POS).into_owned();
        let p = self.p.fixed_view::<2, 2>(I_POS, I_POS).into_owned();
        p.cholesky().map_or(f64::INFINITY, |c| x.dot(&c.solve(&x)))
    }
    /// 1σ of state `i` in user units (position in metres).
    pub fn sigma(&self, i: usize) -> f64 {
        let s = self.p[(i, i)].max(0.0).sqrt();
        if i < 3 {
            s * self.pos_scale[i].abs()
        } else {
            s
        }
    }
}

/// What the observer receives.
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub enum FuseEvent<'a> {
    /// a covariance epoch of the forward filter
    Epoch(&'a FuseEpoch),
    /// a measurement update (GNSS, ZUPT, NHC)
    Update(&'a UpdateReport),
    /// a smoothed epoch (after the forward pass, in time order)
    Smoothed(&'a FuseEpoch),
}

/// Summary of a fused run.
#[derive(Clone, Debug, PartialEq)]
pub struct FuseSummary {
    /// GNSS fixes simulated
    pub fixes: u64,
    /// GNSS fixes rejected by the gate
    pub rejected: u64,
    /// true constant biases (accel \[m/s²\], gyro \[rad/s\])
    pub true_bias: (Vec3, Vec3),
    /// final bias estimates
    pub est_bias: (Vec3, Vec3),
    /// final covariance (the 15 navigation and bias states)
    pub p_final: StateMat,
    /// true scale factors (accel, gyro; dimensionless) when they were estimated
    pub true_scale: Option<(Vec3, Vec3)>,
    /// final scale-factor estimates (zero without the scale-factor states)
    pub est_scale: (Vec3, Vec3),
    /// navigation updates
    pub nav_updates: u64,
}

/// The filter's noise model and bias prior from an IMU error model: (noise, σ_ba, σ_bg,
/// known bias accel, gyro).
pub fn noise_from_model(m: &ImuErrorModel) -> (NoiseModel, Vec3, Vec3, Vec3, Vec3) {
    let v = |a: [f64; 3], u: f64| Vec3::new(a[0] * u, a[1] * u, a[2] * u);
    let vrw_a = v(m.accel_vrw_ugpsqrthz, UG_PER_SQRT_HZ);
    let vrw_b = v(m.accel_vrw_mpsph, MPS_PER_SQRT_H);
    let tau = |t: [f64; 3], s: [f64; 3]| {
        Vec3::from_fn(|i, _| if s[i] > 0.0 { t[i] } else { f64::INFINITY })
    };
    let noise = NoiseModel {
        arw_rad_per_sqrt_s: v(m.gyro_arw_dpsh, DPSH),
        vrw_mps_per_sqrt_s: Vec3::from_fn(|i, _| vrw_a[i].hypot(vrw_b[i])),
        accel_bias_gm_mps2: v(m.accel_bias_gm_ug, UG),
        accel_bias_tau_s: tau(m.accel_bias_gm_tau_s, m.accel_bias_gm_ug),
        gyro_bias_gm_rps: v(m.gyro_bias_gm_dph, DPH),
        gyro_bias_tau_s: tau(m.gyro_bias_gm_tau_s, m.gyro_bias_gm_dph),
        accel_bias_rw: v(m.accel_rrw_ugpsh, UG_PER_SQRT_H),
        gyro_bias_rw: v(m.gyro_rrw_dphpsh, DPHPSH),
    };
    let hyp = |a: Vec3, b: Vec3| Vec3::from_fn(|i, _| a[i].hypot(b[i]));
    let s_ba = hyp(v(m.accel_bias_turn_on_ug, UG), v(m.accel_bias_gm_ug, UG));
    let s_bg = hyp(v(m.gyro_bias_turn_on_dph, DPH), v(m.gyro_bias_gm_dph, DPH));
    (
        noise,
        s_ba,
        s_bg,
        v(m.accel_bias_ug, UG),
        v(m.gyro_bias_dph, DPH),
    )
}

/// Run the filter on the scenario with the GNSS settings, as run number `run` (IMU and
/// GNSS errors and initial errors of that run).
pub fn fuse_scenario(
    scn: &Scenario,
    gnss: &GnssConfig,
    opts: &FuseOptions,
    run: u64,
    cancel: &CancelToken,
    observe: impl FnMut(FuseEvent<'_>),
) -> Result<FuseSummary, FuseError> {
    fuse_scenario_with(scn, None, gnss, opts, run, cancel, observe)
}

/// The exact truth of a scenario, generated once (for Monte Carlo runs sharing it).
pub fn scenario_truth(scn: &Scenario) -> Vec<TruthSample> {
    let cfg = scn.truth_config();
    TruthGenerator::new(&scn.trajectory, cfg).collect()
}

/// [`fuse_scenario`] reusing a truth from [`scenario_truth`] (`None`: generate it).
pub fn fuse_scenario_with(
    scn: &Scenario,
    cached: Option<&[TruthSample]>,
    gnss: &GnssConfig,
    opts: &FuseOptions,
    run: u64,
    cancel: &CancelToken,
    observe: impl FnMut(FuseEvent<'_>),
) -> Result<FuseSummary, FuseError> {
    match opts.scale_factors {
        None => fuse_impl::<N_STATES>(scn, cached, gnss, opts, run, cancel, observe),
        Some(_) => fuse_impl::<N_STATES_SF>(scn, cached, gnss, opts, run, cancel, observe),
    }
}

/// The true scale factors of an IMU error model (dimensionless): `s + M_ii` (the
/// misalignment matrix's diagonal adds to the scale factor, see [`crate::sensors::imu_error`]).
pub fn true_scale_factors(m: &ImuErrorModel) -> (Vec3, Vec3) {
    let sf = |s: [f64; 3], mis: [[f64; 3]; 3]| Vec3::from_fn(|i, _| s[i] * 1e-6 + mis[i][i] * 1e-3);
    (
        sf(m.accel_scale_ppm, m.accel_misalignment_mrad),
        sf(m.gyro_scale_ppm, m.gyro_misalignment_mrad),
    )
}

fn fuse_impl<const N: usize>(
    scn: &Scenario,
    cached: Option<&[TruthSample]>,
    gnss: &GnssConfig,
    opts: &FuseOptions,
    run: u64,
    cancel: &CancelToken,
    mut observe: impl FnMut(FuseEvent<'_>),
) -> Result<FuseSummary, FuseError> {
    let sf_prior = opts.scale_factors.filter(|_| N > N_STATES);
    if let Some(sp) = &sf_prior {
        sp.validate()?;
    }
    if scn.mounting.imu.is_some() {
        return Err(FuseError::Option(
            "mounting",
            "the filter's body frame is the IMU and fuse compares with the truth at the vehicle reference point: remove [mounting] imu_lever_arm_m / imu_mount_deg, and give the antenna's lever arm from the IMU".into(),
        ));
    }
    // the antenna lever arm: [gnss] lever_arm_b_m, or [mounting] gnss_lever_arm_m (the IMU
    // sits at the reference point here, so both are arms from the IMU)
    let gnss_eff;
    let gnss = match scn.mounting.gnss_lever_arm_b_m {
        Some(l) => {
            let own = Vec3::from(gnss.lever_arm_b_m);
            if own != Vec3::zeros() && own != l {
                return Err(FuseError::Option(
                    "mounting.gnss_lever_arm_m",
                    format!(
                        "differs from [gnss] lever_arm_b_m ({:?} m against {:?} m): give one",
                        [l.x, l.y, l.z],
                        gnss.lever_arm_b_m
                    ),
                ));
            }
            gnss_eff = GnssConfig {
                lever_arm_b_m: [l.x, l.y, l.z],
                ..gnss.clone()
            };
            &gnss_eff
        }
        None => gnss,
    };
    let earth = scn.nav.earth.model();
    let dt = scn.imu.dt_s();
    let n = opts.algo.samples.clamp(1, 4);
    let nav_rate = 1.0 / (dt * n as f64);
    if !(opts.cov_rate_hz.is_finite() && opts.cov_rate_hz > 0.0 && opts.cov_rate_hz <= nav_rate) {
        return Err(FuseError::Option(
            "cov_rate_hz",
            format!("must be in (0, {nav_rate}] Hz, got {}", opts.cov_rate_hz),
        ));
    }
    let s = &opts.init_sigma;
    if s.att_rad
        .iter()
        .any(|x| !x.is_finite() || *x < 0.0 || *x > 10.0 * DEG)
        || s.pos_ned_m
            .iter()
            .chain(s.vel_ned_mps.iter())
            .any(|x| !x.is_finite() || *x < 0.0)
    {
        return Err(FuseError::Option(
            "init_sigma",
            "σ must be finite, ≥ 0, and attitude σ ≤ 10° (the linearised filter's limit)".into(),
        ));
    }
    let cov_updates = (nav_rate / opts.cov_rate_hz).round().max(1.0) as usize;
    let cfg = scn.truth_config();
    let generator = TruthGenerator::new(&scn.trajectory, cfg);
    let init_true = generator.initial_state();
    let len_samples = generator.len_samples();
    let mut truth: Box<dyn Iterator<Item = TruthSample> + '_> = match cached {
        Some(c) => Box::new(c.iter().copied()),
        None => Box::new(generator),
    };
    let mut gsim = GnssSimulator::new(gnss, earth, run)?;
    let mut sensor = ImuErrorState::new(&scn.imu.model, scn.imu.seed, run)
        .map_err(|e| FuseError::Imu(e.to_string()))?;
    let (true_bg, true_ba) = sensor.constant_bias();
    let (noise, s_ba, s_bg, known_ba, known_bg) = noise_from_model(&scn.imu.model);

    let mut prev_truth = TruthSample::new(
        0.0,
        Increment::default(),
        init_true.lat_rad,
        init_true.lon_rad,
        init_true.h_m,
        init_true.v_n_mps,
        init_true.c_b_n,
    );
    let mut pending: Vec<GnssFix> = Vec::with_capacity(8);
    // in-motion start: run the sensors and the receiver until the first fix at speed
    let mut skipped = 0u64;
    let mut moving_start = None;
    if let Some(im) = &opts.in_motion {
        if !(im.min_speed_mps.is_finite()
            && im.min_speed_mps > 0.0
            && im.tilt_sigma_rad > 0.0
            && im.tilt_sigma_rad <= 10.0 * DEG
            && im.track_sigma_rad > 0.0
            && im.track_sigma_rad <= 10.0 * DEG)
        {
            return Err(FuseError::Option(
                "in_motion",
                "min speed must be > 0, tilt and track σ in (0, 10°]".into(),
            ));
        }
        loop {
            let Some(ts) = truth.next() else {
                return Err(FuseError::Option(
                    "in_motion",
                    format!(
                        "no GNSS fix with a velocity and a horizontal speed of at least {} m/s in the scenario",
                        im.min_speed_mps
                    ),
                ));
            };
            let meas = sensor.apply(&ts.inc, dt);
            gsim.step(&scn.trajectory, &prev_truth, &ts, &mut pending);
            prev_truth = ts;
            skipped += 1;
            let found = pending.iter().position(|f| {
                f.vel
                    .is_some_and(|(v, _)| v.x.hypot(v.y) >= im.min_speed_mps)
            });
            match found {
                Some(i) => {
                    let f = pending[i];
                    pending.drain(..=i);
                    moving_start = Some((f, ts, meas));
                    break;
                }
                None => pending.clear(),
            }
        }
    }
    let t_start = prev_truth.t_s;
    let init_true = if moving_start.is_some() {
        InitialState {
            lat_rad: prev_truth.lat_rad,
            lon_rad: prev_truth.lon_rad,
            h_m: prev_truth.h_m,
            v_n_mps: prev_truth.v_n_mps,
            c_b_n: prev_truth.c_b_n,
        }
    } else {
        init_true
    };
    // initial errors
    let r0 = earth.radii(init_true.lat_rad);
    let t0 = Vec3::new(
        r0.r_m_m + init_true.h_m,
        (r0.r_n_m + init_true.h_m) * init_true.lat_rad.cos(),
        -1.0,
    );
    let mut w = [0.0; 9];
    if opts.draw_initial_errors {
        let mut rng = ChaCha20Rng::seed_from_u64(gnss.seed);
        rng.set_stream((1u64 << 63) | run.wrapping_mul(16).wrapping_add(10));
        for wi in &mut w {
            *wi = StandardNormal.sample(&mut rng);
        }
    }
    let dp = Vec3::from_fn(|i, _| s.pos_ned_m[i] * w[i]);
    let dv = Vec3::from_fn(|i, _| s.vel_ned_mps[i] * w[3 + i]);
    let eps = Vec3::from_fn(|i, _| s.att_rad[i] * w[6 + i]);
    let init = InitialState {
        lat_rad: init_true.lat_rad + dp.x / t0.x,
        lon_rad: init_true.lon_rad + dp.y / t0.y,
        h_m: init_true.h_m - dp.z,
        v_n_mps: init_true.v_n_mps + dv,
        c_b_n: Quat::from_rotvec(&eps).to_dcm() * init_true.c_b_n,
    };
    let mut init = init;
    let mut p0 = StateMatN::<N>::zeros();
    if let Some(sp) = &sf_prior {
        for i in 0..3 {
            p0[(I_SA + i, I_SA + i)] = (sp.accel_ppm[i] * 1e-6).powi(2);
            p0[(I_SG + i, I_SG + i)] = (sp.gyro_ppm[i] * 1e-6).powi(2);
        }
    }
    let true_sf = sf_prior.map(|_| true_scale_factors(&scn.imu.model));
    for i in 0..3 {
        p0[(I_POS + i, I_POS + i)] = (s.pos_ned_m[i] / t0[i]).powi(2);
        p0[(I_VEL + i, I_VEL + i)] = s.vel_ned_mps[i].powi(2);
        p0[(I_ATT + i, I_ATT + i)] = s.att_rad[i].powi(2);
        p0[(I_BA + i, I_BA + i)] = s_ba[i].powi(2);
        p0[(I_BG + i, I_BG + i)] = s_bg[i].powi(2);
    }
    if let (Some((f, ts, meas)), Some(im)) = (moving_start, opts.in_motion) {
        let (v_a, cv) = f.vel.unwrap_or((Vec3::zeros(), Mat3::identity()));
        let vh = v_a.x.hypot(v_a.y);
        let w_z = meas.dtheta_b_rad.z / dt;
        let yaw = v_a.y.atan2(v_a.x) + w_z * (ts.t_s - f.t_s);
        let pitch = (-v_a.z).atan2(vh);
        let c = sdins_core::math::c_b_n_from_euler(&sdins_core::math::Euler::new(0.0, pitch, yaw));
        let l = Vec3::from(gnss.lever_arm_b_m);
        let w_b = meas.dtheta_b_rad / dt;
        let v = v_a - c * w_b.cross(&l);
        let cl = c * l;
        let r = earth.radii(f.lat_rad);
        let sc = sdins_core::aiding::error_model::position_scale(
            r.r_m_m,
            r.r_n_m,
            f.lat_rad.cos(),
            f.h_m,
        );
        // the fix is at t_f ≤ t_start: advance by the velocity over the gap
        let gap = ts.t_s - f.t_s;
        init = InitialState {
            lat_rad: f.lat_rad + (v.x * gap - cl.x) / sc.x,
            lon_rad: f.lon_rad + (v.y * gap - cl.y) / sc.y,
            h_m: f.h_m - v.z * gap + cl.z,
            v_n_mps: v,
            c_b_n: c,
        };
        let (sy, cy) = yaw.sin_cos();
        let s_psi2 =
            im.track_sigma_rad.powi(2) + (cv[(0, 0)] * sy * sy + cv[(1, 1)] * cy * cy) / (vh * vh);
        let m = crate::fusion::records::euler_error_matrix(&c);
        let mi = m.try_inverse().unwrap_or_else(Mat3::identity);
        let d = Mat3::from_diagonal(&Vec3::new(
            im.tilt_sigma_rad.powi(2),
            im.tilt_sigma_rad.powi(2),
            s_psi2,
        ));
        let pa = mi * d * mi.transpose();
        for i in 0..3 {
            for j in 0..3 {
                p0[(I_POS + i, I_POS + j)] = f.pos_cov_ned_m2[(i, j)] / (sc[i] * sc[j]);
                p0[(I_VEL + i, I_VEL + j)] = cv[(i, j)];
                p0[(I_ATT + i, I_ATT + j)] = pa[(i, j)];
            }
        }
    }
    let mech = AnyMechanization::new(&opts.algo, earth, dt, &init);
    let ekf_cfg = EkfConfig {
        earth,
        dt_s: dt,
        cov_updates,
        noise,
        lever_arm_b_m: if opts.model_lever_arm {
            Vec3::from(gnss.lever_arm_b_m)
        } else {
            Vec3::zeros()
        },
        gate_chi2: opts.gate_chi2,
        max_consecutive_rejections: opts.max_consecutive_rejections,
    };
    let mut ekf = Ekf::<_, N>::new(mech, ekf_cfg, p0, known_ba, known_bg);

    let mut total = len_samples.saturating_sub(skipped) / n as u64;
    if let Some(t) = opts.until_s {
        total = total.min(((t - t_start).max(0.0) * nav_rate).round() as u64);
    }
    let latency_fix = if gnss.latency_modelled {
        gnss.latency_s
    } else {
        0.0
    };
    let mut incs = [Increment::default(); 4];
    // forward records for the smoother: the log, and per epoch the forward state, its
    // bias estimates and the truth
    let mut smooth = opts.smooth.then(|| {
        let epochs = (total / cov_updates as u64 + 2) as usize;
        (
            SmootherLog::<N>::with_capacity(epochs),
            Vec::<(NavState, Estimates, TruthSample)>::with_capacity(epochs),
        )
    });
    let truths = Truths {
        ba: true_ba,
        bg: true_bg,
        sf: true_sf,
    };
    if let Some((log, fwd)) = smooth.as_mut() {
        log.push(&ekf.initial_epoch())?;
        fwd.push((ekf.state(), estimates(&ekf), prev_truth));
    }
    let mut fixes = 0u64;
    let mut last_cur = prev_truth;
    for k in 0..total {
        if k % 1024 == 0 {
            cancel.check()?;
        }
        let mut got = 0;
        for inc in incs.iter_mut().take(n) {
            let Some(ts) = truth.next() else { break };
            *inc = sensor.apply(&ts.inc, dt);
            gsim.step(&scn.trajectory, &prev_truth, &ts, &mut pending);
            prev_truth = ts;
            got += 1;
        }
        if got < n {
            break;
        }
        let cur = prev_truth;
        last_cur = cur;
        ekf.propagate(&incs[..n])?;
        let t_nav = ekf.state().t_s;
        // fixes available by now (tag ≤ t_nav), in time order
        let mut i = 0;
        while i < pending.len() {
            if pending[i].t_s <= t_start + t_nav + 1e-9 {
                let f = pending.remove(i);
                fixes += 1;
                let m = GnssMeasurement {
                    t_s: f.t_s - latency_fix - t_start,
                    lat_rad: f.lat_rad,
                    lon_rad: f.lon_rad,
                    h_m: f.h_m,
                    pos_cov_ned_m2: f.pos_cov_ned_m2,
                    vel: f.vel,
                };
                let mut rep = ekf.update_gnss(&m)?;
                rep.t_s += t_start;
                observe(FuseEvent::Update(&rep));
            } else {
                i += 1;
            }
        }
        let epoch_now = (k + 1) % cov_updates as u64 == 0;
        if epoch_now {
            let at_rest = opts.zupt.is_some_and(|(_, thr)| cur.v_n_mps.norm() < thr);
            if let (true, Some((sig, _))) = (at_rest, opts.zupt) {
                let mut rep = ekf.update_zupt(sig)?;
                rep.t_s += t_start;
                observe(FuseEvent::Update(&rep));
            } else if let Some(sig) = opts.nhc_sigma_mps {
                let mut rep = ekf.update_nhc(sig)?;
                rep.t_s += t_start;
                observe(FuseEvent::Update(&rep));
            }
        }
        if let Some(ep) = ekf.take_epoch() {
            let mut e = epoch_of(
                &ekf.state(),
                &estimates(&ekf),
                ekf.covariance(),
                &cur,
                &earth,
                &truths,
            );
            e.t_s += t_start;
            observe(FuseEvent::Epoch(&e));
            if let Some((log, fwd)) = smooth.as_mut() {
                log.push(&ep)?;
                fwd.push((ekf.state(), estimates(&ekf), cur));
            }
        }
    }
    let _ = last_cur;
    if let Some((log, fwd)) = smooth {
        let mut out: Vec<Option<FuseEpoch>> = vec![None; fwd.len()];
        log.smooth(cancel, |k, _, sm| {
            if let (Some((st, est, tr)), Some(slot)) = (fwd.get(k), out.get_mut(k)) {
                let s_state = correct_nav_state(st, &sm.dx);
                let mut est = *est;
                est.ba += sm.dx.fixed_rows::<3>(I_BA);
                est.bg += sm.dx.fixed_rows::<3>(I_BG);
                if N > N_STATES {
                    est.sa += sm.dx.fixed_rows::<3>(I_SA);
                    est.sg += sm.dx.fixed_rows::<3>(I_SG);
                }
                let mut e = epoch_of(&s_state, &est, &sm.p, tr, &earth, &truths);
                e.t_s += t_start;
                *slot = Some(e);
            }
        })?;
        for e in out.iter().flatten() {
            observe(FuseEvent::Smoothed(e));
        }
    }
    let (ba, bg) = ekf.biases();
    Ok(FuseSummary {
        fixes,
        rejected: ekf.rejected_total(),
        true_bias: (true_ba, true_bg),
        est_bias: (ba, bg),
        p_final: ekf
            .covariance()
            .fixed_view::<N_STATES, N_STATES>(0, 0)
            .into_owned(),
        true_scale: true_sf,
        est_scale: ekf.scale_factors(),
        nav_updates: total,
    })
}

/// The filter's sensor-error estimates at an epoch.
#[derive(Clone, Copy, Debug)]
struct Estimates {
    ba: Vec3,
    bg: Vec3,
    sa: Vec3,
    sg: Vec3,
}

fn estimates<M: sdins_core::nav::Mechanization, const N: usize>(ekf: &Ekf<M, N>) -> Estimates {
    let ((ba, bg), (sa, sg)) = (ekf.biases(), ekf.scale_factors());
    Estimates { ba, bg, sa, sg }
}

/// The true sensor errors of the run (scale factors only when estimated).
struct Truths {
    ba: Vec3,
    bg: Vec3,
    sf: Option<(Vec3, Vec3)>,
}

fn epoch_of<const N: usize>(
    st: &NavState,
    est: &Estimates,
    p: &StateMatN<N>,
    truth: &TruthSample,
    earth: &sdins_core::earth::EarthModel,
    tr: &Truths,
) -> FuseEpoch {
    let (ba, bg, true_ba, true_bg) = (est.ba, est.bg, tr.ba, tr.bg);
    let ne = nav_error(earth, st, truth);
    let mut err = StateVec::zeros();
    err[I_POS] = st.lat_rad - truth.lat_rad;
    err[I_POS + 1] = lon_diff(st.lon_rad, truth.lon_rad);
    err[I_POS + 2] = st.h_m - truth.h_m;
    for i in 0..3 {
        err[I_VEL + i] = ne.vel_err_ned_mps[i];
        err[I_ATT + i] = ne.att_err_rad[i];
        err[I_BA + i] = true_ba[i] - ba[i];
        err[I_BG + i] = true_bg[i] - bg[i];
    }
    let scale_factors = match (tr.sf, N > N_STATES) {
        (Some((sa, sg)), true) => {
            let mut e = SVector::<f64, 6>::zeros();
            for i in 0..3 {
                e[i] = sa[i] - est.sa[i];
                e[3 + i] = sg[i] - est.sg[i];
            }
            Some(ScaleFactorEpoch {
                err: e,
                p: p.fixed_view::<6, 6>(I_SA, I_SA).into_owned(),
            })
        }
        _ => None,
    };
    let r = earth.radii(truth.lat_rad);
    FuseEpoch {
        t_s: st.t_s,
        err,
        p: p.fixed_view::<N_STATES, N_STATES>(0, 0).into_owned(),
        scale_factors,
        pos_scale: Vec3::new(
            r.r_m_m + truth.h_m,
            (r.r_n_m + truth.h_m) * truth.lat_rad.cos(),
            -1.0,
        ),
        nav: ne,
        c_b_n_true: truth.c_b_n,
    }
}
