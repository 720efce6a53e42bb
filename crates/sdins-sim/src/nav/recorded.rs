//! Navigation over recorded IMU increments against an optional reference trajectory:
//! the work of `sdins nav` and Python `sdins.navigate`, in one place.
//!
//! Time base: the state before the first sample is at `t0 = t_first − δt`; update k
//! (k = 1, 2, …) ends at `t0 + k N δt`. A reference row is compared with the state of the
//! update whose end time it matches within 0.1 δt (the errors of [`crate::nav::pipeline`],
//! docs/conventions.md §"Errors").

use crate::cancel::{CancelToken, Cancelled};
use crate::io::imu_file::ImuData;
use crate::io::imu_file::ImuFormat;
use crate::io::initial::validate_initial_state;
use crate::io::truth_file::c_b_n_from_psins;
use crate::io::truth_file::read_truth;
use crate::nav::options::{algorithms, earth_by_name, recorded_nav_defaults, AlgoChoice};
use crate::nav::pipeline::{nav_error, NavError};
use crate::truth::TruthSample;
use sdins_core::coning::Increment;
use sdins_core::earth::EarthModel;
use sdins_core::math::Vec3;
use sdins_core::nav::{AlgorithmSpec, AnyMechanization, InitialState, Mechanization, NavState};
use std::path::{Path, PathBuf};
use std::time::Instant;

const D2R: f64 = std::f64::consts::PI / 180.0;

/// Why a recorded run cannot start.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum NavInputError {
    /// The inputs do not fit together (message says which file or option).
    #[error("{0}")]
    Bad(String),
}

/// The initial state: `init` (the text `lat_deg,lon_deg,h_m,v_n,v_e,v_d,roll_deg,
/// pitch_deg,yaw_deg`) if given, else the first reference row (which must be at the start
/// of the first sample, `t_first − δt`, within 0.1 δt), else the PSINS `.imu` header.
pub fn initial_state(
    init: Option<&str>,
    truth: Option<(&Path, &[TruthSample])>,
    imu_path: &Path,
    data: &ImuData,
) -> Result<InitialState, NavInputError> {
    if let Some(s) = init {
        return crate::io::initial::parse_initial_state(s).map_err(NavInputError::Bad);
    }
    if let Some((tp, tr)) = truth {
        if let Some(r) = tr.first() {
            let t_start = data.t0_s - data.dt_s;
            if (r.t_s - t_start).abs() > 0.1 * data.dt_s {
                return Err(NavInputError::Bad(format!(
                    "{}: the first row (t = {} s) is not at the start of the first sample of {} (t = {} s, its first time stamp {} s minus the interval {} s): give --init",
                    tp.display(),
                    r.t_s,
                    imu_path.display(),
                    t_start,
                    data.t0_s,
                    data.dt_s
                )));
            }
            let s = InitialState {
                lat_rad: r.lat_rad,
                lon_rad: r.lon_rad,
                h_m: r.h_m,
                v_n_mps: r.v_n_mps,
                c_b_n: r.c_b_n,
            };
            validate_initial_state(&s).map_err(|e| {
                NavInputError::Bad(format!(
                    "{}: first row (the initial state): {e}",
                    tp.display()
                ))
            })?;
            return Ok(s);
        }
    }
    match &data.psins {
        Some(h) => {
            let s = InitialState {
                lat_rad: h.lat_deg * D2R,
                lon_rad: h.lon_deg * D2R,
                h_m: h.h_m,
                // PSINS velocity is ENU
                v_n_mps: Vec3::new(h.vel0_enu_mps[1], h.vel0_enu_mps[0], -h.vel0_enu_mps[2]),
                c_b_n: c_b_n_from_psins(
                    h.att0_deg[0] * D2R,
                    h.att0_deg[1] * D2R,
                    h.att0_deg[2] * D2R,
                ),
            };
            validate_initial_state(&s).map_err(|e| {
                NavInputError::Bad(format!(
                    "{}: PSINS header (the initial state): {e}",
                    imu_path.display()
                ))
            })?;
            Ok(s)
        }
        None => Err(NavInputError::Bad(
            "--init is required (no truth file or PSINS header to take it from)".into(),
        )),
    }
}

/// Fail unless at least one reference time falls on a navigation update epoch
/// `t0 + k N δt` (k = 1..=updates) within 0.1 δt: otherwise a reference would silently
/// compare nothing (different time bases, another trajectory, a decimated file that
/// misses every epoch).
pub fn check_time_bases(
    truth: &[TruthSample],
    truth_path: &Path,
    imu_path: &Path,
    t0: f64,
    dt: f64,
    samples: usize,
    n_samples: usize,
) -> Result<(), NavInputError> {
    let upd = dt * samples.max(1) as f64;
    let n_upd = n_samples / samples.max(1);
    let tol = 0.1 * dt;
    let matched = truth.iter().any(|r| {
        let k = ((r.t_s - t0) / upd).round();
        k >= 1.0 && k <= n_upd as f64 && (r.t_s - (t0 + k * upd)).abs() <= tol
    });
    if matched {
        return Ok(());
    }
    let (first, last) = match (truth.first(), truth.last()) {
        (Some(a), Some(b)) => (a.t_s, b.t_s),
        _ => (f64::NAN, f64::NAN),
    };
    Err(NavInputError::Bad(format!(
        "{}: no time matches an update epoch of {}: the updates are at {} s + k·{} s up to {} s, the reference covers {} s to {} s (expected equal times within {} s; are the time bases the same?)",
        truth_path.display(),
        imu_path.display(),
        t0,
        upd,
        t0 + n_upd as f64 * upd,
        first,
        last,
        tol
    )))
}

/// What a recorded run produced besides the states handed to the observer.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordedRun {
    /// navigation updates done
    pub updates: usize,
    /// time in the navigation updates only (taking the states included) \[s\]
    pub wall_s: f64,
    /// errors at every update matched by a reference row, `t_s` on the file's time base
    pub errors: Vec<NavError>,
}

/// Navigate over `incs` (N = `spec.samples` per update; a trailing partial update is
/// ignored) from `init` at time `t0_s`. `observe(t_s, state)` gets every state, `t_s`
/// on the file's time base; states are buffered in blocks of 4096 updates and handed
/// over between the timed blocks, so `wall_s` excludes the observer (docs/performance.md).
/// `cancel` is polled once per block (a few ms of work).
#[allow(clippy::too_many_arguments)]
pub fn navigate(
    spec: &AlgorithmSpec,
    earth: EarthModel,
    dt_s: f64,
    t0_s: f64,
    init: &InitialState,
    incs: &[Increment],
    truth: Option<&[TruthSample]>,
    cancel: &CancelToken,
    mut observe: impl FnMut(f64, &NavState),
) -> Result<RecordedRun, Cancelled> {
    const BLOCK: usize = 4096;
    let mut m = AnyMechanization::new(spec, earth, dt_s, init);
    let n = spec.samples.max(1);
    // the block buffer is allocated once at its full length; `update_many` writes each
    // state into its slot (`Vec::push(m.state())` copied the 128-byte state twice, and one
    // call per block leaves the dispatch on the algorithm's options out of the loop)
    let mut states = vec![m.state(); BLOCK];
    let mut wall = 0.0;
    let mut errors = Vec::new();
    let mut ti = 0usize;
    let mut updates = 0usize;
    for block in incs.chunks(BLOCK * n) {
        cancel.check()?;
        let t0 = Instant::now();
        let k = m.update_many(block, &mut states);
        wall += t0.elapsed().as_secs_f64();
        updates += k;
        for st in &states[..k] {
            let t = t0_s + st.t_s;
            observe(t, st);
            if let Some(tr) = truth {
                while ti < tr.len() && tr[ti].t_s < t - 0.1 * dt_s {
                    ti += 1;
                }
                if let Some(r) = tr.get(ti) {
                    if (r.t_s - t).abs() <= 0.1 * dt_s {
                        let mut e = nav_error(&earth, st, r);
                        e.t_s = t;
                        errors.push(e);
                    }
                }
            }
        }
    }
    Ok(RecordedRun {
        updates,
        wall_s: wall,
        errors,
    })
}

/// `sdins nav` as the library takes it (the CLI's options, typed).
#[derive(Clone, Debug, PartialEq)]
pub struct NavFileRequest {
    /// the IMU file
    pub imu: PathBuf,
    /// its format (`auto`: told apart by the content)
    pub imu_format: ImuFormat,
    /// initial state text (`--init`), else the first reference row or the PSINS header
    pub init: Option<String>,
    /// algorithm name
    pub algo: String,
    /// samples per update
    pub samples: usize,
    /// coning/sculling set name
    pub coning: Option<String>,
    /// earth model name
    pub earth: String,
    /// reference trajectory file
    pub truth: Option<PathBuf>,
    /// the IMU file's column map (docs/own-data.md; `imu_format` must then be `Auto`)
    pub imu_columns: Option<crate::io::imu_columns::ImuColumns>,
}

/// The loaded and checked inputs of a recorded run.
#[derive(Clone, Debug)]
pub struct NavFilePlan {
    /// the request
    pub request: NavFileRequest,
    /// the IMU record
    pub data: ImuData,
    /// the reference rows
    pub truth: Option<Vec<TruthSample>>,
    /// initial state
    pub init: InitialState,
    /// the algorithm
    pub spec: AlgorithmSpec,
    /// earth model
    pub earth: EarthModel,
    /// time of the initial state \[s\] (the file's time base)
    pub t0_s: f64,
    /// navigation updates the run will make
    pub updates: usize,
    /// what the column map did (time base, clock, offsets), when one was given
    pub imu_report: Option<crate::io::imu_columns::InputReport>,
}

/// Read and check the inputs of `sdins nav` (messages name the file, line and option).
pub fn prepare(req: &NavFileRequest) -> Result<NavFilePlan, NavInputError> {
    let bad = |e: String| NavInputError::Bad(e);
    let earth = earth_by_name(&req.earth).map_err(|e| bad(e.to_string()))?;
    let choice = AlgoChoice {
        algos: Some(req.algo.clone()),
        samples: Some(req.samples),
        coning: req.coning.clone(),
        ..AlgoChoice::default()
    };
    let specs = algorithms(&choice, &recorded_nav_defaults()).map_err(|e| bad(e.to_string()))?;
    let spec = match specs.as_slice() {
        [s] => *s,
        [] => return Err(bad("--algo: no algorithm given".into())),
        _ => return Err(bad("--algo: `nav` runs one algorithm".into())),
    };
    let (data, imu_report) =
        crate::io::imu_columns::read_imu_any(&req.imu, req.imu_format, req.imu_columns.as_ref())
            .map_err(bad)?;
    let truth = match &req.truth {
        Some(p) => Some(read_truth(p).map_err(|e| bad(e.to_string()))?),
        None => None,
    };
    let init = initial_state(
        req.init.as_deref(),
        match (&req.truth, &truth) {
            (Some(p), Some(t)) => Some((p.as_path(), t.as_slice())),
            _ => None,
        },
        &req.imu,
        &data,
    )?;
    let t0_s = data.t0_s - data.dt_s; // state epoch before the first sample
    if let (Some(tr), Some(tp)) = (&truth, &req.truth) {
        check_time_bases(
            tr,
            tp,
            &req.imu,
            t0_s,
            data.dt_s,
            spec.samples,
            data.increments.len(),
        )?;
    }
    let updates = data.increments.len() / spec.samples.max(1);
    Ok(NavFilePlan {
        request: req.clone(),
        data,
        truth,
        init,
        spec,
        earth,
        t0_s,
        updates,
        imu_report,
    })
}

/// Navigate a prepared record: `observe(t_s, state)` gets every state (see [`navigate`]).
pub fn run_plan(
    plan: &NavFilePlan,
    cancel: &CancelToken,
    observe: impl FnMut(f64, &NavState),
) -> Result<RecordedRun, Cancelled> {
    navigate(
        &plan.spec,
        plan.earth,
        plan.data.dt_s,
        plan.t0_s,
        &plan.init,
        &plan.data.increments,
        plan.truth.as_deref(),
        cancel,
        observe,
    )
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::nav::pipeline::navigate_recorded;
    use crate::scenario::Scenario;
    use crate::truth::{TruthConfig, TruthGenerator};

    /// The states are those of the plain loop (same bits), and errors against the exact
    /// truth of the same scenario are matched at every update.
    #[test]
    fn same_states_as_the_plain_loop_and_every_epoch_matched() {
        let scn = Scenario::load("turn-90dps").unwrap();
        let cfg = TruthConfig {
            earth: scn.nav.earth.model(),
            dt_s: scn.imu.dt_s(),
            lat0_rad: scn.start.lat_rad,
            lon0_rad: scn.start.lon_rad,
            h0_m: scn.start.h_m,
            substeps: scn.nav.substeps,
        };
        let gen = TruthGenerator::new(&scn.trajectory, cfg);
        let init = gen.initial_state();
        let samples: Vec<TruthSample> = gen.take(3 * 5000).collect();
        let incs: Vec<Increment> = samples.iter().map(|s| s.inc).collect();
        let truth: Vec<TruthSample> = samples.iter().skip(2).step_by(3).copied().collect();
        let spec = AlgorithmSpec::from_name("songlee-complete", 3).unwrap();
        let mut a = Vec::new();
        navigate_recorded(&spec, cfg.earth, cfg.dt_s, &init, &incs, |s| a.push(*s));
        let mut b = Vec::new();
        let r = navigate(
            &spec,
            cfg.earth,
            cfg.dt_s,
            0.0,
            &init,
            &incs,
            Some(&truth),
            &CancelToken::new(),
            |_, s| b.push(*s),
        )
        .unwrap();
        assert_eq!(a, b);
        assert_eq!(r.updates, 5000);
        assert_eq!(r.errors.len(), 5000);
        let tok = CancelToken::new();
        tok.cancel();
        assert!(navigate(
            &spec,
            cfg.earth,
            cfg.dt_s,
            0.0,
            &init,
            &incs,
            None,
            &tok,
            |_, _| {}
        )
        .is_err());
    }
}
