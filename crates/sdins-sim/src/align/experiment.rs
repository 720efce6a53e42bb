//! Alignment experiments: exact static / turntable truth, sensor corruption,
//! and runners for coarse, fine, multi-heading (Algorithms A and B) alignment on top of
//! [`sdins_core::align`]. See docs/theory/alignment.md and docs/validation.md.
//!
//! Multi-heading sequences are built from the existing segment types: a stationary
//! vehicle is turned on the spot with a `turn` segment at zero speed (a rotation about
//! the local vertical; `profile = "constant"` gives a constant 10 °/s, and `profile = "smooth"`
//! also works at zero speed), see [`multiheading_trajectory`]; no new segment type is needed.

use crate::cancel::{CancelToken, Cancelled, POLL_EVERY_SAMPLES};
use crate::sensors::imu_error::{ImuErrorModel, ImuErrorModelError, ImuErrorState};
use crate::truth::trajectory::{Motion, Trajectory};
use crate::truth::{auto_substeps, TruthConfig, TruthGenerator};
use nalgebra::{SMatrix, SVector};
use sdins_core::align::coarse::{self, CoarseMethod, StaticMean};
use sdins_core::align::fine::{FineAlign, FineConfig};
use sdins_core::align::i0::InertialAlign;
use sdins_core::align::model::{pseudo_transform, BiasFrame, Mat12};
use sdins_core::align::multiheading::{AlgorithmB, AttitudeErrorTransition};
use sdins_core::align::{AlignError, Site};
use sdins_core::coning::Increment;
use sdins_core::earth::EarthModel;
use sdins_core::math::{dcm_from_rotvec, Euler, Mat3, Vec3};

/// Why an alignment runner stopped without a result.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AlignStop {
    /// the alignment mathematics failed (degenerate geometry, too few samples, ...)
    #[error("{0}")]
    Align(AlignError),
    /// stopped through the [`CancelToken`]
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
}

impl From<AlignError> for AlignStop {
    fn from(e: AlignError) -> Self {
        AlignStop::Align(e)
    }
}

/// Exact (error-free) IMU increments of a trajectory with the true attitude at the end
/// of every sample.
#[derive(Clone, Debug)]
pub struct TruthRecord {
    /// sample period \[s\]
    pub dt_s: f64,
    /// exact increments
    pub increments: Vec<Increment>,
    /// true `C_b^n` at the end of each sample
    pub c_b_n: Vec<Mat3>,
    /// true `C_b^n` at t = 0
    pub c_b_n0: Mat3,
    /// true speed `‖v^n‖` at the end of each sample \[m/s\]
    pub speed_mps: Vec<f64>,
    /// site (latitude, gravity and earth rate of the truth's earth model)
    pub site: Site,
}

/// Generate the exact truth of `traj` at the given site.
pub fn truth_record(
    traj: &Trajectory,
    earth: EarthModel,
    dt_s: f64,
    lat_rad: f64,
    lon_rad: f64,
    h_m: f64,
) -> TruthRecord {
    let cfg = TruthConfig {
        earth,
        dt_s,
        lat0_rad: lat_rad,
        lon0_rad: lon_rad,
        h0_m: h_m,
        substeps: auto_substeps(dt_s, traj),
    };
    let gen = TruthGenerator::new(traj, cfg);
    let c_b_n0 = gen.initial_state().c_b_n;
    let n = gen.len_samples() as usize;
    let mut increments = Vec::with_capacity(n);
    let mut c_b_n = Vec::with_capacity(n);
    let mut speed_mps = Vec::with_capacity(n);
    for s in gen {
        increments.push(s.inc);
        c_b_n.push(s.c_b_n);
        speed_mps.push(s.v_n_mps.norm());
    }
    TruthRecord {
        dt_s,
        increments,
        c_b_n,
        c_b_n0,
        speed_mps,
        site: Site::from_earth(&earth, lat_rad, h_m),
    }
}

/// Corrupt exact increments with run `run` of an error model.
pub fn corrupt(
    incs: &[Increment],
    dt_s: f64,
    model: &ImuErrorModel,
    seed: u64,
    run: u64,
) -> Result<Vec<Increment>, ImuErrorModelError> {
    let mut st = ImuErrorState::new(model, seed, run)?;
    Ok(st.apply_all(incs, dt_s))
}

/// Stationary sequence at relative headings `headings_deg` (first must be 0) from the
/// start attitude `euler0`: `static_each_s` seconds at each heading, rotations between
/// them at the constant rate `rate_dps` (on-the-spot turns about the local vertical,
/// docs/theory/alignment.md §"Multi-heading alignment" step 3). Returns the trajectory and the
/// start time and duration of each static phase.
pub fn multiheading_trajectory(
    euler0: Euler,
    headings_deg: &[f64],
    static_each_s: f64,
    rate_dps: f64,
) -> (Trajectory, Vec<(f64, f64)>) {
    let mut motions = Vec::new();
    let mut phases = Vec::new();
    let mut t = 0.0;
    let mut prev = 0.0;
    for (k, h) in headings_deg.iter().enumerate() {
        if k > 0 {
            let a = h - prev;
            let dur = (a.abs() / rate_dps).max(1.0);
            motions.push((
                Motion::TurnRate {
                    rate_rps: a.to_radians() / dur,
                },
                dur,
            ));
            t += dur;
        }
        motions.push((Motion::Static, static_each_s));
        phases.push((t, static_each_s));
        t += static_each_s;
        prev = *h;
    }
    (
        Trajectory::new(0.0, 0.0, euler0, &motions, Vec::new()),
        phases,
    )
}

/// Coarse alignment over the samples `[i0, i0 + n)`.
pub fn coarse_window(
    incs: &[Increment],
    dt_s: f64,
    i0: usize,
    n: usize,
    site: &Site,
    method: CoarseMethod,
) -> Result<Mat3, AlignError> {
    let mut m = StaticMean::new();
    for inc in incs.iter().skip(i0).take(n) {
        m.add(inc, dt_s);
    }
    coarse::align(method, &m, site)
}

/// Inertial-frame (i0) coarse alignment over the samples `[i0, i0 + n)`
/// ([`sdins_core::align::i0`]): returns `C_b^n` at the **end** of the window (sample
/// `i0 + n − 1`), robust to sway, rocking, heave and surge of the base.
pub fn i0_window(
    incs: &[Increment],
    dt_s: f64,
    i0: usize,
    n: usize,
    site: &Site,
) -> Result<Mat3, AlignError> {
    let mut a = InertialAlign::new(*site);
    for inc in incs.iter().skip(i0).take(n) {
        a.add(inc, dt_s);
    }
    a.c_b_n()
}

/// Block length of [`disturbance_sigma_z`] \[s\]: long against ship and car disturbance
/// periods (≤ 25 s), short against the fine filter's averaging time (hundreds of s).
pub const DISTURBANCE_BLOCK_S: f64 = 60.0;

/// White-equivalent zero-velocity σ \[m/s\] of a disturbed base at Kalman interval
/// `kf_dt_s` (docs/alignment_i0.md §6): the i0 velocity residual
/// `r_k = C_{ib0}^{n0} v^{ib0}_k − v^{n0}_k` over the first `n` samples is averaged over
/// blocks of τ_b = [`DISTURBANCE_BLOCK_S`] and its low-frequency PSD estimated as
/// `S₀ = τ_b · mean(r̄_block²)` (per axis, averaged over the horizontal axes and the
/// blocks); `σ_z = √(S₀ / Δt_KF)`. A bounded displacement D gives `r̄ ~ D/τ_b`, so a
/// swaying or heaving base is not charged its full velocity variance as if it were white
/// noise at every update. With fewer than two blocks the plain residual RMS is used.
pub fn disturbance_sigma_z(
    incs: &[Increment],
    dt_s: f64,
    n: usize,
    site: &Site,
    c_ib0_n0: &Mat3,
    kf_dt_s: f64,
) -> f64 {
    let per = ((DISTURBANCE_BLOCK_S / dt_s).round() as usize).max(1);
    let mut q = sdins_core::math::Quat::IDENTITY;
    let mut v = Vec3::zeros();
    let (mut blk, mut acc, mut cnt, mut all, mut nall) = (Vec3::zeros(), 0.0, 0usize, 0.0, 0usize);
    for (k, inc) in incs.iter().take(n).enumerate() {
        let half = sdins_core::math::Quat::from_rotvec(&(0.5 * inc.dtheta_b_rad));
        let qm = q.mul(&half);
        v += qm.rotate(&inc.dv_b_mps);
        q = qm.mul(&half).normalized();
        let t = (k + 1) as f64 * dt_s;
        let r = c_ib0_n0 * v - sdins_core::align::i0::gravity_velocity_n0(site, t);
        all += r.x * r.x + r.y * r.y;
        nall += 2;
        blk += r;
        if (k + 1) % per == 0 {
            let m = blk / per as f64;
            acc += 0.5 * (m.x * m.x + m.y * m.y);
            cnt += 1;
            blk = Vec3::zeros();
        }
    }
    if cnt < 2 {
        return (all / nall.max(1) as f64).sqrt();
    }
    let s0 = DISTURBANCE_BLOCK_S * acc / cnt as f64;
    (s0 / kf_dt_s).sqrt()
}

/// Fine alignment started from i0 (docs/alignment_i0.md §6): i0 over the first `n`
/// samples gives `C_b^n(0)`; the filter `cfg` runs over all of `incs` from `C_b^n(0)`
/// with the zero-velocity σ sized from the disturbance,
/// `σ_z = max(cfg.sigma_z_mps, σ_dist)`, σ_dist of [`disturbance_sigma_z`] (the base's
/// own velocity is the error of the zero-velocity measurement). A short or disturbed start window leaves i0 degrees
/// off, outside the small-angle filter's reach and absorbed into the east gyro bias; so
/// the start is refined once: the first pass's final attitude is carried back to t = 0
/// through the gyros, `Ĉ_b^n(0) = exp([ω_ie^n×] T) Ĉ_b^n(T) C_b^{ib0}(T)ᵀ`
/// ([`sdins_core::align::i0`] frame split), and the filter is rerun from it with fresh
/// bias states. `on_update` sees the second pass. Returns the filter, the (refined)
/// start attitude and the σ_z used.
pub fn fine_from_i0<F: FnMut(usize, &FineAlign)>(
    incs: &[Increment],
    dt_s: f64,
    mut cfg: FineConfig,
    n: usize,
    on_update: F,
    token: &CancelToken,
) -> Result<(FineAlign, Mat3, f64), AlignStop> {
    let mut a = InertialAlign::new(cfg.site);
    for inc in incs.iter().take(n) {
        a.add(inc, dt_s);
    }
    let c0 = a.c_b_n0()?;
    cfg.sigma_z_mps = cfg.sigma_z_mps.max(disturbance_sigma_z(
        incs,
        dt_s,
        n,
        &cfg.site,
        &c0,
        cfg.kf_dt_s,
    ));
    let sz = cfg.sigma_z_mps;
    let first = run_fine(incs, dt_s, cfg, &c0, |_, _| {}, token)?;
    // C_b^{ib0}(T) from the gyros
    let mut q = sdins_core::math::Quat::IDENTITY;
    for inc in incs {
        q = q
            .mul(&sdins_core::math::Quat::from_rotvec(&inc.dtheta_b_rad))
            .normalized();
    }
    let t = incs.len() as f64 * dt_s;
    let r = dcm_from_rotvec(&(cfg.site.omega_ie_n() * t));
    let c0b = sdins_core::math::orthonormalize(&(r * first.c_b_n() * q.to_dcm().transpose()));
    Ok((run_fine(incs, dt_s, cfg, &c0b, on_update, token)?, c0b, sz))
}

/// Run a fine alignment over `incs` from `c0`; `on_update(j, &filter)` is called after
/// every Kalman cycle, with `j` the index of the sample that ended it. `token` is polled
/// every [`POLL_EVERY_SAMPLES`] samples.
pub fn run_fine<F: FnMut(usize, &FineAlign)>(
    incs: &[Increment],
    dt_s: f64,
    cfg: FineConfig,
    c0: &Mat3,
    mut on_update: F,
    token: &CancelToken,
) -> Result<FineAlign, Cancelled> {
    let mut fa = FineAlign::new(cfg, c0);
    for (j, inc) in incs.iter().enumerate() {
        if (j as u64).is_multiple_of(POLL_EVERY_SAMPLES) {
            token.check()?;
        }
        if fa.step(inc, dt_s) {
            on_update(j, &fa);
        }
    }
    Ok(fa)
}

/// Result of a multi-heading alignment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MultiHeadingResult {
    /// final attitude estimate
    pub c_b_n: Mat3,
    /// estimated accelerometer bias, body \[m/s²\]
    pub accel_bias_b: Vec3,
    /// estimated gyro bias, body \[rad/s\]
    pub gyro_bias_b: Vec3,
    /// 1σ of the accelerometer bias, body \[m/s²\] (Algorithm B: from the LS covariance)
    pub accel_bias_sigma_b: Vec3,
    /// 1σ of the gyro bias, body \[rad/s\]
    pub gyro_bias_sigma_b: Vec3,
}

/// Algorithm A (docs/theory/alignment.md §"Multi-heading alignment"): 2-step coarse alignment over
/// the first `coarse_s` seconds, then one continuous closed-loop filter with body-frame bias states
/// over the whole record (zero-velocity updates through rotations too). `on_update` as in
/// [`run_fine`].
pub fn algorithm_a<F: FnMut(usize, &FineAlign)>(
    incs: &[Increment],
    dt_s: f64,
    mut cfg: FineConfig,
    coarse_s: f64,
    on_update: F,
    token: &CancelToken,
) -> Result<MultiHeadingResult, AlignStop> {
    let n = (coarse_s / dt_s).round() as usize;
    let c0 = coarse_window(incs, dt_s, 0, n, &cfg.site, CoarseMethod::TwoStep)?;
    cfg.bias_frame = BiasFrame::Body;
    cfg.closed_loop = true;
    let fa = run_fine(incs, dt_s, cfg, &c0, on_update, token)?;
    Ok(MultiHeadingResult {
        c_b_n: fa.c_b_n(),
        accel_bias_b: fa.accel_bias_b(),
        gyro_bias_b: fa.gyro_bias_b(),
        accel_bias_sigma_b: fa.accel_bias_sigma_b(),
        gyro_bias_sigma_b: fa.gyro_bias_sigma_b(),
    })
}

/// Algorithm B (docs/theory/alignment.md §"Multi-heading alignment"): 2-step coarse alignment over
/// the first `coarse_s` seconds, then the INS runs **open loop** (no corrections) over the whole
/// record; at each static phase `(t_start, duration)` a feed-forward 12-state NED filter is
/// restarted and its pseudo estimate `p_k = T x̂` (covariance `T P Tᵀ`) at the end of the phase is
/// stacked into the least-squares problem for `θ = [φ(t_0), b_a, b_g]`. The final attitude is the
/// INS attitude corrected by `φ(t_end) = Φ φ(t_0) + Γ b_g`.
pub fn algorithm_b(
    incs: &[Increment],
    dt_s: f64,
    mut cfg: FineConfig,
    coarse_s: f64,
    phases: &[(f64, f64)],
    token: &CancelToken,
) -> Result<MultiHeadingResult, AlignStop> {
    let site = cfg.site;
    let n = (coarse_s / dt_s).round() as usize;
    let c0 = coarse_window(incs, dt_s, 0, n, &site, CoarseMethod::TwoStep)?;
    cfg.bias_frame = BiasFrame::Ned;
    cfg.closed_loop = false;
    let p0 = cfg.p0;
    let t6 = pseudo_transform(&site);
    let mut fa = FineAlign::new(cfg, &c0);
    let mut tr = AttitudeErrorTransition::default();
    let mut alg = AlgorithmB::new(site);
    let idx = |t: f64| (t / dt_s).round() as usize;
    let starts: Vec<usize> = phases.iter().map(|p| idx(p.0)).collect();
    let ends: Vec<usize> = phases.iter().map(|p| idx(p.0 + p.1)).collect();
    let mut last_t = 0.0;
    for (j, inc) in incs.iter().enumerate() {
        if (j as u64).is_multiple_of(POLL_EVERY_SAMPLES) {
            token.check()?;
        }
        if starts.contains(&j) && j > 0 {
            fa.restart(&p0);
        }
        let c_before = fa.c_b_n_ins();
        fa.step(inc, dt_s);
        // Φ, Γ along the INS attitude (piece-wise constant over 10 samples)
        let t = (j + 1) as f64 * dt_s;
        if (j + 1) % 10 == 0 || ends.contains(&(j + 1)) {
            let c_mid = dcm_from_rotvec(
                &(0.5
                    * sdins_core::math::rotvec_from_dcm(&(fa.c_b_n_ins() * c_before.transpose()))),
            ) * c_before;
            tr.step(&c_mid, t - last_t, &site);
            last_t = t;
        }
        if ends.contains(&(j + 1)) {
            let kf = fa.kf();
            let p: SVector<f64, 6> = t6 * kf.x;
            let cov: SMatrix<f64, 6, 6> = t6 * kf.p * t6.transpose();
            alg.add_position(&tr, &fa.c_b_n_ins(), &p, &cov);
        }
    }
    // remaining time after the last phase
    let t_end = incs.len() as f64 * dt_s;
    if t_end > last_t {
        tr.step(&fa.c_b_n_ins(), t_end - last_t, &site);
    }
    let sol = alg.solve().ok_or(AlignError::Degenerate)?;
    let th = sol.theta;
    let phi0 = Vec3::new(th[0], th[1], th[2]);
    let ba = Vec3::new(th[3], th[4], th[5]);
    let bg = Vec3::new(th[6], th[7], th[8]);
    let phi_end = tr.phi * phi0 + tr.gamma * bg;
    let sd = |i: usize| sol.cov[(i, i)].max(0.0).sqrt();
    Ok(MultiHeadingResult {
        c_b_n: dcm_from_rotvec(&(-phi_end)) * fa.c_b_n_ins(),
        accel_bias_b: ba,
        gyro_bias_b: bg,
        accel_bias_sigma_b: Vec3::new(sd(3), sd(4), sd(5)),
        gyro_bias_sigma_b: Vec3::new(sd(6), sd(7), sd(8)),
    })
}

/// Reference P0 (docs/theory/alignment.md §"Fine alignment") as a convenience re-export.
pub fn p0_reference() -> Mat12 {
    sdins_core::align::model::p0_reference()
}
