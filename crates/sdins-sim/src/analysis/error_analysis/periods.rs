//! Schuler, Foucault and Earth-rate periods (docs/theory/error-analysis.md §"Periods", constants of
//! its §"Constants and units").
//!
//! * Schuler: `ω_s = √(g/R0)`, `T_s = 2π √(R0/g)` = 84.41 min for R0 = 6371 km,
//!   g = 9.80665 m/s². (The paper \[P2\] calls `√(g/R0)` "about 84.4 min"; that is the
//!   period `2π/ω_s`, not `√(g/R0)`, which is a frequency.)
//! * Foucault: `ω_F = Ω sin L`, `T_F = 2π/(Ω sin L)` (39.32 h at 37.5°; \[P2\]'s "about
//!   30 h" holds only near 53°).
//! * Earth rate ("24 h"): `2π/Ω` = 86 164 s = 23.93 h.

use core::f64::consts::TAU;

/// Spherical-Earth constants of the Schuler analysis (docs/theory/error-analysis.md
/// §"Constants and units").
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SchulerParams {
    /// Earth radius R0 \[m\]
    pub r0_m: f64,
    /// gravity magnitude g \[m/s²\]
    pub g_mps2: f64,
    /// Earth rate Ω \[rad/s\]
    pub omega_ie_rps: f64,
}

impl SchulerParams {
    /// The constants of the single-channel formula tables and the Schuler-share reconstruction: R0
    /// = 6 371 000 m, g = 9.80665 m/s², Ω = 7.292115e-5 rad/s.
    pub const P2: SchulerParams = SchulerParams {
        r0_m: 6_371_000.0,
        g_mps2: 9.806_65,
        omega_ie_rps: 7.292_115e-5,
    };

    /// The constants of the T9 24 h comparisons (docs/validation.md §"error propagation"): R0 =
    /// 6371 km with the local gravity of the INS run, g(37.5°, 0) = 9.79949 m/s².
    pub const T9: SchulerParams = SchulerParams {
        r0_m: 6_371_000.0,
        g_mps2: 9.799_49,
        omega_ie_rps: 7.292_115e-5,
    };

    /// Same R0 and Ω as [`SchulerParams::P2`] with the gravity `g(L, h)` of an earth model.
    pub fn with_local_gravity(
        earth: &sdins_core::earth::EarthModel,
        lat_rad: f64,
        h_m: f64,
    ) -> Self {
        SchulerParams {
            g_mps2: earth.gravity(lat_rad, h_m),
            ..Self::P2
        }
    }

    /// Schuler angular frequency `ω_s = √(g/R0)` \[rad/s\].
    pub fn omega_s(&self) -> f64 {
        schuler_frequency(self.g_mps2, self.r0_m)
    }

    /// Schuler period `T_s = 2π/ω_s` \[s\].
    pub fn schuler_period_s(&self) -> f64 {
        TAU / self.omega_s()
    }

    /// Foucault angular frequency `ω_F = Ω sin L` \[rad/s\] (signed, positive north).
    pub fn omega_f(&self, lat_rad: f64) -> f64 {
        foucault_frequency(self.omega_ie_rps, lat_rad)
    }
}

/// Schuler angular frequency `ω_s = √(g/R0)` \[rad/s\] (docs/theory/error-analysis.md §"Periods").
pub fn schuler_frequency(g_mps2: f64, r0_m: f64) -> f64 {
    (g_mps2 / r0_m).sqrt()
}

/// Schuler period `T_s = 2π √(R0/g)` \[s\] (docs/theory/error-analysis.md §"Periods").
pub fn schuler_period_s(g_mps2: f64, r0_m: f64) -> f64 {
    TAU / schuler_frequency(g_mps2, r0_m)
}

/// Foucault angular frequency `ω_F = Ω sin L` \[rad/s\] (docs/theory/error-analysis.md §"Periods").
pub fn foucault_frequency(omega_ie_rps: f64, lat_rad: f64) -> f64 {
    omega_ie_rps * lat_rad.sin()
}

/// Foucault period `T_F = 2π/|Ω sin L|` \[s\] (docs/theory/error-analysis.md §"Periods"); infinite
/// on the equator.
pub fn foucault_period_s(omega_ie_rps: f64, lat_rad: f64) -> f64 {
    TAU / foucault_frequency(omega_ie_rps, lat_rad).abs()
}

/// Earth-rate ("24 h") period `2π/Ω` \[s\] (docs/theory/error-analysis.md §"Periods").
pub fn earth_rate_period_s(omega_ie_rps: f64) -> f64 {
    TAU / omega_ie_rps
}

#[cfg(test)]
mod tests {
    use super::*;
    const D2R: f64 = core::f64::consts::PI / 180.0;

    #[test]
    fn periods_match_spec_4_1() {
        let p = SchulerParams::P2;
        // ω_s = 1.24067e-3 rad/s, T_s = 5064.4 s = 84.41 min (docs/theory/error-analysis.md
        // §"Constants and units", rounded)
        assert!((p.omega_s() - 1.240_67e-3).abs() < 0.000_005e-3);
        // 5064.4 s is the rounded value; 2π√(6371000/9.80665) = 5064.33 s (84.41 min holds)
        assert!((p.schuler_period_s() - 5064.4).abs() < 0.1);
        assert!((p.schuler_period_s() / 60.0 - 84.41).abs() < 0.005);
        // T_F = 39.32 h at 37.5°, 33.85 h at 45°, 29.9 h at 53.1°
        let om = p.omega_ie_rps;
        assert!((foucault_period_s(om, 37.5 * D2R) / 3600.0 - 39.32).abs() < 0.005);
        assert!((foucault_period_s(om, 45.0 * D2R) / 3600.0 - 33.85).abs() < 0.005);
        assert!((foucault_period_s(om, 53.1 * D2R) / 3600.0 - 29.9).abs() < 0.05);
        // 2π/Ω = 86 164 s = 23.93 h
        assert!((earth_rate_period_s(om) - 86_164.0).abs() < 0.5);
        assert!((earth_rate_period_s(om) / 3600.0 - 23.93).abs() < 0.005);
        assert!(foucault_period_s(om, 0.0).is_infinite());
    }

    #[test]
    fn local_gravity_matches_spec_value() {
        let p = SchulerParams::with_local_gravity(
            &sdins_core::earth::EarthModel::WGS84,
            37.5 * D2R,
            0.0,
        );
        assert!((p.g_mps2 - 9.799_490_523_606_893).abs() < 1e-12);
        assert!((p.g_mps2 - SchulerParams::T9.g_mps2).abs() < 1e-5);
    }
}
