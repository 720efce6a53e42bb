//! The exact truth: motion models and the generator of exact trajectory states and IMU
//! increments (docs/theory/mechanizations.md §"Truth generation").
//!
//! | module | what |
//! |---|---|
//! | [`trajectory`] | piecewise analytic motion segments plus attitude/linear overlays |
//! | [`vehicle`] | the attitude a vehicle takes along the nominal velocity (free, car, aircraft) |
//! | [`route`] | routes through waypoints compiled into motion segments |
//! | [`body_motion`] | the "Euler angles + body velocity" base of gnss-ins-sim motion commands |
//! | [`reference`](mod@reference) | a C² interpolant through a recorded trajectory |
//! | [`random_vibration`] | random vibration from a power spectral density |
//! | [`schedule`] | turntable calibration schedules |
//! | [`envelope`] | the kinematic envelope every trajectory is checked against |
//! | [`generator`] | the exact truth generator ([`TruthGenerator`], [`TruthSample`]) |

pub mod body_motion;
pub mod envelope;
pub mod generator;
pub mod random_vibration;
pub mod reference;
pub mod route;
pub mod schedule;
pub mod trajectory;
pub mod vehicle;

pub use generator::{
    auto_substeps, lon_diff, ImuMount, TruthConfig, TruthGenerator, TruthSample, TruthScheme,
};
pub use trajectory::Trajectory;
