//! NaveGo parameter-file parsers (IMU and GNSS; the first byte picks): never panic;
//! accepted values are finite, σ and densities >= 0, correlation times > 0.
#![no_main]
use libfuzzer_sys::fuzz_target;
use sdins_sim::io::navego_params::{parse_navego_gnss_params, parse_navego_imu_params};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Some((&sel, rest)) = data.split_first() else {
        return;
    };
    let text = String::from_utf8_lossy(rest);
    if sel % 2 == 0 {
        if let Ok(p) = parse_navego_imu_params(Path::new("imu_params.txt"), &text) {
            for v in [p.arw_rad_per_sqrt_s, p.vrw_mps_per_sqrt_s, p.gb_dyn_rps, p.ab_dyn_mps2, p.ini_align_err_rpy_rad] {
                assert!(v.iter().all(|x| x.is_finite() && *x >= 0.0));
            }
            assert!(p.gb_corr_s.iter().chain(&p.ab_corr_s).all(|x| x.is_finite() && *x > 0.0));
            assert!(p.ini_align_rpy_rad.iter().all(|x| x.is_finite()));
        }
    } else if let Ok(p) = parse_navego_gnss_params(Path::new("gnss_params.txt"), &text) {
        assert!(p.stdm_ned_m.iter().chain(&p.stdv_ned_mps).all(|x| x.is_finite() && *x > 0.0));
        assert!(p.freq_hz.is_finite() && p.freq_hz > 0.0);
    }
});
