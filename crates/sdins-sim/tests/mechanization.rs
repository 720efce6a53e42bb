//! End-to-end acceptance of the mechanizations against the exact truth
//! (docs/validation.md). Reference values are the signed numbers of the papers' cases as
//! reconstructed there; tolerances ±5 % / ±10 % / bars. The 90-minute runs are release-mode `#[ignore]` tests.
#![allow(clippy::unwrap_used)]
mod common;
use common::*;
use sdins_core::coning::ConingSet;
use sdins_core::nav::{AlgorithmKind as K, AttitudeMode, RotVector};
use sdins_sim::nav::pipeline::NavError;
use sdins_sim::scenario::Scenario;

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn check3(what: &str, got: [f64; 3], want: [f64; 3], rel: [f64; 3]) {
    for i in 0..3 {
        check_rel(&format!("{what}[{i}]"), got[i], want[i], rel[i]);
    }
}

#[test]
fn turn_90dps_spec_7_3() {
    let scn = Scenario::load("turn-90dps").unwrap();
    let sl = spec(K::SongLee, 3);
    let algos = vec![
        sl,
        with(sl, None, Some(AttitudeMode::Five), None),
        with(sl, None, Some(AttitudeMode::Savage), None),
        with(sl, None, None, Some(true)),
        spec(K::DualQuat, 3),
        with(sl, Some(ConingSet::ThreeOpt), None, None),
    ];
    let (_s, got) = run_at(&scn, algos, &[8.0, 30.0], false);
    for g in &got {
        assert_eq!(g.len(), 2);
    }
    // SL transport attitude: ‖ε(8 s)‖ = 8.30e-10 (bar 2e-9); velocity at 30 s within ±5 %
    let e8 = norm(got[0][0].att_err_rad);
    assert!(e8 <= 2e-9, "SL transport ‖ε‖ = {e8:e}");
    check_rel("SL transport ‖ε(8)‖", e8, 8.30e-10, 0.05);
    let v = got[0][1].vel_err_ned_mps;
    check_rel("SL vN(30)", v[0], -3.325e-3, 0.05);
    check_rel("SL vE(30)", v[1], -3.333e-3, 0.05);
    check3(
        "SL pos(30)",
        [got[0][1].pos_err_ned_m[0], got[0][1].pos_err_ned_m[1], 0.0],
        [-7.68e-2, -7.63e-2, 0.0],
        [0.05, 0.05, 0.0],
    );
    // (5)-method attitude 2.99e-7 ± 10 %; Savage Part 1 attitude 2.57e-7 ± 10 %
    check_rel(
        "(5)-method ‖ε(8)‖",
        norm(got[1][0].att_err_rad),
        2.99e-7,
        0.10,
    );
    check_rel(
        "Savage-1 ‖ε(8)‖",
        norm(got[2][0].att_err_rad),
        2.57e-7,
        0.10,
    );
    // SL + rot3: |vel| ≤ 1e-4 m/s
    assert!(
        norm(got[3][1].vel_err_ned_mps) <= 1e-4,
        "{:?}",
        got[3][1].vel_err_ned_mps
    );
    // DQ: |vel| ≤ 1e-7, ‖ε‖ ≤ 1e-10
    assert!(norm(got[4][1].vel_err_ned_mps) <= 1e-7);
    assert!(norm(got[4][0].att_err_rad) <= 1e-10);
    // three_opt identical to three_poly to 4 significant digits (constant-rate legs dominate)
    check_rel(
        "three_opt vN(30)",
        got[5][1].vel_err_ned_mps[0],
        got[0][1].vel_err_ned_mps[0],
        1e-4,
    );
}

#[test]
fn dual_quaternion_paper_case_spec_7_5() {
    let scn = Scenario::load("dq-paper").unwrap();
    let sl = spec(K::SongLee, 2);
    let conventional = with(sl, None, None, None);
    let mut conventional_theta = conventional;
    conventional_theta.rot_vector = Some(RotVector::Theta);
    let (_s, got) = run_at(
        &scn,
        vec![
            conventional_theta,
            spec(K::DualQuat, 2),
            spec(K::Savage, 2),
            conventional,
        ],
        &[420.0],
        false,
    );
    let [c, dq, sav, conv_phi] = [&got[0][0], &got[1][0], &got[2][0], &got[3][0]];
    // Conventional row (the reference values of docs/validation.md §"dual-quaternion paper case"
    // were computed with ½Δθ×Δv rotation compensation): ±10 %
    let row = |e: &NavError| -> Vec<f64> {
        vec![
            e.pos_err_ned_m[0],
            e.pos_err_ned_m[1],
            e.height_err_m,
            e.vel_err_ned_mps[0],
            e.vel_err_ned_mps[1],
            e.vel_err_ned_mps[2],
            e.euler_err_rad[0],
            e.euler_err_rad[1],
            e.euler_err_rad[2],
        ]
    };
    let want = [
        5.33e-3, -1.68e-2, 8.96e-2, 4.23e-5, -1.07e-4, -4.44e-4, -3.71e-8, -1.94e-8, -2.25e-9,
    ];
    for (i, (g, w)) in row(c).iter().zip(want).enumerate() {
        check_rel(&format!("conventional[{i}]"), *g, w, 0.10);
    }
    // SAV row ±10 %
    let want_sav = [
        6.16e-2, 4.98e-1, 7.94e-2, 3.27e-4, 2.38e-3, -4.95e-4, -1.18e-7, -1.05e-7, 5.98e-8,
    ];
    for (i, (g, w)) in row(sav).iter().zip(want_sav).enumerate() {
        check_rel(&format!("savage[{i}]"), *g, w, 0.10);
    }
    // DQ bars: |height| ≤ 1e-3 m, |v_D| ≤ 2e-5 m/s, horizontal ≤ 0.05 m, roll −3.76e-8 ± 10 %
    assert!(dq.height_err_m.abs() <= 1e-3);
    assert!(dq.vel_err_ned_mps[2].abs() <= 2e-5);
    assert!(dq.pos_err_ned_m[0].hypot(dq.pos_err_ned_m[1]) <= 0.05);
    check_rel("DQ roll", dq.euler_err_rad[0], -3.76e-8, 0.10);
    // S2's finding: DQ better than the conventional 2-sample algorithm in height and v_D
    assert!(
        dq.height_err_m.abs() < c.height_err_m.abs()
            && dq.vel_err_ned_mps[2].abs() < c.vel_err_ned_mps[2].abs()
    );
    assert!(
        dq.height_err_m.abs() < sav.height_err_m.abs()
            && dq.vel_err_ned_mps[2].abs() < sav.vel_err_ned_mps[2].abs()
    );
    // The S1 (30) form ½Δφ×Δv is closer to the exact screw (DQ) horizontally than ½Δθ×Δv.
    let h = |e: &NavError| e.pos_err_ned_m[0].hypot(e.pos_err_ned_m[1]);
    assert!((h(conv_phi) - h(dq)).abs() < (h(c) - h(dq)).abs());
}

#[test]
#[ignore = "90-minute scenario: run in release with --ignored"]
fn mach1_east_table1_spec_7_2() {
    let scn = Scenario::load("mach1-east").unwrap();
    let algos = vec![
        spec(K::Savage, 3),
        spec(K::SongLee, 3),
        spec(K::SongLeeComplete, 3),
        spec(K::DualQuat, 3),
    ];
    let (_s, got) = run_at(&scn, algos, &[1800.0, 3600.0, 5400.0], false);
    let p = 0.05;
    let q = 0.20;
    // SAV
    let s = &got[0];
    check3(
        "SAV pos 1800",
        s[0].pos_err_ned_m,
        [-0.3092, 3.318, -0.9397],
        [p; 3],
    );
    check3(
        "SAV vel 1800",
        s[0].vel_err_ned_mps,
        [-3.07e-4, 1.948e-3, -1.920e-3],
        [p; 3],
    );
    check3(
        "SAV att 1800",
        s[0].att_err_rad,
        [-5.20e-7, -4.9e-8, 3.99e-7],
        [p; 3],
    );
    check3(
        "SAV pos 3600",
        s[1].pos_err_ned_m,
        [0.0799, 0.596, -24.41],
        [q, q, p],
    );
    check3(
        "SAV vel 3600",
        s[1].vel_err_ned_mps,
        [9.39e-4, -4.729e-3, -4.255e-2],
        [p; 3],
    );
    check3(
        "SAV att 3600",
        s[1].att_err_rad,
        [-9.3e-8, 1.3e-8, 7.2e-8],
        [q, p, q],
    );
    check3(
        "SAV pos 5400",
        s[2].pos_err_ned_m,
        [3.065, -47.58, -566.7],
        [p; 3],
    );
    check3(
        "SAV vel 5400",
        s[2].vel_err_ned_mps,
        [3.476e-3, -5.288e-2, -0.9916],
        [p; 3],
    );
    check3(
        "SAV att 5400",
        s[2].att_err_rad,
        [7.451e-6, 4.82e-7, -5.718e-6],
        [p; 3],
    );
    // SL
    let s = &got[1];
    check3(
        "SL pos 1800",
        s[0].pos_err_ned_m,
        [-4.43e-3, 4.749e-2, -1.345e-2],
        [p; 3],
    );
    check3(
        "SL vel 1800",
        s[0].vel_err_ned_mps,
        [-4.40e-6, 2.787e-5, -2.747e-5],
        [p; 3],
    );
    check3(
        "SL att 1800",
        s[0].att_err_rad,
        [-7.44e-9, -7.0e-10, 5.71e-9],
        [p; 3],
    );
    check3(
        "SL pos 3600",
        s[1].pos_err_ned_m,
        [1.1e-3, 8.5e-3, -0.3492],
        [q, q, p],
    );
    check3(
        "SL vel 3600",
        s[1].vel_err_ned_mps,
        [1.34e-5, -6.77e-5, -6.088e-4],
        [p; 3],
    );
    check3(
        "SL att 3600",
        s[1].att_err_rad,
        [-1.33e-9, 1.8e-10, 1.03e-9],
        [q, p, q],
    );
    check3(
        "SL pos 5400",
        s[2].pos_err_ned_m,
        [4.381e-2, -0.6809, -8.109],
        [p; 3],
    );
    check3(
        "SL vel 5400",
        s[2].vel_err_ned_mps,
        [4.97e-5, -7.566e-4, -1.419e-2],
        [p; 3],
    );
    check3(
        "SL att 5400",
        s[2].att_err_rad,
        [1.066e-7, 6.90e-9, -8.180e-8],
        [p; 3],
    );
    // S1's claim: SL beats SAV by ≥ 50× in every component at 5400 s
    for (a, b) in [
        (got[0][2].pos_err_ned_m, got[1][2].pos_err_ned_m),
        (got[0][2].vel_err_ned_mps, got[1][2].vel_err_ned_mps),
        (got[0][2].att_err_rad, got[1][2].att_err_rad),
    ] {
        for i in 0..3 {
            assert!(a[i].abs() >= 50.0 * b[i].abs(), "ratio {}", a[i] / b[i]);
        }
    }
    // SLC bars (and the stretch: horizontal ≤ 1e-3 m, D ≤ 2e-2 m)
    let c = &got[2][2];
    assert!(
        c.pos_err_ned_m[0].hypot(c.pos_err_ned_m[1]) <= 1e-3,
        "{:?}",
        c.pos_err_ned_m
    );
    assert!(c.pos_err_ned_m[2].abs() <= 2e-2);
    assert!(
        c.vel_err_ned_mps[0].hypot(c.vel_err_ned_mps[1]) <= 1e-5
            && c.vel_err_ned_mps[2].abs() <= 3e-4
    );
    assert!(norm(c.att_err_rad) <= 2e-9);
    // DQ bars
    let d = &got[3];
    assert!(
        d[1].pos_err_ned_m[0].hypot(d[1].pos_err_ned_m[1]) <= 0.02
            && d[1].pos_err_ned_m[2].abs() <= 0.2
    );
    assert!(
        d[2].pos_err_ned_m[0].hypot(d[2].pos_err_ned_m[1]) <= 0.5
            && d[2].pos_err_ned_m[2].abs() <= 5.0
    );
    assert!(norm(d[2].att_err_rad) <= 5e-8);
}

#[test]
#[ignore = "90-minute scenario: run in release with --ignored"]
fn stationary_90min_spec_7_1() {
    let scn = Scenario::load("stationary").unwrap();
    let algos = vec![
        spec(K::Savage, 3),
        spec(K::SongLee, 3),
        spec(K::SongLeeComplete, 3),
        spec(K::DualQuat, 3),
    ];
    let (_s, got) = run_at(&scn, algos, &[5400.0], false);
    let sav = &got[0][0];
    let refs = [
        (sav.pos_err_ned_m, [0.4581_f64, -6.822, -158.0]),
        (sav.vel_err_ned_mps, [2.77e-4, -1.164e-2, -0.2771]),
        (sav.att_err_rad, [1.068e-6, 7.2e-8, -8.197e-7]),
    ];
    for (g, w) in refs {
        for i in 0..3 {
            if w[i].abs() > 1e-3 {
                check_rel("SAV stationary", g[i], w[i], 0.05);
            }
        }
    }
    for e in [&got[1][0], &got[2][0]] {
        assert!(
            norm(e.pos_err_ned_m) <= 1e-2
                && norm(e.vel_err_ned_mps) <= 1e-5
                && norm(e.att_err_rad) <= 1e-10,
            "{e:?}"
        );
    }
    let d = &got[3][0];
    assert!(d.pos_err_ned_m[0].hypot(d.pos_err_ned_m[1]) <= 0.2 && d.pos_err_ned_m[2].abs() <= 3.0);
}

#[test]
fn any_latitude_heading_and_update_ratio() {
    // Cruise at 250 m/s for 60 s over latitudes up to ±89° and several headings, N = 1..4.
    // The exact algorithms (SLC, DQ) must stay within 1e-4 m and 1e-9 rad (their residual
    // is second order in ΔT: ≤ 9e-6 m and 6e-11 rad measured at N = 4); all four give
    // finite results. Near the pole the transport rate is large (v tanL/R ≈ 2e-3 rad/s at
    // 89°), which exercises the transport attitude and the extra velocity terms.
    for lat in [-89.0, -60.0, 0.0, 45.0, 89.0] {
        for yaw in [0.0, 135.0, 270.0] {
            let text = format!(
                "[start]\nlat_deg = {lat}\nlon_deg = 179.99\nspeed_mps = 250.0\nyaw_deg = {yaw}\n[imu]\nrate_hz = 200.0\n[[segment]]\ntype = \"cruise\"\nduration_s = 60.0\n"
            );
            let scn = Scenario::from_toml(&text, "sweep").unwrap();
            for n in 1..=4 {
                let algos = vec![
                    spec(K::Savage, n),
                    spec(K::SongLee, n),
                    spec(K::SongLeeComplete, n),
                    spec(K::DualQuat, n),
                ];
                let (_s, got) = run_at(&scn, algos, &[60.0], false);
                for (i, g) in got.iter().enumerate() {
                    let e = &g[0];
                    assert!(e
                        .pos_err_ned_m
                        .iter()
                        .chain(&e.vel_err_ned_mps)
                        .chain(&e.att_err_rad)
                        .all(|x| x.is_finite()));
                    if i >= 2 {
                        let pos = norm(e.pos_err_ned_m);
                        let att = norm(e.att_err_rad);
                        assert!(
                            pos <= 1e-4 && att <= 1e-9,
                            "lat {lat} yaw {yaw} N {n} algo {i}: pos {pos:e} att {att:e}"
                        );
                    }
                }
            }
        }
    }
}
