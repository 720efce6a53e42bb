//! `sdins.navigate` (recorded increments, the work of `sdins nav`) and `sdins.run`
//! (scenario truth through algorithms side by side, the work of `sdins run`).

use crate::arrays::{increments, matrix, vector};
use crate::error::err;
use crate::interrupt;
use crate::scenario::Scenario;
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sdins_core::nav::{InitialState, NavState};
use sdins_sim::nav::options::{self, AlgoChoice};
use sdins_sim::nav::pipeline::{NavError, RunObserver};
use sdins_sim::nav::recorded;
use sdins_sim::nav::run::{self as run_lib, RunRequest, SensorRun};
use sdins_sim::truth::TruthSample;

/// Navigation-state columns.
#[derive(Default)]
struct States {
    t_s: Vec<f64>,
    lat_rad: Vec<f64>,
    lon_rad: Vec<f64>,
    h_m: Vec<f64>,
    v_ned_mps: Vec<f64>,
    euler_rad: Vec<f64>,
    q_b_n: Vec<f64>,
}

impl States {
    fn with_capacity(n: usize) -> Self {
        States {
            t_s: Vec::with_capacity(n),
            lat_rad: Vec::with_capacity(n),
            lon_rad: Vec::with_capacity(n),
            h_m: Vec::with_capacity(n),
            v_ned_mps: Vec::with_capacity(3 * n),
            euler_rad: Vec::with_capacity(3 * n),
            q_b_n: Vec::with_capacity(4 * n),
        }
    }
    fn push(&mut self, t: f64, s: &NavState) {
        let e = s.euler();
        let q = s.q_b_n();
        self.t_s.push(t);
        self.lat_rad.push(s.lat_rad);
        self.lon_rad.push(s.lon_rad);
        self.h_m.push(s.h_m);
        self.v_ned_mps
            .extend_from_slice(&[s.v_n_mps.x, s.v_n_mps.y, s.v_n_mps.z]);
        self.euler_rad
            .extend_from_slice(&[e.roll_rad, e.pitch_rad, e.yaw_rad]);
        self.q_b_n.extend_from_slice(&[q.w, q.x, q.y, q.z]);
    }
    fn into_dict<'py>(self, py: Python<'py>, d: &Bound<'py, PyDict>) -> PyResult<()> {
        d.set_item("t_s", vector(py, self.t_s))?;
        d.set_item("lat_rad", vector(py, self.lat_rad))?;
        d.set_item("lon_rad", vector(py, self.lon_rad))?;
        d.set_item("h_m", vector(py, self.h_m))?;
        d.set_item("v_ned_mps", matrix(py, self.v_ned_mps, 3)?)?;
        d.set_item("euler_rad", matrix(py, self.euler_rad, 3)?)?;
        d.set_item("q_b_n", matrix(py, self.q_b_n, 4)?)?;
        Ok(())
    }
}

/// Error columns (`sdins_sim::nav::pipeline::NavError`, docs/conventions.md §"Errors").
#[derive(Default)]
struct Errors {
    t_s: Vec<f64>,
    pos: Vec<f64>,
    vel: Vec<f64>,
    att: Vec<f64>,
    height: Vec<f64>,
    euler: Vec<f64>,
}

impl Errors {
    fn push(&mut self, e: &NavError) {
        self.t_s.push(e.t_s);
        self.pos.extend_from_slice(&e.pos_err_ned_m);
        self.vel.extend_from_slice(&e.vel_err_ned_mps);
        self.att.extend_from_slice(&e.att_err_rad);
        self.height.push(e.height_err_m);
        self.euler.extend_from_slice(&e.euler_err_rad);
    }
    fn into_dict<'py>(self, py: Python<'py>, d: &Bound<'py, PyDict>) -> PyResult<()> {
        d.set_item("t_s", vector(py, self.t_s))?;
        d.set_item("pos_err_ned_m", matrix(py, self.pos, 3)?)?;
        d.set_item("vel_err_ned_mps", matrix(py, self.vel, 3)?)?;
        d.set_item("att_err_rad", matrix(py, self.att, 3)?)?;
        d.set_item("height_err_m", vector(py, self.height))?;
        d.set_item("euler_err_rad", matrix(py, self.euler, 3)?)?;
        Ok(())
    }
}

fn error_dict<'py>(py: Python<'py>, e: &NavError) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("t_s", e.t_s)?;
    d.set_item("pos_err_ned_m", e.pos_err_ned_m.to_vec())?;
    d.set_item("vel_err_ned_mps", e.vel_err_ned_mps.to_vec())?;
    d.set_item("att_err_rad", e.att_err_rad.to_vec())?;
    d.set_item("height_err_m", e.height_err_m)?;
    d.set_item("euler_err_rad", e.euler_err_rad.to_vec())?;
    Ok(d)
}

/// The initial state from a string `lat_deg,lon_deg,h_m,v_n,v_e,v_d,roll_deg,pitch_deg,
/// yaw_deg` or a sequence of those nine numbers (the CLI's `--init`).
fn initial(init: &Bound<'_, PyAny>) -> PyResult<InitialState> {
    let text = match init.extract::<String>() {
        Ok(s) => s,
        Err(_) => {
            let v: Vec<f64> = init.extract().map_err(|_| {
                err("init: expected lat_deg,lon_deg,h_m,v_n,v_e,v_d,roll_deg,pitch_deg,yaw_deg (a string or 9 numbers)")
            })?;
            v.iter()
                .map(|x| format!("{x:?}"))
                .collect::<Vec<_>>()
                .join(",")
        }
    };
    sdins_sim::io::initial::parse_initial_state(&text).map_err(err)
}

/// Navigate recorded increments with one algorithm (see the Python wrapper's docstring).
#[pyfunction]
#[pyo3(signature = (dtheta, dv, dt, init, algo=None, samples=None, coning=None, earth=None, vertical=None, t0_s=None))]
#[allow(clippy::too_many_arguments)]
pub fn navigate<'py>(
    py: Python<'py>,
    dtheta: PyReadonlyArray2<'py, f64>,
    dv: PyReadonlyArray2<'py, f64>,
    dt: f64,
    init: &Bound<'py, PyAny>,
    algo: Option<String>,
    samples: Option<usize>,
    coning: Option<String>,
    earth: Option<&str>,
    vertical: Option<&str>,
    t0_s: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(err(format!(
            "dt {dt}: expected a positive number of seconds"
        )));
    }
    let t0 = t0_s.unwrap_or(0.0);
    if !t0.is_finite() {
        return Err(err(format!("t0_s {t0}: expected a finite time")));
    }
    if options::vertical_hold(vertical, false).map_err(err)? {
        return Err(err(
            "vertical hold: recorded navigation has no reference height; use sdins.run (scenario truth) for a held vertical channel",
        ));
    }
    let earth = options::earth_by_name(earth.unwrap_or("wgs84")).map_err(err)?;
    let init = initial(init)?;
    // the recorded-navigation defaults of `sdins nav`: songlee-complete, N = 1
    let nav = options::recorded_nav_defaults();
    let choice = AlgoChoice {
        algos: Some(algo.unwrap_or_else(|| "songlee-complete".into())),
        samples: Some(samples.unwrap_or(1)),
        coning,
        ..AlgoChoice::default()
    };
    let specs = options::algorithms(&choice, &nav).map_err(err)?;
    let spec = match specs.as_slice() {
        [s] => *s,
        [] => return Err(err("--algo: no algorithm given")),
        _ => return Err(err("--algo: `nav` runs one algorithm")),
    };
    let incs = increments(&dtheta, &dv)?;
    let (st, rec) = interrupt::run(py, |tok| {
        let mut st = States::with_capacity(incs.len() / spec.samples.max(1));
        let r = recorded::navigate(&spec, earth, dt, t0, &init, &incs, None, tok, |t, s| {
            st.push(t, s)
        });
        (st, r)
    })?;
    let rec = rec.map_err(|_| err("interrupted"))?;
    let d = PyDict::new(py);
    d.set_item("algo", spec.kind.name())?;
    d.set_item("samples", spec.samples)?;
    d.set_item("updates", rec.updates)?;
    d.set_item("wall_s", rec.wall_s)?;
    st.into_dict(py, &d)?;
    Ok(d)
}

/// The output rows of a run, per algorithm.
struct Columns(Vec<(States, Errors)>);

impl RunObserver for Columns {
    fn epoch(&mut self, i: usize, st: &NavState, _tr: &TruthSample, e: &NavError) {
        self.0[i].0.push(e.t_s, st);
        self.0[i].1.push(e);
    }
}

/// Run a scenario's exact truth through algorithms side by side (see the wrapper).
#[pyfunction]
#[pyo3(signature = (scenario, algos=None, samples=None, coning=None, attitude=None, rotvec=None, rot3=None, vertical=None, every_s=None, until_s=None, ideal=None, run=None, grade=None))]
#[allow(clippy::too_many_arguments)]
pub fn run<'py>(
    py: Python<'py>,
    scenario: &Scenario,
    algos: Option<&Bound<'py, PyAny>>,
    samples: Option<usize>,
    coning: Option<String>,
    attitude: Option<String>,
    rotvec: Option<String>,
    rot3: Option<bool>,
    vertical: Option<&str>,
    every_s: Option<f64>,
    until_s: Option<f64>,
    ideal: Option<bool>,
    run: Option<u64>,
    grade: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let algos = match algos {
        None => None,
        Some(a) => Some(match a.extract::<String>() {
            Ok(s) => s,
            Err(_) => a
                .extract::<Vec<String>>()
                .map_err(|_| {
                    err("algos: expected a name, a comma-separated string or a list of names")
                })?
                .join(","),
        }),
    };
    let req = RunRequest {
        algos: AlgoChoice {
            algos,
            samples,
            coning,
            attitude,
            rotvec,
            rot3: rot3.unwrap_or(false),
        },
        vertical: vertical.map(str::to_string),
        every_s: every_s.unwrap_or(options::DEFAULT_EVERY_S),
        until_s,
        sensors: if ideal.unwrap_or(false) {
            SensorRun::Ideal
        } else {
            SensorRun::Run(run.unwrap_or(0))
        },
        grade,
    };
    let plan = run_lib::plan(scenario.scn.clone(), &req).map_err(err)?;
    let k = plan.options.algos.len();
    let (cols, sums) = interrupt::run(py, |tok| {
        let mut cols = Columns(
            (0..k)
                .map(|_| (States::default(), Errors::default()))
                .collect(),
        );
        let r = run_lib::run_plan(&plan, tok, &mut cols);
        (cols.0, r)
    })?;
    let sums = sums.map_err(|_| err("interrupted"))?;
    let out = PyDict::new(py);
    for ((st, er), s) in cols.into_iter().zip(&sums) {
        let d = PyDict::new(py);
        d.set_item("algo", &s.algo)?;
        d.set_item("samples", s.samples)?;
        d.set_item("nav_updates", s.nav_updates)?;
        d.set_item("wall_s", s.wall_s)?;
        d.set_item("final", error_dict(py, &s.final_err)?)?;
        d.set_item("max_abs", error_dict(py, &s.max_abs)?)?;
        let nd = PyDict::new(py);
        st.into_dict(py, &nd)?;
        d.set_item("nav", nd)?;
        let ed = PyDict::new(py);
        er.into_dict(py, &ed)?;
        d.set_item("errors", ed)?;
        out.set_item(&s.algo, d)?;
    }
    Ok(out)
}
