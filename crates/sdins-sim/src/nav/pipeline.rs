//! Streaming truth → navigation → errors pipeline, in constant memory.
//!
//! Truth is generated once, in blocks of navigation updates, and every algorithm is
//! fed the same block; each algorithm's time is measured around its own update loop only
//! (the `wall_s` of `sdins run --json`).

use crate::cancel::{CancelToken, Cancelled};
use crate::nav::epochs::{EpochCursor, EpochGrid};
use crate::scenario::Scenario;
use crate::sensors::imu_error::{ImuErrorModel, ImuErrorState};
use crate::truth::{lon_diff, TruthConfig, TruthGenerator, TruthSample};
use sdins_core::coning::Increment;
use sdins_core::earth::EarthModel;
use sdins_core::math::Vec3;
use sdins_core::nav::{AlgorithmSpec, AnyMechanization, Mechanization, NavState};
use std::time::Instant;

/// Navigation errors at one epoch (docs/conventions.md §"Errors").
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct NavError {
    /// time \[s\]
    pub t_s: f64,
    /// position error N, E, D \[m\]: δN = δL(R_M+h), δE = δλ(R_N+h)cosL, δD = −δh
    pub pos_err_ned_m: [f64; 3],
    /// velocity error v_alg − v_true, NED \[m/s\]
    pub vel_err_ned_mps: [f64; 3],
    /// attitude error ε, NED \[rad\], C_alg C_trueᵀ = I + \[ε×\]
    pub att_err_rad: [f64; 3],
    /// height error h_alg − h_true \[m\]
    pub height_err_m: f64,
    /// Euler-angle differences roll, pitch, yaw, wrapped to (−π, π] \[rad\]
    pub euler_err_rad: [f64; 3],
}

impl NavError {
    /// Element-wise maximum of absolute values (`t_s` is the later time). A NaN in
    /// either operand propagates (and stays): a diverged solution must not be hidden
    /// behind the maximum of its finite epochs, as `f64::max` would do.
    #[inline]
    pub fn max_abs(&self, o: &NavError) -> NavError {
        #[inline(always)]
        fn m(a: f64, b: f64) -> f64 {
            let (a, b) = (a.abs(), b.abs());
            if b > a || b.is_nan() {
                b
            } else {
                a
            }
        }
        let m3 = |a: [f64; 3], b: [f64; 3]| [m(a[0], b[0]), m(a[1], b[1]), m(a[2], b[2])];
        NavError {
            t_s: self.t_s.max(o.t_s),
            pos_err_ned_m: m3(self.pos_err_ned_m, o.pos_err_ned_m),
            vel_err_ned_mps: m3(self.vel_err_ned_mps, o.vel_err_ned_mps),
            att_err_rad: m3(self.att_err_rad, o.att_err_rad),
            height_err_m: m(self.height_err_m, o.height_err_m),
            euler_err_rad: m3(self.euler_err_rad, o.euler_err_rad),
        }
    }
}

fn arr(v: &Vec3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// Errors of a navigation state against the truth (docs/conventions.md §"Errors").
///
/// Evaluated without intermediate Euler angles: each Euler-angle difference is one
/// `atan2` of the cross and dot products of the two angles' (sin, cos) pairs, which is
/// the wrapped difference `wrap(α − β)` itself (3 `atan2` instead of 4 `atan2`, 2 `asin`
/// and 3 `fmod`), and only the antisymmetric part of `C_alg C_trueᵀ` is formed. The
/// results equal the textbook formulas to rounding (see the tests).
#[inline]
pub fn nav_error(earth: &EarthModel, nav: &NavState, truth: &TruthSample) -> NavError {
    let (sin_lat, cos_lat) = truth.sin_cos_lat;
    debug_assert!(
        (sin_lat - libm::sin(truth.lat_rad)).abs() <= 1e-15,
        "stale sin_cos_lat"
    );
    let r = earth.radii_sin(sin_lat);
    let dlat = nav.lat_rad - truth.lat_rad;
    let dlon = lon_diff(nav.lon_rad, truth.lon_rad);
    let dh = nav.h_m - truth.h_m;
    let pos = [
        dlat * (r.r_m_m + truth.h_m),
        dlon * (r.r_n_m + truth.h_m) * cos_lat,
        -dh,
    ];
    let (a, t) = (&nav.c_b_n, &truth.c_b_n);
    // (C_a C_tᵀ)_ij = row_i(C_a) · row_j(C_t); ε = vee of its antisymmetric part
    let m =
        |i: usize, j: usize| a[(i, 0)] * t[(j, 0)] + a[(i, 1)] * t[(j, 1)] + a[(i, 2)] * t[(j, 2)];
    let att = [
        0.5 * (m(2, 1) - m(1, 2)),
        0.5 * (m(0, 2) - m(2, 0)),
        0.5 * (m(1, 0) - m(0, 1)),
    ];
    // angle difference of atan2(ya, xa) − atan2(yt, xt), wrapped to (−π, π]
    let diff =
        |ya: f64, xa: f64, yt: f64, xt: f64| atan2_small(ya * xt - xa * yt, xa * xt + ya * yt);
    // pitch = asin(s) with s = −C31 clamped: (sin, cos) = (s, √(1 − s²))
    let sc = |c: &sdins_core::math::Mat3| {
        let s = (-c[(2, 0)]).clamp(-1.0, 1.0);
        (s, (1.0 - s * s).max(0.0).sqrt())
    };
    let (sa, ca) = sc(a);
    let (st, ct) = sc(t);
    NavError {
        t_s: truth.t_s,
        pos_err_ned_m: pos,
        vel_err_ned_mps: arr(&(nav.v_n_mps - truth.v_n_mps)),
        att_err_rad: att,
        height_err_m: dh,
        euler_err_rad: [
            diff(a[(2, 1)], a[(2, 2)], t[(2, 1)], t[(2, 2)]),
            diff(sa, ca, st, ct),
            diff(a[(1, 0)], a[(0, 0)], t[(1, 0)], t[(0, 0)]),
        ],
    }
}

/// `atan2(y, x)` with a short path for the small angles that navigation errors are:
/// for `x > 0` and `|y| ≤ 10⁻³ x`, `atan z = z − z³/3 + z⁵/5 − z⁷/7 + O(z⁹)` with
/// `z = y/x`, whose truncation is below `z⁸/9 ≤ 1.2·10⁻²⁵` relative, far under one ulp;
/// otherwise `libm::atan2`.
#[inline]
pub fn atan2_small(y: f64, x: f64) -> f64 {
    if x > 0.0 && y.abs() <= 1e-3 * x {
        let z = y / x;
        let z2 = z * z;
        z * (1.0 - z2 * (1.0 / 3.0 - z2 * (1.0 / 5.0 - z2 * (1.0 / 7.0))))
    } else {
        libm::atan2(y, x)
    }
}

/// Summary of one algorithm's run.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RunSummary {
    /// algorithm CLI name
    pub algo: String,
    /// samples per update
    pub samples: usize,
    /// number of navigation updates
    pub nav_updates: u64,
    /// time spent in the navigation loop only \[s\]
    pub wall_s: f64,
    /// errors at the last update
    #[serde(rename = "final")]
    pub final_err: NavError,
    /// maximum absolute errors over every update of the run (not only the output epochs:
    /// the same for every observer and every `every_s`)
    pub max_abs: NavError,
}

/// Options of a pipeline run.
#[derive(Clone, Debug, PartialEq)]
pub struct RunOptions {
    /// algorithms to run side by side (all must share N)
    pub algos: Vec<AlgorithmSpec>,
    /// vertical channel held to the truth
    pub vertical_hold: bool,
    /// output rows every `every_s` seconds by the rule of [`crate::nav::epochs`] (the
    /// update nearest to `k·every_s`, the initial state and the last update included);
    /// `None`: every navigation update (not the initial state)
    pub every_s: Option<f64>,
    /// stop after this time \[s\] (None: whole scenario)
    pub until_s: Option<f64>,
    /// apply the scenario's IMU error model as run number `run` (None: ideal sensors)
    pub sensor_run: Option<u64>,
}

/// Why a pipeline run did not complete.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PipelineError {
    /// The cancellation token was set.
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
    /// No algorithm to run.
    #[error("no algorithm given")]
    NoAlgorithm,
    /// Algorithms side by side must consume the same samples per update.
    #[error("algorithms run side by side must share the samples per update: {first} has N = {n0}, {other} has N = {n1}")]
    MixedSamples {
        /// first algorithm
        first: &'static str,
        /// its N
        n0: usize,
        /// the differing one
        other: &'static str,
        /// its N
        n1: usize,
    },
    /// N outside 1..=4, or a coefficient set for another N.
    #[error("{algo}: {what}")]
    BadAlgorithm {
        /// algorithm
        algo: &'static str,
        /// what is wrong
        what: String,
    },
    /// `until_s` is not a positive finite time.
    #[error("until_s = {0}: expected a positive finite time [s]")]
    BadUntil(f64),
    /// The output spacing.
    #[error("{0}")]
    BadEvery(String),
}

/// Check the algorithm list of a run: non-empty, one N in 1..=4 shared by all, coning sets
/// that accept that N.
pub fn check_algorithms(algos: &[AlgorithmSpec]) -> Result<usize, PipelineError> {
    let first = algos.first().ok_or(PipelineError::NoAlgorithm)?;
    let n = first.samples;
    for a in algos {
        if a.samples != n {
            return Err(PipelineError::MixedSamples {
                first: first.kind.name(),
                n0: n,
                other: a.kind.name(),
                n1: a.samples,
            });
        }
        if !(1..=4).contains(&a.samples) {
            return Err(PipelineError::BadAlgorithm {
                algo: a.kind.name(),
                what: format!("samples per update {} is outside 1..=4", a.samples),
            });
        }
        if !a.coning.accepts(a.samples) {
            return Err(PipelineError::BadAlgorithm {
                algo: a.kind.name(),
                what: format!(
                    "coning set {} is for {} samples, not {}",
                    a.coning.name(),
                    a.coning.samples(),
                    a.samples
                ),
            });
        }
    }
    Ok(n)
}

/// What a run reports as it goes (see [`run_observed`]).
pub trait RunObserver {
    /// An output row of algorithm `algo` (the rows of [`RunOptions::every_s`]).
    fn epoch(&mut self, algo: usize, state: &NavState, truth: &TruthSample, err: &NavError);
    /// Every navigation update of algorithm `algo` (figures), when [`Self::wants_updates`].
    fn update(&mut self, _algo: usize, _state: &NavState, _truth: &TruthSample, _err: &NavError) {}
    /// Whether [`Self::update`] is wanted (the errors of every update cost time).
    fn wants_updates(&self) -> bool {
        false
    }
    /// Progress: `done` of `total` updates, once per block.
    fn progress(&mut self, _done: u64, _total: u64) {}
}

struct Closures<O, P>(O, P);

impl<O, P> RunObserver for Closures<O, P>
where
    O: FnMut(usize, &NavState, &TruthSample, &NavError),
    P: FnMut(u64, u64),
{
    fn epoch(&mut self, algo: usize, state: &NavState, truth: &TruthSample, err: &NavError) {
        (self.0)(algo, state, truth, err)
    }
    fn progress(&mut self, done: u64, total: u64) {
        (self.1)(done, total)
    }
}

/// Run the scenario's truth through every algorithm; `observe(i, state, truth, err)` is
/// called at the output rows of algorithm `i` ([`RunOptions::every_s`]). `progress(done,
/// total)` is called once per block. Not cancellable: see [`run_cancellable`].
pub fn run(
    scn: &Scenario,
    opts: &RunOptions,
    observe: impl FnMut(usize, &NavState, &TruthSample, &NavError),
    progress: impl FnMut(u64, u64),
) -> Result<Vec<RunSummary>, PipelineError> {
    run_cancellable(scn, opts, &CancelToken::new(), observe, progress)
}

/// [`run`], polling `cancel` once per block of 2048 updates (a few ms of work).
pub fn run_cancellable(
    scn: &Scenario,
    opts: &RunOptions,
    cancel: &CancelToken,
    observe: impl FnMut(usize, &NavState, &TruthSample, &NavError),
    progress: impl FnMut(u64, u64),
) -> Result<Vec<RunSummary>, PipelineError> {
    run_observed(scn, opts, cancel, &mut Closures(observe, progress))
}

/// The run, reporting to `obs`: its output rows, optionally every update, and progress.
pub fn run_observed(
    scn: &Scenario,
    opts: &RunOptions,
    cancel: &CancelToken,
    obs: &mut impl RunObserver,
) -> Result<Vec<RunSummary>, PipelineError> {
    let n = check_algorithms(&opts.algos)?;
    if let Some(u) = opts.until_s {
        if !(u.is_finite() && u > 0.0) {
            return Err(PipelineError::BadUntil(u));
        }
    }
    let earth = scn.nav.earth.model();
    let cfg = TruthConfig {
        earth,
        dt_s: scn.imu.dt_s(),
        lat0_rad: scn.start.lat_rad,
        lon0_rad: scn.start.lon_rad,
        h0_m: scn.start.h_m,
        substeps: scn.nav.substeps,
    };
    let grid = match opts.every_s {
        Some(e) => Some(
            EpochGrid::new(e, cfg.dt_s * n as f64)
                .map_err(|e| PipelineError::BadEvery(e.to_string()))?,
        ),
        None => None,
    };
    let mut truth = TruthGenerator::new(&scn.trajectory, cfg);
    if let Some(m) = scn.mounting.imu {
        // IMU data at the lever arm and mounting; navigation compared at the IMU
        truth = truth.with_mount(m);
    }
    let init = truth.initial_state();
    let mut mechs: Vec<AnyMechanization> = opts
        .algos
        .iter()
        .map(|a| AnyMechanization::new(a, earth, cfg.dt_s, &init))
        .collect();
    let mut sensor = match opts.sensor_run {
        Some(run) if scn.imu.model != ImuErrorModel::ideal() => {
            ImuErrorState::new(&scn.imu.model, scn.imu.seed, run).ok()
        }
        _ => None,
    };
    let mut total_updates = truth.len_samples() / n as u64;
    if let Some(t) = opts.until_s {
        total_updates = total_updates.min((t / (cfg.dt_s * n as f64)).round() as u64);
    }
    let mut cursors: Vec<Option<EpochCursor>> = (0..mechs.len())
        .map(|_| grid.map(|g| g.cursor(total_updates)))
        .collect();
    let mut last = vec![NavError::default(); mechs.len()];
    let mut maxes = vec![NavError::default(); mechs.len()];
    // the initial state is row 0 of a grid
    let t0_truth = truth.initial_truth();
    for (i, m) in mechs.iter().enumerate() {
        if let Some(c) = cursors[i].as_mut() {
            if c.is_output(0) {
                let st = m.state();
                let e = nav_error(&earth, &st, &t0_truth);
                last[i] = e;
                obs.epoch(i, &st, &t0_truth, &e);
            }
        }
    }
    const BLOCK: usize = 2048;
    let mut incs: Vec<Increment> = Vec::with_capacity(BLOCK * n);
    let mut ends: Vec<TruthSample> = Vec::with_capacity(BLOCK);
    let mut wall = vec![0.0_f64; mechs.len()];
    let mut epochs: Vec<(usize, NavState, bool)> = Vec::with_capacity(BLOCK);
    let mut done = 0_u64;
    while done < total_updates {
        cancel.check()?;
        let count = ((total_updates - done) as usize).min(BLOCK);
        incs.clear();
        ends.clear();
        for _ in 0..count {
            let mut end = None;
            for _ in 0..n {
                if let Some(s) = truth.next() {
                    incs.push(match sensor.as_mut() {
                        Some(st) => st.apply(&s.inc, cfg.dt_s),
                        None => s.inc,
                    });
                    end = Some(s);
                }
            }
            if let Some(e) = end {
                ends.push(truth.at_imu(&e));
            }
        }
        let count = ends.len();
        for (i, m) in mechs.iter_mut().enumerate() {
            // one timed pass over the block (two clock reads per block, not per epoch: with
            // every update observed, per-epoch timing measured the clock); the states of the
            // output epochs are kept and observed after the pass, untimed
            epochs.clear();
            let cursor = &mut cursors[i];
            let t0 = Instant::now();
            for k in 0..count {
                m.update(&incs[k * n..(k + 1) * n]);
                if opts.vertical_hold {
                    m.hold_vertical(ends[k].h_m, ends[k].v_n_mps.z);
                }
                let finished = done + k as u64 + 1;
                let row = match cursor.as_mut() {
                    Some(c) => c.is_output(finished),
                    None => true,
                };
                // every update: max_abs covers the whole run whatever the observer wants
                epochs.push((k, m.state(), row));
            }
            wall[i] += t0.elapsed().as_secs_f64();
            for (k, st, row) in &epochs {
                let tr = &ends[*k];
                let e = nav_error(&earth, st, tr);
                last[i] = e;
                maxes[i] = maxes[i].max_abs(&e);
                if grid.is_some() && obs.wants_updates() {
                    obs.update(i, st, tr, &e);
                }
                if *row {
                    obs.epoch(i, st, tr, &e);
                }
            }
        }
        done += count as u64;
        obs.progress(done, total_updates);
        if count == 0 {
            break;
        }
    }
    Ok(mechs
        .iter()
        .enumerate()
        .map(|(i, _)| RunSummary {
            algo: opts.algos[i].kind.name().to_string(),
            samples: n,
            nav_updates: done,
            wall_s: wall[i],
            final_err: last[i],
            max_abs: maxes[i],
        })
        .collect())
}

/// Navigate over recorded increments (`sdins nav`): `observe` gets the state after
/// every update. Trailing samples that do not fill an update are ignored.
pub fn navigate_recorded(
    spec: &AlgorithmSpec,
    earth: EarthModel,
    dt_s: f64,
    init: &sdins_core::nav::InitialState,
    incs: &[Increment],
    mut observe: impl FnMut(&NavState),
) -> f64 {
    let mut m = AnyMechanization::new(spec, earth, dt_s, init);
    let n = spec.samples.max(1);
    let t0 = Instant::now();
    for chunk in incs.chunks_exact(n) {
        m.update(chunk);
        observe(&m.state());
    }
    t0.elapsed().as_secs_f64()
}

/// Like [`navigate_recorded`], but the returned time covers the navigation updates (and
/// taking their states) only: states are buffered in blocks of 4096 updates and handed
/// to `observe` between the timed blocks, so output formatting is not counted. This is
/// the `wall_s` of `sdins nav` (docs/performance.md compares it with other packages).
pub fn navigate_recorded_timed(
    spec: &AlgorithmSpec,
    earth: EarthModel,
    dt_s: f64,
    init: &sdins_core::nav::InitialState,
    incs: &[Increment],
    mut observe: impl FnMut(&NavState),
) -> f64 {
    const BLOCK: usize = 4096;
    let mut m = AnyMechanization::new(spec, earth, dt_s, init);
    let n = spec.samples.max(1);
    let mut states = Vec::with_capacity(BLOCK);
    let mut wall = 0.0;
    for block in incs.chunks(BLOCK * n) {
        states.clear();
        let t0 = Instant::now();
        for chunk in block.chunks_exact(n) {
            m.update(chunk);
            states.push(m.state());
        }
        wall += t0.elapsed().as_secs_f64();
        states.iter().for_each(&mut observe);
    }
    wall
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use sdins_core::math::{attitude_error, c_b_n_from_euler, euler_from_c_b_n, Euler};
    use sdins_core::nav::wrap_pi;

    #[test]
    fn bad_algorithm_lists_are_errors_not_miscomputation() {
        use sdins_core::nav::AlgorithmKind as K;
        let scn = Scenario::load("turn-90dps").unwrap();
        let opts = |algos: Vec<AlgorithmSpec>, until_s| RunOptions {
            algos,
            vertical_hold: false,
            every_s: None,
            until_s,
            sensor_run: None,
        };
        let mixed = vec![
            AlgorithmSpec::new(K::Savage, 3),
            AlgorithmSpec::new(K::DualQuat, 2),
        ];
        let mut bad_coning = AlgorithmSpec::new(K::Savage, 2);
        bad_coning.coning = sdins_core::coning::ConingSet::ThreePoly;
        for (o, want) in [
            (opts(mixed, Some(1.0)), "share the samples per update"),
            (opts(vec![], Some(1.0)), "no algorithm"),
            (
                opts(vec![AlgorithmSpec::new(K::Savage, 5)], Some(1.0)),
                "outside 1..=4",
            ),
            (opts(vec![bad_coning], Some(1.0)), "coning set"),
            (
                opts(vec![AlgorithmSpec::new(K::Savage, 3)], Some(f64::NAN)),
                "until_s",
            ),
        ] {
            let e = run(&scn, &o, |_, _, _, _| {}, |_, _| {})
                .unwrap_err()
                .to_string();
            assert!(e.contains(want), "{e}");
        }
        let token = CancelToken::new();
        token.cancel();
        let o = opts(vec![AlgorithmSpec::new(K::Savage, 3)], None);
        let r = run_cancellable(&scn, &o, &token, |_, _, _, _| {}, |_, _| {});
        assert_eq!(r, Err(PipelineError::Cancelled(Cancelled)));
    }

    /// The textbook evaluation of docs/conventions.md §"Errors" that `nav_error` must reproduce.
    fn reference(earth: &EarthModel, nav: &NavState, truth: &TruthSample) -> NavError {
        let r = earth.radii(truth.lat_rad);
        let dlat = nav.lat_rad - truth.lat_rad;
        let dlon = wrap_pi(nav.lon_rad - truth.lon_rad);
        let dh = nav.h_m - truth.h_m;
        let ea = euler_from_c_b_n(&nav.c_b_n);
        let et = euler_from_c_b_n(&truth.c_b_n);
        let att = attitude_error(&nav.c_b_n, &truth.c_b_n);
        NavError {
            t_s: truth.t_s,
            pos_err_ned_m: [
                dlat * (r.r_m_m + truth.h_m),
                dlon * (r.r_n_m + truth.h_m) * truth.lat_rad.cos(),
                -dh,
            ],
            vel_err_ned_mps: arr(&(nav.v_n_mps - truth.v_n_mps)),
            att_err_rad: [att.x, att.y, att.z],
            height_err_m: dh,
            euler_err_rad: [
                wrap_pi(ea.roll_rad - et.roll_rad),
                wrap_pi(ea.pitch_rad - et.pitch_rad),
                wrap_pi(ea.yaw_rad - et.yaw_rad),
            ],
        }
    }

    #[test]
    fn fast_nav_error_matches_the_textbook_formulas() {
        let earth = EarthModel::WGS84;
        let d = core::f64::consts::PI / 180.0;
        // (truth euler, nav euler offsets, lat, lon_t, lon_n): wraps at ±180° yaw and
        // longitude, pitch near ±90°, large and tiny errors
        let cases = [
            (
                [10.0, 5.0, 90.0],
                [1e-6, -2e-6, 3e-6],
                37.5,
                127.0,
                127.0 + 1e-7,
            ),
            (
                [-179.9, 0.0, 179.99],
                [-0.2, 0.1, 0.03],
                -45.0,
                179.9999,
                -179.9999,
            ),
            (
                [0.0, 89.9, -179.999],
                [0.5, 0.05, -0.002],
                89.0,
                -180.0,
                180.0,
            ),
            ([120.0, -89.5, 0.0], [-3.0, -0.3, 40.0], 0.0, 0.0, -1e-3),
            (
                [45.0, 30.0, -90.0],
                [170.0, -100.0, 175.0],
                60.0,
                10.0,
                10.5,
            ),
        ];
        for (e, de, lat, lon_t, lon_n) in cases {
            let ct = c_b_n_from_euler(&Euler::new(e[0] * d, e[1] * d, e[2] * d));
            let cn = c_b_n_from_euler(&Euler::new(
                (e[0] + de[0]) * d,
                (e[1] + de[1]) * d,
                (e[2] + de[2]) * d,
            ));
            let truth = TruthSample::new(
                12.5,
                Increment::default(),
                lat * d,
                lon_t * d,
                1200.0,
                Vec3::new(100.0, -50.0, 2.0),
                ct,
            );
            let nav = NavState {
                t_s: 12.5,
                lat_rad: (lat + 1e-5) * d,
                lon_rad: lon_n * d,
                h_m: 1203.0,
                v_n_mps: Vec3::new(100.1, -50.2, 2.3),
                c_b_n: cn,
            };
            let f = nav_error(&earth, &nav, &truth);
            let r = reference(&earth, &nav, &truth);
            let close = |a: &[f64], b: &[f64], tol: f64| {
                for (x, y) in a.iter().zip(b) {
                    assert!((x - y).abs() <= tol, "{e:?} {de:?}: {x} vs {y}");
                }
            };
            close(&f.pos_err_ned_m, &r.pos_err_ned_m, 1e-8);
            close(&f.vel_err_ned_mps, &r.vel_err_ned_mps, 0.0);
            close(&f.att_err_rad, &r.att_err_rad, 1e-15);
            // pitch near ±90° loses precision in both evaluations alike (asin of ~±1)
            close(&f.euler_err_rad, &r.euler_err_rad, 1e-12);
            assert_eq!(f.height_err_m, r.height_err_m);
            assert_eq!(f.t_s, r.t_s);
        }
    }

    #[test]
    fn max_abs_keeps_a_nan() {
        let e = |x: f64| NavError {
            pos_err_ned_m: [x, -2.0 * x, 0.5],
            height_err_m: -x,
            ..NavError::default()
        };
        let m = e(1.0).max_abs(&e(-3.0));
        assert_eq!(m.pos_err_ned_m, [3.0, 6.0, 0.5]);
        assert_eq!(m.height_err_m, 3.0);
        let m = m.max_abs(&e(f64::NAN)).max_abs(&e(10.0));
        assert!(m.pos_err_ned_m[0].is_nan() && m.height_err_m.is_nan());
        assert_eq!(m.pos_err_ned_m[2], 0.5);
        let m = e(f64::NAN).max_abs(&e(1.0));
        assert!(m.pos_err_ned_m[1].is_nan());
    }

    #[test]
    fn small_angle_atan2_equals_libm_to_rounding() {
        // both sides of the 1e-3 switch, signs, x ≠ 1, and the libm fallback region
        let mut worst = 0.0_f64;
        for k in 0..4001 {
            let z = (k as f64 - 2000.0) * 1.25e-6; // |z| ≤ 2.5e-3
            for x in [1.0, 0.37, 3.0e3] {
                let (a, b) = (atan2_small(z * x, x), libm::atan2(z * x, x));
                let ulp = f64::EPSILON * b.abs().max(f64::MIN_POSITIVE);
                worst = worst.max((a - b).abs() / ulp);
            }
        }
        // a 4-term series with 3 roundings vs libm's own ≤ 1 ulp: a few ulp at most
        assert!(worst <= 4.0, "worst {worst} ulp");
        assert_eq!(atan2_small(1e-4, -1.0), libm::atan2(1e-4, -1.0));
        assert_eq!(atan2_small(0.0, 0.0), 0.0);
        assert!(atan2_small(f64::NAN, 1.0).is_nan());
    }

    #[test]
    fn timed_navigation_sees_the_same_states() {
        let init = sdins_core::nav::InitialState {
            lat_rad: 0.6,
            lon_rad: 2.2,
            h_m: 10.0,
            v_n_mps: Vec3::new(1.0, 2.0, 0.0),
            c_b_n: sdins_core::math::Mat3::identity(),
        };
        let inc = Increment {
            dtheta_b_rad: Vec3::new(1e-5, -2e-5, 3e-5),
            dv_b_mps: Vec3::new(1e-3, 2e-3, -9.8e-3),
        };
        // 3 × 4096 + 7 samples: several blocks and a trailing partial update
        let incs = vec![inc; 3 * 4096 + 7];
        let spec = AlgorithmSpec::from_name("songlee", 3).unwrap();
        let earth = EarthModel::WGS84;
        let (mut a, mut b) = (Vec::new(), Vec::new());
        navigate_recorded(&spec, earth, 1e-3, &init, &incs, |s| a.push(*s));
        let w = navigate_recorded_timed(&spec, earth, 1e-3, &init, &incs, |s| b.push(*s));
        assert_eq!(a, b);
        assert_eq!(a.len(), (3 * 4096 + 7) / 3);
        assert!(w >= 0.0);
    }
}
