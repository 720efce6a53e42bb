//! The aiding sensors of one run, simulated from the exact truth: feed consecutive truth
//! samples, receive the measurements whose time of validity lies between them.
//!
//! * Epochs `t_j = j / rate_hz` (j ≥ 1, `t_j ≤` end of the record), anywhere between IMU
//!   samples; the truth at `t_j` as for the GNSS simulator ([`crate::sensors::gnss`]):
//!   position by cubic Hermite interpolation between the samples around `t_j`
//!   ([`crate::sensors::gnss::exact_antenna`]), velocity, attitude and `ω_nb^b` from the
//!   trajectory's exact kinematics, `ω_ib^b = ω_nb^b + C_n^b (ω_ie^n + ω_en^n)`.
//! * Each measurement is the filter's own forward model (`sdins_core::aiding::sensors`)
//!   evaluated at the truth and the true sensor parameters, plus white noise: the models
//!   agree with the simulation by construction, and the Monte Carlo tests check that
//!   the filter's covariance agrees with the errors it makes.
//! * The odometer's non-holonomic rows: the trajectory moves without sideslip, so the
//!   lateral and vertical velocity at the axle is zero in the truth; the constraint's σ
//!   models a white violation, which the simulator draws into the measured values
//!   (`nhc_v_mps`) so that the model holds.
//! * Sensor parameters: the barometer bias is a first-order Gauss–Markov process drawn
//!   from its steady state and advanced exactly between consecutive instants (IMU
//!   samples and measurement epochs: `b ← e^{−Δ/τ} b + σ√(1 − e^{−2Δ/τ}) w`); the odometer
//!   scale factor and the magnetometer hard iron are random constants of the run.
//! * Random numbers: per sensor one ChaCha20 stream per (seed, run, channel), stream
//!   numbers `2⁶³ + 2⁶² + 16·run + channel`: disjoint from the IMU (`6·run + channel`)
//!   and GNSS (`2⁶³ + 16·run + channel`) streams; every epoch draws the same count
//!   whatever happens to it (outages too). Channels: sensor i's noise i (barometer 0,
//!   odometer 1, magnetometer 2, dual antenna 3, body velocity 4); the run's parameters
//!   8 + i (barometer bias path 8, odometer scale factor 9, hard iron 10).

use super::config::AidingConfig;
use crate::sensors::gnss::exact_antenna;
use crate::truth::trajectory::Trajectory;
use crate::truth::TruthSample;
use rand::SeedableRng;
use rand_chacha::ChaCha20Rng;
use rand_distr::{Distribution, StandardNormal};
use sdins_core::aiding::sensors::{
    baseline_az_el, mag_field_ned_ut, vehicle_velocity, AidingMeas, Baro, BodyVelocity,
    DualAntenna, Magnetometer, Odometer,
};
use sdins_core::earth::EarthModel;
use sdins_core::math::{c_b_n_from_euler, Euler, Mat3, Vec3};

const DEG: f64 = std::f64::consts::PI / 180.0;

/// The true sensor parameters at an instant (the truth of the filter's sensor blocks).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SensorTruth {
    /// barometer bias \[m\]
    pub baro_bias_m: f64,
    /// odometer scale-factor error \[1\]
    pub odometer_scale: f64,
    /// magnetometer hard iron, body \[µT\]
    pub hard_iron_ut: Vec3,
}

fn rng(seed: u64, run: u64, channel: u64) -> ChaCha20Rng {
    let mut r = ChaCha20Rng::seed_from_u64(seed);
    r.set_stream((3u64 << 62) | run.wrapping_mul(16).wrapping_add(channel));
    r
}

fn normal(r: &mut ChaCha20Rng) -> f64 {
    StandardNormal.sample(r)
}

/// The rotation body → vehicle from the mounting angles (roll, pitch, yaw of the body
/// relative to the vehicle frame) \[deg\].
pub fn c_b_v_from_mount_deg(m: &[f64; 3]) -> Mat3 {
    c_b_n_from_euler(&Euler::new(m[0] * DEG, m[1] * DEG, m[2] * DEG))
}

/// One sensor's epoch clock.
#[derive(Clone, Debug)]
struct Clock {
    rate_hz: f64,
    next_j: u64,
}

impl Clock {
    fn new(rate_hz: f64) -> Self {
        Self { rate_hz, next_j: 1 }
    }
    /// The next epoch in `(a, b]`, if any (advancing).
    fn next_in(&mut self, a: f64, b: f64) -> Option<f64> {
        loop {
            let t = self.next_j as f64 / self.rate_hz;
            if t > b + 1e-9 / self.rate_hz {
                return None;
            }
            self.next_j += 1;
            if t > a {
                return Some(t);
            }
        }
    }
}

/// The exact truth at one instant, as the measurement models need it.
struct Point {
    h_m: f64,
    v_n_mps: Vec3,
    c_b_n: Mat3,
    omega_ib_b: Vec3,
    omega_ie_n: Vec3,
}

/// The aiding-sensor simulator of one run.
#[derive(Clone, Debug)]
pub struct AidingSimulator {
    /// shared, so that a step borrows it without cloning its outage lists per sample
    cfg: std::sync::Arc<AidingConfig>,
    earth: EarthModel,
    clocks: [Clock; 5],
    rngs: [ChaCha20Rng; 5],
    /// the barometer bias's stream (separate: it draws at every instant)
    bias_rng: ChaCha20Rng,
    truth: SensorTruth,
    t_bias_s: f64,
    mag_n_ut: Vec3,
    c_odo: Mat3,
    c_dvl: Mat3,
}

impl AidingSimulator {
    /// The simulator of run `run` (the configuration is assumed validated).
    pub fn new(cfg: &AidingConfig, earth: EarthModel, run: u64) -> Self {
        let seeds = [
            cfg.baro.as_ref().map_or(0, |c| c.seed),
            cfg.odometer.as_ref().map_or(0, |c| c.seed),
            cfg.magnetometer.as_ref().map_or(0, |c| c.seed),
            cfg.dual_antenna.as_ref().map_or(0, |c| c.seed),
            cfg.body_velocity.as_ref().map_or(0, |c| c.seed),
        ];
        let rate = [
            cfg.baro.as_ref().map_or(1.0, |c| c.rate_hz),
            cfg.odometer.as_ref().map_or(1.0, |c| c.rate_hz),
            cfg.magnetometer.as_ref().map_or(1.0, |c| c.rate_hz),
            cfg.dual_antenna.as_ref().map_or(1.0, |c| c.rate_hz),
            cfg.body_velocity.as_ref().map_or(1.0, |c| c.rate_hz),
        ];
        let rngs: [ChaCha20Rng; 5] = core::array::from_fn(|i| rng(seeds[i], run, i as u64));
        // the run's parameters: channel 8 + i of sensor i's seed (distinct even when the
        // seeds are equal)
        let mut bias_rng = rng(seeds[0], run, 8);
        let mut truth = SensorTruth::default();
        if let Some(c) = &cfg.baro {
            truth.baro_bias_m = c.bias_sigma_m * normal(&mut bias_rng);
        }
        if let Some(c) = &cfg.odometer {
            let mut r = rng(c.seed, run, 9);
            truth.odometer_scale = c.scale_sigma * normal(&mut r);
        }
        if let Some(c) = &cfg.magnetometer {
            let mut r = rng(c.seed, run, 10);
            truth.hard_iron_ut = Vec3::from_fn(|_, _| c.hard_iron_sigma_ut * normal(&mut r));
        }
        let mag_n_ut = cfg.magnetometer.as_ref().map_or(Vec3::zeros(), |c| {
            mag_field_ned_ut(
                c.declination_deg * DEG,
                c.inclination_deg * DEG,
                c.intensity_ut,
            )
        });
        Self {
            cfg: std::sync::Arc::new(cfg.clone()),
            earth,
            clocks: core::array::from_fn(|i| Clock::new(rate[i])),
            rngs,
            bias_rng,
            truth,
            t_bias_s: 0.0,
            mag_n_ut,
            c_odo: cfg
                .odometer
                .as_ref()
                .map_or(Mat3::identity(), |c| c_b_v_from_mount_deg(&c.mount_deg)),
            c_dvl: cfg
                .body_velocity
                .as_ref()
                .map_or(Mat3::identity(), |c| c_b_v_from_mount_deg(&c.mount_deg)),
        }
    }

    /// The true sensor parameters now (after the last [`AidingSimulator::step`]).
    pub fn truth(&self) -> SensorTruth {
        self.truth
    }

    /// Advance the barometer bias to `t_s` (exact Gauss–Markov transition).
    fn advance_bias(&mut self, t_s: f64) {
        if let Some(c) = &self.cfg.baro {
            let dt = t_s - self.t_bias_s;
            if dt > 0.0 {
                let e = (-dt / c.bias_tau_s).exp();
                let s = c.bias_sigma_m * (1.0 - e * e).sqrt();
                self.truth.baro_bias_m =
                    e * self.truth.baro_bias_m + s * normal(&mut self.bias_rng);
                self.t_bias_s = t_s;
            }
        }
    }

    fn point(&self, traj: &Trajectory, a: &TruthSample, b: &TruthSample, t: f64) -> Point {
        let (lat, _, h, _) = exact_antenna(&self.earth, traj, a, b, t, &[0.0; 3]);
        let k = traj.kinematics(t, t);
        let omega_ie_n = self.earth.omega_ie_n(lat);
        let omega_en_n = self.earth.omega_en_n(lat, h, &k.v_n_mps);
        let omega_ib_b = k.omega_nb_b_rps + k.c_b_n.transpose() * (omega_ie_n + omega_en_n);
        Point {
            h_m: h,
            v_n_mps: k.v_n_mps,
            c_b_n: k.c_b_n,
            omega_ib_b,
            omega_ie_n,
        }
    }

    /// Measurements with time of validity in `(a.t_s, b.t_s]`, in time order per sensor
    /// (appended to `out`); the parameters advance to `b.t_s`.
    pub fn step(
        &mut self,
        traj: &Trajectory,
        a: &TruthSample,
        b: &TruthSample,
        out: &mut Vec<AidingMeas>,
    ) {
        let cfg = std::sync::Arc::clone(&self.cfg);
        if let Some(c) = cfg.baro.as_ref() {
            while let Some(t) = self.clocks[0].next_in(a.t_s, b.t_s) {
                self.advance_bias(t);
                let w = normal(&mut self.rngs[0]);
                if c.in_outage(t) {
                    continue;
                }
                let p = self.point(traj, a, b, t);
                out.push(AidingMeas::Baro(Baro {
                    t_s: t,
                    h_baro_m: p.h_m + self.truth.baro_bias_m + c.sigma_m * w,
                    sigma_m: c.sigma_m,
                }));
            }
            self.advance_bias(b.t_s);
        }
        if let Some(c) = cfg.odometer.as_ref() {
            while let Some(t) = self.clocks[1].next_in(a.t_s, b.t_s) {
                let w = normal(&mut self.rngs[1]);
                let w_nhc = [normal(&mut self.rngs[1]), normal(&mut self.rngs[1])];
                if c.in_outage(t) {
                    continue;
                }
                let p = self.point(traj, a, b, t);
                let l = Vec3::from(c.lever_arm_b_m);
                let v_v = vehicle_velocity(
                    &p.c_b_n,
                    &p.v_n_mps,
                    &p.omega_ib_b,
                    &p.omega_ie_n,
                    &self.c_odo,
                    &l,
                );
                let mut speed = (1.0 + self.truth.odometer_scale) * v_v.x + c.sigma_mps * w;
                if c.resolution_mps > 0.0 {
                    speed = (speed / c.resolution_mps).round() * c.resolution_mps;
                }
                out.push(AidingMeas::Odometer(Odometer {
                    t_s: t,
                    speed_mps: speed,
                    sigma_mps: c.speed_var().sqrt(),
                    c_b_v: self.c_odo,
                    lever_arm_b_m: l,
                    nhc_sigma_mps: (c.nhc_sigma_mps > 0.0).then_some(c.nhc_sigma_mps),
                    // the violation the constraint's σ models, drawn
                    nhc_v_mps: [c.nhc_sigma_mps * w_nhc[0], c.nhc_sigma_mps * w_nhc[1]],
                }));
            }
        }
        if let Some(c) = cfg.magnetometer.as_ref() {
            while let Some(t) = self.clocks[2].next_in(a.t_s, b.t_s) {
                let w = Vec3::from_fn(|_, _| normal(&mut self.rngs[2]));
                if c.in_outage(t) {
                    continue;
                }
                let p = self.point(traj, a, b, t);
                let m_b = p.c_b_n.transpose() * self.mag_n_ut + self.truth.hard_iron_ut;
                out.push(AidingMeas::Magnetometer(Magnetometer {
                    t_s: t,
                    m_b_ut: m_b + c.sigma_ut * w,
                    m_n_ut: self.mag_n_ut,
                    sigma_ut: c.sigma_ut,
                }));
            }
        }
        if let Some(c) = cfg.dual_antenna.as_ref() {
            while let Some(t) = self.clocks[3].next_in(a.t_s, b.t_s) {
                let w = [normal(&mut self.rngs[3]), normal(&mut self.rngs[3])];
                if c.in_outage(t) {
                    continue;
                }
                let p = self.point(traj, a, b, t);
                let bl = Vec3::from(c.baseline_b_m);
                let (az, el) = baseline_az_el(&p.c_b_n, &bl);
                let len = bl.norm();
                let s_el = c.sigma_rel_m / len;
                let s_az = s_el / el.cos();
                out.push(AidingMeas::DualAntenna(DualAntenna {
                    t_s: t,
                    az_rad: sdins_core::nav::wrap_pi(az + s_az * w[0]),
                    el_rad: el + s_el * w[1],
                    baseline_b_m: bl,
                    sigma_rel_m: c.sigma_rel_m,
                    heading_only: c.heading_only,
                }));
            }
        }
        if let Some(c) = cfg.body_velocity.as_ref() {
            while let Some(t) = self.clocks[4].next_in(a.t_s, b.t_s) {
                let w = Vec3::from_fn(|_, _| normal(&mut self.rngs[4]));
                if c.in_outage(t) {
                    continue;
                }
                let p = self.point(traj, a, b, t);
                let l = Vec3::from(c.lever_arm_b_m);
                let v_v = vehicle_velocity(
                    &p.c_b_n,
                    &p.v_n_mps,
                    &p.omega_ib_b,
                    &p.omega_ie_n,
                    &self.c_dvl,
                    &l,
                );
                let s = Vec3::from(c.sigma_mps);
                out.push(AidingMeas::BodyVelocity(BodyVelocity {
                    t_s: t,
                    v_v_mps: v_v + s.component_mul(&w),
                    cov_mps2: Mat3::from_diagonal(&s.component_mul(&s)),
                    c_b_v: self.c_dvl,
                    lever_arm_b_m: l,
                }));
            }
        }
    }
}
