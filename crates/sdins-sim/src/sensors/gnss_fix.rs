//! One GNSS position (and optionally velocity) solution, the common currency of the GNSS
//! simulator (`gnss`), the GNSS file readers (`gnss_file`) and the INS/GNSS
//! filter pipeline.
//!
//! Frames and units: geodetic WGS-84 latitude/longitude \[rad\] and ellipsoidal height \[m\] of
//! the **antenna**; covariances in local-level NED \[m², (m/s)²\]; `t_s` on the IMU file's time
//! base \[s\] (readers convert GPS week/seconds, dates and UTC to it).

use sdins_core::math::{Mat3, Vec3};

/// One fix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssFix {
    /// time of validity \[s\], on the IMU time base
    pub t_s: f64,
    /// antenna geodetic latitude \[rad\]
    pub lat_rad: f64,
    /// antenna longitude \[rad\]
    pub lon_rad: f64,
    /// antenna ellipsoidal height \[m\]
    pub h_m: f64,
    /// position error covariance, NED \[m²\] (symmetric, positive definite)
    pub pos_cov_ned_m2: Mat3,
    /// antenna velocity over the earth, NED \[m/s\], with its covariance \[(m/s)²\], if the
    /// receiver reports one
    pub vel: Option<(Vec3, Mat3)>,
}

impl GnssFix {
    /// A fix with diagonal position covariance from per-axis σ (N, E, D) \[m\].
    pub fn with_position_sigma(
        t_s: f64,
        lat_rad: f64,
        lon_rad: f64,
        h_m: f64,
        sigma_ned_m: Vec3,
    ) -> Self {
        Self {
            t_s,
            lat_rad,
            lon_rad,
            h_m,
            pos_cov_ned_m2: Mat3::from_diagonal(&sigma_ned_m.component_mul(&sigma_ned_m)),
            vel: None,
        }
    }
}
