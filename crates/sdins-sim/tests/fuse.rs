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
