//! sdins GNSS CSV reader: never panics; accepted fixes have increasing finite times, |lat| <= 90°, heights in range, PD covariances.
#![no_main]
use libfuzzer_sys::fuzz_target;
use sdins_sim::io::gnss_file::{parse_gnss_str, GnssFormat, GnssReadOptions, H_RANGE_M};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let opts = GnssReadOptions::default();
    let Ok(d) = parse_gnss_str(Path::new("fuzz.gnss"), &text, GnssFormat::Sdins, &opts) else {
        return;
    };
    assert!(!d.fixes.is_empty());
    let mut prev = f64::NEG_INFINITY;
    for f in &d.fixes {
        assert!(f.t_s.is_finite() && f.t_s > prev, "time {} after {prev}", f.t_s);
        prev = f.t_s;
        assert!(f.lat_rad.abs() <= std::f64::consts::FRAC_PI_2);
        assert!(f.lon_rad.abs() <= std::f64::consts::PI);
        assert!(f.h_m >= H_RANGE_M.0 && f.h_m <= H_RANGE_M.1);
        assert!(f.pos_cov_ned_m2.iter().all(|x| x.is_finite()));
        assert_eq!(f.pos_cov_ned_m2, f.pos_cov_ned_m2.transpose());
        assert!(f.pos_cov_ned_m2.cholesky().is_some(), "covariance not PD");
        if let Some((v, c)) = f.vel {
            assert!(v.iter().all(|x| x.is_finite()));
            assert!(c.cholesky().is_some());
        }
    }
});
