//! RINEX navigation files with GPS broadcast ephemerides: version 2.10/2.11 (`N`) and 3.0x
//! (`N`, GPS or mixed; records of other systems are skipped). Ionospheric α/β come from
//! `ION ALPHA`/`ION BETA` (2.x) or `IONOSPHERIC CORR` `GPSA`/`GPSB` (3.x) when present.

use super::error::RinexError;
use super::text::{ascii_text, col, Ctx};
use sdins_core::gnss::{GpsEphemeris, GpsTime, KlobucharCoefficients};
use std::path::Path;

/// A navigation file's GPS content.
#[derive(Clone, Debug, PartialEq)]
pub struct NavFile {
    /// format version
    pub version: f64,
    /// broadcast ionosphere coefficients from the header, when present
    pub klobuchar: Option<KlobucharCoefficients>,
    /// GPS ephemerides in file order (each validated: finite fields, ellipse)
    pub ephemerides: Vec<GpsEphemeris>,
    /// records of other systems that were skipped
    pub skipped_records: usize,
}

/// Reads a RINEX navigation file (size-capped read).
pub fn read_nav(path: &Path) -> Result<NavFile, RinexError> {
    let name = path.display().to_string();
    let bytes = crate::input::read_capped(path).map_err(|source| RinexError::Io {
        file: name.clone(),
        source,
    })?;
    parse_nav(&bytes, &name)
}

fn four(
    ctx: &Ctx,
    ln: usize,
    line: &str,
    start: usize,
    width: usize,
    field: &str,
) -> Result<[f64; 4], RinexError> {
    let mut v = [0.0; 4];
    for (k, x) in v.iter_mut().enumerate() {
        *x = ctx.f64(ln, line, start + width * k, start + width * (k + 1), field)?;
    }
    Ok(v)
}

/// Continuation lines of a RINEX 3 record by system letter (RINEX 3.04 Tables A6–A16).
fn extra_lines3(sys: u8) -> Option<usize> {
    match sys {
        b'G' | b'E' | b'C' | b'J' | b'I' => Some(7),
        b'R' | b'S' => Some(3),
        _ => None,
    }
}

/// Names of the 29 numeric fields of a GPS record in RINEX order (for error messages).
const FIELDS: [&str; 31] = [
    "SV clock bias",
    "SV clock drift",
    "SV clock drift rate",
    "IODE",
    "Crs",
    "Delta n",
    "M0",
    "Cuc",
    "e",
    "Cus",
    "sqrt(A)",
    "Toe",
    "Cic",
    "OMEGA0",
    "Cis",
    "i0",
    "Crc",
    "omega",
    "OMEGA DOT",
    "IDOT",
    "Codes on L2",
    "GPS Week",
    "L2 P data flag",
    "SV accuracy",
    "SV health",
    "TGD",
    "IODC",
    "Transmission time",
    "Fit interval",
    "spare",
    "spare",
];

/// Parses a navigation file from bytes (non-ASCII bytes become spaces first).
pub fn parse_nav(bytes: &[u8], name: &str) -> Result<NavFile, RinexError> {
    let text = ascii_text(bytes);
    let lines: Vec<&str> = text.lines().map(|l| l.trim_end_matches('\r')).collect();
    let ctx = Ctx { file: name };
    let mut version = 0.0;
    let (mut alpha, mut beta) = (None, None);
    let mut i = 0;
    loop {
        let line = *lines.get(i).ok_or_else(|| RinexError::Truncated {
            file: name.into(),
            line: lines.len(),
            what: "the header (no END OF HEADER)".into(),
        })?;
        let ln = i + 1;
        i += 1;
        match col(line, 60, 80).trim() {
            "RINEX VERSION / TYPE" => {
                version = ctx.f64(ln, line, 0, 9, "RINEX VERSION")?;
                let (t, s) = (col(line, 20, 21), col(line, 40, 41));
                let ok = t == "N" && (version < 3.0 || s == "G" || s == "M" || s.trim().is_empty());
                if !ok || !(2.0..4.0).contains(&version) {
                    return Err(RinexError::Unsupported { file: name.into(), line: ln, what: format!("navigation file type {t:?} system {s:?} version {version} (GPS navigation 2.x/3.x only)") });
                }
            }
            "ION ALPHA" => alpha = Some(four(&ctx, ln, line, 2, 12, "ION ALPHA")?),
            "ION BETA" => beta = Some(four(&ctx, ln, line, 2, 12, "ION BETA")?),
            "IONOSPHERIC CORR" => match col(line, 0, 4) {
                "GPSA" => alpha = Some(four(&ctx, ln, line, 5, 12, "IONOSPHERIC CORR GPSA")?),
                "GPSB" => beta = Some(four(&ctx, ln, line, 5, 12, "IONOSPHERIC CORR GPSB")?),
                _ => {}
            },
            "END OF HEADER" => break,
            _ => {}
        }
    }
    if version == 0.0 {
        return Err(ctx.field_err(1, "RINEX VERSION / TYPE", "missing"));
    }
    let v3 = version >= 3.0;
    let mut ephs = Vec::new();
    let mut skipped = 0;
    while i < lines.len() {
        let line = lines[i];
        let ln = i + 1;
        if line.trim().is_empty() {
            i += 1;
            continue;
        }
        let (prn, toc, first) = if v3 {
            let sys = line.as_bytes().first().copied().unwrap_or(b' ');
            let extra = extra_lines3(sys).ok_or_else(|| {
                ctx.field_err(
                    ln,
                    "satellite system",
                    format!("unknown record start {:?}", col(line, 0, 3)),
                )
            })?;
            if sys != b'G' {
                i += 1 + extra;
                skipped += 1;
                continue;
            }
            let prn = ctx.int(ln, line, 1, 3, "PRN")?;
            let c = [(4, 8), (9, 11), (12, 14), (15, 17), (18, 20), (21, 23)];
            (prn, toc_of(&ctx, ln, line, c, false)?, 23)
        } else {
            let prn = ctx.int(ln, line, 0, 2, "PRN")?;
            let c = [(2, 5), (5, 8), (8, 11), (11, 14), (14, 17), (17, 22)];
            (prn, toc_of(&ctx, ln, line, c, true)?, 22)
        };
        if !(1..=32).contains(&prn) {
            return Err(ctx.field_err(ln, "PRN", format!("{prn} (GPS PRNs are 1-32)")));
        }
        let mut d = [0.0f64; 31];
        for (k, x) in d.iter_mut().take(3).enumerate() {
            *x = ctx
                .opt_f64(ln, line, first + 19 * k, first + 19 * (k + 1), FIELDS[k])?
                .unwrap_or(0.0);
        }
        let start = if v3 { 4 } else { 3 };
        for r in 1..=7 {
            let l = *lines.get(i + r).ok_or_else(|| RinexError::Truncated {
                file: name.into(),
                line: lines.len(),
                what: format!("the ephemeris record of G{prn:02} starting at line {ln}"),
            })?;
            for k in 0..4 {
                let idx = 3 + 4 * (r - 1) + k;
                d[idx] = ctx
                    .opt_f64(
                        i + r + 1,
                        l,
                        start + 19 * k,
                        start + 19 * (k + 1),
                        FIELDS[idx],
                    )?
                    .unwrap_or(0.0);
            }
        }
        let eph = build(&ctx, ln, prn as u8, toc, &d)?;
        ephs.push(eph);
        i += 8;
    }
    let klobuchar = match (alpha, beta) {
        (Some(alpha), Some(beta)) if alpha.iter().chain(beta.iter()).any(|v| *v != 0.0) => {
            Some(KlobucharCoefficients { alpha, beta })
        }
        _ => None,
    };
    Ok(NavFile {
        version,
        klobuchar,
        ephemerides: ephs,
        skipped_records: skipped,
    })
}

fn toc_of(
    ctx: &Ctx,
    ln: usize,
    line: &str,
    c: [(usize, usize); 6],
    yy2: bool,
) -> Result<GpsTime, RinexError> {
    let mut y = ctx.int(ln, line, c[0].0, c[0].1, "Toc year")?;
    if yy2 {
        y += if y < 80 { 2000 } else { 1900 };
    }
    let mo = ctx.int(ln, line, c[1].0, c[1].1, "Toc month")?;
    let dd = ctx.int(ln, line, c[2].0, c[2].1, "Toc day")?;
    let h = ctx.int(ln, line, c[3].0, c[3].1, "Toc hour")?;
    let mi = ctx.int(ln, line, c[4].0, c[4].1, "Toc minute")?;
    let s = ctx.f64(ln, line, c[5].0, c[5].1, "Toc second")?;
    let ok = (1980..=2200).contains(&y)
        && (1..=12).contains(&mo)
        && (1..=31).contains(&dd)
        && (0..=24).contains(&h)
        && (0..=59).contains(&mi)
        && (0.0..61.0).contains(&s);
    if !ok {
        return Err(ctx.field_err(
            ln,
            "Toc",
            format!("date/time out of range: {:?}", line.trim_end()),
        ));
    }
    Ok(GpsTime::from_calendar(
        y as i32, mo as u32, dd as u32, h as u32, mi as u32, s,
    ))
}

fn build(
    ctx: &Ctx,
    ln: usize,
    prn: u8,
    toc: GpsTime,
    d: &[f64; 31],
) -> Result<GpsEphemeris, RinexError> {
    let uint = |idx: usize| -> Result<u32, RinexError> {
        let v = d[idx];
        if v >= 0.0 && v <= u32::MAX as f64 && v.fract() == 0.0 {
            Ok(v as u32)
        } else {
            Err(ctx.field_err(
                ln,
                FIELDS[idx],
                format!("{v} is not a non-negative integer (record starting here)"),
            ))
        }
    };
    let week = d[21];
    if !(0.0..=10_000.0).contains(&week) || week.fract() != 0.0 {
        return Err(ctx.field_err(ln, "GPS Week", format!("{week} (record starting here)")));
    }
    if !(0.0..604_800.0).contains(&d[11]) {
        return Err(ctx.field_err(
            ln,
            "Toe",
            format!("{} is not a second of week (record starting here)", d[11]),
        ));
    }
    // toe's week: the record's week, moved by a whole week to within half a week of toc
    let mut toe = GpsTime::new(week as i32, d[11]);
    let dt = toe.diff_s(&toc);
    if dt > 302_400.0 {
        toe = GpsTime::new(toe.week - 1, toe.sow_s);
    } else if dt < -302_400.0 {
        toe = GpsTime::new(toe.week + 1, toe.sow_s);
    }
    let eph = GpsEphemeris {
        prn,
        toc,
        af0_s: d[0],
        af1_sps: d[1],
        af2_sps2: d[2],
        iode: uint(3)?,
        crs_m: d[4],
        delta_n_rps: d[5],
        m0_rad: d[6],
        cuc_rad: d[7],
        e: d[8],
        cus_rad: d[9],
        sqrt_a_sqrtm: d[10],
        toe,
        cic_rad: d[12],
        omega0_rad: d[13],
        cis_rad: d[14],
        i0_rad: d[15],
        crc_m: d[16],
        omega_rad: d[17],
        omega_dot_rps: d[18],
        idot_rps: d[19],
        codes_on_l2: uint(20)?,
        l2p_data_flag: uint(22)?,
        sv_accuracy_m: d[23],
        health: uint(24)?,
        tgd_s: d[25],
        iodc: uint(26)?,
        transmit_time_s: d[27],
        fit_interval_h: d[28],
    };
    eph.validate()
        .map_err(|e| ctx.field_err(ln, "ephemeris", format!("{e} (record starting here)")))?;
    Ok(eph)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    const V2: &str =
        "     2.10           N: GPS NAV DATA                         RINEX VERSION / TYPE
    0.1118D-07 -0.7451D-08 -0.5961D-07  0.1192D-06          ION ALPHA
    0.1167D+06 -0.2294D+06 -0.1311D+06  0.1049D+07          ION BETA
                                                            END OF HEADER
 2 15  1  8  2  0  0.0 5.405521951616D-04 2.273736754432D-12 0.000000000000D+00
    4.900000000000D+01-3.762500000000D+01 4.611977821674D-09-1.812812498346D+00
   -2.050772309303D-06 1.415320031811D-02 1.079961657524D-05 5.153748075485D+03
    3.528000000000D+05 1.750886440277D-07 5.432620325643D-01-2.309679985046D-07
    9.405292705336D-01 1.596875000000D+02-2.344988861010D+00-7.761037564081D-09
    3.135844906242D-10 0.000000000000D+00 1.826000000000D+03 0.000000000000D+00
    2.000000000000D+00 0.000000000000D+00-2.048909664154D-08 4.900000000000D+01
    3.456000000000D+05 4.000000000000D+00
";

    #[test]
    fn rinex2_record_fields_in_order() {
        let n = parse_nav(V2.as_bytes(), "t.n").unwrap();
        let e = n.ephemerides[0];
        assert_eq!(e.prn, 2);
        assert_eq!((e.toc.week, e.toc.sow_s), (1826, 352_800.0));
        assert_eq!((e.toe.week, e.toe.sow_s), (1826, 352_800.0));
        assert_eq!(e.af0_s, 5.405521951616e-04);
        assert_eq!(e.iode, 49);
        assert_eq!(e.sqrt_a_sqrtm, 5.153748075485e+03);
        assert_eq!(e.omega_dot_rps, -7.761037564081e-09);
        assert_eq!(e.tgd_s, -2.048909664154e-08);
        assert_eq!(
            (e.iodc, e.health, e.sv_accuracy_m, e.fit_interval_h),
            (49, 0, 2.0, 4.0)
        );
        assert_eq!(n.klobuchar.unwrap().beta[3], 0.1049e7);
    }

    /// Every single-character corruption and every truncation of a valid file parses or
    /// fails with a typed error: never a panic.
    #[test]
    fn corrupted_files_never_panic() {
        let b = V2.as_bytes();
        for i in 0..b.len() {
            for c in [b'x', b' ', b'9', b'-', b'\n', b'G', 0xd4] {
                let mut m = b.to_vec();
                m[i] = c;
                let _ = parse_nav(&m, "m.n");
            }
            let _ = parse_nav(&b[..i], "m.n");
        }
    }

    #[test]
    fn broken_records_are_located() {
        let bad = V2.replace("1.415320031811D-02", "1.4153200318x1D-02");
        let e = parse_nav(bad.as_bytes(), "t.n").unwrap_err().to_string();
        assert_eq!(e, "t.n:7: e: not a number: \"1.4153200318x1D-02\"");
        let cut: String = V2.lines().take(9).collect::<Vec<_>>().join("\n");
        let e = parse_nav(cut.as_bytes(), "t.n").unwrap_err().to_string();
        assert!(
            e.contains("t.n:9: file ends inside the ephemeris record of G02 starting at line 5"),
            "{e}"
        );
        let bad = V2.replace(" 1.415320031811D-02", " 1.415320031811D+02");
        let e = parse_nav(bad.as_bytes(), "t.n").unwrap_err().to_string();
        assert!(
            e.contains("t.n:5: ephemeris: ephemeris of G02: invalid e"),
            "{e}"
        );
    }
}
