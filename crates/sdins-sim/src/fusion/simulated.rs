//! INS/GNSS fusion on a scenario: the exact truth → IMU errors → GNSS fixes → the one
//! fusion loop ([`crate::fusion::engine`]) → errors against the truth, with the filter's
//! covariance.
//!
//! * Filter model from the scenario's IMU error model ([`noise_from_model`]): ARW, VRW,
//!   turn-on bias σ (prior of random-constant bias states), Gauss–Markov bias (σ, T;
//!   `q = 2σ²/T`), rate random walk; the fixed bias is known (initial estimate). With
//!   [`FuseOptions::scale_factors`] the layout adds the accelerometer and gyro scale
//!   factors (random constants, prior σ from the option, initial estimate 0); the
//!   scenario's `accel_scale_ppm` / `gyro_scale_ppm` plus the diagonal of the misalignment
//!   matrices are then the true values. Not modelled (and therefore not to be simulated in
//!   consistency runs): scale factor (without those blocks), scale asymmetry, off-diagonal
//!   misalignment, g-sensitivity, flicker, quantization, saturation.
//! * The stream ([`crate::fusion::scenario_stream`]): every IMU sample with its truth, the
//!   fixes of the GNSS simulator as they are generated (time of validity = tag − known
//!   latency, arrival = tag), and, with a ZUPT, the truth's rest state.
//! * Initial errors: position/velocity/attitude σ of [`FuseOptions::init_sigma`], drawn
//!   per run from P0 (`draw_initial_errors`, stream channel 10–12 of the GNSS seed) or
//!   zero; the attitude error is applied as `Ĉ = exp([ε×]) C` (convention G). The
//!   linearised filter is limited to initial attitude σ ≤ 10° per axis (larger is
//!   rejected; [`FuseOptions::in_motion`] starts from the GNSS track instead).
//! * Output rows (the loop's epoch rule; by default every covariance interval, so each row
//!   is a covariance epoch): the true error in the filter's state coordinates and P,
//!   after that update's measurements ([`FuseEvent::Epoch`]); every measurement report;
//!   with [`FuseOptions::smooth`] the smoothed rows in time order ([`FuseEvent::Smoothed`]:
//!   the true error of the smoothed state and the smoothed covariance).

use crate::cancel::{CancelToken, Cancelled};
use crate::fusion::engine::{run_engine, EngineConfig, EngineError, EngineEvent, Row};
use crate::fusion::scenario_stream::{scenario_start, ScenarioStream};
use crate::fusion::smoother::SmootherError;
use crate::nav::pipeline::{nav_error, NavError};
use crate::scenario::Scenario;
use crate::sensors::gnss::{GnssConfig, GnssConfigError};
use crate::sensors::imu_error::{ImuErrorModel, DEG, DPH, DPHPSH, DPSH, MPS_PER_SQRT_H};
use crate::sensors::imu_error::{UG, UG_PER_SQRT_H, UG_PER_SQRT_HZ};
use crate::truth::{lon_diff, TruthGenerator, TruthSample};
use nalgebra::{SMatrix, SVector};
use sdins_core::aiding::ekf::{
    FilterError, NoiseModel, UpdateReport, CHI2_999, DEFAULT_MAX_LATENCY_S,
};
use sdins_core::aiding::error_model::{StateMat, I_ATT, I_POS, I_VEL, N_STATES};
use sdins_core::aiding::layout::{BlockKind, Cov, StateLayout, XVec};
use sdins_core::aiding::linalg::MAX_ROWS;
use sdins_core::earth::EarthModel;
use sdins_core::math::{Mat3, Vec3};
use sdins_core::nav::{AlgorithmSpec, NavState};

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
    /// NIS gate thresholds by dof 1…12 (None: no gating)
    pub gate_chi2: Option<[f64; MAX_ROWS]>,
    /// consecutive rejections before the reset policy
    pub max_consecutive_rejections: u32,
    /// ZUPT σ \[m/s\] and the truth speed below which the vehicle is at rest \[m/s\]
    pub zupt: Option<(f64, f64)>,
    /// NHC σ \[m/s\]
    pub nhc_sigma_mps: Option<f64>,
    /// with `zupt`: decide rest with the IMU's stationarity detector instead of the
    /// truth's speed (the speed threshold of `zupt` is then unused)
    pub zupt_detector: Option<crate::fusion::detector::DetectorSettings>,
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
    /// output rows near `t_start + k·every_s` \[s\] (None: the covariance interval, so
    /// that every row is a covariance epoch)
    pub every_s: Option<f64>,
    /// largest latency of a measurement \[s\]
    pub max_latency_s: f64,
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
            zupt_detector: None,
            model_lever_arm: true,
            until_s: None,
            smooth: false,
            in_motion: None,
            scale_factors: None,
            every_s: None,
            max_latency_s: DEFAULT_MAX_LATENCY_S,
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

impl From<EngineError> for FuseError {
    fn from(e: EngineError) -> Self {
        match e {
            EngineError::Option(k, m) => FuseError::Option(k, m),
            EngineError::Filter(f) => FuseError::Filter(f),
            EngineError::Smoother(s) => FuseError::Smoother(s),
            EngineError::Cancelled(c) => FuseError::Cancelled(c),
            EngineError::Detector(d) => FuseError::Option("zupt_detector", d.to_string()),
        }
    }
}

/// One output row of a scenario run: the true error in the filter's state coordinates
/// (navigation `estimate − truth`; sensor parameters `truth − estimate`, zero for blocks
/// whose truth is unknown) and the filter's covariance (leading n × n).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuseEpoch {
    /// time \[s\]
    pub t_s: f64,
    /// true error
    pub err: XVec,
    /// filter covariance
    pub p: Cov,
    /// the state layout
    pub layout: StateLayout,
    /// scale from (δL, δλ, δh) to metres NED
    pub pos_scale: Vec3,
    /// the navigation errors in user units
    pub nav: NavError,
    /// the true attitude at the epoch
    pub c_b_n_true: Mat3,
    /// the filter's navigation state (its `t_s` counts from the navigation start)
    pub state: NavState,
    /// the filter's sensor-parameter estimates (at their block offsets)
    pub est: XVec,
}

/// The scale-factor states of a row (accelerometer x, y, z then gyro x, y, z): true error
/// `s − ŝ` (dimensionless) and its covariance block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScaleFactorEpoch {
    /// true error `s − ŝ`
    pub err: SVector<f64, 6>,
    /// the filter's covariance of those states
    pub p: SMatrix<f64, 6, 6>,
}

/// `xᵀ P⁻¹ x` of a block (∞ when P is not positive definite).
fn nees_of(err: &XVec, p: &Cov, i0: usize, d: usize) -> f64 {
    let mut m = [0.0f64; 9];
    let mut x = [0.0f64; 3];
    for i in 0..d {
        x[i] = err[i0 + i];
        for j in 0..d {
            m[j * 3 + i] = p[(i0 + i, i0 + j)];
        }
    }
    if !sdins_core::aiding::linalg::cholesky(&mut m, 3, d) {
        return f64::INFINITY;
    }
    let mut y = x;
    sdins_core::aiding::linalg::chol_solve(&m, 3, d, &mut y);
    sdins_core::aiding::linalg::dot(&x[..d], &y[..d])
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
        nees_of(&self.err, &self.p, i0, 3)
    }
    /// NEES of a block of the layout (None when the layout lacks it).
    pub fn nees(&self, kind: BlockKind) -> Option<f64> {
        self.layout
            .block(kind)
            .map(|b| nees_of(&self.err, &self.p, b.offset, b.dim))
    }
    /// Horizontal (N, E) position NEES (2 dof).
    pub fn nees_horizontal(&self) -> f64 {
        nees_of(&self.err, &self.p, I_POS, 2)
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
    /// The scale-factor states (when the layout has both scale-factor blocks).
    pub fn scale_factors(&self) -> Option<ScaleFactorEpoch> {
        let a = self.layout.offset(BlockKind::AccelScale)?;
        let g = self.layout.offset(BlockKind::GyroScale)?;
        let idx = [a, a + 1, a + 2, g, g + 1, g + 2];
        Some(ScaleFactorEpoch {
            err: SVector::<f64, 6>::from_fn(|i, _| self.err[idx[i]]),
            p: SMatrix::<f64, 6, 6>::from_fn(|i, j| self.p[(idx[i], idx[j])]),
        })
    }
}

/// What the observer receives.
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub enum FuseEvent<'a> {
    /// a forward output row
    Epoch(&'a FuseEpoch),
    /// a measurement update (GNSS, ZUPT, NHC; times on the scenario clock)
    Update(&'a UpdateReport),
    /// a smoothed output row (after the forward pass, in time order)
    Smoothed(&'a FuseEpoch),
}

/// Summary of a fused run.
#[derive(Clone, Debug, PartialEq)]
pub struct FuseSummary {
    /// GNSS fixes processed (applied, rejected or refused as late)
    pub fixes: u64,
    /// GNSS fixes rejected by the gate
    pub rejected: u64,
    /// measurements refused as late
    pub late: u64,
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
    /// the state layout
    pub layout: StateLayout,
    /// the scenario time of the navigation start \[s\] (0 unless in-motion)
    pub t_start_s: f64,
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

/// The true scale factors of an IMU error model (dimensionless): `s + M_ii` (the
/// misalignment matrix's diagonal adds to the scale factor, see [`crate::sensors::imu_error`]).
pub fn true_scale_factors(m: &ImuErrorModel) -> (Vec3, Vec3) {
    let sf = |s: [f64; 3], mis: [[f64; 3]; 3]| Vec3::from_fn(|i, _| s[i] * 1e-6 + mis[i][i] * 1e-3);
    (
        sf(m.accel_scale_ppm, m.accel_misalignment_mrad),
        sf(m.gyro_scale_ppm, m.gyro_misalignment_mrad),
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

/// The true sensor errors of a run, in the filter's coordinates.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Truths {
    pub(crate) ba: Vec3,
    pub(crate) bg: Vec3,
    pub(crate) sf: Option<(Vec3, Vec3)>,
}

/// The row's true error and covariance.
fn epoch_of(
    row: &Row<'_>,
    p: &Cov,
    truth: &TruthSample,
    earth: &EarthModel,
    tr: &Truths,
) -> FuseEpoch {
    let st = row.state;
    let ne = nav_error(earth, st, truth);
    let mut err = XVec::zeros();
    err[0] = st.lat_rad - truth.lat_rad;
    err[1] = lon_diff(st.lon_rad, truth.lon_rad);
    err[2] = st.h_m - truth.h_m;
    let est = row.est;
    for i in 0..3 {
        err[I_VEL + i] = ne.vel_err_ned_mps[i];
        err[I_ATT + i] = ne.att_err_rad[i];
        err[9 + i] = tr.ba[i] - est[9 + i];
        err[12 + i] = tr.bg[i] - est[12 + i];
    }
    if let Some((sa, sg)) = tr.sf {
        for (kind, v) in [(BlockKind::AccelScale, sa), (BlockKind::GyroScale, sg)] {
            if let Some(o) = row.layout.offset(kind) {
                for i in 0..3 {
                    err[o + i] = v[i] - est[o + i];
                }
            }
        }
    }
    if let Some(t) = row.sensor_truth {
        crate::sensors::aiding::truth_errors(row.layout, t, est, &mut err);
    }
    let r = earth.radii(truth.lat_rad);
    FuseEpoch {
        t_s: row.t_s,
        err,
        p: *p,
        layout: *row.layout,
        pos_scale: Vec3::new(
            r.r_m_m + truth.h_m,
            (r.r_n_m + truth.h_m) * truth.lat_rad.cos(),
            -1.0,
        ),
        nav: ne,
        c_b_n_true: truth.c_b_n,
        state: *st,
        est: *est,
    }
}

/// [`fuse_scenario`] reusing a truth from [`scenario_truth`] (`None`: generate it).
pub fn fuse_scenario_with(
    scn: &Scenario,
    cached: Option<&[TruthSample]>,
    gnss: &GnssConfig,
    opts: &FuseOptions,
    run: u64,
    cancel: &CancelToken,
    mut observe: impl FnMut(FuseEvent<'_>),
) -> Result<FuseSummary, FuseError> {
    let setup = scenario_start(scn, cached, gnss, opts, run)?;
    let earth = setup.cfg.earth;
    let truths = setup.truths;
    let mut stream: ScenarioStream<'_> = setup.stream;
    let n_x = setup.start.layout.n();
    // the smoothed covariances of the epochs the rows need, packed
    let mut smoothed_p: Vec<Option<Vec<f64>>> = Vec::new();
    let mut sink = |ev: EngineEvent<'_>| match ev {
        EngineEvent::Forward(row) => {
            if let (Some(tr), Some(p)) = (row.truth, row.p) {
                let e = epoch_of(row, p, tr, &earth, &truths);
                observe(FuseEvent::Epoch(&e));
            }
        }
        EngineEvent::Update(u) => observe(FuseEvent::Update(u)),
        EngineEvent::SmoothedCov { epoch, p, .. } => {
            if smoothed_p.len() <= epoch {
                smoothed_p.resize(epoch + 1, None);
            }
            let mut v = Vec::with_capacity(n_x * (n_x + 1) / 2);
            for i in 0..n_x {
                for j in i..n_x {
                    v.push(p[(i, j)]);
                }
            }
            smoothed_p[epoch] = Some(v);
        }
        EngineEvent::Smoothed(row) => {
            let Some(Some(v)) = smoothed_p.get(row.epoch) else {
                return;
            };
            let mut p = Cov::zeros();
            let mut k = 0;
            for i in 0..n_x {
                for j in i..n_x {
                    p[(i, j)] = v[k];
                    p[(j, i)] = v[k];
                    k += 1;
                }
            }
            if let Some(tr) = row.truth {
                let e = epoch_of(row, &p, tr, &earth, &truths);
                observe(FuseEvent::Smoothed(&e));
            }
        }
    };
    let s = run_engine(&mut stream, &setup.start, &setup.cfg, cancel, &mut sink)?;
    let c = s.counts[sdins_core::aiding::meas::MeasKind::Gnss.index()];
    let late: u64 = s.counts.iter().map(|c| c.late).sum();
    let est_scale = (
        vec3_at(&s.est, s.layout.offset(BlockKind::AccelScale)),
        vec3_at(&s.est, s.layout.offset(BlockKind::GyroScale)),
    );
    Ok(FuseSummary {
        fixes: c.applied + c.rejected + c.late,
        rejected: c.rejected,
        late,
        true_bias: (truths.ba, truths.bg),
        est_bias: (vec3_at(&s.est, Some(9)), vec3_at(&s.est, Some(12))),
        p_final: s.p.fixed_view::<N_STATES, N_STATES>(0, 0).into_owned(),
        true_scale: truths.sf,
        est_scale,
        nav_updates: s.nav_updates,
        layout: s.layout,
        t_start_s: s.t_start_s,
    })
}

fn vec3_at(x: &XVec, o: Option<usize>) -> Vec3 {
    o.map_or(Vec3::zeros(), |o| Vec3::new(x[o], x[o + 1], x[o + 2]))
}

/// The engine configuration shared by the scenario and recorded front ends.
#[allow(clippy::too_many_arguments)]
pub(crate) fn engine_config(
    algo: AlgorithmSpec,
    earth: EarthModel,
    dt_s: f64,
    cov_rate_hz: f64,
    noise: NoiseModel,
    lever_arm_b_m: Vec3,
    every_s: Option<f64>,
    total_updates: u64,
) -> Result<EngineConfig, FuseError> {
    let n = algo.samples.clamp(1, 4);
    let nav_rate = 1.0 / (dt_s * n as f64);
    if !(cov_rate_hz.is_finite() && cov_rate_hz > 0.0 && cov_rate_hz <= nav_rate) {
        return Err(FuseError::Option(
            "cov_rate_hz",
            format!("must be in (0, {nav_rate}] Hz, got {cov_rate_hz}"),
        ));
    }
    let cov_updates = (nav_rate / cov_rate_hz).round().max(1.0) as usize;
    Ok(EngineConfig {
        algo,
        earth,
        dt_s,
        cov_updates,
        noise,
        gate_chi2: Some(CHI2_999),
        max_consecutive_rejections: 5,
        max_latency_s: DEFAULT_MAX_LATENCY_S,
        lever_arm_b_m,
        zupt_sigma_mps: None,
        nhc_sigma_mps: None,
        zupt_detector: None,
        smooth: false,
        every_s: every_s.unwrap_or(cov_updates as f64 * n as f64 * dt_s),
        total_updates,
    })
}

/// The states of a layout in the order the navigation blocks and sensor blocks appear
/// (helper for callers that print them).
pub fn layout_names(layout: &StateLayout) -> Vec<&'static str> {
    layout.blocks().iter().map(|b| b.kind.name()).collect()
}

/// A navigation state from the start of a scenario (for tests and tools).
pub fn scenario_initial_state(scn: &Scenario) -> NavState {
    let s = TruthGenerator::new(&scn.trajectory, scn.truth_config()).initial_state();
    NavState {
        t_s: 0.0,
        lat_rad: s.lat_rad,
        lon_rad: s.lon_rad,
        h_m: s.h_m,
        v_n_mps: s.v_n_mps,
        c_b_n: s.c_b_n,
    }
}

/// Units of the initial σ for the in-motion start.
pub(crate) const IN_MOTION_MAX_SIGMA_RAD: f64 = 10.0 * DEG;
