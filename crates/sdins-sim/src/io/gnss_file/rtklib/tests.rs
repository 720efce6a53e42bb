use super::*;
use crate::io::gnss_file::{parse_gnss_str, to_imu_time, ImuClock};

const HEAD: &str = "% program   : RTKPOST ver.2.4.3\n% inp file  : rover.obs\n% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)\n";
const COLS: &str = "%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio\n";

fn row(time: &str, q: u8, sd: &str) -> String {
    format!("{time}   35.681234567  139.767123456    40.1234   {q}  10   {sd}   0.00    0.0\n")
}
const SD: &str = "0.0100   0.0080   0.0200   0.0030  -0.0040   0.0050";

fn rt(t: &str) -> Result<GnssData, GnssFileError> {
    parse_gnss_str(
        Path::new("sol.pos"),
        t,
        GnssFormat::Auto,
        &GnssReadOptions::default(),
    )
}

fn file(sys: &str, rows: &[String]) -> String {
    format!("{HEAD}{}{}", COLS.replace("GPST", sys), rows.concat())
}

#[test]
fn date_gpst_and_covariance() {
    let t = file(
        "GPST",
        &[
            row("2020/01/01 00:00:00.000", 1, SD),
            row("2020/01/01 00:00:01.000", 2, SD),
        ],
    );
    let d = rt(&t).unwrap();
    assert_eq!(d.format, GnssFormat::Rtklib);
    assert_eq!(d.time_base, TimeBase::GpsSecondsSinceEpoch);
    assert_eq!(d.report.time_system, "GPST");
    // 2020-01-01 00:00 GPST = week 2086 (starts 2019-12-29) + 3 days
    assert_eq!(d.fixes[0].t_s, 2086.0 * SECONDS_PER_WEEK + 3.0 * 86_400.0);
    let c = d.fixes[0].pos_cov_ned_m2;
    // c_ne = 0.003·|0.003|, c_eu = −0.004², c_un = 0.005²; NED: c_nd = −c_un, c_ed = −c_eu
    assert!((c[(0, 0)] - 1e-4).abs() < 1e-18);
    assert!((c[(2, 2)] - 4e-4).abs() < 1e-18);
    assert!((c[(0, 1)] - 9e-6).abs() < 1e-18);
    assert!((c[(1, 2)] - 16e-6).abs() < 1e-18);
    assert!((c[(0, 2)] + 25e-6).abs() < 1e-18);
    assert_eq!(c, c.transpose());
    // to GPS seconds of week of the first fix
    let m = to_imu_time(Path::new("sol.pos"), &d, ImuClock::GpsSecondsOfWeek).unwrap();
    assert_eq!(m[0].t_s, 3.0 * 86_400.0);
    assert_eq!(m[1].t_s, 3.0 * 86_400.0 + 1.0);
}

#[test]
fn week_seconds_utc_jst() {
    // week/seconds, GPST, crossing a week boundary: continuous
    let t = file(
        "GPST",
        &[row("2086 604799.000", 1, SD), row("2087      0.000", 1, SD)],
    );
    let d = rt(&t).unwrap();
    assert_eq!(d.fixes[1].t_s - d.fixes[0].t_s, 1.0);
    let m = to_imu_time(Path::new("sol.pos"), &d, ImuClock::GpsSecondsOfWeek).unwrap();
    assert_eq!((m[0].t_s, m[1].t_s), (604_799.0, 604_800.0));
    // UTC: +18 s in 2020 (GPS − UTC after 2017-01-01); 17 s in 2016
    let g = rt(&file("GPST", &[row("2020/01/01 00:00:18.000", 1, SD)])).unwrap();
    let u = rt(&file("UTC", &[row("2020/01/01 00:00:00.000", 1, SD)])).unwrap();
    assert_eq!(u.report.time_system, "UTC");
    assert_eq!(g.fixes[0].t_s, u.fixes[0].t_s);
    let u16 = rt(&file("UTC", &[row("2016/12/31 23:59:59.000", 1, SD)])).unwrap();
    let u17 = rt(&file("UTC", &[row("2017/01/01 00:00:00.000", 1, SD)])).unwrap();
    // one UTC second apart, two GPS seconds (the leap second at the end of 2016)
    assert_eq!(u17.fixes[0].t_s - u16.fixes[0].t_s, 2.0);
    // JST = UTC + 9 h
    let j = rt(&file("JST", &[row("2020/01/01 09:00:00.000", 1, SD)])).unwrap();
    assert_eq!(j.fixes[0].t_s, u.fixes[0].t_s);
    // unknown time system
    let x = rt(&file("TAI", &[row("2020/01/01 09:00:00.000", 1, SD)])).unwrap_err();
    assert!(
        matches!(
            x,
            GnssFileError::Unsupported {
                line: 4,
                column: 4,
                ..
            }
        ),
        "{x}"
    );
}

#[test]
fn quality_height_velocity() {
    let rows = [
        row("2086 100.0", 1, SD),
        row("2086 101.0", 5, SD),
        row("2086 102.0", 2, SD),
    ];
    let o = GnssReadOptions::default().with_rtklib_max_q(2);
    let d = parse_gnss_str(
        Path::new("s.pos"),
        &file("GPST", &rows),
        GnssFormat::Rtklib,
        &o,
    )
    .unwrap();
    assert_eq!(
        (d.fixes.len(), d.report.skipped_quality, d.report.rows),
        (2, 1, 3)
    );
    let o1 = GnssReadOptions::default().with_rtklib_max_q(1);
    let only5 = file("GPST", &[row("2086 101.0", 5, SD)]);
    let x = parse_gnss_str(Path::new("s.pos"), &only5, GnssFormat::Rtklib, &o1).unwrap_err();
    assert!(
        matches!(
            x,
            GnssFileError::AllFiltered {
                skipped: 1,
                max_q: 1,
                ..
            }
        ),
        "{x}"
    );
    // geodetic heights: refused without N, shifted with it
    let geo = file("GPST", &rows).replace("ellipsoidal", "geodetic");
    let x = rt(&geo).unwrap_err();
    assert!(
        matches!(x, GnssFileError::Unsupported { line: 3, .. }),
        "{x}"
    );
    let o = GnssReadOptions::default().with_geoid_undulation_m(36.5);
    let d = parse_gnss_str(Path::new("s.pos"), &geo, GnssFormat::Rtklib, &o).unwrap();
    assert!((d.fixes[0].h_m - (40.1234 + 36.5)).abs() < 1e-12);
    // velocity columns: ENU → NED
    let cols = COLS.trim_end().to_string()
        + "  vn(m/s)  ve(m/s)  vu(m/s)   sdvn   sdve   sdvu  sdvne  sdveu  sdvun\n";
    let r = row("2086 100.0", 1, SD).trim_end().to_string()
        + "  1.0  2.0  0.5  0.01 0.02 0.03 0.0 0.0 0.0\n";
    let d = rt(&format!("{HEAD}{cols}{r}")).unwrap();
    let (v, c) = d.fixes[0].vel.unwrap();
    assert_eq!(v, Vec3::new(1.0, 2.0, -0.5));
    assert!((c[(2, 2)] - 9e-4).abs() < 1e-18);
    // ECEF layout refused
    let x = rt(&format!(
        "{HEAD}%  GPST  x-ecef(m)  y-ecef(m)  z-ecef(m)  Q  ns\n2086 1.0 1 2 3 1 5\n"
    ))
    .unwrap_err();
    assert!(
        matches!(x, GnssFileError::Unsupported { line: 4, .. }),
        "{x}"
    );
}

#[test]
fn input_classes() {
    let ok = row("2086 100.0", 1, SD);
    assert!(matches!(rt("").unwrap_err(), GnssFileError::Empty { .. }));
    let x = rt(&format!("{HEAD}{COLS}")).unwrap_err();
    assert!(matches!(x, GnssFileError::NoData { line: 4, .. }), "{x}");
    let x = rt(&file(
        "GPST",
        &[
            ok.clone(),
            row("2086 101.0", 1, SD).replace("40.1234", "nan"),
        ],
    ))
    .unwrap_err();
    assert!(
        matches!(&x, GnssFileError::NonFinite { line: 6, field, .. } if field == "height(m)"),
        "{x}"
    );
    let x = rt(&file("GPST", &[ok.clone(), row("2086 99.0", 1, SD)])).unwrap_err();
    assert!(
        matches!(
            x,
            GnssFileError::TimeNotIncreasing {
                line: 6,
                column: 1,
                ..
            }
        ),
        "{x}"
    );
    let x = rt(&file(
        "GPST",
        &[
            ok.clone(),
            row("2086 101.0", 1, &SD.replacen("0.0080", "0.0000", 1)),
        ],
    ))
    .unwrap_err();
    assert!(
        matches!(&x, GnssFileError::OutOfRange { line: 6, field, .. } if field == "sde(m)"),
        "{x}"
    );
    let x = rt(&file(
        "GPST",
        &[
            ok.clone(),
            row("2086 101.0", 1, SD).replace("35.681234567", "95.681234567"),
        ],
    ))
    .unwrap_err();
    assert!(
        matches!(&x, GnssFileError::OutOfRange { line: 6, column: 14, field, .. } if field == "latitude(deg)"),
        "{x}"
    );
    assert!(
        x.to_string()
            .starts_with("sol.pos:6:14: field `latitude(deg)`"),
        "{x}"
    );
    // not positive definite: |c_ne| > σn σe
    let x = rt(&file(
        "GPST",
        &[row(
            "2086 101.0",
            1,
            "0.0100   0.0080   0.0200   0.0100   0.0000   0.0000",
        )],
    ))
    .unwrap_err();
    assert!(
        matches!(x, GnssFileError::NotPositiveDefinite { line: 5, .. }),
        "{x}"
    );
    // truncated: short, and cut inside the last number
    let x = rt(&format!(
        "{}2086 101.0   35.68",
        file("GPST", std::slice::from_ref(&ok))
    ))
    .unwrap_err();
    assert!(matches!(x, GnssFileError::Truncated { line: 6, .. }), "{x}");
    let cut = row("2086 101.0", 1, SD).trim_end().to_string();
    let cut = &cut[..cut.len() - 2]; // "0.0" → "0."
    let x = rt(&format!("{}{cut}", file("GPST", std::slice::from_ref(&ok)))).unwrap_err();
    assert!(matches!(x, GnssFileError::CutNumber { line: 6, .. }), "{x}");
    // bad dates
    let x = rt(&file("GPST", &[row("2020/02/30 00:00:00.000", 1, SD)])).unwrap_err();
    assert!(
        matches!(
            x,
            GnssFileError::OutOfRange {
                line: 5,
                column: 1,
                ..
            }
        ),
        "{x}"
    );
    let x = rt(&file("GPST", &[row("2086 604800.0", 1, SD)])).unwrap_err();
    assert!(
        matches!(x, GnssFileError::OutOfRange { line: 5, .. }),
        "{x}"
    );
    let x = rt(&file("GPST", &[row("2086 100.0", 7, SD)])).unwrap_err();
    assert!(
        matches!(&x, GnssFileError::OutOfRange { field, .. } if field == "Q"),
        "{x}"
    );
    // BOM accepted; headerless accepted with warnings
    assert_eq!(
        rt(&format!(
            "\u{feff}{}",
            file("GPST", std::slice::from_ref(&ok))
        ))
        .unwrap()
        .fixes
        .len(),
        1
    );
    let d = rt(&ok).unwrap();
    assert_eq!(d.format, GnssFormat::Rtklib);
    assert_eq!(d.report.warnings.len(), 2);
}
