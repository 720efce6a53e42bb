//! GPS broadcast ephemeris and the IS-GPS-200 user algorithms for satellite position,
//! velocity and clock (Groves 2nd ed. §8.5.2 presents the same algorithm).

use super::time::{crossover_s, GpsTime};
use super::{GnssError, F_REL_S_PER_SQRT_M, MU_GPS_M3PS2, OMEGA_E_DOT_RPS};
use crate::math::Vec3;

/// Default validity of a broadcast ephemeris around its toe \[s\]: half of the 4-hour
/// curve-fit interval of IS-GPS-200 §20.3.3.4.3.1 (the same 7200 s RTKLIB uses).
pub const DEFAULT_VALIDITY_S: f64 = 7200.0;

/// One GPS broadcast ephemeris (LNAV subframes 1–3), in the field order of a RINEX-2
/// navigation record (RINEX 2.11 Table A4; RINEX 3 keeps the order):
///
/// | line | fields |
/// |---|---|
/// | 0 | PRN, toc, af0, af1, af2 |
/// | 1 | IODE, Crs, Δn, M0 |
/// | 2 | Cuc, e, Cus, √A |
/// | 3 | toe, Cic, Ω0, Cis |
/// | 4 | i0, Crc, ω, Ω̇ |
/// | 5 | IDOT, codes on L2, GPS week (of toe), L2 P data flag |
/// | 6 | SV accuracy, SV health, TGD, IODC |
/// | 7 | transmission time of message, fit interval |
///
/// Angles are radians (RINEX converts the message's semicircles), as in IS-GPS-200
/// Table 20-III otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpsEphemeris {
    /// PRN number (1–32 for GPS LNAV)
    pub prn: u8,
    /// clock reference time toc
    pub toc: GpsTime,
    /// clock bias af0 \[s\]
    pub af0_s: f64,
    /// clock drift af1 \[s/s\]
    pub af1_sps: f64,
    /// clock drift rate af2 \[s/s²\]
    pub af2_sps2: f64,
    /// issue of data, ephemeris
    pub iode: u32,
    /// sine harmonic correction to the orbit radius Crs \[m\]
    pub crs_m: f64,
    /// mean motion difference Δn \[rad/s\]
    pub delta_n_rps: f64,
    /// mean anomaly at reference time M0 \[rad\]
    pub m0_rad: f64,
    /// cosine harmonic correction to the argument of latitude Cuc \[rad\]
    pub cuc_rad: f64,
    /// eccentricity e
    pub e: f64,
    /// sine harmonic correction to the argument of latitude Cus \[rad\]
    pub cus_rad: f64,
    /// square root of the semi-major axis √A \[√m\]
    pub sqrt_a_sqrtm: f64,
    /// ephemeris reference time toe (week of the RINEX "GPS week" field, adjusted to within
    /// half a week of toc)
    pub toe: GpsTime,
    /// cosine harmonic correction to the inclination Cic \[rad\]
    pub cic_rad: f64,
    /// longitude of the ascending node of the orbit plane at the weekly epoch Ω0 \[rad\]
    pub omega0_rad: f64,
    /// sine harmonic correction to the inclination Cis \[rad\]
    pub cis_rad: f64,
    /// inclination at reference time i0 \[rad\]
    pub i0_rad: f64,
    /// cosine harmonic correction to the orbit radius Crc \[m\]
    pub crc_m: f64,
    /// argument of perigee ω \[rad\]
    pub omega_rad: f64,
    /// rate of right ascension Ω̇ \[rad/s\]
    pub omega_dot_rps: f64,
    /// rate of inclination IDOT \[rad/s\]
    pub idot_rps: f64,
    /// codes on L2 channel (as broadcast)
    pub codes_on_l2: u32,
    /// L2 P data flag
    pub l2p_data_flag: u32,
    /// SV accuracy \[m\] (RINEX gives the URA in metres)
    pub sv_accuracy_m: f64,
    /// SV health (0 = all signals OK)
    pub health: u32,
    /// estimated group delay differential T_GD \[s\]
    pub tgd_s: f64,
    /// issue of data, clock
    pub iodc: u32,
    /// transmission time of message \[s of week\]
    pub transmit_time_s: f64,
    /// curve-fit interval \[h\] (0 when the file leaves it blank)
    pub fit_interval_h: f64,
}

/// Satellite state at a GPS system time: position and velocity in the ECEF frame **of that
/// same instant**, clock bias and drift.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SatState {
    /// satellite antenna phase centre (broadcast ephemeris reference point), ECEF \[m\]
    pub r_sat_e_m: Vec3,
    /// velocity relative to the rotating ECEF frame \[m/s\]
    pub v_sat_e_mps: Vec3,
    /// Δt_sv = af0 + af1(t − toc) + af2(t − toc)² + Δt_r \[s\]: **includes** the
    /// relativistic term and **excludes** T_GD (the dual-frequency P(Y) reference;
    /// IS-GPS-200 §20.3.3.3.3.1)
    pub clock_bias_s: f64,
    /// d(Δt_sv)/dt \[s/s\], including the relativistic term's rate
    pub clock_drift_sps: f64,
    /// the relativistic term Δt_r = F e √A sin E_k \[s\] (part of `clock_bias_s`)
    pub relativistic_s: f64,
}

const KEPLER_TOL_RAD: f64 = 1e-14;
const KEPLER_MAX_ITER: usize = 30;

impl GpsEphemeris {
    /// Checks that every parameter is finite and the orbit is an ellipse
    /// (√A > 0, 0 ≤ e < 1); the user algorithm is only run on ephemerides that pass.
    pub fn validate(&self) -> Result<(), GnssError> {
        let bad = |field| {
            Err(GnssError::InvalidEphemeris {
                prn: self.prn,
                field,
            })
        };
        let fields: [(&'static str, f64); 23] = [
            ("toc", self.toc.sow_s),
            ("af0", self.af0_s),
            ("af1", self.af1_sps),
            ("af2", self.af2_sps2),
            ("Crs", self.crs_m),
            ("delta n", self.delta_n_rps),
            ("M0", self.m0_rad),
            ("Cuc", self.cuc_rad),
            ("e", self.e),
            ("Cus", self.cus_rad),
            ("sqrt A", self.sqrt_a_sqrtm),
            ("toe", self.toe.sow_s),
            ("Cic", self.cic_rad),
            ("OMEGA0", self.omega0_rad),
            ("Cis", self.cis_rad),
            ("i0", self.i0_rad),
            ("Crc", self.crc_m),
            ("omega", self.omega_rad),
            ("OMEGA DOT", self.omega_dot_rps),
            ("IDOT", self.idot_rps),
            ("TGD", self.tgd_s),
            ("SV accuracy", self.sv_accuracy_m),
            ("fit interval", self.fit_interval_h),
        ];
        for (name, v) in fields {
            if !v.is_finite() {
                return bad(name);
            }
        }
        if self.prn == 0 {
            return bad("PRN");
        }
        if self.sqrt_a_sqrtm <= 0.0 {
            return bad("sqrt A");
        }
        if !(0.0..1.0).contains(&self.e) {
            return bad("e");
        }
        Ok(())
    }

    /// tk = t − toe with the week crossover of IS-GPS-200 Table 20-IV \[s\].
    pub fn tk_s(&self, t: &GpsTime) -> f64 {
        crossover_s(t.sow_s - self.toe.sow_s)
    }

    /// Solves Kepler's equation M = E − e sin E by Newton's method (IS-GPS-200 Table 20-IV
    /// "may be solved by iteration"), to 1e-14 rad.
    fn eccentric_anomaly(&self, m: f64) -> Result<f64, GnssError> {
        let mut e_k = m;
        for _ in 0..KEPLER_MAX_ITER {
            let f = e_k - self.e * libm::sin(e_k) - m;
            let step = f / (1.0 - self.e * libm::cos(e_k));
            e_k -= step;
            if libm::fabs(step) < KEPLER_TOL_RAD {
                return Ok(e_k);
            }
        }
        Err(GnssError::KeplerNotConverged { prn: self.prn })
    }

    /// Satellite position, velocity and clock at GPS system time `t` (the time of
    /// transmission): IS-GPS-200 Table 20-IV (position, and the velocity rows of the
    /// same table) with μ and Ω̇e of that table, and the clock polynomial with the
    /// relativistic correction of §20.3.3.3.3.1. T_GD is not applied (see
    /// [`GpsEphemeris::l1_clock_bias_s`]).
    pub fn state(&self, t: &GpsTime) -> Result<SatState, GnssError> {
        self.validate()?;
        let a = self.sqrt_a_sqrtm * self.sqrt_a_sqrtm;
        let n0 = libm::sqrt(MU_GPS_M3PS2 / (a * a * a));
        let tk = self.tk_s(t);
        let n = n0 + self.delta_n_rps;
        let m = self.m0_rad + n * tk;
        let ek = self.eccentric_anomaly(m)?;
        let (sin_e, cos_e) = (libm::sin(ek), libm::cos(ek));
        let one_m_ecos = 1.0 - self.e * cos_e;
        let sq = libm::sqrt(1.0 - self.e * self.e);
        let nu = libm::atan2(sq * sin_e, cos_e - self.e);
        let phi = nu + self.omega_rad;
        let (s2, c2) = (libm::sin(2.0 * phi), libm::cos(2.0 * phi));
        let du = self.cus_rad * s2 + self.cuc_rad * c2;
        let dr = self.crs_m * s2 + self.crc_m * c2;
        let di = self.cis_rad * s2 + self.cic_rad * c2;
        let u = phi + du;
        let r = a * one_m_ecos + dr;
        let i = self.i0_rad + di + self.idot_rps * tk;
        let (su, cu) = (libm::sin(u), libm::cos(u));
        let (xp, yp) = (r * cu, r * su);
        let om_dot = self.omega_dot_rps - OMEGA_E_DOT_RPS;
        let om = self.omega0_rad + om_dot * tk - OMEGA_E_DOT_RPS * self.toe.sow_s;
        let (so, co) = (libm::sin(om), libm::cos(om));
        let (si, ci) = (libm::sin(i), libm::cos(i));
        let r_sat = Vec3::new(xp * co - yp * ci * so, xp * so + yp * ci * co, yp * si);

        // velocity: time derivatives of the rows above
        let e_dot = n / one_m_ecos;
        let nu_dot = e_dot * sq / one_m_ecos;
        let i_dot = self.idot_rps + 2.0 * nu_dot * (self.cis_rad * c2 - self.cic_rad * s2);
        let u_dot = nu_dot + 2.0 * nu_dot * (self.cus_rad * c2 - self.cuc_rad * s2);
        let r_dot = self.e * a * e_dot * sin_e + 2.0 * nu_dot * (self.crs_m * c2 - self.crc_m * s2);
        let xp_dot = r_dot * cu - r * u_dot * su;
        let yp_dot = r_dot * su + r * u_dot * cu;
        let v_sat = Vec3::new(
            -xp * om_dot * so + xp_dot * co
                - yp_dot * so * ci
                - yp * (om_dot * co * ci - i_dot * so * si),
            xp * om_dot * co + xp_dot * so + yp_dot * co * ci
                - yp * (om_dot * so * ci + i_dot * co * si),
            yp_dot * si + yp * i_dot * ci,
        );

        let dt = crossover_s(t.sow_s - self.toc.sow_s);
        let rel = F_REL_S_PER_SQRT_M * self.e * self.sqrt_a_sqrtm * sin_e;
        let rel_dot = F_REL_S_PER_SQRT_M * self.e * self.sqrt_a_sqrtm * cos_e * e_dot;
        Ok(SatState {
            r_sat_e_m: r_sat,
            v_sat_e_mps: v_sat,
            clock_bias_s: self.af0_s + self.af1_sps * dt + self.af2_sps2 * dt * dt + rel,
            clock_drift_sps: self.af1_sps + 2.0 * self.af2_sps2 * dt + rel_dot,
            relativistic_s: rel,
        })
    }

    /// Satellite clock correction for a **single-frequency L1** user,
    /// (Δt_sv)_L1 = Δt_sv − T_GD (IS-GPS-200 §20.3.3.3.3.2), from the full
    /// `clock_bias_s` of [`GpsEphemeris::state`]. Dual-frequency ionosphere-free users use
    /// Δt_sv without T_GD (the same section: T_GD cancels in the combination).
    pub fn l1_clock_bias_s(&self, state: &SatState) -> f64 {
        state.clock_bias_s - self.tgd_s
    }

    /// Time of transmission in GPS system time from the satellite's own clock reading
    /// t_sv: t = t_sv − Δt_sv(t), iterated twice (IS-GPS-200 §20.3.3.3.3.1 notes that t
    /// may be replaced by t_sv in the polynomial; two iterations make the difference
    /// below 1e-15 s for |Δt_sv| < 1 ms).
    pub fn transmit_time(
        &self,
        t_sv: &GpsTime,
        single_frequency_l1: bool,
    ) -> Result<GpsTime, GnssError> {
        let mut t = *t_sv;
        for _ in 0..2 {
            let s = self.state(&t)?;
            let dts = if single_frequency_l1 {
                self.l1_clock_bias_s(&s)
            } else {
                s.clock_bias_s
            };
            t = t_sv.add_s(-dts);
        }
        Ok(t)
    }
}

/// The broadcast ephemeris to use for `prn` at time `t`: among the ephemerides of that
/// PRN whose toe is within `validity_s` of `t` (full time difference, weeks included), the
/// one with the nearest toe (on a tie the later toe, then the later entry). Returns `None`
/// when there is none, or when that nearest ephemeris flags the satellite unhealthy
/// (health ≠ 0): the latest health word in force supersedes older ones, as in RTKLIB.
pub fn select_ephemeris<'a>(
    ephs: &'a [GpsEphemeris],
    prn: u8,
    t: &GpsTime,
    validity_s: f64,
) -> Option<&'a GpsEphemeris> {
    let mut best: Option<(&GpsEphemeris, f64)> = None;
    for e in ephs.iter().filter(|e| e.prn == prn) {
        let d = libm::fabs(t.diff_s(&e.toe));
        if d > validity_s {
            continue;
        }
        let better = match best {
            None => true,
            Some((b, bd)) => d < bd || (d == bd && e.toe.diff_s(&b.toe) >= 0.0),
        };
        if better {
            best = Some((e, d));
        }
    }
    match best {
        Some((e, _)) if e.health == 0 => Some(e),
        _ => None,
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
pub(crate) mod tests {
    use super::*;
    use crate::gnss::C_MPS;

    /// The ABPO ephemeris of G02, 2015-01-08 02:00 (abpo0080.15n, first record).
    pub(crate) fn g02() -> GpsEphemeris {
        GpsEphemeris {
            prn: 2,
            toc: GpsTime::new(1826, 352_800.0),
            af0_s: 5.405521951616e-04,
            af1_sps: 2.273736754432e-12,
            af2_sps2: 0.0,
            iode: 49,
            crs_m: -3.762500000000e+01,
            delta_n_rps: 4.611977821674e-09,
            m0_rad: -1.812812498346e+00,
            cuc_rad: -2.050772309303e-06,
            e: 1.415320031811e-02,
            cus_rad: 1.079961657524e-05,
            sqrt_a_sqrtm: 5.153748075485e+03,
            toe: GpsTime::new(1826, 3.528e5),
            cic_rad: 1.750886440277e-07,
            omega0_rad: 5.432620325643e-01,
            cis_rad: -2.309679985046e-07,
            i0_rad: 9.405292705336e-01,
            crc_m: 1.596875e+02,
            omega_rad: -2.344988861010e+00,
            omega_dot_rps: -7.761037564081e-09,
            idot_rps: 3.135844906242e-10,
            codes_on_l2: 0,
            l2p_data_flag: 0,
            sv_accuracy_m: 2.0,
            health: 0,
            tgd_s: -2.048909664154e-08,
            iodc: 49,
            transmit_time_s: 3.456e5,
            fit_interval_h: 4.0,
        }
    }

    #[test]
    fn velocity_is_the_derivative_of_position_and_clock_drift_of_clock() {
        let eph = g02();
        for k in -12..=12 {
            let t = eph.toe.add_s(600.0 * k as f64);
            let s = eph.state(&t).unwrap();
            let h = 0.5;
            let p = eph.state(&t.add_s(h)).unwrap();
            let m = eph.state(&t.add_s(-h)).unwrap();
            let v_cd = (p.r_sat_e_m - m.r_sat_e_m) / (2.0 * h);
            // central-difference truncation: |r'''| h²/6 ≈ (n³ a) h²/6 ≈ 1.4e-7 m/s
            assert!(
                (v_cd - s.v_sat_e_mps).norm() < 1e-5,
                "{}",
                (v_cd - s.v_sat_e_mps).norm()
            );
            let d_cd = (p.clock_bias_s - m.clock_bias_s) / (2.0 * h);
            assert!((d_cd - s.clock_drift_sps).abs() < 1e-16);
            // Δt_r = F e √A sin E equals −2 r·v / c² for the Keplerian part (Ashby); the
            // harmonic corrections change r·v by ≲ 1e-3 relative: bound 1e-10 s
            let rv = s
                .r_sat_e_m
                .dot(&(s.v_sat_e_mps + Vec3::new(0.0, 0.0, OMEGA_E_DOT_RPS).cross(&s.r_sat_e_m)));
            let rel2 = -2.0 * rv / (C_MPS * C_MPS);
            assert!(
                (rel2 - s.relativistic_s).abs() < 1e-10,
                "{} {}",
                rel2,
                s.relativistic_s
            );
        }
    }

    #[test]
    fn orbit_radius_and_speed_are_gps_like() {
        let s = g02().state(&g02().toe).unwrap();
        let r = s.r_sat_e_m.norm();
        assert!((r - 26_560e3).abs() < 400e3, "{r}");
        let v_i = s.v_sat_e_mps + Vec3::new(0.0, 0.0, OMEGA_E_DOT_RPS).cross(&s.r_sat_e_m);
        assert!((v_i.norm() - 3874.0).abs() < 60.0, "{}", v_i.norm());
    }

    #[test]
    fn invalid_ephemerides_are_refused() {
        let mut e = g02();
        e.e = 1.2;
        assert_eq!(
            e.state(&e.toe),
            Err(GnssError::InvalidEphemeris { prn: 2, field: "e" })
        );
        let mut e = g02();
        e.m0_rad = f64::NAN;
        assert!(e.state(&e.toe).is_err());
        let mut e = g02();
        e.sqrt_a_sqrtm = 0.0;
        assert!(e.state(&e.toe).is_err());
    }

    #[test]
    fn selection_nearest_healthy_within_validity() {
        let a = g02();
        let mut b = g02();
        b.toe = a.toe.add_s(7200.0);
        b.iode = 50;
        let ephs = [a, b];
        let t = a.toe.add_s(3000.0);
        assert_eq!(select_ephemeris(&ephs, 2, &t, 7200.0).unwrap().iode, 49);
        let t = a.toe.add_s(3600.0); // tie: the later toe
        assert_eq!(select_ephemeris(&ephs, 2, &t, 7200.0).unwrap().iode, 50);
        let t = a.toe.add_s(-7300.0);
        assert!(select_ephemeris(&ephs, 2, &t, 7200.0).is_none());
        assert!(select_ephemeris(&ephs, 3, &a.toe, 7200.0).is_none());
        let mut sick = b;
        sick.health = 1;
        let ephs = [a, sick];
        assert!(select_ephemeris(&ephs, 2, &a.toe.add_s(7000.0), 7200.0).is_none());
        assert_eq!(
            select_ephemeris(&ephs, 2, &a.toe.add_s(100.0), 7200.0)
                .unwrap()
                .iode,
            49
        );
    }

    #[test]
    fn week_crossover_of_tk() {
        let mut e = g02();
        e.toe = GpsTime::new(1826, 604_000.0);
        e.toc = e.toe;
        let t = GpsTime::new(1827, 100.0);
        assert_eq!(e.tk_s(&t), 900.0);
        // the state 900 s after toe across the week boundary equals the state 900 s after
        // the same toe within one week
        let s1 = e.state(&t).unwrap();
        let mut e2 = e;
        e2.toe = GpsTime::new(1826, 100_000.0);
        e2.toc = e2.toe;
        e2.omega0_rad += OMEGA_E_DOT_RPS * (100_000.0 - 604_000.0);
        let s2 = e2.state(&GpsTime::new(1826, 100_900.0)).unwrap();
        assert!((s1.r_sat_e_m - s2.r_sat_e_m).norm() < 1e-6);
    }

    #[test]
    fn transmit_time_removes_the_clock_bias() {
        let e = g02();
        let t_sv = e.toe.add_s(100.0);
        let t = e.transmit_time(&t_sv, true).unwrap();
        let s = e.state(&t).unwrap();
        let resid = t_sv.diff_s(&t) - e.l1_clock_bias_s(&s);
        // an f64 second of week resolves 5.8e-11 s near 352 900 s: two ulps
        assert!(resid.abs() < 1.2e-10, "{resid}");
        assert!(t_sv.diff_s(&t) > 5e-4);
    }
}
