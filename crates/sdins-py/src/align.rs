//! `sdins.align` and `sdins.errors`: initial alignment (`sdins_sim::align::run::align`)
//! and stationary error analysis (`sdins_sim::analysis::errors_run::errors`), the library calls of
//! `sdins align` and `sdins errors`.

use crate::arrays::{matrix, vector};
use crate::error::err;
use crate::interrupt;
use crate::scenario::Scenario;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sdins_core::math::Vec3;
use sdins_sim::align::run::{
    align as align_run, AlignInput, AlignMethod, AlignOptions, AlignRunError, FineStart,
    MultiheadingAlg,
};
use sdins_sim::analysis::errors_run::{errors as errors_run, ErrorsError, ErrorsOptions};
use sdins_sim::io::imu_file::{read_imu_file, ImuFormat};
use sdins_sim::sensors::imu_error::{DPH, UG};
use std::path::PathBuf;

fn v3(v: &Vec3, unit: f64) -> Vec<f64> {
    vec![v.x / unit, v.y / unit, v.z / unit]
}

fn run_err(e: AlignRunError) -> PyErr {
    match e {
        AlignRunError::Cancelled => pyo3::exceptions::PyKeyboardInterrupt::new_err("cancelled"),
        other => err(other),
    }
}

/// Align a scenario (with run `run` of its error model) or an IMU file; see the
/// Python wrapper for the parameters. Returns a dict: the `sdins align --json` fields
/// (same units, same numbers), `c_b_n` (3, 3), `samples`, `warnings`, `sigma_z_used_mps`
/// and, for the filters, `history` (arrays per Kalman update).
#[pyfunction]
#[pyo3(signature = (scenario=None, imu=None, format=None, method=None, alg=None, start=None,
    lat_deg=None, h_m=None, window_s=None, duration_s=None, run=None, sigma_z_mps=None,
    vrw_ug_per_sqrt_hz=None, arw_deg_per_sqrt_h=None))]
#[allow(clippy::too_many_arguments)]
pub fn align<'py>(
    py: Python<'py>,
    scenario: Option<&Scenario>,
    imu: Option<PathBuf>,
    format: Option<&str>,
    method: Option<&str>,
    alg: Option<&str>,
    start: Option<&str>,
    lat_deg: Option<f64>,
    h_m: Option<f64>,
    window_s: Option<f64>,
    duration_s: Option<f64>,
    run: Option<u64>,
    sigma_z_mps: Option<f64>,
    vrw_ug_per_sqrt_hz: Option<f64>,
    arw_deg_per_sqrt_h: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = AlignOptions::default();
    let method = match method {
        None => d.method,
        Some("coarse1") => AlignMethod::Coarse1,
        Some("coarse2") => AlignMethod::Coarse2,
        Some("i0") => AlignMethod::I0,
        Some("fine") => AlignMethod::Fine,
        Some("multiheading") => AlignMethod::Multiheading,
        Some(m) => {
            return Err(err(format!(
                "method {m:?}: expected coarse1, coarse2, i0, fine or multiheading"
            )))
        }
    };
    let alg = match alg {
        None => d.alg,
        Some("a") | Some("A") => MultiheadingAlg::A,
        Some("b") | Some("B") => MultiheadingAlg::B,
        Some(a) => return Err(err(format!("alg {a:?}: expected \"a\" or \"b\""))),
    };
    let start = match start {
        None => d.start,
        Some("i0") => FineStart::I0,
        Some("coarse2") => FineStart::Coarse2,
        Some(s) => return Err(err(format!("start {s:?}: expected \"i0\" or \"coarse2\""))),
    };
    let opts = AlignOptions {
        method,
        alg,
        start,
        window_s: window_s.unwrap_or(d.window_s),
        duration_s,
        sigma_z_mps: sigma_z_mps.unwrap_or(d.sigma_z_mps),
        vrw_ug_per_sqrt_hz,
        arw_deg_per_sqrt_h,
    };
    sdins_sim::align::run::check_options(&opts).map_err(run_err)?;
    let fmt: ImuFormat = format.unwrap_or("auto").parse().map_err(err)?;
    let scn = scenario.map(|s| s.scn.clone());
    let (inp, res) = interrupt::run(py, |tok| -> Result<_, PyErr> {
        let inp = match (&scn, &imu) {
            (Some(_), Some(_)) => return Err(err("give either a scenario or imu=, not both")),
            (None, None) => {
                return Err(err(
                    "nothing to align: give a scenario (e.g. \"alignment\") or imu=PATH",
                ))
            }
            (Some(s), None) => {
                AlignInput::from_scenario(s, run.unwrap_or(0), lat_deg).map_err(run_err)?
            }
            (None, Some(p)) => {
                let data = read_imu_file(p, fmt).map_err(err)?;
                AlignInput::from_imu_data(&p.display().to_string(), data, lat_deg, h_m)
                    .map_err(run_err)?
            }
        };
        let res = align_run(&inp, &opts, tok).map_err(run_err)?;
        Ok((inp, res))
    })??;
    let out = PyDict::new(py);
    let e = res.euler;
    out.set_item("method", &res.method)?;
    out.set_item("roll_deg", e.roll_rad.to_degrees())?;
    out.set_item("pitch_deg", e.pitch_rad.to_degrees())?;
    out.set_item("yaw_deg", e.yaw_rad.to_degrees())?;
    let c = res.c_b_n;
    let cm: Vec<f64> = (0..3)
        .flat_map(|i| (0..3).map(move |j| c[(i, j)]))
        .collect();
    out.set_item("c_b_n", matrix(py, cm, 3)?)?;
    let opt3 = |v: Option<Vec3>, unit: f64| v.map(|v| v3(&v, unit));
    out.set_item("accel_bias_ug", opt3(res.accel_bias.map(|b| b.0), UG))?;
    out.set_item("accel_bias_sigma_ug", opt3(res.accel_bias.map(|b| b.1), UG))?;
    out.set_item("gyro_bias_dph", opt3(res.gyro_bias.map(|b| b.0), DPH))?;
    out.set_item("gyro_bias_sigma_dph", opt3(res.gyro_bias.map(|b| b.1), DPH))?;
    out.set_item("attitude_sigma_urad", opt3(res.attitude_sigma, 1e-6))?;
    out.set_item("phi_urad", opt3(res.phi_true, 1e-6))?;
    out.set_item("true_accel_bias_ug", opt3(inp.true_bias.map(|b| b.0), UG))?;
    out.set_item("true_gyro_bias_dph", opt3(inp.true_bias.map(|b| b.1), DPH))?;
    out.set_item("samples", res.samples)?;
    out.set_item("dt_s", inp.dt_s)?;
    out.set_item("lat_deg", inp.lat_deg)?;
    out.set_item("h_m", inp.h_m)?;
    out.set_item("g_mps2", inp.site.g_mps2)?;
    out.set_item("sigma_z_used_mps", res.sigma_z_used_mps)?;
    out.set_item("warnings", res.warnings.clone())?;
    if res.has_history {
        let h = &res.history;
        let n = h.len();
        let col = |f: &dyn Fn(&sdins_sim::align::run::AlignHistoryRow) -> f64| {
            h.iter().map(f).collect::<Vec<f64>>()
        };
        let mat = |f: &dyn Fn(&sdins_sim::align::run::AlignHistoryRow) -> Vec3, unit: f64| {
            let mut v = Vec::with_capacity(3 * n);
            for r in h {
                v.extend(v3(&f(r), unit));
            }
            v
        };
        let hd = PyDict::new(py);
        hd.set_item("t_s", vector(py, col(&|r| r.t_s)))?;
        let mut eul = Vec::with_capacity(3 * n);
        for r in h {
            eul.extend([
                r.euler.roll_rad.to_degrees(),
                r.euler.pitch_rad.to_degrees(),
                r.euler.yaw_rad.to_degrees(),
            ]);
        }
        hd.set_item("euler_deg", matrix(py, eul, 3)?)?;
        hd.set_item(
            "attitude_sigma_urad",
            matrix(py, mat(&|r| r.attitude_sigma, 1e-6), 3)?,
        )?;
        hd.set_item(
            "accel_bias_ug",
            matrix(py, mat(&|r| r.accel_bias_b, UG), 3)?,
        )?;
        hd.set_item(
            "accel_bias_sigma_ug",
            matrix(py, mat(&|r| r.accel_bias_sigma_b, UG), 3)?,
        )?;
        hd.set_item(
            "gyro_bias_dph",
            matrix(py, mat(&|r| r.gyro_bias_b, DPH), 3)?,
        )?;
        hd.set_item(
            "gyro_bias_sigma_dph",
            matrix(py, mat(&|r| r.gyro_bias_sigma_b, DPH), 3)?,
        )?;
        if h.iter().all(|r| r.phi_true.is_some()) && n > 0 {
            hd.set_item(
                "phi_urad",
                matrix(py, mat(&|r| r.phi_true.unwrap_or_default(), 1e-6), 3)?,
            )?;
        } else {
            hd.set_item("phi_urad", py.None())?;
        }
        out.set_item("history", hd)?;
    } else {
        out.set_item("history", py.None())?;
    }
    Ok(out)
}

/// Stationary error analysis; returns `(report_json, t_s, dp_n_m, sigma_p_m, budget)`:
/// the `sdins errors --json` text, the linear model every 10 s (position error N, E, D and
/// its 1σ [m]) and the budget rows.
#[pyfunction]
#[pyo3(signature = (grade=None, gyro_bias_dph=None, accel_bias_ug=None, hours=None,
    lat_deg=None, nonlinear=None))]
pub fn errors<'py>(
    py: Python<'py>,
    grade: Option<String>,
    gyro_bias_dph: Option<Vec<f64>>,
    accel_bias_ug: Option<Vec<f64>>,
    hours: Option<f64>,
    lat_deg: Option<f64>,
    nonlinear: Option<bool>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = ErrorsOptions::default();
    let o = ErrorsOptions {
        grade,
        gyro_bias_dph,
        accel_bias_ug,
        hours: hours.unwrap_or(d.hours),
        lat_deg: lat_deg.unwrap_or(d.lat_deg),
        nonlinear: nonlinear.unwrap_or(d.nonlinear),
    };
    let out = interrupt::run(py, |tok| errors_run(&o, tok))?.map_err(|e| match e {
        ErrorsError::Cancelled => pyo3::exceptions::PyKeyboardInterrupt::new_err("cancelled"),
        other => err(other),
    })?;
    let json = serde_json::to_string(&out.report).map_err(err)?;
    let res = PyDict::new(py);
    res.set_item("report_json", json)?;
    let env = &out.envelope;
    res.set_item("t_s", vector(py, env.iter().map(|e| e.t_s).collect()))?;
    res.set_item(
        "dp_n_m",
        matrix(py, env.iter().flat_map(|e| e.dp_n_m).collect(), 3)?,
    )?;
    res.set_item(
        "sigma_p_m",
        matrix(py, env.iter().flat_map(|e| e.sigma_p_m).collect(), 3)?,
    )?;
    let budget: Vec<(String, String, [f64; 2])> = out
        .budget
        .iter()
        .map(|b| (b.source.clone(), b.value.clone(), b.dp_ne_m))
        .collect();
    res.set_item("budget", budget)?;
    Ok(res)
}

/// The Schuler-share table (`sdins errors --schuler-share --json`) as JSON text.
#[pyfunction]
pub fn schuler_share_json() -> PyResult<String> {
    serde_json::to_string(
        &sdins_sim::analysis::error_analysis::schuler_share::schuler_share_table_p2(),
    )
    .map_err(err)
}

/// Turntable calibration (`sdins calibrate`, `sdins_sim::align::calibration::request`):
/// the `--json` summary as JSON text (the wrapper parses it).
#[pyfunction]
#[pyo3(signature = (scenario, imu=None, imu_format=None, run=None, runs=None, draw_scale_ppm=None, draw_misalignment_mrad=None, draw=None))]
#[allow(clippy::too_many_arguments)]
pub fn calibrate(
    py: Python<'_>,
    scenario: &Scenario,
    imu: Option<PathBuf>,
    imu_format: Option<&str>,
    run: Option<u64>,
    runs: Option<usize>,
    draw_scale_ppm: Option<(f64, f64)>,
    draw_misalignment_mrad: Option<(f64, f64)>,
    draw: Option<bool>,
) -> PyResult<String> {
    use sdins_sim::align::calibration::request::{calibrate as cal, CalibrateRequest};
    use sdins_sim::align::calibration::run::CalibrationError;
    use sdins_sim::align::calibration::DrawSpec;
    let d = DrawSpec::DEFAULT;
    let req = CalibrateRequest {
        imu,
        imu_format: imu_format
            .unwrap_or("auto")
            .parse::<ImuFormat>()
            .map_err(err)?,
        run: run.unwrap_or(0),
        runs: runs.unwrap_or(1),
        draw: draw.unwrap_or(true).then_some(DrawSpec {
            scale_ppm: draw_scale_ppm.unwrap_or(d.scale_ppm),
            misalignment_mrad: draw_misalignment_mrad.unwrap_or(d.misalignment_mrad),
        }),
    };
    let scn = &scenario.scn;
    let res = interrupt::run(py, |tok| cal(scn, &req, tok))?.map_err(|e| match e {
        CalibrationError::Cancelled(_) => {
            pyo3::exceptions::PyKeyboardInterrupt::new_err("cancelled")
        }
        CalibrationError::Draw { key, what } => err(format!("draw_{key}: {what}")),
        other => err(other),
    })?;
    serde_json::to_string(&res.summary_json(scn)).map_err(err)
}
