//! Alignment and calibration: the alignment experiments on exact or recorded data
//! ([`experiment`]), the `align` procedure as one call ([`run`]) and IMU calibration
//! ([`calibration`]). The algorithms themselves are `sdins_core::align`.

pub mod calibration;
pub mod experiment;
pub mod run;
