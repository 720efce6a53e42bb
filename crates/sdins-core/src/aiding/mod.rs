//! Aided navigation: the linear navigation-error model, the state layout, the measurement
//! interface and the error-state Kalman filter with closed-loop correction, and the
//! Rauch–Tung–Striebel smoother step (see `docs/theory/ins-gnss.md`); the stationarity
//! (zero-velocity) detector and the measurement models of the other aiding sensors
//! (barometer, odometer, magnetometer, dual-antenna GNSS, body velocity;
//! `docs/theory/aiding-sensors.md`).

pub mod ekf;
pub mod error_model;
pub mod history;
pub mod layout;
pub mod linalg;
pub mod meas;
pub mod rts;
pub mod sensors;
pub mod stationarity;
