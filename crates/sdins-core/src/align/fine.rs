//! 12-state stationary Kalman fine alignment (docs/theory/alignment.md §"Fine alignment";
//! docs/theory/alignment.md §"Multi-heading alignment" Algorithm A with body-frame bias states).
//!
//! The filter runs its own stationary attitude/velocity propagation at the IMU rate
//! (docs/theory/alignment.md §"Fine alignment", alignment mode; position fixed), per
//! sample `j` of period δt:
//!
//! ```text
//! Δθ' = Δθ_j − b̂_g δt,   Δv' = Δv_j − b̂_a δt
//! v̂  ← v̂ + Ĉ (Δv' + ½ Δθ' × Δv') − ½ (ω_ie^n δt) × (Ĉ Δv') + (g^n − 2 ω_ie^n × v̂) δt
//! Ĉ  ← exp(−[ω_ie^n δt ×]) Ĉ exp([Δθ' ×])
//! ```
//!
//! The `½ Δθ' × Δv'` term (body-rotation compensation) keeps the velocity exact to first
//! order while the IMU turns (multi-heading rotations at 10 °/s, docs/theory/alignment.md
//! §"Multi-heading alignment": a first-order increment update is exact enough); the
//! `−½ (ω_ie^n δt) × Ĉ Δv'` term is the matching navigation-frame rotation over the sample. At rest
//! the two cancel exactly (without the second one the first leaves a spurious `½ ω_ie^n × f^n δt` ≈
//! 0.3 μg east at 100 Hz). Every `kf_dt_s` seconds the filter predicts with `F(Ĉ)` (re-evaluated
//! each cycle, docs/theory/alignment.md §"Fine alignment"), updates with the zero-velocity
//! measurement `z = v̂ − 0` (docs/theory/alignment.md §"Fine alignment") and, in
//! closed loop, resets:
//!
//! ```text
//! v̂ ← v̂ − δv̂,   Ĉ ← exp(−[φ̂×]) Ĉ,
//! b̂_a ← b̂_a + Ĉᵀ δâ,  b̂_g ← b̂_g + Ĉᵀ ε̂   (NED states; body states: add directly),  x̂ ← 0
//! ```
//!
//! In feed-forward mode (used by Algorithm B, docs/theory/alignment.md §"Multi-heading alignment")
//! nothing is reset and the INS runs open loop; [`FineAlign::restart`] re-initialises the filter at
//! each position.

use super::kf::Kf;
use super::model::{discretize, f_matrix, h_zupt, q_continuous, BiasFrame, Mat12, Vec12};
use super::Site;
use crate::coning::Increment;
use crate::math::{dcm_from_rotvec, orthonormalize, Mat3, Vec3};
use nalgebra::SMatrix;

/// Fine-alignment settings (docs/theory/alignment.md §"Fine alignment").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FineConfig {
    /// latitude, gravity, earth rate
    pub site: Site,
    /// frame of the bias states
    pub bias_frame: BiasFrame,
    /// Kalman-filter interval Δt \[s\] (spec: 0.1–1 s; reference 1 s)
    pub kf_dt_s: f64,
    /// zero-velocity measurement σ_z \[m/s\] (docs/theory/alignment.md §"Fine alignment": 1 mm/s on
    /// a benign pad)
    pub sigma_z_mps: f64,
    /// VRW \[m/s/√s\]
    pub vrw: f64,
    /// ARW \[rad/√s\]
    pub arw: f64,
    /// accelerometer-bias random-walk PSD q_ba \[(m/s²)²/s\] (0 for constant biases)
    pub q_ba: f64,
    /// gyro-bias random-walk PSD q_bg \[(rad/s)²/s\]
    pub q_bg: f64,
    /// initial covariance P0 (bias blocks in the frame of `bias_frame`)
    pub p0: Mat12,
    /// closed-loop reset after each update (docs/theory/alignment.md §"Fine alignment"); `false` =
    /// feed-forward
    pub closed_loop: bool,
}

/// The fine-alignment filter with its stationary INS.
#[derive(Clone, Copy, Debug)]
pub struct FineAlign {
    cfg: FineConfig,
    qc: Mat12,
    c_b_n: Mat3,
    v_n: Vec3,
    ba_b: Vec3,
    bg_b: Vec3,
    kf: Kf<12>,
    t_s: f64,
    t_since_kf: f64,
    updates: u64,
}

impl FineAlign {
    /// Start from the coarse attitude `c_b_n0`, zero velocity and zero bias estimates.
    pub fn new(cfg: FineConfig, c_b_n0: &Mat3) -> Self {
        Self {
            qc: q_continuous(cfg.vrw, cfg.arw, cfg.q_ba, cfg.q_bg),
            cfg,
            c_b_n: *c_b_n0,
            v_n: Vec3::zeros(),
            ba_b: Vec3::zeros(),
            bg_b: Vec3::zeros(),
            kf: Kf::new(cfg.p0),
            t_s: 0.0,
            t_since_kf: 0.0,
            updates: 0,
        }
    }

    /// Process one IMU sample of period `dt_s`. Returns `true` if a Kalman cycle
    /// (predict, update, reset) ran at the end of this sample. The measurement is the
    /// zero-velocity update `z = v̂ − 0` (docs/theory/alignment.md §"Fine alignment"); see
    /// [`Self::step_with_velocity`].
    pub fn step(&mut self, inc: &Increment, dt_s: f64) -> bool {
        self.step_with_velocity(inc, dt_s, &Vec3::zeros())
    }

    /// As [`Self::step`], with a measured reference velocity `ṽ^n` \[m/s\] (NED) used if a
    /// Kalman cycle runs at the end of this sample: `z = v̂ − ṽ = H x + ν` with
    /// `ν = −(ṽ − v_true)` assumed `N(0, σ_z² I3)` (docs/theory/alignment.md §"Fine alignment").
    /// For a vehicle at rest `ṽ = 0 + ν`; passing `ṽ = 0` is the plain zero-velocity update, whose
    /// actual noise is whatever the true (sway, vibration) velocity is. A simulation that wants a
    /// statistically matched filter passes `ṽ ~ N(0, σ_z² I3)` drawn per KF cycle.
    pub fn step_with_velocity(&mut self, inc: &Increment, dt_s: f64, v_meas_n: &Vec3) -> bool {
        let w = self.cfg.site.omega_ie_n();
        let dth = inc.dtheta_b_rad - self.bg_b * dt_s;
        let dv = inc.dv_b_mps - self.ba_b * dt_s;
        let dv_c = self.c_b_n * dv;
        let dv_n = dv_c + self.c_b_n * (0.5 * dth.cross(&dv)) - 0.5 * (w * dt_s).cross(&dv_c);
        self.v_n += dv_n + (self.cfg.site.g_n() - 2.0 * w.cross(&self.v_n)) * dt_s;
        self.c_b_n = dcm_from_rotvec(&(-w * dt_s)) * self.c_b_n * dcm_from_rotvec(&dth);
        self.t_s += dt_s;
        self.t_since_kf += dt_s;
        if self.t_since_kf + 1e-9 * self.cfg.kf_dt_s >= self.cfg.kf_dt_s {
            self.kf_cycle(v_meas_n);
            true
        } else {
            false
        }
    }

    fn kf_cycle(&mut self, v_meas_n: &Vec3) {
        let dt = self.t_since_kf;
        self.t_since_kf = 0.0;
        let f = f_matrix(&self.cfg.site, self.cfg.bias_frame, &self.c_b_n);
        let (phi, qd) = discretize(&f, &self.qc, dt);
        self.kf.predict(&phi, &qd);
        let r = SMatrix::<f64, 3, 3>::identity() * (self.cfg.sigma_z_mps * self.cfg.sigma_z_mps);
        // z = v̂ − ṽ (docs/theory/alignment.md §"Fine alignment"; ṽ = 0 for the plain zero-velocity
        // update)
        let _ = self.kf.update(&h_zupt(), &(self.v_n - v_meas_n), &r);
        self.updates += 1;
        if self.cfg.closed_loop {
            self.reset();
        }
    }

    /// Closed-loop reset of docs/theory/alignment.md §"Fine alignment".
    fn reset(&mut self) {
        let x = self.kf.x;
        let dv = x.fixed_rows::<3>(0).into_owned();
        let phi = x.fixed_rows::<3>(3).into_owned();
        let da = x.fixed_rows::<3>(6).into_owned();
        let de = x.fixed_rows::<3>(9).into_owned();
        self.v_n -= dv;
        let (da_b, de_b) = match self.cfg.bias_frame {
            BiasFrame::Ned => (self.c_b_n.transpose() * da, self.c_b_n.transpose() * de),
            BiasFrame::Body => (da, de),
        };
        self.c_b_n = orthonormalize(&(dcm_from_rotvec(&(-phi)) * self.c_b_n));
        self.ba_b += da_b;
        self.bg_b += de_b;
        self.kf.x = Vec12::zeros();
    }

    /// Restart the filter in feed-forward mode (Algorithm B, docs/theory/alignment.md
    /// §"Multi-heading alignment") at a new position: `x̂ = [v̂, 0]`, `P = p0` with the velocity
    /// block set to `σ_z² I3` (the INS velocity error is then known to the measurement accuracy).
    pub fn restart(&mut self, p0: &Mat12) {
        let mut p = *p0;
        let mut x = Vec12::zeros();
        for i in 0..3 {
            for j in 0..12 {
                p[(i, j)] = 0.0;
                p[(j, i)] = 0.0;
            }
            p[(i, i)] = self.cfg.sigma_z_mps * self.cfg.sigma_z_mps;
            x[i] = self.v_n[i];
        }
        self.kf = Kf { x, p };
    }

    /// Current attitude estimate `exp(−[φ̂×]) Ĉ` (equals Ĉ in closed loop).
    pub fn c_b_n(&self) -> Mat3 {
        let phi = self.kf.x.fixed_rows::<3>(3).into_owned();
        if phi == Vec3::zeros() {
            self.c_b_n
        } else {
            dcm_from_rotvec(&(-phi)) * self.c_b_n
        }
    }
    /// The INS attitude Ĉ without the pending (feed-forward) correction.
    pub fn c_b_n_ins(&self) -> Mat3 {
        self.c_b_n
    }
    /// INS velocity v̂ \[m/s\] (NED).
    pub fn v_n(&self) -> Vec3 {
        self.v_n
    }
    fn bias_b(&self, k: usize) -> Vec3 {
        let x = self.kf.x.fixed_rows::<3>(k).into_owned();
        match self.cfg.bias_frame {
            BiasFrame::Ned => self.c_b_n.transpose() * x,
            BiasFrame::Body => x,
        }
    }
    /// Estimated accelerometer bias in body axes \[m/s²\] (applied + pending).
    pub fn accel_bias_b(&self) -> Vec3 {
        self.ba_b + self.bias_b(6)
    }
    /// Estimated gyro bias in body axes \[rad/s\] (applied + pending).
    pub fn gyro_bias_b(&self) -> Vec3 {
        self.bg_b + self.bias_b(9)
    }
    /// The filter (state and covariance).
    pub fn kf(&self) -> &Kf<12> {
        &self.kf
    }
    /// Settings.
    pub fn config(&self) -> &FineConfig {
        &self.cfg
    }
    /// 1σ of the attitude error φ (NED) \[rad\].
    pub fn attitude_sigma(&self) -> Vec3 {
        self.kf.sigma().fixed_rows::<3>(3).into_owned()
    }
    /// 1σ of the accelerometer (`k = 6`) or gyro (`k = 9`) bias, in body axes.
    fn bias_sigma_b(&self, k: usize) -> Vec3 {
        let p = self.kf.p.fixed_view::<3, 3>(k, k).into_owned();
        let pb = match self.cfg.bias_frame {
            BiasFrame::Ned => self.c_b_n.transpose() * p * self.c_b_n,
            BiasFrame::Body => p,
        };
        Vec3::from_fn(|i, _| libm::sqrt(pb[(i, i)].max(0.0)))
    }
    /// 1σ of the accelerometer bias estimate, body axes \[m/s²\].
    pub fn accel_bias_sigma_b(&self) -> Vec3 {
        self.bias_sigma_b(6)
    }
    /// 1σ of the gyro bias estimate, body axes \[rad/s\].
    pub fn gyro_bias_sigma_b(&self) -> Vec3 {
        self.bias_sigma_b(9)
    }
    /// Time since start \[s\].
    pub fn time_s(&self) -> f64 {
        self.t_s
    }
    /// Number of Kalman updates so far.
    pub fn updates(&self) -> u64 {
        self.updates
    }
}

/// Reference settings of docs/theory/alignment.md §"Fine alignment"; docs/validation.md
/// §"fine alignment" T4 with NED bias states, closed loop, KF at 1 Hz, σ_z = 1 mm/s and P0 of
/// docs/theory/alignment.md §"Fine alignment"; `vrw` \[m/s/√s\], `arw` \[rad/√s\].
pub fn reference_config(site: Site, vrw: f64, arw: f64) -> FineConfig {
    FineConfig {
        site,
        bias_frame: BiasFrame::Ned,
        kf_dt_s: 1.0,
        sigma_z_mps: 1e-3,
        vrw,
        arw,
        q_ba: 0.0,
        q_bg: 0.0,
        p0: super::model::p0_reference(),
        closed_loop: true,
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    fn site() -> Site {
        Site {
            lat_rad: 37.5_f64.to_radians(),
            g_mps2: 9.799490523606893,
            omega_ie_rps: 7.292115e-5,
        }
    }

    /// `step` is `step_with_velocity` with ṽ = 0, and a reference velocity enters the
    /// update only through the innovation `z = v̂ − ṽ` (docs/theory/alignment.md
    /// §"Fine alignment"): feeding ṽ equal to an offset that is also added to the INS velocity
    /// leaves the estimate unchanged.
    #[test]
    fn velocity_reference_enters_through_the_innovation() {
        let s = site();
        let cfg = reference_config(s, 0.0, 0.0);
        let c0 = dcm_from_rotvec(&Vec3::new(1e-3, -1e-3, 5e-3));
        let dt = 0.01;
        // truth: C_b^n = I at rest; the filter starts from c0 (1/−1/5 mrad error)
        let inc = Increment::new(s.omega_ie_n() * dt, -s.g_n() * dt);
        let (mut a, mut b) = (FineAlign::new(cfg, &c0), FineAlign::new(cfg, &c0));
        for _ in 0..300 {
            assert_eq!(
                a.step(&inc, dt),
                b.step_with_velocity(&inc, dt, &Vec3::zeros())
            );
        }
        assert_eq!(a.kf().x, b.kf().x);
        assert_eq!(a.kf().p, b.kf().p);
        assert_eq!(a.c_b_n(), b.c_b_n());
        // feed-forward, first KF cycle from x̂ = 0: x̂ = K (v̂ − ṽ), so ṽ = v̂ gives x̂ = 0,
        // ṽ = 0 does not, and P does not depend on ṽ
        let ff = FineConfig {
            closed_loop: false,
            ..cfg
        };
        let (mut d, mut e) = (FineAlign::new(ff, &c0), FineAlign::new(ff, &c0));
        for _ in 0..99 {
            assert!(!d.step(&inc, dt) && !e.step(&inc, dt));
        }
        let mut probe = d;
        assert!(probe.step(&inc, dt));
        assert!(d.step_with_velocity(&inc, dt, &probe.v_n()));
        assert!(e.step(&inc, dt));
        assert!(e.v_n().norm() > 1e-4);
        assert_eq!(d.kf().x, Vec12::zeros());
        assert!(e.kf().x.norm() > 0.0);
        assert_eq!(d.kf().p, e.kf().p);
    }
}
