//! IMU file parser, every format (the first byte picks it): never panics; accepted data
//! has a finite positive sample interval and finite increments within the stated limits.
#![no_main]
use libfuzzer_sys::fuzz_target;
use sdins_sim::io::imu_file::{parse_imu_str, ImuFormat, MAX_DTHETA_RAD};
use std::path::Path;

const FORMATS: [ImuFormat; 6] = [
    ImuFormat::Auto,
    ImuFormat::Sdins,
    ImuFormat::Psins,
    ImuFormat::PsinsCsv,
    ImuFormat::KfGins,
    ImuFormat::NaveGo,
];

fuzz_target!(|data: &[u8]| {
    let Some((&sel, rest)) = data.split_first() else {
        return;
    };
    let format = FORMATS[usize::from(sel) % FORMATS.len()];
    let text = String::from_utf8_lossy(rest);
    let Ok(d) = parse_imu_str(Path::new("fuzz.imu"), &text, format) else {
        return;
    };
    assert!(d.dt_s.is_finite() && d.dt_s > 0.0, "dt {}", d.dt_s);
    assert!(d.t0_s.is_finite());
    assert!(!d.increments.is_empty());
    for i in &d.increments {
        assert!(i.dtheta_b_rad.iter().all(|x| x.is_finite()));
        assert!(i.dv_b_mps.iter().all(|x| x.is_finite()));
        assert!(i.dtheta_b_rad.norm() <= MAX_DTHETA_RAD);
    }
});
