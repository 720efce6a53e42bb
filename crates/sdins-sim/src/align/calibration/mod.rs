//! IMU calibration: turntable schedules ([`crate::truth::schedule`], a kind of motion), the least-squares estimator of
//! biases, scale factors and misalignments ([`estimate`]) and simulated runs and Monte
//! Carlo ([`run`]). Theory and conventions: docs/theory/calibration.md.

pub mod estimate;
pub mod request;
pub mod run;
pub mod table;

pub use crate::truth::schedule::{Schedule, ScheduleError, Standard, Step};
pub use estimate::{EstimateError, TriadAccumulator, TriadEstimate};
pub use run::{
    calibrate_scenario, monte_carlo, CalibrationError, CalibrationRun, DrawSpec, MonteCarloSummary,
    N_PARAMS,
};
