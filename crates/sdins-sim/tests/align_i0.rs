//! Inertial-frame (i0) coarse alignment: real data (PSINS `lasergyro.imu`), exact
//! simulated truth on a swaying/heaving base, and the Monte Carlo against the closed-form
//! floor and ARW/VRW spread (docs/alignment_i0.md).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use sdins_core::align::coarse::CoarseMethod;
use sdins_core::align::Site;
use sdins_core::earth::EarthModel;
use sdins_core::math::euler_from_c_b_n;
use sdins_sim::align::experiment::{coarse_window, i0_window};
use sdins_sim::cancel::CancelToken;

const D2R: f64 = std::f64::consts::PI / 180.0;

fn lasergyro() -> Option<(sdins_sim::io::imu_file::ImuData, Site)> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/psins");
    if !std::path::Path::new(dir).exists() {
        println!("skipped: {dir} is absent");
        return None;
    }
    let path = std::path::Path::new(dir).join("lasergyro.imu");
    let data =
        sdins_sim::io::imu_file::read_imu_file(&path, sdins_sim::io::imu_file::ImuFormat::Psins)
            .unwrap();
    let hdr = data.psins.clone().unwrap();
    let site = Site::from_earth(&EarthModel::PSINS, hdr.lat_deg * D2R, hdr.h_m);
    Some((data, site))
}

/// Issue acceptance: the i0 heading over each successive 300 s window of the lasergyro
/// record spreads by at most 0.1° (max − min); the 2-step heading is printed beside it.
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn lasergyro_i0_heading_over_300s_windows() {
    let Some((data, site)) = lasergyro() else {
        return;
    };
    let dt = data.dt_s;
    let win = (300.0 / dt).round() as usize;
    let nwin = data.increments.len() / win;
    assert!(nwin >= 6, "{nwin} windows");
    let mut yaw = Vec::new();
    for k in 0..nwin {
        let c = i0_window(&data.increments, dt, k * win, win, &site).unwrap();
        let c2 = coarse_window(
            &data.increments,
            dt,
            k * win,
            win,
            &site,
            CoarseMethod::TwoStep,
        )
        .unwrap();
        let e = euler_from_c_b_n(&c);
        let e2 = euler_from_c_b_n(&c2);
        println!(
            "window {k}: i0 r/p/y {:.4}/{:.4}/{:.4}°, 2-step yaw {:.3}°",
            e.roll_rad / D2R,
            e.pitch_rad / D2R,
            e.yaw_rad / D2R,
            e2.yaw_rad / D2R
        );
        yaw.push(e.yaw_rad / D2R);
    }
    let spread =
        yaw.iter().cloned().fold(f64::MIN, f64::max) - yaw.iter().cloned().fold(f64::MAX, f64::min);
    println!("i0 heading spread over {nwin} windows: {spread:.4}°");
    assert!(spread <= 0.1, "spread {spread}°");
}

/// One disturbed-base Monte Carlo (docs/alignment_i0.md §5): exact truth of `scenario`,
/// `runs` error-model draws of `grade` (values from `imu_error::presets` at run time),
/// window `window_s`. Returns per run (i0 heading error − its floor, 2-step heading error)
/// \[rad\] and the closed-form σ of the first.
fn disturbed_mc(scenario: &str, grade: &str, window_s: f64, runs: u64) -> (Vec<(f64, f64)>, f64) {
    use rayon::prelude::*;
    use sdins_core::align::i0::{heading_floor_rad, heading_sigma_rad};
    use sdins_core::math::{attitude_error, Mat3};
    use sdins_sim::align::experiment::{corrupt, truth_record};
    use sdins_sim::sensors::imu_error::{presets, ImuErrorState, DPSH, UG};
    let scn = sdins_sim::scenario::Scenario::load(scenario).unwrap();
    let dt = scn.imu.dt_s();
    let n = (window_s / dt).round() as usize;
    let tr = truth_record(
        &scn.trajectory,
        scn.nav.earth.model(),
        dt,
        scn.start.lat_rad,
        scn.start.lon_rad,
        scn.start.h_m,
    );
    assert!(tr.increments.len() >= n);
    let model = presets::preset(grade).unwrap();
    let site = tr.site;
    // mean attitude over the window: the NED biases the fit sees (sway averages out)
    let mut c_mean = Mat3::zeros();
    for c in &tr.c_b_n[..n] {
        c_mean += c / n as f64;
    }
    let c_end = tr.c_b_n[n - 1];
    let out: Vec<(f64, f64)> = (0..runs)
        .into_par_iter()
        .map(|run| {
            let incs = corrupt(&tr.increments[..n], dt, &model, 11, run).unwrap();
            let (bg, ba) = ImuErrorState::new(&model, 11, run).unwrap().constant_bias();
            let floor = heading_floor_rad(&site, &(c_mean * bg), &(c_mean * ba), window_s);
            let c = i0_window(&incs, dt, 0, n, &site).unwrap();
            let c2 = coarse_window(&incs, dt, 0, n, &site, CoarseMethod::TwoStep).unwrap();
            (
                attitude_error(&c, &c_end).z - floor,
                attitude_error(&c2, &tr.c_b_n[0]).z,
            )
        })
        .collect();
    let arw = model.gyro_arw_dpsh[0] * DPSH;
    let vrw = model.accel_vrw_ugpsqrthz[0] * UG;
    (out, heading_sigma_rad(&site, window_s, arw, vrw))
}

fn mc_check(scenario: &str, grade: &str) {
    let runs = 200;
    let (res, sigma) = disturbed_mc(scenario, grade, 300.0, runs);
    let nf = runs as f64;
    let mean = res.iter().map(|r| r.0).sum::<f64>() / nf;
    let sd = (res.iter().map(|r| (r.0 - mean).powi(2)).sum::<f64>() / (nf - 1.0)).sqrt();
    let se = sd / nf.sqrt();
    let two_abs = res.iter().map(|r| r.1.abs()).sum::<f64>() / nf;
    println!(
        "{scenario} ({grade}, 300 s, {runs} runs): i0 heading error − floor: mean {:.5}° (±3 SE = {:.5}°), sd {:.5}° vs closed form {:.5}° (ratio {:.3}); 2-step mean |heading error| {:.3}°",
        mean.to_degrees(),
        3.0 * se.to_degrees(),
        sd.to_degrees(),
        sigma.to_degrees(),
        sd / sigma,
        two_abs.to_degrees()
    );
    assert!(mean.abs() <= 3.0 * se, "mean {mean} vs 3 SE {}", 3.0 * se);
    // sample sd of N = 200 normal draws: s²/σ² ~ χ²(199)/199, two-sided 99 %:
    // χ²₀.₀₀₅(199) = 151.35, χ²₀.₉₉₅(199) = 254.15 (Wilson–Hilferty) → s/σ ∈ [0.872, 1.130]
    let r = sd / sigma;
    assert!((0.872..=1.130).contains(&r), "sd/σ = {r}");
    // the 2-step method fails on the same data: its heading is off by more than 1° on
    // average (the sway's mean rate swamps the earth rate)
    assert!(
        two_abs.to_degrees() > 1.0,
        "2-step {}",
        two_abs.to_degrees()
    );
}

/// Issue acceptance, moored ship (roll/pitch ±5°, heave, surge), aviation grade.
#[test]
#[ignore = "Monte Carlo: run in release with --ignored"]
fn i0_moored_ship_monte_carlo() {
    mc_check("moored-ship", "aviation");
}

/// Issue acceptance, rocking car, aviation grade.
#[test]
#[ignore = "Monte Carlo: run in release with --ignored"]
fn i0_rocking_car_monte_carlo() {
    mc_check("rocking-car", "aviation");
}

/// Error-free sensors on the exact truth of the disturbed-base built-ins: what is left is
/// the leakage of the sway/heave/surge into the fit (docs/alignment_i0.md §4). The
/// tapered kernel bounds the heading leakage of a horizontal velocity oscillation of
/// amplitude V at ω by `2 (|h'(0)| + |h'(1)|) V / ((ωT)² T² g Ω cos L)`,
/// `|h'(0)| + |h'(1)| = 300`; for the ship (surge 0.089 m/s plus heave 0.29 m/s × sin 5°
/// horizontal, slowest ω = 2π·0.071) that is 68 μrad. Both scenarios must also stay below
/// a tenth of the aviation-grade noise σ (≥ 745.8 μrad = 0.0427°), so that the deterministic part
/// moves the Monte Carlo mean by at most 0.1σ (1.4 standard errors at 200 runs).
#[test]
fn i0_error_free_disturbed_base() {
    use sdins_core::math::attitude_error;
    use sdins_sim::align::experiment::truth_record;
    for (name, window_s) in [("moored-ship", 300.0), ("rocking-car", 300.0)] {
        let scn = sdins_sim::scenario::Scenario::load(name).unwrap();
        let dt = scn.imu.dt_s();
        let n = (window_s / dt).round() as usize;
        let tr = truth_record(
            &scn.trajectory,
            scn.nav.earth.model(),
            dt,
            scn.start.lat_rad,
            scn.start.lon_rad,
            scn.start.h_m,
        );
        let c = i0_window(&tr.increments, dt, 0, n, &tr.site).unwrap();
        let phi = attitude_error(&c, &tr.c_b_n[n - 1]);
        println!(
            "{name}: error-free i0 φ = {:.3?} μrad",
            (phi * 1e6).as_slice()
        );
        let leak = if name == "moored-ship" {
            let s = tr.site;
            let (w, t) = (2.0 * std::f64::consts::PI * 0.071, window_s);
            let v = 0.039802 / w
                + 0.17073 / (2.0 * std::f64::consts::PI * 0.093) * 5f64.to_radians().sin();
            2.0 * 300.0 * v / ((w * t).powi(2) * t * t * s.g_mps2 * s.omega_n())
        } else {
            f64::INFINITY
        };
        assert!(phi.z.abs() <= leak, "{name}: {} > {leak}", phi.z);
        assert!(phi.z.abs() <= 0.1 * 745.8e-6, "{name}: {}", phi.z);
        // tilt: vertical heave averages out; 1 μrad (the noise σ of the tilt is ~5 μrad)
        assert!(phi.x.abs().max(phi.y.abs()) <= 1e-6, "{name}: {phi:?}");
    }
}

/// Issue part 2 on lasergyro: the fine filter started from i0 (start windows 10–300 s)
/// lands within 0.1° of the whole-record i0 heading and varies by at most 0.05° with the
/// start window; its heading σ is printed beside the 300 s window-to-window i0 spread.
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn lasergyro_fine_from_i0_is_start_independent() {
    use sdins_core::align::fine::reference_config;
    use sdins_sim::align::experiment::fine_from_i0;
    use sdins_sim::sensors::imu_error::{DPSH, UG};
    let Some((data, site)) = lasergyro() else {
        return;
    };
    let dt = data.dt_s;
    let all = data.increments.len();
    let c_all = i0_window(&data.increments, dt, 0, all, &site).unwrap();
    let yaw_i0 = euler_from_c_b_n(&c_all).yaw_rad / D2R;
    let mut yaws = Vec::new();
    for w in [10.0, 30.0, 60.0, 120.0, 300.0] {
        let cfg = reference_config(site, 20.0 * UG, 0.002 * DPSH);
        let n = (w / dt).round() as usize;
        let (fa, c0, sz) =
            fine_from_i0(&data.increments, dt, cfg, n, |_, _| {}, &CancelToken::new()).unwrap();
        let y = euler_from_c_b_n(&fa.c_b_n()).yaw_rad / D2R;
        println!(
            "start window {w} s: i0 start yaw {:.3}°, σ_z {:.4} m/s → fine yaw {y:.4}° (1σ {:.4}°), ε_E est {:.4} °/h",
            euler_from_c_b_n(&c0).yaw_rad / D2R,
            sz,
            fa.attitude_sigma().z / D2R,
            (fa.c_b_n() * fa.gyro_bias_b()).y / (D2R / 3600.0)
        );
        yaws.push(y);
    }
    let spread = yaws.iter().cloned().fold(f64::MIN, f64::max)
        - yaws.iter().cloned().fold(f64::MAX, f64::min);
    println!("whole-record i0 yaw {yaw_i0:.4}°; fine spread over start windows {spread:.4}°");
    assert!(spread <= 0.05, "{spread}");
    for y in &yaws {
        assert!((y - yaw_i0).abs() <= 0.1, "{y} vs {yaw_i0}");
    }
}

/// Issue part 2 in simulation: the fine filter started from i0 on the moored ship
/// (aviation grade, i0 window 300 s, filter over 600 s, σ_z from the i0 residual, bias
/// priors from the grade preset) is consistent: the mean attitude NEES over 200 runs lies
/// in the two-sided 99 % band of χ²(600)/200 = \[2.57, 3.46\] (Wilson–Hilferty).
#[test]
#[ignore = "Monte Carlo: run in release with --ignored"]
fn fine_from_i0_moored_ship_nees() {
    use nalgebra::SMatrix;
    use rayon::prelude::*;
    use sdins_core::align::fine::reference_config;
    use sdins_core::math::attitude_error;
    use sdins_sim::align::experiment::{corrupt, fine_from_i0, truth_record};
    use sdins_sim::sensors::imu_error::{presets, DPH, DPSH, UG};
    let scn = sdins_sim::scenario::Scenario::load("moored-ship").unwrap();
    let dt = scn.imu.dt_s();
    let n_all = (600.0 / dt).round() as usize;
    let nw = (300.0 / dt).round() as usize;
    let tr = truth_record(
        &scn.trajectory,
        scn.nav.earth.model(),
        dt,
        scn.start.lat_rad,
        scn.start.lon_rad,
        scn.start.h_m,
    );
    let model = presets::preset("aviation").unwrap();
    let (arw, vrw) = (
        model.gyro_arw_dpsh[0] * DPSH,
        model.accel_vrw_ugpsqrthz[0] * UG,
    );
    let mut cfg = reference_config(tr.site, vrw, arw);
    for i in 0..3 {
        cfg.p0[(6 + i, 6 + i)] = (model.accel_bias_turn_on_ug[i] * UG).powi(2);
        cfg.p0[(9 + i, 9 + i)] = (model.gyro_bias_turn_on_dph[i] * DPH).powi(2);
    }
    let c_end = tr.c_b_n[n_all - 1];
    let runs = 200u64;
    let res: Vec<(f64, f64, f64, f64)> = (0..runs)
        .into_par_iter()
        .map(|run| {
            let incs = corrupt(&tr.increments[..n_all], dt, &model, 23, run).unwrap();
            let (fa, _, sz) =
                fine_from_i0(&incs, dt, cfg, nw, |_, _| {}, &CancelToken::new()).unwrap();
            let phi = attitude_error(&fa.c_b_n(), &c_end);
            let p: SMatrix<f64, 3, 3> = fa.kf().p.fixed_view::<3, 3>(3, 3).into_owned();
            let nees = (phi.transpose() * p.try_inverse().unwrap() * phi)[(0, 0)];
            (nees, phi.z, p[(2, 2)].sqrt(), sz)
        })
        .collect();
    let nf = runs as f64;
    let nees = res.iter().map(|r| r.0).sum::<f64>() / nf;
    let rms_psi = (res.iter().map(|r| r.1 * r.1).sum::<f64>() / nf).sqrt();
    let sig_psi = res.iter().map(|r| r.2).sum::<f64>() / nf;
    let sz = res.iter().map(|r| r.3).sum::<f64>() / nf;
    println!(
        "moored ship, fine from i0 ({runs} runs): mean attitude NEES {nees:.3} (band [2.57, 3.46]); heading RMS error {:.4}° vs mean filter σ {:.4}°; mean σ_z {sz:.3} m/s",
        rms_psi.to_degrees(),
        sig_psi.to_degrees()
    );
    assert!((2.57..=3.46).contains(&nees), "NEES {nees}");
}
