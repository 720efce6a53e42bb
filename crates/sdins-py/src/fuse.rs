//! `sdins.fuse`, `sdins.fuse_files`: the INS/GNSS filter on a scenario or on recorded
//! files through the library call of `sdins fuse` (`sdins_sim::fusion::request::fuse`);
//! `sdins.fuse_montecarlo` and `sdins.fuse_merge`: its Monte Carlo
//! (`sdins_sim::analysis::fuse_mc`, the work of `sdins fuse SCENARIO --runs N --shard i/n`
//! and `sdins fuse --merge`).

use crate::arrays::{matrix, vector};
use crate::error::err;
use crate::interrupt;
use crate::scenario::Scenario;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sdins_core::aiding::linalg::MAX_ROWS;
use sdins_sim::analysis::fuse_mc::{self, FuseMcOptions, FuseMcState as State};
use sdins_sim::analysis::montecarlo::Shard;
use sdins_sim::fusion::request::{
    fuse as fuse_request, FilesData, FuseData, FuseDetails, FuseOutput, FuseRequest, FuseRow,
    FuseRunError, ScenarioData,
};
use sdins_sim::fusion::simulated::ScaleFactorPrior;

/// Number of filter states in the `error` and `sigma` arrays (the navigation and bias
/// states; scale factors separately).
const NX: usize = 15;

fn run_err(e: FuseRunError) -> PyErr {
    if e.is_cancelled() {
        pyo3::exceptions::PyKeyboardInterrupt::new_err("cancelled")
    } else {
        err(e)
    }
}

/// The options shared by `fuse` and `fuse_montecarlo`.
#[allow(clippy::too_many_arguments)]
fn scenario_request(
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
    smooth: Option<bool>,
    in_motion: Option<bool>,
    scale_factors_ppm: Option<(f64, f64)>,
    grade: Option<&str>,
    every_s: Option<f64>,
    max_latency_s: Option<f64>,
) -> PyResult<FuseRequest> {
    let mut r = FuseRequest::new(FuseData::Scenario(ScenarioData {
        scenario: scenario.scn.clone(),
        run: run.unwrap_or(0),
        exact_start: exact_start.unwrap_or(false),
        in_motion: in_motion.unwrap_or(false),
        zupt_sigma_mps,
    }));
    if let Some(a) = algo {
        r.algo = a.to_string();
    }
    r.samples = samples;
    r.cov_rate_hz = cov_rate_hz.unwrap_or(r.cov_rate_hz);
    r.gate = gate.unwrap_or(r.gate);
    r.nhc_sigma_mps = nhc_sigma_mps;
    r.until_s = until_s;
    r.smooth = smooth.unwrap_or(false);
    r.scale_factors = scale_factors_ppm.map(|(a, g)| ScaleFactorPrior::uniform(a, g));
    r.grade = grade.map(str::to_string);
    r.every_s = every_s;
    r.max_latency_s = max_latency_s;
    r.check().map_err(run_err)?;
    Ok(r)
}

/// Run the filter; see the Python wrapper for parameters and the returned dict.
#[pyfunction]
#[pyo3(signature = (scenario, algo=None, samples=None, run=None, cov_rate_hz=None,
    gate=None, exact_start=None, zupt_sigma_mps=None, nhc_sigma_mps=None, until_s=None,
    smooth=None, in_motion=None, scale_factors_ppm=None, grade=None, every_s=None,
    max_latency_s=None, zupt_detector=None))]
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
    smooth: Option<bool>,
    in_motion: Option<bool>,
    scale_factors_ppm: Option<(f64, f64)>,
    grade: Option<&str>,
    every_s: Option<f64>,
    max_latency_s: Option<f64>,
    zupt_detector: Option<bool>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut req = scenario_request(
        scenario,
        algo,
        samples,
        run,
        cov_rate_hz,
        gate,
        exact_start,
        zupt_sigma_mps,
        nhc_sigma_mps,
        until_s,
        smooth,
        in_motion,
        scale_factors_ppm,
        grade,
        every_s,
        max_latency_s,
    )?;
    // the detector trigger takes the ZUPT σ from the truth trigger
    if zupt_detector.unwrap_or(false) {
        if let FuseData::Scenario(d) = &mut req.data {
            let sigma = d
                .zupt_sigma_mps
                .take()
                .ok_or_else(|| err("zupt_detector needs zupt_sigma_mps (the ZUPT's σ)"))?;
            req.zupt_detector = Some((sigma, Default::default()));
        }
        req.check().map_err(run_err)?;
    }
    #[derive(Default)]
    struct Ep {
        t: Vec<f64>,
        err: Vec<f64>,
        pos_m: Vec<f64>,
        vel_mps: Vec<f64>,
        att_rad: Vec<f64>,
        sigma: Vec<f64>,
        nees: Vec<f64>,
        sf_err: Vec<f64>,
        sf_sigma: Vec<f64>,
    }
    impl Ep {
        fn push(&mut self, e: &sdins_sim::fusion::simulated::FuseEpoch) {
            self.t.push(e.t_s);
            self.err.extend(e.err.iter().take(NX));
            self.pos_m.extend(e.nav.pos_err_ned_m);
            self.vel_mps.extend(e.nav.vel_err_ned_mps);
            self.att_rad.extend(e.nav.att_err_rad);
            self.sigma.extend((0..NX).map(|i| e.sigma(i)));
            self.nees
                .extend([e.nees_block(0), e.nees_block(3), e.nees_block(6)]);
            if let Some(sf) = e.scale_factors() {
                self.sf_err.extend(sf.err.iter());
                self.sf_sigma
                    .extend((0..6).map(|i| sf.p[(i, i)].max(0.0).sqrt()));
            }
        }
        fn dict<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
            let out = PyDict::new(py);
            if !self.sf_err.is_empty() {
                out.set_item("scale_factor_error", matrix(py, self.sf_err, 6)?)?;
                out.set_item("scale_factor_sigma", matrix(py, self.sf_sigma, 6)?)?;
            }
            out.set_item("t_s", vector(py, self.t))?;
            out.set_item("error", matrix(py, self.err, NX)?)?;
            out.set_item("pos_error_ned_m", matrix(py, self.pos_m, 3)?)?;
            out.set_item("vel_error_ned_mps", matrix(py, self.vel_mps, 3)?)?;
            out.set_item("att_error_rad", matrix(py, self.att_rad, 3)?)?;
            out.set_item("sigma", matrix(py, self.sigma, NX)?)?;
            out.set_item("nees", matrix(py, self.nees, 3)?)?;
            Ok(out)
        }
    }
    #[derive(Default)]
    struct Acc {
        forward: Ep,
        smoothed: Ep,
        inn: Inn,
    }
    let (acc, o) = interrupt::run(py, |tok| {
        let mut a = Acc::default();
        let r = fuse_request(&req, tok, &mut |ev| match ev {
            FuseOutput::Forward(FuseRow::Scenario(e)) => a.forward.push(e),
            FuseOutput::Smoothed(FuseRow::Scenario(e)) => a.smoothed.push(e),
            FuseOutput::Update(u) => a.inn.push(u),
            _ => {}
        });
        r.map(|o| (a, o))
    })?
    .map_err(run_err)?;
    let FuseDetails::Scenario {
        summary: s, run, ..
    } = &o.details
    else {
        return Err(err("fuse on a scenario returned no scenario result"));
    };
    let out = acc.forward.dict(py)?;
    out.set_item("innovations", acc.inn.dict(py)?)?;
    if req.smooth {
        out.set_item("smoothed", acc.smoothed.dict(py)?)?;
    }
    let v3 = |v: &sdins_core::math::Vec3| vec![v.x, v.y, v.z];
    out.set_item("health", health_dict(py, &o.health)?)?;
    out.set_item("fixes", s.fixes)?;
    out.set_item("rejected", s.rejected)?;
    out.set_item("late", s.late)?;
    out.set_item("nav_updates", s.nav_updates)?;
    out.set_item("accel_bias_est_mps2", v3(&s.est_bias.0))?;
    out.set_item("accel_bias_true_mps2", v3(&s.true_bias.0))?;
    out.set_item("gyro_bias_est_rps", v3(&s.est_bias.1))?;
    out.set_item("gyro_bias_true_rps", v3(&s.true_bias.1))?;
    if let Some((ta, tg)) = s.true_scale {
        out.set_item("accel_scale_est", v3(&s.est_scale.0))?;
        out.set_item("accel_scale_true", v3(&ta))?;
        out.set_item("gyro_scale_est", v3(&s.est_scale.1))?;
        out.set_item("gyro_scale_true", v3(&tg))?;
    }
    out.set_item("samples", o.algo.samples)?;
    out.set_item("run", *run)?;
    Ok(out)
}

/// Measurement reports as flat columns.
#[derive(Default)]
struct Inn {
    t: Vec<f64>,
    t_valid: Vec<f64>,
    kind: Vec<&'static str>,
    dof: Vec<usize>,
    nis: Vec<f64>,
    accepted: Vec<bool>,
    forced: Vec<bool>,
    late: Vec<bool>,
    nu: Vec<f64>,
}

impl Inn {
    fn push(&mut self, u: &sdins_core::aiding::ekf::UpdateReport) {
        self.t.push(u.t_s);
        self.t_valid.push(u.t_valid_s);
        self.kind.push(u.kind.name());
        self.dof.push(u.dof);
        self.nis.push(u.nis);
        self.accepted.push(u.accepted);
        self.forced.push(u.forced);
        self.late.push(u.late);
        self.nu.extend(u.innovation);
    }
    fn dict<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let inn = PyDict::new(py);
        inn.set_item("t_s", vector(py, self.t))?;
        inn.set_item("t_valid_s", vector(py, self.t_valid))?;
        inn.set_item("kind", self.kind)?;
        inn.set_item("dof", self.dof)?;
        inn.set_item("nis", vector(py, self.nis))?;
        inn.set_item("accepted", self.accepted)?;
        inn.set_item("forced", self.forced)?;
        inn.set_item("late", self.late)?;
        inn.set_item("innovation", matrix(py, self.nu, MAX_ROWS)?)?;
        Ok(inn)
    }
}

/// Points of a recorded-data run as flat columns.
#[derive(Default)]
struct Track {
    t: Vec<f64>,
    lat: Vec<f64>,
    lon: Vec<f64>,
    h: Vec<f64>,
    v: Vec<f64>,
    euler: Vec<f64>,
    sigma_nav: Vec<f64>,
    sigma_euler: Vec<f64>,
    bias: Vec<f64>,
    scale: Vec<f64>,
    sigma_scale: Vec<f64>,
}

impl Track {
    fn push(&mut self, p: &sdins_sim::fusion::records::RecordPoint) {
        let s = &p.state;
        let e = s.euler();
        self.t.push(p.t_s);
        self.lat.push(s.lat_rad);
        self.lon.push(s.lon_rad);
        self.h.push(s.h_m);
        self.v.extend([s.v_n_mps.x, s.v_n_mps.y, s.v_n_mps.z]);
        self.euler.extend([e.roll_rad, e.pitch_rad, e.yaw_rad]);
        self.sigma_nav.extend(p.sigma_nav);
        self.sigma_euler.extend(p.sigma_euler_rad);
        let (ba, bg) = p.bias;
        self.bias.extend([ba.x, ba.y, ba.z, bg.x, bg.y, bg.z]);
        let (sa, sg) = p.scale;
        self.scale.extend([sa.x, sa.y, sa.z, sg.x, sg.y, sg.z]);
        self.sigma_scale.extend(p.sigma_scale);
    }
    fn dict<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("t_s", vector(py, self.t))?;
        d.set_item("lat_rad", vector(py, self.lat))?;
        d.set_item("lon_rad", vector(py, self.lon))?;
        d.set_item("h_m", vector(py, self.h))?;
        d.set_item("v_ned_mps", matrix(py, self.v, 3)?)?;
        d.set_item("euler_rad", matrix(py, self.euler, 3)?)?;
        d.set_item("sigma_nav", matrix(py, self.sigma_nav, 9)?)?;
        d.set_item("sigma_euler_rad", matrix(py, self.sigma_euler, 3)?)?;
        d.set_item("bias", matrix(py, self.bias, 6)?)?;
        d.set_item("scale_factor", matrix(py, self.scale, 6)?)?;
        d.set_item("sigma_scale_factor", matrix(py, self.sigma_scale, 6)?)?;
        Ok(d)
    }
}

/// `sdins fuse --imu FILE --gnss FILE` (the same library call); see the Python wrapper
/// for parameters and the returned dict.
#[pyfunction]
#[pyo3(signature = (imu, gnss, imu_format=None, gnss_format=None, grade=None,
    navego_params=None, init=None, attitude_deg=None, attitude_sigma_deg=None, static_s=None,
    lever_arm_m=None, truth=None, smooth=None, algo=None, samples=None, cov_rate_hz=None,
    gate=None, nhc_sigma_mps=None, gnss_offset_s=None, scale_factors_ppm=None, every_s=None,
    max_latency_s=None, imu_columns=None, gnss_columns=None, truth_columns=None, profile=None,
    gps_week=None, gnss_sigma=None, undulation_m=None, sensor_model=None, aiding=None,
    zupt_sigma_mps=None, zupt_window_s=None, zupt_false_alarm=None))]
#[allow(clippy::too_many_arguments)]
pub fn fuse_files<'py>(
    py: Python<'py>,
    imu: std::path::PathBuf,
    gnss: std::path::PathBuf,
    imu_format: Option<&str>,
    gnss_format: Option<&str>,
    grade: Option<&str>,
    navego_params: Option<std::path::PathBuf>,
    init: Option<&str>,
    attitude_deg: Option<[f64; 3]>,
    attitude_sigma_deg: Option<[f64; 3]>,
    static_s: Option<f64>,
    lever_arm_m: Option<[f64; 3]>,
    truth: Option<std::path::PathBuf>,
    smooth: Option<bool>,
    algo: Option<&str>,
    samples: Option<usize>,
    cov_rate_hz: Option<f64>,
    gate: Option<bool>,
    nhc_sigma_mps: Option<f64>,
    gnss_offset_s: Option<f64>,
    scale_factors_ppm: Option<(f64, f64)>,
    every_s: Option<f64>,
    max_latency_s: Option<f64>,
    imu_columns: Option<String>,
    gnss_columns: Option<String>,
    truth_columns: Option<String>,
    profile: Option<std::path::PathBuf>,
    gps_week: Option<u32>,
    gnss_sigma: Option<String>,
    undulation_m: Option<f64>,
    sensor_model: Option<std::path::PathBuf>,
    aiding: Option<std::path::PathBuf>,
    zupt_sigma_mps: Option<f64>,
    zupt_window_s: Option<f64>,
    zupt_false_alarm: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    // the same maps as the CLI's --imu-columns, …; messages name the Python arguments
    let columns = sdins_sim::fusion::files::ColumnOptions {
        imu_columns,
        gnss_columns,
        truth_columns,
        profile,
        gps_week,
        gnss_sigma,
        undulation_m,
    }
    .resolve(&|n: &str| n.to_string())
    .map_err(err)?;
    let mut req = FuseRequest::new(FuseData::Files(FilesData {
        imu: (imu, imu_format.unwrap_or("auto").parse().map_err(err)?),
        gnss: (gnss, gnss_format.unwrap_or("auto").parse().map_err(err)?),
        gnss_offset_s: gnss_offset_s.unwrap_or(0.0),
        navego_params,
        sensor_model,
        init: init.map(str::to_string),
        attitude_deg,
        attitude_sigma_deg,
        static_s,
        lever_arm_m,
        truth,
        columns,
        aiding,
    }));
    if let Some(a) = algo {
        req.algo = a.to_string();
    }
    req.samples = samples;
    req.cov_rate_hz = cov_rate_hz.unwrap_or(req.cov_rate_hz);
    req.gate = gate.unwrap_or(req.gate);
    req.nhc_sigma_mps = nhc_sigma_mps;
    // on recorded data a ZUPT can only come from the stationarity detector
    if let Some(sigma) = zupt_sigma_mps {
        let d = sdins_sim::fusion::detector::DetectorSettings::default();
        req.zupt_detector = Some((
            sigma,
            sdins_sim::fusion::detector::DetectorSettings {
                window_s: zupt_window_s.unwrap_or(d.window_s),
                false_alarm: zupt_false_alarm.unwrap_or(d.false_alarm),
            },
        ));
    }
    req.smooth = smooth.unwrap_or(false);
    req.scale_factors = scale_factors_ppm.map(|(a, g)| ScaleFactorPrior::uniform(a, g));
    req.grade = grade.map(str::to_string);
    req.every_s = every_s;
    req.max_latency_s = max_latency_s;
    req.check().map_err(run_err)?;
    #[derive(Default)]
    struct Acc {
        fwd: Track,
        smo: Track,
        inn: Inn,
    }
    let (acc, o) = interrupt::run(py, |tok| {
        let mut a = Acc::default();
        let r = fuse_request(&req, tok, &mut |ev| match ev {
            FuseOutput::Forward(FuseRow::Files(p, _)) => a.fwd.push(p),
            FuseOutput::Smoothed(FuseRow::Files(p, _)) => a.smo.push(p),
            FuseOutput::Update(u) => a.inn.push(u),
            _ => {}
        });
        r.map(|o| (a, o))
    })?
    .map_err(run_err)?;
    let FuseDetails::Files(r) = &o.details else {
        return Err(err("fuse on files returned no file result"));
    };
    let out = PyDict::new(py);
    out.set_item("forward", acc.fwd.dict(py)?)?;
    if req.smooth {
        out.set_item("smoothed", acc.smo.dict(py)?)?;
    }
    out.set_item("innovations", acc.inn.dict(py)?)?;
    out.set_item("health", health_dict(py, &o.health)?)?;
    out.set_item("fixes_used", o.fixes)?;
    out.set_item("rejected", o.rejected)?;
    out.set_item("late", o.late)?;
    out.set_item("fixes_outside", (r.fixes_outside.0, r.fixes_outside.1))?;
    out.set_item("imu_samples", r.imu_samples)?;
    let inputs = PyDict::new(py);
    for rep in &r.inputs {
        inputs.set_item(rep.kind, rep.summary())?;
    }
    out.set_item("inputs", inputs)?;
    for (name, c) in [("forward_rmse", &r.forward), ("smoothed_rmse", &r.smoothed)] {
        if let Some(c) = c {
            out.set_item(name, c.rmse().to_vec())?;
            out.set_item(format!("{name}_inside_3sigma"), c.inside_3sigma().to_vec())?;
        }
    }
    Ok(out)
}

/// Accumulator state of a fusion Monte Carlo job or shard (picklable as the CLI's
/// `fuse_mc_state.json` text).
#[pyclass(module = "sdins", frozen)]
pub struct FuseMcState {
    pub(crate) state: State,
}

#[pymethods]
impl FuseMcState {
    /// Restore a state from its JSON text (`fuse_mc_state.json`).
    #[new]
    fn new(json: &str) -> PyResult<Self> {
        let state: State = serde_json::from_str(json)
            .map_err(|e| err(format!("not a fuse Monte Carlo state: {e}")))?;
        state.validate().map_err(err)?;
        Ok(FuseMcState { state })
    }

    /// Read `fuse_mc_state.json` (or a folder holding it) written by the CLI.
    #[staticmethod]
    fn from_file(path: std::path::PathBuf) -> PyResult<Self> {
        let file = if path.is_dir() {
            path.join("fuse_mc_state.json")
        } else {
            path
        };
        let text = std::fs::read_to_string(&file)
            .map_err(|e| err(format!("{}: cannot read: {e}", file.display())))?;
        FuseMcState::new(&text).map_err(|e| err(format!("{}: {e}", file.display())))
    }

    /// The state as JSON text.
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.state).map_err(err)
    }

    /// Statistics (dict): `runs`, `complete`, `times_s` (m,), `columns`, `dof`, and `n`,
    /// `mean`, `sd` (m, columns).
    fn statistics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.state.statistics();
        let c = s.columns.len();
        let m = s.times_s.len();
        let (mut n, mut mean, mut sd) = (
            Vec::with_capacity(m * c),
            Vec::with_capacity(m * c),
            Vec::with_capacity(m * c),
        );
        for e in 0..m {
            for col in &s.columns {
                n.push(col.n[e] as f64);
                mean.push(col.mean[e]);
                sd.push(col.sd[e]);
            }
        }
        let d = PyDict::new(py);
        d.set_item("runs", s.runs)?;
        d.set_item("complete", s.complete)?;
        d.set_item("times_s", vector(py, s.times_s.clone()))?;
        d.set_item(
            "columns",
            s.columns.iter().map(|c| c.name.clone()).collect::<Vec<_>>(),
        )?;
        d.set_item("dof", s.columns.iter().map(|c| c.dof).collect::<Vec<_>>())?;
        d.set_item("n", matrix(py, n, c.max(1))?)?;
        d.set_item("mean", matrix(py, mean, c.max(1))?)?;
        d.set_item("sd", matrix(py, sd, c.max(1))?)?;
        Ok(d)
    }

    /// The consistency criterion (docs/validation.md) on a column after `after_s` (dict:
    /// grand_mean, band95, band99, in95, in99, max, epochs, pass, …).
    #[pyo3(signature = (column, after_s=30.0, tests=1))]
    fn consistency<'py>(
        &self,
        py: Python<'py>,
        column: &str,
        after_s: f64,
        tests: usize,
    ) -> PyResult<Bound<'py, PyDict>> {
        let c = self
            .state
            .statistics()
            .consistency(column, after_s, tests)
            .ok_or_else(|| err(format!("no column `{column}`")))?;
        let d = PyDict::new(py);
        d.set_item("name", &c.name)?;
        d.set_item("dof", c.dof)?;
        d.set_item("runs", c.runs)?;
        d.set_item("epochs", c.epochs)?;
        d.set_item("grand_mean", c.grand_mean)?;
        d.set_item("band95", c.band95)?;
        d.set_item("band99", c.band99)?;
        d.set_item("band_grand", c.band_grand)?;
        d.set_item("in95", c.in95)?;
        d.set_item("in99", c.in99)?;
        d.set_item("max", c.max)?;
        d.set_item("epochs_eff", c.epochs_eff)?;
        d.set_item("need95", c.need95)?;
        d.set_item("need99", c.need99)?;
        d.set_item("pass", c.pass)?;
        Ok(d)
    }

    /// Block indices not yet computed.
    fn missing_blocks(&self) -> Vec<u64> {
        self.state.missing_blocks()
    }

    fn __getnewargs__(&self) -> PyResult<(String,)> {
        Ok((self.to_json()?,))
    }

    fn __eq__(&self, other: &FuseMcState) -> bool {
        self.state == other.state
    }

    fn __repr__(&self) -> String {
        let j = &self.state.job;
        format!(
            "FuseMcState({:?}, {} runs, {} blocks present)",
            j.scenario,
            j.runs,
            self.state.blocks.len()
        )
    }
}

/// Compute shard `shard = (i, n)` of a fusion Monte Carlo (see the wrapper's docstring).
#[pyfunction]
#[pyo3(signature = (scenario, runs, seed=None, shard=None, block=None, threads=None,
    draw_scale_factors=None, algo=None, samples=None, cov_rate_hz=None, gate=None,
    exact_start=None, zupt_sigma_mps=None, nhc_sigma_mps=None, until_s=None,
    scale_factors_ppm=None, grade=None, every_s=None, max_latency_s=None))]
#[allow(clippy::too_many_arguments)]
pub fn fuse_montecarlo(
    py: Python<'_>,
    scenario: &Scenario,
    runs: u64,
    seed: Option<u64>,
    shard: Option<(u64, u64)>,
    block: Option<u64>,
    threads: Option<usize>,
    draw_scale_factors: Option<bool>,
    algo: Option<&str>,
    samples: Option<usize>,
    cov_rate_hz: Option<f64>,
    gate: Option<bool>,
    exact_start: Option<bool>,
    zupt_sigma_mps: Option<f64>,
    nhc_sigma_mps: Option<f64>,
    until_s: Option<f64>,
    scale_factors_ppm: Option<(f64, f64)>,
    grade: Option<&str>,
    every_s: Option<f64>,
    max_latency_s: Option<f64>,
) -> PyResult<FuseMcState> {
    let req = scenario_request(
        scenario,
        algo,
        samples,
        None,
        cov_rate_hz,
        gate,
        exact_start,
        zupt_sigma_mps,
        nhc_sigma_mps,
        until_s,
        None,
        None,
        scale_factors_ppm,
        grade,
        every_s,
        max_latency_s,
    )?;
    let mc = FuseMcOptions {
        runs,
        seed: seed.unwrap_or(scenario.scn.imu.seed),
        block: block.unwrap_or(16),
        draw_scale_factors: draw_scale_factors.unwrap_or(false),
    };
    let shard = match shard {
        None => Shard::ALL,
        Some((index, count)) => Shard { index, count },
    };
    let pool = match threads {
        Some(0) => return Err(err("threads 0: expected at least 1")),
        Some(t) => Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .map_err(err)?,
        ),
        None => None,
    };
    let result = interrupt::run(py, |tok| {
        let cancelled = || tok.is_cancelled();
        let compute = || fuse_mc::run_shard(&req, &mc, shard, &|| {}, &cancelled);
        match &pool {
            Some(p) => p.install(compute),
            None => compute(),
        }
    })?;
    Ok(FuseMcState {
        state: result.map_err(err)?,
    })
}

/// Merge shard states exactly (any order).
#[pyfunction]
#[pyo3(signature = (states, allow_partial=None))]
pub fn fuse_merge(
    states: Vec<PyRef<'_, FuseMcState>>,
    allow_partial: Option<bool>,
) -> PyResult<FuseMcState> {
    let v: Vec<State> = states.iter().map(|s| s.state.clone()).collect();
    let merged = State::merge(&v).map_err(err)?;
    let missing = merged.missing_blocks();
    if !missing.is_empty() && !allow_partial.unwrap_or(false) {
        return Err(err(format!(
            "{} blocks missing (first missing block {}): give every shard, or allow_partial=True",
            missing.len(),
            missing[0]
        )));
    }
    Ok(FuseMcState { state: merged })
}

/// The health verdict as a dict: `ok` and `checks` (name, passed, detail); Python never
/// raises for it.
fn health_dict<'py>(
    py: Python<'py>,
    h: &sdins_sim::fusion::health::HealthVerdict,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("ok", h.ok())?;
    let checks = pyo3::types::PyList::empty(py);
    for c in &h.checks {
        let cd = PyDict::new(py);
        cd.set_item("name", c.name)?;
        cd.set_item("passed", c.passed)?;
        cd.set_item("detail", &c.detail)?;
        checks.append(cd)?;
    }
    d.set_item("checks", checks)?;
    Ok(d)
}
