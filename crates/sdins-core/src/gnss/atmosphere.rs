//! Ionosphere and troposphere: the GPS broadcast (Klobuchar) ionosphere model, the
//! Saastamoinen zenith delay with a 1/sin(el) mapping, and the ionosphere-free
//! pseudorange combination (Groves 2nd ed. §9.3.2 "Ionosphere and Troposphere
//! Propagation Errors").

use super::{C_MPS, GAMMA_L1_L2, PI_GPS};

/// Broadcast ionosphere coefficients α0..α3 (s, s/semicircle, s/semicircle², s/semicircle³)
/// and β0..β3 (s, s/semicircle, …) of IS-GPS-200 §20.3.3.5.1.7 / §20.3.3.5.2.5.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KlobucharCoefficients {
    /// α0..α3
    pub alpha: [f64; 4],
    /// β0..β3
    pub beta: [f64; 4],
}

/// The default α/β used for files that carry none (ABPO's and 01.15n's navigation files
/// have no `ION ALPHA`/`ION BETA`): the broadcast set of 1 January 2004, the same set
/// RTKLIB 2.4.3 falls back to, so that single-frequency results compare like with like.
/// It is a mid-activity set; any single broadcast set removes only about half of the
/// ionospheric delay RMS (Klobuchar 1987), and a set from another epoch less.
pub const KLOBUCHAR_DEFAULT: KlobucharCoefficients = KlobucharCoefficients {
    alpha: [0.1118e-07, -0.7451e-08, -0.5961e-07, 0.1192e-06],
    beta: [0.1167e+06, -0.2294e+06, -0.1311e+06, 0.1049e+07],
};

/// Klobuchar L1 ionospheric delay \[s\] (IS-GPS-200 §20.3.3.5.2.5 and Figure 20-4): user
/// geodetic latitude/longitude \[rad\], elevation and azimuth of the satellite \[rad\], GPS
/// time of week \[s\]. Semicircles use the GPS π ([`PI_GPS`]). Returns 0 for a satellite
/// at or below the horizon. Multiply by c for metres; the L2 delay is γ times the L1 delay.
///
/// ψ = 0.0137/(E + 0.11) − 0.022; φ_i = φ_u + ψ cos A clamped to ±0.416;
/// λ_i = λ_u + ψ sin A / cos φ_i; φ_m = φ_i + 0.064 cos(λ_i − 1.617);
/// t = 4.32e4 λ_i + t_GPS mod 86 400; F = 1 + 16 (0.53 − E)³;
/// AMP = Σ α_n φ_m^n ≥ 0, PER = Σ β_n φ_m^n ≥ 72 000, x = 2π (t − 50 400)/PER;
/// T = F [5e-9 + AMP (1 − x²/2 + x⁴/24)] for |x| < 1.57, else F · 5e-9.
pub fn klobuchar_l1_delay_s(
    k: &KlobucharCoefficients,
    lat_rad: f64,
    lon_rad: f64,
    el_rad: f64,
    az_rad: f64,
    tow_s: f64,
) -> f64 {
    if el_rad <= 0.0 {
        return 0.0;
    }
    let e = el_rad / PI_GPS; // semicircles
    let psi = 0.0137 / (e + 0.11) - 0.022;
    let phi_i = (lat_rad / PI_GPS + psi * libm::cos(az_rad)).clamp(-0.416, 0.416);
    let lam_i = lon_rad / PI_GPS + psi * libm::sin(az_rad) / libm::cos(phi_i * PI_GPS);
    let phi_m = phi_i + 0.064 * libm::cos((lam_i - 1.617) * PI_GPS);
    let mut t = 4.32e4 * lam_i + tow_s;
    t -= libm::floor(t / 86_400.0) * 86_400.0;
    let f = 1.0 + 16.0 * libm::pow(0.53 - e, 3.0);
    let poly = |c: &[f64; 4]| c[0] + phi_m * (c[1] + phi_m * (c[2] + phi_m * c[3]));
    let amp = poly(&k.alpha).max(0.0);
    let per = poly(&k.beta).max(72_000.0);
    let x = 2.0 * PI_GPS * (t - 50_400.0) / per;
    if libm::fabs(x) < 1.57 {
        let x2 = x * x;
        f * (5e-9 + amp * (1.0 - x2 / 2.0 + x2 * x2 / 24.0))
    } else {
        f * 5e-9
    }
}

/// Zenith tropospheric delay components \[m\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TropoZenith {
    /// hydrostatic ("dry") zenith delay \[m\]
    pub hydrostatic_m: f64,
    /// wet zenith delay \[m\]
    pub wet_m: f64,
}

/// Relative humidity of the standard atmosphere used with Saastamoinen (0.7, as RTKLIB).
pub const STANDARD_HUMIDITY: f64 = 0.7;

/// Saastamoinen (1972) zenith delays with a standard atmosphere at height `h_m` above
/// the ellipsoid (no geoid model; heights clamped to [0, 10 km], the range of the
/// standard-atmosphere formulas used): P = 1013.25 (1 − 2.2557e-5 h)^5.2568 hPa,
/// T = 288.15 − 6.5e-3 h K, water-vapour pressure e = RH · 6.108 exp((17.15 T − 4684)/(T − 38.45))
/// hPa (Magnus-type saturation pressure, RH = 0.7);
/// ZHD = 0.0022768 P / (1 − 0.00266 cos 2φ − 0.00028 h_km),
/// ZWD = 0.002277 (1255/T + 0.05) e.
pub fn saastamoinen_zenith_m(lat_rad: f64, h_m: f64) -> TropoZenith {
    let h = h_m.clamp(0.0, 10_000.0);
    let p = 1013.25 * libm::pow(1.0 - 2.2557e-5 * h, 5.2568);
    let t = 288.15 - 6.5e-3 * h;
    let e = STANDARD_HUMIDITY * 6.108 * libm::exp((17.15 * t - 4684.0) / (t - 38.45));
    TropoZenith {
        hydrostatic_m: 0.0022768 * p
            / (1.0 - 0.00266 * libm::cos(2.0 * lat_rad) - 0.00028 * h / 1e3),
        wet_m: 0.002277 * (1255.0 / t + 0.05) * e,
    }
}

/// Slant tropospheric delay \[m\]: the Saastamoinen zenith delay times the flat-Earth
/// mapping 1/sin(el) (the form of Saastamoinen's own sec z term). Exact at the zenith;
/// against Niell's (1996) hydrostatic mapping (average coefficients at 45° latitude) it
/// is larger by 0.4 % at 30°, 1.7 % at 15°, 3.7 % at 10° (0.5 m of the 13 m slant delay
/// at sea level) and 13 % at 5°: use it with an elevation mask of 10° or more (the
/// numbers are computed in docs/theory/gnss.md). Returns 0 at or below the horizon.
pub fn saastamoinen_slant_m(lat_rad: f64, h_m: f64, el_rad: f64) -> f64 {
    if el_rad <= 0.0 {
        return 0.0;
    }
    let z = saastamoinen_zenith_m(lat_rad, h_m);
    (z.hydrostatic_m + z.wet_m) / libm::sin(el_rad)
}

/// Ionosphere-free pseudorange from P1 and P2 \[m\]:
/// `PR = (P2 − γ P1)/(1 − γ)`, γ = (f1/f2)² (IS-GPS-200 §20.3.3.3.3.3). The combination
/// references the satellite clock without T_GD and amplifies independent equal noise on
/// P1 and P2 by √(γ² + 1)/(γ − 1) ≈ 2.98.
pub fn iono_free_m(p1_m: f64, p2_m: f64) -> f64 {
    (p2_m - GAMMA_L1_L2 * p1_m) / (1.0 - GAMMA_L1_L2)
}

/// Noise amplification of the ionosphere-free combination for equal independent noise on
/// P1 and P2, √(γ² + 1)/(γ − 1).
pub fn iono_free_noise_factor() -> f64 {
    libm::sqrt(GAMMA_L1_L2 * GAMMA_L1_L2 + 1.0) / (GAMMA_L1_L2 - 1.0)
}

/// The Klobuchar delay in metres, c·T.
pub fn klobuchar_l1_delay_m(
    k: &KlobucharCoefficients,
    lat_rad: f64,
    lon_rad: f64,
    el_rad: f64,
    az_rad: f64,
    tow_s: f64,
) -> f64 {
    C_MPS * klobuchar_l1_delay_s(k, lat_rad, lon_rad, el_rad, az_rad, tow_s)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::gnss::{F_L1_HZ, F_L2_HZ};

    #[test]
    fn iono_free_removes_a_first_order_delay() {
        let (rho, i1) = (22_000_000.0, 7.3);
        let i2 = i1 * (F_L1_HZ / F_L2_HZ) * (F_L1_HZ / F_L2_HZ);
        assert!((iono_free_m(rho + i1, rho + i2) - rho).abs() < 1e-7);
        assert!((iono_free_noise_factor() - 2.978).abs() < 1e-3);
    }

    #[test]
    fn klobuchar_night_floor_zenith_and_obliquity() {
        let k = KLOBUCHAR_DEFAULT;
        // at local midnight (t = 0 at the pierce point) only the 5 ns floor remains, times F
        let el = core::f64::consts::FRAC_PI_2;
        let d = klobuchar_l1_delay_s(&k, 0.0, 0.0, el, 0.0, 0.0);
        let f = 1.0 + 16.0 * libm::pow(0.53 - 0.5, 3.0);
        assert!((d - 5e-9 * f).abs() < 1e-20, "{d}");
        // at 14:00 local time of the pierce point the cosine peaks: F (5 ns + AMP). Looking
        // east (A = 90°) the pierce point is at φ_i = 0, λ_i = ψ.
        let psi = 0.0137 / (0.5 + 0.11) - 0.022;
        let az = core::f64::consts::FRAC_PI_2;
        let phi_m = 0.064 * libm::cos((psi - 1.617) * PI_GPS);
        let amp = k.alpha[0] + phi_m * (k.alpha[1] + phi_m * (k.alpha[2] + phi_m * k.alpha[3]));
        let d = klobuchar_l1_delay_s(&k, 0.0, 0.0, el, az, 50_400.0 - 4.32e4 * psi);
        assert!((d - f * (5e-9 + amp)).abs() < 1e-20, "{d}");
        assert!(amp > 1e-9, "{amp}");
        // low elevations are larger (obliquity F reaches 1 + 16·0.53³ ≈ 3.4 at the horizon)
        let lo = klobuchar_l1_delay_s(&k, 0.0, 0.0, 0.1, 0.0, 50_400.0);
        assert!(lo > 2.5 * d && lo < 3.5 * d);
        assert_eq!(klobuchar_l1_delay_s(&k, 0.0, 0.0, -0.1, 0.0, 0.0), 0.0);
    }

    #[test]
    fn saastamoinen_sea_level_zenith() {
        // sea level, 45°: ZHD = 0.0022768·1013.25/1 ≈ 2.3070 m
        let z = saastamoinen_zenith_m(core::f64::consts::FRAC_PI_4, 0.0);
        assert!(
            (z.hydrostatic_m - 2.30697).abs() < 1e-4,
            "{}",
            z.hydrostatic_m
        );
        assert!(z.wet_m > 0.05 && z.wet_m < 0.2, "{}", z.wet_m);
        let s = saastamoinen_slant_m(0.7, 0.0, core::f64::consts::FRAC_PI_6);
        let zz = saastamoinen_zenith_m(0.7, 0.0);
        assert!((s - 2.0 * (zz.hydrostatic_m + zz.wet_m)).abs() < 1e-12);
        // the height clamp keeps wild heights (early LS iterations) finite
        assert!(saastamoinen_slant_m(0.7, 1e8, 0.5).is_finite());
        assert!(saastamoinen_slant_m(0.7, -1e8, 0.5).is_finite());
    }
}
