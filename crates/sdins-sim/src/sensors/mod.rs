//! Sensor models: the IMU error models and grades ([`imu_error`]), the GNSS receiver
//! simulator ([`gnss`]) and the GNSS fix it produces ([`gnss_fix`], the datum the readers
//! and the filter share), the raw GNSS measurement simulator ([`raw_gnss`]).

pub mod aiding;
pub mod gnss;
pub mod gnss_fix;
pub mod imu_error;
pub mod raw_gnss;

pub use gnss_fix::GnssFix;
