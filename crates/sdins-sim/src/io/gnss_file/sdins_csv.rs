//! sdins GNSS CSV (`docs/gnss-files.md`): header
//! `t_s,lat_deg,lon_deg,h_m,sigma_n_m,sigma_e_m,sigma_d_m`, optionally followed by
//! `v_n_mps,v_e_mps,v_d_mps,sigma_vn_mps,sigma_ve_mps,sigma_vd_mps`; times \[s\] on the IMU
//! file's clock, WGS-84 geodetic latitude/longitude \[deg\], ellipsoidal height \[m\], σ \[m\]
//! north/east/down, NED velocity \[m/s\] and its σ \[m/s\]; covariances diagonal.

use super::rows::{self, Ctx};
use super::{finish, GnssData, GnssFileError, GnssFormat, GnssReadReport, TimeBase};
use crate::sensors::gnss_fix::GnssFix;
use sdins_core::math::{Mat3, Vec3};
use std::path::Path;

/// Columns of the sdins GNSS CSV (position only).
pub const SDINS_GNSS_HEADER: [&str; 7] = [
    "t_s",
    "lat_deg",
    "lon_deg",
    "h_m",
    "sigma_n_m",
    "sigma_e_m",
    "sigma_d_m",
];
/// The six optional velocity columns that may follow.
pub const SDINS_GNSS_VEL_HEADER: [&str; 6] = [
    "v_n_mps",
    "v_e_mps",
    "v_d_mps",
    "sigma_vn_mps",
    "sigma_ve_mps",
    "sigma_vd_mps",
];

pub(crate) fn parse(file: &Path, text: &str) -> Result<GnssData, GnssFileError> {
    let ctx = Ctx { file };
    let lines = rows::lines(text);
    let Some(first) = lines.first() else {
        return Err(GnssFileError::Empty {
            file: file.to_path_buf(),
        });
    };
    let hf = rows::split(first.text);
    let names: Vec<&str> = hf.iter().map(|f| f.text.trim_matches('"')).collect();
    let full: Vec<&str> = SDINS_GNSS_HEADER
        .iter()
        .chain(SDINS_GNSS_VEL_HEADER.iter())
        .copied()
        .collect();
    let with_vel = names == full;
    if !(with_vel || names == SDINS_GNSS_HEADER) {
        let bad = names
            .iter()
            .zip(&full)
            .position(|(a, b)| a != b)
            .unwrap_or(names.len().min(full.len()));
        return Err(GnssFileError::Header {
            file: file.to_path_buf(),
            line: first.no,
            column: hf
                .get(bad)
                .map_or(first.text.chars().count() + 1, |f| f.column),
            expected: format!(
                "`{}` optionally followed by `,{}`",
                SDINS_GNSS_HEADER.join(","),
                SDINS_GNSS_VEL_HEADER.join(",")
            ),
            found: first.text.chars().take(160).collect(),
        });
    }
    let ncol = full.len().min(if with_vel { 13 } else { 7 });
    let unterminated = !text.ends_with('\n');
    let data = &lines[1..];
    let mut fixes = Vec::with_capacity(data.len());
    let mut prev = None;
    for (k, l) in data.iter().enumerate() {
        let f = rows::split(l.text);
        ctx.count(*l, &f, &[ncol], unterminated && k + 1 == data.len())?;
        let t = ctx.num(l.no, f[0], full[0])?;
        ctx.increasing(l.no, f[0], prev, t)?;
        prev = Some(t);
        let lat = ctx.lat_deg(l.no, f[1], full[1])?;
        let lon = ctx.lon_deg(l.no, f[2], full[2])?;
        let h = ctx.h_m(l.no, f[3], full[3])?;
        let s = Vec3::new(
            ctx.sigma(l.no, f[4], full[4])?,
            ctx.sigma(l.no, f[5], full[5])?,
            ctx.sigma(l.no, f[6], full[6])?,
        );
        let mut fix = GnssFix::with_position_sigma(
            t,
            lat.to_radians(),
            rows::wrap_lon_rad(lon.to_radians()),
            h,
            s,
        );
        if with_vel {
            let v = Vec3::new(
                ctx.vel(l.no, f[7], full[7])?,
                ctx.vel(l.no, f[8], full[8])?,
                ctx.vel(l.no, f[9], full[9])?,
            );
            let sv = Vec3::new(
                ctx.sigma(l.no, f[10], full[10])?,
                ctx.sigma(l.no, f[11], full[11])?,
                ctx.sigma(l.no, f[12], full[12])?,
            );
            fix.vel = Some((v, Mat3::from_diagonal(&sv.component_mul(&sv))));
        }
        fixes.push(fix);
    }
    let report = GnssReadReport {
        rows: fixes.len(),
        time_system: "file seconds".into(),
        ..Default::default()
    };
    finish(
        file,
        text,
        Some(first.no),
        fixes,
        GnssFormat::Sdins,
        TimeBase::FileSeconds,
        report,
    )
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::io::gnss_file::{parse_gnss_str, GnssReadOptions};

    const H: &str = "t_s,lat_deg,lon_deg,h_m,sigma_n_m,sigma_e_m,sigma_d_m\n";
    const HV: &str = "t_s,lat_deg,lon_deg,h_m,sigma_n_m,sigma_e_m,sigma_d_m,v_n_mps,v_e_mps,v_d_mps,sigma_vn_mps,sigma_ve_mps,sigma_vd_mps\n";

    fn rows(n: usize) -> String {
        (0..n)
            .map(|k| format!("{},45.5,-73.6,30.25,1.5,1.5,3\n", k as f64))
            .collect()
    }

    fn sd(t: &str) -> Result<GnssData, GnssFileError> {
        parse_gnss_str(
            Path::new("fix.csv"),
            t,
            GnssFormat::Auto,
            &GnssReadOptions::default(),
        )
    }

    #[test]
    fn reads_both_layouts() {
        let d = sd(&format!("{H}{}", rows(3))).unwrap();
        assert_eq!(d.format, GnssFormat::Sdins);
        let f = d.fixes[2];
        assert_eq!(f.t_s, 2.0);
        assert_eq!(f.lat_rad, 45.5f64.to_radians());
        assert_eq!(f.lon_rad, (-73.6f64).to_radians());
        assert_eq!(f.pos_cov_ned_m2[(2, 2)], 9.0);
        let d = sd(&format!(
            "{HV}0,45,7,100,1,2,3,10,-5,0.5,0.1,0.2,0.3\n1,45,7,100,1,2,3,10,-5,0.5,0.1,0.2,0.3\n"
        ))
        .unwrap();
        let (v, c) = d.fixes[0].vel.unwrap();
        assert_eq!(v, Vec3::new(10.0, -5.0, 0.5));
        assert!((c[(1, 1)] - 0.04).abs() < 1e-17);
        // longitude 350° wraps to −10°
        let d = sd(&format!("{H}0,45,350,0,1,1,1\n")).unwrap();
        assert!((d.fixes[0].lon_rad + 10f64.to_radians()).abs() < 1e-15);
    }

    #[test]
    fn input_classes() {
        let e = |t: &str| sd(t).unwrap_err();
        assert!(matches!(e(""), GnssFileError::Empty { .. }));
        let x = parse_gnss_str(
            Path::new("fix.csv"),
            H,
            GnssFormat::Sdins,
            &GnssReadOptions::default(),
        )
        .unwrap_err();
        assert!(matches!(x, GnssFileError::NoData { line: 1, .. }), "{x}");
        let x = e(&format!("{H}{}3,NaN,-73.6,30,1,1,1\n", rows(3)));
        assert!(
            matches!(
                x,
                GnssFileError::NonFinite {
                    line: 5,
                    column: 3,
                    ..
                }
            ),
            "{x}"
        );
        assert!(
            x.to_string().starts_with("fix.csv:5:3: field `lat_deg`"),
            "{x}"
        );
        let x = e(&format!("{H}{}1.5,45,-73.6,30,1,1,1\n", rows(3)));
        assert!(
            matches!(x, GnssFileError::TimeNotIncreasing { line: 5, .. }),
            "{x}"
        );
        let x = e(&format!("{H}{}3,45,-73.6,30,1,0,1\n", rows(3)));
        assert!(
            matches!(&x, GnssFileError::OutOfRange { line: 5, column: 17, field, .. } if field == "sigma_e_m"),
            "{x}"
        );
        let x = e(&format!("{H}{}3,45,-73.6,30,1,1,-2\n", rows(3)));
        assert!(
            matches!(x, GnssFileError::OutOfRange { line: 5, .. }),
            "{x}"
        );
        let x = e(&format!("{H}{}3,-90.01,-73.6,30,1,1,1\n", rows(3)));
        assert!(
            matches!(&x, GnssFileError::OutOfRange { line: 5, column: 3, field, .. } if field == "lat_deg"),
            "{x}"
        );
        let x = e(&format!("{H}{}3,45,-73.6,3", rows(3)));
        assert!(
            matches!(
                x,
                GnssFileError::Truncated {
                    line: 5,
                    found: 4,
                    expected: 7,
                    ..
                }
            ),
            "{x}"
        );
        let x = e(&format!("{H}{}3,45,-73.6,1e7,1,1,1\n", rows(3)));
        assert!(
            matches!(x, GnssFileError::OutOfRange { line: 5, .. }),
            "{x}"
        );
        let x = e("t_s,lat_deg,lon_deg,h_m,sigma_n_m,sigma_e_m\n0,1,2,3,4,5\n");
        assert!(matches!(x, GnssFileError::Header { line: 1, .. }), "{x}");
        let x = e(&format!("{H}{}3,45,-73.6,,1,1,1\n", rows(3)));
        assert!(
            matches!(
                x,
                GnssFileError::NotANumber {
                    line: 5,
                    column: 12,
                    ..
                }
            ),
            "{x}"
        );
        assert_eq!(
            sd(&format!("\u{feff}{H}{}", rows(2))).unwrap().fixes.len(),
            2
        );
    }
}
