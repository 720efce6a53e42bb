//! INS/GNSS filter on simulated scenarios: quick default tests and the acceptance Monte
//! Carlo (`#[ignore]`, release: `cargo test --release -p sdins-sim --test fuse -- --ignored`).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use sdins_core::aiding::ekf::MeasKind;
use sdins_core::aiding::error_model::{I_ATT, I_BA, I_POS, I_VEL};
use sdins_core::nav::{AlgorithmKind, AlgorithmSpec};
use sdins_sim::cancel::CancelToken;
use sdins_sim::fusion::simulated::{fuse_scenario, FuseEvent, FuseOptions};
use sdins_sim::scenario::Scenario;
use sdins_sim::sensors::gnss::GnssConfig;

/// A maneuvering car-like scenario: accelerate, turns both ways, decelerate, cruise.
fn maneuver_toml(grade: &str, rate_hz: f64, minutes: u32) -> String {
    let mut segs = String::new();
    let block = [
        ("accelerate", "accel_mps2 = 1.0", 10.0),
        ("turn", "rate_dps = 9.0", 10.0),
        ("cruise", "", 10.0),
        ("accelerate", "accel_mps2 = -0.5", 10.0),
        ("turn", "rate_dps = -9.0", 10.0),
        ("sturn", "amplitude_dps = 5.0", 10.0),
    ];
    let blocks = (minutes * 60) / 60;
    for _ in 0..blocks {
        for (kind, extra, dur) in block {
            segs.push_str(&format!(
                "[[segment]]\ntype = \"{kind}\"\nduration_s = {dur}\n{extra}\n"
            ));
        }
    }
    format!(
        "name = \"fuse-maneuver\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nh_m = 100.0\nspeed_mps = 10.0\nyaw_deg = 30.0\n[imu]\nrate_hz = {rate_hz}\nseed = 7\ngrade = \"{grade}\"\n[nav]\nsamples = 2\n{segs}"
    )
}

fn scenario(grade: &str, rate_hz: f64, minutes: u32) -> Scenario {
    Scenario::from_toml(&maneuver_toml(grade, rate_hz, minutes), "maneuver.toml").unwrap()
}

#[test]
fn short_run_every_algorithm_stays_consistent() {
    let scn = scenario("tactical", 100.0, 2);
    let gnss = GnssConfig::default();
    for kind in AlgorithmKind::ALL {
        for n in [1, 4] {
            let opts = FuseOptions {
                algo: AlgorithmSpec::new(kind, n),
                ..Default::default()
            };
            let mut worst = 0.0_f64;
            let mut nis = Vec::new();
            let mut last = None;
            let s = fuse_scenario(&scn, &gnss, &opts, 0, &CancelToken::new(), |ev| match ev {
                FuseEvent::Epoch(e) => {
                    if e.t_s > 30.0 {
                        worst = worst.max(e.nees_block(I_POS)).max(e.nees_block(I_VEL));
                    }
                    last = Some(*e);
                }
                FuseEvent::Update(r) if r.kind == MeasKind::Gnss => nis.push(r.nis),
                _ => {}
            })
            .unwrap();
            let e = last.unwrap();
            println!(
                "{} N={n}: fixes {} rejected {} worst NEES {worst:.2} final pos err {:?} σ {:.2}",
                kind.name(),
                s.fixes,
                s.rejected,
                e.nav.pos_err_ned_m,
                e.sigma(I_POS)
            );
            // single run: each 3-dof NEES below the 99.99 % point 21.1 (a gross check)
            assert!(worst < 21.1, "{} N={n}: NEES {worst}", kind.name());
            assert_eq!(s.rejected, 0);
            assert!(s.fixes >= 119);
            let mean_nis = nis.iter().sum::<f64>() / nis.len() as f64;
            // 6-dof NIS, 120 fixes: mean σ = √(12/120) ≈ 0.32, 5σ band
            assert!(
                (mean_nis - 6.0).abs() < 1.6,
                "{} NIS {mean_nis}",
                kind.name()
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// Monte Carlo acceptance tests (release, --ignored)
// ---------------------------------------------------------------------------------------

use rayon::prelude::*;
use sdins_sim::fusion::simulated::{fuse_scenario_with, scenario_truth, FuseEpoch, FuseSummary};

/// Wilson–Hilferty quantile of the mean of `runs` χ²(dof) variables (χ²(runs·dof)/runs).
fn chi2_mean_quantile(dof: f64, runs: f64, z: f64) -> f64 {
    let k = dof * runs;
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3) / runs
}
const Z95: f64 = 1.959_963_984_540_054;
const Z99: f64 = 2.575_829_303_548_901;

struct Run {
    epochs: Vec<FuseEpoch>,
    smoothed: Vec<FuseEpoch>,
    gnss: Vec<(f64, f64, bool)>,
    #[allow(dead_code)]
    summary: FuseSummary,
}

fn run_mc(scn: &Scenario, gnss: &GnssConfig, opts: &FuseOptions, runs: u64) -> Vec<Run> {
    let truth = scenario_truth(scn);
    (0..runs)
        .into_par_iter()
        .map(|r| {
            let mut epochs = Vec::new();
            let mut smoothed = Vec::new();
            let mut g = Vec::new();
            let summary = fuse_scenario_with(
                scn,
                Some(&truth),
                gnss,
                opts,
                r,
                &CancelToken::new(),
                |ev| match ev {
                    FuseEvent::Epoch(e) => epochs.push(*e),
                    FuseEvent::Update(u) if u.kind == MeasKind::Gnss => {
                        g.push((u.t_s, u.nis, u.accepted))
                    }
                    FuseEvent::Smoothed(e) => smoothed.push(*e),
                    _ => {}
                },
            )
            .unwrap();
            Run {
                epochs,
                smoothed,
                gnss: g,
                summary,
            }
        })
        .collect()
}

/// Per-epoch run-means of a statistic, for epochs after `t0` (all runs share epochs).
fn run_means(runs: &[Run], t0: f64, f: impl Fn(&FuseEpoch) -> f64) -> Vec<(f64, f64)> {
    let n = runs[0].epochs.len();
    (0..n)
        .filter(|&k| runs[0].epochs[k].t_s > t0)
        .map(|k| {
            let t = runs[0].epochs[k].t_s;
            let m = runs.iter().map(|r| f(&r.epochs[k])).sum::<f64>() / runs.len() as f64;
            (t, m)
        })
        .collect()
}

/// The consistency criteria (a), (b), (c) on per-epoch run-means of χ²(dof).
fn check_band(name: &str, means: &[f64], dof: f64, runs: f64) -> f64 {
    let (l95, u95) = (
        chi2_mean_quantile(dof, runs, -Z95),
        chi2_mean_quantile(dof, runs, Z95),
    );
    let (l99, u99) = (
        chi2_mean_quantile(dof, runs, -Z99),
        chi2_mean_quantile(dof, runs, Z99),
    );
    let grand = means.iter().sum::<f64>() / means.len() as f64;
    let in95 =
        means.iter().filter(|m| (l95..=u95).contains(*m)).count() as f64 / means.len() as f64;
    let in99 =
        means.iter().filter(|m| (l99..=u99).contains(*m)).count() as f64 / means.len() as f64;
    let max = means.iter().copied().fold(0.0, f64::max);
    println!(
        "{name}: grand mean {grand:.3} (95 % band [{l95:.2}, {u95:.2}]), epochs in 95 % band {:.1} %, in 99 % band {:.1} %, max {max:.2} (limit {:.2})",
        100.0 * in95,
        100.0 * in99,
        2.0 * u99
    );
    assert!((l95..=u95).contains(&grand), "{name}: grand mean {grand}");
    assert!(
        in99 >= 0.70,
        "{name}: only {in99} of epochs in the 99 % band"
    );
    assert!(max <= 2.0 * u99, "{name}: an epoch reaches {max}");
    in95
}

fn no_gate() -> FuseOptions {
    FuseOptions {
        gate_chi2: None,
        ..Default::default()
    }
}

fn consistency(grade: &str) {
    let scn = scenario(grade, 100.0, 10);
    let gnss = GnssConfig::default();
    let runs = run_mc(&scn, &gnss, &no_gate(), 100);
    for (name, i0) in [
        ("position", I_POS),
        ("velocity", I_VEL),
        ("attitude", I_ATT),
    ] {
        let m: Vec<f64> = run_means(&runs, 30.0, |e| e.nees_block(i0))
            .iter()
            .map(|x| x.1)
            .collect();
        check_band(&format!("{grade} NEES {name}"), &m, 3.0, 100.0);
    }
    // GNSS NIS (6 dof) per fix epoch
    let nfix = runs[0].gnss.len();
    let nis: Vec<f64> = (0..nfix)
        .filter(|&k| runs[0].gnss[k].0 > 30.0)
        .map(|k| runs.iter().map(|r| r.gnss[k].1).sum::<f64>() / runs.len() as f64)
        .collect();
    check_band(&format!("{grade} NIS"), &nis, 6.0, 100.0);
    // biases: converge within 3σ; print σ reduction per axis
    let mut outside = 0;
    let mut ratio = [0.0; 6];
    for r in &runs {
        let e = r.epochs.last().unwrap();
        #[allow(clippy::needless_range_loop)]
        for i in 0..6 {
            let idx = I_BA + i;
            if e.err[idx].abs() > 3.0 * e.sigma(idx) {
                outside += 1;
            }
            ratio[i] += e.sigma(idx) / runs[0].epochs[0].sigma(idx).max(1e-300) / runs.len() as f64;
        }
    }
    println!("{grade}: bias errors outside 3σ: {outside} of 600; final/initial σ (ba x y z, bg x y z): {ratio:.3?}");
    // P(|z| > 3) = 0.0027: 1.6 expected of 600; > 7 has probability < 1e-3
    assert!(outside <= 7, "{grade}: {outside} bias errors outside 3σ");
    if grade == "tactical" {
        // observable under these maneuvers with 1 Hz position + velocity: the vertical
        // accelerometer (height channel), the horizontal accelerometers (separated from tilt by
        // the heading changes) and the level gyros (tilt, through f × ε); the z gyro (heading,
        // through the accelerations) more slowly
        for (i, lim) in [(0, 0.5), (1, 0.5), (2, 0.2), (3, 0.5), (4, 0.5), (5, 0.8)] {
            assert!(
                ratio[i] < lim,
                "{grade}: bias state {i}: σ ratio {}",
                ratio[i]
            );
        }
    }
}

#[test]
#[ignore]
fn mc_consistency_tactical() {
    consistency("tactical");
}

#[test]
#[ignore]
fn mc_consistency_aviation() {
    consistency("aviation");
}

#[test]
#[ignore]
fn mc_outage_60s_tactical() {
    let scn = scenario("tactical", 100.0, 7);
    let gnss = GnssConfig {
        sigma_pos_ned_m: [1.0; 3],
        outages_s: vec![[300.0, 360.0]],
        ..Default::default()
    };
    let opts = FuseOptions {
        smooth: true,
        ..no_gate()
    };
    let runs = run_mc(&scn, &gnss, &opts, 100);
    let k_end = runs[0]
        .epochs
        .iter()
        .rposition(|e| e.t_s < 360.0 - 1e-9)
        .unwrap();
    let nees_h = runs
        .iter()
        .map(|r| r.epochs[k_end].nees_horizontal())
        .sum::<f64>()
        / 100.0;
    let (lo, hi) = (
        chi2_mean_quantile(2.0, 100.0, -Z95),
        chi2_mean_quantile(2.0, 100.0, Z95),
    );
    let rms_h = |ep: &dyn Fn(&Run) -> &FuseEpoch| {
        (runs
            .iter()
            .map(|r| {
                let p = ep(r).nav.pos_err_ned_m;
                p[0] * p[0] + p[1] * p[1]
            })
            .sum::<f64>()
            / 100.0)
            .sqrt()
    };
    println!(
        "outage end t = {:.2} s: horizontal NEES {nees_h:.3} (band [{lo:.2}, {hi:.2}]), RMS horizontal error {:.2} m",
        runs[0].epochs[k_end].t_s,
        rms_h(&|r: &Run| &r.epochs[k_end])
    );
    assert!((lo..=hi).contains(&nees_h), "horizontal NEES {nees_h}");

    // smoother: one smoothed epoch per forward epoch (both include the initial row: the
    // engine's epoch rule), P_s ≤ P_f
    let mut worst = f64::INFINITY;
    for r in &runs {
        assert_eq!(r.smoothed.len(), r.epochs.len());
        for (f, s) in r.epochs.iter().zip(&r.smoothed) {
            assert_eq!(f.t_s, s.t_s);
            let d = f.p - s.p;
            let min_eig = d.symmetric_eigenvalues().min();
            worst = worst.min(min_eig / f.p.norm());
        }
    }
    println!("smallest eigenvalue of P_f − P_s over ‖P_f‖: {worst:.3e}");
    assert!(worst >= -1e-12, "P_f − P_s has eigenvalue {worst} ‖P_f‖");
    // smoothed NEES through the outage: the consistency criteria on the outage epochs
    let in_outage = |e: &FuseEpoch| e.t_s > 300.0 && e.t_s < 360.0;
    let idx: Vec<usize> = (0..runs[0].smoothed.len())
        .filter(|&k| in_outage(&runs[0].smoothed[k]))
        .collect();
    let mean_at = |k: usize, f: &dyn Fn(&FuseEpoch) -> f64| {
        runs.iter().map(|r| f(&r.smoothed[k])).sum::<f64>() / runs.len() as f64
    };
    let h: Vec<f64> = idx
        .iter()
        .map(|&k| mean_at(k, &|e| e.nees_horizontal()))
        .collect();
    check_band("smoothed horizontal NEES in the outage", &h, 2.0, 100.0);
    for (name, i0) in [
        ("position", I_POS),
        ("velocity", I_VEL),
        ("attitude", I_ATT),
    ] {
        let m: Vec<f64> = idx
            .iter()
            .map(|&k| mean_at(k, &|e| e.nees_block(i0)))
            .collect();
        check_band(
            &format!("smoothed NEES {name} in the outage"),
            &m,
            3.0,
            100.0,
        );
    }
    // ratio of forward to smoothed maximum RMS horizontal error in the outage
    let max_rms = |get: &dyn Fn(&Run, usize) -> &FuseEpoch, ks: &[usize]| {
        ks.iter()
            .map(|&k| {
                (runs
                    .iter()
                    .map(|r| {
                        let p = get(r, k).nav.pos_err_ned_m;
                        p[0] * p[0] + p[1] * p[1]
                    })
                    .sum::<f64>()
                    / 100.0)
                    .sqrt()
            })
            .fold(0.0, f64::max)
    };
    let kf: Vec<usize> = (0..runs[0].epochs.len())
        .filter(|&k| in_outage(&runs[0].epochs[k]))
        .collect();
    let f_max = max_rms(&|r, k| &r.epochs[k], &kf);
    let s_max = max_rms(&|r, k| &r.smoothed[k], &idx);
    println!(
        "outage: max RMS horizontal error forward {f_max:.3} m, smoothed {s_max:.3} m, ratio {:.2}",
        f_max / s_max
    );
    assert!(s_max < f_max);
}

/// Time-averaged position error along C_b^n l̂ per run (after 30 s).
fn along_lever(r: &Run, l: [f64; 3]) -> f64 {
    let lv = nalgebra::Vector3::from(l).normalize();
    let (mut s, mut n) = (0.0, 0.0);
    for e in r.epochs.iter().filter(|e| e.t_s > 30.0) {
        // the epoch's attitude is the truth's to first order
        let c = e.c_b_n_true;
        let d = c * lv;
        let p = nalgebra::Vector3::from(e.nav.pos_err_ned_m);
        s += p.dot(&d);
        n += 1.0;
    }
    s / n
}

fn mean_se(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = x.iter().map(|a| (a - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, (v / n).sqrt())
}

#[test]
#[ignore]
fn mc_lever_arm_and_offset_fixes() {
    let scn = scenario("tactical", 100.0, 5);
    let l = [1.5, 0.0, -0.5];
    let gnss = GnssConfig {
        offset_s: 0.3712,
        lever_arm_b_m: l,
        ..Default::default()
    };
    let modelled = run_mc(&scn, &gnss, &no_gate(), 100);
    for (name, i0) in [
        ("position", I_POS),
        ("velocity", I_VEL),
        ("attitude", I_ATT),
    ] {
        let m: Vec<f64> = run_means(&modelled, 30.0, |e| e.nees_block(i0))
            .iter()
            .map(|x| x.1)
            .collect();
        check_band(&format!("lever arm modelled NEES {name}"), &m, 3.0, 100.0);
    }
    let a: Vec<f64> = modelled.iter().map(|r| along_lever(r, l)).collect();
    let (m, se) = mean_se(&a);
    println!(
        "lever arm modelled: mean error along C l̂ {m:.4} m, SE {se:.4} m ({:.2} SE)",
        m / se
    );
    assert!(m.abs() <= 3.0 * se);
    let ignored = run_mc(
        &scn,
        &gnss,
        &FuseOptions {
            model_lever_arm: false,
            ..no_gate()
        },
        100,
    );
    let a: Vec<f64> = ignored.iter().map(|r| along_lever(r, l)).collect();
    let (m, se) = mean_se(&a);
    println!(
        "lever arm ignored: mean error along C l̂ {m:.4} m, SE {se:.4} m ({:.1} SE)",
        m / se
    );
    assert!(m.abs() > 10.0 * se);
}

/// Cruise at 16 m/s; along-track mean error with a 50 ms latency.
#[test]
#[ignore]
fn mc_latency_50ms_at_16mps() {
    let toml = "name = \"cruise16\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nspeed_mps = 16.0\nyaw_deg = 45.0\n[imu]\nrate_hz = 100.0\nseed = 3\ngrade = \"tactical\"\n[nav]\nsamples = 2\n[[segment]]\ntype = \"cruise\"\nduration_s = 300.0\n";
    let scn = Scenario::from_toml(toml, "cruise16.toml").unwrap();
    let yaw = 45f64.to_radians();
    let track = [yaw.cos(), yaw.sin()];
    for modelled in [false, true] {
        let gnss = GnssConfig {
            latency_s: 0.05,
            latency_modelled: modelled,
            ..Default::default()
        };
        let runs = run_mc(&scn, &gnss, &no_gate(), 40);
        let a: Vec<f64> = runs
            .iter()
            .map(|r| {
                let v: Vec<f64> = r
                    .epochs
                    .iter()
                    .filter(|e| e.t_s > 60.0)
                    .map(|e| e.nav.pos_err_ned_m[0] * track[0] + e.nav.pos_err_ned_m[1] * track[1])
                    .collect();
                v.iter().sum::<f64>() / v.len() as f64
            })
            .collect();
        let (m, se) = mean_se(&a);
        let expect = if modelled { 0.0 } else { -16.0 * 0.05 };
        println!("latency 50 ms modelled={modelled}: along-track mean {m:.4} m (expected {expect}), SE {se:.4}");
        assert!((m - expect).abs() <= 3.0 * se + 0.01, "{m} vs {expect}");
    }
}

#[test]
fn timing_residual_below_one_percent_of_sigma_at_5mps2() {
    for rate in [100.0, 200.0, 500.0] {
        let toml = format!("name = \"acc5\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nspeed_mps = 1.0\n[imu]\nrate_hz = {rate}\n[nav]\nsamples = 2\n[[segment]]\ntype = \"accelerate\"\naccel_mps2 = 5.0\nduration_s = 10.0\n[[segment]]\ntype = \"turn\"\nrate_dps = 10.0\nduration_s = 5.0\n");
        let scn = Scenario::from_toml(&toml, "acc5.toml").unwrap();
        let gnss = GnssConfig {
            offset_s: 0.3712,
            lever_arm_b_m: [1.5, 0.0, -0.5],
            // near noise-free fixes (noise 1 % of the test limits)
            sigma_pos_ned_m: [1e-4; 3],
            sigma_vel_ned_mps: [5e-6; 3],
            rate_hz: 10.0,
            ..Default::default()
        };
        let opts = FuseOptions {
            draw_initial_errors: false,
            gate_chi2: None,
            ..Default::default()
        };
        let (mut wp, mut wv) = (0.0_f64, 0.0_f64);
        fuse_scenario(&scn, &gnss, &opts, 0, &CancelToken::new(), |ev| {
            if let FuseEvent::Update(u) = ev {
                for i in 0..3 {
                    wp = wp.max(u.innovation[i].abs());
                    wv = wv.max(u.innovation[3 + i].abs());
                }
            }
        })
        .unwrap();
        println!("{rate} Hz: max |ν_pos| {wp:.2e} m, max |ν_vel| {wv:.2e} m/s");
        // 1 % of the default σ (1 m, 0.05 m/s)
        assert!(wp < 0.01 && wv < 5e-4, "{rate} Hz: {wp} m, {wv} m/s");
    }
}

#[test]
fn gating_rejects_a_100m_outlier_and_the_solution_is_unaffected() {
    let scn = scenario("tactical", 100.0, 2);
    let clean = GnssConfig::default();
    let bad = GnssConfig {
        outliers_t_s_ned_m: vec![[60.0, 100.0, 0.0, 0.0]],
        ..Default::default()
    };
    let opts = FuseOptions::default();
    // the reference: the same run with that one fix removed
    let clean = GnssConfig {
        outages_s: vec![[59.99, 60.01]],
        ..clean
    };
    let mut epochs = [Vec::new(), Vec::new()];
    let mut rejected_at = Vec::new();
    for (i, g) in [&clean, &bad].into_iter().enumerate() {
        let s = fuse_scenario(&scn, g, &opts, 0, &CancelToken::new(), |ev| match ev {
            FuseEvent::Epoch(e) => epochs[i].push(*e),
            FuseEvent::Update(u) if !u.accepted => rejected_at.push((i, u.t_s, u.nis)),
            _ => {}
        })
        .unwrap();
        assert_eq!(s.rejected, i as u64);
    }
    println!("rejected: {rejected_at:?}");
    assert_eq!(rejected_at.len(), 1);
    assert!((rejected_at[0].1 - 60.0).abs() < 0.02);
    // the solution equals the one without that fix (up to the extra covariance epoch at
    // the rejected fix's time): < 1e-3 σ at every epoch
    let mut worst = 0.0_f64;
    for (a, b) in epochs[0].iter().zip(&epochs[1]) {
        for i in 0..3 {
            let d = (a.nav.pos_err_ned_m[i] - b.nav.pos_err_ned_m[i]).abs() / a.sigma(I_POS + i);
            worst = worst.max(d);
        }
    }
    println!("largest position difference / σ: {worst:.3}");
    assert!(worst < 1e-3);
}

fn stop_and_go_toml() -> String {
    let mut segs = String::new();
    for _ in 0..5 {
        segs.push_str("[[segment]]\ntype = \"accelerate\"\naccel_mps2 = 2.0\nduration_s = 5.0\n[[segment]]\ntype = \"cruise\"\nduration_s = 15.0\n[[segment]]\ntype = \"turn\"\nrate_dps = 9.0\nduration_s = 10.0\n[[segment]]\ntype = \"accelerate\"\naccel_mps2 = -2.0\nduration_s = 5.0\n[[segment]]\ntype = \"static\"\nduration_s = 15.0\n");
    }
    format!("name = \"stop-and-go\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\n[imu]\nrate_hz = 100.0\nseed = 11\ngrade = \"tactical\"\n[nav]\nsamples = 2\n{segs}")
}

#[test]
#[ignore]
fn mc_zupt_nhc_reduce_outage_error() {
    let scn = Scenario::from_toml(&stop_and_go_toml(), "stop-and-go.toml").unwrap();
    // outage 150–210 s: covers motion and a stop (stops at 185–200 s)
    let gnss = GnssConfig {
        outages_s: vec![[150.0, 210.0]],
        ..Default::default()
    };
    let runs_n = 50;
    let plain = run_mc(&scn, &gnss, &no_gate(), runs_n);
    let aided = run_mc(
        &scn,
        &gnss,
        &FuseOptions {
            zupt: Some((0.01, 1e-3)),
            nhc_sigma_mps: Some(0.05),
            ..no_gate()
        },
        runs_n,
    );
    let k_end = plain[0]
        .epochs
        .iter()
        .rposition(|e| e.t_s < 210.0 - 1e-9)
        .unwrap();
    let stats = |runs: &[Run]| {
        let k = runs[0]
            .epochs
            .iter()
            .rposition(|e| e.t_s < 210.0 - 1e-9)
            .unwrap();
        let rms = (runs
            .iter()
            .map(|r| {
                let p = r.epochs[k].nav.pos_err_ned_m;
                p[0] * p[0] + p[1] * p[1]
            })
            .sum::<f64>()
            / runs.len() as f64)
            .sqrt();
        let nees = runs
            .iter()
            .map(|r| r.epochs[k].nees_horizontal())
            .sum::<f64>()
            / runs.len() as f64;
        (rms, nees)
    };
    let (rms_p, nees_p) = stats(&plain);
    let (rms_a, nees_a) = stats(&aided);
    let n = runs_n as f64;
    let (lo, hi) = (
        chi2_mean_quantile(2.0, n, -Z95),
        chi2_mean_quantile(2.0, n, Z95),
    );
    println!(
        "outage end {:.1} s: plain RMS {rms_p:.2} m NEES {nees_p:.2}; ZUPT+NHC RMS {rms_a:.2} m NEES {nees_a:.2} (band [{lo:.2}, {hi:.2}])",
        plain[0].epochs[k_end].t_s
    );
    assert!(rms_a < 0.5 * rms_p);
    assert!((lo..=hi).contains(&nees_a), "aided NEES {nees_a}");
    assert!((lo..=hi).contains(&nees_p), "plain NEES {nees_p}");
}

#[test]
fn gnss_scenario_section_parses_and_bad_values_name_the_key() {
    let base = maneuver_toml("tactical", 100.0, 1);
    let ok = format!("{base}[gnss]\nrate_hz = 5.0\nlever_arm_b_m = [1.5, 0.0, -0.5]\noutages_s = [[100.0, 160.0]]\n");
    let s = Scenario::from_toml(&ok, "g.toml").unwrap();
    let g = s.gnss.unwrap();
    assert_eq!(g.rate_hz, 5.0);
    assert_eq!(g.outages_s, vec![[100.0, 160.0]]);
    for (text, key) in [
        ("rate_hz = 0.5", "gnss.rate_hz"),
        ("sigma_pos_ned_m = [1.0, -1.0, 1.0]", "gnss.sigma_pos_ned_m"),
        ("sigma_pos_ned_m = [1.0, nan, 1.0]", "gnss.sigma_pos_ned_m"),
        ("dropout_prob = 2.0", "gnss.dropout_prob"),
        ("outages_s = [[5.0, 1.0]]", "gnss.outages_s"),
    ] {
        let e = Scenario::from_toml(&format!("{base}[gnss]\n{text}\n"), "g.toml").unwrap_err();
        assert!(e.to_string().contains(key), "{text}: {e}");
    }
    let e = Scenario::from_toml(&format!("{base}[gnss]\nrate_hzz = 1.0\n"), "g.toml").unwrap_err();
    assert!(e.to_string().contains("rate_hzz"), "{e}");
}

/// In-motion alignment from an unknown heading (GNSS track, then the filter with NHC):
/// ground vehicle at 10 m/s, tactical grade, 1 Hz GNSS, initial heading uniform over
/// ±180° (a stratified grid, one per run), 200 runs. At most 2 runs above 0.5° heading
/// error 60 s after the start of motion; attitude NEES in band from handover + 60 s.
#[test]
#[ignore]
fn mc_in_motion_alignment_from_unknown_heading() {
    use sdins_sim::fusion::simulated::InMotionInit;
    let runs = 200u64;
    let opts = FuseOptions {
        in_motion: Some(InMotionInit::default()),
        ..no_gate()
    };
    let gnss = GnssConfig::default();
    let results: Vec<Run> = (0..runs)
        .into_par_iter()
        .map(|r| {
            let yaw = -180.0 + 360.0 * (r as f64 + 0.5) / runs as f64;
            let mut segs = String::new();
            for _ in 0..3 {
                segs.push_str("[[segment]]\ntype = \"cruise\"\nduration_s = 10.0\n[[segment]]\ntype = \"turn\"\nrate_dps = 9.0\nduration_s = 10.0\n[[segment]]\ntype = \"accelerate\"\naccel_mps2 = 0.5\nduration_s = 10.0\n[[segment]]\ntype = \"turn\"\nrate_dps = -9.0\nduration_s = 10.0\n[[segment]]\ntype = \"accelerate\"\naccel_mps2 = -0.5\nduration_s = 10.0\n[[segment]]\ntype = \"sturn\"\namplitude_dps = 5.0\nduration_s = 10.0\n");
            }
            let toml = format!("name = \"in-motion\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nspeed_mps = 10.0\nyaw_deg = {yaw}\n[imu]\nrate_hz = 100.0\nseed = 21\ngrade = \"tactical\"\n[nav]\nsamples = 2\n{segs}");
            let scn = Scenario::from_toml(&toml, "in-motion.toml").unwrap();
            let mut epochs = Vec::new();
            let summary = fuse_scenario(&scn, &gnss, &opts, r, &CancelToken::new(), |ev| {
                if let FuseEvent::Epoch(e) = ev {
                    epochs.push(*e)
                }
            })
            .unwrap();
            Run {
                epochs,
                smoothed: Vec::new(),
                gnss: Vec::new(),
                summary,
            }
        })
        .collect();
    let t_hand = results[0].epochs[0].t_s;
    // heading error 60 s after the start of motion (t = 0)
    let k60 = results[0]
        .epochs
        .iter()
        .position(|e| e.t_s >= 60.0 - 1e-9)
        .unwrap();
    let errs: Vec<f64> = results
        .iter()
        .map(|r| r.epochs[k60].nav.euler_err_rad[2].to_degrees().abs())
        .collect();
    let above = errs.iter().filter(|e| **e > 0.5).count();
    let max = errs.iter().copied().fold(0.0, f64::max);
    let rms = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len() as f64).sqrt();
    let sig = results[0].epochs[k60].sigma(I_ATT + 2).to_degrees();
    println!(
        "in-motion: handover at t = {t_hand:.2} s; heading error at 60 s: RMS {rms:.4}°, max {max:.4}°, runs above 0.5°: {above} of {runs}; filter σ_ψ (run 0) {sig:.4}°"
    );
    assert!(above <= 2, "{above} runs above 0.5°");
    for k in [k60, results[0].epochs.len() - 1] {
        let z: Vec<f64> = (0..9)
            .map(|i| {
                results
                    .iter()
                    .map(|r| (r.epochs[k].err[i] / r.epochs[k].p[(i, i)].sqrt()).powi(2))
                    .sum::<f64>()
                    / runs as f64
            })
            .collect();
        println!(
            "t = {:.1} s: mean (err/σ)² pos, vel, att: {z:.2?}",
            results[0].epochs[k].t_s
        );
    }
    let m: Vec<f64> = run_means(&results, t_hand + 60.0, |e| e.nees_block(I_ATT))
        .iter()
        .map(|x| x.1)
        .collect();
    let in95 = check_band(
        "in-motion attitude NEES from handover + 60 s",
        &m,
        3.0,
        runs as f64,
    );
    println!(
        "in-motion attitude NEES: {:.1} % of epochs in the 95 % band",
        100.0 * in95
    );
}

/// `[mounting]`: the antenna arm from `[mounting] gnss_lever_arm_m` acts as `[gnss]
/// lever_arm_b_m` (bit-identical runs); conflicting arms and an IMU lever arm are refused
/// by fuse and by the Monte Carlo (they would silently be ignored).
#[test]
fn mounting_gnss_arm_is_used_and_imu_mounting_is_refused() {
    let base = "name = \"m\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nspeed_mps = 10.0\n[imu]\nrate_hz = 100.0\ngrade = \"tactical\"\n[nav]\nsamples = 2\n[[segment]]\ntype = \"turn\"\nrate_dps = 5.0\nduration_s = 20.0\n";
    let run = |toml: &str, gnss: &GnssConfig| {
        let scn = Scenario::from_toml(toml, "m.toml").unwrap();
        let mut last = None;
        let r = fuse_scenario(
            &scn,
            gnss,
            &FuseOptions::default(),
            0,
            &CancelToken::new(),
            |ev| {
                if let FuseEvent::Epoch(e) = ev {
                    last = Some(e.err)
                }
            },
        );
        r.map(|_| last.unwrap())
    };
    let arm = GnssConfig {
        lever_arm_b_m: [1.0, 0.2, -0.5],
        ..Default::default()
    };
    let a = run(base, &arm).unwrap();
    let with_mount = format!("{base}[mounting]\ngnss_lever_arm_m = [1.0, 0.2, -0.5]\n");
    let b = run(&with_mount, &GnssConfig::default()).unwrap();
    assert_eq!(a, b);
    let other = GnssConfig {
        lever_arm_b_m: [0.5, 0.0, 0.0],
        ..Default::default()
    };
    let e = run(&with_mount, &other).unwrap_err().to_string();
    assert!(e.contains("gnss_lever_arm_m"), "{e}");
    let imu_arm = format!("{base}[mounting]\nimu_lever_arm_m = [0.5, 0.0, 0.0]\n");
    let e = run(&imu_arm, &GnssConfig::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("mounting"), "{e}");
    let scn = Scenario::from_toml(&imu_arm, "m.toml").unwrap();
    let mc = sdins_sim::analysis::montecarlo::McOptions {
        runs: 16,
        seed: 1,
        algo: AlgorithmSpec::new(AlgorithmKind::SongLeeComplete, 2),
        every_s: 1.0,
        until_s: None,
        block: 16,
        vertical_hold: true,
    };
    let e = sdins_sim::analysis::montecarlo::runner::job(&scn, &mc)
        .unwrap_err()
        .to_string();
    assert!(e.contains("[mounting]"), "{e}");
}

// ---------------------------------------------------------------------------------------
// The 21-state filter (accelerometer and gyro scale factors)
// ---------------------------------------------------------------------------------------

use sdins_core::aiding::error_model::N_STATES;
use sdins_sim::fusion::simulated::ScaleFactorPrior;

/// Loops in one direction (a 360° and a 180° turn at 9 °/s per minute, with speed
/// changes between): a heading error from the z-gyro scale factor accumulates instead of
/// cancelling between left and right turns.
fn loops_scenario(minutes: u32) -> Scenario {
    let mut segs = String::new();
    let block = [
        ("accelerate", "accel_mps2 = 0.5", 5.0),
        ("turn", "rate_dps = 9.0", 40.0),
        ("accelerate", "accel_mps2 = -0.5", 5.0),
        ("turn", "rate_dps = 9.0", 20.0),
    ];
    for _ in 0..minutes {
        for (kind, extra, dur) in block {
            segs.push_str(&format!(
                "[[segment]]\ntype = \"{kind}\"\nduration_s = {dur}\n{extra}\n"
            ));
        }
    }
    let toml = format!(
        "name = \"fuse-loops\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nh_m = 100.0\nspeed_mps = 15.0\nyaw_deg = 30.0\n[imu]\nrate_hz = 100.0\nseed = 7\ngrade = \"tactical\"\n[nav]\nsamples = 2\n{segs}"
    );
    Scenario::from_toml(&toml, "loops.toml").unwrap()
}

fn sf_opts(accel_ppm: f64, gyro_ppm: f64) -> FuseOptions {
    FuseOptions {
        scale_factors: Some(ScaleFactorPrior::uniform(accel_ppm, gyro_ppm)),
        ..no_gate()
    }
}

fn epochs_of(scn: &Scenario, opts: &FuseOptions) -> (Vec<FuseEpoch>, FuseSummary) {
    let mut v = Vec::new();
    let s = fuse_scenario(
        scn,
        &GnssConfig::default(),
        opts,
        0,
        &CancelToken::new(),
        |ev| {
            if let FuseEvent::Epoch(e) = ev {
                v.push(*e)
            }
        },
    )
    .unwrap();
    (v, s)
}

/// With a zero prior on the scale factors the extra states carry no variance, so the
/// 21-state filter must reproduce the 15-state filter to rounding: a check of the
/// embedding of the 15-state model in the 21-state one.
#[test]
fn zero_prior_scale_factor_filter_equals_15_state_filter() {
    let scn = scenario("tactical", 100.0, 1);
    let (a, _) = epochs_of(&scn, &no_gate());
    let (b, sb) = epochs_of(&scn, &sf_opts(0.0, 0.0));
    assert_eq!(a.len(), b.len());
    let mut worst = 0.0_f64;
    for (x, y) in a.iter().zip(&b) {
        for i in 0..N_STATES {
            let d = (x.err[i] - y.err[i]).abs() / (x.p[(i, i)].sqrt() + 1e-300);
            worst = worst.max(d);
            let dp = (x.p[(i, i)] - y.p[(i, i)]).abs() / x.p[(i, i)].max(1e-300);
            worst = worst.max(dp);
        }
        assert!(y.scale_factors().is_some() && x.scale_factors().is_none());
    }
    println!("largest difference 15 vs 21 states (in σ or relative variance): {worst:.2e}");
    // rounding only: a few hundred epochs of 1e-16 relative operations
    assert!(worst < 1e-9, "{worst}");
    assert_eq!(sb.est_scale, (Default::default(), Default::default()));
}

/// A single run with a large z-gyro and vertical accelerometer scale factor. The z-gyro
/// scale factor is observable here: its estimate (loops in one direction, so the heading error it causes accumulates) must land within
/// 3σ of the truth with σ well below the prior. The vertical
/// accelerometer's is not separable from its bias on a level road (`f_z = −g` constant:
/// only `b_z − g s_z` is observed), so it must merely stay within 3σ.
#[test]
fn scale_factor_filter_estimates_observable_scale_factors() {
    let mut scn = loops_scenario(2);
    scn.imu.model.gyro_scale_ppm = [0.0, 0.0, 1500.0];
    scn.imu.model.accel_scale_ppm = [0.0, 0.0, -800.0];
    let (e, s) = epochs_of(&scn, &sf_opts(1000.0, 1000.0));
    let last = e.last().unwrap();
    let sf = last.scale_factors().unwrap();
    let (ts_a, ts_g) = s.true_scale.unwrap();
    assert!((ts_a.z + 800e-6).abs() < 1e-18 && (ts_g.z - 1500e-6).abs() < 1e-18);
    for (i, name) in [(2, "accel z"), (5, "gyro z")] {
        let sig = sf.p[(i, i)].sqrt();
        println!(
            "{name}: error {:.1} ppm, σ {:.1} ppm (prior 1000 ppm)",
            sf.err[i] * 1e6,
            sig * 1e6
        );
        assert!(sf.err[i].abs() < 3.0 * sig, "{name}");
        if i == 5 {
            assert!(sig < 0.5e-3, "{name}: σ {sig}");
        }
    }
    // the 15-state filter on the same data: its heading error is outside its 3σ
    let (e15, _) = epochs_of(&scn, &no_gate());
    let worst15 = e15.iter().map(|e| e.nees_block(I_ATT)).fold(0.0, f64::max);
    let worst21 = e.iter().map(|e| e.nees_block(I_ATT)).fold(0.0, f64::max);
    println!("worst attitude NEES: 15 states {worst15:.1}, 21 states {worst21:.1}");
    assert!(worst21 < 21.1, "{worst21}");
}

#[test]
#[ignore]
fn mc_consistency_scale_factors_tactical() {
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let scn = loops_scenario(10);
    let gnss = GnssConfig::default();
    let (sa, sg) = (300.0, 300.0);
    let opts = sf_opts(sa, sg);
    let truth = scenario_truth(&scn);
    let runs: Vec<Vec<FuseEpoch>> = (0..100u64)
        .into_par_iter()
        .map(|r| {
            // each run draws its scale factors from the filter's prior
            let mut rng = rand_chacha::ChaCha20Rng::seed_from_u64(1000 + r);
            let mut s = scn.clone();
            for i in 0..3 {
                let (wa, wg): (f64, f64) = (
                    StandardNormal.sample(&mut rng),
                    StandardNormal.sample(&mut rng),
                );
                s.imu.model.accel_scale_ppm[i] = sa * wa;
                s.imu.model.gyro_scale_ppm[i] = sg * wg;
            }
            let mut v = Vec::new();
            fuse_scenario_with(
                &s,
                Some(&truth),
                &gnss,
                &opts,
                r,
                &CancelToken::new(),
                |ev| {
                    if let FuseEvent::Epoch(e) = ev {
                        v.push(*e)
                    }
                },
            )
            .unwrap();
            v
        })
        .collect();
    let n = runs[0].len();
    let means = |f: &dyn Fn(&FuseEpoch) -> f64| -> Vec<f64> {
        (0..n)
            .filter(|&k| runs[0][k].t_s > 30.0)
            .map(|k| runs.iter().map(|r| f(&r[k])).sum::<f64>() / runs.len() as f64)
            .collect()
    };
    for (name, i0) in [
        ("position", I_POS),
        ("velocity", I_VEL),
        ("attitude", I_ATT),
    ] {
        let m = means(&|e| e.nees_block(i0));
        check_band(&format!("21-state NEES {name}"), &m, 3.0, 100.0);
    }
    for (name, i0) in [("accel scale factor", 0), ("gyro scale factor", 3)] {
        let m = means(&|e| e.scale_factors().unwrap().nees_block(i0));
        check_band(&format!("21-state NEES {name}"), &m, 3.0, 100.0);
    }
    let mut ratio = [0.0; 6];
    for r in &runs {
        let (a, b) = (
            r[0].scale_factors().unwrap(),
            r[n - 1].scale_factors().unwrap(),
        );
        for (i, x) in ratio.iter_mut().enumerate() {
            *x += (b.p[(i, i)] / a.p[(i, i)]).sqrt() / runs.len() as f64;
        }
    }
    println!("final/initial σ of the scale factors (accel x y z, gyro x y z): {ratio:.3?}");
    // observable: the z-gyro scale factor (loops at 9 °/s in one direction, the heading
    // error seen through the accelerations) and the lateral accelerometer's (2.4 m/s²
    // centripetal in the turns); not separable: the vertical accelerometer's from its bias
    // (f_z = −g constant on a level road) and the level gyros' (only earth rate and tiny
    // pitch/roll rates). A covariance that tells the truth shrinks only the first two.
    assert!(ratio[5] < 0.8 && ratio[1] < 0.8, "{ratio:?}");
    assert!(
        ratio[2] > 0.9 && ratio[3] > 0.95 && ratio[4] > 0.95,
        "{ratio:?}"
    );
}

// ---------------------------------------------------------------------------------------
// Measurement timing: a fix delivered late
// ---------------------------------------------------------------------------------------

/// A fix delivered 0.3 s late (its arrival moved, nothing else: the filter back-propagates
/// its measurement model from the time of validity to the update, `H_now = H_then
/// Φ(t_then, t_now)`) gives, right after its application, the estimates of the same fix
/// delivered on time, within the effect of the process noise Q over the delay that the
/// back-propagation neglects. Derivation (docs/theory/ins-gnss.md §"Measurement timing"):
/// for a linear filter the two estimates differ by `Δx = (I − K H_n) Q H_nᵀ S_n⁻¹ ν`, and
/// since `(I − KH)` does not expand the `P⁺⁻¹` norm,
/// `‖Δx‖²_{P⁺⁻¹} ≤ λmax(P⁺⁻¹Q) · λmax(R⁻¹ H Q Hᵀ) · NIS`. One fix at a time (30, 60, 90 s
/// of a manoeuvring run), the others on time; Q of the tactical grade over 0.3 s. With the
/// NHC at 10 Hz the late fix also has to undo the corrections applied during its delay.
#[test]
fn late_fix_gives_the_on_time_estimates_within_the_process_noise_bound() {
    late_fix_case(None);
    late_fix_case(Some(0.05));
}

fn late_fix_case(nhc_sigma_mps: Option<f64>) {
    use nalgebra::{SMatrix, SVector};
    use sdins_sim::fusion::engine::{run_engine, EngineEvent, Event};
    use sdins_sim::fusion::scenario_stream::scenario_start;
    type M15 = SMatrix<f64, 15, 15>;
    type V15 = SVector<f64, 15>;
    let scn = scenario("tactical", 100.0, 2);
    let earth = scn.nav.earth.model();
    let gnss = GnssConfig::default();
    let opts = FuseOptions {
        gate_chi2: None,
        nhc_sigma_mps,
        ..Default::default()
    };
    // rows (t, x in NED metres / m/s / rad and the estimates, P in the same units) and the
    // reports of a run with the fix at `late_at` delayed by 0.3 s
    let run = |late_at: Option<f64>| {
        let setup = scenario_start(&scn, None, &gnss, &opts, 1).unwrap();
        let mut stream = setup.stream.map(|ev| match ev {
            Event::Gnss { fix, arrival_s }
                if late_at.is_some_and(|t| (fix.t_s - t).abs() < 1e-9) =>
            {
                Event::Gnss {
                    fix,
                    arrival_s: arrival_s + 0.3,
                }
            }
            e => e,
        });
        let mut rows: Vec<(f64, V15, M15)> = Vec::new();
        let mut reps = Vec::new();
        let mut sink = |ev: EngineEvent<'_>| match ev {
            EngineEvent::Forward(r) => {
                let (s, tr, p) = (r.state, r.truth.unwrap(), r.p.unwrap());
                let e = sdins_sim::nav::pipeline::nav_error(&earth, s, tr);
                let rr = earth.radii(tr.lat_rad);
                let d = [
                    rr.r_m_m + tr.h_m,
                    (rr.r_n_m + tr.h_m) * tr.lat_rad.cos(),
                    -1.0,
                ];
                let x = V15::from_fn(|i, _| match i {
                    0..=2 => e.pos_err_ned_m[i],
                    3..=5 => e.vel_err_ned_mps[i - 3],
                    6..=8 => e.att_err_rad[i - 6],
                    _ => r.est[i],
                });
                let sc = |i: usize| if i < 3 { d[i] } else { 1.0 };
                let pm = M15::from_fn(|i, j| p[(i, j)] * sc(i) * sc(j));
                rows.push((r.t_s, x, pm));
            }
            EngineEvent::Update(u) => reps.push(*u),
            _ => {}
        };
        run_engine(
            &mut stream,
            &setup.start,
            &setup.cfg,
            &CancelToken::new(),
            &mut sink,
        )
        .unwrap();
        (rows, reps)
    };
    // Q over the delay (tactical: VRW 100 μg/√Hz, ARW 0.01 °/√h), NED metres
    let tau: f64 = 0.3;
    let qv = (100e-6 * 9.80665_f64).powi(2);
    let qa = (0.01_f64.to_radians() / 60.0).powi(2);
    let mut q = M15::zeros();
    for i in 0..3 {
        q[(i, i)] = qv * tau.powi(3) / 3.0;
        q[(i, 3 + i)] = qv * tau.powi(2) / 2.0;
        q[(3 + i, i)] = qv * tau.powi(2) / 2.0;
        q[(3 + i, 3 + i)] = qv * tau + 9.81_f64.powi(2) * qa * tau.powi(3) / 3.0;
        q[(6 + i, 6 + i)] = qa * tau;
    }
    // λmax(R⁻¹ H Q Hᵀ), R of the default fixes (σ 1, 1, 2 m; 0.05, 0.05, 0.1 m/s)
    let r_sig = [1.0, 1.0, 2.0, 0.05, 0.05, 0.1];
    let hqh = SMatrix::<f64, 6, 6>::from_fn(|i, j| q[(i, j)] / (r_sig[i] * r_sig[j]));
    let rho = hqh.symmetric_eigenvalues().max();
    let (on, _) = run(None);
    let mut worst = 0.0_f64;
    let mut worst_before = 0.0_f64;
    for t_fix in [30.0, 60.0, 90.0] {
        let (late, late_reps) = run(Some(t_fix));
        let rep = late_reps
            .iter()
            .find(|u| u.kind == MeasKind::Gnss && (u.t_valid_s - t_fix).abs() < 1e-9)
            .unwrap();
        assert!(
            (rep.t_s - t_fix - 0.3).abs() < 0.011 && rep.accepted && !rep.late,
            "{rep:?}"
        );
        let at = |rows: &Vec<(f64, V15, M15)>, t: f64| {
            rows.iter()
                .find(|r| (r.0 - t).abs() < 1e-6)
                .cloned()
                .unwrap()
        };
        let (a, b) = (at(&on, t_fix + 0.3), at(&late, t_fix + 0.3));
        let (a0, b0) = (at(&on, t_fix + 0.2), at(&late, t_fix + 0.2));
        let chol = a.2.cholesky().unwrap();
        let dx = a.1 - b.1;
        let m = dx.dot(&chol.solve(&dx)).sqrt();
        let l = chol.l();
        let li = l.try_inverse().unwrap();
        let lam_q = (li * q * li.transpose()).symmetric_eigenvalues().max();
        let bound = (lam_q * rho * rep.nis).sqrt();
        let dx0 = a0.1 - b0.1;
        let m0 = dx0.dot(&a0.2.cholesky().unwrap().solve(&dx0)).sqrt();
        println!(
            "NHC {nhc_sigma_mps:?}: fix at {t_fix} s, NIS {:.2}: ‖Δx‖ = {m:.3e} in P⁻¹ norm, bound {bound:.3e} (λ_Q {lam_q:.2e}, ρ {rho:.2e}); 0.1 s before it arrives {m0:.3e}",
            rep.nis
        );
        worst = worst.max(m / bound);
        worst_before = worst_before.max(m0);
        assert!(m0 > 10.0 * bound, "the late fix changes nothing?");
    }
    println!("late fix: largest ‖Δx‖/bound {worst:.3}");
    assert!(worst <= 1.0, "{worst} of the bound");
}
