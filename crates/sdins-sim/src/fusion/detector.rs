//! The zero-velocity trigger of the fusion loop when it comes from the IMU itself: the
//! stationarity detector of `sdins_core::aiding::stationarity` (SHOE-type GLRT, threshold
//! from the noise model and a stated false-alarm rate; docs/theory/aiding-sensors.md
//! §"Stationarity detection") on the raw increments, with the filter's bias estimates and
//! attitude removed (`ω̃ − b̂_g − Ĉ_n^b ω_ie^n`, `f̃ − b̂_a`) as they improve.
//!
//! The window is a compile-time size in the core (allocation-free); the supported sizes
//! are [`WINDOWS`], and a requested window in seconds takes the nearest one at the IMU
//! rate. The decision for the sample just pushed is the window ending at it: a stop is
//! recognised one window after it begins, a start within the samples the motion needs to
//! exceed the threshold.

use sdins_core::aiding::stationarity::{
    MotionModel, NoiseModel, StationarityDetector, StationarityError,
};
use sdins_core::coning::Increment;
use sdins_core::math::{Mat3, Vec3};

/// The supported window sizes \[samples\].
pub const WINDOWS: [usize; 6] = [10, 20, 50, 100, 200, 400];

/// The detector's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DetectorSettings {
    /// window length \[s\] (the nearest supported size at the IMU rate is used)
    pub window_s: f64,
    /// probability that a window at rest is declared moving
    pub false_alarm: f64,
}

impl Default for DetectorSettings {
    fn default() -> Self {
        Self {
            window_s: 0.5,
            false_alarm: 1e-3,
        }
    }
}

/// Why the detector cannot be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DetectorError {
    /// A setting is out of range.
    #[error("zero-velocity detector: {0}")]
    Setting(String),
    /// The core detector refused the configuration.
    #[error("zero-velocity detector: {0}")]
    Core(String),
}

fn core_err(e: StationarityError) -> DetectorError {
    DetectorError::Core(match e {
        StationarityError::ResidualBiasDominates => "the residual IMU biases, not the noise, would decide the test at this window (κ = Wσ_b²/σ² > 1e3): shorten the window".into(),
        other => format!("{other}"),
    })
}

macro_rules! any_detector {
    ($($v:ident = $w:literal),*) => {
        /// A detector of one of the supported window sizes.
        #[derive(Clone, Debug)]
        pub enum AnyDetector {
            $(
                #[doc = concat!("window of ", stringify!($w), " samples")]
                $v(Box<StationarityDetector<$w>>),
            )*
        }

        impl AnyDetector {
            fn build(
                w: usize,
                noise: NoiseModel,
                dt_s: f64,
                g_mps2: f64,
                alpha: f64,
            ) -> Result<Self, StationarityError> {
                match w {
                    $($w => Ok(AnyDetector::$v(Box::new(StationarityDetector::<$w>::from_noise_model(noise, dt_s, g_mps2, alpha)?))),)*
                    _ => Err(StationarityError::InvalidConfig),
                }
            }
            /// Window size \[samples\].
            pub fn window(&self) -> usize {
                match self {
                    $(AnyDetector::$v(_) => $w,)*
                }
            }
            /// Feed one sample; `Some(stationary)` once the window is full.
            pub fn push(&mut self, inc: &Increment) -> Result<Option<bool>, StationarityError> {
                match self {
                    $(AnyDetector::$v(d) => Ok(d.push(inc)?.map(|r| r.stationary)),)*
                }
            }
            /// Remove the current bias estimates and the earth rate at the attitude estimate.
            pub fn set_estimates(
                &mut self,
                b_a_mps2: &Vec3,
                b_g_rps: &Vec3,
                c_b_n: &Mat3,
                omega_ie_n: &Vec3,
            ) -> Result<(), StationarityError> {
                match self {
                    $(AnyDetector::$v(d) => {
                        d.set_accel_bias_mps2(b_a_mps2)?;
                        d.set_gyro_bias_rps(b_g_rps)?;
                        d.set_attitude(c_b_n, omega_ie_n)
                    })*
                }
            }
            /// The threshold γ.
            pub fn threshold(&self) -> f64 {
                match self {
                    $(AnyDetector::$v(d) => d.threshold(),)*
                }
            }
            /// Predicted probability that a window is declared moving under `m`.
            pub fn probability_declared_moving(
                &self,
                m: &MotionModel,
            ) -> Result<f64, StationarityError> {
                match self {
                    $(AnyDetector::$v(d) => d.probability_declared_moving(m),)*
                }
            }
        }
    };
}

any_detector!(
    W10 = 10,
    W20 = 20,
    W50 = 50,
    W100 = 100,
    W200 = 200,
    W400 = 400
);

impl AnyDetector {
    /// The detector for IMU noise densities (largest axis) `vrw`, `arw`, sample period
    /// `dt_s`, gravity `g_mps2` and residual-bias σ's (per axis).
    pub fn new(
        settings: &DetectorSettings,
        vrw_mps_per_sqrt_s: f64,
        arw_rad_per_sqrt_s: f64,
        dt_s: f64,
        g_mps2: f64,
        sigma_accel_bias_mps2: f64,
        sigma_gyro_bias_rps: f64,
    ) -> Result<Self, DetectorError> {
        let s = settings;
        if !(s.window_s.is_finite() && s.window_s > 0.0) {
            return Err(DetectorError::Setting(format!(
                "window must be > 0 s, got {}",
                s.window_s
            )));
        }
        if !(1e-9..=0.5).contains(&s.false_alarm) {
            return Err(DetectorError::Setting(format!(
                "false-alarm rate must be in [1e-9, 0.5], got {}",
                s.false_alarm
            )));
        }
        if !(vrw_mps_per_sqrt_s > 0.0 && arw_rad_per_sqrt_s > 0.0) {
            return Err(DetectorError::Setting(
                "needs the IMU's white noise (VRW and ARW > 0): an ideal IMU has no noise model to set the threshold from".into(),
            ));
        }
        let want = s.window_s / dt_s;
        let w = WINDOWS
            .iter()
            .copied()
            .min_by(|a, b| {
                ((*a as f64).ln() - want.ln())
                    .abs()
                    .total_cmp(&((*b as f64).ln() - want.ln()).abs())
            })
            .unwrap_or(50);
        let noise = NoiseModel::from_random_walks(
            vrw_mps_per_sqrt_s,
            arw_rad_per_sqrt_s,
            dt_s,
            sigma_accel_bias_mps2,
            sigma_gyro_bias_rps,
        )
        .map_err(core_err)?;
        AnyDetector::build(w, noise, dt_s, g_mps2, s.false_alarm).map_err(core_err)
    }
}

impl AnyDetector {
    /// [`AnyDetector::new`] from the filter's white noise and the residual-bias σ's per
    /// axis, each taken at its largest axis (the test is isotropic).
    pub fn from_filter_noise(
        settings: &DetectorSettings,
        noise: &sdins_core::aiding::ekf::NoiseModel,
        dt_s: f64,
        g_mps2: f64,
        sigma_accel_bias_mps2: &Vec3,
        sigma_gyro_bias_rps: &Vec3,
    ) -> Result<Self, DetectorError> {
        let max3 = |v: &Vec3| v.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        Self::new(
            settings,
            max3(&noise.vrw_mps_per_sqrt_s),
            max3(&noise.arw_rad_per_sqrt_s),
            dt_s,
            g_mps2,
            max3(sigma_accel_bias_mps2),
            max3(sigma_gyro_bias_rps),
        )
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn window_is_the_nearest_supported_size() {
        let s = |w| DetectorSettings {
            window_s: w,
            false_alarm: 1e-3,
        };
        let d = |w| AnyDetector::new(&s(w), 1e-3, 1e-5, 0.01, 9.8, 0.0, 0.0).unwrap();
        assert_eq!(d(0.5).window(), 50);
        assert_eq!(d(0.14).window(), 10);
        assert_eq!(d(0.15).window(), 20);
        assert_eq!(d(10.0).window(), 400);
        assert!(AnyDetector::new(&s(0.0), 1e-3, 1e-5, 0.01, 9.8, 0.0, 0.0).is_err());
        assert!(AnyDetector::new(&s(0.5), 0.0, 1e-5, 0.01, 9.8, 0.0, 0.0).is_err());
        // a residual bias that dominates the noise is refused with the remedy
        let e = AnyDetector::new(&s(4.0), 1e-3, 1e-7, 0.01, 9.8, 0.0, 1e-4).unwrap_err();
        assert!(e.to_string().contains("shorten the window"), "{e}");
    }
}
