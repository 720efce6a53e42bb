//! The scenario file as deserialised (every value spanned, for located errors), before
//! validation.

use super::*;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BodyMotionDoc {
    pub(super) vx_mps: Option<S<f64>>,
    pub(super) vy_mps: Option<S<f64>>,
    pub(super) vz_mps: Option<S<f64>>,
    pub(super) max_accel_mps2: Option<S<f64>>,
    pub(super) max_angular_accel_dps2: Option<S<f64>>,
    pub(super) max_angular_rate_dps: Option<S<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CommandDoc {
    #[serde(rename = "type")]
    pub(super) kind: S<i64>,
    pub(super) yaw_deg: Option<S<f64>>,
    pub(super) pitch_deg: Option<S<f64>>,
    pub(super) roll_deg: Option<S<f64>>,
    pub(super) vx_mps: Option<S<f64>>,
    pub(super) vy_mps: Option<S<f64>>,
    pub(super) vz_mps: Option<S<f64>>,
    pub(super) yaw_rate_dps: Option<S<f64>>,
    pub(super) pitch_rate_dps: Option<S<f64>>,
    pub(super) roll_rate_dps: Option<S<f64>>,
    pub(super) ax_mps2: Option<S<f64>>,
    pub(super) ay_mps2: Option<S<f64>>,
    pub(super) az_mps2: Option<S<f64>>,
    pub(super) duration_s: S<f64>,
}

pub(super) type S<T> = Spanned<T>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileDoc {
    pub(super) name: Option<String>,
    pub(super) description: Option<String>,
    pub(super) start: Option<S<StartDoc>>,
    pub(super) imu: S<ImuDoc>,
    pub(super) nav: Option<NavDoc>,
    #[serde(default)]
    pub(super) segment: Vec<S<SegmentDoc>>,
    #[serde(default)]
    pub(super) overlay: Vec<S<OverlayDoc>>,
    pub(super) vehicle: Option<S<String>>,
    pub(super) angle_of_attack_deg: Option<S<f64>>,
    pub(super) mounting: Option<S<MountingDoc>>,
    // [gnss] section
    pub(super) gnss: Option<S<crate::sensors::gnss::GnssConfig>>,
    // aiding-sensor tables
    pub(super) baro: Option<S<crate::sensors::aiding::BaroConfig>>,
    pub(super) odometer: Option<S<crate::sensors::aiding::OdometerConfig>>,
    pub(super) magnetometer: Option<S<crate::sensors::aiding::MagnetometerConfig>>,
    pub(super) dual_antenna: Option<S<crate::sensors::aiding::DualAntennaConfig>>,
    pub(super) body_velocity: Option<S<crate::sensors::aiding::BodyVelocityConfig>>,
    pub(super) raw_gnss: Option<S<crate::sensors::raw_gnss::RawGnssTable>>,
    pub(super) calibration: Option<S<CalibrationDoc>>,
    pub(super) body_motion: Option<S<BodyMotionDoc>>,
    #[serde(default)]
    pub(super) command: Vec<S<CommandDoc>>,
    #[serde(default)]
    pub(super) waypoint: Vec<S<WaypointDoc>>,
    pub(super) route: Option<S<RouteDoc>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct WaypointDoc {
    pub(super) lat_deg: S<f64>,
    pub(super) lon_deg: S<f64>,
    pub(super) h_m: Option<S<f64>>,
    pub(super) speed_mps: S<f64>,
    pub(super) hold_s: Option<S<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RouteDoc {
    pub(super) legs: Option<S<String>>,
    pub(super) turn_rate_limit_dps: Option<S<f64>>,
    pub(super) bank_limit_deg: Option<S<f64>>,
    pub(super) roll_rate_limit_dps: Option<S<f64>>,
    pub(super) climb_rate_limit_mps: Option<S<f64>>,
    pub(super) accel_limit_mps2: Option<S<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CalibrationDoc {
    pub(super) schedule: S<String>,
    pub(super) dwell_s: Option<S<f64>>,
    pub(super) rotation_s: Option<S<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MountingDoc {
    pub(super) imu_lever_arm_m: Option<S<Vec<f64>>>,
    pub(super) imu_mount_deg: Option<S<Vec<f64>>>,
    pub(super) gnss_lever_arm_m: Option<S<Vec<f64>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct StartDoc {
    pub(super) lat_deg: S<f64>,
    pub(super) lon_deg: S<f64>,
    pub(super) h_m: Option<S<f64>>,
    pub(super) speed_mps: Option<S<f64>>,
    pub(super) climb_rate_mps: Option<S<f64>>,
    pub(super) roll_deg: Option<S<f64>>,
    pub(super) pitch_deg: Option<S<f64>>,
    pub(super) yaw_deg: Option<S<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ImuDoc {
    pub(super) rate_hz: S<f64>,
    pub(super) seed: Option<u64>,
    pub(super) grade: Option<S<String>>,
    pub(super) errors: Option<toml::Table>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct NavDoc {
    pub(super) samples: Option<S<i64>>,
    pub(super) algos: Option<S<Vec<String>>>,
    pub(super) coning: Option<S<String>>,
    pub(super) earth: Option<S<String>>,
    pub(super) vertical: Option<S<String>>,
    pub(super) substeps: Option<S<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SegmentDoc {
    #[serde(rename = "type")]
    pub(super) kind: S<String>,
    pub(super) duration_s: Option<S<f64>>,
    pub(super) accel_mps2: Option<S<f64>>,
    pub(super) rate_dps: Option<S<f64>>,
    pub(super) angle_deg: Option<S<f64>>,
    pub(super) profile: Option<S<String>>,
    pub(super) amplitude_dps: Option<S<f64>>,
    pub(super) to_climb_rate_mps: Option<S<f64>>,
    pub(super) bank_deg: Option<S<f64>>,
    pub(super) roll_rate_dps: Option<S<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct OverlayDoc {
    #[serde(rename = "type")]
    pub(super) kind: S<String>,
    pub(super) axis: Option<S<String>>,
    pub(super) half_angle_deg: Option<S<f64>>,
    pub(super) freq_hz: Option<S<f64>>,
    pub(super) angle_amp_deg: Option<S<f64>>,
    pub(super) accel_amp_mps2: Option<S<f64>>,
    pub(super) phase_deg: Option<S<f64>>,
    pub(super) angle_deg: Option<S<f64>>,
    pub(super) start_s: Option<S<f64>>,
    pub(super) end_s: Option<S<f64>>,
    pub(super) accel_psd_file: Option<S<String>>,
    pub(super) gyro_psd_file: Option<S<String>>,
    pub(super) accel_psd_breakpoints: Option<S<Vec<Vec<f64>>>>,
    pub(super) gyro_psd_breakpoints: Option<S<Vec<Vec<f64>>>>,
    pub(super) seed: Option<S<u64>>,
}
