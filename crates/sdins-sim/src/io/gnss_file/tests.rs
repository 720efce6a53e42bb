//! Input-class tests of the GNSS readers (the NaveGo reader here; the other readers'
//! tests are beside them).

use super::*;
use crate::io::navego_params::parse_navego_gnss_params;
use sdins_core::math::{Mat3, Vec3};

pub(crate) fn navego_params() -> NavegoGnssParams {
    parse_navego_gnss_params(
        Path::new("gnss_params.txt"),
        "stdm = [5, 5, 10]\nstdv = [0.05, 0.05, 0.05]\nlarm = [0, 0, 0]\nfreq = [5]\n",
    )
    .unwrap()
}

const NAV_H: &str = "t_s,lat_rad,lon_rad,h_m,v_n_mps,v_e_mps,v_d_mps\n";

fn nav_rows(n: usize) -> String {
    (0..n)
        .map(|k| format!("{},-0.573,-1.2006,707.4,1.5,-0.5,0.02\n", 0.2 * k as f64))
        .collect()
}

fn nav(text: &str) -> Result<GnssData, GnssFileError> {
    let o = GnssReadOptions::default().with_navego(navego_params());
    parse_gnss_str(Path::new("gnss.csv"), text, GnssFormat::NaveGo, &o)
}

fn nav_err(text: &str) -> GnssFileError {
    nav(text).unwrap_err()
}

#[test]
fn navego_reads_and_sigma_from_params() {
    let d = nav(&format!("{NAV_H}{}", nav_rows(3))).unwrap();
    assert_eq!(d.format, GnssFormat::NaveGo);
    assert_eq!(d.time_base, TimeBase::FileSeconds);
    assert_eq!(d.fixes.len(), 3);
    let f = d.fixes[1];
    assert_eq!(f.t_s, 0.2);
    assert_eq!(f.lat_rad, -0.573);
    assert_eq!(f.h_m, 707.4);
    assert_eq!(
        f.pos_cov_ned_m2,
        Mat3::from_diagonal(&Vec3::new(25.0, 25.0, 100.0))
    );
    let (v, pv) = f.vel.unwrap();
    assert_eq!(v, Vec3::new(1.5, -0.5, 0.02));
    assert!((pv[(2, 2)] - 0.0025).abs() < 1e-18);
    // headerless when the format is given; auto-detection with header
    assert_eq!(nav(&nav_rows(2)).unwrap().fixes.len(), 2);
    let o = GnssReadOptions::default().with_navego(navego_params());
    let d = parse_gnss_str(
        Path::new("gnss.csv"),
        &format!("{NAV_H}{}", nav_rows(2)),
        GnssFormat::Auto,
        &o,
    )
    .unwrap();
    assert_eq!(d.format, GnssFormat::NaveGo);
    assert!(d.report.detection.as_deref().unwrap().starts_with("navego"));
    // without parameters: a typed error
    let e = parse_gnss_str(
        Path::new("gnss.csv"),
        &nav_rows(2),
        GnssFormat::NaveGo,
        &GnssReadOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(e, GnssFileError::Params(_)), "{e}");
}

#[test]
fn navego_input_classes() {
    assert!(matches!(nav_err(""), GnssFileError::Empty { .. }));
    assert!(matches!(nav_err(" \n\n"), GnssFileError::Empty { .. }));
    assert!(matches!(
        nav_err(NAV_H),
        GnssFileError::NoData { line: 1, .. }
    ));
    // NaN in h_m: line 3, column of the 4th field
    let t = format!(
        "{NAV_H}{}0.4,-0.573,-1.2006,NaN,1.5,-0.5,0.02\n",
        nav_rows(2)
    );
    let e = nav_err(&t);
    assert!(
        matches!(&e, GnssFileError::NonFinite { line: 4, column: 20, field, .. } if field == "h_m"),
        "{e}"
    );
    assert!(
        e.to_string().starts_with("gnss.csv:4:20: field `h_m`"),
        "{e}"
    );
    // time backwards / repeated
    let t = format!(
        "{NAV_H}{}0.1,-0.573,-1.2006,700,1.5,-0.5,0.02\n",
        nav_rows(2)
    );
    assert!(matches!(
        nav_err(&t),
        GnssFileError::TimeNotIncreasing {
            line: 4,
            column: 1,
            ..
        }
    ));
    let t = format!(
        "{NAV_H}{}0.2,-0.573,-1.2006,700,1.5,-0.5,0.02\n",
        nav_rows(2)
    );
    assert!(matches!(
        nav_err(&t),
        GnssFileError::TimeNotIncreasing { .. }
    ));
    // latitude beyond ±90° (radians here)
    let t = format!("{NAV_H}{}0.4,1.6,-1.2006,700,1.5,-0.5,0.02\n", nav_rows(2));
    let e = nav_err(&t);
    assert!(
        matches!(&e, GnssFileError::OutOfRange { line: 4, column: 5, field, .. } if field == "lat_rad"),
        "{e}"
    );
    // truncated last line (no final newline), cut inside a number
    let t = format!("{NAV_H}{}0.4,-0.573,-1.20", nav_rows(2));
    let e = nav_err(&t);
    assert!(
        matches!(
            e,
            GnssFileError::Truncated {
                line: 4,
                expected: 7,
                found: 3,
                ..
            }
        ),
        "{e}"
    );
    // a complete last line without newline: read, with a warning
    let t = format!("{NAV_H}{}0.4,-0.573,-1.2006,700,1.5,-0.5,0.0", nav_rows(2));
    let d = nav(&t).unwrap();
    assert_eq!(d.fixes.len(), 3);
    assert_eq!(d.report.warnings.len(), 1);
    // wrong field count in the middle
    let t = format!("{NAV_H}0,1,2\n{}", nav_rows(2));
    assert!(matches!(
        nav_err(&t),
        GnssFileError::ColumnCount {
            line: 2,
            found: 3,
            ..
        }
    ));
    // bad header names the column
    let e = nav_err(&format!(
        "t_s,lat_deg,lon_rad,h_m,v_n_mps,v_e_mps,v_d_mps\n{}",
        nav_rows(2)
    ));
    assert!(
        matches!(
            e,
            GnssFileError::Header {
                line: 1,
                column: 5,
                ..
            }
        ),
        "{e}"
    );
    // not a number
    let t = format!("{NAV_H}{}0.4,-0.573,x,700,1.5,-0.5,0.02\n", nav_rows(2));
    assert!(matches!(
        nav_err(&t),
        GnssFileError::NotANumber {
            line: 4,
            column: 12,
            ..
        }
    ));
    // absurd speed
    let t = format!(
        "{NAV_H}{}0.4,-0.573,-1.2,700,1e300,-0.5,0.02\n",
        nav_rows(2)
    );
    assert!(matches!(
        nav_err(&t),
        GnssFileError::OutOfRange { line: 4, .. }
    ));
    // BOM accepted
    assert_eq!(
        nav(&format!("\u{feff}{NAV_H}{}", nav_rows(2)))
            .unwrap()
            .fixes
            .len(),
        2
    );
    // σ ≤ 0 comes from the parameters: refused there, located
    let e = parse_navego_gnss_params(
        Path::new("gnss_params.txt"),
        "stdm = [5, -5, 10]\nstdv = [0.05, 0.05, 0.05]\nfreq = [5]\n",
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("gnss_params.txt:1:12: field `stdm`"),
        "{e}"
    );
}

#[test]
fn span_and_time_mapping() {
    let d = nav(&format!("{NAV_H}{}", nav_rows(6))).unwrap(); // t = 0 .. 1.0
    let c = clip_to_imu_span(Path::new("g"), &d.fixes, 0.3, 0.85).unwrap();
    assert_eq!((c.before, c.fixes.len(), c.after), (2, 3, 1));
    let e = clip_to_imu_span(Path::new("g"), &d.fixes, 2.0, 3.0).unwrap_err();
    assert!(
        matches!(e, GnssFileError::NoOverlap { n_fixes: 6, .. }),
        "{e}"
    );
    let m = to_imu_time(
        Path::new("g"),
        &d,
        ImuClock::Offset {
            t_imu_minus_t_gnss_s: 10.0,
        },
    )
    .unwrap();
    assert_eq!(m[1].t_s, 10.2);
    assert!(matches!(
        to_imu_time(Path::new("g"), &d, ImuClock::GpsSecondsOfWeek),
        Err(GnssFileError::TimeBaseMismatch { .. })
    ));
}

#[test]
fn detection_refuses_when_ambiguous() {
    let o = GnssReadOptions::default();
    // 7 numbers near lat 0.5, lon 0.3: KF-GINS degrees or headerless NaveGo radians
    let t = "100.0 0.5 0.3 10.0 1.0 1.0 2.0\n101.0 0.5 0.3 10.0 1.0 1.0 2.0\n";
    let e = parse_gnss_str(Path::new("g.txt"), t, GnssFormat::Auto, &o).unwrap_err();
    match &e {
        GnssFileError::Ambiguous {
            candidates, line, ..
        } => {
            assert_eq!(candidates, &vec!["kfgins", "navego"]);
            assert_eq!(*line, 1);
        }
        _ => panic!("{e}"),
    }
    assert!(e.to_string().contains("candidates: kfgins, navego"), "{e}");
    // given explicitly, either reads
    assert!(parse_gnss_str(Path::new("g.txt"), t, GnssFormat::KfGins, &o).is_ok());
    // unknown content
    let e = parse_gnss_str(Path::new("g.txt"), "a;b\n", GnssFormat::Auto, &o).unwrap_err();
    assert!(
        matches!(e, GnssFileError::UnknownFormat { line: 1, .. }),
        "{e}"
    );
    let e = parse_gnss_str(Path::new("g.txt"), "", GnssFormat::Auto, &o).unwrap_err();
    assert!(matches!(e, GnssFileError::Empty { .. }), "{e}");
    assert_eq!("rtklib".parse::<GnssFormat>(), Ok(GnssFormat::Rtklib));
    assert!("x".parse::<GnssFormat>().is_err());
}
