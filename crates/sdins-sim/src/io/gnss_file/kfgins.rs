//! KF-GINS GNSS text: one fix per line, `t lat lon h σN σE σD` whitespace (or comma)
//! separated, no header; `t` GPS seconds of week \[s\], latitude/longitude \[deg\], height \[m\]
//! (KF-GINS uses it as ellipsoidal), σ \[m\] north, east, down. A week rollover inside the
//! file (time dropping by more than half a week) is unwrapped by adding 604 800 s.

use super::rows::{self, check_cut_number, Ctx};
use super::{
    finish, GnssData, GnssFileError, GnssFormat, GnssReadReport, TimeBase, SECONDS_PER_WEEK,
};
use crate::sensors::gnss_fix::GnssFix;
use sdins_core::math::Vec3;
use std::path::Path;

/// Field names of the KF-GINS GNSS columns (used in error messages).
pub const KFGINS_GNSS_FIELDS: [&str; 7] = [
    "t_gps_sow_s",
    "lat_deg",
    "lon_deg",
    "h_m",
    "sigma_n_m",
    "sigma_e_m",
    "sigma_d_m",
];

pub(crate) fn parse(file: &Path, text: &str) -> Result<GnssData, GnssFileError> {
    let ctx = Ctx { file };
    let lines = rows::lines(text);
    let unterminated = !text.ends_with('\n');
    let n = KFGINS_GNSS_FIELDS;
    let mut fixes = Vec::with_capacity(lines.len());
    let mut prev_t: Option<f64> = None;
    let mut weeks = 0.0;
    let mut prev_fields = Vec::new();
    for (k, l) in lines.iter().enumerate() {
        let f = rows::split(l.text);
        let last = k + 1 == lines.len();
        ctx.count(*l, &f, &[7], unterminated && last)?;
        if last {
            check_cut_number(&ctx, &prev_fields, *l, &f, unterminated)?;
        }
        let t_sow = ctx.num(l.no, f[0], n[0])?;
        ctx.range(
            l.no,
            f[0],
            n[0],
            t_sow,
            (0.0..=SECONDS_PER_WEEK).contains(&t_sow),
            "GPS seconds of week in [0, 604800]",
        )?;
        if let Some(p) = prev_t {
            if t_sow + weeks < p - SECONDS_PER_WEEK / 2.0 {
                weeks += SECONDS_PER_WEEK;
            }
        }
        let t = t_sow + weeks;
        ctx.increasing(l.no, f[0], prev_t, t)?;
        prev_t = Some(t);
        let lat = ctx.lat_deg(l.no, f[1], n[1])?;
        let lon = ctx.lon_deg(l.no, f[2], n[2])?;
        let h = ctx.h_m(l.no, f[3], n[3])?;
        let s = Vec3::new(
            ctx.sigma(l.no, f[4], n[4])?,
            ctx.sigma(l.no, f[5], n[5])?,
            ctx.sigma(l.no, f[6], n[6])?,
        );
        fixes.push(GnssFix::with_position_sigma(
            t,
            lat.to_radians(),
            rows::wrap_lon_rad(lon.to_radians()),
            h,
            s,
        ));
        prev_fields = f;
    }
    let report = GnssReadReport {
        rows: fixes.len(),
        time_system: "GPST".into(),
        ..Default::default()
    };
    finish(
        file,
        text,
        None,
        fixes,
        GnssFormat::KfGins,
        TimeBase::GpsSecondsOfWeek,
        report,
    )
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::io::gnss_file::{parse_gnss_str, GnssReadOptions};

    const L1: &str =
        "456250.000    30.4447858054   114.4718661162     21.095    0.010    0.009    0.019 \n";
    const L2: &str =
        "456251.000    30.4447857891   114.4718661133     21.091    0.010    0.009    0.019 \n";

    fn kf(t: &str) -> Result<GnssData, GnssFileError> {
        parse_gnss_str(
            Path::new("gnss.txt"),
            t,
            GnssFormat::KfGins,
            &GnssReadOptions::default(),
        )
    }

    #[test]
    fn reads_and_detects() {
        let d = parse_gnss_str(
            Path::new("gnss.txt"),
            &format!("{L1}{L2}"),
            GnssFormat::Auto,
            &GnssReadOptions::default(),
        )
        .unwrap();
        assert_eq!(d.format, GnssFormat::KfGins);
        assert_eq!(d.time_base, TimeBase::GpsSecondsOfWeek);
        let f = d.fixes[1];
        assert_eq!(f.t_s, 456251.0);
        assert!((f.lat_rad.to_degrees() - 30.4447857891).abs() < 1e-12);
        assert!((f.pos_cov_ned_m2[(2, 2)] - 0.019 * 0.019).abs() < 1e-18);
        assert_eq!(f.vel, None);
        assert!(d.report.detection.unwrap().starts_with("kfgins"));
    }

    #[test]
    fn week_rollover() {
        let t = "604799.0 30 114 21 0.01 0.01 0.02\n0.0 30 114 21 0.01 0.01 0.02\n1.0 30 114 21 0.01 0.01 0.02\n";
        let d = kf(t).unwrap();
        let ts: Vec<f64> = d.fixes.iter().map(|f| f.t_s).collect();
        assert_eq!(ts, vec![604799.0, 604800.0, 604801.0]);
    }

    #[test]
    fn input_classes() {
        let e = |t: &str| kf(t).unwrap_err();
        assert!(matches!(e(""), GnssFileError::Empty { .. }));
        // a header line is not KF-GINS: not a number
        assert!(matches!(
            e("t lat lon h sn se sd\n"),
            GnssFileError::NotANumber {
                line: 1,
                column: 1,
                ..
            }
        ));
        let x = e(&format!("{L1}456251.000 30.4 114.4 nan 0.01 0.01 0.02\n"));
        assert!(
            matches!(
                x,
                GnssFileError::NonFinite {
                    line: 2,
                    column: 23,
                    ..
                }
            ),
            "{x}"
        );
        let x = e(&format!("{L1}456249.000 30.4 114.4 21 0.01 0.01 0.02\n"));
        assert!(
            matches!(x, GnssFileError::TimeNotIncreasing { line: 2, .. }),
            "{x}"
        );
        let x = e(&format!("{L1}456251.000 30.4 114.4 21 0.01 0 0.02\n"));
        assert!(
            matches!(&x, GnssFileError::OutOfRange { line: 2, column: 31, field, .. } if field == "sigma_e_m"),
            "{x}"
        );
        let x = e(&format!("{L1}456251.000 30.4 114.4 21 0.01 -1 0.02\n"));
        assert!(
            matches!(x, GnssFileError::OutOfRange { line: 2, .. }),
            "{x}"
        );
        let x = e(&format!("{L1}456251.000 90.5 114.4 21 0.01 0.01 0.02\n"));
        assert!(
            matches!(&x, GnssFileError::OutOfRange { line: 2, column: 12, field, .. } if field == "lat_deg"),
            "{x}"
        );
        assert!(
            x.to_string().starts_with("gnss.txt:2:12: field `lat_deg`"),
            "{x}"
        );
        // truncated: short last line, and last number cut (fewer decimals) without newline
        let x = e(&format!("{L1}456251.000    30.44478"));
        assert!(
            matches!(
                x,
                GnssFileError::Truncated {
                    line: 2,
                    found: 2,
                    ..
                }
            ),
            "{x}"
        );
        let cut = L2.trim_end().trim_end_matches('9');
        let x = e(&format!("{L1}{cut}"));
        assert!(
            matches!(
                x,
                GnssFileError::CutNumber {
                    line: 2,
                    expected_decimals: 3,
                    ..
                }
            ),
            "{x}"
        );
        // the complete last line without newline is accepted (with a warning)
        let d = kf(&format!("{L1}{}", L2.trim_end())).unwrap();
        assert_eq!((d.fixes.len(), d.report.warnings.len()), (2, 1));
        // BOM accepted
        assert_eq!(kf(&format!("\u{feff}{L1}{L2}")).unwrap().fixes.len(), 2);
        // header only does not exist in this format; 6 fields is a column count error
        let x = e(&format!("{L1}1 2 3 4 5 6\n"));
        assert!(
            matches!(
                x,
                GnssFileError::ColumnCount {
                    line: 2,
                    found: 6,
                    ..
                }
            ),
            "{x}"
        );
    }
}
