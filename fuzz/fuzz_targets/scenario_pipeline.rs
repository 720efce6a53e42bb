//! Scenario text through truth, the IMU error model and navigation: an accepted scenario
//! gives, over its first ≤ 2 s (and ≤ 4000 IMU samples), truth inside the documented
//! kinematic envelope (docs/scenarios.md, "Kinematic envelope") and finite navigation
//! states and errors for one algorithm fed the corrupted increments; nothing panics.
#![no_main]
use libfuzzer_sys::fuzz_target;
use sdins_core::nav::AlgorithmKind;
use sdins_sim::truth::envelope::Envelope;
use sdins_sim::nav::pipeline::{self, RunOptions};
use sdins_sim::nav::options::{algorithms, AlgoChoice};
use sdins_sim::scenario::Scenario;

/// Relative slack on the envelope limits for the truth samples: the envelope check samples
/// the kinematics on a grid and integrates position with the trapezoidal rule
/// (src/truth/envelope.rs), the truth generator integrates with its own substeps.
const SLACK: f64 = 1e-3;

fuzz_target!(|data: &[u8]| {
    let Some((&pick, rest)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    let Ok(mut scn) = Scenario::from_toml(text, "fuzz.toml") else {
        return;
    };
    // keep each input fast: the accuracy of the truth is not under test here
    scn.nav.substeps = scn.nav.substeps.clamp(1, 4);
    let kind = AlgorithmKind::ALL[pick as usize % AlgorithmKind::ALL.len()];
    let choice = AlgoChoice {
        algos: Some(kind.name().to_string()),
        ..AlgoChoice::default()
    };
    let Ok(algos) = algorithms(&choice, &scn.nav) else {
        return;
    };
    let n = algos[0].samples as f64;
    let dt_s = scn.imu.dt_s();
    let until_s = 2.0_f64.min(4000.0 * dt_s).max(n * dt_s);
    let opts = RunOptions {
        algos,
        vertical_hold: pick & 0x80 != 0,
        every_s: None,
        until_s: Some(until_s),
        sensor_run: Some(u64::from(pick)),
    };
    let env = Envelope::DEFAULT;
    let res = pipeline::run(
        &scn,
        &opts,
        |_, st, tr, e| {
            let v = tr.v_n_mps.norm();
            assert!(
                tr.lat_rad.abs() <= env.max_abs_lat_rad * (1.0 + SLACK)
                    && tr.h_m >= env.min_h_m - SLACK * 1000.0
                    && tr.h_m <= env.max_h_m * (1.0 + SLACK)
                    && v <= env.max_speed_mps * (1.0 + SLACK)
                    && tr.c_b_n.iter().all(|x| x.is_finite())
                    && tr.inc.dtheta_b_rad.iter().all(|x| x.is_finite())
                    && tr.inc.dv_b_mps.iter().all(|x| x.is_finite()),
                "truth outside the envelope or not finite: {tr:?}"
            );
            assert!(
                st.t_s.is_finite()
                    && st.lat_rad.is_finite()
                    && st.lon_rad.is_finite()
                    && st.h_m.is_finite()
                    && st.v_n_mps.iter().all(|x| x.is_finite())
                    && st.c_b_n.iter().all(|x| x.is_finite()),
                "non-finite navigation state {st:?}"
            );
            assert!(
                e.pos_err_ned_m.iter().all(|x| x.is_finite())
                    && e.vel_err_ned_mps.iter().all(|x| x.is_finite())
                    && e.att_err_rad.iter().all(|x| x.is_finite())
                    && e.height_err_m.is_finite(),
                "non-finite navigation error {e:?}"
            );
        },
        |_, _| {},
    );
    if let Ok(summaries) = res {
        for s in &summaries {
            assert!(s.nav_updates >= 1, "no update for an accepted scenario: {s:?}");
        }
    }
});
