//! INS/GNSS filter on simulated scenarios: quick default tests and the acceptance Monte
//! Carlo (`#[ignore]`, release: `cargo test --release -p sdins-sim --test fuse -- --ignored`).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use sdins_core::aiding::ekf::{MeasKind, CHI2_999};
use sdins_core::aiding::error_model::{I_ATT, I_BA, I_BG, I_POS, I_VEL};
use sdins_core::nav::{AlgorithmKind, AlgorithmSpec};
use sdins_sim::cancel::CancelToken;
use sdins_sim::fuse::{fuse_scenario, FuseEvent, FuseOptions};
use sdins_sim::gnss::GnssConfig;
use sdins_sim::scenario::Scenario;

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
                FuseEvent::Update(r) => {
                    if r.kind == MeasKind::Gnss {
                        nis.push(r.nis);
                    }
                }
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
use sdins_sim::fuse::{fuse_scenario_with, scenario_truth, FuseEpoch, FuseSummary};

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
    gnss: Vec<(f64, f64, bool)>,
    summary: FuseSummary,
}

fn run_mc(scn: &Scenario, gnss: &GnssConfig, opts: &FuseOptions, runs: u64) -> Vec<Run> {
    let truth = scenario_truth(scn);
    (0..runs)
        .into_par_iter()
        .map(|r| {
            let mut epochs = Vec::new();
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
                    FuseEvent::Update(u) => {
                        if u.kind == MeasKind::Gnss {
                            g.push((u.t_s, u.nis, u.accepted));
                        }
                    }
                },
            )
            .unwrap();
            Run {
                epochs,
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
