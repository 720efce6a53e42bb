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
