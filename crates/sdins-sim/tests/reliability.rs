//! Numerical reliability: poles, the antimeridian, quaternion normalisation,
//! 72 h stationary runs against the closed form, and a stationary property test.
#![allow(clippy::unwrap_used)]
mod common;
use common::*;
use proptest::prelude::*;
use sdins_core::math::Mat3;
use sdins_core::nav::AlgorithmKind as K;
use sdins_sim::analysis::error_analysis::periods::SchulerParams;
use sdins_sim::analysis::error_analysis::stationary::{StationaryClosedForm, StationaryErrors};
use sdins_sim::nav::pipeline::{run, NavError, RunOptions};
use sdins_sim::scenario::Scenario;

const ALL: [K; 4] = [K::Savage, K::SongLee, K::SongLeeComplete, K::DualQuat];

fn finite(e: &NavError) -> bool {
    e.pos_err_ned_m
        .iter()
        .chain(&e.vel_err_ned_mps)
        .chain(&e.att_err_rad)
        .all(|x| x.is_finite())
}

/// ‖CᵀC − I‖_max: the orthonormality defect of an attitude matrix.
fn ortho_defect(c: &Mat3) -> f64 {
    (c.transpose() * c - Mat3::identity()).abs().max()
}

/// Every update of `scn` for each algorithm: (max |horizontal|, max |att|, max jump of the
/// horizontal error between successive updates, max orthonormality defect), all finite.
fn sweep(scn: &Scenario, n: usize, until: f64) -> Vec<(f64, f64, f64, f64)> {
    let algos: Vec<_> = ALL.iter().map(|&k| spec(k, n)).collect();
    let m = algos.len();
    let mut acc = vec![(0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64); m];
    let mut prev: Vec<Option<[f64; 2]>> = vec![None; m];
    let opts = RunOptions {
        algos,
        vertical_hold: false,
        every_s: None,
        until_s: Some(until),
        sensor_run: None,
    };
    run(
        scn,
        &opts,
        |i, st, _tr, e| {
            assert!(finite(e), "algo {i}: non-finite error {e:?}");
            assert!(st.lon_rad > -std::f64::consts::PI && st.lon_rad <= std::f64::consts::PI);
            let h = [e.pos_err_ned_m[0], e.pos_err_ned_m[1]];
            let a = &mut acc[i];
            a.0 = a.0.max(h[0].hypot(h[1]));
            a.1 =
                a.1.max(e.att_err_rad.iter().fold(0.0, |m, x| m.max(x.abs())));
            if let Some(p) = prev[i] {
                a.2 = a.2.max((h[0] - p[0]).hypot(h[1] - p[1]));
            }
            prev[i] = Some(h);
            a.3 = a.3.max(ortho_defect(&st.c_b_n));
        },
        |_, _| {},
    )
    .unwrap();
    acc
}

#[test]
fn cruise_over_89_9_north_all_algorithms() {
    // 0.1° (11 km) from the pole, 100 m/s east: the vehicle circles the pole at
    // λ̇ = v/((R_N + h) cos L) ≈ 9e-3 rad/s, tan L ≈ 573 in the transport rate.
    for yaw in [90.0, 0.0] {
        // heading north at 30 m/s for 180 s stays 5.6 km short of the pole
        let speed = if yaw == 0.0 { 30.0 } else { 100.0 };
        let text = format!(
            "[start]\nlat_deg = 89.9\nlon_deg = 10.0\nh_m = 1000.0\nspeed_mps = {speed}\nyaw_deg = {yaw}\n[imu]\nrate_hz = 100.0\n[[segment]]\ntype = \"cruise\"\nduration_s = 180.0\n"
        );
        let scn = Scenario::from_toml(&text, "pole").unwrap();
        let r = sweep(&scn, 2, 180.0);
        for (i, (pos, att, jump, ortho)) in r.iter().enumerate() {
            eprintln!(
                "pole yaw {yaw} {:>17}: max |horiz| {pos:.3e} m, max |att| {att:.3e} rad, max step {jump:.3e} m, ortho {ortho:.1e}",
                ALL[i].name()
            );
            if std::env::var_os("SDINS_PRINT_ONLY").is_some() {
                continue;
            }
            assert!(*ortho < 1e-14, "{i}: ortho {ortho:e}");
            if matches!(ALL[i], K::SongLeeComplete | K::DualQuat) {
                // exact algorithms: the 89° sweep of mechanization.rs gives 1e-4 m; at
                // 89.9° tan L is 10× larger and the run 3× longer
                assert!(
                    *pos < 1e-2 && *att < 1e-8,
                    "{}: {pos:e} m {att:e} rad",
                    ALL[i].name()
                );
            }
        }
    }
}

#[test]
fn antimeridian_east_and_west() {
    // 250 m/s along the equator for 60 s: 15 km = 0.135°, crossing ±180° after 10 s.
    for (lon, yaw) in [(179.98, 90.0), (-179.98, 270.0), (359.98, 90.0)] {
        let text = format!(
            "[start]\nlat_deg = 0.5\nlon_deg = {lon}\nspeed_mps = 250.0\nyaw_deg = {yaw}\n[imu]\nrate_hz = 100.0\n[[segment]]\ntype = \"cruise\"\nduration_s = 60.0\n"
        );
        let scn = Scenario::from_toml(&text, "antimeridian").unwrap();
        let r = sweep(&scn, 2, 60.0);
        for (i, (pos, att, jump, ortho)) in r.iter().enumerate() {
            eprintln!(
                "lon {lon} yaw {yaw} {:>17}: max |horiz| {pos:.3e} m, max |att| {att:.3e} rad, max step {jump:.3e} m",
                ALL[i].name()
            );
            assert!(*ortho < 1e-14);
            // continuity: a wrap error would show as a 2π(R_N) ≈ 4e7 m jump
            assert!(*jump < 1e-3, "{}: step {jump:e} m", ALL[i].name());
            if matches!(ALL[i], K::SongLeeComplete | K::DualQuat) {
                assert!(
                    *pos < 1e-4 && *att < 1e-9,
                    "{}: {pos:e} m {att:e} rad",
                    ALL[i].name()
                );
            }
        }
    }
    // the wrap helpers themselves
    use sdins_core::nav::wrap_pi;
    use sdins_sim::truth::lon_diff;
    let pi = std::f64::consts::PI;
    assert_eq!(wrap_pi(pi), pi);
    assert!((wrap_pi(-pi) - pi).abs() < 1e-15);
    assert!((wrap_pi(3.0 * pi + 0.1) - (-pi + 0.1)).abs() < 1e-14);
    // in-range values come back bit for bit (no (a + π) − π rounding)
    for a in [0.1, -3.0, 2.0_f64.sqrt(), -pi + 1e-15, 1e-300] {
        assert_eq!(wrap_pi(a).to_bits(), a.to_bits());
    }
    assert!((lon_diff(-pi + 1e-6, pi - 1e-6) - 2e-6).abs() < 1e-15);
    assert!((lon_diff(pi - 1e-6, -pi + 1e-6) + 2e-6).abs() < 1e-15);
}

/// 72 h stationary at 100 Hz, N = 4, vertical held, 0.01 °/h x-gyro bias (north, level):
/// the horizontal errors follow the closed form of the (docs/theory/error-analysis.md
/// §"Full stationary closed form") and the attitude matrix stays orthonormal to 1e-14.
#[test]
#[ignore = "72 h at 100 Hz: run in release with --ignored (about a minute)"]
fn stationary_72h_vertical_hold_matches_closed_form() {
    let text = "name = \"72h\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\n[imu]\nrate_hz = 100.0\n[imu.errors]\ngyro_bias_dph = [0.01, 0.0, 0.0]\n[nav]\nsamples = 4\nvertical = \"hold\"\n[[segment]]\ntype = \"static\"\nduration_s = 259200.0\n";
    let scn = Scenario::from_toml(text, "72h").unwrap();
    let lat = scn.start.lat_rad;
    let earth = scn.nav.earth.model();
    let params = SchulerParams::with_local_gravity(&earth, lat, 0.0);
    let eps = 0.01 * std::f64::consts::PI / 180.0 / 3600.0;
    let errors = StationaryErrors {
        eps_n: sdins_core::Vec3::new(eps, 0.0, 0.0),
        ..Default::default()
    };
    let cf = StationaryClosedForm::new(lat, &errors, params);
    let algos = vec![spec(K::SongLeeComplete, 4), spec(K::DualQuat, 4)];
    let opts = RunOptions {
        algos,
        vertical_hold: true,
        every_s: Some(600.0),
        until_s: None,
        sensor_run: Some(0),
    };
    let mut worst = [(0.0_f64, 0.0_f64, 0.0_f64); 2]; // (max |closed form|, max |dev|, ortho)
    let mut last = [[0.0; 2]; 2];
    let t0 = std::time::Instant::now();
    let summ = run(
        &scn,
        &opts,
        |i, st, tr, e| {
            assert!(finite(e), "{e:?}");
            let c = cf.eval(tr.t_s);
            let dn = e.pos_err_ned_m[0] - c.dp_n[0];
            let de = e.pos_err_ned_m[1] - c.dp_n[1];
            let w = &mut worst[i];
            w.0 = w.0.max(c.dp_n[0].hypot(c.dp_n[1]));
            w.1 = w.1.max(dn.hypot(de));
            w.2 = w.2.max(ortho_defect(&st.c_b_n));
            last[i] = [e.pos_err_ned_m[0], e.pos_err_ned_m[1]];
        },
        |_, _| {},
    )
    .unwrap();
    let wall = t0.elapsed().as_secs_f64();
    assert_eq!(summ[0].nav_updates, 6_480_000);
    let c = cf.eval(259_200.0);
    for (i, s) in summ.iter().enumerate() {
        let (amp, dev, ortho) = worst[i];
        eprintln!(
            "72 h {:>17}: final N,E {:.1} {:.1} m (closed form {:.1} {:.1}); max |closed form| {amp:.1} m, max |alg − closed form| {dev:.2} m ({:.2} %), max ‖CᵀC − I‖ {ortho:.1e}, nav {:.1} s, total {wall:.1} s",
            s.algo, last[i][0], last[i][1], c.dp_n[0], c.dp_n[1], 100.0 * dev / amp, s.wall_s
        );
        assert!(ortho < 1e-14, "{}: ortho {ortho:e}", s.algo);
        // The closed form uses a spherical earth: the east drift scales with R0 = 6371 km
        // where the mechanization has R_N + h = 6386 km at 37.5° (+0.24 %); the slow-gain and
        // Coriolis approximations of the model are O(r² = (Ω/ω_s)² ≈ 3.5e-3) on the 24 h
        // terms. Measured: 0.35 % (178.6 m of 50.4 km), SLC and DQ within 0.1 m.
        assert!(dev <= 0.005 * amp, "{}: {dev} m of {amp} m", s.algo);
    }
}

proptest! {
    // fixed seed: the same cases on every run
    #![proptest_config(ProptestConfig { cases: 32, rng_seed: proptest::test_runner::RngSeed::Fixed(0x9_5d1), ..ProptestConfig::default() })]

    /// A stationary vehicle stays put (docs/validation.md §"stationary 90 min" scaled from 5400 s
    /// to 60 s). With ideal sensors the SL/SLC residual is roundoff: an attitude residual grows
    /// linearly, a velocity residual linearly, a position residual at most quadratically
    /// (t ≪ Schuler period, t ≪ τ = 570 s of the vertical channel: cosh(60/570) − 1 = 0.6 %),
    /// so the 90-min bounds become att ≤ 1e-10·(60/5400), vel ≤ 1e-5·(60/5400),
    /// pos ≤ 1e-2·(60/5400)² = 1.2e-6 m. DQ: its 90-min horizontal floor 0.2 m scaled the
    /// same way (2.5e-5 m) and |D| ≤ 3 m / cosh(5400/570) ≈ 5e-4 m.
    #[test]
    fn stationary_stays_put(lat in -85.0_f64..85.0, yaw in -180.0_f64..180.0) {
        let text = format!(
            "[start]\nlat_deg = {lat}\nlon_deg = 127.0\nyaw_deg = {yaw}\n[imu]\nrate_hz = 100.0\n[[segment]]\ntype = \"static\"\nduration_s = 60.0\n"
        );
        let scn = Scenario::from_toml(&text, "prop").unwrap();
        let algos = vec![spec(K::SongLee, 3), spec(K::SongLeeComplete, 3), spec(K::DualQuat, 3), spec(K::Savage, 3)];
        let (_s, got) = run_at(&scn, algos, &[60.0], false);
        let s = 60.0 / 5400.0;
        for (i, g) in got.iter().enumerate() {
            let e = &g[0];
            prop_assert!(finite(e));
            let n = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
            match i {
                0 | 1 => {
                    prop_assert!(n(e.pos_err_ned_m) <= 1e-2 * s * s, "pos {:e}", n(e.pos_err_ned_m));
                    prop_assert!(n(e.vel_err_ned_mps) <= 1e-5 * s, "vel {:e}", n(e.vel_err_ned_mps));
                    prop_assert!(n(e.att_err_rad) <= 1e-10 * s, "att {:e}", n(e.att_err_rad));
                }
                2 => {
                    prop_assert!(e.pos_err_ned_m[0].hypot(e.pos_err_ned_m[1]) <= 0.2 * s * s);
                    prop_assert!(e.pos_err_ned_m[2].abs() <= 3.0 / (5400.0_f64 / 570.0).cosh());
                }
                _ => {}
            }
        }
    }
}
