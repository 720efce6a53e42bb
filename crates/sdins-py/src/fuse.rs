//! `sdins.fuse`: the loosely coupled INS/GNSS filter on a scenario
//! (`sdins_sim::fusion::simulated::fuse_scenario`, the library call of `sdins fuse`).

use crate::arrays::{matrix, vector};
use crate::error::err;
use crate::interrupt;
use crate::scenario::Scenario;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sdins_core::aiding::ekf::MeasKind;
use sdins_core::aiding::error_model::{I_ATT, I_POS, I_VEL};
use sdins_core::nav::AlgorithmSpec;
use sdins_sim::fusion::simulated::{fuse_scenario, FuseError, FuseEvent, FuseOptions};

/// Number of filter states.
const NX: usize = 15;

/// Run the filter; see the Python wrapper for parameters and the returned dict.
#[pyfunction]
#[pyo3(signature = (scenario, algo=None, samples=None, run=None, cov_rate_hz=None,
    gate=None, exact_start=None, zupt_sigma_mps=None, nhc_sigma_mps=None, until_s=None,
    smooth=None, in_motion=None, scale_factors_ppm=None))]
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
        smooth: smooth.unwrap_or(d.smooth),
        in_motion: match in_motion {
            Some(true) => Some(sdins_sim::fusion::simulated::InMotionInit::default()),
            Some(false) => None,
            None => d.in_motion,
        },
        scale_factors: scale_factors_ppm
            .map(|(a, g)| sdins_sim::fusion::simulated::ScaleFactorPrior::uniform(a, g)),
        ..d
    };
    let gnss = scn.gnss.clone().unwrap_or_default();
    let run = run.unwrap_or(0);
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
            self.err.extend(e.err.iter());
            self.pos_m.extend(e.nav.pos_err_ned_m);
            self.vel_mps.extend(e.nav.vel_err_ned_mps);
            self.att_rad.extend(e.nav.att_err_rad);
            self.sigma.extend((0..NX).map(|i| e.sigma(i)));
            self.nees.extend([
                e.nees_block(I_POS),
                e.nees_block(I_VEL),
                e.nees_block(I_ATT),
            ]);
            if let Some(sf) = &e.scale_factors {
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
            FuseEvent::Epoch(e) => a.forward.push(e),
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
            FuseEvent::Smoothed(e) => a.smoothed.push(e),
            _ => {}
        });
        r.map(|s| (a, s))
    })?
    .map_err(|e| match e {
        FuseError::Cancelled(_) => pyo3::exceptions::PyKeyboardInterrupt::new_err("cancelled"),
        other => err(other),
    })?;
    let out = acc.forward.dict(py)?;
    let inn = PyDict::new(py);
    inn.set_item("t_s", vector(py, acc.it))?;
    inn.set_item("kind", acc.kind)?;
    inn.set_item("dof", acc.dof)?;
    inn.set_item("nis", vector(py, acc.nis))?;
    inn.set_item("accepted", acc.accepted)?;
    inn.set_item("forced", acc.forced)?;
    inn.set_item("innovation", matrix(py, acc.nu, 6)?)?;
    out.set_item("innovations", inn)?;
    if opts.smooth {
        out.set_item("smoothed", acc.smoothed.dict(py)?)?;
    }
    let v3 = |v: &sdins_core::math::Vec3| vec![v.x, v.y, v.z];
    out.set_item("fixes", s.fixes)?;
    out.set_item("rejected", s.rejected)?;
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
    out.set_item("samples", samples)?;
    out.set_item("run", run)?;
    Ok(out)
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

/// `sdins fuse --imu FILE --gnss FILE` (`sdins_sim::fusion::files::fuse_files`); see the
/// Python wrapper for parameters and the returned dict.
#[pyfunction]
#[pyo3(signature = (imu, gnss, imu_format=None, gnss_format=None, grade=None,
    navego_params=None, init=None, attitude_deg=None, attitude_sigma_deg=None, static_s=None,
    lever_arm_m=None, truth=None, smooth=None, algo=None, samples=None, cov_rate_hz=None,
    gate=None, nhc_sigma_mps=None, gnss_offset_s=None, scale_factors_ppm=None))]
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
) -> PyResult<Bound<'py, PyDict>> {
    use sdins_sim::fusion::files::{FilesError, FilesInput, InitSource, SensorModelSource};
    use sdins_sim::fusion::records::{RecordEvent, RecordOptions};
    use sdins_sim::io::gnss_file::{GnssFormat, GnssReadOptions, ImuClock};
    use sdins_sim::io::imu_file::ImuFormat;
    let d = RecordOptions::default();
    let samples = samples.unwrap_or(d.algo.samples);
    if !(1..=4).contains(&samples) {
        return Err(err(format!("samples: must be 1..4, got {samples}")));
    }
    let algo = match algo {
        None => AlgorithmSpec::new(d.algo.kind, samples),
        Some(a) => AlgorithmSpec::from_name(a, samples)
            .ok_or_else(|| err(format!("algo: unknown algorithm `{a}`")))?,
    };
    let imu_format: ImuFormat = imu_format.unwrap_or("auto").parse().map_err(err)?;
    let gnss_format: GnssFormat = gnss_format.unwrap_or("auto").parse().map_err(err)?;
    let sensor = SensorModelSource::from_options(grade, navego_params.as_deref()).map_err(err)?;
    let init = InitSource::from_options(
        init,
        attitude_deg,
        attitude_sigma_deg,
        static_s,
        navego_params.is_some(),
    )
    .map_err(err)?;
    if lever_arm_m.is_some_and(|l| l.iter().any(|x| !x.is_finite())) {
        return Err(err("lever_arm_m: must be finite"));
    }
    let off = gnss_offset_s.unwrap_or(0.0);
    if !off.is_finite() {
        return Err(err("gnss_offset_s: must be finite"));
    }
    let input = FilesInput {
        imu: (imu, imu_format),
        gnss: (gnss, gnss_format),
        gnss_options: GnssReadOptions::default(),
        clock: if off == 0.0 {
            ImuClock::SameAsGnss
        } else {
            ImuClock::Offset {
                t_imu_minus_t_gnss_s: off,
            }
        },
        sensor,
        init,
        truth,
        check_after_s: 30.0,
        columns: Default::default(),
    };
    let opts = RecordOptions {
        algo,
        cov_rate_hz: cov_rate_hz.unwrap_or(d.cov_rate_hz),
        gate_chi2: match gate {
            None => d.gate_chi2,
            Some(false) => None,
            Some(true) => Some(sdins_core::aiding::ekf::CHI2_999),
        },
        lever_arm_b_m: lever_arm_m.unwrap_or(d.lever_arm_b_m),
        nhc_sigma_mps,
        smooth: smooth.unwrap_or(d.smooth),
        scale_factors: scale_factors_ppm
            .map(|(a, g)| sdins_sim::fusion::simulated::ScaleFactorPrior::uniform(a, g)),
        ..d
    };
    #[derive(Default)]
    struct Acc {
        fwd: Track,
        smo: Track,
        it: Vec<f64>,
        nis: Vec<f64>,
        dof: Vec<usize>,
        accepted: Vec<bool>,
    }
    let (acc, r) = interrupt::run(py, |tok| {
        let mut a = Acc::default();
        let mut t0 = None;
        let r = sdins_sim::fusion::files::fuse_files(&input, &opts, tok, |ev, _| match ev {
            RecordEvent::Forward(p) => {
                t0.get_or_insert(p.t_s - p.state.t_s);
                a.fwd.push(p)
            }
            RecordEvent::Smoothed(p) => a.smo.push(p),
            RecordEvent::Update(u) => {
                a.it.push(t0.unwrap_or(0.0) + u.t_s);
                a.nis.push(u.nis);
                a.dof.push(u.dof);
                a.accepted.push(u.accepted);
            }
            _ => {}
        });
        r.map(|r| (a, r))
    })?
    .map_err(|e| match e {
        FilesError::Fuse(FuseError::Cancelled(_)) => {
            pyo3::exceptions::PyKeyboardInterrupt::new_err("cancelled")
        }
        other => err(other),
    })?;
    let out = PyDict::new(py);
    out.set_item("forward", acc.fwd.dict(py)?)?;
    if opts.smooth {
        out.set_item("smoothed", acc.smo.dict(py)?)?;
    }
    let inn = PyDict::new(py);
    inn.set_item("t_s", vector(py, acc.it))?;
    inn.set_item("nis", vector(py, acc.nis))?;
    inn.set_item("dof", acc.dof)?;
    inn.set_item("accepted", acc.accepted)?;
    out.set_item("innovations", inn)?;
    out.set_item("fixes_used", r.summary.fixes_used)?;
    out.set_item("rejected", r.summary.rejected)?;
    out.set_item("fixes_outside", (r.fixes_outside.0, r.fixes_outside.1))?;
    out.set_item("imu_samples", r.imu_samples)?;
    for (name, c) in [("forward_rmse", &r.forward), ("smoothed_rmse", &r.smoothed)] {
        if let Some(c) = c {
            out.set_item(name, c.rmse().to_vec())?;
            out.set_item(format!("{name}_inside_3sigma"), c.inside_3sigma().to_vec())?;
        }
    }
    Ok(out)
}
