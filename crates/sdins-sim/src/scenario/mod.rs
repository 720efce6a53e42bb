//! Scenario files (TOML): start state, IMU, navigation set-up and motion segments.
//!
//! Every key carries its unit in its name. Unknown keys, missing keys and impossible
//! values are reported with the file, line and key, and a "did you mean" hint for
//! misspelt keys. See `docs/scenarios.md` for the reference (a test checks that it lists
//! exactly the keys accepted here: [`ACCEPTED_KEYS`]).

use crate::truth::trajectory::{Axis, Motion, Overlay, OverlayKind, Trajectory};
use crate::truth::vehicle::{Vehicle, VehicleError};
use sdins_core::earth::EarthModel;
use sdins_core::math::Euler;
use serde::Deserialize;
use std::path::Path;
use toml::Spanned;

mod commands;
mod doc;
pub mod from_reference;
mod keys;
mod parse;
mod sections;

use commands::*;
use doc::*;
pub use keys::{suggest, suggest_from, ACCEPTED_KEYS};
use parse::*;
use sections::*;

const D2R: f64 = std::f64::consts::PI / 180.0;
pub use crate::truth::trajectory::MAX_SEGMENT_S;

/// A scenario error: where and what.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("{file}: cannot read: {reason}")]
    Read {
        /// file name
        file: String,
        /// OS message
        reason: String,
    },
    /// Syntax error, unknown or missing key, wrong type, or an invalid value.
    #[error("{file}:{line}: {key}: {message}")]
    Invalid {
        /// file name
        file: String,
        /// 1-based line
        line: usize,
        /// the key (dotted path)
        key: String,
        /// what is wrong and what is expected
        message: String,
    },
    /// An unknown built-in scenario name.
    #[error("unknown scenario `{name}`: not a file and not a built-in (built-ins: {known})")]
    Unknown {
        /// the name given
        name: String,
        /// the built-in names
        known: String,
    },
    /// Stopped through the cancellation token (route compilation, the command list or
    /// the envelope check of a large scenario).
    #[error("cancelled")]
    Cancelled,
}

// ---- end [body_motion] ----

// ---- end [gnss] ----

/// Sensor placement on the vehicle (`[mounting]`): lever arms from the vehicle reference
/// point in the vehicle frame, the IMU's mounting rotation. The truth is reported at the
/// reference point.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Mounting {
    /// the IMU's lever arm and mounting (none: the IMU at the reference point, aligned)
    pub imu: Option<crate::truth::ImuMount>,
    /// the GNSS antenna's lever arm, vehicle frame \[m\] (for the INS/GNSS simulation)
    pub gnss_lever_arm_b_m: Option<sdins_core::math::Vec3>,
}

/// Which earth model a scenario uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EarthChoice {
    /// WGS-84 (default)
    Wgs84,
    /// PSINS constant set
    Psins,
    /// flat, non-rotating, g = 9.80665
    Flat,
}

impl EarthChoice {
    /// The model value.
    pub fn model(self) -> EarthModel {
        match self {
            EarthChoice::Wgs84 => EarthModel::WGS84,
            EarthChoice::Psins => EarthModel::PSINS,
            EarthChoice::Flat => EarthModel::flat(9.806_65),
        }
    }
    /// Name as written in scenario files.
    pub fn name(self) -> &'static str {
        match self {
            EarthChoice::Wgs84 => "wgs84",
            EarthChoice::Psins => "psins",
            EarthChoice::Flat => "flat",
        }
    }
}

/// Start state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Start {
    /// latitude \[rad\]
    pub lat_rad: f64,
    /// longitude \[rad\]
    pub lon_rad: f64,
    /// height \[m\]
    pub h_m: f64,
    /// horizontal speed along the heading \[m/s\]
    pub speed_mps: f64,
    /// climb rate \[m/s\], positive up (v_D = −climb)
    pub climb_rate_mps: f64,
    /// attitude
    pub euler: Euler,
}

/// IMU set-up.
#[derive(Clone, Debug, PartialEq)]
pub struct ImuConfig {
    /// sample rate \[Hz\]
    pub rate_hz: f64,
    /// random seed (error models, Monte Carlo)
    pub seed: u64,
    /// sensor-grade preset name
    pub grade: Option<String>,
    /// error-model overrides (interpreted by the IMU error model)
    pub errors: Option<toml::Table>,
    /// the resolved error model: the grade preset (default `ideal`) with the overrides
    pub model: crate::sensors::imu_error::ImuErrorModel,
}

impl ImuConfig {
    /// Sample period δt \[s\].
    pub fn dt_s(&self) -> f64 {
        1.0 / self.rate_hz
    }
}

/// Navigation set-up.
#[derive(Clone, Debug, PartialEq)]
pub struct NavConfig {
    /// samples per update N
    pub samples: usize,
    /// algorithms to run by default
    pub algos: Vec<String>,
    /// coning/sculling set name (default: the polynomial set of N)
    pub coning: Option<String>,
    /// earth model
    pub earth: EarthChoice,
    /// vertical channel: `free` or `hold`
    pub vertical_hold: bool,
    /// truth resolution: RK4 substeps per sample; the default Gauss scheme uses one 3-node
    /// panel up to 16 and `⌈substeps/32⌉` 4-node panels above (default:
    /// [`crate::truth::auto_substeps`])
    pub substeps: usize,
}

/// A validated scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// name
    pub name: String,
    /// description
    pub description: String,
    /// start state
    pub start: Start,
    /// IMU
    pub imu: ImuConfig,
    /// navigation set-up
    pub nav: NavConfig,
    /// the trajectory
    pub trajectory: Trajectory,
    /// GNSS receiver simulation (`[gnss]`), if the scenario has one
    pub gnss: Option<crate::sensors::gnss::GnssConfig>,
    /// aiding sensors (`[baro]`, `[odometer]`, `[magnetometer]`, `[dual_antenna]`,
    /// `[body_velocity]`)
    pub aiding: crate::sensors::aiding::AidingConfig,
    /// raw GNSS measurement simulation (`[raw_gnss]`, satellites loaded), if any
    pub raw_gnss: Option<crate::sensors::raw_gnss::RawGnssConfig>,
    /// the scenario text exactly as it was read (provenance: `run.toml` records this, not
    /// the file as it may be later)
    pub source_toml: String,
    /// sensor placement (`[mounting]`)
    pub mounting: Mounting,
    /// per `random_vibration` overlay (in order): the power realised and dropped
    pub vibration: Vec<crate::truth::random_vibration::VibrationReport>,
    /// the compiled route (`[[waypoint]]` scenarios): its motions and per-waypoint report
    pub route: Option<crate::truth::route::CompiledRoute>,
}

impl Scenario {
    /// The exact-truth generator's configuration of this scenario (its earth model, IMU
    /// interval, start position and truth resolution).
    pub fn truth_config(&self) -> crate::truth::TruthConfig {
        crate::truth::TruthConfig {
            earth: self.nav.earth.model(),
            dt_s: self.imu.dt_s(),
            lat0_rad: self.start.lat_rad,
            lon0_rad: self.start.lon_rad,
            h0_m: self.start.h_m,
            substeps: self.nav.substeps,
        }
    }

    /// The raw GNSS measurements of run `run` of the `[raw_gnss]` table over the whole
    /// trajectory (`crate::sensors::raw_gnss::simulate`).
    pub fn simulate_raw_gnss(
        &self,
        run: u64,
    ) -> Result<crate::sensors::raw_gnss::RawGnssRecord, crate::sensors::raw_gnss::RawGnssError>
    {
        let cfg = self
            .raw_gnss
            .as_ref()
            .ok_or(crate::sensors::raw_gnss::RawGnssError::NoTable)?;
        Ok(crate::sensors::raw_gnss::simulate(
            &self.trajectory,
            self.truth_config(),
            cfg,
            run,
        ))
    }

    /// Read and validate a scenario file.
    pub fn from_file(path: &Path) -> Result<Scenario, ScenarioError> {
        Scenario::from_file_with(path, &crate::cancel::CancelToken::new())
    }

    /// [`Scenario::from_file`], polling `cancel` in its long steps (route compilation,
    /// command lists, the envelope check): [`ScenarioError::Cancelled`] once it is set.
    pub fn from_file_with(
        path: &Path,
        cancel: &crate::cancel::CancelToken,
    ) -> Result<Scenario, ScenarioError> {
        let file = path.display().to_string();
        let bytes = crate::input::read_capped(path).map_err(|e| ScenarioError::Read {
            file: file.clone(),
            reason: e.to_string(),
        })?;
        let text = String::from_utf8(bytes).map_err(|e| ScenarioError::Read {
            file: file.clone(),
            reason: format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        })?;
        if crate::io::gnss_ins_sim::looks_like_motion_def(&text) {
            return Scenario::from_motion_def_with(&text, path, &Default::default(), cancel);
        }
        Scenario::from_toml_with(&text, &file, cancel)
    }

    /// A gnss-ins-sim motion-definition file as a scenario
    /// ([`crate::io::gnss_ins_sim::to_scenario_toml`], then [`Scenario::from_toml`] on the result).
    pub fn from_motion_def(
        text: &str,
        path: &Path,
        opts: &crate::io::gnss_ins_sim::ImportOptions,
    ) -> Result<Scenario, ScenarioError> {
        Scenario::from_motion_def_with(text, path, opts, &crate::cancel::CancelToken::new())
    }

    /// [`Scenario::from_motion_def`] polling `cancel` ([`Scenario::from_file_with`]).
    pub fn from_motion_def_with(
        text: &str,
        path: &Path,
        opts: &crate::io::gnss_ins_sim::ImportOptions,
        cancel: &crate::cancel::CancelToken,
    ) -> Result<Scenario, ScenarioError> {
        use crate::io::gnss_ins_sim::{parse_motion_def_with, to_scenario_toml_with, GisError};
        let file = path.display().to_string();
        let conv = |e: GisError| match e {
            GisError::Invalid {
                file,
                line,
                column,
                message,
            } => ScenarioError::Invalid {
                file,
                line,
                key: format!("column {column}"),
                message,
            },
            GisError::Cancelled(_) => ScenarioError::Cancelled,
            other => ScenarioError::Read {
                file: file.clone(),
                reason: other.to_string(),
            },
        };
        let mf = parse_motion_def_with(text, &file, cancel).map_err(conv)?;
        let name = path
            .file_stem()
            .map_or_else(|| "imported".into(), |s| s.to_string_lossy().into_owned());
        let toml = to_scenario_toml_with(&mf, &name, &file, opts, cancel).map_err(conv)?;
        Scenario::from_toml_with(&toml, &file, cancel)
    }

    /// A built-in name or a file path.
    pub fn load(name_or_path: &str) -> Result<Scenario, ScenarioError> {
        Scenario::load_with(name_or_path, &crate::cancel::CancelToken::new())
    }

    /// [`Scenario::load`] polling `cancel` ([`Scenario::from_file_with`]).
    pub fn load_with(
        name_or_path: &str,
        cancel: &crate::cancel::CancelToken,
    ) -> Result<Scenario, ScenarioError> {
        if let Some(b) = builtin(name_or_path) {
            return Scenario::from_toml_with(b.toml, &format!("<built-in {}>", b.name), cancel);
        }
        let p = Path::new(name_or_path);
        if p.exists() {
            return Scenario::from_file_with(p, cancel);
        }
        Err(ScenarioError::Unknown {
            name: name_or_path.to_string(),
            known: BUILTINS
                .iter()
                .map(|b| b.name)
                .collect::<Vec<_>>()
                .join(", "),
        })
    }

    /// Duration \[s\].
    pub fn duration_s(&self) -> f64 {
        self.trajectory.duration_s
    }
}

impl Default for NavConfig {
    /// N = 3, the four paper algorithms, WGS-84, free vertical channel, automatic truth
    /// substeps (`substeps = 0` until the trajectory is known).
    fn default() -> Self {
        NavConfig {
            samples: 3,
            algos: vec![
                "savage".into(),
                "songlee".into(),
                "songlee-complete".into(),
                "dualquat".into(),
            ],
            coning: None,
            earth: EarthChoice::Wgs84,
            vertical_hold: false,
            substeps: 0,
        }
    }
}

/// A built-in scenario.
#[derive(Clone, Copy, Debug)]
pub struct Builtin {
    /// name
    pub name: &'static str,
    /// one-line summary
    pub summary: &'static str,
    /// the scenario file text
    pub toml: &'static str,
}

/// The built-in scenarios (every paper case of docs/validation.md and the alignment
/// reference case).
pub const BUILTINS: &[Builtin] = &[
    Builtin { name: "stationary", summary: "A0: stationary 90 min at 37.5N 127E", toml: include_str!("../../scenarios/stationary.toml") },
    Builtin { name: "mach1-east", summary: "A1: Mach 1 due east, 90 min (Song-Lee Table 1)", toml: include_str!("../../scenarios/mach1-east.toml") },
    Builtin { name: "turn-90dps", summary: "A2: 90 deg/s turn from east to south at Mach 1", toml: include_str!("../../scenarios/turn-90dps.toml") },
    Builtin { name: "dq-paper", summary: "B: stationary, accelerate, S-turn with 1 Hz coning (dual-quaternion paper)", toml: include_str!("../../scenarios/dq-paper.toml") },
    Builtin { name: "alignment", summary: "stationary alignment reference: roll/pitch/yaw 2/-3/40 deg at 37.5N", toml: include_str!("../../scenarios/alignment.toml") },
    Builtin { name: "moored-ship", summary: "disturbed base: moored ship at 40N, roll/pitch sway ±5 deg, 0.5 m heave, 0.2 m surge, marine grade", toml: include_str!("../../scenarios/moored-ship.toml") },
    Builtin { name: "rocking-car", summary: "disturbed base: parked car rocking ±0.8/0.5 deg at 1.373/1.827 Hz with 1 cm heave, aviation grade", toml: include_str!("../../scenarios/rocking-car.toml") },
    Builtin { name: "calibration", summary: "12-position turntable calibration: 300 s dwells, 10 s rotations, tactical grade, 100 Hz (sdins calibrate)", toml: include_str!("../../scenarios/calibration.toml") },
    Builtin { name: "car-odometer", summary: "car with stops and turns: odometer + NHC at the rear axle, 1 Hz GNSS with a 60 s outage, road vibration while moving (5 min, 100 Hz; try --zupt-detector)", toml: include_str!("../../scenarios/car-odometer.toml") },
    Builtin { name: "aircraft-sensors", summary: "aircraft at 3 km: barometer, magnetometer, dual-antenna heading, 1 Hz GNSS with a 60 s outage in a turn (100 Hz)", toml: include_str!("../../scenarios/aircraft-sensors.toml") },
    Builtin { name: "route-demo", summary: "route through 4 waypoints at 45N 10E: two fly-by turns, 50 to 60 m/s, 200 m climb, geodesic legs (230 s, 100 Hz)", toml: include_str!("../../scenarios/route-demo.toml") },
];

/// Look up a built-in scenario by name.
pub fn builtin(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn all_builtins_parse() {
        for b in BUILTINS {
            let s = Scenario::from_toml(b.toml, b.name);
            assert!(s.is_ok(), "{}: {:?}", b.name, s.err());
        }
    }

    fn err_of(text: &str) -> ScenarioError {
        match Scenario::from_toml(text, "t.toml") {
            Err(e) => e,
            Ok(_) => panic!("expected an error for:\n{text}"),
        }
    }

    const BASE: &str = "[start]\nlat_deg = 37.5\nlon_deg = 127.0\n[imu]\nrate_hz = 100.0\n[[segment]]\ntype = \"static\"\nduration_s = 10.0\n";

    #[test]
    fn unknown_key_names_line_and_suggests() {
        let e = err_of(&BASE.replace("lon_deg = 127.0", "lon_deg = 127.0\nlat_dg = 3.0"));
        let ScenarioError::Invalid {
            line, key, message, ..
        } = &e
        else {
            panic!("{e}")
        };
        assert_eq!((*line, key.as_str()), (4, "lat_dg"));
        assert!(message.contains("did you mean `lat_deg`"), "{message}");
    }

    #[test]
    fn missing_key() {
        let e = err_of(&BASE.replace("rate_hz = 100.0\n", ""));
        assert!(
            e.to_string().contains("rate_hz") && e.to_string().contains("missing"),
            "{e}"
        );
    }

    #[test]
    fn impossible_values_name_line_and_key() {
        for (from, to, line, key) in [
            (
                "duration_s = 10.0",
                "duration_s = -1.0",
                8,
                "segment.duration_s",
            ),
            ("rate_hz = 100.0", "rate_hz = 0.0", 5, "imu.rate_hz"),
            ("lat_deg = 37.5", "lat_deg = 95.0", 2, "start.lat_deg"),
            (
                "duration_s = 10.0",
                "duration_s = 10.001",
                8,
                "segment.duration_s",
            ),
            ("lat_deg = 37.5", "lat_deg = nan", 2, "start.lat_deg"),
        ] {
            let e = err_of(&BASE.replace(from, to));
            let ScenarioError::Invalid {
                line: l, key: k, ..
            } = &e
            else {
                panic!("{e}")
            };
            assert_eq!((*l, k.as_str()), (line, key), "{e}");
        }
        let e = err_of(&format!("{BASE}[start2]\n"));
        assert!(e.to_string().contains("start2"), "{e}");
        let e = err_of(&BASE.replace(
            "[start]\nlat_deg = 37.5\n",
            "[start]\nlat_deg = 37.5\nh_m = -2000.0\n",
        ));
        assert!(e.to_string().contains("start.h_m"), "{e}");
    }

    #[test]
    fn wrong_segment_keys() {
        let e = err_of(&BASE.replace("type = \"static\"", "type = \"staticc\""));
        assert!(e.to_string().contains("unknown segment type"), "{e}");
        let e = err_of(&BASE.replace("duration_s = 10.0", "duration_s = 10.0\nrate_dps = 3.0"));
        assert!(
            e.to_string().contains("not a key of segment type `static`"),
            "{e}"
        );
    }
}
