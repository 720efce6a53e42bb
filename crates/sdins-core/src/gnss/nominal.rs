//! The nominal 24-slot GPS constellation as circular pseudo-ephemerides, run through the
//! same IS-GPS-200 orbit code as broadcast ephemerides.
//!
//! Slots: GPS SPS Performance Standard, 3rd ed. (October 2001) Table 3-1 "Reference Orbit
//! Slot Assignments as of the Defined Epoch"; the 4th ed. (September 2008) Table 3.2-1
//! "Baseline 24-Slot Constellation" keeps the same slots, epoch and reference orbit
//! (transcribed here from the 2001 table; see docs/theory/gnss.md). Epoch 00:00 UTC,
//! 1 July 1993, Greenwich hour angle 18 h 36 min 14.4 s (279.06°), FK5/J2000 right
//! ascensions; semi-major axis 26 559.7 km, inclination 55°, eccentricity 0.
//!
//! **Mapping to a scenario start.** The table fixes the constellation relative to the
//! Earth at its epoch: the longitude of each ascending node is RAAN − GHA. A scenario that
//! starts at GPS time `t0` gets the constellation *as seen from the Earth at the table
//! epoch*, with the satellites at the table's arguments of latitude at `t0`
//! (toe = toc = t0, M0 = argument of latitude, ω = 0, Ω0 = RAAN − GHA + Ω̇e·toe so that
//! IS-GPS-200's Ω_k = Ω0 + (Ω̇ − Ω̇e) t_k − Ω̇e toe equals RAAN − GHA − Ω̇e t_k). The
//! nodes do not regress (Ω̇ = 0, no J2), the clocks are perfect (af0 = af1 = af2 = 0,
//! and e = 0 makes the relativistic term 0) and T_GD = 0. The PRN of slot k (A1, A2, …,
//! F4 in table order) is k + 1. Because the user algorithm forms t − toe from seconds of
//! week with the ±302 400 s crossover, the set is valid within 3.5 days of `t0`.

use super::ephemeris::GpsEphemeris;
use super::time::GpsTime;
use super::OMEGA_E_DOT_RPS;

/// One slot of the baseline constellation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NominalSlot {
    /// slot name, plane letter and slot number
    pub name: &'static str,
    /// right ascension of the ascending node at the epoch \[deg\]
    pub raan_deg: f64,
    /// argument of latitude at the epoch \[deg\]
    pub arg_lat_deg: f64,
}

const fn slot(name: &'static str, raan_deg: f64, arg_lat_deg: f64) -> NominalSlot {
    NominalSlot {
        name,
        raan_deg,
        arg_lat_deg,
    }
}

/// The 24 slots in table order (GPS SPS PS 2001 Table 3-1 = 2008 Table 3.2-1 baseline slots).
pub const NOMINAL_SLOTS: [NominalSlot; 24] = [
    slot("A1", 272.847, 268.126),
    slot("A2", 272.847, 161.786),
    slot("A3", 272.847, 11.676),
    slot("A4", 272.847, 41.806),
    slot("B1", 332.847, 80.956),
    slot("B2", 332.847, 173.336),
    slot("B3", 332.847, 309.976),
    slot("B4", 332.847, 204.376),
    slot("C1", 32.847, 111.876),
    slot("C2", 32.847, 11.796),
    slot("C3", 32.847, 339.666),
    slot("C4", 32.847, 241.556),
    slot("D1", 92.847, 135.226),
    slot("D2", 92.847, 265.446),
    slot("D3", 92.847, 35.156),
    slot("D4", 92.847, 167.356),
    slot("E1", 152.847, 197.046),
    slot("E2", 152.847, 302.596),
    slot("E3", 152.847, 66.066),
    slot("E4", 152.847, 333.686),
    slot("F1", 212.847, 238.886),
    slot("F2", 212.847, 345.226),
    slot("F3", 212.847, 105.206),
    slot("F4", 212.847, 135.346),
];

/// Semi-major axis of the reference orbit \[m\].
pub const NOMINAL_A_M: f64 = 26_559_700.0;
/// Inclination of the reference orbit \[deg\].
pub const NOMINAL_INCLINATION_DEG: f64 = 55.0;
/// Greenwich hour angle at the table epoch, 18 h 36 min 14.4 s \[deg\].
pub const NOMINAL_GHA_DEG: f64 = (18.0 + 36.0 / 60.0 + 14.4 / 3600.0) * 15.0;

/// The 24 pseudo-ephemerides for a scenario starting at `t0` (see the module notes for
/// the mapping). SV accuracy 2.0 m (URA index 0), healthy, fit interval 4 h.
pub fn nominal_constellation(t0: GpsTime) -> [GpsEphemeris; 24] {
    let d2r = core::f64::consts::PI / 180.0;
    core::array::from_fn(|k| {
        let s = NOMINAL_SLOTS[k];
        GpsEphemeris {
            prn: k as u8 + 1,
            toc: t0,
            af0_s: 0.0,
            af1_sps: 0.0,
            af2_sps2: 0.0,
            iode: 1,
            crs_m: 0.0,
            delta_n_rps: 0.0,
            m0_rad: s.arg_lat_deg * d2r,
            cuc_rad: 0.0,
            e: 0.0,
            cus_rad: 0.0,
            sqrt_a_sqrtm: libm::sqrt(NOMINAL_A_M),
            toe: t0,
            cic_rad: 0.0,
            omega0_rad: (s.raan_deg - NOMINAL_GHA_DEG) * d2r + OMEGA_E_DOT_RPS * t0.sow_s,
            cis_rad: 0.0,
            i0_rad: NOMINAL_INCLINATION_DEG * d2r,
            crc_m: 0.0,
            omega_rad: 0.0,
            omega_dot_rps: 0.0,
            idot_rps: 0.0,
            codes_on_l2: 1,
            l2p_data_flag: 0,
            sv_accuracy_m: 2.0,
            health: 0,
            tgd_s: 0.0,
            iodc: 1,
            transmit_time_s: t0.sow_s,
            fit_interval_h: 4.0,
        }
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::earth::EarthModel;
    use crate::gnss::geometry::{elevation_azimuth, line_of_sight};
    use crate::gnss::lsq::{Dop, Normal4};
    use crate::math::Vec3;
    use nalgebra::Vector4;

    #[test]
    fn slots_sit_where_the_table_puts_them() {
        let t0 = GpsTime::new(1826, 345_600.0);
        let d2r = core::f64::consts::PI / 180.0;
        for (k, e) in nominal_constellation(t0).iter().enumerate() {
            let s = e.state(&t0).unwrap();
            let r = s.r_sat_e_m;
            assert!((r.norm() - NOMINAL_A_M).abs() < 1e-6);
            let u = NOMINAL_SLOTS[k].arg_lat_deg * d2r;
            let i = 55.0 * d2r;
            assert!((r.z - NOMINAL_A_M * libm::sin(u) * libm::sin(i)).abs() < 1e-6);
            // ECEF node longitude RAAN − GHA: r·(node direction) = a cos u
            let lon = (NOMINAL_SLOTS[k].raan_deg - NOMINAL_GHA_DEG) * d2r;
            let node = Vec3::new(libm::cos(lon), libm::sin(lon), 0.0);
            assert!((r.dot(&node) - NOMINAL_A_M * libm::cos(u)).abs() < 1e-6);
        }
    }

    /// The SPS PS promises PDOP ≤ 6 for at least 98 % of time globally with the baseline
    /// 24 slots all healthy (5° mask). The ideal nominal constellation must do at least that
    /// on a latitude/longitude grid over one day, with never fewer than 4 satellites.
    #[test]
    fn pdop_availability_meets_the_performance_standard() {
        let t0 = GpsTime::new(1826, 345_600.0);
        let ephs = nominal_constellation(t0);
        let earth = EarthModel::WGS84;
        let (mut good, mut total, mut min_vis) = (0usize, 0usize, usize::MAX);
        for ilat in -4..=4 {
            for ilon in 0..8 {
                let (lat, lon) = (
                    ilat as f64 * 20.0_f64.to_radians(),
                    ilon as f64 * 45.0_f64.to_radians(),
                );
                let r = earth.ecef_from_geodetic(lat, lon, 0.0);
                let c = EarthModel::c_e_n(lat, lon);
                for it in 0..96 {
                    let t = t0.add_s(900.0 * it as f64);
                    let mut g = Normal4::new();
                    for e in &ephs {
                        let s = e.state(&t).unwrap();
                        let (u, _) = line_of_sight(&s.r_sat_e_m, &r).unwrap();
                        let (el, _) = elevation_azimuth(&c, &u);
                        if el >= 5f64.to_radians() {
                            let un = c * u;
                            g.add(&Vector4::new(-un.x, -un.y, -un.z, 1.0), 0.0, 1.0);
                        }
                    }
                    min_vis = min_vis.min(g.rows());
                    total += 1;
                    if let Ok((_, q)) = g.solve() {
                        if Dop::from_q(&q).pdop <= 6.0 {
                            good += 1;
                        }
                    }
                }
            }
        }
        let frac = good as f64 / total as f64;
        assert!(min_vis >= 4, "{min_vis}");
        assert!(frac >= 0.98, "{frac}");
    }
}
