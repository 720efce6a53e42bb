//! Single-channel (short-term) position-error formulas: the corrected \[P2\] (1)–(3) and
//! their companion terms (docs/theory/error-analysis.md §"Single-channel formulas").
//!
//! The formulas ignore the Earth-rate (24 h) loop and the Foucault rotation; against the full
//! model (docs/theory/error-analysis.md §"Single-channel formulas") they are 1 % error at 1 h, 4.7
//! % at 2 h and 21 % at 4 h off (east gyro, 37.5°). **Validity policy (chosen here):** the checked
//! entry point
//! [`position_error`] returns [`ShortTermError::BeyondValidity`] for `t >`
//! [`VALIDITY_LIMIT_S`] (2 h), so no caller can silently use them for long times.
//! The raw formulas (`eq1_*`, `eq2_*`, `eq3_*`, ...) are public *without* the check
//! because the Schuler-share reconstruction (docs/theory/error-analysis.md §"The Schuler share")
//! deliberately evaluates them at any t; their doc comments say so.
//!
//! Units: R0 \[m\], t \[s\], ε \[rad/s\], δa \[m/s²\], results in metres. NED, convention G,
//! bias = measured − true.

use super::periods::SchulerParams;
use sdins_core::Vec3;

/// Validity limit of the single-channel formulas: 2 h (docs/theory/error-analysis.md
/// §"Single-channel formulas": t ≲ 2 h).
pub const VALIDITY_LIMIT_S: f64 = 7200.0;

/// Error of the checked short-term formulas.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ShortTermError {
    /// The time is beyond the validity of the single-channel formulas.
    #[error(
        "t = {t_s} s is beyond the {limit_s} s validity of the single-channel formulas \
         (docs/theory/error-analysis.md); use the stationary closed form"
    )]
    BeyondValidity {
        /// requested time \[s\]
        t_s: f64,
        /// validity limit \[s\]
        limit_s: f64,
    },
    /// The time is negative or not finite.
    #[error("time must be finite and non-negative, got {0} s")]
    InvalidTime(f64),
}

/// \[P2\] (1), corrected sign: north error from an east gyro bias ε_E,
/// `δp_N = −R0 ε_E (t − sin(ω_s t)/ω_s)`. No validity check.
pub fn eq1_east_gyro(eps_e: f64, t: f64, p: &SchulerParams) -> f64 {
    let ws = p.omega_s();
    -p.r0_m * eps_e * (t - (ws * t).sin() / ws)
}

/// \[P2\] (2): north error from a down gyro bias ε_D,
/// `δp_N = −R0 λ̇ cos L (t²/2 − (1 − cos ω_s t)/ω_s²) ε_D`, `λ̇ = Ω + v_E/(R0 cos L)`
/// (stationary: `λ̇ cos L = Ω cos L`). No validity check.
pub fn eq2_down_gyro(eps_d: f64, lat_rad: f64, v_e_mps: f64, t: f64, p: &SchulerParams) -> f64 {
    let ws = p.omega_s();
    let lam_dot_cos = p.omega_ie_rps * lat_rad.cos() + v_e_mps / p.r0_m;
    -p.r0_m * lam_dot_cos * (0.5 * t * t - (1.0 - (ws * t).cos()) / (ws * ws)) * eps_d
}

/// \[P2\] (3): north error from a north accelerometer bias,
/// `δp_N = (1 − cos ω_s t)/ω_s² · δa_N = R0 (δa_N/g)(1 − cos ω_s t)`. The same formula gives
/// the east error from δa_E (docs/theory/error-analysis.md §"Single-channel formulas" companion
/// term). No validity check.
pub fn eq3_accel(da: f64, t: f64, p: &SchulerParams) -> f64 {
    let ws = p.omega_s();
    da * (1.0 - (ws * t).cos()) / (ws * ws)
}

/// Companion term: east error from a north gyro bias, `δp_E = +R0 ε_N (t − sin ω_s t/ω_s)`.
/// No validity check.
pub fn east_from_north_gyro(eps_n: f64, t: f64, p: &SchulerParams) -> f64 {
    -eq1_east_gyro(eps_n, t, p)
}

/// Companion terms for initial tilt: `δp_N = −R0 φ_E0 (1 − cos ω_s t)` and
/// `δp_E = +R0 φ_N0 (1 − cos ω_s t)`; returns (north, east). No validity check.
pub fn from_initial_tilt(phi0: &Vec3, t: f64, p: &SchulerParams) -> (f64, f64) {
    let c = 1.0 - (p.omega_s() * t).cos();
    (-p.r0_m * phi0.y * c, p.r0_m * phi0.x * c)
}

/// Companion term for an initial horizontal velocity error, `δp = δv0 sin(ω_s t)/ω_s`
/// per channel; returns (north, east). No validity check.
pub fn from_initial_velocity(dv0_n: &Vec3, t: f64, p: &SchulerParams) -> (f64, f64) {
    let ws = p.omega_s();
    let s = (ws * t).sin() / ws;
    (dv0_n.x * s, dv0_n.y * s)
}

/// Inputs of the single-channel formulas (NED, SI units, convention G).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShortTermInputs {
    /// latitude L \[rad\]
    pub lat_rad: f64,
    /// east velocity for (2) \[m/s\] (0 when stationary)
    pub v_e_mps: f64,
    /// NED gyro bias ε \[rad/s\]
    pub eps_n: Vec3,
    /// NED accelerometer bias δa \[m/s²\]
    pub da_n: Vec3,
    /// initial attitude error φ0 \[rad\]
    pub phi0: Vec3,
    /// initial velocity error δv0 \[m/s\] (vertical ignored)
    pub dv0_n: Vec3,
}

/// The individual terms of the single-channel formulas at one time \[m\].
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ShortTermTerms {
    /// (1): δp_N from ε_E
    pub north_east_gyro: f64,
    /// (2): δp_N from ε_D
    pub north_down_gyro: f64,
    /// (3): δp_N from δa_N
    pub north_accel: f64,
    /// δp_N from φ_E0
    pub north_tilt: f64,
    /// δp_N from δv_N0
    pub north_velocity: f64,
    /// δp_E from ε_N
    pub east_north_gyro: f64,
    /// δp_E from δa_E
    pub east_accel: f64,
    /// δp_E from φ_N0
    pub east_tilt: f64,
    /// δp_E from δv_E0
    pub east_velocity: f64,
}

impl ShortTermTerms {
    /// Total north error \[m\].
    pub fn north(&self) -> f64 {
        self.north_east_gyro
            + self.north_down_gyro
            + self.north_accel
            + self.north_tilt
            + self.north_velocity
    }
    /// Total east error \[m\].
    pub fn east(&self) -> f64 {
        self.east_north_gyro + self.east_accel + self.east_tilt + self.east_velocity
    }
}

/// All single-channel terms at time `t`, **checked**: errors beyond [`VALIDITY_LIMIT_S`].
pub fn position_error(
    inp: &ShortTermInputs,
    t: f64,
    p: &SchulerParams,
) -> Result<ShortTermTerms, ShortTermError> {
    if !t.is_finite() || t < 0.0 {
        return Err(ShortTermError::InvalidTime(t));
    }
    if t > VALIDITY_LIMIT_S {
        return Err(ShortTermError::BeyondValidity {
            t_s: t,
            limit_s: VALIDITY_LIMIT_S,
        });
    }
    let (nt, et) = from_initial_tilt(&inp.phi0, t, p);
    let (nv, ev) = from_initial_velocity(&inp.dv0_n, t, p);
    Ok(ShortTermTerms {
        north_east_gyro: eq1_east_gyro(inp.eps_n.y, t, p),
        north_down_gyro: eq2_down_gyro(inp.eps_n.z, inp.lat_rad, inp.v_e_mps, t, p),
        north_accel: eq3_accel(inp.da_n.x, t, p),
        north_tilt: nt,
        north_velocity: nv,
        east_north_gyro: east_from_north_gyro(inp.eps_n.x, t, p),
        east_accel: eq3_accel(inp.da_n.y, t, p),
        east_tilt: et,
        east_velocity: ev,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::super::{DEG_PER_HOUR, MICRO_G};
    use super::*;
    const D2R: f64 = core::f64::consts::PI / 180.0;

    #[test]
    fn key_magnitudes_spec_4_2() {
        let p = SchulerParams::P2;
        // Schuler amplitude of a gyro bias: R0 ε/ω_s = 249 m per 0.01 °/h
        let amp = p.r0_m * 0.01 * DEG_PER_HOUR / p.omega_s();
        assert!((amp - 249.0).abs() < 0.5, "{amp}");
        // accelerometer: peak 2 R0 δa/g = 382 m per 30 μg, reached at T_s/2
        let peak = eq3_accel(30.0 * MICRO_G, p.schuler_period_s() / 2.0, &p);
        assert!((peak - 382.0).abs() < 0.5, "{peak}");
        assert!((peak - 2.0 * p.r0_m * 30.0 * MICRO_G / p.g_mps2).abs() < 1e-9);
    }

    #[test]
    fn eq1_values_in_spec_table() {
        // docs/theory/error-analysis.md §"Single-channel formulas" validity table, column (1):
        // −1353 m at 1 h, −2106 m at 2 h, −4656 m at 4 h, −26.6 km at 24 h (0.01 °/h east gyro).
        // The table compares with the T9 runs, so it uses g = 9.79949: with g = 9.80665 the 4 h
        // value is −4655.1 m.
        let p = SchulerParams::T9;
        let e = 0.01 * DEG_PER_HOUR;
        for (h, want, tol) in [
            (1.0, -1353.0, 1.0),
            (2.0, -2106.0, 1.0),
            (4.0, -4656.0, 1.0),
            (24.0, -26_600.0, 50.0),
        ] {
            let got = eq1_east_gyro(e, h * 3600.0, &p);
            assert!((got - want).abs() <= tol, "{h} h: {got} vs {want}");
        }
    }

    #[test]
    fn validity_limit_enforced() {
        let p = SchulerParams::P2;
        let inp = ShortTermInputs {
            lat_rad: 37.5 * D2R,
            eps_n: Vec3::new(0.0, 1e-7, 0.0),
            ..Default::default()
        };
        assert!(position_error(&inp, VALIDITY_LIMIT_S, &p).is_ok());
        assert!(matches!(
            position_error(&inp, VALIDITY_LIMIT_S + 1.0, &p),
            Err(ShortTermError::BeyondValidity { .. })
        ));
        assert!(matches!(
            position_error(&inp, -1.0, &p),
            Err(ShortTermError::InvalidTime(_))
        ));
        assert!(matches!(
            position_error(&inp, f64::NAN, &p),
            Err(ShortTermError::InvalidTime(_))
        ));
    }

    #[test]
    fn small_time_limits() {
        // For ω_s t ≪ 1: (1) → −R0 ε_E ω_s² t³/6 = −g ε_E t³/6; (3) → δa t²/2;
        // (2) → −R0 Ω cosL ε_D ω_s² t⁴/24. Relative truncation O((ω_s t)²/20) ≈ 8e-6 at t = 10 s.
        let p = SchulerParams::P2;
        let t = 10.0;
        let (e, a) = (1e-6, 1e-3);
        let ws2 = p.omega_s().powi(2);
        let rel = |x: f64, y: f64| ((x - y) / y).abs();
        assert!(rel(eq1_east_gyro(e, t, &p), -p.g_mps2 * e * t.powi(3) / 6.0) < 1e-4);
        assert!(rel(eq3_accel(a, t, &p), a * t * t / 2.0) < 1e-4);
        let l = 37.5 * D2R;
        let want2 = -p.r0_m * p.omega_ie_rps * l.cos() * e * ws2 * t.powi(4) / 24.0;
        assert!(rel(eq2_down_gyro(e, l, 0.0, t, &p), want2) < 1e-3);
        let terms = position_error(
            &ShortTermInputs {
                lat_rad: l,
                eps_n: Vec3::new(e, e, e),
                da_n: Vec3::new(a, a, 0.0),
                ..Default::default()
            },
            t,
            &p,
        )
        .unwrap();
        assert!((terms.east() - (terms.east_north_gyro + terms.east_accel)).abs() < 1e-12);
        assert!(rel(terms.east_north_gyro, p.g_mps2 * e * t.powi(3) / 6.0) < 1e-4);
    }
}
