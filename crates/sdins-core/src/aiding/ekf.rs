//! Error-state extended Kalman filter with closed-loop correction (Groves 2nd ed.
//! §14.1–§14.3) on top of any [`Mechanization`], with a runtime state layout
//! ([`super::layout`]) at a fixed capacity and one measurement interface
//! ([`super::meas`]). No allocation: every matrix is a fixed-size value and every product
//! runs over the active dimension `n` of the layout.
//!
//! ## State and conventions
//! The layout's blocks: navigation (δL, δλ, δh; δv^n; ε) **estimate − truth**, sensor
//! parameters (IMU biases, optional scale factors, other sensor blocks) **truth −
//! estimate** (the residual error of the compensated output), so that `δv̇ ∋ C_b^n b_a`
//! and `ε̇ ∋ C_b^n b_g` as in [`super::error_model`]. Attitude: convention G,
//! `Ĉ_b^n = (I + [ε×]) C_b^n`.
//!
//! ## Propagation
//! The navigation state is advanced every update by the mechanization with compensated
//! increments `(Δθ − b̂_g δt) ⊘ (1 + ŝ_g)`, `(Δv − b̂_a δt) ⊘ (1 + ŝ_a)` (per axis, the
//! exact inverse of `f̃ = (1 + s) f + b`; `ŝ = 0` without the scale-factor blocks). The
//! covariance is propagated every `cov_updates` navigation updates (and at every
//! measurement) over the interval `τ` since the last covariance epoch:
//! * `F` of the error model at the epoch's state with the interval-mean specific force
//!   `f^n = Σ Ĉ_b^n Δv / τ`, the scale-factor columns `Σ Ĉ diag(Δv)/τ`, `Σ Ĉ diag(Δθ)/τ`
//!   (Groves §14.2, "additional IMU error states"), and each block's process model;
//! * `Φ = I + Fτ + (Fτ)²/2 + (Fτ)³/6` (Groves (3.34) truncated, §14.2.3);
//! * `Q = ½(Φ Q_c Φᵀ + Q_c) τ` (trapezoidal rule), `Q_c = G diag(ARW², VRW², q) Gᵀ` with the
//!   white noises entering through `C_b^n` (Groves §14.2.2), plus the exact discrete noise
//!   of blocks that declare one (the receiver clock);
//! * `P⁻ = Φ P Φᵀ + Q`, symmetrised.
//!
//! ## Update ([`Ekf::update`], one entry point for every measurement)
//! `S = H P Hᵀ + R` (Cholesky; failure is [`FilterError::NotPositiveDefinite`]),
//! `NIS = νᵀ S⁻¹ ν`, `K = P Hᵀ S⁻¹`, `x̂ = K ν`, Joseph form
//! `P⁺ = (I − KH) P (I − KH)ᵀ + K R Kᵀ` (Groves (3.86)), symmetrised. Then the closed-loop
//! correction (Groves §14.1.1): `L −= x̂_L`, …, `v −= δv̂`, `Ĉ ← exp(−[ε̂×]) Ĉ`, and every
//! sensor parameter `p̂ += x̂_p`; `x̂ = 0`.
//!
//! ## Measurement timing
//! * Time of validity inside the last navigation interval `(t_{k−1}, t_k]`: the state at
//!   `t` by constant acceleration over the interval, `v(t) = v_k − aτ`,
//!   `p(t) = p_k − τ(v_k − ½aτ)`, `a = (v_k − v_{k−1})/(t_k − t_{k−1})`, `τ = t_k − t`,
//!   attitude for lever arms `Ĉ(t) = Ĉ_k exp(−[ω_ib^b τ×])`; the error state is taken as
//!   constant over τ.
//! * Earlier, up to `max_latency_s` (and the history: [`super::history`]): the same
//!   interpolation in the stored interval that holds `t`, the model evaluated there, then
//!   back-propagated to now: `H_now = H_then Φ(t_then, t_now)` and
//!   `ν' = ν − H_then Σ_i Φ(t_then, t_i) δx̂_i` for the corrections `δx̂_i` applied since,
//!   with `Φ(t_{i−1}, t_i) = Φ_i⁻¹ ≈ I − F_iτ_i + (F_iτ_i)²/2 − (F_iτ_i)³/6` rebuilt from the
//!   stored epochs (the interval holding `t_then` with its own F over the part after it).
//!   Approximation: the process noise between `t_then` and now is neglected in the
//!   measurement model (see `docs/theory/ins-gnss.md` for the bound).
//! * Older, or not covered by the history: refused, counted ([`Ekf::late_total`]) and
//!   reported (`UpdateReport::late`).
//!
//! ## Gating and its policy
//! A gated measurement ([`Measurement::gated`], the GNSS fixes) whose NIS exceeds the
//! threshold of its degrees of freedom is rejected and counted. After
//! `max_consecutive_rejections` consecutive rejections of one kind the filter assumes that
//! it, not the sensor, has diverged: [`Measurement::reset`] re-seeds the covariance of the
//! observed states and the measurement is applied ungated.

use super::error_model::{f_matrix, position_scale, ModelPoint, N_STATES};
use super::history::{nav_entry_at, EpochEntry, NavEntry, Ring, HIST_EPOCHS, HIST_UPDATES};
use super::layout::{BlockKind, Cov, Process, StateLayout, XVec};
use super::linalg::{
    chol_solve, cholesky, dot, mul, mul_tr, propagate as propagate_p, symmetrize, transition, HMat,
    KMat, MVec, MAX_ROWS,
};
pub use super::meas::{GnssMeasurement, MeasKind};
use super::meas::{MeasError, MeasModel, MeasPoint, Measurement, Nhc, Zupt};
use crate::coning::Increment;
use crate::earth::EarthModel;
use crate::math::{Mat3, Quat, Vec3};
use crate::nav::{wrap_pi, Mechanization, NavState};
pub use error::FilterError;

mod error;

/// 99.9 % quantiles of χ² with 1…12 degrees of freedom (default gate).
pub const CHI2_999: [f64; MAX_ROWS] = [
    10.828, 13.816, 16.266, 18.467, 20.515, 22.458, 24.322, 26.124, 27.877, 29.588, 31.264, 32.909,
];

/// Default largest latency of a measurement \[s\].
pub const DEFAULT_MAX_LATENCY_S: f64 = 1.0;

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

impl NoiseModel {
    /// The bias processes per axis (accelerometer, gyro): Gauss–Markov plus random walk,
    /// `q = K² + 2σ²/T`, `F = −1/T` (a random constant with `T = ∞` and `K = 0`).
    pub fn bias_processes(&self) -> ([Process; 3], [Process; 3]) {
        (
            core::array::from_fn(|i| {
                Process::gauss_markov_rw(
                    self.accel_bias_gm_mps2[i],
                    self.accel_bias_tau_s[i],
                    self.accel_bias_rw[i],
                )
            }),
            core::array::from_fn(|i| {
                Process::gauss_markov_rw(
                    self.gyro_bias_gm_rps[i],
                    self.gyro_bias_tau_s[i],
                    self.gyro_bias_rw[i],
                )
            }),
        )
    }
    /// The 15-state layout with these bias processes.
    pub fn layout(&self) -> StateLayout {
        let (a, g) = self.bias_processes();
        StateLayout::ins(a, g)
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
    /// white sensor noise (ARW, VRW) driving velocity and attitude
    pub noise: NoiseModel,
    /// NIS gate by degrees of freedom 1…12 (`None`: no gating)
    pub gate_chi2: Option<[f64; MAX_ROWS]>,
    /// consecutive rejections of one kind before the reset policy (≥ 1)
    pub max_consecutive_rejections: u32,
    /// largest accepted age of a measurement at its application \[s\]
    pub max_latency_s: f64,
}

/// Outcome of one measurement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateReport {
    /// filter time at the update \[s\]
    pub t_s: f64,
    /// the measurement's time of validity \[s\]
    pub t_valid_s: f64,
    /// measurement kind
    pub kind: MeasKind,
    /// degrees of freedom (measurement dimension)
    pub dof: usize,
    /// innovation ν = ĥ − z (first `dof` entries; back-propagated to the update time
    /// for a delayed measurement)
    pub innovation: [f64; MAX_ROWS],
    /// its standard deviations √diag(S)
    pub sigma: [f64; MAX_ROWS],
    /// normalised innovation squared νᵀ S⁻¹ ν (NaN when refused as late)
    pub nis: f64,
    /// applied (false: rejected by the gate, or late)
    pub accepted: bool,
    /// applied after the reset policy (consecutive rejections)
    pub forced: bool,
    /// refused: older than the largest latency or than the history
    pub late: bool,
}

/// One covariance epoch k, what a Rauch–Tung–Striebel smoother needs (see
/// [`super::rts`]): `P(k|k−1) = Φ P(k−1|k−1) Φᵀ + Q`, the covariance after the epoch's
/// measurements `P(k|k)`, and the sum of the closed-loop corrections `δx̂` applied at the
/// epoch (the error of the state *before* the corrections is the error after them plus
/// `dx`). Only the leading `n × n` blocks are meaningful.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CovEpoch {
    /// time \[s\]
    pub t_s: f64,
    /// active dimension
    pub n: usize,
    /// transition Φ(k, k−1) used from the previous epoch
    pub phi: Cov,
    /// predicted covariance P(k|k−1)
    pub p_pred: Cov,
    /// covariance after the epoch's measurements P(k|k) (filled by [`Ekf::take_epoch`])
    pub p_post: Cov,
    /// sum of the corrections applied at the epoch (filled by [`Ekf::take_epoch`])
    pub dx: XVec,
}

/// A navigation state corrected by an error estimate `x` (estimate − truth, the states of
/// [`super::error_model`]): `L −= δL`, `λ −= δλ`, `h −= δh`, `v −= δv`,
/// `Ĉ ← exp(−[ε×]) Ĉ` (Groves §14.1.1). The filter's closed-loop correction and the
/// smoother's re-applied corrections both use it (only the first 9 states are read).
pub fn correct_nav_state(state: &NavState, x: &XVec) -> NavState {
    let mut s = *state;
    s.lat_rad -= x[0];
    s.lon_rad = wrap_pi(s.lon_rad - x[1]);
    s.h_m -= x[2];
    s.v_n_mps -= Vec3::new(x[3], x[4], x[5]);
    let eps = Vec3::new(x[6], x[7], x[8]);
    s.c_b_n = Quat::from_rotvec(&(-eps)).to_dcm() * s.c_b_n;
    s
}

/// The filter.
#[derive(Clone, Debug)]
pub struct Ekf<M: Mechanization> {
    mech: M,
    cfg: EkfConfig,
    layout: StateLayout,
    p: Cov,
    /// sensor-parameter estimates at their block offsets
    est: XVec,
    prev: NavState,
    cur: NavState,
    /// Σ Ĉ Δv, Σ Ĉ diag(Δv), Σ Ĉ diag(Δθ) since the covariance epoch, and its interval
    f_acc: Vec3,
    sa_acc: Mat3,
    sg_acc: Mat3,
    tau_acc: f64,
    updates_acc: usize,
    /// compensated rate of the last update \[rad/s\]
    omega_ib_b: Vec3,
    last_epoch: Option<CovEpoch>,
    /// corrections applied since the last covariance epoch
    dx_acc: XVec,
    consecutive: [u32; MeasKind::COUNT],
    rejected_total: u64,
    late_total: u64,
    nav_hist: Ring<NavEntry, HIST_UPDATES>,
    epoch_hist: Ring<EpochEntry, HIST_EPOCHS>,
}

fn finite_state(s: &NavState) -> bool {
    s.lat_rad.is_finite()
        && s.lon_rad.is_finite()
        && s.h_m.is_finite()
        && s.v_n_mps.iter().all(|x| x.is_finite())
        && s.c_b_n.iter().all(|x| x.is_finite())
}

fn cov_ok(p: &Cov, n: usize) -> bool {
    (0..n).all(|j| (0..n).all(|i| p[(i, j)].is_finite())) && (0..n).all(|i| p[(i, i)] >= 0.0)
}

fn vec3_at(x: &XVec, o: Option<usize>) -> Vec3 {
    o.map_or(Vec3::zeros(), |o| Vec3::new(x[o], x[o + 1], x[o + 2]))
}

impl<M: Mechanization> Ekf<M> {
    /// New filter on `mech` (at its initial state) with the state layout `layout`, initial
    /// covariance `p0` (leading `n × n` block used) and initial parameter estimates `est0`
    /// (b̂_a \[m/s²\] at 9–11, b̂_g \[rad/s\] at 12–14, the other blocks at their offsets).
    pub fn new(mech: M, cfg: EkfConfig, layout: StateLayout, p0: &Cov, est0: &XVec) -> Self {
        let s = mech.state();
        let n = layout.n();
        let mut p = Cov::zeros();
        for j in 0..n {
            for i in 0..n {
                p[(i, j)] = (p0[(i, j)] + p0[(j, i)]) * 0.5;
            }
        }
        let mut est = XVec::zeros();
        for i in 9..n {
            est[i] = est0[i];
        }
        let entry = EpochEntry {
            t_s: s.t_s,
            tau_s: 0.0,
            lat_rad: s.lat_rad,
            h_m: s.h_m,
            v_n_mps: s.v_n_mps,
            c_b_n: s.c_b_n,
            f_n_mps2: Vec3::zeros(),
            sa: Mat3::zeros(),
            sg: Mat3::zeros(),
            dx: XVec::zeros(),
        };
        Self {
            mech,
            cfg,
            layout,
            p,
            est,
            prev: s,
            cur: s,
            f_acc: Vec3::zeros(),
            sa_acc: Mat3::zeros(),
            sg_acc: Mat3::zeros(),
            tau_acc: 0.0,
            updates_acc: 0,
            omega_ib_b: Vec3::zeros(),
            last_epoch: None,
            dx_acc: XVec::zeros(),
            consecutive: [0; MeasKind::COUNT],
            rejected_total: 0,
            late_total: 0,
            nav_hist: Ring::new(NavEntry {
                prev: s,
                cur: s,
                omega_ib_b: Vec3::zeros(),
            }),
            epoch_hist: Ring::new(entry),
        }
    }

    /// Current navigation state (corrected).
    pub fn state(&self) -> NavState {
        self.cur
    }
    /// Current covariance (leading `n × n` block).
    pub fn covariance(&self) -> &Cov {
        &self.p
    }
    /// The state layout.
    pub fn layout(&self) -> &StateLayout {
        &self.layout
    }
    /// Sensor-parameter estimates at their block offsets (zero in the navigation blocks).
    pub fn estimates(&self) -> &XVec {
        &self.est
    }
    /// Estimated biases (accelerometer \[m/s²\], gyro \[rad/s\]).
    pub fn biases(&self) -> (Vec3, Vec3) {
        (vec3_at(&self.est, Some(9)), vec3_at(&self.est, Some(12)))
    }
    /// Estimated scale factors (accelerometer, gyro; dimensionless; zero without the
    /// scale-factor blocks).
    pub fn scale_factors(&self) -> (Vec3, Vec3) {
        (
            vec3_at(&self.est, self.layout.offset(BlockKind::AccelScale)),
            vec3_at(&self.est, self.layout.offset(BlockKind::GyroScale)),
        )
    }
    /// Gated measurements rejected by the gate so far.
    pub fn rejected_total(&self) -> u64 {
        self.rejected_total
    }
    /// Measurements refused as older than the largest latency (or the history).
    pub fn late_total(&self) -> u64 {
        self.late_total
    }
    /// The configuration.
    pub fn config(&self) -> &EkfConfig {
        &self.cfg
    }
    /// The mechanization.
    pub fn mechanization(&self) -> &M {
        &self.mech
    }

    /// Take the covariance epoch recorded since the last call (for a smoother), with the
    /// current covariance as `P(k|k)` and the corrections applied since the epoch began.
    /// Call it after each navigation update and its measurements: an epoch not taken
    /// before the next covariance propagation is replaced.
    pub fn take_epoch(&mut self) -> Option<CovEpoch> {
        self.last_epoch.take().map(|mut e| {
            e.p_post = self.p;
            e.dx = self.dx_acc;
            e
        })
    }

    /// The initial epoch (time of the initial state, `Φ = I`, `P(0|−1) = P(0|0) = P0`,
    /// no correction): the first record of a smoother log.
    pub fn initial_epoch(&self) -> CovEpoch {
        CovEpoch {
            t_s: self.cur.t_s,
            n: self.layout.n(),
            phi: Cov::identity(),
            p_pred: self.p,
            p_post: self.p,
            dx: XVec::zeros(),
        }
    }

    /// Advance one navigation update with the N raw samples; the covariance every
    /// `cov_updates` updates.
    pub fn propagate(&mut self, samples: &[Increment]) -> Result<(), FilterError> {
        let dt = self.cfg.dt_s;
        let (b_a, b_g) = self.biases();
        let (s_a, s_g) = self.scale_factors();
        let mut comp = [Increment::default(); 4];
        let n = samples.len().min(4);
        let mut dv_sum = Vec3::zeros();
        let mut dth_sum = Vec3::zeros();
        let (k_g, k_a) = (Vec3::repeat(1.0) + s_g, Vec3::repeat(1.0) + s_a);
        for (c, s) in comp.iter_mut().zip(samples.iter()) {
            *c = Increment::new(
                (s.dtheta_b_rad - b_g * dt).component_div(&k_g),
                (s.dv_b_mps - b_a * dt).component_div(&k_a),
            );
            dv_sum += c.dv_b_mps;
            dth_sum += c.dtheta_b_rad;
        }
        self.nav_hist.push(NavEntry {
            prev: self.prev,
            cur: self.cur,
            omega_ib_b: self.omega_ib_b,
        });
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
        if self.layout.has(BlockKind::AccelScale) {
            self.sa_acc += c_mid * Mat3::from_diagonal(&dv_sum);
        }
        if self.layout.has(BlockKind::GyroScale) {
            self.sg_acc += c_mid * Mat3::from_diagonal(&dth_sum);
        }
        self.tau_acc += tau;
        self.updates_acc += 1;
        if self.updates_acc >= self.cfg.cov_updates.max(1) {
            self.propagate_covariance()?;
        }
        Ok(())
    }

    /// F and Q_c of the layout at a stored epoch (see the module documentation).
    fn system(&self, e: &EpochEntry, f: &mut Cov, qc: Option<&mut Cov>) {
        let pt = ModelPoint::on_earth(
            &self.cfg.earth,
            e.lat_rad,
            e.h_m,
            e.v_n_mps,
            e.c_b_n,
            e.f_n_mps2,
        );
        let f15 = f_matrix(&pt, true, false);
        f.fill(0.0);
        f.fixed_view_mut::<N_STATES, N_STATES>(0, 0).copy_from(&f15);
        if let Some(o) = self.layout.offset(BlockKind::AccelScale) {
            f.fixed_view_mut::<3, 3>(3, o).copy_from(&e.sa);
        }
        if let Some(o) = self.layout.offset(BlockKind::GyroScale) {
            f.fixed_view_mut::<3, 3>(6, o).copy_from(&e.sg);
        }
        let mut dummy = Cov::zeros();
        let qc = match qc {
            Some(q) => {
                q.fill(0.0);
                let nm = &self.cfg.noise;
                let c = e.c_b_n;
                let sq = |v: &Vec3| Mat3::from_diagonal(&v.component_mul(v));
                q.fixed_view_mut::<3, 3>(3, 3)
                    .copy_from(&(c * sq(&nm.vrw_mps_per_sqrt_s) * c.transpose()));
                q.fixed_view_mut::<3, 3>(6, 6)
                    .copy_from(&(c * sq(&nm.arw_rad_per_sqrt_s) * c.transpose()));
                q
            }
            None => &mut dummy,
        };
        self.layout.add_processes(f, qc);
    }

    /// Propagate P over the interval accumulated since the last covariance epoch (no-op if
    /// it is empty).
    pub fn propagate_covariance(&mut self) -> Result<(), FilterError> {
        let tau = self.tau_acc;
        if tau <= 0.0 {
            return Ok(());
        }
        let n = self.layout.n();
        let s = self.cur;
        let entry = EpochEntry {
            t_s: s.t_s,
            tau_s: tau,
            lat_rad: s.lat_rad,
            h_m: s.h_m,
            v_n_mps: s.v_n_mps,
            c_b_n: s.c_b_n,
            f_n_mps2: self.f_acc / tau,
            sa: self.sa_acc / tau,
            sg: self.sg_acc / tau,
            dx: XVec::zeros(),
        };
        let (mut f, mut qc, mut phi, mut t, mut q) = (
            Cov::zeros(),
            Cov::zeros(),
            Cov::zeros(),
            Cov::zeros(),
            Cov::zeros(),
        );
        self.system(&entry, &mut f, Some(&mut qc));
        transition(&mut phi, &f, tau, n);
        mul(&mut t, &phi, &qc, n);
        mul_tr(&mut q, &t, &phi, n);
        let half = 0.5 * tau;
        for j in 0..n {
            for i in 0..n {
                q[(i, j)] = (q[(i, j)] + qc[(i, j)]) * half;
            }
        }
        self.layout.add_exact_q(&mut q, tau);
        propagate_p(&mut self.p, &phi, &q, n);
        self.f_acc = Vec3::zeros();
        self.sa_acc = Mat3::zeros();
        self.sg_acc = Mat3::zeros();
        self.tau_acc = 0.0;
        self.updates_acc = 0;
        if !cov_ok(&self.p, n) {
            return Err(FilterError::NotPositiveDefinite {
                t_s: s.t_s,
                what: "propagated covariance P",
            });
        }
        self.last_epoch = Some(CovEpoch {
            t_s: s.t_s,
            n,
            phi,
            p_pred: self.p,
            p_post: self.p,
            dx: XVec::zeros(),
        });
        if let Some(last) = self.epoch_hist.back_mut(0) {
            last.dx = self.dx_acc;
        }
        self.epoch_hist.push(entry);
        self.dx_acc = XVec::zeros();
        Ok(())
    }

    /// The state at `t_s` inside the interval `(prev, cur]` by constant acceleration (see
    /// the module documentation): (lat, lon, h, v^n).
    fn state_at(&self, prev: &NavState, cur: &NavState, t_s: f64) -> (f64, f64, f64, Vec3) {
        let (p, c) = (prev, cur);
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

    fn point<'a>(
        &'a self,
        prev: &NavState,
        cur: &NavState,
        omega: Vec3,
        t_s: f64,
    ) -> MeasPoint<'a> {
        let (lat, lon, h, v) = self.state_at(prev, cur, t_s);
        let tau = cur.t_s - t_s;
        MeasPoint {
            t_s,
            lat_rad: lat,
            lon_rad: lon,
            h_m: h,
            v_n_mps: v,
            c_b_n: cur.c_b_n * Quat::from_rotvec(&(-omega * tau)).to_dcm(),
            omega_ib_b: omega,
            earth: &self.cfg.earth,
            layout: &self.layout,
            est: &self.est,
        }
    }

    /// Apply a measurement (the one entry point): timing, model, gate and its policy,
    /// Joseph-form update, closed-loop correction.
    pub fn update(&mut self, m: &dyn Measurement) -> Result<UpdateReport, FilterError> {
        let t_now = self.cur.t_s;
        let t_v = m.t_valid_s();
        let step = (self.cur.t_s - self.prev.t_s).max(1e-9);
        if !t_v.is_finite() || t_v > t_now + step {
            return Err(FilterError::BadMeasurement { t_s: t_now });
        }
        self.propagate_covariance()?;
        let bad = |e: MeasError| match e {
            MeasError::NonFinite => FilterError::BadMeasurement { t_s: t_now },
            MeasError::MissingBlock(block) => FilterError::MissingBlock { t_s: t_now, block },
        };
        let mut model = MeasModel::zeros(0);
        if t_v >= self.prev.t_s {
            let pt = self.point(&self.prev, &self.cur, self.omega_ib_b, t_v);
            m.evaluate(&pt, &mut model).map_err(bad)?;
            return self.apply(m, &model, None);
        }
        let entry = if t_now - t_v <= self.cfg.max_latency_s {
            nav_entry_at(&self.nav_hist, t_v).copied()
        } else {
            None
        };
        let back = entry.map(|e| {
            let pt = self.point(&e.prev, &e.cur, e.omega_ib_b, t_v);
            let r = m.evaluate(&pt, &mut model);
            r.map(|_| e.cur.t_s)
        });
        let t_entry = match back {
            Some(r) => r.map_err(bad)?,
            None => return Ok(self.refuse_late(m)),
        };
        let then_model = model.clone();
        if !self.back_propagate(&mut model, t_v, t_entry) {
            return Ok(self.refuse_late(m));
        }
        self.apply(m, &model, Some(&then_model))
    }

    fn refuse_late(&mut self, m: &dyn Measurement) -> UpdateReport {
        self.late_total += 1;
        UpdateReport {
            t_s: self.cur.t_s,
            t_valid_s: m.t_valid_s(),
            kind: m.kind(),
            dof: 0,
            innovation: [0.0; MAX_ROWS],
            sigma: [0.0; MAX_ROWS],
            nis: f64::NAN,
            accepted: false,
            forced: false,
            late: true,
        }
    }

    /// Map a model evaluated at `t_then` (in the navigation interval ending at `t_entry`)
    /// to the current error state: `H ← H Φ(t_then, now)`, `ν ← ν − Σ H Φ(t_then, t_i) δx̂_i`
    /// over the corrections after `t_entry`. `false` when the epoch history does not reach
    /// back to `t_then`.
    fn back_propagate(&self, model: &mut MeasModel, t_then: f64, t_entry: f64) -> bool {
        let n = self.layout.n();
        let d = model.dim;
        // the epochs after t_then, oldest first; the first one's interval must hold t_then
        let mut k_first = None;
        for k in 0..self.epoch_hist.len() {
            match self.epoch_hist.back(k) {
                Some(e) if e.t_s > t_then => k_first = Some(k),
                _ => break,
            }
        }
        let Some(k_first) = k_first else {
            return false;
        };
        match self.epoch_hist.back(k_first) {
            Some(e) if e.t_s - e.tau_s <= t_then => {}
            _ => return false,
        }
        let (mut f, mut phi_inv) = (Cov::zeros(), Cov::zeros());
        let mut h = model.h;
        let mut s = MVec::zeros();
        for k in (0..=k_first).rev() {
            let Some(e) = self.epoch_hist.back(k) else {
                return false;
            };
            let span = if k == k_first {
                e.t_s - t_then
            } else {
                e.tau_s
            };
            self.system(e, &mut f, None);
            transition(&mut phi_inv, &f, -span, n);
            // h ← h Φ⁻¹ (d × n)
            let mut next = HMat::zeros();
            for r in 0..d {
                for j in 0..n {
                    let mut acc = 0.0;
                    for i in 0..n {
                        acc += h[(r, i)] * phi_inv[(i, j)];
                    }
                    next[(r, j)] = acc;
                }
            }
            h = next;
            if e.t_s > t_entry {
                let dx = if k == 0 { &self.dx_acc } else { &e.dx };
                for r in 0..d {
                    let mut acc = 0.0;
                    for j in 0..n {
                        acc += h[(r, j)] * dx[j];
                    }
                    s[r] += acc;
                }
            }
        }
        for r in 0..d {
            model.nu[r] -= s[r];
        }
        model.h = h;
        true
    }

    /// Gate, policy and Joseph update of an evaluated model.
    fn apply(
        &mut self,
        m: &dyn Measurement,
        model: &MeasModel,
        then_model: Option<&MeasModel>,
    ) -> Result<UpdateReport, FilterError> {
        let kind = m.kind();
        let d = model.dim.clamp(1, MAX_ROWS);
        let threshold = if m.gated() {
            self.cfg.gate_chi2.map(|g| g[d - 1])
        } else {
            None
        };
        let mut rep = self.joseph(kind, model, threshold)?;
        rep.t_valid_s = m.t_valid_s();
        if !m.gated() {
            return Ok(rep);
        }
        let c = &mut self.consecutive[kind.index()];
        if rep.accepted {
            *c = 0;
            return Ok(rep);
        }
        self.rejected_total += 1;
        *c += 1;
        if *c < self.cfg.max_consecutive_rejections.max(1) {
            return Ok(rep);
        }
        *c = 0;
        m.reset(&mut self.p, then_model.unwrap_or(model), &self.layout);
        let mut forced = self.joseph(kind, model, None)?;
        forced.t_valid_s = m.t_valid_s();
        forced.forced = true;
        Ok(forced)
    }

    /// Joseph-form update with an optional gate; applies the closed-loop correction.
    fn joseph(
        &mut self,
        kind: MeasKind,
        model: &MeasModel,
        threshold: Option<f64>,
    ) -> Result<UpdateReport, FilterError> {
        const R: usize = MAX_ROWS;
        let t_s = self.cur.t_s;
        let n = self.layout.n();
        let d = model.dim.clamp(1, R);
        let (h, nu, r) = (&model.h, &model.nu, &model.r);
        // P Hᵀ (n × d)
        let mut pht = KMat::zeros();
        for c in 0..d {
            for i in 0..n {
                pht[(i, c)] = self.p[(i, 0)] * h[(c, 0)];
            }
            for k in 1..n {
                let hk = h[(c, k)];
                for i in 0..n {
                    pht[(i, c)] += self.p[(i, k)] * hk;
                }
            }
        }
        // S = H P Hᵀ + R, symmetrised
        let mut s = [0.0f64; R * R];
        for b in 0..d {
            for a in 0..d {
                let mut acc = h[(a, 0)] * pht[(0, b)];
                for k in 1..n {
                    acc += h[(a, k)] * pht[(k, b)];
                }
                s[b * R + a] = acc + r[(a, b)];
            }
        }
        for b in 0..d {
            for a in b..d {
                let v = (s[b * R + a] + s[a * R + b]) * 0.5;
                s[b * R + a] = v;
                s[a * R + b] = v;
            }
        }
        let mut rep = UpdateReport {
            t_s,
            t_valid_s: t_s,
            kind,
            dof: d,
            innovation: [0.0; R],
            sigma: [0.0; R],
            nis: f64::NAN,
            accepted: true,
            forced: false,
            late: false,
        };
        for i in 0..d {
            rep.innovation[i] = nu[i];
            rep.sigma[i] = libm::sqrt(s[i * R + i]);
        }
        let mut l = s;
        let not_pd = FilterError::NotPositiveDefinite {
            t_s,
            what: "innovation covariance S",
        };
        if !cholesky(&mut l, R, d) {
            return Err(not_pd);
        }
        let mut y = [0.0; R];
        y[..d].copy_from_slice(&nu.as_slice()[..d]);
        chol_solve(&l, R, d, &mut y);
        let nis = dot(&nu.as_slice()[..d], &y[..d]);
        rep.nis = nis;
        if !nis.is_finite() {
            return Err(not_pd);
        }
        if let Some(th) = threshold {
            if nis > th {
                rep.accepted = false;
                return Ok(rep);
            }
        }
        // K = P Hᵀ S⁻¹: row i of K solves S kᵢ = (P Hᵀ)ᵢ
        let mut k = KMat::zeros();
        for i in 0..n {
            let mut row = [0.0; R];
            for (c, v) in row.iter_mut().enumerate().take(d) {
                *v = pht[(i, c)];
            }
            chol_solve(&l, R, d, &mut row);
            for c in 0..d {
                k[(i, c)] = row[c];
            }
        }
        // x = K ν
        let mut x = XVec::zeros();
        for i in 0..n {
            x[i] = k[(i, 0)] * nu[0];
        }
        for c in 1..d {
            for i in 0..n {
                x[i] += k[(i, c)] * nu[c];
            }
        }
        // I − K H
        let mut ikh = Cov::zeros();
        for j in 0..n {
            for i in 0..n {
                let mut acc = k[(i, 0)] * h[(0, j)];
                for c in 1..d {
                    acc += k[(i, c)] * h[(c, j)];
                }
                ikh[(i, j)] = if i == j { 1.0 } else { 0.0 } - acc;
            }
        }
        // (I − KH) P (I − KH)ᵀ + K R Kᵀ
        let (mut a, mut b) = (Cov::zeros(), Cov::zeros());
        mul(&mut a, &ikh, &self.p, n);
        mul_tr(&mut b, &a, &ikh, n);
        let mut kr = KMat::zeros();
        for c2 in 0..d {
            for i in 0..n {
                let mut acc = k[(i, 0)] * r[(0, c2)];
                for c in 1..d {
                    acc += k[(i, c)] * r[(c, c2)];
                }
                kr[(i, c2)] = acc;
            }
        }
        for j in 0..n {
            for i in 0..n {
                let mut acc = kr[(i, 0)] * k[(j, 0)];
                for c in 1..d {
                    acc += kr[(i, c)] * k[(j, c)];
                }
                self.p[(i, j)] = b[(i, j)] + acc;
            }
        }
        symmetrize(&mut self.p, n);
        if !cov_ok(&self.p, n) {
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

    /// Closed-loop correction of the navigation state and the sensor parameters.
    fn apply_correction(&mut self, x: &XVec) {
        let n = self.layout.n();
        self.dx_acc += x;
        let s = correct_nav_state(&self.cur, x);
        for i in 9..n {
            self.est[i] += x[i];
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

    /// GNSS fix (position, optionally velocity): [`Ekf::update`] with a
    /// [`GnssMeasurement`].
    pub fn update_gnss(&mut self, m: &GnssMeasurement) -> Result<UpdateReport, FilterError> {
        self.update(m)
    }

    /// Zero-velocity update now, σ per axis \[m/s\].
    pub fn update_zupt(&mut self, sigma_mps: f64) -> Result<UpdateReport, FilterError> {
        let t_s = self.cur.t_s;
        self.update(&Zupt { t_s, sigma_mps })
    }

    /// Non-holonomic constraint now, σ \[m/s\].
    pub fn update_nhc(&mut self, sigma_mps: f64) -> Result<UpdateReport, FilterError> {
        let t_s = self.cur.t_s;
        self.update(&Nhc { t_s, sigma_mps })
    }
}
