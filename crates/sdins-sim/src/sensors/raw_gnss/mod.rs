//! Raw GNSS measurements (GPS L1 C/A pseudorange and range rate) simulated from the exact
//! truth, for tightly coupled integration and for outside receivers through RINEX 3.04.
//!
//! Per epoch `t_j = j / rate_hz` and per visible satellite (elevation mask, sky mask,
//! PRN list), at the exact antenna position and velocity (lever arm, as
//! [`crate::sensors::gnss::exact_antenna`]):
//!
//! ```text
//! P = ρ + c δt_r − c Δt_sv + c T_GD + I + T + e_sis + ε_P (+ outlier)
//! ρ̇_P = ρ̇ + c δṫ_r − c Δṫ_sv + ε_ρ̇
//! ```
//!
//! * ρ, ρ̇: the light-time solution with Earth rotation of `sdins_core::gnss::predict`;
//!   Δt_sv the broadcast clock polynomial with the relativistic term (IS-GPS-200
//!   §20.3.3.3.3.1), T_GD for L1 (§20.3.3.3.3.2).
//! * δt_r, δṫ_r: the two-state receiver clock ([`sdins_core::gnss::ClockModel`], exact
//!   Φ and Q), plus the `clock_jump_t_s_ms` steps.
//! * I = (`iono_scale` + r_i(t)) · K: K the Klobuchar delay (IS-GPS-200 §20.3.3.5.2.5),
//!   r_i a per-satellite first-order Gauss–Markov fraction (σ `iono_resid_frac`, τ
//!   `iono_resid_tau_s`); T = Saastamoinen · 1/sin el + T_z(t)/sin el, T_z a Gauss–Markov
//!   zenith residual. The correction models (Klobuchar, Saastamoinen) differ from this
//!   truth by the residual processes; [`Uere`] gives their σ per measurement.
//! * e_sis: a random constant per satellite and run, σ = `sis_ura_scale` · URA.
//! * ε: white, σ0 / sin el.
//! * The range rate leaves out the rates of the atmospheric delays (below 1 cm/s at
//!   10° elevation, mm/s above 30°; the Doppler solvers do not model them either).
//! * Time tags: the true reception time is `start + t_j` (GPST); the epoch is tagged
//!   with the receiver clock's reading `start + t_j + δt_r`, as a receiver does.
//!
//! Satellites: the nominal 24-slot constellation (`sdins_core::gnss::nominal_constellation`
//! at the scenario start, re-epoched every 2 h: [`config::nominal_for`]) or the GPS
//! broadcast ephemerides of a RINEX navigation file. RINEX 3.04 output:
//! `RawGnssRecord::obs_rinex3`, `nav_rinex3` (in `crate::io::rinex`). Random numbers: ChaCha20 streams
//! `2⁶² + 64·run + channel` of the table's seed (disjoint from the IMU, GNSS-fix and
//! aiding streams). Theory and sources: docs/theory/raw-gnss.md.

mod config;
mod sim;

pub use config::{
    nominal_for, parse_gpst, RawGnssConfig, RawGnssConfigError, RawGnssTable, NOMINAL_REEPOCH_S,
};
pub use sim::{RawGnssSimulator, RawObs, RawTruth, Uere};

use crate::truth::trajectory::Trajectory;
use crate::truth::{TruthConfig, TruthGenerator};
use sdins_core::gnss::{GpsEphemeris, GpsTime, KlobucharCoefficients};

/// Why `Scenario::simulate_raw_gnss` could not run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RawGnssError {
    /// The scenario has no `[raw_gnss]` table.
    #[error("the scenario has no [raw_gnss] table")]
    NoTable,
}

/// The raw measurements of one run of a scenario, with what the RINEX files need.
#[derive(Clone, Debug, PartialEq)]
pub struct RawGnssRecord {
    /// GPS time of the scenario start
    pub start: GpsTime,
    /// epoch rate \[Hz\]
    pub rate_hz: f64,
    /// the measurements, in time order, PRN order within an epoch
    pub obs: Vec<RawObs>,
    /// the ephemerides flown
    pub ephemerides: Vec<GpsEphemeris>,
    /// Klobuchar coefficients (truth and model)
    pub klobuchar: KlobucharCoefficients,
    /// the antenna's position at the first epoch, ECEF \[m\] (the RINEX approximate position)
    pub approx_position_e_m: Option<[f64; 3]>,
}

/// Simulates the raw GNSS measurements of run `run` over a whole trajectory (the truth
/// generated as for the IMU with `tc`). A scenario with a `[raw_gnss]` table does this
/// through `Scenario::simulate_raw_gnss`.
pub fn simulate(
    traj: &Trajectory,
    tc: TruthConfig,
    cfg: &RawGnssConfig,
    run: u64,
) -> RawGnssRecord {
    let gen = TruthGenerator::new(traj, tc);
    let mut prev = gen.initial_truth();
    let mut sim = RawGnssSimulator::new(cfg, tc.earth, run);
    let mut obs = Vec::new();
    for s in gen {
        sim.step(traj, &prev, &s, &mut obs);
        prev = s;
    }
    RawGnssRecord {
        start: cfg.start,
        rate_hz: cfg.table.rate_hz,
        approx_position_e_m: obs
            .first()
            .map(|o| [o.truth.r_e_m.x, o.truth.r_e_m.y, o.truth.r_e_m.z]),
        obs,
        ephemerides: cfg.ephemerides.clone(),
        klobuchar: cfg.klobuchar,
    }
}
