//! # sdins-core
//!
//! `#![no_std]`, allocation-free strapdown inertial navigation mathematics: attitude
//! representations, the WGS-84 earth model and its variants, coning/sculling
//! compensation and the navigation mechanizations. This crate is what would run on a
//! flight computer; everything here works on fixed-size values.
//!
//! Conventions (stated once for the whole project, see `docs/conventions.md`):
//! * navigation frame `n` is local-level **NED**, body frame `b` is **FRD**;
//! * `c_b_n` is the direction-cosine matrix taking body coordinates to navigation
//!   coordinates, `v_n = c_b_n * v_b`;
//! * quaternions are **Hamilton, scalar first**: `q_b_n` satisfies
//!   `(0, v_n) = q_b_n ⊗ (0, v_b) ⊗ q_b_n*`;
//! * Euler angles are 3-2-1 (yaw, pitch, roll): `c_b_n = Rz(yaw) Ry(pitch) Rx(roll)`;
//! * attitude errors use convention G: `c_b_n_est = (I + [eps×]) c_b_n_true`.
//!
//! ## Quick start: a flight-computer loop
//!
//! Pick a mechanization ([`nav::AlgorithmSpec`]: algorithm and samples per update), give it
//! the initial state, then call `update` with every N IMU increments (Δθ, Δv over one
//! sample, body FRD). Nothing allocates. Here the vehicle is at rest at 45° N, so the exact
//! increments are constant, `Δθ = C_n^b ω_ie^n δt` and `Δv = −C_n^b g^n δt` (Groves 2nd
//! ed., eqs. 5.18 and 5.54 with zero velocity), and any drift is the algorithm's own error.
//!
//! ```
//! use sdins_core::coning::Increment;
//! use sdins_core::earth::EarthModel;
//! use sdins_core::math::{c_b_n_from_euler, Euler, Vec3};
//! use sdins_core::nav::{AlgorithmKind, AlgorithmSpec, AnyMechanization, InitialState, Mechanization};
//!
//! let earth = EarthModel::WGS84;
//! let lat = 45f64.to_radians();
//! let dt = 0.01; // 100 Hz IMU
//! let c_b_n = c_b_n_from_euler(&Euler::new(0.0, 0.0, 0.0));
//! let inc = Increment::new(
//!     c_b_n.transpose() * earth.omega_ie_n(lat) * dt,
//!     -(c_b_n.transpose() * earth.gravity_n(lat, 0.0)) * dt,
//! );
//! let init = InitialState { lat_rad: lat, lon_rad: 0.0, h_m: 0.0, v_n_mps: Vec3::zeros(), c_b_n };
//! let spec = AlgorithmSpec::new(AlgorithmKind::SongLeeComplete, 2);
//! let mut nav = AnyMechanization::new(&spec, earth, dt, &init);
//! for _ in 0..3000 {
//!     nav.update(&[inc; 2]); // 2 samples per update: 60 s
//! }
//! let s = nav.state();
//! assert!((s.t_s - 60.0).abs() < 1e-9);
//! // at rest the solution must stay at rest: 1 mm/s after 60 s would already be a
//! // gross error (a 1 μg accelerometer bias alone gives 0.6 mm/s)
//! assert!(s.v_n_mps.norm() < 1e-3, "{}", s.v_n_mps.norm());
//! assert!((s.lat_rad - lat).abs() < 1e-9);
//! ```
//!
//! `cargo run --release -p sdins-core --example flight_loop` runs the same loop for an hour.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod aiding;
pub mod align;
pub mod coning;
pub mod earth;
pub mod gnss;
pub mod math;
pub mod nav;

pub use math::{Mat3, Vec3};
