//! The stationarity detector on real data: PSINS `lasergyro.imu` (navigation-grade RLG IMU,
//! parked vehicle with disturbances, 1847 s at 100 Hz, 34.25° N), read in place
//! (docs/theory/aiding-sensors.md §"Stationarity detection", real data).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use sdins_core::aiding::stationarity::chi2::chi2_quantile;
use sdins_core::aiding::stationarity::{
    IntervalTracker, NoiseModel, StationarityDetector, WindowReport,
};
use sdins_core::coning::Increment;
use sdins_core::earth::EarthModel;
use sdins_core::math::{c_b_n_from_euler, Euler, Mat3, Vec3};

const D2R: f64 = std::f64::consts::PI / 180.0;
const DPH: f64 = D2R / 3600.0;
const UG: f64 = 9.80665e-6;
const ALPHA: f64 = 1e-3;

/// `../shared/data/psins/lasergyro.imu` beside the project, read in place; a checkout
/// elsewhere (a git worktree) may name the data folder in `SDINS_SHARED_DATA`. Absent: a
/// visible skip.
fn lasergyro_path() -> Option<std::path::PathBuf> {
    let beside = std::path::PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/psins/lasergyro.imu"
    ));
    let from_env = std::env::var_os("SDINS_SHARED_DATA")
        .map(|d| std::path::PathBuf::from(d).join("psins/lasergyro.imu"));
    let found = std::iter::once(beside.clone())
        .chain(from_env)
        .find(|p| p.exists());
    if found.is_none() {
        println!(
            "skipped: {} is absent (../shared/data is not in this checkout)",
            beside.display()
        );
    }
    found
}

/// The reports of the disjoint windows (every W-th), with or without the earth rate.
fn disjoint_reports<const W: usize>(
    incs: &[Increment],
    noise: NoiseModel,
    dt: f64,
    g: f64,
    earth_rate: Option<(&Mat3, Vec3)>,
) -> (Vec<WindowReport>, Vec<WindowReport>, f64) {
    let mut det = StationarityDetector::<W>::from_noise_model(noise, dt, g, ALPHA).unwrap();
    if let Some((c_b_n, w_n)) = earth_rate {
        det.set_attitude(c_b_n, &w_n).unwrap();
    }
    let all: Vec<WindowReport> = incs.iter().filter_map(|s| det.push(s).unwrap()).collect();
    let disjoint = all
        .iter()
        .filter(|r| r.last_sample % W as u64 == W as u64 - 1)
        .copied()
        .collect();
    (all, disjoint, det.threshold())
}

/// Noise model: the per-sample σ's are the Allan deviations at τ = δt (largest axis), which
/// for white noise equal the per-sample σ and for the pulse quantization and dither of this
/// RLG IMU exceed it (quantization: ADEV(δt)² = 1.5 σ²), so the threshold is conservative;
/// residual biases of a navigation-grade unit: 0.01 °/h, and 150 μg (50 μg bias, 50 ppm
/// scale factor on g, ~100 μGal-level gravity-model error). α = 1e-3 per window.
///
/// Asserted: (1) most one-second windows of the parked record are accepted (≥ 50 %);
/// (2) the windows declared moving are body motion, not noise: all but the false alarms
/// that α explains (Poisson 99 % bound on α·N) show rotation below 5 Hz (the scatter of
/// ten 0.1 s means of the rate) beyond the 1e-3 quantile of its own rest law χ²(27);
/// (3) the earth-rate term is what the theory says: over 10 s windows accepted with and
/// without it, the gyro-mean part rises by `W Ω²/σ_g²` (within 3 standard errors).
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn lasergyro_parked_windows_are_accepted() {
    let Some(path) = lasergyro_path() else {
        return;
    };
    let data =
        sdins_sim::io::imu_file::read_imu_file(&path, sdins_sim::io::imu_file::ImuFormat::Psins)
            .unwrap();
    let hdr = data.psins.clone().unwrap();
    let dt = data.dt_s;
    let incs = &data.increments;
    let earth = EarthModel::PSINS;
    let lat = hdr.lat_deg * D2R;
    let g = earth.gravity(lat, hdr.h_m);
    let allan = sdins_sim::analysis::allan::analyse(incs, dt);
    let adev0: Vec<f64> = allan.curves.iter().map(|c| c.adev[0]).collect();
    assert!((allan.curves[0].tau_s[0] - dt).abs() < 1e-12);
    let sigma_g = adev0[..3].iter().copied().fold(0.0, f64::max);
    let sigma_a = adev0[3..].iter().copied().fold(0.0, f64::max);
    println!(
        "ADEV(δt = {dt} s): gyro {:.3e} {:.3e} {:.3e} rad/s, accel {:.4} {:.4} {:.4} m/s² (FRD); σ_g = {sigma_g:.3e} rad/s, σ_a = {sigma_a:.4} m/s²",
        adev0[0], adev0[1], adev0[2], adev0[3], adev0[4], adev0[5]
    );
    let noise = NoiseModel {
        sigma_accel_mps2: sigma_a,
        sigma_gyro_rps: sigma_g,
        sigma_accel_bias_mps2: 150.0 * UG,
        sigma_gyro_bias_rps: 0.01 * DPH,
    };
    // attitude for the earth rate: roll and pitch from the mean specific force, heading
    // from the header (PSINS yaw is counter-clockwise from north: NED yaw = −yaw_psins)
    let fm: Vec3 = incs.iter().map(|i| i.dv_b_mps).sum::<Vec3>() / (incs.len() as f64 * dt);
    let roll = (-fm.y).atan2(-fm.z);
    let pitch = (fm.x / fm.norm()).asin();
    let yaw = -hdr.att0_deg[2] * D2R;
    let c_b_n = c_b_n_from_euler(&Euler::new(roll, pitch, yaw));
    let w_n = earth.omega_ie_n(lat);
    println!(
        "g = {g:.5} m/s² (PSINS model at {:.4}° N, {} m), |f̄| = {:.5}; roll {:.3}°, pitch {:.3}°, yaw {:.1}° NED",
        hdr.lat_deg,
        hdr.h_m,
        fm.norm(),
        roll / D2R,
        pitch / D2R,
        yaw / D2R
    );

    // ---- one-second windows
    const W: usize = 100;
    let (all, disjoint, gamma) = disjoint_reports::<W>(incs, noise, dt, g, Some((&c_b_n, w_n)));
    let n = disjoint.len();
    let n_stat = disjoint.iter().filter(|r| r.stationary).count();
    let frac = n_stat as f64 / n as f64;
    println!(
        "W = {W} (1 s), α = {ALPHA}: γ = {gamma:.4}; {n_stat}/{n} disjoint windows stationary ({:.1} %)",
        100.0 * frac
    );
    let mean_part = |f: &dyn Fn(&WindowReport) -> f64, stat: bool| {
        let v: Vec<f64> = disjoint
            .iter()
            .filter(|r| r.stationary == stat)
            .map(f)
            .collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    };
    for stat in [true, false] {
        println!(
            "{} windows, mean parts of W·T: accel scatter {:.1}, accel magnitude {:.3}, gyro scatter {:.1}, gyro mean {:.2} (white model at rest: {}, 1, {}, 3)",
            if stat { "stationary" } else { "moving" },
            mean_part(&|r| r.accel_scatter, stat),
            mean_part(&|r| r.accel_magnitude, stat),
            mean_part(&|r| r.gyro_scatter, stat),
            mean_part(&|r| r.gyro_mean, stat),
            3 * (W - 1),
            3 * (W - 1)
        );
    }
    // each sensor triad against its own 1e-3 quantile (χ²(3W − 2), χ²(3W))
    let qa = chi2_quantile(1.0 - ALPHA, 3.0 * W as f64 - 2.0).unwrap();
    let qg = chi2_quantile(1.0 - ALPHA, 3.0 * W as f64).unwrap();
    let acc = disjoint
        .iter()
        .filter(|r| r.accel_scatter + r.accel_magnitude > qa)
        .count();
    let gyr = disjoint
        .iter()
        .filter(|r| r.gyro_scatter + r.gyro_mean > qg)
        .count();
    println!("accelerometer part alone beyond its 1e-3 quantile in {acc} windows, gyro part alone in {gyr}");
    // low-frequency rotation: scatter of the ten 0.1 s block means of the rate, in units of
    // the white-model variance σ_g²/10 of a block mean: χ²(27) at rest
    let ql = chi2_quantile(1.0 - 1e-3, 27.0).unwrap();
    let lf = |r: &WindowReport| {
        let k0 = r.first_sample as usize;
        let blocks: Vec<Vec3> = (0..10)
            .map(|b| {
                incs[k0 + 10 * b..k0 + 10 * (b + 1)]
                    .iter()
                    .map(|i| i.dtheta_b_rad)
                    .sum::<Vec3>()
                    / (10.0 * dt)
            })
            .collect();
        let bm = blocks.iter().sum::<Vec3>() / 10.0;
        blocks.iter().map(|b| (b - bm).norm_squared()).sum::<f64>() / (sigma_g * sigma_g / 10.0)
    };
    let moving: Vec<&WindowReport> = disjoint.iter().filter(|r| !r.stationary).collect();
    let moving_lf = moving.iter().filter(|r| lf(r) > ql).count();
    let stat_lf = disjoint
        .iter()
        .filter(|r| r.stationary && lf(r) > ql)
        .count();
    println!(
        "rotation below 5 Hz beyond its 1e-3 quantile: {moving_lf}/{} moving windows, {stat_lf}/{n_stat} stationary windows",
        moving.len()
    );
    // stationary intervals (sliding windows, at least 1 s) and the moving gaps between them
    let mut tracker = IntervalTracker::new(W, W as u64);
    let mut intervals = Vec::new();
    for r in &all {
        intervals.extend(tracker.push(r));
    }
    intervals.extend(tracker.finish());
    let mut gaps = Vec::new();
    let mut next = 0u64;
    for iv in &intervals {
        if iv.first_sample > next {
            gaps.push((next, iv.first_sample - 1));
        }
        next = iv.last_sample + 1;
    }
    if next < incs.len() as u64 {
        gaps.push((next, incs.len() as u64 - 1));
    }
    let moving_s: f64 = gaps.iter().map(|(a, b)| (b - a + 1) as f64 * dt).sum();
    println!(
        "{} stationary intervals ≥ 1 s; not stationary: {moving_s:.1} s of {:.1} s in {} gaps:",
        intervals.len(),
        incs.len() as f64 * dt,
        gaps.len()
    );
    let list: Vec<String> = gaps
        .iter()
        .map(|(a, b)| format!("{:.2}–{:.2}", *a as f64 * dt, *b as f64 * dt))
        .collect();
    println!("{}", list.join(", "));

    // ---- ten-second windows with and without the earth rate
    const W2: usize = 1000;
    let (_, with, gamma2) = disjoint_reports::<W2>(incs, noise, dt, g, Some((&c_b_n, w_n)));
    let (_, without, _) = disjoint_reports::<W2>(incs, noise, dt, g, None);
    let diffs: Vec<f64> = with
        .iter()
        .zip(&without)
        .filter(|(a, b)| a.stationary && b.stationary)
        .map(|(a, b)| b.gyro_mean - a.gyro_mean)
        .collect();
    let m = diffs.len() as f64;
    let mean = diffs.iter().sum::<f64>() / m;
    let se = (diffs.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (m - 1.0) / m).sqrt();
    let omega = earth.omega_ie_rps;
    let predicted = W2 as f64 * omega * omega / (sigma_g * sigma_g);
    let (k_with, k_without) = (
        with.iter().filter(|r| r.stationary).count(),
        without.iter().filter(|r| r.stationary).count(),
    );
    println!(
        "W = {W2} (10 s): γ = {gamma2:.4}; stationary {k_with}/{} with the earth rate, {k_without}/{} without; gyro-mean part rises by {mean:.2} ± {se:.2} (SE) over {} windows accepted by both, predicted W Ω²/σ_g² = {predicted:.2} of W·γ = {:.0}",
        with.len(),
        without.len(),
        diffs.len(),
        gamma2 * W2 as f64
    );

    assert!(frac >= 0.5, "{frac}");
    // false alarms at rest: Poisson with mean α·N; its 99 % upper bound
    let expected_fa = ALPHA * n as f64;
    let fa_bound = expected_fa + 2.576 * expected_fa.sqrt() + 2.0;
    let unexplained = moving.len() - moving_lf;
    println!("moving windows without low-frequency rotation: {unexplained} (false alarms expected {expected_fa:.1}, bound {fa_bound:.1})");
    assert!((unexplained as f64) <= fa_bound);
    assert!(diffs.len() >= 50, "{}", diffs.len());
    assert!(
        (mean - predicted).abs() <= 3.0 * se,
        "{mean} vs {predicted} ± 3·{se}"
    );
}
