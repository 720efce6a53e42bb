//! RINEX 3.04 writers: GPS observation files and GPS navigation files, readable by
//! [`super::obs`], [`super::nav`] and RTKLIB.

use super::nav::NavFile;
use super::obs::ObsFile;
use sdins_core::gnss::GpsEphemeris;
use std::fmt::Write as _;

/// A header line: the content padded to 60 columns, then the label.
fn hline(out: &mut String, content: &str, label: &str) {
    let _ = writeln!(out, "{content:<60}{label}");
}

/// Fortran `Dw.p`-style scientific notation, `E` exponent with sign and two digits,
/// right-aligned in `width` (e.g. `D19.12`: ` 5.405521951616E-04`); exponents beyond ±99
/// (never met in navigation data) widen the field.
pub fn fmt_d(v: f64, width: usize, prec: usize) -> String {
    let s = format!("{v:.prec$E}");
    let (mant, exp) = s.split_once('E').unwrap_or((s.as_str(), "0"));
    let e: i32 = exp.parse().unwrap_or(0);
    let sign = if e < 0 { '-' } else { '+' };
    format!("{:>width$}", format!("{mant}E{sign}{:02}", e.abs()))
}

/// The observation file as RINEX 3.04 text (GPS only). Values are written `F14.3` with
/// their LLI and signal-strength digits; missing values are blank.
pub fn obs_to_rinex3(f: &ObsFile) -> String {
    let h = &f.header;
    let mut o = String::new();
    hline(
        &mut o,
        &format!(
            "{:9.2}{:11}{:<20}{:<20}",
            3.04, "", "OBSERVATION DATA", "G: GPS"
        ),
        "RINEX VERSION / TYPE",
    );
    hline(
        &mut o,
        &format!("{:<20}{:<20}{:<20}", "sdins", "", ""),
        "PGM / RUN BY / DATE",
    );
    hline(&mut o, &h.marker_name, "MARKER NAME");
    hline(&mut o, "", "OBSERVER / AGENCY");
    hline(
        &mut o,
        &format!("{:<20}{:<20}{:<20}", "", h.receiver_type, ""),
        "REC # / TYPE / VERS",
    );
    hline(&mut o, "", "ANT # / TYPE");
    let p = h.approx_position_e_m.unwrap_or([0.0; 3]);
    hline(
        &mut o,
        &format!("{:14.4}{:14.4}{:14.4}", p[0], p[1], p[2]),
        "APPROX POSITION XYZ",
    );
    let a = h.antenna_delta_hen_m;
    hline(
        &mut o,
        &format!("{:14.4}{:14.4}{:14.4}", a[0], a[1], a[2]),
        "ANTENNA: DELTA H/E/N",
    );
    for (k, chunk) in h.gps_types.chunks(13).enumerate() {
        let mut s = if k == 0 {
            format!("G  {:3}", h.gps_types.len())
        } else {
            " ".repeat(6)
        };
        for c in chunk {
            let _ = write!(s, " {c}");
        }
        hline(&mut o, &s, "SYS / # / OBS TYPES");
    }
    if let Some(iv) = h.interval_s {
        hline(&mut o, &format!("{iv:10.3}"), "INTERVAL");
    }
    if let Some(t) = h.first_obs.or_else(|| f.epochs.first().map(|e| e.t)) {
        let (y, mo, d, hh, mi, s) = t.to_calendar();
        hline(
            &mut o,
            &format!("{y:6}{mo:6}{d:6}{hh:6}{mi:6}{s:13.7}     GPS"),
            "TIME OF FIRST OBS",
        );
    }
    for c in h.gps_types.iter().filter(|c| c.0[0] == b'L') {
        hline(&mut o, &format!("G {c}  0.00000"), "SYS / PHASE SHIFT");
    }
    hline(&mut o, "", "END OF HEADER");
    for e in &f.epochs {
        let (y, mo, d, hh, mi, s) = e.t.to_calendar();
        let clk = e
            .rx_clock_offset_s
            .map(|c| format!("      {c:15.12}"))
            .unwrap_or_default();
        let _ = writeln!(
            o,
            "> {y:4} {mo:02} {d:02} {hh:02} {mi:02}{s:11.7}  {}{:3}{clk}",
            e.flag,
            e.sats.len()
        );
        for s in &e.sats {
            let mut l = format!("G{:02}", s.prn);
            for v in &s.values {
                match v {
                    Some(v) => {
                        let digit =
                            |d: Option<u8>| d.map(|d| char::from(b'0' + d.min(9))).unwrap_or(' ');
                        let _ = write!(l, "{:14.3}{}{}", v.value, digit(v.lli), digit(v.ssi));
                    }
                    None => l.push_str(&" ".repeat(16)),
                }
            }
            let _ = writeln!(o, "{}", l.trim_end());
        }
    }
    o
}

fn eph_record(o: &mut String, e: &GpsEphemeris) {
    let (y, mo, d, hh, mi, s) = e.toc.to_calendar();
    let f = |v: f64| fmt_d(v, 19, 12);
    let _ = writeln!(
        o,
        "G{:02} {y:4} {mo:02} {d:02} {hh:02} {mi:02} {:02}{}{}{}",
        e.prn,
        s.round() as u32,
        f(e.af0_s),
        f(e.af1_sps),
        f(e.af2_sps2)
    );
    let rows: [[f64; 4]; 7] = [
        [e.iode as f64, e.crs_m, e.delta_n_rps, e.m0_rad],
        [e.cuc_rad, e.e, e.cus_rad, e.sqrt_a_sqrtm],
        [e.toe.sow_s, e.cic_rad, e.omega0_rad, e.cis_rad],
        [e.i0_rad, e.crc_m, e.omega_rad, e.omega_dot_rps],
        [
            e.idot_rps,
            e.codes_on_l2 as f64,
            e.toe.week as f64,
            e.l2p_data_flag as f64,
        ],
        [e.sv_accuracy_m, e.health as f64, e.tgd_s, e.iodc as f64],
        [e.transmit_time_s, e.fit_interval_h, 0.0, 0.0],
    ];
    for (k, r) in rows.iter().enumerate() {
        let n = if k == 6 { 2 } else { 4 };
        let mut l = String::from("    ");
        for v in r.iter().take(n) {
            l.push_str(&f(*v));
        }
        let _ = writeln!(o, "{l}");
    }
}

/// The GPS ephemerides (and α/β, when present) as a RINEX 3.04 navigation file. The clock
/// epoch toc is written in whole seconds (RINEX 3 `I2`).
pub fn nav_to_rinex3(n: &NavFile) -> String {
    let mut o = String::new();
    hline(
        &mut o,
        &format!(
            "{:9.2}{:11}{:<20}{:<20}",
            3.04, "", "N: GNSS NAV DATA", "G: GPS"
        ),
        "RINEX VERSION / TYPE",
    );
    hline(
        &mut o,
        &format!("{:<20}{:<20}{:<20}", "sdins", "", ""),
        "PGM / RUN BY / DATE",
    );
    if let Some(k) = n.klobuchar {
        for (name, c) in [("GPSA", k.alpha), ("GPSB", k.beta)] {
            let s: String = c.iter().map(|v| fmt_d(*v, 12, 4)).collect();
            hline(&mut o, &format!("{name} {s}"), "IONOSPHERIC CORR");
        }
    }
    hline(&mut o, "", "END OF HEADER");
    for e in &n.ephemerides {
        eph_record(&mut o, e);
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fortran_d_format() {
        assert_eq!(fmt_d(5.405521951616e-04, 19, 12), " 5.405521951616E-04");
        assert_eq!(fmt_d(-2.0489e-8, 19, 12), "-2.048900000000E-08");
        assert_eq!(fmt_d(0.0, 19, 12), " 0.000000000000E+00");
        assert_eq!(fmt_d(1826.0, 19, 12), " 1.826000000000E+03");
        assert_eq!(fmt_d(0.1118e-7, 12, 4), "  1.1180E-08");
    }
}
