//! Aided navigation: the linear navigation-error model and the INS/GNSS error-state
//! Kalman filter with closed-loop correction (see `docs/theory/ins-gnss.md`), and the
//! stationarity (zero-velocity) detector (`docs/theory/aiding-sensors.md`).

pub mod ekf;
pub mod error_model;
pub mod rts;
pub mod stationarity;
