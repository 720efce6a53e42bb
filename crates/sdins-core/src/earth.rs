//! Earth model (docs/theory/mechanizations.md §"Earth model"): ellipsoid radii, normal gravity,
//! earth rate, transport rate, geodetic ↔ ECEF and `C_e^n`.
//!
//! The model is a value ([`EarthModel`]) so that the WGS-84 default, the PSINS constant
//! set (for PSINS data) and a flat, non-rotating model (for flat-NED fixtures) can be
//! selected per run. Truth and navigation must use the same model.

use crate::math::{Mat3, Vec3};

/// Normal-gravity formula of an [`EarthModel`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Gravity {
    /// Somigliana closed form with the NIMA TR8350.2 eq. 4-3 height series:
    /// `γ(L) = γ_e (1 + k sin²L)/√(1 − e² sin²L)`,
    /// `g = γ(L)[1 − (2/a)(1 + f + m − 2f sin²L) h + (3/a²) h²]`.
    Somigliana {
        /// equatorial normal gravity γ_e \[m/s²\]
        gamma_e: f64,
        /// Somigliana constant k
        k: f64,
        /// m = ω²a²b/GM
        m: f64,
    },
    /// Somigliana on the ellipsoid with only the linear free-air factor:
    /// `g = γ(L)(1 − 2h/a)` (drops the flattening, centrifugal and h² terms of the
    /// TR8350.2 series; used by simpler INS codes, e.g. pyins).
    SomiglianaLinear {
        /// equatorial normal gravity γ_e \[m/s²\]
        gamma_e: f64,
        /// Somigliana constant k
        k: f64,
    },
    /// PSINS: `g = g0 (1 + c2 sin²L + c4 sin⁴L) − dh · h`.
    Psins {
        /// g0 \[m/s²\]
        g0: f64,
        /// coefficient of sin²L
        c2: f64,
        /// coefficient of sin⁴L
        c4: f64,
        /// height gradient \[1/s²\]
        dh: f64,
    },
    /// Constant magnitude (flat-earth fixtures).
    Constant {
        /// g \[m/s²\]
        g_mps2: f64,
    },
}

/// An earth model: ellipsoid, rotation rate and gravity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthModel {
    /// semi-major axis a \[m\]
    pub a_m: f64,
    /// flattening f
    pub f: f64,
    /// first eccentricity squared e² = f(2 − f)
    pub e2: f64,
    /// earth rotation rate Ω_e \[rad/s\]
    pub omega_ie_rps: f64,
    /// gravity model
    pub gravity: Gravity,
    /// whether the navigation frame turns with the vehicle's motion over the ellipsoid
    /// (transport rate ω_en). `false` only for the flat model.
    pub transport: bool,
}

/// Radii of curvature at a latitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Radii {
    /// meridian radius R_M \[m\]
    pub r_m_m: f64,
    /// prime-vertical radius R_N \[m\]
    pub r_n_m: f64,
}

/// Latitude-dependent earth quantities computed from one `sin/cos(L)` and one square
/// root (the hot path of the mechanizations).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalEarth {
    /// sin L
    pub sin_lat: f64,
    /// cos L
    pub cos_lat: f64,
    /// meridian radius R_M \[m\]
    pub r_m_m: f64,
    /// prime-vertical radius R_N \[m\]
    pub r_n_m: f64,
    /// normal gravity g(L, h) \[m/s²\]
    pub g_mps2: f64,
}

/// `sin(a + d)`, `cos(a + d)` from `sin a`, `cos a` for a small step `d` (|d| < 1e-3 rad:
/// series to d⁶, truncation below 1e-24; larger steps fall back to libm).
#[inline]
pub fn sin_cos_shift(s: f64, c: f64, d: f64) -> (f64, f64) {
    if libm::fabs(d) >= 1e-3 {
        let (sd, cd) = (libm::sin(d), libm::cos(d));
        return (s * cd + c * sd, c * cd - s * sd);
    }
    let d2 = d * d;
    let sd = d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0));
    let cdm1 = -d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0)); // cos d − 1
    (s + (s * cdm1 + c * sd), c + (c * cdm1 - s * sd))
}

/// `sin(a + d)`, `cos(a + d)` from `sin a`, `cos a` for the small steps of one navigation
/// update: |d| < 1e-4 rad by the series `sin d = d − d³/6`, `cos d − 1 = −d²/2 + d⁴/24`
/// (first omitted terms d⁵/120 < 8.4e-23 and d⁶/720 < 1.4e-27, far below the rounding of
/// the sums, 1.1e-16), larger steps by [`sin_cos_shift`].
///
/// Below |d| = 1e-6 rad (the latitude steps of one update: 1e-7 rad at Mach 1 and 6 ms)
/// the series stop at `sin d = d`, `cos d − 1 = −d²/2` (omitted d³/6 < 1.7e-19, 1/600 of
/// the rounding of a sine near 1, and d⁴/24 < 4.2e-26).
#[inline(always)]
pub fn sin_cos_step(s: f64, c: f64, d: f64) -> (f64, f64) {
    let ad = libm::fabs(d);
    if ad < 1e-6 {
        let half_d2 = 0.5 * d * d;
        (s + (c * d - s * half_d2), c - (s * d + c * half_d2))
    } else if ad < 1e-4 {
        sin_cos_series4(s, c, d)
    } else {
        sin_cos_shift(s, c, d)
    }
}

/// The series of [`sin_cos_step`] (|d| < 1e-4 rad).
#[inline(always)]
fn sin_cos_series4(s: f64, c: f64, d: f64) -> (f64, f64) {
    let d2 = d * d;
    let sd = d - d * d2 * (1.0 / 6.0);
    let cdm1 = d2 * (d2 * (1.0 / 24.0) - 0.5); // cos d − 1
    (s + (s * cdm1 + c * sd), c + (c * cdm1 - s * sd))
}

/// `sin`/`cos` of a slowly varying angle `base + x` without a libm call per evaluation:
/// libm evaluates a reference angle `base + x_ref` once, and every later `x` within
/// 1e-4 rad of it is one angle addition from the reference, with the series of
/// [`sin_cos_step`] for the difference (truncation below 1e-22).
///
/// Every value is one shift away from a libm value, so the rounding does not accumulate
/// along a trajectory (as it would if each value were shifted from the previous one):
/// the error is that of libm plus the final additions of the shift, ≈ 1 ulp. When `x`
/// leaves the window, the reference moves to `x` (one `sincos`). The local-level
/// mechanization tracks half the latitude and half the transport angle of S1 eq. (32); at
/// Mach 1 each needs a new reference about once a second.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SinCosTrack {
    base: f64,
    x_ref: f64,
    s_ref: f64,
    c_ref: f64,
}

impl SinCosTrack {
    /// Half-width of the window around the reference \[rad\].
    pub const WINDOW_RAD: f64 = 1e-4;

    /// Track `base + x`, with the reference at `x`.
    pub fn new(base: f64, x: f64) -> Self {
        let (s_ref, c_ref) = libm::sincos(base + x);
        Self {
            base,
            x_ref: x,
            s_ref,
            c_ref,
        }
    }

    /// `(sin, cos)` of the reference angle (libm's values).
    #[inline]
    pub fn sin_cos_ref(&self) -> (f64, f64) {
        (self.s_ref, self.c_ref)
    }

    /// `(sin, cos)` of `base + x`; moves the reference to `x` (one `sincos`) when
    /// `|x − x_ref| ≥ 1e-4` rad (or `x` is not finite).
    #[inline]
    pub fn sin_cos(&mut self, x: f64) -> (f64, f64) {
        let d = x - self.x_ref;
        if libm::fabs(d) < Self::WINDOW_RAD {
            sin_cos_series4(self.s_ref, self.c_ref, d)
        } else {
            *self = Self::new(self.base, x);
            (self.s_ref, self.c_ref)
        }
    }
}

/// The latitude-independent factors of [`EarthModel::local_sc`] and
/// [`EarthModel::radii_sin`] (`1 − e²`, `2/a`, `1 + f + m`, `2f`, `3/a²`), computed once:
/// the mechanizations keep one and evaluate the earth terms of every update without
/// recomputing them. Each factor is the same expression as in the formula, so the results
/// are the same bits as [`EarthModel::local_sc`]'s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthCoeffs {
    a_m: f64,
    e2: f64,
    one_minus_e2: f64,
    gravity: GravityCoeffs,
}

/// [`Gravity`] with its constant factors evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
enum GravityCoeffs {
    /// `γ_e (1 + k s²)/w · (1 − (2/a)(1 + f + m − 2f s²) h + (3/a²) h²)`
    Somigliana {
        gamma_e: f64,
        k: f64,
        two_over_a: f64,
        one_f_m: f64,
        two_f: f64,
        three_over_a2: f64,
    },
    /// `γ_e (1 + k s²)/w · (1 − 2h/a)`
    SomiglianaLinear { gamma_e: f64, k: f64 },
    /// `g0 (1 + c2 s² + c4 s⁴) − dh h`
    Psins { g0: f64, c2: f64, c4: f64, dh: f64 },
    /// constant
    Constant { g_mps2: f64 },
}

impl EarthCoeffs {
    /// Radii from `sin L` (no trigonometry): see [`EarthModel::radii`].
    #[inline(always)]
    pub fn radii_sin(&self, sin_lat: f64) -> Radii {
        let w2 = 1.0 - self.e2 * sin_lat * sin_lat;
        let r_n_m = self.a_m / libm::sqrt(w2);
        Radii {
            r_m_m: r_n_m * self.one_minus_e2 / w2,
            r_n_m,
        }
    }

    /// [`LocalEarth`] from `sin L`, `cos L` and the height.
    #[inline(always)]
    pub fn local_sc(&self, sin_lat: f64, cos_lat: f64, h_m: f64) -> LocalEarth {
        let s2 = sin_lat * sin_lat;
        let w2 = 1.0 - self.e2 * s2;
        let w = libm::sqrt(w2);
        let r_n_m = self.a_m / w;
        // the WGS-84 default first (one test and branch, not a jump table)
        let g_mps2 = if let GravityCoeffs::Somigliana {
            gamma_e,
            k,
            two_over_a,
            one_f_m,
            two_f,
            three_over_a2,
        } = self.gravity
        {
            let gamma = gamma_e * (1.0 + k * s2) / w;
            gamma * (1.0 - two_over_a * (one_f_m - two_f * s2) * h_m + three_over_a2 * h_m * h_m)
        } else {
            match self.gravity {
                GravityCoeffs::SomiglianaLinear { gamma_e, k } => {
                    gamma_e * (1.0 + k * s2) / w * (1.0 - 2.0 * h_m / self.a_m)
                }
                GravityCoeffs::Psins { g0, c2, c4, dh } => {
                    g0 * (1.0 + c2 * s2 + c4 * s2 * s2) - dh * h_m
                }
                GravityCoeffs::Constant { g_mps2 } => g_mps2,
                GravityCoeffs::Somigliana { .. } => f64::NAN, // handled above
            }
        };
        LocalEarth {
            sin_lat,
            cos_lat,
            r_m_m: r_n_m * self.one_minus_e2 / w2,
            r_n_m,
            g_mps2,
        }
    }
}

impl EarthModel {
    /// The constant factors of the latitude-dependent terms ([`EarthCoeffs`]).
    #[inline(always)]
    pub fn coeffs(&self) -> EarthCoeffs {
        let a = self.a_m;
        EarthCoeffs {
            a_m: a,
            e2: self.e2,
            one_minus_e2: 1.0 - self.e2,
            gravity: match self.gravity {
                Gravity::Somigliana { gamma_e, k, m } => GravityCoeffs::Somigliana {
                    gamma_e,
                    k,
                    two_over_a: 2.0 / a,
                    one_f_m: 1.0 + self.f + m,
                    two_f: 2.0 * self.f,
                    three_over_a2: 3.0 / (a * a),
                },
                Gravity::SomiglianaLinear { gamma_e, k } => {
                    GravityCoeffs::SomiglianaLinear { gamma_e, k }
                }
                Gravity::Psins { g0, c2, c4, dh } => GravityCoeffs::Psins { g0, c2, c4, dh },
                Gravity::Constant { g_mps2 } => GravityCoeffs::Constant { g_mps2 },
            },
        }
    }

    /// Radii from `sin L` (no trigonometry): see [`EarthModel::radii`].
    #[inline]
    pub fn radii_sin(&self, sin_lat: f64) -> Radii {
        self.coeffs().radii_sin(sin_lat)
    }

    /// [`LocalEarth`] at latitude `lat_rad` and height `h_m`.
    #[inline]
    pub fn local(&self, lat_rad: f64, h_m: f64) -> LocalEarth {
        // one shared argument reduction; same kernels, same values as sin and cos
        let (s, c) = libm::sincos(lat_rad);
        self.local_sc(s, c, h_m)
    }

    /// [`LocalEarth`] from precomputed `sin L`, `cos L`.
    #[inline]
    pub fn local_sc(&self, sin_lat: f64, cos_lat: f64, h_m: f64) -> LocalEarth {
        self.coeffs().local_sc(sin_lat, cos_lat, h_m)
    }

    /// Earth rate in NED from a [`LocalEarth`].
    #[inline]
    pub fn omega_ie_n_local(&self, le: &LocalEarth) -> Vec3 {
        Vec3::new(
            self.omega_ie_rps * le.cos_lat,
            0.0,
            -self.omega_ie_rps * le.sin_lat,
        )
    }

    /// Transport rate in NED from a [`LocalEarth`] (zero for the flat model).
    #[inline]
    pub fn omega_en_n_local(&self, le: &LocalEarth, h_m: f64, v_n_mps: &Vec3) -> Vec3 {
        if !self.transport {
            return Vec3::zeros();
        }
        let rn = le.r_n_m + h_m;
        Vec3::new(
            v_n_mps.y / rn,
            -v_n_mps.x / (le.r_m_m + h_m),
            -v_n_mps.y * (le.sin_lat / le.cos_lat) / rn,
        )
    }

    /// WGS-84 (docs/theory/mechanizations.md §"Earth model"): a = 6378137, f = 1/298.257223563, Ω =
    /// 7.292115e-5 rad/s, Somigliana gravity with the TR8350.2 height series.
    pub const WGS84: EarthModel = EarthModel {
        a_m: 6_378_137.0,
        f: 1.0 / 298.257_223_563,
        e2: (1.0 / 298.257_223_563) * (2.0 - 1.0 / 298.257_223_563),
        omega_ie_rps: 7.292_115e-5,
        gravity: Gravity::Somigliana {
            gamma_e: 9.780_325_335_9,
            k: 1.931_852_652_41e-3,
            m: 3.449_786_506_84e-3,
        },
        transport: true,
    };

    /// WGS-84 with the linear free-air gravity `γ(L)(1 − 2h/a)`
    /// ([`Gravity::SomiglianaLinear`]), for data generated with that model (the
    /// pyins comparison of docs/performance.md): the vertical channel is unstable, so a
    /// 1e-5 m/s² gravity mismatch alone grows to hundreds of metres of height in an hour.
    pub const WGS84_LINEAR_G: EarthModel = EarthModel {
        gravity: Gravity::SomiglianaLinear {
            gamma_e: 9.780_325_335_9,
            k: 1.931_852_652_41e-3,
        },
        ..EarthModel::WGS84
    };

    /// PSINS toolbox constant set: Re = 6378137, f = 1/298.257, wie = 7.2921151467e-5,
    /// g = 9.7803267714 (1 + 5.27094e-3 sin²L + 2.32718e-5 sin⁴L) − 3.086e-6 h.
    pub const PSINS: EarthModel = EarthModel {
        a_m: 6_378_137.0,
        f: 1.0 / 298.257,
        e2: (1.0 / 298.257) * (2.0 - 1.0 / 298.257),
        omega_ie_rps: 7.292_115_146_7e-5,
        gravity: Gravity::Psins {
            g0: 9.780_326_771_4,
            c2: 5.270_94e-3,
            c4: 2.327_18e-5,
            dh: 3.086e-6,
        },
        transport: true,
    };

    /// Flat, non-rotating earth with constant gravity `g_mps2` (e.g. 9.80665). Positions are
    /// still carried as latitude/longitude on the WGS-84 ellipsoid, but the navigation frame
    /// neither rotates with the earth nor with the vehicle's motion.
    pub const fn flat(g_mps2: f64) -> EarthModel {
        EarthModel {
            a_m: 6_378_137.0,
            f: 1.0 / 298.257_223_563,
            e2: (1.0 / 298.257_223_563) * (2.0 - 1.0 / 298.257_223_563),
            omega_ie_rps: 0.0,
            gravity: Gravity::Constant { g_mps2 },
            transport: false,
        }
    }

    /// Meridian and prime-vertical radii:
    /// `R_N = a/√(1 − e² sin²L)`, `R_M = a(1 − e²)/(1 − e² sin²L)^{3/2}`.
    #[inline]
    pub fn radii(&self, lat_rad: f64) -> Radii {
        let s = libm::sin(lat_rad);
        let w2 = 1.0 - self.e2 * s * s;
        let w = libm::sqrt(w2);
        let r_n_m = self.a_m / w;
        Radii {
            r_m_m: r_n_m * (1.0 - self.e2) / w2,
            r_n_m,
        }
    }

    /// Magnitude of normal gravity g(L, h) \[m/s²\] (positive down).
    #[inline]
    pub fn gravity(&self, lat_rad: f64, h_m: f64) -> f64 {
        let s = libm::sin(lat_rad);
        let s2 = s * s;
        match self.gravity {
            Gravity::Somigliana { gamma_e, k, m } => {
                let gamma = gamma_e * (1.0 + k * s2) / libm::sqrt(1.0 - self.e2 * s2);
                let a = self.a_m;
                gamma
                    * (1.0 - (2.0 / a) * (1.0 + self.f + m - 2.0 * self.f * s2) * h_m
                        + (3.0 / (a * a)) * h_m * h_m)
            }
            Gravity::SomiglianaLinear { gamma_e, k } => {
                gamma_e * (1.0 + k * s2) / libm::sqrt(1.0 - self.e2 * s2)
                    * (1.0 - 2.0 * h_m / self.a_m)
            }
            Gravity::Psins { g0, c2, c4, dh } => g0 * (1.0 + c2 * s2 + c4 * s2 * s2) - dh * h_m,
            Gravity::Constant { g_mps2 } => g_mps2,
        }
    }

    /// Gravity vector in NED, `g_n = [0, 0, g(L, h)]` (plumb bob, no deflection).
    #[inline]
    pub fn gravity_n(&self, lat_rad: f64, h_m: f64) -> Vec3 {
        Vec3::new(0.0, 0.0, self.gravity(lat_rad, h_m))
    }

    /// Earth rate in NED: `ω_ie^n = Ω [cos L, 0, −sin L]`.
    #[inline]
    pub fn omega_ie_n(&self, lat_rad: f64) -> Vec3 {
        Vec3::new(
            self.omega_ie_rps * libm::cos(lat_rad),
            0.0,
            -self.omega_ie_rps * libm::sin(lat_rad),
        )
    }

    /// Transport rate in NED:
    /// `ω_en^n = [v_E/(R_N+h), −v_N/(R_M+h), −v_E tan L/(R_N+h)]` (zero for the flat model).
    #[inline]
    pub fn omega_en_n(&self, lat_rad: f64, h_m: f64, v_n_mps: &Vec3) -> Vec3 {
        if !self.transport {
            return Vec3::zeros();
        }
        let r = self.radii(lat_rad);
        let rn = r.r_n_m + h_m;
        Vec3::new(
            v_n_mps.y / rn,
            -v_n_mps.x / (r.r_m_m + h_m),
            -v_n_mps.y * libm::tan(lat_rad) / rn,
        )
    }

    /// ECEF position of a geodetic point:
    /// `r^e = [(R_N+h) cosL cosλ, (R_N+h) cosL sinλ, (R_N(1−e²)+h) sinL]`.
    pub fn ecef_from_geodetic(&self, lat_rad: f64, lon_rad: f64, h_m: f64) -> Vec3 {
        let rn = self.radii(lat_rad).r_n_m;
        let (sl, cl) = (libm::sin(lat_rad), libm::cos(lat_rad));
        let (so, co) = (libm::sin(lon_rad), libm::cos(lon_rad));
        Vec3::new(
            (rn + h_m) * cl * co,
            (rn + h_m) * cl * so,
            (rn * (1.0 - self.e2) + h_m) * sl,
        )
    }

    /// Geodetic (lat, lon, h) of an ECEF position, by the fixed iteration of
    /// docs/theory/mechanizations.md §"Earth model" (10 iterations from `L = atan2(z, p(1 − e²))`).
    /// Near the poles (p below 1 mm) the height is taken from |z|.
    pub fn geodetic_from_ecef(&self, r_e: &Vec3) -> (f64, f64, f64) {
        let lon = libm::atan2(r_e.y, r_e.x);
        let p = libm::sqrt(r_e.x * r_e.x + r_e.y * r_e.y);
        if p < 1e-3 {
            let lat = if r_e.z >= 0.0 {
                core::f64::consts::FRAC_PI_2
            } else {
                -core::f64::consts::FRAC_PI_2
            };
            let b = self.a_m * libm::sqrt(1.0 - self.e2);
            return (lat, lon, libm::fabs(r_e.z) - b);
        }
        let mut lat = libm::atan2(r_e.z, p * (1.0 - self.e2));
        for _ in 0..10 {
            let rn = self.radii(lat).r_n_m;
            let h = p / libm::cos(lat) - rn;
            lat = libm::atan2(r_e.z, p * (1.0 - self.e2 * rn / (rn + h)));
        }
        // Well-conditioned at every latitude: h = p cosL + z sinL − a√(1 − e² sin²L).
        let (sl, cl) = (libm::sin(lat), libm::cos(lat));
        let h = p * cl + r_e.z * sl - self.a_m * libm::sqrt(1.0 - self.e2 * sl * sl);
        (lat, lon, h)
    }

    /// `C_e^n(L, λ)`, ECEF to NED (docs/theory/mechanizations.md §"Earth model").
    pub fn c_e_n(lat_rad: f64, lon_rad: f64) -> Mat3 {
        let (sl, cl) = (libm::sin(lat_rad), libm::cos(lat_rad));
        let (so, co) = (libm::sin(lon_rad), libm::cos(lon_rad));
        Mat3::new(
            -sl * co,
            -sl * so,
            cl,
            -so,
            co,
            0.0,
            -cl * co,
            -cl * so,
            -sl,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::FRAC_PI_4;

    const D2R: f64 = core::f64::consts::PI / 180.0;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn linear_free_air_gravity() {
        let (e, w) = (EarthModel::WGS84_LINEAR_G, EarthModel::WGS84);
        let lat = 0.96;
        // same on the ellipsoid, 1 − 2h/a above it
        assert!((e.gravity(lat, 0.0) - w.gravity(lat, 0.0)).abs() < 1e-15);
        let h = 1500.0;
        let want = w.gravity(lat, 0.0) * (1.0 - 2.0 * h / 6_378_137.0);
        assert!((e.gravity(lat, h) - want).abs() < 1e-14);
        // the TR8350.2 series is ~9e-6 m/s² weaker at 1.5 km, 55°N
        assert!((e.gravity(lat, h) - w.gravity(lat, h) - 9.0e-6).abs() < 0.5e-6);
    }

    #[test]
    fn wgs84_radii_published_values() {
        // NIMA TR8350.2 Table 3.1 / 3.3: b = 6356752.3142 m; R_M(0) = b²/a, R_M(90°) = a²/b.
        let e = EarthModel::WGS84;
        let b = 6_356_752.314_245_18_f64;
        let eq = e.radii(0.0);
        let pole = e.radii(90.0 * D2R);
        assert!(rel(eq.r_n_m, 6_378_137.0) < 1e-12);
        assert!(rel(eq.r_m_m, b * b / 6_378_137.0) < 1e-9);
        assert!(rel(pole.r_n_m, 6_378_137.0 * 6_378_137.0 / b) < 1e-9);
        assert!(rel(pole.r_m_m, 6_378_137.0 * 6_378_137.0 / b) < 1e-9);
        // 45°: R_N = a/√(1 − e²/2)
        let r45 = e.radii(FRAC_PI_4);
        assert!(rel(r45.r_n_m, 6_378_137.0 / (1.0 - e.e2 / 2.0).sqrt()) < 1e-12);
        assert!(rel(r45.r_n_m, 6_388_838.290_121_148) < 1e-9);
    }

    #[test]
    fn wgs84_gravity_published_values() {
        // TR8350.2: γ_e = 9.7803253359, γ_p = 9.8321849378 m/s²; docs/validation.md
        // §"stationary 90 min" value at 37.5°.
        let e = EarthModel::WGS84;
        assert!(rel(e.gravity(0.0, 0.0), 9.780_325_335_9) < 1e-9);
        assert!(rel(e.gravity(90.0 * D2R, 0.0), 9.832_184_937_8) < 1e-9);
        assert!(rel(e.gravity(37.5 * D2R, 0.0), 9.799_490_523_606_893) < 1e-12);
        // 45°: evaluated independently with
        // python3 -c "import math;a=6378137.0;f=1/298.257223563;e2=f*(2-f);s2=0.5;
        //   print(repr(9.7803253359*(1+1.93185265241e-3*s2)/math.sqrt(1-e2*s2)))"
        // -> 9.806197769373238
        assert!(rel(e.gravity(FRAC_PI_4, 0.0), 9.806_197_769_373_238) < 1e-12);
        // Height term: dg/dh ≈ −3.086e-6 /s² near the surface.
        let dgdh = (e.gravity(FRAC_PI_4, 100.0) - e.gravity(FRAC_PI_4, 0.0)) / 100.0;
        assert!((dgdh + 3.086e-6).abs() < 0.005e-6);
    }

    #[test]
    fn ecef_round_trip_all_heights() {
        // ECEF → geodetic → ECEF. The f64 floor is the quantisation of the latitude itself
        // (one ulp of a latitude near 1 rad is 2.2e-16 rad = 1.4e-9 m on the ground) plus the
        // rounding of r (ulp of 6.4e6 m = 9.3e-10 m): a flat 1e-9 m bound holds only where the
        // latitude ulp is small, so the bound is that floor, evaluated per point.
        let e = EarthModel::WGS84;
        for &lat in &[-89.9, -60.0, -1.0, 0.0, 37.5, 80.0, 89.99] {
            for &h in &[-1000.0, 0.0, 380.0, 10_000.0, 100_000.0] {
                for &lon in &[-179.5, 0.0, 127.0] {
                    let (lat_r, lon_r) = (lat * D2R, lon * D2R);
                    let r = e.ecef_from_geodetic(lat_r, lon_r, h);
                    let (l2, o2, h2) = e.geodetic_from_ecef(&r);
                    let r2 = e.ecef_from_geodetic(l2, o2, h2);
                    let err = (r2 - r).abs().max();
                    let ulp = |x: f64| f64::EPSILON * x.abs().max(f64::MIN_POSITIVE);
                    let floor = ulp(lat_r) * (e.radii(lat_r).r_m_m + h) + 2.0 * ulp(r.norm());
                    assert!(err <= floor.max(1e-9), "lat {lat} lon {lon} h {h}: {err}");
                    // geodetic → ECEF → geodetic: latitude within 2 ulp; height within a few
                    // ulp of |r| (it is a difference of numbers of size 6.4e6 m)
                    assert!((l2 - lat_r).abs() <= 2.0 * f64::EPSILON * lat_r.abs().max(1e-3));
                    assert!((h2 - h).abs() <= 4.0 * ulp(r.norm()), "h {h}: {}", h2 - h);
                }
            }
        }
    }

    #[test]
    fn c_e_n_maps_up_to_minus_down() {
        let (lat, lon) = (0.6, 2.2);
        let c = EarthModel::c_e_n(lat, lon);
        assert!((c * c.transpose() - Mat3::identity()).abs().max() < 1e-15);
        // The ellipsoid normal (geodetic up) in ECEF maps to [0, 0, −1].
        let up = Vec3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin());
        assert!((c * up - Vec3::new(0.0, 0.0, -1.0)).norm() < 1e-15);
        // Earth rate ω_ie^e = [0,0,Ω] maps to ω_ie^n.
        let e = EarthModel::WGS84;
        let w = c * Vec3::new(0.0, 0.0, e.omega_ie_rps);
        assert!((w - e.omega_ie_n(lat)).norm() < 1e-20);
    }

    #[test]
    fn hoisted_coefficients_give_the_same_bits() {
        // EarthCoeffs::local_sc against the formula written out with the factors inline
        for e in [
            EarthModel::WGS84,
            EarthModel::PSINS,
            EarthModel::WGS84_LINEAR_G,
            EarthModel::flat(9.80665),
        ] {
            for &(lat, h) in &[(0.3_f64, 100.0), (-1.2, 5000.0), (1.55, -300.0)] {
                let (s, c) = (libm::sin(lat), libm::cos(lat));
                let le = e.coeffs().local_sc(s, c, h);
                let s2 = s * s;
                let w2 = 1.0 - e.e2 * s2;
                let w = libm::sqrt(w2);
                let r_n = e.a_m / w;
                let g = match e.gravity {
                    Gravity::Somigliana { gamma_e, k, m } => {
                        let a = e.a_m;
                        gamma_e * (1.0 + k * s2) / w
                            * (1.0 - (2.0 / a) * (1.0 + e.f + m - 2.0 * e.f * s2) * h
                                + (3.0 / (a * a)) * h * h)
                    }
                    Gravity::SomiglianaLinear { gamma_e, k } => {
                        gamma_e * (1.0 + k * s2) / w * (1.0 - 2.0 * h / e.a_m)
                    }
                    Gravity::Psins { g0, c2, c4, dh } => {
                        g0 * (1.0 + c2 * s2 + c4 * s2 * s2) - dh * h
                    }
                    Gravity::Constant { g_mps2 } => g_mps2,
                };
                assert_eq!(le.g_mps2, g);
                assert_eq!(le.r_n_m, r_n);
                assert_eq!(le.r_m_m, r_n * (1.0 - e.e2) / w2);
            }
        }
    }

    #[test]
    fn sin_cos_step_and_track_agree_with_libm() {
        let a = 0.7_f64;
        let (s, c) = (a.sin(), a.cos());
        for d in [0.0, 3e-9, -4e-7, 9.9e-7, 1.0e-6, -5e-5, 9.9e-5, 2e-4, -3e-3] {
            let (ss, cc) = sin_cos_step(s, c, d);
            assert!(
                (ss - (a + d).sin()).abs() < 3e-16 && (cc - (a + d).cos()).abs() < 3e-16,
                "{d}"
            );
        }
        // a track along a trajectory: every value within a few ulp of libm, no drift
        let mut tr = SinCosTrack::new(0.3, 0.0);
        let mut worst: f64 = 0.0;
        for k in 0..200_000 {
            let x = 3.7e-7 * k as f64 - 1e-13 * (k as f64).powi(2);
            let (s, c) = tr.sin_cos(x);
            worst = worst.max((s - (0.3 + x).sin()).abs().max((c - (0.3 + x).cos()).abs()));
        }
        assert!(worst < 3e-16, "{worst:e}");
    }

    #[test]
    fn local_earth_matches_separate_functions() {
        for e in [
            EarthModel::WGS84,
            EarthModel::PSINS,
            EarthModel::WGS84_LINEAR_G,
        ] {
            for &(lat, h) in &[(0.3_f64, 100.0), (-1.2, 5000.0), (1.55, -300.0)] {
                let le = e.local(lat, h);
                let r = e.radii(lat);
                assert!(rel(le.r_m_m, r.r_m_m) < 1e-15 && rel(le.r_n_m, r.r_n_m) < 1e-15);
                assert!(rel(le.g_mps2, e.gravity(lat, h)) < 1e-15);
                let v = Vec3::new(100.0, -50.0, 3.0);
                let w = e.omega_en_n(lat, h, &v);
                assert!(
                    (e.omega_en_n_local(&le, h, &v) - w).norm() <= 4.0 * f64::EPSILON * w.norm()
                );
                assert!((e.omega_ie_n_local(&le) - e.omega_ie_n(lat)).norm() < 1e-20);
            }
        }
        for d in [1e-9, 3e-7, 9e-4, 2e-3, -0.5] {
            let (s, c) = sin_cos_shift(0.7_f64.sin(), 0.7_f64.cos(), d);
            assert!(
                (s - (0.7 + d).sin()).abs() < 3e-16 && (c - (0.7 + d).cos()).abs() < 3e-16,
                "{d}"
            );
        }
    }

    #[test]
    fn psins_and_flat_variants() {
        let p = EarthModel::PSINS;
        let s2 = (34.25 * D2R).sin().powi(2);
        let g =
            9.780_326_771_4 * (1.0 + 5.270_94e-3 * s2 + 2.327_18e-5 * s2 * s2) - 3.086e-6 * 380.0;
        assert_eq!(p.gravity(34.25 * D2R, 380.0), g);
        let f = EarthModel::flat(9.80665);
        assert_eq!(f.gravity(1.0, 1000.0), 9.80665);
        assert_eq!(f.omega_ie_n(0.5), Vec3::zeros());
        assert_eq!(
            f.omega_en_n(0.5, 0.0, &Vec3::new(10.0, 5.0, 0.0)),
            Vec3::zeros()
        );
    }
}
