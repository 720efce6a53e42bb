//! # sdins-sim
//!
//! Scenarios, the exact truth generator (trajectory and IMU increments), IMU error
//! models and sensor grades, Allan variance, IMU file readers, error analysis and
//! Monte Carlo. Builds on the `no_std` navigation core, `sdins-core`.
//!
//! ## Quick start: scenario → run → errors
//!
//! A [`scenario::Scenario`] (built in or a TOML file, docs/scenarios.md) defines the
//! trajectory and the IMU; [`nav::pipeline::run`] generates the exact truth and its IMU
//! increments once and navigates every algorithm on them, calling the observer at each
//! output epoch with the errors against the truth (position δN, δE, δD in metres,
//! velocity in m/s, attitude ε in rad; docs/conventions.md).
//!
//! ```
//! use sdins_core::nav::{AlgorithmKind, AlgorithmSpec};
//! use sdins_sim::nav::pipeline::{run, RunOptions};
//! use sdins_sim::scenario::Scenario;
//!
//! let scn = Scenario::load("turn-90dps")?; // Mach 1 east, 90°/s turn from 6 to 8 s
//! let opts = RunOptions {
//!     algos: vec![
//!         AlgorithmSpec::new(AlgorithmKind::Savage, 3),
//!         AlgorithmSpec::new(AlgorithmKind::DualQuat, 3),
//!     ],
//!     vertical_hold: false,
//!     every_s: Some(0.6),  // output rows every 0.6 s (the updates nearest to k·0.6 s)
//!     until_s: Some(10.0), // through the turn
//!     sensor_run: None,    // ideal sensors: the errors are the algorithms' own
//! };
//! let mut epochs = 0;
//! let sums = run(&scn, &opts, |_algo, _state, _truth, _err| epochs += 1, |_, _| {})?;
//! assert!(epochs > 0);
//! let pos = |i: usize| {
//!     let p = sums[i].final_err.pos_err_ned_m;
//!     p[0].hypot(p[1])
//! };
//! println!("horizontal error after 10 s: Savage {:.2e} m, dual quaternion {:.2e} m", pos(0), pos(1));
//! // the dual quaternion's coning/sculling is exact to higher order through the turn
//! assert!(pos(1) < pos(0));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! `cargo run --release -p sdins-sim --example navigate` is the same tour at full length.

pub mod align;
pub mod analysis;
pub mod cancel;
pub mod fusion;
pub mod input;
pub mod io;
pub mod nav;
pub mod scenario;
pub mod sensors;
pub mod truth;
