//! `sdins.truth`: the exact truth trajectory and IMU increments as arrays.

use crate::arrays::{matrix, vector};
use crate::error::err;
use crate::interrupt;
use crate::scenario::Scenario;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sdins_core::coning::Increment;
use sdins_core::math::{euler_from_c_b_n, Quat};
use sdins_sim::nav::truth_rows::{self, TruthObserver, TruthRequest, TruthRow};

/// The columns, filled in place: every array is allocated once at its final length
/// and handed to numpy without a copy.
struct Columns {
    t_s: Vec<f64>,
    lat_rad: Vec<f64>,
    lon_rad: Vec<f64>,
    h_m: Vec<f64>,
    v_ned_mps: Vec<f64>,
    euler_rad: Vec<f64>,
    q_b_n: Vec<f64>,
    imu_t_s: Vec<f64>,
    dtheta_rad: Vec<f64>,
    dv_mps: Vec<f64>,
}

impl Columns {
    fn with_capacity(rows: usize, imu: usize) -> Self {
        Columns {
            t_s: Vec::with_capacity(rows),
            lat_rad: Vec::with_capacity(rows),
            lon_rad: Vec::with_capacity(rows),
            h_m: Vec::with_capacity(rows),
            v_ned_mps: Vec::with_capacity(rows * 3),
            euler_rad: Vec::with_capacity(rows * 3),
            q_b_n: Vec::with_capacity(rows * 4),
            imu_t_s: Vec::with_capacity(imu),
            dtheta_rad: Vec::with_capacity(imu * 3),
            dv_mps: Vec::with_capacity(imu * 3),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn push_row(
        &mut self,
        t: f64,
        lat: f64,
        lon: f64,
        h: f64,
        v: [f64; 3],
        c: &sdins_core::math::Mat3,
    ) {
        let e = euler_from_c_b_n(c);
        let q = Quat::from_dcm(c);
        self.t_s.push(t);
        self.lat_rad.push(lat);
        self.lon_rad.push(lon);
        self.h_m.push(h);
        self.v_ned_mps.extend_from_slice(&v);
        self.euler_rad
            .extend_from_slice(&[e.roll_rad, e.pitch_rad, e.yaw_rad]);
        self.q_b_n.extend_from_slice(&[q.w, q.x, q.y, q.z]);
    }
}

impl TruthObserver for Columns {
    fn imu(&mut self, t_s: f64, i: &Increment) {
        self.imu_t_s.push(t_s);
        self.dtheta_rad
            .extend_from_slice(&[i.dtheta_b_rad.x, i.dtheta_b_rad.y, i.dtheta_b_rad.z]);
        self.dv_mps
            .extend_from_slice(&[i.dv_b_mps.x, i.dv_b_mps.y, i.dv_b_mps.z]);
    }
    fn row(&mut self, r: &TruthRow) {
        let v = r.v_n_mps;
        self.push_row(
            r.t_s,
            r.lat_rad,
            r.lon_rad,
            r.h_m,
            [v.x, v.y, v.z],
            &r.c_b_n,
        );
    }
}

/// Exact truth of `scenario` (see `sdins.truth` in python/sdins/__init__.py for the
/// documented wrapper): a dict of float64 arrays.
#[pyfunction]
#[pyo3(signature = (scenario, until_s=None, every=None, imu=None))]
pub fn truth<'py>(
    py: Python<'py>,
    scenario: &Scenario,
    until_s: Option<f64>,
    every: Option<u64>,
    imu: Option<bool>,
) -> PyResult<Bound<'py, PyDict>> {
    let req = TruthRequest {
        every: every.unwrap_or(1),
        until_s,
        imu: imu.unwrap_or(true),
        ..TruthRequest::default()
    };
    let scn = &scenario.scn;
    let plan = truth_rows::plan(scn, req).map_err(err)?;
    let c = interrupt::run(py, |tok| {
        let mut c = Columns::with_capacity(
            plan.rows as usize,
            if req.imu { plan.samples as usize } else { 0 },
        );
        truth_rows::run(scn, &plan, tok, &mut c).map(|()| c)
    })?
    .map_err(|_| err("interrupted"))?;
    let d = PyDict::new(py);
    d.set_item("dt_s", scn.imu.dt_s())?;
    d.set_item("t_s", vector(py, c.t_s))?;
    d.set_item("lat_rad", vector(py, c.lat_rad))?;
    d.set_item("lon_rad", vector(py, c.lon_rad))?;
    d.set_item("h_m", vector(py, c.h_m))?;
    d.set_item("v_ned_mps", matrix(py, c.v_ned_mps, 3)?)?;
    d.set_item("euler_rad", matrix(py, c.euler_rad, 3)?)?;
    d.set_item("q_b_n", matrix(py, c.q_b_n, 4)?)?;
    d.set_item("imu_t_s", vector(py, c.imu_t_s))?;
    d.set_item("dtheta_rad", matrix(py, c.dtheta_rad, 3)?)?;
    d.set_item("dv_mps", matrix(py, c.dv_mps, 3)?)?;
    Ok(d)
}
