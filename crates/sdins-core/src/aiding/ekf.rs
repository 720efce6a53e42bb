//! Loosely coupled INS/GNSS error-state extended Kalman filter with closed-loop correction
//! (Groves 2nd ed. §14.1–§14.3), on top of any [`Mechanization`]. No allocation per step:
//! every matrix is a fixed-size nalgebra value.
//!
//! ## State and conventions
//! The 15 error states of [`super::error_model`] (δL, δλ, δh; δv^n; ε; b_a; b_g), all
//! **estimate − truth**, or 21 with the accelerometer and gyro scale factors
//! (`Ekf<M, 21>`; states 15–20 = `s − ŝ`, random constants with prior σ from P0 and no
//! process noise). Attitude: convention G of `docs/conventions.md`,
//! `Ĉ_b^n = (I + [ε×]) C_b^n`. The bias states are the residual errors of the
//! *compensated* sensor outputs (`f̂ − f`, `ω̂ − ω`, i.e. true bias − estimated bias), so
//! that `δv̇ ∋ C_b^n b_a` and `ε̇ ∋ C_b^n b_g` as in the error model.
//!
//! ## Propagation
//! The navigation state is advanced every update by the mechanization with compensated
//! increments `(Δθ − b̂_g δt) ⊘ (1 + ŝ_g)`, `(Δv − b̂_a δt) ⊘ (1 + ŝ_a)` (per axis; the exact
//! inverse of the sensor model `f̃ = (1 + s) f + b`; `ŝ = 0` in the 15-state filter). The covariance is propagated at a lower rate,
//! every `cov_updates` navigation updates (and at every measurement), over the interval
//! `τ` since the last covariance epoch:
//! * `F` of the error model at the epoch's state with the interval-mean specific force
//!   `f^n = Σ Ĉ_b^n Δv / τ`, plus the bias models: a first-order Gauss–Markov bias of
//!   steady-state σ and correlation time T has `ḃ = −b/T + w`, `q = 2σ²/T`; `T = ∞` is a
//!   random constant (optionally plus a random walk of density K, `q = K²`); in the
//!   21-state filter the scale-factor columns `∂δv̇/∂δs_a = C_b^n diag(f^b)` and
//!   `∂ε̇/∂δs_g = C_b^n diag(ω_ib^b)` are the interval means `Σ Ĉ diag(Δv)/τ` and
//!   `Σ Ĉ diag(Δθ)/τ` (Groves 2nd ed. §14.2, the "additional IMU error states");
//! * `Φ = I + Fτ + (Fτ)²/2 + (Fτ)³/6` (Groves (3.34) truncated, §14.2.3);
//! * `Q = ½(Φ Q_c Φᵀ + Q_c) τ` (trapezoidal rule), `Q_c = G diag(ARW², VRW², q_b) Gᵀ`, the
//!   white noises entering through `C_b^n` (Groves §14.2.2);
//! * `P⁻ = Φ P Φᵀ + Q`, symmetrised.
//!
//! ## Measurements (innovation `ν = ĥ(x̂) − z = H x + noise`)
//! * GNSS position of the antenna at lever arm `l` (body): `p̂_a = p̂ + Ĉ_b^n l` (Groves
//!   (14.110)); `ν_p = T (L̂_a − L, λ̂_a − λ, ĥ_a − h)` with `T = diag(R_M+h, (R_N+h)cos L, −1)`
//!   \[m, NED\]; `H_p = [T, 0, −[(Ĉ l)×], 0, 0]`.
//! * GNSS velocity: `v̂_a = v̂ + Ĉ (ω̂_eb^b × l)`, `ω_eb^b = ω_ib^b − C_n^b ω_ie^n` (Groves
//!   (14.111)); `H_v = [0, I, −[(Ĉ(ω × l))×], 0, −Ĉ [l×]]`, and in the 21-state filter
//!   `−Ĉ [l×] diag(ω_ib^b)` in the gyro scale-factor columns.
//! * Time of validity: a fix with time `t` inside the last navigation interval
//!   `(t_{k−1}, t_k]` is compared with the state interpolated to `t` with constant
//!   acceleration over the interval: `v(t) = v_k − a τ`, `p(t) = p_k − τ (v_k − ½ a τ)`,
//!   `τ = t_k − t`, `a = (v_k − v_{k−1})/(t_k − t_{k−1})`; the error state is taken as
//!   constant over τ (it changes on the Schuler time scale). The attitude used for the
//!   lever arm is `Ĉ(t) = Ĉ_k exp(−[ω_ib^b τ ×])` (the navigation-frame rotation over τ,
//!   ≤ 1e-4 rad/s · τ, is neglected).
//! * ZUPT: `ν = v̂^n`, `H = [0, I, 0, 0, 0]`; triggered by the caller (a flag).
//! * NHC (body frame; the vehicle frame is the body frame here): `ν = (Ĉᵀ v̂)_{y,z}`,
//!   `H = rows y, z of [0, Ĉᵀ, Ĉᵀ[v̂×], 0, 0]`.
//!
//! ## Update
//! `S = H P Hᵀ + R` (Cholesky; failure is [`FilterError::NotPositiveDefinite`]),
//! `NIS = νᵀ S⁻¹ ν`, `K = P Hᵀ S⁻¹`, `x̂ = K ν`, Joseph form
//! `P⁺ = (I − KH) P (I − KH)ᵀ + K R Kᵀ` (Groves (3.82)... (3.85) family), symmetrised.
//! Then the closed-loop correction (Groves §14.1.1): `L −= x̂_L`, …, `v −= δv̂`,
//! `Ĉ ← exp(−[ε̂×]) Ĉ`, `b̂_a += x̂_ba`, `b̂_g += x̂_bg` (and `ŝ += x̂_s`), `x̂ = 0`.
//!
//! ## Gating and its policy
//! A GNSS fix whose NIS exceeds the threshold of its degrees of freedom is rejected and
//! counted. After `max_consecutive_rejections` consecutive rejections the filter assumes
//! that it, not the receiver, has diverged: the position (and, with a velocity fix,
//! velocity) rows and columns of P are cleared, their diagonal blocks set to 100 R, and the
//! fix is applied ungated (a reset of position/velocity onto GNSS).

use super::error_model::{
    f_matrix, position_scale, transition, ModelPoint, StateMatN, StateVecN, I_ATT, I_BA, I_BG,
    I_POS, I_SA, I_SG, I_VEL, N_STATES,
};
use crate::coning::Increment;
use crate::earth::EarthModel;
use crate::math::{skew, Mat3, Quat, Vec3};
use crate::nav::{wrap_pi, Mechanization, NavState};
use nalgebra::{SMatrix, SVector};

/// 99.9 % quantiles of χ² with 1…6 degrees of freedom (default gate).
pub const CHI2_999: [f64; 6] = [10.828, 13.816, 16.266, 18.467, 20.515, 22.458];

/// Sensor noise and bias models of the filter (SI units, per body axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseModel {
    /// gyro angle random walk \[rad/√s\]
    pub arw_rad_per_sqrt_s: Vec3,
    /// accelerometer velocity random walk \[m/s/√s\]
    pub vrw_mps_per_sqrt_s: Vec3,
    /// accelerometer-bias Gauss–Markov steady-state σ \[m/s²\] (with `T = ∞`: unused)
    pub accel_bias_gm_mps2: Vec3,
    /// accelerometer-bias correlation time T \[s\]; `f64::INFINITY` = random constant
    pub accel_bias_tau_s: Vec3,
    /// gyro-bias Gauss–Markov steady-state σ \[rad/s\]
    pub gyro_bias_gm_rps: Vec3,
    /// gyro-bias correlation time T \[s\]; `f64::INFINITY` = random constant
    pub gyro_bias_tau_s: Vec3,
    /// accelerometer-bias random walk \[m/s²/√s\]
    pub accel_bias_rw: Vec3,
    /// gyro-bias random walk \[rad/s/√s\]
    pub gyro_bias_rw: Vec3,
}

impl Default for NoiseModel {
    fn default() -> Self {
        let inf = Vec3::repeat(f64::INFINITY);
        Self {
            arw_rad_per_sqrt_s: Vec3::zeros(),
            vrw_mps_per_sqrt_s: Vec3::zeros(),
            accel_bias_gm_mps2: Vec3::zeros(),
            accel_bias_tau_s: inf,
            gyro_bias_gm_rps: Vec3::zeros(),
            gyro_bias_tau_s: inf,
            accel_bias_rw: Vec3::zeros(),
            gyro_bias_rw: Vec3::zeros(),
        }
    }
}

/// Filter configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EkfConfig {
    /// earth model (the mechanization's)
    pub earth: EarthModel,
    /// sensor sample period δt \[s\]
    pub dt_s: f64,
    /// navigation updates per covariance epoch (≥ 1)
    pub cov_updates: usize,
    /// sensor noise and bias models
    pub noise: NoiseModel,
    /// GNSS antenna lever arm from the IMU, body frame \[m\]
    pub lever_arm_b_m: Vec3,
    /// NIS gate for GNSS fixes by degrees of freedom 1…6 (`None`: no gating)
    pub gate_chi2: Option<[f64; 6]>,
    /// consecutive GNSS rejections before the reset policy (≥ 1)
    pub max_consecutive_rejections: u32,
}

/// A GNSS fix as the filter sees it (the antenna's geodetic position, optionally NED
/// velocity, with their NED covariances).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssMeasurement {
    /// time of validity \[s\] (the navigation time base)
    pub t_s: f64,
    /// antenna latitude \[rad\]
    pub lat_rad: f64,
    /// antenna longitude \[rad\]
    pub lon_rad: f64,
    /// antenna ellipsoidal height \[m\]
    pub h_m: f64,
    /// NED position covariance \[m²\]
    pub pos_cov_ned_m2: Mat3,
    /// NED velocity \[m/s\] and covariance \[(m/s)²\]
    pub vel: Option<(Vec3, Mat3)>,
}

/// Kind of a measurement update.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum MeasKind {
    /// GNSS position (3) or position + velocity (6)
    Gnss,
    /// zero-velocity update
    Zupt,
    /// non-holonomic constraint (body y, z velocity)
    Nhc,
}

/// Outcome of one measurement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateReport {
    /// filter time at the update \[s\]
    pub t_s: f64,
    /// measurement kind
    pub kind: MeasKind,
    /// degrees of freedom (measurement dimension)
    pub dof: usize,
    /// innovation ν (first `dof` entries) \[m, m/s\]
    pub innovation: [f64; 6],
    /// its standard deviations √diag(S)
    pub sigma: [f64; 6],
    /// normalised innovation squared νᵀ S⁻¹ ν
    pub nis: f64,
    /// applied (false: rejected by the gate)
    pub accepted: bool,
    /// applied after the reset policy (consecutive rejections)
    pub forced: bool,
}

/// What the filter refuses to continue with.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum FilterError {
    /// A covariance (P or an innovation covariance S) is not positive definite or not finite.
    NotPositiveDefinite {
        /// filter time \[s\]
        t_s: f64,
        /// which matrix
        what: &'static str,
    },
    /// The navigation state became non-finite.
    NonFiniteState {
        /// filter time \[s\]
        t_s: f64,
    },
    /// A measurement has a non-finite value.
    BadMeasurement {
        /// filter time \[s\]
        t_s: f64,
    },
}

impl core::fmt::Display for FilterError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            FilterError::NotPositiveDefinite { t_s, what } => write!(
                f,
                "epoch t = {t_s} s: {what} is not finite or not positive definite"
            ),
            FilterError::NonFiniteState { t_s } => {
                write!(f, "epoch t = {t_s} s: navigation state is not finite")
            }
            FilterError::BadMeasurement { t_s } => {
                write!(f, "epoch t = {t_s} s: measurement has a non-finite value")
            }
        }
    }
}

impl core::error::Error for FilterError {}

/// One covariance epoch k, what a Rauch–Tung–Striebel smoother needs (see
/// [`super::rts`]): `P(k|k−1) = Φ P(k−1|k−1) Φᵀ + Q`, the covariance after the epoch's
/// measurements `P(k|k)`, and the sum of the closed-loop corrections `δx̂` applied at the
/// epoch (the error of the state *before* the corrections is the error after them plus
/// `dx`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CovEpoch<const N: usize = N_STATES> {
    /// time \[s\]
    pub t_s: f64,
    /// transition Φ(k, k−1) used from the previous epoch
    pub phi: StateMatN<N>,
    /// predicted covariance P(k|k−1)
    pub p_pred: StateMatN<N>,
    /// covariance after the epoch's measurements P(k|k) (filled by [`Ekf::take_epoch`])
    pub p_post: StateMatN<N>,
    /// sum of the corrections applied at the epoch (filled by [`Ekf::take_epoch`])
    pub dx: StateVecN<N>,
}

/// A navigation state corrected by an error estimate `x` (estimate − truth, the states of
/// [`super::error_model`]): `L −= δL`, `λ −= δλ`, `h −= δh`, `v −= δv`,
/// `Ĉ ← exp(−[ε×]) Ĉ` (Groves §14.1.1). The filter's closed-loop correction and the
/// smoother's re-applied corrections both use it (only the first 9 states are read).
pub fn correct_nav_state<const N: usize>(state: &NavState, x: &StateVecN<N>) -> NavState {
    let mut s = *state;
    s.lat_rad -= x[I_POS];
    s.lon_rad = wrap_pi(s.lon_rad - x[I_POS + 1]);
    s.h_m -= x[I_POS + 2];
    s.v_n_mps -= x.fixed_rows::<3>(I_VEL).into_owned();
    let eps: Vec3 = x.fixed_rows::<3>(I_ATT).into_owned();
    s.c_b_n = Quat::from_rotvec(&(-eps)).to_dcm() * s.c_b_n;
    s
}

/// The filter: `N = 15` (biases) or `N = 21` (biases and scale factors).
#[derive(Clone, Debug)]
pub struct Ekf<M: Mechanization, const N: usize = N_STATES> {
    mech: M,
    cfg: EkfConfig,
    p: StateMatN<N>,
    b_a: Vec3,
    b_g: Vec3,
    /// scale-factor estimates (zero in the 15-state filter)
    s_a: Vec3,
    s_g: Vec3,
    /// Σ Ĉ diag(Δv) and Σ Ĉ diag(Δθ) since the covariance epoch (21 states)
    sa_acc: Mat3,
    sg_acc: Mat3,
    prev: NavState,
    cur: NavState,
    /// Σ Ĉ Δv since the covariance epoch, and its interval
    f_acc: Vec3,
    tau_acc: f64,
    updates_acc: usize,
    /// compensated rate of the last update \[rad/s\]
    omega_ib_b: Vec3,
    last_epoch: Option<CovEpoch<N>>,
    /// corrections applied since the last covariance epoch
    dx_acc: StateVecN<N>,
    consecutive_rejections: u32,
    rejected_total: u64,
}

fn finite_state(s: &NavState) -> bool {
    s.lat_rad.is_finite()
        && s.lon_rad.is_finite()
        && s.h_m.is_finite()
        && s.v_n_mps.iter().all(|x| x.is_finite())
        && s.c_b_n.iter().all(|x| x.is_finite())
}

fn cov_ok<const N: usize>(p: &StateMatN<N>) -> bool {
    p.iter().all(|x| x.is_finite()) && (0..N).all(|i| p[(i, i)] >= 0.0)
}

impl<M: Mechanization, const N: usize> Ekf<M, N> {
    /// Whether the filter carries the scale-factor states.
    const SCALE_FACTORS: bool = {
        assert!(
            N == N_STATES || N == N_STATES + 6,
            "the filter has 15 or 21 states"
        );
        N > N_STATES
    };

    /// New filter on `mech` (at its initial state), initial covariance `p0`, initial bias
    /// estimates `b_a0` \[m/s²\], `b_g0` \[rad/s\]; scale-factor estimates start at zero
    /// ([`Ekf::with_scale_factors`] sets them).
    pub fn new(mech: M, cfg: EkfConfig, p0: StateMatN<N>, b_a0: Vec3, b_g0: Vec3) -> Self {
        let _ = Self::SCALE_FACTORS;
        let s = mech.state();
        Self {
            mech,
            cfg,
            p: (p0 + p0.transpose()) * 0.5,
            b_a: b_a0,
            b_g: b_g0,
            s_a: Vec3::zeros(),
            s_g: Vec3::zeros(),
            sa_acc: Mat3::zeros(),
            sg_acc: Mat3::zeros(),
            prev: s,
            cur: s,
            f_acc: Vec3::zeros(),
            tau_acc: 0.0,
            updates_acc: 0,
            omega_ib_b: Vec3::zeros(),
            last_epoch: None,
            dx_acc: StateVecN::<N>::zeros(),
            consecutive_rejections: 0,
            rejected_total: 0,
        }
    }

    /// Start the scale-factor estimates at `s_a0`, `s_g0` (dimensionless, e.g. 1e-4 =
    /// 100 ppm); ignored by the 15-state filter.
    pub fn with_scale_factors(mut self, s_a0: Vec3, s_g0: Vec3) -> Self {
        if Self::SCALE_FACTORS {
            self.s_a = s_a0;
            self.s_g = s_g0;
        }
        self
    }

    /// Current navigation state (corrected).
    pub fn state(&self) -> NavState {
        self.cur
    }
    /// Current covariance.
    pub fn covariance(&self) -> &StateMatN<N> {
        &self.p
    }
    /// Estimated biases (accelerometer \[m/s²\], gyro \[rad/s\]).
    pub fn biases(&self) -> (Vec3, Vec3) {
        (self.b_a, self.b_g)
    }
    /// Estimated scale factors (accelerometer, gyro; dimensionless; zero with 15 states).
    pub fn scale_factors(&self) -> (Vec3, Vec3) {
        (self.s_a, self.s_g)
    }
    /// GNSS fixes rejected by the gate so far.
    pub fn rejected_total(&self) -> u64 {
        self.rejected_total
    }
    /// The configuration.
    pub fn config(&self) -> &EkfConfig {
        &self.cfg
    }
    /// Take the covariance epoch recorded since the last call (for a smoother), with the
    /// current covariance as `P(k|k)` and the corrections applied since the epoch began.
    /// Call it after each navigation update and its measurements: an epoch not taken
    /// before the next covariance propagation is replaced.
    pub fn take_epoch(&mut self) -> Option<CovEpoch<N>> {
        self.last_epoch.take().map(|mut e| {
            e.p_post = self.p;
            e.dx = self.dx_acc;
            e
        })
    }

    /// The initial epoch (time of the initial state, `Φ = I`, `P(0|−1) = P(0|0) = P0`,
    /// no correction): the first record of a smoother log.
    pub fn initial_epoch(&self) -> CovEpoch<N> {
        CovEpoch {
            t_s: self.cur.t_s,
            phi: StateMatN::<N>::identity(),
            p_pred: self.p,
            p_post: self.p,
            dx: StateVecN::<N>::zeros(),
        }
    }
    /// The mechanization.
    pub fn mechanization(&self) -> &M {
        &self.mech
    }

    /// Advance one navigation update with the N raw samples; the covariance every
    /// `cov_updates` updates.
    pub fn propagate(&mut self, samples: &[Increment]) -> Result<(), FilterError> {
        let dt = self.cfg.dt_s;
        let mut comp = [Increment::default(); 4];
        let n = samples.len().min(4);
        let mut dv_sum = Vec3::zeros();
        let mut dth_sum = Vec3::zeros();
        let (k_g, k_a) = (Vec3::repeat(1.0) + self.s_g, Vec3::repeat(1.0) + self.s_a);
        for (c, s) in comp.iter_mut().zip(samples.iter()) {
            *c = Increment::new(
                (s.dtheta_b_rad - self.b_g * dt).component_div(&k_g),
                (s.dv_b_mps - self.b_a * dt).component_div(&k_a),
            );
            dv_sum += c.dv_b_mps;
            dth_sum += c.dtheta_b_rad;
        }
        let c_before = self.cur.c_b_n;
        self.mech.update(&comp[..n]);
        self.prev = self.cur;
        self.cur = self.mech.state();
        if !finite_state(&self.cur) {
            return Err(FilterError::NonFiniteState { t_s: self.cur.t_s });
        }
        let tau = self.cur.t_s - self.prev.t_s;
        self.omega_ib_b = if tau > 0.0 {
            dth_sum / tau
        } else {
            Vec3::zeros()
        };
        let c_mid = 0.5 * (c_before + self.cur.c_b_n);
        self.f_acc += c_mid * dv_sum;
        if Self::SCALE_FACTORS {
            self.sa_acc += c_mid * Mat3::from_diagonal(&dv_sum);
            self.sg_acc += c_mid * Mat3::from_diagonal(&dth_sum);
        }
        self.tau_acc += tau;
        self.updates_acc += 1;
        if self.updates_acc >= self.cfg.cov_updates.max(1) {
            self.propagate_covariance()?;
        }
        Ok(())
    }

    /// Propagate P over the interval accumulated since the last covariance epoch (no-op if
    /// it is empty).
    pub fn propagate_covariance(&mut self) -> Result<(), FilterError> {
        let tau = self.tau_acc;
        if tau <= 0.0 {
            return Ok(());
        }
        let s = &self.cur;
        let f_n = self.f_acc / tau;
        let pt = ModelPoint::on_earth(&self.cfg.earth, s.lat_rad, s.h_m, s.v_n_mps, s.c_b_n, f_n);
        let f15 = f_matrix(&pt, true, false);
        let mut f = StateMatN::<N>::zeros();
        f.fixed_view_mut::<N_STATES, N_STATES>(0, 0).copy_from(&f15);
        if Self::SCALE_FACTORS {
            f.fixed_view_mut::<3, 3>(I_VEL, I_SA)
                .copy_from(&(self.sa_acc / tau));
            f.fixed_view_mut::<3, 3>(I_ATT, I_SG)
                .copy_from(&(self.sg_acc / tau));
        }
        let nm = &self.cfg.noise;
        let mut qc = StateMatN::<N>::zeros();
        let c = s.c_b_n;
        let sq = |v: &Vec3| Mat3::from_diagonal(&v.component_mul(v));
        qc.fixed_view_mut::<3, 3>(I_VEL, I_VEL)
            .copy_from(&(c * sq(&nm.vrw_mps_per_sqrt_s) * c.transpose()));
        qc.fixed_view_mut::<3, 3>(I_ATT, I_ATT)
            .copy_from(&(c * sq(&nm.arw_rad_per_sqrt_s) * c.transpose()));
        for i in 0..3 {
            let (ta, sa) = (nm.accel_bias_tau_s[i], nm.accel_bias_gm_mps2[i]);
            let (tg, sg) = (nm.gyro_bias_tau_s[i], nm.gyro_bias_gm_rps[i]);
            let mut qa = nm.accel_bias_rw[i] * nm.accel_bias_rw[i];
            let mut qg = nm.gyro_bias_rw[i] * nm.gyro_bias_rw[i];
            if ta.is_finite() && ta > 0.0 {
                f[(I_BA + i, I_BA + i)] = -1.0 / ta;
                qa += 2.0 * sa * sa / ta;
            }
            if tg.is_finite() && tg > 0.0 {
                f[(I_BG + i, I_BG + i)] = -1.0 / tg;
                qg += 2.0 * sg * sg / tg;
            }
            qc[(I_BA + i, I_BA + i)] = qa;
            qc[(I_BG + i, I_BG + i)] = qg;
        }
        let phi = transition(&f, tau);
        let q = (phi * qc * phi.transpose() + qc) * (0.5 * tau);
        let p = phi * self.p * phi.transpose() + q;
        self.p = (p + p.transpose()) * 0.5;
        self.f_acc = Vec3::zeros();
        self.sa_acc = Mat3::zeros();
        self.sg_acc = Mat3::zeros();
        self.tau_acc = 0.0;
        self.updates_acc = 0;
        if !cov_ok(&self.p) {
            return Err(FilterError::NotPositiveDefinite {
                t_s: s.t_s,
                what: "propagated covariance P",
            });
        }
        self.last_epoch = Some(CovEpoch {
            t_s: s.t_s,
            phi,
            p_pred: self.p,
            p_post: self.p,
            dx: StateVecN::<N>::zeros(),
        });
        self.dx_acc = StateVecN::<N>::zeros();
        Ok(())
    }

    /// The navigation state interpolated to time `t_s` inside (or just before) the last
    /// update interval, constant acceleration (see the module documentation): (lat, lon,
    /// h, v^n).
    fn state_at(&self, t_s: f64) -> (f64, f64, f64, Vec3) {
        let (p, c) = (&self.prev, &self.cur);
        let dt = c.t_s - p.t_s;
        let tau = c.t_s - t_s;
        let a = if dt > 0.0 {
            (c.v_n_mps - p.v_n_mps) / dt
        } else {
            Vec3::zeros()
        };
        let v = c.v_n_mps - a * tau;
        let dp = -tau * (c.v_n_mps - 0.5 * a * tau);
        let r = self.cfg.earth.radii(c.lat_rad);
        let (_, cl) = libm::sincos(c.lat_rad);
        let t = position_scale(r.r_m_m, r.r_n_m, cl, c.h_m);
        (
            c.lat_rad + dp.x / t.x,
            c.lon_rad + dp.y / t.y,
            c.h_m - dp.z,
            v,
        )
    }

    /// Process a GNSS fix whose time of validity lies in the last update interval.
    pub fn update_gnss(&mut self, m: &GnssMeasurement) -> Result<UpdateReport, FilterError> {
        let t_now = self.cur.t_s;
        let finite = m.t_s.is_finite()
            && m.lat_rad.is_finite()
            && m.lon_rad.is_finite()
            && m.h_m.is_finite()
            && m.pos_cov_ned_m2.iter().all(|x| x.is_finite())
            && m.vel
                .is_none_or(|(v, c)| v.iter().chain(c.iter()).all(|x| x.is_finite()));
        if !finite {
            return Err(FilterError::BadMeasurement { t_s: t_now });
        }
        self.propagate_covariance()?;
        let (lat, lon, h, v) = self.state_at(m.t_s);
        // attitude at the time of validity: rotated back by the body rate over τ
        let tau = self.cur.t_s - m.t_s;
        let c = self.cur.c_b_n * Quat::from_rotvec(&(-self.omega_ib_b * tau)).to_dcm();
        let l = self.cfg.lever_arm_b_m;
        let r = self.cfg.earth.radii(lat);
        let (_, cl) = libm::sincos(lat);
        let t = position_scale(r.r_m_m, r.r_n_m, cl, h);
        let cl_n = c * l;
        // antenna position predicted: p + C l (NED offset → curvilinear)
        let nu_p = Vec3::new(
            (lat - m.lat_rad) * t.x + cl_n.x,
            wrap_pi(lon - m.lon_rad) * t.y + cl_n.y,
            -(h - m.h_m) + cl_n.z,
        );
        let mut h_p = SMatrix::<f64, 3, N>::zeros();
        for i in 0..3 {
            h_p[(i, I_POS + i)] = t[i];
        }
        h_p.fixed_view_mut::<3, 3>(0, I_ATT)
            .copy_from(&(-skew(&cl_n)));
        let gate = self.cfg.gate_chi2;
        match m.vel {
            None => {
                let rep = self.gated::<3>(&h_p, &nu_p, &m.pos_cov_ned_m2, gate, false)?;
                Ok(rep)
            }
            Some((v_meas, v_cov)) => {
                let w_ie_n = self.cfg.earth.omega_ie_n(lat);
                let w_eb = self.omega_ib_b - c.transpose() * w_ie_n;
                let wl = c * w_eb.cross(&l);
                let nu_v = v + wl - v_meas;
                let mut hm = SMatrix::<f64, 6, N>::zeros();
                hm.fixed_view_mut::<3, N>(0, 0).copy_from(&h_p);
                for i in 0..3 {
                    hm[(3 + i, I_VEL + i)] = 1.0;
                }
                hm.fixed_view_mut::<3, 3>(3, I_ATT).copy_from(&(-skew(&wl)));
                hm.fixed_view_mut::<3, 3>(3, I_BG)
                    .copy_from(&(-(c * skew(&l))));
                if Self::SCALE_FACTORS {
                    let w = Mat3::from_diagonal(&self.omega_ib_b);
                    hm.fixed_view_mut::<3, 3>(3, I_SG)
                        .copy_from(&(-(c * skew(&l) * w)));
                }
                let mut nu = SVector::<f64, 6>::zeros();
                nu.fixed_rows_mut::<3>(0).copy_from(&nu_p);
                nu.fixed_rows_mut::<3>(3).copy_from(&nu_v);
                let mut rm = SMatrix::<f64, 6, 6>::zeros();
                rm.fixed_view_mut::<3, 3>(0, 0).copy_from(&m.pos_cov_ned_m2);
                rm.fixed_view_mut::<3, 3>(3, 3).copy_from(&v_cov);
                self.gated::<6>(&hm, &nu, &rm, gate, true)
            }
        }
    }

    fn gated<const D: usize>(
        &mut self,
        h: &SMatrix<f64, D, N>,
        nu: &SVector<f64, D>,
        r: &SMatrix<f64, D, D>,
        gate: Option<[f64; 6]>,
        with_vel: bool,
    ) -> Result<UpdateReport, FilterError> {
        let threshold = gate.map(|g| g[D - 1]);
        let rep = self.update(MeasKind::Gnss, h, nu, r, threshold)?;
        if rep.accepted {
            self.consecutive_rejections = 0;
            return Ok(rep);
        }
        self.rejected_total += 1;
        self.consecutive_rejections += 1;
        if self.consecutive_rejections < self.cfg.max_consecutive_rejections.max(1) {
            return Ok(rep);
        }
        // reset policy: decorrelate position (and velocity) and re-seed them from the fix
        self.consecutive_rejections = 0;
        let t = h.fixed_view::<3, 3>(0, I_POS).diagonal();
        for i in 0..3 {
            self.p.row_mut(I_POS + i).fill(0.0);
            self.p.column_mut(I_POS + i).fill(0.0);
            if with_vel {
                self.p.row_mut(I_VEL + i).fill(0.0);
                self.p.column_mut(I_VEL + i).fill(0.0);
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                self.p[(I_POS + i, I_POS + j)] = 100.0 * r[(i, j)] / (t[i] * t[j]);
                if with_vel {
                    self.p[(I_VEL + i, I_VEL + j)] = 100.0 * r[(3 + i, 3 + j)];
                }
            }
        }
        let mut forced = self.update(MeasKind::Gnss, h, nu, r, None)?;
        forced.forced = true;
        Ok(forced)
    }

    /// Zero-velocity update with per-axis σ \[m/s\] (the caller decides when the vehicle is
    /// at rest).
    pub fn update_zupt(&mut self, sigma_mps: f64) -> Result<UpdateReport, FilterError> {
        self.propagate_covariance()?;
        let mut h = SMatrix::<f64, 3, N>::zeros();
        for i in 0..3 {
            h[(i, I_VEL + i)] = 1.0;
        }
        let r = SMatrix::<f64, 3, 3>::identity() * (sigma_mps * sigma_mps);
        let nu = self.cur.v_n_mps;
        self.update(MeasKind::Zupt, &h, &nu, &r, None)
    }

    /// Non-holonomic constraint: body-frame lateral and vertical velocity zero, σ \[m/s\].
    pub fn update_nhc(&mut self, sigma_mps: f64) -> Result<UpdateReport, FilterError> {
        self.propagate_covariance()?;
        let ct = self.cur.c_b_n.transpose();
        let v = self.cur.v_n_mps;
        let v_b = ct * v;
        let hv = ct;
        let ha = ct * skew(&v);
        let mut h = SMatrix::<f64, 2, N>::zeros();
        for (row, axis) in [1usize, 2].iter().enumerate() {
            for j in 0..3 {
                h[(row, I_VEL + j)] = hv[(*axis, j)];
                h[(row, I_ATT + j)] = ha[(*axis, j)];
            }
        }
        let nu = SVector::<f64, 2>::new(v_b.y, v_b.z);
        let r = SMatrix::<f64, 2, 2>::identity() * (sigma_mps * sigma_mps);
        self.update(MeasKind::Nhc, &h, &nu, &r, None)
    }

    /// Generic update (Joseph form) with optional gate; applies the closed-loop correction.
    fn update<const D: usize>(
        &mut self,
        kind: MeasKind,
        h: &SMatrix<f64, D, N>,
        nu: &SVector<f64, D>,
        r: &SMatrix<f64, D, D>,
        threshold: Option<f64>,
    ) -> Result<UpdateReport, FilterError> {
        let t_s = self.cur.t_s;
        let pht = self.p * h.transpose();
        let s = h * pht + r;
        let s = (s + s.transpose()) * 0.5;
        let chol = s.cholesky().ok_or(FilterError::NotPositiveDefinite {
            t_s,
            what: "innovation covariance S",
        })?;
        let nis = nu.dot(&chol.solve(nu));
        let mut rep = UpdateReport {
            t_s,
            kind,
            dof: D,
            innovation: [0.0; 6],
            sigma: [0.0; 6],
            nis,
            accepted: true,
            forced: false,
        };
        for i in 0..D.min(6) {
            rep.innovation[i] = nu[i];
            rep.sigma[i] = libm::sqrt(s[(i, i)]);
        }
        if !nis.is_finite() {
            return Err(FilterError::NotPositiveDefinite {
                t_s,
                what: "innovation covariance S",
            });
        }
        if let Some(th) = threshold {
            if nis > th {
                rep.accepted = false;
                return Ok(rep);
            }
        }
        // K = P Hᵀ S⁻¹  (solve S Kᵀ = H P)
        let k: SMatrix<f64, N, D> = chol.solve(&pht.transpose()).transpose();
        let x = k * nu;
        let ikh = StateMatN::<N>::identity() - k * h;
        let p = ikh * self.p * ikh.transpose() + k * r * k.transpose();
        self.p = (p + p.transpose()) * 0.5;
        if !cov_ok(&self.p) {
            return Err(FilterError::NotPositiveDefinite {
                t_s,
                what: "updated covariance P",
            });
        }
        self.apply_correction(&x);
        if !finite_state(&self.cur) {
            return Err(FilterError::NonFiniteState { t_s });
        }
        Ok(rep)
    }

    /// Closed-loop correction of the navigation state and biases with the error estimate.
    fn apply_correction(&mut self, x: &StateVecN<N>) {
        self.dx_acc += x;
        let s = correct_nav_state(&self.cur, x);
        self.b_a += x.fixed_rows::<3>(I_BA).into_owned();
        self.b_g += x.fixed_rows::<3>(I_BG).into_owned();
        if Self::SCALE_FACTORS {
            self.s_a += x.fixed_rows::<3>(I_SA).into_owned();
            self.s_g += x.fixed_rows::<3>(I_SG).into_owned();
        }
        // the interpolation base moves with the state
        let d_lat = s.lat_rad - self.cur.lat_rad;
        let d_lon = wrap_pi(s.lon_rad - self.cur.lon_rad);
        self.prev.lat_rad += d_lat;
        self.prev.lon_rad = wrap_pi(self.prev.lon_rad + d_lon);
        self.prev.h_m += s.h_m - self.cur.h_m;
        self.prev.v_n_mps += s.v_n_mps - self.cur.v_n_mps;
        self.mech.correct_state(&s);
        self.cur = self.mech.state();
    }
}
