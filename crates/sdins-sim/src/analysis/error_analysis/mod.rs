//! Error analysis: INS error propagation and the Schuler
//! analysis of docs/theory/error-analysis.md.
//!
//! Conventions (docs/conventions.md): navigation frame NED; attitude errors in **convention G**,
//! `Ĉ_b^n = (I + [φ×]) C_b^n`; every error is *estimate − truth*; sensor biases are
//! *measured − true*. Convention TW (`ψ_TW = −φ_G`) is available through
//! [`phi_g_from_psi_tw`] / [`psi_tw_from_phi_g`]. Units are SI (m, m/s, rad, rad/s, m/s²)
//! unless a name says otherwise (`_ug`, `_dph`, `_h`).
//!
//! * [`periods`]: Schuler, Foucault and Earth-rate periods (docs/theory/error-analysis.md
//!   §"Periods"; docs/theory/error-analysis.md §"Constants and units").
//! * [`short_term`]: the corrected single-channel formulas, the paper's (1)–(3)
//!   (docs/theory/error-analysis.md §"Single-channel formulas"), with the 2 h validity limit
//!   enforced by a typed error.
//! * [`stationary`]: the full stationary closed form (Schuler + 24 h + Foucault,
//!   docs/theory/error-analysis.md §"Full stationary closed form").
//! * [`linear_model`]: the 15-state phi-angle error model along any trajectory and the
//!   covariance propagation `P = ΦPΦᵀ + Q`.
//! * [`schuler_share`]: the reconstruction of the paper's Table 1 (docs/theory/error-analysis.md
//!   §"The Schuler share").
//! * [`nonlinear`]: stationary nonlinear free-inertial runs with injected biases
//!   (docs/validation.md §"error propagation" T9).
//! * [`reference`](mod@reference): reference trajectories and error statistics for the linear model from
//!   scenarios and IMU error models.
//! * [`grades`]: the sensor-grade bias/noise values of docs/imu-errors.md §"Grades" used here.

pub mod grades;
pub mod linear_model;
pub mod nonlinear;
pub mod periods;
pub mod reference;
pub mod schuler_share;
pub mod short_term;
pub mod stationary;

use sdins_core::Vec3;

/// 1 μg in m/s² (docs/theory/error-analysis.md §"Constants and units").
pub const MICRO_G: f64 = 9.806_65e-6;
/// 1 °/h in rad/s (docs/theory/error-analysis.md §"Constants and units").
pub const DEG_PER_HOUR: f64 = core::f64::consts::PI / 180.0 / 3600.0;
/// ARW 1 °/√h in rad/√s (docs/theory/error-analysis.md §"Constants and units"): (π/180)/60.
pub const DEG_PER_SQRT_HOUR: f64 = core::f64::consts::PI / 180.0 / 60.0;
/// VRW 1 μg/√Hz in m/s/√s (docs/theory/error-analysis.md §"Constants and units").
pub const MICRO_G_PER_SQRT_HZ: f64 = 9.806_65e-6;

/// Convert a convention-TW attitude error (`Ĉ = (I − [ψ×])C`) to convention G: `φ = −ψ`
/// (docs/conventions.md §"Errors").
pub fn phi_g_from_psi_tw(psi_tw: &Vec3) -> Vec3 {
    -psi_tw
}

/// Convert a convention-G attitude error to convention TW: `ψ_TW = −φ_G` (docs/conventions.md
/// §"Errors").
pub fn psi_tw_from_phi_g(phi_g: &Vec3) -> Vec3 {
    -phi_g
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_constants_match_spec_0_4() {
        assert!((DEG_PER_HOUR - 4.848_136_8e-6).abs() < 1e-13);
        assert!((DEG_PER_SQRT_HOUR - 2.908_9e-4).abs() < 1e-8);
        // 20 μg/√Hz = 1.96e-4 m/s/√s (docs/imu-errors.md §"Grades")
        assert!((20.0 * MICRO_G_PER_SQRT_HZ - 1.96e-4).abs() < 1e-6);
        let v = Vec3::new(1.0, -2.0, 3.0);
        assert_eq!(phi_g_from_psi_tw(&psi_tw_from_phi_g(&v)), v);
    }
}
