//! The exact truth of a scenario computed once and shared by every run.
//!
//! Every Monte Carlo run navigates the *same* truth; only the sensor errors differ. Where
//! the truth needs the integrator (manoeuvres, overlays such as the 1 Hz coning of
//! `dq-paper`) it costs more than the navigation itself (≈ 2.3 μs per 100 Hz sample
//! there with the Gauss scheme, ≈ 35 μs with the former RK4), so the runner computes it
//! once: the exact increments of every sample, the
//! held vertical channel (h, v_D) at every update end, and the full truth sample at every
//! output epoch. [`TruthCache::run`] then replays exactly the operations of
//! [`crate::nav::pipeline::run`] (same sensor-error order, same updates, same epochs), so a
//! cached run is bit-identical to a streamed one (tested). Constant-rate trajectories
//! (static, level cruise) use the generator's closed form, which is cheaper than reading
//! a cache, and are streamed instead ([`worth_caching`]).

use crate::nav::epochs::EpochGrid;
use crate::nav::pipeline::{nav_error, NavError};
use crate::scenario::Scenario;
use crate::sensors::imu_error::{ImuErrorModel, ImuErrorState};
use crate::truth::{TruthConfig, TruthGenerator, TruthSample};
use sdins_core::coning::Increment;
use sdins_core::earth::EarthModel;
use sdins_core::nav::{AlgorithmSpec, AnyMechanization, InitialState, Mechanization};

/// Largest cache built automatically (bytes).
pub const MAX_CACHE_BYTES: u64 = 1 << 30;

/// The cached truth of one scenario for a given N and epoch spacing.
#[derive(Clone, Debug)]
pub struct TruthCache {
    earth: EarthModel,
    dt_s: f64,
    init: InitialState,
    n: usize,
    rows: Vec<u64>,
    incs: Vec<Increment>,
    vert: Vec<[f64; 2]>,
    epochs: Vec<TruthSample>,
}

fn config(scn: &Scenario) -> TruthConfig {
    TruthConfig {
        earth: scn.nav.earth.model(),
        dt_s: scn.imu.dt_s(),
        lat0_rad: scn.start.lat_rad,
        lon0_rad: scn.start.lon_rad,
        h0_m: scn.start.h_m,
        substeps: scn.nav.substeps,
    }
}

/// Number of navigation updates of a run (as [`crate::nav::pipeline::run`] computes it).
fn total_updates(n_samples: u64, n: usize, dt_s: f64, until_s: Option<f64>) -> u64 {
    let mut t = n_samples / n as u64;
    if let Some(u) = until_s {
        t = t.min((u / (dt_s * n as f64)).round() as u64);
    }
    t
}

/// Whether to cache: the truth needs the integrator (not a constant-rate trajectory) and the cache
/// fits in [`MAX_CACHE_BYTES`].
pub fn worth_caching(scn: &Scenario, n: usize, until_s: Option<f64>) -> bool {
    if scn.trajectory.is_constant_parallel() {
        return false;
    }
    let cfg = config(scn);
    let samples = TruthGenerator::new(&scn.trajectory, cfg).len_samples();
    let upd = total_updates(samples, n.max(1), cfg.dt_s, until_s);
    let bytes = upd * (n as u64 * std::mem::size_of::<Increment>() as u64 + 16);
    bytes <= MAX_CACHE_BYTES
}

impl TruthCache {
    /// Generate the truth once for `n` samples per update and output rows every
    /// `every_s` seconds by the rule of [`crate::nav::epochs`] (the initial state and the
    /// last update included), up to `until_s`.
    pub fn build(scn: &Scenario, n: usize, every_s: f64, until_s: Option<f64>) -> Self {
        let cfg = config(scn);
        let n = n.max(1);
        let mut gen = TruthGenerator::new(&scn.trajectory, cfg);
        let init = gen.initial_state();
        let total = total_updates(gen.len_samples(), n, cfg.dt_s, until_s);
        // a bad spacing is refused by `job`; here the rows are the initial state and the end
        let rows = match EpochGrid::new(every_s, cfg.dt_s * n as f64) {
            Ok(g) => g.updates(total),
            Err(_) => vec![0, total],
        };
        let mut next_row = rows.iter().peekable();
        let mut incs = Vec::with_capacity(total as usize * n);
        let mut vert = Vec::with_capacity(total as usize);
        let mut epochs = Vec::new();
        if next_row.next_if_eq(&&0).is_some() {
            epochs.push(gen.initial_truth());
        }
        let mut done = 0_u64;
        while done < total {
            let mut end = None;
            for _ in 0..n {
                if let Some(s) = gen.next() {
                    incs.push(s.inc);
                    end = Some(s);
                }
            }
            let Some(e) = end else { break };
            vert.push([e.h_m, e.v_n_mps.z]);
            done += 1;
            if next_row.next_if_eq(&&done).is_some() {
                epochs.push(e);
            }
        }
        TruthCache {
            earth: cfg.earth,
            dt_s: cfg.dt_s,
            init,
            n,
            rows,
            incs,
            vert,
            epochs,
        }
    }

    /// One run: the sensor errors of (`seed`, `run`) applied to the cached increments,
    /// navigated by `algo`; the errors at every epoch.
    pub fn run(
        &self,
        model: &ImuErrorModel,
        seed: u64,
        run: u64,
        algo: &AlgorithmSpec,
        vertical_hold: bool,
    ) -> Vec<NavError> {
        let mut sensor = if *model != ImuErrorModel::ideal() {
            ImuErrorState::new(model, seed, run).ok()
        } else {
            None
        };
        let mut mech = AnyMechanization::new(algo, self.earth, self.dt_s, &self.init);
        let n = self.n;
        let mut buf: Vec<Increment> = Vec::with_capacity(n);
        let mut out = Vec::with_capacity(self.epochs.len());
        let mut ep = self.epochs.iter();
        let mut rows = self.rows.iter().peekable();
        if rows.next_if_eq(&&0).is_some() {
            if let Some(tr) = ep.next() {
                out.push(nav_error(&self.earth, &mech.state(), tr));
            }
        }
        for (u, chunk) in self.incs.chunks(n).enumerate() {
            buf.clear();
            for inc in chunk {
                buf.push(match sensor.as_mut() {
                    Some(st) => st.apply(inc, self.dt_s),
                    None => *inc,
                });
            }
            mech.update(&buf);
            if vertical_hold {
                let [h, vd] = self.vert[u];
                mech.hold_vertical(h, vd);
            }
            let finished = u as u64 + 1;
            if rows.next_if_eq(&&finished).is_some() {
                if let Some(tr) = ep.next() {
                    out.push(nav_error(&self.earth, &mech.state(), tr));
                }
            }
        }
        out
    }
}
