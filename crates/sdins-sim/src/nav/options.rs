//! The options of a side-by-side run (`sdins run`, `sdins nav`, Python `sdins.run` and
//! `sdins.navigate`) turned into typed values: algorithm list, vertical channel, output
//! decimation. One parser for every front end, so a default changed here reaches all.
//!
//! Messages name the option as the command line spells it (`--samples`, `--coning`, …).

use crate::scenario::{EarthChoice, NavConfig, Scenario};
use crate::sensors::imu_error::ImuErrorModel;
use sdins_core::coning::ConingSet;
use sdins_core::earth::EarthModel;
use sdins_core::nav::{AlgorithmKind, AlgorithmSpec, AttitudeMode, RotVector};

/// A bad option value: the message names the option and the accepted values.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum OptionError {
    /// The value of an option is not accepted.
    #[error("{0}")]
    Bad(String),
}

pub(crate) fn bad(s: impl Into<String>) -> OptionError {
    OptionError::Bad(s.into())
}

/// Algorithm choice as given by a front end; `None` = the scenario's (or library) default.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct AlgoChoice {
    /// comma-separated algorithm names (savage, songlee, songlee-complete, dualquat)
    pub algos: Option<String>,
    /// IMU samples per navigation update, 1..=4
    pub samples: Option<usize>,
    /// coning/sculling set name
    pub coning: Option<String>,
    /// attitude update of the local-level algorithms: transport, five, savage
    pub attitude: Option<String>,
    /// rotation-compensation vector: theta, phi
    pub rotvec: Option<String>,
    /// add the third-order rotation compensation
    pub rot3: bool,
}

/// The navigation defaults of a recorded run (`sdins nav`, Python `sdins.navigate`), where
/// there is no scenario: songlee-complete, N = 1, the recommended coning set of N, WGS-84,
/// free vertical channel.
pub fn recorded_nav_defaults() -> NavConfig {
    NavConfig {
        samples: 1,
        algos: vec!["songlee-complete".to_string()],
        coning: None,
        earth: EarthChoice::Wgs84,
        vertical_hold: false,
        substeps: 1,
    }
}

/// Build the algorithm list: names default to `nav.algos`, samples to `nav.samples`,
/// the coning set to `nav.coning`, else 1prev for N = 1 and the polynomial set of N
/// otherwise ([`ConingSet::recommended_for`], coning.md).
pub fn algorithms(c: &AlgoChoice, nav: &NavConfig) -> Result<Vec<AlgorithmSpec>, OptionError> {
    let n = c.samples.unwrap_or(nav.samples);
    if !(1..=4).contains(&n) {
        return Err(bad(format!("--samples {n}: expected 1, 2, 3 or 4")));
    }
    let names: Vec<String> = match &c.algos {
        Some(s) => s
            .split(',')
            .map(|x| x.trim().to_string())
            .filter(|x| !x.is_empty())
            .collect(),
        None => nav.algos.clone(),
    };
    // each algorithm once: its outputs (nav_ALGO.csv, err_ALGO.csv) are named after it
    for (i, a) in names.iter().enumerate() {
        if names[..i].contains(a) {
            return Err(bad(format!(
                "--algo {}: {a} is named twice (each algorithm runs once)",
                names.join(",")
            )));
        }
    }
    let coning_name = c.coning.clone().or_else(|| nav.coning.clone());
    let coning = match &coning_name {
        None => ConingSet::recommended_for(n),
        Some(name) => {
            let set = ConingSet::parse(name, n).ok_or_else(|| {
                bad(format!(
                    "--coning {name}: unknown set (expected none, 1prev, two, three_poly, three_opt, four_poly, four_opt, polynomial, optimal)"
                ))
            })?;
            if !set.accepts(n) {
                return Err(bad(format!(
                    "--coning {name}: the set is for {} samples, but --samples is {n}",
                    set.samples()
                )));
            }
            set
        }
    };
    let attitude = match c.attitude.as_deref() {
        None => None,
        Some("transport") => Some(AttitudeMode::Transport),
        Some("five") => Some(AttitudeMode::Five),
        Some("savage") => Some(AttitudeMode::Savage),
        Some(o) => {
            return Err(bad(format!(
                "--attitude {o}: expected transport, five or savage"
            )))
        }
    };
    let rot_vector = match c.rotvec.as_deref() {
        None => None,
        Some("theta") => Some(RotVector::Theta),
        Some("phi") => Some(RotVector::Phi),
        Some(o) => return Err(bad(format!("--rotvec {o}: expected theta or phi"))),
    };
    names
        .iter()
        .map(|name| {
            let kind = AlgorithmKind::from_name(name).ok_or_else(|| {
                bad(format!(
                    "--algo: unknown algorithm `{name}` (expected savage, songlee, songlee-complete, dualquat)"
                ))
            })?;
            let mut spec = AlgorithmSpec::new(kind, n);
            spec.coning = coning;
            spec.attitude = attitude;
            spec.rot_vector = rot_vector;
            if c.rot3 {
                spec.rot3 = Some(true);
            }
            Ok(spec)
        })
        .collect()
}

/// Vertical channel: `None` = `default_hold`, `free`, or `hold` (height and v_D taken
/// from the truth every update).
pub fn vertical_hold(v: Option<&str>, default_hold: bool) -> Result<bool, OptionError> {
    match v {
        None => Ok(default_hold),
        Some("free") => Ok(false),
        Some("hold") => Ok(true),
        Some(o) => Err(bad(format!("--vertical {o}: expected free or hold"))),
    }
}

/// Output decimation in updates for an epoch spacing `every_s` \[s\] and an update
/// interval `dt_update_s` \[s\]: round(every_s / dt_update_s), at least 1.
pub fn every_updates(every_s: f64, dt_update_s: f64) -> Result<u64, OptionError> {
    if !(every_s.is_finite() && every_s > 0.0) {
        return Err(bad(format!(
            "--every-s {every_s}: expected a positive number of seconds"
        )));
    }
    Ok(((every_s / dt_update_s).round() as u64).max(1))
}

/// Earth model by name: wgs84, wgs84-linear (gravity γ(L)(1 − 2h/a), as pyins), psins,
/// flat (g = 9.80665 m/s², earth.md).
pub fn earth_by_name(name: &str) -> Result<EarthModel, OptionError> {
    match name {
        "wgs84" => Ok(EarthModel::WGS84),
        "wgs84-linear" => Ok(EarthModel::WGS84_LINEAR_G),
        "psins" => Ok(EarthModel::PSINS),
        "flat" => Ok(EarthModel::flat(9.806_65)),
        o => Err(bad(format!(
            "--earth {o}: expected wgs84, wgs84-linear, psins or flat"
        ))),
    }
}

/// Default output epoch spacing of `sdins run` / `sdins.run` \[s\].
pub const DEFAULT_EVERY_S: f64 = 1.0;

/// Replace the scenario's IMU error model by the grade preset `grade` (marine, aviation,
/// intermediate, tactical, consumer; imu-errors.md).
pub fn apply_grade(scn: &mut Scenario, grade: &str) -> Result<(), OptionError> {
    scn.imu.model = ImuErrorModel::preset(grade).map_err(|e| bad(format!("--grade: {e}")))?;
    scn.imu.grade = Some(grade.to_string());
    Ok(())
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn defaults_come_from_the_scenario() {
        let scn = Scenario::load("mach1-east").unwrap();
        let a = algorithms(&AlgoChoice::default(), &scn.nav).unwrap();
        assert_eq!(a.len(), scn.nav.algos.len());
        assert!(a.iter().all(|s| s.samples == scn.nav.samples));
    }

    #[test]
    fn bad_values_name_the_option() {
        let scn = Scenario::load("mach1-east").unwrap();
        let c = AlgoChoice {
            samples: Some(5),
            ..AlgoChoice::default()
        };
        assert!(algorithms(&c, &scn.nav)
            .unwrap_err()
            .to_string()
            .starts_with("--samples 5"));
        assert!(vertical_hold(Some("up"), false)
            .unwrap_err()
            .to_string()
            .starts_with("--vertical up"));
        assert!(every_updates(f64::NAN, 0.01).is_err());
        assert_eq!(every_updates(1.0, 0.006).unwrap(), 167);
        assert!(earth_by_name("mars").is_err());
    }
}
