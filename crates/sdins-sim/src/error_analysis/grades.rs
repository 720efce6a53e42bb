//! Sensor grades for the error analysis: the one grade table of
//! [`crate::imu_error::presets`] (no copy here).

pub use crate::imu_error::presets::{grade as grade_by_name, Grade, P2Box, GRADES};
