//! Shared set-up of the benchmarks: a scenario's exact truth recorded into memory once,
//! so that the timed loops read increments from a buffer (no truth generation inside).

#![allow(dead_code)]

use sdins_core::coning::Increment;
use sdins_core::earth::EarthModel;
use sdins_core::nav::InitialState;
use sdins_sim::scenario::Scenario;
use sdins_sim::truth::{TruthConfig, TruthGenerator, TruthSample};

/// The truth configuration `pipeline::run` uses for a scenario.
pub fn truth_config(scn: &Scenario) -> TruthConfig {
    TruthConfig {
        earth: scn.nav.earth.model(),
        dt_s: scn.imu.dt_s(),
        lat0_rad: scn.start.lat_rad,
        lon0_rad: scn.start.lon_rad,
        h0_m: scn.start.h_m,
        substeps: scn.nav.substeps,
    }
}

/// A scenario's truth in memory.
pub struct Recorded {
    /// earth model of the scenario
    pub earth: EarthModel,
    /// sensor period \[s\]
    pub dt_s: f64,
    /// exact initial state
    pub init: InitialState,
    /// one increment per sensor sample
    pub incs: Vec<Increment>,
    /// the truth at the end of every `n`-th sample (every navigation update)
    pub ends: Vec<TruthSample>,
    /// samples per update the `ends` were taken for
    pub n: usize,
}

/// Load a built-in scenario.
pub fn scenario(name: &str) -> Scenario {
    Scenario::load(name).expect("built-in scenario")
}

/// Record up to `max_samples` samples (a whole number of updates of `n` samples) of the
/// scenario's truth.
pub fn record(scn: &Scenario, n: usize, max_samples: Option<usize>) -> Recorded {
    let cfg = truth_config(scn);
    let gen = TruthGenerator::new(&scn.trajectory, cfg);
    let init = gen.initial_state();
    let total = gen.len_samples() as usize;
    let len = max_samples.map_or(total, |m| m.min(total)) / n * n;
    let mut incs = Vec::with_capacity(len);
    let mut ends = Vec::with_capacity(len / n);
    for (k, s) in gen.take(len).enumerate() {
        incs.push(s.inc);
        if (k + 1) % n == 0 {
            ends.push(s);
        }
    }
    Recorded {
        earth: cfg.earth,
        dt_s: cfg.dt_s,
        init,
        incs,
        ends,
        n,
    }
}

/// One full end-to-end run from the in-memory buffer: every navigation update is followed
/// by its error against the truth, and the maximum absolute errors are returned (so
/// nothing can be optimised away). Not inlined, so callgrind can select it by name
/// (`--toggle-collect='*full_run*'`).
#[inline(never)]
pub fn full_run(
    rec: &Recorded,
    spec: &sdins_core::nav::AlgorithmSpec,
) -> sdins_sim::nav::pipeline::NavError {
    use sdins_core::nav::{AnyMechanization, Mechanization};
    let mut m = AnyMechanization::new(spec, rec.earth, rec.dt_s, &rec.init);
    let mut max = sdins_sim::nav::pipeline::NavError::default();
    for (chunk, end) in rec.incs.chunks_exact(rec.n).zip(&rec.ends) {
        m.update(chunk);
        let e = sdins_sim::nav::pipeline::nav_error(&rec.earth, &m.state(), end);
        max = max.max_abs(&e);
    }
    max
}
