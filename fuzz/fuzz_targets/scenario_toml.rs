//! Scenario TOML parser: never panics; an accepted scenario has a finite, positive
//! duration and produces finite truth for its first samples.
#![no_main]
use libfuzzer_sys::fuzz_target;
use sdins_sim::scenario::Scenario;
use sdins_sim::truth::{TruthConfig, TruthGenerator};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(scn) = Scenario::from_toml(text, "fuzz.toml") else {
        return;
    };
    let d = scn.duration_s();
    assert!(d.is_finite() && d >= 0.0, "duration {d}");
    let cfg = TruthConfig {
        earth: scn.nav.earth.model(),
        dt_s: scn.imu.dt_s(),
        lat0_rad: scn.start.lat_rad,
        lon0_rad: scn.start.lon_rad,
        h0_m: scn.start.h_m,
        // keep each input fast: the accuracy of the truth is not under test here
        substeps: scn.nav.substeps.clamp(1, 4),
    };
    let gen = TruthGenerator::new(&scn.trajectory, cfg);
    let _ = gen.len_samples();
    for s in gen.take(3) {
        assert!(
            s.lat_rad.is_finite()
                && s.lon_rad.is_finite()
                && s.h_m.is_finite()
                && s.v_n_mps.iter().all(|x| x.is_finite())
                && s.inc.dtheta_b_rad.iter().all(|x| x.is_finite())
                && s.inc.dv_b_mps.iter().all(|x| x.is_finite()),
            "non-finite truth {s:?}"
        );
    }
});
