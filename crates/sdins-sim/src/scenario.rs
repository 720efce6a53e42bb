//! Scenario files (TOML): start state, IMU, navigation set-up and motion segments.
//!
//! Every key carries its unit in its name. Unknown keys, missing keys and impossible
//! values are reported with the file, line and key, and a "did you mean" hint for
//! misspelt keys. See `docs/scenarios.md` for the reference (a test checks that it lists
//! exactly the keys accepted here: [`ACCEPTED_KEYS`]).

use crate::trajectory::{Axis, Motion, Overlay, OverlayKind, Trajectory};
use crate::vehicle::{Vehicle, VehicleError};
use sdins_core::earth::EarthModel;
use sdins_core::math::Euler;
use serde::Deserialize;
use std::path::Path;
use toml::Spanned;

const D2R: f64 = std::f64::consts::PI / 180.0;
/// Longest accepted segment \[s\] (keeps sample counts far from integer overflow).
pub const MAX_SEGMENT_S: f64 = 1.0e7;

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
}

/// Every key the parser accepts, by table (the documentation test compares with
/// `docs/scenarios.md`).
pub const ACCEPTED_KEYS: &[(&str, &[&str])] = &[
    (
        "",
        &[
            "name",
            "description",
            "start",
            "imu",
            "nav",
            "segment",
            "overlay",
            "vehicle",
            "angle_of_attack_deg",
            "mounting",
            "gnss",
            "calibration",
            "body_motion",
            "command",
            "waypoint",
            "route",
        ],
    ),
    (
        "waypoint",
        &["lat_deg", "lon_deg", "h_m", "speed_mps", "hold_s"],
    ),
    (
        "route",
        &[
            "legs",
            "turn_rate_limit_dps",
            "bank_limit_deg",
            "roll_rate_limit_dps",
            "climb_rate_limit_mps",
            "accel_limit_mps2",
        ],
    ),
    BODY_MOTION_KEYS,
    COMMAND_KEYS,
    ("calibration", &["schedule", "dwell_s", "rotation_s"]),
    (
        "mounting",
        &["imu_lever_arm_m", "imu_mount_deg", "gnss_lever_arm_m"],
    ),
    (
        "start",
        &[
            "lat_deg",
            "lon_deg",
            "h_m",
            "speed_mps",
            "climb_rate_mps",
            "roll_deg",
            "pitch_deg",
            "yaw_deg",
        ],
    ),
    ("imu", &["rate_hz", "seed", "grade", "errors"]),
    (
        "nav",
        &[
            "samples", "algos", "coning", "earth", "vertical", "substeps",
        ],
    ),
    (
        "segment",
        &[
            "type",
            "duration_s",
            "accel_mps2",
            "rate_dps",
            "angle_deg",
            "profile",
            "amplitude_dps",
            "to_climb_rate_mps",
            "bank_deg",
            "roll_rate_dps",
        ],
    ),
    (
        "overlay",
        &[
            "type",
            "axis",
            "half_angle_deg",
            "freq_hz",
            "angle_amp_deg",
            "accel_amp_mps2",
            "phase_deg",
            "angle_deg",
            "start_s",
            "end_s",
            "accel_psd_file",
            "gyro_psd_file",
            "accel_psd_breakpoints",
            "gyro_psd_breakpoints",
            "seed",
        ],
    ),
    GNSS_KEYS,
];

// ---- [body_motion] and [[command]] (gnss-ins-sim motion commands) ----
/// Keys of `[body_motion]` (start body velocity and the motion limits).
const BODY_MOTION_KEYS: (&str, &[&str]) = (
    "body_motion",
    &[
        "vx_mps",
        "vy_mps",
        "vz_mps",
        "max_accel_mps2",
        "max_angular_accel_dps2",
        "max_angular_rate_dps",
    ],
);
/// Keys of `[[command]]` ([`crate::body_motion::BodyCommand`]).
const COMMAND_KEYS: (&str, &[&str]) = (
    "command",
    &[
        "type",
        "yaw_deg",
        "pitch_deg",
        "roll_deg",
        "vx_mps",
        "vy_mps",
        "vz_mps",
        "yaw_rate_dps",
        "pitch_rate_dps",
        "roll_rate_dps",
        "ax_mps2",
        "ay_mps2",
        "az_mps2",
        "duration_s",
    ],
);

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BodyMotionDoc {
    vx_mps: Option<S<f64>>,
    vy_mps: Option<S<f64>>,
    vz_mps: Option<S<f64>>,
    max_accel_mps2: Option<S<f64>>,
    max_angular_accel_dps2: Option<S<f64>>,
    max_angular_rate_dps: Option<S<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CommandDoc {
    #[serde(rename = "type")]
    kind: S<i64>,
    yaw_deg: Option<S<f64>>,
    pitch_deg: Option<S<f64>>,
    roll_deg: Option<S<f64>>,
    vx_mps: Option<S<f64>>,
    vy_mps: Option<S<f64>>,
    vz_mps: Option<S<f64>>,
    yaw_rate_dps: Option<S<f64>>,
    pitch_rate_dps: Option<S<f64>>,
    roll_rate_dps: Option<S<f64>>,
    ax_mps2: Option<S<f64>>,
    ay_mps2: Option<S<f64>>,
    az_mps2: Option<S<f64>>,
    duration_s: S<f64>,
}
// ---- end [body_motion] ----

// ---- [gnss] section (INS/GNSS fusion) ----
/// Keys of the `[gnss]` table (`crate::gnss::GnssConfig`).
const GNSS_KEYS: (&str, &[&str]) = (
    "gnss",
    &[
        "rate_hz",
        "offset_s",
        "sigma_pos_ned_m",
        "sigma_vel_ned_mps",
        "gm_sigma_ned_m",
        "gm_tau_s",
        "lever_arm_b_m",
        "outages_s",
        "dropout_prob",
        "outliers_t_s_ned_m",
        "latency_s",
        "latency_modelled",
        "seed",
    ],
);
// ---- end [gnss] ----

type S<T> = Spanned<T>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileDoc {
    name: Option<String>,
    description: Option<String>,
    start: Option<S<StartDoc>>,
    imu: S<ImuDoc>,
    nav: Option<NavDoc>,
    #[serde(default)]
    segment: Vec<S<SegmentDoc>>,
    #[serde(default)]
    overlay: Vec<S<OverlayDoc>>,
    vehicle: Option<S<String>>,
    angle_of_attack_deg: Option<S<f64>>,
    mounting: Option<S<MountingDoc>>,
    // [gnss] section
    gnss: Option<S<crate::gnss::GnssConfig>>,
    calibration: Option<S<CalibrationDoc>>,
    body_motion: Option<S<BodyMotionDoc>>,
    #[serde(default)]
    command: Vec<S<CommandDoc>>,
    #[serde(default)]
    waypoint: Vec<S<WaypointDoc>>,
    route: Option<S<RouteDoc>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WaypointDoc {
    lat_deg: S<f64>,
    lon_deg: S<f64>,
    h_m: Option<S<f64>>,
    speed_mps: S<f64>,
    hold_s: Option<S<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RouteDoc {
    legs: Option<S<String>>,
    turn_rate_limit_dps: Option<S<f64>>,
    bank_limit_deg: Option<S<f64>>,
    roll_rate_limit_dps: Option<S<f64>>,
    climb_rate_limit_mps: Option<S<f64>>,
    accel_limit_mps2: Option<S<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CalibrationDoc {
    schedule: S<String>,
    dwell_s: Option<S<f64>>,
    rotation_s: Option<S<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MountingDoc {
    imu_lever_arm_m: Option<S<Vec<f64>>>,
    imu_mount_deg: Option<S<Vec<f64>>>,
    gnss_lever_arm_m: Option<S<Vec<f64>>>,
}

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

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StartDoc {
    lat_deg: S<f64>,
    lon_deg: S<f64>,
    h_m: Option<S<f64>>,
    speed_mps: Option<S<f64>>,
    climb_rate_mps: Option<S<f64>>,
    roll_deg: Option<S<f64>>,
    pitch_deg: Option<S<f64>>,
    yaw_deg: Option<S<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ImuDoc {
    rate_hz: S<f64>,
    seed: Option<u64>,
    grade: Option<S<String>>,
    errors: Option<toml::Table>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NavDoc {
    samples: Option<S<i64>>,
    algos: Option<S<Vec<String>>>,
    coning: Option<S<String>>,
    earth: Option<S<String>>,
    vertical: Option<S<String>>,
    substeps: Option<S<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SegmentDoc {
    #[serde(rename = "type")]
    kind: S<String>,
    duration_s: Option<S<f64>>,
    accel_mps2: Option<S<f64>>,
    rate_dps: Option<S<f64>>,
    angle_deg: Option<S<f64>>,
    profile: Option<S<String>>,
    amplitude_dps: Option<S<f64>>,
    to_climb_rate_mps: Option<S<f64>>,
    bank_deg: Option<S<f64>>,
    roll_rate_dps: Option<S<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OverlayDoc {
    #[serde(rename = "type")]
    kind: S<String>,
    axis: Option<S<String>>,
    half_angle_deg: Option<S<f64>>,
    freq_hz: Option<S<f64>>,
    angle_amp_deg: Option<S<f64>>,
    accel_amp_mps2: Option<S<f64>>,
    phase_deg: Option<S<f64>>,
    angle_deg: Option<S<f64>>,
    start_s: Option<S<f64>>,
    end_s: Option<S<f64>>,
    accel_psd_file: Option<S<String>>,
    gyro_psd_file: Option<S<String>>,
    accel_psd_breakpoints: Option<S<Vec<Vec<f64>>>>,
    gyro_psd_breakpoints: Option<S<Vec<Vec<f64>>>>,
    seed: Option<S<u64>>,
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
    pub model: crate::imu_error::ImuErrorModel,
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
    pub gnss: Option<crate::gnss::GnssConfig>,
    /// the scenario text exactly as it was read (provenance: `run.toml` records this, not
    /// the file as it may be later)
    pub source_toml: String,
    /// sensor placement (`[mounting]`)
    pub mounting: Mounting,
    /// per `random_vibration` overlay (in order): the power realised and dropped
    pub vibration: Vec<crate::random_vibration::VibrationReport>,
    /// the compiled route (`[[waypoint]]` scenarios): its motions and per-waypoint report
    pub route: Option<crate::route::CompiledRoute>,
}

struct Ctx<'a> {
    file: &'a str,
    text: &'a str,
}

impl Ctx<'_> {
    fn line_of(&self, pos: usize) -> usize {
        self.text
            .get(..pos.min(self.text.len()))
            .map_or(1, |s| s.bytes().filter(|&b| b == b'\n').count() + 1)
    }
    fn err<T>(
        &self,
        span: std::ops::Range<usize>,
        key: &str,
        message: impl Into<String>,
    ) -> Result<T, ScenarioError> {
        Err(ScenarioError::Invalid {
            file: self.file.to_string(),
            line: self.line_of(span.start),
            key: key.to_string(),
            message: message.into(),
        })
    }
    fn finite(&self, v: &S<f64>, key: &str) -> Result<f64, ScenarioError> {
        let x = *v.get_ref();
        if !x.is_finite() {
            return self.err(v.span(), key, "must be a finite number");
        }
        Ok(x)
    }
    fn range(
        &self,
        v: &S<f64>,
        key: &str,
        lo: f64,
        hi: f64,
        what: &str,
    ) -> Result<f64, ScenarioError> {
        let x = self.finite(v, key)?;
        if !(lo..=hi).contains(&x) {
            return self.err(
                v.span(),
                key,
                format!("{x} is out of range: expected {what}"),
            );
        }
        Ok(x)
    }
    fn positive(&self, v: &S<f64>, key: &str) -> Result<f64, ScenarioError> {
        let x = self.finite(v, key)?;
        if x <= 0.0 {
            return self.err(v.span(), key, format!("{x} must be > 0"));
        }
        Ok(x)
    }
}

fn levenshtein(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur.push(sub.min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}

fn is_subsequence(short: &str, long: &str) -> bool {
    let mut it = long.chars();
    short.chars().all(|c| it.any(|x| x == c))
}

/// Closest of `candidates` to an unknown key (for "did you mean" hints): the smallest
/// edit distance within half the key's length, or a key whose letters appear in order in
/// the unknown one (`heigth_m` → `h_m`).
pub fn suggest_from<'a>(unknown: &str, candidates: &[&'a str]) -> Option<&'a str> {
    let best = candidates
        .iter()
        .copied()
        .map(|k| (levenshtein(unknown, k), k))
        .min_by_key(|(d, _)| *d);
    if let Some((d, k)) = best {
        if d <= 3.max(unknown.len() / 2) {
            return Some(k);
        }
    }
    candidates
        .iter()
        .copied()
        .filter(|k| k.len() >= 3 && is_subsequence(k, unknown))
        .max_by_key(|k| k.len())
}

/// Closest accepted key (of any table) to an unknown one.
pub fn suggest(unknown: &str) -> Option<&'static str> {
    let all: Vec<&'static str> = ACCEPTED_KEYS
        .iter()
        .flat_map(|(_, keys)| keys.iter().copied())
        .collect();
    suggest_from(unknown, &all)
}

fn toml_error(file: &str, text: &str, e: &toml::de::Error) -> ScenarioError {
    let line = e.span().map_or(1, |s| {
        text.get(..s.start)
            .map_or(1, |p| p.matches('\n').count() + 1)
    });
    let msg = e.message().trim().to_string();
    let mut key = String::from("(syntax)");
    let mut message = msg.clone();
    if let Some(rest) = msg.strip_prefix("unknown field `") {
        if let Some(end) = rest.find('`') {
            let name = &rest[..end];
            key = name.to_string();
            // candidates: the keys the parser listed as expected here
            let expected: Vec<&str> = rest.split('`').skip(2).step_by(2).collect();
            let hint = if expected.is_empty() {
                suggest(name)
            } else {
                suggest_from(name, &expected)
            };
            message = format!(
                "unknown key{}",
                hint.map(|s| format!(" (did you mean `{s}`?)"))
                    .unwrap_or_default()
            );
            if let Some(exp) = rest.find("expected") {
                message.push_str(&format!("; {}", &rest[exp..]));
            }
        }
    } else if let Some(rest) = msg.strip_prefix("missing field `") {
        if let Some(end) = rest.find('`') {
            key = rest[..end].to_string();
            message = "missing required key".to_string();
        }
    }
    ScenarioError::Invalid {
        file: file.to_string(),
        line,
        key,
        message,
    }
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

    /// Parse and validate scenario text; `file` names it in error messages.
    pub fn from_toml(text: &str, file: &str) -> Result<Scenario, ScenarioError> {
        let doc: FileDoc = toml::from_str(text).map_err(|e| toml_error(file, text, &e))?;
        let cx = Ctx { file, text };
        let start_from_route;
        let start_doc: &S<StartDoc> = match (&doc.start, doc.waypoint.first()) {
            (Some(s), None) => s,
            (Some(s), Some(_)) => {
                return cx.err(s.span(), "start", "a route's first [[waypoint]] is its start position (and its heading and speed come from the route): leave [start] out");
            }
            (None, Some(w)) => {
                let wd = w.get_ref();
                start_from_route = S::new(
                    w.span(),
                    StartDoc {
                        lat_deg: wd.lat_deg.clone(),
                        lon_deg: wd.lon_deg.clone(),
                        h_m: wd.h_m.clone(),
                        speed_mps: None,
                        climb_rate_mps: None,
                        roll_deg: None,
                        pitch_deg: None,
                        yaw_deg: None,
                    },
                );
                &start_from_route
            }
            (None, None) => {
                return Err(ScenarioError::Invalid {
                    file: file.into(),
                    line: 1,
                    key: "start".into(),
                    message:
                        "missing required key (a [start] table, or a route of [[waypoint]] tables)"
                            .into(),
                });
            }
        };
        let st = start_doc.get_ref();
        let lat = cx.range(
            &st.lat_deg,
            "start.lat_deg",
            -90.0,
            90.0,
            "latitude in [-90, 90] deg",
        )?;
        if lat.abs() > 89.0 {
            // The local-level (NED) mechanization is singular at the poles: tan L and
            // 1/cos L in the transport rate and longitude rate. We accept up to ±89.99°.
            if lat.abs() > 89.99 {
                return cx.err(st.lat_deg.span(), "start.lat_deg", format!("{lat} is too close to a pole: the local-level NED mechanization needs |lat| ≤ 89.99 deg"));
            }
        }
        let lon = cx.range(
            &st.lon_deg,
            "start.lon_deg",
            -180.0,
            360.0,
            "longitude in [-180, 360] deg",
        )?;
        let h = match &st.h_m {
            Some(v) => cx.range(
                v,
                "start.h_m",
                -1000.0,
                100_000.0,
                "height in [-1000, 100000] m",
            )?,
            None => 0.0,
        };
        let speed = match &st.speed_mps {
            Some(v) => cx.range(v, "start.speed_mps", 0.0, 3000.0, "speed in [0, 3000] m/s")?,
            None => 0.0,
        };
        let climb = match &st.climb_rate_mps {
            Some(v) => cx.range(
                v,
                "start.climb_rate_mps",
                -500.0,
                500.0,
                "climb rate in [-500, 500] m/s",
            )?,
            None => 0.0,
        };
        let ang = |v: &Option<S<f64>>, key: &str, lim: f64| -> Result<f64, ScenarioError> {
            match v {
                Some(v) => {
                    Ok(
                        cx.range(v, key, -lim, lim, &format!("angle in [-{lim}, {lim}] deg"))?
                            * D2R,
                    )
                }
                None => Ok(0.0),
            }
        };
        let euler = Euler::new(
            ang(&st.roll_deg, "start.roll_deg", 180.0)?,
            ang(&st.pitch_deg, "start.pitch_deg", 89.9)?,
            ang(&st.yaw_deg, "start.yaw_deg", 360.0)?,
        );
        let start = Start {
            lat_rad: lat * D2R,
            lon_rad: lon * D2R,
            h_m: h,
            speed_mps: speed,
            climb_rate_mps: climb,
            euler,
        };
        // the one initial-state validator every source uses (the ranges above name the key)
        if let Err(e) = crate::initial::validate_initial_state(&sdins_core::nav::InitialState {
            lat_rad: start.lat_rad,
            lon_rad: start.lon_rad,
            h_m: start.h_m,
            v_n_mps: sdins_core::math::Vec3::new(speed, 0.0, -climb),
            c_b_n: sdins_core::math::c_b_n_from_euler(&euler),
        }) {
            return cx.err(start_doc.span(), "start", e.to_string());
        }

        let im = doc.imu.get_ref();
        let rate_hz = cx.positive(&im.rate_hz, "imu.rate_hz")?;
        if rate_hz > 100_000.0 {
            return cx.err(
                im.rate_hz.span(),
                "imu.rate_hz",
                format!("{rate_hz} Hz is beyond 100 kHz"),
            );
        }
        let grade = im.grade.as_ref().map(|g| g.get_ref().clone());
        let base = match &im.grade {
            None => crate::imu_error::ImuErrorModel::ideal(),
            Some(g) => match crate::imu_error::ImuErrorModel::preset(g.get_ref()) {
                Ok(m) => m,
                Err(e) => return cx.err(g.span(), "imu.grade", e.to_string()),
            },
        };
        let model = match &im.errors {
            None => base,
            Some(t) => {
                let r = if t.contains_key("preset") {
                    crate::imu_error::ImuErrorModel::from_table(t)
                } else {
                    base.with_overrides(t)
                };
                match r {
                    Ok(m) => m,
                    Err(e) => return cx.err(doc.imu.span(), "imu.errors", e.to_string()),
                }
            }
        };
        let imu = ImuConfig {
            rate_hz,
            seed: im.seed.unwrap_or(1),
            grade,
            errors: im.errors.clone(),
            model,
        };

        let nav = parse_nav(&cx, doc.nav.as_ref())?;

        let dt = 1.0 / rate_hz;
        let vehicle = parse_vehicle(&cx, &doc)?;
        if vehicle != Vehicle::Free {
            for (v, key) in [
                (&st.roll_deg, "start.roll_deg"),
                (&st.pitch_deg, "start.pitch_deg"),
            ] {
                if let Some(v) = v {
                    if *v.get_ref() != 0.0 {
                        return cx.err(v.span(), key, format!("with vehicle = \"{}\" roll and pitch follow the motion (bank, flight-path angle, road grade): leave this key out", vehicle.name()));
                    }
                }
            }
        }
        let calibration = parse_calibration(&cx, &doc, speed, climb, vehicle, 1.0 / rate_hz)?;
        let body = parse_body_motion(&cx, &doc, start_doc.get_ref(), euler, vehicle, dt)?;
        let mut motions = Vec::new();
        // the [[segment]] of each motion (a coordinated turn is three motions)
        let mut seg_of_motion: Vec<std::ops::Range<usize>> = Vec::new();
        let mut speed_now = speed;
        for s in &doc.segment {
            let sd = s.get_ref();
            let kind = sd.kind.get_ref().as_str();
            let profile = sd.profile.as_ref().map(|p| p.get_ref().as_str());
            let coordinated = kind == "turn" && profile == Some("coordinated");
            let dur = match (&sd.duration_s, coordinated) {
                (Some(d), false) => cx.positive(d, "segment.duration_s")?,
                (Some(d), true) => {
                    return cx.err(d.span(), "segment.duration_s", "a coordinated turn takes its duration from angle_deg, bank_deg and roll_rate_dps: leave duration_s out");
                }
                (None, true) => 1.0,
                (None, false) => {
                    return cx.err(s.span(), "segment.duration_s", "missing required key");
                }
            };
            if dur > MAX_SEGMENT_S {
                let span = sd.duration_s.as_ref().map_or(s.span(), |d| d.span());
                return cx.err(
                    span,
                    "segment.duration_s",
                    format!("{dur} s is too long: expected at most {MAX_SEGMENT_S:e} s (116 days)"),
                );
            }
            let n = dur / dt;
            let dspan = sd.duration_s.as_ref().map_or(s.span(), |d| d.span());
            if !coordinated && n.round() < 1.0 {
                return cx.err(
                    dspan,
                    "segment.duration_s",
                    format!("{dur} s is shorter than one IMU sample ({dt} s at {rate_hz} Hz)"),
                );
            }
            if !coordinated && (n - n.round()).abs() > 1e-6 * n.max(1.0) {
                return cx.err(dspan, "segment.duration_s", format!("{dur} s is not a whole number of IMU samples at {rate_hz} Hz (segment boundaries must fall on sample boundaries)"));
            }
            // keys allowed per type
            let allowed: &[&str] = match kind {
                "static" | "cruise" => &[],
                "accelerate" => &["accel_mps2", "profile"],
                "turn" if coordinated => &["angle_deg", "profile", "bank_deg", "roll_rate_dps"],
                "turn" => &["rate_dps", "angle_deg", "profile"],
                "sturn" => &["amplitude_dps"],
                "climb" => &["to_climb_rate_mps", "profile"],
                other => {
                    return cx.err(sd.kind.span(), "segment.type", format!("unknown segment type `{other}`: expected one of static, cruise, accelerate, turn, sturn, climb"));
                }
            };
            let present: [(&str, Option<std::ops::Range<usize>>); 8] = [
                ("bank_deg", sd.bank_deg.as_ref().map(|v| v.span())),
                ("roll_rate_dps", sd.roll_rate_dps.as_ref().map(|v| v.span())),
                ("accel_mps2", sd.accel_mps2.as_ref().map(|v| v.span())),
                ("rate_dps", sd.rate_dps.as_ref().map(|v| v.span())),
                ("angle_deg", sd.angle_deg.as_ref().map(|v| v.span())),
                ("profile", sd.profile.as_ref().map(|v| v.span())),
                ("amplitude_dps", sd.amplitude_dps.as_ref().map(|v| v.span())),
                (
                    "to_climb_rate_mps",
                    sd.to_climb_rate_mps.as_ref().map(|v| v.span()),
                ),
            ];
            for (k, span) in present {
                if let Some(span) = span {
                    if !allowed.contains(&k) {
                        return cx.err(
                            span,
                            &format!("segment.{k}"),
                            format!(
                                "not a key of segment type `{kind}` (it takes: {})",
                                if allowed.is_empty() {
                                    "duration_s only".to_string()
                                } else {
                                    allowed.join(", ")
                                }
                            ),
                        );
                    }
                }
            }
            let need = |v: &Option<S<f64>>, key: &str| -> Result<f64, ScenarioError> {
                match v {
                    Some(v) => cx.finite(v, key),
                    None => cx.err(
                        s.span(),
                        key,
                        format!("missing required key for segment type `{kind}`"),
                    ),
                }
            };
            let motion = match kind {
                "static" => {
                    if speed_now != 0.0 {
                        return cx.err(sd.kind.span(), "segment.type", format!("a static segment needs zero speed, but the vehicle moves at {speed_now} m/s here (use `cruise`)"));
                    }
                    Motion::Static
                }
                "cruise" => Motion::Cruise,
                "turn" if coordinated => {
                    let angle = need(&sd.angle_deg, "segment.angle_deg")?;
                    let bank = need(&sd.bank_deg, "segment.bank_deg")?;
                    let roll = need(&sd.roll_rate_dps, "segment.roll_rate_dps")?;
                    if !(bank > 0.0 && bank < 90.0) {
                        let span = sd.bank_deg.as_ref().map_or(s.span(), |v| v.span());
                        return cx.err(
                            span,
                            "segment.bank_deg",
                            format!("{bank} deg: expected a bank limit in (0, 90) deg"),
                        );
                    }
                    if !(roll > 0.0 && roll <= 360.0) {
                        let span = sd.roll_rate_dps.as_ref().map_or(s.span(), |v| v.span());
                        return cx.err(
                            span,
                            "segment.roll_rate_dps",
                            format!("{roll} deg/s: expected a roll-rate limit in (0, 360] deg/s"),
                        );
                    }
                    if angle == 0.0 || speed_now <= 0.0 {
                        return cx.err(s.span(), "segment.angle_deg", format!("a coordinated turn needs a non-zero angle and a moving vehicle (speed here {speed_now} m/s)"));
                    }
                    match crate::vehicle::coordinated_turn(
                        speed_now,
                        angle * D2R,
                        bank * D2R,
                        roll * D2R,
                        dt,
                    ) {
                        Ok(parts) => {
                            for p in parts {
                                motions.push(p);
                                seg_of_motion.push(s.span());
                            }
                        }
                        Err(e) => return cx.err(s.span(), "segment.type", e.to_string()),
                    }
                    continue;
                }
                "accelerate" => {
                    let a = need(&sd.accel_mps2, "segment.accel_mps2")?;
                    if a.abs() > 1000.0 * 9.80665 {
                        return cx.err(
                            s.span(),
                            "segment.accel_mps2",
                            format!("{a} m/s² exceeds 1000 g"),
                        );
                    }
                    speed_now = crate::trajectory::accelerated_speed(speed_now, a, dur);
                    if speed_now < 0.0 {
                        return cx.err(s.span(), "segment.accel_mps2", format!("the speed would become negative ({speed_now} m/s) by the end of this segment"));
                    }
                    match profile {
                        None | Some("linear") => Motion::Accelerate { accel_mps2: a },
                        Some("smooth") => Motion::AccelerateSmooth {
                            delta_speed_mps: a * dur,
                        },
                        Some(other) => {
                            let span = sd.profile.as_ref().map_or(s.span(), |p| p.span());
                            return cx.err(span, "segment.profile", format!("unknown profile `{other}` for accelerate: expected linear or smooth"));
                        }
                    }
                }
                "turn" => {
                    let profile = sd
                        .profile
                        .as_ref()
                        .map_or("constant", |p| p.get_ref().as_str());
                    match (profile, &sd.rate_dps, &sd.angle_deg) {
                        ("constant", Some(r), None) => Motion::TurnRate {
                            rate_rps: cx.finite(r, "segment.rate_dps")? * D2R,
                        },
                        ("constant", None, Some(a)) => Motion::TurnRate {
                            rate_rps: cx.finite(a, "segment.angle_deg")? * D2R / dur,
                        },
                        ("smooth", None, Some(a)) => Motion::TurnSmooth {
                            angle_rad: cx.finite(a, "segment.angle_deg")? * D2R,
                        },
                        ("smooth", Some(r), None) => Motion::TurnSmooth {
                            angle_rad: cx.finite(r, "segment.rate_dps")? * D2R * dur,
                        },
                        ("constant" | "smooth", Some(_), Some(_)) => {
                            return cx.err(
                                s.span(),
                                "segment.rate_dps",
                                "give either rate_dps or angle_deg, not both",
                            );
                        }
                        ("constant" | "smooth", None, None) => {
                            return cx.err(
                                s.span(),
                                "segment.angle_deg",
                                "a turn needs rate_dps or angle_deg",
                            );
                        }
                        (other, _, _) => {
                            let span = sd.profile.as_ref().map_or(s.span(), |p| p.span());
                            return cx.err(
                                span,
                                "segment.profile",
                                format!("unknown profile `{other}`: expected constant or smooth"),
                            );
                        }
                    }
                }
                "sturn" => Motion::STurn {
                    amplitude_rps: need(&sd.amplitude_dps, "segment.amplitude_dps")? * D2R,
                },
                _ => {
                    let to = need(&sd.to_climb_rate_mps, "segment.to_climb_rate_mps")?;
                    match profile {
                        None | Some("linear") => Motion::Climb {
                            to_climb_rate_mps: to,
                        },
                        Some("smooth") => Motion::ClimbSmooth {
                            to_climb_rate_mps: to,
                        },
                        Some(other) => {
                            let span = sd.profile.as_ref().map_or(s.span(), |p| p.span());
                            return cx.err(span, "segment.profile", format!("unknown profile `{other}` for climb: expected linear or smooth"));
                        }
                    }
                }
            };
            motions.push((motion, (n.round()) * dt));
            seg_of_motion.push(s.span());
        }
        let mut route_report = None;
        let (mut speed, mut euler, mut start) = (speed, euler, start);
        if !doc.waypoint.is_empty() || doc.route.is_some() {
            if let Some(sg) = doc.segment.first() {
                return cx.err(sg.span(), "segment", "a scenario takes either [[segment]] tables or a route of [[waypoint]] tables, not both");
            }
            if let Some(c) = &doc.calibration {
                return cx.err(c.span(), "calibration", "a [calibration] schedule cannot be combined with a route of [[waypoint]] tables");
            }
            let compiled = parse_route(&cx, &doc, nav.earth.model(), dt)?;
            for &w in &compiled.motion_waypoint {
                seg_of_motion.push(doc.waypoint.get(w).map_or(0..0, |x| x.span()));
            }
            motions = compiled.motions.clone();
            speed = compiled.start_speed_mps;
            euler.yaw_rad = compiled.start_heading_rad;
            start.speed_mps = speed;
            start.euler = euler;
            route_report = Some(compiled);
        }
        if let Some(sched) = &calibration {
            motions.push((Motion::Static, sched.duration_s));
            seg_of_motion.push(doc.calibration.as_ref().map_or(0..0, |c| c.span()));
        }
        if let Some((_, spans)) = &body {
            seg_of_motion = spans.clone();
        }
        if motions.is_empty() && body.is_none() {
            return Err(ScenarioError::Invalid {
                file: file.into(),
                line: 1,
                key: "segment".into(),
                message: "a scenario needs at least one [[segment]] (or a [calibration] table)"
                    .into(),
            });
        }
        let total: f64 = match &body {
            Some((b, _)) => b.duration_s,
            None => motions.iter().map(|m| m.1).sum(),
        };

        let mut overlays = Vec::new();
        let mut vib_list = Vec::new();
        let mut vib_reports = Vec::new();
        for (oi, o) in doc.overlay.iter().enumerate() {
            let od = o.get_ref();
            let kind = od.kind.get_ref().as_str();
            let rv_keys = [
                od.accel_psd_file.as_ref().map(|v| v.span()),
                od.gyro_psd_file.as_ref().map(|v| v.span()),
                od.accel_psd_breakpoints.as_ref().map(|v| v.span()),
                od.gyro_psd_breakpoints.as_ref().map(|v| v.span()),
                od.seed.as_ref().map(|v| v.span()),
            ];
            if kind != "random_vibration" {
                if let Some(span) = rv_keys.iter().flatten().next() {
                    return cx.err(
                        span.clone(),
                        "overlay",
                        format!("a PSD or seed key belongs to overlay type `random_vibration`, not `{kind}`"),
                    );
                }
            }
            let need_pos = |v: &Option<S<f64>>, key: &str| -> Result<f64, ScenarioError> {
                match v {
                    Some(v) => cx.positive(v, key),
                    None => cx.err(
                        o.span(),
                        key,
                        format!("missing required key for overlay type `{kind}`"),
                    ),
                }
            };
            let axis = |default: Axis| -> Result<Axis, ScenarioError> {
                match &od.axis {
                    None => Ok(default),
                    Some(a) => match a.get_ref().as_str() {
                        "x" => Ok(Axis::X),
                        "y" => Ok(Axis::Y),
                        "z" => Ok(Axis::Z),
                        other => cx.err(
                            a.span(),
                            "overlay.axis",
                            format!("unknown axis `{other}`: expected x, y or z"),
                        ),
                    },
                }
            };
            if kind == "rotation" {
                overlays.push(parse_rotation(&cx, o, total)?);
                continue;
            }
            if let Some(a) = &od.angle_deg {
                return cx.err(
                    a.span(),
                    "overlay.angle_deg",
                    format!("angle_deg belongs to overlay type `rotation`, not `{kind}`"),
                );
            }
            let (start_s, end_s) = overlay_window(&cx, od, total)?;
            if kind == "random_vibration" {
                let (rv, rep) = parse_random_vibration(
                    &cx,
                    o,
                    file,
                    rate_hz,
                    im.seed.unwrap_or(1),
                    end_s.min(total) - start_s,
                    oi as u64,
                )?;
                overlays.push(Overlay {
                    kind: OverlayKind::RandomVibration { id: vib_list.len() },
                    start_s,
                    end_s,
                });
                vib_list.push(rv);
                vib_reports.push(rep);
                continue;
            }
            let freq = need_pos(&od.freq_hz, "overlay.freq_hz")?;
            if freq > 0.5 * rate_hz {
                return cx.err(
                    o.span(),
                    "overlay.freq_hz",
                    format!(
                        "{freq} Hz is above the Nyquist frequency {} Hz of the IMU",
                        0.5 * rate_hz
                    ),
                );
            }
            let omega = 2.0 * std::f64::consts::PI * freq;
            let k = match kind {
                "coning" => {
                    let a = need_pos(&od.half_angle_deg, "overlay.half_angle_deg")?;
                    if a >= 90.0 {
                        return cx.err(
                            o.span(),
                            "overlay.half_angle_deg",
                            "half-angle must be below 90 deg",
                        );
                    }
                    OverlayKind::Coning {
                        axis: axis(Axis::Z)?,
                        half_angle_rad: a * D2R,
                        omega_rps: omega,
                    }
                }
                "sculling" => OverlayKind::Sculling {
                    angle_amp_rad: need_pos(&od.angle_amp_deg, "overlay.angle_amp_deg")? * D2R,
                    accel_amp_mps2: need_pos(&od.accel_amp_mps2, "overlay.accel_amp_mps2")?,
                    omega_rps: omega,
                },
                "vibration" => OverlayKind::Vibration {
                    axis: axis(Axis::Z)?,
                    accel_amp_mps2: need_pos(&od.accel_amp_mps2, "overlay.accel_amp_mps2")?,
                    omega_rps: omega,
                },
                "sway" => {
                    let a = need_pos(&od.angle_amp_deg, "overlay.angle_amp_deg")?;
                    if a >= 90.0 {
                        return cx.err(
                            o.span(),
                            "overlay.angle_amp_deg",
                            "sway amplitude must be below 90 deg",
                        );
                    }
                    let phase = match &od.phase_deg {
                        Some(v) => cx.range(
                            v,
                            "overlay.phase_deg",
                            -360.0,
                            360.0,
                            "a phase in degrees within ±360",
                        )?,
                        None => 0.0,
                    };
                    OverlayKind::Sway {
                        axis: axis(Axis::X)?,
                        amp_rad: a * D2R,
                        omega_rps: omega,
                        phase_rad: phase * D2R,
                    }
                }
                other => {
                    return cx.err(od.kind.span(), "overlay.type", format!("unknown overlay type `{other}`: expected coning, sculling, vibration, sway, random_vibration or rotation"));
                }
            };
            overlays.push(Overlay {
                kind: k,
                start_s,
                end_s,
            });
        }

        if let Some(sched) = &calibration {
            overlays.extend(sched.overlays());
        }
        let trajectory = match body {
            Some((b, _)) => Trajectory::from_body_motion(b, overlays),
            None => Trajectory::new(speed, -climb, euler, &motions, overlays),
        }
        .with_random_vibration(vib_list);
        let trajectory = match trajectory.with_vehicle(vehicle, nav.earth.model(), lat * D2R, h) {
            Ok(t) => t,
            Err(e) => {
                let i = match &e {
                    VehicleError::Joint { index, .. } | VehicleError::Vertical { index, .. } => {
                        *index
                    }
                };
                let span = seg_of_motion
                    .get(i.saturating_sub(1))
                    .cloned()
                    .unwrap_or(0..0);
                let which = doc
                    .segment
                    .iter()
                    .position(|d| d.span() == span)
                    .map_or(i, |p| p + 1);
                let what = match &route_report {
                    // a route's motion i belongs to a waypoint's turn or leg
                    Some(r) => format!(
                        "route motion {i} (the turn or leg of [[waypoint]] number {})",
                        r.motion_waypoint
                            .get(i.saturating_sub(1))
                            .map_or(0, |w| w + 1)
                    ),
                    None => format!("[[segment]] number {which}"),
                };
                let msg = e
                    .to_string()
                    .replacen(&format!("segment {i} (1-based)"), &what, 1);
                return cx.err(span, "segment", msg);
            }
        };
        if let Err(e) = crate::envelope::check_trajectory(
            &trajectory,
            crate::envelope::StartPosition {
                lat_rad: start.lat_rad,
                h_m: start.h_m,
            },
            dt,
            &crate::envelope::Envelope::DEFAULT,
        ) {
            // the trajectory's segment k comes from a [[segment]] (a coordinated turn
            // gives three)
            let span = match e.segment().and_then(|k| seg_of_motion.get(k)) {
                Some(span) => span.clone(),
                None => start_doc.span(),
            };
            return cx.err(span, "segment", e.to_string());
        }
        let mounting = parse_mounting(&cx, doc.mounting.as_ref())?;
        let mut nav = nav;
        if nav.substeps == 0 {
            nav.substeps = crate::truth::auto_substeps(dt, &trajectory);
        }
        // [gnss] section
        let gnss = match &doc.gnss {
            None => None,
            Some(g) => {
                let cfg = g.get_ref().clone();
                if let Err(crate::gnss::GnssConfigError::Invalid { key, what }) = cfg.validate() {
                    return cx.err(g.span(), &format!("gnss.{key}"), what);
                }
                Some(cfg)
            }
        };
        Ok(Scenario {
            name: doc.name.unwrap_or_else(|| {
                Path::new(file)
                    .file_stem()
                    .map_or_else(|| "scenario".into(), |s| s.to_string_lossy().into_owned())
            }),
            description: doc.description.unwrap_or_default(),
            start,
            imu,
            nav,
            trajectory,
            gnss,
            source_toml: text.to_string(),
            mounting,
            vibration: vib_reports,
            route: route_report,
        })
    }

    /// Read and validate a scenario file.
    pub fn from_file(path: &Path) -> Result<Scenario, ScenarioError> {
        let file = path.display().to_string();
        let bytes = crate::input::read_capped(path).map_err(|e| ScenarioError::Read {
            file: file.clone(),
            reason: e.to_string(),
        })?;
        let text = String::from_utf8(bytes).map_err(|e| ScenarioError::Read {
            file: file.clone(),
            reason: format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        })?;
        if crate::gnss_ins_sim::looks_like_motion_def(&text) {
            return Scenario::from_motion_def(&text, path, &Default::default());
        }
        Scenario::from_toml(&text, &file)
    }

    /// A gnss-ins-sim motion-definition file as a scenario
    /// ([`crate::gnss_ins_sim::to_scenario_toml`], then [`Scenario::from_toml`] on the result).
    pub fn from_motion_def(
        text: &str,
        path: &Path,
        opts: &crate::gnss_ins_sim::ImportOptions,
    ) -> Result<Scenario, ScenarioError> {
        use crate::gnss_ins_sim::{parse_motion_def, to_scenario_toml, GisError};
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
            other => ScenarioError::Read {
                file: file.clone(),
                reason: other.to_string(),
            },
        };
        let mf = parse_motion_def(text, &file).map_err(conv)?;
        let name = path
            .file_stem()
            .map_or_else(|| "imported".into(), |s| s.to_string_lossy().into_owned());
        let toml = to_scenario_toml(&mf, &name, &file, opts).map_err(conv)?;
        Scenario::from_toml(&toml, &file)
    }

    /// A built-in name or a file path.
    pub fn load(name_or_path: &str) -> Result<Scenario, ScenarioError> {
        if let Some(b) = builtin(name_or_path) {
            return Scenario::from_toml(b.toml, &format!("<built-in {}>", b.name));
        }
        let p = Path::new(name_or_path);
        if p.exists() {
            return Scenario::from_file(p);
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

/// `[[waypoint]]` and `[route]`: the route, compiled ([`crate::route::compile`]); its
/// errors located at the waypoint they name.
fn parse_route(
    cx: &Ctx<'_>,
    doc: &FileDoc,
    earth: EarthModel,
    dt: f64,
) -> Result<crate::route::CompiledRoute, ScenarioError> {
    use crate::route::{LegKind, Route, RouteError, RouteLimits, TurnLimit, Waypoint};
    let route_span = doc.route.as_ref().map_or(0..0, |r| r.span());
    if doc.waypoint.len() < 2 {
        let span = doc.waypoint.first().map_or(route_span, |w| w.span());
        return cx.err(
            span,
            "waypoint",
            format!(
                "a route needs at least two [[waypoint]] tables (got {})",
                doc.waypoint.len()
            ),
        );
    }
    let mut wps = Vec::with_capacity(doc.waypoint.len());
    for w in &doc.waypoint {
        let wd = w.get_ref();
        let lat = cx.range(
            &wd.lat_deg,
            "waypoint.lat_deg",
            -89.5,
            89.5,
            "latitude in [-89.5, 89.5] deg",
        )?;
        let lon = cx.range(
            &wd.lon_deg,
            "waypoint.lon_deg",
            -180.0,
            360.0,
            "longitude in [-180, 360] deg",
        )?;
        let h = match &wd.h_m {
            Some(v) => cx.range(
                v,
                "waypoint.h_m",
                -1000.0,
                100_000.0,
                "height in [-1000, 100000] m",
            )?,
            None => 0.0,
        };
        let v = cx.range(
            &wd.speed_mps,
            "waypoint.speed_mps",
            0.0,
            3000.0,
            "speed in (0, 3000] m/s",
        )?;
        if v <= 0.0 {
            return cx.err(
                wd.speed_mps.span(),
                "waypoint.speed_mps",
                "a route's speed must be > 0 (use hold_s for time at rest)",
            );
        }
        let hold = match &wd.hold_s {
            Some(x) => cx.range(
                x,
                "waypoint.hold_s",
                0.0,
                MAX_SEGMENT_S,
                "a time at rest in [0, 1e7] s",
            )?,
            None => 0.0,
        };
        wps.push(Waypoint {
            lat_rad: lat * D2R,
            lon_rad: lon * D2R,
            h_m: h,
            speed_mps: v,
            hold_s: hold,
        });
    }
    let mut limits = RouteLimits::default();
    let mut legs = LegKind::GreatCircle;
    if let Some(r) = &doc.route {
        let rd = r.get_ref();
        if let Some(l) = &rd.legs {
            legs = match l.get_ref().as_str() {
                "great_circle" => LegKind::GreatCircle,
                "rhumb" => LegKind::Rhumb,
                other => {
                    return cx.err(
                        l.span(),
                        "route.legs",
                        format!("unknown leg kind `{other}`: expected great_circle or rhumb"),
                    )
                }
            };
        }
        match (&rd.turn_rate_limit_dps, &rd.bank_limit_deg) {
            (Some(a), Some(_)) => {
                return cx.err(
                    a.span(),
                    "route.turn_rate_limit_dps",
                    "give either turn_rate_limit_dps or bank_limit_deg, not both",
                )
            }
            (Some(a), None) => {
                limits.turn = TurnLimit::Rate(
                    cx.range(
                        a,
                        "route.turn_rate_limit_dps",
                        1e-3,
                        360.0,
                        "a turn-rate limit in [0.001, 360] deg/s",
                    )? * D2R,
                )
            }
            (None, Some(b)) => {
                limits.turn = TurnLimit::Bank(
                    cx.range(
                        b,
                        "route.bank_limit_deg",
                        0.1,
                        80.0,
                        "a bank limit in [0.1, 80] deg",
                    )? * D2R,
                )
            }
            (None, None) => {}
        }
        if let Some(x) = &rd.roll_rate_limit_dps {
            limits.roll_rate_rps = cx.range(
                x,
                "route.roll_rate_limit_dps",
                0.01,
                360.0,
                "a roll-rate limit in [0.01, 360] deg/s",
            )? * D2R;
        }
        if let Some(x) = &rd.climb_rate_limit_mps {
            limits.climb_rate_mps = cx.range(
                x,
                "route.climb_rate_limit_mps",
                1e-3,
                500.0,
                "a climb-rate limit in [0.001, 500] m/s",
            )?;
        }
        if let Some(x) = &rd.accel_limit_mps2 {
            limits.accel_mps2 = cx.range(
                x,
                "route.accel_limit_mps2",
                1e-3,
                100.0,
                "an acceleration limit in [0.001, 100] m/s²",
            )?;
        }
    }
    let route = Route {
        waypoints: wps,
        legs,
        limits,
    };
    crate::route::compile(&route, earth, dt).map_err(|e| {
        let wp = match &e {
            RouteError::Value { waypoint, .. }
            | RouteError::Coincident { waypoint, .. }
            | RouteError::Pole { waypoint, .. }
            | RouteError::TooShort { waypoint, .. }
            | RouteError::Turn { waypoint, .. }
            | RouteError::Solve { waypoint, .. } => Some(*waypoint),
            _ => None,
        };
        let span = match wp.and_then(|i| doc.waypoint.get(i.saturating_sub(1))) {
            Some(w) => w.span(),
            None => route_span.clone(),
        };
        let key = if wp.is_some() { "waypoint" } else { "route" };
        ScenarioError::Invalid {
            file: cx.file.to_string(),
            line: cx.line_of(span.start),
            key: key.to_string(),
            message: format!("[[waypoint]] route: {e}"),
        }
    })
}

/// `[calibration]`: a standard turntable schedule (crate::calibration::schedule) in
/// place of `[[segment]]` and `[[overlay]]`, at rest (zero speed and climb rate, free
/// vehicle).
fn parse_calibration(
    cx: &Ctx<'_>,
    doc: &FileDoc,
    speed: f64,
    climb: f64,
    vehicle: Vehicle,
    dt: f64,
) -> Result<Option<crate::calibration::Schedule>, ScenarioError> {
    use crate::calibration::schedule::{
        Schedule, ScheduleError, Standard, DEFAULT_DWELL_S, DEFAULT_ROTATION_S,
    };
    let Some(c) = &doc.calibration else {
        return Ok(None);
    };
    let span = c.span();
    if let Some(s) = doc.segment.first() {
        return cx.err(s.span(), "segment", "a [calibration] scenario builds its own static segment and rotations: remove the [[segment]] tables");
    }
    if let Some(o) = doc.overlay.first() {
        return cx.err(
            o.span(),
            "overlay",
            "a [calibration] scenario builds its own rotations: remove the [[overlay]] tables",
        );
    }
    if speed != 0.0 || climb != 0.0 || vehicle != Vehicle::Free {
        return cx.err(span, "calibration", "a calibration schedule is at rest on the table: start.speed_mps and start.climb_rate_mps must be 0 and vehicle left out");
    }
    let cd = c.get_ref();
    let Some(kind) = Standard::from_name(cd.schedule.get_ref()) else {
        return cx.err(
            cd.schedule.span(),
            "calibration.schedule",
            format!(
                "unknown schedule `{}`: expected 6-position or 12-position",
                cd.schedule.get_ref()
            ),
        );
    };
    let dwell = match &cd.dwell_s {
        Some(v) => cx.positive(v, "calibration.dwell_s")?,
        None => DEFAULT_DWELL_S,
    };
    let rot = match &cd.rotation_s {
        Some(v) => cx.positive(v, "calibration.rotation_s")?,
        None => DEFAULT_ROTATION_S,
    };
    if dwell > MAX_SEGMENT_S / 16.0 || rot > MAX_SEGMENT_S / 16.0 {
        return cx.err(
            span,
            "calibration",
            format!(
                "dwell_s and rotation_s must be at most {:e} s",
                MAX_SEGMENT_S / 16.0
            ),
        );
    }
    match Schedule::standard(kind, dwell, rot, dt) {
        Ok(s) => Ok(Some(s)),
        Err(ScheduleError::Duration { key, what }) => {
            let v = if key == "dwell_s" {
                &cd.dwell_s
            } else {
                &cd.rotation_s
            };
            cx.err(
                v.as_ref().map_or(span, |v| v.span()),
                &format!("calibration.{key}"),
                what,
            )
        }
        Err(e) => cx.err(span, "calibration", e.to_string()),
    }
}

/// `[[overlay]] type = "rotation"`: `axis`, `angle_deg`, `start_s` and `end_s` required,
/// no `freq_hz` (the raised-cosine rate follows from the angle and the window).
fn parse_rotation(cx: &Ctx<'_>, o: &S<OverlayDoc>, total: f64) -> Result<Overlay, ScenarioError> {
    let od = o.get_ref();
    for (k, present) in [
        ("freq_hz", od.freq_hz.is_some()),
        ("half_angle_deg", od.half_angle_deg.is_some()),
        ("angle_amp_deg", od.angle_amp_deg.is_some()),
        ("accel_amp_mps2", od.accel_amp_mps2.is_some()),
        ("phase_deg", od.phase_deg.is_some()),
    ] {
        if present {
            return cx.err(
                o.span(),
                &format!("overlay.{k}"),
                "not a key of overlay type `rotation` (its keys: axis, angle_deg, start_s, end_s)",
            );
        }
    }
    let axis = match &od.axis {
        None => {
            return cx.err(
                o.span(),
                "overlay.axis",
                "missing required key for overlay type `rotation`",
            )
        }
        Some(a) => match a.get_ref().as_str() {
            "x" => Axis::X,
            "y" => Axis::Y,
            "z" => Axis::Z,
            other => {
                return cx.err(
                    a.span(),
                    "overlay.axis",
                    format!("unknown axis `{other}`: expected x, y or z"),
                )
            }
        },
    };
    let Some(a) = &od.angle_deg else {
        return cx.err(
            o.span(),
            "overlay.angle_deg",
            "missing required key for overlay type `rotation`",
        );
    };
    let angle = cx.range(
        a,
        "overlay.angle_deg",
        -3600.0,
        3600.0,
        "an angle within ±3600 deg",
    )?;
    if angle == 0.0 {
        return cx.err(
            a.span(),
            "overlay.angle_deg",
            "a rotation needs a non-zero angle",
        );
    }
    let (Some(s0), Some(s1)) = (&od.start_s, &od.end_s) else {
        return cx.err(
            o.span(),
            "overlay.end_s",
            "overlay type `rotation` needs both start_s and end_s",
        );
    };
    let start_s = cx.range(
        s0,
        "overlay.start_s",
        0.0,
        total,
        "a time within the scenario",
    )?;
    let end_s = cx.range(
        s1,
        "overlay.end_s",
        start_s,
        total,
        "a time after start_s within the scenario",
    )?;
    if end_s <= start_s {
        return cx.err(
            s1.span(),
            "overlay.end_s",
            "a rotation needs end_s > start_s",
        );
    }
    Ok(OverlayKind::rotation(axis, angle * D2R, start_s, end_s))
}

/// `start_s`/`end_s` of an overlay (defaults 0 and ∞).
fn overlay_window(cx: &Ctx<'_>, od: &OverlayDoc, total: f64) -> Result<(f64, f64), ScenarioError> {
    let start_s = match &od.start_s {
        Some(v) => cx.range(
            v,
            "overlay.start_s",
            0.0,
            total,
            "a time within the scenario",
        )?,
        None => 0.0,
    };
    let end_s = match &od.end_s {
        Some(v) => cx.range(
            v,
            "overlay.end_s",
            start_s,
            f64::INFINITY,
            "a time after start_s",
        )?,
        None => f64::INFINITY,
    };
    Ok((start_s, end_s))
}

/// A `random_vibration` overlay: its PSD tables (files relative to the scenario file),
/// realised over its window ([`crate::random_vibration`]).
fn parse_random_vibration(
    cx: &Ctx<'_>,
    o: &S<OverlayDoc>,
    file: &str,
    rate_hz: f64,
    imu_seed: u64,
    window_s: f64,
    index: u64,
) -> Result<
    (
        crate::random_vibration::RandomVibration,
        crate::random_vibration::VibrationReport,
    ),
    ScenarioError,
> {
    use crate::random_vibration::{PsdTable, RandomVibration, RandomVibrationSpec};
    let od = o.get_ref();
    for (k, v) in [
        ("overlay.axis", od.axis.as_ref().map(|v| v.span())),
        ("overlay.freq_hz", od.freq_hz.as_ref().map(|v| v.span())),
        (
            "overlay.half_angle_deg",
            od.half_angle_deg.as_ref().map(|v| v.span()),
        ),
        (
            "overlay.angle_amp_deg",
            od.angle_amp_deg.as_ref().map(|v| v.span()),
        ),
        (
            "overlay.accel_amp_mps2",
            od.accel_amp_mps2.as_ref().map(|v| v.span()),
        ),
        ("overlay.phase_deg", od.phase_deg.as_ref().map(|v| v.span())),
    ] {
        if let Some(span) = v {
            return cx.err(
                span,
                k,
                "not a key of overlay type `random_vibration` (its spectrum comes from the PSD keys)",
            );
        }
    }
    let base = Path::new(file).parent().unwrap_or(Path::new(""));
    let table = |path: &Option<S<String>>,
                 bp: &Option<S<Vec<Vec<f64>>>>,
                 what: &str|
     -> Result<Option<PsdTable>, ScenarioError> {
        let fkey = format!("overlay.{what}_psd_file");
        let bkey = format!("overlay.{what}_psd_breakpoints");
        match (path, bp) {
            (Some(p), Some(_)) => cx.err(
                p.span(),
                &fkey,
                format!("give either {fkey} or {bkey}, not both"),
            ),
            (Some(p), None) => {
                let full = base.join(p.get_ref());
                PsdTable::read_csv(&full)
                    .map(Some)
                    .or_else(|e| cx.err(p.span(), &fkey, e.to_string()))
            }
            (None, Some(b)) => PsdTable::from_breakpoints(b.get_ref(), &bkey)
                .map(Some)
                .or_else(|e| {
                    let msg = match e {
                        crate::random_vibration::PsdError::Invalid {
                            line,
                            column,
                            message,
                            ..
                        } => format!("breakpoint {line}, entry {column}: {message}"),
                        other => other.to_string(),
                    };
                    cx.err(b.span(), &bkey, msg)
                }),
            (None, None) => Ok(None),
        }
    };
    let accel = table(&od.accel_psd_file, &od.accel_psd_breakpoints, "accel")?;
    let gyro = table(&od.gyro_psd_file, &od.gyro_psd_breakpoints, "gyro")?;
    if accel.is_none() && gyro.is_none() {
        return cx.err(
            o.span(),
            "overlay",
            "a random_vibration overlay needs accel_psd_file, accel_psd_breakpoints, gyro_psd_file or gyro_psd_breakpoints",
        );
    }
    let spec = RandomVibrationSpec {
        accel,
        gyro,
        seed: od.seed.as_ref().map_or(imu_seed, |s| *s.get_ref()),
    };
    RandomVibration::realise(&spec, window_s, 0.5 * rate_hz, index)
        .or_else(|m| cx.err(o.span(), "overlay", m))
}

fn parse_mounting(cx: &Ctx<'_>, m: Option<&S<MountingDoc>>) -> Result<Mounting, ScenarioError> {
    let Some(m) = m else {
        return Ok(Mounting::default());
    };
    let vec3 = |v: &Option<S<Vec<f64>>>, key: &str, lim: f64, unit: &str| {
        let Some(v) = v else {
            return Ok(None);
        };
        let x = v.get_ref();
        if x.len() != 3 || x.iter().any(|c| !c.is_finite() || c.abs() > lim) {
            return cx.err(
                v.span(),
                key,
                format!("expected three finite numbers [x, y, z] within ±{lim} {unit}, got {x:?}"),
            );
        }
        Ok(Some(sdins_core::math::Vec3::new(x[0], x[1], x[2])))
    };
    let m = m.get_ref();
    let arm = vec3(&m.imu_lever_arm_m, "mounting.imu_lever_arm_m", 100.0, "m")?;
    let ang = vec3(&m.imu_mount_deg, "mounting.imu_mount_deg", 180.0, "deg")?;
    let gnss = vec3(&m.gnss_lever_arm_m, "mounting.gnss_lever_arm_m", 100.0, "m")?;
    let imu = if arm.is_some() || ang.is_some() {
        let a = ang.unwrap_or_default() * D2R;
        Some(crate::truth::ImuMount::new(
            arm.unwrap_or_default(),
            Euler::new(a.x, a.y, a.z),
        ))
    } else {
        None
    };
    Ok(Mounting {
        imu,
        gnss_lever_arm_b_m: gnss,
    })
}

fn parse_vehicle(cx: &Ctx<'_>, doc: &FileDoc) -> Result<Vehicle, ScenarioError> {
    let alpha = match &doc.angle_of_attack_deg {
        Some(a) => Some((
            cx.range(
                a,
                "angle_of_attack_deg",
                -30.0,
                30.0,
                "an angle of attack in [-30, 30] deg",
            )? * D2R,
            a.span(),
        )),
        None => None,
    };
    let v = match doc
        .vehicle
        .as_ref()
        .map(|v| (v.get_ref().as_str(), v.span()))
    {
        None | Some(("free", _)) => Vehicle::Free,
        Some(("car", _)) => Vehicle::Car,
        Some(("aircraft", _)) => Vehicle::Aircraft {
            angle_of_attack_rad: alpha.as_ref().map_or(0.0, |a| a.0),
        },
        Some((other, span)) => {
            return cx.err(
                span,
                "vehicle",
                format!("unknown vehicle `{other}`: expected free, aircraft or car"),
            );
        }
    };
    if let (Some((_, span)), false) = (alpha, matches!(v, Vehicle::Aircraft { .. })) {
        return cx.err(
            span,
            "angle_of_attack_deg",
            "only an aircraft has an angle of attack (set vehicle = \"aircraft\")",
        );
    }
    Ok(v)
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

fn parse_nav(cx: &Ctx<'_>, nav: Option<&NavDoc>) -> Result<NavConfig, ScenarioError> {
    let mut cfg = NavConfig::default();
    let Some(n) = nav else { return Ok(cfg) };
    if let Some(s) = &n.samples {
        let v = *s.get_ref();
        if !(1..=4).contains(&v) {
            return cx.err(
                s.span(),
                "nav.samples",
                format!("{v}: expected 1, 2, 3 or 4 samples per update"),
            );
        }
        cfg.samples = v as usize;
    }
    if let Some(s) = &n.substeps {
        let v = *s.get_ref();
        if !(1..=1024).contains(&v) {
            return cx.err(s.span(), "nav.substeps", format!("{v}: expected 1..=1024"));
        }
        cfg.substeps = v as usize;
    }
    if let Some(a) = &n.algos {
        for name in a.get_ref() {
            if sdins_core::nav::AlgorithmKind::from_name(name).is_none() {
                let names: Vec<&str> = sdins_core::nav::AlgorithmKind::ALL
                    .iter()
                    .map(|k| k.name())
                    .collect();
                let hint = suggest_from(name, &names)
                    .map(|s| format!(" (did you mean `{s}`?)"))
                    .unwrap_or_default();
                return cx.err(
                    a.span(),
                    "nav.algos",
                    format!(
                        "unknown algorithm `{name}`{hint}: expected {}",
                        names.join(", ")
                    ),
                );
            }
        }
        cfg.algos = a.get_ref().clone();
    }
    if let Some(c) = &n.coning {
        let name = c.get_ref();
        match sdins_core::coning::ConingSet::parse(name, cfg.samples) {
            Some(set) if set.accepts(cfg.samples) => {}
            Some(set) => {
                return cx.err(
                    c.span(),
                    "nav.coning",
                    format!(
                        "`{name}` is the set for {} samples per update, but nav.samples is {}",
                        set.samples(),
                        cfg.samples
                    ),
                )
            }
            None => {
                return cx.err(
                    c.span(),
                    "nav.coning",
                    format!("unknown coning set `{name}`: expected none, 1prev, two, three_poly, three_opt, four_poly, four_opt, polynomial or optimal"),
                )
            }
        }
        cfg.coning = Some(name.clone());
    }
    if let Some(e) = &n.earth {
        cfg.earth = match e.get_ref().as_str() {
            "wgs84" => EarthChoice::Wgs84,
            "psins" => EarthChoice::Psins,
            "flat" => EarthChoice::Flat,
            other => {
                return cx.err(
                    e.span(),
                    "nav.earth",
                    format!("unknown earth model `{other}`: expected wgs84, psins or flat"),
                )
            }
        };
    }
    if let Some(v) = &n.vertical {
        cfg.vertical_hold = match v.get_ref().as_str() {
            "free" => false,
            "hold" => true,
            other => {
                return cx.err(
                    v.span(),
                    "nav.vertical",
                    format!("unknown vertical mode `{other}`: expected free or hold"),
                )
            }
        };
    }
    Ok(cfg)
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
    Builtin { name: "stationary", summary: "A0: stationary 90 min at 37.5N 127E", toml: include_str!("../scenarios/stationary.toml") },
    Builtin { name: "mach1-east", summary: "A1: Mach 1 due east, 90 min (Song-Lee Table 1)", toml: include_str!("../scenarios/mach1-east.toml") },
    Builtin { name: "turn-90dps", summary: "A2: 90 deg/s turn from east to south at Mach 1", toml: include_str!("../scenarios/turn-90dps.toml") },
    Builtin { name: "dq-paper", summary: "B: stationary, accelerate, S-turn with 1 Hz coning (dual-quaternion paper)", toml: include_str!("../scenarios/dq-paper.toml") },
    Builtin { name: "alignment", summary: "stationary alignment reference: roll/pitch/yaw 2/-3/40 deg at 37.5N", toml: include_str!("../scenarios/alignment.toml") },
    Builtin { name: "moored-ship", summary: "disturbed base: moored ship at 40N, roll/pitch sway ±5 deg, 0.5 m heave, 0.2 m surge, marine grade", toml: include_str!("../scenarios/moored-ship.toml") },
    Builtin { name: "rocking-car", summary: "disturbed base: parked car rocking ±0.8/0.5 deg at 1.373/1.827 Hz with 1 cm heave, aviation grade", toml: include_str!("../scenarios/rocking-car.toml") },
    Builtin { name: "calibration", summary: "12-position turntable calibration: 300 s dwells, 10 s rotations, tactical grade, 100 Hz (sdins calibrate)", toml: include_str!("../scenarios/calibration.toml") },
    Builtin { name: "route-demo", summary: "route through 4 waypoints at 45N 10E: two fly-by turns, 50 to 60 m/s, 200 m climb, geodesic legs (230 s, 100 Hz)", toml: include_str!("../scenarios/route-demo.toml") },
];

/// Look up a built-in scenario by name.
pub fn builtin(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

/// The compiled `[[command]]` motion and each command's span.
type CompiledCommands = (crate::body_motion::BodyMotion, Vec<std::ops::Range<usize>>);
/// The six channel keys of a command, with their values.
type ChannelKeys<'a> = [(&'a Option<S<f64>>, &'static str); 6];

/// `[[command]]` and `[body_motion]`: gnss-ins-sim motion commands on the "Euler angles +
/// body velocity" base ([`crate::body_motion`]), in place of `[[segment]]`; free vehicle,
/// start attitude from `[start]`, start body velocity from `[body_motion]`. Returns the
/// compiled motion and the span of each command.
fn parse_body_motion(
    cx: &Ctx<'_>,
    doc: &FileDoc,
    st: &StartDoc,
    euler: Euler,
    vehicle: Vehicle,
    dt: f64,
) -> Result<Option<CompiledCommands>, ScenarioError> {
    use crate::body_motion::{BodyCommand, BodyMotion, BodyStart, CommandKind, MotionLimits};
    if doc.command.is_empty() {
        if let Some(b) = &doc.body_motion {
            return cx.err(
                b.span(),
                "body_motion",
                "[body_motion] goes with [[command]] tables: add commands or remove it",
            );
        }
        return Ok(None);
    }
    let first = doc.command[0].span();
    if let Some(s) = doc.segment.first() {
        return cx.err(
            s.span(),
            "segment",
            "[[command]] tables replace [[segment]]: use one or the other",
        );
    }
    if let Some(c) = &doc.calibration {
        return cx.err(
            c.span(),
            "calibration",
            "[[command]] tables and [calibration] exclude each other",
        );
    }
    if vehicle != Vehicle::Free {
        return cx.err(
            first,
            "vehicle",
            "[[command]] motion sets the body velocity directly: it needs vehicle = \"free\"",
        );
    }
    if let Some(w) = doc.waypoint.first() {
        return cx.err(
            w.span(),
            "waypoint",
            "[[command]] tables and [[waypoint]] routes exclude each other: use one or the other",
        );
    }
    for (v, key) in [
        (&st.speed_mps, "start.speed_mps"),
        (&st.climb_rate_mps, "start.climb_rate_mps"),
    ] {
        if let Some(v) = v {
            return cx.err(
                v.span(),
                key,
                "with [[command]] tables the start velocity is [body_motion] vx_mps, vy_mps, vz_mps: leave this key out",
            );
        }
    }
    let bm = doc.body_motion.as_ref().map(|b| b.get_ref());
    let opt = |v: Option<&S<f64>>, key: &str, lim: f64, def: f64| -> Result<f64, ScenarioError> {
        match v {
            Some(v) => cx.range(v, key, -lim, lim, &format!("a value in [-{lim}, {lim}]")),
            None => Ok(def),
        }
    };
    let pos = |v: Option<&S<f64>>, key: &str, def: f64| -> Result<f64, ScenarioError> {
        match v {
            Some(v) => cx.positive(v, key),
            None => Ok(def),
        }
    };
    let vel_b = [
        opt(
            bm.and_then(|b| b.vx_mps.as_ref()),
            "body_motion.vx_mps",
            3000.0,
            0.0,
        )?,
        opt(
            bm.and_then(|b| b.vy_mps.as_ref()),
            "body_motion.vy_mps",
            3000.0,
            0.0,
        )?,
        opt(
            bm.and_then(|b| b.vz_mps.as_ref()),
            "body_motion.vz_mps",
            3000.0,
            0.0,
        )?,
    ];
    let d = MotionLimits::DEFAULT.to_mode();
    let limits = MotionLimits::from_mode([
        pos(
            bm.and_then(|b| b.max_accel_mps2.as_ref()),
            "body_motion.max_accel_mps2",
            d[0],
        )?,
        pos(
            bm.and_then(|b| b.max_angular_accel_dps2.as_ref()),
            "body_motion.max_angular_accel_dps2",
            d[1],
        )?,
        pos(
            bm.and_then(|b| b.max_angular_rate_dps.as_ref()),
            "body_motion.max_angular_rate_dps",
            d[2],
        )?,
    ]);
    let mut commands = Vec::with_capacity(doc.command.len());
    let mut spans = Vec::with_capacity(doc.command.len());
    for c in &doc.command {
        let cd = c.get_ref();
        let Some(kind) = CommandKind::from_number(*cd.kind.get_ref()) else {
            return cx.err(
                cd.kind.span(),
                "command.type",
                format!(
                    "{} is not a command type: expected 1, 2, 3, 4 or 5",
                    cd.kind.get_ref()
                ),
            );
        };
        let rates = kind == CommandKind::Rates;
        let (given, other): (ChannelKeys<'_>, ChannelKeys<'_>) = {
            let a = [
                (&cd.yaw_deg, "yaw_deg"),
                (&cd.pitch_deg, "pitch_deg"),
                (&cd.roll_deg, "roll_deg"),
                (&cd.vx_mps, "vx_mps"),
                (&cd.vy_mps, "vy_mps"),
                (&cd.vz_mps, "vz_mps"),
            ];
            let r = [
                (&cd.yaw_rate_dps, "yaw_rate_dps"),
                (&cd.pitch_rate_dps, "pitch_rate_dps"),
                (&cd.roll_rate_dps, "roll_rate_dps"),
                (&cd.ax_mps2, "ax_mps2"),
                (&cd.ay_mps2, "ay_mps2"),
                (&cd.az_mps2, "az_mps2"),
            ];
            if rates {
                (r, a)
            } else {
                (a, r)
            }
        };
        for (v, k) in other {
            if let Some(v) = v {
                let takes = given.map(|g| g.1).join(", ");
                return cx.err(
                    v.span(),
                    &format!("command.{k}"),
                    format!(
                        "not a key of command type {} (it takes: {takes}, duration_s)",
                        kind.number()
                    ),
                );
            }
        }
        let mut x = [0.0; 6];
        for (i, (v, k)) in given.iter().enumerate() {
            if let Some(v) = v {
                x[i] = cx.range(v, &format!("command.{k}"), -1e6, 1e6, "a value within ±1e6")?;
            }
        }
        let dur = cx.positive(&cd.duration_s, "command.duration_s")?;
        if dur > MAX_SEGMENT_S {
            return cx.err(
                cd.duration_s.span(),
                "command.duration_s",
                format!("{dur} s is too long: expected at most {MAX_SEGMENT_S:e} s"),
            );
        }
        let n = dur / dt;
        if n.round() < 1.0 || (n - n.round()).abs() > 1e-6 * n.max(1.0) {
            return cx.err(
                cd.duration_s.span(),
                "command.duration_s",
                format!("{dur} s is not a whole number of IMU samples ({dt} s) (command boundaries must fall on sample boundaries)"),
            );
        }
        commands.push(BodyCommand {
            kind,
            euler_ypr: [x[0] * D2R, x[1] * D2R, x[2] * D2R],
            vel_b: [x[3], x[4], x[5]],
            duration_s: n.round() * dt,
        });
        spans.push(c.span());
    }
    let start = BodyStart {
        euler_ypr: [euler.yaw_rad, euler.pitch_rad, euler.roll_rad],
        vel_b,
    };
    Ok(Some((
        BodyMotion::compile(start, &commands, limits, dt),
        spans,
    )))
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
