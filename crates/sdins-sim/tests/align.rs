//! Alignment acceptance tests, docs/validation.md (T1, T2, T4–T7) and the real-data check on PSINS
//! `lasergyro.imu`.
//!
//! Tolerances come from the theory (docs/theory/alignment.md) and its reference prototype; the
//! Monte Carlo ones are `#[ignore]`d (run with `cargo test --release -- --ignored`).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{SMatrix, SVector};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use sdins_core::align::coarse::{self, CoarseMethod};
use sdins_core::align::fine::{reference_config, FineAlign, FineConfig};
use sdins_core::align::model::{
    null_space_body, null_space_ned, p0_reference, pseudo9_transform, residual_projector,
    BiasFrame, Vec12,
};
use sdins_core::align::Site;
use sdins_core::earth::EarthModel;
use sdins_core::math::{attitude_error, dcm_from_rotvec, Euler, Mat3, Vec3};
use sdins_sim::align::experiment::{
    algorithm_a, algorithm_b, coarse_window, corrupt, multiheading_trajectory, run_fine,
    truth_record, TruthRecord,
};
use sdins_sim::cancel::CancelToken;
use sdins_sim::scenario::Scenario;
use sdins_sim::sensors::imu_error::{ImuErrorModel, DPH, DPSH, UG};
use std::sync::OnceLock;

const D2R: f64 = std::f64::consts::PI / 180.0;
const URAD: f64 = 1e-6;

fn ref_ba() -> Vec3 {
    Vec3::new(50.0, -80.0, 30.0) * UG
}
fn ref_bg() -> Vec3 {
    Vec3::new(0.01, -0.02, 0.015) * DPH
}
fn vrw() -> f64 {
    20.0 * UG
}
fn arw() -> f64 {
    0.002 * DPSH
}

fn bias_model(ba: &Vec3, bg: &Vec3) -> ImuErrorModel {
    ImuErrorModel {
        accel_bias_ug: [ba.x / UG, ba.y / UG, ba.z / UG],
        gyro_bias_dph: [bg.x / DPH, bg.y / DPH, bg.z / DPH],
        ..ImuErrorModel::default()
    }
}

fn noisy_model(ba: &Vec3, bg: &Vec3) -> ImuErrorModel {
    ImuErrorModel {
        accel_vrw_ugpsqrthz: [20.0; 3],
        gyro_arw_dpsh: [0.002; 3],
        ..bias_model(ba, bg)
    }
}

/// The REF scenario (built-in `alignment`: 37.5°, 2/−3/40°, 100 Hz, 1800 s), exact truth.
fn ref_truth() -> &'static TruthRecord {
    static T: OnceLock<TruthRecord> = OnceLock::new();
    T.get_or_init(|| {
        let scn = Scenario::load("alignment").unwrap();
        truth_record(
            &scn.trajectory,
            EarthModel::WGS84,
            scn.imu.dt_s(),
            scn.start.lat_rad,
            scn.start.lon_rad,
            scn.start.h_m,
        )
    })
}

fn ref_site() -> Site {
    ref_truth().site
}

/// x0 = \[δv0, φ0, δa^n, ε^n\] (NED residual biases at the true attitude).
fn x0_ned(phi0: &Vec3, c: &Mat3, ba: &Vec3, bg: &Vec3) -> Vec12 {
    let mut x = Vec12::zeros();
    x.fixed_rows_mut::<3>(3).copy_from(phi0);
    x.fixed_rows_mut::<3>(6).copy_from(&(c * ba));
    x.fixed_rows_mut::<3>(9).copy_from(&(c * bg));
    x
}

#[test]
fn t1_coarse_noise_free_matches_corrected_table() {
    let tr = ref_truth();
    let s = ref_site();
    assert!((s.g_mps2 - 9.799490523606893).abs() < 1e-12);
    let incs = corrupt(
        &tr.increments[..6000],
        tr.dt_s,
        &bias_model(&ref_ba(), &ref_bg()),
        1,
        0,
    )
    .unwrap();
    let c = tr.c_b_n0;
    let (da, eps) = (c * ref_ba(), c * ref_bg());
    // docs/theory/alignment.md §"Reference case": NED biases
    assert!((da / UG - Vec3::new(89.2243, -30.8676, 29.7693)).norm() < 1e-3);
    assert!((eps / DPH - Vec3::new(0.020261, -0.009774, 0.014797)).norm() < 1e-6);
    for (m, want_spec) in [
        (CoarseMethod::OneStep, Vec3::new(30.89, 653.21, 795.41)),
        (CoarseMethod::TwoStep, Vec3::new(30.89, 89.29, 795.41)),
    ] {
        let table = coarse::error_table(m, &da, &eps, &s);
        assert!(
            (table / URAD - want_spec).amax() < 0.01,
            "{m:?} table {:?}",
            table / URAD
        );
        let est = coarse_window(&incs, tr.dt_s, 0, incs.len(), &s, m).unwrap();
        let phi = attitude_error(&est, &c);
        println!(
            "T1 {m:?}: φ = {:.2?} μrad, table {:.2?}",
            (phi / URAD).as_slice(),
            (table / URAD).as_slice()
        );
        assert!((phi - table).amax() <= 5.0 * URAD, "{m:?}");
    }
}

/// T1 randomized: 1000 cases (|roll|,|pitch| ≤ 30°, any yaw, |L| ≤ 70°, biases
/// N(0, 100 μg), N(0, 0.01 °/h)): |sim − table| ≤ 5 μrad + 1 % of max|table|.
#[test]
fn t1_coarse_randomized_against_table() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut n = || -> f64 { StandardNormal.sample(&mut rng) };
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        let u = |x: f64| x.tanh(); // (−1, 1)
        let e = Euler::new(
            30.0 * D2R * u(n()),
            30.0 * D2R * u(n()),
            std::f64::consts::PI * u(n()),
        );
        let s = Site {
            lat_rad: 70.0 * D2R * u(n()),
            g_mps2: 9.8,
            omega_ie_rps: 7.292115e-5,
        };
        let c = sdins_core::math::c_b_n_from_euler(&e);
        let ba = Vec3::new(n(), n(), n()) * 100.0 * UG;
        let bg = Vec3::new(n(), n(), n()) * 0.01 * DPH;
        let f = c.transpose() * (-s.g_n()) + ba;
        let w = c.transpose() * s.omega_ie_n() + bg;
        for m in [CoarseMethod::OneStep, CoarseMethod::TwoStep] {
            let est = match m {
                CoarseMethod::OneStep => coarse::one_step(&f, &w, &s),
                CoarseMethod::TwoStep => coarse::two_step(&f, &w, &s),
            }
            .unwrap();
            let phi = attitude_error(&est, &c);
            let table = coarse::error_table(m, &(c * ba), &(c * bg), &s);
            let d = (phi - table).amax();
            worst = worst.max(d / (5.0 * URAD + 0.01 * table.amax()));
            assert!(
                d <= 5.0 * URAD + 0.01 * table.amax(),
                "{m:?} {e:?} L={} d={d}",
                s.lat_rad
            );
        }
    }
    println!("T1 randomized: worst |sim − table| / tolerance = {worst:.3}");
}

/// T2: coarse-alignment noise, biases 0, T_c = 60 s, 200 runs: sample σ within ±15 % of
/// docs/theory/alignment.md §"Coarse alignment" (σ_tilt 2.58 μrad, σ_yaw 1.298 mrad, 1-step σ(φ_E)
/// 0.649 mrad).
#[test]
fn t2_coarse_noise_sigma() {
    let tr = ref_truth();
    let s = ref_site();
    let n = 6000;
    let model = noisy_model(&Vec3::zeros(), &Vec3::zeros());
    let errs: Vec<(Vec3, Vec3)> = (0..200u64)
        .into_par_iter()
        .map(|run| {
            let incs = corrupt(&tr.increments[..n], tr.dt_s, &model, 11, run).unwrap();
            let p1 = attitude_error(
                &coarse_window(&incs, tr.dt_s, 0, n, &s, CoarseMethod::OneStep).unwrap(),
                &tr.c_b_n0,
            );
            let p2 = attitude_error(
                &coarse_window(&incs, tr.dt_s, 0, n, &s, CoarseMethod::TwoStep).unwrap(),
                &tr.c_b_n0,
            );
            (p1, p2)
        })
        .collect();
    let sd = |f: &dyn Fn(&(Vec3, Vec3)) -> f64| {
        let m = errs.iter().map(f).sum::<f64>() / errs.len() as f64;
        (errs.iter().map(|e| (f(e) - m).powi(2)).sum::<f64>() / (errs.len() - 1) as f64).sqrt()
    };
    let (st, sy, se1) = coarse::noise_sigma(vrw(), arw(), 60.0, &s);
    assert!((st / URAD - 2.58).abs() < 0.01 && (sy - 1.298e-3).abs() < 2e-6);
    assert!((se1 - 0.649e-3).abs() < 2e-6);
    let tilt_n = sd(&|e| e.1.x);
    let tilt_e = sd(&|e| e.1.y);
    let yaw = sd(&|e| e.1.z);
    let e1 = sd(&|e| e.0.y);
    println!(
        "T2: σ tilt N/E {:.2}/{:.2} μrad (2.58), σ yaw {:.3} mrad (1.298), 1-step σ φE {:.3} mrad (0.649)",
        tilt_n / URAD, tilt_e / URAD, yaw * 1e3, e1 * 1e3
    );
    for (got, want) in [(tilt_n, st), (tilt_e, st), (yaw, sy), (e1, se1)] {
        assert!((got / want - 1.0).abs() <= 0.15, "{got} vs {want}");
    }
}

/// T4: fine alignment, noise-free REF, φ0 = \[0.5, −0.5, 5\] mrad: from 300 s on,
/// |φ_N,E − Π x0| ≤ 10 μrad, |φ_D − Π x0| ≤ 20 μrad; Π x0 = \[35.23, 91.91, 907.05\] μrad.
#[test]
fn t4_fine_noise_free() {
    let tr = ref_truth();
    let s = ref_site();
    let incs = corrupt(
        &tr.increments,
        tr.dt_s,
        &bias_model(&ref_ba(), &ref_bg()),
        1,
        0,
    )
    .unwrap();
    let phi0 = Vec3::new(0.5e-3, -0.5e-3, 5e-3);
    let c = tr.c_b_n0;
    let c0 = dcm_from_rotvec(&phi0) * c;
    // Noise-free truth: the matched filter has Q = 0 (see the aviation-Q run below).
    let cfg = reference_config(s, 0.0, 0.0);
    let pi = residual_projector(&null_space_ned(&s), &cfg.p0).unwrap();
    let res = pi * x0_ned(&phi0, &c, &ref_ba(), &ref_bg());
    let want = res.fixed_rows::<3>(3).into_owned();
    println!("T4 Π x0 φ = {:.2?} μrad", (want / URAD).as_slice());
    assert!((want / URAD - Vec3::new(35.23, 91.91, 907.05)).amax() < 0.05);
    let (mut max_t, mut max_h) = (0.0f64, 0.0f64);
    let (mut at60, mut at120) = (0.0f64, 0.0f64);
    run_fine(
        &incs,
        tr.dt_s,
        cfg,
        &c0,
        |j, fa| {
            let t = (j + 1) as f64 * tr.dt_s;
            let d = attitude_error(&fa.c_b_n(), &tr.c_b_n[j]) - want;
            if t >= 300.0 - 1e-6 {
                max_t = max_t.max(d.x.abs().max(d.y.abs()));
                max_h = max_h.max(d.z.abs());
            }
            if t >= 60.0 - 1e-6 {
                at60 = at60.max(d.x.abs().max(d.y.abs()));
            }
            if t >= 120.0 - 1e-6 {
                at120 = at120.max(d.z.abs());
            }
            let ti = t.round() as u64;
            if [10, 30, 60, 120, 200, 300, 600, 900, 1200, 1800].contains(&ti) {
                println!(
                    "  t={ti} d={:.2?} μrad σ={:.1?} μrad",
                    (d / URAD).as_slice(),
                    (fa.attitude_sigma() / URAD).as_slice()
                );
            }
        },
        &CancelToken::new(),
    )
    .unwrap();
    println!(
        "T4: max |tilt − Πx0| from 300 s {:.2} μrad (≤10), heading {:.2} μrad (≤20); tilt from 60 s {:.2}, heading from 120 s {:.2}",
        max_t / URAD, max_h / URAD, at60 / URAD, at120 / URAD
    );
    assert!(max_t <= 10.0 * URAD);
    assert!(max_h <= 20.0 * URAD);
    // Reference case T4 literally: the same noise-free data with Q from aviation noise. The tilt
    // still meets 10 μrad; the heading drifts off Π x0 by up to ≈ 60 μrad (ARW in Q makes
    // the filter a fading-memory estimator of the weakly observable ε'_D, and Π x0 is the
    // limit of the exact Bayesian (Q = 0) filter only). That deviation is a quarter of the
    // filter's own 1σ of the observable heading φ'_D (≈ 250 μrad at 1800 s), so the bound
    // used is 0.5σ.
    let cfg = reference_config(s, vrw(), arw());
    let (mut max_t, mut max_h, mut sig_h) = (0.0f64, 0.0f64, 0.0f64);
    let t9 = pseudo9_transform(&s);
    run_fine(
        &incs,
        tr.dt_s,
        cfg,
        &c0,
        |j, fa| {
            let t = (j + 1) as f64 * tr.dt_s;
            let d = attitude_error(&fa.c_b_n(), &tr.c_b_n[j]) - want;
            if t >= 300.0 - 1e-6 {
                max_t = max_t.max(d.x.abs().max(d.y.abs()));
                let pp = t9 * fa.kf().p * t9.transpose();
                let sh = pp[(5, 5)].sqrt();
                max_h = max_h.max(d.z.abs() / sh);
                sig_h = sh;
            }
        },
        &CancelToken::new(),
    )
    .unwrap();
    println!(
        "T4 with aviation Q: max |tilt − Πx0| from 300 s {:.2} μrad, max |φ_D − Πx0|/σ(φ'_D) {:.3}, σ(φ'_D)@1800 {:.0} μrad",
        max_t / URAD, max_h, sig_h / URAD
    );
    assert!(max_t <= 10.0 * URAD);
    assert!(max_h <= 0.5);
}

/// Per-run deviations from Π x0 at the check times of T5.
fn t5_run(run: u64) -> ([Vec3; 4], f64) {
    let tr = ref_truth();
    let s = ref_site();
    let incs = corrupt(
        &tr.increments,
        tr.dt_s,
        &noisy_model(&ref_ba(), &ref_bg()),
        5,
        run,
    )
    .unwrap();
    let phi0 = Vec3::new(0.5e-3, -0.5e-3, 5e-3);
    let c = tr.c_b_n0;
    let cfg = reference_config(s, vrw(), arw());
    let pi = residual_projector(&null_space_ned(&s), &cfg.p0).unwrap();
    let want = (pi * x0_ned(&phi0, &c, &ref_ba(), &ref_bg()))
        .fixed_rows::<3>(3)
        .into_owned();
    let mut out = [Vec3::zeros(); 4];
    let mut max_tilt: f64 = 0.0;
    run_fine(
        &incs,
        tr.dt_s,
        cfg,
        &(dcm_from_rotvec(&phi0) * c),
        |j, fa| {
            let t = ((j + 1) as f64 * tr.dt_s).round() as u64;
            let d = attitude_error(&fa.c_b_n(), &tr.c_b_n[j]) - want;
            if t >= 300 {
                max_tilt = max_tilt.max(d.x.abs().max(d.y.abs()));
            }
            match t {
                300 => out[0] = d,
                600 => out[1] = d,
                900 => out[2] = d,
                1800 => out[3] = d,
                _ => {}
            }
        },
        &CancelToken::new(),
    )
    .unwrap();
    (out, max_tilt)
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// T5: fine alignment with aviation noise, 50 runs.
#[test]
#[ignore = "Monte Carlo, 50 runs: run with --release -- --ignored"]
fn t5_fine_aviation_noise_monte_carlo() {
    let runs: Vec<([Vec3; 4], f64)> = (0..50u64).into_par_iter().map(t5_run).collect();
    let tilt300: Vec<f64> = runs.iter().flat_map(|r| [r.0[0].x, r.0[0].y]).collect();
    let tilt_rms = rms(&tilt300); // per-axis RMS
    let head = |k: usize| rms(&runs.iter().map(|r| r.0[k].z).collect::<Vec<_>>());
    let max_tilt = runs.iter().map(|r| r.1).fold(0.0, f64::max);
    let max_h900 = runs.iter().map(|r| r.0[2].z.abs()).fold(0.0, f64::max);
    println!(
        "T5 (50 runs): tilt RMS@300 {:.2} μrad (≤20), max tilt ≥300 s {:.1} μrad (≤80), heading RMS @600/900/1800 {:.3}/{:.3}/{:.3} mrad (≤0.6/0.5/0.35), max heading@900 {:.3} mrad (≤1.5)",
        tilt_rms / URAD, max_tilt / URAD, head(1) * 1e3, head(2) * 1e3, head(3) * 1e3, max_h900 * 1e3
    );
    assert!(tilt_rms <= 20.0 * URAD);
    assert!(max_tilt <= 80.0 * URAD);
    assert!(head(1) <= 0.6e-3);
    assert!(head(2) <= 0.5e-3);
    assert!(head(3) <= 0.35e-3);
    assert!(max_h900 <= 1.5e-3);
}

/// Wilson–Hilferty 95 % band of the mean of N χ²(k) variables.
fn chi2_mean_band(k: usize, n: usize) -> (f64, f64) {
    let dof = (k * n) as f64;
    let a = 2.0 / (9.0 * dof);
    let q = |z: f64| dof * (1.0 - a + z * a.sqrt()).powi(3) / n as f64;
    (q(-1.959964), q(1.959964))
}

/// NEES epochs \[s\].
const NEES_TIMES: [u64; 4] = [60, 300, 900, 1800];

/// Consistency Monte Carlo: initial error (δv, φ, biases) drawn per run from N(0, P0),
/// aviation noise (VRW 20 μg/√Hz, ARW 0.002 °/√h) at 100 Hz, KF at 1 Hz with
/// `R = σ_z² I3`. If `meas_noise`, the zero-velocity measurement is `ṽ = 0 + ν`,
/// `ν ~ N(0, σ_z² I3)` (exactly the R of the filter); otherwise `ṽ = 0` (noise-free).
///
/// Returns, per epoch of [`NEES_TIMES`], the run-mean of
/// `[NEES of the 9 observable coordinates p = T9 e (docs/theory/alignment.md
/// §"Observability at one heading"), marginal NEES of δv (3 dof), marginal NEES of the 6 pseudo
/// states φ', ε'_N, ε'_D, δa_D (6 dof)]`, with `e` = true error − estimate (estimate = 0 after the
/// closed-loop reset; convention G, `φ = log(Ĉ Cᵀ)`; residual biases resolved with the true C) and
/// the covariance `T9 P T9ᵀ`.
fn nees_monte_carlo(runs: u64, sigma_z: f64, meas_noise: bool) -> Vec<[f64; 3]> {
    let tr = ref_truth();
    let s = ref_site();
    let cfg = FineConfig {
        sigma_z_mps: sigma_z,
        ..reference_config(s, vrw(), arw())
    };
    let t9 = pseudo9_transform(&s);
    let times = NEES_TIMES;
    let p0 = p0_reference();
    let out: Vec<[[f64; 3]; 4]> = (0..runs)
        .into_par_iter()
        .map(|run| {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1000 + run);
            let z = Vec12::from_fn(|_, _| StandardNormal.sample(&mut rng));
            let x0 = p0.map(f64::sqrt) * z; // P0 diagonal
            let c = tr.c_b_n0;
            let phi0 = x0.fixed_rows::<3>(3).into_owned();
            let ba = c.transpose() * x0.fixed_rows::<3>(6).into_owned();
            let bg = c.transpose() * x0.fixed_rows::<3>(9).into_owned();
            let dv0 = x0.fixed_rows::<3>(0).into_owned();
            let incs = corrupt(&tr.increments, tr.dt_s, &noisy_model(&ba, &bg), 77, run).unwrap();
            let mut fa = FineAlign::new(cfg, &(dcm_from_rotvec(&phi0) * c));
            let mut nees = [[0.0; 3]; 4];
            let mut v_off = dv0;
            let mut vrng = rand_chacha::ChaCha8Rng::seed_from_u64(5000 + run);
            for (j, inc) in incs.iter().enumerate() {
                // ṽ = 0 + ν, ν ~ N(0, σ_z² I3), drawn afresh for every sample so that
                // whichever sample closes a KF interval uses an independent draw
                let v_meas = if meas_noise {
                    Vec3::from_fn(|_, _| {
                        let w: f64 = StandardNormal.sample(&mut vrng);
                        sigma_z * w
                    })
                } else {
                    Vec3::zeros()
                };
                let mut inc2 = *inc;
                if j == 0 {
                    // inject δv0 as a velocity step in the first sample
                    inc2.dv_b_mps += fa.c_b_n_ins().transpose() * v_off;
                    v_off = Vec3::zeros();
                }
                if fa.step_with_velocity(&inc2, tr.dt_s, &v_meas) {
                    let t = ((j + 1) as f64 * tr.dt_s).round() as u64;
                    if let Some(k) = times.iter().position(|&x| x == t) {
                        let ct = tr.c_b_n[j];
                        let mut e = Vec12::zeros();
                        e.fixed_rows_mut::<3>(0).copy_from(&fa.v_n());
                        e.fixed_rows_mut::<3>(3)
                            .copy_from(&attitude_error(&fa.c_b_n(), &ct));
                        e.fixed_rows_mut::<3>(6)
                            .copy_from(&(ct * (ba - fa.accel_bias_b())));
                        e.fixed_rows_mut::<3>(9)
                            .copy_from(&(ct * (bg - fa.gyro_bias_b())));
                        let ep: SVector<f64, 9> = t9 * e;
                        let pp: SMatrix<f64, 9, 9> = t9 * fa.kf().p * t9.transpose();
                        nees[k][0] = (ep.transpose() * pp.try_inverse().unwrap() * ep)[0];
                        // marginal NEES of δv (3 dof) and of the 6 pseudo states (6 dof)
                        let ev = ep.fixed_rows::<3>(0);
                        let pv = pp.fixed_view::<3, 3>(0, 0).into_owned();
                        nees[k][1] = (ev.transpose() * pv.try_inverse().unwrap() * ev)[0];
                        let e6 = ep.fixed_rows::<6>(3);
                        let p6 = pp.fixed_view::<6, 6>(3, 3).into_owned();
                        nees[k][2] = (e6.transpose() * p6.try_inverse().unwrap() * e6)[0];
                    }
                }
            }
            nees
        })
        .collect();
    let mean = |k: usize, c: usize| out.iter().map(|r| r[k][c]).sum::<f64>() / runs as f64;
    let (lo, hi) = chi2_mean_band(9, runs as usize);
    println!(
        "NEES, {runs} runs, σ_z = {:.0e} m/s, simulated measurement noise: {meas_noise}",
        sigma_z
    );
    for (k, t) in times.iter().enumerate() {
        println!(
            "  {t:>4} s: pseudo-9 {:.2} (band [{lo:.2}, {hi:.2}]), δv {:.2} (3), pseudo-6 {:.2} (6)",
            mean(k, 0),
            mean(k, 1),
            mean(k, 2)
        );
    }
    (0..times.len())
        .map(|k| [mean(k, 0), mean(k, 1), mean(k, 2)])
        .collect()
}

/// Filter consistency (NEES) with a statistically matched measurement: the simulated
/// zero-velocity measurement carries exactly the noise the filter assumes,
/// `ν ~ N(0, σ_z² I3)`, σ_z = 1 mm/s (docs/theory/alignment.md §"Fine alignment"). The mean
/// pseudo-state NEES (9 dof) over 50 runs lies in its 95 % χ² band at 60, 300, 900 and 1800 s.
///
/// Why the simulated ν: in the simulation the IMU is exactly at rest, so the plain
/// zero-velocity update `ṽ = 0` is noise-free, while the filter uses R = (1 mm/s)² — a
/// tuning value for sway/vibration on a real pad. A filter whose R exceeds the true
/// measurement noise is conservative by construction; a NEES test must use the truth
/// of the simulation. (A tiny R with ṽ = 0 does not work either: the posterior δv
/// variance is then ≈ R while the true δv error is ≈ R/σ⁻, so the δv part of the NEES
/// tends to 0; see [`nees_without_measurement_noise_is_conservative_in_dv_only`].)
#[test]
#[ignore = "Monte Carlo, 50 runs: run with --release -- --ignored"]
fn t5_nees_pseudo_states_consistent() {
    let (lo, hi) = chi2_mean_band(9, 50);
    let means = nees_monte_carlo(50, 1e-3, true);
    for (m, t) in means.iter().zip(NEES_TIMES) {
        assert!(m[0] >= lo && m[0] <= hi, "NEES at {t} s = {}", m[0]);
    }
}

/// The diagnosis of the formerly failing NEES test, kept as a regression check: with
/// the noise-free `ṽ = 0` and R = (1 mm/s)² the whole NEES deficit is in the 3 velocity
/// states, whose marginal NEES (≈ 1.1–1.3) lies below its 3-dof band, while the 6 pseudo
/// states (attitude, observable bias combinations) are consistent.
///
/// Scalar derivation (velocity random walk, steady state, q = VRW² Δt, r = σ_z²): the
/// filter's prior is `p = q/2 + √(q²/4 + q r)` (≈ 2.1e-7 m²/s² here), gain
/// `K = p/(p + r)` ≈ 0.18 and `P⁺ = p − q`. With ν ≡ 0 the true posterior error obeys
/// `P_t = (1 − K)² (P_t + q)`, i.e. `P_t = (1 − K)² q / (1 − (1 − K)²)` ≈ 2.1 q, against
/// the filter's `P⁺` ≈ 4.6 q: ratio ≈ 0.45, δv NEES ≈ 3 · 0.45 ≈ 1.35 (observed 1.1–1.3;
/// the scalar model ignores the tilt coupling).
#[test]
#[ignore = "Monte Carlo, 50 runs: run with --release -- --ignored"]
fn nees_without_measurement_noise_is_conservative_in_dv_only() {
    let (lo3, _) = chi2_mean_band(3, 50);
    let (lo6, hi6) = chi2_mean_band(6, 50);
    let means = nees_monte_carlo(50, 1e-3, false);
    for (m, t) in means.iter().zip(NEES_TIMES) {
        assert!(
            m[1] < lo3,
            "δv NEES at {t} s = {} (expected below {lo3})",
            m[1]
        );
        assert!(
            m[2] >= lo6 && m[2] <= hi6,
            "pseudo-6 NEES at {t} s = {} (band [{lo6}, {hi6}])",
            m[2]
        );
    }
}

// ---------------------------------------------------------------- multi-heading

const STATIC_TOTAL_S: f64 = 1200.0;

fn mh_case(headings: &[f64]) -> (TruthRecord, Vec<(f64, f64)>) {
    let scn = Scenario::load("alignment").unwrap();
    let each = STATIC_TOTAL_S / headings.len() as f64;
    let (traj, phases) = multiheading_trajectory(scn.start.euler, headings, each, 10.0);
    let tr = truth_record(
        &traj,
        EarthModel::WGS84,
        scn.imu.dt_s(),
        scn.start.lat_rad,
        scn.start.lon_rad,
        scn.start.h_m,
    );
    (tr, phases)
}

/// (relative headings, truth, static phases)
type MhCase = (Vec<f64>, TruthRecord, Vec<(f64, f64)>);

fn mh_cases() -> &'static [MhCase] {
    static C: OnceLock<Vec<MhCase>> = OnceLock::new();
    C.get_or_init(|| {
        [
            vec![0.0],
            vec![0.0, 180.0],
            vec![0.0, 90.0],
            vec![0.0, 90.0, 180.0, 270.0],
        ]
        .into_par_iter()
        .map(|h| {
            let (tr, ph) = mh_case(&h);
            (h, tr, ph)
        })
        .collect()
    })
}

fn mh_cfg(s: Site) -> FineConfig {
    FineConfig {
        bias_frame: BiasFrame::Body,
        ..reference_config(s, vrw(), arw())
    }
}

/// Matched filter for noise-free data (Q = 0, see T4).
fn mh_cfg_nf(s: Site) -> FineConfig {
    FineConfig {
        bias_frame: BiasFrame::Body,
        ..reference_config(s, 0.0, 0.0)
    }
}

/// Errors of a multi-heading result: (b_a err \[μg\], b_g err \[°/h\], φ \[μrad\]).
fn mh_errors(
    r: &sdins_sim::align::experiment::MultiHeadingResult,
    tr: &TruthRecord,
    ba: &Vec3,
    bg: &Vec3,
) -> (Vec3, Vec3, Vec3) {
    let c_end = tr.c_b_n.last().unwrap();
    (
        (r.accel_bias_b - ba) / UG,
        (r.gyro_bias_b - bg) / DPH,
        attitude_error(&r.c_b_n, c_end) / URAD,
    )
}

/// T6: multi-heading, noise-free, Algorithm A (body-frame biases), 1200 s static total,
/// 10 °/s rotations; and the negative test with NED-frame bias states.
#[test]
fn t6_multiheading_noise_free_algorithm_a() {
    for (h, tr, _ph) in mh_cases() {
        let s = tr.site;
        let incs = corrupt(
            &tr.increments,
            tr.dt_s,
            &bias_model(&ref_ba(), &ref_bg()),
            1,
            0,
        )
        .unwrap();
        let r = algorithm_a(
            &incs,
            tr.dt_s,
            mh_cfg_nf(s),
            60.0,
            |_, _| {},
            &CancelToken::new(),
        )
        .unwrap();
        let (ea, eg, phi) = mh_errors(&r, tr, &ref_ba(), &ref_bg());
        println!(
            "T6 A {h:?}: b_a err {:.3?} μg, b_g err {:.5?} °/h, φ {:.2?} μrad",
            ea.as_slice(),
            eg.as_slice(),
            phi.as_slice()
        );
        if h.len() == 1 {
            // not estimated: horizontal b_a error ≥ 80 % of the true magnitude
            assert!(ea.x.abs() >= 0.8 * 50.0 && ea.y.abs() >= 0.8 * 80.0);
            // φ equals the finite-prior residual Π x0 (coarse start) within 10/30 μrad
            let c = tr.c_b_n0;
            let incs60 = &incs[..6000];
            let c0 = coarse_window(incs60, tr.dt_s, 0, 6000, &s, CoarseMethod::TwoStep).unwrap();
            let phi0 = attitude_error(&c0, &c);
            let mut x0 = Vec12::zeros();
            x0.fixed_rows_mut::<3>(3).copy_from(&phi0);
            x0.fixed_rows_mut::<3>(6).copy_from(&ref_ba());
            x0.fixed_rows_mut::<3>(9).copy_from(&ref_bg());
            let pi = residual_projector(&null_space_body(&s, &c), &p0_reference()).unwrap();
            let want = (pi * x0).fixed_rows::<3>(3).into_owned() / URAD;
            println!("   Π x0 φ = {:.2?} μrad", want.as_slice());
            assert!((phi.x - want.x).abs().max((phi.y - want.y).abs()) <= 10.0);
            assert!((phi.z - want.z).abs() <= 30.0);
        } else {
            assert!(ea.amax() <= 0.2, "{h:?} b_a");
            assert!(eg.x.abs().max(eg.y.abs()) <= 0.002, "{h:?} b_g");
            assert!(eg.z.abs() <= 0.008, "{h:?} b_gz");
            assert!(phi.x.abs().max(phi.y.abs()) <= 1.0, "{h:?} tilt");
            assert!(phi.z.abs() <= 30.0, "{h:?} heading");
        }
    }
    // negative test: NED-frame bias states across 0/180 must fail (heading > 1 mrad)
    let (_, tr, _) = &mh_cases()[1];
    let incs = corrupt(
        &tr.increments,
        tr.dt_s,
        &bias_model(&ref_ba(), &ref_bg()),
        1,
        0,
    )
    .unwrap();
    let c0 = coarse_window(&incs, tr.dt_s, 0, 6000, &tr.site, CoarseMethod::TwoStep).unwrap();
    let cfg = FineConfig {
        bias_frame: BiasFrame::Ned,
        ..mh_cfg_nf(tr.site)
    };
    let fa = run_fine(&incs, tr.dt_s, cfg, &c0, |_, _| {}, &CancelToken::new()).unwrap();
    let phi = attitude_error(&fa.c_b_n(), tr.c_b_n.last().unwrap());
    println!(
        "T6 negative (NED states, 0/180): φ = {:.1?} μrad",
        (phi / URAD).as_slice()
    );
    assert!(phi.z.abs() > 1e-3);
}

/// Algorithm B (docs/theory/alignment.md §"Multi-heading alignment") on simulated signals,
/// noise-free: same accuracy class as Algorithm A for 2 and 4 headings; single heading is
/// rank-deficient.
#[test]
fn algorithm_b_noise_free_signals() {
    for (h, tr, ph) in mh_cases() {
        let incs = corrupt(
            &tr.increments,
            tr.dt_s,
            &bias_model(&ref_ba(), &ref_bg()),
            1,
            0,
        )
        .unwrap();
        let cfg = reference_config(tr.site, 0.0, 0.0);
        let r = algorithm_b(&incs, tr.dt_s, cfg, 60.0, ph, &CancelToken::new());
        if h.len() == 1 {
            assert!(r.is_err());
            continue;
        }
        let r = r.unwrap();
        let (ea, eg, phi) = mh_errors(&r, tr, &ref_ba(), &ref_bg());
        println!(
            "Alg B {h:?}: b_a err {:.3?} μg, b_g err {:.5?} °/h, φ {:.2?} μrad",
            ea.as_slice(),
            eg.as_slice(),
            phi.as_slice()
        );
        assert!(ea.amax() <= 0.5, "{h:?} b_a");
        assert!(eg.x.abs().max(eg.y.abs()) <= 0.002, "{h:?} b_g");
        assert!(phi.x.abs().max(phi.y.abs()) <= 2.0, "{h:?} tilt");
        assert!(phi.z.abs() <= 30.0, "{h:?} heading");
    }
}

/// T7: multi-heading with aviation noise, 50 runs, Algorithm A.
#[test]
#[ignore = "Monte Carlo, 50 runs × 4 sequences: run with --release -- --ignored"]
fn t7_multiheading_aviation_noise_monte_carlo() {
    for (h, tr, _) in mh_cases() {
        let model = noisy_model(&ref_ba(), &ref_bg());
        let errs: Vec<(Vec3, Vec3, Vec3)> = (0..50u64)
            .into_par_iter()
            .map(|run| {
                let incs = corrupt(&tr.increments, tr.dt_s, &model, 9, run).unwrap();
                let r = algorithm_a(
                    &incs,
                    tr.dt_s,
                    mh_cfg(tr.site),
                    60.0,
                    |_, _| {},
                    &CancelToken::new(),
                )
                .unwrap();
                mh_errors(&r, tr, &ref_ba(), &ref_bg())
            })
            .collect();
        let r =
            |f: &dyn Fn(&(Vec3, Vec3, Vec3)) -> f64| rms(&errs.iter().map(f).collect::<Vec<_>>());
        let (bax, bay, baz) = (r(&|e| e.0.x), r(&|e| e.0.y), r(&|e| e.0.z));
        let (bgx, bgy, bgz) = (r(&|e| e.1.x), r(&|e| e.1.y), r(&|e| e.1.z));
        let (pn, pe, pd) = (r(&|e| e.2.x), r(&|e| e.2.y), r(&|e| e.2.z));
        println!(
            "T7 {h:?} (50 runs RMS): b_a {bax:.2}/{bay:.2}/{baz:.2} μg, b_g {bgx:.4}/{bgy:.4}/{bgz:.4} °/h, φ {pn:.1}/{pe:.1}/{pd:.0} μrad"
        );
        if h.len() == 1 {
            assert!(pn.max(pe) >= 25.0 && pd >= 800.0);
        } else {
            assert!(bax.max(bay) <= 5.0);
            assert!(bgx.max(bgy) <= 0.006);
            assert!(pn.max(pe) <= 8.0);
            assert!(pd <= 500.0);
        }
    }
}

// ---------------------------------------------------------------- real data

/// PSINS `lasergyro.imu` (navigation-grade RLG, parked, 100 Hz, ≈1847 s, 34.25°N):
/// coarse 2-step and fine alignment over consecutive 300 s windows give roll/pitch
/// consistent to 0.05° once the vehicle's own measured motion between windows is carried
/// along (measured ≤ 0.0025°), and a heading near +90° NED (PSINS header: −90.6°
/// counter-clockwise). The 1-step coarse values are reported.
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn lasergyro_real_data_alignment() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/psins");
    let path = std::path::Path::new(dir).join("lasergyro.imu");
    if !std::path::Path::new(dir).exists() {
        println!("skipped: {dir} is absent");
        return;
    }
    let data =
        sdins_sim::io::imu_file::read_imu_file(&path, sdins_sim::io::imu_file::ImuFormat::Psins)
            .unwrap();
    let hdr = data.psins.clone().unwrap();
    let site = Site::from_earth(&EarthModel::PSINS, hdr.lat_deg * D2R, hdr.h_m);
    let dt = data.dt_s;
    let win = (300.0 / dt).round() as usize;
    let nwin = data.increments.len() / win;
    assert!(nwin >= 6, "{nwin} windows");
    let mut rows: Vec<[Euler; 3]> = Vec::new();
    let mut mats: Vec<[Mat3; 3]> = Vec::new();
    for k in 0..nwin {
        let w = &data.increments[k * win..(k + 1) * win];
        let c2 = coarse_window(w, dt, 0, win, &site, CoarseMethod::TwoStep).unwrap();
        let c1 = coarse_window(w, dt, 0, win, &site, CoarseMethod::OneStep).unwrap();
        let c0 = coarse_window(w, dt, 0, 6000, &site, CoarseMethod::TwoStep).unwrap();
        let mut cfg = reference_config(site, 20.0 * UG, 0.002 * DPSH);
        cfg.sigma_z_mps = 0.01; // parked vehicle: sway (docs/theory/alignment.md §"Fine alignment")
        let fa = run_fine(w, dt, cfg, &c0, |_, _| {}, &CancelToken::new()).unwrap();
        let e = [
            sdins_core::math::euler_from_c_b_n(&c2),
            sdins_core::math::euler_from_c_b_n(&c1),
            sdins_core::math::euler_from_c_b_n(&fa.c_b_n()),
        ];
        println!(
            "window {k} ({}–{} s): coarse2 r/p/y {:.4}/{:.4}/{:.3}°, coarse1 {:.4}/{:.4}/{:.3}°, fine {:.4}/{:.4}/{:.3}°",
            k * 300,
            (k + 1) * 300,
            e[0].roll_rad / D2R, e[0].pitch_rad / D2R, e[0].yaw_rad / D2R,
            e[1].roll_rad / D2R, e[1].pitch_rad / D2R, e[1].yaw_rad / D2R,
            e[2].roll_rad / D2R, e[2].pitch_rad / D2R, e[2].yaw_rad / D2R,
        );
        rows.push(e);
        mats.push([c2, c1, fa.c_b_n()]);
    }
    // Spread over the windows (reported): the record itself tilts (pitch 0.84° → 0.99°,
    // roll 0.29° → 0.42° over 30 min in the raw specific force, with rotations the
    // gyros see), so raw whole-record spreads measure the vehicle, not the alignment.
    for (m, name) in ["coarse2", "coarse1", "fine"].iter().enumerate() {
        let spread = |f: &dyn Fn(&Euler) -> f64| {
            let v: Vec<f64> = rows.iter().map(|r| f(&r[m]) / D2R).collect();
            v.iter().copied().fold(f64::MIN, f64::max) - v.iter().copied().fold(f64::MAX, f64::min)
        };
        let (sr, sp, sy) = (
            spread(&|e| e.roll_rad),
            spread(&|e| e.pitch_rad),
            spread(&|e| e.yaw_rad),
        );
        println!("{name}: raw spread over windows roll {sr:.4}°, pitch {sp:.4}°, yaw {sy:.4}°");
    }
    // Consistency (asserted, 0.05°): window k−1's estimate carried to window k with the
    // measured motion, against window k's own estimate. Parked, the n frame turns only
    // with the earth: C(t) = E(t − t0) C0 B(t), E(τ) = exp(−[ω_ie^n×]τ), B(t) = Π exp([Δθ_j×])
    // (gyro track from t0). This is exact up to the gyro errors (an RLG bias of 0.01 °/h
    // moves the carried attitude by 1e-3° in 300 s) and independent of the estimate's
    // heading error. Fine alignment estimates C at the window end:
    //   C_k = E(300 s) C_{k−1} B(t_{k−1})ᵀ B(t_k).
    // Coarse alignment levels on the window mean, i.e. estimates the mean attitude, so
    //   C_k = E(300 s) C_{k−1} M_{k−1}⁻¹ M_k,  M_k = mean of B over window k,
    // (E varies by ±0.6° within a window and the tilt by < 0.1°: the neglected
    // cross terms are < 0.005°). The body's inertial rotation B contains the earth's
    // 1.04° turn about north per 300 s; it cancels against E only in the true heading,
    // so a heading error δψ leaks 1.04°·sin δψ into the carried tilt (about east, i.e.
    // roll for this east-facing vehicle; 0.15° for a coarse 8° heading error). The carry
    // therefore uses the estimate's roll/pitch with the mean fine heading of all windows
    // (window spread 1.5°, so its error is a fraction of that: < 0.03° leak).
    let mut track = Vec::with_capacity(data.increments.len() + 1);
    let mut b = Mat3::identity();
    track.push(b);
    for s in &data.increments {
        b *= dcm_from_rotvec(&s.dtheta_b_rad);
        track.push(b);
    }
    let earth_turn = dcm_from_rotvec(&(-site.omega_ie_n() * (win as f64 * dt)));
    let window_mean = |k: usize| -> Mat3 {
        let sum: Mat3 = track[k * win + 1..=(k + 1) * win].iter().sum();
        sdins_core::math::orthonormalize(&(sum / win as f64))
    };
    let yaw_ref = rows.iter().map(|r| r[2].yaw_rad).sum::<f64>() / nwin as f64;
    println!("reference heading (mean fine) {:.3}° NED", yaw_ref / D2R);
    let with_ref_heading = |c: &Mat3| {
        let e = sdins_core::math::euler_from_c_b_n(c);
        sdins_core::math::c_b_n_from_euler(&Euler::new(e.roll_rad, e.pitch_rad, yaw_ref))
    };
    let mut worst = [[0.0_f64; 2]; 3];
    for k in 1..nwin {
        for (m, name) in ["coarse2", "coarse1", "fine"].iter().enumerate() {
            let (r0, r1) = if m == 2 {
                (track[k * win], track[(k + 1) * win])
            } else {
                (window_mean(k - 1), window_mean(k))
            };
            let carried = earth_turn * with_ref_heading(&mats[k - 1][m]) * r0.transpose() * r1;
            let pred = sdins_core::math::euler_from_c_b_n(&carried);
            let got = &rows[k][m];
            let (dr, dp) = (
                (got.roll_rad - pred.roll_rad) / D2R,
                (got.pitch_rad - pred.pitch_rad) / D2R,
            );
            println!("window {k} {name}: estimate − carried estimate of window {}: roll {dr:+.4}°, pitch {dp:+.4}°", k - 1);
            worst[m][0] = worst[m][0].max(dr.abs());
            worst[m][1] = worst[m][1].max(dp.abs());
        }
    }
    for (m, name) in ["coarse2", "coarse1", "fine"].iter().enumerate() {
        println!(
            "{name}: motion-compensated consistency max |Δroll| {:.4}°, |Δpitch| {:.4}°",
            worst[m][0], worst[m][1]
        );
        // The 1-step method orthonormalises [f, ω, f×ω] together, so the window-mean gyro
        // error of a disturbed parked vehicle (net settling rotations of ~0.1° per window
        // are ~1 °/h, a few degrees of direction on the 15 °/h earth rate) leaks into its
        // tilt: measured up to 0.19° in roll. Levelling on f alone (2-step) and the
        // filter do not have that path; they are the methods held to 0.05°.
        if *name != "coarse1" {
            assert!(
                worst[m][0] <= 0.05 && worst[m][1] <= 0.05,
                "{name}: {:?}",
                worst[m]
            );
        }
    }
    for (k, r) in rows.iter().enumerate() {
        assert!(
            (r[0].roll_rad - r[2].roll_rad).abs() / D2R <= 0.1,
            "window {k} roll"
        );
        assert!(
            (r[0].pitch_rad - r[2].pitch_rad).abs() / D2R <= 0.1,
            "window {k} pitch"
        );
        assert!(
            (r[2].yaw_rad / D2R - 90.0).abs() < 2.0,
            "window {k} fine yaw"
        );
        assert!(
            (r[0].yaw_rad / D2R - 90.0).abs() < 8.0,
            "window {k} coarse yaw"
        );
        if k > 0 {
            {
                let m = 0;
                let p = &rows[k - 1][m];
                assert!(
                    (r[m].roll_rad - p.roll_rad).abs() / D2R <= 0.1,
                    "window {k} roll step"
                );
                assert!(
                    (r[m].pitch_rad - p.pitch_rad).abs() / D2R <= 0.1,
                    "window {k} pitch step"
                );
            }
        }
    }
}
