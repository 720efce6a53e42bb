//! `sdins.corrupt`, `sdins.read_imu`, `sdins.allan`: sensor errors, IMU files, Allan
//! deviation (imu-errors.md, imu-files.md, IEEE Std 952).

use crate::arrays::{from_increments, increments, matrix, vector};
use crate::error::err;
use crate::interrupt;
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use sdins_sim::io::imu_file::ImuFormat;
use sdins_sim::sensors::imu_error::ImuErrorModel;
use std::path::PathBuf;

/// A Python value of an `errors=` dict as TOML (numbers, strings, lists of numbers).
fn to_toml(key: &str, v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if let Ok(b) = v.extract::<bool>() {
        return Ok(toml::Value::Boolean(b));
    }
    if let Ok(i) = v.extract::<i64>() {
        return Ok(toml::Value::Integer(i));
    }
    if let Ok(f) = v.extract::<f64>() {
        return Ok(toml::Value::Float(f));
    }
    if let Ok(s) = v.extract::<String>() {
        return Ok(toml::Value::String(s));
    }
    if let Ok(seq) = v.extract::<Vec<f64>>() {
        return Ok(toml::Value::Array(
            seq.into_iter().map(toml::Value::Float).collect(),
        ));
    }
    Err(err(format!(
        "errors[{key:?}]: expected a number, a string or a sequence of numbers"
    )))
}

/// The error model: `errors` (keys of `[imu.errors]`, docs/scenarios.md, optionally
/// with `preset`) over the `grade` preset, or the grade alone.
pub fn model(grade: Option<&str>, errors: Option<&Bound<'_, PyDict>>) -> PyResult<ImuErrorModel> {
    let table = match errors {
        None => None,
        Some(d) => {
            let mut t = toml::Table::new();
            for (k, v) in d.iter() {
                let key: String = k.extract()?;
                let val = to_toml(&key, &v)?;
                t.insert(key, val);
            }
            Some(t)
        }
    };
    match (grade, table) {
        (None, None) => Err(err("corrupt: give grade= or errors=")),
        (Some(g), None) => ImuErrorModel::preset(g).map_err(|e| err(format!("grade: {e}"))),
        (None, Some(t)) => ImuErrorModel::from_table(&t).map_err(|e| err(format!("errors: {e}"))),
        (Some(g), Some(t)) => ImuErrorModel::preset(g)
            .map_err(|e| err(format!("grade: {e}")))?
            .with_overrides(&t)
            .map_err(|e| err(format!("errors: {e}"))),
    }
}

/// Corrupt exact increments with run `run` of an error model (imu-errors.md).
#[pyfunction]
#[pyo3(signature = (dtheta, dv, dt, grade=None, errors=None, seed=None, run=None))]
#[allow(clippy::too_many_arguments)]
pub fn corrupt<'py>(
    py: Python<'py>,
    dtheta: PyReadonlyArray2<'py, f64>,
    dv: PyReadonlyArray2<'py, f64>,
    dt: f64,
    grade: Option<&str>,
    errors: Option<&Bound<'py, PyDict>>,
    seed: Option<u64>,
    run: Option<u64>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(err(format!(
            "dt {dt}: expected a positive number of seconds"
        )));
    }
    let m = model(grade, errors)?;
    let incs = increments(&dtheta, &dv)?;
    let (seed, run) = (seed.unwrap_or(1), run.unwrap_or(0));
    let out = interrupt::run(py, |_| {
        sdins_sim::align::experiment::corrupt(&incs, dt, &m, seed, run)
    })?
    .map_err(err)?;
    from_increments(py, &out)
}

/// Read an IMU file (sdins CSV, PSINS .imu / trj CSV, KF-GINS, NaveGo) into FRD arrays.
#[pyfunction]
#[pyo3(signature = (path, format=None, columns=None, profile=None))]
pub fn read_imu<'py>(
    py: Python<'py>,
    path: PathBuf,
    format: Option<&str>,
    columns: Option<String>,
    profile: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let fmt: ImuFormat = format.unwrap_or("auto").parse().map_err(err)?;
    // a column map (`columns=`, the CLI's --imu-columns) or a profile's [imu] map
    let with_profile = profile.is_some();
    let cols = sdins_sim::fusion::files::ColumnOptions {
        imu_columns: columns,
        profile,
        ..Default::default()
    }
    .resolve(&|n: &str| {
        if n == "imu_columns" {
            "columns".into()
        } else {
            n.to_string()
        }
    })
    .map_err(err)?
    .imu;
    if with_profile && cols.is_none() {
        return Err(err("profile: the profile has no [imu] map"));
    }
    let (data, rep) = interrupt::run(py, |_| {
        sdins_sim::io::imu_columns::read_imu_any(&path, fmt, cols.as_ref())
    })?
    .map_err(err)?;
    let d = PyDict::new(py);
    if let Some(r) = rep {
        d.set_item("input", r.summary())?;
    }
    let (a, b) = from_increments(py, &data.increments)?;
    let n = data.increments.len();
    let t: Vec<f64> = (0..n).map(|k| data.t0_s + k as f64 * data.dt_s).collect();
    d.set_item("format", data.format.name())?;
    d.set_item("dt_s", data.dt_s)?;
    d.set_item("t0_s", data.t0_s)?;
    d.set_item("t_s", vector(py, t))?;
    d.set_item("dtheta_rad", a)?;
    d.set_item("dv_mps", b)?;
    if let Some(h) = &data.psins {
        let hd = PyDict::new(py);
        hd.set_item("lat_deg", h.lat_deg)?;
        hd.set_item("lon_deg", h.lon_deg)?;
        hd.set_item("h_m", h.h_m)?;
        hd.set_item("vel0_enu_mps", h.vel0_enu_mps.to_vec())?;
        hd.set_item("att0_deg", h.att0_deg.to_vec())?;
        d.set_item("psins_header", hd)?;
    }
    Ok(d)
}

/// Overlapping Allan deviation of the six channels of increments with period `dt`, and
/// the IEEE Std 952 fits (SI units: rad/s, m/s²).
#[pyfunction]
pub fn allan<'py>(
    py: Python<'py>,
    dtheta: PyReadonlyArray2<'py, f64>,
    dv: PyReadonlyArray2<'py, f64>,
    dt: f64,
) -> PyResult<Bound<'py, PyDict>> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(err(format!(
            "dt {dt}: expected a positive number of seconds"
        )));
    }
    let incs = increments(&dtheta, &dv)?;
    let rep = interrupt::run(py, |_| sdins_sim::analysis::allan::analyse(&incs, dt))?;
    let d = PyDict::new(py);
    let tau = rep
        .curves
        .first()
        .map(|c| c.tau_s.clone())
        .unwrap_or_default();
    let m = tau.len();
    let mut adev = Vec::with_capacity(m * 6);
    for k in 0..m {
        for c in &rep.curves {
            adev.push(c.adev.get(k).copied().unwrap_or(f64::NAN));
        }
    }
    d.set_item("tau_s", vector(py, tau))?;
    d.set_item("adev", matrix(py, adev, 6)?)?;
    d.set_item("warnings", rep.warnings())?;
    let fits = PyList::empty(py);
    for f in &rep.fits {
        let fd = PyDict::new(py);
        fd.set_item("white", f.white)?;
        fd.set_item("white_tau_s", f.white_tau_s)?;
        fd.set_item("bias_instability", f.bias_instability)?;
        fd.set_item("bias_instability_tau_s", f.bias_instability_tau_s)?;
        fd.set_item("quantization", f.quantization)?;
        fd.set_item("rate_random_walk", f.rate_random_walk)?;
        fits.append(fd)?;
    }
    d.set_item("fits", fits)?;
    Ok(d)
}
