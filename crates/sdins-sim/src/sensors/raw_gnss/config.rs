//! `[raw_gnss]`: the scenario table of the raw GNSS simulator, its validation and its
//! resolution into satellites (nominal or broadcast) and a GPS start time.

use sdins_core::gnss::{
    nominal_constellation, ClockModel, GpsEphemeris, GpsTime, KlobucharCoefficients,
    KLOBUCHAR_DEFAULT, MU_GPS_M3PS2, OMEGA_E_DOT_RPS,
};
use serde::{Deserialize, Serialize};

/// Why a `[raw_gnss]` table is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RawGnssConfigError {
    /// The value of `raw_gnss.key` is out of range or unusable.
    #[error("[raw_gnss] {key}: {what}")]
    Invalid {
        /// the key
        key: &'static str,
        /// what is wrong
        what: String,
    },
}

fn bad(key: &'static str, what: impl Into<String>) -> RawGnssConfigError {
    RawGnssConfigError::Invalid {
        key,
        what: what.into(),
    }
}

/// The `[raw_gnss]` table as written (defaults: a TCXO receiver clock, 1 Hz, 10° mask,
/// σ0 = 0.5 m and 0.05 m/s, the Klobuchar truth with a 30 % Gauss–Markov residual,
/// Saastamoinen with a 5 cm zenith residual, signal-in-space errors 0.35 × URA).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RawGnssTable {
    /// epoch rate \[Hz\]
    pub rate_hz: f64,
    /// GPS time of the scenario start: `"YYYY-MM-DD hh:mm:ss"` (GPST) or `"WEEK SOW"`
    pub start_gpst: String,
    /// RINEX navigation file with GPS broadcast ephemerides (relative to the scenario);
    /// absent: the nominal 24-slot constellation
    pub nav_file: Option<String>,
    /// Klobuchar α0..α3 (default: the nav file's, else the core's default set)
    pub klobuchar_alpha: Option<[f64; 4]>,
    /// Klobuchar β0..β3
    pub klobuchar_beta: Option<[f64; 4]>,
    /// elevation mask \[deg\]
    pub mask_deg: f64,
    /// sky mask: `[azimuth_deg, min_elevation_deg]` points, piecewise linear in azimuth
    /// (wrapping at 360°)
    pub sky_mask_az_el_deg: Vec<[f64; 2]>,
    /// keep only these PRNs (empty: all)
    pub prns: Vec<u8>,
    /// pseudorange white noise at the zenith σ0 \[m\]; σ(el) = σ0 / sin el
    pub sigma_pr_m: f64,
    /// range-rate white noise at the zenith \[m/s\]; σ(el) = σ / sin el
    pub sigma_rr_mps: f64,
    /// receiver clock white-FM coefficient h0 \[s\]
    pub h0_s: f64,
    /// receiver clock random-walk-FM coefficient h₋₂ \[1/s\]
    pub h_m2_per_s: f64,
    /// ionosphere truth = `iono_scale` × Klobuchar (+ the residual)
    pub iono_scale: f64,
    /// σ of the residual ionosphere as a fraction of the Klobuchar delay
    pub iono_resid_frac: f64,
    /// correlation time of the residual ionosphere \[s\]
    pub iono_resid_tau_s: f64,
    /// σ of the residual zenith troposphere \[m\] (mapped 1/sin el)
    pub tropo_resid_zenith_m: f64,
    /// correlation time of the residual troposphere \[s\]
    pub tropo_resid_tau_s: f64,
    /// signal-in-space (ephemeris and satellite clock) error σ as a fraction of the URA
    /// (a random constant per satellite and run)
    pub sis_ura_scale: f64,
    /// lever arm IMU → antenna, body axes \[m\]
    pub lever_arm_b_m: [f64; 3],
    /// receiver clock jumps `[t_s, jump_ms]` (±1 ms in real receivers)
    pub clock_jump_t_s_ms: Vec<[f64; 2]>,
    /// pseudorange outliers `[t_s, prn, offset_m]` (multipath, NLOS), at the epoch
    /// nearest `t_s`
    pub outliers_t_s_prn_m: Vec<[f64; 3]>,
    /// outages `[start_s, end_s)`
    pub outages_s: Vec<[f64; 2]>,
    /// random seed
    pub seed: u64,
}

impl Default for RawGnssTable {
    fn default() -> Self {
        RawGnssTable {
            rate_hz: 1.0,
            start_gpst: "2024-03-05 10:00:00".into(),
            nav_file: None,
            klobuchar_alpha: None,
            klobuchar_beta: None,
            mask_deg: 10.0,
            sky_mask_az_el_deg: Vec::new(),
            prns: Vec::new(),
            sigma_pr_m: 0.5,
            sigma_rr_mps: 0.05,
            h0_s: ClockModel::TCXO.h0,
            h_m2_per_s: ClockModel::TCXO.h_minus2,
            iono_scale: 1.0,
            iono_resid_frac: 0.3,
            iono_resid_tau_s: 1800.0,
            tropo_resid_zenith_m: 0.05,
            tropo_resid_tau_s: 3600.0,
            sis_ura_scale: 0.35,
            lever_arm_b_m: [0.0; 3],
            clock_jump_t_s_ms: Vec::new(),
            outliers_t_s_prn_m: Vec::new(),
            outages_s: Vec::new(),
            seed: 29,
        }
    }
}

fn nonneg(key: &'static str, v: f64) -> Result<(), RawGnssConfigError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(bad(key, format!("must be finite and ≥ 0, got {v}")))
    }
}

fn positive(key: &'static str, v: f64) -> Result<(), RawGnssConfigError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(bad(key, format!("must be finite and > 0, got {v}")))
    }
}

/// Parses `"YYYY-MM-DD hh:mm:ss[.s]"` (GPST) or `"WEEK SOW"`.
pub fn parse_gpst(s: &str) -> Option<GpsTime> {
    let s = s.trim();
    if s.contains('-') {
        let (date, time) = s.split_once([' ', 'T'])?;
        let d: Vec<&str> = date.split('-').collect();
        let t: Vec<&str> = time.trim().split(':').collect();
        if d.len() != 3 || t.len() != 3 {
            return None;
        }
        let (y, mo, da) = (d[0].parse().ok()?, d[1].parse().ok()?, d[2].parse().ok()?);
        let (h, mi, sec): (u32, u32, f64) =
            (t[0].parse().ok()?, t[1].parse().ok()?, t[2].parse().ok()?);
        let ok = (1980..=2100).contains(&y)
            && (1..=12).contains(&mo)
            && (1..=31).contains(&da)
            && h < 24
            && mi < 60
            && (0.0..60.0).contains(&sec);
        ok.then(|| GpsTime::from_calendar(y, mo, da, h, mi, sec))
    } else {
        let mut it = s.split_whitespace();
        let w: i32 = it.next()?.parse().ok()?;
        let sow: f64 = it.next()?.parse().ok()?;
        let ok = it.next().is_none() && (0..=5000).contains(&w) && (0.0..604_800.0).contains(&sow);
        ok.then(|| GpsTime::new(w, sow))
    }
}

impl RawGnssTable {
    /// Checks every key's range (file-independent).
    pub fn validate(&self) -> Result<(), RawGnssConfigError> {
        if !(self.rate_hz.is_finite() && (0.01..=100.0).contains(&self.rate_hz)) {
            return Err(bad(
                "rate_hz",
                format!("must be in 0.01…100, got {}", self.rate_hz),
            ));
        }
        if parse_gpst(&self.start_gpst).is_none() {
            return Err(bad(
                "start_gpst",
                format!(
                    "expected \"YYYY-MM-DD hh:mm:ss\" or \"WEEK SOW\", got {:?}",
                    self.start_gpst
                ),
            ));
        }
        for (key, c) in [
            ("klobuchar_alpha", self.klobuchar_alpha),
            ("klobuchar_beta", self.klobuchar_beta),
        ] {
            if c.is_some_and(|c| c.iter().any(|v| !v.is_finite())) {
                return Err(bad(key, "must be four finite numbers"));
            }
        }
        if self.klobuchar_alpha.is_some() != self.klobuchar_beta.is_some() {
            return Err(bad(
                "klobuchar_beta",
                "give klobuchar_alpha and klobuchar_beta together",
            ));
        }
        if !(self.mask_deg.is_finite() && (0.0..90.0).contains(&self.mask_deg)) {
            return Err(bad(
                "mask_deg",
                format!("must be in [0, 90), got {}", self.mask_deg),
            ));
        }
        for p in &self.sky_mask_az_el_deg {
            let ok = (0.0..=360.0).contains(&p[0]) && (0.0..=90.0).contains(&p[1]);
            if !ok {
                return Err(bad(
                    "sky_mask_az_el_deg",
                    format!("points are [az in 0…360, el in 0…90], got {p:?}"),
                ));
            }
        }
        if let Some(p) = self.prns.iter().find(|p| !(1..=32).contains(*p)) {
            return Err(bad("prns", format!("GPS PRNs are 1…32, got {p}")));
        }
        nonneg("sigma_pr_m", self.sigma_pr_m)?;
        nonneg("sigma_rr_mps", self.sigma_rr_mps)?;
        nonneg("h0_s", self.h0_s)?;
        nonneg("h_m2_per_s", self.h_m2_per_s)?;
        nonneg("iono_scale", self.iono_scale)?;
        nonneg("iono_resid_frac", self.iono_resid_frac)?;
        positive("iono_resid_tau_s", self.iono_resid_tau_s)?;
        nonneg("tropo_resid_zenith_m", self.tropo_resid_zenith_m)?;
        positive("tropo_resid_tau_s", self.tropo_resid_tau_s)?;
        nonneg("sis_ura_scale", self.sis_ura_scale)?;
        if self
            .lever_arm_b_m
            .iter()
            .any(|v| !v.is_finite() || v.abs() > 100.0)
        {
            return Err(bad("lever_arm_b_m", "must be finite with |x| ≤ 100 m"));
        }
        for j in &self.clock_jump_t_s_ms {
            if !(j[0].is_finite() && j[0] >= 0.0 && j[1].is_finite() && j[1].abs() <= 1000.0) {
                return Err(bad(
                    "clock_jump_t_s_ms",
                    format!("entries are [t_s ≥ 0, jump_ms with |jump| ≤ 1000], got {j:?}"),
                ));
            }
        }
        for o in &self.outliers_t_s_prn_m {
            let prn_ok = o[1].fract() == 0.0 && (1.0..=32.0).contains(&o[1]);
            if !(o[0].is_finite() && o[0] >= 0.0 && prn_ok && o[2].is_finite()) {
                return Err(bad(
                    "outliers_t_s_prn_m",
                    format!("entries are [t_s ≥ 0, PRN 1…32, offset_m], got {o:?}"),
                ));
            }
        }
        for w in &self.outages_s {
            if !(w[0].is_finite() && w[1].is_finite() && w[0] < w[1]) {
                return Err(bad(
                    "outages_s",
                    format!("windows are [start_s, end_s) with start < end, got {w:?}"),
                ));
            }
        }
        Ok(())
    }

    /// The receiver clock model of the table.
    pub fn clock(&self) -> ClockModel {
        ClockModel {
            h0: self.h0_s,
            h_minus2: self.h_m2_per_s,
        }
    }
}

/// Spacing of the re-epoched nominal pseudo-ephemerides \[s\] (RTKLIB and
/// [`sdins_core::gnss::select_ephemeris`] accept an ephemeris within 2 h of its toe).
pub const NOMINAL_REEPOCH_S: f64 = 7200.0;

/// The nominal constellation for a scenario starting at `t0` and lasting `duration_s`:
/// [`nominal_constellation`]`(t0)` and the same orbits re-epoched every
/// [`NOMINAL_REEPOCH_S`] (toe' = toe + Δ, M0' = M0 + nΔ, Ω0 corrected for a week
/// crossing), so that every instant has a set within an hour of its toe.
pub fn nominal_for(t0: GpsTime, duration_s: f64) -> Vec<GpsEphemeris> {
    let base = nominal_constellation(t0);
    let n_sets = (duration_s.max(0.0) / NOMINAL_REEPOCH_S).ceil() as usize + 1;
    let mut out = Vec::with_capacity(24 * n_sets);
    for k in 0..n_sets {
        let d = k as f64 * NOMINAL_REEPOCH_S;
        for e in &base {
            let mut e2 = *e;
            let a = e.sqrt_a_sqrtm * e.sqrt_a_sqrtm;
            let n = (MU_GPS_M3PS2 / (a * a * a)).sqrt();
            e2.toe = e.toe.add_s(d);
            e2.toc = e2.toe;
            e2.m0_rad = e.m0_rad + n * d;
            e2.omega0_rad = e.omega0_rad + OMEGA_E_DOT_RPS * (e2.toe.sow_s - e.toe.sow_s - d);
            e2.transmit_time_s = e2.toe.sow_s;
            e2.iode = (k % 255) as u32 + 1;
            e2.iodc = e2.iode;
            out.push(e2);
        }
    }
    out
}

/// The table resolved: the satellites, the start time and the ionosphere coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct RawGnssConfig {
    /// the table as written
    pub table: RawGnssTable,
    /// GPS time of the scenario start (t = 0)
    pub start: GpsTime,
    /// the ephemerides the satellites fly (and that the navigation file gets)
    pub ephemerides: Vec<GpsEphemeris>,
    /// Klobuchar coefficients of the truth and of the correction model
    pub klobuchar: KlobucharCoefficients,
    /// whether the ephemerides are the nominal constellation
    pub nominal: bool,
}

impl RawGnssConfig {
    /// Validates the table and resolves the satellites: `nav` the broadcast ephemerides
    /// and ionosphere coefficients of the table's `nav_file` (read by the caller:
    /// `Scenario` parsing reads it relative to the scenario), or `None` for the nominal
    /// constellation over `duration_s`.
    pub fn resolve(
        table: &RawGnssTable,
        nav: Option<(Vec<GpsEphemeris>, Option<KlobucharCoefficients>)>,
        duration_s: f64,
    ) -> Result<RawGnssConfig, RawGnssConfigError> {
        table.validate()?;
        let start = parse_gpst(&table.start_gpst).ok_or_else(|| bad("start_gpst", "unparsable"))?;
        let (ephemerides, file_k, nominal) = match nav {
            None => (nominal_for(start, duration_s), None, true),
            Some((e, _)) if e.is_empty() => {
                return Err(bad("nav_file", "the file has no GPS ephemerides"));
            }
            Some((e, k)) => (e, k, false),
        };
        let klobuchar = match (table.klobuchar_alpha, table.klobuchar_beta) {
            (Some(alpha), Some(beta)) => KlobucharCoefficients { alpha, beta },
            _ => file_k.unwrap_or(KLOBUCHAR_DEFAULT),
        };
        Ok(RawGnssConfig {
            table: table.clone(),
            start,
            ephemerides,
            klobuchar,
            nominal,
        })
    }

    /// The minimum elevation of the sky mask at azimuth `az_deg` \[deg\] (piecewise
    /// linear between the points sorted by azimuth, wrapping at 360°; 0 without points).
    pub fn sky_mask_el_deg(&self, az_deg: f64) -> f64 {
        let mut p = self.table.sky_mask_az_el_deg.clone();
        match p.len() {
            0 => return 0.0,
            1 => return p[0][1],
            _ => {}
        }
        p.sort_by(|a, b| a[0].total_cmp(&b[0]));
        let n = p.len();
        for k in 0..n {
            let (a, b) = (p[k], p[(k + 1) % n]);
            let b_az = if k + 1 == n { b[0] + 360.0 } else { b[0] };
            let az = if az_deg < a[0] {
                az_deg + 360.0
            } else {
                az_deg
            };
            if (a[0]..=b_az).contains(&az) {
                let w = if b_az > a[0] {
                    (az - a[0]) / (b_az - a[0])
                } else {
                    0.0
                };
                return a[1] + w * (b[1] - a[1]);
            }
        }
        p[0][1]
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// The re-epoched nominal sets fly the same orbits: every set gives the same satellite
    /// position at the same instant (to a micrometre), across a week boundary too.
    #[test]
    fn reepoched_nominal_sets_are_the_same_orbits() {
        for t0 in [
            GpsTime::new(2304, 208_800.0),
            GpsTime::new(2304, 604_800.0 - 3600.0),
        ] {
            let e = nominal_for(t0, 5.0 * 3600.0);
            assert_eq!(e.len(), 24 * 4);
            for k in 1..4 {
                for i in 0..24 {
                    let (a, b) = (&e[i], &e[24 * k + i]);
                    assert_eq!(a.prn, b.prn);
                    let t = b.toe.add_s(-1234.5);
                    let d = a.state(&t).unwrap().r_sat_e_m - b.state(&t).unwrap().r_sat_e_m;
                    assert!(d.norm() < 1e-6, "set {k} G{:02}: {}", a.prn, d.norm());
                }
            }
        }
    }

    #[test]
    fn sky_mask_is_piecewise_linear_and_wraps() {
        let table = RawGnssTable {
            sky_mask_az_el_deg: vec![[90.0, 40.0], [350.0, 20.0], [10.0, 30.0]],
            ..RawGnssTable::default()
        };
        let c = RawGnssConfig {
            table,
            start: GpsTime::new(2304, 0.0),
            ephemerides: Vec::new(),
            klobuchar: KLOBUCHAR_DEFAULT,
            nominal: true,
        };
        assert!((c.sky_mask_el_deg(10.0) - 30.0).abs() < 1e-12);
        assert!((c.sky_mask_el_deg(50.0) - 35.0).abs() < 1e-12);
        assert!((c.sky_mask_el_deg(220.0) - 30.0).abs() < 1e-12); // 90 → 350 halfway
        assert!((c.sky_mask_el_deg(0.0) - 25.0).abs() < 1e-12); // 350 → 10 across north
        assert!((c.sky_mask_el_deg(355.0) - 22.5).abs() < 1e-12);
        assert_eq!(
            parse_gpst("2304 208800"),
            Some(GpsTime::new(2304, 208_800.0))
        );
        assert_eq!(
            parse_gpst("2024-03-05 10:00:00"),
            Some(GpsTime::from_calendar(2024, 3, 5, 10, 0, 0.0))
        );
        assert_eq!(parse_gpst("2024-13-05 10:00:00"), None);
    }
}
