//! `sdins nav --init` value list: never panics; an accepted state is finite and in range.
#![no_main]
use libfuzzer_sys::fuzz_target;
use sdins_sim::io::initial::parse_initial_state;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(s) = parse_initial_state(&text) {
        assert!(s.lat_rad.abs() <= 89.99_f64.to_radians() + 1e-12);
        assert!((-1000.0..=100_000.0).contains(&s.h_m));
        assert!(s.v_n_mps.iter().all(|x| x.is_finite()));
        assert!(s.c_b_n.iter().all(|x| x.is_finite()));
    }
});
