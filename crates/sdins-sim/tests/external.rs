//! External-data acceptance of the mechanizations: PSINS trajectories with the
//! PSINS constant set, the smsfusion coning/sculling fixture (flat earth), and real MEMS
//! data from the BROAD data set. Files are read in place from `../shared/data`; the tests
//! skip with a printed reason only when that folder is absent.
#![allow(clippy::unwrap_used)]
use sdins_core::coning::{ConingSet, Increment};
use sdins_core::earth::EarthModel;
use sdins_core::math::{attitude_error, c_b_n_from_euler, Euler, Quat, Vec3};
use sdins_core::nav::{AlgorithmKind, AlgorithmSpec, InitialState};
use sdins_sim::io::imu_file::{read_imu_file, ImuFormat};
use sdins_sim::io::truth_file::{c_b_n_from_psins, read_psins_avp};
use sdins_sim::nav::pipeline::{nav_error, navigate_recorded, NavError};
use std::path::PathBuf;

mod common;
use common::shared_data as data;

const ARCSEC: f64 = std::f64::consts::PI / 180.0 / 3600.0;

/// Navigate a PSINS trj case with the PSINS earth model; errors at the truth epochs.
fn psins_case(name: &str, spec: AlgorithmSpec) -> Option<Vec<NavError>> {
    let imu = read_imu_file(
        &data(&format!("csv/psins/{name}_imu.csv"))?,
        ImuFormat::PsinsCsv,
    )
    .unwrap();
    let truth = read_psins_avp(&data(&format!("csv/psins/{name}_avp.csv"))?).unwrap();
    let a0: Vec<f64> = std::fs::read_to_string(data(&format!("csv/psins/{name}_avp0.csv"))?)
        .unwrap()
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|x| x.trim().parse().unwrap())
        .collect();
    let init = InitialState {
        lat_rad: a0[6],
        lon_rad: a0[7],
        h_m: a0[8],
        v_n_mps: Vec3::new(a0[4], a0[3], -a0[5]),
        c_b_n: c_b_n_from_psins(a0[0], a0[1], a0[2]),
    };
    let earth = EarthModel::PSINS;
    let mut errs = Vec::new();
    let mut k = 0;
    navigate_recorded(&spec, earth, imu.dt_s, &init, &imu.increments, |st| {
        if let Some(tr) = truth.get(k) {
            errs.push(nav_error(&earth, st, tr));
        }
        k += spec.samples;
    });
    Some(errs)
}

fn slc1() -> AlgorithmSpec {
    // one sample per update with the previous-sample coning/sculling term, as PSINS's own
    // single-subsample mechanization
    let mut s = AlgorithmSpec::new(AlgorithmKind::SongLeeComplete, 1);
    s.coning = ConingSet::OnePrev;
    s
}

fn check_psins(e: &NavError, what: &str) {
    let att = e.att_err_rad.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    let vel = e
        .vel_err_ned_mps
        .iter()
        .fold(0.0_f64, |a, b| a.max(b.abs()));
    let hor = e.pos_err_ned_m[0].hypot(e.pos_err_ned_m[1]);
    eprintln!(
        "{what} t={}: att {:.4} arcsec, vel {:.3} mm/s, horizontal {:.3} m",
        e.t_s,
        att / ARCSEC,
        vel * 1e3,
        hor
    );
    assert!(
        att <= 0.1 * ARCSEC,
        "{what}: attitude {} arcsec",
        att / ARCSEC
    );
    assert!(vel <= 1e-3, "{what}: velocity {vel} m/s");
    assert!(hor <= 0.5, "{what}: horizontal {hor} m");
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn psins_trj10ms_at_900s() {
    for spec in [slc1(), {
        let mut d = slc1();
        d.kind = AlgorithmKind::DualQuat;
        d
    }] {
        let Some(errs) = psins_case("trj10ms", spec) else {
            return;
        };
        let e = errs.iter().find(|e| (e.t_s - 900.0).abs() < 1e-6).unwrap();
        check_psins(e, &format!("trj10ms {}", spec.kind.name()));
    }
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn psins_trj_transfer_at_end() {
    let Some(errs) = psins_case("trj_transfer", slc1()) else {
        return;
    };
    check_psins(errs.last().unwrap(), "trj_transfer");
}

fn read_csv(path: &PathBuf) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|x| x.trim().parse::<f64>().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    (head, rows)
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn smsfusion_coning_sculling_attitude_at_8s() {
    // 200 Hz rates on a flat NED earth with g = 9.80665; increments by the trapezoid rule
    // (its error O(δt³ω̈) ≈ 1e-8 rad per sample here), truth from the fixture.
    let Some(p) = data("smsfusion_coning_sculling/coning_sculling_sim_highfreq_20251218A.csv")
    else {
        return;
    };
    let (head, rows) = read_csv(&p);
    let col = |n: &str| head.iter().position(|h| h == n).unwrap();
    let (gx, ax, r, vx) = (
        col("Gx_rads"),
        col("Ax_ms2"),
        col("Roll_rad"),
        col("VelX_ms"),
    );
    let dt = rows[1][0] - rows[0][0];
    let incs: Vec<Increment> = rows
        .windows(2)
        .map(|w| {
            let g = |i: usize| Vec3::new(w[i][gx], w[i][gx + 1], w[i][gx + 2]);
            let a = |i: usize| Vec3::new(w[i][ax], w[i][ax + 1], w[i][ax + 2]);
            Increment::new((g(0) + g(1)) * 0.5 * dt, (a(0) + a(1)) * 0.5 * dt)
        })
        .collect();
    let eul = |row: &Vec<f64>| c_b_n_from_euler(&Euler::new(row[r], row[r + 1], row[r + 2]));
    let init = InitialState {
        lat_rad: 0.5,
        lon_rad: 0.1,
        h_m: 0.0,
        v_n_mps: Vec3::new(rows[0][vx], rows[0][vx + 1], rows[0][vx + 2]),
        c_b_n: eul(&rows[0]),
    };
    for kind in [AlgorithmKind::SongLeeComplete, AlgorithmKind::DualQuat] {
        let spec = AlgorithmSpec::new(kind, 2);
        let mut worst = 0.0_f64;
        let mut k = 0;
        navigate_recorded(&spec, EarthModel::flat(9.806_65), dt, &init, &incs, |st| {
            k += 2;
            let t = rows[k][0];
            if (t - 8.0).abs() < 1e-9 {
                let e = attitude_error(&st.c_b_n, &eul(&rows[k]));
                worst = e.norm();
            }
        });
        eprintln!(
            "smsfusion {}: attitude error at 8 s {:.3e} deg",
            kind.name(),
            worst.to_degrees()
        );
        assert!(
            worst.to_degrees() <= 1e-3,
            "{}: {} deg",
            kind.name(),
            worst.to_degrees()
        );
        assert!(worst > 0.0);
    }
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn broad_mems_gyro_only_attitude_at_10s() {
    // Real MEMS (BROAD trials 02, 07): gyro-only attitude over the first 10 s of optical
    // truth, the gyro bias being the mean of the second of gyro data just before (at rest),
    // the initial attitude the mean optical quaternion over 0.25 s. Bound from theory: the
    // 1 s bias estimate has σ_b = σ_ω/√n (σ_ω from the same second), so after 10 s the
    // drift is within 3σ_b·10 s; the optical truth adds its own sample jitter σ_q (twice:
    // start and end). The bar is 0.2°. (A bias taken from the first second of the
    // file instead, seconds earlier, leaves 0.23° on trial 07: the MEMS bias drifts.)
    for trial in [
        "02_undisturbed_slow_rotation_B",
        "07_undisturbed_fast_rotation_B",
    ] {
        let Some(p) = data(&format!("csv/broad/{trial}.csv")) else {
            return;
        };
        let (head, rows) = read_csv(&p);
        let col = |n: &str| head.iter().position(|h| h == n).unwrap();
        let (g, q) = (col("gyr_x_radps"), col("q_w"));
        let dt = rows[1][0] - rows[0][0];
        let rate = |row: &Vec<f64>| Vec3::new(row[g], row[g + 1], row[g + 2]);
        let quat = |row: &Vec<f64>| {
            let qq = Quat::new(row[q], row[q + 1], row[q + 2], row[q + 3]).normalized();
            if qq.w < 0.0 {
                qq.scale(-1.0)
            } else {
                qq
            }
        };
        let n_bias = (1.0 / dt).round() as usize;
        let start = (n_bias..rows.len())
            .find(|&i| !rows[i][q].is_nan())
            .unwrap();
        // the second of gyro data just before the start (the vehicle is at rest there)
        let win = &rows[start - n_bias..start];
        let bias = win.iter().map(rate).sum::<Vec3>() / n_bias as f64;
        let var = win
            .iter()
            .map(|r| (rate(r) - bias).norm_squared())
            .sum::<f64>()
            / (n_bias - 1) as f64;
        let sigma_b = (var / n_bias as f64).sqrt(); // 3-axis RMS of the mean [rad/s]
        let mean_q = |a: usize, b: usize| {
            let mut acc = Quat::new(0.0, 0.0, 0.0, 0.0);
            for r in &rows[a..b] {
                if !r[q].is_nan() {
                    acc = acc.add(&quat(r));
                }
            }
            acc.normalized()
        };
        let w = (0.25 / dt).round() as usize;
        let q0 = mean_q(start, start + w);
        // jitter of the optical truth: RMS angle of single samples about that mean
        let jit: Vec<f64> = rows[start..start + w]
            .iter()
            .filter(|r| !r[q].is_nan())
            .map(|r| q0.conj().mul(&quat(r)).to_rotvec().norm())
            .collect();
        let sigma_q = (jit.iter().map(|x| x * x).sum::<f64>() / jit.len() as f64).sqrt();
        let mid = start + w / 2; // the epoch that the averaged start attitude represents
        let end = mid + (10.0 / dt).round() as usize;
        let mut est = q0;
        for k in mid..end {
            let dth = (rate(&rows[k]) + rate(&rows[k + 1]) - 2.0 * bias) * 0.5 * dt;
            est = est.mul(&Quat::from_rotvec(&dth)).normalized();
        }
        let truth = mean_q(end - w / 2, end + w / 2);
        let err = truth.conj().mul(&est).to_rotvec().norm();
        let bound = 3.0 * sigma_b * 10.0 + 2.0 * sigma_q;
        eprintln!(
            "BROAD {trial}: error after 10 s = {:.3} deg (bias-noise bound {:.3} deg: σ_b {:.2e} rad/s, truth jitter {:.3} deg)",
            err.to_degrees(), bound.to_degrees(), sigma_b, sigma_q.to_degrees()
        );
        assert!(
            err <= bound,
            "{trial}: {} deg > {} deg",
            err.to_degrees(),
            bound.to_degrees()
        );
        assert!(err.to_degrees() <= 0.2, "{trial}: {} deg", err.to_degrees());
    }
}
