//! Sensor grades for the error analysis: the one grade table of
//! [`crate::sensors::imu_error::presets`] (no copy here).

pub use crate::sensors::imu_error::presets::{grade as grade_by_name, Grade, P2Box, GRADES};
