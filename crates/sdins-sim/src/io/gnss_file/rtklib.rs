//! RTKLIB `.pos` solution files (RTKPOST/RTKNAVI/rnx2rtkp output): `%` header lines, the
//! last of them naming the columns with the time system first (`GPST`, `UTC` or `JST`),
//! then one solution per line: time as a date `yyyy/mm/dd hh:mm:ss.sss` or as
//! `week seconds-of-week`, `latitude(deg) longitude(deg) height(m) Q ns sdn(m) sde(m)
//! sdu(m) sdne(m) sdeu(m) sdun(m) age(s) ratio`, optionally followed by the velocity
//! columns `vn(m/s) ve(m/s) vu(m/s) sdvn sdve sdvu sdvne sdveu sdvun`.
//!
//! RTKLIB writes the off-diagonal terms as signed square roots, `sdne = sign(c_ne)·√|c_ne|`
//! (its manual, appendix B "solution file"), so `c_ne = sdne·|sdne|`. The ENU covariance
//! becomes NED with `c_ND = −c_NU`, `c_ED = −c_EU`, `c_DD = c_UU`; it must be positive
//! definite. Times become GPS seconds since 1980-01-06: week·604 800 + seconds (full week
//! numbers, so no 1024-week ambiguity; seconds running past a week stay continuous); UTC
//! dates add GPS − UTC from [`LEAP_SECONDS`](super::LEAP_SECONDS); JST is UTC + 9 h.
//! Heights: the header line `(lat/lon/height=WGS84/ellipsoidal…)` is required to say
//! `ellipsoidal` or `geodetic`; geodetic (mean-sea-level) heights are refused unless a
//! geoid undulation N is given (h = H + N, constant for the file). Without that header line
//! (a headerless file) ellipsoidal heights and GPST are assumed, with a warning. Latitude
//! in degrees-minutes-seconds, ECEF and ENU-baseline layouts are refused.

use super::gps_time::{days_in_month, gps_minus_utc_s, gps_seconds_from_date};
use super::rows::{self, check_cut_number, Ctx, Field, Line};
use super::{
    finish, GnssData, GnssFileError, GnssFormat, GnssReadOptions, GnssReadReport, TimeBase,
    SECONDS_PER_WEEK,
};
use crate::sensors::gnss_fix::GnssFix;
use sdins_core::math::{Mat3, Vec3};
use std::path::Path;

/// The default RTKLIB columns after the time.
const DEFAULT_COLUMNS: [&str; 13] = [
    "latitude(deg)",
    "longitude(deg)",
    "height(m)",
    "Q",
    "ns",
    "sdn(m)",
    "sde(m)",
    "sdu(m)",
    "sdne(m)",
    "sdeu(m)",
    "sdun(m)",
    "age(s)",
    "ratio",
];
const VEL_COLUMNS: [&str; 9] = [
    "vn(m/s)", "ve(m/s)", "vu(m/s)", "sdvn", "sdve", "sdvu", "sdvne", "sdveu", "sdvun",
];

/// Time systems.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum TimeSys {
    Gpst,
    Utc,
    Jst,
}

/// Is this a headerless RTKLIB solution line (date + time or week + seconds, then at least
/// the 13 default columns)?
pub(crate) fn looks_like_data(line: &str) -> bool {
    let f: Vec<&str> = line.split_whitespace().collect();
    if f.len() < 15 {
        return false;
    }
    let date = f[0].len() == 10 && f[0].as_bytes().get(4) == Some(&b'/') && f[1].contains(':');
    let week = f[0].parse::<u32>().is_ok() && f[1].parse::<f64>().is_ok();
    (date || week) && f[2..15].iter().all(|s| s.parse::<f64>().is_ok())
}

/// Column indices in a data line (after the two time tokens).
struct Cols {
    lat: usize,
    lon: usize,
    h: usize,
    q: usize,
    sd: [usize; 6],
    vel: Option<[usize; 9]>,
    n: usize,
}

fn columns(ctx: &Ctx<'_>, line: Line<'_>, names: &[Field<'_>]) -> Result<Cols, GnssFileError> {
    let find = |n: &str| names.iter().position(|f| f.text == n);
    let unsupported = |col: usize, what: String| GnssFileError::Unsupported {
        file: ctx.f(),
        line: line.no,
        column: col,
        what,
    };
    for f in names {
        if f.text.starts_with("latitude(d'")
            || f.text.contains("ecef")
            || f.text.contains("baseline")
        {
            return Err(unsupported(
                f.column,
                format!("RTKLIB column `{}`: only latitude/longitude in decimal degrees is read; export with `-d` off and position format `llh` (sol format lat/lon/height)", f.text),
            ));
        }
    }
    let mut idx = [0usize; 11];
    for (k, name) in DEFAULT_COLUMNS[..11].iter().enumerate() {
        idx[k] = find(name).ok_or_else(|| GnssFileError::Header {
            file: ctx.f(),
            line: line.no,
            column: 1,
            expected: format!("an RTKLIB column `{name}`"),
            found: line.text.chars().take(160).collect(),
        })?;
    }
    let vel = if let Some(v0) = find(VEL_COLUMNS[0]) {
        let mut v = [0usize; 9];
        for (k, name) in VEL_COLUMNS.iter().enumerate() {
            v[k] = find(name).ok_or_else(|| GnssFileError::Header {
                file: ctx.f(),
                line: line.no,
                column: names[v0].column,
                expected: format!("the RTKLIB velocity column `{name}` with `vn(m/s)`"),
                found: line.text.chars().take(160).collect(),
            })?;
        }
        Some(v)
    } else {
        None
    };
    Ok(Cols {
        lat: idx[0],
        lon: idx[1],
        h: idx[2],
        q: idx[3],
        sd: [idx[5], idx[6], idx[7], idx[8], idx[9], idx[10]],
        vel,
        n: names.len(),
    })
}

/// ENU (σn, σe, σu, signed σne, σeu, σun) → NED covariance.
fn ned_cov(s: [f64; 6]) -> Mat3 {
    let sq = |x: f64| x * x.abs();
    let (nn, ee, uu) = (s[0] * s[0], s[1] * s[1], s[2] * s[2]);
    let (ne, eu, un) = (sq(s[3]), sq(s[4]), sq(s[5]));
    Mat3::new(nn, ne, -un, ne, ee, -eu, -un, -eu, uu)
}

/// Parse the time tokens into GPS seconds since the epoch.
fn time(
    ctx: &Ctx<'_>,
    l: Line<'_>,
    a: Field<'_>,
    b: Field<'_>,
    sys: TimeSys,
) -> Result<f64, GnssFileError> {
    if a.text.contains('/') {
        let bad = |fld: Field<'_>, what: &str| GnssFileError::NotANumber {
            file: ctx.f(),
            line: l.no,
            column: fld.column,
            field: what.to_string(),
            text: fld.text.chars().take(40).collect(),
        };
        let d: Vec<&str> = a.text.split('/').collect();
        let tm: Vec<&str> = b.text.split(':').collect();
        if d.len() != 3 || tm.len() != 3 {
            return Err(bad(
                if d.len() != 3 { a } else { b },
                "date yyyy/mm/dd hh:mm:ss.sss",
            ));
        }
        let y: i32 = d[0].parse().map_err(|_| bad(a, "year"))?;
        let mo: u32 = d[1].parse().map_err(|_| bad(a, "month"))?;
        let dd: u32 = d[2].parse().map_err(|_| bad(a, "day"))?;
        let h: u32 = tm[0].parse().map_err(|_| bad(b, "hour"))?;
        let mi: u32 = tm[1].parse().map_err(|_| bad(b, "minute"))?;
        let s: f64 = tm[2].parse().map_err(|_| bad(b, "second"))?;
        let ok_date = (1980..=2100).contains(&y)
            && (1..=12).contains(&mo)
            && dd >= 1
            && dd <= days_in_month(y, mo);
        ctx.range(
            l.no,
            a,
            "date",
            f64::from(y),
            ok_date,
            "a calendar date from 1980 to 2100",
        )?;
        let ok_time = h < 24 && mi < 60 && s.is_finite() && (0.0..61.0).contains(&s);
        ctx.range(
            l.no,
            b,
            "time",
            s,
            ok_time,
            "a time of day hh:mm:ss.sss (seconds < 61)",
        )?;
        let t = gps_seconds_from_date(y, mo, dd, h, mi, s);
        Ok(match sys {
            TimeSys::Gpst => t,
            TimeSys::Utc => t + gps_minus_utc_s(y, mo, dd),
            TimeSys::Jst => {
                // JST = UTC + 9 h: the UTC date decides the leap seconds
                let utc = t - 9.0 * 3600.0;
                let days = (utc / 86_400.0).floor() as i64;
                let (uy, um, ud) = civil_from_gps_days(days);
                utc + gps_minus_utc_s(uy, um, ud)
            }
        })
    } else {
        let w = ctx.num(l.no, a, "gps_week")?;
        ctx.range(
            l.no,
            a,
            "gps_week",
            w,
            (0.0..10_000.0).contains(&w) && w.fract() == 0.0,
            "a whole GPS week number",
        )?;
        let tow = ctx.num(l.no, b, "gps_tow_s")?;
        ctx.range(
            l.no,
            b,
            "gps_tow_s",
            tow,
            (0.0..SECONDS_PER_WEEK).contains(&tow),
            "seconds of week in [0, 604800)",
        )?;
        let t = w * SECONDS_PER_WEEK + tow;
        Ok(match sys {
            TimeSys::Gpst => t,
            // a week/seconds count on UTC or JST: convert via the UTC date it falls on
            TimeSys::Utc | TimeSys::Jst => {
                let utc = t - if sys == TimeSys::Jst {
                    9.0 * 3600.0
                } else {
                    0.0
                };
                let (uy, um, ud) = civil_from_gps_days((utc / 86_400.0).floor() as i64);
                utc + gps_minus_utc_s(uy, um, ud)
            }
        })
    }
}

/// Civil date of a day count since the GPS epoch (inverse of the era algorithm).
fn civil_from_gps_days(days: i64) -> (i32, u32, u32) {
    let z = days + super::gps_time::days_from_civil(1980, 1, 6) + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let y = yoe + era * 400;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    ((y + i64::from(m <= 2)) as i32, m, d)
}

pub(crate) fn parse(
    file: &Path,
    text: &str,
    opts: &GnssReadOptions,
) -> Result<GnssData, GnssFileError> {
    let ctx = Ctx { file };
    let lines = rows::lines(text);
    if lines.is_empty() {
        return Err(GnssFileError::Empty {
            file: file.to_path_buf(),
        });
    }
    let n_header = lines
        .iter()
        .position(|l| !l.text.trim_start().starts_with('%'))
        .unwrap_or(lines.len());
    let header = &lines[..n_header];
    let mut report = GnssReadReport::default();
    // height type
    let mut geoid_n = 0.0;
    match header.iter().find(|l| l.text.contains("lat/lon/height=")) {
        Some(l) => {
            let k = l.text.find("lat/lon/height=").unwrap_or(0);
            let rest = &l.text[k..];
            let col = l.text[..k].chars().count() + 1;
            if rest.contains("ellipsoidal") {
            } else if rest.contains("geodetic") {
                match opts.geoid_undulation_m {
                    Some(n) if n.is_finite() && n.abs() <= 200.0 => {
                        geoid_n = n;
                        report.warnings.push(format!(
                            "geodetic (mean-sea-level) heights made ellipsoidal with the given geoid undulation N = {n} m"
                        ));
                    }
                    _ => {
                        return Err(GnssFileError::Unsupported {
                            file: ctx.f(),
                            line: l.no,
                            column: col,
                            what: "RTKLIB heights are geodetic (mean sea level): give a geoid undulation (finite, |N| <= 200 m) or export ellipsoidal heights (RTKLIB option out-height = ellipsoidal)".into(),
                        })
                    }
                }
            } else {
                return Err(GnssFileError::Unsupported {
                    file: ctx.f(),
                    line: l.no,
                    column: col,
                    what: format!(
                        "RTKLIB `{}`: expected the datum WGS84 and the height type `ellipsoidal` or `geodetic`",
                        rest.chars().take(60).collect::<String>()
                    ),
                });
            }
            if !rest.starts_with("lat/lon/height=WGS84") {
                return Err(GnssFileError::Unsupported {
                    file: ctx.f(),
                    line: l.no,
                    column: col,
                    what: "RTKLIB datum is not WGS84 (only WGS84 is read)".into(),
                });
            }
        }
        None => report.warnings.push(
            "no RTKLIB `lat/lon/height=` header line: heights assumed ellipsoidal (WGS84)".into(),
        ),
    }
    // column line: the last header line
    let (sys, cols, sys_name) = match header.last() {
        Some(l) => {
            let body = l.text.trim_start().trim_start_matches('%');
            let off = l.text.len() - body.len();
            let mut names = rows::split(body);
            for f in &mut names {
                f.column += l.text[..off].chars().count();
            }
            let Some(first) = names.first().copied() else {
                return Err(GnssFileError::Header {
                    file: ctx.f(),
                    line: l.no,
                    column: 1,
                    expected: "the RTKLIB column line `%  GPST latitude(deg) ...`".into(),
                    found: l.text.into(),
                });
            };
            let sys = match first.text {
                "GPST" => TimeSys::Gpst,
                "UTC" => TimeSys::Utc,
                "JST" => TimeSys::Jst,
                other => {
                    return Err(GnssFileError::Unsupported {
                        file: ctx.f(),
                        line: l.no,
                        column: first.column,
                        what: format!(
                            "RTKLIB time system `{other}`: expected GPST, UTC or JST as the first column name"
                        ),
                    })
                }
            };
            (sys, columns(&ctx, *l, &names[1..])?, first.text.to_string())
        }
        None => {
            report
                .warnings
                .push("no RTKLIB header: time system GPST and default columns assumed".into());
            let n: Vec<Field<'_>> = DEFAULT_COLUMNS
                .iter()
                .map(|t| Field { text: t, column: 1 })
                .collect();
            let l = Line { no: 0, text: "" };
            (TimeSys::Gpst, columns(&ctx, l, &n)?, "GPST".to_string())
        }
    };
    report.time_system = sys_name;
    let data = &lines[n_header..];
    let unterminated = !text.ends_with('\n');
    let mut fixes = Vec::with_capacity(data.len());
    let mut prev_t = None;
    let mut prev_fields: Vec<Field<'_>> = Vec::new();
    for (k, l) in data.iter().enumerate() {
        let f = rows::split(l.text);
        let last = k + 1 == data.len();
        ctx.count(*l, &f, &[2 + cols.n], unterminated && last)?;
        if last {
            check_cut_number(&ctx, &prev_fields, *l, &f, unterminated)?;
        }
        let d = &f[2..];
        let t = time(&ctx, *l, f[0], f[1], sys)?;
        ctx.increasing(l.no, f[0], prev_t, t)?;
        prev_t = Some(t);
        let q = ctx.num(l.no, d[cols.q], "Q")?;
        ctx.range(
            l.no,
            d[cols.q],
            "Q",
            q,
            (1.0..=6.0).contains(&q) && q.fract() == 0.0,
            "a quality flag 1..6",
        )?;
        if let Some(max) = opts.rtklib_max_q {
            if q > f64::from(max) {
                report.skipped_quality += 1;
                prev_fields = f;
                continue;
            }
        }
        let lat = ctx.lat_deg(l.no, d[cols.lat], "latitude(deg)")?;
        let lon = ctx.lon_deg(l.no, d[cols.lon], "longitude(deg)")?;
        let hf = d[cols.h];
        let h = ctx.num(l.no, hf, "height(m)")? + geoid_n;
        let h = ctx.range(
            l.no,
            hf,
            "height(m)",
            h,
            (super::H_RANGE_M.0..=super::H_RANGE_M.1).contains(&h),
            "an ellipsoidal height within [-1000, 100000] m",
        )?;
        let names = [
            "sdn(m)", "sde(m)", "sdu(m)", "sdne(m)", "sdeu(m)", "sdun(m)",
        ];
        let mut s = [0.0; 6];
        for i in 0..6 {
            let fld = d[cols.sd[i]];
            s[i] = if i < 3 {
                ctx.sigma(l.no, fld, names[i])?
            } else {
                let v = ctx.num(l.no, fld, names[i])?;
                ctx.range(
                    l.no,
                    fld,
                    names[i],
                    v,
                    v.abs() <= super::MAX_SIGMA_M,
                    "a signed σ within ±1e6",
                )?
            };
        }
        let pos_cov = ned_cov(s);
        if pos_cov.cholesky().is_none() {
            return Err(GnssFileError::NotPositiveDefinite {
                file: ctx.f(),
                line: l.no,
                column: d[cols.sd[0]].column,
                fields: names.join(" "),
            });
        }
        let vel = match cols.vel {
            None => None,
            Some(vc) => {
                let vn = ["vn(m/s)", "ve(m/s)", "vu(m/s)"];
                let v_enu: Vec<f64> = (0..3)
                    .map(|i| ctx.vel(l.no, d[vc[i]], vn[i]))
                    .collect::<Result<_, _>>()?;
                let sn = ["sdvn", "sdve", "sdvu", "sdvne", "sdveu", "sdvun"];
                let mut sv = [0.0; 6];
                for i in 0..6 {
                    let fld = d[vc[3 + i]];
                    sv[i] = if i < 3 {
                        ctx.sigma(l.no, fld, sn[i])?
                    } else {
                        let v = ctx.num(l.no, fld, sn[i])?;
                        ctx.range(
                            l.no,
                            fld,
                            sn[i],
                            v,
                            v.abs() <= super::MAX_SIGMA_M,
                            "a signed σ within ±1e6",
                        )?
                    };
                }
                let c = ned_cov(sv);
                if c.cholesky().is_none() {
                    return Err(GnssFileError::NotPositiveDefinite {
                        file: ctx.f(),
                        line: l.no,
                        column: d[vc[3]].column,
                        fields: sn.join(" "),
                    });
                }
                Some((Vec3::new(v_enu[0], v_enu[1], -v_enu[2]), c))
            }
        };
        fixes.push(GnssFix {
            t_s: t,
            lat_rad: lat.to_radians(),
            lon_rad: rows::wrap_lon_rad(lon.to_radians()),
            h_m: h,
            pos_cov_ned_m2: pos_cov,
            vel,
        });
        prev_fields = f;
    }
    report.rows = data.len();
    if fixes.is_empty() && report.skipped_quality > 0 {
        return Err(GnssFileError::AllFiltered {
            file: ctx.f(),
            skipped: report.skipped_quality,
            max_q: opts.rtklib_max_q.unwrap_or(6),
        });
    }
    let header_line = header.last().map(|l| l.no);
    finish(
        file,
        text,
        header_line,
        fixes,
        GnssFormat::Rtklib,
        TimeBase::GpsSecondsSinceEpoch,
        report,
    )
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests;
