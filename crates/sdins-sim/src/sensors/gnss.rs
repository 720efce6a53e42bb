//! GNSS receiver simulation from the exact truth (position/velocity fixes of the antenna).
//!
//! * Epochs `t_j = offset_s + j / rate_hz` (j ≥ 0, `0 < t_j ≤` end of the record): fixes may
//!   fall anywhere between IMU samples.
//! * Truth at `t_j`: velocity, attitude and the body rate `ω_nb^b` from the trajectory's
//!   exact kinematics at `t_j`; the position by cubic Hermite interpolation of latitude,
//!   longitude and height between the two IMU samples around `t_j`, with the exact rates
//!   `L̇ = v_N/(R_M+h)`, `λ̇ = v_E/((R_N+h)cos L)`, `ḣ = −v_D` at both ends (error
//!   ≤ δt⁴/384 · max|p⁽⁴⁾|: about 1e-10 m at 100 Hz).
//! * Lever arm `l` (body, IMU → antenna; Groves (14.110)–(14.111)):
//!   `r_a^e = r^e + C_n^e C_b^n l` (through ECEF), `v_a^n = v^n + C_b^n (ω_eb^b × l)` with
//!   `ω_eb^b = ω_ib^b − C_n^b ω_ie^n = ω_nb^b + C_n^b ω_en^n`.
//! * Errors: white position and NED-velocity noise (per-axis σ), optional first-order
//!   Gauss–Markov position error `e_{j+1} = e^{−Δ/T} e_j + σ√(1 − e^{−2Δ/T}) w`,
//!   `e_0 ~ N(0, σ²)` (stepped at every epoch, also at dropped ones).
//! * Outages `[start, end)` and random dropouts (probability per epoch) remove fixes.
//! * Latency: the fix is tagged `t_j + latency_s`; the fuse pipeline either corrects the
//!   tag by the known latency (`latency_modelled = true`, the default) or uses it as is.
//! * The reported covariance is `diag(σ_white² + σ_GM²)` (the filter does not model the
//!   correlation of the GM part).
//!
//! Random numbers: one ChaCha20 stream per (seed, run, channel) — channels 0–2 position
//! noise, 3–5 velocity noise, 6–8 Gauss–Markov, 9 dropouts — each drawing exactly one
//! number per epoch, so a run's fixes do not depend on threads, chunking or other runs.
//! The stream numbers `2⁶³ + 16·run + channel` are disjoint from the IMU error streams
//! (`6·run + channel`).

use crate::sensors::gnss_fix::GnssFix;
use crate::truth::trajectory::Trajectory;
use crate::truth::TruthSample;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha20Rng;
use rand_distr::StandardNormal;
use sdins_core::earth::EarthModel;
use sdins_core::math::{Mat3, Vec3};
use sdins_core::nav::wrap_pi;

/// GNSS simulation settings (units in the names).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GnssConfig {
    /// fix rate \[Hz\], 1…20 (0: no GNSS)
    pub rate_hz: f64,
    /// time of the first epoch relative to the IMU clock \[s\]
    pub offset_s: f64,
    /// white position noise σ N, E, D \[m\]
    pub sigma_pos_ned_m: [f64; 3],
    /// white velocity noise σ N, E, D \[m/s\]; all 0: no velocity in the fixes
    pub sigma_vel_ned_mps: [f64; 3],
    /// Gauss–Markov position error σ N, E, D \[m\] (0: off)
    pub gm_sigma_ned_m: [f64; 3],
    /// its correlation time \[s\]
    pub gm_tau_s: f64,
    /// antenna lever arm from the IMU in body axes \[m\]
    pub lever_arm_b_m: [f64; 3],
    /// outages as `[start_s, end_s]` pairs
    pub outages_s: Vec<[f64; 2]>,
    /// probability that an epoch is dropped, 0…1
    pub dropout_prob: f64,
    /// injected outliers `[t_s, dN_m, dE_m, dD_m]`: added to the fix of the epoch nearest
    /// `t_s` (within half a period)
    pub outliers_t_s_ned_m: Vec<[f64; 4]>,
    /// time-tag latency \[s\] (tag = time of validity + latency)
    pub latency_s: f64,
    /// whether the filter knows (and corrects) the latency
    pub latency_modelled: bool,
    /// random seed of the GNSS errors
    pub seed: u64,
}

impl Default for GnssConfig {
    fn default() -> Self {
        Self {
            rate_hz: 1.0,
            offset_s: 0.0,
            sigma_pos_ned_m: [1.0, 1.0, 2.0],
            sigma_vel_ned_mps: [0.05, 0.05, 0.1],
            gm_sigma_ned_m: [0.0; 3],
            gm_tau_s: 100.0,
            lever_arm_b_m: [0.0; 3],
            outages_s: Vec::new(),
            dropout_prob: 0.0,
            outliers_t_s_ned_m: Vec::new(),
            latency_s: 0.0,
            latency_modelled: true,
            seed: 1,
        }
    }
}

/// A bad GNSS setting (names the key).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GnssConfigError {
    /// The value of `key` is out of range.
    #[error("[gnss] {key}: {what}")]
    Invalid {
        /// key name
        key: &'static str,
        /// what is wrong
        what: String,
    },
}

fn bad(key: &'static str, what: impl Into<String>) -> GnssConfigError {
    GnssConfigError::Invalid {
        key,
        what: what.into(),
    }
}

impl GnssConfig {
    /// Check every value (finite, in range).
    pub fn validate(&self) -> Result<(), GnssConfigError> {
        if !(self.rate_hz.is_finite() && (1.0..=20.0).contains(&self.rate_hz)) {
            return Err(bad(
                "rate_hz",
                format!("must be in 1…20, got {}", self.rate_hz),
            ));
        }
        if !self.offset_s.is_finite() {
            return Err(bad("offset_s", "must be finite"));
        }
        let pos = |key, v: &[f64; 3], strict: bool| {
            for x in v {
                if !x.is_finite() || *x < 0.0 || (strict && *x <= 0.0) {
                    return Err(bad(
                        key,
                        format!(
                            "must be finite and {}, got {x}",
                            if strict { "> 0" } else { "≥ 0" }
                        ),
                    ));
                }
            }
            Ok(())
        };
        pos("sigma_pos_ned_m", &self.sigma_pos_ned_m, true)?;
        pos("sigma_vel_ned_mps", &self.sigma_vel_ned_mps, false)?;
        let v = self.sigma_vel_ned_mps;
        if v.iter().any(|x| *x > 0.0) && v.contains(&0.0) {
            return Err(bad("sigma_vel_ned_mps", "set all three axes or none"));
        }
        pos("gm_sigma_ned_m", &self.gm_sigma_ned_m, false)?;
        if self.gm_sigma_ned_m.iter().any(|x| *x > 0.0)
            && !(self.gm_tau_s.is_finite() && self.gm_tau_s > 0.0)
        {
            return Err(bad(
                "gm_tau_s",
                format!("must be > 0, got {}", self.gm_tau_s),
            ));
        }
        if self
            .lever_arm_b_m
            .iter()
            .any(|x| !x.is_finite() || x.abs() > 100.0)
        {
            return Err(bad("lever_arm_b_m", "must be finite and within ±100 m"));
        }
        for o in &self.outages_s {
            if !(o[0].is_finite() && o[1].is_finite() && o[1] > o[0]) {
                return Err(bad("outages_s", format!("need start < end, got {o:?}")));
            }
        }
        if self
            .outliers_t_s_ned_m
            .iter()
            .flatten()
            .any(|x| !x.is_finite())
        {
            return Err(bad("outliers_t_s_ned_m", "must be finite"));
        }
        if !(self.dropout_prob.is_finite() && (0.0..=1.0).contains(&self.dropout_prob)) {
            return Err(bad("dropout_prob", "must be in 0…1"));
        }
        if !(self.latency_s.is_finite() && (0.0..=1.0).contains(&self.latency_s)) {
            return Err(bad("latency_s", "must be in 0…1 s"));
        }
        Ok(())
    }

    /// Whether the fixes carry a velocity.
    pub fn has_velocity(&self) -> bool {
        self.sigma_vel_ned_mps.iter().all(|x| *x > 0.0)
    }

    /// Whether `t_s` falls in a scheduled outage.
    pub fn in_outage(&self, t_s: f64) -> bool {
        self.outages_s.iter().any(|o| t_s >= o[0] && t_s < o[1])
    }
}

/// Stream number of a GNSS channel.
fn stream(run: u64, channel: u64) -> u64 {
    (1u64 << 63) | run.wrapping_mul(16).wrapping_add(channel)
}

/// The GNSS simulator of one run: feed it consecutive truth samples.
#[derive(Clone, Debug)]
pub struct GnssSimulator {
    cfg: GnssConfig,
    earth: EarthModel,
    rng: [ChaCha20Rng; 10],
    gm: Vec3,
    next_j: u64,
    /// epochs emitted and dropped so far
    pub emitted: u64,
    /// epochs removed by outages or dropouts
    pub removed: u64,
}

impl GnssSimulator {
    /// Simulator for run `run` (validates the configuration).
    pub fn new(cfg: &GnssConfig, earth: EarthModel, run: u64) -> Result<Self, GnssConfigError> {
        cfg.validate()?;
        let rng: [ChaCha20Rng; 10] = core::array::from_fn(|ch| {
            let mut r = ChaCha20Rng::seed_from_u64(cfg.seed);
            r.set_stream(stream(run, ch as u64));
            r
        });
        let mut s = Self {
            cfg: cfg.clone(),
            earth,
            rng,
            gm: Vec3::zeros(),
            next_j: 0,
            emitted: 0,
            removed: 0,
        };
        for i in 0..3 {
            let w: f64 = s.rng[6 + i].sample(StandardNormal);
            s.gm[i] = cfg.gm_sigma_ned_m[i] * w;
        }
        // first epoch strictly after t = 0
        let mut j = 0u64;
        while cfg.offset_s + j as f64 / cfg.rate_hz <= 0.0 {
            j += 1;
        }
        s.next_j = j;
        Ok(s)
    }

    /// The configuration.
    pub fn config(&self) -> &GnssConfig {
        &self.cfg
    }

    fn epoch_time(&self, j: u64) -> f64 {
        self.cfg.offset_s + j as f64 / self.cfg.rate_hz
    }

    /// Fixes with time of validity in `(a.t_s, b.t_s]` (at most a few; appended to `out`).
    pub fn step(
        &mut self,
        traj: &Trajectory,
        a: &TruthSample,
        b: &TruthSample,
        out: &mut Vec<GnssFix>,
    ) {
        loop {
            let t = self.epoch_time(self.next_j);
            if t > b.t_s {
                return;
            }
            self.next_j += 1;
            if t <= a.t_s {
                continue;
            }
            // one draw per channel per epoch, whatever happens to the fix
            let mut w = [0.0; 9];
            for (i, wi) in w.iter_mut().enumerate() {
                *wi = self.rng[i].sample(StandardNormal);
            }
            let u: f64 = self.rng[9].gen();
            let dt_gm = 1.0 / self.cfg.rate_hz;
            if self.cfg.gm_sigma_ned_m.iter().any(|x| *x > 0.0) && self.next_j > 1 {
                let e = (-dt_gm / self.cfg.gm_tau_s).exp();
                let s = (1.0 - e * e).sqrt();
                for i in 0..3 {
                    self.gm[i] = e * self.gm[i] + self.cfg.gm_sigma_ned_m[i] * s * w[6 + i];
                }
            }
            if self.cfg.in_outage(t) || u < self.cfg.dropout_prob {
                self.removed += 1;
                continue;
            }
            out.push(self.fix_at(traj, a, b, t, &w));
            self.emitted += 1;
        }
    }

    /// The exact antenna fix at `t` (no noise), and the noisy one (`w` = standard normals).
    fn fix_at(
        &self,
        traj: &Trajectory,
        a: &TruthSample,
        b: &TruthSample,
        t: f64,
        w: &[f64; 9],
    ) -> GnssFix {
        let truth = exact_antenna(&self.earth, traj, a, b, t, &self.cfg.lever_arm_b_m);
        let c = &self.cfg;
        let r = self.earth.radii(truth.0);
        let scale = Vec3::new(r.r_m_m + truth.2, (r.r_n_m + truth.2) * truth.0.cos(), -1.0);
        let mut err = Vec3::zeros();
        let mut var = Vec3::zeros();
        let half = 0.5 / c.rate_hz;
        for o in c
            .outliers_t_s_ned_m
            .iter()
            .filter(|o| (o[0] - t).abs() < half)
        {
            err += Vec3::new(o[1], o[2], o[3]);
        }
        for i in 0..3 {
            err[i] += c.sigma_pos_ned_m[i] * w[i] + self.gm[i];
            var[i] = c.sigma_pos_ned_m[i].powi(2) + c.gm_sigma_ned_m[i].powi(2);
        }
        let vel = if c.has_velocity() {
            let mut v = truth.3;
            let mut vv = Vec3::zeros();
            for i in 0..3 {
                v[i] += c.sigma_vel_ned_mps[i] * w[3 + i];
                vv[i] = c.sigma_vel_ned_mps[i].powi(2);
            }
            Some((v, Mat3::from_diagonal(&vv)))
        } else {
            None
        };
        GnssFix {
            t_s: t + c.latency_s,
            lat_rad: truth.0 + err.x / scale.x,
            lon_rad: wrap_pi(truth.1 + err.y / scale.y),
            h_m: truth.2 - err.z,
            pos_cov_ned_m2: Mat3::from_diagonal(&var),
            vel,
        }
    }
}

/// Exact antenna (lat, lon, h, v^n) at `t ∈ [a.t_s, b.t_s]` (see the module documentation).
pub fn exact_antenna(
    earth: &EarthModel,
    traj: &Trajectory,
    a: &TruthSample,
    b: &TruthSample,
    t: f64,
    lever_arm_b_m: &[f64; 3],
) -> (f64, f64, f64, Vec3) {
    let h_dt = b.t_s - a.t_s;
    let s = if h_dt > 0.0 { (t - a.t_s) / h_dt } else { 1.0 };
    let rates = |x: &TruthSample| {
        let r = earth.radii(x.lat_rad);
        Vec3::new(
            x.v_n_mps.x / (r.r_m_m + x.h_m),
            x.v_n_mps.y / ((r.r_n_m + x.h_m) * x.lat_rad.cos()),
            -x.v_n_mps.z,
        )
    };
    let (ra, rb) = (rates(a), rates(b));
    // cubic Hermite basis
    let (s2, s3) = (s * s, s * s * s);
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = s3 - 2.0 * s2 + s;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = s3 - s2;
    let dlon = crate::truth::lon_diff(b.lon_rad, a.lon_rad);
    let herm = |pa: f64, pb: f64, va: f64, vb: f64| {
        h00 * pa + h10 * h_dt * va + h01 * pb + h11 * h_dt * vb
    };
    let lat = herm(a.lat_rad, b.lat_rad, ra.x, rb.x);
    let lon = a.lon_rad + herm(0.0, dlon, ra.y, rb.y);
    let h = herm(a.h_m, b.h_m, ra.z, rb.z);
    let k = traj.kinematics(t, t);
    let l = Vec3::from(*lever_arm_b_m);
    if l == Vec3::zeros() {
        return (lat, wrap_pi(lon), h, k.v_n_mps);
    }
    let c = k.c_b_n;
    let rr = earth.radii(lat);
    let v = k.v_n_mps;
    let w_en = Vec3::new(
        v.y / (rr.r_n_m + h),
        -v.x / (rr.r_m_m + h),
        -v.y * lat.tan() / (rr.r_n_m + h),
    );
    let w_eb_b = k.omega_nb_b_rps + c.transpose() * w_en;
    let v_a = v + c * w_eb_b.cross(&l);
    // position through ECEF: r_a = r + C_n^e C_b^n l
    let r_e = earth.ecef_from_geodetic(lat, lon, h);
    let c_n_e = EarthModel::c_e_n(lat, lon).transpose();
    let r_a = r_e + c_n_e * (c * l);
    let (la, lo, ha) = earth.geodetic_from_ecef(&r_a);
    (la, wrap_pi(lo), ha, v_a)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_key() {
        GnssConfig::default().validate().unwrap();
        let cases = [
            (
                "rate_hz",
                GnssConfig {
                    rate_hz: 25.0,
                    ..Default::default()
                },
            ),
            (
                "sigma_pos_ned_m",
                GnssConfig {
                    sigma_pos_ned_m: [1.0, 0.0, 1.0],
                    ..Default::default()
                },
            ),
            (
                "dropout_prob",
                GnssConfig {
                    dropout_prob: f64::NAN,
                    ..Default::default()
                },
            ),
            (
                "outages_s",
                GnssConfig {
                    outages_s: vec![[10.0, 5.0]],
                    ..Default::default()
                },
            ),
            (
                "gm_tau_s",
                GnssConfig {
                    gm_sigma_ned_m: [1.0; 3],
                    gm_tau_s: 0.0,
                    ..Default::default()
                },
            ),
            (
                "latency_s",
                GnssConfig {
                    latency_s: -0.1,
                    ..Default::default()
                },
            ),
        ];
        for (key, c) in cases {
            assert!(c.validate().unwrap_err().to_string().contains(key), "{key}");
        }
    }
}
