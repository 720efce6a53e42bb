//! Sensor-grade values used by the error analysis (spec §4.5).
//!
//! This is a small, self-contained copy of the spec §4.5 table so that the error analysis
//! does not depend on the IMU-error presets of issue 4. Sources, per column:
//! * `p2_*`: the grade boxes of \[P2\] Table 1 (spec §4.4/§4.5);
//! * `typical_*`: Groves Tables 4.1/4.2 "as commonly quoted" (spec §4.5; quoted there from
//!   memory of the 2nd edition; the lower end of each quoted range is used);
//! * noise: **bold** spec values (aviation, tactical, consumer) are the presets of Groves'
//!   public companion code; marine and intermediate noise values are the spec's
//!   *engineering interpolations* (`noise_interpolated = true`).

use super::{DEG_PER_SQRT_HOUR, MICRO_G_PER_SQRT_HZ};
use serde::Serialize;

/// One sensor grade.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Grade {
    /// grade name (lower case, as accepted by the CLI)
    pub name: &'static str,
    /// \[P2\] accelerometer-bias box \[μg\] (min, max); `None` if \[P2\] gives none
    pub p2_accel_bias_ug: Option<(f64, f64)>,
    /// \[P2\] gyro-bias box [°/h] (min, max)
    pub p2_gyro_bias_dph: Option<(f64, f64)>,
    /// \[P2\]'s reported Schuler share [%] (min, max)
    pub p2_share_pct: Option<(f64, f64)>,
    /// typical accelerometer bias \[μg\] (Groves, lower end of the quoted range)
    pub typical_accel_bias_ug: f64,
    /// typical gyro bias [°/h]
    pub typical_gyro_bias_dph: f64,
    /// velocity random walk [μg/√Hz]
    pub vrw_ug_per_sqrt_hz: f64,
    /// angle random walk [°/√h]
    pub arw_deg_per_sqrt_h: f64,
    /// true when the noise values are the spec's engineering interpolation
    pub noise_interpolated: bool,
}

impl Grade {
    /// VRW in m/s/√s.
    pub fn vrw_si(&self) -> f64 {
        self.vrw_ug_per_sqrt_hz * MICRO_G_PER_SQRT_HZ
    }
    /// ARW in rad/√s.
    pub fn arw_si(&self) -> f64 {
        self.arw_deg_per_sqrt_h * DEG_PER_SQRT_HOUR
    }
}

/// The grades of spec §4.5, best first.
pub const GRADES: [Grade; 5] = [
    Grade {
        name: "marine",
        p2_accel_bias_ug: Some((20.0, 30.0)),
        p2_gyro_bias_dph: Some((0.0035, 0.01)),
        p2_share_pct: Some((17.5, 33.9)),
        typical_accel_bias_ug: 10.0,
        typical_gyro_bias_dph: 0.001,
        vrw_ug_per_sqrt_hz: 10.0,
        arw_deg_per_sqrt_h: 0.001,
        noise_interpolated: true,
    },
    Grade {
        name: "aviation",
        p2_accel_bias_ug: Some((30.0, 100.0)),
        p2_gyro_bias_dph: Some((0.01, 0.1)),
        p2_share_pct: Some((13.0, 21.2)),
        typical_accel_bias_ug: 30.0,
        typical_gyro_bias_dph: 0.01,
        vrw_ug_per_sqrt_hz: 20.0,
        arw_deg_per_sqrt_h: 0.002,
        noise_interpolated: false,
    },
    Grade {
        name: "intermediate",
        p2_accel_bias_ug: Some((100.0, 150.0)),
        p2_gyro_bias_dph: Some((0.1, 0.5)),
        p2_share_pct: Some((12.8, 16.2)),
        typical_accel_bias_ug: 100.0,
        typical_gyro_bias_dph: 0.1,
        vrw_ug_per_sqrt_hz: 50.0,
        arw_deg_per_sqrt_h: 0.005,
        noise_interpolated: true,
    },
    Grade {
        name: "tactical",
        p2_accel_bias_ug: None,
        p2_gyro_bias_dph: None,
        p2_share_pct: None,
        typical_accel_bias_ug: 1000.0,
        typical_gyro_bias_dph: 1.0,
        vrw_ug_per_sqrt_hz: 100.0,
        arw_deg_per_sqrt_h: 0.01,
        noise_interpolated: false,
    },
    Grade {
        name: "consumer",
        p2_accel_bias_ug: None,
        p2_gyro_bias_dph: None,
        p2_share_pct: None,
        typical_accel_bias_ug: 3000.0,
        typical_gyro_bias_dph: 100.0,
        vrw_ug_per_sqrt_hz: 1000.0,
        arw_deg_per_sqrt_h: 1.0,
        noise_interpolated: false,
    },
];

/// Look a grade up by name (case-insensitive; "navigation" is an alias of "aviation",
/// "automotive" of "consumer").
pub fn grade_by_name(name: &str) -> Option<&'static Grade> {
    let n = name.to_ascii_lowercase();
    let n = match n.as_str() {
        "navigation" => "aviation",
        "automotive" => "consumer",
        other => other,
    };
    GRADES.iter().find(|g| g.name == n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_and_units() {
        let a = grade_by_name("Navigation").map(|g| g.name);
        assert_eq!(a, Some("aviation"));
        assert!(grade_by_name("bogus").is_none());
        let av = GRADES[1];
        // spec §4.5: 20 μg/√Hz = 1.96e-4 m/s/√s
        assert!((av.vrw_si() - 1.961e-4).abs() < 0.001e-4);
        // 0.002 °/√h = 5.818e-7 rad/√s
        assert!((av.arw_si() - 5.818e-7).abs() < 0.001e-7);
    }
}
