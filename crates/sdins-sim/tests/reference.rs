//! Recorded trajectories → exact IMU → navigation, on NaveGo's and PSINS's own reference
//! trajectories (docs/validation.md §"Recorded trajectories").
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;
use common::shared_data as data;

use sdins_core::math::Vec3;
use sdins_core::nav::{AlgorithmKind, AlgorithmSpec};
use sdins_sim::nav::pipeline::{run, NavError, RunOptions};
use sdins_sim::scenario::from_reference::{scenario_from_reference, ReferenceOptions};
use sdins_sim::truth::{lon_diff, TruthConfig, TruthGenerator};

struct RoundTrip {
    /// truth generator's position against the interpolant's at the samples [m]
    truth_vs_interp_m: f64,
    /// navigation against the truth: position [m], attitude [rad], velocity [m/s]
    nav: NavError,
}

/// Reference → truth and IMU at `rate_hz` → songlee-complete N = 3, and the truth's own
/// position against the interpolant.
fn round_trip(file: &std::path::Path, rate_hz: f64) -> RoundTrip {
    let opts = ReferenceOptions {
        rate_hz,
        ..ReferenceOptions::default()
    };
    let (scn, sum) = scenario_from_reference(file, &opts).unwrap();
    eprintln!(
        "{}: {} rows over {} s from t0 = {} s; truth {} s at {rate_hz} Hz; velocity vs file: {:?}",
        file.display(),
        sum.rows,
        sum.span_s,
        sum.t0_s,
        sum.duration_s,
        sum.velocity
    );
    let tr = scn.trajectory.reference().unwrap();
    let earth = scn.nav.earth.model();
    let mut worst = 0.0_f64;
    for s in TruthGenerator::new(&scn.trajectory, scn.truth_config()) {
        let p = tr.at(s.t_s, s.t_s - 1e-9);
        let le = earth.radii(s.lat_rad);
        let d = Vec3::new(
            (s.lat_rad - p.lat_rad) * (le.r_m_m + s.h_m),
            lon_diff(s.lon_rad, p.lon_rad) * (le.r_n_m + s.h_m) * s.lat_rad.cos(),
            s.h_m - p.h_m,
        );
        worst = worst.max(d.norm());
    }
    let ro = RunOptions {
        algos: vec![AlgorithmSpec::new(AlgorithmKind::SongLeeComplete, 3)],
        vertical_hold: false,
        every_s: None,
        until_s: None,
        sensor_run: None,
    };
    let sums = run(&scn, &ro, |_, _, _, _| {}, |_, _| {}).unwrap();
    RoundTrip {
        truth_vs_interp_m: worst,
        nav: sums[0].max_abs,
    }
}

fn check(r: &RoundTrip, what: &str) {
    let pos = r
        .nav
        .pos_err_ned_m
        .iter()
        .fold(0.0_f64, |a, b| a.max(b.abs()));
    let att = r
        .nav
        .att_err_rad
        .iter()
        .fold(0.0_f64, |a, b| a.max(b.abs()));
    let vel = r
        .nav
        .vel_err_ned_mps
        .iter()
        .fold(0.0_f64, |a, b| a.max(b.abs()));
    eprintln!(
        "{what}: truth vs interpolant {:.3e} m; navigation max |δp| {pos:.3e} m, |δv| {vel:.3e} m/s, |ε| {att:.3e} rad",
        r.truth_vs_interp_m
    );
    // the truth integrates the interpolant's velocity: its position is the interpolant's
    // to the quadrature's rounding (well below a micrometre)
    assert!(
        r.truth_vs_interp_m < 1e-6,
        "{what}: {}",
        r.truth_vs_interp_m
    );
    // the acceptance bounds of the round trip
    assert!(pos <= 1e-3, "{what}: position {pos} m");
    assert!(att <= 2e-10, "{what}: attitude {att} rad");
}

/// NaveGo's synthetic `ref` (437 s, 200 Hz rows) → 1 kHz IMU → navigation. Its rows
/// step the angular rate between two rows (at 59.0 s the roll rate 2.5°/s stops and a
/// 20°/s yaw rate starts, and so at every turn entry and exit): any interpolant through
/// the rows turns the rate within one 5 ms row, and songlee-complete's algorithmic error
/// on that transition falls as δt⁴ (max attitude error 6.5e-8 rad at 200 Hz, 4.6e-9 at
/// 400 Hz, 1.0e-10 at 1 kHz; docs/validation.md §"Recorded trajectories"), so the bound
/// is met with five IMU samples per row.
#[test]
#[ignore = "long: release, about 3 s"]
fn navego_ref_round_trip() {
    let Some(f) = data("csv/navego/ref.csv") else {
        return;
    };
    check(&round_trip(&f, 1000.0), "NaveGo ref at 1 kHz");
}

/// PSINS `trj10ms` avp (966 s, 10 Hz rows) → 200 Hz IMU → navigation (at 100 Hz: 1.9 mm
/// and 1.2e-9 rad, the same transition effect at its rate steps).
#[test]
#[ignore = "long: release, about 3 s"]
fn psins_trj10ms_round_trip() {
    let Some(f) = data("csv/psins/trj10ms_avp.csv") else {
        return;
    };
    check(&round_trip(&f, 200.0), "PSINS trj10ms at 200 Hz");
}

/// The default Gauss truth against the RK4 reference at twice the substeps on NaveGo's
/// ref: the start, the first turn entry (58–60 s, where the interpolant turns a rate step
/// within one row) and a steady turn.
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn gauss_matches_rk4_on_a_reference() {
    let Some(f) = data("csv/navego/ref.csv") else {
        return;
    };
    let (scn, _) = scenario_from_reference(
        &f,
        &ReferenceOptions {
            rate_hz: 200.0,
            ..ReferenceOptions::default()
        },
    )
    .unwrap();
    let c1 = scn.truth_config();
    // RK4 is Simpson's rule per substep: its error h⁴·f⁽⁴⁾/2880 is large where the
    // interpolant turns a rate step within one row (3.5e-12 rad at 32 substeps at 59.0 s),
    // so the reference runs at 2048 substeps, (1/64)⁴ of that
    assert_eq!(c1.substeps, 256, "panels of 1/8 of the 5 ms rows");
    let c2 = TruthConfig {
        substeps: 2048,
        ..c1
    };
    let (mut dth, mut dv) = (0.0_f64, 0.0_f64);
    for (start, len) in [(0.0, 1.0), (58.0, 2.0), (62.0, 1.0)] {
        let k = (start / c1.dt_s).round() as u64;
        let n = (len / c1.dt_s).round() as usize;
        let a = TruthGenerator::new(&scn.trajectory, c1).starting_at_sample(k);
        let b = TruthGenerator::new(&scn.trajectory, c2)
            .reference_rk4()
            .starting_at_sample(k);
        for (x, y) in a.zip(b).take(n) {
            dth = dth.max((x.inc.dtheta_b_rad - y.inc.dtheta_b_rad).norm());
            dv = dv.max((x.inc.dv_b_mps - y.inc.dv_b_mps).norm());
        }
    }
    eprintln!("NaveGo ref, Gauss vs RK4: dθ {dth:e} rad, dv {dv:e} m/s");
    // dθ: the bound of tests/truth.rs. dv: the rounding of the reference's 2048-term sums,
    // √2048·ulp(|Δv| ≈ 0.05 m/s) ≈ 3e-16 m/s, decides
    assert!(dth <= 2e-17, "{dth:e}");
    assert!(dv <= 5e-16, "{dv:e}");
}

/// NaveGo's own IMU simulation from the same `ref` (`imu2`, ADIS16488, 200 Hz: rates and
/// specific force) against ours: 1 s means of `imu2` minus its static biases `gb_sta`,
/// `ab_sta` against the 1 s means of our exact increments. The band is 3σ of the difference
/// of 1 s means under `imu2`'s own noise model (`imu2_params.txt`): white noise `g_std`,
/// `a_std` per 200 Hz sample (σ/√200 for the mean) and the Gauss–Markov bias `gb_dyn`,
/// `ab_dyn` in quadrature.
#[test]
#[ignore = "long: release, about 5 s"]
fn navego_imu2_one_second_means() {
    let (Some(f), Some(imu2)) = (data("csv/navego/ref.csv"), data("csv/navego/imu2.csv")) else {
        return;
    };
    let (scn, _) = scenario_from_reference(
        &f,
        &ReferenceOptions {
            rate_hz: 200.0,
            ..ReferenceOptions::default()
        },
    )
    .unwrap();
    // ours: Σ Δθ, Σ Δv over the samples ending in (k, k+1] s
    let n_s = scn.trajectory.duration_s.floor() as usize;
    let mut ours = vec![[0.0; 6]; n_s];
    for s in TruthGenerator::new(&scn.trajectory, scn.truth_config()) {
        let k = ((s.t_s - 1e-9).floor()) as usize;
        if k < n_s {
            let (a, b) = (s.inc.dtheta_b_rad, s.inc.dv_b_mps);
            for (j, x) in [b.x, b.y, b.z, a.x, a.y, a.z].iter().enumerate() {
                ours[k][j] += x;
            }
        }
    }
    // imu2: mean of the samples stamped in [k, k+1) s, minus the static biases
    let (gb_sta, ab_sta) = (0.00349065850398866, 0.1569064);
    let mut theirs = vec![([0.0; 6], 0usize); n_s];
    let mut rd = csv::Reader::from_path(&imu2).unwrap();
    for r in rd.records() {
        let r = r.unwrap();
        let v: Vec<f64> = r.iter().map(|x| x.parse().unwrap()).collect();
        let k = v[0].floor() as usize;
        if k < n_s {
            for j in 0..6 {
                theirs[k].0[j] += v[1 + j] - if j < 3 { ab_sta } else { gb_sta };
            }
            theirs[k].1 += 1;
        }
    }
    let sig_a = ((0.00683536555146996f64 / 200f64.sqrt()).powi(2) + 0.000980665f64.powi(2)).sqrt();
    let sig_g = ((0.00123413414948844f64 / 200f64.sqrt()).powi(2)
        + 3.1512889272119835e-05f64.powi(2))
    .sqrt();
    let names = ["f_x", "f_y", "f_z", "w_x", "w_y", "w_z"];
    let diff = |k: usize, j: usize| theirs[k].0[j] / theirs[k].1 as f64 - ours[k][j];
    let sig = |j: usize| if j < 3 { sig_a } else { sig_g };
    // NaveGo draws a run-to-run part of the static bias on top of gb_sta/ab_sta
    // (noise_b_sta): the whole-run median of the difference estimates that constant
    let mut offset = [0.0; 6];
    for (j, o) in offset.iter_mut().enumerate() {
        let mut d: Vec<f64> = (0..n_s).map(|k| diff(k, j)).collect();
        d.sort_by(f64::total_cmp);
        *o = d[n_s / 2];
    }
    eprintln!(
        "1 s windows: {n_s}; 3σ bands: f {:.3e} m/s², ω {:.3e} rad/s",
        3.0 * sig_a,
        3.0 * sig_g
    );
    eprintln!("median difference imu2 − gb_sta/ab_sta − ours (f m/s², ω rad/s): {offset:?}");
    let mut raw_out = 0;
    let mut outside = Vec::new();
    for k in 0..n_s {
        for j in 0..6 {
            let d = diff(k, j);
            if d.abs() > 3.0 * sig(j) {
                raw_out += 1;
            }
            let r = d - offset[j];
            if r.abs() > 3.0 * sig(j) {
                outside.push((k, names[j], r, r / sig(j)));
            }
        }
    }
    eprintln!(
        "outside 3σ: {raw_out} of {} window-axes as given; after the median offset:",
        6 * n_s
    );
    for (k, n, d, z) in &outside {
        eprintln!("  [{k}, {}) s  {n}: {d:+.4e} ({z:+.1}σ)", k + 1);
    }
    eprintln!("{} of {} window-axes", outside.len(), 6 * n_s);
    for j in 0..6 {
        let nominal = if j < 3 { ab_sta } else { gb_sta };
        // the run-to-run part stays within ±10 % of the nominal static bias
        assert!(
            offset[j].abs() <= 0.1 * nominal,
            "{}: {}",
            names[j],
            offset[j]
        );
    }
    // Steady straight windows: our 1 s means equal those of both neighbours within 3σ and
    // the yaw rate is below 1°/s. There the two generators must agree to the noise: a
    // Gaussian difference leaves 0.27 % outside 3σ (allow 1 %). The others are the turns
    // (NaveGo's body-frame accelerations lag by half a sample: f_x off by ψ̇·a_y·δt/2 ≈
    // 0.354·5.5·0.0025 = 4.9e-3 m/s²) and the steps of the motion (entries and exits of
    // the turns, the start), where its velocity differencing smears the step.
    let steady = |k: usize| {
        k > 0
            && k + 1 < n_s
            && (0..6).all(|j| {
                (ours[k - 1][j] - ours[k][j]).abs() < 3.0 * sig(j)
                    && (ours[k + 1][j] - ours[k][j]).abs() < 3.0 * sig(j)
            })
            && ours[k][5].abs() < 1f64.to_radians()
    };
    let n_steady = (0..n_s).filter(|&k| steady(k)).count();
    let out_steady = outside.iter().filter(|o| steady(o.0)).count();
    eprintln!(
        "steady straight windows: {n_steady} of {n_s}; outside 3σ there: {out_steady} of {} window-axes",
        6 * n_steady
    );
    assert!(n_steady > n_s / 4, "{n_steady}");
    assert!(
        out_steady as f64 <= 0.01 * (6 * n_steady) as f64,
        "{out_steady}"
    );
}
