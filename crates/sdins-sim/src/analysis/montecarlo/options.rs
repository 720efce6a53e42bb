//! The Monte Carlo options of a job as given by a front end (`sdins montecarlo`, Python
//! `sdins.montecarlo`), turned into [`McOptions`] with the messages of
//! [`crate::nav::options`].

use super::McOptions;
use crate::nav::options::{bad, OptionError};
use crate::scenario::Scenario;
use sdins_core::coning::ConingSet;
use sdins_core::nav::AlgorithmSpec;

/// Default output epoch spacing of Monte Carlo \[s\].
pub const DEFAULT_MC_EVERY_S: f64 = 10.0;

/// Monte Carlo options as given by a front end; `None` = the library default.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct McChoice {
    /// number of runs
    pub runs: u64,
    /// seed of the sensor-error streams (default: the scenario's `[imu] seed`)
    pub seed: Option<u64>,
    /// algorithm name (default songlee-complete)
    pub algo: Option<String>,
    /// samples per update (default: the scenario's)
    pub samples: Option<usize>,
    /// output epoch spacing \[s\] (default [`DEFAULT_MC_EVERY_S`])
    pub every_s: Option<f64>,
    /// stop time \[s\] (default: whole scenario)
    pub until_s: Option<f64>,
    /// vertical channel hold or free (default hold)
    pub vertical: Option<String>,
    /// runs per block (default [`super::DEFAULT_BLOCK`])
    pub block: Option<u64>,
}

/// The Monte Carlo options of a job (montecarlo.md).
pub fn mc_options(scn: &Scenario, c: &McChoice) -> Result<McOptions, OptionError> {
    let n = c.samples.unwrap_or(scn.nav.samples);
    let name = c.algo.as_deref().unwrap_or("songlee-complete");
    let mut algo = AlgorithmSpec::from_name(name, n).ok_or_else(|| {
        bad(format!(
            "--algo {name}: expected savage, songlee, songlee-complete or dualquat"
        ))
    })?;
    algo.coning = ConingSet::recommended_for(n);
    if !(1..=4).contains(&n) {
        return Err(bad(format!("--samples {n}: expected 1..=4")));
    }
    let vertical_hold = match c.vertical.as_deref().unwrap_or("hold") {
        "hold" => true,
        "free" => false,
        o => return Err(bad(format!("--vertical {o}: expected hold or free"))),
    };
    if let Some(u) = c.until_s {
        if !(u.is_finite() && u > 0.0) {
            return Err(bad(format!("--until-s {u}: expected > 0")));
        }
    }
    if let Some(e) = c.every_s {
        if !(e.is_finite() && e > 0.0) {
            return Err(bad(format!(
                "--every-s {e}: expected a positive number of seconds"
            )));
        }
    }
    Ok(McOptions {
        runs: c.runs,
        seed: c.seed.unwrap_or(scn.imu.seed),
        algo,
        every_s: c.every_s.unwrap_or(DEFAULT_MC_EVERY_S),
        until_s: c.until_s,
        block: c.block.unwrap_or(super::DEFAULT_BLOCK),
        vertical_hold,
    })
}

/// A Monte Carlo job as a front end gives it: the choice, a grade replacing the scenario's
/// error model, the shard and the worker threads.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct McRequest {
    /// runs, seed, algorithm, epochs, …
    pub choice: McChoice,
    /// IMU grade preset replacing the scenario's error model (`--grade`)
    pub grade: Option<String>,
    /// the shard to compute (default: the whole job)
    pub shard: Option<super::Shard>,
    /// worker threads (default: rayon's global pool); the numbers do not depend on it
    pub threads: Option<usize>,
}

/// A validated job: the scenario with its grade, the options, the shard and the pool.
pub struct McPlan {
    /// the scenario (grade applied)
    pub scenario: Scenario,
    /// the options
    pub options: McOptions,
    /// the shard
    pub shard: super::Shard,
    /// runs in the shard
    pub runs: u64,
    /// output epochs (rows of the statistics)
    pub epochs: u64,
    pool: Option<rayon::ThreadPool>,
}

/// Validate a request (messages name the option: `--grade`, `--threads`, …).
pub fn plan(mut scenario: Scenario, req: &McRequest) -> Result<McPlan, OptionError> {
    if let Some(g) = &req.grade {
        crate::nav::options::apply_grade(&mut scenario, g)?;
    }
    let options = mc_options(&scenario, &req.choice)?;
    let shard = req.shard.unwrap_or(super::Shard::ALL);
    let pool = match req.threads {
        None => None,
        Some(t) if (1..=1024).contains(&t) => Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .map_err(|e| bad(format!("--threads {t}: {e}")))?,
        ),
        Some(t) => return Err(bad(format!("--threads {t}: expected 1 … 1024"))),
    };
    let end = options
        .until_s
        .map_or(scenario.duration_s(), |t| t.min(scenario.duration_s()));
    Ok(McPlan {
        runs: super::runner::shard_runs(&options, shard),
        epochs: (end / options.every_s) as u64 + 2,
        scenario,
        options,
        shard,
        pool,
    })
}

impl McPlan {
    /// Whether every run is the same (ideal sensors): worth a warning.
    pub fn ideal_sensors(&self) -> bool {
        self.scenario.imu.model == crate::sensors::imu_error::ImuErrorModel::ideal()
    }

    /// Compute the shard; `on_run()` after every finished run (from worker threads),
    /// `cancelled()` polled between runs.
    pub fn run(
        &self,
        on_run: &(dyn Fn() + Sync),
        cancelled: &(dyn Fn() -> bool + Sync),
    ) -> Result<super::McState, super::McError> {
        let compute =
            || super::run_shard(&self.scenario, &self.options, self.shard, on_run, cancelled);
        match &self.pool {
            Some(p) => p.install(compute),
            None => compute(),
        }
    }
}
