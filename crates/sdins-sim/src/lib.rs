//! # sdins-sim
//!
//! Scenarios, the exact truth generator (trajectory and IMU increments), IMU error
//! models and sensor grades, Allan variance, IMU file readers, error analysis and
//! Monte Carlo. Builds on the `no_std` navigation core, `sdins-core`.

pub mod align;
pub mod allan;
pub mod cancel;
pub mod envelope;
pub mod error_analysis;
pub mod fuse;
pub mod gnss;
pub mod gnss_fix;
pub mod imu_error;
pub mod imu_file;
pub mod initial;
pub mod montecarlo;
pub mod pipeline;
pub mod scenario;
pub mod trajectory;
pub mod truth;
pub mod truth_file;
