//! The event stream of a scenario for the fusion loop ([`crate::fusion::engine`]) and the
//! filter's start: the exact truth sample by sample, corrupted by the run's IMU errors,
//! the GNSS simulator's fixes as they are generated, and the truth's rest state.
//!
//! * Per truth sample: `Imu` (the measured increment and the truth), `Rest` when the truth's
//!   speed crosses the ZUPT threshold, then every fix whose time of validity lies in the
//!   sample (`Gnss`: time of validity = tag − the known latency when it is modelled,
//!   arrival = the tag).
//! * The start ([`scenario_start`]): the truth's initial state with drawn errors, or, in
//!   motion, the first fix at speed (heading from its track).

use crate::fusion::engine::{EngineConfig, Event, Start};
use crate::fusion::simulated::{
    engine_config, noise_from_model, true_scale_factors, FuseError, FuseOptions, Truths,
    IN_MOTION_MAX_SIGMA_RAD,
};
use crate::scenario::Scenario;
use crate::sensors::aiding::{add_blocks, AidingSimulator};
use crate::sensors::gnss::{GnssConfig, GnssSimulator};
use crate::sensors::gnss_fix::GnssFix;
use crate::sensors::imu_error::{ImuErrorState, DEG};
use crate::truth::trajectory::Trajectory;
use crate::truth::{TruthGenerator, TruthSample};
use rand::SeedableRng;
use rand_chacha::ChaCha20Rng;
use rand_distr::{Distribution, StandardNormal};
use sdins_core::aiding::layout::{BlockKind, Cov, XVec};
use sdins_core::aiding::meas::Measurement;
use sdins_core::aiding::sensors::AidingMeas;
use sdins_core::coning::Increment;
use sdins_core::math::{Mat3, Quat, Vec3};
use sdins_core::nav::InitialState;
use std::collections::VecDeque;

/// The stream of a scenario run.
pub struct ScenarioStream<'a> {
    truth: Box<dyn Iterator<Item = TruthSample> + 'a>,
    traj: &'a Trajectory,
    sensor: ImuErrorState,
    gsim: GnssSimulator,
    aiding: Option<AidingSimulator>,
    aid_out: Vec<AidingMeas>,
    prev: TruthSample,
    dt_s: f64,
    queue: VecDeque<Event>,
    fixes: Vec<GnssFix>,
    latency_fix_s: f64,
    zupt_speed_mps: Option<f64>,
    rest: bool,
}

impl Iterator for ScenarioStream<'_> {
    type Item = Event;
    fn next(&mut self) -> Option<Event> {
        if let Some(e) = self.queue.pop_front() {
            return Some(e);
        }
        let ts = self.truth.next()?;
        let inc = self.sensor.apply(&ts.inc, self.dt_s);
        self.gsim.step(self.traj, &self.prev, &ts, &mut self.fixes);
        if let Some(a) = self.aiding.as_mut() {
            a.step(self.traj, &self.prev, &ts, &mut self.aid_out);
            self.queue.push_back(Event::SensorTruth(a.truth()));
        }
        self.prev = ts;
        if let Some(thr) = self.zupt_speed_mps {
            let rest = ts.v_n_mps.norm() < thr;
            if rest != self.rest {
                self.rest = rest;
                self.queue.push_back(Event::Rest(rest));
            }
        }
        for f in self.fixes.drain(..) {
            self.queue.push_back(Event::Gnss {
                fix: GnssFix {
                    t_s: f.t_s - self.latency_fix_s,
                    ..f
                },
                arrival_s: f.t_s,
            });
        }
        for m in self.aid_out.drain(..) {
            let arrival_s = m.t_valid_s();
            self.queue.push_back(Event::Meas { meas: m, arrival_s });
        }
        Some(Event::Imu {
            t_s: ts.t_s,
            inc,
            truth: Some(ts),
        })
    }
}

/// What a scenario run starts from.
pub struct ScenarioSetup<'a> {
    /// the event stream (positioned after the samples used to start)
    pub stream: ScenarioStream<'a>,
    /// the filter's start
    pub start: Start,
    /// the loop's settings
    pub cfg: EngineConfig,
    /// the run's true sensor errors
    pub(crate) truths: Truths,
}

fn check_options(opts: &FuseOptions) -> Result<(), FuseError> {
    if let Some(sp) = &opts.scale_factors {
        sp.validate()?;
    }
    let s = &opts.init_sigma;
    if s.att_rad
        .iter()
        .any(|x| !x.is_finite() || *x < 0.0 || *x > 10.0 * DEG)
        || s.pos_ned_m
            .iter()
            .chain(s.vel_ned_mps.iter())
            .any(|x| !x.is_finite() || *x < 0.0)
    {
        return Err(FuseError::Option(
            "init_sigma",
            "σ must be finite, ≥ 0, and attitude σ ≤ 10° (the linearised filter's limit)".into(),
        ));
    }
    if let Some(im) = &opts.in_motion {
        if !(im.min_speed_mps.is_finite()
            && im.min_speed_mps > 0.0
            && im.tilt_sigma_rad > 0.0
            && im.tilt_sigma_rad <= IN_MOTION_MAX_SIGMA_RAD
            && im.track_sigma_rad > 0.0
            && im.track_sigma_rad <= IN_MOTION_MAX_SIGMA_RAD)
        {
            return Err(FuseError::Option(
                "in_motion",
                "min speed must be > 0, tilt and track σ in (0, 10°]".into(),
            ));
        }
    }
    if let Some(e) = opts.every_s {
        if !(e.is_finite() && e > 0.0) {
            return Err(FuseError::Option(
                "every_s",
                format!("must be finite and > 0, got {e}"),
            ));
        }
    }
    Ok(())
}

/// The antenna lever arm: `[gnss] lever_arm_b_m`, or `[mounting] gnss_lever_arm_m` (the
/// IMU sits at the reference point, so both are arms from the IMU).
fn effective_gnss(scn: &Scenario, gnss: &GnssConfig) -> Result<GnssConfig, FuseError> {
    if scn.mounting.imu.is_some() {
        return Err(FuseError::Option(
            "mounting",
            "the filter's body frame is the IMU and fuse compares with the truth at the vehicle reference point: remove [mounting] imu_lever_arm_m / imu_mount_deg, and give the antenna's lever arm from the IMU".into(),
        ));
    }
    match scn.mounting.gnss_lever_arm_b_m {
        Some(l) => {
            let own = Vec3::from(gnss.lever_arm_b_m);
            if own != Vec3::zeros() && own != l {
                return Err(FuseError::Option(
                    "mounting.gnss_lever_arm_m",
                    format!(
                        "differs from [gnss] lever_arm_b_m ({:?} m against {:?} m): give one",
                        [l.x, l.y, l.z],
                        gnss.lever_arm_b_m
                    ),
                ));
            }
            Ok(GnssConfig {
                lever_arm_b_m: [l.x, l.y, l.z],
                ..gnss.clone()
            })
        }
        None => Ok(gnss.clone()),
    }
}

/// The stream and the start of run `run` of a scenario (see the module documentation).
pub fn scenario_start<'a>(
    scn: &'a Scenario,
    cached: Option<&'a [TruthSample]>,
    gnss: &GnssConfig,
    opts: &FuseOptions,
    run: u64,
) -> Result<ScenarioSetup<'a>, FuseError> {
    check_options(opts)?;
    scn.aiding
        .validate()
        .map_err(|e| FuseError::Option("aiding", e.to_string()))?;
    let gnss = effective_gnss(scn, gnss)?;
    let earth = scn.nav.earth.model();
    let dt = scn.imu.dt_s();
    let n = opts.algo.samples.clamp(1, 4);
    let nav_rate = 1.0 / (dt * n as f64);
    let generator = TruthGenerator::new(&scn.trajectory, scn.truth_config());
    let init_true = generator.initial_state();
    let len_samples = generator.len_samples();
    let truth: Box<dyn Iterator<Item = TruthSample> + 'a> = match cached {
        Some(c) => Box::new(c.iter().copied()),
        None => Box::new(generator),
    };
    let sensor = ImuErrorState::new(&scn.imu.model, scn.imu.seed, run)
        .map_err(|e| FuseError::Imu(e.to_string()))?;
    let (true_bg, true_ba) = sensor.constant_bias();
    let (noise, s_ba, s_bg, known_ba, known_bg) = noise_from_model(&scn.imu.model);
    let prev = TruthSample::new(
        0.0,
        Increment::default(),
        init_true.lat_rad,
        init_true.lon_rad,
        init_true.h_m,
        init_true.v_n_mps,
        init_true.c_b_n,
    );
    let mut stream = ScenarioStream {
        truth,
        traj: &scn.trajectory,
        sensor,
        gsim: GnssSimulator::new(&gnss, earth, run)?,
        aiding: scn
            .aiding
            .any()
            .then(|| AidingSimulator::new(&scn.aiding, earth, run)),
        aid_out: Vec::with_capacity(8),
        prev,
        dt_s: dt,
        queue: VecDeque::new(),
        fixes: Vec::with_capacity(8),
        latency_fix_s: if gnss.latency_modelled {
            gnss.latency_s
        } else {
            0.0
        },
        zupt_speed_mps: opts
            .zupt
            .filter(|_| opts.zupt_detector.is_none())
            .map(|z| z.1),
        rest: false,
    };
    // in-motion start: run the sensors and the receiver until the first fix at speed
    let mut skipped = 0u64;
    let mut moving = None;
    if let Some(im) = &opts.in_motion {
        let mut last_inc = Increment::default();
        loop {
            let Some(ev) = stream.next() else {
                return Err(FuseError::Option(
                    "in_motion",
                    format!(
                        "no GNSS fix with a velocity and a horizontal speed of at least {} m/s in the scenario",
                        im.min_speed_mps
                    ),
                ));
            };
            match ev {
                Event::Imu { inc, .. } => {
                    last_inc = inc;
                    skipped += 1;
                }
                Event::Gnss { fix, .. }
                    if fix
                        .vel
                        .is_some_and(|(v, _)| v.x.hypot(v.y) >= im.min_speed_mps) =>
                {
                    moving = Some((fix, stream.prev, last_inc));
                    break;
                }
                _ => {}
            }
        }
    }
    let start_truth = stream.prev;
    let t_start = start_truth.t_s;
    let init_true = if moving.is_some() {
        InitialState {
            lat_rad: start_truth.lat_rad,
            lon_rad: start_truth.lon_rad,
            h_m: start_truth.h_m,
            v_n_mps: start_truth.v_n_mps,
            c_b_n: start_truth.c_b_n,
        }
    } else {
        init_true
    };
    // initial errors
    let s = &opts.init_sigma;
    let r0 = earth.radii(init_true.lat_rad);
    let t0 = Vec3::new(
        r0.r_m_m + init_true.h_m,
        (r0.r_n_m + init_true.h_m) * init_true.lat_rad.cos(),
        -1.0,
    );
    let mut w = [0.0; 9];
    if opts.draw_initial_errors {
        let mut rng = ChaCha20Rng::seed_from_u64(gnss.seed);
        rng.set_stream((1u64 << 63) | run.wrapping_mul(16).wrapping_add(10));
        for wi in &mut w {
            *wi = StandardNormal.sample(&mut rng);
        }
    }
    let dp = Vec3::from_fn(|i, _| s.pos_ned_m[i] * w[i]);
    let dv = Vec3::from_fn(|i, _| s.vel_ned_mps[i] * w[3 + i]);
    let eps = Vec3::from_fn(|i, _| s.att_rad[i] * w[6 + i]);
    // without drawn errors the truth itself (adding zero errors would turn −0 into +0)
    let mut init = if opts.draw_initial_errors {
        InitialState {
            lat_rad: init_true.lat_rad + dp.x / t0.x,
            lon_rad: init_true.lon_rad + dp.y / t0.y,
            h_m: init_true.h_m - dp.z,
            v_n_mps: init_true.v_n_mps + dv,
            c_b_n: Quat::from_rotvec(&eps).to_dcm() * init_true.c_b_n,
        }
    } else {
        init_true
    };
    let mut layout = noise.layout();
    if opts.scale_factors.is_some() {
        layout = layout
            .with_scale_factors()
            .map_err(|e| FuseError::Option("scale_factors", e.to_string()))?;
    }
    let mut p0 = Cov::zeros();
    if let (Some(sp), Some(a), Some(g)) = (
        &opts.scale_factors,
        layout.offset(BlockKind::AccelScale),
        layout.offset(BlockKind::GyroScale),
    ) {
        for i in 0..3 {
            p0[(a + i, a + i)] = (sp.accel_ppm[i] * 1e-6).powi(2);
            p0[(g + i, g + i)] = (sp.gyro_ppm[i] * 1e-6).powi(2);
        }
    }
    for i in 0..3 {
        p0[(i, i)] = (s.pos_ned_m[i] / t0[i]).powi(2);
        p0[(3 + i, 3 + i)] = s.vel_ned_mps[i].powi(2);
        p0[(6 + i, 6 + i)] = s.att_rad[i].powi(2);
        p0[(9 + i, 9 + i)] = s_ba[i].powi(2);
        p0[(12 + i, 12 + i)] = s_bg[i].powi(2);
    }
    layout = add_blocks(&scn.aiding, layout, &mut p0)
        .map_err(|e| FuseError::Option("aiding", e.to_string()))?;
    if let (Some((f, ts, meas)), Some(im)) = (moving, opts.in_motion) {
        init = in_motion_start(&f, &ts, &meas, dt, &gnss, &earth, &im, &mut p0);
    }
    let mut est0 = XVec::zeros();
    for i in 0..3 {
        est0[9 + i] = known_ba[i];
        est0[12 + i] = known_bg[i];
    }
    let mut total = len_samples.saturating_sub(skipped) / n as u64;
    if let Some(t) = opts.until_s {
        total = total.min(((t - t_start).max(0.0) * nav_rate).round() as u64);
    }
    let mut cfg = engine_config(
        opts.algo,
        earth,
        dt,
        opts.cov_rate_hz,
        noise,
        if opts.model_lever_arm {
            Vec3::from(gnss.lever_arm_b_m)
        } else {
            Vec3::zeros()
        },
        opts.every_s,
        total,
    )?;
    cfg.gate_chi2 = opts.gate_chi2;
    cfg.max_consecutive_rejections = opts.max_consecutive_rejections;
    cfg.max_latency_s = opts.max_latency_s;
    cfg.zupt_sigma_mps = opts.zupt.map(|z| z.0);
    cfg.nhc_sigma_mps = opts.nhc_sigma_mps;
    cfg.zupt_detector = opts.zupt_detector;
    cfg.smooth = opts.smooth;
    let sensor_truth = stream.aiding.as_ref().map(AidingSimulator::truth);
    Ok(ScenarioSetup {
        stream,
        start: Start {
            t_start_s: t_start,
            state: init,
            layout,
            p0,
            est0,
            truth: Some(start_truth),
            sensor_truth,
        },
        cfg,
        truths: Truths {
            ba: true_ba,
            bg: true_bg,
            sf: opts
                .scale_factors
                .map(|_| true_scale_factors(&scn.imu.model)),
        },
    })
}

/// The in-motion initial state from the fix `f` at speed (heading from its track, pitch
/// from the climb, roll 0) advanced to the start sample `ts`; its σ into `p0`.
#[allow(clippy::too_many_arguments)]
fn in_motion_start(
    f: &GnssFix,
    ts: &TruthSample,
    meas: &Increment,
    dt: f64,
    gnss: &GnssConfig,
    earth: &sdins_core::earth::EarthModel,
    im: &crate::fusion::simulated::InMotionInit,
    p0: &mut Cov,
) -> InitialState {
    let (v_a, cv) = f.vel.unwrap_or((Vec3::zeros(), Mat3::identity()));
    let vh = v_a.x.hypot(v_a.y);
    let w_z = meas.dtheta_b_rad.z / dt;
    let yaw = v_a.y.atan2(v_a.x) + w_z * (ts.t_s - f.t_s);
    let pitch = (-v_a.z).atan2(vh);
    let c = sdins_core::math::c_b_n_from_euler(&sdins_core::math::Euler::new(0.0, pitch, yaw));
    let l = Vec3::from(gnss.lever_arm_b_m);
    let w_b = meas.dtheta_b_rad / dt;
    let v = v_a - c * w_b.cross(&l);
    let cl = c * l;
    let r = earth.radii(f.lat_rad);
    let sc =
        sdins_core::aiding::error_model::position_scale(r.r_m_m, r.r_n_m, f.lat_rad.cos(), f.h_m);
    // the fix is at t_f ≤ t_start: advance by the velocity over the gap
    let gap = ts.t_s - f.t_s;
    let (sy, cy) = yaw.sin_cos();
    let s_psi2 =
        im.track_sigma_rad.powi(2) + (cv[(0, 0)] * sy * sy + cv[(1, 1)] * cy * cy) / (vh * vh);
    let m = crate::fusion::records::euler_error_matrix(&c);
    let mi = m.try_inverse().unwrap_or_else(Mat3::identity);
    let d = Mat3::from_diagonal(&Vec3::new(
        im.tilt_sigma_rad.powi(2),
        im.tilt_sigma_rad.powi(2),
        s_psi2,
    ));
    let pa = mi * d * mi.transpose();
    for i in 0..3 {
        for j in 0..3 {
            p0[(i, j)] = f.pos_cov_ned_m2[(i, j)] / (sc[i] * sc[j]);
            p0[(3 + i, 3 + j)] = cv[(i, j)];
            p0[(6 + i, 6 + j)] = pa[(i, j)];
        }
    }
    InitialState {
        lat_rad: f.lat_rad + (v.x * gap - cl.x) / sc.x,
        lon_rad: f.lon_rad + (v.y * gap - cl.y) / sc.y,
        h_m: f.h_m - v.z * gap + cl.z,
        v_n_mps: v,
        c_b_n: c,
    }
}
