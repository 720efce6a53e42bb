//! GPS measurement mathematics for tightly coupled GNSS: broadcast orbits and clocks,
//! signal transit time with Earth rotation, elevation/azimuth, ionosphere and troposphere
//! corrections, single-point positioning (SPP), Doppler velocity and DOP.
//!
//! Everything here is `no_std`, allocation-free and works on fixed-size values; the RINEX
//! readers and the file-level SPP driver live in `sdins-sim` (`io::rinex`, `nav::spp`). The theory, the
//! sources and the measured accuracy are in `docs/theory/gnss.md`.
//!
//! Sources: IS-GPS-200 (Revision N, 2022; the user algorithms have been unchanged since
//! Revision D) sections and tables as cited per item; P. D. Groves, *Principles of GNSS,
//! Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed., Artech House 2013,
//! by section (§8.5 satellite orbits and geometry, §9.3 range errors, §9.4 navigation
//! processor).
//!
//! Frames and units are in the names: `_e` ECEF (WGS-84), `_n` local NED (the project's
//! navigation frame), `_m`, `_mps`, `_s`, `_sps` (seconds per second), `_rad`.

mod atmosphere;
mod clock;
mod doppler;
mod ephemeris;
mod geometry;
mod lsq;
mod nominal;
mod spp;
mod time;

pub use atmosphere::{
    iono_free_m, iono_free_noise_factor, klobuchar_l1_delay_m, klobuchar_l1_delay_s,
    saastamoinen_slant_m, saastamoinen_zenith_m, KlobucharCoefficients, TropoZenith,
    KLOBUCHAR_DEFAULT, STANDARD_HUMIDITY,
};
pub use clock::{ClockModel, ClockNoise, ClockState};
pub use doppler::{solve_velocity, DopplerSatellite, VelocityOptions, VelocitySolution};
pub use ephemeris::{select_ephemeris, GpsEphemeris, SatState, DEFAULT_VALIDITY_S};
pub use geometry::{
    elevation_azimuth, line_of_sight, predict, range_rate_mps, rot_z, transit, Prediction,
    ReceiverState, Transit,
};
pub use lsq::{Dop, MAX_CONDITION};
pub use nominal::{
    nominal_constellation, NominalSlot, NOMINAL_A_M, NOMINAL_GHA_DEG, NOMINAL_INCLINATION_DEG,
    NOMINAL_SLOTS,
};
pub use spp::{
    solve_position, IonoCorrection, PositionSolution, SppOptions, SppSatellite, UereModel,
};
pub use time::{crossover_s, GpsTime, SECONDS_PER_WEEK};

/// Speed of light in vacuum c \[m/s\] (IS-GPS-200 §20.3.4.3, "c = 2.99792458 × 10⁸").
pub const C_MPS: f64 = 299_792_458.0;
/// WGS-84 gravitational parameter μ used by the GPS user algorithm \[m³/s²\]
/// (IS-GPS-200 Table 20-IV).
pub const MU_GPS_M3PS2: f64 = 3.986005e14;
/// WGS-84 Earth rotation rate Ω̇e used by the GPS user algorithm \[rad/s\]
/// (IS-GPS-200 Table 20-IV).
pub const OMEGA_E_DOT_RPS: f64 = 7.2921151467e-5;
/// The GPS standard value of π (IS-GPS-200 §20.3.3.4.3.1: "π = 3.1415926535898");
/// used to convert the semicircle quantities of the user algorithms.
#[allow(clippy::approx_constant)] // deliberately the specification's rounded value
pub const PI_GPS: f64 = 3.1415926535898;
/// Relativistic clock constant F = −2√μ/c² \[s/√m\] (IS-GPS-200 §20.3.3.3.3.1,
/// F = −4.442807633 × 10⁻¹⁰ s/m^½).
pub const F_REL_S_PER_SQRT_M: f64 = -4.442807633e-10;
/// L1 carrier frequency f1 \[Hz\] (IS-GPS-200 §3.3.1.1: 154 × 10.23 MHz).
pub const F_L1_HZ: f64 = 1_575.42e6;
/// L2 carrier frequency f2 \[Hz\] (IS-GPS-200 §3.3.1.1: 120 × 10.23 MHz).
pub const F_L2_HZ: f64 = 1_227.60e6;
/// L1 wavelength λ1 = c / f1 \[m\].
pub const LAMBDA_L1_M: f64 = C_MPS / F_L1_HZ;
/// γ = (f1/f2)² = (77/60)² (IS-GPS-200 §20.3.3.3.3.2).
pub const GAMMA_L1_L2: f64 = (77.0 / 60.0) * (77.0 / 60.0);
/// Largest number of satellites one SPP or Doppler solution takes (the fixed capacity of
/// the allocation-free solvers; GPS has at most 32 PRNs).
pub const MAX_SATS: usize = 32;

/// Why a GNSS computation refused its input. Nothing here panics or returns NaN: a
/// computation that cannot be done says why.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum GnssError {
    /// The ephemeris is not usable (non-finite or out-of-range parameter).
    InvalidEphemeris {
        /// PRN of the ephemeris
        prn: u8,
        /// the offending field
        field: &'static str,
    },
    /// Kepler's equation did not converge (only for eccentricities far outside GPS's).
    KeplerNotConverged {
        /// PRN of the ephemeris
        prn: u8,
    },
    /// The light-time iteration did not converge (receiver inside the satellite?).
    TransitNotConverged,
    /// Fewer usable satellites than unknowns.
    TooFewSatellites {
        /// usable satellites
        got: usize,
        /// unknowns
        need: usize,
    },
    /// More satellites than [`MAX_SATS`].
    TooManySatellites {
        /// satellites given
        got: usize,
    },
    /// The geometry is singular or too ill-conditioned to solve (normal matrix not
    /// positive definite at the stated tolerance).
    SingularGeometry,
    /// The iterative solution did not converge within its iteration cap.
    NotConverged {
        /// iterations done
        iterations: usize,
    },
    /// A measurement or input value is not finite.
    NonFinite {
        /// which input
        what: &'static str,
    },
}

impl core::fmt::Display for GnssError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            GnssError::InvalidEphemeris { prn, field } => {
                write!(f, "ephemeris of G{prn:02}: invalid {field}")
            }
            GnssError::KeplerNotConverged { prn } => {
                write!(
                    f,
                    "ephemeris of G{prn:02}: Kepler's equation did not converge"
                )
            }
            GnssError::TransitNotConverged => write!(f, "light-time iteration did not converge"),
            GnssError::TooFewSatellites { got, need } => {
                write!(f, "{got} usable satellites, {need} needed")
            }
            GnssError::TooManySatellites { got } => {
                write!(f, "{got} satellites, at most {MAX_SATS} per solution")
            }
            GnssError::SingularGeometry => write!(f, "singular satellite geometry"),
            GnssError::NotConverged { iterations } => {
                write!(f, "no convergence after {iterations} iterations")
            }
            GnssError::NonFinite { what } => write!(f, "non-finite {what}"),
        }
    }
}
