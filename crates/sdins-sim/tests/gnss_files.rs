//! The GNSS readers and NaveGo parameter parsers on the real files in `../shared/data`
//! (skipped with a printed reason when the folder is absent).
#![allow(clippy::unwrap_used)]

use sdins_sim::io::gnss_file::{
    clip_to_imu_span, imu_span_s, read_gnss_file, to_imu_time, GnssFormat, GnssReadOptions,
    ImuClock, TimeBase,
};
use sdins_sim::io::imu_file::{read_imu_file, ImuFormat};
use sdins_sim::io::navego_params::{read_navego_gnss_params, read_navego_imu_params};
use std::path::{Path, PathBuf};

fn data(sub: &str) -> Option<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data")
        .join(sub);
    if d.is_dir() {
        Some(d)
    } else {
        println!("skipped: {} not found", d.display());
        None
    }
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn navego_params_files() {
    let Some(d) = data("csv/navego") else { return };
    let i1 = read_navego_imu_params(&d.join("imu1_params.txt")).unwrap();
    let i2 = read_navego_imu_params(&d.join("imu2_params.txt")).unwrap();
    // ADIS16405 (imu1): 3 °/s and 50 mg static biases, 2 °/√h ARW, 0.2 m/s/√h VRW, as
    // NaveGo's example defines them in those units
    let d2r = std::f64::consts::PI / 180.0;
    for a in 0..3 {
        assert!((i1.gb_sta_rps[a] - 3.0 * d2r).abs() < 1e-15);
        assert!((i1.ab_sta_mps2[a] - 0.050 * 9.80665).abs() < 1e-15);
        assert!((i1.arw_rad_per_sqrt_s[a] - 2.0 * d2r / 60.0).abs() < 1e-15);
        assert!((i1.vrw_mps_per_sqrt_s[a] - 0.2 / 60.0).abs() < 1e-15);
        assert_eq!(i1.gb_corr_s[a], 100.0);
    }
    assert_eq!(i1.ini_align_rpy_rad, [0.0, 0.0, -15.0 * d2r]);
    assert!((i1.ini_align_err_rpy_rad[2] - 2.0 * d2r).abs() < 1e-15);
    assert!(i2.gb_sta_rps[0] < i1.gb_sta_rps[0]);
    assert!(i1.other.contains_key("m_std"));
    let g = read_navego_gnss_params(&d.join("gnss_params.txt")).unwrap();
    assert_eq!(g.stdm_ned_m, [5.0, 5.0, 10.0]);
    assert_eq!(g.larm_frd_m, [0.0; 3]);
    assert_eq!(g.freq_hz, 5.0);
    assert!((g.stdv_ned_mps[0] - 0.0514444).abs() < 1e-15);
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn navego_gnss_csv() {
    let Some(d) = data("csv/navego") else { return };
    let path = d.join("gnss.csv");
    let g = read_gnss_file(&path, GnssFormat::Auto, &GnssReadOptions::default()).unwrap();
    assert_eq!(g.format, GnssFormat::NaveGo);
    assert_eq!(g.time_base, TimeBase::FileSeconds);
    // 5 Hz from 0 to 437.2 s
    assert_eq!(g.fixes.len(), 2187);
    assert_eq!(g.fixes[0].t_s, 0.0);
    assert!((g.fixes[2186].t_s - 437.2).abs() < 1e-9);
    assert!((g.fixes[0].lat_rad.to_degrees() + 32.83).abs() < 0.01);
    assert_eq!(g.fixes[0].pos_cov_ned_m2[(2, 2)], 100.0);
    assert!(g.report.warnings.is_empty());
    // all fixes inside the 200 Hz IMU record
    let imu = read_imu_file(&d.join("imu1.csv"), ImuFormat::Auto).unwrap();
    let (a, b) = imu_span_s(&imu);
    let m = to_imu_time(&path, &g, ImuClock::SameAsGnss).unwrap();
    let c = clip_to_imu_span(&path, &m, a, b).unwrap();
    println!(
        "navego: {} fixes, IMU span {a}..{b} s, kept {}, before {}, after {}",
        g.fixes.len(),
        c.fixes.len(),
        c.before,
        c.after
    );
    assert_eq!(c.fixes.len() + c.before + c.after, 2187);
    assert!(c.after <= 1);
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn kfgins_gnss_text() {
    let Some(d) = data("kfgins") else { return };
    let path = d.join("GNSS-RTK.txt");
    let g = read_gnss_file(&path, GnssFormat::Auto, &GnssReadOptions::default()).unwrap();
    assert_eq!(g.format, GnssFormat::KfGins);
    assert_eq!(g.time_base, TimeBase::GpsSecondsOfWeek);
    // 1 Hz from 456250 to 459662 s of week
    let n = g.fixes.len();
    assert_eq!(g.fixes[0].t_s, 456_250.0);
    assert_eq!(g.fixes[n - 1].t_s, 459_662.0);
    assert_eq!(n, 3413);
    assert!((g.fixes[0].lat_rad.to_degrees() - 30.4447858054).abs() < 1e-10);
    assert!((g.fixes[0].pos_cov_ned_m2[(0, 0)] - 1e-4).abs() < 1e-18);
    println!(
        "kfgins: {n} fixes, {}",
        g.report.detection.as_deref().unwrap_or("")
    );
    // the same fixes on a KF-GINS IMU clock (seconds of week): an IMU record of 456300 ..
    // 456400 s keeps 101 fixes
    let m = to_imu_time(&path, &g, ImuClock::GpsSecondsOfWeek).unwrap();
    let c = clip_to_imu_span(&path, &m, 456_300.0, 456_400.0).unwrap();
    assert_eq!((c.before, c.fixes.len(), c.after), (50, 101, n - 151));
}

/// NaveGo's fixes against its reference trajectory: the errors must have the σ that
/// `gnss_params.txt` states (5, 5, 10 m and 0.0514 m/s), which checks the reader's units
/// (radians, NED, σ order). Sample σ of n = 2187 draws: relative standard error 1/√(2n)
/// = 1.5 %; the band is ±5 standard errors (7.6 %). The noise is white, so the mean must be
/// within 5 σ/√n.
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn navego_fixes_have_the_stated_noise() {
    let Some(d) = data("csv/navego") else { return };
    let g = read_gnss_file(
        &d.join("gnss.csv"),
        GnssFormat::NaveGo,
        &GnssReadOptions::default(),
    )
    .unwrap();
    let text = std::fs::read_to_string(d.join("ref.csv")).unwrap();
    let refs: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    // WGS-84 radii of curvature (Groves eq. 2.105, 2.106)
    let (a, e2) = (6_378_137.0, 6.694_379_990_14e-3);
    let mut err: Vec<[f64; 6]> = Vec::new();
    for f in &g.fixes {
        let k = refs.partition_point(|r| r[0] < f.t_s - 1e-6);
        let r = &refs[k];
        assert!((r[0] - f.t_s).abs() < 1e-6, "no reference row at {}", f.t_s);
        let s2 = r[1].sin().powi(2);
        let rn = a * (1.0 - e2) / (1.0 - e2 * s2).powf(1.5);
        let re = a / (1.0 - e2 * s2).sqrt();
        let (v, _) = f.vel.unwrap();
        err.push([
            (f.lat_rad - r[1]) * (rn + r[3]),
            (f.lon_rad - r[2]) * (re + r[3]) * r[1].cos(),
            -(f.h_m - r[3]),
            v[0] - r[4],
            v[1] - r[5],
            v[2] - r[6],
        ]);
    }
    let n = err.len() as f64;
    let sig = [
        g.fixes[0].pos_cov_ned_m2[(0, 0)].sqrt(),
        g.fixes[0].pos_cov_ned_m2[(1, 1)].sqrt(),
        g.fixes[0].pos_cov_ned_m2[(2, 2)].sqrt(),
        g.fixes[0].vel.unwrap().1[(0, 0)].sqrt(),
        g.fixes[0].vel.unwrap().1[(1, 1)].sqrt(),
        g.fixes[0].vel.unwrap().1[(2, 2)].sqrt(),
    ];
    for i in 0..6 {
        let mean = err.iter().map(|e| e[i]).sum::<f64>() / n;
        let sd = (err.iter().map(|e| (e[i] - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        println!(
            "axis {i}: mean {mean:.4}, sample σ {sd:.4}, stated σ {:.4}",
            sig[i]
        );
        assert!(
            mean.abs() < 5.0 * sig[i] / n.sqrt(),
            "axis {i}: mean {mean}"
        );
        assert!(
            (sd / sig[i] - 1.0).abs() < 5.0 / (2.0 * n).sqrt(),
            "axis {i}: σ {sd}"
        );
    }
}
