//! NaveGo's GNSS data as converted to CSV: header
//! `t_s,lat_rad,lon_rad,h_m,v_n_mps,v_e_mps,v_d_mps` (the header may be missing when the
//! format is given), one fix per row; NaveGo keeps σ out of the data, so the position
//! covariance is `diag(stdm²)` (stdm = \[north, east, height\] m) and the velocity covariance
//! `diag(stdv²)` from `gnss_params.txt`.

use super::rows::{self, Ctx};
use super::{finish, GnssData, GnssFileError, GnssFormat, GnssReadReport, TimeBase};
use crate::io::navego_params::NavegoGnssParams;
use crate::sensors::gnss_fix::GnssFix;
use sdins_core::math::{Mat3, Vec3};
use std::path::Path;

/// Column names of NaveGo's converted `gnss.csv`.
pub const NAVEGO_GNSS_HEADER: [&str; 7] = [
    "t_s", "lat_rad", "lon_rad", "h_m", "v_n_mps", "v_e_mps", "v_d_mps",
];

pub(crate) fn parse(
    file: &Path,
    text: &str,
    p: &NavegoGnssParams,
) -> Result<GnssData, GnssFileError> {
    let ctx = Ctx { file };
    let lines = rows::lines(text);
    let Some(first) = lines.first() else {
        return Err(GnssFileError::Empty {
            file: file.to_path_buf(),
        });
    };
    let first_fields = rows::split(first.text);
    let has_header = first_fields
        .first()
        .is_some_and(|f| f.text.parse::<f64>().is_err());
    let mut header_line = None;
    if has_header {
        let names: Vec<&str> = first_fields
            .iter()
            .map(|f| f.text.trim_matches('"'))
            .collect();
        if names != NAVEGO_GNSS_HEADER {
            let bad = names
                .iter()
                .zip(NAVEGO_GNSS_HEADER)
                .position(|(a, b)| *a != b)
                .unwrap_or(names.len().min(NAVEGO_GNSS_HEADER.len()));
            return Err(GnssFileError::Header {
                file: file.to_path_buf(),
                line: first.no,
                column: first_fields.get(bad).map_or(1, |f| f.column),
                expected: format!("`{}`", NAVEGO_GNSS_HEADER.join(",")),
                found: first.text.chars().take(120).collect(),
            });
        }
        header_line = Some(first.no);
    }
    let sq = |s: [f64; 3]| Mat3::from_diagonal(&Vec3::new(s[0] * s[0], s[1] * s[1], s[2] * s[2]));
    let pos_cov = sq(p.stdm_ned_m);
    let vel_cov = sq(p.stdv_ned_mps);
    let unterminated = !text.ends_with('\n');
    let data = &lines[usize::from(has_header)..];
    let mut fixes = Vec::with_capacity(data.len());
    let mut prev = None;
    for (k, l) in data.iter().enumerate() {
        let f = rows::split(l.text);
        ctx.count(*l, &f, &[7], unterminated && k + 1 == data.len())?;
        let n = NAVEGO_GNSS_HEADER;
        let t = ctx.num(l.no, f[0], n[0])?;
        ctx.increasing(l.no, f[0], prev, t)?;
        prev = Some(t);
        let lat = ctx.num(l.no, f[1], n[1])?;
        ctx.range(
            l.no,
            f[1],
            n[1],
            lat,
            lat.abs() <= std::f64::consts::FRAC_PI_2,
            "a latitude within ±π/2 rad",
        )?;
        let lon = ctx.num(l.no, f[2], n[2])?;
        ctx.range(
            l.no,
            f[2],
            n[2],
            lon,
            lon.abs() <= 2.0 * std::f64::consts::PI,
            "a longitude within ±2π rad",
        )?;
        let h = ctx.h_m(l.no, f[3], n[3])?;
        let v = Vec3::new(
            ctx.vel(l.no, f[4], n[4])?,
            ctx.vel(l.no, f[5], n[5])?,
            ctx.vel(l.no, f[6], n[6])?,
        );
        fixes.push(GnssFix {
            t_s: t,
            lat_rad: lat,
            lon_rad: rows::wrap_lon_rad(lon),
            h_m: h,
            pos_cov_ned_m2: pos_cov,
            vel: Some((v, vel_cov)),
        });
    }
    let report = GnssReadReport {
        rows: fixes.len(),
        time_system: "file seconds".into(),
        ..Default::default()
    };
    finish(
        file,
        text,
        header_line,
        fixes,
        GnssFormat::NaveGo,
        TimeBase::FileSeconds,
        report,
    )
}
