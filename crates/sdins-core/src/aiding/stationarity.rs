//! Stationarity (zero-velocity) detection from the IMU alone: a sliding-window
//! generalised-likelihood-ratio test in the form of the SHOE detector, with the gyro term
//! referred to the expected rate at rest and a threshold derived from the noise model
//! (docs/theory/aiding-sensors.md §"Stationarity detection").
//!
//! Sources: I. Skog, P. Händel, J.-O. Nilsson and J. Rantakokko, "Zero-velocity detection —
//! an algorithm evaluation", IEEE Trans. Biomed. Eng. 57(11):2657–2666, 2010, §III (the
//! stance-hypothesis optimal detector, "SHOE", derived as the GLRT for a window of samples
//! with known noise variances, unknown gravity direction and known gravity magnitude);
//! P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
//! Systems*, 2nd ed., §15.3 (zero velocity and zero angular-rate updates and the
//! detection of the stationary condition that they need).
//!
//! ## Statistic
//!
//! One sample `k` is the increment pair over δt (body FRD) turned into mean rates,
//! `f̃_k = Δv_k/δt − b̂_a` \[m/s²\], `ω̃_k = Δθ_k/δt` \[rad/s\]. Over the last W samples, with
//! `f̄`, `ω̄` the window means and `ω_e = b̂_g + Ĉ_n^b ω_ie^n` the gyro output expected at
//! rest (estimated bias plus earth rate, both set by the caller and updatable):
//!
//! ```text
//! W·T = Σ_k ‖f̃_k − g f̄/‖f̄‖‖²/σ_a² + Σ_k ‖ω̃_k − ω_e‖²/σ_g²
//!     = [A + W(‖f̄‖ − g)²]/σ_a² + [G + W‖ω̄ − ω_e‖²]/σ_g²,
//! A = Σ_k ‖f̃_k − f̄‖²,   G = Σ_k ‖ω̃_k − ω̄‖².
//! ```
//!
//! The first line is Skog et al.'s SHOE statistic with `ω̃_k` replaced by `ω̃_k − ω_e`
//! (their foot-mounted MEMS case neglects the earth rate and the bias; a tactical gyro does
//! not allow it: with ARW 0.003 °/√h at 200 Hz the per-sample σ_g is 2.5 °/h, so a 10 °/h
//! bias and the 15 °/h earth rate are 4–6 σ_g per sample and 55–85 times the window mean's
//! σ_g/√W after W = 200 samples); the second line is the exact split used here, computed from
//! running sums that are recomputed from the ring buffer every W samples (O(1) per
//! sample, no drift). Stationary is declared when `T < γ`.
//!
//! ## Threshold
//!
//! At rest with white Gaussian noise of per-axis σ_a, σ_g per sample and residual biases
//! (the errors of b̂_a, b̂_g, of g and of the earth rate through Ĉ_n^b) of per-axis σ_ba,
//! σ_bg, the four parts are independent and
//!
//! ```text
//! W·T ~ χ²(6W − 6) + (1 + κ_g) χ²(3) + (1 + κ_a) χ²(1),
//! κ_g = W σ_bg²/σ_g²,  κ_a = W σ_ba²/σ_a²
//! ```
//!
//! (the scatter terms A, G lose one degree of freedom per axis to the mean; the residual
//! bias is constant over the window and adds to the window mean, whose variance per axis is
//! σ²/W + σ_b²; the magnitude term is, to first order in σ/(g√W), the radial component of the
//! mean error). Without residual biases this is χ²(6W − 2). The threshold is the upper
//! α-quantile of this law, `γ = q_{1−α}/W`, computed exactly ([`chi2::WeightedChiSquare`]).
//! α is the probability that a window at rest is declared moving, averaged over the
//! residual-bias population.
//!
//! ## Prediction in motion
//!
//! [`StationarityDetector::probability_declared_moving`] evaluates the same law with white
//! vibration of RMS `a_v` (per axis, specific force) and `ω_v` (angular rate) and with steady
//! offsets (a sustained turn or acceleration): the scatter weights become `1 + a_v²/σ_a²`
//! and `1 + ω_v²/σ_g²`, and the mean terms become non-central. The accelerometer part grows by
//! about `3W a_v²/σ_a²` (W a_v²/σ_a² per axis). No IMU-only test can tell a standstill from
//! perfectly smooth, straight, constant-velocity motion: there both hypotheses give the same
//! data.
//!
//! ## Use
//!
//! ```
//! use sdins_core::aiding::stationarity::{IntervalTracker, NoiseModel, StationarityDetector};
//! use sdins_core::coning::Increment;
//! use sdins_core::earth::EarthModel;
//! use sdins_core::math::{Mat3, Vec3};
//!
//! let (dt, d2r) = (0.005, core::f64::consts::PI / 180.0);
//! let earth = EarthModel::WGS84;
//! let lat = 45.0 * d2r;
//! let g = earth.gravity(lat, 0.0);
//! // tactical IMU: VRW 0.03 m/s/√h, ARW 0.003 °/√h; residual biases 100 μg, 0.1 °/h
//! let noise =
//!     NoiseModel::from_random_walks(0.03 / 60.0, 0.003 * d2r / 60.0, dt, 1e-4 * g, 0.1 * d2r / 3600.0)?;
//! let mut det = StationarityDetector::<200>::from_noise_model(noise, dt, g, 1e-3)?;
//! let c_b_n = Mat3::identity(); // level, heading north
//! det.set_attitude(&c_b_n, &earth.omega_ie_n(lat))?; // update as the attitude changes
//! det.set_gyro_bias_rps(&Vec3::zeros())?; // b̂_g from the navigation filter
//! let mut tracker = IntervalTracker::new(200, 200); // intervals of at least 1 s
//! // 2 s at rest (error-free increments here)
//! let rest = Increment::new(
//!     c_b_n.transpose() * earth.omega_ie_n(lat) * dt,
//!     -(c_b_n.transpose() * earth.gravity_n(lat, 0.0)) * dt,
//! );
//! let mut stationary = 0;
//! for _ in 0..400 {
//!     if let Some(report) = det.push(&rest)? {
//!         stationary += usize::from(report.stationary);
//!         tracker.push(&report);
//!     }
//! }
//! assert_eq!(stationary, 201);
//! let interval = tracker.finish().expect("one interval");
//! assert_eq!((interval.first_sample, interval.last_sample), (0, 399));
//! # Ok::<(), sdins_core::aiding::stationarity::StationarityError>(())
//! ```

pub mod chi2;

use crate::coning::Increment;
use crate::math::{Mat3, Vec3};
use chi2::{Chi2Error, ChiSquareTerm, WeightedChiSquare};

/// Why a detector cannot be built or a sample cannot be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum StationarityError {
    /// A noise σ, δt, g, threshold or false-alarm rate is not finite or out of range
    /// (σ in \[1e-30, 1e30\], α in \[1e-9, 0.5\], W ≥ 2).
    InvalidConfig,
    /// An input sample or vector is not finite, or a rate beyond 1e100 (the sample is not used).
    InvalidInput,
    /// `κ = W σ_b²/σ² > 1e3` ([`MAX_KAPPA`]): the residual bias, not the noise, would decide the test
    /// (estimate the bias first or shorten the window).
    ResidualBiasDominates,
    /// The χ² computation failed.
    Distribution(Chi2Error),
}

impl core::fmt::Display for StationarityError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            StationarityError::InvalidConfig => {
                f.write_str("stationarity detector: invalid noise model, δt, g, threshold or α")
            }
            StationarityError::InvalidInput => {
                f.write_str("stationarity detector: non-finite or out-of-range input")
            }
            StationarityError::ResidualBiasDominates => f.write_str(
                "stationarity detector: residual bias variance exceeds 1e3 × the window-mean noise variance",
            ),
            StationarityError::Distribution(e) => write!(f, "stationarity detector: {e}"),
        }
    }
}

impl From<Chi2Error> for StationarityError {
    fn from(e: Chi2Error) -> Self {
        StationarityError::Distribution(e)
    }
}

/// Per-sample white noise and residual-bias uncertainty of the IMU, per axis, at the
/// detector's input rate (isotropic: the same σ on the three axes, as in Skog et al.).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseModel {
    /// σ of the per-sample specific force `Δv/δt` \[m/s²\] (white: `VRW/√δt`)
    pub sigma_accel_mps2: f64,
    /// σ of the per-sample angular rate `Δθ/δt` \[rad/s\] (white: `ARW/√δt`)
    pub sigma_gyro_rps: f64,
    /// σ of the residual accelerometer bias (b_a − b̂_a), per axis, plus the error of the
    /// caller's g \[m/s²\]
    pub sigma_accel_bias_mps2: f64,
    /// σ of the residual gyro bias (b_g − b̂_g), per axis, plus the earth-rate error from the
    /// attitude error (`Ω·|δψ|`) \[rad/s\]
    pub sigma_gyro_bias_rps: f64,
}

impl NoiseModel {
    /// From the random-walk densities: `σ_a = VRW/√δt`, `σ_g = ARW/√δt` (a white rate noise
    /// of density N integrated over δt has σ = N√δt in the increment, N/√δt in the mean rate).
    pub fn from_random_walks(
        vrw_mps_per_sqrt_s: f64,
        arw_rad_per_sqrt_s: f64,
        dt_s: f64,
        sigma_accel_bias_mps2: f64,
        sigma_gyro_bias_rps: f64,
    ) -> Result<Self, StationarityError> {
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return Err(StationarityError::InvalidConfig);
        }
        let s = libm::sqrt(dt_s);
        let m = Self {
            sigma_accel_mps2: vrw_mps_per_sqrt_s / s,
            sigma_gyro_rps: arw_rad_per_sqrt_s / s,
            sigma_accel_bias_mps2,
            sigma_gyro_bias_rps,
        };
        m.check()?;
        Ok(m)
    }

    fn check(&self) -> Result<(), StationarityError> {
        let sigma_ok = |s: f64| (1e-30..=1e30).contains(&s);
        let bias_ok = |s: f64| s == 0.0 || sigma_ok(s);
        if sigma_ok(self.sigma_accel_mps2)
            && sigma_ok(self.sigma_gyro_rps)
            && bias_ok(self.sigma_accel_bias_mps2)
            && bias_ok(self.sigma_gyro_bias_rps)
        {
            Ok(())
        } else {
            Err(StationarityError::InvalidConfig)
        }
    }

    /// `(κ_a, κ_g) = (W σ_ba²/σ_a², W σ_bg²/σ_g²)`: residual-bias variance of the window mean
    /// in units of the white-noise variance of the window mean.
    pub fn kappas(&self, window: usize) -> (f64, f64) {
        let w = window as f64;
        let r = |b: f64, s: f64| w * (b / s) * (b / s);
        (
            r(self.sigma_accel_bias_mps2, self.sigma_accel_mps2),
            r(self.sigma_gyro_bias_rps, self.sigma_gyro_rps),
        )
    }
}

/// What the vehicle does during a window, for [`StationarityDetector::probability_declared_moving`].
/// All zero is rest.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MotionModel {
    /// RMS per axis of zero-mean specific-force vibration, white at the sample rate \[m/s²\]
    pub vibration_accel_mps2: f64,
    /// RMS per axis of zero-mean angular-rate vibration, white at the sample rate \[rad/s\]
    pub vibration_gyro_rps: f64,
    /// steady `‖f̄‖ − g` beyond bias and noise, e.g. `√(g² + a²) − g` for a horizontal
    /// acceleration a \[m/s²\]
    pub mean_accel_offset_mps2: f64,
    /// steady `‖ω̄ − ω_e‖` beyond bias and noise, e.g. a turn rate or an unmodelled earth rate
    /// \[rad/s\]
    pub mean_rate_offset_rps: f64,
}

/// The result of one full window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindowReport {
    /// index of the window's first sample (samples counted from 0 since construction or
    /// [`StationarityDetector::reset`])
    pub first_sample: u64,
    /// index of the window's last sample (the one just pushed)
    pub last_sample: u64,
    /// the statistic T (per-sample mean, Skog et al.'s normalisation; mean ≈ 6 at rest)
    pub statistic: f64,
    /// the threshold γ in the same units
    pub threshold: f64,
    /// `T < γ`
    pub stationary: bool,
    /// `A/σ_a²`: scatter of the specific force about its window mean
    pub accel_scatter: f64,
    /// `W(‖f̄‖ − g)²/σ_a²`: gravity-magnitude mismatch of the window mean
    pub accel_magnitude: f64,
    /// `G/σ_g²`: scatter of the angular rate about its window mean
    pub gyro_scatter: f64,
    /// `W‖ω̄ − ω_e‖²/σ_g²`: offset of the mean rate from the rate expected at rest
    pub gyro_mean: f64,
}

/// Sliding-window stationarity detector over the last `W` samples (const capacity, no
/// allocation). Feed one [`Increment`] per sample with [`push`](Self::push).
#[derive(Clone, Debug)]
pub struct StationarityDetector<const W: usize> {
    noise: NoiseModel,
    dt_s: f64,
    g_mps2: f64,
    threshold: f64,
    alpha: f64,
    gyro_bias_rps: Vec3,
    earth_rate_b_rps: Vec3,
    accel_bias_mps2: Vec3,
    f_ring: [Vec3; W],
    w_ring: [Vec3; W],
    head: usize,
    len: usize,
    count: u64,
    since_refresh: usize,
    centre_f: Vec3,
    centre_w: Vec3,
    sum_f: Vec3,
    sum_ff: f64,
    sum_w: Vec3,
    sum_ww: f64,
}

/// Largest residual-bias ratio `κ = W σ_b²/σ²` accepted: beyond it the bias decides the test
/// (the threshold is then ~(1 + κ) times a χ²(3) quantile), and the exact law needs ~κ·W
/// series terms per evaluation (κ = 1e3, W = 200, α = 1e-6: 0.13 s to build).
pub const MAX_KAPPA: f64 = 1e3;

/// Largest |rate| accepted \[rad/s or m/s²\]: keeps every sum of squares finite.
const MAX_INPUT: f64 = 1e100;

fn finite_vec(v: &Vec3) -> bool {
    v.iter()
        .all(|c| c.is_finite() && libm::fabs(*c) <= MAX_INPUT)
}

impl<const W: usize> StationarityDetector<W> {
    fn build(noise: NoiseModel, dt_s: f64, g_mps2: f64) -> Result<Self, StationarityError> {
        noise.check()?;
        let ok = W >= 2
            && W <= 1 << 20
            && dt_s.is_finite()
            && dt_s > 0.0
            && g_mps2.is_finite()
            && g_mps2 > 0.0;
        if !ok {
            return Err(StationarityError::InvalidConfig);
        }
        let (ka, kg) = noise.kappas(W);
        if ka > MAX_KAPPA || kg > MAX_KAPPA {
            return Err(StationarityError::ResidualBiasDominates);
        }
        Ok(Self {
            noise,
            dt_s,
            g_mps2,
            threshold: 0.0,
            alpha: 0.0,
            gyro_bias_rps: Vec3::zeros(),
            earth_rate_b_rps: Vec3::zeros(),
            accel_bias_mps2: Vec3::zeros(),
            f_ring: [Vec3::zeros(); W],
            w_ring: [Vec3::zeros(); W],
            head: 0,
            len: 0,
            count: 0,
            since_refresh: 0,
            centre_f: Vec3::zeros(),
            centre_w: Vec3::zeros(),
            sum_f: Vec3::zeros(),
            sum_ff: 0.0,
            sum_w: Vec3::zeros(),
            sum_ww: 0.0,
        })
    }

    /// Threshold from theory: `γ = q_{1−α}/W`, q the upper α-quantile of the law of `W·T` at
    /// rest (module docs). `false_alarm_rate` α ∈ \[1e-9, 0.5\] is the probability that a
    /// window at rest is declared moving (below 1e-9 the survival function's absolute
    /// accuracy, ~1e-15 and ~1e-13 for widely spread weights, would no longer fix α to 1e-4);
    /// `dt_s` the sample period; `g_mps2` local gravity.
    pub fn from_noise_model(
        noise: NoiseModel,
        dt_s: f64,
        g_mps2: f64,
        false_alarm_rate: f64,
    ) -> Result<Self, StationarityError> {
        if !(1e-9..=0.5).contains(&false_alarm_rate) {
            return Err(StationarityError::InvalidConfig);
        }
        let mut d = Self::build(noise, dt_s, g_mps2)?;
        let q = d.rest_distribution()?.upper_quantile(false_alarm_rate)?;
        d.threshold = q / W as f64;
        d.alpha = false_alarm_rate;
        Ok(d)
    }

    /// Explicit threshold γ on T (Skog et al.'s normalisation); the implied false-alarm
    /// rate is computed from the noise model ([`false_alarm_rate`](Self::false_alarm_rate)).
    pub fn with_threshold(
        noise: NoiseModel,
        dt_s: f64,
        g_mps2: f64,
        threshold: f64,
    ) -> Result<Self, StationarityError> {
        if !(threshold.is_finite() && threshold > 0.0) {
            return Err(StationarityError::InvalidConfig);
        }
        let mut d = Self::build(noise, dt_s, g_mps2)?;
        d.alpha = d.rest_distribution()?.sf(threshold * W as f64)?;
        d.threshold = threshold;
        Ok(d)
    }

    /// Law of `W·T` at rest: `χ²(6W − 6) + (1 + κ_g) χ²(3) + (1 + κ_a) χ²(1)`.
    pub fn rest_distribution(&self) -> Result<WeightedChiSquare, StationarityError> {
        self.distribution(&MotionModel::default())
    }

    fn distribution(&self, m: &MotionModel) -> Result<WeightedChiSquare, StationarityError> {
        let vals = [
            m.vibration_accel_mps2,
            m.vibration_gyro_rps,
            m.mean_accel_offset_mps2,
            m.mean_rate_offset_rps,
        ];
        if !vals
            .iter()
            .all(|v| v.is_finite() && libm::fabs(*v) <= MAX_INPUT)
        {
            return Err(StationarityError::InvalidInput);
        }
        let w = W as f64;
        let (ka, kg) = self.noise.kappas(W);
        let sq = |x: f64| x * x;
        let ra = sq(m.vibration_accel_mps2 / self.noise.sigma_accel_mps2);
        let rg = sq(m.vibration_gyro_rps / self.noise.sigma_gyro_rps);
        let wa = 1.0 + ka + ra;
        let wg = 1.0 + kg + rg;
        let la = w * sq(m.mean_accel_offset_mps2 / self.noise.sigma_accel_mps2) / wa;
        let lg = w * sq(m.mean_rate_offset_rps / self.noise.sigma_gyro_rps) / wg;
        let scatter = 3.0 * (w - 1.0);
        Ok(WeightedChiSquare::new(&[
            ChiSquareTerm::central(1.0 + ra, scatter),
            ChiSquareTerm::central(1.0 + rg, scatter),
            ChiSquareTerm {
                weight: wg,
                dof: 3.0,
                noncentrality: lg,
            },
            ChiSquareTerm {
                weight: wa,
                dof: 1.0,
                noncentrality: la,
            },
        ])?)
    }

    /// Predicted probability that a window is declared moving under the motion `m`
    /// (white vibration and steady offsets, module docs); `MotionModel::default()` (rest)
    /// gives the false-alarm rate. `1 −` this is the probability of declaring a moving
    /// window stationary.
    pub fn probability_declared_moving(&self, m: &MotionModel) -> Result<f64, StationarityError> {
        Ok(self.distribution(m)?.sf(self.threshold * W as f64)?)
    }

    /// The threshold γ on T.
    pub fn threshold(&self) -> f64 {
        self.threshold
    }

    /// The false-alarm rate α at rest: as given, or implied by an explicit threshold.
    pub fn false_alarm_rate(&self) -> f64 {
        self.alpha
    }

    /// The noise model.
    pub fn noise(&self) -> &NoiseModel {
        &self.noise
    }

    /// Estimated gyro bias b̂_g \[rad/s\] (body), removed from the rate before the test.
    pub fn set_gyro_bias_rps(&mut self, b_g_rps: &Vec3) -> Result<(), StationarityError> {
        if !finite_vec(b_g_rps) {
            return Err(StationarityError::InvalidInput);
        }
        self.gyro_bias_rps = *b_g_rps;
        Ok(())
    }

    /// Estimated accelerometer bias b̂_a \[m/s²\] (body), removed from the specific force.
    pub fn set_accel_bias_mps2(&mut self, b_a_mps2: &Vec3) -> Result<(), StationarityError> {
        if !finite_vec(b_a_mps2) {
            return Err(StationarityError::InvalidInput);
        }
        self.accel_bias_mps2 = *b_a_mps2;
        Ok(())
    }

    /// Earth rate resolved in the body frame, `Ĉ_n^b ω_ie^n` \[rad/s\] (or any other rate the
    /// body has at rest, e.g. zero on a non-rotating test bench).
    pub fn set_earth_rate_b_rps(&mut self, omega_ie_b_rps: &Vec3) -> Result<(), StationarityError> {
        if !finite_vec(omega_ie_b_rps) {
            return Err(StationarityError::InvalidInput);
        }
        self.earth_rate_b_rps = *omega_ie_b_rps;
        Ok(())
    }

    /// Earth rate from the attitude estimate: `ω_ie^b = Ĉ_b^nᵀ ω_ie^n`.
    pub fn set_attitude(
        &mut self,
        c_b_n: &Mat3,
        omega_ie_n_rps: &Vec3,
    ) -> Result<(), StationarityError> {
        if !(c_b_n.iter().all(|c| c.is_finite()) && finite_vec(omega_ie_n_rps)) {
            return Err(StationarityError::InvalidInput);
        }
        self.set_earth_rate_b_rps(&(c_b_n.transpose() * omega_ie_n_rps))
    }

    /// The gyro output expected at rest, `ω_e = b̂_g + Ĉ_n^b ω_ie^n` \[rad/s\].
    pub fn expected_rate_b_rps(&self) -> Vec3 {
        self.gyro_bias_rps + self.earth_rate_b_rps
    }

    /// Forget the buffered samples (the sample counter restarts at 0).
    pub fn reset(&mut self) {
        self.head = 0;
        self.len = 0;
        self.count = 0;
        self.since_refresh = 0;
        self.sum_f = Vec3::zeros();
        self.sum_w = Vec3::zeros();
        self.sum_ff = 0.0;
        self.sum_ww = 0.0;
    }

    /// Recompute the running sums from the ring, centred on the current means.
    fn refresh(&mut self) {
        let n = self.len as f64;
        let mean_f = self.centre_f + self.sum_f / n;
        let mean_w = self.centre_w + self.sum_w / n;
        self.centre_f = mean_f;
        self.centre_w = mean_w;
        let (mut sf, mut sw) = (Vec3::zeros(), Vec3::zeros());
        let (mut sff, mut sww) = (0.0, 0.0);
        for i in 0..self.len {
            let df = self.f_ring[i] - mean_f;
            let dw = self.w_ring[i] - mean_w;
            sf += df;
            sw += dw;
            sff += df.norm_squared();
            sww += dw.norm_squared();
        }
        self.sum_f = sf;
        self.sum_w = sw;
        self.sum_ff = sff;
        self.sum_ww = sww;
        self.since_refresh = 0;
    }

    /// Feed one sample (Δθ, Δv over δt, body FRD). Returns the window's report once W
    /// samples are buffered (then on every sample), `None` before. A non-finite sample is
    /// refused with [`StationarityError::InvalidInput`] and leaves the detector unchanged.
    pub fn push(&mut self, inc: &Increment) -> Result<Option<WindowReport>, StationarityError> {
        let f = inc.dv_b_mps / self.dt_s;
        let w = inc.dtheta_b_rad / self.dt_s;
        if !(finite_vec(&f) && finite_vec(&w)) {
            return Err(StationarityError::InvalidInput);
        }
        if self.len == 0 {
            self.centre_f = f;
            self.centre_w = w;
        }
        if self.len == W {
            let (of, ow) = (self.f_ring[self.head], self.w_ring[self.head]);
            let (df, dw) = (of - self.centre_f, ow - self.centre_w);
            self.sum_f -= df;
            self.sum_w -= dw;
            self.sum_ff -= df.norm_squared();
            self.sum_ww -= dw.norm_squared();
        } else {
            self.len += 1;
        }
        self.f_ring[self.head] = f;
        self.w_ring[self.head] = w;
        self.head = (self.head + 1) % W;
        let (df, dw) = (f - self.centre_f, w - self.centre_w);
        self.sum_f += df;
        self.sum_w += dw;
        self.sum_ff += df.norm_squared();
        self.sum_ww += dw.norm_squared();
        self.count += 1;
        self.since_refresh += 1;
        if self.len < W {
            return Ok(None);
        }
        if self.since_refresh >= W {
            self.refresh();
        }
        Ok(Some(self.report()))
    }

    fn report(&self) -> WindowReport {
        let n = W as f64;
        let mean_f = self.centre_f + self.sum_f / n - self.accel_bias_mps2;
        let mean_w = self.centre_w + self.sum_w / n;
        let a = (self.sum_ff - self.sum_f.norm_squared() / n).max(0.0);
        let g = (self.sum_ww - self.sum_w.norm_squared() / n).max(0.0);
        let va = self.noise.sigma_accel_mps2 * self.noise.sigma_accel_mps2;
        let vg = self.noise.sigma_gyro_rps * self.noise.sigma_gyro_rps;
        let dm = mean_f.norm() - self.g_mps2;
        let accel_scatter = a / va;
        let accel_magnitude = n * dm * dm / va;
        let gyro_scatter = g / vg;
        let gyro_mean = n * (mean_w - self.expected_rate_b_rps()).norm_squared() / vg;
        let statistic =
            ((accel_scatter + accel_magnitude + gyro_scatter + gyro_mean) / n).min(f64::MAX);
        WindowReport {
            first_sample: self.count - W as u64,
            last_sample: self.count - 1,
            statistic,
            threshold: self.threshold,
            stationary: statistic < self.threshold,
            accel_scatter,
            accel_magnitude,
            gyro_scatter,
            gyro_mean,
        }
    }
}

/// A run of samples declared stationary, `first_sample..=last_sample`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StationaryInterval {
    /// first sample index
    pub first_sample: u64,
    /// last sample index (inclusive)
    pub last_sample: u64,
}

impl StationaryInterval {
    /// Number of samples.
    pub fn len_samples(&self) -> u64 {
        self.last_sample - self.first_sample + 1
    }
}

/// Turns window decisions into stationary intervals with a minimum duration.
///
/// A window declared stationary vouches for all its W samples, so a run of consecutive
/// stationary windows ending at samples `n₁ … n₂` gives the interval `[n₁ − W + 1, n₂]`
/// (clipped to start after the previous interval). A window declared moving ends the run.
/// For motion strong enough to be seen in one sample (a turn, a jolt) the interval ends
/// exactly at the last sample before the motion and starts at the first sample after it.
/// Runs shorter than `min_samples` are dropped. Feed windows in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IntervalTracker {
    window: u64,
    min_samples: u64,
    current: Option<StationaryInterval>,
    next_free: u64,
}

impl IntervalTracker {
    /// `window`: the samples a decision covers (the detector's W; 1 for per-sample
    /// decisions); `min_samples`: shortest interval reported.
    pub fn new(window: usize, min_samples: u64) -> Self {
        Self {
            window: window.max(1) as u64,
            min_samples: min_samples.max(1),
            current: None,
            next_free: 0,
        }
    }

    /// One decision about the window ending at `last_sample`. Returns the interval that
    /// this decision closes, if it lasted at least `min_samples`.
    pub fn push_decision(
        &mut self,
        last_sample: u64,
        stationary: bool,
    ) -> Option<StationaryInterval> {
        let first = (last_sample + 1)
            .saturating_sub(self.window)
            .max(self.next_free);
        match (stationary, self.current) {
            (true, Some(mut c)) if first <= c.last_sample + 1 => {
                c.last_sample = c.last_sample.max(last_sample);
                self.current = Some(c);
                None
            }
            (true, _) => {
                let closed = self.finish();
                let first = first.max(self.next_free);
                self.current = Some(StationaryInterval {
                    first_sample: first,
                    last_sample,
                });
                closed
            }
            (false, _) => self.finish(),
        }
    }

    /// A [`WindowReport`] as one decision.
    pub fn push(&mut self, report: &WindowReport) -> Option<StationaryInterval> {
        self.push_decision(report.last_sample, report.stationary)
    }

    /// Close the open interval (end of data).
    pub fn finish(&mut self) -> Option<StationaryInterval> {
        let c = self.current.take()?;
        self.next_free = c.last_sample + 1;
        (c.len_samples() >= self.min_samples).then_some(c)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::math::{c_b_n_from_euler, Euler};
    extern crate std;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};
    use std::println;

    const D2R: f64 = core::f64::consts::PI / 180.0;
    const DPH: f64 = D2R / 3600.0;
    const G: f64 = 9.80665;
    /// Tactical grade at 200 Hz: ARW 0.003 °/√h, VRW 0.03 m/s/√h.
    const DT: f64 = 0.005;
    const ARW: f64 = 0.003 * D2R / 60.0;
    const VRW: f64 = 0.03 / 60.0;

    fn tactical(sigma_ba: f64, sigma_bg: f64) -> NoiseModel {
        NoiseModel::from_random_walks(VRW, ARW, DT, sigma_ba, sigma_bg).unwrap()
    }

    /// Samples of a body at rest (or moving) with white Gaussian noise.
    struct Sim {
        rng: ChaCha8Rng,
        sigma_a: f64,
        sigma_g: f64,
        f_b: Vec3,
        w_b: Vec3,
    }

    impl Sim {
        /// At rest at latitude 45° with the attitude (roll, pitch, yaw) [deg]: the specific
        /// force `C_n^b [0, 0, −g]`, the rate `C_n^b ω_ie^n` plus `gyro_bias`.
        fn rest(seed: u64, noise: &NoiseModel, rpy_deg: [f64; 3], gyro_bias: Vec3) -> Self {
            let c = c_b_n_from_euler(&Euler::new(
                rpy_deg[0] * D2R,
                rpy_deg[1] * D2R,
                rpy_deg[2] * D2R,
            ));
            Self {
                rng: ChaCha8Rng::seed_from_u64(seed),
                sigma_a: noise.sigma_accel_mps2,
                sigma_g: noise.sigma_gyro_rps,
                f_b: c.transpose() * Vec3::new(0.0, 0.0, -G),
                w_b: c.transpose() * earth_n() + gyro_bias,
            }
        }
        fn gauss3(&mut self) -> Vec3 {
            let mut v = Vec3::zeros();
            for c in v.iter_mut() {
                *c = StandardNormal.sample(&mut self.rng);
            }
            v
        }
        fn sample_with(&mut self, f_b: Vec3, w_b: Vec3) -> Increment {
            let nf = self.gauss3() * self.sigma_a;
            let nw = self.gauss3() * self.sigma_g;
            Increment::new((w_b + nw) * DT, (f_b + nf) * DT)
        }
        fn sample(&mut self) -> Increment {
            self.sample_with(self.f_b, self.w_b)
        }
    }

    fn earth_n() -> Vec3 {
        let (s, c) = libm::sincos(45.0 * D2R);
        Vec3::new(7.292_115e-5 * c, 0.0, -7.292_115e-5 * s)
    }

    /// The two-sided 99 % binomial band `nα ± 2.576 √(nα(1 − α))` (normal approximation,
    /// n α ≥ 100 in every use).
    fn band(n: usize, p: f64) -> (f64, f64) {
        let m = n as f64 * p;
        let h = 2.576 * libm::sqrt(m * (1.0 - p));
        (m - h, m + h)
    }

    /// Counts the disjoint windows (every W-th report) declared moving over `n` windows of
    /// rest data; a fresh residual bias (σ_ba, σ_bg per axis) is drawn for every window.
    fn rest_rate<const W: usize>(det: &mut StationarityDetector<W>, n: usize, seed: u64) -> usize {
        let noise = *det.noise();
        let mut sim = Sim::rest(seed, &noise, [3.0, -40.0, 120.0], Vec3::zeros());
        let mut bias_rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
        let mut bias = |s: f64| {
            let v: [f64; 3] = core::array::from_fn(|_| StandardNormal.sample(&mut bias_rng));
            Vec3::new(v[0], v[1], v[2]) * s
        };
        det.set_attitude(
            &c_b_n_from_euler(&Euler::new(3.0 * D2R, -40.0 * D2R, 120.0 * D2R)),
            &earth_n(),
        )
        .unwrap();
        let (f0, w0) = (sim.f_b, sim.w_b);
        let mut moving = 0;
        for _ in 0..n {
            let (ba, bg) = (
                bias(noise.sigma_accel_bias_mps2),
                bias(noise.sigma_gyro_bias_rps),
            );
            for _ in 0..W {
                let s = sim.sample_with(f0 + ba, w0 + bg);
                if let Some(r) = det.push(&s).unwrap() {
                    if r.last_sample % W as u64 == W as u64 - 1 && !r.stationary {
                        moving += 1;
                    }
                }
            }
        }
        moving
    }

    fn check_rest_rate<const W: usize>(alpha: f64, n: usize, seed: u64) {
        let mut det =
            StationarityDetector::<W>::from_noise_model(tactical(0.0, 0.0), DT, G, alpha).unwrap();
        let k = rest_rate(&mut det, n, seed);
        let (lo, hi) = band(n, alpha);
        println!(
            "W = {W}: {k} of {n} windows at rest declared moving ({:.5}), stated α = {alpha}, 99 % band [{lo:.0}, {hi:.0}]; γ = {:.4}",
            k as f64 / n as f64,
            det.threshold()
        );
        assert!(
            (k as f64) >= lo && (k as f64) <= hi,
            "W = {W}: {k} outside [{lo}, {hi}]"
        );
    }

    #[test]
    fn false_alarm_rate_at_rest_matches_the_stated_rate() {
        check_rest_rate::<5>(1e-3, 200_000, 1);
        check_rest_rate::<20>(1e-2, 20_000, 2);
        check_rest_rate::<200>(5e-2, 2_000, 3);
    }

    /// Residual biases widen the law at rest: with the widened threshold the rate over the
    /// residual-bias population is the stated α; a threshold that ignores them (κ = 0) is
    /// exceeded at the rate the same theory predicts for it.
    #[test]
    fn residual_bias_widens_the_threshold_and_keeps_the_stated_rate() {
        const W: usize = 20;
        let (alpha, n) = (1e-2, 20_000);
        let s = tactical(0.0, 0.0);
        // κ_g = 2, κ_a = 5
        let sigma_bg = s.sigma_gyro_rps * libm::sqrt(2.0 / W as f64);
        let sigma_ba = s.sigma_accel_mps2 * libm::sqrt(5.0 / W as f64);
        let noise = tactical(sigma_ba, sigma_bg);
        let (ka, kg) = noise.kappas(W);
        assert!((ka - 5.0).abs() < 1e-12 && (kg - 2.0).abs() < 1e-12);
        let mut det = StationarityDetector::<W>::from_noise_model(noise, DT, G, alpha).unwrap();
        let k = rest_rate(&mut det, n, 11);
        let (lo, hi) = band(n, alpha);
        // the naive threshold on the same data (same seed: the same samples and biases)
        let mut naive = StationarityDetector::<W>::from_noise_model(s, DT, G, alpha).unwrap();
        naive.noise = noise; // the data's biases, the naive threshold
        let predicted = naive
            .probability_declared_moving(&MotionModel::default())
            .unwrap();
        let kn = rest_rate(&mut naive, n, 11);
        let (nlo, nhi) = band(n, predicted);
        println!(
            "κ_a = 5, κ_g = 2: γ = {:.4} (naive {:.4}); moving at rest {k}/{n} (band [{lo:.0}, {hi:.0}]); naive threshold {kn}/{n}, predicted {:.4} (band [{nlo:.0}, {nhi:.0}])",
            det.threshold(),
            naive.threshold(),
            predicted
        );
        assert!((k as f64) >= lo && (k as f64) <= hi);
        assert!(predicted > 2.0 * alpha, "{predicted}");
        assert!((kn as f64) >= nlo && (kn as f64) <= nhi);
    }

    /// A turn at 5 °/s and an acceleration of 0.1 g after 2 s at rest (W = 200, 1 s): every
    /// window that holds a moving sample is declared moving. One turning sample alone adds
    /// `(1 − 1/W)(5 °/s)²/σ_g² ≈ 5e7` to W·T and one accelerating sample
    /// `(1 − 1/W)(0.98 m/s²)²/σ_a² ≈ 1.9e4`, against W·γ ≈ 1.3e3 (α = 1e-3); once the
    /// window is all acceleration the scatter is back to noise and the magnitude term
    /// `W(√(g² + a²) − g)²/σ_a² ≈ 9.6e3` carries the decision.
    #[test]
    fn turns_and_accelerations_are_declared_moving() {
        const W: usize = 200;
        let noise = tactical(0.0, 0.0);
        for (case, turn) in [("turn 5 °/s", true), ("acceleration 0.1 g", false)] {
            let mut det = StationarityDetector::<W>::from_noise_model(noise, DT, G, 1e-3).unwrap();
            let mut sim = Sim::rest(21, &noise, [0.0, 0.0, 0.0], Vec3::zeros());
            det.set_attitude(&Mat3::identity(), &earth_n()).unwrap();
            let start = 2 * W as u64;
            let (mut rest_moving, mut moving, mut all_accel) = (0, 0, 0);
            for i in 0..(6 * W as u64) {
                let s = if i < start {
                    sim.sample()
                } else if turn {
                    let w = sim.w_b + Vec3::new(0.0, 0.0, 5.0 * D2R);
                    sim.sample_with(sim.f_b, w)
                } else {
                    // forward acceleration a: specific force gains +a along x (FRD)
                    sim.sample_with(sim.f_b + Vec3::new(0.1 * G, 0.0, 0.0), sim.w_b)
                };
                let Some(r) = det.push(&s).unwrap() else {
                    continue;
                };
                if r.last_sample < start {
                    rest_moving += usize::from(!r.stationary);
                } else {
                    assert!(
                        !r.stationary,
                        "{case}: window ending {} stationary",
                        r.last_sample
                    );
                    moving += 1;
                    if !turn && r.first_sample >= start {
                        // all-acceleration window: the magnitude term decides
                        assert!(r.accel_scatter < W as f64 * r.threshold, "{r:?}");
                        assert!(r.accel_magnitude > W as f64 * r.threshold, "{r:?}");
                        all_accel += 1;
                    }
                }
            }
            println!("{case}: {moving} windows with motion, all moving; {rest_moving} of {} rest windows moving", start as usize - W + 1);
            assert_eq!(moving, 4 * W);
            assert!(turn || all_accel == 3 * W + 1);
        }
    }

    /// Tactical IMU (σ_g = 2.55 °/h per sample at 200 Hz) at rest with a gyro bias of 10 °/h
    /// per axis, W = 200 (1 s), α = 1e-2: with `b̂_g` and the attitude supplied (residual
    /// 0.1 °/h) the windows are stationary at the stated rate; with neither, the earth rate
    /// (15.04 °/h) and the bias (17.3 °/h), each far above the window-mean noise
    /// σ_g/√W = 0.18 °/h, make every window moving, as the non-central law predicts.
    #[test]
    fn earth_rate_and_gyro_bias_must_be_removed_at_tactical_grade() {
        const W: usize = 200;
        let (alpha, n) = (1e-2, 2_000);
        let bias = Vec3::new(10.0, -10.0, 10.0) * DPH; // 10 °/h per axis
        let noise = tactical(0.0, 0.1 * DPH);
        let rpy = [2.0, -1.0, 60.0];
        let c = c_b_n_from_euler(&Euler::new(rpy[0] * D2R, rpy[1] * D2R, rpy[2] * D2R));
        let mut with = StationarityDetector::<W>::from_noise_model(noise, DT, G, alpha).unwrap();
        with.set_attitude(&c, &earth_n()).unwrap();
        with.set_gyro_bias_rps(&bias).unwrap();
        let mut without = with.clone();
        without.set_gyro_bias_rps(&Vec3::zeros()).unwrap();
        without.set_earth_rate_b_rps(&Vec3::zeros()).unwrap();
        let offset = (c.transpose() * earth_n() + bias).norm();
        let predicted = without
            .probability_declared_moving(&MotionModel {
                mean_rate_offset_rps: offset,
                ..MotionModel::default()
            })
            .unwrap();
        let mut sim = Sim::rest(31, &noise, rpy, bias);
        let (mut k_with, mut k_without) = (0, 0);
        for _ in 0..n * W {
            let s = sim.sample();
            let a = with.push(&s).unwrap();
            let b = without.push(&s).unwrap();
            if let (Some(a), Some(b)) = (a, b) {
                if a.last_sample % W as u64 == W as u64 - 1 {
                    k_with += usize::from(!a.stationary);
                    k_without += usize::from(!b.stationary);
                }
            }
        }
        let (lo, hi) = band(n, alpha);
        println!(
            "expected rate supplied: {k_with}/{n} moving (band [{lo:.0}, {hi:.0}]); not supplied (offset {:.2} °/h): {k_without}/{n} moving, predicted P = {predicted}",
            offset / DPH
        );
        assert!((k_with as f64) >= lo && (k_with as f64) <= hi);
        assert!(predicted > 1.0 - 1e-12);
        assert_eq!(k_without, n);
    }

    /// The predicted probability of declaring a window moving, against Monte Carlo: white
    /// vibration (a_v = 0.5 σ_a, ω_v = 0.3 σ_g) and a steady unmodelled rate offset.
    #[test]
    fn motion_predictions_match_monte_carlo() {
        const W: usize = 20;
        let n = 10_000;
        let noise = tactical(0.0, 0.0);
        let (av, wv) = (0.5 * noise.sigma_accel_mps2, 0.3 * noise.sigma_gyro_rps);
        let offset = Vec3::new(0.0, 0.6, -0.8) * (0.9 * noise.sigma_gyro_rps);
        let cases = [
            (
                "vibration",
                MotionModel {
                    vibration_accel_mps2: av,
                    vibration_gyro_rps: wv,
                    ..MotionModel::default()
                },
                Vec3::zeros(),
            ),
            (
                "rate offset",
                MotionModel {
                    mean_rate_offset_rps: offset.norm(),
                    ..MotionModel::default()
                },
                offset,
            ),
        ];
        for (i, (name, m, off)) in cases.iter().enumerate() {
            let mut det = StationarityDetector::<W>::from_noise_model(noise, DT, G, 1e-2).unwrap();
            det.set_attitude(&Mat3::identity(), &earth_n()).unwrap();
            let p = det.probability_declared_moving(m).unwrap();
            let mut sim = Sim::rest(41 + i as u64, &noise, [0.0, 0.0, 0.0], Vec3::zeros());
            // the vibration enters as extra white noise of the stated RMS
            sim.sigma_a = libm::hypot(noise.sigma_accel_mps2, m.vibration_accel_mps2);
            sim.sigma_g = libm::hypot(noise.sigma_gyro_rps, m.vibration_gyro_rps);
            sim.w_b += off;
            let mut k = 0;
            for _ in 0..n * W {
                if let Some(r) = det.push(&sim.sample()).unwrap() {
                    if r.last_sample % W as u64 == W as u64 - 1 {
                        k += usize::from(!r.stationary);
                    }
                }
            }
            let (lo, hi) = band(n, p);
            println!("{name}: {k}/{n} windows declared moving, predicted {p:.4} (band [{lo:.0}, {hi:.0}])");
            assert!(
                p > 0.1 && p < 0.9,
                "{p}: choose a case that tests the law, not its tails"
            );
            assert!((k as f64) >= lo && (k as f64) <= hi);
        }
    }

    /// The O(1) running sums (refreshed every W samples) against a two-pass evaluation of
    /// the window, after 10⁴ samples of rest, turning and accelerating data.
    #[test]
    fn running_sums_match_a_two_pass_evaluation() {
        const W: usize = 50;
        let noise = tactical(1e-3, 1e-6);
        let mut det = StationarityDetector::<W>::from_noise_model(noise, DT, G, 1e-3).unwrap();
        det.set_gyro_bias_rps(&Vec3::new(1e-5, -2e-5, 3e-5))
            .unwrap();
        det.set_accel_bias_mps2(&Vec3::new(0.01, 0.02, -0.03))
            .unwrap();
        det.set_earth_rate_b_rps(&Vec3::new(5e-5, 0.0, -5e-5))
            .unwrap();
        let mut sim = Sim::rest(51, &noise, [10.0, 20.0, 30.0], Vec3::zeros());
        let mut buf: std::vec::Vec<Increment> = std::vec::Vec::new();
        let mut worst = 0.0_f64;
        for i in 0..10_000 {
            let phase = (i / 700) % 3;
            let s = match phase {
                0 => sim.sample(),
                1 => sim.sample_with(sim.f_b, sim.w_b + Vec3::new(0.3, 0.0, 0.1)),
                _ => sim.sample_with(sim.f_b + Vec3::new(2.0, -1.0, 0.5), sim.w_b),
            };
            buf.push(s);
            let Some(r) = det.push(&s).unwrap() else {
                continue;
            };
            let win = &buf[buf.len() - W..];
            let f: std::vec::Vec<Vec3> = win
                .iter()
                .map(|x| x.dv_b_mps / DT - Vec3::new(0.01, 0.02, -0.03))
                .collect();
            let w: std::vec::Vec<Vec3> = win.iter().map(|x| x.dtheta_b_rad / DT).collect();
            let fm = f.iter().sum::<Vec3>() / W as f64;
            let u = fm / fm.norm();
            let we = det.expected_rate_b_rps();
            // Skog et al.'s SHOE sum, literally
            let t: f64 = f
                .iter()
                .zip(&w)
                .map(|(fk, wk)| {
                    (fk - G * u).norm_squared() / noise.sigma_accel_mps2.powi(2)
                        + (wk - we).norm_squared() / noise.sigma_gyro_rps.powi(2)
                })
                .sum::<f64>()
                / W as f64;
            worst = worst.max((r.statistic - t).abs() / t);
        }
        println!("running sums vs two-pass SHOE sum: worst relative difference {worst:e}");
        // the running sums subtract squares of size ‖f − centre‖² ≤ (2 m/s²)² from sums of
        // size W·σ²-to-W·(2 m/s²)²: relative roundoff ~ W·ε·(2/σ_a)² ≈ 1e-9 at worst
        assert!(worst < 1e-8, "{worst:e}");
    }

    #[test]
    fn intervals_from_window_decisions() {
        // W = 4, min 6 samples: windows ending at 3..=20, moving at 10..=12 and 20
        let mut t = IntervalTracker::new(4, 6);
        let mut out = std::vec::Vec::new();
        for last in 3..=20u64 {
            let stationary = !(10..=12).contains(&last) && last != 20;
            if let Some(iv) = t.push_decision(last, stationary) {
                out.push(iv);
            }
        }
        if let Some(iv) = t.finish() {
            out.push(iv);
        }
        // run 3..=9 covers samples 0..=9; run 13..=19 covers 10..=19 (clipped to start after 9)
        assert_eq!(
            out,
            [
                StationaryInterval {
                    first_sample: 0,
                    last_sample: 9
                },
                StationaryInterval {
                    first_sample: 10,
                    last_sample: 19
                }
            ]
        );
        // a short run is dropped; a strong event at sample 30 (windows 30..=33 moving)
        // leaves exactly sample 30 out
        let mut t = IntervalTracker::new(4, 3);
        let mut out = std::vec::Vec::new();
        for last in 3..=40u64 {
            let moving = (30..=33).contains(&last) || last == 5;
            out.extend(t.push_decision(last, !moving));
        }
        out.extend(t.finish());
        assert_eq!(out.len(), 3, "{out:?}");
        assert_eq!((out[0].first_sample, out[0].last_sample), (0, 4)); // window 3..=4
        assert_eq!((out[1].first_sample, out[1].last_sample), (5, 29));
        assert_eq!((out[2].first_sample, out[2].last_sample), (31, 40));
        assert_eq!(out[1].len_samples(), 25);
        let mut t = IntervalTracker::new(4, 100);
        assert_eq!(t.push_decision(3, true), None);
        assert_eq!(t.finish(), None); // 4 samples < 100
    }

    #[test]
    fn invalid_configuration_and_input_are_refused() {
        let ok = tactical(0.0, 0.0);
        type D = StationarityDetector<10>;
        assert_eq!(
            D::from_noise_model(ok, 0.0, G, 1e-3).unwrap_err(),
            StationarityError::InvalidConfig
        );
        assert_eq!(
            D::from_noise_model(ok, DT, f64::NAN, 1e-3).unwrap_err(),
            StationarityError::InvalidConfig
        );
        assert_eq!(
            D::from_noise_model(ok, DT, G, 0.7).unwrap_err(),
            StationarityError::InvalidConfig
        );
        assert_eq!(
            D::with_threshold(ok, DT, G, -1.0).unwrap_err(),
            StationarityError::InvalidConfig
        );
        let mut bad = ok;
        bad.sigma_gyro_rps = 0.0;
        assert_eq!(
            D::from_noise_model(bad, DT, G, 1e-3).unwrap_err(),
            StationarityError::InvalidConfig
        );
        bad = ok;
        bad.sigma_accel_bias_mps2 = f64::INFINITY;
        assert_eq!(
            D::from_noise_model(bad, DT, G, 1e-3).unwrap_err(),
            StationarityError::InvalidConfig
        );
        bad = ok;
        bad.sigma_gyro_bias_rps = 1e3 * ok.sigma_gyro_rps; // κ_g = 1e7
        assert_eq!(
            D::from_noise_model(bad, DT, G, 1e-3).unwrap_err(),
            StationarityError::ResidualBiasDominates
        );
        assert_eq!(
            StationarityDetector::<1>::from_noise_model(ok, DT, G, 1e-3).unwrap_err(),
            StationarityError::InvalidConfig
        );
        // a refused sample leaves the detector as it was
        let mut d = D::from_noise_model(ok, DT, G, 1e-3).unwrap();
        let mut sim = Sim::rest(61, &ok, [0.0, 0.0, 0.0], Vec3::zeros());
        let mut e = d.clone();
        let mut reports = (std::vec::Vec::new(), std::vec::Vec::new());
        for i in 0..25 {
            let s = sim.sample();
            if i == 12 {
                let mut nan = s;
                nan.dv_b_mps.y = f64::NAN;
                assert_eq!(d.push(&nan), Err(StationarityError::InvalidInput));
                let mut huge = s;
                huge.dtheta_b_rad.x = 1e300;
                assert_eq!(d.push(&huge), Err(StationarityError::InvalidInput));
            }
            reports.0.extend(d.push(&s).unwrap());
            reports.1.extend(e.push(&s).unwrap());
        }
        assert_eq!(reports.0, reports.1);
        assert_eq!(
            d.set_gyro_bias_rps(&Vec3::new(f64::NAN, 0.0, 0.0)),
            Err(StationarityError::InvalidInput)
        );
        let m = MotionModel {
            vibration_accel_mps2: f64::NAN,
            ..MotionModel::default()
        };
        assert_eq!(
            d.probability_declared_moving(&m),
            Err(StationarityError::InvalidInput)
        );
    }

    /// An explicit threshold reports the false-alarm rate it implies, and the rest
    /// prediction returns it.
    #[test]
    fn explicit_threshold_round_trip() {
        let noise = tactical(2e-4, 0.05 * DPH);
        let a = StationarityDetector::<40>::from_noise_model(noise, DT, G, 1e-4).unwrap();
        let b = StationarityDetector::<40>::with_threshold(noise, DT, G, a.threshold()).unwrap();
        assert!(
            (b.false_alarm_rate() / 1e-4 - 1.0).abs() < 1e-9,
            "{}",
            b.false_alarm_rate()
        );
        let p = a
            .probability_declared_moving(&MotionModel::default())
            .unwrap();
        assert!((p / 1e-4 - 1.0).abs() < 1e-9, "{p}");
        // W·T at rest without biases is χ²(6W − 2): the threshold is its quantile
        let c =
            StationarityDetector::<40>::from_noise_model(tactical(0.0, 0.0), DT, G, 1e-4).unwrap();
        let q = chi2::chi2_quantile(1.0 - 1e-4, 6.0 * 40.0 - 2.0).unwrap();
        assert!((c.threshold() * 40.0 / q - 1.0).abs() < 1e-12);
    }
}
