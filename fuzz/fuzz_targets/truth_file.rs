//! Reference-trajectory reader (sdins truth.csv and PSINS avp): never panics; accepted
//! rows are finite, in range and strictly increasing in time.
#![no_main]
use libfuzzer_sys::fuzz_target;
use sdins_sim::io::truth_file::parse_truth_str;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let Ok(rows) = parse_truth_str(Path::new("fuzz.csv"), &text) else {
        return;
    };
    assert!(!rows.is_empty());
    for w in rows.windows(2) {
        assert!(w[1].t_s > w[0].t_s);
    }
    for r in &rows {
        assert!(r.lat_rad.abs() <= std::f64::consts::FRAC_PI_2 + 1e-12);
        assert!(r.h_m.is_finite() && r.lon_rad.is_finite());
        assert!(r.c_b_n.iter().all(|x| x.is_finite()));
        assert!(r.v_n_mps.iter().all(|x| x.is_finite()));
    }
});
