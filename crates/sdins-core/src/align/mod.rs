//! Initial alignment of a stationary strapdown INS (docs/theory/alignment.md §"Coarse alignment";
//! docs/theory/alignment.md §"Fine alignment"; docs/theory/alignment.md
//! §"Multi-heading alignment").
//!
//! One file per concept:
//! * [`coarse`]: 1-step analytic (TRIAD-type, polar-orthonormalised) and 2-step
//!   (levelling + gyrocompassing) coarse alignment from averaged static increments,
//!   and the corrected first-order error table (docs/theory/alignment.md §"Coarse alignment").
//! * [`model`]: the 12-state stationary error model `F`, its discretisation, the null
//!   space `n1, n2, n3`, the pseudo (observable) coordinates and the finite-prior
//!   residual projector `Π` (docs/theory/alignment.md §"Fine alignment"; docs/theory/alignment.md
//!   §"Observability at one heading").
//! * [`i0`]: inertial-frame coarse alignment on a disturbed (swaying, heaving) base
//!   (gravity's apparent motion in the inertially frozen body frame, Wahba fit).
//! * [`kf`]: the generic Kalman filter core (prediction, Joseph-form update).
//! * [`fine`]: the 12-state zero-velocity Kalman fine alignment with its own stationary
//!   attitude/velocity propagation, closed-loop reset or feed-forward (docs/theory/alignment.md
//!   §"Fine alignment", Algorithm A with body-frame bias states, §"Multi-heading alignment").
//! * [`observability`]: numerical rank and unobservable directions of piece-wise
//!   constant `(F_j, H)` (docs/theory/alignment.md §"Observability at one heading": rank procedure,
//!   stripped observability matrix).
//! * [`multiheading`]: Algorithm B of docs/theory/alignment.md §"Multi-heading alignment"
//!   (pseudo-error least squares) with the exact attitude-error transition `Φ_k, Γ_k`.
//!
//! Conventions: NED / FRD, `c_b_n`, attitude error convention G,
//! `Ĉ_b^n = (I + [φ×]) C_b^n` (docs/conventions.md §"Errors"); use [`phi_tw_from_g`] for Titterton
//! & Weston's ψ. Biases are "measured − true" (docs/theory/imu-errors.md §"IMU error model");
//! estimator bias states are residuals (true − current estimate).
//!
//! Everything is `no_std` and allocation-free (fixed-size nalgebra matrices).

pub mod coarse;
pub mod fine;
pub mod i0;
pub mod kf;
pub mod model;
pub mod multiheading;
pub mod observability;

use crate::math::Vec3;

/// Converts a convention-G attitude error φ to Titterton & Weston's ψ (docs/conventions.md
/// §"Errors": `ψ_TW = −φ_G`).
#[inline]
pub fn phi_tw_from_g(phi_g: &Vec3) -> Vec3 {
    -phi_g
}

/// Why an alignment computation cannot be done.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum AlignError {
    /// |latitude| > 80°: the sec L terms diverge (docs/theory/alignment.md §"Coarse alignment",
    /// validity).
    LatitudeTooHigh,
    /// The averaged specific force or rate is zero / not finite, or a matrix is singular.
    Degenerate,
    /// The static window is empty.
    NoData,
}

impl core::fmt::Display for AlignError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            AlignError::LatitudeTooHigh => {
                "latitude beyond ±80°: gyrocompassing is ill-conditioned (docs/theory/alignment.md)"
            }
            AlignError::Degenerate => {
                "degenerate input (zero or non-finite specific force or rate, singular matrix)"
            }
            AlignError::NoData => "empty static window",
        })
    }
}

/// Site constants used by every alignment algorithm: latitude, gravity magnitude and
/// earth rate (docs/theory/error-analysis.md §"Constants and units"). The truth and the algorithm
/// must use the same `g`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Site {
    /// geodetic latitude L \[rad\]
    pub lat_rad: f64,
    /// local gravity magnitude g(L, h) \[m/s²\]
    pub g_mps2: f64,
    /// earth rate Ω \[rad/s\]
    pub omega_ie_rps: f64,
}

impl Site {
    /// From an earth model at latitude `lat_rad` and height `h_m`.
    pub fn from_earth(earth: &crate::earth::EarthModel, lat_rad: f64, h_m: f64) -> Self {
        Self {
            lat_rad,
            g_mps2: earth.gravity(lat_rad, h_m),
            omega_ie_rps: earth.omega_ie_rps,
        }
    }
    /// `ω_ie^n = Ω [cos L, 0, −sin L]` (docs/theory/error-analysis.md §"Constants and units").
    #[inline]
    pub fn omega_ie_n(&self) -> Vec3 {
        Vec3::new(
            self.omega_ie_rps * libm::cos(self.lat_rad),
            0.0,
            -self.omega_ie_rps * libm::sin(self.lat_rad),
        )
    }
    /// `g^n = [0, 0, g]`.
    #[inline]
    pub fn g_n(&self) -> Vec3 {
        Vec3::new(0.0, 0.0, self.g_mps2)
    }
    /// Ω_N = Ω cos L.
    #[inline]
    pub fn omega_n(&self) -> f64 {
        self.omega_ie_rps * libm::cos(self.lat_rad)
    }
    /// Ω_D = −Ω sin L.
    #[inline]
    pub fn omega_d(&self) -> f64 {
        -self.omega_ie_rps * libm::sin(self.lat_rad)
    }
    /// tan L.
    #[inline]
    pub fn tan_lat(&self) -> f64 {
        libm::tan(self.lat_rad)
    }
}
