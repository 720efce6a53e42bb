//! Shared helpers for the integration tests.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use sdins_core::coning::ConingSet;
use sdins_core::nav::{AlgorithmKind, AlgorithmSpec, AttitudeMode};
use sdins_sim::nav::pipeline::{run, NavError, RunOptions, RunSummary};
use sdins_sim::scenario::Scenario;

/// `rel` under `../shared/data` (read in place), or `None` with the printed reason when
/// that folder is absent (a user's clone); in CI it is present and the tests run.
pub fn shared_data(rel: &str) -> Option<std::path::PathBuf> {
    let p = std::path::PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/"
    ))
    .join(rel);
    if p.exists() {
        Some(p)
    } else {
        eprintln!(
            "skipped: {} not present (../shared/data is absent in this checkout)",
            p.display()
        );
        None
    }
}

pub fn spec(kind: AlgorithmKind, n: usize) -> AlgorithmSpec {
    AlgorithmSpec::new(kind, n)
}

pub fn with(
    mut s: AlgorithmSpec,
    coning: Option<ConingSet>,
    att: Option<AttitudeMode>,
    rot3: Option<bool>,
) -> AlgorithmSpec {
    if let Some(c) = coning {
        s.coning = c;
    }
    s.attitude = att.or(s.attitude);
    s.rot3 = rot3.or(s.rot3);
    s
}

/// Run and collect the errors at the given epochs (seconds).
pub fn run_at(
    scn: &Scenario,
    algos: Vec<AlgorithmSpec>,
    epochs: &[f64],
    hold: bool,
) -> (Vec<RunSummary>, Vec<Vec<NavError>>) {
    let n = algos[0].samples;
    let dt_u = scn.imu.dt_s() * n as f64;
    let mut got = vec![Vec::new(); algos.len()];
    let until = epochs.iter().copied().fold(0.0, f64::max);
    let opts = RunOptions {
        algos,
        vertical_hold: hold,
        every_s: None,
        sensor_run: None,
        until_s: Some(until),
    };
    let want: Vec<u64> = epochs.iter().map(|t| (t / dt_u).round() as u64).collect();
    let summ = run(
        scn,
        &opts,
        |i, _st, tr, e| {
            let k = (tr.t_s / dt_u).round() as u64;
            if want.contains(&k) {
                got[i].push(*e);
            }
        },
        |_, _| {},
    )
    .unwrap();
    (summ, got)
}

/// Signed comparison within a relative tolerance.
pub fn check_rel(what: &str, got: f64, want: f64, rel: f64) {
    let ok = (got - want).abs() <= rel * want.abs();
    assert!(
        ok,
        "{what}: got {got:.6e}, want {want:.6e} ±{:.0}%",
        rel * 100.0
    );
}

pub fn print(name: &str, e: &NavError) {
    eprintln!(
        "{name:>24} t={:7.1} pos {:+.4e} {:+.4e} {:+.4e} vel {:+.4e} {:+.4e} {:+.4e} att {:+.4e} {:+.4e} {:+.4e} h {:+.3e} eul {:+.3e} {:+.3e} {:+.3e}",
        e.t_s, e.pos_err_ned_m[0], e.pos_err_ned_m[1], e.pos_err_ned_m[2], e.vel_err_ned_mps[0], e.vel_err_ned_mps[1], e.vel_err_ned_mps[2],
        e.att_err_rad[0], e.att_err_rad[1], e.att_err_rad[2], e.height_err_m, e.euler_err_rad[0], e.euler_err_rad[1], e.euler_err_rad[2]
    );
}
