//! `sdins.fuse`: the loosely coupled INS/GNSS filter on a scenario
//! (`sdins_sim::fuse::fuse_scenario`, the library call of `sdins fuse`).

use crate::arrays::{matrix, vector};
use crate::error::err;
use crate::interrupt;
use crate::scenario::Scenario;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sdins_core::aiding::ekf::MeasKind;
use sdins_core::aiding::error_model::{I_ATT, I_POS, I_VEL};
use sdins_core::nav::AlgorithmSpec;
use sdins_sim::fuse::{fuse_scenario, FuseError, FuseEvent, FuseOptions};

/// Number of filter states.
const NX: usize = 15;

/// Run the filter; see the Python wrapper for parameters and the returned dict.
#[pyfunction]
#[pyo3(signature = (scenario, algo=None, samples=None, run=None, cov_rate_hz=None,
    gate=None, exact_start=None, zupt_sigma_mps=None, nhc_sigma_mps=None, until_s=None))]
#[allow(clippy::too_many_arguments)]
pub fn fuse<'py>(
    py: Python<'py>,
    scenario: &Scenario,
    algo: Option<&str>,
    samples: Option<usize>,
    run: Option<u64>,
    cov_rate_hz: Option<f64>,
    gate: Option<bool>,
    exact_start: Option<bool>,
    zupt_sigma_mps: Option<f64>,
    nhc_sigma_mps: Option<f64>,
    until_s: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let scn = scenario.scn.clone();
    let d = FuseOptions::default();
    let samples = samples.unwrap_or(scn.nav.samples);
    if !(1..=4).contains(&samples) {
        return Err(err(format!("samples: must be 1..4, got {samples}")));
    }
    let algo = match algo {
        None => AlgorithmSpec::new(d.algo.kind, samples),
        Some(a) => AlgorithmSpec::from_name(a, samples)
            .ok_or_else(|| err(format!("algo: unknown algorithm `{a}`")))?,
    };
    for (name, v) in [
        ("cov_rate_hz", cov_rate_hz),
        ("zupt_sigma_mps", zupt_sigma_mps),
        ("nhc_sigma_mps", nhc_sigma_mps),
        ("until_s", until_s),
    ] {
        if let Some(x) = v {
            if !(x.is_finite() && x > 0.0) {
                return Err(err(format!("{name}: must be finite and > 0, got {x}")));
            }
        }
    }
    let opts = FuseOptions {
        algo,
        cov_rate_hz: cov_rate_hz.unwrap_or(d.cov_rate_hz),
        draw_initial_errors: exact_start.map_or(d.draw_initial_errors, |e| !e),
        gate_chi2: match gate {
            None => d.gate_chi2,
            Some(false) => None,
            Some(true) => Some(sdins_core::aiding::ekf::CHI2_999),
        },
        zupt: zupt_sigma_mps.map(|s| (s, 1e-3)),
        nhc_sigma_mps,
        until_s,
        ..d
    };
    let gnss = scn.gnss.clone().unwrap_or_default();
    let run = run.unwrap_or(0);
    #[derive(Default)]
    struct Acc {
        t: Vec<f64>,
        err: Vec<f64>,
        pos_m: Vec<f64>,
        vel_mps: Vec<f64>,
        att_rad: Vec<f64>,
        sigma: Vec<f64>,
        nees: Vec<f64>,
        it: Vec<f64>,
        kind: Vec<&'static str>,
        dof: Vec<usize>,
        nis: Vec<f64>,
        accepted: Vec<bool>,
        forced: Vec<bool>,
        nu: Vec<f64>,
    }
    let (acc, s) = interrupt::run(py, |tok| {
        let mut a = Acc::default();
        let r = fuse_scenario(&scn, &gnss, &opts, run, tok, |ev| match ev {
            FuseEvent::Epoch(e) => {
                a.t.push(e.t_s);
                a.err.extend(e.err.iter());
                a.pos_m.extend(e.nav.pos_err_ned_m);
                a.vel_mps.extend(e.nav.vel_err_ned_mps);
                a.att_rad.extend(e.nav.att_err_rad);
                a.sigma.extend((0..NX).map(|i| e.sigma(i)));
                a.nees.extend([
                    e.nees_block(I_POS),
                    e.nees_block(I_VEL),
                    e.nees_block(I_ATT),
                ]);
            }
            FuseEvent::Update(u) => {
                a.it.push(u.t_s);
                a.kind.push(match u.kind {
                    MeasKind::Gnss => "gnss",
                    MeasKind::Zupt => "zupt",
                    MeasKind::Nhc => "nhc",
                    _ => "other",
                });
                a.dof.push(u.dof);
                a.nis.push(u.nis);
                a.accepted.push(u.accepted);
                a.forced.push(u.forced);
                a.nu.extend(u.innovation);
            }
            // smoothed epochs (RTS) are not requested by these options
            _ => {}
        });
        r.map(|s| (a, s))
    })?
    .map_err(|e| match e {
        FuseError::Cancelled(_) => pyo3::exceptions::PyKeyboardInterrupt::new_err("cancelled"),
        other => err(other),
    })?;
    let out = PyDict::new(py);
    out.set_item("t_s", vector(py, acc.t))?;
    out.set_item("error", matrix(py, acc.err, NX)?)?;
    out.set_item("pos_error_ned_m", matrix(py, acc.pos_m, 3)?)?;
    out.set_item("vel_error_ned_mps", matrix(py, acc.vel_mps, 3)?)?;
    out.set_item("att_error_rad", matrix(py, acc.att_rad, 3)?)?;
    out.set_item("sigma", matrix(py, acc.sigma, NX)?)?;
    out.set_item("nees", matrix(py, acc.nees, 3)?)?;
    let inn = PyDict::new(py);
    inn.set_item("t_s", vector(py, acc.it))?;
    inn.set_item("kind", acc.kind)?;
    inn.set_item("dof", acc.dof)?;
    inn.set_item("nis", vector(py, acc.nis))?;
    inn.set_item("accepted", acc.accepted)?;
    inn.set_item("forced", acc.forced)?;
    inn.set_item("innovation", matrix(py, acc.nu, 6)?)?;
    out.set_item("innovations", inn)?;
    let v3 = |v: &sdins_core::math::Vec3| vec![v.x, v.y, v.z];
    out.set_item("fixes", s.fixes)?;
    out.set_item("rejected", s.rejected)?;
    out.set_item("nav_updates", s.nav_updates)?;
    out.set_item("accel_bias_est_mps2", v3(&s.est_bias.0))?;
    out.set_item("accel_bias_true_mps2", v3(&s.true_bias.0))?;
    out.set_item("gyro_bias_est_rps", v3(&s.est_bias.1))?;
    out.set_item("gyro_bias_true_rps", v3(&s.true_bias.1))?;
    out.set_item("samples", samples)?;
    out.set_item("run", run)?;
    Ok(out)
}
