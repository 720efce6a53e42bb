//! The one fusion loop: a time-ordered stream of events (IMU samples, measurements of any
//! kind, rest indications) through the error-state filter (`sdins_core::aiding::ekf`), the
//! output-epoch rule ([`crate::nav::epochs::EpochGrid`]) and, optionally, the
//! Rauch–Tung–Striebel smoother ([`crate::fusion::smoother`]). Scenario fusion
//! ([`crate::fusion::simulated`]: the stream generated from the exact truth) and recorded
//! fusion ([`crate::fusion::records`]: the stream read from files) both run it.
//!
//! ## The stream ([`Event`])
//! * `Imu`: one raw IMU sample ending at `t_s` (the source's clock), with the truth at that
//!   instant when the source knows it;
//! * `Gnss`: a fix (its `t_s` the time of validity) and its arrival time; a source may
//!   deliver a measurement before it arrives, never after the IMU sample during which it
//!   arrives;
//! * `Rest`: the vehicle is (or is no longer) at rest (the scenario's truth, or a flag
//!   column); ignored when the loop's own stationarity detector decides
//!   ([`EngineConfig::zupt_detector`]: every raw sample goes through it, with the filter's
//!   bias estimates and attitude refreshed at each covariance epoch);
//! * `Meas`: a measurement of another sensor (barometer, odometer, magnetometer, dual
//!   antenna, body velocity), with its arrival time, handled like a fix;
//! * `SensorTruth`: the true sensor parameters from now on (scenarios; passed to the
//!   rows).
//!
//! ## The loop
//! Every `N` IMU samples one navigation update (`Ekf::propagate`). Then, in arrival
//! order, every pending measurement whose arrival lies at or before the update's end
//! (1 ns tolerance) is applied at its time of validity (`Ekf::update`). Every
//! `cov_updates` updates (the covariance epochs of the regular rate) the constraint: a
//! ZUPT when at rest, else the NHC, when configured. Output rows: update `j` is a row when
//! [`crate::nav::epochs::EpochCursor::is_output`] says so (row 0 is the initial state, the
//! last update is always a row); a row carries the current covariance, i.e. that of the
//! latest covariance epoch, and the state at that epoch (`Row::cov_state`, for σ in
//! state-dependent units). With smoothing, the covariance epochs are logged and after the
//! forward pass the smoother's epochs (`SmoothedCov`, last to first) and then the smoothed
//! rows (`Smoothed`, in time order, the correction interpolated between epochs) are
//! reported.

use crate::cancel::{CancelToken, Cancelled};
use crate::fusion::detector::{AnyDetector, DetectorError, DetectorSettings};
use crate::fusion::smoother::{SmootherError, SmootherLog};
use crate::nav::epochs::EpochGrid;
use crate::sensors::aiding::{shifted, SensorTruth};
use crate::sensors::gnss_fix::GnssFix;
use crate::truth::TruthSample;
use sdins_core::aiding::ekf::{
    correct_nav_state, CovEpoch, Ekf, EkfConfig, FilterError, NoiseModel, UpdateReport,
};
use sdins_core::aiding::layout::{Cov, StateLayout, XVec};
use sdins_core::aiding::linalg::MAX_ROWS;
use sdins_core::aiding::meas::{GnssMeasurement, MeasKind};
use sdins_core::aiding::sensors::AidingMeas;
use sdins_core::coning::Increment;
use sdins_core::earth::EarthModel;
use sdins_core::math::Vec3;
use sdins_core::nav::{AlgorithmSpec, AnyMechanization, InitialState, NavState};
use std::collections::VecDeque;

/// One event of the stream.
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub enum Event {
    /// one raw IMU sample ending at `t_s` (source clock) \[s\], and the truth then
    Imu {
        /// end of the sample \[s\]
        t_s: f64,
        /// measured increments (FRD)
        inc: Increment,
        /// the truth at `t_s` (scenarios)
        truth: Option<TruthSample>,
    },
    /// a GNSS fix (`fix.t_s` = time of validity, source clock) arriving at `arrival_s`
    Gnss {
        /// the fix
        fix: GnssFix,
        /// arrival time \[s\]
        arrival_s: f64,
    },
    /// at rest from now on (`true`) or moving
    Rest(bool),
    /// a measurement of any other kind (its time of validity on the source clock)
    /// arriving at `arrival_s`
    Meas {
        /// the measurement
        meas: AidingMeas,
        /// arrival time \[s\]
        arrival_s: f64,
    },
    /// the true sensor parameters from now on (scenarios)
    SensorTruth(SensorTruth),
}

/// Where and how the filter starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Start {
    /// time of the initial state on the source clock \[s\]
    pub t_start_s: f64,
    /// the initial navigation state
    pub state: InitialState,
    /// the state layout
    pub layout: StateLayout,
    /// initial covariance (leading n × n)
    pub p0: Cov,
    /// initial sensor-parameter estimates (at their block offsets)
    pub est0: XVec,
    /// the truth at the start (scenarios)
    pub truth: Option<TruthSample>,
    /// the true sensor parameters at the start (scenarios with aiding sensors)
    pub sensor_truth: Option<SensorTruth>,
}

/// The loop's settings.
#[derive(Clone, Debug, PartialEq)]
pub struct EngineConfig {
    /// mechanization
    pub algo: AlgorithmSpec,
    /// earth model
    pub earth: EarthModel,
    /// IMU sample period \[s\]
    pub dt_s: f64,
    /// navigation updates per regular covariance epoch
    pub cov_updates: usize,
    /// white sensor noise
    pub noise: NoiseModel,
    /// NIS gate by dof (None: off)
    pub gate_chi2: Option<[f64; MAX_ROWS]>,
    /// consecutive rejections before the reset policy
    pub max_consecutive_rejections: u32,
    /// largest latency of a measurement \[s\]
    pub max_latency_s: f64,
    /// GNSS antenna lever arm, body \[m\]
    pub lever_arm_b_m: Vec3,
    /// ZUPT σ \[m/s\] (applied at the regular covariance epochs while at rest)
    pub zupt_sigma_mps: Option<f64>,
    /// NHC σ \[m/s\] (applied at the regular covariance epochs while moving)
    pub nhc_sigma_mps: Option<f64>,
    /// decide rest with the IMU's stationarity detector ([`crate::fusion::detector`])
    /// instead of the stream's `Rest` events (which are then ignored)
    pub zupt_detector: Option<DetectorSettings>,
    /// run the smoother
    pub smooth: bool,
    /// output rows: the updates nearest to `t_start + k·every_s` \[s\]
    pub every_s: f64,
    /// navigation updates of the whole run (the last is always a row)
    pub total_updates: u64,
}

/// An output row (a navigation update).
#[derive(Clone, Copy, Debug)]
pub struct Row<'a> {
    /// update index (0 = the initial state)
    pub index: u64,
    /// time on the source clock \[s\]
    pub t_s: f64,
    /// the navigation state (its `t_s` counts from the start)
    pub state: &'a NavState,
    /// sensor-parameter estimates
    pub est: &'a XVec,
    /// forward rows: the covariance (of the latest covariance epoch); smoothed rows: None
    /// (the smoothed covariance of epoch [`Row::epoch`] came with `SmoothedCov`)
    pub p: Option<&'a Cov>,
    /// the state at the latest covariance epoch (where P belongs)
    pub cov_state: &'a NavState,
    /// index of the latest covariance epoch (0 = the initial one)
    pub epoch: usize,
    /// the layout
    pub layout: &'a StateLayout,
    /// the truth at the row (scenarios)
    pub truth: Option<&'a TruthSample>,
    /// the true sensor parameters at the row (scenarios with aiding sensors)
    pub sensor_truth: Option<&'a SensorTruth>,
}

/// What the loop reports.
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub enum EngineEvent<'a> {
    /// a forward row
    Forward(&'a Row<'a>),
    /// a measurement (times on the source clock)
    Update(&'a UpdateReport),
    /// a smoothed covariance epoch (last to first)
    SmoothedCov {
        /// epoch index
        epoch: usize,
        /// the smoothed covariance
        p: &'a Cov,
        /// the forward state at the epoch
        state: &'a NavState,
    },
    /// a smoothed row (in time order)
    Smoothed(&'a Row<'a>),
}

/// Per measurement kind: applied, rejected by the gate, refused as late.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct KindCounts {
    /// applied (including forced)
    pub applied: u64,
    /// rejected by the gate
    pub rejected: u64,
    /// refused as late
    pub late: u64,
}

/// What a run did.
#[derive(Clone, Debug, PartialEq)]
pub struct EngineSummary {
    /// navigation updates
    pub nav_updates: u64,
    /// covariance epochs (after the initial one)
    pub cov_epochs: u64,
    /// per kind ([`MeasKind::index`])
    pub counts: [KindCounts; MeasKind::COUNT],
    /// final navigation state
    pub state: NavState,
    /// final estimates
    pub est: XVec,
    /// final covariance
    pub p: Cov,
    /// the layout
    pub layout: StateLayout,
    /// the start on the source clock \[s\]
    pub t_start_s: f64,
    /// bytes of the smoother log (0 without smoothing)
    pub smoother_bytes: usize,
}

/// Why the loop stopped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EngineError {
    /// A setting is out of range.
    #[error("fuse option `{0}`: {1}")]
    Option(&'static str, String),
    /// The filter failed.
    #[error(transparent)]
    Filter(#[from] FilterError),
    /// The smoother failed.
    #[error(transparent)]
    Smoother(#[from] SmootherError),
    /// Cancelled.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
    /// The zero-velocity detector cannot be built.
    #[error(transparent)]
    Detector(#[from] DetectorError),
}

/// The smoother's forward records.
struct Track {
    log: SmootherLog,
    /// per epoch: the estimates (n values) and the state
    epoch_est: Vec<f64>,
    epoch_state: Vec<NavState>,
    /// per row: the forward state
    rows: Vec<NavState>,
    truth: Vec<TruthSample>,
    sensor_truth: Vec<SensorTruth>,
    /// update interval \[s\]
    dt_update_s: f64,
}

impl Track {
    fn epoch(&mut self, ep: &CovEpoch, est: &XVec, st: &NavState) -> Result<(), SmootherError> {
        self.log.push(ep)?;
        self.epoch_est.extend((0..ep.n).map(|i| est[i]));
        self.epoch_state.push(*st);
        Ok(())
    }
}

fn check(cfg: &EngineConfig) -> Result<(), EngineError> {
    let bad = |k: &'static str, m: String| Err(EngineError::Option(k, m));
    if !(cfg.dt_s.is_finite() && cfg.dt_s > 0.0) {
        return bad("dt_s", format!("must be > 0, got {}", cfg.dt_s));
    }
    if !(cfg.every_s.is_finite() && cfg.every_s > 0.0) {
        return bad("every_s", format!("must be > 0, got {}", cfg.every_s));
    }
    if !(cfg.max_latency_s.is_finite() && cfg.max_latency_s >= 0.0) {
        return bad(
            "max_latency_s",
            format!("must be ≥ 0, got {}", cfg.max_latency_s),
        );
    }
    for (k, v) in [
        ("zupt_sigma_mps", cfg.zupt_sigma_mps),
        ("nhc_sigma_mps", cfg.nhc_sigma_mps),
    ] {
        if let Some(x) = v {
            if !(x.is_finite() && x > 0.0) {
                return bad(k, format!("must be finite and > 0, got {x}"));
            }
        }
    }
    Ok(())
}

/// Run the loop over `events` from `start`; `observe` sees every row and report.
pub fn run_engine(
    events: &mut dyn Iterator<Item = Event>,
    start: &Start,
    cfg: &EngineConfig,
    cancel: &CancelToken,
    observe: &mut dyn FnMut(EngineEvent<'_>),
) -> Result<EngineSummary, EngineError> {
    check(cfg)?;
    let n = cfg.algo.samples.clamp(1, 4);
    let grid = EpochGrid::new(cfg.every_s, cfg.dt_s * n as f64)
        .map_err(|e| EngineError::Option("every_s", e.to_string()))?;
    let mut cursor = grid.cursor(cfg.total_updates);
    let t0 = start.t_start_s;
    let mech = AnyMechanization::new(&cfg.algo, cfg.earth, cfg.dt_s, &start.state);
    let ekf_cfg = EkfConfig {
        earth: cfg.earth,
        dt_s: cfg.dt_s,
        cov_updates: cfg.cov_updates.max(1),
        noise: cfg.noise,
        gate_chi2: cfg.gate_chi2,
        max_consecutive_rejections: cfg.max_consecutive_rejections,
        max_latency_s: cfg.max_latency_s,
    };
    let mut ekf = Ekf::new(mech, ekf_cfg, start.layout, &start.p0, &start.est0);
    let nx = start.layout.n();
    let mut track = cfg.smooth.then(|| {
        let epochs = (cfg.total_updates / cfg.cov_updates.max(1) as u64 + 2) as usize;
        let rows = (cfg.total_updates as f64 * cfg.dt_s * n as f64 / cfg.every_s + 2.0) as usize;
        Track {
            log: SmootherLog::with_capacity(epochs, nx),
            epoch_est: Vec::with_capacity(epochs * nx),
            epoch_state: Vec::with_capacity(epochs),
            rows: Vec::with_capacity(rows.min(cfg.total_updates as usize + 1)),
            truth: Vec::new(),
            sensor_truth: Vec::new(),
            dt_update_s: cfg.dt_s * n as f64,
        }
    });
    let mut cov_state = ekf.state();
    let mut epoch = 0usize;
    if let Some(t) = track.as_mut() {
        t.epoch(&ekf.initial_epoch(), ekf.estimates(), &cov_state)?;
    }
    let mut truth = start.truth;
    let mut sensor_truth = start.sensor_truth;
    let emit_row = |ekf: &Ekf<AnyMechanization>,
                    j: u64,
                    cov_state: &NavState,
                    epoch: usize,
                    truth: Option<&TruthSample>,
                    sensor_truth: Option<&SensorTruth>,
                    track: &mut Option<Track>,
                    observe: &mut dyn FnMut(EngineEvent<'_>)| {
        let st = ekf.state();
        let row = Row {
            index: j,
            t_s: t0 + st.t_s,
            state: &st,
            est: ekf.estimates(),
            p: Some(ekf.covariance()),
            cov_state,
            epoch,
            layout: ekf.layout(),
            truth,
            sensor_truth,
        };
        observe(EngineEvent::Forward(&row));
        if let Some(t) = track.as_mut() {
            t.rows.push(st);
            if let Some(tr) = truth {
                t.truth.push(*tr);
            }
            if let Some(s) = sensor_truth {
                t.sensor_truth.push(*s);
            }
        }
    };
    let mut last_row = None;
    if cursor.is_output(0) {
        emit_row(
            &ekf,
            0,
            &cov_state,
            0,
            truth.as_ref(),
            sensor_truth.as_ref(),
            &mut track,
            observe,
        );
        last_row = Some(0);
    }
    let mut detector = match cfg.zupt_detector {
        Some(ds) if cfg.zupt_sigma_mps.is_some() => Some(build_detector(&ds, cfg, start)?),
        _ => None,
    };
    let mut counts = [KindCounts::default(); MeasKind::COUNT];
    let mut pending: VecDeque<(f64, Pending)> = VecDeque::new();
    let mut held: Option<Event> = None;
    let mut at_rest = false;
    let mut incs = [Increment::default(); 4];
    let mut k = 0u64;
    let mut cov_epochs = 0u64;
    'outer: while k < cfg.total_updates {
        if k.is_multiple_of(1024) {
            cancel.check()?;
        }
        // n samples, and every non-IMU event up to the next sample
        let mut got = 0;
        loop {
            let ev = match held.take() {
                Some(e) => Some(e),
                None => events.next(),
            };
            let Some(ev) = ev else {
                if got < n {
                    break 'outer;
                }
                break;
            };
            match ev {
                Event::Imu { inc, truth: tr, .. } => {
                    if got == n {
                        held = Some(ev);
                        break;
                    }
                    incs[got] = inc;
                    got += 1;
                    if let Some(d) = detector.as_mut() {
                        // a non-finite sample fails the propagation below with its time
                        if let Ok(Some(r)) = d.push(&inc) {
                            at_rest = r;
                        }
                    }
                    if tr.is_some() {
                        truth = tr;
                    }
                }
                Event::Gnss { fix, arrival_s } => pending.push_back((arrival_s, Pending::Fix(fix))),
                Event::Meas { meas, arrival_s } => {
                    pending.push_back((arrival_s, Pending::Meas(meas)))
                }
                Event::Rest(r) if detector.is_none() => at_rest = r,
                Event::Rest(_) => {}
                Event::SensorTruth(s) => sensor_truth = Some(s),
            }
        }
        ekf.propagate(&incs[..n])?;
        let t_nav = ekf.state().t_s;
        // measurements that have arrived by now, in arrival order
        let mut i = 0;
        while i < pending.len() {
            if pending[i].0 - t0 <= t_nav + 1e-9 {
                let Some((_, p)) = pending.remove(i) else {
                    break;
                };
                let m = match p {
                    Pending::Fix(f) => AidingMeas::Gnss(GnssMeasurement {
                        t_s: f.t_s - t0,
                        lat_rad: f.lat_rad,
                        lon_rad: f.lon_rad,
                        h_m: f.h_m,
                        pos_cov_ned_m2: f.pos_cov_ned_m2,
                        vel: f.vel,
                        lever_arm_b_m: cfg.lever_arm_b_m,
                    }),
                    Pending::Meas(m) => shifted(m, t0),
                };
                let rep = ekf.update(&m)?;
                report(&rep, &mut counts, t0, observe);
            } else {
                i += 1;
            }
        }
        if (k + 1).is_multiple_of(cfg.cov_updates.max(1) as u64) {
            let rep = match (at_rest, cfg.zupt_sigma_mps, cfg.nhc_sigma_mps) {
                (true, Some(s), _) => Some(ekf.update_zupt(s)?),
                (_, _, Some(s)) => Some(ekf.update_nhc(s)?),
                _ => None,
            };
            if let Some(rep) = rep {
                report(&rep, &mut counts, t0, observe);
            }
        }
        if let Some(ep) = ekf.take_epoch() {
            if let Some(d) = detector.as_mut() {
                let (st, est) = (ekf.state(), ekf.estimates());
                let b_a = Vec3::new(est[9], est[10], est[11]);
                let b_g = Vec3::new(est[12], est[13], est[14]);
                let _ = d.set_estimates(&b_a, &b_g, &st.c_b_n, &cfg.earth.omega_ie_n(st.lat_rad));
            }
            cov_epochs += 1;
            epoch += 1;
            cov_state = ekf.state();
            if let Some(t) = track.as_mut() {
                t.epoch(&ep, ekf.estimates(), &cov_state)?;
            }
        }
        k += 1;
        if cursor.is_output(k) {
            emit_row(
                &ekf,
                k,
                &cov_state,
                epoch,
                truth.as_ref(),
                sensor_truth.as_ref(),
                &mut track,
                observe,
            );
            last_row = Some(k);
        }
    }
    if last_row != Some(k) {
        emit_row(
            &ekf,
            k,
            &cov_state,
            epoch,
            truth.as_ref(),
            sensor_truth.as_ref(),
            &mut track,
            observe,
        );
    }
    let mut smoother_bytes = 0;
    if let Some(t) = track {
        smoother_bytes = t.log.bytes();
        smooth_rows(&t, t0, nx, ekf.layout(), cancel, observe)?;
    }
    Ok(EngineSummary {
        nav_updates: k,
        cov_epochs,
        counts,
        state: ekf.state(),
        est: *ekf.estimates(),
        p: *ekf.covariance(),
        layout: *ekf.layout(),
        t_start_s: t0,
        smoother_bytes,
    })
}

/// The detector from the filter's white noise (largest axis), gravity at the start and
/// the prior σ of the bias blocks (largest axis) as the residual biases.
fn build_detector(
    ds: &DetectorSettings,
    cfg: &EngineConfig,
    start: &Start,
) -> Result<AnyDetector, EngineError> {
    let sd = |o: usize| Vec3::from_fn(|i, _| start.p0[(o + i, o + i)].max(0.0).sqrt());
    let g = cfg.earth.gravity(start.state.lat_rad, start.state.h_m);
    let mut d = AnyDetector::from_filter_noise(ds, &cfg.noise, cfg.dt_s, g, &sd(9), &sd(12))?;
    let b_a = Vec3::new(start.est0[9], start.est0[10], start.est0[11]);
    let b_g = Vec3::new(start.est0[12], start.est0[13], start.est0[14]);
    d.set_estimates(
        &b_a,
        &b_g,
        &start.state.c_b_n,
        &cfg.earth.omega_ie_n(start.state.lat_rad),
    )
    .map_err(|e| EngineError::Option("zupt_detector", format!("{e}")))?;
    Ok(d)
}

/// A measurement waiting for its arrival time.
#[derive(Clone, Copy, Debug)]
#[allow(clippy::large_enum_variant)]
enum Pending {
    Fix(GnssFix),
    Meas(AidingMeas),
}

/// Count a report and pass it on with its times on the source clock.
fn report(
    rep: &UpdateReport,
    counts: &mut [KindCounts; MeasKind::COUNT],
    t0: f64,
    observe: &mut dyn FnMut(EngineEvent<'_>),
) {
    let c = &mut counts[rep.kind.index()];
    if rep.late {
        c.late += 1;
    } else if rep.accepted {
        c.applied += 1;
    } else {
        c.rejected += 1;
    }
    let mut r = *rep;
    r.t_s += t0;
    r.t_valid_s += t0;
    observe(EngineEvent::Update(&r));
}

/// The backward pass and the smoothed rows.
fn smooth_rows(
    t: &Track,
    t0: f64,
    nx: usize,
    layout: &StateLayout,
    cancel: &CancelToken,
    observe: &mut dyn FnMut(EngineEvent<'_>),
) -> Result<(), EngineError> {
    let corr = t.log.smooth(cancel, |k, _, sm| {
        if let Some(st) = t.epoch_state.get(k) {
            observe(EngineEvent::SmoothedCov {
                epoch: k,
                p: &sm.p,
                state: st,
            });
        }
    })?;
    let mut e = 0usize;
    for (i, fwd) in t.rows.iter().enumerate() {
        if i % 4096 == 0 {
            cancel.check()?;
        }
        while e + 1 < corr.len() && t.log.t_s(e + 1).is_some_and(|te| te <= fwd.t_s + 1e-9) {
            e += 1;
        }
        let x = corr.at(e, fwd.t_s);
        let s = correct_nav_state(fwd, &x);
        let mut est = XVec::zeros();
        for k in 0..nx {
            est[k] = t.epoch_est.get(e * nx + k).copied().unwrap_or(0.0);
            if k >= 9 {
                est[k] += x[k];
            }
        }
        let Some(cov_state) = t.epoch_state.get(e) else {
            continue;
        };
        let row = Row {
            index: (fwd.t_s / t.dt_update_s).round() as u64,
            t_s: t0 + s.t_s,
            state: &s,
            est: &est,
            p: None,
            cov_state,
            epoch: e,
            layout,
            truth: t.truth.get(i),
            sensor_truth: t.sensor_truth.get(i),
        };
        observe(EngineEvent::Smoothed(&row));
    }
    Ok(())
}
